//! The per-frame broadphase update (documented on [`Batch::update`]).

mod large;
mod moved;

use crate::aabb::Aabb3;
use crate::batch::sealed::{ReadBoxes, ReadMaps, WriteBoxes};
use crate::batch::{Batch, BatchError, BoxSink, BoxSource, Maps};
use crate::block;
use crate::extended;
use crate::lane::Vector;
use crate::method::{Method, Rounding};
use crate::simd::{self, Backend, Job, LaneArray};
use crate::transform::Simd3Job;
use crate::transform::{Class, Transform3};

pub use crate::fat::Margin;
pub use large::{LargePose, LargeRigid3};
pub use moved::Moved;

use glam::DVec3;

/// The objects an update visits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Active<'a> {
    /// Every object.
    All,
    /// The objects at these indices, strictly ascending.
    Indices(&'a [u32]),
    /// The objects whose bit is set: bit `i % 64` of word `i / 64`, with `len.div_ceil(64)`
    /// words and no bit at or past `len`.
    Mask(&'a [u64]),
}

/// Two poses per object, the current and the predicted one: the tight box is the union of
/// the boxes at both (the swept box of continuous collision detection), computed in the
/// same pass.
///
/// Where either box needs the extended path (an overflow, an infinite face, a NaN), both
/// are recomputed there: the union still contains both exact images, though its bits may
/// differ from the union of two [`Batch::transform`] results. A NaN at either pose gives
/// an invalid box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Swept<A, B> {
    /// The poses at the start of the step.
    pub current: A,
    /// The poses at the end of the step.
    pub predicted: B,
}

/// Large-world poses ([`LargeRigid3`] or `glam::DAffine3`, one per object) and the `f64`
/// origin the boxes are relative to. Always rounded outward, whatever the batch's
/// rounding; the method applies to the rotation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LargeWorld<'a, T> {
    /// One pose per object.
    pub poses: &'a [T],
    /// The origin of the world boxes, in world units (the camera or the region's center).
    pub origin: DVec3,
}

/// Poses an update reads: any [`TransformSource`](crate::TransformSource), a [`Swept`]
/// pair of them, or a [`LargeWorld`].
pub trait PoseSource<const N: usize>: sealed::Poses<N> {}
impl<const N: usize, P: sealed::Poses<N>> PoseSource<N> for P {}

pub(crate) mod sealed {
    //! What a pose source must do: tight boxes in lanes, and one at a time on the
    //! extended path.

    use super::*;

    /// Tight world boxes from local boxes.
    pub trait Poses<const N: usize> {
        /// Refuses a pose count other than `len` (a shared pose has none).
        fn check_len(&self, len: usize) -> Result<(), BatchError>;
        /// The tight boxes of objects `i..i + count` from their local boxes in lanes, and a
        /// lane value that is 0 where the result stands and nonzero where the object must
        /// be recomputed by [`Poses::tight_one`].
        fn tight<L: LaneArray>(
            &self,
            i: usize,
            count: usize,
            lo: Vector<L, N>,
            hi: Vector<L, N>,
            method: Method,
            outward: bool,
        ) -> (Vector<L, N>, Vector<L, N>, L);
        /// The tight box of object `i` on the extended path, which takes every input.
        fn tight_one(
            &self,
            i: usize,
            lo: [f32; N],
            hi: [f32; N],
            method: Method,
            rounding: Rounding,
        ) -> [[f32; N]; 2];
        /// Asks for object `i`'s poses ahead of a scattered access.
        fn prefetch(&self, i: usize) {
            let _ = i;
        }
        /// Runs an update of AoS 3D boxes on the single-box kernel and returns true, or
        /// returns false where these poses or the backend have none.
        fn update_aos3(&self, update: AosUpdate<'_>, backend: Backend) -> bool {
            let _ = (update, backend);
            false
        }
    }
}

use sealed::Poses;

