//! The runs bvkit compiles once, in itself ([`Route`]), and the dispatch to them. A run's
//! boxes, poses and output each say which route they take (their `ROUTE` constant) and
//! hand themselves over by name ([`NamedBoxes`], [`NamedPoses`], [`NamedBoxesMut`]);
//! where all three agree ([`Route::of`]), [`Engine::run`] hands the names to the route's
//! function, which is neither generic nor inlined: a caller's call site then compiles a
//! call rather than the loops. Any other run takes the lane loop where it is called.
//!
//! The routes: AoS 3D boxes with AoS or shared poses of a 3D class ([`aos`]: the AoS loop,
//! or on the scalar backend the lane loop), or a [`Swept`](crate::Swept) pair of them
//! ([`aos`] at each pose, and the union); AoSoA blocks of 3D boxes with blocks of rigid
//! poses ([`blocks`]); and, in a transform only, SoA columns of 3D boxes with columns of
//! rigid poses ([`soa`]) and AoS 2D boxes with AoS rigid 2D poses ([`aos2`]): the lane
//! loop. The layouts and classes name themselves where they are defined (`layout`,
//! `transform`), below the engine; the sinks name themselves here.

use super::{Active, AosCall, AosSink, CHUNK, Engine, Fat, PoseSource, Sink, Store};
use crate::aabb::{Aabb2, Aabb3};
use crate::fat::{Margin, Moved};
use crate::layout::{
    Aabb3x8, AabbSoaMut, AabbSoaRef, AosPoses, BoxSink, BoxSource, NamedBoxes, NamedBoxesMut,
    NamedPoses, Rigid3SoaRef, Rigid3x8, Route,
};
use crate::method::{Method, Rounding};
use crate::simd::Backend;
use crate::transform::Rigid2;

/// A sink by name: its output, and what it does with the tight boxes.
pub(crate) enum NamedSink<'s> {
    /// The plain sink: every tight box written to `out`.
    Store {
        /// The boxes written.
        out: NamedBoxesMut<'s>,
        /// Store whole AoSoA blocks past the caches.
        stream: bool,
    },
    /// The update's sink over the fat boxes `fat`.
    Fat {
        /// The fat boxes.
        fat: NamedBoxesMut<'s>,
        /// How much a rewritten fat box exceeds its tight box.
        margin: Margin,
        /// The objects whose fat box was rewritten.
        moved: &'s mut Moved,
    },
}

/// How a sink names itself: the route of its output, and its output by name.
pub(crate) trait SinkRoute<const N: usize>: Sink<N> {
    /// The run of this sink's output that bvkit compiles once, if any.
    const ROUTE: Route;
    /// The sink by name, where [`SinkRoute::ROUTE`] is not [`Route::Generic`].
    fn named(&mut self) -> Option<NamedSink<'_>>;
}

impl<const N: usize, O: BoxSink<N>> SinkRoute<N> for Store<O> {
    const ROUTE: Route = O::ROUTE;
    #[inline(always)]
    fn named(&mut self) -> Option<NamedSink<'_>> {
        let stream = self.stream;
        Some(NamedSink::Store {
            out: self.out.named_boxes_mut()?,
            stream,
        })
    }
}

impl<const N: usize, F: BoxSink<N>> SinkRoute<N> for Fat<'_, F> {
    /// Columns of boxes and 2D boxes have a route in a transform only: an update's fat sink
    /// over columns took the library's IR past its budget (`docs/speed.md`, "Compile time
    /// of a call site").
    const ROUTE: Route = match F::ROUTE {
        Route::Soa | Route::Aos2 => Route::Generic,
        route => route,
    };
    #[inline(always)]
    fn named(&mut self) -> Option<NamedSink<'_>> {
        Some(NamedSink::Fat {
            fat: self.fat.named_boxes_mut()?,
            margin: self.margin,
            moved: &mut *self.moved,
        })
    }
}

