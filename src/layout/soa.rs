//! SoA columns: one `f32` slice per scalar field, the layout of ECS-style storage.

use alloc::vec;
use alloc::vec::Vec;
use glam::Affine3A;

use super::{BoxSink, BoxSource, NamedItem, TransformSource};
use super::{box_lanes, zero_fields};
use crate::aabb::{Aabb2, Aabb3, Boxes};
use crate::error::BatchError;
use crate::fields::{Fields, MAX_FIELDS};
use crate::lane::Vector;
use crate::simd::LaneArray;
use crate::transform::{Class, Rigid3};

/// Owned columns of values of `T` (boxes or transforms): `columns[n][k]` is field `n` of
/// value `k`, in the field order of `T` (see [`Block8`](super::Block8)).
pub struct Soa<T: Fields> {
    /// One column per field (`[Vec<f32>; F]` for `F` fields).
    pub columns: T::Array<Vec<f32>>,
}

/// Borrowed columns to read; every column must have the same length.
pub struct SoaRef<'a, T: Fields> {
    /// One column per field (`[&[f32]; F]` for `F` fields).
    pub columns: T::Array<&'a [f32]>,
}

/// Borrowed columns to write; every column must have the same length.
pub struct SoaMut<'a, T: Fields> {
    /// One column per field (`[&mut [f32]; F]` for `F` fields).
    pub columns: T::Array<&'a mut [f32]>,
}

/// Owned 3D boxes as columns `min.x, min.y, min.z, max.x, max.y, max.z`.
pub type AabbSoa = Soa<Aabb3>;
/// Borrowed 3D box columns to read.
pub type AabbSoaRef<'a> = SoaRef<'a, Aabb3>;
/// Borrowed 3D box columns to write.
pub type AabbSoaMut<'a> = SoaMut<'a, Aabb3>;
/// Owned 2D boxes as columns `min.x, min.y, max.x, max.y`.
pub type Aabb2Soa = Soa<Aabb2>;
/// Borrowed 2D box columns to read.
pub type Aabb2SoaRef<'a> = SoaRef<'a, Aabb2>;
/// Borrowed 2D box columns to write.
pub type Aabb2SoaMut<'a> = SoaMut<'a, Aabb2>;
/// Owned 3D affine transforms as twelve columns.
pub type Affine3Soa = Soa<Affine3A>;
/// Borrowed 3D affine transform columns.
pub type Affine3SoaRef<'a> = SoaRef<'a, Affine3A>;
/// Owned rigid transforms as seven columns (the quaternion, then the translation).
pub type Rigid3Soa = Soa<Rigid3>;
/// Borrowed rigid transform columns.
pub type Rigid3SoaRef<'a> = SoaRef<'a, Rigid3>;

impl<T: Fields> Clone for Soa<T> {
    fn clone(&self) -> Self {
        Self::from_columns(T::array(|n| self.columns.as_ref()[n].clone()))
    }
}

impl<T: Fields> PartialEq for Soa<T> {
    fn eq(&self, other: &Self) -> bool {
        self.columns.as_ref() == other.columns.as_ref()
    }
}

impl<T: Fields> core::fmt::Debug for Soa<T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Soa")
            .field("columns", &self.columns.as_ref())
            .finish()
    }
}

impl<T: Fields> Clone for SoaRef<'_, T> {
    fn clone(&self) -> Self {
        Self::new(T::array(|n| self.columns.as_ref()[n]))
    }
}

impl<'a, T: Fields> Copy for SoaRef<'a, T> where T::Array<&'a [f32]>: Copy {}

impl<T: Fields> core::fmt::Debug for SoaRef<'_, T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("SoaRef")
            .field("columns", &self.columns.as_ref())
            .finish()
    }
}

impl<T: Fields> core::fmt::Debug for SoaMut<'_, T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("SoaMut")
            .field("columns", &self.columns.as_ref())
            .finish()
    }
}

impl<T: Fields> Soa<T> {
    /// Columns from their data.
    #[must_use]
    pub fn from_columns(columns: T::Array<Vec<f32>>) -> Self {
        Self { columns }
    }

