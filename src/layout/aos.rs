//! AoS slices (`&[Aabb3]`, `&[Rigid3]`, …, 2D alike), `Vec`s of them, and shared transforms,
//! as lanes.
//!
//! Loaders run over every lane with a constant index (`k < count` masks the tail), so
//! that the lane arrays stay in registers and the main loop, where `count` is the lane
//! width, has no mask at all.

use super::{BoxSink, BoxSource, TransformSource};
use super::{NamedItem, box_lanes, zero_fields};
use crate::aabb::Boxes;
use crate::error::BatchError;
use crate::fields::{Fields, MAX_FIELDS};
use crate::lane::Vector;
use crate::simd::LaneArray;
use crate::transform::Class;
use alloc::vec::Vec;

/// Items `i..i + count` of a slice, field `n` of item `k` in lane `k` of `f[n]`.
#[inline(always)]
fn gather<L: LaneArray, T: Fields>(items: &[T], i: usize, count: usize) -> [L; MAX_FIELDS] {
    let mut f = zero_fields::<L>();
    for k in 0..L::WIDTH {
        if k < count {
            let v = items[i + k].to_fields();
            for n in 0..T::FIELDS {
                f[n].set(k, v[n]);
            }
        }
    }
    f
}

impl<const N: usize, B: Boxes<N> + NamedItem> BoxSource<N> for &[B] {
    fn len(&self) -> Result<usize, BatchError> {
        Ok(<[B]>::len(self))
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, N>, Vector<L, N>) {
        box_lanes(&gather::<L, B>(self, i, count))
    }
    fn get(&self, i: usize) -> ([f32; N], [f32; N]) {
        let (lo, hi) = box_lanes::<f32, N>(&self[i].to_fields());
        (lo.0, hi.0)
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        crate::simd::prefetch(&self[i]);
    }
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, len: usize) -> Self {
        &self[..len]
    }
}

impl<const N: usize, B: Boxes<N> + NamedItem> BoxSink<N> for &mut [B] {
    fn len(&mut self) -> Result<usize, BatchError> {
        Ok(<[B]>::len(self))
    }
    type Read<'r>
        = &'r [B]
    where
        Self: 'r;
    #[inline(always)]
    fn read(&self) -> &[B] {
        self
    }
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, len: usize) -> Self {
        &mut self[..len]
    }
    #[inline(always)]
    fn store<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        min: Vector<L, N>,
        max: Vector<L, N>,
    ) {
        for k in 0..L::WIDTH {
            if k < count {
                let mut v = [0.0; MAX_FIELDS];
                for a in 0..N {
                    v[a] = min.0[a].get(k);
                    v[N + a] = max.0[a].get(k);
                }
                self[i + k] = B::from_fields(&v);
            }
        }
    }
    fn set(&mut self, i: usize, min: [f32; N], max: [f32; N]) {
        let mut v = [0.0; MAX_FIELDS];
        v[..N].copy_from_slice(&min);
        v[N..2 * N].copy_from_slice(&max);
        self[i] = B::from_fields(&v);
    }
    #[cfg(feature = "rayon")]
    type Part<'p>
        = &'p mut [B]
    where
        Self: 'p;
    #[cfg(feature = "rayon")]
    fn parts(&mut self, chunk: usize) -> Vec<&mut [B]> {
        self.chunks_mut(chunk).collect()
    }
}

impl<const N: usize, T: Class<N>> TransformSource<N> for &[T] {
    type Class = T;
    fn len(&self) -> Result<Option<usize>, BatchError> {
        Ok(Some(<[T]>::len(self)))
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> T::Lanes<L> {
        T::lanes(&gather::<L, T>(self, i, count))
    }
    fn get(&self, i: usize) -> T {
        self[i]
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        crate::simd::prefetch(&self[i]);
    }
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, len: usize) -> Self {
        &self[..len]
    }
}

/// One transform shared by every box (compound bodies, instanced props).
impl<const N: usize, T: Class<N>> TransformSource<N> for &T {
    type Class = T;
    fn len(&self) -> Result<Option<usize>, BatchError> {
        Ok(None)
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, _: usize, _: usize) -> T::Lanes<L> {
        let v = self.to_fields();
        let mut f = zero_fields::<L>();
        for n in 0..T::FIELDS {
            f[n] = L::splat(v[n]);
        }
        T::lanes(&f)
    }
    fn get(&self, _: usize) -> T {
        **self
    }
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, _: usize) -> Self {
        self
    }
}

impl<'a, const N: usize, E: Boxes<N> + NamedItem> BoxSource<N> for &'a Vec<E> {
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
        crate::simd::prefetch(&self[i]);
    }
    type Trimmed = &'a [E];
    #[inline(always)]
    fn trim(self, len: usize) -> &'a [E] {
        &self[..len]
    }
}

impl<'a, const N: usize, E: Boxes<N> + NamedItem> BoxSink<N> for &'a mut Vec<E> {
    fn len(&mut self) -> Result<usize, BatchError> {
        BoxSink::len(&mut self.as_mut_slice())
    }
    type Read<'r>
        = &'r [E]
    where
        Self: 'r;
    #[inline(always)]
    fn read(&self) -> &[E] {
        self
    }
    type Trimmed = &'a mut [E];
    #[inline(always)]
    fn trim(self, len: usize) -> &'a mut [E] {
        &mut self[..len]
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
    fn set(&mut self, i: usize, min: [f32; N], max: [f32; N]) {
        self.as_mut_slice().set(i, min, max);
    }
    #[cfg(feature = "rayon")]
    type Part<'p>
        = &'p mut [E]
    where
        Self: 'p;
    #[cfg(feature = "rayon")]
    fn parts(&mut self, chunk: usize) -> Vec<&mut [E]> {
        self.chunks_mut(chunk).collect()
    }
}

impl<'a, const N: usize, E: Class<N>> TransformSource<N> for &'a Vec<E> {
    type Class = E;
    fn len(&self) -> Result<Option<usize>, BatchError> {
        TransformSource::len(&self.as_slice())
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> <Self::Class as Class<N>>::Lanes<L> {
        TransformSource::load(&self.as_slice(), i, count)
    }
    fn get(&self, i: usize) -> Self::Class {
        TransformSource::get(&self.as_slice(), i)
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        crate::simd::prefetch(&self[i]);
    }
    type Trimmed = &'a [E];
    #[inline(always)]
    fn trim(self, len: usize) -> &'a [E] {
        &self[..len]
    }
}
