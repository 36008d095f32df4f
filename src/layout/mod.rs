//! The layouts boxes and transforms are stored in (AoS slices, AoSoA blocks of eight, SoA
//! columns), as the sources and sinks of the engine: each loads and stores lanes, and hands
//! single items to the extended path.

mod aos;
mod aosoa;
mod named;
mod soa;

use crate::error::BatchError;
use crate::lane::Vector;
use crate::simd::LaneArray;
use crate::transform::Class;

pub use crate::transform::{
    AosPoses, Maps, NamedBoxes, NamedBoxesMut, NamedItem, NamedPoses, Route,
};
pub use named::Named;

pub use aosoa::{
    Aabb2x8, Aabb3x8, Affine2x8, Affine3x8, Block8, Rigid2x8, Rigid3x8, Similarity3x8,
    Translation2x8, Translation3x8, Trs3x8,
};
pub use soa::{
    Aabb2Soa, Aabb2SoaMut, Aabb2SoaRef, AabbSoa, AabbSoaMut, AabbSoaRef, Affine3Soa, Affine3SoaRef,
    Rigid3Soa, Rigid3SoaRef, Soa, SoaMut, SoaRef,
};

/// Boxes a batch reads, in some layout: see [`Batch`](crate::Batch) for the list. Sealed:
/// its items are bvkit's own (how a layout loads lanes and single boxes), and hidden.
#[allow(clippy::len_without_is_empty)] // hidden machinery, not a collection
pub trait BoxSource<const N: usize>: Named {
    /// The number of boxes, or an error when the layout's columns disagree.
    #[doc(hidden)]
    fn len(&self) -> Result<usize, BatchError>;
    /// Boxes `i..i + count` (`count <= L::WIDTH`) as lanes; lanes past `count` are zero.
    #[doc(hidden)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, N>, Vector<L, N>);
    /// Box `i` as `(min, max)`, for the extended path.
    #[doc(hidden)]
    fn get(&self, i: usize) -> ([f32; N], [f32; N]);
    /// Asks for box `i`'s cache lines ahead of a scattered access.
    #[doc(hidden)]
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        let _ = i;
    }
    /// The same boxes, as the engine's loop reads them.
    #[doc(hidden)]
    type Trimmed: BoxSource<N> + Clone;
    /// The first `len` boxes (`len` at most [`BoxSource::len`]), every slice cut to
    /// that length. The engine trims inside its loop's function, so that every slice
    /// carries the loop's own bound `len` and the per-column (or per-item) bounds
    /// checks fold into one per span; a layout with nothing to gain returns itself.
    #[doc(hidden)]
    fn trim(self, len: usize) -> Self::Trimmed;
}

/// Boxes a batch writes, in some layout: see [`Batch`](crate::Batch) for the list. Sealed,
/// as [`BoxSource`].
#[allow(clippy::len_without_is_empty)] // hidden machinery, not a collection
pub trait BoxSink<const N: usize>: Named {
    /// The number of boxes, or an error when the layout's columns disagree (`&mut`, so
    /// that a `Vec` can ask its slice).
    #[doc(hidden)]
    fn len(&mut self) -> Result<usize, BatchError>;
    /// Writes lanes `0..count` to boxes `i..i + count`.
    #[doc(hidden)]
    fn store<L: LaneArray>(&mut self, i: usize, count: usize, min: Vector<L, N>, max: Vector<L, N>);
    /// [`BoxSink::store`] past the caches where the layout allows it (whole AoSoA
    /// blocks); the caller fences before returning.
    #[doc(hidden)]
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
    #[doc(hidden)]
    fn set(&mut self, i: usize, min: [f32; N], max: [f32; N]);
    /// The same boxes as a source, for a sink that reads the boxes it may rewrite (the
    /// broadphase's fat boxes).
    #[doc(hidden)]
    type Read<'r>: BoxSource<N>
    where
        Self: 'r;
    /// The boxes as a source.
    #[doc(hidden)]
    fn read(&self) -> Self::Read<'_>;
    /// The same boxes, as the engine's loop writes them.
    #[doc(hidden)]
    type Trimmed: BoxSink<N>;
    /// The first `len` boxes, every slice cut to that length: see [`BoxSource::trim`].
    #[doc(hidden)]
    fn trim(self, len: usize) -> Self::Trimmed;
    /// A part of the sink: the same layout over a run of boxes.
    #[cfg(feature = "rayon")]
    #[doc(hidden)]
    type Part<'p>: BoxSink<N> + Send
    where
        Self: 'p;
    /// Disjoint parts of `chunk` boxes each, in order (the last may be shorter);
    /// `chunk` is a multiple of 16, so that parts start on whole AoSoA blocks and spans.
    #[cfg(feature = "rayon")]
    #[doc(hidden)]
    fn parts(&mut self, chunk: usize) -> alloc::vec::Vec<Self::Part<'_>>;
}

/// Transforms in some layout: one per item, or one shared by all. A batch takes any of
/// them as its [`PoseSource`](crate::PoseSource) (which adds swept and large-world poses);
/// [`BoundingVolume::transformed_aabbs`](crate::BoundingVolume::transformed_aabbs), which
/// needs the transforms themselves, takes only these. Sealed, as [`BoxSource`].
#[allow(clippy::len_without_is_empty)] // hidden machinery, not a collection
pub trait TransformSource<const N: usize>: Named {
    /// The transform class.
    #[doc(hidden)]
    type Class: Class<N>;
    /// The number of transforms, `None` for one shared transform, or an error when
    /// the layout's columns disagree.
    #[doc(hidden)]
    fn len(&self) -> Result<Option<usize>, BatchError>;
    /// Transforms `i..i + count` as lanes; lanes past `count` are zero.
    #[doc(hidden)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> <Self::Class as Class<N>>::Lanes<L>;
    /// Transform `i`, for the extended path.
    #[doc(hidden)]
    fn get(&self, i: usize) -> Self::Class;
    /// Asks for transform `i`'s cache lines ahead of a scattered access.
    #[doc(hidden)]
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        let _ = i;
    }
    /// The same transforms, as the engine's loop reads them.
    #[doc(hidden)]
    type Trimmed: TransformSource<N, Class = Self::Class> + Clone;
    /// The first `len` transforms (a shared one stays whole), every slice cut to that
    /// length: see [`BoxSource::trim`].
    #[doc(hidden)]
    fn trim(self, len: usize) -> Self::Trimmed;
}

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
