//! The runs bvkit compiles once, in itself ([`Route`]): a generic call site hands its
//! boxes, poses and output over by name ([`Boxes3`], [`Named3`], the sink's output), and
//! compiles a call rather than the loops.

use super::{Active, AosCall, AosSink, Engine, Fat, PoseSource, Store};
#[cfg(doc)]
use crate::layout::Route;
use crate::layout::{Aabb3x8, AabbSoaMut, BoxSource, Boxes3, Rigid3SoaRef};
use crate::method::{Method, Rounding};
use crate::simd::Backend;
use crate::transform::Named3;

/// A run on a [`Route`], its lengths and its active set checked, with its boxes and poses
/// by name: what the engine hands to its sink ([`super::Sink::run_named`]), which adds
/// itself by name and calls [`NamedCall::aos`] or [`NamedCall::blocks`].
#[derive(Clone, Copy)]
pub(crate) struct NamedCall<'a> {
    /// The local boxes.
    pub local: Boxes3<'a>,
    /// The poses (a [`Swept`](crate::Swept) pair's current ones).
    pub poses: Named3<'a>,
    /// A [`Swept`](crate::Swept) pair's predicted poses ([`Route::Swept`]).
    pub predicted: Option<Named3<'a>>,
    /// The objects visited.
    pub active: Active<'a>,
    /// The method.
    pub method: Method,
    /// The rounding.
    pub rounding: Rounding,
    /// The backend.
    pub backend: Backend,
    /// The lanes may fuse multiply-adds.
    pub fused: bool,
}

/// The sinks of a route of the lane loop ([`Route::Blocks`]): the plain sink or the fat
/// sink over output `O`.
pub(crate) enum LaneSink<'a, O> {
    /// Every tight box written.
    Store(Store<O>),
    /// Each tight box compared with its fat box.
    Fat(Fat<'a, O>),
}

impl NamedCall<'_> {
    /// [`Route::Aos`] into `sink`: the AoS loop with the poses' class, or on the scalar
    /// backend the lane loop ([`AosCall::run`]); on [`Route::Swept`], that at each pose
    /// and the union ([`AosCall::swept`]). Neither generic nor inlined, so that it is
    /// compiled once, in bvkit, for the five classes and both sinks.
    #[inline(never)]
    pub fn aos(self, sink: AosSink<'_>) {
        let Boxes3::Aos(local) = self.local else {
            unreachable!("AoS boxes name themselves so (a test checks every layout)");
        };
        let call = AosCall {
            local,
            poses: self.poses,
            active: self.active,
            method: self.method,
            rounding: self.rounding,
            backend: self.backend,
        };
        match self.predicted {
            None => call.run(sink),
            Some(predicted) => call.swept(predicted, sink),
        }
    }

    /// [`Route::Blocks`] into `sink`: the lane loop over AoSoA blocks of boxes and of rigid
    /// poses, on every backend. Compiled once, in bvkit, as [`NamedCall::aos`] is.
    #[inline(never)]
    pub fn blocks(self, sink: LaneSink<'_, &mut [Aabb3x8]>) {
        let (Boxes3::Blocks(local), Named3::Rigid3x8(poses)) = (self.local, self.poses) else {
            unreachable!("blocks of boxes and of rigid poses name themselves so (tested)");
        };
        match sink {
            LaneSink::Store(sink) => self.lanes(local, poses, local.len() * 8, sink),
            LaneSink::Fat(sink) => self.lanes(local, poses, local.len() * 8, sink),
        }
    }

    /// [`Route::Soa`] into `sink`: the lane loop over columns of boxes and of rigid poses,
    /// on every backend, in a transform. Compiled once, in bvkit, as [`NamedCall::aos`]
    /// is. An update's fat sink over columns has no route: its walks would have cost the
    /// library 75K lines of IR (607,114 against 531,692), past its budget.
    #[inline(never)]
    pub fn soa(self, sink: Store<AabbSoaMut<'_>>) {
        let (Boxes3::Soa(local), Named3::Rigid3Soa(poses)) = (self.local, self.poses) else {
            unreachable!("columns of boxes and of rigid poses name themselves so (tested)");
        };
        let len = local.columns[0].len();
        self.lanes(local, Rigid3SoaRef::new(poses), len, sink);
    }

    /// The lane loop over `len` objects into `sink`.
    fn lanes<B: BoxSource<3>, P: PoseSource<3>>(
        self,
        local: B,
        poses: P,
        len: usize,
        sink: impl super::Sink<3>,
    ) {
        let engine = Engine {
            local,
            poses,
            sink,
            len,
            active: self.active,
            method: self.method,
            rounding: self.rounding,
        };
        engine.run_lanes(self.backend, self.fused);
    }
}
