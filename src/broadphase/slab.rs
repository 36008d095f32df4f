//! The slab test of a cast, conservative by proof: a box moving along a direction (a ray is
//! a box of one point) against eight boxes at once.
//!
//! **What is decided.** A cast is a box `O = [lo, hi]` (for a ray, `lo = hi` = the origin)
//! moving along `d` for `t` in `[0, max]`; it meets a box `P` at `t` when `O + t·d` and `P`
//! share a point (closed boxes). On axis `a` that is `P.min ≤ hi + t·d` and
//! `lo + t·d ≤ P.max`: for `d_a > 0`, `t ∈ [t0, t1]` with `t0 = (P.min − hi)/d_a` and
//! `t1 = (P.max − lo)/d_a`; for `d_a < 0`, `t ∈ [t1, t0]`; for `d_a = 0`, every `t` when
//! `P.min ≤ hi` and `lo ≤ P.max`, none otherwise. The cast meets `P` when the intersection of
//! the three intervals with `[0, max]` is not empty, and its **entry** is the least `t` of
//! that intersection. These are exact statements about the given `f32` values.
//!
//! **The computed interval contains the exact one.** Each bound is computed in `f64`, from
//! `f32` inputs (exact in `f64`): `x = fl(P.min − hi)`, `r = fl(1/d_a)`, `t̃ = fl(x·r)`.
//! Every operand is finite, and no result can overflow or be subnormal: a nonzero difference
//! of two `f32` values is at least `2^-149` and at most `2^129` in magnitude, `|r|` lies in
//! `[2^-128, 2^149]`, so `|t̃|` lies in `[2^-277, 2^278]`, far inside `f64`'s normal range
//! (so FTZ and DAZ change nothing here; DAZ reads a subnormal `f32` input as zero, and the
//! statements then hold for the values read). Each of the three roundings has a relative
//! error of at most `u = 2^-53`, so `t̃ = t·(1 + δ)` with `|δ| ≤ (1 + u)^3 − 1 < 3.0001·u`,
//! and `t̃ = 0` exactly when `t = 0`. The bounds are widened by `K = 2^-50 = 8u` of
//! themselves: `lower(t̃) = fl(t̃ − |t̃|·K)` (the product is exact: a power of two, no
//! underflow). For `t̃ > 0`, `lower(t̃) ≤ t̃·(1 − K)·(1 + u) < t̃·(1 − 7u)`, while
//! `t = t̃/(1 + δ) > t̃·(1 − 3.0001u)`: so `lower(t̃) < t`. For `t̃ < 0` (all negative),
//! `lower(t̃) ≤ t̃·(1 + K)·(1 − u) = t̃·(1 + 7u − 8u²) < t̃/(1 − 3.0001u) ≤ t`.
//! `upper` is the mirror image, `upper(t̃) ≥ t`. The parallel case compares the inputs
//! exactly. So each computed near bound is at most the exact one and each far bound at
//! least the exact one, and the computed interval `[max(0, lower near), min(max, upper
//! far)]` contains the exact one: **a box the exact cast meets within `max` is never
//! missed, and the computed entry (rounded down to `f32`) is never beyond the exact
//! entry.** (The computed interval may also accept a box the exact cast misses by a
//! relative `2^-49` of the distance: a candidate, as every broadphase hit is.)
//!
//! An empty child slot (`+∞` below `−∞`) gives infinite or NaN bounds and is masked out by
//! its reference, never by the arithmetic.

use glam::Vec3A;

/// The relative widening of every computed bound: `2^-50`.
const K: f64 = 1.0 / (1u64 << 50) as f64;

/// A cast prepared once for its slab tests (see the [module docs](self)): per axis, which
/// faces give the near and the far bound and the coordinates of the moving box they are
/// measured from, or the parallel test.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Sweep {
    lo: [f64; 3],
    hi: [f64; 3],
    /// `1/d_a`, or 0 where `d_a = 0` (the axis is then tested by `parallel`).
    inv: [f64; 3],
    parallel: [bool; 3],
}

/// `max(a, b)` for non-NaN `a` (and `b` where it matters): one instruction, where
/// `f64::max`'s NaN rule costs three.
#[inline(always)]
fn larger(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

/// `min(a, b)`, as [`larger`].
#[inline(always)]
fn smaller(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

impl Sweep {
    /// The box `[lo, hi]` moving along `d` (finite, `lo ≤ hi`: the caller checks).
    pub(crate) fn new(lo: Vec3A, hi: Vec3A, d: Vec3A) -> Self {
        let parallel = [0, 1, 2].map(|a| d[a] == 0.0);
        Self {
            lo: [0, 1, 2].map(|a| f64::from(lo[a])),
            hi: [0, 1, 2].map(|a| f64::from(hi[a])),
            inv: [0, 1, 2].map(|a| {
                if parallel[a] {
                    0.0
                } else {
                    1.0 / f64::from(d[a])
                }
            }),
            parallel,
        }
    }

    /// For `W` boxes (their faces as columns: a node's eight), the entry bound of each (never beyond
    /// the exact entry), and bit `k` set when box `k` may be met within `[0, limit]`
    /// (always, when the exact cast meets it). A bound of an empty slot may be NaN: the
    /// caller masks such slots.
    #[inline(always)]
    pub(crate) fn test<const W: usize>(
        &self,
        min: &[[f32; W]; 3],
        max: &[[f32; W]; 3],
        limit: f64,
    ) -> ([f64; W], u32) {
        let mut enter = [0.0f64; W];
        let mut exit = [limit; W];
        let mut meets = [true; W];
        for a in 0..3 {
            let (lo, hi, inv) = (self.lo[a], self.hi[a], self.inv[a]);
            if self.parallel[a] {
                for k in 0..W {
                    meets[k] &= f64::from(min[a][k]) <= hi && lo <= f64::from(max[a][k]);
                }
                continue;
            }
            // Moving up the axis, a box is entered at its min face (from `hi`) and left at
            // its max face (from `lo`); moving down, the other way round.
            let (near_face, near_from, far_face, far_from) = if inv > 0.0 {
                (&min[a], hi, &max[a], lo)
            } else {
                (&max[a], lo, &min[a], hi)
            };
            for k in 0..W {
                let near = (f64::from(near_face[k]) - near_from) * inv;
                let far = (f64::from(far_face[k]) - far_from) * inv;
                enter[k] = larger(near - near.abs() * K, enter[k]);
                exit[k] = smaller(far + far.abs() * K, exit[k]);
            }
        }
        let mut bits = 0;
        for k in 0..W {
            bits |= u32::from(meets[k] && enter[k] <= exit[k]) << k;
        }
        (enter, bits)
    }
}
