//! Conversions to and from bevy_math 0.19 (feature `bevy`): boxes both ways with
//! `bevy_math::bounding::{Aabb3d, Aabb2d}`, poses from `bevy_math::{Isometry3d,
//! Isometry2d}` (and back).
//!
//! bevy_math 0.19 is built on glam 0.32 and bvkit on glam 0.33, so each conversion copies
//! the floats through arrays, bit for bit. Nothing is checked here: a NaN or inverted
//! `Aabb3d` converts as it is, and the call that uses it refuses it as it refuses any bad
//! box (for example [`DynamicTree::insert`](crate::broadphase::DynamicTree::insert) with
//! [`BroadphaseError::InvalidBox`](crate::broadphase::BroadphaseError::InvalidBox)). bevy
//! 0.20 moves the bounding boxes to `bevy_shape`, with the same fields.

use bevy_math::bounding::{Aabb2d, Aabb3d};
use bevy_math::{Isometry2d, Isometry3d, Rot2};
use glam::{Quat, Vec2, Vec3A};

use crate::{Aabb2, Aabb3, Rigid2, Rigid3};

impl From<Aabb3d> for Aabb3 {
    #[inline]
    fn from(b: Aabb3d) -> Self {
        Self::new(
            Vec3A::from_array(b.min.to_array()),
            Vec3A::from_array(b.max.to_array()),
        )
    }
}

impl From<Aabb3> for Aabb3d {
    #[inline]
    fn from(b: Aabb3) -> Self {
        Self {
            min: bevy_math::Vec3A::from_array(b.min.to_array()),
            max: bevy_math::Vec3A::from_array(b.max.to_array()),
        }
    }
}

impl From<Aabb2d> for Aabb2 {
    #[inline]
    fn from(b: Aabb2d) -> Self {
        Self::new(
            Vec2::from_array(b.min.to_array()),
            Vec2::from_array(b.max.to_array()),
        )
    }
}

impl From<Aabb2> for Aabb2d {
    #[inline]
    fn from(b: Aabb2) -> Self {
        Self {
            min: bevy_math::Vec2::from_array(b.min.to_array()),
            max: bevy_math::Vec2::from_array(b.max.to_array()),
        }
    }
}

/// The rotation as stored (bvkit uses a quaternion as given, unit or not: see
/// [`Transform3`](crate::Transform3)), then the translation.
impl From<Isometry3d> for Rigid3 {
    #[inline]
    fn from(p: Isometry3d) -> Self {
        Self {
            rotation: Quat::from_array(p.rotation.to_array()),
            translation: Vec3A::from_array(p.translation.to_array()),
        }
    }
}

impl From<Rigid3> for Isometry3d {
    #[inline]
    fn from(p: Rigid3) -> Self {
        Self {
            rotation: bevy_math::Quat::from_array(p.rotation.to_array()),
            translation: bevy_math::Vec3A::from_array(p.translation.to_array()),
        }
    }
}

/// `Rot2` holds the rotation's cosine and sine, as [`Rigid2`] does.
impl From<Isometry2d> for Rigid2 {
    #[inline]
    fn from(p: Isometry2d) -> Self {
        Self {
            cos: p.rotation.cos,
            sin: p.rotation.sin,
            translation: Vec2::from_array(p.translation.to_array()),
        }
    }
}

impl From<Rigid2> for Isometry2d {
    #[inline]
    fn from(p: Rigid2) -> Self {
        Self {
            rotation: Rot2 {
                cos: p.cos,
                sin: p.sin,
            },
            translation: bevy_math::Vec2::from_array(p.translation.to_array()),
        }
    }
}