impl<const N: usize, X: ReadMaps<N>> Poses<N> for X {
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
        block::transform(&self.load::<L>(i, count), lo, hi, method, outward)
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
    fn prefetch(&self, i: usize) {
        ReadMaps::prefetch(self, i);
    }
    fn update_aos3(&self, update: AosUpdate<'_>, backend: Backend) -> bool {
        match self.maps() {
            Some(maps) => X::Class::run_simd3(AosUpdateOn { maps, update }, backend),
            None => false,
        }
    }
}

impl<const N: usize, A: Poses<N>, B: Poses<N>> Poses<N> for Swept<A, B> {
    fn check_len(&self, len: usize) -> Result<(), BatchError> {
        self.current.check_len(len)?;
        self.predicted.check_len(len)
    }
    fn prefetch(&self, i: usize) {
        self.current.prefetch(i);
        self.predicted.prefetch(i);
    }
    /// The union of the two boxes; a lane that does not stand at either pose does not
    /// stand (so that a NaN at one pose is never hidden by the other's box).
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
        use crate::lane::Lane;
        let (min0, max0, s0) = self.current.tight(i, count, lo, hi, method, outward);
        let (min1, max1, s1) = self.predicted.tight(i, count, lo, hi, method, outward);
        (min0.min(min1), max0.max(max1), s0.abs() + s1.abs())
    }
    fn tight_one(
        &self,
        i: usize,
        lo: [f32; N],
        hi: [f32; N],
        method: Method,
        rounding: Rounding,
    ) -> [[f32; N]; 2] {
        let [min0, max0] = self.current.tight_one(i, lo, hi, method, rounding);
        let [min1, max1] = self.predicted.tight_one(i, lo, hi, method, rounding);
        if [min0, max0, min1, max1]
            .iter()
            .flatten()
            .any(|x| x.is_nan())
        {
            return [[f32::NAN; N]; 2];
        }
        [
            core::array::from_fn(|a| min0[a].min(min1[a])),
            core::array::from_fn(|a| max0[a].max(max1[a])),
        ]
    }
}

impl<T: LargePose> Poses<3> for LargeWorld<'_, T> {
    fn check_len(&self, len: usize) -> Result<(), BatchError> {
        BatchError::check_len("poses", len, self.poses.len())
    }
    fn prefetch(&self, i: usize) {
        simd::prefetch(&self.poses[i]);
    }
    /// One object at a time: the `f64` steps have no lane form.
    #[inline(always)]
    fn tight<L: LaneArray>(
        &self,
        i: usize,
        count: usize,
        mut lo: Vector<L, 3>,
        mut hi: Vector<L, 3>,
        method: Method,
        _: bool,
    ) -> (Vector<L, 3>, Vector<L, 3>, L) {
        for k in 0..count {
            let lane = |v: &Vector<L, 3>| v.0.map(|x| x.get(k));
            let [min, max] = self.tight_one(i + k, lane(&lo), lane(&hi), method, Rounding::Outward);
            for a in 0..3 {
                lo.0[a].set(k, min[a]);
                hi.0[a].set(k, max[a]);
            }
        }
        (lo, hi, L::splat(0.0))
    }
    fn tight_one(
        &self,
        i: usize,
        lo: [f32; 3],
        hi: [f32; 3],
        method: Method,
        _: Rounding,
    ) -> [[f32; 3]; 2] {
        let local = Aabb3::new(lo.into(), hi.into());
        let b = self.poses[i].relative_aabb(&local, self.origin, method);
        [b.min.to_array(), b.max.to_array()]
    }
}

