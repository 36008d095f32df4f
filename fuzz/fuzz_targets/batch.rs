//! Batches of fuzzed boxes through a backend, method, rounding and transform class chosen by
//! the input, in every layout (AoS, AoSoA, SoA, shared): each box obeys the single-box
//! contract, and bad lengths are refused with the output untouched.
#![no_main]

use bvkit::{
    Aabb3, Backend, Batch, Block8, Method, Rounding, Soa, Transform2, Transform3, Translation3,
};
use bvkit_fuzz::oracle::{Bound, Exactly};
use bvkit_fuzz::{Floats, affine2, affine3, assert_contract, bound_of, rigid2};
use glam::Vec3A;
use libfuzzer_sys::fuzz_target;

/// Every 3D layout of one class against the oracle.
fn layouts3<T: Transform3, P: Exactly<3>>(batch: Batch, ps: &[P], inputs: impl Fn(&P) -> (Aabb3, T)) {
    let bound = |m| bound_of(T::nearest_gamma(m), batch.rounding);
    let b: Bound = bound(batch.method);
    let (local, xfs): (Vec<Aabb3>, Vec<T>) = ps.iter().map(inputs).unzip();
    let n = ps.len();
    let what = format!("{:?} {:?} {:?}", batch.backend(), batch.method, batch.rounding);
    let mut out = vec![Aabb3::NAN; n];
    batch.transform(&local, &xfs, &mut out).unwrap();
    for (p, o) in ps.iter().zip(&out) {
        assert_contract(p, o.min.to_array(), o.max.to_array(), b, &format!("aos {what}"));
    }
    let (lb, xb) = (Block8::pack(&local), Block8::pack(&xfs));
    let mut ob = vec![Block8::<Aabb3>::default(); lb.len()];
    batch.transform(&lb, &xb, &mut ob).unwrap();
    for (p, o) in ps.iter().zip(Block8::unpack(&ob, n)) {
        assert_contract(p, o.min.to_array(), o.max.to_array(), b, &format!("aosoa {what}"));
    }
    let (ls, xs) = (Soa::from_slice(&local), Soa::from_slice(&xfs));
    let mut os = Soa::filled(n, Aabb3::NAN);
    batch.transform(&ls, &xs, &mut os).unwrap();
    for (k, p) in ps.iter().enumerate() {
        let o = os.get(k);
        assert_contract(p, o.min.to_array(), o.max.to_array(), b, &format!("soa {what}"));
    }
    if let Some(first) = xfs.first() {
        batch.transform(&local, first, &mut out).unwrap();
        for (p, o) in ps.iter().zip(&out) {
            let p = ps[0].with_box(p.lo(), p.hi());
            assert_contract(&p, o.min.to_array(), o.max.to_array(), b, &format!("shared {what}"));
        }
        let mut short = vec![Aabb3::NAN; n - 1];
        assert!(batch.transform(&local, &xfs, &mut short).is_err());
        assert!(short.iter().all(|b| b.min.is_nan()), "output written on a length error");
    }
}

fuzz_target!(|data: &[u8]| {
    let mut f = Floats::new(data);
    // One backend, method, rounding and class per input, so that each execution is cheap
    // and the fuzzer spends its time on the boxes.
    let supported = Backend::supported();
    let backend = supported[usize::from(f.byte()) % supported.len()];
    let method = Method::ALL[usize::from(f.byte()) % 3];
    let rounding = Rounding::ALL[usize::from(f.byte()) % 2];
    let class = f.byte() % 8;
    let n = usize::from(f.byte() % 24);
    let batch = Batch::new(method, rounding).on(backend).unwrap();
    match class {
        0 => {
            let ps: Vec<_> = (0..n).map(|_| f.problem::<3>()).collect();
            layouts3(batch, &ps, affine3);
        }
        1 => {
            let ps: Vec<_> = (0..n).map(|_| f.translation_problem::<3>()).collect();
            layouts3(batch, &ps, |p| (affine3(p).0, Translation3(Vec3A::from_array(p.t))));
        }
        2 => {
            let ps: Vec<_> = (0..n).map(|_| f.quat_problem(None)).collect();
            layouts3(batch, &ps, |p| (p.aabb(), p.rigid3()));
        }
        3 => {
            let ps: Vec<_> = (0..n).map(|_| f.quat_problem(Some(true))).collect();
            layouts3(batch, &ps, |p| (p.aabb(), p.similarity3()));
        }
        4 => {
            let ps: Vec<_> = (0..n).map(|_| f.quat_problem(Some(false))).collect();
            layouts3(batch, &ps, |p| (p.aabb(), p.trs3()));
        }
        c => {
            // 2D: affine, rigid, translation, AoS.
            let ps: Vec<_> = (0..n).map(|_| f.problem::<2>()).collect();
            let what = format!("2D {c} {backend:?} {method:?} {rounding:?}");
            let mut out = vec![bvkit::Aabb2::NAN; n];
            if c == 5 {
                let (l, x): (Vec<_>, Vec<_>) = ps.iter().map(affine2).unzip();
                batch.transform(&l, &x, &mut out).unwrap();
                let b = bound_of(glam::Affine2::nearest_gamma(method), rounding);
                for (p, o) in ps.iter().zip(&out) {
                    assert_contract(p, o.min.to_array(), o.max.to_array(), b, &what);
                }
            } else if c == 6 {
                let rigid: Vec<_> = ps.iter().map(rigid2).collect();
                let (l, x): (Vec<_>, Vec<_>) = rigid.iter().map(|(_, b, x)| (*b, *x)).unzip();
                batch.transform(&l, &x, &mut out).unwrap();
                let b = bound_of(bvkit::Rigid2::nearest_gamma(method), rounding);
                for ((p, _, _), o) in rigid.iter().zip(&out) {
                    assert_contract(p, o.min.to_array(), o.max.to_array(), b, &what);
                }
            } else {
                let ps: Vec<_> = (0..n).map(|_| f.translation_problem::<2>()).collect();
                let (l, x): (Vec<_>, Vec<_>) = ps
                    .iter()
                    .map(|p| (affine2(p).0, bvkit::Translation2(glam::Vec2::from_array(p.t))))
                    .unzip();
                batch.transform(&l, &x, &mut out).unwrap();
                let b = bound_of(bvkit::Translation2::nearest_gamma(method), rounding);
                for (p, o) in ps.iter().zip(&out) {
                    assert_contract(p, o.min.to_array(), o.max.to_array(), b, &what);
                }
            }
        }
    }
});
