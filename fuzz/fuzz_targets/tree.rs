//! The trees' node-pair box test against the exact rational separating-axis test: two boxes
//! and two rigid poses from the fuzzer (any quaternion, unit or not), and whenever the exact
//! boxes overlap under the query's relative map, the conservative test must say so. Then two
//! two-triangle meshes at those poses: `overlapping_triangles` equals the brute-force exact
//! pairs, `intersects` agrees, and nothing panics (bad vertices are an error, and so is a
//! pose that cannot be placed: never a silent "no contact").
#![no_main]

use bvkit_support::sat;

use bvkit::tree::{QueryError, Relative, TriMesh, triangles_intersect};
use bvkit::{Aabb3, Rigid3};
use bvkit_fuzz::{Floats, query_error_justified};
use glam::{Quat, Vec3, Vec3A};
use libfuzzer_sys::fuzz_target;

fn ordered(f: &mut Floats) -> Aabb3 {
    let (p, q) = (Vec3A::from_array(f.array()), Vec3A::from_array(f.array()));
    Aabb3::new(p.min(q), p.max(q))
}

fn pose(f: &mut Floats) -> Rigid3 {
    Rigid3::new(Quat::from_array(f.array()), Vec3A::from_array(f.array()))
}

fuzz_target!(|data: &[u8]| {
    let mut f = Floats::new(data);
    let (pa, pb) = (pose(&mut f), pose(&mut f));
    let (a, b) = (ordered(&mut f), ordered(&mut f));
    let reach = |x: &Aabb3| f64::from(x.min.abs().max(x.max.abs()).max_element());
    let finite = [a.min, a.max, b.min, b.max].iter().all(|v| v.is_finite());
    match Relative::new(&pa, reach(&a), &pb, reach(&b), 0.0) {
        Ok(rel) => {
            let ours = rel.overlaps(&a, &b);
            if finite && sat::exact_overlap(&a, &b, rel.matrix(), rel.translation()) {
                assert!(
                    ours,
                    "exact boxes overlap, reported separated: {a:?} {b:?} {pa:?} {pb:?}"
                );
            }
        }
        // An error only for a box with an infinite face (its reach) or a pose that cannot
        // be placed.
        Err(QueryError::InvalidReach { .. }) => assert!(!finite, "{a:?} {b:?}"),
        Err(e) => assert!(justified(&pa, &pb, e), "{e}: {pa:?} {pb:?}"),
    }
    let mut mesh = || {
        let v: Vec<Vec3> = (0..4).map(|_| Vec3::from_array(f.array())).collect();
        TriMesh::new(v, vec![[0, 1, 2], [1, 3, 2]])
    };
    let (Ok(ma), Ok(mb)) = (mesh(), mesh()) else {
        return;
    };
    let q = match ma.query(pa, &mb, pb) {
        Ok(q) => q,
        Err(e) => {
            assert!(justified(&pa, &pb, e), "{e}: {pa:?} {pb:?}");
            assert_eq!(ma.intersects(pa, &mb, pb), Err(e));
            return;
        }
    };
    let mut ours = q.overlapping_triangles();
    ours.sort_unstable();
    let mut brute = Vec::new();
    for i in 0..2 {
        for j in 0..2 {
            let ta = ma.triangle(i).unwrap().map(|v| v.as_dvec3());
            let tb = mb.triangle(j).unwrap().map(|v| q.relative().place(v));
            assert!(
                tb.iter().all(|p| p.is_finite()),
                "placed outside f64: {tb:?}"
            );
            if triangles_intersect(&ta, &tb) {
                brute.push((i, j));
            }
        }
    }
    assert_eq!(ours, brute, "{ma:?} {mb:?} {pa:?} {pb:?}");
    assert_eq!(q.intersects(), !brute.is_empty());
});

fn justified(pa: &Rigid3, pb: &Rigid3, e: QueryError) -> bool {
    query_error_justified(&(*pa).into(), &(*pb).into(), 0.0, e)
}
