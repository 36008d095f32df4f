//! The exact oracle: error-free arithmetic on the `f32` inputs.
//!
//! Every finite `f32` is an integer multiple of `2^-149`, so every product of two is a
//! multiple of `2^-298`; scaled by `2^298`, the exact faces of a transformed box are
//! integers, summed here without rounding in arbitrary precision. Containment is decided
//! by exact comparison; errors are measured as exact differences, converted to `f64` only
//! for reporting against a bound.
#![allow(dead_code, clippy::needless_range_loop)]

use bvkit::method::{TINY_ERROR, TINY_PAD};
use bvkit::{Aabb2, Aabb3, Method, Rigid2, Rounding};
use glam::{Affine2, Affine3A, Mat2, Mat3A, Vec2, Vec3A};
use num_bigint::BigInt;
use num_traits::{Signed, ToPrimitive, Zero};

/// The exponent of the fixed-point scale: exact values are `integer · 2^-SCALE`.
const SCALE: i32 = 298;

/// An exact extended real: `±inf` or `integer · 2^-298`.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Exact {
    NegInf,
    Finite(BigInt),
    PosInf,
}

/// `(significand, exponent)` with `x = significand · 2^exponent`, for finite `x`.
fn decompose(x: f32) -> (i64, i32) {
    let bits = x.to_bits();
    let biased = ((bits >> 23) & 0xff) as i32;
    let fraction = i64::from(bits & 0x7f_ffff);
    let (significand, exponent) = if biased == 0 {
        (fraction, -149)
    } else {
        (fraction | 1 << 23, biased - 150)
    };
    (
        if x.is_sign_negative() {
            -significand
        } else {
            significand
        },
        exponent,
    )
}

impl Exact {
    pub const ZERO: Exact = Exact::Finite(BigInt::ZERO);

    /// The exact value of a non-NaN `f32`.
    pub fn of(x: f32) -> Exact {
        assert!(!x.is_nan(), "the oracle takes no NaN");
        if x == f32::INFINITY {
            return Exact::PosInf;
        }
        if x == f32::NEG_INFINITY {
            return Exact::NegInf;
        }
        let (s, e) = decompose(x);
        Exact::Finite(BigInt::from(s) << (e + SCALE) as usize)
    }

    /// The exact product `m · x`, with `0 · ±inf = 0` (a zero entry contributes nothing).
    pub fn product(m: f32, x: f32) -> Exact {
        assert!(!(m.is_nan() || x.is_nan()), "the oracle takes no NaN");
        if m == 0.0 || x == 0.0 {
            return Exact::ZERO;
        }
        if m.is_infinite() || x.is_infinite() {
            let negative = (m < 0.0) != (x < 0.0);
            return if negative {
                Exact::NegInf
            } else {
                Exact::PosInf
            };
        }
        let (sm, em) = decompose(m);
        let (sx, ex) = decompose(x);
        Exact::Finite((BigInt::from(sm) * BigInt::from(sx)) << (em + ex + SCALE) as usize)
    }

    /// The exact sum; `+inf + -inf` has no value and is an oracle misuse.
    pub fn add(&self, other: &Exact) -> Exact {
        match (self, other) {
            (Exact::Finite(a), Exact::Finite(b)) => Exact::Finite(a + b),
            (Exact::NegInf, Exact::PosInf) | (Exact::PosInf, Exact::NegInf) => {
                panic!("inf - inf in the oracle")
            }
            (Exact::Finite(_), inf) | (inf, _) => inf.clone(),
        }
    }

    /// The absolute value.
    pub fn abs(&self) -> Exact {
        match self {
            Exact::Finite(a) => Exact::Finite(a.abs()),
            _ => Exact::PosInf,
        }
    }

    /// The nearest `f64` (for reporting; `±inf` stays infinite).
    pub fn to_f64(&self) -> f64 {
        match self {
            Exact::NegInf => f64::NEG_INFINITY,
            Exact::PosInf => f64::INFINITY,
            Exact::Finite(a) if a.is_zero() => 0.0,
            Exact::Finite(a) => {
                // Shift into f64's range before scaling so that no step overflows.
                let bits = a.bits() as i32;
                let shift = (bits - 60).max(0);
                let top = (a >> shift as usize).to_f64().expect("fits");
                top * 2f64.powi(shift - SCALE)
            }
        }
    }

    /// `self − other` as an `f64`, for finite values.
    pub fn minus(&self, other: &Exact) -> f64 {
        match (self, other) {
            (Exact::Finite(a), Exact::Finite(b)) => Exact::Finite(a - b).to_f64(),
            _ => panic!("minus takes finite values"),
        }
    }
}

