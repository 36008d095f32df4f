//! Bounding spheres and their fits.

use super::ball::smallest_ball;
use super::bound::{Bounded, largest, segment_distance};
use super::cloud::{self, exact};
use super::{Fit, FitError};
use crate::aabb::Aabb3;
use alloc::vec::Vec;
use glam::{DVec3, Vec3, Vec3A};

/// A ball: the points `x` with `|x − center| <= radius`, exactly, on the `f32` fields.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::AnyBitPattern))]
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Sphere {
    /// The center.
    pub center: Vec3A,
    /// The radius.
    pub radius: f32,
}

/// How many passes the fast fit spends adding the farthest point to its support set.
const FAST_PASSES: usize = 4;

impl Sphere {
    /// The sphere fitted to `points` with the given effort: [`Fit::Pca`] centers on the mean
    /// of the distinct points; [`Fit::Fast`] on the smallest ball of the extremal points along
    /// 13 directions, grown by the farthest points; [`Fit::Tight`] on the exact smallest
    /// enclosing ball. The radius is then certified from every point.
    ///
    /// # Errors
    /// [`FitError::Empty`] for no points, [`FitError::NonFinite`] for a non-finite point,
    /// [`FitError::Overflow`] when the radius would overflow `f32`.
    pub fn fit(points: &[Vec3], fit: Fit) -> Result<Self, FitError> {
        let bounds = cloud::validate(points)?;
        let center = match fit {
            Fit::Pca => cloud::summary(&cloud::unique(points)).mean,
            Fit::Fast => fast_center(points),
            Fit::Tight => smallest_center(points),
        };
        Self::around(points, &bounds, center)
    }

    /// The sphere around `points` centered at `center`, moved into their bounding box
    /// `bounds` and rounded to `f32` (so finite): the radius is the largest certified
    /// distance ([`segment_distance`] with `a = b`), so every point is in.
    fn around(points: &[Vec3], bounds: &Aabb3, center: DVec3) -> Result<Self, FitError> {
        let center = cloud::round_within(center, bounds);
        let c = center.as_dvec3();
        let radius = largest(
            points
                .iter()
                .map(|&p| segment_distance(exact(p), c, c).upper()),
        )
        .ok_or(FitError::Overflow)?;
        Ok(Self { center, radius })
    }

    /// True when `p` may lie in the ball: never false for a point of the ball, true only
    /// within `2^-47·(|p − c| + Σ_j |p_j − c_j|)` of it. NaN gives false.
    #[inline]
    #[must_use]
    pub fn contains_point(&self, p: Vec3A) -> bool {
        let c = self.center.as_dvec3();
        segment_distance(p.as_dvec3(), c, c).lower_f64() <= f64::from(self.radius)
    }

    /// The volume `4/3·π·r³`.
    #[inline]
    #[must_use]
    pub fn volume(&self) -> f32 {
        (4.0 / 3.0
            * core::f64::consts::PI
            * f64::from(self.radius)
            * f64::from(self.radius)
            * f64::from(self.radius)) as f32
    }

    /// An axis-aligned box, rounded outward, that contains the ball: `c ± r`, one rounding
    /// each, within `u·(|c| + r)` (the lemma's form).
    #[must_use]
    pub fn aabb(&self) -> Aabb3 {
        let c = self.center.as_dvec3();
        let r = f64::from(self.radius);
        let face = |sign: f64| c + DVec3::splat(sign * r);
        let scale = c.abs() + DVec3::splat(r.abs());
        Aabb3::new(
            Vec3A::from_array([0, 1, 2].map(|i| {
                Bounded {
                    value: face(-1.0)[i],
                    scale: scale[i],
                }
                .lower()
            })),
            Vec3A::from_array([0, 1, 2].map(|i| {
                Bounded {
                    value: face(1.0)[i],
                    scale: scale[i],
                }
                .upper()
            })),
        )
    }
}

/// The center of the exact smallest enclosing ball (Welzl, on the distinct points shuffled).
fn smallest_center(points: &[Vec3]) -> DVec3 {
    let mut distinct: Vec<[f64; 3]> = cloud::unique(points)
        .iter()
        .map(|&p| exact(p).to_array())
        .collect();
    cloud::shuffle(&mut distinct);
    DVec3::from_array(smallest_ball(&distinct).center)
}

/// The fast center: the smallest ball of the extremal points along the 13 sample
/// directions ([`super::sweep::projections`]; EPOS-26, Larsson 2008), then up to
/// [`FAST_PASSES`] times: find the farthest point from the center, and if it lies outside,
/// add it to the support set and take the smallest ball again.
fn fast_center(points: &[Vec3]) -> DVec3 {
    let mut support: Vec<[f64; 3]> = cloud::summary(points)
        .extremal
        .iter()
        .map(|p| p.to_array())
        .collect();
    let mut ball = smallest_ball(&support);
    for _ in 0..FAST_PASSES {
        let c = DVec3::from_array(ball.center);
        let (far, distance2) = points
            .iter()
            .map(|&p| (exact(p), exact(p).distance_squared(c)))
            .fold(
                (c, 0.0),
                |best, next| if next.1 > best.1 { next } else { best },
            );
        if distance2 <= ball.radius2 {
            break;
        }
        support.push(far.to_array());
        ball = smallest_ball(&support);
    }
    DVec3::from_array(ball.center)
}
