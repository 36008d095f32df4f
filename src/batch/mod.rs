//! The batch engine: layouts, sources and sinks, and the lane and AoS loops (documented
//! on [`Batch`]).

mod aos;
mod aos3;
mod aosoa;
#[cfg(feature = "rayon")]
mod parallel;
mod soa;

use core::fmt;

use crate::block;
use crate::extended;
use crate::lane::Vector;
use crate::method::{Method, Rounding};
use crate::simd::{self, Backend, Job, LaneArray};
use crate::transform::Class;

pub use aosoa::{
    Aabb2x8, Aabb3x8, Affine2x8, Affine3x8, Block8, Rigid2x8, Rigid3x8, Similarity3x8,
    Translation2x8, Translation3x8, Trs3x8,
};
pub use soa::{
    Aabb2Soa, Aabb2SoaMut, Aabb2SoaRef, AabbSoa, AabbSoaMut, AabbSoaRef, Affine3Soa, Affine3SoaRef,
    Rigid3Soa, Rigid3SoaRef, Soa, SoaMut, SoaRef,
};

use crate::aabb::Aabb3;
pub(crate) use aos3::{Aos3, Maps};

/// Why a batch was refused. Nothing was written.
#[derive(Clone, Copy, Debug, PartialEq)]
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
    /// A broadphase margin is negative, infinite or NaN.
    InvalidMargin(crate::fat::Margin),
    /// A broadphase active set is malformed; the reason is given.
    InvalidActive(&'static str),
    /// More objects than `u32` indices can name.
    TooManyObjects(usize),
}

impl BatchError {
    /// `Ok` when `found == expected`, else [`BatchError::LengthMismatch`] for `what`: the one
    /// place a length check is written.
    #[inline]
    pub(crate) fn check_len(what: &'static str, expected: usize, found: usize) -> Result<(), Self> {
        if found == expected {
            Ok(())
        } else {
            Err(Self::LengthMismatch {
                what,
                expected,
                found,
            })
        }
    }
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
            Self::InvalidMargin(m) => write!(
                f,
                "margin {m:?} is invalid: both fields must be finite and non-negative"
            ),
            Self::InvalidActive(why) => write!(f, "invalid active set: {why}"),
            Self::TooManyObjects(n) => {
                write!(f, "{n} objects is more than u32 indices can name")
            }
        }
    }
}

impl core::error::Error for BatchError {}

/// Boxes a batch reads, in some layout: see [`Batch`] for the list.
pub trait BoxSource<const N: usize>: sealed::ReadBoxes<N> {}
impl<const N: usize, S: sealed::ReadBoxes<N>> BoxSource<N> for S {}

/// Boxes a batch writes, in some layout.
pub trait BoxSink<const N: usize>: sealed::WriteBoxes<N> {}
impl<const N: usize, S: sealed::WriteBoxes<N>> BoxSink<N> for S {}

/// Transforms a batch reads: one per box in some layout, or one shared by all.
pub trait TransformSource<const N: usize>: sealed::ReadMaps<N> {}
impl<const N: usize, S: sealed::ReadMaps<N>> TransformSource<N> for S {}

pub(crate) mod sealed {
    //! What a layout must do: load lanes, store lanes, and hand single items to the
    //! extended path.

    use super::*;