/// A box `[lo, hi]` and an affine map `x ↦ M x + t` with `cols[j][i] = m_ij`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Problem<const N: usize> {
    pub cols: [[f32; N]; N],
    pub t: [f32; N],
    pub lo: [f32; N],
    pub hi: [f32; N],
}

/// What the contract demands of a result.
#[derive(Clone, Debug, PartialEq)]
pub enum Expected<const N: usize> {
    /// NaN input or a non-finite matrix: an invalid (NaN) box.
    Invalid,
    /// An empty box: exactly `EMPTY`.
    Empty,
    /// The exact faces, and the magnitude `S_i` of each axis.
    Faces {
        lo: [Exact; N],
        hi: [Exact; N],
        magnitude: [f64; N],
    },
}

impl<const N: usize> Problem<N> {
    fn values(&self) -> impl Iterator<Item = f32> + '_ {
        self.cols
            .iter()
            .flatten()
            .chain(&self.t)
            .chain(&self.lo)
            .chain(&self.hi)
            .copied()
    }

    /// True when the box holds no real point.
    pub fn is_empty(&self) -> bool {
        (0..N).any(|j| {
            self.lo[j] > self.hi[j]
                || self.lo[j] == f32::INFINITY
                || self.hi[j] == f32::NEG_INFINITY
        })
    }

    /// What the contract demands, decided exactly.
    pub fn expected(&self) -> Expected<N> {
        let matrix_finite = self
            .cols
            .iter()
            .flatten()
            .chain(&self.t)
            .all(|x| x.is_finite());
        if self.values().any(f32::is_nan) || !matrix_finite {
            return Expected::Invalid;
        }
        if self.is_empty() {
            return Expected::Empty;
        }
        let mut lo = core::array::from_fn(|_| Exact::ZERO);
        let mut hi = core::array::from_fn(|_| Exact::ZERO);
        let mut magnitude = [0.0; N];
        for i in 0..N {
            let (mut l, mut h) = (Exact::of(self.t[i]), Exact::of(self.t[i]));
            let mut s = Exact::of(self.t[i]).abs();
            for j in 0..N {
                let m = self.cols[j][i];
                let a = Exact::product(m, self.lo[j]);
                let b = Exact::product(m, self.hi[j]);
                let reach = a.abs().max(b.abs());
                let (low, high) = if a <= b { (a, b) } else { (b, a) };
                l = l.add(&low);
                h = h.add(&high);
                s = s.add(&reach);
            }
            lo[i] = l;
            hi[i] = h;
            magnitude[i] = s.to_f64();
        }
        Expected::Faces { lo, hi, magnitude }
    }
}

/// `u = 2^-24`.
pub const U: f64 = 1.0 / 16_777_216.0;

/// Higham's `γ(n)`.
pub fn gamma(n: u32) -> f64 {
    let nu = f64::from(n) * U;
    nu / (1.0 - nu)
}

/// The bound a result is held to.
#[derive(Clone, Copy, Debug)]
pub enum Bound {
    /// Nearest: `|face − exact| <= γ(n)·S + tiny`.
    Nearest { gamma_n: u32, tiny: f64 },
    /// Outward: contains the exact face, and `|face − exact| <= 2·(k·u·S + tiny)`.
    Outward { k: u32, tiny: f64 },
}

impl Bound {
    /// The bound bvkit documents for `method` and `rounding` in `dims` dimensions.
    pub fn documented(method: Method, rounding: Rounding, dims: u32) -> Bound {
        match rounding {
            Rounding::Nearest => Bound::Nearest {
                gamma_n: method.nearest_gamma(dims),
                tiny: f64::from(TINY_ERROR),
            },
            Rounding::Outward => Bound::Outward {
                k: method.outward_pad(dims),
                tiny: f64::from(TINY_PAD),
            },
        }
    }

    fn allowance(&self, magnitude: f64) -> f64 {
        match *self {
            Bound::Nearest { gamma_n, tiny } => gamma(gamma_n) * magnitude + tiny,
            Bound::Outward { k, tiny } => 2.0 * (f64::from(k) * U * magnitude + tiny),
        }
    }
}

/// What one checked result measured.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measured {
    /// The largest face error in units of `u·S` (`S` floored at one subnormal ulp).
    pub worst_error_us: f64,
    /// True when the result contains the exact box.
    pub contains: bool,
    /// `volume(result) / volume(exact) − 1`, when the exact volume is positive and finite.
    pub overhead: Option<f64>,
}

