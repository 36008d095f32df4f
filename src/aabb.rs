//! Axis-aligned bounding boxes in 3D and 2D.
//!
//! A box is the set of real points `p` with `min <= p <= max` on every axis. It is
//! *empty* when it holds no real point: `min > max` on some axis, or a face at the wrong
//! infinity (`min = +inf` or `max = -inf`). [`Aabb3::EMPTY`] (`min = +inf`,
//! `max = -inf`) is the canonical empty box and the identity of [`Aabb3::union`]. A box
//! with a NaN anywhere is *invalid* ([`Aabb3::is_valid`] is false), never empty.

use glam::{Vec2, Vec3A};

use crate::fields::{Fields, MAX_FIELDS};

/// An axis-aligned box in 3D, `min <= p <= max`.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::AnyBitPattern))]
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Aabb3 {
    /// The lower corner.
    pub min: Vec3A,
    /// The upper corner.
    pub max: Vec3A,
}

/// An axis-aligned box in 2D, `min <= p <= max`.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::Pod, bytemuck::Zeroable))]
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Aabb2 {
    /// The lower corner.
    pub min: Vec2,
    /// The upper corner.
    pub max: Vec2,
}

macro_rules! impl_aabb {
    ($Aabb:ident, $Vec:ident, $measure:ident, $measure_doc:literal) => {
        impl $Aabb {
            /// The empty box: `min = +inf`, `max = -inf`. Transforming it gives it back.
            pub const EMPTY: Self = Self {
                min: $Vec::INFINITY,
                max: $Vec::NEG_INFINITY,
            };

            /// The invalid box every NaN input maps to: all faces NaN.
            pub const NAN: Self = Self {
                min: $Vec::NAN,
                max: $Vec::NAN,
            };

            /// The box with corners `min` and `max`.
            #[inline]
            #[must_use]
            pub const fn new(min: $Vec, max: $Vec) -> Self {
                Self { min, max }
            }

            /// The box `center ± half_extents`.
            #[inline]
            #[must_use]
            pub fn from_center_half_extents(center: $Vec, half_extents: $Vec) -> Self {
                Self {
                    min: center - half_extents,
                    max: center + half_extents,
                }
            }

            /// The smallest box holding every point (`EMPTY` for none; NaN points make it
            /// invalid).
            #[must_use]
            pub fn from_points(points: impl IntoIterator<Item = $Vec>) -> Self {
                points.into_iter().fold(Self::EMPTY, |b, p| Self {
                    min: b.min.min(p),
                    max: b.max.max(p),
                })
            }

            /// The center `(min + max) / 2`, halved first so that it never overflows.
            #[inline]
            #[must_use]
            pub fn center(&self) -> $Vec {
                self.min * 0.5 + self.max * 0.5
            }

            /// The half-extents `(max - min) / 2` (negative on an axis where the box is empty).
            #[inline]
            #[must_use]
            pub fn half_extents(&self) -> $Vec {
                self.max * 0.5 - self.min * 0.5
            }

            /// True when the box holds no real point (see the module docs).
            #[inline]
            #[must_use]
            pub fn is_empty(&self) -> bool {
                self.min.cmpgt(self.max).any()
                    || self.min.cmpeq($Vec::INFINITY).any()
                    || self.max.cmpeq($Vec::NEG_INFINITY).any()
            }

            /// True when no face is NaN.
            #[inline]
            #[must_use]
            pub fn is_valid(&self) -> bool {
                !(self.min.is_nan() || self.max.is_nan())
            }

            /// True when `p` lies in the box (faces included).
            #[inline]
            #[must_use]
            pub fn contains_point(&self, p: $Vec) -> bool {
                self.min.cmple(p).all() && p.cmple(self.max).all()
            }

            /// True when every point of `other` lies in `self`; an empty `other` is
            /// contained in every valid box.
            #[inline]
            #[must_use]
            pub fn contains(&self, other: &Self) -> bool {
                if !(self.is_valid() && other.is_valid()) {
                    return false;
                }
                other.is_empty()
                    || (self.min.cmple(other.min).all() && other.max.cmple(self.max).all())
            }

            /// The smallest box holding both.
            #[inline]
            #[must_use]
            pub fn union(&self, other: &Self) -> Self {
                Self {
                    min: self.min.min(other.min),
                    max: self.max.max(other.max),
                }
            }

            #[doc = $measure_doc]
            #[inline]
            #[must_use]
            pub fn $measure(&self) -> f32 {
                if self.is_empty() {
                    0.0
                } else {
                    (self.max - self.min).element_product()
                }
            }
        }

        impl Default for $Aabb {
            /// The empty box.
            #[inline]
            fn default() -> Self {
                Self::EMPTY
            }
        }
    };
}

