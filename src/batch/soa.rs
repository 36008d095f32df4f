//! SoA columns: one `f32` slice per scalar field, the layout of ECS-style storage.

use glam::Affine3A;

use super::{BatchError, BoxSink, BoxSource, MapSource};
use crate::aabb::Aabb3;
use crate::kernel::AffineLanes;
use crate::lane::{Lane, Vector};
use crate::simd::LaneArray;

/// Owned SoA boxes: `min[axis][box]`, `max[axis][box]` (`min[0]` is `min_x`, ...).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AabbSoa {
    /// The lower corners, one column per axis.
    pub min: [Vec<f32>; 3],
    /// The upper corners, one column per axis.
    pub max: [Vec<f32>; 3],
}

/// Borrowed SoA boxes to read; every column must have the same length.
#[derive(Clone, Copy, Debug)]
pub struct AabbSoaRef<'a> {
    /// The lower corners, one column per axis.
    pub min: [&'a [f32]; 3],
    /// The upper corners, one column per axis.
    pub max: [&'a [f32]; 3],
}

/// Borrowed SoA boxes to write; every column must have the same length.
#[derive(Debug)]
pub struct AabbSoaMut<'a> {
    /// The lower corners, one column per axis.
    pub min: [&'a mut [f32]; 3],
    /// The upper corners, one column per axis.
    pub max: [&'a mut [f32]; 3],
}

/// Owned SoA transforms: `cols[j][i][k]` is entry `m_ij` of transform `k`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Affine3Soa {
    /// The columns of the linear parts, one `f32` column per entry.
    pub cols: [[Vec<f32>; 3]; 3],
    /// The translations, one column per axis.
    pub translation: [Vec<f32>; 3],
}

/// Borrowed SoA transforms (twelve columns of the same length).
#[derive(Clone, Copy, Debug)]
pub struct Affine3SoaRef<'a> {
    /// The columns of the linear parts, one `f32` column per entry.
    pub cols: [[&'a [f32]; 3]; 3],
    /// The translations, one column per axis.
    pub translation: [&'a [f32]; 3],
}

impl AabbSoa {
    /// The boxes as columns.
    #[must_use]
    pub fn from_boxes(boxes: &[Aabb3]) -> Self {
        Self {
            min: core::array::from_fn(|a| boxes.iter().map(|b| b.min[a]).collect()),
            max: core::array::from_fn(|a| boxes.iter().map(|b| b.max[a]).collect()),
        }
    }

    /// `len` empty boxes.
    #[must_use]
    pub fn empty(len: usize) -> Self {
        Self {
            min: core::array::from_fn(|_| vec![f32::INFINITY; len]),
            max: core::array::from_fn(|_| vec![f32::NEG_INFINITY; len]),
        }
    }

    /// Box `k`.
    #[must_use]
    pub fn get(&self, k: usize) -> Aabb3 {
        Aabb3::new(
            self.min.each_ref().map(|c| c[k]).into(),
            self.max.each_ref().map(|c| c[k]).into(),
        )
    }

    /// A read view.
    #[must_use]
    pub fn view(&self) -> AabbSoaRef<'_> {
        AabbSoaRef {
            min: self.min.each_ref().map(Vec::as_slice),
            max: self.max.each_ref().map(Vec::as_slice),
        }
    }

    /// A write view.
    #[must_use]
    pub fn view_mut(&mut self) -> AabbSoaMut<'_> {
        AabbSoaMut {
            min: self.min.each_mut().map(Vec::as_mut_slice),
            max: self.max.each_mut().map(Vec::as_mut_slice),
        }
    }
}

impl Affine3Soa {
    /// The transforms as columns.
    #[must_use]
    pub fn from_affines(xfs: &[Affine3A]) -> Self {
        Self {
            cols: core::array::from_fn(|j| {
                core::array::from_fn(|i| xfs.iter().map(|x| x.matrix3.col(j)[i]).collect())
            }),
            translation: core::array::from_fn(|i| xfs.iter().map(|x| x.translation[i]).collect()),
        }
    }

    /// A read view.
    #[must_use]
    pub fn view(&self) -> Affine3SoaRef<'_> {
        Affine3SoaRef {
            cols: self
                .cols
                .each_ref()
                .map(|c| c.each_ref().map(Vec::as_slice)),
            translation: self.translation.each_ref().map(Vec::as_slice),
        }
    }
}

