//! Every batch layout on every backend this CPU supports, against the scalar reference and
//! the exact oracle, for every method and rounding, at awkward lengths.

mod cases;
mod oracle;

use bvkit::{
    Aabb2, Aabb3, Aabb3x8, AabbSoa, Affine3Soa, Affine3x8, Backend, Batch, BatchError, Method,
    Rigid2, Rounding, transform_slice,
};
use glam::{Affine2, Affine3A, Vec2, Vec3A};
use rand::RngExt;

use cases::{Class, problem, rigid_problem, rng};
use oracle::{Bound, Problem, affine2, affine3, check};

const LENGTHS: [usize; 8] = [0, 1, 7, 8, 9, 63, 1000, 0];

/// Problems of mixed classes, so that lanes of one block take different paths.
fn problems<const N: usize>(
    len: usize,
    seed: u64,
    make: impl Fn(Class, &mut rand::rngs::StdRng) -> Problem<N>,
) -> Vec<Problem<N>> {
    let r = &mut rng(seed);
    (0..len)
        .map(|_| {
            let class = if r.random_bool(0.7) {
                Class::Typical
            } else {
                Class::ALL[r.random_range(0..Class::ALL.len())]
            };
            make(class, r)
        })
        .collect()
}

/// Same faces: equal values (min/max may pick either zero of `max(+0, -0)`), NaN as NaN.
fn same(a: &[f32], b: &[f32]) -> bool {
    a.iter()
        .zip(b)
        .all(|(x, y)| x == y || (x.is_nan() && y.is_nan()))
}

/// A box as its faces, so that one checker serves 3D and 2D.
trait Faces<const N: usize>: core::fmt::Debug {
    fn faces(&self) -> ([f32; N], [f32; N]);
}

impl Faces<3> for Aabb3 {
    fn faces(&self) -> ([f32; 3], [f32; 3]) {
        (self.min.to_array(), self.max.to_array())
    }
}

impl Faces<2> for Aabb2 {
    fn faces(&self) -> ([f32; 2], [f32; 2]) {
        (self.min.to_array(), self.max.to_array())
    }
}

/// Backends whose arithmetic is the scalar reference's, rounding for rounding (no FMA).
fn bitwise_like_scalar(b: Backend) -> bool {
    matches!(b, Backend::Scalar | Backend::Baseline)
        || (b == Backend::Wide && !cfg!(target_feature = "fma"))
}

/// Every box of `out` against the oracle, and against the scalar `reference` when the
/// backend rounds as the scalar path does.
fn check_boxes<const N: usize, B: Faces<N>>(
    name: &str,
    ps: &[Problem<N>],
    out: &[B],
    reference: &[B],
    bitwise: bool,
    method: Method,
    rounding: Rounding,
) {
    assert_eq!(out.len(), ps.len(), "{name}");
    let bound = Bound::documented(method, rounding, N as u32);
    for (k, (p, o)) in ps.iter().zip(out).enumerate() {
        let (min, max) = o.faces();
        if let Err(e) = check(p, min, max, bound) {
            panic!("{name} box {k}: {e}\n{p:?}");
        }
        let (rmin, rmax) = reference[k].faces();
        assert!(
            !bitwise || (same(&min, &rmin) && same(&max, &rmax)),
            "{name} box {k}: {o:?} != scalar {:?}",
            reference[k]
        );
    }
}

