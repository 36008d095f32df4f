//! The layouts boxes and transforms are stored in (AoS slices, AoSoA blocks of eight, SoA
//! columns), as the sources and sinks of the engine: each loads and stores lanes, and hands
//! single items to the extended path.

mod aos;
mod aosoa;
mod soa;

use crate::error::BatchError;
use crate::lane::Vector;
use crate::simd::LaneArray;

pub use aosoa::{
    Aabb2x8, Aabb3x8, Affine2x8, Affine3x8, Block8, Rigid2x8, Rigid3x8, Similarity3x8,
    Translation2x8, Translation3x8, Trs3x8,
};
pub use soa::{
    Aabb2Soa, Aabb2SoaMut, Aabb2SoaRef, AabbSoa, AabbSoaMut, AabbSoaRef, Affine3Soa, Affine3SoaRef,
    Rigid3Soa, Rigid3SoaRef, Soa, SoaMut, SoaRef,
};

/// Transforms read as AoS: one per box, or one shared.
#[derive(Clone, Copy)]
pub(crate) enum Maps<'a, T> {
    /// Transform `k` for box `k`.
    Each(&'a [T]),
    /// One transform for every box.
    Shared(&'a T),
}

/// Boxes a batch reads, in some layout: see [`Batch`](crate::Batch) for the list.
pub trait BoxSource<const N: usize>: sealed::ReadBoxes<N> {}
impl<const N: usize, S: sealed::ReadBoxes<N>> BoxSource<N> for S {}

/// Boxes a batch writes, in some layout.
pub trait BoxSink<const N: usize>: sealed::WriteBoxes<N> {}
impl<const N: usize, S: sealed::WriteBoxes<N>> BoxSink<N> for S {}

/// Transforms in some layout: one per item, or one shared by all. A batch takes any of
/// them as its [`PoseSource`](crate::PoseSource) (which adds swept and large-world poses);
/// [`BoundingVolume::transformed_aabbs`](crate::BoundingVolume::transformed_aabbs), which
/// needs the transforms themselves, takes only these.
pub trait TransformSource<const N: usize>: sealed::ReadMaps<N> {}
impl<const N: usize, S: sealed::ReadMaps<N>> TransformSource<N> for S {}

pub(crate) mod sealed {
    //! What a layout must do: load lanes, store lanes, and hand single items to the
    //! extended path.

    use super::*;
    use crate::aabb::Aabb3;
    use crate::lane::Vector;
    use crate::simd::LaneArray;
    use crate::transform::Class;

    /// Boxes to read.
    pub trait ReadBoxes<const N: usize> {
        /// The number of boxes, or an error when the layout's columns disagree.
        fn len(&self) -> Result<usize, BatchError>;
        /// Boxes `i..i + count` (`count <= L::WIDTH`) as lanes; lanes past `count` are zero.
        fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, N>, Vector<L, N>);
        /// Box `i` as `(min, max)`, for the extended path.
        fn get(&self, i: usize) -> ([f32; N], [f32; N]);
        /// True when [`ReadBoxes::aabb3s`] always returns the boxes.
        const AABB3S: bool = false;
        /// The boxes as an AoS slice of [`Aabb3`], when they are one.
        fn aabb3s(&self) -> Option<&[Aabb3]> {
            None
        }
        /// Asks for box `i`'s cache lines ahead of a scattered access.
        #[inline(always)]
        fn prefetch(&self, i: usize) {
            let _ = i;
        }
        /// The same boxes, as the engine's loop reads them.
        type Trimmed: ReadBoxes<N> + Clone;
        /// The first `len` boxes (`len` at most [`ReadBoxes::len`]), every slice cut to
        /// that length. The engine trims inside its loop's function, so that every slice
        /// carries the loop's own bound `len` and the per-column (or per-item) bounds
        /// checks fold into one per span; a layout with nothing to gain returns itself.
        fn trim(self, len: usize) -> Self::Trimmed;
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
        /// True when [`WriteBoxes::aabb3s_mut`] always returns the boxes.
        const AABB3S: bool = false;
        /// The boxes as an AoS slice of [`Aabb3`], when they are one.
        fn aabb3s_mut(&mut self) -> Option<&mut [Aabb3]> {
            None
        }
        /// The same boxes as a source, for a sink that reads the boxes it may rewrite (the
        /// broadphase's fat boxes).
        type Read<'r>: ReadBoxes<N>
        where
            Self: 'r;
        /// The boxes as a source.
        fn read(&self) -> Self::Read<'_>;
        /// The same boxes, as the engine's loop writes them.
        type Trimmed: WriteBoxes<N>;
        /// The first `len` boxes, every slice cut to that length: see [`ReadBoxes::trim`].
        fn trim(self, len: usize) -> Self::Trimmed;
        /// A part of the sink: the same layout over a run of boxes.
        #[cfg(feature = "rayon")]
        type Part<'p>: WriteBoxes<N> + Send
        where
            Self: 'p;
        /// Disjoint parts of `chunk` boxes each, in order (the last may be shorter);
        /// `chunk` is a multiple of 16, so that parts start on whole AoSoA blocks and spans.
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
        /// True when [`ReadMaps::maps`] always returns the transforms.
        const MAPS: bool = false;
        /// The transforms as an AoS slice or one shared transform, when they are.
        fn maps(&self) -> Option<Maps<'_, Self::Class>> {
            None
        }
        /// Asks for transform `i`'s cache lines ahead of a scattered access.
        #[inline(always)]
        fn prefetch(&self, i: usize) {
            let _ = i;
        }
        /// The same transforms, as the engine's loop reads them.
        type Trimmed: ReadMaps<N, Class = Self::Class> + Clone;
        /// The first `len` transforms (a shared one stays whole), every slice cut to that
        /// length: see [`ReadBoxes::trim`].
        fn trim(self, len: usize) -> Self::Trimmed;
    }
}

pub(crate) use sealed::{ReadBoxes, ReadMaps, WriteBoxes};

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

/// Lane helpers shared by the layouts.
#[inline(always)]
fn zero_fields<L: LaneArray>() -> [L; crate::fields::MAX_FIELDS] {
    [L::splat(0.0); crate::fields::MAX_FIELDS]
}
