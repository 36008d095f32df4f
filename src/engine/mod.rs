//! The engine under every batch transform and every broadphase update: the active set,
//! the lane loop and the AoS loop, from a box source and a pose source into a sink.
//!
//! A run reads each active object's local box, computes its tight world box from its pose,
//! and hands it to a sink: [`Store`] writes it (the batch transform), the fat sink ([`Fat`])
//! compares it with the fat box and records what moved. Two loops do this:
//! - [`Engine`], in lanes, for every layout; lanes whose result does not stand are redone
//!   one at a time on the extended path, and the sink takes those too;
//! - the AoS loop, for AoS 3D boxes with AoS or shared poses, on the single-box kernel
//!   (glam's `Vec3A`), on every backend but the scalar one.
//!
//! The layouts of a route (AoS 3D boxes with AoS or shared poses, or a `Swept` pair of
//! them; AoSoA blocks of 3D boxes with blocks of rigid poses; and, in a transform, SoA
//! columns of 3D boxes with columns of rigid poses, and AoS 2D boxes with AoS rigid 2D
//! poses) run in code compiled here once: [`Engine::run`] hands them over by name
//! ([`route`]). Every other layout runs the lane loop compiled where it is called.

/// `$body` once per method, with `$m` bound to it as a constant, so that each copy is
/// specialised to its kernel: the one place the methods are spelled out. With `if $cond`
/// first, only where the constant `$cond` holds; otherwise `$body` once, with `$m` the
/// method as a run-time value.
macro_rules! specialise {
    (if $cond:expr, $method:expr, |$m:ident| $body:expr) => {
        if $cond {
            specialise!($method, |$m| $body)
        } else {
            let $m = $method;
            $body
        }
    };
    ($method:expr, |$m:ident| $body:expr) => {
        match $method {
            Method::Naive => {
                let $m = Method::Naive;
                $body
            }
            Method::AbsMatrix => {
                let $m = Method::AbsMatrix;
                $body
            }
            Method::SignSelect => {
                let $m = Method::SignSelect;
                $body
            }
        }
    };
}

mod active;
mod aos;
mod route;
mod sink;

pub use active::Active;
#[cfg(feature = "rayon")]
pub(crate) use aos::window;
pub(crate) use aos::{AosCall, CHUNK};
#[cfg(test)]
pub(crate) use route::{NamedSink, SinkRoute};
pub(crate) use sink::{AosSink, Fat, Sink, Store};

use active::{
    List, Lookahead, Mask, Span, SpanWidth, Subset, Upcoming, Visit, Width, dense, mask_of,
};
use core::marker::PhantomData;

use crate::error::BatchError;
use crate::extended;
use crate::kernel;
use crate::lane::Vector;
use crate::layout::{BoxSource, Named, TransformSource};
use crate::method::{Method, Rounding};
use crate::simd::{self, Backend, Job, LaneArray};
use crate::transform::Class;