/// Checks one face against its exact value; `lower` says which side "outward" is.
fn check_face(
    face: f32,
    exact: &Exact,
    magnitude: f64,
    bound: Bound,
    lower: bool,
) -> Result<(f64, bool), String> {
    if face.is_nan() {
        return Err("NaN face".into());
    }
    let face_exact = Exact::of(face);
    let contains = if lower {
        face_exact <= *exact
    } else {
        face_exact >= *exact
    };
    if matches!(bound, Bound::Outward { .. }) && !contains {
        return Err(format!(
            "Outward face {face:e} does not contain the exact face {:e}",
            exact.to_f64()
        ));
    }
    let allowance = bound.allowance(magnitude);
    match exact {
        Exact::Finite(_) => {}
        inf => {
            return if face_exact == *inf {
                Ok((0.0, contains))
            } else {
                Err(format!(
                    "face {face:e} for the unbounded exact face {inf:?}"
                ))
            };
        }
    }
    if face.abs() >= f32::MAX {
        // At the end of the f32 range (MAX or inf): allowed where the bound itself reaches
        // past the range on that side, so that no closer f32 exists.
        let reach = exact.to_f64() + if face > 0.0 { allowance } else { -allowance };
        if reach.abs() >= f64::from(f32::MAX) && (reach > 0.0) == (face > 0.0) {
            return Ok((0.0, contains));
        }
        if face.is_infinite() {
            return Err(format!(
                "face {face:e} overflows, exact {:e} with allowance {allowance:e}",
                exact.to_f64()
            ));
        }
    }
    let error = face_exact.minus(exact).abs();
    if error > allowance * (1.0 + 1e-12) {
        return Err(format!(
            "face {face:e} misses the exact {:e} by {error:e} > allowance {allowance:e} (S = {magnitude:e})",
            exact.to_f64()
        ));
    }
    let unit = U * magnitude + f64::from(f32::from_bits(1));
    Ok((error / unit, contains))
}

/// Checks a result against the contract and measures it.
pub fn check<const N: usize>(
    p: &Problem<N>,
    min: [f32; N],
    max: [f32; N],
    bound: Bound,
) -> Result<Measured, String> {
    if let Some(measured) = check_certified_f64(p, min, max, bound) {
        return Ok(measured);
    }
    check_exact(p, min, max, bound)
}

/// The same verdict as [`check_exact`] when `f64` arithmetic with a rigorous error bound
/// decides every comparison; `None` (undecided, or a failure to report exactly) otherwise.
///
/// For finite inputs each product of two `f32` is exact in `f64` and the sum of `N + 1`
/// terms errs by at most `N·2^-53` times the sum of their magnitudes; the bound used here
/// is twice that plus the smallest normal `f64`, which also covers the rounding of the
/// comparisons themselves. Only verdicts that hold for every value within the bound are
/// returned, so the oracle stays exact; it is only faster where nothing is close.
fn check_certified_f64<const N: usize>(
    p: &Problem<N>,
    min: [f32; N],
    max: [f32; N],
    bound: Bound,
) -> Option<Measured> {
    let all = p
        .cols
        .iter()
        .flatten()
        .chain(&p.t)
        .chain(&p.lo)
        .chain(&p.hi);
    if !all.clone().all(|x| x.is_finite()) || p.is_empty() {
        return None;
    }
    if !min.iter().chain(&max).all(|x| x.is_finite()) {
        return None;
    }
    let mut measured = Measured {
        contains: true,
        ..Measured::default()
    };
    let (mut exact_volume, mut volume) = (1.0f64, 1.0f64);
    for i in 0..N {
        let t = f64::from(p.t[i]);
        let (mut lo, mut hi, mut magnitude) = (t, t, t.abs());
        for j in 0..N {
            let m = f64::from(p.cols[j][i]);
            let (a, b) = (m * f64::from(p.lo[j]), m * f64::from(p.hi[j]));
            lo += a.min(b);
            hi += a.max(b);
            magnitude += a.abs().max(b.abs());
        }
        let error =
            2.0 * (N as f64 + 1.0) * f64::EPSILON / 2.0 * magnitude * 1.001 + f64::MIN_POSITIVE;
        let allowance = bound.allowance(magnitude * (1.0 - 1e-9));
        for (face, exact, lower) in [(min[i], lo, true), (max[i], hi, false)] {
            let face = f64::from(face);
            let gap = face - exact; // exact − face is within ±error of the true difference
            if matches!(bound, Bound::Outward { .. }) {
                let contained = if lower { gap < -error } else { gap > error };
                if !contained {
                    return None; // undecided, or broken: the exact check reports it
                }
            } else {
                let outside = if lower { gap > error } else { gap < -error };
                let inside = if lower { gap < -error } else { gap > error };
                if !(outside || inside) {
                    return None;
                }
                measured.contains &= inside;
            }
            if gap.abs() + error > allowance {
                return None;
            }
            let unit = U * magnitude + f64::from(f32::from_bits(1));
            measured.worst_error_us = measured.worst_error_us.max(gap.abs() / unit);
        }
        exact_volume *= hi - lo;
        volume *= f64::from(max[i]) - f64::from(min[i]);
    }
    if exact_volume > 0.0 && exact_volume.is_finite() && volume.is_finite() {
        measured.overhead = Some(volume / exact_volume - 1.0);
    }
    Some(measured)
}

