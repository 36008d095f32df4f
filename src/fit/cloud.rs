//! The input point cloud: validation, duplicates, moments and a deterministic shuffle.

use super::FitError;
use crate::Aabb3;
use alloc::vec::Vec;
use glam::{DMat3, DVec3, Vec3, Vec3A};

/// Checks the input and returns its bounding box: an error for no point or a non-finite one.
pub(crate) fn validate(points: &[Vec3]) -> Result<Aabb3, FitError> {
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(FitError::NonFinite {
            index,
            point: points[index].to_array(),
        });
    }
    if points.is_empty() {
        return Err(FitError::Empty);
    }
    Ok(Aabb3::from_points(points.iter().map(|&p| p.into())))
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
pub(crate) fn unique(points: &[Vec3]) -> Vec<Vec3> {
    let key = |p: &Vec3| (*p + Vec3::ZERO).to_array().map(f32::to_bits);
    let mut keys: Vec<[u32; 3]> = points.iter().map(key).collect();
    keys.sort_unstable();
    keys.dedup();
    keys.into_iter()
        .map(|k| Vec3::from_array(k.map(f32::from_bits)))
        .collect()
}

/// The mean, summed in `f64`.
pub(crate) fn mean(points: &[Vec3]) -> DVec3 {
    points.iter().map(|&p| exact(p)).sum::<DVec3>() / points.len() as f64
}

/// The covariance `Σ (p − m)(p − m)ᵀ / n` about the mean `m`, in two passes (no cancellation
/// of large squared coordinates).
pub(crate) fn covariance(points: &[Vec3], mean: DVec3) -> DMat3 {
    let mut c = [[0.0f64; 3]; 3];
    for &p in points {
        let d = (exact(p) - mean).to_array();
        for (i, row) in c.iter_mut().enumerate() {
            for (j, cij) in row.iter_mut().enumerate().skip(i) {
                *cij += d[i] * d[j];
            }
        }
    }
    let n = points.len() as f64;
    DMat3::from_cols_array_2d(&[
        [c[0][0], c[0][1], c[0][2]],
        [c[0][1], c[1][1], c[1][2]],
        [c[0][2], c[1][2], c[2][2]],
    ]) * (1.0 / n)
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

/// Sample directions for extremal points: the 3 coordinate axes, the 4 cube diagonals
/// (these 7 are DiTO-14's) and the 6 face diagonals (all 13 are EPOS-26's).
pub(crate) const DIRECTIONS: [Vec3; 13] = [
    Vec3::new(1.0, 0.0, 0.0),
    Vec3::new(0.0, 1.0, 0.0),
    Vec3::new(0.0, 0.0, 1.0),
    Vec3::new(1.0, 1.0, 1.0),
    Vec3::new(1.0, 1.0, -1.0),
    Vec3::new(1.0, -1.0, 1.0),
    Vec3::new(1.0, -1.0, -1.0),
    Vec3::new(1.0, 1.0, 0.0),
    Vec3::new(1.0, -1.0, 0.0),
    Vec3::new(1.0, 0.0, 1.0),
    Vec3::new(1.0, 0.0, -1.0),
    Vec3::new(0.0, 1.0, 1.0),
    Vec3::new(0.0, 1.0, -1.0),
];

/// The points of least and greatest `p·n` for each direction `n`, as pairs
/// `[min_0, max_0, min_1, max_1, ...]` (`f32` dot products: any input point is a valid pick).
pub(crate) fn extremal_points<const N: usize>(
    points: &[Vec3],
    directions: &[Vec3; N],
) -> Vec<DVec3> {
    let mut lo = [(f32::INFINITY, 0usize); N];
    let mut hi = [(f32::NEG_INFINITY, 0usize); N];
    for (i, p) in points.iter().enumerate() {
        for (k, n) in directions.iter().enumerate() {
            let q = p.dot(*n);
            if q < lo[k].0 {
                lo[k] = (q, i);
            }
            if q > hi[k].0 {
                hi[k] = (q, i);
            }
        }
    }
    lo.iter()
        .zip(&hi)
        .flat_map(|(l, h)| [exact(points[l.1]), exact(points[h.1])])
        .collect()
}
