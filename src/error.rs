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
