//! Parallel batches on the rayon pool (feature `rayon`).
//!
//! The output is split into parts of whole spans (and whole AoSoA blocks); each part runs the serial batch on
//! a window of the inputs. Every box is computed by the same code whichever part it falls
//! in (the tail runs in one lane of the same arithmetic), so the result is bit-identical
//! to [`Batch::transform`] on the same backend. An update's parts start on whole words of
//! 64 objects, so that each takes its window of the active set as it is (a mask's words, a
//! list's entries rebased), and their moved sets join in part order into the serial one.

use alloc::vec::Vec;
use rayon::prelude::*;

use super::update::check_update;
use super::{Batch, checked_len};
use crate::engine::{Active, PoseSource, window};
use crate::error::BatchError;
use crate::fat::{Margin, Moved};
use crate::lane::Vector;
use crate::layout::{BoxSink, BoxSource, Named, NamedBoxes, NamedPoses, Route};
use crate::method::{Method, Rounding};
use crate::simd::LaneArray;

/// The fewest boxes a part gets: below this the pool's overhead outweighs the work.
const MIN_PART: usize = 4096;

/// Items `start..start + len` of a source.
struct Window<'a, S> {
    src: &'a S,
    start: usize,
    len: usize,
}

impl<S> Clone for Window<'_, S> {
    fn clone(&self) -> Self {
        Self { ..*self }
    }
}

impl<const N: usize, S: BoxSource<N>> BoxSource<N> for Window<'_, S> {
    fn len(&self) -> Result<usize, BatchError> {
        Ok(self.len)
    }
    #[inline(always)]
    fn load<L: LaneArray>(&self, i: usize, count: usize) -> (Vector<L, N>, Vector<L, N>) {
        self.src.load(self.start + i, count)
    }
    fn get(&self, i: usize) -> ([f32; N], [f32; N]) {
        self.src.get(self.start + i)
    }
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, _: usize) -> Self {
        self
    }
}

/// A window keeps the AoS routes (its boxes or poses AoS, or a `Swept` pair of AoS poses):
/// its items by name are the source's, cut to the window with a checked `get` (the window
/// always lies inside: its range was split from the source's checked length).
impl<S: Named> Named for Window<'_, S> {
    const ROUTE: Route = match S::ROUTE {
        Route::Aos => Route::Aos,
        Route::Swept => Route::Swept,
        _ => Route::Generic,
    };
    #[inline(always)]
    fn named_boxes(&self) -> Option<NamedBoxes<'_>> {
        match self.src.named_boxes()? {
            NamedBoxes::Aos(boxes) => Some(NamedBoxes::Aos(
                boxes.get(self.start..self.start.checked_add(self.len)?)?,
            )),
            NamedBoxes::Blocks(_) | NamedBoxes::Soa(_) | NamedBoxes::Aos2(_) => None,
        }
    }
    #[inline(always)]
    fn named_poses(&self) -> Option<NamedPoses<'_>> {
        self.cut(self.src.named_poses()?)
    }
    #[inline(always)]
    fn named_predicted(&self) -> Option<NamedPoses<'_>> {
        self.cut(self.src.named_predicted()?)
    }
}

impl<S> Window<'_, S> {
    /// The window's part of AoS poses by name (any other name has no route in a part).
    fn cut<'p>(&self, poses: NamedPoses<'p>) -> Option<NamedPoses<'p>> {
        match poses {
            NamedPoses::Aos(poses) => window(poses, self.start, self.len).map(NamedPoses::Aos),
            NamedPoses::Blocks(_) | NamedPoses::Soa(_) | NamedPoses::Aos2(_) => None,
        }
    }
}

impl<const N: usize, S: PoseSource<N>> PoseSource<N> for Window<'_, S> {
    // The whole source's length was checked.
    fn check_len(&self, _: usize) -> Result<(), BatchError> {
        Ok(())
    }
    #[inline(always)]
    fn tight<L: LaneArray>(
        &self,
        i: usize,
        count: usize,
        lo: Vector<L, N>,
        hi: Vector<L, N>,
        method: Method,
        outward: bool,
    ) -> (Vector<L, N>, Vector<L, N>, L) {
        self.src
            .tight(self.start + i, count, lo, hi, method, outward)
    }
    fn tight_one(
        &self,
        i: usize,
        lo: [f32; N],
        hi: [f32; N],
        method: Method,
        rounding: Rounding,
    ) -> [[f32; N]; 2] {
        self.src.tight_one(self.start + i, lo, hi, method, rounding)
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        self.src.prefetch(self.start + i);
    }
    const LANES: bool = S::LANES;
    type Trimmed = Self;
    #[inline(always)]
    fn trim(self, _: usize) -> Self {
        self
    }
}

