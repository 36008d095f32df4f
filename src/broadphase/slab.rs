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
//! relative `2^-49` of the distance, or by a few `f32` steps in the `f32` form below: a
//! candidate, as every broadphase hit is.)
//!
//! **The `f32` form.** Most casts take the same test in `f32` ([`Sweep::test_f32`]), whose
//! bounds are widened by four `f32` steps where the `f64` ones are widened by `2^-50`. It
//! applies where nothing can overflow, underflow harmfully or be flushed: every nonzero
//! `|d_a|` in `[2^-20, 2^100]` and every coordinate of the moving box and of the tree's boxes
//! at most `2^126` in magnitude (the tree keeps whether any box went beyond). Then
//! `x = fl(P.min − hi)` cannot overflow (`|x| ≤ 2^127`) and is exact when subnormal (or, under
//! FTZ, flushed from below `2^-126`, which moves `t` by less than `2^-106`); `r = fl(1/d_a)`
//! is normal; `t̃ = fl(x·r)`, when its magnitude is at least `τ = 2^-100`, is normal and
//! `t̃ = t·(1 + δ)` with `|δ| ≤ (1 + 2^-24)^3 − 1 < 3.0001·2^-24`. An `f32` step at `t̃` is at
//! least `2^-24·|t̃|` (and four steps down from a power of two still `4·2^-24·|t̃|`), so four
//! steps toward `−∞` give a lower bound of `t` and four toward `+∞` an upper bound. Where
//! `|t̃| < τ`, the product may have underflowed (or been flushed), but then `|t| < 2^-99`
//! and the bounds are `−τ` and `τ`. Where the product overflows to `±∞`, `|t|` is at least
//! `MAX·(1 − 1.5·2^-24)`, and four steps from `±∞` land three steps inside `±MAX`
//! (`MAX·(1 − 3·2^-24)`), no further out than `t`. DAZ reads a subnormal input as zero, and
//! the statements hold for the values read. Every other cast takes the `f64` test.
//!
//! An empty child slot (`+∞` below `−∞`) gives infinite or NaN bounds and is masked out by
//! its reference, never by the arithmetic.

use crate::num::pow2;
use glam::Vec3A;

/// The relative widening of every computed bound: `2^-50`.
const K: f64 = 1.0 / (1u64 << 50) as f64;

/// The largest coordinate magnitude the `f32` test takes: `2^126` (powers of two are exact
/// in `f32`).
pub(crate) const F32_REACH: f32 = pow2(126) as f32;
/// `τ`: below it a computed `f32` bound may have underflowed.
const TINY: f32 = pow2(-100) as f32;
/// The nonzero direction components the `f32` test takes: `[2^-20, 2^100]`.
const DIRECTION: core::ops::RangeInclusive<f32> = pow2(-20) as f32..=pow2(100) as f32;

/// A cast prepared once for its slab tests (see the [module docs](self)): its box, its
/// direction's reciprocals, its parallel axes, and whether the `f32` test takes it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Sweep {
    lo: [f64; 3],
    hi: [f64; 3],
    /// `1/d_a`, or 0 where `d_a = 0` (the axis is then tested by `parallel`).
    inv: [f64; 3],
    parallel: [bool; 3],
    /// The same in `f32` (`fl(1/d_a)`), and whether the `f32` test takes the cast.
    lo32: [f32; 3],
    hi32: [f32; 3],
    inv32: [f32; 3],
    fits_f32: bool,
}

/// Four `f32` steps toward `−∞` (`−τ` near zero; `−∞` stays). Both steps are computed and
/// one is picked, so that the lanes stay in vectors.
#[inline(always)]
fn below(t: f32) -> f32 {
    let bits = t.to_bits();
    let down = f32::from_bits(bits.wrapping_sub(4));
    let out = f32::from_bits(bits.wrapping_add(4).min(0xff80_0000));
    let stepped = if t > 0.0 { down } else { out };
    if t.abs() < TINY { -TINY } else { stepped }
}

/// Four `f32` steps toward `+∞` (`τ` near zero; `+∞` stays).
#[inline(always)]
fn above(t: f32) -> f32 {
    let bits = t.to_bits();
    let out = f32::from_bits(bits.wrapping_add(4).min(0x7f80_0000));
    let back = f32::from_bits(bits.wrapping_sub(4));
    let stepped = if t > 0.0 { out } else { back };
    if t.abs() < TINY { TINY } else { stepped }
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
        let reach = F32_REACH;
        let fits_f32 = (0..3).all(|a| {
            let m = d[a].abs();
            (parallel[a] || DIRECTION.contains(&m)) && lo[a].abs() <= reach && hi[a].abs() <= reach
        });
        Self {
            lo32: lo.to_array(),
            hi32: hi.to_array(),
            inv32: [0, 1, 2].map(|a| if parallel[a] { 0.0 } else { 1.0 / d[a] }),
            fits_f32,
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
    /// True when the `f32` test takes the cast against boxes whose coordinates are all at
    /// most [`F32_REACH`] in magnitude (`tame`).
    #[inline(always)]
    pub(crate) fn fits_f32(&self, tame: bool) -> bool {
        self.fits_f32 && tame
    }

    /// [`Sweep::test`] in `f32`, for a cast that [`Sweep::fits_f32`] (module docs): the same
    /// guarantees, each bound four `f32` steps wide.
    #[inline(always)]
    pub(crate) fn test_f32<const W: usize>(
        &self,
        min: &[[f32; W]; 3],
        max: &[[f32; W]; 3],
        limit: f32,
    ) -> ([f32; W], u32) {
        let mut enter = [0.0f32; W];
        let mut exit = [limit; W];
        let mut meets = [true; W];
        for a in 0..3 {
            let (lo, hi, inv) = (self.lo32[a], self.hi32[a], self.inv32[a]);
            if self.parallel[a] {
                for k in 0..W {
                    meets[k] &= min[a][k] <= hi && lo <= max[a][k];
                }
                continue;
            }
            let (near_face, near_from, far_face, far_from) = if inv > 0.0 {
                (&min[a], hi, &max[a], lo)
            } else {
                (&max[a], lo, &min[a], hi)
            };
            for k in 0..W {
                let near = below((near_face[k] - near_from) * inv);
                let far = above((far_face[k] - far_from) * inv);
                enter[k] = if near > enter[k] { near } else { enter[k] };
                exit[k] = if far < exit[k] { far } else { exit[k] };
            }
        }
        let mut bits = 0;
        for k in 0..W {
            bits |= u32::from(meets[k] && enter[k] <= exit[k]) << k;
        }
        (enter, bits)
    }
}
