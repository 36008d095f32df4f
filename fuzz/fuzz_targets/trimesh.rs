//! `TriMesh` against its contract: meshes of 3 to 6 triangles (indices may be out of range,
//! vertices anything), both layouts, `refit`, `with_tolerance` and similarity poses (any
//! quaternion, any scale). A build or refit errs exactly when the input is bad and then
//! leaves the mesh as it was; a query errs only when its poses or tolerance cannot be
//! decided ([`bvkit_fuzz::query_error_justified`]); otherwise `overlapping_triangles` equals
//! the brute-force pairs of the exact leaf test (or of the distance, with a tolerance) on the
//! query's placed vertices, in every layout, and `intersects` agrees.
#![no_main]

use bvkit::tree::{
    Layout, Paired, Quantized, Query, TriMesh, triangles_distance_sq, triangles_intersect,
};
use bvkit::{Rigid3, Similarity3};
use bvkit_fuzz::{Floats, query_error_justified, similarity};
use glam::Vec3;
use libfuzzer_sys::fuzz_target;

/// Vertices and triangles: `3 + b % 4` of each from the next bytes.
fn raw(f: &mut Floats) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let (nv, nt) = (3 + f.byte() as usize % 4, 3 + f.byte() as usize % 4);
    let v = (0..nv).map(|_| Vec3::from_array(f.array())).collect();
    // An index out of range now and then (a byte of 250 or more).
    let index = |f: &mut Floats| match f.byte() {
        b @ 250.. => nv as u32 + u32::from(b - 250),
        b => u32::from(b) % nv as u32,
    };
    let t = (0..nt).map(|_| [(); 3].map(|()| index(f))).collect();
    (v, t)
}

fn good(v: &[Vec3], t: &[[u32; 3]]) -> bool {
    v.iter().all(|p| p.is_finite()) && t.iter().flatten().all(|&i| (i as usize) < v.len())
}

/// The pairs `(i, j)` the query must report: every pair of triangles whose placed vertices
/// meet (exact leaf test), or lie within the tolerance (`f64` distance).
fn brute<LA: Layout, LB: Layout>(
    q: &Query<TriMesh<LA>, TriMesh<LB>>,
    a: &TriMesh<LA>,
    b: &TriMesh<LB>,
    tolerance: f32,
) -> Vec<(u32, u32)> {
    let mut pairs = Vec::new();
    for i in 0..a.triangles().len() as u32 {
        let ta = a.triangle(i).unwrap().map(|v| v.as_dvec3());
        for j in 0..b.triangles().len() as u32 {
            let tb = b.triangle(j).unwrap().map(|v| q.relative().place(v));
            assert!(
                tb.iter().all(|p| p.is_finite()),
                "placed outside f64: {tb:?}"
            );
            let meet = if tolerance > 0.0 {
                triangles_distance_sq(&ta, &tb) <= f64::from(tolerance).powi(2)
            } else {
                triangles_intersect(&ta, &tb)
            };
            if meet {
                pairs.push((i, j));
            }
        }
    }
    pairs
}

/// The query's answer, checked against brute force; `None` for a justified error.
fn check<LA: Layout, LB: Layout>(
    a: &TriMesh<LA>,
    b: &TriMesh<LB>,
    pa: Similarity3,
    pb: Similarity3,
    tolerance: f32,
) -> Option<Vec<(u32, u32)>> {
    // The construction checks the poses and the range, then `with_tolerance` the tolerance.
    let q = Query::similarity(a, pa, b, pb).map_err(|e| (e, 0.0));
    let q = match q.and_then(|q| q.with_tolerance(tolerance).map_err(|e| (e, tolerance))) {
        Ok(q) => q,
        Err((e, t)) => {
            let why = query_error_justified(&pa, &pb, t, e);
            assert!(why, "{e}: {pa:?} {pb:?} {tolerance}");
            return None;
        }
    };
    assert!(a.reach().is_finite() && b.reach().is_finite());
    let mut ours = q.overlapping_triangles();
    ours.sort_unstable();
    let expected = brute(&q, a, b, tolerance);
    assert_eq!(ours, expected, "{a:?} {b:?} {pa:?} {pb:?} {tolerance}");
    assert_eq!(q.intersects(), !expected.is_empty());
    Some(ours)
}

fuzz_target!(|data: &[u8]| {
    let mut f = Floats::new(data);
    let flags = f.byte();
    let pa = similarity(&mut f, flags & 1 != 0);
    let pb = similarity(&mut f, flags & 2 != 0);
    // Zero, or any value (negated on a flag, so that negative ones occur often).
    let tolerance = match (flags & 4 != 0, flags & 8 != 0) {
        (false, _) => 0.0,
        (true, false) => f.next(),
        (true, true) => -f.next().abs(),
    };
    let (va, ia) = raw(&mut f);
    let (vb, ib) = raw(&mut f);
    let refit: Option<Vec<Vec3>> = (flags & 16 != 0).then(|| {
        let n = va.len() + usize::from(flags & 32 != 0);
        (0..n).map(|_| Vec3::from_array(f.array())).collect()
    });
    let built = TriMesh::new(va.clone(), ia.clone());
    assert_eq!(built.is_ok(), good(&va, &ia));
    let (Ok(mut a), Ok(b)) = (built, TriMesh::new(vb, ib)) else {
        return;
    };
    if let Some(v) = refit {
        let before = a.vertices().to_vec();
        match a.refit(&v) {
            Ok(()) => {
                assert!(v.len() == before.len() && v.iter().all(|p| p.is_finite()));
                assert_eq!(a.vertices(), &v[..]);
            }
            Err(e) => {
                assert!(
                    v.len() != before.len() || !v.iter().all(|p| p.is_finite()),
                    "{e}"
                );
                assert_eq!(a.vertices(), &before[..]);
            }
        }
    }
    let (aq, bq) = (a.with_layout::<Quantized>(), b.with_layout::<Quantized>());
    let (aw, bw) = (a.with_layout::<Paired>(), b.with_layout::<Paired>());
    // The layouts find the same pairs. (Near the 2^300 range limit one may err where
    // another does not: a quantized tree's reach is a few grid steps larger.)
    let compact = check(&a, &b, pa, pb, tolerance);
    if let (Some(x), Some(y)) = (check(&aq, &bq, pa, pb, tolerance), &compact) {
        assert_eq!(&x, y);
    }
    if let (Some(x), Some(y)) = (check(&aw, &bw, pa, pb, tolerance), &compact) {
        assert_eq!(&x, y);
    }
    // The rigid entry points agree with the similarity query at unit scale.
    if pa.scale == 1.0 && pb.scale == 1.0 && tolerance == 0.0 {
        let rigid = |p: Similarity3| Rigid3::new(p.rotation, p.translation);
        let r = a
            .overlapping_triangles(rigid(pa), &b, rigid(pb))
            .map(|mut v| {
                v.sort_unstable();
                v
            });
        assert_eq!(r.ok(), compact);
    }
});