    /// Boxes to read.
    pub trait ReadBoxes<const N: usize> {
        /// The number of boxes, or an error when the layout's columns disagree.
        fn len(&self) -> Result<usize, BatchError>;
        /// Boxes `i..i + count` (`count <= L::WIDTH`) as lanes; lanes past `count` are zero.
        fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, N>, Vector<L, N>);
        /// Box `i` as `(min, max)`, for the extended path.
        fn get(&self, i: usize) -> ([f32; N], [f32; N]);
        /// The boxes as an AoS slice of [`Aabb3`], when they are one.
        fn aabb3s(&self) -> Option<&[Aabb3]> {
            None
        }
        /// Asks for box `i`'s cache lines ahead of a scattered access.
        fn prefetch(&self, i: usize) {
            let _ = i;
        }
    }

    /// Boxes to write.
    pub trait WriteBoxes<const N: usize> {
        /// The number of boxes, or an error when the layout's columns disagree (`&mut`, so
        /// that a `Vec` can ask its slice).
        fn len(&mut self) -> Result<usize, BatchError>;
        /// Writes lanes `0..count` to boxes `i..i + count`.
        fn store<L: LaneArray>(
            &mut self,
            i: usize,
            count: usize,
            min: Vector<L, N>,
            max: Vector<L, N>,
        );
        /// [`WriteBoxes::store`] past the caches where the layout allows it (whole AoSoA
        /// blocks); the caller fences before returning.
        #[inline(always)]
        fn store_streaming<L: LaneArray>(
            &mut self,
            i: usize,
            count: usize,
            min: Vector<L, N>,
            max: Vector<L, N>,
        ) {
            self.store(i, count, min, max);
        }
        /// Writes box `i`.
        fn set(&mut self, i: usize, min: [f32; N], max: [f32; N]);
        /// The boxes as an AoS slice of [`Aabb3`], when they are one.
        fn aabb3s_mut(&mut self) -> Option<&mut [Aabb3]> {
            None
        }
        /// The same boxes as a source, for the broadphase update, which reads the fat
        /// boxes it may rewrite.
        type Read<'r>: ReadBoxes<N>
        where
            Self: 'r;
        /// The boxes as a source.
        fn read(&self) -> Self::Read<'_>;
        /// A part of the sink: the same layout over a run of boxes.
        #[cfg(feature = "rayon")]
        type Part<'p>: WriteBoxes<N> + Send
        where
            Self: 'p;
        /// Disjoint parts of `chunk` boxes each, in order (the last may be shorter);
        /// `chunk` is a multiple of 16, so that parts start on whole AoSoA and lane blocks.
        #[cfg(feature = "rayon")]
        fn parts(&mut self, chunk: usize) -> alloc::vec::Vec<Self::Part<'_>>;
    }

    /// Transforms to read.
    pub trait ReadMaps<const N: usize> {
        /// The transform class.
        type Class: Class<N>;
        /// The number of transforms, `None` for one shared transform, or an error when
        /// the layout's columns disagree.
        fn len(&self) -> Result<Option<usize>, BatchError>;
        /// Transforms `i..i + count` as lanes; lanes past `count` are zero.
        fn load<L: LaneArray>(&self, i: usize, count: usize)
        -> <Self::Class as Class<N>>::Lanes<L>;
        /// Transform `i`, for the extended path.
        fn get(&self, i: usize) -> Self::Class;
        /// The transforms as an AoS slice or one shared transform, when they are.
        fn maps(&self) -> Option<Maps<'_, Self::Class>> {
            None
        }
        /// Asks for transform `i`'s cache lines ahead of a scattered access.
        fn prefetch(&self, i: usize) {
            let _ = i;
        }
    }
}

use sealed::{ReadBoxes, ReadMaps, WriteBoxes};

/// Box `(min, max)` lanes from the fields of a box type in lanes.
#[inline(always)]
fn box_lanes<L: Copy, const N: usize>(
    f: &[L; crate::fields::MAX_FIELDS],
) -> (Vector<L, N>, Vector<L, N>) {
    (
        crate::fields::vector_at(f, 0),
        crate::fields::vector_at(f, N),
    )
}

/// The job every batch runs: blocks of lanes through the kernel.
struct Run<B, X, O> {
    local: B,
    xf: X,
    out: O,
    len: usize,
    method: Method,
    rounding: Rounding,
    /// Store past the caches: the output is larger than [`Batch::NON_TEMPORAL_BYTES`].
    stream: bool,
}

impl<B, X, O> Run<B, X, O> {
    /// Every block with one kernel; `method` is a constant at each call site, so that each
    /// loop is specialised to its kernel.
    #[inline(always)]
    fn blocks<L: LaneArray, const N: usize>(&mut self, method: Method, outward: bool)
    where
        B: ReadBoxes<N>,
        X: ReadMaps<N>,
        O: WriteBoxes<N>,
    {
        let w = L::WIDTH;
        let mut i = 0;
        while i + w <= self.len {
            self.block::<L, N>(i, w, method, outward);
            i += w;
        }
        // The tail one box at a time, in one lane of the same arithmetic: smaller code than
        // a masked block, and the same bits.
        while i < self.len {
            self.block::<L::One, N>(i, 1, method, outward);
            i += 1;
        }
    }