#[test]
fn every_3d_layout_on_every_backend() {
    let random_len = rng(7).random_range(100..3000);
    for (n, &len) in LENGTHS.iter().enumerate() {
        let len = if n == LENGTHS.len() - 1 {
            random_len
        } else {
            len
        };
        let ps = problems::<3>(len, 100 + n as u64, problem);
        let (local, xfs): (Vec<Aabb3>, Vec<Affine3A>) = ps.iter().map(affine3).unzip();
        let shared = xfs.first().copied().unwrap_or(Affine3A::IDENTITY);
        let shared_ps: Vec<Problem<3>> = ps
            .iter()
            .map(|p| Problem {
                cols: ps[0].cols,
                t: ps[0].t,
                ..*p
            })
            .collect();
        for method in Method::ALL {
            for rounding in Rounding::ALL {
                // The scalar reference: the single-box scalar kernel.
                let reference: Vec<Aabb3> = local
                    .iter()
                    .zip(&xfs)
                    .map(|(b, x)| b.transformed_scalar(x, method, rounding))
                    .collect();
                let reference_shared: Vec<Aabb3> = local
                    .iter()
                    .map(|b| b.transformed_scalar(&shared, method, rounding))
                    .collect();
                for backend in Backend::supported() {
                    let batch = Batch::new(method, rounding).on(backend).unwrap();
                    let bitwise = bitwise_like_scalar(backend);
                    let name = |layout: &str| {
                        format!("{layout} {backend:?} {method:?} {rounding:?} len {len}")
                    };

                    let mut out = vec![Aabb3::NAN; len];
                    batch.aos(&local, &xfs, &mut out).unwrap();
                    check_boxes(
                        &name("aos"),
                        &ps,
                        &out,
                        &reference,
                        bitwise,
                        method,
                        rounding,
                    );
                    if !ps.is_empty() {
                        batch.aos_shared(&local, &shared, &mut out).unwrap();
                        check_boxes(
                            &name("aos shared"),
                            &shared_ps,
                            &out,
                            &reference_shared,
                            bitwise,
                            method,
                            rounding,
                        );
                    }

                    let (local8, xfs8) = (Aabb3x8::pack(&local), Affine3x8::pack(&xfs));
                    let mut out8 = vec![Aabb3x8::EMPTY; local8.len()];
                    batch.aosoa(&local8, &xfs8, &mut out8).unwrap();
                    check_boxes(
                        &name("aosoa"),
                        &ps,
                        &Aabb3x8::unpack(&out8, len),
                        &reference,
                        bitwise,
                        method,
                        rounding,
                    );
                    // Padding lanes: EMPTY through the identity stays EMPTY.
                    assert!(
                        Aabb3x8::unpack(&out8, local8.len() * 8)[len..]
                            .iter()
                            .all(|b| *b == Aabb3::EMPTY)
                    );
                    if !ps.is_empty() {
                        batch.aosoa_shared(&local8, &shared, &mut out8).unwrap();
                        check_boxes(
                            &name("aosoa shared"),
                            &shared_ps,
                            &Aabb3x8::unpack(&out8, len),
                            &reference_shared,
                            bitwise,
                            method,
                            rounding,
                        );
                    }

                    let (soa, xsoa) = (AabbSoa::from_boxes(&local), Affine3Soa::from_affines(&xfs));
                    let mut out_soa = AabbSoa::empty(len);
                    batch
                        .soa(soa.view(), xsoa.view(), out_soa.view_mut())
                        .unwrap();
                    let got: Vec<Aabb3> = (0..len).map(|k| out_soa.get(k)).collect();
                    check_boxes(
                        &name("soa"),
                        &ps,
                        &got,
                        &reference,
                        bitwise,
                        method,
                        rounding,
                    );
                    if !ps.is_empty() {
                        batch
                            .soa_shared(soa.view(), &shared, out_soa.view_mut())
                            .unwrap();
                        let got: Vec<Aabb3> = (0..len).map(|k| out_soa.get(k)).collect();
                        check_boxes(
                            &name("soa shared"),
                            &shared_ps,
                            &got,
                            &reference_shared,
                            bitwise,
                            method,
                            rounding,
                        );
                    }
                }
                let mut out = vec![Aabb3::NAN; len];
                transform_slice(&local, &xfs, &mut out, method, rounding).unwrap();
                check_boxes(
                    "transform_slice",
                    &ps,
                    &out,
                    &reference,
                    false,
                    method,
                    rounding,
                );
            }
        }
    }
}

