//! Errors of the fallible entry points.

use core::fmt;

/// Why a transform could not be applied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TransformError {
    /// The `Mat4` is not affine: its last row is not `(0, 0, 0, 1)`.
    NotAffine {
        /// The last row that was found.
        last_row: [f32; 4],
    },
    /// The matrix holds a NaN or an infinite entry.
    NonFiniteMatrix,
    /// A corner of the box maps to `w <= 0` (or NaN): it lies on or behind the eye plane,
    /// where the projective image of the box is not bounded.
    NonPositiveW {
        /// The index of the corner (bit `j` picks `max` on axis `j`).
        corner: usize,
        /// Its `w`.
        w: f32,
    },
    /// A projective transform of a box with an infinite face: it has no corner to project.
    UnboundedProjective,
}

impl fmt::Display for TransformError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotAffine { last_row } => write!(
                f,
                "matrix is not affine: last row is {last_row:?}, expected [0, 0, 0, 1]"
            ),
            Self::NonFiniteMatrix => write!(f, "matrix has a NaN or infinite entry"),
            Self::NonPositiveW { corner, w } => write!(
                f,
                "box corner {corner} maps to w = {w}: on or behind the eye plane"
            ),
            Self::UnboundedProjective => {
                write!(f, "a box with an infinite face has no projective image")
            }
        }
    }
}

impl core::error::Error for TransformError {}

/// Why a batch was refused. Nothing was written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BatchError {
    /// Two inputs, or an input and the output, differ in length.
    LengthMismatch {
        /// Which sequence has the wrong length.
        what: &'static str,
        /// The length of the local boxes.
        expected: usize,
        /// The length found.
        found: usize,
    },
    /// The backend asked for cannot run on this CPU.
    UnsupportedBackend(crate::simd::Backend),
    /// A broadphase margin is negative, infinite or NaN.
    InvalidMargin(crate::fat::Margin),
    /// A broadphase active set is malformed; the reason is given.
    InvalidActive(&'static str),
    /// More objects than `u32` indices can name.
    TooManyObjects(usize),
}

impl BatchError {
    /// `Ok` when `found == expected`, else [`BatchError::LengthMismatch`] for `what`: the one
    /// place a length check is written.
    #[inline]
    pub(crate) fn check_len(what: &'static str, expected: usize, found: usize) -> Result<(), Self> {
        if found == expected {
            Ok(())
        } else {
            Err(Self::LengthMismatch {
                what,
                expected,
                found,
            })
        }
    }
}

impl fmt::Display for BatchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::LengthMismatch {
                what,
                expected,
                found,
            } => write!(
                f,
                "{what} has length {found}, expected {expected} (the local boxes' length)"
            ),
            Self::UnsupportedBackend(b) => write!(f, "backend {b:?} is not supported by this CPU"),
            Self::InvalidMargin(m) => write!(
                f,
                "margin {m:?} is invalid: both fields must be finite and non-negative"
            ),
            Self::InvalidActive(why) => write!(f, "invalid active set: {why}"),
            Self::TooManyObjects(n) => {
                write!(f, "{n} objects is more than u32 indices can name")
            }
        }
    }
}

impl core::error::Error for BatchError {}
