//! The sinks of a run: where its tight boxes go. [`Store`] writes them (the batch
//! transform); [`Fat`] compares each with its fat box, rewrites the fat boxes they left and
//! records their objects (the broadphase update). The lane loop takes any [`Sink`]; the AoS
//! loop takes the two as one [`AosSink`].

use super::{CHUNK, Extended, PoseSource};
use crate::aabb::Aabb3;
use crate::fat::{Margin, Moved};
use crate::kernel::gather;
use crate::lane::Vector;
use crate::layout::{BoxSink, BoxSource};
use crate::simd::{self, BoxGroup, LaneArray};

/// Where the lane loop's tight boxes go.
pub(crate) trait Sink<const N: usize> {
    /// The tight boxes `[min, max]` of objects `i..i + count` in lanes, of which the
    /// `active_lanes` bits are active. Where `redo` is nonzero the lane's box does not stand and
    /// must be replaced by `extended.tight(i + k)`, its box on the extended path.
    fn span<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        active_lanes: u64,
        tight: [Vector<L, N>; 2],
        redo: L,
        extended: &Extended<'_, impl BoxSource<N> + Clone, impl PoseSource<N> + Clone>,
    );
    /// Asks for object `i`'s output ahead of a scattered access.
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        let _ = i;
    }
    /// After the last span (a fence after streaming stores).
    fn finish(&mut self) {}
    /// True when the sink takes every object ([`Active::All`](super::Active::All)), as a
    /// batch transform's does: its runs then compile only that walk (a third of the loops
    /// otherwise).
    const EVERY: bool = false;
    /// The same sink, as the loop writes it.
    type Trimmed: Sink<N>;
    /// The sink for the first `len` objects, every slice cut to that length (see
    /// [`BoxSource::trim`]).
    fn trim(self, len: usize) -> Self::Trimmed;
}

/// The plain sink: every tight box written to `out`, past the caches when `stream` is set.
pub(crate) struct Store<O> {
    /// The boxes written.
    pub out: O,
    /// Store whole AoSoA blocks past the caches, and fence at the end.
    pub stream: bool,
}

impl<const N: usize, O: BoxSink<N>> Sink<N> for Store<O> {
    #[inline(always)]
    fn span<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        active_lanes: u64,
        [min, max]: [Vector<L, N>; 2],
        redo: L,
        extended: &Extended<'_, impl BoxSource<N> + Clone, impl PoseSource<N> + Clone>,
    ) {
        // Every object is active: a store writes whole spans.
        debug_assert_eq!(active_lanes.count_ones() as usize, count);
        if self.stream {
            self.out.store_streaming(i, count, min, max);
        } else {
            self.out.store(i, count, min, max);
        }
        // The rare lanes that do not stand are recomputed from the source data. The branch
        // is marked cold, so that the registers go to the common path; and nothing here
        // takes `&mut self` out of line, so the layout descriptors stay in registers
        // (`docs/decisions.md`, "The cold redo of lanes that do not stand").
        if redo.any_nonzero() {
            core::hint::cold_path();
            for k in 0..count {
                if redo.get(k) != 0.0 {
                    let [min, max] = extended.tight(i + k);
                    self.out.set(i + k, min, max);
                }
            }
        }
    }
    fn finish(&mut self) {
        if self.stream {
            simd::store_fence();
        }
    }
    const EVERY: bool = true;
    type Trimmed = Store<O::Trimmed>;
    #[inline(always)]
    fn trim(self, len: usize) -> Store<O::Trimmed> {
        Store {
            out: self.out.trim(len),
            stream: self.stream,
        }
    }
}

/// The update's sink: each tight box compared with its fat box, the fat boxes it left
/// rewritten, and their objects recorded.
pub(crate) struct Fat<'a, F> {
    /// The fat boxes.
    pub fat: F,
    /// How much a rewritten fat box exceeds its tight box.
    pub margin: Margin,
    /// The objects whose fat box was rewritten.
    pub moved: &'a mut Moved,
}

