//! A cast's input and its callback's answer: [`Ray`] and [`CastControl`].

use glam::Vec3A;

/// A ray: the points `origin + t·direction` for `t` in `[0, max]` (`max` in units of the
/// direction's length: the distance, for a unit direction; `f32::INFINITY` for no end).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Ray {
    /// Where the ray starts.
    pub origin: Vec3A,
    /// Its direction (any length but zero).
    pub direction: Vec3A,
    /// The largest `t` it reaches.
    pub max: f32,
}

impl Ray {
    /// The ray from `origin` along `direction` up to `t = max`.
    #[inline]
    #[must_use]
    pub const fn new(origin: Vec3A, direction: Vec3A, max: f32) -> Self {
        Self {
            origin,
            direction,
            max,
        }
    }

    /// True when the tree casts it: a finite origin, a finite nonzero direction, and `max`
    /// not NaN nor negative.
    #[inline]
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.origin.is_finite()
            && self.direction.is_finite()
            && self.direction != Vec3A::ZERO
            && self.max >= 0.0
    }
}

/// What a cast does after its callback saw a hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CastControl {
    /// Go on to the other boxes within the cast's length (all hits).
    Continue,
    /// Go on, with the cast's length cut to `t` if shorter (the closest hit: the narrow
    /// phase's exact distance to the shape); a NaN `t` stops the cast.
    Clip(f32),
    /// Stop now (any hit).
    Stop,
}
