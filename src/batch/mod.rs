//! [`Batch`] and its verbs, a thin public layer over the engine, a file each:
//! [`Batch::transform`] (`transform`), [`Batch::update`] with the broadphase's fat boxes
//! and pose sources (`update`, `large`; the moved set it fills is `fat/moved.rs`), and the
//! `_par` entry points (`parallel`, feature `rayon`).

mod large;
#[cfg(feature = "rayon")]
mod parallel;
mod transform;
mod update;

pub use large::{LargePose, LargeRigid3};
pub use update::{LargeWorld, Swept};

#[cfg(doc)]
use crate::aabb::Aabb3;
use crate::engine::PoseSource;
use crate::error::BatchError;
use crate::layout::{BoxSink, BoxSource};
use crate::method::{Method, Rounding};
use crate::simd::Backend;

/// How a batch runs: the method, the rounding and the backend.
///
/// # Batch transforms
///
/// Many boxes at once, in any layout, through any transform class, on the best backend.
///
/// One entry point, [`Batch::transform`], takes a [`BoxSource`], a [`PoseSource`] and
/// a [`BoxSink`]:
///
/// | layout | boxes read | boxes written | transforms read |
/// |---|---|---|---|
/// | AoS slices | `&[Aabb3]`, `&Vec<Aabb3>` | `&mut [Aabb3]`, `&mut Vec<Aabb3>` | `&[T]`, `&Vec<T>` |
/// | AoSoA blocks of 8 | `&[Aabb3x8]` | `&mut [Aabb3x8]` | `&[Block8<T>]` (`&[Rigid3x8]`, …) |
/// | SoA columns | [`SoaRef`](crate::SoaRef), `&Soa` | [`SoaMut`](crate::SoaMut), `&mut Soa` | [`SoaRef`](crate::SoaRef), `&Soa` |
/// | shared | | | `&T`: one transform for the whole batch |
///
/// The poses can also be a [`Swept`] pair of any two of these (the union of the boxes at
/// both) or [`LargeWorld`] poses (boxes relative to an `f64` origin), as for the update.
/// `T` is any transform class ([`crate::Transform3`], [`crate::Transform2`]); 2D boxes
/// (`Aabb2`) work the same way. Every combination runs the same lane-generic kernels as the
/// single-box path and keeps the same contract; lengths are checked before anything is
/// written, and any length is accepted (the last partial span runs one box at a time, in
/// one lane of the same arithmetic).
///
/// ```
/// use bvkit::{Aabb3, Batch, Method, Rigid3, Rounding};
/// use glam::{Quat, Vec3A};
///
/// let local = vec![Aabb3::new(Vec3A::ZERO, Vec3A::ONE); 100];
/// let poses = vec![Rigid3::new(Quat::IDENTITY, Vec3A::X); 100];
/// let mut world = vec![Aabb3::EMPTY; 100];
/// Batch::new(Method::AbsMatrix, Rounding::Outward).transform(&local, &poses, &mut world)?;
/// assert!(world[99].contains_point(Vec3A::new(2.0, 1.0, 1.0)));
/// # Ok::<(), bvkit::BatchError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Batch {
    /// The transform method.
    pub method: Method,
    /// The rounding guarantee.
    pub rounding: Rounding,
    backend: Backend,
    deterministic: bool,
}

impl Batch {
    /// Outputs larger than this many bytes of box fields (32 MiB: about 1.4M 3D boxes,
    /// beyond the last-level cache of most CPUs) are written past the caches when they are
    /// AoSoA blocks: non-temporal stores of whole blocks, then a store fence. The bits are
    /// the same, and large batches run faster (`docs/speed.md`). A consumer that reads the
    /// boxes back gains nothing from them staying in a cache they do not fit.
    pub const NON_TEMPORAL_BYTES: usize = 32 << 20;

    /// A batch on the fastest backend of this CPU ([`Backend::detect`]).
    #[must_use]
    pub fn new(method: Method, rounding: Rounding) -> Self {
        Self {
            method,
            rounding,
            backend: Backend::detect(),
            deterministic: false,
        }
    }