    /// The values as columns.
    #[must_use]
    pub fn from_slice(values: &[T]) -> Self {
        let mut columns = T::array(|_| Vec::with_capacity(values.len()));
        for v in values {
            let f = v.to_fields();
            for (column, x) in columns.as_mut().iter_mut().zip(f) {
                column.push(x);
            }
        }
        Self::from_columns(columns)
    }

    /// `len` copies of `value`.
    #[must_use]
    pub fn filled(len: usize, value: T) -> Self {
        let f = value.to_fields();
        Self::from_columns(T::array(|n| vec![f[n]; len]))
    }

    /// The number of values (of the first column).
    #[must_use]
    pub fn len(&self) -> usize {
        self.columns.as_ref().first().map_or(0, Vec::len)
    }

    /// True when there are no values.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Value `k`.
    ///
    /// # Panics
    /// When `k` is out of range of any column (`k >= len()`, or the columns are ragged and
    /// one is shorter), as a slice index does.
    #[must_use]
    pub fn get(&self, k: usize) -> T {
        let mut v = [0.0; MAX_FIELDS];
        for (n, (x, column)) in v.iter_mut().zip(self.columns.as_ref()).enumerate() {
            assert!(
                k < column.len(),
                "Soa index {k} out of range: column {n} has {} values",
                column.len()
            );
            *x = column[k];
        }
        T::from_fields(&v)
    }

    /// A read view.
    #[must_use]
    pub fn view(&self) -> SoaRef<'_, T> {
        let columns = self.columns.as_ref();
        SoaRef::new(T::array(|n| columns[n].as_slice()))
    }

    /// A write view.
    #[must_use]
    pub fn view_mut(&mut self) -> SoaMut<'_, T> {
        let mut columns = self.columns.as_mut().iter_mut();
        SoaMut::new(T::array(|_| {
            columns.next().map_or(&mut [][..], Vec::as_mut_slice)
        }))
    }
}

impl<'a, T: Fields> SoaRef<'a, T> {
    /// A view of borrowed columns, one per field of `T` in its field order.
    #[must_use]
    pub fn new(columns: T::Array<&'a [f32]>) -> Self {
        Self { columns }
    }

    /// Every column cut to its first `len` values (the engine's trim), in place: built anew
    /// by `array::from_fn`, left out of line for many columns, the lengths came back
    /// through memory as values the compiler could not tell equal to `len`.
    #[inline(always)]
    fn prefix(mut self, len: usize) -> Self {
        for column in self.columns.as_mut() {
            let whole: &'a [f32] = column;
            *column = &whole[..len];
        }
        self
    }
}

impl<'a, T: Fields> SoaMut<'a, T> {
    /// A view of borrowed columns to write, one per field of `T` in its field order.
    #[must_use]
    pub fn new(columns: T::Array<&'a mut [f32]>) -> Self {
        Self { columns }
    }

    /// Every column cut to its first `len` values (the engine's trim), in place, as for
    /// [`SoaRef`].
    #[inline(always)]
    fn prefix(mut self, len: usize) -> Self {
        for column in self.columns.as_mut() {
            let whole = core::mem::take(column);
            *column = &mut whole[..len];
        }
        self
    }
}

/// The common length of `columns`, or the mismatch of the first that differs.
fn common_len(
    what: &'static str,
    mut columns: impl Iterator<Item = usize>,
) -> Result<usize, BatchError> {
    let first = columns.next().unwrap_or(0);
    for found in columns {
        BatchError::check_len(what, first, found)?;
    }
    Ok(first)
}

/// Columns of equal length split into views of `chunk` values each (the last may be
/// shorter), for the parallel batch.
#[cfg(feature = "rayon")]
fn split_columns<'p, T: Fields>(
    columns: impl Iterator<Item = &'p mut [f32]>,
    chunk: usize,
) -> Vec<SoaMut<'p, T>> {
    let mut len = 0;
    let mut chunks: Vec<_> = columns
        .map(|c| {
            len = c.len();
            c.chunks_mut(chunk)
        })
        .collect();
    (0..len.div_ceil(chunk))
        .map(|_| SoaMut::new(T::array(|n| chunks[n].next().unwrap_or_default())))
        .collect()
}

