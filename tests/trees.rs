//! Local-frame AABB trees against exact references:
//! - the node-pair box test against an exact rational separating-axis test (zero false
//!   "separated" verdicts over the adversarial classes);
//! - `overlapping_triangles` and `intersects` against a brute-force all-pairs test;
//! - the triangle test against an exact separating-axis reference;
//! - errors, refit, layouts and their sizes.

use bvkit_support::sat;
use bvkit_support::trimesh;

use std::ops::ControlFlow;

use bvkit::tree::{
    AabbTree, Compact, MeshError, Object, Paired, Quantized, Query, QueryError, Relative, TriMesh,
    triangles_distance_sq, triangles_intersect,
};
use bvkit::{Aabb3, Rigid3, Similarity3};
use glam::{DVec3, Quat, Vec3, Vec3A};
use sat::{exact_overlap, exact_triangles};
use trimesh::Uniform;

fn reach(boxes: &[Aabb3]) -> f64 {
    boxes
        .iter()
        .map(|b| f64::from(b.min.abs().max(b.max.abs()).max_element()))
        .fold(0.0, f64::max)
}

fn aabb(c: Vec3, h: Vec3) -> Aabb3 {
    Aabb3::new((c - h).into(), (c + h).into())
}

/// One adversarial case: `(a, b, pa, pb)`.
type Case = (Aabb3, Aabb3, Rigid3, Rigid3);

/// A box `b` and a pose, then `a` placed to just touch (or just miss) `b`'s exact image on
/// one axis of A: its face is the f64 extreme of the image, rounded to f32 either way.
fn near_contact(g: &mut Uniform, b: Aabb3, pa: Rigid3, pb: Rigid3, size: f32) -> Aabb3 {
    let rel = Relative::new(&pa, 1.0, &pb, 1.0, 0.0).unwrap();
    let corners: Vec<DVec3> = (0..8)
        .map(|k| {
            let p = Vec3::new(
                if k & 1 == 0 { b.min.x } else { b.max.x },
                if k & 2 == 0 { b.min.y } else { b.max.y },
                if k & 4 == 0 { b.min.z } else { b.max.z },
            );
            rel.place(p)
        })
        .collect();
    let axis = (g.next() * 3.0) as usize % 3;
    let upper = g.next() < 0.5;
    let mid: DVec3 = corners.iter().copied().sum::<DVec3>() / 8.0;
    let extreme = if upper {
        corners.iter().map(|c| c[axis]).fold(f64::MIN, f64::max)
    } else {
        corners.iter().map(|c| c[axis]).fold(f64::MAX, f64::min)
    };
    let mut face = extreme as f32;
    match (g.next() * 3.0) as u32 {
        0 => face = face.next_up(),
        1 => face = face.next_down(),
        _ => {}
    }
    let mut lo = mid.as_vec3() - Vec3::splat(size);
    let mut hi = mid.as_vec3() + Vec3::splat(size);
    // a sits beyond the face: its near face at `face`.
    if upper {
        lo[axis] = face;
        hi[axis] = face + size;
    } else {
        hi[axis] = face;
        lo[axis] = face - size;
    }
    Aabb3::new(lo.into(), hi.into())
}

fn adversarial_cases() -> Vec<(&'static str, Case)> {
    let mut g = Uniform(0x5eed_b0c5);
    let mut cases = Vec::new();
    let classes: [&str; 9] = [
        "generic",
        "far from origin",
        "thin and zero-width",
        "quarter turns (parallel edges)",
        "near identity",
        "touching faces (identity)",
        "huge scale",
        "tiny scale",
        "non-unit quaternions",
    ];
    for (ci, &class) in classes.iter().enumerate() {
        for _ in 0..220 {
            let scale: f32 = match class {
                "huge scale" => 1e30,
                "tiny scale" => 1e-30,
                _ => 1.0,
            };
            let offset = if class == "far from origin" {
                Vec3::new(3.0e5, -7.0e5, 1.1e6)
            } else {
                Vec3::ZERO
            };
            let mut size = Vec3::new(g.range(0.01, 2.0), g.range(0.01, 2.0), g.range(0.01, 2.0));
            if class == "thin and zero-width" {
                let k = (g.next() * 3.0) as usize % 3;
                size[k] = if g.next() < 0.5 { 0.0 } else { 1e-7 };
                if g.next() < 0.3 {
                    size[(k + 1) % 3] = 0.0;
                }
            }
            let rot = |g: &mut Uniform| -> Quat {
                match class {
                    "quarter turns (parallel edges)" => {
                        let k = (g.next() * 24.0) as i32;
                        Quat::from_euler(
                            glam::EulerRot::XYZ,
                            (k % 4) as f32 * std::f32::consts::FRAC_PI_2,
                            ((k / 4) % 3) as f32 * std::f32::consts::FRAC_PI_2,
                            ((k / 12) % 2) as f32 * std::f32::consts::PI,
                        )
                    }
                    "near identity" => Quat::from_xyzw(
                        g.range(-1e-7, 1e-7),
                        g.range(-1e-7, 1e-7),
                        g.range(-1e-7, 1e-7),
                        1.0,
                    ),
                    "touching faces (identity)" => Quat::IDENTITY,
                    "non-unit quaternions" => {
                        let q = g.rotation();
                        q * g.range(0.999, 1.001)
                    }
                    _ => g.rotation(),
                }
            };
            let (qa, qb) = (rot(&mut g), rot(&mut g));
            let ta = offset * scale
                + Vec3::new(g.range(-1.0, 1.0), g.range(-1.0, 1.0), g.range(-1.0, 1.0)) * scale;
            let tb =
                ta + Vec3::new(g.range(-2.0, 2.0), g.range(-2.0, 2.0), g.range(-2.0, 2.0)) * scale;
            let (pa, pb) = (Rigid3::new(qa, ta.into()), Rigid3::new(qb, tb.into()));
            let cb = offset * scale * 0.0
                + Vec3::new(g.range(-1.0, 1.0), g.range(-1.0, 1.0), g.range(-1.0, 1.0)) * scale;
            let b = aabb(cb, size * scale);
            let a = if ci % 2 == 0 || class == "touching faces (identity)" || g.next() < 0.5 {
                near_contact(&mut g, b, pa, pb, 0.5 * scale)
            } else {
                let ca =
                    Vec3::new(g.range(-2.0, 2.0), g.range(-2.0, 2.0), g.range(-2.0, 2.0)) * scale;
                aabb(
                    ca,
                    Vec3::new(g.range(0.0, 1.0), g.range(0.0, 1.0), g.range(0.0, 1.0)) * scale,
                )
            };
            cases.push((class, (a, b, pa, pb)));
        }
    }
    cases
}

