//! Rotations given by quaternions: [`Rigid3`] (the pose of rapier, parry, Jolt and PhysX),
//! [`Similarity3`] (plus a uniform scale) and [`Trs3`] (per-axis scale, bevy's `Transform`).
//!
//! All three run one kernel: the box is scaled first (a per-axis sign select, one rounding
//! per face), then rotated by `R(q)`, computed in lanes straight from the quaternion, and
//! translated. No `Affine3A` is built.

use glam::{Affine3A, Mat3A, Quat, Vec3, Vec3A};

use super::{Class, Transform3};
use crate::extended::ExtendedMap;
use crate::fields::{Fields, MAX_FIELDS, vector_at};
use crate::kernel::MapKernel;
use crate::kernel::{self, AffineLanes};
use crate::lane::{Axes, Lane, Vector};
use crate::method::Method;

/// A rotation then a translation: `x ↦ R(q)·x + t`.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::AnyBitPattern))]
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Rigid3 {
    /// The rotation; used as stored (see [`Transform3`]).
    pub rotation: Quat,
    /// The translation, applied after the rotation.
    pub translation: Vec3A,
}

/// A uniform scale, a rotation, then a translation: `x ↦ R(q)·(σ·x) + t`.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::AnyBitPattern))]
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Similarity3 {
    /// The uniform scale `σ` (negative is a point reflection).
    pub scale: f32,
    /// The rotation; used as stored.
    pub rotation: Quat,
    /// The translation, applied last.
    pub translation: Vec3A,
}

/// A per-axis scale, a rotation, then a translation: `x ↦ R(q)·(s ∘ x) + t`, the order of
/// bevy's `Transform`.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::AnyBitPattern))]
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Trs3 {
    /// The per-axis scale `s`, applied first (negative and zero entries are allowed).
    pub scale: Vec3A,
    /// The rotation; used as stored.
    pub rotation: Quat,
    /// The translation, applied last.
    pub translation: Vec3A,
}

impl Rigid3 {
    /// No motion.
    pub const IDENTITY: Self = Self::new(Quat::IDENTITY, Vec3A::ZERO);

    /// The rotation `rotation` followed by the translation `translation`.
    #[inline]
    #[must_use]
    pub const fn new(rotation: Quat, translation: Vec3A) -> Self {
        Self {
            rotation,
            translation,
        }
    }
}

impl Similarity3 {
    /// No motion.
    pub const IDENTITY: Self = Self::new(1.0, Quat::IDENTITY, Vec3A::ZERO);

    /// Scale by `scale`, rotate by `rotation`, then translate by `translation`.
    #[inline]
    #[must_use]
    pub const fn new(scale: f32, rotation: Quat, translation: Vec3A) -> Self {
        Self {
            scale,
            rotation,
            translation,
        }
    }
}

impl Trs3 {
    /// No motion.
    pub const IDENTITY: Self = Self::new(Vec3A::ONE, Quat::IDENTITY, Vec3A::ZERO);

    /// Scale by `scale`, rotate by `rotation`, then translate by `translation`.
    #[inline]
    #[must_use]
    pub const fn new(scale: Vec3A, rotation: Quat, translation: Vec3A) -> Self {
        Self {
            scale,
            rotation,
            translation,
        }
    }
}

impl From<(Quat, Vec3)> for Rigid3 {
    #[inline]
    fn from((rotation, translation): (Quat, Vec3)) -> Self {
        Self::new(rotation, translation.into())
    }
}

impl From<(Quat, Vec3A)> for Rigid3 {
    #[inline]
    fn from((rotation, translation): (Quat, Vec3A)) -> Self {
        Self::new(rotation, translation)
    }
}

impl From<(f32, Quat, Vec3)> for Similarity3 {
    #[inline]
    fn from((scale, rotation, translation): (f32, Quat, Vec3)) -> Self {
        Self::new(scale, rotation, translation.into())
    }
}

/// From `(scale, rotation, translation)`, the order of glam's
/// `Affine3A::to_scale_rotation_translation`.
impl From<(Vec3, Quat, Vec3)> for Trs3 {
    #[inline]
    fn from((scale, rotation, translation): (Vec3, Quat, Vec3)) -> Self {
        Self::new(scale.into(), rotation, translation.into())
    }
}

impl From<Rigid3> for Similarity3 {
    #[inline]
    fn from(xf: Rigid3) -> Self {
        Self::new(1.0, xf.rotation, xf.translation)
    }
}