/// The poses a batch reads, for [`Batch::transform`](crate::Batch::transform) and
/// [`Batch::update`](crate::Batch::update) alike: transforms
/// of any class in any layout (AoS slices `&[T]`, AoSoA blocks, SoA columns, or one shared
/// `&T`), a [`Swept`](crate::Swept) pair of them, or [`LargeWorld`](crate::LargeWorld)
/// poses. Sealed, as
/// [`BoxSource`].
pub trait PoseSource<const N: usize>: Named {
    #[doc(hidden)]
    /// Refuses a pose count other than `len` (a shared pose has none).
    fn check_len(&self, len: usize) -> Result<(), BatchError>;
    #[doc(hidden)]
    /// The tight boxes of objects `i..i + count` from their local boxes in lanes, and a
    /// lane value `redo`: 0 where the result stands, nonzero where the object must be
    /// redone by [`PoseSource::tight_one`].
    fn tight<L: LaneArray>(
        &self,
        i: usize,
        count: usize,
        lo: Vector<L, N>,
        hi: Vector<L, N>,
        method: Method,
        outward: bool,
    ) -> (Vector<L, N>, Vector<L, N>, L);
    #[doc(hidden)]
    /// The tight box of object `i` on the extended path, which takes every input.
    fn tight_one(
        &self,
        i: usize,
        lo: [f32; N],
        hi: [f32; N],
        method: Method,
        rounding: Rounding,
    ) -> [[f32; N]; 2];
    #[doc(hidden)]
    /// Asks for object `i`'s poses ahead of a scattered access.
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        let _ = i;
    }
    #[doc(hidden)]
    /// False when [`PoseSource::tight`] has no lane form (it computes each lane on its
    /// own): the run then takes lanes of one on every backend, the scalar reference's, and
    /// compiles no other.
    const LANES: bool = true;
    #[doc(hidden)]
    /// The same poses, as the loop reads them.
    type Trimmed: PoseSource<N> + Clone;
    #[doc(hidden)]
    /// The first `len` poses, every slice cut to that length (see
    /// [`BoxSource::trim`](crate::layout::BoxSource::trim)).
    fn trim(self, len: usize) -> Self::Trimmed;
}

impl<const N: usize, X: TransformSource<N>> PoseSource<N> for X {
    fn check_len(&self, len: usize) -> Result<(), BatchError> {
        match self.len()? {
            Some(found) => BatchError::check_len("poses", len, found),
            None => Ok(()),
        }
    }
    #[inline(always)]
    fn tight<L: LaneArray>(
        &self,
        i: usize,
        count: usize,
        lo: Vector<L, N>,
        hi: Vector<L, N>,
        method: Method,
        outward: bool,
    ) -> (Vector<L, N>, Vector<L, N>, L) {
        kernel::transform_checked(&self.load::<L>(i, count), lo, hi, method, outward)
    }
    fn tight_one(
        &self,
        i: usize,
        lo: [f32; N],
        hi: [f32; N],
        _: Method,
        rounding: Rounding,
    ) -> [[f32; N]; 2] {
        let (min, max) = extended::transform(&self.get(i).extended(), lo, hi, rounding);
        [min, max]
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        TransformSource::prefetch(self, i);
    }
    type Trimmed = X::Trimmed;
    #[inline(always)]
    fn trim(self, len: usize) -> X::Trimmed {
        TransformSource::trim(self, len)
    }
}

/// The tight box of one object on the extended path, for a lane that does not stand: from
/// the run's sources, which it hands by value to an out-of-line function. The loop must
/// never take the address of its trimmed sources: their lengths would then stay in memory
/// and every column's bound be checked on every span (as happened when the cold path called
/// a closure that borrowed them); and the cold path's addressing must stay out of the loop
/// (inlined, it made LLVM keep a pointer per column, in stack slots updated on every span).
pub(crate) struct Extended<'r, B, P> {
    local: &'r B,
    poses: &'r P,
    method: Method,
    rounding: Rounding,
}

impl<B: Clone, P: Clone> Extended<'_, B, P> {
    /// Object `i`'s tight box `[min, max]`.
    #[inline(always)]
    pub(crate) fn tight<const N: usize>(&self, i: usize) -> [[f32; N]; 2]
    where
        B: BoxSource<N>,
        P: PoseSource<N>,
    {
        tight_one(
            self.local.clone(),
            self.poses.clone(),
            i,
            self.method,
            self.rounding,
        )
    }
}

/// Object `i`'s tight box on the extended path, from copies of the sources.
#[inline(never)]
fn tight_one<const N: usize, B: BoxSource<N>, P: PoseSource<N>>(
    local: B,
    poses: P,
    i: usize,
    method: Method,
    rounding: Rounding,
) -> [[f32; N]; 2] {
    let (lo, hi) = local.get(i);
    poses.tight_one(i, lo, hi, method, rounding)
}