#[test]
fn box_pair_test_never_separates_overlapping_boxes() {
    let mut overlapping = 0;
    let mut separated_found = 0;
    let mut separated_total = 0;
    for (class, (a, b, pa, pb)) in adversarial_cases() {
        let rel = Relative::new(&pa, reach(&[a]), &pb, reach(&[b]), 0.0).unwrap();
        let exact = exact_overlap(&a, &b, rel.matrix(), rel.translation());
        let ours = rel.overlaps(&a, &b);
        assert!(
            ours || !exact,
            "{class}: exact boxes overlap but reported separated: {a:?} {b:?} {pa:?} {pb:?}"
        );
        if exact {
            overlapping += 1;
        } else {
            separated_total += 1;
            separated_found += !ours as u32;
        }
    }
    // Not vacuous: both verdicts occur, and most separations are seen by 6 axes + pad.
    assert!(overlapping > 300, "{overlapping}");
    assert!(separated_total > 300, "{separated_total}");
    assert!(
        separated_found * 3 > separated_total,
        "{separated_found}/{separated_total}"
    );
}

#[test]
fn box_tree_leaf_pairs_contain_every_exact_overlap() {
    let mut g = Uniform(77);
    let boxes = |g: &mut Uniform, n: usize| -> Vec<Aabb3> {
        (0..n)
            .map(|_| {
                let c = Vec3::new(g.range(-3.0, 3.0), g.range(-3.0, 3.0), g.range(-3.0, 3.0));
                let mut h = Vec3::new(g.range(0.0, 0.4), g.range(0.0, 0.4), g.range(0.0, 0.4));
                if g.next() < 0.2 {
                    h.x = 0.0;
                }
                aabb(c, h)
            })
            .collect()
    };
    for round in 0..6 {
        let (ba, bb) = (boxes(&mut g, 40), boxes(&mut g, 30));
        let (pa, pb) = (
            trimesh::poses(1, 1.0, round)[0],
            trimesh::poses(1, 1.0, round + 99)[0],
        );
        let (ta, tb) = (AabbTree::new(&ba).unwrap(), AabbTree::new(&bb).unwrap());
        let (qa, qb) = (
            AabbTree::<Quantized>::build(&ba).unwrap(),
            AabbTree::<Quantized>::build(&bb).unwrap(),
        );
        let (wa, wb) = (
            AabbTree::<Paired>::build(&ba).unwrap(),
            AabbTree::<Paired>::build(&bb).unwrap(),
        );
        let pairs = ta.query(pa, &tb, pb).unwrap().leaf_pairs();
        let qpairs = qa.query(pa, &qb, pb).unwrap().leaf_pairs();
        let wpairs = wa.query(pa, &wb, pb).unwrap().leaf_pairs();
        let rel = Relative::new(&pa, 1.0, &pb, 1.0, 0.0).unwrap();
        let mut exact_count = 0;
        for (i, a) in ba.iter().enumerate() {
            for (j, b) in bb.iter().enumerate() {
                if exact_overlap(a, b, rel.matrix(), rel.translation()) {
                    exact_count += 1;
                    let p = (i as u32, j as u32);
                    assert!(pairs.contains(&p), "compact tree culled {p:?}");
                    assert!(qpairs.contains(&p), "quantized tree culled {p:?}");
                    assert!(wpairs.contains(&p), "paired tree culled {p:?}");
                }
            }
        }
        assert!(exact_count > 0);
        // Conservative but tight: the tree reports each pair once, and only pairs whose
        // boxes pass the per-pair test.
        let mut sorted = pairs.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), pairs.len());
        let rel = ta.query(pa, &tb, pb).unwrap().relative().to_owned();
        for &(i, j) in &pairs {
            assert!(rel.overlaps(&ba[i as usize], &bb[j as usize]));
        }
        // The paired tree holds the boxes on its grid, a little larger; it still reports
        // only pairs whose own boxes pass (found by the `aabb_tree` fuzz target).
        for &(i, j) in &wpairs {
            assert!(
                rel.overlaps(&ba[i as usize], &bb[j as usize]),
                "paired {i} {j}"
            );
        }
    }
}

