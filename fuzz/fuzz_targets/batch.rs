//! Batches of fuzzed boxes through a backend, method, rounding and transform class chosen by
//! the input, in every layout (AoS, AoSoA, SoA, shared): each box obeys the single-box
//! contract, and bad lengths are refused with the output untouched. In 3D also: a ragged
//! SoA (any column of the boxes, transforms or output one shorter or longer) is refused by
//! `transform`, `transform_par`, `update` and `transformed_aabbs` with nothing written; and
//! `transform_par` gives the bits of `transform` in every layout, on the fuzzed boxes
//! repeated past the size at which it splits the work.
#![no_main]

use bvkit::{
    Aabb3, Active, Backend, Batch, BatchError, Block8, BoundingVolume, Margin, Method, Moved,
    Rounding, Soa, Sphere, Transform2, Transform3, Translation3,
};
use bvkit_fuzz::oracle::{Bound, Exactly};
use bvkit_fuzz::{Floats, affine2, affine3, assert_contract, bound_of, rigid2};
use glam::Vec3A;
use libfuzzer_sys::fuzz_target;

/// The bits of every column.
fn column_bits(columns: &[Vec<f32>]) -> Vec<u32> {
    columns.iter().flatten().map(|x| x.to_bits()).collect()
}

/// Column `c` (modulo their number) one longer, or one shorter where it has a value.
fn make_ragged(columns: &mut [Vec<f32>], c: usize, longer: bool) {
    let column = &mut columns[c % columns.len()];
    if longer || column.pop().is_none() {
        column.push(0.0);
    }
}

/// Every entry point refuses SoA columns of unequal lengths and writes nothing: `role` 0
/// makes a box column ragged, 1 a transform column, 2 an output column.
fn ragged3<T: Transform3>(
    batch: Batch,
    local: &[Aabb3],
    xfs: &[T],
    (role, c, longer): (u8, usize, bool),
) {
    let (mut l, mut x, mut o) = (
        Soa::from_slice(local),
        Soa::from_slice(xfs),
        Soa::filled(local.len(), Aabb3::NAN),
    );
    match role % 3 {
        0 => make_ragged(&mut l.columns, c, longer),
        1 => make_ragged(x.columns.as_mut(), c, longer),
        _ => make_ragged(&mut o.columns, c, longer),
    }
    let before = column_bits(&o.columns);
    let refused = |r: Result<(), BatchError>, what: &str| {
        assert!(
            matches!(r, Err(BatchError::LengthMismatch { .. })),
            "ragged {role} {c} {longer} {what}: {r:?}"
        );
    };
    refused(batch.transform(&l, &x, &mut o), "transform");
    refused(batch.transform_par(&l, &x, &mut o), "transform_par");
    let mut moved = Moved::new();
    refused(
        batch.update(Margin::ZERO, Active::All, &l, &x, &mut o, &mut moved),
        "update",
    );
    assert!(
        column_bits(&o.columns) == before && moved.is_empty(),
        "ragged {role} {c}: written"
    );
    if role % 3 == 1 {
        let spheres = vec![
            Sphere {
                center: Vec3A::ZERO,
                radius: 1.0
            };
            local.len()
        ];
        let mut out = vec![Aabb3::NAN; local.len()];
        refused(
            Sphere::transformed_aabbs(&spheres, &x, &mut out, batch.rounding),
            "volumes",
        );
        assert!(out.iter().all(|b| b.min.is_nan()), "volumes: written");
    }
}