impl_aabb!(Aabb3, Vec3A, volume, "The volume (0 for an empty box).");
impl_aabb!(Aabb2, Vec2, area, "The area (0 for an empty box).");

impl Aabb3 {
    /// The 8 corners; bit `j` of the index picks `max` (1) or `min` (0) on axis `j`.
    #[inline]
    #[must_use]
    pub fn corners(&self) -> [Vec3A; 8] {
        let pick = |k: usize, j: usize| if k >> j & 1 == 0 { self.min } else { self.max };
        core::array::from_fn(|k| Vec3A::new(pick(k, 0).x, pick(k, 1).y, pick(k, 2).z))
    }
}

impl Aabb2 {
    /// The 4 corners; bit `j` of the index picks `max` (1) or `min` (0) on axis `j`.
    #[inline]
    #[must_use]
    pub fn corners(&self) -> [Vec2; 4] {
        let pick = |k: usize, j: usize| if k >> j & 1 == 0 { self.min } else { self.max };
        core::array::from_fn(|k| Vec2::new(pick(k, 0).x, pick(k, 1).y))
    }
}

/// Fields `[min.x, min.y, min.z, max.x, max.y, max.z]`; blocks pad with `EMPTY`.
impl Fields for Aabb3 {
    const FIELDS: usize = 6;
    type Array<C: Send + Sync> = [C; 6];
    #[inline(always)]
    fn array<C: Send + Sync>(f: impl FnMut(usize) -> C) -> Self::Array<C> {
        core::array::from_fn(f)
    }
    const PADDING: Self = Self::EMPTY;
    #[inline(always)]
    fn to_fields(&self) -> [f32; MAX_FIELDS] {
        let (a, b) = (self.min, self.max);
        [a.x, a.y, a.z, b.x, b.y, b.z, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    }
    #[inline(always)]
    fn from_fields(f: &[f32; MAX_FIELDS]) -> Self {
        Self::new(Vec3A::new(f[0], f[1], f[2]), Vec3A::new(f[3], f[4], f[5]))
    }
}

/// Fields `[min.x, min.y, max.x, max.y]`; blocks pad with `EMPTY`.
impl Fields for Aabb2 {
    const FIELDS: usize = 4;
    type Array<C: Send + Sync> = [C; 4];
    #[inline(always)]
    fn array<C: Send + Sync>(f: impl FnMut(usize) -> C) -> Self::Array<C> {
        core::array::from_fn(f)
    }
    const PADDING: Self = Self::EMPTY;
    #[inline(always)]
    fn to_fields(&self) -> [f32; MAX_FIELDS] {
        let (a, b) = (self.min, self.max);
        [a.x, a.y, b.x, b.y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    }
    #[inline(always)]
    fn from_fields(f: &[f32; MAX_FIELDS]) -> Self {
        Self::new(Vec2::new(f[0], f[1]), Vec2::new(f[2], f[3]))
    }
}

/// A box type of `N` dimensions: its fields are `min` then `max`. The two are [`Aabb3`]
/// and [`Aabb2`].
pub(crate) trait Boxes<const N: usize>: Fields {}
impl Boxes<3> for Aabb3 {}
impl Boxes<2> for Aabb2 {}
