//! Every transform class × method × rounding × path × layout × supported backend, against
//! the exact oracle and the scalar reference, at awkward lengths and over every extreme
//! class; and the batch entry point's length checks.

use bvkit_support::cases;
#[cfg(target_arch = "x86_64")]
use bvkit_support::mxcsr;
use bvkit_support::oracle;

use bvkit::{
    Aabb2, Aabb3, Aabb3x8, Backend, Batch, BatchError, Block8, Method, Rigid2, Rigid3, Rounding,
    Similarity3, Soa, Translation2, Translation3, Trs3,
};
use bvkit::{Transform2, Transform3};
use glam::{Affine2, Affine3A, Vec2, Vec3A};
use proptest::prelude::*;
use rand::RngExt;
use rand::rngs::StdRng;

use cases::{Class, Scale, problem, quat_problem, rigid_problem, rng, translation_problem};
use oracle::{Bound, Exactly, Problem, QuatProblem, affine2, affine3, check, rigid2};

/// A transform class under test: its problems, as bvkit's inputs, and its paths.
trait Case<const N: usize> {
    type P: Exactly<N> + Copy;
    type B: Copy + core::fmt::Debug + PartialEq;
    type T: Copy + core::fmt::Debug;
    const NAME: &'static str;
    fn make(class: Class, r: &mut StdRng) -> Self::P;
    fn inputs(p: &Self::P) -> (Self::B, Self::T);
    fn faces(b: &Self::B) -> ([f32; N], [f32; N]);
    fn order(method: Method) -> u32;
    /// The single-box paths: (name, result).
    fn single(b: &Self::B, xf: &Self::T, m: Method, r: Rounding) -> Vec<(&'static str, Self::B)>;
    /// The scalar reference.
    fn scalar(b: &Self::B, xf: &Self::T, m: Method, r: Rounding) -> Self::B;
    /// Every batch layout, as (name, result); names with "shared" ran every box through
    /// the first transform.
    fn batches(
        batch: Batch,
        local: &[Self::B],
        xfs: &[Self::T],
    ) -> Vec<(&'static str, Vec<Self::B>)>;
}

/// The batch layouts of one box type and transform class, through the one entry point:
/// AoS, AoSoA, SoA, and one shared transform. (Every call site compiles the kernels for
/// every backend, so the other forms, which only delegate, are tested once, on `Rigid3`.)
macro_rules! batches {
    ($batch:expr, $local:expr, $xfs:expr, $B:ty, $empty:expr) => {{
        let (batch, local, xfs): (Batch, &[$B], &[_]) = ($batch, $local, $xfs);
        let n = local.len();
        let mut results = Vec::new();
        let mut out = vec![$empty; n];
        batch.transform(local, xfs, &mut out[..]).unwrap();
        results.push(("aos", out));
        let (lb, xb) = (Block8::pack(local), Block8::pack(xfs));
        let mut ob = vec![Block8::default(); lb.len()];
        batch.transform(&lb[..], &xb[..], &mut ob[..]).unwrap();
        results.push(("aosoa", Block8::unpack(&ob, n)));
        let (ls, xs) = (Soa::from_slice(local), Soa::from_slice(xfs));
        let mut os = Soa::filled(n, $empty);
        batch
            .transform(ls.view(), xs.view(), os.view_mut())
            .unwrap();
        results.push(("soa", (0..n).map(|k| os.get(k)).collect()));
        if let Some(first) = xfs.first() {
            let mut out = vec![$empty; n];
            batch.transform(local, first, &mut out[..]).unwrap();
            results.push(("shared", out));
        }
        results
    }};
}

macro_rules! case3 {
    ($case:ident, $T:ty, $P:ty, $make:expr, $inputs:expr) => {
        struct $case;
        impl Case<3> for $case {
            type P = $P;
            type B = Aabb3;
            type T = $T;
            const NAME: &'static str = stringify!($T);
            fn make(class: Class, r: &mut StdRng) -> $P {
                $make(class, r)
            }
            fn inputs(p: &$P) -> (Aabb3, $T) {
                $inputs(p)
            }
            fn faces(b: &Aabb3) -> ([f32; 3], [f32; 3]) {
                (b.min.to_array(), b.max.to_array())
            }
            fn order(method: Method) -> u32 {
                <$T as Transform3>::nearest_order(method)
            }
            fn single(b: &Aabb3, xf: &$T, m: Method, r: Rounding) -> Vec<(&'static str, Aabb3)> {
                vec![
                    ("single simd", b.transformed(xf, m, r)),
                    ("single scalar", b.transformed_scalar(xf, m, r)),
                ]
            }
            fn scalar(b: &Aabb3, xf: &$T, m: Method, r: Rounding) -> Aabb3 {
                b.transformed_scalar(xf, m, r)
            }
            fn batches(
                batch: Batch,
                local: &[Aabb3],
                xfs: &[$T],
            ) -> Vec<(&'static str, Vec<Aabb3>)> {
                batches!(batch, local, xfs, Aabb3, Aabb3::NAN)
            }
        }
    };
}

macro_rules! case2 {
    ($case:ident, $T:ty, $make:expr, $inputs:expr) => {
        struct $case;
        impl Case<2> for $case {
            type P = Problem<2>;
            type B = Aabb2;
            type T = $T;
            const NAME: &'static str = stringify!($T);
            fn make(class: Class, r: &mut StdRng) -> Problem<2> {
                $make(class, r)
            }
            fn inputs(p: &Problem<2>) -> (Aabb2, $T) {
                $inputs(p)
            }
            fn faces(b: &Aabb2) -> ([f32; 2], [f32; 2]) {
                (b.min.to_array(), b.max.to_array())
            }
            fn order(method: Method) -> u32 {
                <$T as Transform2>::nearest_order(method)
            }
            fn single(b: &Aabb2, xf: &$T, m: Method, r: Rounding) -> Vec<(&'static str, Aabb2)> {
                vec![("single", b.transformed(xf, m, r))]
            }
            fn scalar(b: &Aabb2, xf: &$T, m: Method, r: Rounding) -> Aabb2 {
                b.transformed(xf, m, r)
            }
            fn batches(
                batch: Batch,
                local: &[Aabb2],
                xfs: &[$T],
            ) -> Vec<(&'static str, Vec<Aabb2>)> {
                batches!(batch, local, xfs, Aabb2, Aabb2::NAN)
            }
        }
    };
}

fn box3(p: &Problem<3>) -> Aabb3 {
    Aabb3::new(Vec3A::from_array(p.lo), Vec3A::from_array(p.hi))
}

fn box2(p: &Problem<2>) -> Aabb2 {
    Aabb2::new(Vec2::from_array(p.lo), Vec2::from_array(p.hi))
}

case3!(CaseAffine3, Affine3A, Problem<3>, problem::<3>, affine3);
case3!(
    CaseTranslation3,
    Translation3,
    Problem<3>,
    translation_problem::<3>,
    |p: &Problem<3>| (box3(p), Translation3(Vec3A::from_array(p.t)))
);
case3!(
    CaseRigid3,
    Rigid3,
    QuatProblem,
    |c, r| quat_problem(c, Scale::Unit, r),
    |p: &QuatProblem| (p.aabb(), p.rigid3())
);
case3!(
    CaseSimilarity3,
    Similarity3,
    QuatProblem,
    |c, r| quat_problem(c, Scale::Uniform, r),
    |p: &QuatProblem| (p.aabb(), p.similarity3())
);
case3!(
    CaseTrs3,
    Trs3,
    QuatProblem,
    |c, r| quat_problem(c, Scale::PerAxis, r),
    |p: &QuatProblem| (p.aabb(), p.trs3())
);
case2!(CaseAffine2, Affine2, problem::<2>, affine2);
case2!(CaseRigid2, Rigid2, rigid_problem, rigid2);
case2!(
    CaseTranslation2,
    Translation2,
    translation_problem::<2>,
    |p: &Problem<2>| (box2(p), Translation2(Vec2::from_array(p.t)))
);

/// Same faces: equal values (min/max may pick either zero of `max(+0, -0)`), NaN as NaN.
fn same(a: &[f32], b: &[f32]) -> bool {
    a.iter()
        .zip(b)
        .all(|(x, y)| x == y || (x.is_nan() && y.is_nan()))
}

/// Backends whose arithmetic is the scalar reference's, rounding for rounding (no FMA).
fn bitwise_like_scalar(b: Backend) -> bool {
    matches!(b, Backend::Scalar | Backend::Baseline)
        || (b == Backend::Wide && !cfg!(target_feature = "fma"))
}

/// Every single-box path of one problem against the oracle.
fn check_single<const N: usize, C: Case<N>>(p: &C::P) -> Result<(), String> {
    let (b, xf) = C::inputs(p);
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let bound = Bound::of_order(C::order(method), rounding);
            for (path, out) in C::single(&b, &xf, method, rounding) {
                let (min, max) = C::faces(&out);
                check(p, min, max, bound).map_err(|e| {
                    format!("{} {method:?} {rounding:?} {path}: {e}\n{p:?}", C::NAME)
                })?;
            }
        }
    }
    Ok(())
}