    #[inline(always)]
    fn block<L: LaneArray, const N: usize>(
        &mut self,
        i: usize,
        count: usize,
        method: Method,
        outward: bool,
    ) where
        B: ReadBoxes<N>,
        X: ReadMaps<N>,
        O: WriteBoxes<N>,
    {
        let (lo, hi) = self.local.load::<L>(i, count);
        let map = self.xf.load::<L>(i, count);
        let (min, max, stands) = block::transform(&map, lo, hi, method, outward);
        if self.stream {
            self.out.store_streaming(i, count, min, max);
        } else {
            self.out.store(i, count, min, max);
        }
        // The rare lanes that do not stand are recomputed from the source data; nothing
        // here takes `&mut self` out of line, so the layout descriptors stay in registers.
        if stands.any_nonzero() {
            for k in 0..count {
                if stands.get(k) != 0.0 {
                    let (lo, hi) = self.local.get(i + k);
                    let map = self.xf.get(i + k).extended();
                    let (min, max) = extended::transform(&map, lo, hi, self.rounding);
                    self.out.set(i + k, min, max);
                }
            }
        }
    }
}

/// A [`Run`] in `N` dimensions, as a [`Job`] for the dispatcher.
struct RunN<const N: usize, B, X, O>(Run<B, X, O>);

impl<const N: usize, B: ReadBoxes<N>, X: ReadMaps<N>, O: WriteBoxes<N>> Job for RunN<N, B, X, O> {
    /// One loop per method, so that each is specialised to its kernel; the rounding is a
    /// loop-invariant branch (specialising it too doubled the code, and the build time of
    /// every call site, for no measurable speed).
    #[inline(always)]
    fn run<L: LaneArray>(self) {
        let mut run = self.0;
        let outward = run.rounding == Rounding::Outward;
        match run.method {
            Method::Naive => run.blocks::<L, N>(Method::Naive, outward),
            Method::AbsMatrix => run.blocks::<L, N>(Method::AbsMatrix, outward),
            Method::SignSelect => run.blocks::<L, N>(Method::SignSelect, outward),
        }
        if run.stream {
            simd::store_fence();
        }
    }
}

/// How a batch runs: the method, the rounding and the backend.
///
/// # Batch transforms
///
/// Many boxes at once, in any layout, through any transform class, on the best backend.
///
/// One entry point, [`Batch::transform`], takes a [`BoxSource`], a [`TransformSource`] and
/// a [`BoxSink`]:
///
/// | layout | boxes read | boxes written | transforms read |
/// |---|---|---|---|
/// | AoS slices | `&[Aabb3]`, `&Vec<Aabb3>` | `&mut [Aabb3]`, `&mut Vec<Aabb3>` | `&[T]`, `&Vec<T>` |
/// | AoSoA blocks of 8 | `&[Aabb3x8]` | `&mut [Aabb3x8]` | `&[Block8<T>]` (`&[Rigid3x8]`, …) |
/// | SoA columns | [`SoaRef`], `&Soa` | [`SoaMut`], `&mut Soa` | [`SoaRef`], `&Soa` |
/// | shared | | | `&T`: one transform for the whole batch |
///
/// `T` is any transform class ([`crate::Transform3`], [`crate::Transform2`]); 2D boxes
/// (`Aabb2`) work the same way. Every combination runs the same lane-generic kernels as the
/// single-box path and keeps the same contract; lengths are checked before anything is
/// written, and any length is accepted (the last partial block runs one box at a time, in
/// one lane of the same arithmetic).
///
/// ```
/// use bvkit::{Aabb3, Batch, Method, Rigid3, Rounding};
/// use glam::{Quat, Vec3A};
///
/// let local = vec![Aabb3::new(Vec3A::ZERO, Vec3A::ONE); 100];
/// let poses = vec![Rigid3::new(Quat::IDENTITY, Vec3A::X); 100];
/// let mut world = vec![Aabb3::EMPTY; 100];
/// Batch::new(Method::AbsMatrix, Rounding::Outward).transform(&local, &poses, &mut world)?;
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
    deterministic: bool,
}

