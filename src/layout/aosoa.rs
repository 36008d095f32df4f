//! AoSoA blocks: eight boxes or eight transforms per 32-byte-aligned block, one `[f32; 8]`
//! per scalar field, so that a lane block is a handful of aligned vector loads.
//!
//! Blocks are not trimmed for the engine: a span's loads index whole blocks (`i / 8`),
//! which the loop bound on `i` does not cover.

use alloc::vec::Vec;
use glam::{Affine2, Affine3A};

pub use crate::fields::Block8;

use super::{BoxSink, BoxSource, TransformSource};
use super::{NamedItem, box_lanes, zero_fields};
use crate::aabb::{Aabb2, Aabb3, Boxes};
use crate::error::BatchError;
use crate::fields::{Fields, MAX_FIELDS};
use crate::lane::Vector;
use crate::simd::LaneArray;
use crate::transform::{Class, Rigid2, Rigid3, Similarity3, Translation2, Translation3, Trs3};

/// Eight 3D boxes: fields `min.x, min.y, min.z, max.x, max.y, max.z`.
pub type Aabb3x8 = Block8<Aabb3>;
/// Eight 2D boxes: fields `min.x, min.y, max.x, max.y`.
pub type Aabb2x8 = Block8<Aabb2>;
/// Eight 3D affine transforms: the columns of the matrix, then the translation.
pub type Affine3x8 = Block8<Affine3A>;
/// Eight 2D affine transforms: the columns of the matrix, then the translation.
pub type Affine2x8 = Block8<Affine2>;
/// Eight 3D translations.
pub type Translation3x8 = Block8<Translation3>;
/// Eight 2D translations.
pub type Translation2x8 = Block8<Translation2>;
/// Eight rigid 3D poses: quaternion `x, y, z, w`, then the translation.
pub type Rigid3x8 = Block8<Rigid3>;
/// Eight 3D similarities: quaternion, translation, then the scale.
pub type Similarity3x8 = Block8<Similarity3>;
/// Eight scale-rotation-translations: quaternion, translation, then the three scales.
pub type Trs3x8 = Block8<Trs3>;
/// Eight rigid 2D poses: `cos, sin`, then the translation.
pub type Rigid2x8 = Block8<Rigid2>;

// Pod per class: the derive cannot see through the sealed `Fields::Array`, so each block
// states its field array, and the compiler checks it and the size.
#[cfg(feature = "bytemuck")]
macro_rules! pod_blocks {
    ($($t:ty: $fields:literal),* $(,)?) => {$(
        const _: fn(Block8<$t>) -> [[f32; 8]; $fields] = |block| block.fields;
        const _: () = assert!(size_of::<Block8<$t>>() == 32 * $fields);
        // SAFETY: `Block8<$t>` is `repr(C, align(32))` around exactly `[[f32; 8]; $fields]`
        // (both checked above): no padding (its size is a multiple of its alignment), every
        // bit pattern a valid `f32`, no pointer or interior mutability; `Copy + 'static`.
        #[allow(unsafe_code)]
        unsafe impl bytemuck::Zeroable for Block8<$t> {}
        // SAFETY: as above.
        #[allow(unsafe_code)]
        unsafe impl bytemuck::Pod for Block8<$t> {}
    )*};
}

#[cfg(feature = "bytemuck")]
pod_blocks! {
    Aabb3: 6, Aabb2: 4, Affine3A: 12, Affine2: 6, Translation3: 3, Translation2: 2,
    Rigid3: 7, Similarity3: 8, Trs3: 10, Rigid2: 4,
}

impl<const N: usize, B: Boxes<N> + NamedItem> BoxSource<N> for &[Block8<B>] {
    fn len(&self) -> Result<usize, BatchError> {
        Ok(<[Block8<B>]>::len(self) * 8)
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, N>, Vector<L, N>) {
        box_lanes(&gather_blocks::<L, B>(self, i, count))
    }
    fn get(&self, i: usize) -> ([f32; N], [f32; N]) {
        let (lo, hi) = box_lanes::<f32, N>(&self[i / 8].get(i % 8).to_fields());
        (lo.0, hi.0)
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        self[i / 8].prefetch(i % 8);
    }
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, _: usize) -> Self {
        self
    }
}