/// Problems of mixed classes, so that lanes of one block take different paths.
fn mixed<const N: usize, C: Case<N>>(len: usize, seed: u64) -> Vec<C::P> {
    let r = &mut rng(seed);
    (0..len)
        .map(|_| {
            let class = if r.random_bool(0.7) {
                Class::Typical
            } else {
                Class::ALL[r.random_range(0..Class::ALL.len())]
            };
            C::make(class, r)
        })
        .collect()
}

/// Every layout on every backend, every method and rounding, at awkward lengths.
fn every_layout<const N: usize, C: Case<N>>() {
    let random_len = rng(7).random_range(100..1500);
    for (n, len) in [0, 1, 7, 8, 9, 16, 63, 300, random_len]
        .into_iter()
        .enumerate()
    {
        let ps = mixed::<N, C>(len, 100 + n as u64);
        let (local, xfs): (Vec<C::B>, Vec<C::T>) = ps.iter().map(C::inputs).unzip();
        for method in Method::ALL {
            for rounding in Rounding::ALL {
                let bound = Bound::of_order(C::order(method), rounding);
                let reference: Vec<C::B> = local
                    .iter()
                    .zip(&xfs)
                    .map(|(b, x)| C::scalar(b, x, method, rounding))
                    .collect();
                // Deterministic mode: every backend and layout gives the scalar bits.
                let modes = Backend::supported()
                    .into_iter()
                    .flat_map(|backend| [(backend, false), (backend, true)]);
                for (backend, deterministic) in modes {
                    let mut batch = Batch::new(method, rounding).on(backend).unwrap();
                    if deterministic {
                        batch = batch.deterministic();
                    }
                    let bitwise = deterministic || bitwise_like_scalar(backend);
                    for (layout, out) in C::batches(batch, &local, &xfs) {
                        let mode = if deterministic { " deterministic" } else { "" };
                        let name = format!(
                            "{} {layout} {backend:?}{mode} {method:?} {rounding:?} len {len}",
                            C::NAME
                        );
                        let shared = layout.contains("shared");
                        assert_eq!(out.len(), len, "{name}");
                        for (k, (p, o)) in ps.iter().zip(&out).enumerate() {
                            let p = if shared {
                                ps[0].with_box(p.lo(), p.hi())
                            } else {
                                *p
                            };
                            let (min, max) = C::faces(o);
                            if let Err(e) = check(&p, min, max, bound) {
                                panic!("{name} box {k}: {e}\n{p:?}");
                            }
                            let (rmin, rmax) = C::faces(&reference[k]);
                            assert!(
                                shared || !bitwise || (same(&min, &rmin) && same(&max, &rmax)),
                                "{name} box {k}: {o:?} != scalar {:?}",
                                reference[k]
                            );
                        }
                    }
                }
            }
        }
    }
}

