//! Batches of fuzzed boxes through a backend, method and rounding chosen by the input, in
//! every layout: each box obeys the single-box contract, and bad lengths are refused with
//! the output untouched.
#![no_main]

use bvkit::{
    Aabb2, Aabb3, Aabb3x8, AabbSoa, Affine3Soa, Affine3x8, Backend, Batch, Method, Rounding,
};
use bvkit_fuzz::{Floats, affine2, affine3, assert_contract, bound, oracle::Problem, rigid2};
use glam::Affine3A;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut f = Floats::new(data);
    // One backend, method and rounding per input, so that each execution is cheap and the
    // fuzzer spends its time on the boxes.
    let supported = Backend::supported();
    let backend = supported[usize::from(f.byte()) % supported.len()];
    let method = Method::ALL[usize::from(f.byte()) % 3];
    let rounding = Rounding::ALL[usize::from(f.byte()) % 2];
    let n = usize::from(f.byte() % 24);
    let ps: Vec<Problem<3>> = (0..n).map(|_| f.problem()).collect();
    let ps2: Vec<Problem<2>> = (0..n).map(|_| f.problem()).collect();
    let (local, xfs): (Vec<Aabb3>, Vec<Affine3A>) = ps.iter().map(affine3).unzip();
    let (l2, a2): (Vec<_>, Vec<_>) = ps2.iter().map(affine2).unzip();
    let rigid: Vec<_> = ps2.iter().map(rigid2).collect();
    let (l8, x8) = (Aabb3x8::pack(&local), Affine3x8::pack(&xfs));
    let (ls, xs) = (AabbSoa::from_boxes(&local), Affine3Soa::from_affines(&xfs));

    let batch = Batch::new(method, rounding).on(backend).unwrap();
    let (b3, b2) = (bound(method, rounding, 3), bound(method, rounding, 2));
    let what = format!("{backend:?} {method:?} {rounding:?}");
    let mut out = vec![Aabb3::NAN; n];
    batch.aos(&local, &xfs, &mut out).unwrap();
    for (p, o) in ps.iter().zip(&out) {
        assert_contract(
            p,
            o.min.to_array(),
            o.max.to_array(),
            b3,
            &format!("aos {what}"),
        );
    }
    let mut o8 = vec![Aabb3x8::EMPTY; l8.len()];
    batch.aosoa(&l8, &x8, &mut o8).unwrap();
    for (p, o) in ps.iter().zip(Aabb3x8::unpack(&o8, n)) {
        assert_contract(
            p,
            o.min.to_array(),
            o.max.to_array(),
            b3,
            &format!("aosoa {what}"),
        );
    }
    let mut os = AabbSoa::empty(n);
    batch.soa(ls.view(), xs.view(), os.view_mut()).unwrap();
    for (k, p) in ps.iter().enumerate() {
        let o = os.get(k);
        assert_contract(
            p,
            o.min.to_array(),
            o.max.to_array(),
            b3,
            &format!("soa {what}"),
        );
    }
    let mut o2 = vec![Aabb2::NAN; n];
    batch.aos2(&l2, &a2, &mut o2).unwrap();
    for (p, o) in ps2.iter().zip(&o2) {
        assert_contract(
            p,
            o.min.to_array(),
            o.max.to_array(),
            b2,
            &format!("aos2 {what}"),
        );
    }
    let (rl, rx): (Vec<_>, Vec<_>) = rigid.iter().map(|(_, b, x)| (*b, *x)).unzip();
    batch.aos_rigid2(&rl, &rx, &mut o2).unwrap();
    for ((p, _, _), o) in rigid.iter().zip(&o2) {
        assert_contract(
            p,
            o.min.to_array(),
            o.max.to_array(),
            b2,
            &format!("rigid2 {what}"),
        );
    }
    if n > 0 {
        let mut short = vec![Aabb3::NAN; n - 1];
        assert!(batch.aos(&local, &xfs, &mut short).is_err());
        assert!(
            short.iter().all(|b| b.min.is_nan()),
            "output written on a length error"
        );
    }
});