impl Batch {
    /// The broadphase update: for every [`Active`] object, its tight world box (`local`
    /// through `poses`, with this batch's method, rounding and backend); where it is not
    /// inside the object's box in `fat`, that box is rewritten as the tight box fattened
    /// by `margin` ([`Aabb3::fattened`]) and the object joins `moved`. Every other fat box
    /// is left untouched. `moved` is cleared first, and holds exactly the rewritten
    /// objects, ascending; the result is deterministic.
    ///
    /// A tight box that is invalid (a NaN pose) is never inside a fat box: it is written,
    /// and reported as moved at every update until its pose is valid again. An empty
    /// local box is inside every valid fat box.
    ///
    /// # Errors
    /// Nothing is written, and `moved` is untouched, when:
    /// - [`BatchError::LengthMismatch`]: the poses (unless shared) or `fat` differ in
    ///   length from `local`, or a SoA layout's columns disagree;
    /// - [`BatchError::InvalidMargin`]: a margin field is negative, infinite or NaN;
    /// - [`BatchError::InvalidActive`]: an index is out of range or not strictly
    ///   ascending, or a mask has the wrong number of words or a bit past the last object;
    /// - [`BatchError::TooManyObjects`]: more objects than `u32` indices can name.
    ///
    /// # The broadphase update
    ///
    /// Fat boxes rewritten only when an object leaves them, and the set of objects whose fat
    /// box changed.
    ///
    /// A broadphase tree holds a *fat* box per object, larger than the object by a
    /// [`Margin`], so that small motions need no tree update. Each frame,
    /// [`Batch::update`] computes every active object's tight world box and compares it with
    /// its fat box:
    /// - inside: nothing is written;
    /// - outside (or NaN): the fat box is rewritten as the tight box grown by the margin and
    ///   rounded outward, and the object joins the [`Moved`] set, which the broadphase
    ///   reinserts.
    ///
    /// Every layout and transform class of [`Batch::transform`] works, with the same method,
    /// rounding and backend, and so do [`Swept`] pose pairs (the union of the boxes at the
    /// current and the predicted pose, for continuous collision) and [`LargeWorld`] poses
    /// (`f64` positions, boxes relative to an `f64` origin, always rounded outward).
    /// [`Active`] restricts the update to a list or a mask of objects, so that sleeping and
    /// static objects cost nothing.
    ///
    /// ```
    /// use bvkit::{Aabb3, Active, Batch, Margin, Method, Moved, Rigid3, Rounding};
    /// use glam::{Quat, Vec3A};
    ///
    /// let local = vec![Aabb3::new(Vec3A::splat(-0.5), Vec3A::splat(0.5)); 100];
    /// let mut poses = vec![Rigid3::new(Quat::IDENTITY, Vec3A::ZERO); 100];
    /// let mut fat = vec![Aabb3::EMPTY; 100];
    /// let mut moved = Moved::new();
    /// let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
    /// let margin = Margin::new(0.1, 0.0);
    ///
    /// batch.update(margin, Active::All, &local, &poses, &mut fat, &mut moved)?;
    /// assert_eq!(moved.len(), 100); // every fat box was EMPTY
    ///
    /// poses[7].translation.x += 0.05; // within the margin: nothing moves
    /// poses[9].translation.x += 1.0; // out of its fat box
    /// batch.update(margin, Active::All, &local, &poses, &mut fat, &mut moved)?;
    /// assert_eq!(moved.indices(), &[9]);
    /// # Ok::<(), bvkit::BatchError>(())
    /// ```
    pub fn update<const N: usize>(
        &self,
        margin: Margin,
        active: Active<'_>,
        local: impl BoxSource<N>,
        poses: impl PoseSource<N>,
        mut fat: impl BoxSink<N>,
        moved: &mut Moved,
    ) -> Result<(), BatchError> {
        if !margin.is_valid() {
            return Err(BatchError::InvalidMargin(margin));
        }
        let len = local.len()?;
        poses.check_len(len)?;
        BatchError::check_len("fat boxes", len, fat.len()?)?;
        // Indices 0..len must fit in u32; compared in u64, since `u32::MAX + 1` overflows a
        // 32-bit usize.
        if len as u64 > u64::from(u32::MAX) + 1 {
            return Err(BatchError::TooManyObjects(len));
        }
        check_active(active, len)?;
        moved.reset(len);
        if let (false, Some(local), Some(fat)) =
            (self.is_deterministic(), local.aabb3s(), fat.aabb3s_mut())
        {
            let update = AosUpdate {
                local,
                fat,
                active,
                moved: &mut *moved,
                margin,
                method: self.method,
                rounding: self.rounding,
            };
            if poses.update_aos3(update, self.backend()) {
                return Ok(());
            }
        }
        let update = Update {
            local,
            poses,
            fat,
            len,
            method: self.method,
            rounding: self.rounding,
            margin,
            active,
            moved,
        };
        simd::dispatch(self.backend(), !self.is_deterministic(), update);
        Ok(())
    }
}