/// Outward under flush-to-zero and denormals-are-zero, as engines often run: every
/// single-box path and every layout on every backend, computed with both MXCSR modes set,
/// then judged by the exact oracle with the modes restored.
///
/// Two sets of problems: the normal-range problems of every extreme class, on which the
/// kernels form no subnormal number, so the modes change no bit; and boxes and
/// translations in the lowest normal binades (scaled by `2^-118`), where products and sums
/// underflow and are flushed, and only the pads' normal absolute part keeps the result
/// around the exact image (a subnormal pad constant is read as zero under DAZ).
#[cfg(target_arch = "x86_64")]
fn outward_under_ftz_and_daz<const N: usize, C: Case<N>>(tiny: bool) {
    let r = &mut rng(0xf72 + u64::from(tiny));
    let tiny_scale = 1.0 / (1u128 << 118) as f32;
    let ps: Vec<C::P> = (0..900)
        .map(|k| {
            if tiny {
                C::make(Class::Typical, r).scaled_box(tiny_scale)
            } else {
                C::make(Class::ALL[k % Class::ALL.len()], r)
            }
        })
        .filter(|p| {
            if tiny {
                p.all_normal()
            } else {
                p.normal_range()
            }
        })
        .collect();
    assert!(ps.len() > 300, "{} problems kept", ps.len());
    let (local, xfs): (Vec<C::B>, Vec<C::T>) = ps.iter().map(C::inputs).unzip();
    let modes = mxcsr::FTZ | mxcsr::DAZ;
    let rounding = Rounding::Outward;
    for method in Method::ALL {
        let bound = Bound::of_order(C::order(method), rounding);
        let (singles, _) = mxcsr::run(modes, (&local, &xfs), |(local, xfs)| {
            let each = local.iter().zip(xfs);
            each.map(|(b, xf)| C::single(b, xf, method, rounding))
                .collect::<Vec<_>>()
        });
        let mut runs: Vec<(String, Vec<C::B>)> = Vec::new();
        for path in 0..singles[0].len() {
            let name = singles[0][path].0.to_string();
            runs.push((name, singles.iter().map(|s| s[path].1).collect()));
        }
        let backends = Backend::supported()
            .into_iter()
            .flat_map(|backend| [(backend, false), (backend, true)]);
        for (backend, deterministic) in backends {
            let mut batch = Batch::new(method, rounding).on(backend).unwrap();
            if deterministic {
                batch = batch.deterministic();
            }
            let (outs, _) = mxcsr::run(modes, (&local, &xfs), |(local, xfs)| {
                C::batches(batch, local, xfs)
            });
            for (layout, out) in outs {
                let mode = if deterministic { " deterministic" } else { "" };
                runs.push((format!("{layout} {backend:?}{mode}"), out));
            }
        }
        for (name, out) in runs {
            for (k, (p, o)) in ps.iter().zip(&out).enumerate() {
                let p = if name.contains("shared") {
                    ps[0].with_box(p.lo(), p.hi())
                } else {
                    *p
                };
                let (min, max) = C::faces(o);
                if let Err(e) = check(&p, min, max, bound) {
                    panic!(
                        "{} {name} {method:?} under FTZ and DAZ, box {k}: {e}\n{p:?}",
                        C::NAME
                    );
                }
            }
        }
    }
}

