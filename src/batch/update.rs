//! The per-frame broadphase update (documented on [`Batch::update`]): a thin public layer
//! over the engine, whose sink is the fat boxes and the moved set.

use super::Batch;
use super::large::LargePose;
#[cfg(doc)]
use super::large::LargeRigid3;
use crate::aabb::Aabb3;
use crate::engine::{Active, Engine, Fat, PoseSource};
use crate::error::BatchError;
use crate::fat::{Margin, Moved};
use crate::lane::Vector;
use crate::layout::{BoxSink, BoxSource, Named, NamedPoses, Route};
use crate::method::{Method, Rounding};
use crate::simd::{self, LaneArray};

use glam::DVec3;

/// Two poses per object, the current and the predicted one: the tight box is the union of
/// the boxes at both (the swept box of continuous collision detection). A NaN at either
/// pose gives the invalid box.
///
/// With AoS 3D boxes (`&[Aabb3]`) and AoS or shared poses of any 3D classes at both ends,
/// the run is compiled once in bvkit, not at the call site: the AoS loop at each pose, a
/// block of objects at a time, and the union, so each box is exactly the union of two
/// [`Batch::transform`] results. In any other layout both boxes are computed in one pass
/// of the lane loop; where either needs the extended path (an overflow, an infinite face,
/// a NaN), both are recomputed there: the union still contains both exact images, though
/// its bits may differ from the union of two [`Batch::transform`] results.
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

/// Two sets of AoS or shared poses of 3D classes take the AoS loop at each pose, in code
/// compiled once in bvkit (with AoS 3D boxes); any other pair the lane loop.
impl<A: Named, B: Named> Named for Swept<A, B> {
    const ROUTE: Route = match (A::ROUTE, B::ROUTE) {
        (Route::Aos, Route::Aos) => Route::Swept,
        _ => Route::Generic,
    };
    #[inline(always)]
    fn named_poses(&self) -> Option<NamedPoses<'_>> {
        match Self::ROUTE {
            Route::Swept => self.current.named_poses(),
            _ => None,
        }
    }
    #[inline(always)]
    fn named_predicted(&self) -> Option<NamedPoses<'_>> {
        match Self::ROUTE {
            Route::Swept => self.predicted.named_poses(),
            _ => None,
        }
    }
}

impl<const N: usize, A: PoseSource<N>, B: PoseSource<N>> PoseSource<N> for Swept<A, B> {
    fn check_len(&self, len: usize) -> Result<(), BatchError> {
        self.current.check_len(len)?;
        self.predicted.check_len(len)
    }
    const LANES: bool = A::LANES && B::LANES;
    type Trimmed = Swept<A::Trimmed, B::Trimmed>;
    #[inline(always)]
    fn trim(self, len: usize) -> Self::Trimmed {
        Swept {
            current: self.current.trim(len),
            predicted: self.predicted.trim(len),
        }
    }
    #[inline(always)]
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

/// Large-world poses take no route: their lanes are computed one at a time.
impl<T> Named for LargeWorld<'_, T> {}

impl<T: LargePose> PoseSource<3> for LargeWorld<'_, T> {
    fn check_len(&self, len: usize) -> Result<(), BatchError> {
        BatchError::check_len("poses", len, self.poses.len())
    }
    /// Each object's box is computed on its own in `f64` (below), so the run takes lanes
    /// of one on every backend: the same boxes, and a call site compiles one lane type's
    /// loops, not four.
    const LANES: bool = false;
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, len: usize) -> Self {
        Self {
            poses: &self.poses[..len],
            origin: self.origin,
        }
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        simd::prefetch(&self.poses[i]);
    }
    /// One object at a time: the `f64` steps have no lane form. A box with a non-finite
    /// face (empty, unbounded, overflowing or NaN) does not stand: the sinks compare lanes
    /// of finite faces only (`fat::outside`, where `inf − inf` is NaN), so such an object
    /// goes to the sink's one-object path, which takes any faces.
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
        let mut redo = L::splat(0.0);
        for k in 0..count {
            let lane = |v: &Vector<L, 3>| v.0.map(|x| x.get(k));
            let [min, max] = self.tight_one(i + k, lane(&lo), lane(&hi), method, Rounding::Outward);
            for a in 0..3 {
                lo.0[a].set(k, min[a]);
                hi.0[a].set(k, max[a]);
            }
            if !min.iter().chain(&max).all(|x| x.is_finite()) {
                redo.set(k, 1.0);
            }
        }
        (lo, hi, redo)
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
    /// static objects are never written and cost little (the lane loop may read those that
    /// share a span of 8 or 16 objects with active ones). `Batch::update_par` (feature
    /// `rayon`) runs it on the rayon pool, with the same results.
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
        let len = check_update(margin, active, &local, &poses, &mut fat)?;
        moved.reset(len);
        let engine = Engine {
            local,
            poses,
            sink: Fat { fat, margin, moved },
            len,
            active,
            method: self.method,
            rounding: self.rounding,
        };
        engine.run(self.backend(), !self.is_deterministic());
        Ok(())
    }
}