/// An update of AoS 3D boxes, its inputs checked: run on the single-box kernel, since
/// gathering AoS boxes into lanes costs more than the kernel (as for
/// [`Batch::transform`]).
pub(crate) struct AosUpdate<'a> {
    local: &'a [Aabb3],
    fat: &'a mut [Aabb3],
    active: Active<'a>,
    moved: &'a mut Moved,
    margin: Margin,
    method: Method,
    rounding: Rounding,
}

/// An [`AosUpdate`] with its poses, one per box or shared.
struct AosUpdateOn<'a, T> {
    maps: Maps<'a, T>,
    update: AosUpdate<'a>,
}

impl<T> Simd3Job<T> for AosUpdateOn<'_, T> {
    fn run(self, backend: Backend) -> bool
    where
        T: Transform3,
    {
        if let Backend::Scalar | Backend::Wide = backend {
            return false;
        }
        // One loop per method and rounding, each specialised to its kernel.
        let u = &self.update;
        match (u.method, u.rounding) {
            (Method::Naive, Rounding::Nearest) => self.objects(Method::Naive, Rounding::Nearest),
            (Method::Naive, Rounding::Outward) => self.objects(Method::Naive, Rounding::Outward),
            (Method::AbsMatrix, Rounding::Nearest) => {
                self.objects(Method::AbsMatrix, Rounding::Nearest)
            }
            (Method::AbsMatrix, Rounding::Outward) => {
                self.objects(Method::AbsMatrix, Rounding::Outward)
            }
            (Method::SignSelect, Rounding::Nearest) => {
                self.objects(Method::SignSelect, Rounding::Nearest)
            }
            (Method::SignSelect, Rounding::Outward) => {
                self.objects(Method::SignSelect, Rounding::Outward)
            }
        }
        true
    }
}

impl<T: Transform3> AosUpdateOn<'_, T> {
    /// Every active object through [`Aabb3::transformed`], its fat box compared and
    /// rewritten on `Vec3A` (the same arithmetic, so the same bits, as the lanes).
    #[inline(always)]
    fn objects(self, method: Method, rounding: Rounding) {
        let AosUpdate {
            local,
            fat,
            active,
            moved,
            margin,
            ..
        } = self.update;
        // Method calls rather than closures: a closure here was compiled out of line, with
        // the method and rounding as run-time values instead of constants.
        let job = Chunk {
            local,
            maps: self.maps,
            margin,
            method,
            rounding,
        };
        // Scattered objects: their lines are requested `AHEAD` objects in advance.
        let ahead = |fat: &[Aabb3], i: usize| {
            simd::prefetch(&local[i]);
            simd::prefetch(&fat[i]);
            simd::prefetch(job.pose(i));
        };
        let mut early = ActiveIndices::new(active);
        early.by_ref().take(AHEAD).for_each(|i| ahead(fat, i));
        match active {
            Active::All => job.run(0, local.len(), fat, moved),
            Active::Indices(ix) => {
                for &i in ix {
                    if let Some(j) = early.next() {
                        ahead(fat, j);
                    }
                    job.one(i as usize, fat, moved);
                }
            }
            Active::Mask(words) => {
                for (w, &word) in words.iter().enumerate() {
                    if word == u64::MAX {
                        // A run: the hardware prefetcher follows it; the lookahead skips it.
                        job.run(64 * w, 64 * w + 64, fat, moved);
                        early.nth(63);
                        continue;
                    }
                    let mut bits = word;
                    while bits != 0 {
                        if let Some(j) = early.next() {
                            ahead(fat, j);
                        }
                        job.one(64 * w + bits.trailing_zeros() as usize, fat, moved);
                        bits &= bits - 1;
                    }
                }
            }
        }
    }
}

/// The AoS update's kernel: the method and rounding are constants at each call site.
struct Chunk<'a, T> {
    local: &'a [Aabb3],
    maps: Maps<'a, T>,
    margin: Margin,
    method: Method,
    rounding: Rounding,
}