/// Asks for entry `i` of every column.
#[inline(always)]
fn prefetch_columns(columns: &[&[f32]], i: usize) {
    for column in columns {
        crate::simd::prefetch(&column[i]);
    }
}

/// Lanes `i..i + count` of every column: one vector load per column for a whole span,
/// lane by lane for the tail.
#[inline(always)]
fn gather<L: LaneArray, T: Fields>(
    columns: &T::Array<&[f32]>,
    i: usize,
    count: usize,
) -> [L; MAX_FIELDS] {
    let columns = columns.as_ref();
    let mut f = zero_fields::<L>();
    if count == L::WIDTH {
        // `i..end` rather than `i..`: the check `i <= end` is shared by every column, so
        // each column costs one length check.
        let end = i + L::WIDTH;
        for n in 0..T::FIELDS {
            f[n] = L::load(&columns[n][i..end]);
        }
        return f;
    }
    for n in 0..T::FIELDS {
        for k in 0..L::WIDTH {
            if k < count {
                f[n].set(k, columns[n][i + k]);
            }
        }
    }
    f
}

impl<const N: usize, B: Boxes<N> + NamedItem> BoxSource<N> for SoaRef<'_, B> {
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, len: usize) -> Self {
        self.prefix(len)
    }
    fn len(&self) -> Result<usize, BatchError> {
        common_len(
            "a column of the local boxes",
            self.columns.as_ref().iter().map(|c| c.len()),
        )
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, N>, Vector<L, N>) {
        box_lanes(&gather::<L, B>(&self.columns, i, count))
    }
    fn get(&self, i: usize) -> ([f32; N], [f32; N]) {
        let c = self.columns.as_ref();
        (
            core::array::from_fn(|a| c[a][i]),
            core::array::from_fn(|a| c[N + a][i]),
        )
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        prefetch_columns(self.columns.as_ref(), i);
    }
}

impl<const N: usize, B: Boxes<N> + NamedItem> BoxSink<N> for SoaMut<'_, B> {
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, len: usize) -> Self {
        self.prefix(len)
    }
    fn len(&mut self) -> Result<usize, BatchError> {
        common_len(
            "a column of the output",
            self.columns.as_ref().iter().map(|c| c.len()),
        )
    }
    type Read<'r>
        = SoaRef<'r, B>
    where
        Self: 'r;
    #[inline(always)]
    fn read(&self) -> SoaRef<'_, B> {
        let columns = self.columns.as_ref();
        SoaRef::new(B::array(|n| &*columns[n]))
    }
    #[inline(always)]
    fn store<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        min: Vector<L, N>,
        max: Vector<L, N>,
    ) {
        let columns = self.columns.as_mut();
        if count == L::WIDTH {
            let end = i + L::WIDTH;
            for a in 0..N {
                min.0[a].store(&mut columns[a][i..end]);
                max.0[a].store(&mut columns[N + a][i..end]);
            }
            return;
        }
        for a in 0..N {
            for k in 0..L::WIDTH {
                if k < count {
                    columns[a][i + k] = min.0[a].get(k);
                    columns[N + a][i + k] = max.0[a].get(k);
                }
            }
        }
    }
    /// Inlined: out of line, it would take the address of the engine's trimmed output,
    /// whose lengths would then stay in memory and be checked on every span.
    #[inline(always)]
    fn set(&mut self, i: usize, min: [f32; N], max: [f32; N]) {
        let columns = self.columns.as_mut();
        for a in 0..N {
            columns[a][i] = min[a];
            columns[N + a][i] = max[a];
        }
    }
    #[cfg(feature = "rayon")]
    type Part<'p>
        = SoaMut<'p, B>
    where
        Self: 'p;
    #[cfg(feature = "rayon")]
    fn parts(&mut self, chunk: usize) -> Vec<SoaMut<'_, B>> {
        split_columns(self.columns.as_mut().iter_mut().map(|c| &mut **c), chunk)
    }
}