impl<'a, const N: usize, F: BoxSink<N>> Sink<N> for Fat<'a, F> {
    #[inline(always)]
    fn span<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        active_lanes: u64,
        tight: [Vector<L, N>; 2],
        redo: L,
        extended: &Extended<'_, impl BoxSource<N> + Clone, impl PoseSource<N> + Clone>,
    ) {
        let (fat_min, fat_max) = self.fat.read().load::<L>(i, count);
        let outside = crate::fat::outside(tight[0], tight[1], fat_min, fat_max);
        // The common case, every box inside its fat box and standing: one reduction.
        if !(outside + redo).any_nonzero() {
            return;
        }
        // Boxes left a whole span of active boxes that all stand: the span is stored here,
        // the boxes that stay with their own bits; out of line with the rarer cases, it
        // was most of an update where many bodies move (`docs/decisions.md`, "A whole
        // span's store in line").
        if count == L::WIDTH && active_lanes == u64::MAX >> (64 - L::WIDTH) && !redo.any_nonzero() {
            self.blend(i, count, -outside, tight, [fat_min, fat_max]);
            self.moved.record(i, u64::from(outside.nonzero_mask()));
            return;
        }
        self.rewrite(
            i,
            count,
            active_lanes,
            [outside.portable(), redo.portable()],
            tight.map(L::portable_vector),
            [fat_min, fat_max].map(L::portable_vector),
            extended,
        );
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        self.fat.read().prefetch(i);
    }
    type Trimmed = Fat<'a, F::Trimmed>;
    #[inline(always)]
    fn trim(self, len: usize) -> Self::Trimmed {
        Fat {
            fat: self.fat.trim(len),
            margin: self.margin,
            moved: self.moved,
        }
    }
}

impl<F> Fat<'_, F> {
    /// The rest of a span where a box left its fat box or did not stand, but for a whole
    /// span that stands (stored inline, [`Sink::span`]): the fat boxes rewritten and the
    /// objects recorded. Out of line: inlined, its code (though rarely run) made LLVM spill
    /// the hot path (`docs/decisions.md`, "The rare rewrite of a fat sink's span, out of
    /// line"). It uses no multiply-add, so it needs none of the dispatcher's target
    /// features, and it takes the portable lanes ([`LaneArray::Portable`]), which code
    /// compiled without them can hold.
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    fn rewrite<L: LaneArray, const N: usize>(
        &mut self,
        i: usize,
        count: usize,
        active_lanes: u64,
        [outside, redo]: [L; 2],
        [min, max]: [Vector<L, N>; 2],
        [fat_min, fat_max]: [Vector<L, N>; 2],
        extended: &Extended<'_, impl BoxSource<N> + Clone, impl PoseSource<N> + Clone>,
    ) where
        F: BoxSink<N>,
    {
        let redo_lanes = u64::from(redo.nonzero_mask()) & active_lanes;
        let left = u64::from(outside.nonzero_mask()) & active_lanes & !redo_lanes;
        if left != 0 && active_lanes != u64::MAX >> (64 - count) {
            // A span shared with inactive objects: only the boxes rewritten are stored, so
            // that an inactive object's fat box is never written.
            let (grown_min, grown_max) = self.margin.grow(min, max);
            let mut bits = left;
            while bits != 0 {
                let k = bits.trailing_zeros() as usize;
                let lane = |v: &Vector<L, N>| v.0.map(|x| x.get(k));
                self.fat.set(i + k, lane(&grown_min), lane(&grown_max));
                bits &= bits - 1;
            }
        } else if left != 0 {
            // Every object of the span is active, some do not stand: the whole span is
            // stored, the lanes that stay with their own bits. Lanes picked by a dynamic
            // index would pin the vectors to memory and stop LLVM from vectorising the
            // span. Negative where the box is rewritten.
            let mut keep = L::splat(0.0);
            for k in 0..L::WIDTH {
                keep.set(k, if left >> k & 1 != 0 { -1.0 } else { 0.0 });
            }
            self.blend(i, count, keep, [min, max], [fat_min, fat_max]);
        }
        let mut moved = left;
        let mut bits = redo_lanes;
        while bits != 0 {
            let k = bits.trailing_zeros() as usize;
            if self.leaves(i + k, extended.tight(i + k)) {
                moved |= 1 << k;
            }
            bits &= bits - 1;
        }
        self.moved.record(i, moved);
    }

    /// Stores the span of objects `i..i + count`: the fat box where `keep` is nonnegative
    /// (`outside` negated is such a mask: 0 where a box stays, negative where it left or
    /// its fat box is NaN), the tight box grown elsewhere.
    #[inline(always)]
    fn blend<L: LaneArray, const N: usize>(
        &mut self,
        i: usize,
        count: usize,
        keep: L,
        [min, max]: [Vector<L, N>; 2],
        [fat_min, fat_max]: [Vector<L, N>; 2],
    ) where
        F: BoxSink<N>,
    {
        let (grown_min, grown_max) = self.margin.grow(min, max);
        let (mut min, mut max) = (fat_min, fat_max);
        for a in 0..N {
            min.0[a] = keep.select_nonneg(fat_min.0[a], grown_min.0[a]);
            max.0[a] = keep.select_nonneg(fat_max.0[a], grown_max.0[a]);
        }
        self.fat.store(i, count, min, max);
    }

    /// True when object `i`'s tight box from the extended path leaves its fat box, which
    /// is then rewritten.
    #[cold]
    fn leaves<const N: usize>(&mut self, i: usize, tight: [[f32; N]; 2]) -> bool
    where
        F: BoxSink<N>,
    {
        if crate::fat::inside(tight, self.fat.read().get(i).into()) {
            return false;
        }
        let (min, max) = self
            .margin
            .grow::<f32, N>(Vector(tight[0]), Vector(tight[1]));
        self.fat.set(i, min.0, max.0);
        true
    }
}