/// The checks of an update, before anything is written: the margin, the lengths, the
/// objects' count and the active set. Returns the number of objects.
pub(super) fn check_update<const N: usize>(
    margin: Margin,
    active: Active<'_>,
    local: &impl BoxSource<N>,
    poses: &impl PoseSource<N>,
    fat: &mut impl BoxSink<N>,
) -> Result<usize, BatchError> {
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
    active.check(len)?;
    Ok(len)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::Active;
    use crate::layout::{Aabb3x8, Block8, Rigid3x8, Soa};
    use crate::transform::Rigid3;
    use core::cell::Cell;
    use glam::{Quat, Vec3A};

    /// A fat sink that records, in a bit per object, every box written through it.
    struct Spy<'w, F> {
        fat: F,
        written: &'w Cell<u64>,
    }

    /// A spy takes no route: the lane loop, with every write seen.
    impl<F> Named for Spy<'_, F> {}

    impl<const N: usize, F: BoxSink<N>> BoxSink<N> for Spy<'_, F> {
        fn len(&mut self) -> Result<usize, BatchError> {
            self.fat.len()
        }
        fn store<L: LaneArray>(
            &mut self,
            i: usize,
            count: usize,
            min: Vector<L, N>,
            max: Vector<L, N>,
        ) {
            self.written
                .set(self.written.get() | (u64::MAX >> (64 - count)) << i);
            self.fat.store(i, count, min, max);
        }
        fn set(&mut self, i: usize, min: [f32; N], max: [f32; N]) {
            self.written.set(self.written.get() | 1 << i);
            self.fat.set(i, min, max);
        }
        type Read<'r>
            = F::Read<'r>
        where
            Self: 'r;
        fn read(&self) -> Self::Read<'_> {
            self.fat.read()
        }
        type Trimmed = Self;
        fn trim(self, _: usize) -> Self {
            self
        }
        #[cfg(feature = "rayon")]
        type Part<'p>
            = F::Part<'p>
        where
            Self: 'p;
        #[cfg(feature = "rayon")]
        fn parts(&mut self, chunk: usize) -> alloc::vec::Vec<Self::Part<'_>> {
            self.fat.parts(chunk)
        }
    }

    /// The objects whose fat box an update from empty fat boxes `fat` writes, as bits.
    fn written<B: BoxSource<3>, P: PoseSource<3>, F>(
        batch: &Batch,
        active: Active<'_>,
        local: B,
        poses: P,
        mut fat: F,
    ) -> u64
    where
        for<'f> &'f mut F: BoxSink<3>,
    {
        let written = Cell::new(0);
        let spy = Spy {
            fat: &mut fat,
            written: &written,
        };
        let margin = Margin::new(0.1, 0.0);
        batch
            .update(margin, active, local, poses, spy, &mut Moved::new())
            .unwrap();
        written.get()
    }

    #[test]
    fn inactive_objects_are_never_written() {
        // Every active object leaves its (empty) fat box; every other object is inactive,
        // so each span of the lane loop mixes the two.
        let n = 40; // the spy's bit per object
        assert!(n <= 64);
        let local = alloc::vec![Aabb3::new(Vec3A::splat(-1.0), Vec3A::ONE); n];
        let poses: alloc::vec::Vec<Rigid3> = (0..n)
            .map(|i| Rigid3::new(Quat::from_rotation_z(i as f32), Vec3A::X * i as f32))
            .collect();
        let mask = [0x55_5555_5555_u64];
        let indices: alloc::vec::Vec<u32> = (0..n as u32).filter(|i| i % 3 == 0).collect();
        let (l8, p8): (alloc::vec::Vec<Aabb3x8>, alloc::vec::Vec<Rigid3x8>) =
            (Block8::pack(&local), Block8::pack(&poses));
        let (ls, ps) = (Soa::from_slice(&local), Soa::from_slice(&poses));
        for backend in crate::simd::Backend::supported() {
            for (active, set) in [
                (Active::Mask(&mask), mask[0]),
                (
                    Active::Indices(&indices),
                    indices.iter().map(|&i| 1 << i).sum(),
                ),
            ] {
                for deterministic in [false, true] {
                    let mut batch = Batch::new(Method::AbsMatrix, Rounding::Outward)
                        .on(backend)
                        .unwrap();
                    if deterministic {
                        batch = batch.deterministic();
                    }
                    let what = alloc::format!("{backend:?} {active:?} {deterministic}");
                    // The spy hides the AoS slice, so AoS boxes take the lane loop (the AoS
                    // loop visits active objects only).
                    let fat = alloc::vec![Aabb3::EMPTY; n];
                    let aos = written(&batch, active, &local[..], &poses[..], fat.clone());
                    assert_eq!(aos, set, "AoS, lane loop {what}");
                    let aosoa = written(&batch, active, &l8[..], &p8[..], Block8::pack(&fat));
                    assert_eq!(aosoa, set, "AoSoA {what}");
                    let soa = written(&batch, active, &ls, &ps, Soa::from_slice(&fat));
                    assert_eq!(soa, set, "SoA {what}");
                }
            }
        }
    }
}