impl<const N: usize, T: Class<N>> TransformSource<N> for SoaRef<'_, T> {
    type Class = T;
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, len: usize) -> Self {
        self.prefix(len)
    }
    fn len(&self) -> Result<Option<usize>, BatchError> {
        common_len(
            "a column of the transforms",
            self.columns.as_ref().iter().map(|c| c.len()),
        )
        .map(Some)
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> T::Lanes<L> {
        T::lanes(&gather::<L, T>(&self.columns, i, count))
    }
    fn get(&self, i: usize) -> T {
        let mut v = [0.0; MAX_FIELDS];
        for (x, column) in v.iter_mut().zip(self.columns.as_ref()) {
            *x = column[i];
        }
        T::from_fields(&v)
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        prefetch_columns(self.columns.as_ref(), i);
    }
}

impl<'a, const N: usize, E: NamedItem> BoxSource<N> for &'a Soa<E>
where
    SoaRef<'a, E>: BoxSource<N>,
{
    type Trimmed = SoaRef<'a, E>;
    #[inline(always)]
    fn trim(self, len: usize) -> SoaRef<'a, E> {
        self.view().prefix(len)
    }
    fn len(&self) -> Result<usize, BatchError> {
        BoxSource::len(&self.view())
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, N>, Vector<L, N>) {
        BoxSource::load(&self.view(), i, count)
    }
    fn get(&self, i: usize) -> ([f32; N], [f32; N]) {
        BoxSource::get(&self.view(), i)
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        BoxSource::prefetch(&self.view(), i);
    }
}

impl<'a, const N: usize, E: NamedItem> BoxSink<N> for &'a mut Soa<E>
where
    for<'b> SoaMut<'b, E>: BoxSink<N>,
    for<'b> SoaRef<'b, E>: BoxSource<N>,
{
    type Trimmed = SoaMut<'a, E>;
    #[inline(always)]
    fn trim(self, len: usize) -> SoaMut<'a, E> {
        self.view_mut().prefix(len)
    }
    fn len(&mut self) -> Result<usize, BatchError> {
        BoxSink::len(&mut self.view_mut())
    }
    type Read<'r>
        = SoaRef<'r, E>
    where
        Self: 'r;
    #[inline(always)]
    fn read(&self) -> SoaRef<'_, E> {
        self.view()
    }
    #[inline(always)]
    fn store<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        min: Vector<L, N>,
        max: Vector<L, N>,
    ) {
        self.view_mut().store(i, count, min, max);
    }
    fn set(&mut self, i: usize, min: [f32; N], max: [f32; N]) {
        self.view_mut().set(i, min, max);
    }
    #[cfg(feature = "rayon")]
    type Part<'p>
        = SoaMut<'p, E>
    where
        Self: 'p;
    #[cfg(feature = "rayon")]
    fn parts(&mut self, chunk: usize) -> Vec<SoaMut<'_, E>> {
        split_columns(
            self.columns.as_mut().iter_mut().map(Vec::as_mut_slice),
            chunk,
        )
    }
}

impl<'a, const N: usize, E: NamedItem> TransformSource<N> for &'a Soa<E>
where
    SoaRef<'a, E>: TransformSource<N>,
{
    type Class = <SoaRef<'a, E> as TransformSource<N>>::Class;
    type Trimmed = SoaRef<'a, E>;
    #[inline(always)]
    fn trim(self, len: usize) -> SoaRef<'a, E> {
        self.view().prefix(len)
    }
    fn len(&self) -> Result<Option<usize>, BatchError> {
        TransformSource::len(&self.view())
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> <Self::Class as Class<N>>::Lanes<L> {
        TransformSource::load(&self.view(), i, count)
    }
    fn get(&self, i: usize) -> Self::Class {
        TransformSource::get(&self.view(), i)
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        TransformSource::prefetch(&self.view(), i);
    }
}
