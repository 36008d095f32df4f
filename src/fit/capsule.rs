//! Capsules (swept spheres) and their fits.

use super::ball::smallest_ball;
use super::bound::{Bounded, largest, segment_distance};
use super::cloud::{self, exact};
use super::eigen::principal_axes;
use super::obb::{Obb3, tight_frames};
use super::search::{compass_search, nelder_mead};
use super::{Fit, FitError};
use crate::aabb::Aabb3;
use crate::num::sqrt;
use alloc::vec::Vec;
use core::f64::consts::PI;
use glam::{DVec3, Vec3, Vec3A};

/// A capsule: the points `x` within `radius` of the segment `[a, b]`, exactly, on the `f32`
/// fields (`dist(x, [a, b]) = min over real t ∈ [0, 1] of |x − a − t(b − a)|`).
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::AnyBitPattern))]
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Capsule {
    /// One end of the axis segment.
    pub a: Vec3A,
    /// The other end.
    pub b: Vec3A,
    /// The radius.
    pub radius: f32,
}

/// A capsule in `f64`, before rounding.
#[derive(Clone, Copy, Debug)]
struct Capsule64 {
    a: DVec3,
    b: DVec3,
    radius: f64,
}

impl Capsule64 {
    /// `π r² |b − a| + 4/3 π r³`.
    fn volume(&self) -> f64 {
        PI * self.radius * self.radius * (self.a.distance(self.b) + 4.0 / 3.0 * self.radius)
    }
}

/// Golden-section steps of the tight fit's search over the radius.
const RADIUS_STEPS: usize = 24;

impl Capsule {
    /// The capsule fitted to `points` with the given effort: [`Fit::Pca`] on the major
    /// principal axis through the mean; [`Fit::Fast`] on the best of the fast box's axes and
    /// the major principal axis, centered by the minimum enclosing circle of the points
    /// projected across it;
    /// [`Fit::Tight`] on a direction optimised from the tight box's axes, with the radius
    /// optimised too, then a local search over direction, axis position and radius at once.
    /// All with the shortest segment (minimal caps), and the radius then certified from
    /// every point.
    ///
    /// # Errors
    /// [`FitError::Empty`] for no points, [`FitError::NonFinite`] for a non-finite point,
    /// [`FitError::Overflow`] when the radius would overflow `f32`.
    pub fn fit(points: &[Vec3], fit: Fit) -> Result<Self, FitError> {
        let bounds = cloud::validate(points)?;
        let capsule = match fit {
            Fit::Pca => pca_capsule(points),
            Fit::Fast => fast_capsule(points),
            Fit::Tight => tight_capsule(points),
        };
        Self::around(points, &bounds, capsule.a, capsule.b)
    }

    /// The capsule on the segment `[a, b]`, its ends moved into the points' bounding box
    /// `bounds` and rounded to `f32` (so finite), its radius the largest certified distance
    /// of a point to it ([`segment_distance`]).
    fn around(points: &[Vec3], bounds: &Aabb3, a: DVec3, b: DVec3) -> Result<Self, FitError> {
        let (a, b) = (
            cloud::round_within(a, bounds),
            cloud::round_within(b, bounds),
        );
        let (ad, bd) = (a.as_dvec3(), b.as_dvec3());
        let radius = largest(
            points
                .iter()
                .map(|&p| segment_distance(exact(p), ad, bd).upper()),
        )
        .ok_or(FitError::Overflow)?;
        Ok(Self { a, b, radius })
    }

    /// True when `p` may lie in the capsule: never false for a point of it, true only
    /// within `2^-47·(dist + Σ_j |p_j − a_j| + Σ_j |b_j − a_j|)` of it. NaN gives false.
    #[inline]
    #[must_use]
    pub fn contains_point(&self, p: Vec3A) -> bool {
        let distance = segment_distance(p.as_dvec3(), self.a.as_dvec3(), self.b.as_dvec3());
        distance.lower_f64() <= f64::from(self.radius)
    }

    /// The volume `π r² |b − a| + 4/3 π r³`.
    #[inline]
    #[must_use]
    pub fn volume(&self) -> f32 {
        let (a, b) = (self.a.as_dvec3(), self.b.as_dvec3());
        let radius = f64::from(self.radius);
        Capsule64 { a, b, radius }.volume() as f32
    }

