//! The AoS loop of 3D boxes: each box as glam stores it, through the single-box kernel.
//!
//! Gathering AoS boxes and transforms into one-field-per-register lanes costs a shuffle per
//! field per box, more than the kernel itself (measured in `docs/speed.md`). So `&[Aabb3]`
//! boxes with AoS or shared transforms run [`Aabb3::transformed`] on every active box, on
//! glam's `Vec3A`: the same bits as the single-box calls on every SIMD backend (never
//! fused on a default build), and the same contract, the extended path included.

use super::Active;
use super::active::{Lookahead, Spans, Width};
use crate::aabb::Aabb3;
use crate::layout::Maps;
use crate::method::{Method, Rounding};
use crate::simd::{self, Backend};
use crate::transform::{Simd3Job, Transform3};

/// The objects of one step of a mask's walk: a mask word's worth.
const SPAN: usize = 64;

/// Where the AoS loop's tight boxes go.
pub(crate) trait AosSink {
    /// Objects `start..start + local.len()`, every one active, with their poses in order:
    /// object `start + k`'s tight box is `tight.of(&local[k], pose)`.
    fn run<'p, T: Transform3 + 'p>(
        &mut self,
        start: usize,
        local: &[Aabb3],
        poses: impl Iterator<Item = &'p T>,
        tight: Tight,
    );
    /// Object `i` alone, with its tight box.
    fn one(&mut self, i: usize, tight: Aabb3);
    /// Asks for object `i`'s output ahead of a scattered access.
    fn prefetch(&self, i: usize);
}

/// The plain AoS sink: every tight box written.
impl AosSink for &mut [Aabb3] {
    #[inline(always)]
    fn run<'p, T: Transform3 + 'p>(
        &mut self,
        start: usize,
        local: &[Aabb3],
        poses: impl Iterator<Item = &'p T>,
        tight: Tight,
    ) {
        // The slices zipped: no index, so no bounds checks.
        for ((out, local), pose) in self[start..].iter_mut().zip(local).zip(poses) {
            *out = tight.of(local, pose);
        }
    }
    #[inline(always)]
    fn one(&mut self, i: usize, tight: Aabb3) {
        self[i] = tight;
    }
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        simd::prefetch(&self[i]);
    }
}

/// The single-box kernel of one method and rounding. A method call rather than a closure:
/// a closure was compiled out of line, with the method and rounding as run-time values
/// where each loop has them as constants.
#[derive(Clone, Copy)]
pub(crate) struct Tight {
    method: Method,
    rounding: Rounding,
}

impl Tight {
    /// The tight world box of `local` at `pose`.
    #[inline(always)]
    pub fn of<T: Transform3>(self, local: &Aabb3, pose: &T) -> Aabb3 {
        local.transformed(pose, self.method, self.rounding)
    }
}

/// The poses of the AoS loop, split once from [`Maps`]: a slice, or one shared pose.
trait PoseList<'p, T: 'p>: Copy {
    /// Object `i`'s pose.
    fn at(self, i: usize) -> &'p T;
    /// The poses of objects `start..`, in order.
    fn from(self, start: usize) -> impl Iterator<Item = &'p T>;
}

impl<'p, T> PoseList<'p, T> for &'p [T] {
    #[inline(always)]
    fn at(self, i: usize) -> &'p T {
        &self[i]
    }
    #[inline(always)]
    fn from(self, start: usize) -> impl Iterator<Item = &'p T> {
        self[start..].iter()
    }
}

/// One pose shared by every object.
struct Shared<'p, T>(&'p T);

impl<T> Clone for Shared<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for Shared<'_, T> {}

impl<'p, T> PoseList<'p, T> for Shared<'p, T> {
    #[inline(always)]
    fn at(self, _: usize) -> &'p T {
        self.0
    }
    #[inline(always)]
    fn from(self, _: usize) -> impl Iterator<Item = &'p T> {
        core::iter::repeat(self.0)
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
        let AosOn { run, maps } = self;
        let local = run.local;
        // One loop per method, rounding and pose kind, each specialised to its kernel.
        specialise!(run.method, run.rounding, |method, rounding| match maps {
            Maps::Each(poses) => walk(run, &poses[..local.len()], method, rounding),
            Maps::Shared(pose) => walk(run, Shared(pose), method, rounding),
        });
        true
    }
}

/// Every active object through [`Aabb3::transformed`]: all of them in one run; the objects
/// of a list one at a time; the spans of a mask, its whole words that follow each other
/// as one run and the rest one at a time. Scattered objects have their memory requested
/// ahead, one object further as each runs. `method` and `rounding` are constants at each
/// call site.
#[inline(always)]
fn walk<'p, T: Transform3 + 'p, S: AosSink>(
    run: AosRun<'_, S>,
    poses: impl PoseList<'p, T>,
    method: Method,
    rounding: Rounding,
) {
    let AosRun {
        local,
        mut sink,
        active,
        ..
    } = run;
    let tight = Tight { method, rounding };
    if let Active::All = active {
        sink.run(0, local, poses.from(0), tight);
        return;
    }
    let ahead = |sink: &S, i: usize| {
        simd::prefetch(&local[i]);
        simd::prefetch(poses.at(i));
        sink.prefetch(i);
    };
    // Each walk builds its own lookahead, so that the kind of active set is a constant in
    // its loop.
    if let Active::Indices(ix) = active {
        // A list in its order: building each span's mask from a list cost more than the
        // objects (1.4x at 1% and 10% active, measured on an Intel Xeon).
        let mut lookahead = Lookahead::new(active);
        for j in lookahead.requests() {
            ahead(&sink, j);
        }
        for &i in ix {
            let i = i as usize;
            lookahead.advance(1);
            for j in lookahead.requests() {
                ahead(&sink, j);
            }
            sink.one(i, tight.of(&local[i], poses.at(i)));
        }
        return;
    }
    let mut lookahead = Lookahead::new(active);
    for j in lookahead.requests() {
        ahead(&sink, j);
    }
    let mut spans = Spans::<Width<SPAN>>::new(active, local.len()).peekable();
    while let Some(span) = spans.next() {
        lookahead.enter(span);
        if span.is_full() {
            let mut end = span.start + span.count;
            while let Some(next) = spans.next_if(|s| s.start == end && s.is_full()) {
                lookahead.enter(next);
                end += next.count;
            }
            sink.run(
                span.start,
                &local[span.start..end],
                poses.from(span.start),
                tight,
            );
            continue;
        }
        let mut bits = span.lanes;
        while bits != 0 {
            let i = span.start + bits.trailing_zeros() as usize;
            lookahead.advance(1);
            for j in lookahead.requests() {
                ahead(&sink, j);
            }
            sink.one(i, tight.of(&local[i], poses.at(i)));
            bits &= bits - 1;
        }
    }
}
