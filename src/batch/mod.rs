//! Batch transforms: many boxes at once, in three layouts, on the best backend.
//!
//! - AoSoA blocks ([`Aabb3x8`], [`Affine3x8`]): the fast path.
//! - SoA columns ([`AabbSoaRef`], [`AabbSoaMut`], [`Affine3SoaRef`]): ECS-style storage.
//! - AoS slices (`&[Aabb3]`, `&[Affine3A]`, and 2D `&[Aabb2]` with `&[Affine2]` or
//!   `&[Rigid2]`): convenience.
//!
//! Every layout has a shared-transform form (one transform for the whole batch). All
//! run the same lane-generic kernels as the single-box path and keep the same contract;
//! lengths are checked before anything is written, and any length is accepted (the
//! last partial block runs with masked lanes).

mod aos;
mod aosoa;
mod soa;

use core::fmt;

use glam::{Affine2, Affine3A};

use crate::aabb::{Aabb2, Aabb3};
use crate::block::{self, MapLanes};
use crate::extended;
use crate::lane::Vector;
use crate::method::{Method, Rounding};
use crate::rigid2::Rigid2;
use crate::simd::{self, Backend, Job, LaneArray};

pub use aosoa::{Aabb3x8, Affine3x8};
pub use soa::{AabbSoa, AabbSoaMut, AabbSoaRef, Affine3Soa, Affine3SoaRef};

/// Why a batch was refused. Nothing was written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BatchError {
    /// Two inputs, or an input and the output, differ in length.
    LengthMismatch {
        /// Which sequence has the wrong length.
        what: &'static str,
        /// The length of the local boxes.
        expected: usize,
        /// The length found.
        found: usize,
    },
    /// The backend asked for cannot run on this CPU.
    UnsupportedBackend(Backend),
}

impl fmt::Display for BatchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::LengthMismatch {
                what,
                expected,
                found,
            } => write!(
                f,
                "{what} has length {found}, expected {expected} (the local boxes' length)"
            ),
            Self::UnsupportedBackend(b) => write!(f, "backend {b:?} is not supported by this CPU"),
        }
    }
}

impl std::error::Error for BatchError {}

/// Boxes to read, in some layout.
pub(crate) trait BoxSource<const N: usize> {
    /// The number of boxes, or an error when the layout's columns disagree.
    fn len(&self) -> Result<usize, BatchError>;
    /// Boxes `i..i + count` (`count <= L::WIDTH`) as lanes; lanes past `count` are zero.
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, N>, Vector<L, N>);
    /// Box `i` as `(min, max)`, for the extended path.
    fn get(&self, i: usize) -> ([f32; N], [f32; N]);
}

/// Boxes to write, in some layout.
pub(crate) trait BoxSink<const N: usize> {
    /// The number of boxes, or an error when the layout's columns disagree.
    fn len(&self) -> Result<usize, BatchError>;
    /// Writes lanes `0..count` to boxes `i..i + count`.
    fn store<L: LaneArray>(&mut self, i: usize, count: usize, min: Vector<L, N>, max: Vector<L, N>);
    /// Writes box `i`.
    fn set(&mut self, i: usize, min: [f32; N], max: [f32; N]);
}

/// Transforms to read: one per box, or one shared by all.
pub(crate) trait MapSource<const N: usize> {
    /// The lanes a kernel runs on.
    type Lanes<L: LaneArray>: MapLanes<L, N>;
    /// The number of transforms, `None` for one shared transform.
    fn len(&self) -> Option<usize>;
    /// Transforms `i..i + count` as lanes; lanes past `count` are zero.
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> Self::Lanes<L>;
    /// Transform `i` as columns (`cols[j][i] = m_ij`) and translation.
    fn get(&self, i: usize) -> ([[f32; N]; N], [f32; N]);
}

/// The job every batch entry point runs: blocks of lanes through the kernel.
struct Run<B, X, O, const N: usize> {
    local: B,
    xf: X,
    out: O,
    len: usize,
    method: Method,
    rounding: Rounding,
}

impl<const N: usize, B: BoxSource<N>, X: MapSource<N>, O: BoxSink<N>> Run<B, X, O, N> {
    /// Every block with one kernel; `method` and `outward` are constants at each call site,
    /// so that each loop is specialised to its kernel.
    #[inline(always)]
    fn blocks<L: LaneArray>(&mut self, method: Method, outward: bool) {
        let w = L::WIDTH;
        let mut i = 0;
        while i + w <= self.len {
            self.block::<L>(i, w, method, outward);
            i += w;
        }
        if i < self.len {
            self.block::<L>(i, self.len - i, method, outward);
        }
    }