impl<T: Transform3> Chunk<'_, T> {
    #[inline(always)]
    fn pose(&self, i: usize) -> &T {
        match self.maps {
            Maps::Each(poses) => &poses[i],
            Maps::Shared(pose) => pose,
        }
    }

    /// Object `i` alone (a scattered object).
    #[inline(always)]
    fn one(&self, i: usize, fat: &mut [Aabb3], moved: &mut Moved) {
        let tight = self.local[i].transformed(self.pose(i), self.method, self.rounding);
        if !crate::fat::inside_aabb3(&tight, &fat[i]) {
            fat[i] = tight.fattened(self.margin);
            moved.record(i, 1);
        }
    }

    /// Objects `start..end` eight at a time: the tight boxes and the mask of those that
    /// left their fat boxes, then a loop over its set bits. A branch per object would
    /// mispredict on every object a walk moves at random; the loop mispredicts once a
    /// chunk.
    #[inline(always)]
    fn run(&self, start: usize, end: usize, fat: &mut [Aabb3], moved: &mut Moved) {
        let chunks = self.local[start..end]
            .chunks(8)
            .zip(fat[start..end].chunks_mut(8));
        for (c, (local, fat)) in chunks.enumerate() {
            let base = start + 8 * c;
            let mut tight = [Aabb3::EMPTY; 8];
            let mut left = 0;
            for (k, (l, f)) in local.iter().zip(&*fat).enumerate() {
                tight[k] = l.transformed(self.pose(base + k), self.method, self.rounding);
                left |= u32::from(!crate::fat::inside_aabb3(&tight[k], f)) << k;
            }
            let mut bits = left;
            while bits != 0 {
                let k = bits.trailing_zeros() as usize;
                fat[k] = tight[k].fattened(self.margin);
                bits &= bits - 1;
            }
            moved.record(base, left);
        }
    }
}

/// How many scattered objects ahead the update requests memory.
const AHEAD: usize = 16;

/// The indices of an index list or a mask, ascending.
struct ActiveIndices<'a> {
    active: Active<'a>,
    /// The next position in the list, or the current mask word.
    at: usize,
    /// The bits of the current mask word not yet visited.
    bits: u64,
}

impl<'a> ActiveIndices<'a> {
    fn new(active: Active<'a>) -> Self {
        let bits = match active {
            Active::Mask(words) => words.first().copied().unwrap_or(0),
            _ => 0,
        };
        Self {
            active,
            at: 0,
            bits,
        }
    }
}

impl Iterator for ActiveIndices<'_> {
    type Item = usize;
    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        match self.active {
            Active::All => None,
            Active::Indices(ix) => {
                let i = *ix.get(self.at)?;
                self.at += 1;
                Some(i as usize)
            }
            Active::Mask(words) => {
                while self.bits == 0 {
                    self.at += 1;
                    self.bits = *words.get(self.at)?;
                }
                let i = 64 * self.at + self.bits.trailing_zeros() as usize;
                self.bits &= self.bits - 1;
                Some(i)
            }
        }
    }
}

/// Refuses indices out of range or out of order, and masks of the wrong shape.
fn check_active(active: Active<'_>, len: usize) -> Result<(), BatchError> {
    let refuse = |why| Err(BatchError::InvalidActive(why));
    match active {
        Active::All => Ok(()),
        Active::Indices(ix) => {
            if ix.last().is_some_and(|&i| i as usize >= len) {
                return refuse("an index is past the last object");
            }
            if ix.windows(2).any(|w| w[0] >= w[1]) {
                return refuse("the indices are not strictly ascending");
            }
            Ok(())
        }
        Active::Mask(words) => {
            if words.len() != len.div_ceil(64) {
                return refuse("the mask does not have len.div_ceil(64) words");
            }
            let tail = len % 64;
            if tail != 0 && words.last().is_some_and(|w| w >> tail != 0) {
                return refuse("the mask has a bit past the last object");
            }
            Ok(())
        }
    }
}

