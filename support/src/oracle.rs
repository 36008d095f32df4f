//! The exact oracle: error-free arithmetic on the `f32` inputs.
//!
//! Every finite `f32` is an integer multiple of `2^-149`, so every product of up to four
//! is a multiple of `2^-596`; scaled by `2^600`, the exact faces of a transformed box are
//! integers, summed here without rounding in arbitrary precision. That covers the affine
//! maps (a matrix entry times a coordinate) and the quaternion classes (`R(q)` is a sum
//! of products of two components, times a scale, times a coordinate). Containment is
//! decided by exact comparison; errors are measured as exact differences, converted to
//! `f64` only for reporting against a bound.
#![allow(dead_code, clippy::needless_range_loop)]

use bvkit::{Aabb2, Aabb3, Method, Rigid2, Rigid3, Rounding, Similarity3, Trs3};
use bvkit::{TINY_ERROR, TINY_PAD};
use glam::{Affine2, Affine3A, Mat2, Mat3A, Quat, Vec2, Vec3A};
use num_bigint::BigInt;
use num_traits::{Signed, ToPrimitive, Zero};

/// The exponent of the fixed-point scale: exact values are `integer · 2^-SCALE`.
pub const SCALE: i32 = 600;

/// An exact extended real: `±inf` or `integer · 2^-600`.
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

    /// The exact value of a finite `f64` (its exponent must be at least `-SCALE`).
    pub fn of_f64(x: f64) -> Exact {
        assert!(x.is_finite());
        if x == 0.0 {
            return Exact::ZERO;
        }
        let bits = x.to_bits();
        let biased = ((bits >> 52) & 0x7ff) as i32;
        let fraction = (bits & ((1 << 52) - 1)) as i64;
        let (s, e) = if biased == 0 {
            (fraction, -1074)
        } else {
            (fraction | 1 << 52, biased - 1075)
        };
        assert!(e + SCALE >= 0, "{x} is below the oracle's scale");
        let s = if x < 0.0 { -s } else { s };
        Exact::Finite(BigInt::from(s) << (e + SCALE) as usize)
    }

    /// The exact product of a finite `f64` and an `f32`, with `0 · ±inf = 0`.
    pub fn product_f64(m: f64, x: f32) -> Exact {
        Exact::of_f64(m).mul_f32(x)
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

    /// The exact product `self · x` (`0 · ±inf = 0`), for finite `self` that is a product
    /// of at most three `f32` values (so that the result is a multiple of `2^-600`).
    pub fn mul_f32(&self, x: f32) -> Exact {
        assert!(!x.is_nan(), "the oracle takes no NaN");
        let Exact::Finite(a) = self else {
            panic!("mul_f32 takes a finite value")
        };
        if a.is_zero() || x == 0.0 {
            return Exact::ZERO;
        }
        if x.is_infinite() {
            return if (a.is_negative()) != (x < 0.0) {
                Exact::NegInf
            } else {
                Exact::PosInf
            };
        }
        let (sx, ex) = decompose(x);
        let p = a * BigInt::from(sx);
        if ex >= 0 {
            Exact::Finite(p << ex as usize)
        } else {
            let shift = (-ex) as usize;
            assert!((&p >> shift) << shift == p, "product below 2^-600");
            Exact::Finite(p >> shift)
        }
    }

    /// `2 · self` (finite).
    pub fn double(&self) -> Exact {
        self.add(self)
    }

    /// `−self`.
    pub fn neg(&self) -> Exact {
        match self {
            Exact::Finite(a) => Exact::Finite(-a),
            Exact::PosInf => Exact::NegInf,
            Exact::NegInf => Exact::PosInf,
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

/// A box `[lo, hi]` and an affine map `x ↦ M x + t` with `cols[j][i] = m_ij` (a
/// translation is the identity matrix).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Problem<const N: usize> {
    pub cols: [[f32; N]; N],
    pub t: [f32; N],
    pub lo: [f32; N],
    pub hi: [f32; N],
}

/// A box `[lo, hi]` and a quaternion map `x ↦ R(q)·(s ∘ x) + t`, `R(q)` the standard
/// formula evaluated exactly on the stored components (`q = [x, y, z, w]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuatProblem {
    pub q: [f32; 4],
    pub s: [f32; 3],
    pub t: [f32; 3],
    pub lo: [f32; 3],
    pub hi: [f32; 3],
}

/// What the contract demands of a result.
#[derive(Clone, Debug, PartialEq)]
pub enum Expected<const N: usize> {
    /// NaN input or a non-finite map: an invalid (NaN) box.
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

/// A problem the oracle can judge: a box and a map whose exact image it computes.
pub trait Exactly<const N: usize>: core::fmt::Debug {
    fn lo(&self) -> [f32; N];
    fn hi(&self) -> [f32; N];
    fn t(&self) -> [f32; N];
    /// Every parameter of the map (matrix or quaternion, scale, translation).
    fn map_values(&self) -> Vec<f32>;
    /// The exact matrix, `cols[j][i] = m_ij` (finite map parameters).
    fn exact_cols(&self) -> [[Exact; N]; N];
    /// The matrix in `f64`, and a bound on the error of every entry of each column.
    fn approx_cols(&self) -> ([[f64; N]; N], [f64; N]);
    /// The weight `μ_ij` of `max(|lo_j|, |hi_j|)` in the documented magnitude `S_i`.
    fn weights(&self) -> [[f64; N]; N];
    /// The factor `τ` of the absolute terms (`τ·TINY_ERROR`, `τ·TINY_PAD`).
    fn tau(&self) -> f64;
    /// The same map with another box.
    fn with_box(&self, lo: [f32; N], hi: [f32; N]) -> Self
    where
        Self: Sized;

    /// The same problem with the box and the translation scaled by `f` (a power of two).
    fn scaled_box(&self, f: f32) -> Self
    where
        Self: Sized;

    /// The values a kernel multiplies that are not map parameters (the scaled box of a
    /// quaternion class, the computed entries of `R(q)`); none beyond the inputs here.
    fn derived_values(&self) -> Vec<f32> {
        Vec::new()
    }

    /// Every nonzero finite value a kernel multiplies is at least `2^-32`: bvkit's
    /// normal-range inputs, on which no kernel forms a subnormal number.
    fn normal_range(&self) -> bool {
        let least = 1.0 / 4_294_967_296.0; // 2^-32
        self.map_values()
            .into_iter()
            .chain(self.lo())
            .chain(self.hi())
            .chain(self.derived_values())
            .all(|x| x == 0.0 || !x.is_finite() || x.abs() >= least)
    }

    /// No input is subnormal.
    fn all_normal(&self) -> bool {
        self.map_values()
            .into_iter()
            .chain(self.lo())
            .chain(self.hi())
            .all(|x| x == 0.0 || !x.is_finite() || x.is_normal())
    }

    /// True when the box holds no real point.
    fn is_empty(&self) -> bool {
        let (lo, hi) = (self.lo(), self.hi());
        (0..N).any(|j| lo[j] > hi[j] || lo[j] == f32::INFINITY || hi[j] == f32::NEG_INFINITY)
    }

    /// True when every input is finite.
    fn all_finite(&self) -> bool {
        self.map_values()
            .into_iter()
            .chain(self.lo())
            .chain(self.hi())
            .all(f32::is_finite)
    }

    /// What the contract demands, decided exactly.
    fn expected(&self) -> Expected<N> {
        let (lo_in, hi_in, t) = (self.lo(), self.hi(), self.t());
        let map = self.map_values();
        let any_nan = map.iter().chain(&lo_in).chain(&hi_in).any(|x| x.is_nan());
        if any_nan || !map.iter().all(|x| x.is_finite()) {
            return Expected::Invalid;
        }
        if self.is_empty() {
            return Expected::Empty;
        }
        let cols = self.exact_cols();
        let weights = self.weights();
        let mut lo = core::array::from_fn(|_| Exact::ZERO);
        let mut hi = core::array::from_fn(|_| Exact::ZERO);
        let mut magnitude = [0.0; N];
        for i in 0..N {
            let (mut l, mut h) = (Exact::of(t[i]), Exact::of(t[i]));
            let mut s = f64::from(t[i]).abs();
            for j in 0..N {
                let a = cols[j][i].mul_f32(lo_in[j]);
                let b = cols[j][i].mul_f32(hi_in[j]);
                let (low, high) = if a <= b { (a, b) } else { (b, a) };
                l = l.add(&low);
                h = h.add(&high);
                let reach = f64::from(lo_in[j]).abs().max(f64::from(hi_in[j]).abs());
                if weights[i][j] != 0.0 {
                    s += weights[i][j] * reach;
                }
            }
            lo[i] = l;
            hi[i] = h;
            magnitude[i] = s;
        }
        Expected::Faces { lo, hi, magnitude }
    }
}

impl<const N: usize> Exactly<N> for Problem<N> {
    fn lo(&self) -> [f32; N] {
        self.lo
    }
    fn hi(&self) -> [f32; N] {
        self.hi
    }
    fn t(&self) -> [f32; N] {
        self.t
    }
    fn map_values(&self) -> Vec<f32> {
        self.cols.iter().flatten().chain(&self.t).copied().collect()
    }
    fn exact_cols(&self) -> [[Exact; N]; N] {
        self.cols.map(|c| c.map(Exact::of))
    }
    fn approx_cols(&self) -> ([[f64; N]; N], [f64; N]) {
        (self.cols.map(|c| c.map(f64::from)), [0.0; N])
    }
    fn weights(&self) -> [[f64; N]; N] {
        core::array::from_fn(|i| core::array::from_fn(|j| f64::from(self.cols[j][i]).abs()))
    }
    fn tau(&self) -> f64 {
        1.0
    }
    fn with_box(&self, lo: [f32; N], hi: [f32; N]) -> Self {
        Problem { lo, hi, ..*self }
    }
    fn scaled_box(&self, f: f32) -> Self {
        let by = |v: [f32; N]| v.map(|x| x * f);
        Problem {
            lo: by(self.lo),
            hi: by(self.hi),
            t: by(self.t),
            ..*self
        }
    }
}

impl QuatProblem {
    /// `ρ = 1 + 2‖q‖²` in `f64`.
    pub fn rho(&self) -> f64 {
        1.0 + 2.0
            * self
                .q
                .iter()
                .map(|&c| f64::from(c) * f64::from(c))
                .sum::<f64>()
    }

    /// The exact `R(q)`, rows then columns: `r[i][j] = R_ij`.
    fn exact_rotation(&self) -> [[Exact; 3]; 3] {
        let [x, y, z, w] = self.q;
        let p = Exact::product;
        let one = Exact::of(1.0);
        let diag = |a: f32, b: f32| one.add(&p(a, a).add(&p(b, b)).double().neg());
        let off = |a: Exact, b: Exact| a.add(&b).double();
        [
            [
                diag(y, z),
                off(p(x, y), p(w, z).neg()),
                off(p(x, z), p(w, y)),
            ],
            [
                off(p(x, y), p(w, z)),
                diag(x, z),
                off(p(y, z), p(w, x).neg()),
            ],
            [
                off(p(x, z), p(w, y).neg()),
                off(p(y, z), p(w, x)),
                diag(x, y),
            ],
        ]
    }
}

impl Exactly<3> for QuatProblem {
    fn lo(&self) -> [f32; 3] {
        self.lo
    }
    fn hi(&self) -> [f32; 3] {
        self.hi
    }
    fn t(&self) -> [f32; 3] {
        self.t
    }
    fn map_values(&self) -> Vec<f32> {
        self.q
            .iter()
            .chain(&self.s)
            .chain(&self.t)
            .copied()
            .collect()
    }
    fn exact_cols(&self) -> [[Exact; 3]; 3] {
        let r = self.exact_rotation();
        core::array::from_fn(|j| core::array::from_fn(|i| r[i][j].mul_f32(self.s[j])))
    }
    fn approx_cols(&self) -> ([[f64; 3]; 3], [f64; 3]) {
        // Each entry of R is a sum of at most three exact f64 terms (2 roundings), times
        // s_j (one more): within 4·2^-53·ρ·|s_j|; twice that is kept.
        let r = self.exact_rotation();
        let rho = self.rho();
        (
            core::array::from_fn(|j| {
                core::array::from_fn(|i| r[i][j].to_f64() * f64::from(self.s[j]))
            }),
            core::array::from_fn(|j| 8.0 * f64::EPSILON / 2.0 * rho * f64::from(self.s[j]).abs()),
        )
    }
    fn weights(&self) -> [[f64; 3]; 3] {
        let rho = self.rho();
        [core::array::from_fn(|j| rho * f64::from(self.s[j]).abs()); 3]
    }
    fn tau(&self) -> f64 {
        2.0 * self.rho()
    }
    fn with_box(&self, lo: [f32; 3], hi: [f32; 3]) -> Self {
        QuatProblem { lo, hi, ..*self }
    }
    fn scaled_box(&self, f: f32) -> Self {
        let by = |v: [f32; 3]| v.map(|x| x * f);
        QuatProblem {
            lo: by(self.lo),
            hi: by(self.hi),
            t: by(self.t),
            ..*self
        }
    }
    fn derived_values(&self) -> Vec<f32> {
        // R(q) as bvkit computes it (glam's formula, unnormalised), and the scaled box.
        let r = glam::Mat3::from_quat(Quat::from_array(self.q));
        let scaled = (0..3).flat_map(|j| [self.s[j] * self.lo[j], self.s[j] * self.hi[j]]);
        r.to_cols_array().into_iter().chain(scaled).collect()
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
                gamma_n: method.nearest_order(dims),
                tiny: f64::from(TINY_ERROR),
            },
            Rounding::Outward => Bound::Outward {
                k: method.outward_factor(dims),
                tiny: f64::from(TINY_PAD),
            },
        }
    }

    /// The bound of order `gamma_n` (Nearest) or pad `gamma_n + 2` (Outward).
    pub fn of_order(gamma_n: u32, rounding: Rounding) -> Bound {
        match rounding {
            Rounding::Nearest => Bound::Nearest {
                gamma_n,
                tiny: f64::from(TINY_ERROR),
            },
            Rounding::Outward => Bound::Outward {
                k: gamma_n + 2,
                tiny: f64::from(TINY_PAD),
            },
        }
    }

    fn allowance(&self, magnitude: f64, tau: f64) -> f64 {
        match *self {
            Bound::Nearest { gamma_n, tiny } => gamma(gamma_n) * magnitude + tau * tiny,
            Bound::Outward { k, tiny } => 2.0 * (f64::from(k) * U * magnitude + tau * tiny),
        }
    }
}

