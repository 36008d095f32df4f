//! AoS slices (`&[Aabb3]`, `&[Affine3A]`, 2D `&[Aabb2]`, `&[Affine2]`, `&[Rigid2]`) and
//! shared transforms, as lanes.
//!
//! Loaders run over every lane with a constant index (`k < count` masks the tail), so
//! that the lane arrays stay in registers and the main loop, where `count` is the lane
//! width, has no mask at all.

use glam::{Affine2, Affine3A, Vec2, Vec3A};

use super::{BatchError, BoxSink, BoxSource, MapSource};
use crate::aabb::{Aabb2, Aabb3};
use crate::block::{Rigid2Lanes, splat};
use crate::kernel::AffineLanes;
use crate::lane::{Lane, Vector};
use crate::rigid2::Rigid2;
use crate::simd::LaneArray;

impl BoxSource<3> for &[Aabb3] {
    fn len(&self) -> Result<usize, BatchError> {
        Ok(<[Aabb3]>::len(self))
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, 3>, Vector<L, 3>) {
        let (mut lo, mut hi) = (Vector::<L, 3>::splat(0.0), Vector::<L, 3>::splat(0.0));
        for k in 0..L::WIDTH {
            if k < count {
                let b = &self[i + k];
                for a in 0..3 {
                    lo.0[a].set(k, b.min[a]);
                    hi.0[a].set(k, b.max[a]);
                }
            }
        }
        (lo, hi)
    }
    fn get(&self, i: usize) -> ([f32; 3], [f32; 3]) {
        (self[i].min.to_array(), self[i].max.to_array())
    }
}

impl BoxSink<3> for &mut [Aabb3] {
    fn len(&self) -> Result<usize, BatchError> {
        Ok(<[Aabb3]>::len(self))
    }
    #[inline(always)]
    fn store<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        min: Vector<L, 3>,
        max: Vector<L, 3>,
    ) {
        for k in 0..L::WIDTH {
            if k < count {
                let lane =
                    |v: &Vector<L, 3>| Vec3A::new(v.0[0].get(k), v.0[1].get(k), v.0[2].get(k));
                self[i + k] = Aabb3::new(lane(&min), lane(&max));
            }
        }
    }
    fn set(&mut self, i: usize, min: [f32; 3], max: [f32; 3]) {
        self[i] = Aabb3::new(Vec3A::from_array(min), Vec3A::from_array(max));
    }
}

impl MapSource<3> for &[Affine3A] {
    type Lanes<L: LaneArray> = AffineLanes<Vector<L, 3>, 3>;
    fn len(&self) -> Option<usize> {
        Some(<[Affine3A]>::len(self))
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> Self::Lanes<L> {
        let mut map = AffineLanes {
            cols: [Vector::<L, 3>::splat(0.0); 3],
            t: Vector::splat(0.0),
        };
        for k in 0..L::WIDTH {
            if k < count {
                let xf = &self[i + k];
                for a in 0..3 {
                    for j in 0..3 {
                        map.cols[j].0[a].set(k, xf.matrix3.col(j)[a]);
                    }
                    map.t.0[a].set(k, xf.translation[a]);
                }
            }
        }
        map
    }
    fn get(&self, i: usize) -> ([[f32; 3]; 3], [f32; 3]) {
        affine3_parts(&self[i])
    }
}

fn affine3_parts(xf: &Affine3A) -> ([[f32; 3]; 3], [f32; 3]) {
    let m = &xf.matrix3;
    (
        [
            m.x_axis.to_array(),
            m.y_axis.to_array(),
            m.z_axis.to_array(),
        ],
        xf.translation.to_array(),
    )
}

impl MapSource<3> for &Affine3A {
    type Lanes<L: LaneArray> = AffineLanes<Vector<L, 3>, 3>;
    fn len(&self) -> Option<usize> {
        None
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, _: usize, _: usize) -> Self::Lanes<L> {
        let col = |c: Vec3A| Vector([splat(c.x), splat(c.y), splat(c.z)]);
        AffineLanes {
            cols: [
                col(self.matrix3.x_axis),
                col(self.matrix3.y_axis),
                col(self.matrix3.z_axis),
            ],
            t: col(self.translation),
        }
    }
    fn get(&self, _: usize) -> ([[f32; 3]; 3], [f32; 3]) {
        affine3_parts(self)
    }
}

impl BoxSource<2> for &[Aabb2] {
    fn len(&self) -> Result<usize, BatchError> {
        Ok(<[Aabb2]>::len(self))
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, 2>, Vector<L, 2>) {
        let (mut lo, mut hi) = (Vector::<L, 2>::splat(0.0), Vector::<L, 2>::splat(0.0));
        for k in 0..L::WIDTH {
            if k < count {
                let b = &self[i + k];
                for a in 0..2 {
                    lo.0[a].set(k, b.min[a]);
                    hi.0[a].set(k, b.max[a]);
                }
            }
        }
        (lo, hi)
    }
    fn get(&self, i: usize) -> ([f32; 2], [f32; 2]) {
        (self[i].min.to_array(), self[i].max.to_array())
    }
}

impl BoxSink<2> for &mut [Aabb2] {
    fn len(&self) -> Result<usize, BatchError> {
        Ok(<[Aabb2]>::len(self))
    }
    #[inline(always)]
    fn store<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        min: Vector<L, 2>,
        max: Vector<L, 2>,
    ) {
        for k in 0..L::WIDTH {
            if k < count {
                let lane = |v: &Vector<L, 2>| Vec2::new(v.0[0].get(k), v.0[1].get(k));
                self[i + k] = Aabb2::new(lane(&min), lane(&max));
            }
        }
    }
    fn set(&mut self, i: usize, min: [f32; 2], max: [f32; 2]) {
        self[i] = Aabb2::new(Vec2::from_array(min), Vec2::from_array(max));
    }
}

