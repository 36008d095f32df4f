//! Fitted volumes through transforms: the AABB of a volume's image under any 3D transform
//! class ([`BoundingVolume`], one volume or a slice), and the image itself under a
//! similarity ([`Obb3::transformed`], [`Sphere::transformed`], [`Capsule::transformed`]).
//!
//! **The map in `f64`.** Every class is read as `x ↦ M x + t` through its extended-range
//! form: an affine matrix exactly, a quaternion class's `R(q)·diag(s)` within
//! `ε_k = 2^-50·ρ·|s_k|` on each entry of column `k` (`ρ = 1 + 2‖q‖²`). Products of the
//! `f32` inputs never overflow in `f64`, and every rounding is relative but for an operation
//! whose result falls below `f64`'s normal range (only when several inputs lie near the
//! bottom of `f32`'s subnormal range at once): it errs by at most `2^-1075`, which the
//! absolute term `2^-1000` of every scale covers ([`certified`]). Each
//! face (or radius, or half-extent) is then one `f64` expression on exact data whose error
//! the [`bound`](super::bound) lemma turns into an outward `f32`: an absolute error `ε·x`
//! enters its scale as `2^50·ε·x` (`γ(8)·2^50 >= 1`), and an expression of up to 12
//! roundings, or one divided by a determinant known to `γ(4)·κ` relative, doubles its
//! scale per such excess (`2·γ(8) >= γ(12)`, `2·γ(8)·κ >= 2·γ(4)·κ/(1 − γ(4)·κ)` while
//! `γ(4)·κ <= 1/2`).
//!
//! **The box's dual basis.** An [`Obb3`] is the slab set `|(y − c)·a_k| <= h_k` of its `f32`
//! axes, which is `c + Σ_j s_j·B_j/D` with `|s_j| <= h_j`, `B_j = a_{j+1} × a_{j+2}` and
//! `D = a_0·B_0` (since `B_j·a_k = δ_jk·D`): exact even when the axes are not quite
//! orthonormal. Each `f64` entry of `B_j` is one rounding (its products are exact); the
//! computed `D` is within `γ(4)·κ·|D|`, `κ = Σ_l |a_0l·B_0l| / |D|` (1 for orthonormal axes).

use glam::{DMat3, DVec3, Mat3A, Vec3A};

use super::bound::Bounded;
use super::{Capsule, Obb3, Sphere};
use crate::aabb::Aabb3;
use crate::error::BatchError;
use crate::extended::ExtendedMap;
use crate::layout::TransformSource;
use crate::method::Rounding;
use crate::transform::{Class, Similarity3, Transform3};

/// `2^50`: an absolute error `ε` is covered by `2^50·ε` in the lemma's scale.
const ABSOLUTE: f64 = (1u64 << 50) as f64;

/// Beyond this conditioning `κ` a box's axes are taken as singular (`γ(4)·κ` near 1/2).
const MAX_KAPPA: f64 = (1u64 << 40) as f64;

/// The whole space: the bound of a volume with an infinite field or singular axes.
const EVERYWHERE: Aabb3 = Aabb3::new(Vec3A::NEG_INFINITY, Vec3A::INFINITY);

/// The map of a transform class in `f64` ([`ExtendedMap`]); `None` when a parameter is
/// NaN or infinite.
fn map_of<T: Class<3>>(xf: &T) -> Option<ExtendedMap<3>> {
    let map = xf.extended();
    (!map.invalid).then_some(map)
}

/// The scale of `M p + t` over points with `|p_k| <= reach_k`, the map's error folded in:
/// `|t| + |M|·reach + 2^50·Σ_k ε_k·reach_k` on every axis.
fn magnitude(map: &ExtendedMap<3>, reach: DVec3) -> DVec3 {
    let error = DVec3::from_array(map.col_error).dot(reach);
    map.translation().abs() + map.matrix().abs() * reach + DVec3::splat(ABSOLUTE * error)
}