    /// The same batch in deterministic mode, for lockstep networking and replays: no
    /// multiply-add is fused, so that every backend, every layout and the scalar reference
    /// give the same bits (on any x86-64 CPU, for the same build). It costs the fused
    /// backends a few percent in cache; the default stays the fastest. The AoS 3D path (and
    /// [`Aabb3::transformed`]) never fuses, so it gives these bits in both modes; so do the
    /// lanes without the `std` feature (`core` has no fused multiply-add).
    #[must_use]
    pub fn deterministic(self) -> Self {
        Self {
            deterministic: true,
            ..self
        }
    }

    /// True in [deterministic mode](Batch::deterministic).
    #[must_use]
    pub fn is_deterministic(&self) -> bool {
        self.deterministic
    }

    /// The same batch forced onto `backend`, for tests and benchmarks.
    ///
    /// # Errors
    /// [`BatchError::UnsupportedBackend`] when this CPU cannot run it.
    pub fn on(self, backend: Backend) -> Result<Self, BatchError> {
        if backend.is_supported() {
            Ok(Self { backend, ..self })
        } else {
            Err(BatchError::UnsupportedBackend(backend))
        }
    }

    /// The backend the batch runs on.
    #[must_use]
    pub fn backend(&self) -> Backend {
        self.backend
    }
}

fn checked_len<const N: usize>(
    local: &impl BoxSource<N>,
    poses: &impl PoseSource<N>,
    out: &mut impl BoxSink<N>,
) -> Result<usize, BatchError> {
    let len = local.len()?;
    poses.check_len(len)?;
    BatchError::check_len("output", len, out.len()?)?;
    Ok(len)
}

#[cfg(test)]
mod tests {
    //! Lanes of 16 (no backend's lane type now, but the engine takes any width): every
    //! lane does the same arithmetic at any width, and the tail runs in one lane of the
    //! same arithmetic, so they must reproduce the 8-lane backends exactly. This covers the
    //! wide code paths (blocks spanning two AoSoA blocks, tails, the extended path).

    use super::*;
    use crate::aabb::{Aabb2, Aabb3};
    use crate::engine::{Active, Engine, Fat, NamedSink, SinkRoute, Store};
    use crate::fat::{Margin, Moved};
    use crate::layout::{
        Aabb3x8, Block8, NamedBoxes, NamedBoxesMut, NamedPoses, Route, Soa, TransformSource,
    };
    use crate::simd::{F32s, LaneArray};
    use crate::transform::{Rigid2, Rigid3, Similarity3, Translation2, Translation3, Trs3};
    use alloc::{vec, vec::Vec};
    use glam::{Affine3A, Quat, Vec3, Vec3A};

    fn run_lanes<L: LaneArray, B: BoxSource<3>, X: TransformSource<3>, O: BoxSink<3>>(
        method: Method,
        rounding: Rounding,
        local: B,
        xf: X,
        mut out: O,
    ) {
        let len = checked_len(&local, &xf, &mut out).expect("lengths");
        let engine = Engine {
            local,
            poses: xf,
            sink: Store { out, stream: false },
            len,
            active: Active::All,
            method,
            rounding,
        };
        engine.run_in::<L>();
    }

    fn inputs(n: usize) -> (Vec<Aabb3>, Vec<Affine3A>, Vec<Trs3>) {
        let specials = [f32::NAN, f32::INFINITY, -f32::INFINITY, 3e38, -0.0, 1e-45];
        let mut boxes = Vec::new();
        let mut affines = Vec::new();
        let mut trs = Vec::new();
        for k in 0..n {
            let x = k as f32;
            let mut b = Aabb3::new(Vec3A::new(-x, 0.5 * x, -1.0), Vec3A::new(x + 1.0, x, 2.0));
            let scale = Vec3::new(1.0 + x * 0.01, 2.0, -0.5);
            let q = Quat::from_rotation_y(x);
            let mut xf = Affine3A::from_scale_rotation_translation(scale, q, Vec3::splat(x * 10.0));
            let mut t: Trs3 = (scale, q, Vec3::splat(x)).into();
            if k % 7 == 3 {
                b.min.y = specials[k % specials.len()];
            }
            if k % 11 == 5 {
                xf.matrix3.y_axis.z = specials[k % specials.len()];
                t.rotation.z = specials[k % specials.len()];
            }
            boxes.push(b);
            affines.push(xf);
            trs.push(t);
        }
        (boxes, affines, trs)
    }

