//! The transform methods, the rounding modes and the error bound each pair guarantees.
//!
//! All bounds are stated against the exact image of the input box, computed in exact
//! arithmetic from the given `f32` values, and scaled by the per-axis magnitude
//!
//! ```text
//! S_i = |t_i| + sum_j |m_ij| * max(|min_j|, |max_j|)
//! ```
//!
//! A bound relative to the result alone would be unsound: the faces of a rotated box
//! can cancel to zero while the rounding errors that produced them did not.
//!
//! | method       | dims | Nearest error       | Outward pad            |
//! |--------------|------|---------------------|------------------------|
//! | `Naive`      | N    | `γ(N+1)·S + TINY_ERROR` | `(N+3)·u·S + TINY_PAD` |
//! | `SignSelect` | N    | `γ(N+1)·S + TINY_ERROR` | `(N+3)·u·S + TINY_PAD` |
//! | `AbsMatrix`  | N    | `γ(N+3)·S + TINY_ERROR` | `(N+5)·u·S + TINY_PAD` |
//!
//! `γ(n) = n·u / (1 − n·u)` with `u = 2^-24` (Higham's constant). Outward faces contain the
//! exact faces and lie within twice the pad of them.

/// Unit roundoff of `f32` round-to-nearest: `u = 2^-24`.
pub const UNIT_ROUNDOFF: f32 = 1.0 / 16_777_216.0;

/// Absolute error allowance for gradual underflow in a Nearest result: `2^-148`.
///
/// Each product whose result is subnormal may be off by half the smallest subnormal,
/// `2^-150`; no kernel forms more than four such products per face.
pub const TINY_ERROR: f32 = f32::from_bits(2); // 2 * 2^-149

/// Absolute part of the Outward pad, `2^-146`: covers [`TINY_ERROR`] with room for the
/// underflow of the pad's own computation.
pub const TINY_PAD: f32 = f32::from_bits(8); // 8 * 2^-149

/// Higham's `γ(n) = n·u / (1 − n·u)`: the relative error bound of `n` chained roundings.
#[inline]
#[must_use]
pub fn gamma(n: u32) -> f64 {
    let nu = f64::from(n) * f64::from(UNIT_ROUNDOFF);
    nu / (1.0 - nu)
}

/// How a box is carried through the transform.
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
    pub const fn nearest_gamma(self, dims: u32) -> u32 {
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
    pub const fn outward_pad(self, dims: u32) -> u32 {
        self.nearest_gamma(dims) + 2
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