/// The fat sink on the AoS loop.
impl Fat<'_, &mut [Aabb3]> {
    /// Sixty-four objects at a time, in two passes. The first tests each group of `W`
    /// against its fat boxes in registers ([`BoxGroup::le_xyz`]) and gathers the objects
    /// that left into one word, with no branch. The second visits only the groups where a
    /// box left: it stores the group's fat boxes with the grown boxes picked in
    /// ([`BoxGroup::pick`]), so the others keep their bits. A branch per group mispredicts
    /// on the groups a walk moves at random, and past the caches each miss also discards
    /// the loads issued behind it; the two passes' visit mispredicts about once per 64
    /// objects (`docs/decisions.md`, "Two passes over the fat boxes"). The objects are
    /// recorded once per 64.
    #[inline(always)]
    fn take<const W: usize, P: BoxGroup<W>>(&mut self, first: usize, tight: &[Aabb3]) {
        debug_assert_eq!(first % 64, 0, "a chunk starts on a word of the moved set");
        let every = u32::MAX >> (32 - W);
        let fat = &mut self.fat[first..first + tight.len()];
        let whole = tight.len() - tight.len() % W;
        let mut left = 0;
        let groups = tight[..whole].chunks_exact(W).zip(fat.chunks_exact(W));
        for (g, (tight, fat)) in groups.enumerate() {
            let ((min, max), (fat_min, fat_max)) = (join::<W, P>(tight), join::<W, P>(fat));
            let inside = P::le_xyz(fat_min, min) & P::le_xyz(max, fat_max);
            left |= u64::from(!inside & every) << (g * W);
        }
        let mut groups = left;
        while groups != 0 {
            let at = groups.trailing_zeros() as usize / W * W;
            groups &= !(u64::from(every) << at);
            let (tight, fat) = (&tight[at..at + W], &mut fat[at..at + W]);
            let ((min, max), (fat_min, fat_max)) = (join::<W, P>(tight), join::<W, P>(fat));
            let inside = !(left >> at) as u32 & every;
            let (grown_min, grown_max) = self.margin.grow::<P, 1>(Vector([min]), Vector([max]));
            let min = P::pick(inside, fat_min, grown_min.0[0]).parts();
            let max = P::pick(inside, fat_max, grown_max.0[0]).parts();
            for (k, fat) in fat.iter_mut().enumerate() {
                *fat = Aabb3 {
                    min: min[k],
                    max: max[k],
                };
            }
        }
        for k in whole..tight.len() {
            left |= u64::from(!keep(&mut fat[k], tight[k], self.margin)) << k;
        }
        self.moved.record(first, left);
    }
    #[inline(always)]
    fn one(&mut self, i: usize, tight: Aabb3) {
        if !keep(&mut self.fat[i], tight, self.margin) {
            self.moved.record(i, 1);
        }
    }
}