/// The update as a job for the dispatcher.
struct Update<'a, const N: usize, B, P, F> {
    local: B,
    poses: P,
    fat: F,
    len: usize,
    method: Method,
    rounding: Rounding,
    margin: Margin,
    active: Active<'a>,
    moved: &'a mut Moved,
}

impl<const N: usize, B: ReadBoxes<N>, P: Poses<N>, F: WriteBoxes<N>> Job
    for Update<'_, N, B, P, F>
{
    /// One loop per method, as in [`Batch::transform`].
    #[inline(always)]
    fn run<L: LaneArray>(mut self) {
        let outward = self.rounding == Rounding::Outward;
        match self.method {
            Method::Naive => self.visit::<L>(Method::Naive, outward),
            Method::AbsMatrix => self.visit::<L>(Method::AbsMatrix, outward),
            Method::SignSelect => self.visit::<L>(Method::SignSelect, outward),
        }
    }
}

impl<const N: usize, B: ReadBoxes<N>, P: Poses<N>, F: WriteBoxes<N>> Update<'_, N, B, P, F> {
    /// The active objects in aligned lane blocks: a block with more than one active lane
    /// runs in lanes (its inactive lanes are computed and ignored), a lone active object
    /// and the tail run one lane of the same arithmetic (one call site of each, so that
    /// the kernels are inlined twice per method, as in [`Batch::transform`]).
    #[inline(always)]
    fn visit<L: LaneArray>(&mut self, method: Method, outward: bool) {
        // Scattered objects: their lines are requested `AHEAD` objects in advance.
        let scattered = !matches!(self.active, Active::All);
        let mut early = ActiveIndices::new(self.active);
        early.by_ref().take(AHEAD).for_each(|i| self.prefetch(i));
        for (start, count, active) in Blocks::new(self.active, self.len, L::WIDTH) {
            let ones = active.count_ones() as usize;
            if scattered && ones < count {
                for _ in 0..ones {
                    if let Some(i) = early.next() {
                        self.prefetch(i);
                    }
                }
            } else if scattered {
                // A whole block: a run the hardware prefetcher follows; the lookahead skips it.
                early.nth(ones - 1);
            }
            if count == L::WIDTH && active & (active - 1) != 0 {
                self.block::<L>(start, L::WIDTH, active, method, outward);
            } else {
                let mut bits = active;
                while bits != 0 {
                    let k = bits.trailing_zeros() as usize;
                    self.block::<L::One>(start + k, 1, 1, method, outward);
                    bits &= bits - 1;
                }
            }
        }
    }

    /// Asks for object `i`'s local box, poses and fat box.
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        self.local.prefetch(i);
        self.poses.prefetch(i);
        self.fat.read().prefetch(i);
    }

    /// Objects `i..i + count`, of which the `lanes` bits are active: the tight boxes in
    /// lanes, the fat boxes they leave rewritten, and the lanes that do not stand redone
    /// one at a time on the extended path.
    #[inline(always)]
    fn block<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        lanes: u32,
        method: Method,
        outward: bool,
    ) {
        let (lo, hi) = self.local.load::<L>(i, count);
        let (min, max, stands) = self.poses.tight::<L>(i, count, lo, hi, method, outward);
        let (fat_min, fat_max) = self.fat.read().load::<L>(i, count);
        let outside = crate::fat::outside(min, max, fat_min, fat_max);
        // The common case, every box inside its fat box and standing: one reduction.
        if !(outside + stands).any_nonzero() {
            return;
        }
        self.rewrite(
            i,
            count,
            lanes,
            method,
            [outside, stands],
            [min, max],
            [fat_min, fat_max],
        );
    }

    /// The rest of a block where a box left its fat box or did not stand: the fat boxes
    /// rewritten and the objects recorded. Out of line: inlined, its code (though rarely
    /// run) made LLVM spill the hot path, which then ran three times slower. It uses no
    /// multiply-add, so it needs none of the dispatcher's target features.
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    fn rewrite<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        lanes: u32,
        method: Method,
        [outside, stands]: [L; 2],
        [min, max]: [Vector<L, N>; 2],
        [fat_min, fat_max]: [Vector<L, N>; 2],
    ) {
        let redo = stands.nonzero_mask() & lanes;
        let left = outside.nonzero_mask() & lanes & !redo;
        if left != 0 {
            // The whole block is stored, the lanes that stay with their own bits: lanes
            // picked by a dynamic index would pin the vectors to memory and stop LLVM from
            // vectorising the block.
            let (grown_min, grown_max) = self.margin.grow(min, max);
            // Negative where the box is rewritten. `outside` is 0 where a box stays and at
            // least 1 where it left, so where every lane is active and stands its negation
            // is the mask; otherwise it is built lane by lane.
            let keep = if left == outside.nonzero_mask() {
                -outside
            } else {
                let mut keep = L::splat(0.0);
                for k in 0..L::WIDTH {
                    keep.set(k, if left >> k & 1 != 0 { -1.0 } else { 0.0 });
                }
                keep
            };
            let (mut min, mut max) = (fat_min, fat_max);
            for a in 0..N {
                min.0[a] = keep.select_nonneg(fat_min.0[a], grown_min.0[a]);
                max.0[a] = keep.select_nonneg(fat_max.0[a], grown_max.0[a]);
            }
            self.fat.store(i, count, min, max);
        }
        let mut moved = left;
        let mut bits = redo;
        while bits != 0 {
            let k = bits.trailing_zeros() as usize;
            if self.redo(i + k, method) {
                moved |= 1 << k;
            }
            bits &= bits - 1;
        }
        self.moved.record(i, moved);
    }

    /// Object `i` on the extended path; true when its fat box was rewritten.
    #[cold]
    fn redo(&mut self, i: usize, method: Method) -> bool {
        let (lo, hi) = self.local.get(i);
        let tight = self.poses.tight_one(i, lo, hi, method, self.rounding);
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

/// The active objects in aligned blocks of `width` (1, 8 or 16) lanes, ascending:
/// `(start, count, active)` with `start` a multiple of `width`, `count` the lanes that
/// exist (`width`, or fewer in the last block) and `active` the nonzero mask of the active
/// ones. Empty mask words are skipped whole.
struct Blocks<'a> {
    active: Active<'a>,
    len: usize,
    width: usize,
    /// The next block's start, or the next position in an index list.
    at: usize,
}