/// `transform_par` against `transform`, bitwise, in every layout, on `local` and `xfs`
/// repeated to more than two parts.
fn parallel3<T: Transform3>(batch: Batch, local: &[Aabb3], xfs: &[T]) {
    let n = 2 * 4096 + 8 + local.len();
    let local: Vec<Aabb3> = local.iter().copied().cycle().take(n).collect();
    let xfs: Vec<T> = xfs.iter().copied().cycle().take(n).collect();
    let bits = |b: &[Aabb3]| -> Vec<[u32; 6]> {
        b.iter()
            .map(|b| {
                let [x, y, z] = b.min.to_array().map(f32::to_bits);
                let [u, v, w] = b.max.to_array().map(f32::to_bits);
                [x, y, z, u, v, w]
            })
            .collect()
    };
    let (mut serial, mut parallel) = (vec![Aabb3::NAN; n], vec![Aabb3::NAN; n]);
    batch.transform(&local, &xfs, &mut serial).unwrap();
    batch.transform_par(&local, &xfs, &mut parallel).unwrap();
    assert!(
        bits(&serial) == bits(&parallel),
        "aos transform_par differs"
    );
    let (lb, xb) = (Block8::pack(&local), Block8::pack(&xfs));
    let (mut sb, mut pb) = (
        vec![Block8::<Aabb3>::default(); lb.len()],
        vec![Block8::<Aabb3>::default(); lb.len()],
    );
    batch.transform(&lb, &xb, &mut sb).unwrap();
    batch.transform_par(&lb, &xb, &mut pb).unwrap();
    assert!(
        bits(&Block8::unpack(&sb, n)) == bits(&Block8::unpack(&pb, n)),
        "aosoa transform_par differs"
    );
    let (ls, xs) = (Soa::from_slice(&local), Soa::from_slice(&xfs));
    let (mut ss, mut ps) = (Soa::filled(n, Aabb3::NAN), Soa::filled(n, Aabb3::NAN));
    batch.transform(&ls, &xs, &mut ss).unwrap();
    batch.transform_par(&ls, &xs, &mut ps).unwrap();
    assert!(
        column_bits(&ss.columns) == column_bits(&ps.columns),
        "soa transform_par differs"
    );
}

