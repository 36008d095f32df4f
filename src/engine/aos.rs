//! The AoS loop of 3D boxes: each box as glam stores it, through the single-box kernel.
//!
//! Gathering AoS boxes and transforms into one-field-per-register lanes costs a shuffle per
//! field per box, more than the kernel itself (measured in `docs/speed.md`). So `&[Aabb3]`
//! boxes with AoS or shared transforms run the single-box kernel on glam's `Vec3A`
//! layout, several boxes per vector ([`BoxGroup`]: one per 128-bit part), and redo a chunk
//! box by box with [`Aabb3::transformed`] where its test fails: the same bits as the single-box
//! calls on every backend (which never fuse), and the same contract, the extended path
//! included.

use core::marker::PhantomData;

use glam::Vec3A;

use super::active::{self, List, Lookahead, Mask, Span, SpanWidth, Subset, Upcoming, Visit, Width};
use super::{Active, AosSink, Engine, PoseSource, Sink, Store};
use crate::aabb::Aabb3;
use crate::kernel::{MapKernel, gather};
use crate::layout::{AosPoses, Maps};
use crate::method::{Method, Rounding};
use crate::simd::{self, Backend, BoxGroup, GroupJob};
use crate::transform::{Rigid3, Similarity3, Transform3, Translation3, Trs3};

/// The objects of a span of a mask's walk ([`active::walk`]): a mask word's worth, whole
/// words that follow each other run several boxes per vector (`docs/decisions.md`, "The
/// AoS loop's spans of 64"). An index list is walked one entry at a time.
const SPAN: usize = 64;

/// The validity test of the AoS loop is taken once per this many objects.
pub(crate) const CHUNK: usize = 64;

/// The single-box kernel of one method and rounding, and its groups `P` of `W` boxes. A
/// method call rather than a closure: a closure was compiled out of line, with the method as
/// a run-time value where each loop has it as a constant.
pub(crate) struct Tight<P, const W: usize> {
    method: Method,
    rounding: Rounding,
    groups: PhantomData<P>,
}

impl<P, const W: usize> Clone for Tight<P, W> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<P, const W: usize> Copy for Tight<P, W> {}

impl<P: BoxGroup<W>, const W: usize> Tight<P, W> {
    /// The tight world box of `local` at `pose`.
    #[inline(always)]
    pub fn of<T: Transform3>(self, local: &Aabb3, pose: &T) -> Aabb3 {
        local.transformed(pose, self.method, self.rounding)
    }

    /// `out[k] = self.of(&local[k], poses.at(start + k))` for every `k`, `W` objects per
    /// vector of `P`. The single-box kernel's own test (`lo <= hi`, finite faces) is
    /// gathered over each chunk of [`CHUNK`] objects, and a chunk where it fails anywhere is
    /// redone one object at a time with [`Tight::of`]. Each part of a group runs the
    /// operations of the single-box kernel, so every object gets exactly `of`'s bits.
    ///
    /// Every walk passes poses of one variant, built where it calls: inlined, the match on
    /// it folds away, and each kernel compiles one loop per variant.
    #[inline(always)]
    pub fn boxes<T: Transform3>(
        self,
        local: &[Aabb3],
        poses: Maps<'_, T>,
        start: usize,
        out: &mut [Aabb3],
    ) {
        for (c, (local, out)) in local.chunks(CHUNK).zip(out.chunks_mut(CHUNK)).enumerate() {
            let first = start + c * CHUNK;
            let stands = match poses {
                Maps::Each(poses) => {
                    let groups = poses[first..].chunks_exact(W).map(|g| gather(|k| &g[k]));
                    self.groups(local, groups, out)
                }
                Maps::Shared(pose) => self.groups(local, core::iter::repeat([pose; W]), out),
            };
            for k in local.len() - local.len() % W..local.len() {
                out[k] = self.of(&local[k], poses.at(first + k));
            }
            if !P::all_xyz(stands) {
                core::hint::cold_path();
                for (k, (l, o)) in local.iter().zip(out.iter_mut()).enumerate() {
                    *o = self.of(l, poses.at(first + k));
                }
            }
        }
    }

