//! Rigid 2D transforms: a rotation given by its cosine and sine, plus a translation.

use glam::{Affine2, Mat2, Vec2};

use super::{Class, Transform2};
use crate::extended::ExtendedMap;
use crate::fields::{Fields, MAX_FIELDS};
use crate::kernel::MapKernel;
use crate::kernel::{self, AffineLanes};
use crate::lane::{Lane, Vector};
use crate::method::Method;

/// A rotation `[[cos, -sin], [sin, cos]]` followed by a translation: `p ↦ R p + t`.
///
/// `cos` and `sin` are used as given; a pair that has drifted off the unit circle is a
/// slightly scaled rotation, and every kernel still bounds the exact image of that map.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::Pod, bytemuck::Zeroable))]
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Rigid2 {
    /// The cosine of the rotation angle.
    pub cos: f32,
    /// The sine of the rotation angle.
    pub sin: f32,
    /// The translation, applied after the rotation.
    pub translation: Vec2,
}

impl Rigid2 {
    /// The identity transform.
    pub const IDENTITY: Self = Self {
        cos: 1.0,
        sin: 0.0,
        translation: Vec2::ZERO,
    };

    /// The rotation by `cos`/`sin` followed by `translation`.
    #[inline]
    #[must_use]
    pub const fn new(cos: f32, sin: f32, translation: Vec2) -> Self {
        Self {
            cos,
            sin,
            translation,
        }
    }

    /// The rotation by `angle` radians (counter-clockwise) followed by `translation`.
    #[inline]
    #[must_use]
    pub fn from_angle_translation(angle: f32, translation: Vec2) -> Self {
        let (sin, cos) = crate::num::sin_cos(angle);
        Self::new(cos, sin, translation)
    }

    /// The rotation by `angle` radians (counter-clockwise), no translation.
    #[inline]
    #[must_use]
    pub fn from_angle(angle: f32) -> Self {
        Self::from_angle_translation(angle, Vec2::ZERO)
    }

    /// The same map as a general 2D affine transform.
    #[inline]
    #[must_use]
    pub fn to_affine2(&self) -> Affine2 {
        Affine2::from(*self)
    }

    /// `R p + t`.
    #[inline]
    #[must_use]
    pub fn transform_point(&self, p: Vec2) -> Vec2 {
        Vec2::new(
            self.cos * p.x - self.sin * p.y,
            self.sin * p.x + self.cos * p.y,
        ) + self.translation
    }
}

impl From<Rigid2> for Affine2 {
    #[inline]
    fn from(xf: Rigid2) -> Affine2 {
        Affine2::from_mat2_translation(
            Mat2::from_cols(Vec2::new(xf.cos, xf.sin), Vec2::new(-xf.sin, xf.cos)),
            xf.translation,
        )
    }
}

/// Rigid 2D maps `[[cos, −sin], [sin, cos]]`, `t` per lane.
#[derive(Clone, Copy, Debug)]
pub struct Rigid2Lanes<L> {
    pub cos: L,
    pub sin: L,
    pub t: [L; 2],
}

impl<L: Lane> MapKernel<Vector<L, 2>> for Rigid2Lanes<L> {
    /// [`Method::SignSelect`] is Eberly's sign branch; the others run as for the matrix.
    #[inline(always)]
    fn transform(
        &self,
        lo: Vector<L, 2>,
        hi: Vector<L, 2>,
        method: Method,
        outward: bool,
    ) -> (Vector<L, 2>, Vector<L, 2>) {
        let (cos, sin) = (self.cos, self.sin);
        let a = AffineLanes {
            cols: [Vector([cos, sin]), Vector([-sin, cos])],
            t: Vector(self.t),
        };
        if method != Method::SignSelect {
            return kernel::transform(&a, lo, hi, method, outward);
        }
        let (min, max) = kernel::sign_branch_rigid2(cos, sin, self.t, lo.0, hi.0);
        let (min, max) = (Vector(min), Vector(max));
        if outward {
            let pad = kernel::outward_pad(&a, lo, hi, method.outward_factor(2));
            (min - pad, max + pad)
        } else {
            (min, max)
        }
    }
}

/// Fields `[cos, sin, t0, t1]`.
impl Fields for Rigid2 {
    const FIELDS: usize = 4;
    type Array<C: Send + Sync> = [C; 4];
    #[inline(always)]
    fn array<C: Send + Sync>(f: impl FnMut(usize) -> C) -> Self::Array<C> {
        core::array::from_fn(f)
    }
    const PADDING: Self = Rigid2::IDENTITY;
    #[inline(always)]
    fn to_fields(&self) -> [f32; MAX_FIELDS] {
        let (c, s, t) = (self.cos, self.sin, self.translation);
        [c, s, t.x, t.y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    }
    #[inline(always)]
    fn from_fields(f: &[f32; MAX_FIELDS]) -> Self {
        Self::new(f[0], f[1], Vec2::new(f[2], f[3]))
    }
}

impl Class<2> for Rigid2 {
    type Lanes<L: Lane> = Rigid2Lanes<L>;
    #[inline(always)]
    fn lanes<L: Lane>(f: &[L; MAX_FIELDS]) -> Self::Lanes<L> {
        Rigid2Lanes {
            cos: f[0],
            sin: f[1],
            t: [f[2], f[3]],
        }
    }
    fn extended(&self) -> ExtendedMap<2> {
        let (c, s) = (self.cos, self.sin);
        ExtendedMap::exact([[c, s], [-s, c]], self.translation.to_array())
    }
    fn order(method: Method) -> u32 {
        method.nearest_order(2)
    }
}

impl Transform2 for Rigid2 {}