    #[inline(always)]
    fn block<L: LaneArray>(&mut self, i: usize, count: usize, method: Method, outward: bool) {
        let (lo, hi) = self.local.load::<L>(i, count);
        let map = self.xf.load::<L>(i, count);
        let (min, max, stands) = block::transform(&map, lo, hi, method, outward);
        self.out.store(i, count, min, max);
        // Lanes past `count` hold a zero box through a zero map: they stand. The rare
        // others are recomputed from the source data; nothing here takes `&mut self` out
        // of line, so the layout descriptors stay in registers.
        if stands.any_nonzero() {
            for k in 0..count {
                if stands.get(k) != 0.0 {
                    let (lo, hi) = self.local.get(i + k);
                    let (cols, t) = self.xf.get(i + k);
                    let (min, max) = extended::transform(cols, t, lo, hi, self.rounding);
                    self.out.set(i + k, min, max);
                }
            }
        }
    }
}

impl<const N: usize, B: BoxSource<N>, X: MapSource<N>, O: BoxSink<N>> Job for Run<B, X, O, N> {
    #[inline(always)]
    fn run<L: LaneArray>(mut self) {
        let outward = self.rounding == Rounding::Outward;
        match (self.method, outward) {
            (Method::Naive, false) => self.blocks::<L>(Method::Naive, false),
            (Method::Naive, true) => self.blocks::<L>(Method::Naive, true),
            (Method::AbsMatrix, false) => self.blocks::<L>(Method::AbsMatrix, false),
            (Method::AbsMatrix, true) => self.blocks::<L>(Method::AbsMatrix, true),
            (Method::SignSelect, false) => self.blocks::<L>(Method::SignSelect, false),
            (Method::SignSelect, true) => self.blocks::<L>(Method::SignSelect, true),
        }
    }
}

/// How a batch runs: the method, the rounding and the backend.
///
/// ```
/// use bvkit::{Aabb3, Batch, Method, Rounding};
/// use glam::{Affine3A, Vec3, Vec3A};
///
/// let local = vec![Aabb3::new(Vec3A::ZERO, Vec3A::ONE); 100];
/// let poses = vec![Affine3A::from_translation(Vec3::X); 100];
/// let mut world = vec![Aabb3::EMPTY; 100];
/// Batch::new(Method::AbsMatrix, Rounding::Outward).aos(&local, &poses, &mut world)?;
/// assert!(world[99].contains_point(Vec3A::new(2.0, 1.0, 1.0)));
/// # Ok::<(), bvkit::BatchError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Batch {
    /// The transform method.
    pub method: Method,
    /// The rounding guarantee.
    pub rounding: Rounding,
    backend: Backend,
}

impl Batch {
    /// A batch on the fastest backend of this CPU ([`Backend::detect`]).
    #[must_use]
    pub fn new(method: Method, rounding: Rounding) -> Self {
        Self {
            method,
            rounding,
            backend: Backend::detect(),
        }
    }

    /// The same batch forced onto `backend`, for tests and benchmarks.
    ///
    /// # Errors
    /// [`BatchError::UnsupportedBackend`] when this CPU cannot run it.
    pub fn on(self, backend: Backend) -> Result<Self, BatchError> {
        if backend.is_supported() {
            Ok(Self { backend, ..self })
        } else {
            Err(BatchError::UnsupportedBackend(backend))
        }
    }

    /// The backend the batch runs on.
    #[must_use]
    pub fn backend(&self) -> Backend {
        self.backend
    }

    fn run<const N: usize>(
        &self,
        local: impl BoxSource<N>,
        xf: impl MapSource<N>,
        out: impl BoxSink<N>,
    ) -> Result<(), BatchError> {
        let len = checked_len(&local, &xf, &out)?;
        let job: Run<_, _, _, N> = Run {
            local,
            xf,
            out,
            len,
            method: self.method,
            rounding: self.rounding,
        };
        simd::dispatch(self.backend, job);
        Ok(())
    }

    /// AoS 3D boxes one at a time on the single-box SIMD kernel (lanes = axes):
    /// transposing AoS boxes into box lanes costs more than the lanes save. The scalar
    /// backend keeps the lane path, which is the scalar reference.
    fn per_box(&self, local: &[Aabb3], xf: impl Fn(usize) -> Affine3A, out: &mut [Aabb3]) {
        for (i, (b, o)) in local.iter().zip(out).enumerate() {
            *o = b.transformed(&xf(i), self.method, self.rounding);
        }
    }
}