    /// The whole groups of a chunk, `out[k]` from `local[k]` at the poses `groups` yields
    /// `W` at a time: the single-box kernel's test, set where every result stands.
    #[inline(always)]
    fn groups<'p, T: Transform3 + 'p>(
        self,
        local: &[Aabb3],
        groups: impl Iterator<Item = [&'p T; W]>,
        out: &mut [Aabb3],
    ) -> P::Mask {
        let outward = self.rounding == Rounding::Outward;
        let mut stands = P::all_set();
        let boxes = local.chunks_exact(W).zip(out.chunks_exact_mut(W));
        for ((l, o), group) in boxes.zip(groups) {
            let maps = gather(|k| group[k].simd());
            let map = T::join(&maps, P::join);
            let lo = P::join(gather(|k| l[k].min));
            let hi = P::join(gather(|k| l[k].max));
            let (min, max) = map.transform(lo, hi, self.method, outward);
            stands = P::and(stands, P::stands(lo, hi, min, max));
            for ((o, min), max) in o.iter_mut().zip(min.parts()).zip(max.parts()) {
                *o = Aabb3 { min, max };
            }
        }
        stands
    }
}

/// A run of the AoS loop, its lengths and its active set checked: everything but the
/// poses.
pub(crate) struct AosRun<'a> {
    /// The local boxes.
    pub local: &'a [Aabb3],
    /// Where the tight boxes go.
    pub sink: AosSink<'a>,
    /// The objects visited.
    pub active: Active<'a>,
    /// The method.
    pub method: Method,
    /// The rounding.
    pub rounding: Rounding,
}

impl AosRun<'_> {
    /// Runs over the active objects with `maps`, on a backend that [`takes_aos`]. Each walk
    /// is a job of its own, so that its loop has the dispatch wrapper's registers to
    /// itself: compiled beside the scattered walks, the loop over every object kept the
    /// output pointer on the stack. The plain sink takes every object.
    #[inline(always)]
    pub fn run<T: Transform3>(self, maps: Maps<'_, T>, backend: Backend) {
        debug_assert!(matches!(self.sink, AosSink::Fat(..)) || self.active == Active::All);
        match self.active {
            Active::All => simd::dispatch_groups(backend, EveryInGroups { run: self, maps }),
            // A list's objects are scattered: they run in no group, compiled once for the
            // baseline.
            Active::Indices(ix) => SubsetInGroups {
                run: self,
                maps,
                set: List(ix),
                width: PhantomData::<Width<1>>,
            }
            .run::<1, Vec3A>(),
            Active::Mask(words) => simd::dispatch_groups(
                backend,
                SubsetInGroups {
                    run: self,
                    maps,
                    set: Mask(words),
                    width: PhantomData::<Width<SPAN>>,
                },
            ),
        }
    }
}

/// True where the AoS loop runs: every backend but the scalar reference, in both modes (the
/// single-box kernel never fuses, so it gives the reference's bits).
#[inline(always)]
pub(crate) fn takes_aos(backend: Backend) -> bool {
    backend != Backend::Scalar
}