/// The unit of [`Measured::worst_error_us`]: `u·S`, `S` floored at `TINY_PAD / u`.
fn error_unit(magnitude: f64) -> f64 {
    U * magnitude + f64::from(TINY_PAD)
}

/// What one checked result measured.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measured {
    /// The largest face error in units of `u·S`, `S` floored at `TINY_PAD / u`: the pads'
    /// documented absolute part sets the faces of boxes at the origin, and a floor below
    /// it (one subnormal ulp, once) measured that term as `2^49·u·S` there.
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
    tau: f64,
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
    let allowance = bound.allowance(magnitude, tau);
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
    Ok((error / error_unit(magnitude), contains))
}

/// Checks a result against the contract and measures it.
pub fn check<const N: usize>(
    p: &impl Exactly<N>,
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
/// For finite inputs each matrix entry is known in `f64` within its column's error bound
/// (exactly for an affine map), each product with a coordinate rounds at most once, and
/// the sum of `N + 1` terms errs by at most `N·2^-53` times the sum of their magnitudes;
/// the bound used here is `(N + 3)·2^-52` of that, plus the entries' errors, plus the
/// smallest normal `f64`, which also covers the rounding of the comparisons themselves.
/// Only verdicts that hold for every value within the bound are returned, so the oracle
/// stays exact; it is only faster where nothing is close.
fn check_certified_f64<const N: usize>(
    p: &impl Exactly<N>,
    min: [f32; N],
    max: [f32; N],
    bound: Bound,
) -> Option<Measured> {
    if !p.all_finite() || p.is_empty() {
        return None;
    }
    if !min.iter().chain(&max).all(|x| x.is_finite()) {
        return None;
    }
    let (lo_in, hi_in, t_in) = (p.lo(), p.hi(), p.t());
    let (cols, col_error) = p.approx_cols();
    let weights = p.weights();
    let tau = p.tau();
    let mut measured = Measured {
        contains: true,
        ..Measured::default()
    };
    let (mut exact_volume, mut volume) = (1.0f64, 1.0f64);
    for i in 0..N {
        let t = f64::from(t_in[i]);
        let (mut lo, mut hi, mut terms, mut magnitude) = (t, t, t.abs(), t.abs());
        let mut entry_error = 0.0;
        for j in 0..N {
            let m = cols[j][i];
            let (x_lo, x_hi) = (f64::from(lo_in[j]), f64::from(hi_in[j]));
            let (a, b) = (m * x_lo, m * x_hi);
            lo += a.min(b);
            hi += a.max(b);
            let reach = x_lo.abs().max(x_hi.abs());
            terms += a.abs().max(b.abs());
            magnitude += weights[i][j] * reach;
            entry_error += col_error[j] * reach;
        }
        let error = (N as f64 + 3.0) * f64::EPSILON * terms * 1.001
            + entry_error * 1.001
            + f64::MIN_POSITIVE;
        let allowance = bound.allowance(magnitude * (1.0 - 1e-9), tau);
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
            let unit = error_unit(magnitude);
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
    p: &impl Exactly<N>,
    min: [f32; N],
    max: [f32; N],
    bound: Bound,
) -> Result<Measured, String> {
    let tau = p.tau();
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
                    let (error, contains) =
                        check_face(face, exact, magnitude[i], tau, bound, lower).map_err(|e| {
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

impl QuatProblem {
    /// The box.
    pub fn aabb(&self) -> Aabb3 {
        Aabb3::new(Vec3A::from_array(self.lo), Vec3A::from_array(self.hi))
    }
    fn quat(&self) -> Quat {
        Quat::from_array(self.q)
    }
    /// As a rigid pose (the scale must be 1).
    pub fn rigid3(&self) -> Rigid3 {
        assert_eq!(self.s, [1.0; 3], "a rigid problem has unit scale");
        Rigid3::new(self.quat(), Vec3A::from_array(self.t))
    }
    /// As a similarity (the scale must be uniform).
    pub fn similarity3(&self) -> Similarity3 {
        assert!(
            self.s[0].to_bits() == self.s[1].to_bits()
                && self.s[1].to_bits() == self.s[2].to_bits()
                || self.s.iter().all(|x| x.is_nan()),
            "a similarity problem has a uniform scale"
        );
        Similarity3::new(self.s[0], self.quat(), Vec3A::from_array(self.t))
    }
    /// As a scale-rotation-translation.
    pub fn trs3(&self) -> Trs3 {
        Trs3::new(
            Vec3A::from_array(self.s),
            self.quat(),
            Vec3A::from_array(self.t),
        )
    }
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