impl MapSource<2> for &[Affine2] {
    type Lanes<L: LaneArray> = AffineLanes<Vector<L, 2>, 2>;
    fn len(&self) -> Option<usize> {
        Some(<[Affine2]>::len(self))
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> Self::Lanes<L> {
        let mut map = AffineLanes {
            cols: [Vector::<L, 2>::splat(0.0); 2],
            t: Vector::splat(0.0),
        };
        for k in 0..L::WIDTH {
            if k < count {
                let xf = &self[i + k];
                for a in 0..2 {
                    for j in 0..2 {
                        map.cols[j].0[a].set(k, xf.matrix2.col(j)[a]);
                    }
                    map.t.0[a].set(k, xf.translation[a]);
                }
            }
        }
        map
    }
    fn get(&self, i: usize) -> ([[f32; 2]; 2], [f32; 2]) {
        affine2_parts(&self[i])
    }
}

fn affine2_parts(xf: &Affine2) -> ([[f32; 2]; 2], [f32; 2]) {
    (
        [xf.matrix2.x_axis.to_array(), xf.matrix2.y_axis.to_array()],
        xf.translation.to_array(),
    )
}

impl MapSource<2> for &Affine2 {
    type Lanes<L: LaneArray> = AffineLanes<Vector<L, 2>, 2>;
    fn len(&self) -> Option<usize> {
        None
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, _: usize, _: usize) -> Self::Lanes<L> {
        let col = |c: Vec2| Vector([splat(c.x), splat(c.y)]);
        AffineLanes {
            cols: [col(self.matrix2.x_axis), col(self.matrix2.y_axis)],
            t: col(self.translation),
        }
    }
    fn get(&self, _: usize) -> ([[f32; 2]; 2], [f32; 2]) {
        affine2_parts(self)
    }
}

fn rigid2_parts(xf: &Rigid2) -> ([[f32; 2]; 2], [f32; 2]) {
    (
        [[xf.cos, xf.sin], [-xf.sin, xf.cos]],
        xf.translation.to_array(),
    )
}

impl MapSource<2> for &[Rigid2] {
    type Lanes<L: LaneArray> = Rigid2Lanes<L>;
    fn len(&self) -> Option<usize> {
        Some(<[Rigid2]>::len(self))
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> Self::Lanes<L> {
        let zero: L = splat(0.0);
        let mut map = Rigid2Lanes {
            cos: zero,
            sin: zero,
            t: [zero; 2],
        };
        for k in 0..L::WIDTH {
            if k < count {
                let xf = &self[i + k];
                map.cos.set(k, xf.cos);
                map.sin.set(k, xf.sin);
                map.t[0].set(k, xf.translation.x);
                map.t[1].set(k, xf.translation.y);
            }
        }
        map
    }
    fn get(&self, i: usize) -> ([[f32; 2]; 2], [f32; 2]) {
        rigid2_parts(&self[i])
    }
}

impl MapSource<2> for &Rigid2 {
    type Lanes<L: LaneArray> = Rigid2Lanes<L>;
    fn len(&self) -> Option<usize> {
        None
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, _: usize, _: usize) -> Self::Lanes<L> {
        Rigid2Lanes {
            cos: splat(self.cos),
            sin: splat(self.sin),
            t: [splat(self.translation.x), splat(self.translation.y)],
        }
    }
    fn get(&self, _: usize) -> ([[f32; 2]; 2], [f32; 2]) {
        rigid2_parts(self)
    }
}