/// The poses of objects `start..start + len` (a shared pose stays whole), or `None` past
/// the end: what one part of a parallel batch reads, or one block of a swept run.
pub(crate) fn window(poses: AosPoses<'_>, start: usize, len: usize) -> Option<AosPoses<'_>> {
    fn part<T>(maps: Maps<'_, T>, start: usize, len: usize) -> Option<Maps<'_, T>> {
        match maps {
            Maps::Each(poses) => Some(Maps::Each(poses.get(start..start.checked_add(len)?)?)),
            shared @ Maps::Shared(_) => Some(shared),
        }
    }
    Some(match poses {
        AosPoses::Translation3(p) => AosPoses::Translation3(part(p, start, len)?),
        AosPoses::Rigid3(p) => AosPoses::Rigid3(part(p, start, len)?),
        AosPoses::Similarity3(p) => AosPoses::Similarity3(part(p, start, len)?),
        AosPoses::Trs3(p) => AosPoses::Trs3(part(p, start, len)?),
        AosPoses::Affine3A(p) => AosPoses::Affine3A(part(p, start, len)?),
    })
}

/// A run of the engine over AoS 3D boxes with AoS or shared poses (`Route::Aos`), with
/// the poses by name: what the AoS route ([`super::route`]) runs, once in bvkit for both sinks,
/// not at every call site.
#[derive(Clone, Copy)]
pub(crate) struct AosCall<'a> {
    /// The local boxes.
    pub local: &'a [Aabb3],
    /// The poses.
    pub poses: AosPoses<'a>,
    /// The objects visited.
    pub active: Active<'a>,
    /// The method.
    pub method: Method,
    /// The rounding.
    pub rounding: Rounding,
    /// The backend.
    pub backend: Backend,
}

impl AosCall<'_> {
    /// Runs into `sink`, with the poses in their class's type: the AoS loop, or on the
    /// scalar backend the lane loop. Called from one function only, which is neither
    /// generic nor inlined (the AoS route's, in [`super::route`]).
    #[inline(always)]
    pub fn run(self, sink: AosSink<'_>) {
        match self.poses {
            AosPoses::Translation3(maps) => self.class::<Translation3>(maps, sink),
            AosPoses::Rigid3(maps) => self.class::<Rigid3>(maps, sink),
            AosPoses::Similarity3(maps) => self.class::<Similarity3>(maps, sink),
            AosPoses::Trs3(maps) => self.class::<Trs3>(maps, sink),
            AosPoses::Affine3A(maps) => self.class::<glam::Affine3A>(maps, sink),
        }
    }

    /// [`AosCall::run`] with poses of class `T`. Not forced inline: in a debug build, the
    /// five classes' loops inlined into one function took a 1.3 MB stack frame.
    fn class<T: Transform3>(self, maps: Maps<'_, T>, sink: AosSink<'_>) {
        if takes_aos(self.backend) {
            let run = AosRun {
                local: self.local,
                sink,
                active: self.active,
                method: self.method,
                rounding: self.rounding,
            };
            return run.run(maps, self.backend);
        }
        match maps {
            Maps::Each(poses) => self.sink(poses, sink),
            Maps::Shared(pose) => self.sink(pose, sink),
        }
    }

    /// The lane loop with `poses` into `sink`, on the scalar backend.
    fn sink<P: PoseSource<3>>(self, poses: P, sink: AosSink<'_>) {
        match sink {
            AosSink::Store(out) => self.scalar_lane_loop(poses, Store { out, stream: false }),
            AosSink::Fat(fat, _) => self.scalar_lane_loop(poses, fat),
        }
    }

    /// The lane loop with `poses` into `sink`, in the scalar reference's lanes.
    fn scalar_lane_loop<P: PoseSource<3>>(self, poses: P, sink: impl Sink<3>) {
        debug_assert_eq!(self.backend, Backend::Scalar);
        let engine = Engine {
            local: self.local,
            poses,
            sink,
            len: self.local.len(),
            active: self.active,
            method: self.method,
            rounding: self.rounding,
        };
        engine.run_scalar();
    }
}

/// The objects [`AosCall::swept`] computes at each pose in one run: two chunks, its two
/// scratch blocks 8 KiB on the stack: past the caches, larger blocks read their streams
/// one run at a time (`docs/decisions.md`, "The swept update's blocks").
const SWEPT_BLOCK: usize = 2 * CHUNK;