/// Checks a result against the contract in exact arithmetic and measures it.
pub fn check_exact<const N: usize>(
    p: &Problem<N>,
    min: [f32; N],
    max: [f32; N],
    bound: Bound,
) -> Result<Measured, String> {
    match p.expected() {
        Expected::Invalid => {
            if min.iter().chain(&max).any(|x| x.is_nan()) {
                Ok(Measured::default())
            } else {
                Err(format!(
                    "NaN/non-finite input gave a valid box {min:?} {max:?}"
                ))
            }
        }
        Expected::Empty => {
            if min == [f32::INFINITY; N] && max == [f32::NEG_INFINITY; N] {
                Ok(Measured {
                    contains: true,
                    ..Measured::default()
                })
            } else {
                Err(format!("empty input gave {min:?} {max:?}, not EMPTY"))
            }
        }
        Expected::Faces { lo, hi, magnitude } => {
            let mut measured = Measured {
                contains: true,
                ..Measured::default()
            };
            let (mut exact_volume, mut volume) = (1.0f64, 1.0f64);
            for i in 0..N {
                for (face, exact, lower) in [(min[i], &lo[i], true), (max[i], &hi[i], false)] {
                    let (error, contains) = check_face(face, exact, magnitude[i], bound, lower)
                        .map_err(|e| {
                            format!("axis {i} {}: {e}", if lower { "min" } else { "max" })
                        })?;
                    measured.worst_error_us = measured.worst_error_us.max(error);
                    measured.contains &= contains;
                }
                exact_volume *= hi[i].to_f64() - lo[i].to_f64();
                volume *= f64::from(max[i]) - f64::from(min[i]);
            }
            if exact_volume > 0.0 && exact_volume.is_finite() && volume.is_finite() {
                measured.overhead = Some(volume / exact_volume - 1.0);
            }
            Ok(measured)
        }
    }
}

impl Exact {
    /// The exact dot product `row · p` of `f32` values (no infinities).
    pub fn dot(row: &[f32], p: &[f32]) -> Exact {
        row.iter()
            .zip(p)
            .fold(Exact::ZERO, |acc, (&m, &x)| acc.add(&Exact::product(m, x)))
    }

    /// Decides `face · w <= n` exactly, that is `face <= n / w` for `w > 0`.
    pub fn face_le_ratio(face: f32, n: &Exact, w: &Exact) -> bool {
        match (Exact::of(face), n, w) {
            (Exact::Finite(f), Exact::Finite(n), Exact::Finite(w)) => {
                assert!(w > &BigInt::ZERO);
                f * w <= n << SCALE as usize
            }
            (Exact::NegInf, _, _) => true,
            (Exact::PosInf, _, _) => false,
            _ => panic!("face_le_ratio takes finite n and w"),
        }
    }

    /// Decides `face >= n / w` exactly for `w > 0`.
    pub fn face_ge_ratio(face: f32, n: &Exact, w: &Exact) -> bool {
        let negated = match n {
            Exact::Finite(n) => Exact::Finite(-n),
            _ => panic!("face_ge_ratio takes finite n"),
        };
        Exact::face_le_ratio(-face, &negated, w)
    }
}

/// A 3D problem as bvkit's inputs.
pub fn affine3(p: &Problem<3>) -> (Aabb3, Affine3A) {
    let [x, y, z] = p.cols.map(Vec3A::from_array);
    let xf = Affine3A {
        matrix3: Mat3A::from_cols(x, y, z),
        translation: Vec3A::from_array(p.t),
    };
    (
        Aabb3::new(Vec3A::from_array(p.lo), Vec3A::from_array(p.hi)),
        xf,
    )
}

/// A 2D problem as bvkit's inputs.
pub fn affine2(p: &Problem<2>) -> (Aabb2, Affine2) {
    let [x, y] = p.cols.map(Vec2::from_array);
    let xf = Affine2::from_mat2_translation(Mat2::from_cols(x, y), Vec2::from_array(p.t));
    (
        Aabb2::new(Vec2::from_array(p.lo), Vec2::from_array(p.hi)),
        xf,
    )
}

/// A 2D problem as a rigid transform `(cos, sin)` taken from its first column; the
/// problem's matrix must be `[[c, -s], [s, c]]` for the oracle to judge it.
pub fn rigid2(p: &Problem<2>) -> (Aabb2, Rigid2) {
    let b = Aabb2::new(Vec2::from_array(p.lo), Vec2::from_array(p.hi));
    (
        b,
        Rigid2::new(p.cols[0][0], p.cols[0][1], Vec2::from_array(p.t)),
    )
}