impl From<Similarity3> for Trs3 {
    #[inline]
    fn from(xf: Similarity3) -> Self {
        Self::new(Vec3A::splat(xf.scale), xf.rotation, xf.translation)
    }
}

/// `R(q)·diag(s)` as glam columns, rounded as the kernels round `R(q)`.
fn affine(q: Quat, scale: Vec3A, translation: Vec3A) -> Affine3A {
    let (cols, _) = kernel::rotation(q.to_array(), 1.0);
    let col = |j: usize| Vec3A::from_array(cols[j]) * scale[j];
    Affine3A {
        matrix3: Mat3A::from_cols(col(0), col(1), col(2)),
        translation,
    }
}

impl From<Rigid3> for Affine3A {
    #[inline]
    fn from(xf: Rigid3) -> Affine3A {
        affine(xf.rotation, Vec3A::ONE, xf.translation)
    }
}

impl From<Similarity3> for Affine3A {
    #[inline]
    fn from(xf: Similarity3) -> Affine3A {
        affine(xf.rotation, Vec3A::splat(xf.scale), xf.translation)
    }
}

impl From<Trs3> for Affine3A {
    #[inline]
    fn from(xf: Trs3) -> Affine3A {
        affine(xf.rotation, xf.scale, xf.translation)
    }
}

/// A quaternion class in lanes: the columns of `R(q)`, `ρ = 1 + 2‖q‖²`, the per-axis scale
/// of the box (ignored unless `SCALED`) and the translation.
#[derive(Clone, Copy, Debug)]
pub struct QuatLanes<V, const SCALED: bool> {
    pub cols: [V; 3],
    pub rho: V,
    pub scale: V,
    pub t: V,
}

impl<V: Axes, const SCALED: bool> MapKernel<V> for QuatLanes<V, SCALED> {
    #[inline(always)]
    fn transform(&self, lo: V, hi: V, method: Method, outward: bool) -> (V, V) {
        let (lo, hi) = if SCALED {
            kernel::scale_box(self.scale, lo, hi)
        } else {
            (lo, hi)
        };
        let a = AffineLanes {
            cols: self.cols,
            t: self.t,
        };
        let (min, max) = kernel::bound(&a, lo, hi, method);
        if outward {
            let k = quat_gamma(method, SCALED) + 2;
            let pad = kernel::rotation_pad(self.rho, self.t, lo, hi, k);
            (min - pad, max + pad)
        } else {
            (min, max)
        }
    }
}

/// The method's order plus 3 for the rounding of `R(q)`, plus 1 for the scaled box.
const fn quat_gamma(method: Method, scaled: bool) -> u32 {
    method.nearest_order(3) + 3 + scaled as u32
}

/// The lanes of a quaternion class whose fields start `[qx, qy, qz, qw, tx, ty, tz]`.
#[inline(always)]
fn quat_lanes<L: Lane, const SCALED: bool>(
    f: &[L; MAX_FIELDS],
    scale: Vector<L, 3>,
) -> QuatLanes<Vector<L, 3>, SCALED> {
    let (cols, rho) = kernel::rotation([f[0], f[1], f[2], f[3]], L::splat(1.0));
    QuatLanes {
        cols: [Vector(cols[0]), Vector(cols[1]), Vector(cols[2])],
        rho: Vector([rho; 3]),
        scale,
        t: vector_at(f, 4),
    }
}

/// A quaternion class's pose in lanes of `Vec3A` values (or several poses' side by side):
/// the quaternion's vector part `(x, y, z)`, its `w` in every component, the per-axis scale
/// and the translation. `R(q)` is computed in the lanes, where the kernel runs: once per
/// group of poses in the AoS loop, on four poses at a time with AVX-512.
#[derive(Clone, Copy, Debug)]
pub struct QuatPose<V, const SCALED: bool> {
    v: V,
    w: V,
    scale: V,
    t: V,
}

impl<const SCALED: bool> QuatPose<Vec3A, SCALED> {
    #[inline(always)]
    fn new(q: Quat, scale: Vec3A, t: Vec3A) -> Self {
        QuatPose {
            v: Vec3A::new(q.x, q.y, q.z),
            w: Vec3A::splat(q.w),
            scale,
            t,
        }
    }
}