impl AosCall<'_> {
    /// [`Route::Swept`](crate::layout::Route::Swept) into `sink`: the boxes at
    /// `self.poses` and at `predicted`, each computed by [`AosCall::run`] (the AoS loop,
    /// or the scalar backend's lane loop) into scratch a block of objects at a time, and
    /// their [`union`]. So each tight box is exactly the union of two
    /// [`Batch::transform`](crate::Batch::transform) results, and a swept run compiles no
    /// loop of its own. An index list, and a block of a mask with few active objects, run
    /// one object at a time ([`tight`]), as the AoS loop runs a list.
    pub fn swept(self, predicted: AosPoses<'_>, mut sink: AosSink<'_>) {
        let len = self.local.len();
        let one = |i: usize| {
            let at = |poses| tight(poses, i, &self.local[i], self.method, self.rounding);
            union(&at(self.poses), &at(predicted))
        };
        // The active objects of chunk `c` (a word of the moved set).
        let lanes = |c: usize| {
            let every = u64::MAX >> (64 - CHUNK.min(len - c * CHUNK));
            match self.active {
                Active::Mask(words) => words[c] & every,
                _ => every,
            }
        };
        if let Active::Indices(ix) = self.active {
            for &i in ix {
                let i = i as usize;
                sink.one(i, one(i));
            }
            return;
        }
        let mut at = [[Aabb3::EMPTY; SWEPT_BLOCK]; 2];
        for start in (0..len).step_by(SWEPT_BLOCK) {
            let n = SWEPT_BLOCK.min(len - start);
            let chunks = start / CHUNK..(start + n).div_ceil(CHUNK);
            let count: u32 = chunks.clone().map(|c| lanes(c).count_ones()).sum();
            if (count as usize) < n / 4 {
                for c in chunks {
                    let mut bits = lanes(c);
                    while bits != 0 {
                        let i = c * CHUNK + bits.trailing_zeros() as usize;
                        sink.one(i, one(i));
                        bits &= bits - 1;
                    }
                }
                continue;
            }
            let local = &self.local[start..start + n];
            for (poses, out) in [self.poses, predicted].into_iter().zip(&mut at) {
                let poses = window(poses, start, n).expect("the poses' lengths were checked");
                let block = AosCall {
                    local,
                    poses,
                    active: Active::All,
                    ..self
                };
                block.run(AosSink::Store(&mut out[..n]));
            }
            let mut words = [0; SWEPT_BLOCK / CHUNK];
            chunks.zip(&mut words).for_each(|(c, w)| *w = lanes(c));
            let [a, b] = at.each_ref().map(|at| &at[..n]);
            let unite = Unite {
                at: [a, b],
                words,
                sink: &mut sink,
                start,
            };
            simd::dispatch_groups(self.backend, unite);
        }
    }
}