/// The common length of a batch, checked before anything is written.
fn checked_len<const N: usize>(
    local: &impl BoxSource<N>,
    xf: &impl MapSource<N>,
    out: &impl BoxSink<N>,
) -> Result<usize, BatchError> {
    let len = local.len()?;
    let mismatch = |what, found| BatchError::LengthMismatch {
        what,
        expected: len,
        found,
    };
    if let Some(n) = xf.len().filter(|&n| n != len) {
        return Err(mismatch("transforms", n));
    }
    let out_len = out.len()?;
    if out_len != len {
        return Err(mismatch("output", out_len));
    }
    Ok(len)
}

impl Batch {
    /// AoSoA blocks, one transform block per box block: the fast path.
    ///
    /// # Errors
    /// [`BatchError::LengthMismatch`] unless all three have the same number of blocks.
    pub fn aosoa(
        &self,
        local: &[Aabb3x8],
        xf: &[Affine3x8],
        out: &mut [Aabb3x8],
    ) -> Result<(), BatchError> {
        self.run(local, xf, out)
    }

    /// AoSoA blocks through one shared transform.
    ///
    /// # Errors
    /// [`BatchError::LengthMismatch`] unless `local` and `out` have the same number of blocks.
    pub fn aosoa_shared(
        &self,
        local: &[Aabb3x8],
        xf: &Affine3A,
        out: &mut [Aabb3x8],
    ) -> Result<(), BatchError> {
        self.run(local, xf, out)
    }

    /// SoA columns, one transform per box.
    ///
    /// # Errors
    /// [`BatchError::LengthMismatch`] unless every column has the same length.
    pub fn soa(
        &self,
        local: AabbSoaRef<'_>,
        xf: Affine3SoaRef<'_>,
        out: AabbSoaMut<'_>,
    ) -> Result<(), BatchError> {
        self.run(local, xf, out)
    }

    /// SoA columns through one shared transform.
    ///
    /// # Errors
    /// [`BatchError::LengthMismatch`] unless every column has the same length.
    pub fn soa_shared(
        &self,
        local: AabbSoaRef<'_>,
        xf: &Affine3A,
        out: AabbSoaMut<'_>,
    ) -> Result<(), BatchError> {
        self.run(local, xf, out)
    }

    /// AoS slices, one transform per box.
    ///
    /// # Errors
    /// [`BatchError::LengthMismatch`] unless all three slices have the same length.
    pub fn aos(
        &self,
        local: &[Aabb3],
        xf: &[Affine3A],
        out: &mut [Aabb3],
    ) -> Result<(), BatchError> {
        if self.backend == Backend::Scalar {
            return self.run(local, xf, out);
        }
        checked_len::<3>(&local, &xf, &out)?;
        self.per_box(local, |i| xf[i], out);
        Ok(())
    }

    /// AoS slices through one shared transform (compound bodies, instanced props).
    ///
    /// # Errors
    /// [`BatchError::LengthMismatch`] unless `local` and `out` have the same length.
    pub fn aos_shared(
        &self,
        local: &[Aabb3],
        xf: &Affine3A,
        out: &mut [Aabb3],
    ) -> Result<(), BatchError> {
        if self.backend == Backend::Scalar {
            return self.run(local, xf, out);
        }
        checked_len::<3>(&local, &xf, &out)?;
        self.per_box(local, |_| *xf, out);
        Ok(())
    }

    /// 2D AoS slices, one affine transform per box.
    ///
    /// # Errors
    /// [`BatchError::LengthMismatch`] unless all three slices have the same length.
    pub fn aos2(
        &self,
        local: &[Aabb2],
        xf: &[Affine2],
        out: &mut [Aabb2],
    ) -> Result<(), BatchError> {
        self.run(local, xf, out)
    }

    /// 2D AoS slices through one shared affine transform.
    ///
    /// # Errors
    /// [`BatchError::LengthMismatch`] unless `local` and `out` have the same length.
    pub fn aos2_shared(
        &self,
        local: &[Aabb2],
        xf: &Affine2,
        out: &mut [Aabb2],
    ) -> Result<(), BatchError> {
        self.run(local, xf, out)
    }

    /// 2D AoS slices, one rigid transform per box; [`Method::SignSelect`] is Eberly's sign
    /// branch in lanes.
    ///
    /// # Errors
    /// [`BatchError::LengthMismatch`] unless all three slices have the same length.
    pub fn aos_rigid2(
        &self,
        local: &[Aabb2],
        xf: &[Rigid2],
        out: &mut [Aabb2],
    ) -> Result<(), BatchError> {
        self.run(local, xf, out)
    }

    /// 2D AoS slices through one shared rigid transform.
    ///
    /// # Errors
    /// [`BatchError::LengthMismatch`] unless `local` and `out` have the same length.
    pub fn aos_rigid2_shared(
        &self,
        local: &[Aabb2],
        xf: &Rigid2,
        out: &mut [Aabb2],
    ) -> Result<(), BatchError> {
        self.run(local, xf, out)
    }
}

