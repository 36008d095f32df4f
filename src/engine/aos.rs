//! The AoS loop of 3D boxes: each box as glam stores it, through the single-box kernel.
//!
//! Gathering AoS boxes and transforms into one-field-per-register lanes costs a shuffle per
//! field per box, more than the kernel itself (measured in `docs/speed.md`). So `&[Aabb3]`
//! boxes with AoS or shared transforms run [`Aabb3::transformed`] on every active box, on
//! glam's `Vec3A`: the same bits as the single-box calls on every SIMD backend (never
//! fused on a default build), and the same contract, the extended path included.

use super::Active;
use super::active::{Lookahead, Spans};
use crate::aabb::Aabb3;
use crate::layout::Maps;
use crate::method::{Method, Rounding};
use crate::simd::{self, Backend};
use crate::transform::{Simd3Job, Transform3};

/// The objects of one step of the AoS loop: a mask word's worth.
const SPAN: usize = 64;

/// Where the AoS loop's tight boxes go.
pub(crate) trait AosSink {
    /// The objects `start..start + count`, of which the `lanes` bits are active: object
    /// `start + k`'s tight box is `tight(k)`, computed where the sink asks for it.
    fn span(&mut self, start: usize, count: usize, lanes: u64, tight: impl Fn(usize) -> Aabb3);
    /// Asks for object `i`'s output ahead of a scattered access.
    fn prefetch(&self, i: usize);
}

/// The plain AoS sink: every tight box written.
impl AosSink for &mut [Aabb3] {
    #[inline(always)]
    fn span(&mut self, start: usize, count: usize, lanes: u64, tight: impl Fn(usize) -> Aabb3) {
        let out = &mut self[start..start + count];
        if lanes.count_ones() as usize == count {
            for (k, o) in out.iter_mut().enumerate() {
                *o = tight(k);
            }
        } else {
            let mut bits = lanes;
            while bits != 0 {
                let k = bits.trailing_zeros() as usize;
                out[k] = tight(k);
                bits &= bits - 1;
            }
        }
    }
    fn prefetch(&self, i: usize) {
        simd::prefetch(&self[i]);
    }
}

/// A run of the AoS loop, its lengths and its active set checked: everything but the
/// poses, which the pose source adds ([`AosRun::with`]).
pub(crate) struct AosRun<'a, S> {
    /// The local boxes.
    pub local: &'a [Aabb3],
    /// Where the tight boxes go.
    pub sink: S,
    /// The objects visited.
    pub active: Active<'a>,
    /// The method.
    pub method: Method,
    /// The rounding.
    pub rounding: Rounding,
}

impl<'a, S> AosRun<'a, S> {
    /// The run with its poses, one per object or shared.
    pub fn with<T>(self, maps: Maps<'a, T>) -> AosOn<'a, T, S> {
        AosOn { run: self, maps }
    }
}

/// An [`AosRun`] with its poses, as a job for the class's single-box kernel.
pub(crate) struct AosOn<'a, T, S> {
    run: AosRun<'a, S>,
    maps: Maps<'a, T>,
}

impl<T, S: AosSink> Simd3Job<T> for AosOn<'_, T, S> {
    fn run(self, backend: Backend) -> bool
    where
        T: Transform3,
    {
        if let Backend::Scalar | Backend::Wide = backend {
            return false;
        }
        // One loop per method and rounding, each specialised to its kernel: the one place
        // the six combinations are spelled out.
        match (self.run.method, self.run.rounding) {
            (Method::Naive, Rounding::Nearest) => self.objects(Method::Naive, Rounding::Nearest),
            (Method::Naive, Rounding::Outward) => self.objects(Method::Naive, Rounding::Outward),
            (Method::AbsMatrix, Rounding::Nearest) => {
                self.objects(Method::AbsMatrix, Rounding::Nearest)
            }
            (Method::AbsMatrix, Rounding::Outward) => {
                self.objects(Method::AbsMatrix, Rounding::Outward)
            }
            (Method::SignSelect, Rounding::Nearest) => {
                self.objects(Method::SignSelect, Rounding::Nearest)
            }
            (Method::SignSelect, Rounding::Outward) => {
                self.objects(Method::SignSelect, Rounding::Outward)
            }
        }
        true
    }
}

impl<T: Transform3, S: AosSink> AosOn<'_, T, S> {
    /// Every active object through [`Aabb3::transformed`], a span of [`SPAN`] objects at a
    /// time; `method` and `rounding` are constants at each call site. Method calls rather
    /// than a closure over the loop: a closure here was compiled out of line, with the
    /// method and rounding as run-time values instead of constants.
    #[inline(always)]
    fn objects(self, method: Method, rounding: Rounding) {
        let AosOn { run, maps } = self;
        let AosRun {
            local,
            mut sink,
            active,
            ..
        } = run;
        let ahead = |sink: &S, i: usize| {
            simd::prefetch(&local[i]);
            simd::prefetch(maps.get(i));
            sink.prefetch(i);
        };
        let mut lookahead = Lookahead::new(active, local.len(), |i| ahead(&sink, i));
        for span in Spans::new(active, local.len(), SPAN) {
            lookahead.step(span, |i| ahead(&sink, i));
            let (start, count) = (span.start, span.count);
            let (local, maps) = (&local[start..start + count], maps.window(start, count));
            let tight = |k: usize| local[k].transformed(maps.get(k), method, rounding);
            sink.span(start, count, span.lanes, tight);
        }
    }
}
