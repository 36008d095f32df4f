//! Translations: a box moved without rotation or scale, the class of spheres and sprites.

use glam::{Affine2, Affine3A, Vec2, Vec3, Vec3A};

use super::{Class, Transform2, Transform3};
use crate::extended::ExtendedMap;
use crate::fields::{Fields, MAX_FIELDS, vector_at};
use crate::kernel;
use crate::kernel::MapKernel;
use crate::lane::{Axes, Lane, Vector};
use crate::method::Method;

/// A 3D translation `x ↦ x + t`.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::AnyBitPattern))]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(transparent)]
pub struct Translation3(pub Vec3A);

/// A 2D translation `x ↦ x + t`.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::Pod, bytemuck::Zeroable))]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(transparent)]
pub struct Translation2(pub Vec2);

impl Translation3 {
    /// No motion.
    pub const IDENTITY: Self = Self(Vec3A::ZERO);

    /// `p + t`.
    #[inline]
    #[must_use]
    pub fn transform_point(&self, p: Vec3A) -> Vec3A {
        p + self.0
    }
}

impl Translation2 {
    /// No motion.
    pub const IDENTITY: Self = Self(Vec2::ZERO);

    /// `p + t`.
    #[inline]
    #[must_use]
    pub fn transform_point(&self, p: Vec2) -> Vec2 {
        p + self.0
    }
}

impl From<Vec3> for Translation3 {
    #[inline]
    fn from(t: Vec3) -> Self {
        Self(t.into())
    }
}

impl From<Vec3A> for Translation3 {
    #[inline]
    fn from(t: Vec3A) -> Self {
        Self(t)
    }
}

impl From<Vec2> for Translation2 {
    #[inline]
    fn from(t: Vec2) -> Self {
        Self(t)
    }
}

impl From<Translation3> for Affine3A {
    #[inline]
    fn from(t: Translation3) -> Affine3A {
        Affine3A::from_translation(t.0.into())
    }
}

impl From<Translation2> for Affine2 {
    #[inline]
    fn from(t: Translation2) -> Affine2 {
        Affine2::from_translation(t.0)
    }
}

/// A translation in lanes.
#[derive(Clone, Copy, Debug)]
pub struct TranslationLanes<V> {
    pub t: V,
}

impl<V: Lane> MapKernel<V> for TranslationLanes<V> {
    /// Every method is the same map here: `[lo + t, hi + t]`.
    #[inline(always)]
    fn transform(&self, lo: V, hi: V, _: Method, outward: bool) -> (V, V) {
        kernel::translate(self.t, lo, hi, outward)
    }
}

/// Fields `[t0, t1, t2]`.
impl Fields for Translation3 {
    const FIELDS: usize = 3;
    type Array<C: Send + Sync> = [C; 3];
    #[inline(always)]
    fn array<C: Send + Sync>(f: impl FnMut(usize) -> C) -> Self::Array<C> {
        core::array::from_fn(f)
    }
    const PADDING: Self = Self::IDENTITY;
    #[inline(always)]
    fn to_fields(&self) -> [f32; MAX_FIELDS] {
        let t = self.0;
        [t.x, t.y, t.z, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    }
    #[inline(always)]
    fn from_fields(f: &[f32; MAX_FIELDS]) -> Self {
        Self(Vec3A::new(f[0], f[1], f[2]))
    }
}

/// One rounding per face: `n = 1` for every method (they coincide).
impl Class<3> for Translation3 {
    type Lanes<L: Lane> = TranslationLanes<Vector<L, 3>>;
    #[inline(always)]
    fn lanes<L: Lane>(f: &[L; MAX_FIELDS]) -> Self::Lanes<L> {
        TranslationLanes { t: vector_at(f, 0) }
    }
    fn extended(&self) -> ExtendedMap<3> {
        let one = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        ExtendedMap::exact(one, self.0.to_array())
    }
    fn order(_: Method) -> u32 {
        1
    }
}

impl Transform3 for Translation3 {
    type Simd<P: Axes> = TranslationLanes<P>;
    #[inline(always)]
    fn join<P: Axes, const W: usize>(
        maps: &[TranslationLanes<Vec3A>; W],
        join: impl Fn([Vec3A; W]) -> P,
    ) -> TranslationLanes<P> {
        TranslationLanes {
            t: join(kernel::gather(|k| maps[k].t)),
        }
    }
    #[inline(always)]
    fn simd(&self) -> TranslationLanes<Vec3A> {
        TranslationLanes { t: self.0 }
    }
}

/// Fields `[t0, t1]`.
impl Fields for Translation2 {
    const FIELDS: usize = 2;
    type Array<C: Send + Sync> = [C; 2];
    #[inline(always)]
    fn array<C: Send + Sync>(f: impl FnMut(usize) -> C) -> Self::Array<C> {
        core::array::from_fn(f)
    }
    const PADDING: Self = Self::IDENTITY;
    #[inline(always)]
    fn to_fields(&self) -> [f32; MAX_FIELDS] {
        let t = self.0;
        [t.x, t.y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    }
    #[inline(always)]
    fn from_fields(f: &[f32; MAX_FIELDS]) -> Self {
        Self(Vec2::new(f[0], f[1]))
    }
}

/// One rounding per face: `n = 1` for every method (they coincide).
impl Class<2> for Translation2 {
    type Lanes<L: Lane> = TranslationLanes<Vector<L, 2>>;
    #[inline(always)]
    fn lanes<L: Lane>(f: &[L; MAX_FIELDS]) -> Self::Lanes<L> {
        TranslationLanes { t: vector_at(f, 0) }
    }
    fn extended(&self) -> ExtendedMap<2> {
        ExtendedMap::exact([[1.0, 0.0], [0.0, 1.0]], self.0.to_array())
    }
    fn order(_: Method) -> u32 {
        1
    }
}

impl Transform2 for Translation2 {}
