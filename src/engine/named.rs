//! The runs bvkit compiles once, in itself ([`Route`]): a generic call site hands its
//! boxes, poses and output over by name ([`NamedBoxes`], [`NamedPoses`], the sink's output), and
//! compiles a call rather than the loops.

use super::{Active, AosCall, AosSink, Engine, Fat, PoseSource, Store};
use crate::aabb::Aabb2;
#[cfg(doc)]
use crate::layout::Route;
use crate::layout::{Aabb3x8, AabbSoaMut, BoxSource, NamedBoxes, Rigid3SoaRef};
use crate::method::{Method, Rounding};
use crate::simd::Backend;
use crate::transform::NamedPoses;

/// A run on a [`Route`], its lengths and its active set checked, with its boxes and poses
/// by name: what the engine hands to its sink ([`super::Sink::run_named`]), which adds
/// itself by name and calls the route's function ([`NamedCall::aos`], [`NamedCall::blocks`],
/// [`NamedCall::soa`] or [`NamedCall::aos2`]).
#[derive(Clone, Copy)]
pub(crate) struct NamedCall<'a> {
    /// The local boxes.
    pub local: NamedBoxes<'a>,
    /// The poses (a [`Swept`](crate::Swept) pair's current ones).
    pub poses: NamedPoses<'a>,
    /// A [`Swept`](crate::Swept) pair's predicted poses ([`Route::Swept`]).
    pub predicted: Option<NamedPoses<'a>>,
    /// The objects visited.
    pub active: Active<'a>,
    /// The method.
    pub method: Method,
    /// The rounding.
    pub rounding: Rounding,
    /// The backend.
    pub backend: Backend,
    /// The lanes may fuse multiply-adds.
    pub fused: bool,
}

/// The sinks of a route of the lane loop ([`Route::Blocks`]): the plain sink or the fat
/// sink over output `O`.
pub(crate) enum LaneSink<'a, O> {
    /// Every tight box written.
    Store(Store<O>),
    /// Each tight box compared with its fat box.
    Fat(Fat<'a, O>),
}

impl NamedCall<'_> {
    /// [`Route::Aos`] into `sink`: the AoS loop with the poses' class, or on the scalar
    /// backend the lane loop ([`AosCall::run`]); on [`Route::Swept`], that at each pose
    /// and the union ([`AosCall::swept`]). Neither generic nor inlined, so that it is
    /// compiled once, in bvkit, for the five classes and both sinks.
    #[inline(never)]
    pub fn aos(self, sink: AosSink<'_>) {
        let NamedBoxes::Aos(local) = self.local else {
            unreachable!("AoS boxes name themselves so (a test checks every layout)");
        };
        let call = AosCall {
            local,
            poses: self.poses,
            active: self.active,
            method: self.method,
            rounding: self.rounding,
            backend: self.backend,
        };
        match self.predicted {
            None => call.run(sink),
            Some(predicted) => call.swept(predicted, sink),
        }
    }

    /// [`Route::Blocks`] into `sink`: the lane loop over AoSoA blocks of boxes and of rigid
    /// poses, on every backend. Compiled once, in bvkit, as [`NamedCall::aos`] is.
    #[inline(never)]
    pub fn blocks(self, sink: LaneSink<'_, &mut [Aabb3x8]>) {
        let (NamedBoxes::Blocks(local), NamedPoses::Rigid3x8(poses)) = (self.local, self.poses)
        else {
            unreachable!("blocks of boxes and of rigid poses name themselves so (tested)");
        };
        match sink {
            LaneSink::Store(sink) => self.lane_loop(local, poses, local.len() * 8, sink),
            LaneSink::Fat(sink) => self.lane_loop(local, poses, local.len() * 8, sink),
        }
    }

    /// [`Route::Soa`] into `sink`: the lane loop over columns of boxes and of rigid poses,
    /// on every backend, in a transform. Compiled once, in bvkit, as [`NamedCall::aos`]
    /// is. An update's fat sink over columns has no route: its walks would have cost the
    /// library 75K lines of IR (607,114 against 531,692), past its budget.
    #[inline(never)]
    pub fn soa(self, sink: Store<AabbSoaMut<'_>>) {
        let (NamedBoxes::Soa(local), NamedPoses::Rigid3Soa(poses)) = (self.local, self.poses)
        else {
            unreachable!("columns of boxes and of rigid poses name themselves so (tested)");
        };
        let len = local.columns[0].len();
        self.lane_loop(local, Rigid3SoaRef::new(poses), len, sink);
    }

    /// [`Route::Aos2`] into `sink`: the lane loop over AoS 2D boxes and rigid poses, on
    /// every backend, in a transform. Compiled once, in bvkit, as [`NamedCall::aos`] is.
    #[inline(never)]
    pub fn aos2(self, sink: Store<&mut [Aabb2]>) {
        let (NamedBoxes::Aos2(local), NamedPoses::Rigid2(poses)) = (self.local, self.poses) else {
            unreachable!("2D boxes and rigid poses name themselves so (tested)");
        };
        self.lane_loop(local, poses, local.len(), sink);
    }

    /// The lane loop over `len` objects into `sink`.
    fn lane_loop<const N: usize, B: BoxSource<N>, P: PoseSource<N>>(
        self,
        local: B,
        poses: P,
        len: usize,
        sink: impl super::Sink<N>,
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