    /// An axis-aligned box, rounded outward, that contains the capsule:
    /// `min(a, b) − r` and `max(a, b) + r`, one rounding each (the lemma's form).
    #[must_use]
    pub fn aabb(&self) -> Aabb3 {
        let (a, b) = (self.a.as_dvec3(), self.b.as_dvec3());
        let r = f64::from(self.radius);
        let face = |p: DVec3, sign: f64, i: usize| Bounded {
            value: p[i] + sign * r,
            scale: p[i].abs() + r.abs(),
        };
        Aabb3::new(
            Vec3A::from_array([0, 1, 2].map(|i| face(a.min(b), -1.0, i).lower())),
            Vec3A::from_array([0, 1, 2].map(|i| face(a.max(b), 1.0, i).upper())),
        )
    }
}

/// The shortest segment on the line `origin + t·dir` (unit `dir`) whose capsule of radius
/// `radius` holds `points` (minimal caps).
///
/// A point at height `s = (p − o)·d` and distance `ρ` from the line is in the capsule
/// exactly when the segment meets `[s − w, s + w]`, `w = √(r² − ρ²)`: so the segment must
/// reach up to `max(s − w)` and down to `min(s + w)`; when those cross, one point suffices
/// (the capsule is a sphere). A point farther than `r` from the line counts with `w = 0`
/// (the certified radius then grows to reach it).
fn capped(points: &[DVec3], origin: DVec3, dir: DVec3, radius: f64) -> Capsule64 {
    let (mut top, mut bottom) = (f64::NEG_INFINITY, f64::INFINITY);
    for &p in points {
        let v = p - origin;
        let s = v.dot(dir);
        let w = sqrt((radius * radius - (v - dir * s).length_squared()).max(0.0));
        top = top.max(s - w);
        bottom = bottom.min(s + w);
    }
    let (t0, t1) = if top <= bottom {
        let mid = 0.5 * (top + bottom);
        (mid, mid)
    } else {
        (bottom, top)
    };
    Capsule64 {
        a: origin + dir * t0,
        b: origin + dir * t1,
        radius,
    }
}

/// The line along `dir` through the center of the minimum enclosing circle of the points
/// projected across it, and that circle's radius.
fn circle_axis(points: &[DVec3], dir: DVec3) -> (DVec3, f64) {
    let (e1, e2) = dir.any_orthonormal_pair();
    let mut flat: Vec<[f64; 2]> = points.iter().map(|p| [p.dot(e1), p.dot(e2)]).collect();
    cloud::shuffle(&mut flat);
    let circle = smallest_ball(&flat);
    (
        e1 * circle.center[0] + e2 * circle.center[1],
        circle.radius(),
    )
}

/// The capsule along `dir` centered by the minimum enclosing circle, with minimal caps.
fn circle_capsule(points: &[DVec3], dir: DVec3) -> Capsule64 {
    let (origin, radius) = circle_axis(points, dir);
    capped(points, origin, dir, radius)
}

/// The smallest of some capsules, skipping degenerate ones (a NaN axis from a degenerate
/// frame: its volume is NaN, which must never win).
fn smallest(capsules: impl IntoIterator<Item = Capsule64>) -> Capsule64 {
    capsules
        .into_iter()
        .filter(|s| s.volume().is_finite())
        .min_by(|a, b| a.volume().total_cmp(&b.volume()))
        .unwrap_or(Capsule64 {
            a: DVec3::ZERO,
            b: DVec3::ZERO,
            radius: 0.0,
        })
}

/// The PCA baseline: the major principal axis of the distinct points through their mean,
/// the radius the largest distance from that line.
fn pca_capsule(points: &[Vec3]) -> Capsule64 {
    let distinct: Vec<DVec3> = cloud::unique(points).into_iter().map(exact).collect();
    let unique_f32: Vec<Vec3> = distinct.iter().map(|p| p.as_vec3()).collect();
    let moments = cloud::summary(&unique_f32);
    let (mean, dir) = (moments.mean, principal_axes(moments.covariance).x_axis);
    let radius = distinct
        .iter()
        .map(|&p| (p - mean).reject_from_normalized(dir).length())
        .fold(0.0, f64::max);
    capped(&distinct, mean, dir, radius)
}

