//! Transform classes: the types, their kernels and their bounds (documented on
//! [`Transform3`]).

mod affine;
mod named;
mod quat;
mod rigid2;
mod translation;

pub use quat::{Rigid3, Similarity3, Trs3};
pub use rigid2::Rigid2;
pub use translation::{Translation2, Translation3};

use crate::kernel::MapKernel;
use crate::lane::Axes;
use crate::method::Method;

pub use named::{AosPoses, Maps, NamedBoxes, NamedBoxesMut, NamedItem, NamedPoses, Route};
pub(crate) use sealed::Class;

/// A 3D transform class: every single-box and batch entry point accepts any of them.
///
/// Implemented by [`Translation3`], [`Rigid3`], [`Similarity3`], [`Trs3`] and
/// `glam::Affine3A`; sealed, since each class carries its own kernel. Convert other pose
/// types into one of these (`Rigid3::from((rotation, translation))`, …).
///
/// # Transform classes
///
/// One type per kind of map a scene uses, each with the cheapest kernel that is exact for
/// it.
///
/// | class | map `x ↦ M x + t` | fields | methods |
/// |---|---|---:|---|
/// | [`Translation3`], [`Translation2`] | `x + t` | 3, 2 | all three coincide: six (four) additions |
/// | [`Rigid3`] | `R(q)·x + t` | 7 | as for the matrix `R(q)` |
/// | [`Similarity3`] | `R(q)·(σ·x) + t` | 8 | the box scaled, then as [`Rigid3`] |
/// | [`Trs3`] | `R(q)·(s ∘ x) + t` (bevy's `Transform`) | 10 | the box scaled, then as [`Rigid3`] |
/// | `Affine3A`, `Affine2` | `M x + t` | 12, 6 | naive, abs-matrix, sign-select |
/// | [`Rigid2`] | `[[c, −s], [s, c]]·x + t` | 4 | sign-select is Eberly's sign branch |
///
/// The **exact map** of a quaternion class, which the contract refers to, is the standard
/// formula `R(q)` (glam's `Mat3::from_quat`: `1 − 2(y² + z²)`, `2(xy − wz)`, …) evaluated
/// exactly on the stored `f32` components, with no normalisation assumed, times the scale,
/// plus the translation. [`Rounding::Outward`](crate::Rounding::Outward) contains the
/// exact image under that map.
///
/// ## Bounds per class
///
/// Every bound has the form of [`Method`]: Nearest faces within
/// `γ(n)·S_i + τ·TINY_ERROR`, Outward faces containing the exact face and within twice the
/// pad `(n + 2)·u·S_i + τ·TINY_PAD`, where `n` is [`Transform3::nearest_order`]
/// ([`Transform2::nearest_order`]) and the magnitude `S_i` and the factor `τ` are:
///
/// - affine maps and [`Rigid2`]: `S_i = |t_i| + Σ_j |m_ij|·max(|lo_j|, |hi_j|)`, `τ = 1`;
/// - translations: `S_i = |t_i| + max(|lo_i|, |hi_i|)`, `τ = 1`, `n = 1` (one rounding);
///   Outward steps every face one ulp outward (at least `2^-104` from zero);
/// - quaternion classes: with `ρ = 1 + 2‖q‖²`, which bounds every `|R_ij(q)|` for any
///   `q`, `S_i = |t_i| + ρ·Σ_j |s_j|·max(|lo_j|, |hi_j|)` and `τ = 2ρ`; `n` is the
///   method's order plus 3 for the rounding of `R(q)` (plus 1 more for the scaled box).
///
/// Why the quaternion magnitude uses `ρ` rather than `|m_ij|`: the computed `R(q)` entries
/// err by up to `γ(3)·ρ` each, which cancellation can make large against `|R_ij|` itself
/// (a quarter turn has `R_00 ≈ 0`), so the error must be measured against `ρ`. For a unit
/// quaternion `ρ = 3`. Underflow in the scaled box adds at most `2^-150` per coordinate,
/// which `R` amplifies by up to `ρ`: hence `τ = 2ρ`.
///
/// A quaternion, scale or translation holding NaN or an infinity has no finite image: the
/// result is the NaN box, as for a non-finite matrix. A zero quaternion is the identity
/// rotation of the formula (`R(0) = I`), and a quaternion far from unit length is the
/// linear map the formula gives; both are bounded like any other.
pub trait Transform3: Class<3> {
    /// The order `n` of this class's Nearest bound `γ(n)·S + τ·TINY_ERROR` under `method`
    /// (see [`Transform3`]); the Outward pad is `(n + 2)·u·S + τ·TINY_PAD`.
    #[must_use]
    fn nearest_order(method: Method) -> u32 {
        <Self as Class<3>>::order(method)
    }

    /// The class on lanes `P` whose 128-bit parts hold one pose each, their lanes the
    /// axes of one box: on glam's SIMD `Vec3A`, one pose (sealed machinery, as
    /// [`Class`]'s).
    #[doc(hidden)]
    type Simd<P: Axes>: MapKernel<P> + Copy;
    /// The pose on `Vec3A` lanes.
    #[doc(hidden)]
    fn simd(&self) -> Self::Simd<glam::Vec3A>;
    /// `W` poses side by side in lanes `P`, one per 128-bit part: every field `join` of
    /// the poses' own (the AoS loop's several boxes per instruction).
    #[doc(hidden)]
    fn join<P: Axes, const W: usize>(
        poses: &[Self::Simd<glam::Vec3A>; W],
        join: impl Fn([glam::Vec3A; W]) -> P,
    ) -> Self::Simd<P>;
}

/// A 2D transform class: [`Translation2`], [`Rigid2`] and `glam::Affine2`.
pub trait Transform2: Class<2> {
    /// The order `n` of this class's Nearest bound `γ(n)·S + τ·TINY_ERROR` under `method`.
    #[must_use]
    fn nearest_order(method: Method) -> u32 {
        <Self as Class<2>>::order(method)
    }
}

pub(crate) mod sealed {
    //! The machinery behind the public traits: how a class is stored as fields, how it
    //! becomes lanes, its kernel and its extended-range form.

    use super::*;
    use crate::extended::ExtendedMap;
    use crate::fields::{Fields, MAX_FIELDS};
    use crate::kernel::MapKernel;
    use crate::lane::{Lane, Vector};

    /// A transform class in `N` dimensions.
    pub trait Class<const N: usize>: Fields + NamedItem {
        /// The class in lanes (`Vector<L, N>` holds one box per lane of `L`).
        type Lanes<L: Lane>: MapKernel<Vector<L, N>>;
        /// The lanes from the fields in lanes (`f[k]` holds field `k` of every lane).
        fn lanes<L: Lane>(f: &[L; MAX_FIELDS]) -> Self::Lanes<L>;
        /// The map for the extended-range path.
        fn extended(&self) -> ExtendedMap<N>;
        /// The order `n` of the Nearest bound under `method`.
        fn order(method: Method) -> u32;
    }
}