#[test]
fn every_2d_layout_on_every_backend() {
    let random_len = rng(8).random_range(100..3000);
    for (n, &len) in LENGTHS.iter().enumerate() {
        let len = if n == LENGTHS.len() - 1 {
            random_len
        } else {
            len
        };
        let ps = problems::<2>(len, 200 + n as u64, problem);
        let rps = problems::<2>(len, 300 + n as u64, rigid_problem);
        let (local, xfs): (Vec<Aabb2>, Vec<Affine2>) = ps.iter().map(affine2).unzip();
        let rlocal: Vec<Aabb2> = rps.iter().map(|p| affine2(p).0).collect();
        let rigid: Vec<Rigid2> = rps
            .iter()
            .map(|p| Rigid2::new(p.cols[0][0], p.cols[0][1], Vec2::from_array(p.t)))
            .collect();
        for method in Method::ALL {
            for rounding in Rounding::ALL {
                let reference: Vec<Aabb2> = local
                    .iter()
                    .zip(&xfs)
                    .map(|(b, x)| b.transformed(x, method, rounding))
                    .collect();
                let rreference: Vec<Aabb2> = rlocal
                    .iter()
                    .zip(&rigid)
                    .map(|(b, x)| b.transformed_rigid(x, method, rounding))
                    .collect();
                for backend in Backend::supported() {
                    let batch = Batch::new(method, rounding).on(backend).unwrap();
                    let bitwise = bitwise_like_scalar(backend);
                    let name = |layout: &str| {
                        format!("{layout} {backend:?} {method:?} {rounding:?} len {len}")
                    };
                    let mut out = vec![Aabb2::NAN; len];
                    batch.aos2(&local, &xfs, &mut out).unwrap();
                    check_boxes(
                        &name("aos2"),
                        &ps,
                        &out,
                        &reference,
                        bitwise,
                        method,
                        rounding,
                    );
                    batch.aos_rigid2(&rlocal, &rigid, &mut out).unwrap();
                    check_boxes(
                        &name("rigid2"),
                        &rps,
                        &out,
                        &rreference,
                        bitwise,
                        method,
                        rounding,
                    );
                    if let (Some(x), Some(r)) = (xfs.first(), rigid.first()) {
                        let sp: Vec<Problem<2>> = ps
                            .iter()
                            .map(|p| Problem {
                                cols: ps[0].cols,
                                t: ps[0].t,
                                ..*p
                            })
                            .collect();
                        let sref: Vec<Aabb2> = local
                            .iter()
                            .map(|b| b.transformed(x, method, rounding))
                            .collect();
                        batch.aos2_shared(&local, x, &mut out).unwrap();
                        check_boxes(
                            &name("aos2 shared"),
                            &sp,
                            &out,
                            &sref,
                            bitwise,
                            method,
                            rounding,
                        );
                        let srp: Vec<Problem<2>> = rps
                            .iter()
                            .map(|p| Problem {
                                cols: rps[0].cols,
                                t: rps[0].t,
                                ..*p
                            })
                            .collect();
                        let srref: Vec<Aabb2> = rlocal
                            .iter()
                            .map(|b| b.transformed_rigid(r, method, rounding))
                            .collect();
                        batch.aos_rigid2_shared(&rlocal, r, &mut out).unwrap();
                        check_boxes(
                            &name("rigid2 shared"),
                            &srp,
                            &out,
                            &srref,
                            bitwise,
                            method,
                            rounding,
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn bad_lengths_are_refused_and_leave_the_output_untouched() {
    let local = vec![Aabb3::new(Vec3A::ZERO, Vec3A::ONE); 10];
    let xfs = vec![Affine3A::IDENTITY; 9];
    let sentinel = Aabb3::new(Vec3A::splat(7.0), Vec3A::splat(8.0));
    for backend in Backend::supported() {
        let batch = Batch::new(Method::SignSelect, Rounding::Outward)
            .on(backend)
            .unwrap();
        let mut out = vec![sentinel; 10];
        assert_eq!(
            batch.aos(&local, &xfs, &mut out),
            Err(BatchError::LengthMismatch {
                what: "transforms",
                expected: 10,
                found: 9
            })
        );
        assert!(out.iter().all(|b| *b == sentinel));
        let mut short = vec![sentinel; 11];
        let err = batch
            .aos_shared(&local, &Affine3A::IDENTITY, &mut short)
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

        let (l8, x8) = (Aabb3x8::pack(&local), Affine3x8::pack(&xfs[..8]));
        let mut o8 = vec![Aabb3x8::from([sentinel; 8]); 2];
        assert!(batch.aosoa(&l8, &x8, &mut o8).is_err());
        assert!(o8.iter().all(|b| *b == Aabb3x8::from([sentinel; 8])));

        let soa = AabbSoa::from_boxes(&local);
        let mut ragged = soa.clone();
        ragged.max[2].pop();
        let mut out_soa = AabbSoa::from_boxes(&[sentinel; 10]);
        let before = out_soa.clone();
        let xsoa = Affine3Soa::from_affines(&[Affine3A::IDENTITY; 10]);
        assert!(matches!(
            batch.soa(ragged.view(), xsoa.view(), out_soa.view_mut()),
            Err(BatchError::LengthMismatch { .. })
        ));
        let mut xragged = xsoa.clone();
        xragged.cols[1][2].push(0.0);
        assert!(matches!(
            batch.soa(soa.view(), xragged.view(), out_soa.view_mut()),
            Err(BatchError::LengthMismatch { .. })
        ));
        assert_eq!(out_soa, before);

        let l2 = vec![Aabb2::new(Vec2::ZERO, Vec2::ONE); 3];
        let mut o2 = vec![Aabb2::EMPTY; 2];
        assert!(
            batch
                .aos_rigid2(&l2, &[Rigid2::IDENTITY; 3], &mut o2)
                .is_err()
        );
        assert!(o2.iter().all(|b| *b == Aabb2::EMPTY));
    }
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
    // On x86-64 with AVX2 the detected backend must be a runtime-dispatched one.
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        assert!(matches!(Backend::detect(), Backend::Avx2 | Backend::Avx512));
    }
}