/// `p` through the map rounded to the nearest `f32`, and its exact distance from the
/// exact image in the 1-norm, bounded: `Σ_i |v_i − p'_i|` (3 more roundings on the 4 of
/// `v`) with the scale of `v` plus `|p'|`.
fn moved(map: &ExtendedMap<3>, p: Vec3A) -> (Vec3A, Bounded) {
    let v = map.apply(p.as_dvec3());
    let moved = v.as_vec3a();
    let shift = Bounded {
        value: (v - moved.as_dvec3()).abs().element_sum(),
        scale: (magnitude(map, p.as_dvec3().abs()) + moved.as_dvec3().abs()).element_sum(),
    };
    (moved, shift)
}

/// The lemma's bound on `value`, with `2^-1000` added to its `scale`: an ample cover for
/// the absolute error, at most `2^-1075` each, of the operations that underflow in `f64`.
fn certified(value: f64, scale: f64) -> Bounded {
    const TINY_SCALE: f64 = f64::from_bits(23 << 52); // 2^(23 − 1023)
    Bounded {
        value,
        scale: scale + TINY_SCALE,
    }
}

/// An `f32` face from an `f64` value bounded by the lemma: rounded to nearest, or outward.
fn face(value: f64, scale: f64, rounding: Rounding, lower: bool) -> f32 {
    let bounded = certified(value, scale);
    match (rounding, lower) {
        (Rounding::Nearest, _) => value as f32,
        (Rounding::Outward, true) => bounded.lower(),
        (Rounding::Outward, false) => bounded.upper(),
    }
}

/// The box `[lo, hi]` of `f64` faces, each within the lemma's bound of its `scale`.
fn faces(lo: DVec3, hi: DVec3, scale: DVec3, rounding: Rounding) -> Aabb3 {
    let side = |v: DVec3, lower| {
        Vec3A::from_array([0, 1, 2].map(|i| face(v[i], scale[i], rounding, lower)))
    };
    Aabb3::new(side(lo, true), side(hi, false))
}

/// The dual basis `B_j` (columns, not divided by `D`), `|D|` and `κ` of a box's axes (see
/// the module docs); `None` for axes too close to singular to bound.
fn dual(rotation: Mat3A) -> Option<(DMat3, f64, f64)> {
    let a = rotation.as_dmat3();
    let col = |j: usize| a.col((j + 1) % 3).cross(a.col((j + 2) % 3));
    let b = DMat3::from_cols(col(0), col(1), col(2));
    let det = a.x_axis.dot(b.x_axis).abs();
    let kappa = a.x_axis.abs().dot(b.x_axis.abs()) / det;
    (kappa < MAX_KAPPA).then_some((b, det, kappa))
}

/// `|σ|·max(1, 2‖q‖² − 1)`, which bounds the spectral norm of `σ·R(q)` for any `q`: the
/// formula is `R(q) = ‖q‖²·Q + (1 − ‖q‖²)·I` with `Q` the rotation of `q/‖q‖`. Computed
/// within `γ(8)` relative (`‖q‖²` to `γ(3)`, doubled against `2‖q‖² − 1 >= ‖q‖²`, the
/// subtraction, the product with `|σ|`).
fn stretch(xf: &Similarity3) -> f64 {
    let n = xf.rotation.as_dquat().length_squared();
    (2.0 * n - 1.0).max(1.0) * f64::from(xf.scale).abs()
}

/// A volume whose image under a map can be bounded: the machinery behind [`BoundingVolume`].
pub(crate) trait ImageBound {
    /// The bound of the image under `map` (`None`: a NaN or infinite map parameter).
    fn aabb_under(&self, map: Option<&ExtendedMap<3>>, rounding: Rounding) -> Aabb3;
}

