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
    /// Boxes `i..i + count` (count <= lanes) as lanes.
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, N>, Vector<L, N>);
}

/// Boxes to write, in some layout.
pub(crate) trait BoxSink<const N: usize> {
    /// The number of boxes, or an error when the layout's columns disagree.
    fn len(&self) -> Result<usize, BatchError>;
    /// Writes lanes `0..count` to boxes `i..i + count`.
    fn store<L: LaneArray>(&mut self, i: usize, count: usize, min: Vector<L, N>, max: Vector<L, N>);
}

/// Transforms to read: one per box, or one shared by all.
pub(crate) trait MapSource<const N: usize> {
    /// The lanes a kernel runs on.
    type Lanes<L: LaneArray>: MapLanes<L, N>;
    /// The number of transforms, `None` for one shared transform.
    fn len(&self) -> Option<usize>;
    /// Transforms `i..i + count` as lanes.
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> Self::Lanes<L>;
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

impl<const N: usize, B: BoxSource<N>, X: MapSource<N>, O: BoxSink<N>> Job for Run<B, X, O, N> {
    #[inline(always)]
    fn run<L: LaneArray>(mut self) {
        let w = L::WIDTH;
        let mut i = 0;
        while i + w <= self.len {
            let (lo, hi) = self.local.load::<L>(i, w);
            let map = self.xf.load::<L>(i, w);
            let (min, max) = block::transform(&map, lo, hi, self.method, self.rounding);
            self.out.store(i, w, min, max);
            i += w;
        }
        if i < self.len {
            let count = self.len - i;
            let (lo, hi) = self.local.load::<L>(i, count);
            let map = self.xf.load::<L>(i, count);
            let (min, max) = block::transform(&map, lo, hi, self.method, self.rounding);
            self.out.store(i, count, min, max);
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
        self.run(local, xf, out)
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
        self.run(local, xf, out)
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