/// Every 3D layout of one class against the oracle; `extra` is the fuzzer's choice of the
/// ragged SoA and whether to run the parallel comparison.
fn layouts3<T: Transform3, P: Exactly<3>>(
    batch: Batch,
    ps: &[P],
    inputs: impl Fn(&P) -> (Aabb3, T),
    extra: (u8, usize, bool, bool),
) {
    let bound = |m| bound_of(T::nearest_order(m), batch.rounding);
    let b: Bound = bound(batch.method);
    let (local, xfs): (Vec<Aabb3>, Vec<T>) = ps.iter().map(inputs).unzip();
    let n = ps.len();
    let what = format!(
        "{:?} {:?} {:?}",
        batch.backend(),
        batch.method,
        batch.rounding
    );
    let mut out = vec![Aabb3::NAN; n];
    batch.transform(&local, &xfs, &mut out).unwrap();
    for (p, o) in ps.iter().zip(&out) {
        assert_contract(
            p,
            o.min.to_array(),
            o.max.to_array(),
            b,
            &format!("aos {what}"),
        );
    }
    // The AoS loop (two or four boxes per vector, its test taken per chunk) gives every box the
    // bits of the single-box call, on every backend and in both modes.
    let bits = |b: &Aabb3| [b.min.to_array(), b.max.to_array()].map(|v| v.map(f32::to_bits));
    for ((l, x), o) in local.iter().zip(&xfs).zip(&out) {
        let single = l.transformed(x, batch.method, batch.rounding);
        assert_eq!(
            bits(o),
            bits(&single),
            "aos {what}: not the single-box bits of {l:?}"
        );
    }
    let (lb, xb) = (Block8::pack(&local), Block8::pack(&xfs));
    let mut ob = vec![Block8::<Aabb3>::default(); lb.len()];
    batch.transform(&lb, &xb, &mut ob).unwrap();
    for (p, o) in ps.iter().zip(Block8::unpack(&ob, n)) {
        assert_contract(
            p,
            o.min.to_array(),
            o.max.to_array(),
            b,
            &format!("aosoa {what}"),
        );
    }
    let (ls, xs) = (Soa::from_slice(&local), Soa::from_slice(&xfs));
    let mut os = Soa::filled(n, Aabb3::NAN);
    batch.transform(&ls, &xs, &mut os).unwrap();
    for (k, p) in ps.iter().enumerate() {
        let o = os.get(k);
        assert_contract(
            p,
            o.min.to_array(),
            o.max.to_array(),
            b,
            &format!("soa {what}"),
        );
    }
    if let Some(first) = xfs.first() {
        batch.transform(&local, first, &mut out).unwrap();
        for (p, o) in ps.iter().zip(&out) {
            let p = ps[0].with_box(p.lo(), p.hi());
            assert_contract(
                &p,
                o.min.to_array(),
                o.max.to_array(),
                b,
                &format!("shared {what}"),
            );
        }
        let mut short = vec![Aabb3::NAN; n - 1];
        assert!(batch.transform(&local, &xfs, &mut short).is_err());
        assert!(
            short.iter().all(|b| b.min.is_nan()),
            "output written on a length error"
        );
    }
    let (role, c, longer, parallel) = extra;
    ragged3(batch, &local, &xfs, (role, c, longer));
    if parallel && n > 0 {
        parallel3(batch, &local, &xfs);
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
    let mut batch = Batch::new(method, rounding).on(backend).unwrap();
    let (mode, role, c) = (f.byte(), f.byte(), usize::from(f.byte()));
    if mode & 1 == 1 {
        batch = batch.deterministic();
    }
    // The parallel comparison costs thousands of boxes, each through instrumented code (at
    // one input in sixteen it took nine tenths of the time): one input in 256.
    let extra = (role, c, mode & 2 == 2, mode >> 4 == 0 && role >> 4 == 0);
    match class {
        0 => {
            let ps: Vec<_> = (0..n).map(|_| f.problem::<3>()).collect();
            layouts3(batch, &ps, affine3, extra);
        }
        1 => {
            let ps: Vec<_> = (0..n).map(|_| f.translation_problem::<3>()).collect();
            layouts3(
                batch,
                &ps,
                |p| (affine3(p).0, Translation3(Vec3A::from_array(p.t))),
                extra,
            );
        }
        2 => {
            let ps: Vec<_> = (0..n).map(|_| f.quat_problem(None)).collect();
            layouts3(batch, &ps, |p| (p.aabb(), p.rigid3()), extra);
        }
        3 => {
            let ps: Vec<_> = (0..n).map(|_| f.quat_problem(Some(true))).collect();
            layouts3(batch, &ps, |p| (p.aabb(), p.similarity3()), extra);
        }
        4 => {
            let ps: Vec<_> = (0..n).map(|_| f.quat_problem(Some(false))).collect();
            layouts3(batch, &ps, |p| (p.aabb(), p.trs3()), extra);
        }
        c => {
            // 2D: affine, rigid, translation, AoS.
            let ps: Vec<_> = (0..n).map(|_| f.problem::<2>()).collect();
            let what = format!("2D {c} {backend:?} {method:?} {rounding:?}");
            let mut out = vec![bvkit::Aabb2::NAN; n];
            if c == 5 {
                let (l, x): (Vec<_>, Vec<_>) = ps.iter().map(affine2).unzip();
                batch.transform(&l, &x, &mut out).unwrap();
                let b = bound_of(glam::Affine2::nearest_order(method), rounding);
                for (p, o) in ps.iter().zip(&out) {
                    assert_contract(p, o.min.to_array(), o.max.to_array(), b, &what);
                }
            } else if c == 6 {
                let rigid: Vec<_> = ps.iter().map(rigid2).collect();
                let (l, x): (Vec<_>, Vec<_>) = rigid.iter().map(|(_, b, x)| (*b, *x)).unzip();
                batch.transform(&l, &x, &mut out).unwrap();
                let b = bound_of(bvkit::Rigid2::nearest_order(method), rounding);
                for ((p, _, _), o) in rigid.iter().zip(&out) {
                    assert_contract(p, o.min.to_array(), o.max.to_array(), b, &what);
                }
            } else {
                let ps: Vec<_> = (0..n).map(|_| f.translation_problem::<2>()).collect();
                let (l, x): (Vec<_>, Vec<_>) = ps
                    .iter()
                    .map(|p| {
                        (
                            affine2(p).0,
                            bvkit::Translation2(glam::Vec2::from_array(p.t)),
                        )
                    })
                    .unzip();
                batch.transform(&l, &x, &mut out).unwrap();
                let b = bound_of(bvkit::Translation2::nearest_order(method), rounding);
                for (p, o) in ps.iter().zip(&out) {
                    assert_contract(p, o.min.to_array(), o.max.to_array(), b, &what);
                }
            }
        }
    }
});
