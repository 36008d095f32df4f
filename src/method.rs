//! `Method`, `Rounding` and the constants of the bounds (documented on [`Method`]).

use crate::num::pow2;

/// Unit roundoff of `f32` round-to-nearest: `u = 2^-24`.
pub const UNIT_ROUNDOFF: f32 = 1.0 / 16_777_216.0;

/// Absolute error allowance for gradual underflow in a Nearest result: `2^-148`.
///
/// Each product whose result is subnormal may be off by half the smallest subnormal,
/// `2^-150`; no kernel forms more than four such products per face. On normal-range inputs
/// (see [`Rounding::Outward`]) no kernel forms a subnormal value, so this term is never used
/// there; it is a bound, never an operand.
pub const TINY_ERROR: f32 = f32::from_bits(2); // 2 * 2^-149

/// A bound on the absolute part of every Outward pad: `2^-100`, about `8·10^-31`.
///
/// Every pad is `k·u·(S + 2^-80)` (`k <= 16`): its absolute part `k·u·2^-80` is a normal
/// number, so no pad feeds a subnormal operand to the arithmetic, and DAZ cannot zero it.
pub const TINY_PAD: f32 = pow2(-100) as f32;

/// The reach every pad adds to its magnitude `S`: `2^-80`, so that every pad `k·u·(S +
/// 2^-80)` is at least `4·2^-24·2^-80 = 2^-102`, a normal number whose ulp (at least
/// `2^-125`) makes the padded face of a normal-range input zero or normal (see
/// [`crate::kernel`]).
pub(crate) const REACH_FLOOR: f32 = pow2(-80) as f32;

/// Higham's `γ(n) = n·u / (1 − n·u)`: the relative error bound of `n` chained roundings.
#[inline]
#[must_use]
pub fn gamma(n: u32) -> f64 {
    let nu = f64::from(n) * f64::from(UNIT_ROUNDOFF);
    nu / (1.0 - nu)
}

/// How a box is carried through the transform.
///
/// # Methods, roundings and their bounds
///
/// All bounds are stated against the exact image of the input box, computed in exact
/// arithmetic from the given `f32` values, and scaled by the per-axis magnitude
///
/// ```text
/// S_i = |t_i| + sum_j |m_ij| * max(|min_j|, |max_j|)
/// ```
///
/// A bound relative to the result alone would be unsound: the faces of a rotated box
/// can cancel to zero while the rounding errors that produced them did not.
///
/// | method       | dims | Nearest error       | Outward pad            |
/// |--------------|------|---------------------|------------------------|
/// | `Naive`      | N    | `γ(N+1)·S + TINY_ERROR` | `(N+3)·u·S + TINY_PAD` |
/// | `SignSelect` | N    | `γ(N+1)·S + TINY_ERROR` | `(N+3)·u·S + TINY_PAD` |
/// | `AbsMatrix`  | N    | `γ(N+3)·S + TINY_ERROR` | `(N+5)·u·S + TINY_PAD` |
///
/// `γ(n) = n·u / (1 − n·u)` with `u = 2^-24` (Higham's constant). Outward faces contain the
/// exact faces and lie within twice the pad of them.
///
/// ## Subnormal numbers, FTZ and DAZ
///
/// Call an input **normal-range** when every nonzero finite value a kernel multiplies (box
/// coordinates, translations, matrix entries; the computed entries of `R(q)` and the
/// scaled box for the quaternion classes) is at least `2^-32` (about `2.3·10^-10`) in
/// magnitude. Real scenes are: a rotation entry of exactly zero is fine, one of `10^-12`
/// is not. On normal-range input no kernel reads or produces a subnormal number, on any
/// path (the proof is beside the pads in `src/kernel.rs`), so none pays the microcode assist that Intel
/// cores take for one, and the results are bit for bit the same whatever the MXCSR modes
/// flush-to-zero (FTZ) and denormals-are-zero (DAZ) say: every guarantee holds with
/// either or both set. The pads' absolute parts are normal constants for this reason.
///
/// Outside that range (subnormal inputs, or products below `2^-126`) the default mode
/// keeps every guarantee, at the CPU's subnormal speed: subnormal inputs take that slower
/// path. Under FTZ the CPU flushes a result below `2^-126` to zero, an error under
/// `2^-126` per operation; the pad's absolute part (at least `2^-102`; a translation's
/// step from zero is `2^-104`) covers those errors for matrices whose entries are at most
/// `2^16` in magnitude, so Outward still contains the exact image of inputs whose values
/// are all normal (tested on boxes in the lowest normal binades).
/// Under DAZ the CPU reads a subnormal input as zero: the result then bounds the box and
/// map with those values replaced by zero, which can miss the exact image of the given
/// values by about `2^-126·(1 + Σ_j |m_ij|)` per axis.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// Transform every corner (8 in 3D, 4 in 2D) and take the component-wise min and max.
    Naive,
    /// Arvo's center/extent form: world center `M c + t`, world half-extent `|M| e`.
    AbsMatrix,
    /// For every matrix entry pick the face that minimises (maximises) `m_ij * x_j` by the
    /// sign of `m_ij`; for [`Rigid2`](crate::Rigid2) this is Eberly's four-case sign branch.
    SignSelect,
}

impl Method {
    /// Every method, in a fixed order (the order of tables and plots).
    pub const ALL: [Method; 3] = [Method::Naive, Method::AbsMatrix, Method::SignSelect];

    /// The number `n` of the Nearest bound `γ(n)·S + TINY_ERROR` in `dims` dimensions.
    ///
    /// Naive and SignSelect sum `dims` products onto the translation: `dims` products and
    /// `dims` additions, each rounding once, so `γ(dims + 1)`. AbsMatrix first forms
    /// `2c = min + max` and `2e = max − min` (one rounding each), then the same dot
    /// products, then `(2c' ∓ 2e')/2` (one more rounding): `γ(dims + 3)`.
    #[inline]
    #[must_use]
    pub const fn nearest_order(self, dims: u32) -> u32 {
        match self {
            Method::Naive | Method::SignSelect => dims + 1,
            Method::AbsMatrix => dims + 3,
        }
    }

    /// The factor `k` of the Outward pad `k·u·S + TINY_PAD` in `dims` dimensions.
    ///
    /// It is the Nearest order plus two: one `u·S` for the rounding of the padded face
    /// itself, one that absorbs the rounding of the computed `S` and of the pad.
    #[inline]
    #[must_use]
    pub const fn outward_factor(self, dims: u32) -> u32 {
        self.nearest_order(dims) + 2
    }

    /// A short lower-case name, for tables.
    #[inline]
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Method::Naive => "naive",
            Method::AbsMatrix => "abs-matrix",
            Method::SignSelect => "sign-select",
        }
    }
}

/// Which guarantee the result carries.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Rounding {
    /// Plain round-to-nearest arithmetic: faces within the method's documented error bound
    /// of the exact faces, on either side.
    Nearest,
    /// The result provably contains the exact transformed box, padded by the method's
    /// documented pad.
    Outward,
}

impl Rounding {
    /// Both roundings, in a fixed order.
    pub const ALL: [Rounding; 2] = [Rounding::Nearest, Rounding::Outward];

    /// A short lower-case name, for tables.
    #[inline]
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Rounding::Nearest => "nearest",
            Rounding::Outward => "outward",
        }
    }
}