impl Batch {
    /// [`Batch::transform`] on the rayon pool: the same checks, and bit-identical results
    /// (on the same backend, in either mode). Parts are at least 4096 boxes, about four per
    /// thread, so a small batch runs on the calling thread.
    ///
    /// # Errors
    /// As [`Batch::transform`]; `out` is then untouched.
    pub fn transform_par<const N: usize, B, X, O>(
        &self,
        local: B,
        poses: X,
        mut out: O,
    ) -> Result<(), BatchError>
    where
        B: BoxSource<N> + Sync,
        X: PoseSource<N> + Sync,
        O: BoxSink<N>,
    {
        let len = checked_len(&local, &poses, &mut out)?;
        let parts_wanted = 4 * rayon::current_num_threads();
        let chunk = len
            .div_ceil(parts_wanted)
            .max(MIN_PART)
            .next_multiple_of(16);
        out.parts(chunk)
            .into_par_iter()
            .enumerate()
            .try_for_each(|(k, part)| {
                let start = k * chunk;
                let len = chunk.min(len - start);
                self.transform(
                    Window {
                        src: &local,
                        start,
                        len,
                    },
                    Window {
                        src: &poses,
                        start,
                        len,
                    },
                    part,
                )
            })
    }
}

impl Batch {
    /// [`Batch::update`] on the rayon pool: the same checks, and the same fat boxes and moved
    /// set (bit-identical, on the same backend, in either mode). Parts are at least 4096
    /// objects, about four per thread, so a small scene runs on the calling thread.
    ///
    /// # Errors
    /// As [`Batch::update`]; `fat` and `moved` are then untouched.
    pub fn update_par<const N: usize, B, X, O>(
        &self,
        margin: Margin,
        active: Active<'_>,
        local: B,
        poses: X,
        mut fat: O,
        moved: &mut Moved,
    ) -> Result<(), BatchError>
    where
        B: BoxSource<N> + Sync,
        X: PoseSource<N> + Sync,
        O: BoxSink<N>,
    {
        let len = check_update(margin, active, &local, &poses, &mut fat)?;
        let parts_wanted = 4 * rayon::current_num_threads();
        let chunk = len
            .div_ceil(parts_wanted)
            .max(MIN_PART)
            .next_multiple_of(64);
        let parts: Vec<Moved> = fat
            .parts(chunk)
            .into_par_iter()
            .enumerate()
            .map(|(k, part)| {
                let start = k * chunk;
                let len = chunk.min(len - start);
                let mut found = Moved::new();
                // The part's window of the active set: a list's entries in it, rebased.
                let list: Vec<u32>;
                let active = match active {
                    Active::All => Active::All,
                    Active::Mask(words) => {
                        Active::Mask(&words[start / 64..(start + len).div_ceil(64)])
                    }
                    Active::Indices(ix) => {
                        let (lo, hi) = (start as u32, (start + len) as u64);
                        let first = ix.partition_point(|&i| i < lo);
                        let end = ix.partition_point(|&i| u64::from(i) < hi);
                        list = ix[first..end].iter().map(|&i| i - lo).collect();
                        Active::Indices(&list)
                    }
                };
                // The checks above passed for the whole scene, so they pass for each part:
                // no part fails after another has written.
                let local = Window {
                    src: &local,
                    start,
                    len,
                };
                let poses = Window {
                    src: &poses,
                    start,
                    len,
                };
                self.update(margin, active, local, poses, part, &mut found)
                    .map(|()| found)
            })
            .collect::<Result<_, _>>()?;
        moved.reset(len);
        for (k, part) in parts.iter().enumerate() {
            moved.append(k * chunk, part);
        }
        Ok(())
    }
}