impl Batch {
    /// Outputs larger than this many bytes of box fields (32 MiB: about 1.4M 3D boxes,
    /// beyond the last-level cache of most CPUs) are written past the caches when they are
    /// AoSoA blocks: non-temporal stores of whole blocks, then a store fence. The bits are
    /// the same, and large batches run faster (`docs/speed.md`). A consumer that reads the
    /// boxes back gains nothing from them staying in a cache they do not fit.
    pub const NON_TEMPORAL_BYTES: usize = 32 << 20;

    /// A batch on the fastest backend of this CPU ([`Backend::detect`]).
    #[must_use]
    pub fn new(method: Method, rounding: Rounding) -> Self {
        Self {
            method,
            rounding,
            backend: Backend::detect(),
            deterministic: false,
        }
    }

    /// The same batch in deterministic mode, for lockstep networking and replays: no
    /// multiply-add is fused, and the AoS path runs in lanes like every other layout, so
    /// that every backend, every layout and the scalar reference give the same bits
    /// (on any x86-64 CPU, for the same build). It costs the fused backends a few percent
    /// in cache; the default stays the fastest. Without the `std` feature the batch kernels
    /// never fuse (`core` has no fused multiply-add), so the lane backends already give
    /// these bits; only the AoS path still differs until this mode is chosen.
    #[must_use]
    pub fn deterministic(self) -> Self {
        Self {
            deterministic: true,
            ..self
        }
    }

    /// True in [deterministic mode](Batch::deterministic).
    #[must_use]
    pub fn is_deterministic(&self) -> bool {
        self.deterministic
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

    /// `out[k] = local[k]` through transform `k` (or the shared transform) for every `k`:
    /// every layout, every transform class, in 3D and 2D.
    ///
    /// # Errors
    /// [`BatchError::LengthMismatch`] unless the boxes, the transforms (unless shared) and
    /// the output have the same length, and the columns of a SoA layout agree; `out` is
    /// then untouched.
    pub fn transform<const N: usize>(
        &self,
        local: impl BoxSource<N>,
        xf: impl TransformSource<N>,
        mut out: impl BoxSink<N>,
    ) -> Result<(), BatchError> {
        let len = checked_len(&local, &xf, &mut out)?;
        if let (false, Some(local), Some(maps), Some(out)) = (
            self.deterministic,
            local.aabb3s(),
            xf.maps(),
            out.aabb3s_mut(),
        ) {
            let batch = Aos3 {
                local,
                maps,
                out,
                method: self.method,
                rounding: self.rounding,
            };
            if Class::run_simd3(batch, self.backend) {
                return Ok(());
            }
        }
        let run = Run {
            local,
            xf,
            out,
            len,
            method: self.method,
            rounding: self.rounding,
            stream: len.saturating_mul(2 * N * size_of::<f32>()) > Self::NON_TEMPORAL_BYTES,
        };
        simd::dispatch(self.backend, !self.deterministic, RunN::<N, _, _, _>(run));
        Ok(())
    }
}

/// The common length of a batch, checked before anything is written.
fn checked_len<const N: usize>(
    local: &impl ReadBoxes<N>,
    xf: &impl ReadMaps<N>,
    out: &mut impl WriteBoxes<N>,
) -> Result<usize, BatchError> {
    let len = local.len()?;
    if let Some(n) = xf.len()? {
        BatchError::check_len("transforms", len, n)?;
    }
    BatchError::check_len("output", len, out.len()?)?;
    Ok(len)
}

/// Lane helpers shared by the layouts.
#[inline(always)]
fn zero_fields<L: LaneArray>() -> [L; crate::fields::MAX_FIELDS] {
    [L::splat(0.0); crate::fields::MAX_FIELDS]
}

#[cfg(test)]
mod tests {
    //! The 16-lane instantiation (the AVX-512 backend's lane type) run without AVX-512:
    //! every lane does the same arithmetic at any width, and the tail runs in one lane of
    //! the same arithmetic, so it must reproduce the 8-lane backends exactly. This covers
    //! the 16-lane code paths (blocks spanning two AoSoA blocks, tails, the extended path)
    //! on CPUs that cannot run the AVX-512 backend.

    use super::*;
    use crate::simd::F32s;
    use crate::transform::{Rigid3, Trs3};
    use alloc::{vec, vec::Vec};
    use glam::{Affine3A, Quat, Vec3, Vec3A};

