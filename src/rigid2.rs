//! Rigid 2D transforms: a rotation given by its cosine and sine, plus a translation.

use glam::{Affine2, Mat2, Vec2};

/// A rotation `[[cos, -sin], [sin, cos]]` followed by a translation: `p ↦ R p + t`.
///
/// `cos` and `sin` are used as given; a pair that has drifted off the unit circle is a
/// slightly scaled rotation, and every kernel still bounds the exact image of that map.
#[derive(Clone, Copy, Debug, PartialEq)]
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
        let (sin, cos) = angle.sin_cos();
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
        Affine2::from_mat2_translation(
            Mat2::from_cols(
                Vec2::new(self.cos, self.sin),
                Vec2::new(-self.sin, self.cos),
            ),
            self.translation,
        )
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
