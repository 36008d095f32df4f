//! The input point cloud: validation, duplicates and a deterministic shuffle; its bounds,
//! extremal points and moments are sweeps in lanes ([`super::sweep`]).

use super::FitError;
use crate::aabb::Aabb3;
use alloc::vec::Vec;
use glam::{DVec3, Vec3, Vec3A};

pub(crate) use super::sweep::{Summary, summary};

/// Checks the input and returns its bounding box: an error for no point or a non-finite one.
pub(crate) fn validate(points: &[Vec3]) -> Result<Aabb3, FitError> {
    if points.is_empty() {
        return Err(FitError::Empty);
    }
    super::sweep::bounds(points).map_err(|index| FitError::NonFinite {
        index,
        point: points[index].to_array(),
    })
}

/// Checks the input as [`validate`] does, and returns its [`Summary`] (bounding box
/// included) from the same sweep.
pub(crate) fn summarize(points: &[Vec3]) -> Result<Summary, FitError> {
    if points.is_empty() {
        return Err(FitError::Empty);
    }
    let summary = summary(points);
    if summary.finite {
        return Ok(summary);
    }
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(FitError::NonFinite {
            index,
            point: points[index].to_array(),
        });
    }
    Ok(summary)
}

/// The exact `f64` value of an `f32` point (the conversion is exact).
#[inline]
pub(crate) fn exact(p: Vec3) -> DVec3 {
    p.as_dvec3()
}

/// `p` moved into the bounding box `bounds` of the points, then rounded to nearest: always
/// finite (NaN goes to `bounds.min`). A fit's center or axis end may be any point, since its
/// extents are derived afterwards from every input point; one in the box never overflows.
#[inline]
pub(crate) fn round_within(p: DVec3, bounds: &Aabb3) -> Vec3A {
    p.clamp(bounds.min.as_dvec3(), bounds.max.as_dvec3())
        .as_vec3a()
}

/// The distinct points, in a deterministic order (`-0.0` and `0.0` are one coordinate).
///
/// Each point is keyed by its coordinates' bits in one `u128` (`x` highest), whose order
/// is that of the `[x, y, z]` bits in turn and compares in two words, not three branches.
pub(crate) fn unique(points: &[Vec3]) -> Vec<Vec3> {
    let key = |p: &Vec3| {
        let [x, y, z] = (*p + Vec3::ZERO).to_array().map(f32::to_bits);
        (u128::from(x) << 64) | (u128::from(y) << 32) | u128::from(z)
    };
    let mut keys: Vec<u128> = points.iter().map(key).collect();
    keys.sort_unstable();
    keys.dedup();
    keys.into_iter()
        .map(|k| Vec3::from_array([k >> 64, k >> 32, k].map(|bits| f32::from_bits(bits as u32))))
        .collect()
}

/// A fixed-seed permutation (xorshift64* driving Fisher–Yates): the randomised ball
/// algorithms need an order unrelated to the geometry, and the fits stay deterministic.
pub(crate) fn shuffle<T>(items: &mut [T]) {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    for i in (1..items.len()).rev() {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        let r = state.wrapping_mul(0x2545_f491_4f6c_dd1d);
        items.swap(i, (r % (i as u64 + 1)) as usize);
    }
}