    fn run_lanes<L: LaneArray, B: ReadBoxes<3>, X: ReadMaps<3>, O: WriteBoxes<3>>(
        method: Method,
        rounding: Rounding,
        local: B,
        xf: X,
        mut out: O,
    ) {
        let len = checked_len(&local, &xf, &mut out).expect("lengths");
        let run = Run {
            local,
            xf,
            out,
            len,
            method,
            rounding,
            stream: false,
        };
        RunN::<3, _, _, _>(run).run::<L>();
    }

    fn inputs(n: usize) -> (Vec<Aabb3>, Vec<Affine3A>, Vec<Trs3>) {
        let specials = [f32::NAN, f32::INFINITY, -f32::INFINITY, 3e38, -0.0, 1e-45];
        let mut boxes = Vec::new();
        let mut affines = Vec::new();
        let mut trs = Vec::new();
        for k in 0..n {
            let x = k as f32;
            let mut b = Aabb3::new(Vec3A::new(-x, 0.5 * x, -1.0), Vec3A::new(x + 1.0, x, 2.0));
            let scale = Vec3::new(1.0 + x * 0.01, 2.0, -0.5);
            let q = Quat::from_rotation_y(x);
            let mut xf = Affine3A::from_scale_rotation_translation(scale, q, Vec3::splat(x * 10.0));
            let mut t: Trs3 = (scale, q, Vec3::splat(x)).into();
            if k % 7 == 3 {
                b.min.y = specials[k % specials.len()];
            }
            if k % 11 == 5 {
                xf.matrix3.y_axis.z = specials[k % specials.len()];
                t.rotation.z = specials[k % specials.len()];
            }
            boxes.push(b);
            affines.push(xf);
            trs.push(t);
        }
        (boxes, affines, trs)
    }

    fn same(a: &[Aabb3], b: &[Aabb3]) -> bool {
        let eq = |x: f32, y: f32| x == y || (x.is_nan() && y.is_nan());
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(p, q)| (0..3).all(|i| eq(p.min[i], q.min[i]) && eq(p.max[i], q.max[i])))
    }

    #[test]
    fn sixteen_lanes_reproduce_eight() {
        for n in [0, 1, 15, 16, 17, 40, 333] {
            let (local, affines, trs) = inputs(n);
            let rigid: Vec<Rigid3> = trs
                .iter()
                .map(|t| Rigid3::new(t.rotation, t.translation))
                .collect();
            for method in Method::ALL {
                for rounding in Rounding::ALL {
                    let (m, r) = (method, rounding);
                    let mut reference = vec![Aabb3::NAN; n];
                    let mut sixteen = vec![Aabb3::NAN; n];
                    // Unfused and fused (`f32::mul_add` is correctly rounded whether or not
                    // the instruction exists, so both widths must agree either way).
                    run_lanes::<F32s<8, false>, _, _, _>(
                        m,
                        r,
                        &local[..],
                        &affines[..],
                        &mut reference[..],
                    );
                    run_lanes::<F32s<16, false>, _, _, _>(
                        m,
                        r,
                        &local[..],
                        &affines[..],
                        &mut sixteen[..],
                    );
                    assert!(same(&reference, &sixteen), "{m:?} {r:?} n={n}");
                    run_lanes::<F32s<8, true>, _, _, _>(
                        m,
                        r,
                        &local[..],
                        &trs[..],
                        &mut reference[..],
                    );
                    run_lanes::<F32s<16, true>, _, _, _>(
                        m,
                        r,
                        &local[..],
                        &trs[..],
                        &mut sixteen[..],
                    );
                    assert!(same(&reference, &sixteen), "{m:?} {r:?} n={n} trs fused");
                    // AoSoA blocks, where 16 lanes span two blocks.
                    let (l8, x8) = (Block8::pack(&local), Block8::pack(&rigid));
                    let mut o8 = vec![Aabb3x8::default(); l8.len()];
                    run_lanes::<F32s<8, true>, _, _, _>(
                        m,
                        r,
                        &local[..],
                        &rigid[..],
                        &mut reference[..],
                    );
                    run_lanes::<F32s<16, true>, _, _, _>(m, r, &l8[..], &x8[..], &mut o8[..]);
                    let got: Vec<Aabb3> = Block8::unpack(&o8, n);
                    assert!(same(&got, &reference), "{m:?} {r:?} n={n} aosoa");
                }
            }
        }
    }
}
