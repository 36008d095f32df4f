//! Points in volumes, decided exactly in fixed point: every finite `f32` is an integer
//! multiple of `2^-149`, so `F(x) = x·2^149` is an integer, and each statement of the docs
//! is a polynomial inequality in the `F` of the fields and coordinates (see `tests/fit.rs`).

use crate::oracle::{self, Exact};
use bvkit::{Capsule, Obb3, Sphere};
use glam::{Mat3A, Vec3A};
use num_bigint::BigInt;
use num_traits::Signed;

/// `x·2^149`, exactly.
pub fn fixed(x: f32) -> BigInt {
    match Exact::of(x) {
        Exact::Finite(v) => v >> (oracle::SCALE - 149) as usize,
        _ => panic!("finite values only"),
    }
}

pub fn fixed3(v: Vec3A) -> [BigInt; 3] {
    v.to_array().map(fixed)
}

pub fn sub(a: &[BigInt; 3], b: &[BigInt; 3]) -> [BigInt; 3] {
    core::array::from_fn(|i| &a[i] - &b[i])
}

pub fn dot(a: &[BigInt; 3], b: &[BigInt; 3]) -> BigInt {
    (0..3).map(|i| &a[i] * &b[i]).sum()
}

pub fn cross(a: &[BigInt; 3], b: &[BigInt; 3]) -> [BigInt; 3] {
    core::array::from_fn(|i| &a[(i + 1) % 3] * &b[(i + 2) % 3] - &a[(i + 2) % 3] * &b[(i + 1) % 3])
}

/// The box's slab statement: `|(p − c)·a_k| <= h_k` for each axis.
pub fn in_box(obb: &Obb3, p: Vec3A) -> bool {
    let d = sub(&fixed3(p), &fixed3(obb.center));
    (0..3).all(|k| {
        let s = dot(&d, &fixed3(obb.rotation.col(k)));
        s.abs() <= fixed(obb.half_extents[k]) << 149usize
    })
}

/// True when `p = c + R·u` with `|u_k| <= h_k` for the box's `f32` fields, exactly (the
/// corner reading; module docs).
pub fn in_box_as_corners(obb: &Obb3, p: Vec3A) -> bool {
    let a = [0, 1, 2].map(|k| fixed3(obb.rotation.col(k)));
    let dual = [0, 1, 2].map(|k| cross(&a[(k + 1) % 3], &a[(k + 2) % 3]));
    let det = dot(&a[0], &dual[0]).abs();
    let d = sub(&fixed3(p), &fixed3(obb.center));
    det != BigInt::ZERO
        && (0..3).all(|k| dot(&d, &dual[k]).abs() << 149usize <= fixed(obb.half_extents[k]) * &det)
}

/// The ball's statement: `|p − c| <= r` (none for a negative `r`).
pub fn in_ball(ball: &Sphere, p: Vec3A) -> bool {
    let d = sub(&fixed3(p), &fixed3(ball.center));
    let r = fixed(ball.radius);
    ball.radius >= 0.0 && dot(&d, &d) <= &r * &r
}

/// The capsule's statement: `dist(p, [a, b]) <= r` (none for a negative `r`), through the exact closest point.
pub fn in_capsule(capsule: &Capsule, p: Vec3A) -> bool {
    let (a, b, p) = (fixed3(capsule.a), fixed3(capsule.b), fixed3(p));
    if capsule.radius < 0.0 {
        return false; // empty
    }
    let r2 = fixed(capsule.radius).pow(2);
    let (v, w) = (sub(&p, &a), sub(&b, &a));
    let (vw, ww) = (dot(&v, &w), dot(&w, &w));
    if vw <= BigInt::ZERO || ww == BigInt::ZERO {
        dot(&v, &v) <= r2
    } else if vw >= ww {
        let u = sub(&p, &b);
        dot(&u, &u) <= r2
    } else {
        dot(&v, &v) * &ww - &vw * &vw <= r2 * ww
    }
}

/// True when `max_k Σ_j |a_k·a_j − δ_kj| > limit` for the columns `a_k` (all finite).
pub fn defect_exceeds(rotation: Mat3A, limit: f32) -> bool {
    let a = [0, 1, 2].map(|k| fixed3(rotation.col(k)));
    let one = BigInt::from(1) << 298usize;
    let limit = fixed(limit) << 149usize;
    (0..3).any(|k| {
        let row: BigInt = (0..3)
            .map(|j| (dot(&a[k], &a[j]) - if k == j { one.clone() } else { BigInt::ZERO }).abs())
            .sum();
        row > limit
    })
}
