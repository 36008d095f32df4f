//! Fitting bounding volumes to points: oriented boxes ([`Obb3`]), spheres ([`Sphere`]) and
//! capsules ([`Capsule`]), from the PCA baseline ([`Fit::Pca`]) to tight fits
//! ([`Fit::Tight`]); and their world AABBs under any transform class ([`BoundingVolume`]),
//! and their images under similarities (`Obb3::transformed`, …).
//!
//! **Containment.** Every fit computes in `f64` on the exact values of the `f32` inputs,
//! rounds its result to `f32`, and then derives the extents (or radius) of that `f32`
//! result from every input point with a proven error bound, rounded outward
//! ([`bound`]'s lemma). Each input point therefore lies in the returned volume, read as an
//! exact statement on its `f32` fields (see [`Obb3`], [`Sphere`], [`Capsule`]). Nothing
//! else (eigenvectors, hull, optimisation) has to be exact: it only chooses the shape.
//!
//! **Input.** Duplicates and degenerate sets (one point, collinear, planar) are normal input;
//! an empty slice or a NaN or infinite coordinate is a [`FitError`]. So is a result that
//! `f32` cannot hold (points spread toward `±f32::MAX`): a fit returns a volume whose fields
//! are all finite and that contains every point, or an error. Nothing panics.

mod ball;
mod bound;
mod capsule;
mod cloud;
mod eigen;
mod extremal;
mod hull;
mod obb;
mod rect;
mod search;
mod sphere;
mod sweep;
mod world;

pub use capsule::Capsule;
pub use obb::Obb3;
pub use sphere::Sphere;
pub use world::BoundingVolume;

use core::fmt;

/// How hard a fit works: the PCA baseline, a fast fit (the default) or a tight one.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Fit {
    /// The classic baseline: principal axes of the distinct points, centered on their mean.
    Pca,
    /// Linear time, never worse than the AABB nor the PCA axes with a midrange center.
    #[default]
    Fast,
    /// Convex hull, exhaustive candidates and local refinement; never worse than `Fast`.
    Tight,
}

/// Why points could not be fitted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FitError {
    /// No points were given.
    Empty,
    /// A point has a NaN or infinite coordinate.
    NonFinite {
        /// The index of the first such point.
        index: usize,
        /// Its coordinates.
        point: [f32; 3],
    },
    /// The rotation given to [`Obb3::from_axes`] is not orthonormal: it has a NaN or
    /// infinite entry, or its columns `a_k` are off by more than `2^-10`, measured as
    /// `max_k Σ_j |a_k·a_j − δ_kj|`.
    NotOrthonormal {
        /// That measure, bounded above (NaN for a non-finite entry).
        defect: f32,
    },
    /// The points spread so far toward `±f32::MAX` that the fitted volume does not fit in
    /// `f32`: a half-extent or a radius would overflow.
    Overflow,
}

impl fmt::Display for FitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Empty => write!(f, "cannot fit a bounding volume to no points"),
            Self::NonFinite { index, point } => {
                write!(f, "point {index} is not finite: {point:?}")
            }
            Self::NotOrthonormal { defect } => write!(
                f,
                "the rotation is not orthonormal: defect {defect:e}, at most 2^-10 allowed"
            ),
            Self::Overflow => write!(
                f,
                "the fitted volume overflows f32: the points spread too far"
            ),
        }
    }
}

impl core::error::Error for FitError {}
