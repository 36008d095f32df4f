//! General affine maps, `glam::Affine3A` and `glam::Affine2`: the matrix as given.

use glam::{Affine2, Affine3A, Mat2, Mat3A, Vec2, Vec3A};

use super::{Class, Transform2, Transform3};
use crate::extended::ExtendedMap;
use crate::fields::{Fields, MAX_FIELDS, vector_at};
use crate::kernel::AffineLanes;
use crate::lane::{Axes, Lane, Vector};
use crate::method::Method;

/// Fields `[m00, m10, m20, m01, …, m22, t0, t1, t2]`: the columns, then the translation.
impl Fields for Affine3A {
    const FIELDS: usize = 12;
    type Array<C: Send + Sync> = [C; 12];
    #[inline(always)]
    fn array<C: Send + Sync>(f: impl FnMut(usize) -> C) -> Self::Array<C> {
        core::array::from_fn(f)
    }
    const PADDING: Self = Affine3A::IDENTITY;
    #[inline(always)]
    fn to_fields(&self) -> [f32; MAX_FIELDS] {
        let m = &self.matrix3;
        let (x, y, z, t) = (m.x_axis, m.y_axis, m.z_axis, self.translation);
        [x.x, x.y, x.z, y.x, y.y, y.z, z.x, z.y, z.z, t.x, t.y, t.z]
    }
    #[inline(always)]
    fn from_fields(f: &[f32; MAX_FIELDS]) -> Self {
        let v = |k: usize| Vec3A::new(f[k], f[k + 1], f[k + 2]);
        Affine3A {
            matrix3: Mat3A::from_cols(v(0), v(3), v(6)),
            translation: v(9),
        }
    }
}

impl Class<3> for Affine3A {
    type Lanes<L: Lane> = AffineLanes<Vector<L, 3>, 3>;
    #[inline(always)]
    fn lanes<L: Lane>(f: &[L; MAX_FIELDS]) -> Self::Lanes<L> {
        AffineLanes {
            cols: [vector_at(f, 0), vector_at(f, 3), vector_at(f, 6)],
            t: vector_at(f, 9),
        }
    }
    fn extended(&self) -> ExtendedMap<3> {
        let f = self.to_fields();
        ExtendedMap::exact(
            core::array::from_fn(|j| core::array::from_fn(|i| f[3 * j + i])),
            [f[9], f[10], f[11]],
        )
    }
    fn order(method: Method) -> u32 {
        method.nearest_order(3)
    }
}

impl Transform3 for Affine3A {
    type Simd<P: Axes> = AffineLanes<P, 3>;
    #[inline(always)]
    fn join<P: Axes, const W: usize>(
        maps: &[AffineLanes<Vec3A, 3>; W],
        join: impl Fn([Vec3A; W]) -> P,
    ) -> AffineLanes<P, 3> {
        AffineLanes::join(maps, join)
    }
    #[inline(always)]
    fn simd(&self) -> AffineLanes<Vec3A, 3> {
        let m = &self.matrix3;
        AffineLanes {
            cols: [m.x_axis, m.y_axis, m.z_axis],
            t: self.translation,
        }
    }
}

/// Fields `[m00, m10, m01, m11, t0, t1]`.
impl Fields for Affine2 {
    const FIELDS: usize = 6;
    type Array<C: Send + Sync> = [C; 6];
    #[inline(always)]
    fn array<C: Send + Sync>(f: impl FnMut(usize) -> C) -> Self::Array<C> {
        core::array::from_fn(f)
    }
    const PADDING: Self = Affine2::IDENTITY;
    #[inline(always)]
    fn to_fields(&self) -> [f32; MAX_FIELDS] {
        let m = &self.matrix2;
        let (x, y, t) = (m.x_axis, m.y_axis, self.translation);
        [x.x, x.y, y.x, y.y, t.x, t.y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    }
    #[inline(always)]
    fn from_fields(f: &[f32; MAX_FIELDS]) -> Self {
        let v = |k: usize| Vec2::new(f[k], f[k + 1]);
        Affine2::from_mat2_translation(Mat2::from_cols(v(0), v(2)), v(4))
    }
}

impl Class<2> for Affine2 {
    type Lanes<L: Lane> = AffineLanes<Vector<L, 2>, 2>;
    #[inline(always)]
    fn lanes<L: Lane>(f: &[L; MAX_FIELDS]) -> Self::Lanes<L> {
        AffineLanes {
            cols: [vector_at(f, 0), vector_at(f, 2)],
            t: vector_at(f, 4),
        }
    }
    fn extended(&self) -> ExtendedMap<2> {
        let f = self.to_fields();
        ExtendedMap::exact([[f[0], f[1]], [f[2], f[3]]], [f[4], f[5]])
    }
    fn order(method: Method) -> u32 {
        method.nearest_order(2)
    }
}

impl Transform2 for Affine2 {}