    fn same(a: &[Aabb3], b: &[Aabb3]) -> bool {
        let eq = |x: f32, y: f32| x == y || (x.is_nan() && y.is_nan());
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(p, q)| (0..3).all(|i| eq(p.min[i], q.min[i]) && eq(p.max[i], q.max[i])))
    }

    /// The route the layouts' types name: where it is not generic, every source and both
    /// sinks over the output name themselves with that route's variants, as the dispatch
    /// matches them (so its one `unreachable!` is never reached).
    fn route<const N: usize, B: BoxSource<N>, X: PoseSource<N>, O: BoxSink<N>>(
        local: B,
        xf: X,
        out: O,
    ) -> Route {
        fn kind(boxes: &NamedBoxesMut<'_>) -> &'static str {
            match boxes {
                NamedBoxesMut::Aos(_) => "AoS",
                NamedBoxesMut::Blocks(_) => "blocks",
                NamedBoxesMut::Soa(_) => "columns",
                NamedBoxesMut::Aos2(_) => "AoS 2D",
            }
        }
        let route = Engine::<N, B, X, Store<O>>::ROUTE;
        // An update's sink takes the same routes, but for the columns' and the 2D one.
        let fat = Engine::<N, B, X, Fat<'_, O>>::ROUTE;
        assert_eq!(
            fat,
            if matches!(route, Route::Soa | Route::Aos2) {
                Route::Generic
            } else {
                route
            }
        );
        let predicted = xf.named_predicted();
        let (local, poses) = (local.named_boxes(), xf.named_poses());
        let mut moved = Moved::new();
        let mut fat = Fat {
            fat: out,
            margin: Margin::ZERO,
            moved: &mut moved,
        };
        let fat_out = match fat.named() {
            Some(NamedSink::Fat { fat, .. }) => Some(kind(&fat)),
            Some(NamedSink::Store { .. }) => panic!("a fat sink names itself Store"),
            None => None,
        };
        let mut store = Store {
            out: fat.fat,
            stream: false,
        };
        let out = match store.named() {
            Some(NamedSink::Store { out, .. }) => Some(out),
            Some(NamedSink::Fat { .. }) => panic!("a plain sink names itself Fat"),
            None => None,
        };
        // The fat sink names the same output as the plain one.
        assert_eq!(fat_out, out.as_ref().map(kind));
        let named = (local, poses, out);
        match route {
            Route::Generic => {}
            Route::Aos => assert!(
                matches!(
                    named,
                    (
                        Some(NamedBoxes::Aos(_)),
                        Some(NamedPoses::Aos(_)),
                        Some(NamedBoxesMut::Aos(_))
                    )
                ) && predicted.is_none()
            ),
            Route::Swept => assert!(matches!(
                (named, predicted),
                (
                    (
                        Some(NamedBoxes::Aos(_)),
                        Some(NamedPoses::Aos(_)),
                        Some(NamedBoxesMut::Aos(_))
                    ),
                    Some(NamedPoses::Aos(_))
                )
            )),
            Route::Blocks => assert!(matches!(
                named,
                (
                    Some(NamedBoxes::Blocks(_)),
                    Some(NamedPoses::Blocks(_)),
                    Some(NamedBoxesMut::Blocks(_))
                )
            )),
            Route::Soa => assert!(matches!(
                named,
                (
                    Some(NamedBoxes::Soa(_)),
                    Some(NamedPoses::Soa(_)),
                    Some(NamedBoxesMut::Soa(_))
                )
            )),
            Route::Aos2 => assert!(matches!(
                named,
                (
                    Some(NamedBoxes::Aos2(_)),
                    Some(NamedPoses::Aos2(_)),
                    Some(NamedBoxesMut::Aos2(_))
                )
            )),
        }
        route
    }

    /// Every layout whose constants name a route converts to it; the others take none.
    #[test]
    fn routes_always_convert() {
        let local = vec![Aabb3::EMPTY; 16];
        let mut out = vec![Aabb3::NAN; 16];
        let (rigid, affine) = (vec![Rigid3::IDENTITY; 16], vec![Affine3A::IDENTITY; 16]);
        assert_eq!(route(&local[..], &rigid[..], &mut out[..]), Route::Aos);
        assert_eq!(route(&local, &rigid, &mut out), Route::Aos);
        assert_eq!(route(&local[..], &rigid[0], &mut out[..]), Route::Aos);
        assert_eq!(route(&local, &affine, &mut out), Route::Aos);
        assert_eq!(route(&local, &Trs3::IDENTITY, &mut out), Route::Aos);
        assert_eq!(
            route(&local, &[Similarity3::IDENTITY; 16][..], &mut out),
            Route::Aos
        );
        assert_eq!(
            route(&local, &[Translation3::IDENTITY; 16][..], &mut out),
            Route::Aos
        );
        let (l8, r8) = (Block8::pack(&local), Block8::pack(&rigid));
        let mut o8 = vec![Aabb3x8::default(); 2];
        assert_eq!(route(&l8[..], &r8[..], &mut o8[..]), Route::Blocks);
        assert_eq!(route(&l8, &r8, &mut o8), Route::Blocks);
        // Not compiled in bvkit: other classes in blocks, shared poses with blocks, mixed
        // layouts.
        let a8: Vec<Block8<Affine3A>> = Block8::pack(&affine);
        assert_eq!(route(&l8, &a8, &mut o8), Route::Generic);
        assert_eq!(route(&l8, &rigid[0], &mut o8), Route::Generic);
        assert_eq!(route(&l8, &r8, &mut out), Route::Generic);
        assert_eq!(route(&local, &r8, &mut out), Route::Generic);
        assert_eq!(route(&local, &rigid, &mut o8), Route::Generic);
        // Swept pairs of AoS or shared poses, of any 3D classes, with AoS boxes; not of
        // blocks, nor with blocks of boxes, nor a pair of pairs.
        fn swept<A, B>(current: A, predicted: B) -> Swept<A, B> {
            Swept { current, predicted }
        }
        let sw = swept(&rigid[..], &rigid[..]);
        assert_eq!(route(&local, sw, &mut out), Route::Swept);
        assert_eq!(
            route(&local, swept(&rigid[..], &rigid[2]), &mut out),
            Route::Swept
        );
        let trs = [Trs3::IDENTITY; 16];
        assert_eq!(
            route(&local, swept(&affine, &trs[..]), &mut out),
            Route::Swept
        );
        assert_eq!(
            route(&local, swept(&r8[..], &r8[..]), &mut out),
            Route::Generic
        );
        assert_eq!(route(&l8, swept(&r8[..], &r8[..]), &mut o8), Route::Generic);
        assert_eq!(route(&l8, sw, &mut o8), Route::Generic);
        let pair = Swept {
            current: sw,
            predicted: &rigid[..],
        };
        assert_eq!(route(&local, pair, &mut out), Route::Generic);
        // Columns of boxes with columns of rigid poses, owned or borrowed; not of other
        // classes, nor with other layouts.
        let (ls, rs) = (Soa::from_slice(&local), Soa::from_slice(&rigid));
        let mut os = Soa::from_slice(&out);
        assert_eq!(route(&ls, &rs, &mut os), Route::Soa);
        assert_eq!(route(ls.view(), rs.view(), os.view_mut()), Route::Soa);
        assert_eq!(route(ls.view(), &rs, &mut os), Route::Soa);
        let affine_soa = Soa::from_slice(&affine);
        assert_eq!(route(&ls, &affine_soa, &mut os), Route::Generic);
        assert_eq!(route(&ls, &rigid[..], &mut os), Route::Generic);
        assert_eq!(route(&local, &rs, &mut out), Route::Generic);
        assert_eq!(route(&ls, &rs, &mut out), Route::Generic);
        // 2D: AoS boxes with AoS rigid poses; not a shared pose, nor other classes, nor
        // other layouts, nor a swept pair.
        let local2 = vec![Aabb2::EMPTY; 16];
        let mut out2 = vec![Aabb2::NAN; 16];
        let rigid2 = vec![Rigid2::IDENTITY; 16];
        assert_eq!(route(&local2[..], &rigid2[..], &mut out2[..]), Route::Aos2);
        assert_eq!(route(&local2, &rigid2, &mut out2), Route::Aos2);
        assert_eq!(route(&local2, &rigid2[0], &mut out2), Route::Generic);
        let affine2 = vec![glam::Affine2::IDENTITY; 16];
        assert_eq!(route(&local2, &affine2, &mut out2), Route::Generic);
        let translation2 = vec![Translation2::IDENTITY; 16];
        assert_eq!(route(&local2, &translation2, &mut out2), Route::Generic);
        let (l2, r2) = (Block8::pack(&local2), Block8::pack(&rigid2));
        let mut o2 = vec![Block8::splat(Aabb2::NAN); 2];
        assert_eq!(route(&l2, &r2, &mut o2), Route::Generic);
        assert_eq!(route(&local2, &r2, &mut out2), Route::Generic);
        let (ls2, mut os2) = (Soa::from_slice(&local2), Soa::from_slice(&out2));
        assert_eq!(route(&ls2, &rigid2, &mut os2), Route::Generic);
        assert_eq!(route(&ls2, &rigid2, &mut out2), Route::Generic);
        let sw2 = swept(&rigid2[..], &rigid2[..]);
        assert_eq!(route(&local2, sw2, &mut out2), Route::Generic);
    }

    #[test]
    fn sixteen_lanes_reproduce_eight() {
        for n in [0, 1, 15, 16, 17, 40, 333] {
            let (local, affines, trs) = inputs(n);
            let rigid: Vec<Rigid3> = trs
                .iter()
                .map(|t| Rigid3::new(t.rotation, t.translation))
                .collect();
            for method in Method::ALL {
                for rounding in Rounding::ALL {
                    let (m, r) = (method, rounding);
                    let mut reference = vec![Aabb3::NAN; n];
                    let mut sixteen = vec![Aabb3::NAN; n];
                    // Unfused and fused (`f32::mul_add` is correctly rounded whether or not
                    // the instruction exists, so both widths must agree either way).
                    run_lanes::<F32s<8, false>, _, _, _>(
                        m,
                        r,
                        &local[..],
                        &affines[..],
                        &mut reference[..],
                    );
                    run_lanes::<F32s<16, false>, _, _, _>(
                        m,
                        r,
                        &local[..],
                        &affines[..],
                        &mut sixteen[..],
                    );
                    assert!(same(&reference, &sixteen), "{m:?} {r:?} n={n}");
                    run_lanes::<F32s<8, true>, _, _, _>(
                        m,
                        r,
                        &local[..],
                        &trs[..],
                        &mut reference[..],
                    );
                    run_lanes::<F32s<16, true>, _, _, _>(
                        m,
                        r,
                        &local[..],
                        &trs[..],
                        &mut sixteen[..],
                    );
                    assert!(same(&reference, &sixteen), "{m:?} {r:?} n={n} trs fused");
                    // AoSoA blocks, where 16 lanes span two blocks.
                    let (l8, x8) = (Block8::pack(&local), Block8::pack(&rigid));
                    let mut o8 = vec![Aabb3x8::default(); l8.len()];
                    run_lanes::<F32s<8, true>, _, _, _>(
                        m,
                        r,
                        &local[..],
                        &rigid[..],
                        &mut reference[..],
                    );
                    run_lanes::<F32s<16, true>, _, _, _>(m, r, &l8[..], &x8[..], &mut o8[..]);
                    let got: Vec<Aabb3> = Block8::unpack(&o8, n);
                    assert!(same(&got, &reference), "{m:?} {r:?} n={n} aosoa");
                }
            }
        }
    }
}