/// A bounding volume ([`Obb3`], [`Sphere`], [`Capsule`]) whose world AABB under any 3D
/// [transform class](crate::Transform3) bvkit computes: the axis-aligned bound of the image
/// of the exact volume (the statement of its docs, exact on its `f32` fields) under the
/// exact map.
///
/// - [`Rounding::Outward`] contains that image. Each face lies within
///   `2u·|x_i| + 2^-43·(1 + κ)·S_i + 2^-149` of the exact face `x_i`.
/// - [`Rounding::Nearest`] rounds the same `f64` evaluation to nearest: within
///   `u·|x_i| + 2^-44·(1 + κ)·S_i + 2^-150`.
///
/// Here `u = 2^-24`, `κ` is 1 for spheres and capsules and for a box the conditioning
/// `κ = Σ_l |a_0l·B_0l| / |a_0·B_0|` of its axes, `B_0 = a_1 × a_2` (1 when orthonormal), and
/// `S_i = |t_i| + Σ_k μ_ik·reach_k` with `μ_ik = |m_ik|` for an affine map (the identity
/// for a translation) and `ρ·|s_k|` for a quaternion class, as in [`crate::Transform3`];
/// `reach_k` is `|c_k| + Σ_j |b_jk|·h_j` for a box (`b_j` its dual basis, its axes when
/// orthonormal), `|c_k| + r` for a sphere and `max(|a_k|, |b_k|) + r` for a capsule. As
/// `|x_i| <= S_i`, for orthonormal axes these are within `3u·S_i + TINY_PAD` (Outward) and
/// `γ(2)·S_i + TINY_ERROR` (Nearest), tighter than any box kernel of [`crate::Method`].
///
/// Bad input follows the crate's contract: NaN anywhere, or a non-finite map parameter,
/// gives [`Aabb3::NAN`]; an empty volume (a negative radius or half-extent) gives
/// [`Aabb3::EMPTY`]; a volume with an infinite field, or a box with singular axes, bounds
/// no finite set and gives the whole space; faces beyond the `f32` range are `±inf`. The
/// evaluation is one `f64` form per volume (there is no choice of [`crate::Method`]), and
/// nothing panics.
///
/// ```
/// use bvkit::{Aabb3, BoundingVolume, Fit, Obb3, Rigid3, Rounding, Sphere};
/// use glam::{Quat, Vec3, Vec3A};
///
/// let points = [Vec3::ZERO, Vec3::X, Vec3::new(0.0, 2.0, 1.0)];
/// let obb = Obb3::fit(&points, Fit::Fast)?;
/// let pose = Rigid3::new(Quat::from_rotation_y(0.7), Vec3A::new(5.0, 0.0, 0.0));
/// // The origin is a fitted point, and maps exactly to the translation.
/// assert!(obb.transformed_aabb(&pose, Rounding::Outward).contains_point(pose.translation));
/// assert!(obb.transformed(pose).contains_point(pose.translation));
///
/// // Many at once: one transform per volume, or one shared (`&pose`).
/// let balls = vec![Sphere::fit(&points, Fit::Tight)?; 4];
/// let mut world = vec![Aabb3::EMPTY; 4];
/// Sphere::transformed_aabbs(&balls, &pose, &mut world, Rounding::Outward)?;
/// assert_eq!(world[3], balls[3].transformed_aabb(&pose, Rounding::Outward));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub trait BoundingVolume: ImageBound + Sized {
    /// The AABB of the volume's image under `xf` (see the [trait docs](BoundingVolume)).
    #[inline]
    #[must_use]
    fn transformed_aabb<T: Transform3>(&self, xf: &T, rounding: Rounding) -> Aabb3 {
        self.aabb_under(map_of(xf).as_ref(), rounding)
    }

    /// `out[k]` = the AABB of `volumes[k]` through transform `k`, or through the one shared
    /// transform (`&T`); transforms in any layout of [`crate::Batch`]. Each result is
    /// bitwise that of [`BoundingVolume::transformed_aabb`].
    ///
    /// # Errors
    /// [`BatchError::LengthMismatch`] unless the transforms (unless shared) and `out` have
    /// the length of `volumes`; `out` is then untouched.
    fn transformed_aabbs(
        volumes: &[Self],
        xf: impl TransformSource<3>,
        out: &mut [Aabb3],
        rounding: Rounding,
    ) -> Result<(), BatchError> {
        let expected = volumes.len();
        if let Some(found) = xf.len()? {
            BatchError::check_len("transforms", expected, found)?;
        }
        BatchError::check_len("output", expected, out.len())?;
        for (k, (volume, o)) in volumes.iter().zip(out.iter_mut()).enumerate() {
            *o = volume.aabb_under(map_of(&xf.get(k)).as_ref(), rounding);
        }
        Ok(())
    }
}