/// `out[k] = local[k]` through `xf[k]` for every `k`, on the fastest backend of this CPU.
///
/// # Errors
/// [`BatchError::LengthMismatch`] unless all three slices have the same length; `out` is
/// then untouched.
pub fn transform_slice(
    local: &[Aabb3],
    xf: &[Affine3A],
    out: &mut [Aabb3],
    method: Method,
    rounding: Rounding,
) -> Result<(), BatchError> {
    Batch::new(method, rounding).aos(local, xf, out)
}

#[cfg(test)]
mod tests {
    //! The 16-lane instantiation (the AVX-512 backend's lane type) run without AVX-512:
    //! every lane does the same arithmetic at any width, so it must reproduce the 8-lane
    //! backends exactly. This covers the 16-lane code paths (blocks spanning two AoSoA
    //! blocks, tails, the extended path) on CPUs that cannot run the AVX-512 backend.

    use super::*;
    use crate::simd::F32s;
    use glam::{Quat, Vec3, Vec3A};

    fn run_lanes<L: LaneArray>(
        method: Method,
        rounding: Rounding,
        local: &[Aabb3],
        xf: &[Affine3A],
        out: &mut [Aabb3],
    ) {
        let job: Run<_, _, _, 3> = Run {
            local,
            xf,
            out,
            len: local.len(),
            method,
            rounding,
        };
        job.run::<L>();
    }

    fn inputs(n: usize) -> (Vec<Aabb3>, Vec<Affine3A>) {
        let specials = [f32::NAN, f32::INFINITY, -f32::INFINITY, 3e38, -0.0, 1e-45];
        (0..n)
            .map(|k| {
                let x = k as f32;
                let mut b = Aabb3::new(Vec3A::new(-x, 0.5 * x, -1.0), Vec3A::new(x + 1.0, x, 2.0));
                let mut xf = Affine3A::from_scale_rotation_translation(
                    Vec3::new(1.0 + x * 0.01, 2.0, 0.5),
                    Quat::from_rotation_y(x),
                    Vec3::splat(x * 10.0),
                );
                if k % 7 == 3 {
                    b.min.y = specials[k % specials.len()];
                }
                if k % 11 == 5 {
                    xf.matrix3.y_axis.z = specials[k % specials.len()];
                }
                (b, xf)
            })
            .unzip()
    }

    fn same(a: &[Aabb3], b: &[Aabb3]) -> bool {
        let eq = |x: f32, y: f32| x == y || (x.is_nan() && y.is_nan());
        a.iter()
            .zip(b)
            .all(|(p, q)| (0..3).all(|i| eq(p.min[i], q.min[i]) && eq(p.max[i], q.max[i])))
    }

    #[test]
    fn sixteen_lanes_reproduce_eight() {
        for n in [0, 1, 15, 16, 17, 40, 333] {
            let (local, xf) = inputs(n);
            for method in Method::ALL {
                for rounding in Rounding::ALL {
                    let mut reference = vec![Aabb3::NAN; n];
                    let mut sixteen = vec![Aabb3::NAN; n];
                    run_lanes::<F32s<8, false>>(method, rounding, &local, &xf, &mut reference);
                    run_lanes::<F32s<16, false>>(method, rounding, &local, &xf, &mut sixteen);
                    assert!(same(&reference, &sixteen), "{method:?} {rounding:?} n={n}");
                    // Fused: `f32::mul_add` is correctly rounded whether or not the
                    // instruction exists, so both widths must agree here too.
                    run_lanes::<F32s<8, true>>(method, rounding, &local, &xf, &mut reference);
                    run_lanes::<F32s<16, true>>(method, rounding, &local, &xf, &mut sixteen);
                    assert!(
                        same(&reference, &sixteen),
                        "{method:?} {rounding:?} n={n} fused"
                    );
                    // AoSoA blocks, where 16 lanes span two blocks.
                    let (l8, x8) = (Aabb3x8::pack(&local), Affine3x8::pack(&xf));
                    let mut o8 = vec![Aabb3x8::EMPTY; l8.len()];
                    let job: Run<_, _, _, 3> = Run {
                        local: &l8[..],
                        xf: &x8[..],
                        out: &mut o8[..],
                        len: l8.len() * 8,
                        method,
                        rounding,
                    };
                    job.run::<F32s<16, true>>();
                    assert!(
                        same(&Aabb3x8::unpack(&o8, n), &reference),
                        "{method:?} {rounding:?} n={n} aosoa"
                    );
                }
            }
        }
    }
}