/// The fast fit: the best of the fast box's three axes and the major principal axis (of
/// the points as given), each centered by a minimum enclosing circle. The box's axes alone
/// can all miss an elongated set's long direction when its box is turned about it.
fn fast_capsule(points: &[Vec3]) -> Capsule64 {
    let exact_points: Vec<DVec3> = points.iter().map(|&p| exact(p)).collect();
    let frame =
        Obb3::fit(points, Fit::Fast).map_or(glam::DMat3::IDENTITY, |b| b.rotation.as_dmat3());
    let major = principal_axes(cloud::summary(points).covariance).x_axis;
    smallest(
        [frame.x_axis, frame.y_axis, frame.z_axis, major]
            .into_iter()
            .filter_map(|axis| Some(circle_capsule(&exact_points, axis.try_normalize()?))),
    )
}

/// The best radius for the axis along `dir`: a golden-section search of the volume over
/// `r` from the enclosing circle's radius (the thinnest capsule) to the radius at which
/// the segment shrinks to a point (a sphere on the axis).
fn best_radius(points: &[DVec3], dir: DVec3) -> Capsule64 {
    let (origin, thinnest) = circle_axis(points, dir);
    let sphere_like = capped(points, origin, dir, thinnest);
    let middle = 0.5 * (sphere_like.a + sphere_like.b);
    let widest = points
        .iter()
        .map(|p| p.distance(middle))
        .fold(thinnest, f64::max);
    let volume = |r: f64| capped(points, origin, dir, r).volume();
    let ratio = 0.5 * (sqrt(5.0) - 1.0);
    let (mut lo, mut hi) = (thinnest, widest);
    for _ in 0..RADIUS_STEPS {
        let (x1, x2) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
        if volume(x1) <= volume(x2) {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    smallest([thinnest, 0.5 * (lo + hi), widest].map(|r| capped(points, origin, dir, r)))
}

/// The tight fit: from each axis of the tight box's candidate frames, a compass search
/// over directions `normalize(d + θ0 e1 + θ1 e2)`, each direction with its best radius;
/// the best of those and of the fast and PCA capsules is then [`refined`].
fn tight_capsule(points: &[Vec3]) -> Capsule64 {
    let distinct: Vec<DVec3> = cloud::unique(points).into_iter().map(exact).collect();
    let mut tight = tight_frames(&distinct);
    cloud::shuffle(&mut tight.support);
    let support = &tight.support;
    let searched = tight.frames.iter().take(2).flat_map(|frame| {
        (0..3).map(move |k| {
            let seed = frame.col(k);
            let (e1, e2) = seed.any_orthonormal_pair();
            let dir = |t: [f64; 2]| (seed + e1 * t[0] + e2 * t[1]).normalize();
            let (t, _) = compass_search(|t| best_radius(support, dir(t)).volume(), 0.05, 1e-5, 200);
            best_radius(support, dir(t))
        })
    });
    let baseline = [fast_capsule(points), pca_capsule(points)];
    let mut best = smallest(searched.chain(baseline));
    // The simplex settles on ridges of the volume: restarted from where it stopped, with
    // a smaller first step, it goes on down.
    for round in 0..REFINEMENTS {
        let next = refined(support, best, 0.1 / (1 + round) as f64);
        if next.volume() >= best.volume() {
            break;
        }
        best = next;
    }
    best
}

/// Restarts of the tight capsule's five-way local search, at most.
const REFINEMENTS: usize = 8;

/// A local search from `start` over all five degrees of freedom at once: the axis's
/// direction, where it crosses the plane across it, and the radius (at least the largest
/// distance of a point from the axis). The search over directions fixes the axis through
/// the enclosing circle's center; a capsule with a wider radius and shorter caps may sit
/// off it.
fn refined(points: &[DVec3], start: Capsule64, step: f64) -> Capsule64 {
    let Some(seed) = (start.b - start.a).try_normalize() else {
        return start;
    };
    let (e1, e2) = seed.any_orthonormal_pair();
    let (middle, radius) = (0.5 * (start.a + start.b), start.radius);
    let capsule = |t: [f64; 5]| {
        let dir = (seed + e1 * t[0] + e2 * t[1]).normalize();
        let origin = middle + (e1 * t[2] + e2 * t[3]) * radius;
        let reach = points
            .iter()
            .map(|&p| (p - origin).reject_from_normalized(dir).length_squared())
            .fold(0.0, f64::max);
        capped(
            points,
            origin,
            dir,
            (radius * (1.0 + t[4])).max(sqrt(reach)),
        )
    };
    let (t, _) = nelder_mead(|t| capsule(t).volume(), step, 1e-9, 1000);
    capsule(t)
}