impl<V: Axes, const SCALED: bool> QuatPose<V, SCALED> {
    /// `R(q)` and `ρ`, with the products and sums of [`kernel::rotation`] in the same
    /// order, so the same bits, in each part of the lanes.
    #[inline(always)]
    fn lanes(&self) -> QuatLanes<V, SCALED> {
        let (v, w) = (self.v, self.w);
        let v2 = v + v;
        let sq = v * v2; // (xx, yy, zz)
        let p = v.yxx() * v2.zzy(); // (yz, xz, xy)
        let wv = w * v2; // (wx, wy, wz)
        let diagonal = V::splat(1.0) - (sq.yxx() + sq.zzy()); // 1 − (yy + zz), …
        let (a, b) = (p + wv, p - wv); // (yz + wx, xz + wy, xy + wz), (yz − wx, xz − wy, xy − wz)
        let cols = [
            V::merge(diagonal, a.axis(2), b.axis(1)),
            V::merge(b.axis(2), diagonal, a.axis(0)),
            V::merge(a.axis(1), b.axis(0), diagonal),
        ];
        let rho = V::splat(1.0) + ((sq.axis(0) + sq.axis(1)) + (sq.axis(2) + w * (w + w)));
        QuatLanes {
            cols,
            rho,
            scale: self.scale,
            t: self.t,
        }
    }
}

impl<V: Axes, const SCALED: bool> MapKernel<V> for QuatPose<V, SCALED> {
    #[inline(always)]
    fn transform(&self, lo: V, hi: V, method: Method, outward: bool) -> (V, V) {
        self.lanes().transform(lo, hi, method, outward)
    }
}

impl<const SCALED: bool> QuatPose<Vec3A, SCALED> {
    /// `W` poses side by side, every field `join` of the poses' own: the quaternion
    /// classes' [`Transform3::join`].
    #[inline(always)]
    fn join<P: Axes, const W: usize>(
        poses: &[Self; W],
        join: impl Fn([Vec3A; W]) -> P,
    ) -> QuatPose<P, SCALED> {
        QuatPose {
            v: join(kernel::gather(|k| poses[k].v)),
            w: join(kernel::gather(|k| poses[k].w)),
            scale: join(kernel::gather(|k| poses[k].scale)),
            t: join(kernel::gather(|k| poses[k].t)),
        }
    }
}

/// The fields of a quaternion class: `[qx, qy, qz, qw, tx, ty, tz, scale…]`.
#[inline(always)]
fn quat_fields(q: Quat, t: Vec3A, scale: &[f32]) -> [f32; MAX_FIELDS] {
    let mut f = [0.0; MAX_FIELDS];
    f[..4].copy_from_slice(&q.to_array());
    f[4..7].copy_from_slice(&t.to_array());
    f[7..7 + scale.len()].copy_from_slice(scale);
    f
}

fn quat_of(f: &[f32; MAX_FIELDS]) -> Quat {
    Quat::from_xyzw(f[0], f[1], f[2], f[3])
}

impl Fields for Rigid3 {
    const FIELDS: usize = 7;
    type Array<C: Send + Sync> = [C; 7];
    #[inline(always)]
    fn array<C: Send + Sync>(f: impl FnMut(usize) -> C) -> Self::Array<C> {
        core::array::from_fn(f)
    }
    const PADDING: Self = Self::IDENTITY;
    #[inline(always)]
    fn to_fields(&self) -> [f32; MAX_FIELDS] {
        quat_fields(self.rotation, self.translation, &[])
    }
    #[inline(always)]
    fn from_fields(f: &[f32; MAX_FIELDS]) -> Self {
        Self::new(quat_of(f), Vec3A::new(f[4], f[5], f[6]))
    }
}

impl Fields for Similarity3 {
    const FIELDS: usize = 8;
    type Array<C: Send + Sync> = [C; 8];
    #[inline(always)]
    fn array<C: Send + Sync>(f: impl FnMut(usize) -> C) -> Self::Array<C> {
        core::array::from_fn(f)
    }
    const PADDING: Self = Self::IDENTITY;
    #[inline(always)]
    fn to_fields(&self) -> [f32; MAX_FIELDS] {
        quat_fields(self.rotation, self.translation, &[self.scale])
    }
    #[inline(always)]
    fn from_fields(f: &[f32; MAX_FIELDS]) -> Self {
        Self::new(f[7], quat_of(f), Vec3A::new(f[4], f[5], f[6]))
    }
}

