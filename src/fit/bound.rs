//! Certified rounding: `f64` evaluations with a proven error bound, rounded outward to `f32`.
//!
//! Every fit computes in `f64` on the exact values of the `f32` inputs and then certifies
//! its `f32` result against the same inputs. The certificates all rest on one lemma.
//!
//! **Lemma.** Let `x` be a real quantity and `value` its `f64` evaluation by at most 8
//! roundings of `+ − × √` on exact `f32` data, whose error analysis gives
//! `|x − value| ≤ γ(8)·(|value| + scale)` for a known `scale >= 0`, with `u = 2^-53` and
//! `γ(n) = n·u / (1 − n·u) < 2^-49.9`. Then [`Bounded::upper`] `>= x` and
//! [`Bounded::lower`] `<= x`.
//!
//! *Proof.* The pad `SLACK·(|value| + scale)` with `SLACK = 2^-48` is computed with two
//! roundings, so it is at least `2^-48·(1 − 2u)·(|value| + scale) > γ(8)·(|value| + scale) + u·|value + pad|`:
//! it covers the evaluation error and the rounding of the final sum. `round_up` (`round_down`)
//! then returns an `f32` on the far side of that sum. No `f64` step can underflow or overflow:
//! products of `f32` values lie in `[2^-298, 2^256]`, well inside `f64`'s normal range. ∎
//!
//! Callers name the roundings of their expression next to each use.

use crate::num::{pow2, round_down, round_up, two_sum};
use glam::DVec3;

/// The relative pad `2^-48`, four times the worst error `γ(8) < 2^-49.9` of the evaluations.
pub(crate) const SLACK: f64 = pow2(-48);

/// An `f64` evaluation `value` of a real `x` with `|x − value| ≤ γ(8)·(|value| + scale)`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Bounded {
    /// The computed value.
    pub value: f64,
    /// The magnitude the rounding errors scale with (sums of absolute terms).
    pub scale: f64,
}

impl Bounded {
    /// The pad `SLACK·(|value| + scale)` that covers the evaluation error.
    #[inline]
    fn pad(self) -> f64 {
        SLACK * (self.value.abs() + self.scale)
    }

    /// An `f32` at or above `x` (the lemma).
    #[inline]
    #[must_use]
    pub fn upper(self) -> f32 {
        round_up(self.value + self.pad())
    }

    /// An `f32` at or below `x` (the lemma).
    #[inline]
    #[must_use]
    pub fn lower(self) -> f32 {
        round_down(self.value - self.pad())
    }

    /// An `f64` at or below `x`: the pad is subtracted with one rounding, covered by the lemma.
    #[inline]
    #[must_use]
    pub fn lower_f64(self) -> f64 {
        self.value - self.pad()
    }
}

/// The distance from `p` to the segment `[a, b]` (a point when `a = b`), bounded both ways.
///
/// Any `t ∈ [0, 1]` names the point `a + t(b − a)` of the exact segment, so the exact
/// distance is at most `|(p − a) − t(b − a)|`. Each coordinate of that vector rounds four
/// times (two differences, the product, the difference), within `γ(3)·(|p_j − a_j| +
/// t·|b_j − a_j|)`; the norm (three squares, two sums, a root) adds `γ(3)` relative: the
/// lemma's form with `scale = Σ_j |p_j − a_j| + t·Σ_j |b_j − a_j|`, so `upper()` is certified.
/// The other way, `t` is the clamped projection, off the exact one by `γ(4)·|p − a|/|b − a|`;
/// by Pythagoras the distance from `a + t(b − a)` exceeds the exact distance by at most
/// `γ(4)·|p − a|`, within the same scale: `lower_f64()` never exceeds the exact distance.
#[inline]
pub(crate) fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> Bounded {
    let ab = b - a;
    let ap = p - a;
    let length2 = ab.length_squared();
    let t = if length2 > 0.0 {
        (ap.dot(ab) / length2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    Bounded {
        value: (ap - ab * t).length(),
        scale: ap.abs().element_sum() + t * ab.abs().element_sum(),
    }
}

/// A bound on `|Σ terms|` that is 0 when no partial sum rounds and the sum is 0.
///
/// TwoSum gives each partial sum `s_i = fl(s_{i-1} + t_i)` with its exact error `e_i`, so
/// `Σ terms = s_N + Σ_i e_i` exactly and `|Σ terms| <= |s_N| + Σ_i |e_i|`. That bound is
/// returned as evaluated in `f64`: `N − 1` roundings of non-negative terms, within
/// `γ(N − 1)` of it relative (callers count them in the lemma's form).
#[inline]
#[must_use]
pub(crate) fn sum_magnitude<const N: usize>(terms: [f64; N]) -> f64 {
    let (mut sum, mut errors) = (0.0, 0.0);
    for t in terms {
        let (s, e) = two_sum(sum, t);
        sum = s;
        errors += e.abs();
    }
    sum.abs() + errors
}

/// The largest of `values` (0 for none), or `None` when one is NaN or infinite: the radius
/// of a fitted volume, which must not drop a NaN (as `f32::max` does) nor overflow.
#[inline]
#[must_use]
pub(crate) fn largest(values: impl IntoIterator<Item = f32>) -> Option<f32> {
    values
        .into_iter()
        .try_fold(0.0f32, |r, x| x.is_finite().then(|| r.max(x)))
}
