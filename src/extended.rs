//! The extended-range path: every box the fast kernels do not answer.
//!
//! It runs in `f64`. For an affine map the product of two `f32` values is exact there and
//! no sum of four of them can overflow or underflow, so the only error is the rounding of
//! three `f64` additions (`3·2^-53` relative to the magnitude of the terms) and the final
//! rounding to `f32`. A quaternion class gives its matrix in `f64` with a bound on each
//! column's error and the exact sign of every entry (see [`ExtendedMap::rotation`]). It
//! decides the documented values:
//!
//! - NaN anywhere in the input: the NaN box (`is_valid() == false`);
//! - a non-finite map parameter (matrix, quaternion, scale or translation): the NaN box
//!   (no finite image exists);
//! - an empty box (no real point: `min > max`, `min = +inf` or `max = -inf`): `EMPTY`;
//! - an unbounded face: the exact unbounded result, a zero matrix entry contributing 0;
//! - a face beyond the `f32` range: `±inf` for Nearest, the outermost finite or infinite
//!   value that still contains the exact face for Outward; never NaN.

use glam::{DMat3, DVec3, Quat};

use crate::method::Rounding;
use crate::num::{pow2, round_down, round_up, two_sum};

/// Relative bound for the `f64` sum of at most four products, each exact or rounded once,
/// with room for the rounding of the pad itself: `8·2^-53`.
const F64_SUM_PAD: f64 = 8.0 * pow2(-53);

/// A map `x ↦ M x + t` in `f64` for the extended path.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ExtendedMap<const N: usize> {
    /// `cols[j][i]` approximates `m_ij`, with its exact sign: zero exactly when `m_ij` is.
    pub cols: [[f64; N]; N],
    /// A bound on `|cols[j][i] − m_ij|` for every `i` (0 when the entries are exact).
    pub col_error: [f64; N],
    /// The translation.
    pub t: [f32; N],
    /// A parameter of the map is NaN or infinite.
    pub invalid: bool,
}

impl<const N: usize> ExtendedMap<N> {
    /// A map whose entries are `f32` values, exact in `f64`.
    pub fn exact(cols: [[f32; N]; N], t: [f32; N]) -> Self {
        let invalid = !cols.iter().flatten().chain(&t).all(|x| x.is_finite());
        Self {
            cols: cols.map(|c| c.map(f64::from)),
            col_error: [0.0; N],
            t,
            invalid,
        }
    }
}

impl ExtendedMap<3> {
    /// `M` as a glam matrix (each entry within `col_error` of its column's).
    #[inline]
    pub fn matrix(&self) -> DMat3 {
        DMat3::from_cols_array_2d(&self.cols)
    }

    /// `t` as a glam vector.
    #[inline]
    pub fn translation(&self) -> DVec3 {
        DVec3::from_array(self.t.map(f64::from))
    }

    /// `M p + t` in `f64`: each coordinate rounds at most 4 times (a product, three sums).
    #[inline]
    pub fn apply(&self, p: DVec3) -> DVec3 {
        self.matrix() * p + self.translation()
    }

    /// `R(q)·diag(s)`, `t`, from the exact formula of [`crate::kernel::rotation`].
    ///
    /// Every product of two `f32` is exact in `f64`, so each off-diagonal entry
    /// `2(xy ± wz)` rounds once and keeps its exact sign (an `f64` sum is zero only when
    /// exact, products of `f32` never underflow there). A diagonal entry `1 − 2(a + b)`,
    /// `a = y²`, `b = z²`: `a + b` is split exactly by TwoSum into `h + l`, so the sign
    /// is that of `1/2 − h`, or of `−l` when `h = 1/2`; its value errs by at most
    /// `2·2^-53·(1 + 2(a + b)) <= 2^-52·ρ`. Times `s_j` (one more rounding) every entry of
    /// column `j` is within `4·2^-53·|s_j|·ρ`; the bound kept is twice that.
    pub fn rotation(q: Quat, s: [f32; 3], t: [f32; 3]) -> Self {
        let [x, y, z, w] = q.to_array().map(f64::from);
        let diagonal = |a: f64, b: f64| {
            let (h, l) = two_sum(a, b);
            let sign = if h == 0.5 { -l } else { 0.5 - h };
            let value = 1.0 - 2.0 * h - 2.0 * l;
            match sign.partial_cmp(&0.0) {
                Some(core::cmp::Ordering::Equal) => 0.0,
                // The rounded value may have lost the sign only when it is within its
                // error of zero: any value of the right sign within that error will do.
                _ if value * sign <= 0.0 => sign.signum() * f64::MIN_POSITIVE,
                _ => value,
            }
        };
        let r = [
            [
                diagonal(y * y, z * z),
                2.0 * (x * y + w * z),
                2.0 * (x * z - w * y),
            ],
            [
                2.0 * (x * y - w * z),
                diagonal(x * x, z * z),
                2.0 * (y * z + w * x),
            ],
            [
                2.0 * (x * z + w * y),
                2.0 * (y * z - w * x),
                diagonal(x * x, y * y),
            ],
        ];
        let rho = 1.0 + 2.0 * (x * x + y * y + z * z + w * w);
        let invalid = !q.is_finite() || !s.iter().chain(&t).all(|v| v.is_finite());
        Self {
            cols: core::array::from_fn(|j| r[j].map(|m| m * f64::from(s[j]))),
            col_error: core::array::from_fn(|j| 8.0 * F64_ULP * f64::from(s[j]).abs() * rho),
            t,
            invalid,
        }
    }
}