impl BoundingVolume for Obb3 {}
impl BoundingVolume for Sphere {}
impl BoundingVolume for Capsule {}

impl Obb3 {
    fn is_nan(&self) -> bool {
        self.center.is_nan() || self.half_extents.is_nan() || self.rotation.is_nan()
    }

    fn is_finite(&self) -> bool {
        self.center.is_finite() && self.half_extents.is_finite() && self.rotation.is_finite()
    }

    /// The image of the box under the similarity `xf` (a [`crate::Rigid3`] converts),
    /// rounded outward: every point of the exact image of the exact box (the slab set of
    /// its `f32` fields, under `x ↦ σ·R(q)·x + t` with `R(q)` exact on the stored `q`)
    /// satisfies the returned box's slab inequalities exactly. So its
    /// [`Obb3::contains_point`] and its [`BoundingVolume::transformed_aabb`] hold the image.
    ///
    /// The center is `σ·R(q)·c + t` and the axes `R(q)·a_k`, each rounded to nearest (the
    /// axes stay orthonormal to within `f32` rounding for a unit `q`; a reflection `σ < 0`
    /// only flips every slab, which changes nothing). Each half-extent is the support of the
    /// exact image on its new axis, rounded up: for a unit `q` and orthonormal axes it
    /// exceeds `|σ|·h_k` by about the rounding of the center. NaN or an infinite field
    /// gives NaN fields; an empty box stays empty; singular axes give infinite
    /// half-extents.
    #[must_use]
    pub fn transformed(&self, xf: impl Into<Similarity3>) -> Self {
        // With `M = σ·R(q)` and the dual basis `B_j`, `D` (module docs), the image is
        // `M c + t + Σ_j s_j·M B_j/D`, `|s_j| <= h_j`: on axis `a'_k` about `c'` it reaches
        // `h'_k = |(M c + t − c')·a'_k| + Σ_j h_j·|a'_k·(M B_j)|/|D|`. Its `f64` value
        // rounds at most 12 times (the cross product, `M·B`, the dot with `a'_k`, `·h`, the
        // sum, `/D`, the sum with the center term of 9 roundings) and `D` is within
        // `γ(4)·κ`: the lemma with scale `2·(1 + κ)·|a'_k|·(|c'| + magnitude(reach))`
        // certifies it (module docs).
        let xf = xf.into();
        let (Some(map), true) = (map_of(&xf), self.is_finite()) else {
            return Self {
                center: Vec3A::NAN,
                half_extents: Vec3A::NAN,
                rotation: Mat3A::NAN,
            };
        };
        let r =
            DMat3::from_cols_array_2d(&ExtendedMap::rotation(xf.rotation, [1.0; 3], [0.0; 3]).cols);
        let axes = r * self.rotation.as_dmat3();
        let rotation = Mat3A::from_cols(
            axes.x_axis.as_vec3a(),
            axes.y_axis.as_vec3a(),
            axes.z_axis.as_vec3a(),
        );
        let (center, _) = moved(&map, self.center);
        let half_extents = match dual(self.rotation) {
            _ if self.half_extents.min_element() < 0.0 => self.half_extents,
            None => Vec3A::INFINITY,
            Some((b, det, kappa)) => {
                let (h, c, c2) = (
                    self.half_extents.as_dvec3(),
                    self.center.as_dvec3(),
                    center.as_dvec3(),
                );
                let a2t = rotation.as_dmat3().transpose();
                let support =
                    (a2t * (map.matrix() * b)).abs() * h / det + (a2t * (map.apply(c) - c2)).abs();
                let reach = c.abs() + b.abs() * h / det;
                let scale = a2t.abs() * (magnitude(&map, reach) + c2.abs()) * (2.0 * (1.0 + kappa));
                Vec3A::from_array([0, 1, 2].map(|k| certified(support[k], scale[k]).upper()))
            }
        };
        Self {
            center,
            half_extents,
            rotation,
        }
    }
}