/// [`outward_under_ftz_and_daz`] for every class.
#[cfg(target_arch = "x86_64")]
fn every_class_under_ftz_and_daz(tiny: bool) {
    outward_under_ftz_and_daz::<3, CaseAffine3>(tiny);
    outward_under_ftz_and_daz::<3, CaseTranslation3>(tiny);
    outward_under_ftz_and_daz::<3, CaseRigid3>(tiny);
    outward_under_ftz_and_daz::<3, CaseSimilarity3>(tiny);
    outward_under_ftz_and_daz::<3, CaseTrs3>(tiny);
    outward_under_ftz_and_daz::<2, CaseAffine2>(tiny);
    outward_under_ftz_and_daz::<2, CaseRigid2>(tiny);
    outward_under_ftz_and_daz::<2, CaseTranslation2>(tiny);
}

#[cfg(target_arch = "x86_64")]
#[test]
fn outward_contains_under_ftz_and_daz_on_normal_range_input() {
    every_class_under_ftz_and_daz(false);
}

#[cfg(target_arch = "x86_64")]
#[test]
fn outward_contains_under_ftz_and_daz_on_tiny_normal_input() {
    every_class_under_ftz_and_daz(true);
}

#[test]
fn affine3_every_layout_on_every_backend() {
    every_layout::<3, CaseAffine3>();
}

#[test]
fn translation3_every_layout_on_every_backend() {
    every_layout::<3, CaseTranslation3>();
}

#[test]
fn rigid3_every_layout_on_every_backend() {
    every_layout::<3, CaseRigid3>();
}

#[test]
fn similarity3_every_layout_on_every_backend() {
    every_layout::<3, CaseSimilarity3>();
}

#[test]
fn trs3_every_layout_on_every_backend() {
    every_layout::<3, CaseTrs3>();
}

#[test]
fn affine2_every_layout_on_every_backend() {
    every_layout::<2, CaseAffine2>();
}

#[test]
fn rigid2_every_layout_on_every_backend() {
    every_layout::<2, CaseRigid2>();
}

#[test]
fn translation2_every_layout_on_every_backend() {
    every_layout::<2, CaseTranslation2>();
}

fn class() -> impl Strategy<Value = Class> {
    proptest::sample::select(Class::ALL.to_vec())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    #[test]
    fn translation3_single_box(class in class(), seed in any::<u64>()) {
        let p = CaseTranslation3::make(class, &mut rng(seed));
        let r = check_single::<3, CaseTranslation3>(&p);
        prop_assert!(r.is_ok(), "{}", r.unwrap_err());
    }

    #[test]
    fn rigid3_single_box(class in class(), seed in any::<u64>()) {
        let p = CaseRigid3::make(class, &mut rng(seed));
        let r = check_single::<3, CaseRigid3>(&p);
        prop_assert!(r.is_ok(), "{}", r.unwrap_err());
    }

    #[test]
    fn similarity3_single_box(class in class(), seed in any::<u64>()) {
        let p = CaseSimilarity3::make(class, &mut rng(seed));
        let r = check_single::<3, CaseSimilarity3>(&p);
        prop_assert!(r.is_ok(), "{}", r.unwrap_err());
    }

    #[test]
    fn trs3_single_box(class in class(), seed in any::<u64>()) {
        let p = CaseTrs3::make(class, &mut rng(seed));
        let r = check_single::<3, CaseTrs3>(&p);
        prop_assert!(r.is_ok(), "{}", r.unwrap_err());
    }

    #[test]
    fn translation2_single_box(class in class(), seed in any::<u64>()) {
        let p = CaseTranslation2::make(class, &mut rng(seed));
        let r = check_single::<2, CaseTranslation2>(&p);
        prop_assert!(r.is_ok(), "{}", r.unwrap_err());
    }
}

