//! AoSoA blocks: eight boxes or eight transforms per 32-byte-aligned block, one `[f32; 8]`
//! per scalar field, so that a lane block is a handful of aligned vector loads.

use glam::{Affine3A, Mat3A, Vec3A};

use super::{BatchError, BoxSink, BoxSource, MapSource};
use crate::aabb::Aabb3;
use crate::kernel::AffineLanes;
use crate::lane::{Lane, Vector};
use crate::simd::LaneArray;

/// Eight 3D boxes, field by field: `min[axis][box]`, `max[axis][box]` (6 × `[f32; 8]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct Aabb3x8 {
    /// The lower corners, one `[f32; 8]` per axis.
    pub min: [[f32; 8]; 3],
    /// The upper corners, one `[f32; 8]` per axis.
    pub max: [[f32; 8]; 3],
}

/// Eight 3D affine transforms, field by field: `cols[j][i][k]` is entry `m_ij` of
/// transform `k`, `translation[i][k]` its translation (12 × `[f32; 8]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct Affine3x8 {
    /// The columns of the linear parts.
    pub cols: [[[f32; 8]; 3]; 3],
    /// The translations.
    pub translation: [[f32; 8]; 3],
}

impl Aabb3x8 {
    /// Eight empty boxes.
    pub const EMPTY: Self = Self {
        min: [[f32::INFINITY; 8]; 3],
        max: [[f32::NEG_INFINITY; 8]; 3],
    };

    /// Box `k` of the block.
    #[inline]
    #[must_use]
    pub fn get(&self, k: usize) -> Aabb3 {
        Aabb3::new(
            Vec3A::from_array(self.min.map(|a| a[k])),
            Vec3A::from_array(self.max.map(|a| a[k])),
        )
    }

    /// Sets box `k` of the block.
    #[inline]
    pub fn set(&mut self, k: usize, b: Aabb3) {
        for a in 0..3 {
            self.min[a][k] = b.min[a];
            self.max[a][k] = b.max[a];
        }
    }

    /// Packs boxes into blocks, the last one padded with `EMPTY`.
    #[must_use]
    pub fn pack(boxes: &[Aabb3]) -> Vec<Aabb3x8> {
        boxes
            .chunks(8)
            .map(|chunk| {
                let mut block = Self::EMPTY;
                chunk.iter().enumerate().for_each(|(k, &b)| block.set(k, b));
                block
            })
            .collect()
    }

    /// Unpacks the first `len` boxes of the blocks.
    #[must_use]
    pub fn unpack(blocks: &[Aabb3x8], len: usize) -> Vec<Aabb3> {
        (0..len.min(blocks.len() * 8))
            .map(|b| blocks[b / 8].get(b % 8))
            .collect()
    }
}

impl From<[Aabb3; 8]> for Aabb3x8 {
    #[inline]
    fn from(boxes: [Aabb3; 8]) -> Self {
        Self {
            min: core::array::from_fn(|a| boxes.map(|b| b.min[a])),
            max: core::array::from_fn(|a| boxes.map(|b| b.max[a])),
        }
    }
}

impl From<Aabb3x8> for [Aabb3; 8] {
    #[inline]
    fn from(block: Aabb3x8) -> Self {
        core::array::from_fn(|k| block.get(k))
    }
}

impl Affine3x8 {
    /// Eight identity transforms.
    pub const IDENTITY: Self = Self {
        cols: [
            [[1.0; 8], [0.0; 8], [0.0; 8]],
            [[0.0; 8], [1.0; 8], [0.0; 8]],
            [[0.0; 8], [0.0; 8], [1.0; 8]],
        ],
        translation: [[0.0; 8]; 3],
    };

    /// Transform `k` of the block.
    #[inline]
    #[must_use]
    pub fn get(&self, k: usize) -> Affine3A {
        let col = |j: usize| Vec3A::from_array(self.cols[j].map(|a| a[k]));
        Affine3A {
            matrix3: Mat3A::from_cols(col(0), col(1), col(2)),
            translation: Vec3A::from_array(self.translation.map(|a| a[k])),
        }
    }

    /// Sets transform `k` of the block.
    #[inline]
    pub fn set(&mut self, k: usize, xf: &Affine3A) {
        for j in 0..3 {
            for i in 0..3 {
                self.cols[j][i][k] = xf.matrix3.col(j)[i];
            }
        }
        for i in 0..3 {
            self.translation[i][k] = xf.translation[i];
        }
    }

    /// Packs transforms into blocks, the last one padded with identities.
    #[must_use]
    pub fn pack(xfs: &[Affine3A]) -> Vec<Affine3x8> {
        xfs.chunks(8)
            .map(|chunk| {
                let mut block = Self::IDENTITY;
                chunk
                    .iter()
                    .enumerate()
                    .for_each(|(k, xf)| block.set(k, xf));
                block
            })
            .collect()
    }
}