/// `c ± |M·B/D|·h` with `c = M c + t`: the abs-matrix form on the dual basis (module docs).
///
/// Error: the center rounds 5 times per leaf (`M c + t`, then `±`); the extent 9 times (the
/// cross product, `M·B`, `·h`, the sum over `j`, `/D`, `±`), and `D` is within `γ(4)·κ`;
/// the map's error adds `Σ_k ε_k·reach_k` with `reach = |c| + |B|·h/|D|`. The lemma's scale
/// is therefore `2·(1 + κ)·magnitude(reach)` (module docs).
impl ImageBound for Obb3 {
    fn aabb_under(&self, map: Option<&ExtendedMap<3>>, rounding: Rounding) -> Aabb3 {
        let Some(map) = map.filter(|_| !self.is_nan()) else {
            return Aabb3::NAN;
        };
        if self.half_extents.min_element() < 0.0 {
            return Aabb3::EMPTY;
        }
        let Some((b, det, kappa)) = dual(self.rotation).filter(|_| self.is_finite()) else {
            return EVERYWHERE;
        };
        let (c, h) = (self.center.as_dvec3(), self.half_extents.as_dvec3());
        let center = map.apply(c);
        let extent = (map.matrix() * b).abs() * h / det;
        let scale = magnitude(map, c.abs() + b.abs() * h / det) * (2.0 * (1.0 + kappa));
        faces(center - extent, center + extent, scale, rounding)
    }
}

/// The bound of a ball of radius `r` about `p` under `map`: `M p + t ± r·‖row_i(M)‖`, the
/// support of the image ellipsoid on axis `i`.
///
/// Error: the center rounds 4 times per leaf, the row norm within `γ(4)` relative (three
/// squares and two sums inside the root halve to `γ(3)/2`, the root one more), times `r`
/// and `±`: 6 roundings; `‖row_i(M)‖ <= Σ_k |m_ik|` and the norm of `M`'s error row is at
/// most `Σ_k ε_k`, so `magnitude(|p| + r)` is the lemma's scale.
fn swept_point(map: &ExtendedMap<3>, p: Vec3A, radius: f32, rounding: Rounding) -> Aabb3 {
    let (p, r) = (p.as_dvec3(), f64::from(radius));
    let rows = map.matrix().transpose();
    let norms = DVec3::new(
        rows.x_axis.length(),
        rows.y_axis.length(),
        rows.z_axis.length(),
    );
    let center = map.apply(p);
    faces(
        center - norms * r,
        center + norms * r,
        magnitude(map, p.abs() + r),
        rounding,
    )
}

/// The bound of a capsule (or a sphere, `a = b`) under `map`, with the contract's bad input.
fn swept_segment(
    map: Option<&ExtendedMap<3>>,
    [a, b]: [Vec3A; 2],
    radius: f32,
    rounding: Rounding,
) -> Aabb3 {
    let nan = a.is_nan() || b.is_nan() || radius.is_nan();
    let Some(map) = map.filter(|_| !nan) else {
        return Aabb3::NAN;
    };
    if radius < 0.0 {
        return Aabb3::EMPTY;
    }
    if !(a.is_finite() && b.is_finite() && radius.is_finite()) {
        return EVERYWHERE;
    }
    // The image is the segment's image swept by the ellipsoid: its bound is the union of
    // the ends' bounds (the segment's image is the hull of the ends' images).
    swept_point(map, a, radius, rounding).union(&swept_point(map, b, radius, rounding))
}