impl<const N: usize, B: BoxSource<N>, P: PoseSource<N>, S: SinkRoute<N>> Engine<'_, N, B, P, S> {
    /// The route of this run: the one its boxes, poses and output all name.
    pub(crate) const ROUTE: Route = Route::of(B::ROUTE, P::ROUTE, S::ROUTE);
    /// No route: the lane loop, compiled at the call site. A `bool` constant, so that the
    /// branch below is decided before monomorphization: a `matches!` on [`Self::ROUTE`]
    /// is not, and a call site then compiled the lane loop too (5.3 s against 0.46 s for
    /// `tests/callsite`'s release rebuild, Intel Xeon; the single-unit IR count hid it).
    const GENERIC: bool = matches!(Self::ROUTE, Route::Generic);

    /// Runs on `backend` (`fused` lets the lanes fuse multiply-adds): on the run's
    /// [`Route`], in code compiled once in bvkit; without one, in the lane loop compiled
    /// here.
    #[inline(always)]
    pub fn run(self, backend: Backend, fused: bool) {
        if Self::GENERIC {
            return self.run_lanes(backend, fused);
        }
        let Engine {
            local,
            poses,
            mut sink,
            active,
            method,
            rounding,
            ..
        } = self;
        let call = RouteCall {
            active,
            method,
            rounding,
            backend,
            fused,
        };
        let predicted = poses.named_predicted();
        match (local.named_boxes(), poses.named_poses(), sink.named()) {
            (Some(NamedBoxes::Aos(local)), Some(NamedPoses::Aos(poses)), Some(sink)) => {
                // A swept run has its predicted poses, and only a swept run.
                let predicted = match (Self::ROUTE, predicted) {
                    (Route::Aos, None) => None,
                    (Route::Swept, Some(NamedPoses::Aos(predicted))) => Some(predicted),
                    _ => mismatch(),
                };
                match sink {
                    NamedSink::Store {
                        out: NamedBoxesMut::Aos(out),
                        ..
                    } => aos(call, local, poses, predicted, AosOut::Store(out)),
                    NamedSink::Fat {
                        fat: NamedBoxesMut::Aos(fat),
                        margin,
                        moved,
                    } => aos(
                        call,
                        local,
                        poses,
                        predicted,
                        AosOut::Fat(fat, margin, moved),
                    ),
                    _ => mismatch(),
                }
            }
            (Some(NamedBoxes::Blocks(local)), Some(NamedPoses::Blocks(poses)), Some(sink)) => {
                match sink {
                    NamedSink::Store {
                        out: NamedBoxesMut::Blocks(out),
                        stream,
                    } => blocks(call, local, poses, BlocksOut::Store(Store { out, stream })),
                    NamedSink::Fat {
                        fat: NamedBoxesMut::Blocks(fat),
                        margin,
                        moved,
                    } => blocks(
                        call,
                        local,
                        poses,
                        BlocksOut::Fat(Fat { fat, margin, moved }),
                    ),
                    _ => mismatch(),
                }
            }
            (
                Some(NamedBoxes::Soa(local)),
                Some(NamedPoses::Soa(poses)),
                Some(NamedSink::Store {
                    out: NamedBoxesMut::Soa(out),
                    stream,
                }),
            ) => soa(call, local, poses, out, stream),
            (
                Some(NamedBoxes::Aos2(local)),
                Some(NamedPoses::Aos2(poses)),
                Some(NamedSink::Store {
                    out: NamedBoxesMut::Aos2(out),
                    stream,
                }),
            ) => aos2(call, local, poses, Store { out, stream }),
            _ => mismatch(),
        }
    }
}

/// The one arm no run reaches: [`Route::of`] gives a route other than
/// [`Route::Generic`] only when the boxes, poses and output name it together (the
/// poses `Swept` with AoS boxes and output for [`Route::Swept`]); every layout and sink
/// names itself with its route's variants whenever its `ROUTE` says so, and a swept pair
/// names its predicted poses too (a test in `batch` checks each layout, pose kind and
/// sink).
#[cold]
fn mismatch() -> ! {
    unreachable!("a run on a route is named by that route's variants (tested in batch)")
}