/// One run of the engine, its lengths and its active set checked.
pub(crate) struct Engine<'a, const N: usize, B, P, S> {
    /// The local boxes.
    pub local: B,
    /// The poses.
    pub poses: P,
    /// Where the tight boxes go.
    pub sink: S,
    /// The number of objects.
    pub len: usize,
    /// The objects visited.
    pub active: Active<'a>,
    /// The method.
    pub method: Method,
    /// The rounding.
    pub rounding: Rounding,
}

impl<'a, const N: usize, B: BoxSource<N>, P: PoseSource<N>, S: Sink<N>> Engine<'a, N, B, P, S> {
    /// Runs in lanes on `backend` (`fused` lets the lanes fuse multiply-adds).
    #[inline(always)]
    pub fn run_lanes(self, backend: Backend, fused: bool) {
        self.run_jobs::<false>(backend, fused);
    }

    /// Runs in the scalar reference's lanes: what the AoS route takes on the scalar backend
    /// ([`AosCall::run`]), the one backend it takes the lane loop on, so that the AoS
    /// route compiles no other lane type's loops.
    #[inline(always)]
    pub fn run_scalar(self) {
        self.run_jobs::<true>(Backend::Scalar, false);
    }

    /// Runs in lanes, on the scalar reference's alone where `SCALAR`.
    ///
    /// The active set picks the loop before the dispatch, so that each job holds only
    /// what its loop reads: compiled beside the scattered walk, whose closures borrow the
    /// whole run, the plain loop reloaded the layouts' pointers on every span. A sink that
    /// takes every object ([`Sink::EVERY`]) compiles only that loop.
    #[inline(always)]
    fn run_jobs<const SCALAR: bool>(self, backend: Backend, fused: bool) {
        if S::EVERY {
            debug_assert_eq!(self.active, Active::All);
            return Self::dispatch::<SCALAR, _>(backend, fused, EveryInLanes(self.split().1));
        }
        match self.split() {
            (Active::All, run) => Self::dispatch::<SCALAR, _>(backend, fused, EveryInLanes(run)),
            // A dense list runs as a mask, in lanes; a sparse one an entry at a time, in one
            // lane, where spans of the lane width would rarely hold two of its objects.
            // So the lane loop compiles no walk that builds spans from a list: that walk
            // was more than a third of a call site's release rebuild (one `transform` and
            // one `update` on AoSoA blocks; more for a `Swept` update).
            (Active::Indices(ix), run) if dense(ix.len(), run.len) => {
                let words = mask_of(ix, run.len);
                Self::dispatch::<SCALAR, _>(
                    backend,
                    fused,
                    SubsetInLanes {
                        run,
                        set: Mask(&words),
                    },
                )
            }
            (Active::Indices(ix), run) => {
                Self::dispatch::<SCALAR, _>(backend, fused, SubsetInLanes { run, set: List(ix) })
            }
            (Active::Mask(words), run) => Self::dispatch::<SCALAR, _>(
                backend,
                fused,
                SubsetInLanes {
                    run,
                    set: Mask(words),
                },
            ),
        }
    }

    /// [`simd::dispatch`], or straight to the scalar reference's lanes: where `SCALAR`
    /// ([`Engine::run_scalar`]); and for poses without a lane form
    /// ([`PoseSource::LANES`]), whose lanes would only be computed one at a time (a
    /// `LargeWorld` update's call site compiled four lane types' loops for that).
    #[inline(always)]
    fn dispatch<const SCALAR: bool, J: Job>(backend: Backend, fused: bool, job: J) {
        if SCALAR || !P::LANES {
            job.run::<f32>();
        } else {
            simd::dispatch(backend, fused, job);
        }
    }

    /// [`Engine::run`] in lanes of type `L`, without the dispatch.
    #[cfg(test)]
    pub fn run_in<L: LaneArray>(self) {
        match self.split() {
            (Active::All, run) => Job::run::<L>(EveryInLanes(run)),
            (Active::Indices(ix), run) => Job::run::<L>(SubsetInLanes { run, set: List(ix) }),
            (Active::Mask(words), run) => Job::run::<L>(SubsetInLanes {
                run,
                set: Mask(words),
            }),
        }
    }