impl ImageBound for Sphere {
    fn aabb_under(&self, map: Option<&ExtendedMap<3>>, rounding: Rounding) -> Aabb3 {
        swept_segment(map, [self.center; 2], self.radius, rounding)
    }
}

impl ImageBound for Capsule {
    fn aabb_under(&self, map: Option<&ExtendedMap<3>>, rounding: Rounding) -> Aabb3 {
        swept_segment(map, [self.a, self.b], self.radius, rounding)
    }
}

/// The radius of a swept volume's image: `stretch·r` plus the largest shift of a moved
/// point, bounded. The swept term rounds up to 10 times (the stretch's 8, `·r`, the sum),
/// so it enters the scale too, doubled with the shifts' scales (module docs).
fn image_radius(xf: &Similarity3, radius: f32, shifts: &[Bounded]) -> f32 {
    let swept = stretch(xf) * f64::from(radius);
    let shift = shifts.iter().map(|s| s.value).fold(0.0, f64::max);
    let scale: f64 = shifts.iter().map(|s| s.scale).sum();
    certified(swept + shift, 2.0 * (swept + scale)).upper()
}

impl Sphere {
    /// The image of the ball under the similarity `xf` (a [`crate::Rigid3`] converts),
    /// rounded outward: it contains the exact image of the exact ball under
    /// `x ↦ σ·R(q)·x + t` (`R(q)` exact on the stored `q`, any length).
    ///
    /// The center is `σ·R(q)·c + t` rounded to nearest; the radius
    /// `|σ|·max(1, 2‖q‖² − 1)·r` (the image of the ball lies within `‖σ·R(q)‖₂·r` of the
    /// image of its center) plus the distance from the exact image of the center to the
    /// rounded one, bounded in the 1-norm, rounded up. NaN or infinite input gives NaN
    /// fields; an empty ball stays empty.
    #[must_use]
    pub fn transformed(&self, xf: impl Into<Similarity3>) -> Self {
        let xf = xf.into();
        let finite = self.center.is_finite() && self.radius.is_finite();
        let Some(map) = map_of(&xf).filter(|_| finite) else {
            return Self {
                center: Vec3A::NAN,
                radius: f32::NAN,
            };
        };
        let (center, shift) = moved(&map, self.center);
        let radius = match self.radius {
            r if r < 0.0 => r,
            r => image_radius(&xf, r, &[shift]),
        };
        Self { center, radius }
    }
}

impl Capsule {
    /// The image of the capsule under the similarity `xf` (a [`crate::Rigid3`] converts),
    /// rounded outward: it contains the exact image of the exact capsule under
    /// `x ↦ σ·R(q)·x + t`.
    ///
    /// The ends are moved and rounded to nearest; an affine map takes the segment to the
    /// segment of the exact images, each of whose points lies within the larger end shift
    /// of the rounded segment, and the swept ball to an ellipsoid within
    /// `|σ|·max(1, 2‖q‖² − 1)·r`: the radius is their sum, rounded up. NaN or infinite input
    /// gives NaN fields; an empty capsule stays empty.
    #[must_use]
    pub fn transformed(&self, xf: impl Into<Similarity3>) -> Self {
        let xf = xf.into();
        let finite = self.a.is_finite() && self.b.is_finite() && self.radius.is_finite();
        let Some(map) = map_of(&xf).filter(|_| finite) else {
            return Self {
                a: Vec3A::NAN,
                b: Vec3A::NAN,
                radius: f32::NAN,
            };
        };
        let ((a, shift_a), (b, shift_b)) = (moved(&map, self.a), moved(&map, self.b));
        let radius = match self.radius {
            r if r < 0.0 => r,
            r => image_radius(&xf, r, &[shift_a, shift_b]),
        };
        Self { a, b, radius }
    }
}
