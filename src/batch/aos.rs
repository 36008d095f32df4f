//! AoS slices (`&[Aabb3]`, `&[Affine3A]`, 2D `&[Aabb2]`, `&[Affine2]`, `&[Rigid2]`) and
//! shared transforms, as lanes.

use glam::{Affine2, Affine3A, Vec2, Vec3A};

use super::{BatchError, BoxSink, BoxSource, MapSource};
use crate::aabb::{Aabb2, Aabb3};
use crate::block::{Rigid2Lanes, gather, splat};
use crate::kernel::AffineLanes;
use crate::lane::Vector;
use crate::rigid2::Rigid2;
use crate::simd::LaneArray;

impl BoxSource<3> for &[Aabb3] {
    fn len(&self) -> Result<usize, BatchError> {
        Ok(<[Aabb3]>::len(self))
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, 3>, Vector<L, 3>) {
        (
            Vector(core::array::from_fn(|a| {
                gather(i, count, |b| self[b].min[a])
            })),
            Vector(core::array::from_fn(|a| {
                gather(i, count, |b| self[b].max[a])
            })),
        )
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
        for (k, out) in self[i..i + count].iter_mut().enumerate() {
            let lane = |v: &Vector<L, 3>| Vec3A::from_array(v.0.map(|x| x.get(k)));
            *out = Aabb3::new(lane(&min), lane(&max));
        }
    }
}

impl MapSource<3> for &[Affine3A] {
    type Lanes<L: LaneArray> = AffineLanes<Vector<L, 3>, 3>;
    fn len(&self) -> Option<usize> {
        Some(<[Affine3A]>::len(self))
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> Self::Lanes<L> {
        AffineLanes {
            cols: core::array::from_fn(|j| {
                Vector(core::array::from_fn(|a| {
                    gather(i, count, |b| self[b].matrix3.col(j)[a])
                }))
            }),
            t: Vector(core::array::from_fn(|a| {
                gather(i, count, |b| self[b].translation[a])
            })),
        }
    }
}

impl MapSource<3> for &Affine3A {
    type Lanes<L: LaneArray> = AffineLanes<Vector<L, 3>, 3>;
    fn len(&self) -> Option<usize> {
        None
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, _: usize, _: usize) -> Self::Lanes<L> {
        AffineLanes {
            cols: core::array::from_fn(|j| Vector(self.matrix3.col(j).to_array().map(splat))),
            t: Vector(self.translation.to_array().map(splat)),
        }
    }
}

impl BoxSource<2> for &[Aabb2] {
    fn len(&self) -> Result<usize, BatchError> {
        Ok(<[Aabb2]>::len(self))
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, 2>, Vector<L, 2>) {
        (
            Vector(core::array::from_fn(|a| {
                gather(i, count, |b| self[b].min[a])
            })),
            Vector(core::array::from_fn(|a| {
                gather(i, count, |b| self[b].max[a])
            })),
        )
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
        for (k, out) in self[i..i + count].iter_mut().enumerate() {
            let lane = |v: &Vector<L, 2>| Vec2::from_array(v.0.map(|x| x.get(k)));
            *out = Aabb2::new(lane(&min), lane(&max));
        }
    }
}

impl MapSource<2> for &[Affine2] {
    type Lanes<L: LaneArray> = AffineLanes<Vector<L, 2>, 2>;
    fn len(&self) -> Option<usize> {
        Some(<[Affine2]>::len(self))
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> Self::Lanes<L> {
        AffineLanes {
            cols: core::array::from_fn(|j| {
                Vector(core::array::from_fn(|a| {
                    gather(i, count, |b| self[b].matrix2.col(j)[a])
                }))
            }),
            t: Vector(core::array::from_fn(|a| {
                gather(i, count, |b| self[b].translation[a])
            })),
        }
    }
}

impl MapSource<2> for &Affine2 {
    type Lanes<L: LaneArray> = AffineLanes<Vector<L, 2>, 2>;
    fn len(&self) -> Option<usize> {
        None
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, _: usize, _: usize) -> Self::Lanes<L> {
        AffineLanes {
            cols: core::array::from_fn(|j| Vector(self.matrix2.col(j).to_array().map(splat))),
            t: Vector(self.translation.to_array().map(splat)),
        }
    }
}

impl MapSource<2> for &[Rigid2] {
    type Lanes<L: LaneArray> = Rigid2Lanes<L>;
    fn len(&self) -> Option<usize> {
        Some(<[Rigid2]>::len(self))
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> Self::Lanes<L> {
        Rigid2Lanes {
            cos: gather(i, count, |b| self[b].cos),
            sin: gather(i, count, |b| self[b].sin),
            t: core::array::from_fn(|a| gather(i, count, |b| self[b].translation[a])),
        }
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
            t: self.translation.to_array().map(splat),
        }
    }
}