impl<const N: usize, B: Boxes<N> + NamedItem> BoxSink<N> for &mut [Block8<B>] {
    fn len(&mut self) -> Result<usize, BatchError> {
        Ok(<[Block8<B>]>::len(self) * 8)
    }
    type Read<'r>
        = &'r [Block8<B>]
    where
        Self: 'r;
    #[inline(always)]
    fn read(&self) -> &[Block8<B>] {
        self
    }
    #[inline(always)]
    fn store<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        min: Vector<L, N>,
        max: Vector<L, N>,
    ) {
        if count == L::WIDTH && 8 % L::WIDTH == 0 {
            let (block, slot) = (&mut self[i / 8], i % 8);
            for a in 0..N {
                let fields = block.fields.as_mut();
                min.0[a].store(&mut fields[a][slot..]);
                max.0[a].store(&mut fields[N + a][slot..]);
            }
            return;
        }
        if count == L::WIDTH && L::WIDTH % 8 == 0 {
            for c in 0..L::WIDTH / 8 {
                let (lows, highs) = self[i / 8 + c].fields.as_mut().split_at_mut(N);
                for a in 0..N {
                    for (k, (lo, hi)) in lows[a].iter_mut().zip(&mut highs[a]).enumerate() {
                        *lo = min.0[a].get(8 * c + k);
                        *hi = max.0[a].get(8 * c + k);
                    }
                }
            }
            return;
        }
        for k in 0..L::WIDTH {
            if k < count {
                let (block, slot) = (&mut self[(i + k) / 8], (i + k) % 8);
                let fields = block.fields.as_mut();
                for a in 0..N {
                    fields[a][slot] = min.0[a].get(k);
                    fields[N + a][slot] = max.0[a].get(k);
                }
            }
        }
    }
    #[inline(always)]
    fn store_streaming<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        min: Vector<L, N>,
        max: Vector<L, N>,
    ) {
        // Whole 8-lane blocks only: three full cache lines per 3D block, nothing to merge.
        if count == 8 && L::WIDTH == 8 {
            let fields = self[i / 8].fields.as_mut();
            for a in 0..N {
                min.0[a].store_streaming(&mut fields[a]);
                max.0[a].store_streaming(&mut fields[N + a]);
            }
        } else {
            self.store(i, count, min, max);
        }
    }
    fn set(&mut self, i: usize, min: [f32; N], max: [f32; N]) {
        let fields = self[i / 8].fields.as_mut();
        for a in 0..N {
            fields[a][i % 8] = min[a];
            fields[N + a][i % 8] = max[a];
        }
    }
    #[cfg(feature = "rayon")]
    type Part<'p>
        = &'p mut [Block8<B>]
    where
        Self: 'p;
    #[cfg(feature = "rayon")]
    fn parts(&mut self, chunk: usize) -> Vec<&mut [Block8<B>]> {
        self.chunks_mut(chunk / 8).collect()
    }
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, _: usize) -> Self {
        self
    }
}

impl<const N: usize, T: Class<N>> TransformSource<N> for &[Block8<T>] {
    type Class = T;
    fn len(&self) -> Result<Option<usize>, BatchError> {
        Ok(Some(<[Block8<T>]>::len(self) * 8))
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> T::Lanes<L> {
        T::lanes(&gather_blocks::<L, T>(self, i, count))
    }
    fn get(&self, i: usize) -> T {
        self[i / 8].get(i % 8)
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        self[i / 8].prefetch(i % 8);
    }
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, _: usize) -> Self {
        self
    }
}