/// The common length of `columns`, or the mismatch of the first that differs.
fn common_len(
    what: &'static str,
    mut columns: impl Iterator<Item = usize>,
) -> Result<usize, BatchError> {
    let first = columns.next().unwrap_or(0);
    match columns.find(|&n| n != first) {
        None => Ok(first),
        Some(found) => Err(BatchError::LengthMismatch {
            what,
            expected: first,
            found,
        }),
    }
}

/// Lanes `i..i + L::WIDTH` of three columns: three vector loads. A function, not a
/// closure: closures in the loaders were left outlined, which stops vectorisation.
#[inline(always)]
fn columns<L: LaneArray>(c: &[&[f32]; 3], i: usize) -> Vector<L, 3> {
    Vector([
        L::load(&c[0][i..]),
        L::load(&c[1][i..]),
        L::load(&c[2][i..]),
    ])
}

impl BoxSource<3> for AabbSoaRef<'_> {
    fn len(&self) -> Result<usize, BatchError> {
        common_len(
            "a column of the local boxes",
            self.min.iter().chain(&self.max).map(|c| c.len()),
        )
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, 3>, Vector<L, 3>) {
        if count == L::WIDTH {
            return (columns(&self.min, i), columns(&self.max, i));
        }
        let (mut lo, mut hi) = (Vector::<L, 3>::splat(0.0), Vector::<L, 3>::splat(0.0));
        for a in 0..3 {
            for k in 0..L::WIDTH {
                if k < count {
                    lo.0[a].set(k, self.min[a][i + k]);
                    hi.0[a].set(k, self.max[a][i + k]);
                }
            }
        }
        (lo, hi)
    }
    fn get(&self, i: usize) -> ([f32; 3], [f32; 3]) {
        (self.min.map(|c| c[i]), self.max.map(|c| c[i]))
    }
}

impl BoxSink<3> for AabbSoaMut<'_> {
    fn len(&self) -> Result<usize, BatchError> {
        common_len(
            "a column of the output",
            self.min.iter().chain(&self.max).map(|c| c.len()),
        )
    }
    #[inline(always)]
    fn store<L: LaneArray>(
        &mut self,
        i: usize,
        count: usize,
        min: Vector<L, 3>,
        max: Vector<L, 3>,
    ) {
        if count == L::WIDTH {
            for a in 0..3 {
                min.0[a].store(&mut self.min[a][i..]);
                max.0[a].store(&mut self.max[a][i..]);
            }
            return;
        }
        for a in 0..3 {
            for k in 0..L::WIDTH {
                if k < count {
                    self.min[a][i + k] = min.0[a].get(k);
                    self.max[a][i + k] = max.0[a].get(k);
                }
            }
        }
    }
    fn set(&mut self, i: usize, min: [f32; 3], max: [f32; 3]) {
        for a in 0..3 {
            self.min[a][i] = min[a];
            self.max[a][i] = max[a];
        }
    }
}

impl MapSource<3> for Affine3SoaRef<'_> {
    type Lanes<L: LaneArray> = AffineLanes<Vector<L, 3>, 3>;
    fn len(&self) -> Option<usize> {
        // A transform column of another length is reported as that length.
        let mut lens = self
            .cols
            .iter()
            .flatten()
            .chain(&self.translation)
            .map(|c| c.len());
        let first = lens.next().unwrap_or(0);
        Some(lens.find(|&n| n != first).unwrap_or(first))
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> Self::Lanes<L> {
        if count == L::WIDTH {
            return AffineLanes {
                cols: [
                    columns(&self.cols[0], i),
                    columns(&self.cols[1], i),
                    columns(&self.cols[2], i),
                ],
                t: columns(&self.translation, i),
            };
        }
        let mut map = AffineLanes {
            cols: [Vector::<L, 3>::splat(0.0); 3],
            t: Vector::splat(0.0),
        };
        for a in 0..3 {
            for k in 0..L::WIDTH {
                if k < count {
                    for j in 0..3 {
                        map.cols[j].0[a].set(k, self.cols[j][a][i + k]);
                    }
                    map.t.0[a].set(k, self.translation[a][i + k]);
                }
            }
        }
        map
    }
    fn get(&self, i: usize) -> ([[f32; 3]; 3], [f32; 3]) {
        (
            self.cols.map(|c| c.map(|row| row[i])),
            self.translation.map(|row| row[i]),
        )
    }
}