    /// The active set, and the rest of the run.
    #[inline(always)]
    fn split(self) -> (Active<'a>, Run<N, B, P, S>) {
        let run = Run {
            local: self.local,
            poses: self.poses,
            sink: self.sink,
            len: self.len,
            method: self.method,
            rounding: self.rounding,
        };
        (self.active, run)
    }
}

/// A run without its active set.
struct Run<const N: usize, B, P, S> {
    local: B,
    poses: P,
    sink: S,
    len: usize,
    method: Method,
    rounding: Rounding,
}

/// The lane loop's visit of a scattered active set, in lanes `L`, walked in spans of `W`:
/// the lane width, or one object.
struct Spans<'r, L, W, R> {
    run: &'r mut R,
    method: Method,
    outward: bool,
    lanes: PhantomData<(L, W)>,
}

impl<L: LaneArray, W: SpanWidth, const N: usize, B, P, S> Visit for Spans<'_, L, W, Run<N, B, P, S>>
where
    B: BoxSource<N> + Clone,
    P: PoseSource<N> + Clone,
    S: Sink<N>,
{
    #[inline(always)]
    fn whole(&mut self, start: usize, end: usize) {
        self.run.range::<L>(start, end, self.method, self.outward);
    }

    /// Its objects requested first; then the span runs in lanes, its inactive lanes (and
    /// those past the last object) computed and ignored, or a list's entry in one lane of
    /// the same arithmetic. A lone active object of a mask runs in lanes too: in one lane
    /// it would compile a third kernel into every walk (`docs/decisions.md`, "No one-lane
    /// kernel in a mask's walk").
    #[inline(always)]
    fn part<U: Upcoming>(&mut self, span: Span, ahead: &mut Lookahead<U>) {
        ahead.advance(span.active_lanes.count_ones() as usize);
        for i in ahead.requests() {
            self.request(i);
        }
        let (method, outward) = (self.method, self.outward);
        if W::OBJECTS == L::WIDTH {
            self.run
                .run_span::<L>(span.start, span.count, span.active_lanes, method, outward);
        } else {
            debug_assert_eq!(span.count, 1);
            self.run
                .run_span::<L::One>(span.start, 1, 1, method, outward);
        }
    }

    #[inline(always)]
    fn request(&self, i: usize) {
        self.run.prefetch(i);
    }
}

/// The lane loop over every object ([`Active::All`]).
struct EveryInLanes<const N: usize, B, P, S>(Run<N, B, P, S>);

/// The lane loop over the objects of a list or a mask: `A`, a [`Subset`] of one kind.
struct SubsetInLanes<const N: usize, B, P, S, A> {
    run: Run<N, B, P, S>,
    set: A,
}

impl<const N: usize, B: BoxSource<N>, P: PoseSource<N>, S: Sink<N>> Job
    for EveryInLanes<N, B, P, S>
{
    /// One loop per method, so that each is specialised to its kernel; the rounding is a
    /// loop-invariant branch. The scalar reference (lanes of one) has one loop, the method
    /// a run-time value: it is there to be checked against, not to be fast
    /// (`docs/decisions.md`, "One loop for the scalar reference").
    #[inline(always)]
    fn run<L: LaneArray>(self) {
        let mut run = self.0.trim();
        let outward = run.rounding == Rounding::Outward;
        let len = run.len;
        specialise!(if L::WIDTH > 1, run.method, |method| run.range::<L>(0, len, method, outward));
        run.sink.finish();
    }
}