impl<const N: usize, B: Boxes<N> + NamedItem> BoxSource<N> for &Vec<Block8<B>> {
    fn len(&self) -> Result<usize, BatchError> {
        BoxSource::len(&self.as_slice())
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, N>, Vector<L, N>) {
        BoxSource::load(&self.as_slice(), i, count)
    }
    fn get(&self, i: usize) -> ([f32; N], [f32; N]) {
        BoxSource::get(&self.as_slice(), i)
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        BoxSource::prefetch(&self.as_slice(), i);
    }
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, _: usize) -> Self {
        self
    }
}

impl<const N: usize, B: Boxes<N> + NamedItem> BoxSink<N> for &mut Vec<Block8<B>> {
    fn len(&mut self) -> Result<usize, BatchError> {
        BoxSink::len(&mut self.as_mut_slice())
    }
    type Read<'r>
        = &'r [Block8<B>]
    where
        Self: 'r;
    #[inline(always)]
    fn read(&self) -> &[Block8<B>] {
        self
    }
    #[inline(always)]
    fn store<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        min: Vector<L, N>,
        max: Vector<L, N>,
    ) {
        self.as_mut_slice().store(i, count, min, max);
    }
    #[inline(always)]
    fn store_streaming<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        min: Vector<L, N>,
        max: Vector<L, N>,
    ) {
        self.as_mut_slice().store_streaming(i, count, min, max);
    }
    fn set(&mut self, i: usize, min: [f32; N], max: [f32; N]) {
        self.as_mut_slice().set(i, min, max);
    }
    #[cfg(feature = "rayon")]
    type Part<'p>
        = &'p mut [Block8<B>]
    where
        Self: 'p;
    #[cfg(feature = "rayon")]
    fn parts(&mut self, chunk: usize) -> Vec<&mut [Block8<B>]> {
        self.chunks_mut(chunk / 8).collect()
    }
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, _: usize) -> Self {
        self
    }
}

impl<const N: usize, T: Class<N>> TransformSource<N> for &Vec<Block8<T>> {
    type Class = T;
    fn len(&self) -> Result<Option<usize>, BatchError> {
        TransformSource::len(&self.as_slice())
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> T::Lanes<L> {
        TransformSource::load(&self.as_slice(), i, count)
    }
    fn get(&self, i: usize) -> T {
        TransformSource::get(&self.as_slice(), i)
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        TransformSource::prefetch(&self.as_slice(), i);
    }
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, _: usize) -> Self {
        self
    }
}

/// Lanes `i..i + count` of every field of the blocks. When they fill a whole lane block
/// inside one AoSoA block (`i` a multiple of the lane width, which divides 8) each field
/// is one vector load; otherwise (the tail, or 16 lanes spanning two blocks) lanes go one
/// by one.
#[inline(always)]
fn gather_blocks<L: LaneArray, T: Fields>(
    blocks: &[Block8<T>],
    i: usize,
    count: usize,
) -> [L; MAX_FIELDS] {
    let mut f = zero_fields::<L>();
    if count == L::WIDTH && 8 % L::WIDTH == 0 {
        let (fields, slot) = (blocks[i / 8].fields.as_ref(), i % 8);
        for n in 0..T::FIELDS {
            f[n] = L::load(&fields[n][slot..]);
        }
        return f;
    }
    if count == L::WIDTH && L::WIDTH % 8 == 0 {
        // Wider lanes than a block (16 for AVX-512): whole blocks, eight lanes at a time.
        for c in 0..L::WIDTH / 8 {
            let fields = blocks[i / 8 + c].fields.as_ref();
            for n in 0..T::FIELDS {
                for (k, &x) in fields[n].iter().enumerate() {
                    f[n].set(8 * c + k, x);
                }
            }
        }
        return f;
    }
    for k in 0..L::WIDTH {
        if k < count {
            let (fields, slot) = (blocks[(i + k) / 8].fields.as_ref(), (i + k) % 8);
            for n in 0..T::FIELDS {
                f[n].set(k, fields[n][slot]);
            }
        }
    }
    f
}