/// The forms that delegate to the layouts above: `Vec`s by reference, owned SoA by
/// reference, mixed layouts, a shared transform over AoSoA boxes. In deterministic mode,
/// so that every form must give the same bits (by default AoS runs the unfused single-box
/// kernel and the other layouts the backend's fused lanes; `every_layout` checks each
/// against the oracle).
#[test]
fn every_form_of_the_entry_point() {
    let ps = mixed::<3, CaseRigid3>(203, 9);
    let (local, xfs): (Vec<Aabb3>, Vec<Rigid3>) = ps.iter().map(CaseRigid3::inputs).unzip();
    let n = local.len();
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let batch = Batch::new(method, rounding).deterministic();
            let bound = Bound::of_order(CaseRigid3::order(method), rounding);
            let mut expect = vec![Aabb3::NAN; n];
            batch
                .transform(&local[..], &xfs[..], &mut expect[..])
                .unwrap();
            let mut shared = vec![Aabb3::NAN; n];
            batch
                .transform(&local[..], &xfs[0], &mut shared[..])
                .unwrap();

            let same_box = |a: &Aabb3, b: &Aabb3| {
                let (a, b) = (CaseRigid3::faces(a), CaseRigid3::faces(b));
                same(&a.0, &b.0) && same(&a.1, &b.1)
            };
            let mut out = vec![Aabb3::NAN; n];
            batch.transform(&local, &xfs, &mut out).unwrap();
            assert!(
                out.iter().zip(&expect).all(|(a, b)| same_box(a, b)),
                "Vec by reference"
            );

            let (ls, xs) = (Soa::from_slice(&local), Soa::from_slice(&xfs));
            let mut os = Soa::filled(n, Aabb3::NAN);
            batch.transform(&ls, &xs, &mut os).unwrap();
            assert!(
                (0..n).all(|k| same_box(&os.get(k), &expect[k])),
                "owned SoA"
            );

            // AoSoA boxes, AoS transforms (the length must be a multiple of 8).
            let m = n / 8 * 8;
            let lb = Block8::pack(&local[..m]);
            let mut ob = vec![Aabb3x8::default(); lb.len()];
            batch.transform(&lb, &xfs[..m], &mut ob).unwrap();
            let got: Vec<Aabb3> = Block8::unpack(&ob, m);
            assert!(
                got.iter().zip(&expect).all(|(a, b)| same_box(a, b)),
                "AoSoA boxes, AoS transforms"
            );

            let lb = Block8::pack(&local);
            let mut ob = vec![Aabb3x8::default(); lb.len()];
            batch.transform(&lb, &xfs[0], &mut ob).unwrap();
            let got: Vec<Aabb3> = Block8::unpack(&ob, n);
            for (k, (p, o)) in ps.iter().zip(&got).enumerate() {
                let p = ps[0].with_box(p.lo, p.hi);
                let r = check(&p, o.min.to_array(), o.max.to_array(), bound);
                assert!(r.is_ok(), "AoSoA shared box {k}: {}", r.unwrap_err());
                assert!(same_box(o, &shared[k]), "AoSoA shared box {k}");
            }
        }
    }
}

#[test]
fn bad_lengths_are_refused_and_leave_the_output_untouched() {
    let local = vec![Aabb3::new(Vec3A::ZERO, Vec3A::ONE); 10];
    let xfs = vec![Rigid3::IDENTITY; 9];
    let sentinel = Aabb3::new(Vec3A::splat(7.0), Vec3A::splat(8.0));
    for backend in Backend::supported() {
        let batch = Batch::new(Method::SignSelect, Rounding::Outward)
            .on(backend)
            .unwrap();
        let mut out = vec![sentinel; 10];
        assert_eq!(
            batch.transform(&local, &xfs, &mut out),
            Err(BatchError::LengthMismatch {
                what: "poses",
                expected: 10,
                found: 9
            })
        );
        assert!(out.iter().all(|b| *b == sentinel));
        let mut short = vec![sentinel; 11];
        let err = batch
            .transform(&local, &Trs3::IDENTITY, &mut short)
            .unwrap_err();
        assert_eq!(
            err,
            BatchError::LengthMismatch {
                what: "output",
                expected: 10,
                found: 11
            }
        );
        assert!(short.iter().all(|b| *b == sentinel));
        assert!(!err.to_string().is_empty());

        let (l8, x8) = (Block8::pack(&local), Block8::pack(&xfs[..8]));
        let mut o8 = vec![Block8::from([sentinel; 8]); 2];
        assert!(batch.transform(&l8, &x8, &mut o8).is_err());
        assert!(o8.iter().all(|b| *b == Block8::from([sentinel; 8])));

        let soa = Soa::from_slice(&local);
        let mut ragged = soa.clone();
        ragged.columns[5].pop();
        let mut out_soa = Soa::filled(10, sentinel);
        let before = out_soa.clone();
        let xsoa = Soa::from_slice(&[Similarity3::IDENTITY; 10]);
        assert!(matches!(
            batch.transform(ragged.view(), xsoa.view(), out_soa.view_mut()),
            Err(BatchError::LengthMismatch { .. })
        ));
        let mut xragged = xsoa.clone();
        xragged.columns[7].push(0.0);
        assert!(matches!(
            batch.transform(&soa, &xragged, &mut out_soa),
            Err(BatchError::LengthMismatch { .. })
        ));
        assert_eq!(out_soa, before);

        let l2 = vec![Aabb2::new(Vec2::ZERO, Vec2::ONE); 3];
        let mut o2 = vec![Aabb2::EMPTY; 2];
        assert!(
            batch
                .transform(&l2, &[Rigid2::IDENTITY; 3][..], &mut o2)
                .is_err()
        );
        assert!(o2.iter().all(|b| *b == Aabb2::EMPTY));
    }
}

/// Every way to make `soa` ragged: each of its `columns` in turn one shorter and one longer.
fn ragged<S: Clone>(soa: &S, columns: fn(&mut S) -> &mut [Vec<f32>]) -> Vec<S> {
    let mut soa = soa.clone();
    let mut all = Vec::new();
    for c in 0..columns(&mut soa).len() {
        for longer in [false, true] {
            let mut r = soa.clone();
            if longer {
                columns(&mut r)[c].push(0.0);
            } else {
                columns(&mut r)[c].pop();
            }
            all.push(r);
        }
    }
    all
}

