//! [`Batch::transform`]: the engine with every object active and the plain sink.

use super::{Batch, checked_len};
use crate::engine::{Active, Engine, PoseSource, Store};
use crate::error::BatchError;
use crate::layout::{BoxSink, BoxSource};

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
        poses: impl PoseSource<N>,
        mut out: impl BoxSink<N>,
    ) -> Result<(), BatchError> {
        let len = checked_len(&local, &poses, &mut out)?;
        let engine = Engine {
            local,
            poses,
            sink: Store {
                out,
                stream: len.saturating_mul(2 * N * size_of::<f32>()) > Self::NON_TEMPORAL_BYTES,
            },
            len,
            active: Active::All,
            method: self.method,
            rounding: self.rounding,
        };
        engine.run(self.backend, !self.deterministic);
        Ok(())
    }
}