#[test]
fn paired_trees_report_only_pairs_whose_own_boxes_pass() {
    // A big box makes the grid coarse (a step of 1/32); the small boxes are 0.01 apart,
    // far more than the pad and far less than a step. Their grid boxes overlap, their own
    // boxes do not (found by the `aabb_tree` fuzz target).
    let big = aabb(Vec3::ZERO, Vec3::splat(1000.0));
    let a = [big, Aabb3::new(Vec3A::ZERO, Vec3A::splat(0.001))];
    let b = [
        big,
        Aabb3::new(Vec3A::new(0.011, 0.0, 0.0), Vec3A::new(0.012, 0.001, 0.001)),
    ];
    let id = Rigid3::IDENTITY;
    let (ca, cb) = (AabbTree::new(&a).unwrap(), AabbTree::new(&b).unwrap());
    let (wa, wb) = (
        AabbTree::<Paired>::build(&a).unwrap(),
        AabbTree::<Paired>::build(&b).unwrap(),
    );
    let q = ca.query(id, &cb, id).unwrap();
    assert!(!q.relative().overlaps(&a[1], &b[1]));
    let mut compact = q.leaf_pairs();
    let mut paired = wa.query(id, &wb, id).unwrap().leaf_pairs();
    compact.sort_unstable();
    paired.sort_unstable();
    assert_eq!(compact, [(0, 0), (0, 1), (1, 0)]);
    assert_eq!(paired, compact);
}

// ---------------------------------------------------------------------------------------
// Triangles.

fn random_triangle(g: &mut Uniform, spread: f64) -> [DVec3; 3] {
    core::array::from_fn(|_| {
        DVec3::new(
            f64::from(g.range(-spread, spread)),
            f64::from(g.range(-spread, spread)),
            f64::from(g.range(-spread, spread)),
        )
    })
}

#[test]
fn triangle_test_matches_exact_reference() {
    let mut g = Uniform(4242);
    let mut hits = 0;
    for k in 0..2500 {
        let a = random_triangle(&mut g, 1.0);
        let mut b = random_triangle(&mut g, 1.0);
        match k % 5 {
            // touching: a vertex of b on an edge or at a vertex of a (exact midpoint)
            1 => b[0] = a[0],
            2 => b[1] = (a[0] + a[1]) * 0.5,
            // coplanar: b in a's plane (an exact affine combination on a dyadic grid)
            3 => {
                for p in &mut b {
                    let (s, t) = (f64::from(g.range(-1.0, 2.0)), f64::from(g.range(-1.0, 2.0)));
                    let (s, t) = ((s * 8.0).round() / 8.0, (t * 8.0).round() / 8.0);
                    *p = a[0] + (a[1] - a[0]) * s + (a[2] - a[0]) * t;
                }
            }
            // quarter-turned copy sharing an edge
            4 => b = [a[0], a[1], DVec3::new(a[2].y, -a[2].x, a[2].z)],
            _ => {}
        }
        let degenerate = |t: &[DVec3; 3]| (t[1] - t[0]).cross(t[2] - t[0]) == DVec3::ZERO;
        if degenerate(&a) || degenerate(&b) {
            continue;
        }
        let exact = exact_triangles(&a, &b);
        assert_eq!(triangles_intersect(&a, &b), exact, "{a:?} {b:?}");
        assert_eq!(triangles_intersect(&b, &a), exact, "{b:?} {a:?}");
        hits += exact as u32;
    }
    assert!(hits > 300, "{hits}");
}

#[test]
fn degenerate_triangles() {
    let d = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    let tri = [d(0.0, 0.0, 0.0), d(2.0, 0.0, 0.0), d(0.0, 2.0, 0.0)];
    // A segment through the face, touching it, and beside it.
    let through = [d(0.5, 0.5, -1.0), d(0.5, 0.5, 1.0), d(0.5, 0.5, 1.0)];
    let touching = [d(1.0, 1.0, 0.0), d(1.0, 1.0, 3.0), d(1.0, 1.0, 3.0)];
    let beside = [d(1.01, 1.0, -1.0), d(1.01, 1.0, 1.0), d(1.01, 1.0, 0.5)];
    assert!(triangles_intersect(&tri, &through));
    assert!(triangles_intersect(&tri, &touching));
    assert!(!triangles_intersect(&tri, &beside));
    // A point on an edge, a point just off it, collinear segments overlapping or not.
    let on_edge = [d(1.0, 0.0, 0.0); 3];
    let off_edge = [d(1.0, -1e-300, 0.0); 3];
    assert!(triangles_intersect(&tri, &on_edge));
    assert!(!triangles_intersect(&tri, &off_edge));
    let s1 = [d(0.0, 0.0, 5.0), d(1.0, 1.0, 5.0), d(2.0, 2.0, 5.0)];
    let s2 = [d(2.0, 2.0, 5.0), d(3.0, 3.0, 5.0), d(3.0, 3.0, 5.0)];
    let s3 = [d(2.5, 2.5, 5.0), d(3.0, 3.0, 5.0), d(3.0, 3.0, 5.0)];
    assert!(triangles_intersect(&s1, &s2));
    assert!(!triangles_intersect(&s1, &s3));
    assert!(triangles_intersect(
        &[d(1.0, 1.0, 1.0); 3],
        &[d(1.0, 1.0, 1.0); 3]
    ));
    assert!(!triangles_intersect(
        &[d(1.0, 1.0, 1.0); 3],
        &[d(1.0, 1.0, 1.0 + 1e-15); 3]
    ));
    // Distances.
    assert_eq!(triangles_distance_sq(&tri, &through), 0.0);
    let lifted = tri.map(|p| p + d(0.0, 0.0, 0.5));
    assert!((triangles_distance_sq(&tri, &lifted) - 0.25).abs() < 1e-12);
}