#[test]
fn ragged_soa_is_refused_with_nothing_written() {
    use bvkit::Swept;
    use bvkit::{Active, BoundingVolume, Margin, Moved, Sphere};
    // 21 values: two whole lane blocks and a tail, so that a late index panic would come
    // after earlier blocks were written.
    let n = 21;
    let local = vec![Aabb3::new(Vec3A::ZERO, Vec3A::ONE); n];
    let poses: Vec<Rigid3> = (0..n)
        .map(|k| Rigid3 {
            translation: Vec3A::splat(k as f32),
            ..Rigid3::IDENTITY
        })
        .collect();
    let (lsoa, xsoa) = (Soa::from_slice(&local), Soa::from_slice(&poses));
    let sentinel = Aabb3::new(Vec3A::splat(7.0), Vec3A::splat(8.0));
    let refused = |r: Result<(), BatchError>, what: &str| {
        assert!(
            matches!(r, Err(BatchError::LengthMismatch { .. })),
            "{what}: {r:?}"
        );
    };
    for backend in Backend::supported() {
        for batch in [
            Batch::new(Method::SignSelect, Rounding::Outward)
                .on(backend)
                .unwrap(),
            Batch::new(Method::AbsMatrix, Rounding::Nearest)
                .on(backend)
                .unwrap()
                .deterministic(),
        ] {
            let what = format!("{backend:?}");
            let fresh = || Soa::filled(n, sentinel);
            // Ragged transforms, through transform, update and both sides of Swept.
            for x in ragged(&xsoa, |s| s.columns.as_mut()) {
                let mut out = fresh();
                refused(batch.transform(&lsoa, &x, &mut out), &what);
                refused(
                    batch.transform(lsoa.view(), x.view(), out.view_mut()),
                    &what,
                );
                let mut aos = vec![sentinel; n];
                refused(batch.transform(&local, &x, &mut aos[..]), &what);
                let mut moved = Moved::new();
                let margin = Margin::new(0.1, 0.0);
                refused(
                    batch.update(margin, Active::All, &lsoa, &x, &mut out, &mut moved),
                    &what,
                );
                let swept = Swept {
                    current: &xsoa,
                    predicted: &x,
                };
                refused(
                    batch.update(margin, Active::All, &lsoa, swept, &mut out, &mut moved),
                    &what,
                );
                let swept = Swept {
                    current: &x,
                    predicted: &xsoa,
                };
                refused(
                    batch.update(
                        margin,
                        Active::All,
                        &local[..],
                        swept,
                        &mut aos[..],
                        &mut moved,
                    ),
                    &what,
                );
                assert!(
                    out == fresh() && aos.iter().all(|b| *b == sentinel),
                    "{what}: written"
                );
                assert!(moved.is_empty(), "{what}: moved written");
            }
            // Ragged boxes and ragged outputs.
            let update = |l: &Soa<Aabb3>, out: &mut Soa<Aabb3>| {
                let margin = Margin::new(0.1, 0.0);
                batch.update(margin, Active::All, l, &xsoa, out, &mut Moved::new())
            };
            for l in ragged(&lsoa, |s| s.columns.as_mut()) {
                let mut out = fresh();
                refused(batch.transform(&l, &xsoa, &mut out), &what);
                refused(update(&l, &mut out), &what);
                assert!(out == fresh(), "{what}: written");
            }
            for mut out in ragged(&fresh(), |s| s.columns.as_mut()) {
                let before = out.clone();
                refused(batch.transform(&lsoa, &xsoa, &mut out), &what);
                refused(update(&lsoa, &mut out), &what);
                assert!(out == before, "{what}: written");
            }
        }
    }
    // The fitted volumes' batch entry point reads transforms in the same layouts.
    let spheres = vec![
        Sphere {
            center: Vec3A::ZERO,
            radius: 1.0
        };
        n
    ];
    for x in ragged(&xsoa, |s| s.columns.as_mut()) {
        let mut out = vec![sentinel; n];
        refused(
            Sphere::transformed_aabbs(&spheres, &x, &mut out, Rounding::Outward),
            "volumes",
        );
        assert!(out.iter().all(|b| *b == sentinel), "volumes: written");
    }
}

// Out-of-range indices panic as documented, with a message that names the container.
#[test]
#[should_panic(expected = "Block8 index 8 out of range")]
fn block8_get_out_of_range_says_so() {
    let _ = Block8::splat(Aabb3::EMPTY).get(8);
}

#[test]
#[should_panic(expected = "Block8 index 9 out of range")]
fn block8_set_out_of_range_says_so() {
    Block8::splat(Rigid3::IDENTITY).set(9, Rigid3::IDENTITY);
}