/// The first `W` boxes as a group: their minima and their maxima. A function, not a
/// closure: a closure is not inlined into the dispatcher's target features, and called out
/// of line it passed its groups through memory (`docs/decisions.md`, "The groups of the
/// update's fat pass, built by a function").
#[inline(always)]
fn join<const W: usize, P: BoxGroup<W>>(boxes: &[Aabb3]) -> (P, P) {
    (
        P::join(gather(|k| boxes[k].min)),
        P::join(gather(|k| boxes[k].max)),
    )
}

/// One object of the AoS loop: true when its tight box lies inside its fat box; otherwise
/// the fat box becomes the tight box fattened.
#[inline(always)]
fn keep(fat: &mut Aabb3, tight: Aabb3, margin: Margin) -> bool {
    let inside = crate::fat::inside_aabb3(&tight, fat);
    if !inside {
        *fat = tight.fattened(margin);
    }
    inside
}

/// The sink of the AoS loop: the plain sink over AoS 3D boxes, or the fat sink. One type,
/// so that bvkit compiles the AoS loop once per class for both; the loop matches it once
/// per chunk of [`CHUNK`] objects, or per object of a scattered span. The loop computes a
/// chunk into the slice the sink gives ([`AosSink::chunk`]), then hands it over
/// ([`AosSink::take`]): the sink never calls back into the loop.
pub(crate) enum AosSink<'a> {
    /// Every tight box written where it is computed.
    Store(&'a mut [Aabb3]),
    /// Each tight box compared with its fat box, a chunk at a time computed into the
    /// scratch chunk (the caller's, so that a transform's runs fill none).
    Fat(Fat<'a, &'a mut [Aabb3]>, &'a mut [Aabb3; CHUNK]),
}

impl AosSink<'_> {
    /// Where the tight boxes of objects `first..first + len` are computed (`len` at most
    /// [`CHUNK`]): the output itself, or the scratch chunk.
    #[inline(always)]
    pub fn chunk(&mut self, first: usize, len: usize) -> &mut [Aabb3] {
        match self {
            AosSink::Store(out) => &mut out[first..first + len],
            AosSink::Fat(_, scratch) => &mut scratch[..len],
        }
    }

    /// The tight boxes of objects `first..first + len`, computed where [`AosSink::chunk`]
    /// said, compared in groups `P` of `W` boxes.
    #[inline(always)]
    pub fn take<const W: usize, P: BoxGroup<W>>(&mut self, first: usize, len: usize) {
        if let AosSink::Fat(fat, scratch) = self {
            fat.take::<W, P>(first, &scratch[..len]);
        }
    }

    /// Object `i` alone, with its tight box.
    #[inline(always)]
    pub fn one(&mut self, i: usize, tight: Aabb3) {
        match self {
            AosSink::Store(out) => out[i] = tight,
            AosSink::Fat(fat, _) => fat.one(i, tight),
        }
    }

    /// Asks for object `i`'s output ahead of a scattered access.
    #[inline(always)]
    pub fn prefetch(&self, i: usize) {
        // The plain sink takes every object, in order: only the fat sink is scattered.
        if let AosSink::Fat(fat, _) = self {
            simd::prefetch(&fat.fat[i]);
        }
    }
}