impl<const N: usize, B: BoxSource<N>, P: PoseSource<N>, S: Sink<N>, A: Subset> Job
    for SubsetInLanes<N, B, P, S, A>
{
    /// As for [`EveryInLanes`].
    #[inline(always)]
    fn run<L: LaneArray>(self) {
        let (mut run, set) = (self.run.trim(), self.set);
        let outward = run.rounding == Rounding::Outward;
        let len = run.len;
        specialise!(if L::WIDTH > 1, run.method, |method| {
            if A::BY_ENTRY {
                let mut spans = Spans::<L, Width<1>, _> {
                    run: &mut run,
                    method,
                    outward,
                    lanes: PhantomData,
                };
                active::walk::<Width<1>>(set, len, &mut spans);
            } else {
                let mut spans = Spans::<L, L, _> {
                    run: &mut run,
                    method,
                    outward,
                    lanes: PhantomData,
                };
                active::walk::<L>(set, len, &mut spans);
            }
        });
        run.sink.finish();
    }
}

impl<const N: usize, B: BoxSource<N>, P: PoseSource<N>, S: Sink<N>> Run<N, B, P, S> {
    /// The run with every source and sink trimmed to `len`: called inside the job, so that
    /// the lengths the slices carry are the loop's own bound, and their checks fold into
    /// one per span.
    #[inline(always)]
    fn trim(self) -> Run<N, B::Trimmed, P::Trimmed, S::Trimmed> {
        let len = self.len;
        Run {
            local: self.local.trim(len),
            poses: self.poses.trim(len),
            sink: self.sink.trim(len),
            len,
            method: self.method,
            rounding: self.rounding,
        }
    }
}

impl<const N: usize, B, P, S> Run<N, B, P, S>
where
    B: BoxSource<N> + Clone,
    P: PoseSource<N> + Clone,
    S: Sink<N>,
{
    /// Objects `start..end`, every one active: a plain loop over spans of the lane width,
    /// then the tail. Over every object, walking spans is slower on cheap kernels in cache:
    /// the per-span decoding and mask tests are not free there (`docs/decisions.md`, "A
    /// plain loop where every object is active").
    #[inline(always)]
    fn range<L: LaneArray>(&mut self, start: usize, end: usize, method: Method, outward: bool) {
        let (w, mut i) = (L::WIDTH, start);
        while i + w <= end {
            self.run_span::<L>(i, w, u64::MAX >> (64 - w), method, outward);
            i += w;
        }
        // The tail. A sink that takes every object (a transform's) runs it one object at a
        // time: its loop has no other partial span, and a one-lane kernel is less code than
        // a partial span's loads and stores (`docs/decisions.md`, "A transform's tail, one
        // object at a time"). Any other runs it as one partial span, as
        // its walks run every other span, so that they compile no one-lane kernel. (A lane
        // type of one object, the scalar reference's, has no tail.)
        if S::EVERY {
            while L::WIDTH > 1 && i < end {
                self.run_span::<L::One>(i, 1, 1, method, outward);
                i += 1;
            }
        } else if i < end {
            let count = end - i;
            self.run_span::<L>(i, count, u64::MAX >> (64 - count), method, outward);
        }
    }

    /// Asks for object `i`'s local box, poses and output.
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        self.local.prefetch(i);
        self.poses.prefetch(i);
        self.sink.prefetch(i);
    }

    /// Objects `i..i + count` in lanes, into the sink. Inlined into the dispatch wrapper,
    /// for its target features, except in debug builds: there every inlined copy keeps
    /// its own stack slots, and the six copies of a [`crate::Swept`] update's two kernels
    /// needed more than a 2 MiB thread stack. Out of line it computes the same bits (a
    /// fused multiply-add is correctly rounded with or without the instruction).
    #[cfg_attr(not(debug_assertions), inline(always))]
    #[cfg_attr(debug_assertions, inline(never))]
    fn run_span<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        active_lanes: u64,
        method: Method,
        outward: bool,
    ) {
        let (lo, hi) = self.local.load::<L>(i, count);
        let (min, max, redo) = self.poses.tight::<L>(i, count, lo, hi, method, outward);
        let extended = Extended {
            local: &self.local,
            poses: &self.poses,
            method,
            rounding: self.rounding,
        };
        self.sink
            .span(i, count, active_lanes, [min, max], redo, &extended);
    }
}