impl<'a> Blocks<'a> {
    fn new(active: Active<'a>, len: usize, width: usize) -> Self {
        Self {
            active,
            len,
            width,
            at: 0,
        }
    }

    /// The lanes of the block at `start`, and the mask of all of them.
    #[inline(always)]
    fn lanes(&self, start: usize) -> (usize, u32) {
        let count = self.width.min(self.len - start);
        (count, (((1u64 << count) - 1) as u32))
    }
}

impl Iterator for Blocks<'_> {
    type Item = (usize, usize, u32);
    #[inline(always)]
    fn next(&mut self) -> Option<(usize, usize, u32)> {
        match self.active {
            Active::All => {
                let start = self.at;
                if start >= self.len {
                    return None;
                }
                self.at += self.width;
                let (count, all) = self.lanes(start);
                Some((start, count, all))
            }
            Active::Mask(words) => loop {
                let start = self.at;
                if start >= self.len {
                    return None;
                }
                // Straight to the block of the next set bit, a whole empty word at a time.
                let word = words[start / 64];
                let rest = word >> (start % 64);
                if rest == 0 {
                    self.at = (start / 64 + 1) * 64;
                    continue;
                }
                let next = start + rest.trailing_zeros() as usize;
                let block = next - next % self.width;
                self.at = block + self.width;
                let (count, all) = self.lanes(block);
                return Some((block, count, (word >> (block % 64)) as u32 & all));
            },
            Active::Indices(ix) => {
                let first = *ix.get(self.at)? as usize;
                let start = first - first % self.width;
                let (count, _) = self.lanes(start);
                let mut active = 0;
                while let Some(&i) = ix.get(self.at).filter(|&&i| (i as usize) < start + count) {
                    active |= 1 << (i as usize - start);
                    self.at += 1;
                }
                Some((start, count, active))
            }
        }
    }
}