/// `2^-53`, the unit roundoff of `f64`.
const F64_ULP: f64 = pow2(-53);

/// The box `[lo, hi]` through `map` in extended range.
#[cold]
#[inline(never)]
pub(crate) fn transform<const N: usize>(
    map: &ExtendedMap<N>,
    lo: [f32; N],
    hi: [f32; N],
    rounding: Rounding,
) -> ([f32; N], [f32; N]) {
    let any_nan = lo.iter().chain(&hi).any(|x| x.is_nan());
    if any_nan || map.invalid {
        return ([f32::NAN; N], [f32::NAN; N]);
    }
    let empty =
        (0..N).any(|j| lo[j] > hi[j] || lo[j] == f32::INFINITY || hi[j] == f32::NEG_INFINITY);
    if empty {
        return ([f32::INFINITY; N], [f32::NEG_INFINITY; N]);
    }
    let mut min = [0.0; N];
    let mut max = [0.0; N];
    for i in 0..N {
        let ti = f64::from(map.t[i]);
        let (mut lo_i, mut hi_i) = (ti, ti);
        // Magnitudes of the terms summed into each face: their f64 rounding error bound.
        let (mut lo_mag, mut hi_mag) = (ti.abs(), ti.abs());
        // The error carried in from inexact matrix entries, per face.
        let (mut lo_err, mut hi_err) = (0.0, 0.0);
        // Whether every f64 operation was exact: then no pad is needed.
        let mut exact = true;
        for j in 0..N {
            let m = map.cols[j][i];
            if m == 0.0 {
                continue; // exactly 0, even against an infinite face
            }
            let (a, b) = (m * f64::from(lo[j]), m * f64::from(hi[j]));
            let ((low, x_low), (high, x_high)) = if a <= b {
                ((a, lo[j]), (b, hi[j]))
            } else {
                ((b, hi[j]), (a, lo[j]))
            };
            let e = map.col_error[j];
            exact &= e == 0.0 && is_exact_sum(lo_i, low) && is_exact_sum(hi_i, high);
            lo_i += low;
            hi_i += high;
            lo_mag += low.abs();
            hi_mag += high.abs();
            if e > 0.0 {
                lo_err += e * f64::from(x_low).abs();
                hi_err += e * f64::from(x_high).abs();
            }
        }
        // A face has real points on every axis, so no lower term is +inf and no upper
        // term is -inf: the sums are never NaN. An infinite face is exact: its pad (inf
        // at most) leaves it infinite on the same side.
        (min[i], max[i]) = match rounding {
            Rounding::Nearest => (lo_i as f32, hi_i as f32),
            Rounding::Outward if exact => (round_down(lo_i), round_up(hi_i)),
            Rounding::Outward => (
                round_down(lo_i - (lo_mag * F64_SUM_PAD + lo_err)),
                round_up(hi_i + (hi_mag * F64_SUM_PAD + hi_err)),
            ),
        };
    }
    (min, max)
}

/// True when `a + b` is exact in `f64` (Knuth's TwoSum error term is zero), or infinite.
#[inline]
fn is_exact_sum(a: f64, b: f64) -> bool {
    let s = a + b;
    if !s.is_finite() {
        return true; // an infinite face is exact: no finite term changes it
    }
    two_sum(a, b).1 == 0.0
}