impl Fields for Trs3 {
    const FIELDS: usize = 10;
    type Array<C: Send + Sync> = [C; 10];
    #[inline(always)]
    fn array<C: Send + Sync>(f: impl FnMut(usize) -> C) -> Self::Array<C> {
        core::array::from_fn(f)
    }
    const PADDING: Self = Self::IDENTITY;
    #[inline(always)]
    fn to_fields(&self) -> [f32; MAX_FIELDS] {
        quat_fields(self.rotation, self.translation, &self.scale.to_array())
    }
    #[inline(always)]
    fn from_fields(f: &[f32; MAX_FIELDS]) -> Self {
        let scale = Vec3A::new(f[7], f[8], f[9]);
        Self::new(scale, quat_of(f), Vec3A::new(f[4], f[5], f[6]))
    }
}

impl Class<3> for Rigid3 {
    type Lanes<L: Lane> = QuatLanes<Vector<L, 3>, false>;
    #[inline(always)]
    fn lanes<L: Lane>(f: &[L; MAX_FIELDS]) -> Self::Lanes<L> {
        quat_lanes(f, Vector([L::splat(1.0); 3]))
    }
    fn extended(&self) -> ExtendedMap<3> {
        ExtendedMap::rotation(self.rotation, [1.0; 3], self.translation.to_array())
    }
    fn order(method: Method) -> u32 {
        quat_gamma(method, false)
    }
}

impl Class<3> for Similarity3 {
    type Lanes<L: Lane> = QuatLanes<Vector<L, 3>, true>;
    #[inline(always)]
    fn lanes<L: Lane>(f: &[L; MAX_FIELDS]) -> Self::Lanes<L> {
        quat_lanes(f, Vector([f[7]; 3]))
    }
    fn extended(&self) -> ExtendedMap<3> {
        let s = self.scale;
        ExtendedMap::rotation(self.rotation, [s; 3], self.translation.to_array())
    }
    fn order(method: Method) -> u32 {
        quat_gamma(method, true)
    }
}

impl Class<3> for Trs3 {
    type Lanes<L: Lane> = QuatLanes<Vector<L, 3>, true>;
    #[inline(always)]
    fn lanes<L: Lane>(f: &[L; MAX_FIELDS]) -> Self::Lanes<L> {
        quat_lanes(f, vector_at(f, 7))
    }
    fn extended(&self) -> ExtendedMap<3> {
        let (s, t) = (self.scale.to_array(), self.translation.to_array());
        ExtendedMap::rotation(self.rotation, s, t)
    }
    fn order(method: Method) -> u32 {
        quat_gamma(method, true)
    }
}

impl Transform3 for Rigid3 {
    type Simd<P: Axes> = QuatPose<P, false>;
    #[inline(always)]
    fn join<P: Axes, const W: usize>(
        poses: &[QuatPose<Vec3A, false>; W],
        join: impl Fn([Vec3A; W]) -> P,
    ) -> QuatPose<P, false> {
        QuatPose::join(poses, join)
    }
    #[inline(always)]
    fn simd(&self) -> QuatPose<Vec3A, false> {
        QuatPose::new(self.rotation, Vec3A::ONE, self.translation)
    }
}
impl Transform3 for Similarity3 {
    type Simd<P: Axes> = QuatPose<P, true>;
    #[inline(always)]
    fn join<P: Axes, const W: usize>(
        poses: &[QuatPose<Vec3A, true>; W],
        join: impl Fn([Vec3A; W]) -> P,
    ) -> QuatPose<P, true> {
        QuatPose::join(poses, join)
    }
    #[inline(always)]
    fn simd(&self) -> QuatPose<Vec3A, true> {
        QuatPose::new(self.rotation, Vec3A::splat(self.scale), self.translation)
    }
}
impl Transform3 for Trs3 {
    type Simd<P: Axes> = QuatPose<P, true>;
    #[inline(always)]
    fn join<P: Axes, const W: usize>(
        poses: &[QuatPose<Vec3A, true>; W],
        join: impl Fn([Vec3A; W]) -> P,
    ) -> QuatPose<P, true> {
        QuatPose::join(poses, join)
    }
    #[inline(always)]
    fn simd(&self) -> QuatPose<Vec3A, true> {
        QuatPose::new(self.rotation, self.scale, self.translation)
    }
}