// ---------------------------------------------------------------------------------------
// Meshes against brute force.

fn brute_force<L, M>(
    a: &TriMesh<L>,
    b: &TriMesh<M>,
    rel: &Relative,
    tolerance: f32,
) -> Vec<(u32, u32)>
where
    L: bvkit::tree::Layout,
    M: bvkit::tree::Layout,
{
    let mut pairs = Vec::new();
    for i in 0..a.triangles().len() as u32 {
        let ta = a.triangle(i).unwrap().map(|v| v.as_dvec3());
        for j in 0..b.triangles().len() as u32 {
            let tb = b.triangle(j).unwrap().map(|v| rel.place(v));
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

/// A named mesh: vertices and triangles.
type Named = (&'static str, Vec<Vec3>, Vec<[u32; 3]>);

fn small_meshes() -> Vec<Named> {
    let (tv, tt) = trimesh::torus(1.0, 0.35, 10, 6);
    let cube_v: Vec<Vec3> = (0..8)
        .map(|k| Vec3::new((k & 1) as f32, ((k >> 1) & 1) as f32, ((k >> 2) & 1) as f32) - 0.5)
        .collect();
    let cube_t = vec![
        [0, 1, 3],
        [0, 3, 2],
        [4, 6, 7],
        [4, 7, 5],
        [0, 4, 5],
        [0, 5, 1],
        [2, 3, 7],
        [2, 7, 6],
        [0, 2, 6],
        [0, 6, 4],
        [1, 5, 7],
        [1, 7, 3],
    ];
    // A fan with a degenerate triangle and a repeated one.
    let fan_v = vec![
        Vec3::ZERO,
        Vec3::X,
        Vec3::Y,
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::Z,
    ];
    let fan_t = vec![[0, 1, 2], [0, 1, 3], [0, 2, 4], [0, 1, 2], [1, 4, 2]];
    vec![
        ("torus", tv, tt),
        ("cube", cube_v, cube_t),
        ("fan", fan_v, fan_t),
    ]
}

#[test]
fn overlapping_triangles_equal_brute_force() {
    let meshes = small_meshes();
    let mut total_pairs = 0;
    let mut any_disjoint = false;
    for (na, va, ia) in &meshes {
        let a = TriMesh::new(va.clone(), ia.clone()).unwrap();
        let aq = a.with_layout::<Quantized>();
        let aw = a.with_layout::<Paired>();
        for (nb, vb, ib) in &meshes {
            let b = TriMesh::new(vb.clone(), ib.clone()).unwrap();
            let bq = b.with_layout::<Quantized>();
            let bw = b.with_layout::<Paired>();
            for (k, (pa, pb)) in trimesh::poses(12, 0.8, 1)
                .into_iter()
                .zip(trimesh::poses(12, 0.8, 2))
                .enumerate()
            {
                // Some exact touching poses too: identity and quarter turns.
                let pb = if k % 4 == 0 {
                    Rigid3::new(
                        Quat::from_rotation_z(std::f32::consts::FRAC_PI_2),
                        Vec3A::ZERO,
                    )
                } else {
                    pb
                };
                let tolerance = if k % 3 == 2 { 0.05 } else { 0.0 };
                let q = Query::new(&a, pa, &b, pb)
                    .unwrap()
                    .with_tolerance(tolerance)
                    .unwrap();
                let mut ours = q.overlapping_triangles();
                ours.sort_unstable();
                let expected = brute_force(&a, &b, q.relative(), tolerance);
                assert_eq!(ours, expected, "{na} vs {nb}, pose {k}");
                assert_eq!(
                    q.intersects(),
                    !expected.is_empty(),
                    "{na} vs {nb}, pose {k}"
                );
                let mut quant = Query::new(&aq, pa, &bq, pb)
                    .and_then(|q| q.with_tolerance(tolerance))
                    .unwrap()
                    .overlapping_triangles();
                quant.sort_unstable();
                assert_eq!(quant, expected, "quantized {na} vs {nb}, pose {k}");
                let mut paired = Query::new(&aw, pa, &bw, pb)
                    .and_then(|q| q.with_tolerance(tolerance))
                    .unwrap()
                    .overlapping_triangles();
                paired.sort_unstable();
                assert_eq!(paired, expected, "paired {na} vs {nb}, pose {k}");
                let mut mixed = Query::new(&a, pa, &bw, pb)
                    .and_then(|q| q.with_tolerance(tolerance))
                    .unwrap()
                    .overlapping_triangles();
                mixed.sort_unstable();
                assert_eq!(mixed, expected, "compact × paired {na} vs {nb}, pose {k}");
                let mut cross = q.with_cross_axes_near_leaves(true).overlapping_triangles();
                cross.sort_unstable();
                assert_eq!(cross, expected, "cross axes {na} vs {nb}, pose {k}");
                total_pairs += expected.len();
                any_disjoint |= expected.is_empty();
            }
        }
    }
    assert!(total_pairs > 100 && any_disjoint, "{total_pairs}");
}

#[test]
fn visitor_stops_early() {
    let (v, t) = trimesh::torus(1.0, 0.35, 10, 6);
    let a = TriMesh::new(v, t).unwrap();
    let q = a
        .query(
            Rigid3::IDENTITY,
            &a,
            Rigid3::new(Quat::from_rotation_x(0.3), Vec3A::ZERO),
        )
        .unwrap();
    let all = q.overlapping_triangles();
    assert!(all.len() > 3);
    let mut seen = 0;
    let (flow, _) = q.visit(|_, _| {
        seen += 1;
        if seen == 3 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    assert!(flow.is_break());
    assert_eq!(seen, 3);
}

#[test]
fn first_contact_is_the_first_pair_in_descent_order() {
    let (v, t) = trimesh::torus(1.0, 0.3, 40, 25);
    let a = TriMesh::new(v, t).unwrap();
    let w = a.with_layout::<Paired>();
    let (mut hits, mut misses) = (0, 0);
    for (k, pose) in trimesh::poses(40, 1.2, 21).into_iter().enumerate() {
        let qw = w.query(Rigid3::IDENTITY, &w, pose).unwrap();
        let all = qw.overlapping_triangles();
        assert_eq!(
            qw.first_contact().0,
            all.first().copied(),
            "paired, pose {k}"
        );
        let q = a.query(Rigid3::IDENTITY, &a, pose).unwrap();
        let all = q.overlapping_triangles();
        let (first, stats) = q.first_contact();
        assert_eq!(first, all.first().copied(), "pose {k}");
        assert_eq!(q.intersects(), first.is_some(), "pose {k}");
        // It stops at once: no more work than the whole descent.
        let whole = q.visit(|_, _| ControlFlow::Continue(())).1;
        assert!(stats.node_pairs <= whole.node_pairs, "pose {k}");
        if first.is_some() {
            hits += 1;
        } else {
            misses += 1;
            assert_eq!(stats, whole, "pose {k}");
        }
    }
    assert!(hits > 5 && misses > 5, "{hits} hits, {misses} misses");
}

// ---------------------------------------------------------------------------------------
// Layouts, errors, refit.

#[test]
fn layouts_fit_their_budgets() {
    let (v, t) = trimesh::torus(1.0, 0.3, 40, 25);
    let n = t.len();
    let a = TriMesh::new(v, t).unwrap();
    assert!(a.tree_bytes() <= 32 * n, "{}", a.tree_bytes());
    let q = a.with_layout::<Quantized>();
    assert!(q.tree_bytes() <= 20 * n, "{}", q.tree_bytes());
    let w = a.with_layout::<Paired>();
    assert!(w.tree_bytes() <= 32 * n, "{}", w.tree_bytes());
    assert_eq!(a.tree_bytes() / 32, n - 1);
    // Deterministic: the same input builds the same tree.
    let b = TriMesh::new(a.vertices().to_vec(), a.triangles().to_vec()).unwrap();
    let pose = trimesh::poses(1, 0.5, 9)[0];
    assert_eq!(
        a.query(Rigid3::IDENTITY, &a, pose)
            .unwrap()
            .visit_boxes(|_, _| ControlFlow::Continue(()))
            .1,
        b.query(Rigid3::IDENTITY, &b, pose)
            .unwrap()
            .visit_boxes(|_, _| ControlFlow::Continue(()))
            .1
    );
}

#[test]
fn bad_input_is_an_error() {
    let v = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    assert_eq!(
        TriMesh::new(v.clone(), vec![]).unwrap_err(),
        MeshError::Empty
    );
    assert!(matches!(
        TriMesh::new(v.clone(), vec![[0, 1, 3]]),
        Err(MeshError::IndexOutOfRange {
            triangle: 0,
            index: 3,
            vertices: 3
        })
    ));
    let mut bad = v.clone();
    bad[1].y = f32::NAN;
    assert!(matches!(
        TriMesh::new(bad.clone(), vec![[0, 1, 2]]),
        Err(MeshError::NonFiniteVertex { vertex: 1, .. })
    ));
    let mut mesh = TriMesh::new(v.clone(), vec![[0, 1, 2]]).unwrap();
    assert!(mesh.refit(&bad).is_err());
    assert!(mesh.refit(&v[..2]).is_err());
    assert!(AabbTree::new(&[]).is_err());
    assert!(AabbTree::new(&[Aabb3::new(Vec3A::ONE, Vec3A::ZERO)]).is_err());
    assert!(AabbTree::new(&[Aabb3::new(Vec3A::ZERO, Vec3A::INFINITY)]).is_err());
    // One triangle against itself: touching everywhere.
    assert_eq!(
        mesh.overlapping_triangles(Rigid3::IDENTITY, &mesh, Rigid3::IDENTITY),
        Ok(vec![(0, 0)])
    );
}

/// A mesh whose vertices reach `±f32::MAX` is accepted by `TriMesh::new`, so it must be
/// queried like any other: a triangle against itself touches.
fn huge_mesh() -> TriMesh {
    let huge = vec![
        Vec3::splat(-f32::MAX),
        Vec3::splat(f32::MAX),
        Vec3::new(f32::MAX, 0.0, -f32::MAX),
        Vec3::new(0.0, f32::MAX, f32::MAX),
    ];
    TriMesh::new(huge, vec![[0, 1, 2], [2, 1, 0], [1, 3, 0]]).unwrap()
}

#[test]
fn geometry_reaching_f32_max_reports_contact() {
    let h = huge_mesh();
    let hq = h.with_layout::<Quantized>();
    let hw = h.with_layout::<Paired>();
    assert!(h.reach().is_finite() && hq.reach().is_finite() && hw.reach().is_finite());
    assert!(h.reach() >= f64::from(f32::MAX));
    assert_eq!(h.triangle(3), None);
    let id = Rigid3::IDENTITY;
    let turned = Rigid3::new(Quat::from_rotation_y(1.0), Vec3A::splat(1e38));
    for (pb, name) in [(id, "identity"), (turned, "turned")] {
        let q = Query::new(&h, id, &hq, pb).unwrap();
        let mut ours = q.overlapping_triangles();
        ours.sort_unstable();
        let expected = brute_force(&h, &hq, q.relative(), 0.0);
        assert!(!expected.is_empty(), "{name}");
        assert_eq!(ours, expected, "{name}");
        assert_eq!(h.intersects(id, &hq, pb), Ok(true), "{name}");
        assert_eq!(hq.intersects(id, &h, pb), Ok(true), "{name}");
        assert_eq!(hw.intersects(id, &hq, pb), Ok(true), "{name}");
        let mut paired = Query::new(&hw, id, &hw, pb)
            .unwrap()
            .overlapping_triangles();
        paired.sort_unstable();
        let expected = brute_force(
            &hw,
            &hw,
            Query::new(&hw, id, &hw, pb).unwrap().relative(),
            0.0,
        );
        assert!(!expected.is_empty(), "{name}");
        assert_eq!(paired, expected, "paired, {name}");
    }
    // Each triangle meets itself, in both layouts.
    for (i, j) in [(0, 0), (1, 1), (2, 2)] {
        assert!(
            h.overlapping_triangles(id, &h, id)
                .unwrap()
                .contains(&(i, j))
        );
        assert!(
            hq.overlapping_triangles(id, &hq, id)
                .unwrap()
                .contains(&(i, j))
        );
    }
    // Bare boxes: a box reaching ±f32::MAX overlaps itself and a small box inside it.
    let boxes = [
        Aabb3::new(Vec3A::splat(-f32::MAX), Vec3A::splat(f32::MAX)),
        Aabb3::new(Vec3A::ZERO, Vec3A::new(f32::MAX, 1.0, f32::MAX)),
        Aabb3::new(Vec3A::ONE, Vec3A::splat(2.0)),
    ];
    let t = AabbTree::new(&boxes).unwrap();
    let tq = AabbTree::<Quantized>::build(&boxes).unwrap();
    let tw = AabbTree::<Paired>::build(&boxes).unwrap();
    assert!(t.reach().is_finite() && tq.reach().is_finite() && tw.reach().is_finite());
    for pairs in [
        t.query(id, &t, id).unwrap().leaf_pairs(),
        tq.query(id, &tq, id).unwrap().leaf_pairs(),
        tw.query(id, &tw, turned).unwrap().leaf_pairs(),
        t.query(id, &tq, turned).unwrap().leaf_pairs(),
    ] {
        for p in [(0, 0), (0, 2), (2, 0), (1, 1)] {
            assert!(pairs.contains(&p), "{p:?} missing from {pairs:?}");
        }
    }
}

#[test]
fn queries_that_cannot_decide_are_errors() {
    let (v, t) = trimesh::torus(1.0, 0.35, 10, 6);
    let a = TriMesh::new(v, t).unwrap();
    let aq = a.with_layout::<Quantized>();
    let id = Rigid3::IDENTITY;
    // The same poses with valid components overlap: the errors below are not misses.
    assert_eq!(a.intersects(id, &a, id), Ok(true));
    let nan_q = Rigid3::new(Quat::from_xyzw(f32::NAN, 0.0, 0.0, 1.0), Vec3A::ZERO);
    let inf_t = Rigid3::new(Quat::IDENTITY, Vec3A::new(0.0, f32::INFINITY, 0.0));
    let pose_b = QueryError::NonFinitePose { object: Object::B };
    let pose_a = QueryError::NonFinitePose { object: Object::A };
    assert_eq!(a.intersects(id, &a, nan_q), Err(pose_b));
    assert_eq!(a.intersects(inf_t, &aq, id), Err(pose_a));
    assert_eq!(a.overlapping_triangles(id, &a, inf_t), Err(pose_b));
    // Tolerances: NaN, negative and infinite are errors; zero and positive are not.
    for tolerance in [f32::NAN, -0.5, f32::INFINITY, f32::NEG_INFINITY] {
        let r = a.query(id, &a, id).unwrap().with_tolerance(tolerance);
        assert!(
            matches!(r, Err(QueryError::InvalidTolerance { .. })),
            "{tolerance}"
        );
    }
    assert!(a.query(id, &a, id).unwrap().with_tolerance(0.0).is_ok());
    assert!(a.query(id, &a, id).unwrap().with_tolerance(0.1).is_ok());
    // Similarity poses: a zero scale and a NaN scale; a negative one reflects and is fine.
    let s = |scale: f32| Similarity3::new(scale, Quat::IDENTITY, Vec3A::ZERO);
    let zero = Query::similarity(&a, s(0.0), &aq, Similarity3::IDENTITY);
    assert!(matches!(
        zero,
        Err(QueryError::ZeroScale { object: Object::A })
    ));
    let nan = Query::similarity(&a, Similarity3::IDENTITY, &aq, s(f32::NAN));
    assert!(matches!(
        nan,
        Err(QueryError::NonFinitePose { object: Object::B })
    ));
    assert!(
        Query::similarity(&a, s(-1.0), &aq, s(-1.0))
            .unwrap()
            .intersects()
    );
    // A relative map out of range: huge non-unit quaternions on both poses (|M| near 2^400,
    // and near 2^510 with N·M overflowing f64), and a scale ratio of 2^276 on a huge mesh. One such
    // quaternion alone stays in range, and the exact leaf test decides it.
    let big = Rigid3::new(Quat::from_xyzw(1e30, 0.0, 0.0, 0.0), Vec3A::ZERO);
    assert_eq!(a.intersects(id, &a, big), Ok(true));
    for q in [
        Quat::from_xyzw(1e30, 0.0, 0.0, 0.0),
        Quat::from_array([f32::MAX; 4]),
    ] {
        let p = Rigid3::new(q, Vec3A::ZERO);
        assert_eq!(a.intersects(p, &a, p), Err(QueryError::OutOfRange), "{q:?}");
    }
    // The largest scale ratio (2^276) on a small mesh is in range; on a mesh reaching
    // f32::MAX it places B near 2^404.
    assert!(Query::similarity(&a, s(1e-45), &aq, s(f32::MAX)).is_ok());
    let h = huge_mesh();
    let ratio = Query::similarity(&a, s(1e-45), &h, s(f32::MAX));
    assert!(matches!(ratio, Err(QueryError::OutOfRange)));
    // Bare trees: the same errors.
    let boxes = [Aabb3::new(Vec3A::ZERO, Vec3A::ONE)];
    let tree = AabbTree::new(&boxes).unwrap();
    assert!(matches!(
        tree.query(id, &tree, nan_q),
        Err(QueryError::NonFinitePose { .. })
    ));
    assert_eq!(
        tree.query(id, &tree, id).unwrap().leaf_pairs(),
        vec![(0, 0)]
    );
    // The box-pair test on its own: bad reaches and tolerances.
    for (reach, tolerance) in [
        (f64::NAN, 0.0),
        (-1.0, 0.0),
        (f64::INFINITY, 0.0),
        (1.0, -1.0),
    ] {
        assert!(Relative::new(&id, reach, &id, 1.0, tolerance).is_err());
    }
    // Each error says what was wrong.
    let text = QueryError::ZeroScale { object: Object::A }.to_string();
    assert!(text.contains("zero scale"), "{text}");
}

#[test]
fn refit_matches_a_fresh_build() {
    let (v, t) = trimesh::torus(1.0, 0.35, 10, 6);
    let mut a = TriMesh::new(v.clone(), t.clone()).unwrap();
    let mut aq = a.with_layout::<Quantized>();
    let mut aw = a.with_layout::<Paired>();
    let moved: Vec<Vec3> = v
        .iter()
        .map(|p| *p * Vec3::new(1.3, 0.7, 1.0) + Vec3::new(0.1 * p.z.sin(), 0.0, 0.2))
        .collect();
    a.refit(&moved).unwrap();
    aq.refit(&moved).unwrap();
    aw.refit(&moved).unwrap();
    let fresh = TriMesh::new(moved, t.clone()).unwrap();
    let other = TriMesh::new(v, t).unwrap();
    for pose in trimesh::poses(8, 0.7, 5) {
        let mut x = a
            .overlapping_triangles(Rigid3::IDENTITY, &other, pose)
            .unwrap();
        let mut y = fresh
            .overlapping_triangles(Rigid3::IDENTITY, &other, pose)
            .unwrap();
        let mut z = aq
            .overlapping_triangles(Rigid3::IDENTITY, &other, pose)
            .unwrap();
        let mut w = aw
            .overlapping_triangles(Rigid3::IDENTITY, &other, pose)
            .unwrap();
        x.sort_unstable();
        y.sort_unstable();
        z.sort_unstable();
        w.sort_unstable();
        assert_eq!(x, y);
        assert_eq!(z, y);
        assert_eq!(w, y);
    }
    let _: &TriMesh<Compact> = &a;
}

#[test]
fn similarity_poses() {
    // Boxes: the adversarial cases with uniform scales on both poses.
    let mut g = Uniform(31337);
    let mut overlapping = 0;
    for (class, (a, b, pa, pb)) in adversarial_cases().into_iter().step_by(3) {
        let (sa, sb) = (g.range(0.25, 4.0), g.range(0.25, 4.0));
        let (sa, sb) = if g.next() < 0.2 { (-sa, sb) } else { (sa, sb) };
        let pa = Similarity3::new(sa, pa.rotation, pa.translation);
        let pb = Similarity3::new(sb, pb.rotation, pb.translation);
        let rel = Relative::similarity(&pa, reach(&[a]), &pb, reach(&[b]), 0.0).unwrap();
        let exact = exact_overlap(&a, &b, rel.matrix(), rel.translation());
        assert!(
            rel.overlaps(&a, &b) || !exact,
            "{class}: {a:?} {b:?} {pa:?} {pb:?}"
        );
        overlapping += exact as u32;
    }
    assert!(overlapping > 50, "{overlapping}");
    // Meshes: brute force at scaled poses.
    let (v, t) = trimesh::torus(1.0, 0.35, 10, 6);
    let a = TriMesh::new(v.clone(), t.clone()).unwrap();
    let b = TriMesh::new(v, t).unwrap().with_layout::<Quantized>();
    let mut total = 0;
    for (k, p) in trimesh::poses(10, 0.6, 21).into_iter().enumerate() {
        let s = 0.5 + 0.2 * k as f32;
        let pa = Similarity3::new(1.5, Quat::IDENTITY, Vec3A::ZERO);
        let pb = Similarity3::new(s, p.rotation, p.translation);
        let q = Query::similarity(&a, pa, &b, pb).unwrap();
        let mut ours = q.overlapping_triangles();
        ours.sort_unstable();
        let expected = brute_force(&a, &b, q.relative(), 0.0);
        assert_eq!(ours, expected, "pose {k}");
        total += expected.len();
    }
    assert!(total > 20, "{total}");
}

#[test]
fn sums_that_would_overflow_f32_never_separate() {
    // Found by the `tree` fuzz target: the placed center overflows f32 while the exact
    // boxes overlap just below f32::MAX.
    let a = Aabb3::new(
        Vec3A::new(-0.9887, -8.002_044_4e30, -0.8871),
        Vec3A::splat(f32::MAX),
    );
    let b = Aabb3::new(
        Vec3A::new(-0.7234, -2_097_152.0, 2.98e-43),
        Vec3A::new(0.0, 1e30, 1.175_494_4e-38),
    );
    let pa = Rigid3::new(Quat::IDENTITY, Vec3A::new(1e30, 1.2556e-41, 0.0));
    let pb = Rigid3::new(
        Quat::from_xyzw(0.0, 1.001_403_8, 0.0, 0.0),
        Vec3A::new(1e30, f32::MAX, f32::MAX),
    );
    let rel = Relative::new(&pa, reach(&[a]), &pb, reach(&[b]), 0.0).unwrap();
    assert!(exact_overlap(&a, &b, rel.matrix(), rel.translation()));
    assert!(rel.overlaps(&a, &b));
    assert_eq!(rel.pad(), f32::INFINITY);
}

#[test]
fn adversarial_builds_find_every_overlap() {
    // Exponentially spaced boxes (SAH would peel one per level) and boxes far from the
    // origin (the quantized grid): the tree still finds every exact overlap.
    let spaced: Vec<Aabb3> = (0..160)
        .map(|k| aabb(Vec3::new(1.07f32.powi(k), 0.0, 0.0), Vec3::splat(0.3)))
        .collect();
    let far: Vec<Aabb3> = (0..120)
        .map(|k| {
            let c = Vec3::new(
                1.0e5 + (k % 7) as f32 * 0.25,
                -3.0e5 + (k / 7) as f32 * 0.25,
                7.0e4,
            );
            aabb(c, Vec3::new(0.1, 0.2, 0.0))
        })
        .collect();
    for boxes in [spaced, far] {
        let compact = AabbTree::new(&boxes).unwrap();
        let quantized = AabbTree::<Quantized>::build(&boxes).unwrap();
        let paired = AabbTree::<Paired>::build(&boxes).unwrap();
        for (k, pose) in trimesh::poses(2, 0.3, 8).into_iter().enumerate() {
            let c0 = boxes[0].center();
            // B is A turned about A's first box (so that the far boxes still meet).
            let pose = Rigid3::new(pose.rotation, c0 - pose.rotation * c0);
            let q = compact.query(Rigid3::IDENTITY, &compact, pose).unwrap();
            let (pairs, qpairs, wpairs) = (
                q.leaf_pairs(),
                quantized
                    .query(Rigid3::IDENTITY, &quantized, pose)
                    .unwrap()
                    .leaf_pairs(),
                paired
                    .query(Rigid3::IDENTITY, &paired, pose)
                    .unwrap()
                    .leaf_pairs(),
            );
            let rel = q.relative();
            let mut exact = 0;
            for (i, a) in boxes.iter().enumerate() {
                for (j, b) in boxes.iter().enumerate().step_by(4) {
                    if exact_overlap(a, b, rel.matrix(), rel.translation()) {
                        exact += 1;
                        assert!(pairs.contains(&(i as u32, j as u32)), "compact, pose {k}");
                        assert!(
                            qpairs.contains(&(i as u32, j as u32)),
                            "quantized, pose {k}"
                        );
                        assert!(wpairs.contains(&(i as u32, j as u32)), "paired, pose {k}");
                    }
                }
            }
            assert!(exact > 0);
        }
    }
}
