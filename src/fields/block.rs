//! AoSoA blocks: eight values of a plain-data type, field by field.

use alloc::vec::Vec;

use super::{Fields, MAX_FIELDS};

/// Eight values of `T` (boxes or transforms), field by field: `fields[n][k]` is field `n`
/// of value `k`, in the field order of `T` (a box: `min` then `max`; a transform: see its
/// class). Aliases name the common ones ([`Rigid3x8`](crate::Rigid3x8),
/// [`Aabb3x8`](crate::Aabb3x8), …).
#[repr(C, align(32))]
pub struct Block8<T: Fields> {
    /// The fields, eight lanes each (`[[f32; 8]; F]` for `F` fields).
    pub fields: T::Array<[f32; 8]>,
}

impl<T: Fields> Clone for Block8<T>
where
    T::Array<[f32; 8]>: Clone,
{
    fn clone(&self) -> Self {
        Self {
            fields: self.fields.clone(),
        }
    }
}

impl<T: Fields> Copy for Block8<T> where T::Array<[f32; 8]>: Copy {}

impl<T: Fields> PartialEq for Block8<T> {
    fn eq(&self, other: &Self) -> bool {
        self.fields.as_ref() == other.fields.as_ref()
    }
}

impl<T: Fields> core::fmt::Debug for Block8<T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Block8")
            .field("fields", &self.fields.as_ref())
            .finish()
    }
}

impl<T: Fields> Block8<T> {
    /// A block from its fields.
    #[inline]
    #[must_use]
    pub fn from_fields(fields: T::Array<[f32; 8]>) -> Self {
        Self { fields }
    }

    /// Eight copies of `value`.
    #[must_use]
    pub fn splat(value: T) -> Self {
        let v = value.to_fields();
        Self::from_fields(T::array(|n| [v[n]; 8]))
    }

    /// Value `k` of the block.
    ///
    /// # Panics
    /// When `k >= 8`, as a slice index does.
    #[inline]
    #[must_use]
    pub fn get(&self, k: usize) -> T {
        assert!(
            k < 8,
            "Block8 index {k} out of range: a block holds 8 values"
        );
        let mut v = [0.0; MAX_FIELDS];
        for (x, field) in v.iter_mut().zip(self.fields.as_ref()) {
            *x = field[k];
        }
        T::from_fields(&v)
    }

    /// Asks for the cache lines of value `k` (one per field at most).
    #[inline(always)]
    pub(crate) fn prefetch(&self, k: usize) {
        for field in self.fields.as_ref() {
            crate::simd::prefetch(&field[k]);
        }
    }

    /// Sets value `k` of the block.
    ///
    /// # Panics
    /// When `k >= 8`, as a slice index does.
    #[inline]
    pub fn set(&mut self, k: usize, value: T) {
        assert!(
            k < 8,
            "Block8 index {k} out of range: a block holds 8 values"
        );
        let v = value.to_fields();
        for (field, x) in self.fields.as_mut().iter_mut().zip(v) {
            field[k] = x;
        }
    }

    /// Packs values into blocks, the last one padded (identity transforms, empty boxes).
    #[must_use]
    pub fn pack(values: &[T]) -> Vec<Self> {
        values
            .chunks(8)
            .map(|chunk| {
                let mut block = Self::default();
                chunk.iter().enumerate().for_each(|(k, &v)| block.set(k, v));
                block
            })
            .collect()
    }

    /// Unpacks the first `len` values of the blocks.
    #[must_use]
    pub fn unpack(blocks: &[Self], len: usize) -> Vec<T> {
        (0..len.min(blocks.len() * 8))
            .map(|i| blocks[i / 8].get(i % 8))
            .collect()
    }
}

/// Eight copies of the padding value: identity transforms, or empty boxes.
impl<T: Fields> Default for Block8<T> {
    fn default() -> Self {
        Self::splat(T::PADDING)
    }
}

impl<T: Fields> From<[T; 8]> for Block8<T> {
    #[inline]
    fn from(values: [T; 8]) -> Self {
        let mut block = Self::default();
        values
            .iter()
            .enumerate()
            .for_each(|(k, &v)| block.set(k, v));
        block
    }
}

impl<T: Fields> From<Block8<T>> for [T; 8] {
    #[inline]
    fn from(block: Block8<T>) -> Self {
        core::array::from_fn(|k| block.get(k))
    }
}