/// What every route takes besides its boxes, poses and sink: the objects visited, the
/// method, the rounding and the backend.
#[derive(Clone, Copy)]
struct RouteCall<'a> {
    active: Active<'a>,
    method: Method,
    rounding: Rounding,
    backend: Backend,
    fused: bool,
}

impl RouteCall<'_> {
    /// The lane loop over `len` objects into `sink`.
    fn lane_loop<const N: usize, B: BoxSource<N>, P: PoseSource<N>>(
        self,
        local: B,
        poses: P,
        len: usize,
        sink: impl Sink<N>,
    ) {
        let engine = Engine {
            local,
            poses,
            sink,
            len,
            active: self.active,
            method: self.method,
            rounding: self.rounding,
        };
        engine.run_lanes(self.backend, self.fused);
    }
}

/// The AoS route's output: boxes written, or fat boxes compared.
enum AosOut<'s> {
    Store(&'s mut [Aabb3]),
    Fat(&'s mut [Aabb3], Margin, &'s mut Moved),
}

/// The blocks route's sink: the plain sink or the fat sink over blocks.
enum BlocksOut<'s> {
    Store(Store<&'s mut [Aabb3x8]>),
    Fat(Fat<'s, &'s mut [Aabb3x8]>),
}

/// [`Route::Aos`]: the AoS loop with the poses' class, or on the scalar backend the lane
/// loop ([`AosCall::run`]); on [`Route::Swept`] (`predicted` given), that at each pose and
/// the union ([`AosCall::swept`]). Neither generic nor inlined, so that it is compiled
/// once, in bvkit, for the five classes and both sinks.
#[inline(never)]
fn aos(
    call: RouteCall<'_>,
    local: &[Aabb3],
    poses: AosPoses<'_>,
    predicted: Option<AosPoses<'_>>,
    out: AosOut<'_>,
) {
    let call = AosCall {
        local,
        poses,
        active: call.active,
        method: call.method,
        rounding: call.rounding,
        backend: call.backend,
    };
    let mut scratch;
    let sink = match out {
        AosOut::Store(out) => AosSink::Store(out),
        AosOut::Fat(fat, margin, moved) => {
            scratch = [Aabb3::EMPTY; CHUNK];
            AosSink::Fat(Fat { fat, margin, moved }, &mut scratch)
        }
    };
    match predicted {
        None => call.run(sink),
        Some(predicted) => call.swept(predicted, sink),
    }
}

/// [`Route::Blocks`]: the lane loop over AoSoA blocks of boxes and of rigid poses, on every
/// backend. Compiled once, in bvkit, as [`aos`] is.
#[inline(never)]
fn blocks(call: RouteCall<'_>, local: &[Aabb3x8], poses: &[Rigid3x8], sink: BlocksOut<'_>) {
    match sink {
        BlocksOut::Store(sink) => call.lane_loop(local, poses, local.len() * 8, sink),
        BlocksOut::Fat(sink) => call.lane_loop(local, poses, local.len() * 8, sink),
    }
}

/// [`Route::Soa`]: the lane loop over columns of boxes and of rigid poses, on every
/// backend, in a transform. Compiled once, in bvkit, as [`aos`] is.
#[inline(never)]
fn soa(
    call: RouteCall<'_>,
    local: [&[f32]; 6],
    poses: [&[f32]; 7],
    out: [&mut [f32]; 6],
    stream: bool,
) {
    let len = local[0].len();
    let sink = Store {
        out: AabbSoaMut::new(out),
        stream,
    };
    call.lane_loop(AabbSoaRef::new(local), Rigid3SoaRef::new(poses), len, sink);
}

/// [`Route::Aos2`]: the lane loop over AoS 2D boxes and rigid poses, on every backend, in a
/// transform. Compiled once, in bvkit, as [`aos`] is.
#[inline(never)]
fn aos2(call: RouteCall<'_>, local: &[Aabb2], poses: &[Rigid2], sink: Store<&mut [Aabb2]>) {
    call.lane_loop(local, poses, local.len(), sink);
}