impl From<[Affine3A; 8]> for Affine3x8 {
    #[inline]
    fn from(xfs: [Affine3A; 8]) -> Self {
        let mut block = Self::IDENTITY;
        xfs.iter().enumerate().for_each(|(k, xf)| block.set(k, xf));
        block
    }
}

impl From<Affine3x8> for [Affine3A; 8] {
    #[inline]
    fn from(block: Affine3x8) -> Self {
        core::array::from_fn(|k| block.get(k))
    }
}

/// True when lanes `i..i + count` fill a whole lane block that lies inside one AoSoA
/// block (`i` is a multiple of the lane width, which divides 8): then each field is one
/// vector load. Otherwise (the tail, or 16 lanes spanning two blocks) lanes go one by one.
#[inline(always)]
fn whole<L: LaneArray>(count: usize) -> bool {
    count == L::WIDTH && 8 % L::WIDTH == 0
}

/// Lanes `slot..slot + L::WIDTH` of three fields of a block: three vector loads (a
/// function, not a closure, so that it is always inlined).
#[inline(always)]
fn fields<L: LaneArray>(f: &[[f32; 8]; 3], slot: usize) -> Vector<L, 3> {
    Vector([
        L::load(&f[0][slot..]),
        L::load(&f[1][slot..]),
        L::load(&f[2][slot..]),
    ])
}

impl BoxSource<3> for &[Aabb3x8] {
    fn len(&self) -> Result<usize, BatchError> {
        Ok(<[Aabb3x8]>::len(self) * 8)
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, 3>, Vector<L, 3>) {
        if whole::<L>(count) {
            let (block, slot) = (&self[i / 8], i % 8);
            return (fields(&block.min, slot), fields(&block.max, slot));
        }
        let (mut lo, mut hi) = (Vector::<L, 3>::splat(0.0), Vector::<L, 3>::splat(0.0));
        for k in 0..L::WIDTH {
            if k < count {
                let (block, slot) = (&self[(i + k) / 8], (i + k) % 8);
                for a in 0..3 {
                    lo.0[a].set(k, block.min[a][slot]);
                    hi.0[a].set(k, block.max[a][slot]);
                }
            }
        }
        (lo, hi)
    }
    fn get(&self, i: usize) -> ([f32; 3], [f32; 3]) {
        let b = self[i / 8].get(i % 8);
        (b.min.to_array(), b.max.to_array())
    }
}

impl BoxSink<3> for &mut [Aabb3x8] {
    fn len(&self) -> Result<usize, BatchError> {
        Ok(<[Aabb3x8]>::len(self) * 8)
    }
    #[inline(always)]
    fn store<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        min: Vector<L, 3>,
        max: Vector<L, 3>,
    ) {
        if whole::<L>(count) {
            let (block, slot) = (&mut self[i / 8], i % 8);
            for a in 0..3 {
                min.0[a].store(&mut block.min[a][slot..]);
                max.0[a].store(&mut block.max[a][slot..]);
            }
            return;
        }
        for k in 0..L::WIDTH {
            if k < count {
                let (block, slot) = (&mut self[(i + k) / 8], (i + k) % 8);
                for a in 0..3 {
                    block.min[a][slot] = min.0[a].get(k);
                    block.max[a][slot] = max.0[a].get(k);
                }
            }
        }
    }
    fn set(&mut self, i: usize, min: [f32; 3], max: [f32; 3]) {
        self[i / 8].set(
            i % 8,
            Aabb3::new(Vec3A::from_array(min), Vec3A::from_array(max)),
        );
    }
}

impl MapSource<3> for &[Affine3x8] {
    type Lanes<L: LaneArray> = AffineLanes<Vector<L, 3>, 3>;
    fn len(&self) -> Option<usize> {
        Some(<[Affine3x8]>::len(self) * 8)
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> Self::Lanes<L> {
        if whole::<L>(count) {
            let (block, slot) = (&self[i / 8], i % 8);
            return AffineLanes {
                cols: [
                    fields(&block.cols[0], slot),
                    fields(&block.cols[1], slot),
                    fields(&block.cols[2], slot),
                ],
                t: fields(&block.translation, slot),
            };
        }
        let mut map = AffineLanes {
            cols: [Vector::<L, 3>::splat(0.0); 3],
            t: Vector::splat(0.0),
        };
        for k in 0..L::WIDTH {
            if k < count {
                let (block, slot) = (&self[(i + k) / 8], (i + k) % 8);
                for a in 0..3 {
                    for j in 0..3 {
                        map.cols[j].0[a].set(k, block.cols[j][a][slot]);
                    }
                    map.t.0[a].set(k, block.translation[a][slot]);
                }
            }
        }
        map
    }
    fn get(&self, i: usize) -> ([[f32; 3]; 3], [f32; 3]) {
        let block = &self[i / 8];
        let slot = i % 8;
        (
            block.cols.map(|c| c.map(|row| row[slot])),
            block.translation.map(|row| row[slot]),
        )
    }
}