/// The union of a block's boxes at two poses ([`AosCall::swept`]) into the sink, `W`
/// objects per vector of `P`: a chunk whose objects are all active at once, the others one
/// object at a time.
struct Unite<'s, 'a> {
    /// The boxes of objects `start..` at each pose.
    at: [&'s [Aabb3]; 2],
    /// The active objects of each chunk of the block.
    words: [u64; SWEPT_BLOCK / CHUNK],
    sink: &'s mut AosSink<'a>,
    start: usize,
}

impl GroupJob for Unite<'_, '_> {
    #[inline(always)]
    fn run<const W: usize, P: BoxGroup<W>>(self) {
        let Unite {
            at: [a, b],
            words,
            sink,
            start,
        } = self;
        let chunks = a.chunks(CHUNK).zip(b.chunks(CHUNK)).zip(words);
        for (c, ((a, b), bits)) in chunks.enumerate() {
            let (first, m) = (start + c * CHUNK, a.len());
            if bits != u64::MAX >> (64 - m) {
                let mut bits = bits;
                while bits != 0 {
                    let k = bits.trailing_zeros() as usize;
                    sink.one(first + k, union(&a[k], &b[k]));
                    bits &= bits - 1;
                }
                continue;
            }
            let out = sink.chunk(first, m);
            // The sum of every face is NaN where a face is (or where infinite faces of
            // both signs meet): such a chunk is redone one object at a time.
            let mut sum = P::splat(0.0);
            let groups = out
                .chunks_exact_mut(W)
                .zip(a.chunks_exact(W).zip(b.chunks_exact(W)));
            for (o, (a, b)) in groups {
                let (a_min, a_max) = (P::join(gather(|k| a[k].min)), P::join(gather(|k| a[k].max)));
                let (b_min, b_max) = (P::join(gather(|k| b[k].min)), P::join(gather(|k| b[k].max)));
                sum = sum + ((a_min + a_max) + (b_min + b_max));
                let (min, max) = (a_min.min(b_min).parts(), a_max.max(b_max).parts());
                for ((o, min), max) in o.iter_mut().zip(min).zip(max) {
                    *o = Aabb3 { min, max };
                }
            }
            for k in m - m % W..m {
                out[k] = union(&a[k], &b[k]);
            }
            if sum.parts().iter().any(|s| s.is_nan()) {
                core::hint::cold_path();
                for ((o, a), b) in out.iter_mut().zip(a).zip(b) {
                    *o = union(a, b);
                }
            }
            sink.take::<W, P>(first, m);
        }
    }
}

/// Object `i`'s tight box from its local box `local`, by the single-box kernel (the bits
/// of [`Tight::of`], which every backend's AoS run gives).
fn tight(
    poses: AosPoses<'_>,
    i: usize,
    local: &Aabb3,
    method: Method,
    rounding: Rounding,
) -> Aabb3 {
    match poses {
        AosPoses::Translation3(p) => local.transformed(p.at(i), method, rounding),
        AosPoses::Rigid3(p) => local.transformed(p.at(i), method, rounding),
        AosPoses::Similarity3(p) => local.transformed(p.at(i), method, rounding),
        AosPoses::Trs3(p) => local.transformed(p.at(i), method, rounding),
        AosPoses::Affine3A(p) => local.transformed(p.at(i), method, rounding),
    }
}

/// The union of an object's boxes at two poses; the invalid box where either has a NaN
/// face, so that a NaN at one pose is never hidden by the other's box.
#[inline(always)]
fn union(a: &Aabb3, b: &Aabb3) -> Aabb3 {
    let nan = a.min.is_nan_mask() | a.max.is_nan_mask() | b.min.is_nan_mask() | b.max.is_nan_mask();
    if nan.any() { Aabb3::NAN } else { a.union(b) }
}

/// `$walk(run, poses, tight, $set)` once per method and pose kind, each specialised to its
/// kernel, with groups `$groups` of `$w` boxes (the naive baseline too, so that the trade
/// report charges the method and not its loop). The rounding is a branch the loop does not
/// change (`docs/decisions.md`, "The AoS loops' kernels and rounding").
macro_rules! each_kernel {
    ($run:expr, $maps:expr, $w:ident, $groups:ty, $walk:ident $(, $set:expr)?) => {{
        specialise!($run.method, |method| {
            each_kernel!(@with $run, $maps, method, $w, $groups, $walk $(, $set)?)
        })
    }};
    (@with $run:expr, $maps:expr, $method:expr, $w:expr, $groups:ty, $walk:ident
        $(, $set:expr)?) => {{
        let len = $run.local.len();
        let tight = Tight::<$groups, $w> {
            method: $method,
            rounding: $run.rounding,
            groups: PhantomData,
        };
        match $maps {
            Maps::Each(poses) => $walk($run, Maps::Each(&poses[..len]), tight $(, $set)?),
            shared @ Maps::Shared(_) => $walk($run, shared, tight $(, $set)?),
        }
    }};
}

/// The AoS loop, in groups of boxes, over every object.
struct EveryInGroups<'a, 'm, T> {
    run: AosRun<'a>,
    maps: Maps<'m, T>,
}

impl<T: Transform3> GroupJob for EveryInGroups<'_, '_, T> {
    #[inline(always)]
    fn run<const W: usize, P: BoxGroup<W>>(self) {
        each_kernel!(self.run, self.maps, W, P, whole);
    }
}

/// The AoS loop, in groups of boxes, over the objects of an index list or a mask: `A`, a
/// [`Subset`] of one kind, in spans of `Sp`.
struct SubsetInGroups<'a, 'm, T, A, Sp> {
    run: AosRun<'a>,
    maps: Maps<'m, T>,
    set: A,
    width: PhantomData<Sp>,
}

impl<T: Transform3, A: Subset, Sp: SpanWidth> GroupJob for SubsetInGroups<'_, '_, T, A, Sp> {
    #[inline(always)]
    fn run<const W: usize, P: BoxGroup<W>>(self) {
        each_kernel!(self.run, self.maps, W, P, scattered, (self.set, self.width));
    }
}

/// [`EveryInGroups`] with one method, rounding and pose kind.
#[inline(always)]
fn whole<T: Transform3, const W: usize, P: BoxGroup<W>>(
    run: AosRun<'_>,
    poses: Maps<'_, T>,
    tight: Tight<P, W>,
) {
    let AosRun {
        local, mut sink, ..
    } = run;
    chunks(&mut sink, 0, local, poses, tight);
}

/// Objects `start..start + local.len()`, every one active, `start` a multiple of [`CHUNK`]:
/// their tight boxes into the sink a chunk at a time.
#[inline(always)]
fn chunks<T: Transform3, const W: usize, P: BoxGroup<W>>(
    sink: &mut AosSink<'_>,
    start: usize,
    local: &[Aabb3],
    poses: Maps<'_, T>,
    tight: Tight<P, W>,
) {
    for (c, local) in local.chunks(CHUNK).enumerate() {
        let first = start + c * CHUNK;
        tight.boxes(local, poses, first, sink.chunk(first, local.len()));
        sink.take::<W, P>(first, local.len());
    }
}

/// The active objects of `set` ([`active::walk`]): runs of whole spans several boxes per
/// vector, with the validity test per chunk ([`Tight::boxes`]), and the objects of other
/// spans one at a time.
#[inline(always)]
fn scattered<T: Transform3, const W: usize, P: BoxGroup<W>, Sp: SpanWidth>(
    run: AosRun<'_>,
    poses: Maps<'_, T>,
    tight: Tight<P, W>,
    (set, _): (impl Subset, PhantomData<Sp>),
) {
    let AosRun { local, sink, .. } = run;
    let mut objects = Objects {
        local,
        sink,
        poses,
        tight,
    };
    active::walk::<Sp>(set, local.len(), &mut objects);
}

/// The AoS loop's visit of a scattered active set.
struct Objects<'a, 'p, T, G> {
    local: &'a [Aabb3],
    sink: AosSink<'a>,
    poses: Maps<'p, T>,
    tight: G,
}

impl<T: Transform3, const W: usize, P: BoxGroup<W>> Visit for Objects<'_, '_, T, Tight<P, W>> {
    #[inline(always)]
    fn whole(&mut self, start: usize, end: usize) {
        let local = &self.local[start..end];
        chunks(&mut self.sink, start, local, self.poses, self.tight);
    }

    /// One object at a time, each requesting one object further as it runs (a burst of
    /// requests stalls the loop once the line fill buffers are full).
    #[inline(always)]
    fn part<U: Upcoming>(&mut self, span: Span, ahead: &mut Lookahead<U>) {
        let mut bits = span.active_lanes;
        while bits != 0 {
            let i = span.start + bits.trailing_zeros() as usize;
            ahead.advance(1);
            for j in ahead.requests() {
                self.request(j);
            }
            let tight = self.tight.of(&self.local[i], self.poses.at(i));
            self.sink.one(i, tight);
            bits &= bits - 1;
        }
    }

    #[inline(always)]
    fn request(&self, i: usize) {
        simd::prefetch(&self.local[i]);
        simd::prefetch(self.poses.at(i));
        self.sink.prefetch(i);
    }
}