#[test]
#[should_panic(expected = "Soa index 2 out of range: column 0 has 2 values")]
fn soa_get_on_a_short_column_says_so() {
    let mut soa = Soa::from_slice(&[Aabb3::EMPTY; 3]);
    soa.columns[0].pop();
    let _ = soa.get(2);
}

#[test]
fn backends_are_detected_and_forced() {
    let supported = Backend::supported();
    assert!(supported.contains(&Backend::Scalar) && supported.contains(&Backend::Baseline));
    assert!(supported.contains(&Backend::detect()));
    for b in Backend::ALL {
        let forced = Batch::new(Method::Naive, Rounding::Nearest).on(b);
        assert_eq!(forced.is_ok(), b.is_supported());
        if let Ok(batch) = forced {
            assert_eq!(batch.backend(), b);
        }
    }
    // On x86-64 the detected backend is the most capable run-time-dispatched one the CPU
    // has (without `std` there is no run-time detection: tests/features.rs covers that
    // case).
    #[cfg(all(target_arch = "x86_64", feature = "std"))]
    if Backend::Avx512.is_supported() {
        assert_eq!(Backend::detect(), Backend::Avx512);
    } else if Backend::Avx2.is_supported() {
        assert_eq!(Backend::detect(), Backend::Avx2);
    }
}

/// Outputs past `Batch::NON_TEMPORAL_BYTES` go to AoSoA blocks through non-temporal
/// stores: the bits equal the same blocks transformed in small calls (ordinary stores), on
/// the 8-lane backends, with NaN and unbounded boxes mixed in (their lanes are rewritten by the
/// extended path after the streamed store).
#[test]
fn streamed_outputs_have_the_same_bits() {
    use bvkit::Rigid3x8;
    use glam::Quat;
    let n = (Batch::NON_TEMPORAL_BYTES / 24 + 100).next_multiple_of(8);
    let local: Vec<Aabb3> = (0..n)
        .map(|k| match k % 997 {
            0 => Aabb3::new(Vec3A::splat(f32::NAN), Vec3A::ONE),
            1 => Aabb3::new(Vec3A::splat(f32::NEG_INFINITY), Vec3A::ONE),
            r => Aabb3::new(Vec3A::splat(-(r as f32)), Vec3A::new(1.0, 2.0, r as f32)),
        })
        .collect();
    let poses: Vec<Rigid3> = (0..n)
        .map(|k| {
            let a = k as f32 * 1e-3;
            Rigid3::new(Quat::from_xyzw(a.sin(), 0.3, a.cos(), 0.9), Vec3A::splat(a))
        })
        .collect();
    let (local8, poses8) = (Aabb3x8::pack(&local), Rigid3x8::pack(&poses));
    let bits = |blocks: &[Aabb3x8]| -> Vec<u32> {
        blocks
            .iter()
            .flat_map(|b| b.fields.iter().flatten().map(|x| x.to_bits()))
            .collect()
    };
    // The 8-lane backends stream (the others store as usual).
    let eight = [Backend::Baseline, Backend::Avx2].into_iter();
    for backend in eight.filter(|b| b.is_supported()) {
        let batch = Batch::new(Method::AbsMatrix, Rounding::Outward)
            .on(backend)
            .unwrap();
        let mut streamed = vec![Aabb3x8::default(); n / 8];
        batch.transform(&local8, &poses8, &mut streamed).unwrap();
        let mut stored = vec![Aabb3x8::default(); n / 8];
        for ((l, p), o) in local8
            .chunks(4096)
            .zip(poses8.chunks(4096))
            .zip(stored.chunks_mut(4096))
        {
            batch.transform(l, p, o).unwrap();
        }
        assert!(bits(&streamed) == bits(&stored), "{backend:?}");
    }
}

/// Boxes as the AoS loop meets them: ordinary ones, with one in about 97 that the fast
/// kernels cannot answer (NaN, empty, unbounded, overflowing) at a random position.
fn sparse_bad_boxes(len: usize, r: &mut StdRng) -> Vec<Aabb3> {
    let big = f32::MAX * 0.75;
    let bad = [
        Aabb3::new(Vec3A::new(f32::NAN, -1.0, 0.0), Vec3A::ONE),
        Aabb3::EMPTY,
        Aabb3::new(Vec3A::new(-1.0, f32::NEG_INFINITY, 0.0), Vec3A::ONE),
        Aabb3::new(Vec3A::splat(-big), Vec3A::splat(big)),
        Aabb3::new(Vec3A::ONE, Vec3A::new(1.0, 0.5, 1.0)),
    ];
    (0..len)
        .map(|_| {
            if r.random_range(0..97) == 0 {
                return bad[r.random_range(0..bad.len())];
            }
            let c = Vec3A::new(r.random(), r.random(), r.random()) * 200.0 - 100.0;
            let e = Vec3A::new(r.random(), r.random(), r.random()) * 5.0;
            Aabb3::new(c - e, c + e)
        })
        .collect()
}

/// The bits of a box, `x`, `y` and `z` of each face (NaN payloads included).
fn box_bits(b: &Aabb3) -> [[u32; 3]; 2] {
    [b.min.to_array(), b.max.to_array()].map(|v| v.map(f32::to_bits))
}

