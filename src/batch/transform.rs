//! [`Batch::transform`]: the engine with every object active and the plain sink, or, for AoS
//! 3D layouts, the AoS runs compiled here once per class.

use super::PoseSource;
use super::{AosLayouts, Batch, checked_len};
use crate::aabb::Aabb3;
use crate::engine::{Active, AosPoses, AosRun, ClassJob, Engine, Store, takes_aos};
use crate::error::BatchError;
use crate::layout::{BoxSink, BoxSource, Maps};
use crate::transform::Transform3;

impl Batch {
    /// `out[k] = local[k]` through pose `k` (or the shared pose) for every `k`: every
    /// layout, every transform class, in 3D and 2D; and the union of the boxes at two poses
    /// ([`Swept`](crate::Swept)) or boxes relative to an `f64` origin
    /// ([`LargeWorld`](crate::LargeWorld)), as the update takes them.
    ///
    /// # Errors
    /// [`BatchError::LengthMismatch`] unless the boxes, the poses (unless shared) and
    /// the output have the same length, and the columns of a SoA layout agree; `out` is
    /// then untouched.
    pub fn transform<const N: usize>(
        &self,
        local: impl BoxSource<N>,
        xf: impl PoseSource<N>,
        mut out: impl BoxSink<N>,
    ) -> Result<(), BatchError> {
        let len = checked_len(&local, &xf, &mut out)?;
        self.transform_checked(local, xf, out, len);
        Ok(())
    }

    /// [`Batch::transform`], its lengths checked: the layouts pick the loop when the call
    /// site is compiled, so that AoS 3D layouts compile no lane loop there and call code
    /// compiled once in bvkit.
    #[inline(always)]
    fn transform_checked<const N: usize, B: BoxSource<N>, X: PoseSource<N>, O: BoxSink<N>>(
        &self,
        local: B,
        xf: X,
        mut out: O,
        len: usize,
    ) {
        if AosLayouts::<N, B, X, O>::ALL {
            let (Some(local), Some(poses), Some(out)) =
                (local.aabb3s(), xf.aos(), out.aabb3s_mut())
            else {
                unreachable!("AoS 3D layouts always convert (a test checks every layout)");
            };
            self.transform_aos(local, poses, out);
        } else {
            self.transform_lanes(local, xf, out, len);
        }
    }

    /// [`Batch::transform`] in the lane loop, its lengths checked.
    #[inline(always)]
    fn transform_lanes<const N: usize>(
        &self,
        local: impl BoxSource<N>,
        xf: impl PoseSource<N>,
        out: impl BoxSink<N>,
        len: usize,
    ) {
        let engine = Engine {
            local,
            poses: xf,
            sink: Store {
                out,
                stream: len.saturating_mul(2 * N * size_of::<f32>()) > Self::NON_TEMPORAL_BYTES,
            },
            len,
            active: Active::All,
            method: self.method,
            rounding: self.rounding,
        };
        engine.run_every(self.backend, !self.deterministic);
    }

    /// [`Batch::transform`] of AoS 3D boxes with AoS or shared poses, lengths checked:
    /// compiled here once per class, for every call site.
    #[inline(never)]
    fn transform_aos(&self, local: &[Aabb3], poses: AosPoses<'_>, out: &mut [Aabb3]) {
        /// The transform of one class.
        struct Job<'b, 'o> {
            batch: &'b Batch,
            local: &'b [Aabb3],
            out: &'o mut [Aabb3],
        }
        impl<'a> ClassJob<'a> for Job<'_, '_> {
            fn run<T: Transform3>(self, maps: Maps<'a, T>) {
                let Job { batch, local, out } = self;
                if takes_aos(batch.backend) {
                    let run = AosRun {
                        local,
                        sink: out,
                        active: Active::All,
                        method: batch.method,
                        rounding: batch.rounding,
                    };
                    return run.run_every(maps, batch.backend);
                }
                let len = local.len();
                match maps {
                    Maps::Each(poses) => batch.transform_lanes(local, poses, out, len),
                    Maps::Shared(pose) => batch.transform_lanes(local, pose, out, len),
                }
            }
        }
        poses.run(Job {
            batch: self,
            local,
            out,
        });
    }
}