/// The AoS loop runs two or four boxes per vector and the single-box kernel's test once per chunk of
/// 64, redoing a failed chunk one box at a time. Whatever the backend, the mode, the
/// method, the rounding, the pose kind, the length (odd tails, chunk edges) and wherever
/// the bad boxes fall, every box gets the bits of `Aabb3::transformed` on it, and an update
/// the fat boxes and moved set of the scalar backend.
fn aos_like_single_box<T: Transform3 + Copy + core::fmt::Debug>(
    name: &str,
    pose: impl Fn(&mut StdRng) -> T,
) {
    let r = &mut rng(0xa05);
    for len in [0, 1, 2, 3, 63, 64, 65, 127, 128, 129, 300, 1031] {
        let local = sparse_bad_boxes(len, r);
        let poses: Vec<T> = (0..len.max(1)).map(|_| pose(r)).collect();
        let poses = &poses[..len];
        let shared = pose(r);
        let words: Vec<u64> = (0..len.div_ceil(64)).map(|_| r.random()).collect();
        let words: Vec<u64> = words
            .iter()
            .enumerate()
            .map(|(w, &m)| {
                if 64 * (w + 1) <= len {
                    m
                } else {
                    m & ((1 << (len % 64)) - 1)
                }
            })
            .collect();
        let list: Vec<u32> = (0..len as u32).filter(|_| r.random_bool(0.3)).collect();
        for method in Method::ALL {
            for rounding in Rounding::ALL {
                let single: Vec<Aabb3> = local
                    .iter()
                    .zip(poses)
                    .map(|(b, x)| b.transformed(x, method, rounding))
                    .collect();
                let single_shared: Vec<Aabb3> = local
                    .iter()
                    .map(|b| b.transformed(&shared, method, rounding))
                    .collect();
                let scalar = Batch::new(method, rounding).on(Backend::Scalar).unwrap();
                for backend in Backend::supported() {
                    for deterministic in [false, true] {
                        let mut batch = Batch::new(method, rounding).on(backend).unwrap();
                        if deterministic {
                            batch = batch.deterministic();
                        }
                        let what = format!(
                            "{name} {backend:?} {deterministic} {method:?} {rounding:?} len {len}"
                        );
                        let mut out = vec![Aabb3::NAN; len];
                        batch.transform(&local, poses, &mut out).unwrap();
                        for (k, (o, s)) in out.iter().zip(&single).enumerate() {
                            assert_eq!(box_bits(o), box_bits(s), "{what} box {k}: {:?}", local[k]);
                        }
                        batch.transform(&local, &shared, &mut out).unwrap();
                        for (k, (o, s)) in out.iter().zip(&single_shared).enumerate() {
                            assert_eq!(box_bits(o), box_bits(s), "{what} shared box {k}");
                        }
                        let margin = bvkit::Margin::new(0.5, 0.1);
                        for active in [
                            bvkit::Active::All,
                            bvkit::Active::Indices(&list),
                            bvkit::Active::Mask(&words),
                        ] {
                            let run = |b: &Batch| {
                                let mut fat = vec![Aabb3::NAN; len];
                                let mut moved = bvkit::Moved::new();
                                for _ in 0..2 {
                                    b.update(margin, active, &local, poses, &mut fat, &mut moved)
                                        .unwrap();
                                }
                                (fat, moved.indices().to_vec())
                            };
                            let ((fat, moved), (want_fat, want_moved)) =
                                (run(&batch), run(&scalar));
                            assert_eq!(moved, want_moved, "{what} {active:?}");
                            for (k, (f, w)) in fat.iter().zip(&want_fat).enumerate() {
                                assert_eq!(box_bits(f), box_bits(w), "{what} {active:?} fat {k}");
                            }
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn aos_batches_give_the_single_box_bits_with_bad_boxes_anywhere() {
    fn quat(r: &mut StdRng) -> glam::Quat {
        let v = glam::Vec4::new(r.random(), r.random(), r.random(), r.random()) * 2.0 - 1.0;
        glam::Quat::from_vec4(v).normalize()
    }
    fn t(r: &mut StdRng) -> glam::Vec3 {
        glam::Vec3::new(r.random(), r.random(), r.random()) * 2000.0 - 1000.0
    }
    aos_like_single_box("rigid3", |r| Rigid3::new(quat(r), t(r).into()));
    aos_like_single_box("affine3", |r| {
        let s = glam::Vec3::new(r.random(), r.random(), r.random()) * 3.0 - 1.5;
        Affine3A::from_scale_rotation_translation(s, quat(r), t(r))
    });
    aos_like_single_box("trs3", |r| {
        let s = glam::Vec3::new(r.random(), r.random(), r.random()) * 3.0;
        Trs3::from((s, quat(r), t(r)))
    });
    aos_like_single_box("similarity3", |r| {
        Similarity3::new(r.random::<f32>() * 4.0, quat(r), t(r).into())
    });
    aos_like_single_box("translation3", |r| Translation3(t(r).into()));
}
