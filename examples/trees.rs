//! Trees report: two tori (5k and 20k triangles) at 200 seeded poses and two copies of
//! spot at 200 seeded poses; bvkit's `intersects` against parry3d's
//! `query::intersection_test` between the two `TriMesh` shapes, and bvkit's
//! `overlapping_triangles` against parry's `Bvh::leaf_pairs` plus its triangle tests, in the
//! same run, for each of bvkit's three layouts. Prints a Markdown table (µs per query, node
//! pairs per query, bytes per triangle), then the targets of the trees issues, each met or
//! missed, judged on bvkit's fastest layout for that scene and query (named).
//!
//! `cargo run --release --features peers --example trees [--quick]`: with `--quick`, 8 poses per scene and
//! one timed run each, to check that the report runs (CI).

use bvkit_support::parry3d;
use bvkit_support::timing::{self, quick};
use bvkit_support::trimesh;

use std::cell::Cell;
use std::ops::ControlFlow;
use std::time::Duration;

use bvkit::Rigid3;
use bvkit::tree::{Paired, Quantized, TriMesh};
use glam::Vec3;
use parry3d::bounding_volume::BoundingVolume;
use parry3d::math::Pose;
use parry3d::query;
use parry3d::shape::TriMesh as ParryMesh;

/// The fastest of repeated calls (at least 3, for at least 0.3 s in all; one with `--quick`).
fn time<T>(f: impl FnMut() -> T) -> Duration {
    timing::fastest(Duration::from_millis(300), f)
}

struct Scene {
    name: &'static str,
    a: (Vec<Vec3>, Vec<[u32; 3]>),
    b: (Vec<Vec3>, Vec<[u32; 3]>),
    poses: Vec<Rigid3>,
}

fn scenes() -> Vec<Scene> {
    let poses = if quick() { 8 } else { 200 };
    vec![
        Scene {
            name: "tori 5k × 20k",
            a: trimesh::torus(1.0, 0.3, 50, 50),
            b: trimesh::torus(1.0, 0.3, 100, 100),
            poses: trimesh::poses(poses, 0.9, 11),
        },
        Scene {
            name: "spot × spot",
            a: trimesh::spot(),
            b: trimesh::spot(),
            poses: trimesh::poses(poses, 0.5, 12),
        },
    ]
}

fn parry_pose(p: &Rigid3) -> Pose {
    Pose::from_parts(p.translation.into(), p.rotation)
}

fn main() {
    println!(
        "| scene | query | bvkit µs/query | parry µs/query | speed-up | node pairs/query (bvkit, parry) | pairs found (bvkit, parry) |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|");
    let mut first_contact = Vec::new();
    let mut all_pairs = Vec::new();
    let mut bytes = Vec::new();
    for s in scenes() {
        let a = TriMesh::new(s.a.0.clone(), s.a.1.clone()).expect("mesh a");
        let b = TriMesh::new(s.b.0.clone(), s.b.1.clone()).expect("mesh b");
        let (aq, bq) = (a.with_layout::<Quantized>(), b.with_layout::<Quantized>());
        let (aw, bw) = (a.with_layout::<Paired>(), b.with_layout::<Paired>());
        let pa_ = ParryMesh::new(s.a.0.clone(), s.a.1.clone()).expect("parry a");
        let pb_ = ParryMesh::new(s.b.0.clone(), s.b.1.clone()).expect("parry b");
        let n = s.poses.len() as f64;
        let id = Rigid3::IDENTITY;
        let per = |d: Duration| d.as_secs_f64() * 1e6 / n;

        // First contact.
        let hits = s
            .poses
            .iter()
            .filter(|&&p| a.intersects(id, &b, p).expect("finite pose"))
            .count();
        let parry_hits = s
            .poses
            .iter()
            .filter(|&p| {
                query::intersection_test(&Pose::IDENTITY, &pa_, &parry_pose(p), &pb_)
                    .map(|r| r.intersecting)
                    .unwrap_or(false)
            })
            .count();
        let ours = time(|| {
            s.poses
                .iter()
                .filter(|&&p| a.intersects(id, &b, p).expect("finite pose"))
                .count()
        });
        let ours_q = time(|| {
            s.poses
                .iter()
                .filter(|&&p| aq.intersects(id, &bq, p).expect("finite pose"))
                .count()
        });
        let ours_w = time(|| {
            s.poses
                .iter()
                .filter(|&&p| aw.intersects(id, &bw, p).expect("finite pose"))
                .count()
        });
        let theirs = time(|| {
            s.poses
                .iter()
                .filter(|&p| {
                    query::intersection_test(&Pose::IDENTITY, &pa_, &parry_pose(p), &pb_)
                        .map(|r| r.intersecting)
                        .unwrap_or(false)
                })
                .count()
        });
        let visited: u64 = s
            .poses
            .iter()
            .map(|&p| {
                a.query(id, &b, p)
                    .expect("finite pose")
                    .first_contact()
                    .1
                    .node_pairs
            })
            .sum();
        let (fastest, best) = fastest_of(ours, ours_q, ours_w);
        println!(
            "| {} | intersects | {:.2} (quantized {:.2}, paired {:.2}) | {:.2} | {:.1}× ({fastest}) | {:.0}, – | {hits}/200, {parry_hits}/200 |",
            s.name,
            per(ours),
            per(ours_q),
            per(ours_w),
            per(theirs),
            theirs.as_secs_f64() / best.as_secs_f64(),
            visited as f64 / n,
        );
        first_contact.push(theirs.as_secs_f64() / best.as_secs_f64());

        // All pairs.
        let pairs: usize = s
            .poses
            .iter()
            .map(|&p| {
                a.overlapping_triangles(id, &b, p)
                    .expect("finite pose")
                    .len()
            })
            .sum();
        let parry_checks = Cell::new(0u64);
        let parry_all = |count: bool| -> usize {
            s.poses
                .iter()
                .map(|p| {
                    let pos12 = parry_pose(p);
                    pa_.bvh()
                        .leaf_pairs(pb_.bvh(), |n1, n2| {
                            if count {
                                parry_checks.set(parry_checks.get() + 1);
                            }
                            n1.aabb().intersects(&n2.aabb().transform_by(&pos12))
                        })
                        .filter(|&(i, j)| {
                            let t1 = pa_.triangle(i);
                            let t2 = pb_.triangle(j).transformed(&pos12);
                            query::intersection_test(&Pose::IDENTITY, &t1, &Pose::IDENTITY, &t2)
                                .map(|r| r.intersecting)
                                .unwrap_or(false)
                        })
                        .count()
                })
                .sum()
        };
        let parry_pairs = parry_all(true);
        let ours = time(|| {
            s.poses
                .iter()
                .map(|&p| {
                    a.overlapping_triangles(id, &b, p)
                        .expect("finite pose")
                        .len()
                })
                .sum::<usize>()
        });
        let ours_q = time(|| {
            s.poses
                .iter()
                .map(|&p| {
                    aq.overlapping_triangles(id, &bq, p)
                        .expect("finite pose")
                        .len()
                })
                .sum::<usize>()
        });
        let ours_w = time(|| {
            s.poses
                .iter()
                .map(|&p| {
                    aw.overlapping_triangles(id, &bw, p)
                        .expect("finite pose")
                        .len()
                })
                .sum::<usize>()
        });
        let ours_x = time(|| {
            s.poses
                .iter()
                .map(|&p| {
                    a.query(id, &b, p)
                        .expect("finite pose")
                        .with_cross_axes_near_leaves(true)
                        .overlapping_triangles()
                        .len()
                })
                .sum::<usize>()
        });
        let theirs = time(|| parry_all(false));
        let (visited, leaves): (u64, u64) = s
            .poses
            .iter()
            .map(|&p| {
                let st = a
                    .query(id, &b, p)
                    .expect("finite pose")
                    .visit(|_, _| ControlFlow::Continue(()))
                    .1;
                (st.node_pairs, st.leaf_pairs)
            })
            .fold((0, 0), |(x, y), (u, v)| (x + u, y + v));
        let leaves_x: u64 = s
            .poses
            .iter()
            .map(|&p| {
                a.query(id, &b, p)
                    .expect("finite pose")
                    .with_cross_axes_near_leaves(true)
                    .visit(|_, _| ControlFlow::Continue(()))
                    .1
                    .leaf_pairs
            })
            .sum();
        let (fastest, best) = fastest_of(ours, ours_q, ours_w);
        println!(
            "| {} | overlapping_triangles | {:.1} (quantized {:.1}, paired {:.1}; 15 axes near leaves {:.1}) | {:.1} | {:.1}× ({fastest}) | {:.0}, {:.0} | {pairs}, {parry_pairs} |",
            s.name,
            per(ours),
            per(ours_q),
            per(ours_w),
            per(ours_x),
            per(theirs),
            theirs.as_secs_f64() / best.as_secs_f64(),
            visited as f64 / n,
            parry_checks.get() as f64 / n,
        );
        println!(
            "| {} | triangle tests/query (6 axes, 15 near leaves) | {:.0}, {:.0} | | | | |",
            s.name,
            leaves as f64 / n,
            leaves_x as f64 / n
        );
        all_pairs.push(theirs.as_secs_f64() / best.as_secs_f64());
        let tris = |m: usize| m as f64 / s.b.1.len() as f64;
        bytes.push((
            s.name,
            tris(b.tree_bytes()),
            tris(bq.tree_bytes()),
            tris(bw.tree_bytes()),
            tris(pb_.bvh().total_memory_size()),
        ));
    }
    println!();
    println!(
        "| mesh (B) | bvkit compact B/tri | bvkit quantized B/tri | bvkit paired B/tri | parry Bvh B/tri |"
    );
    println!("|---|---:|---:|---:|---:|");
    for (name, c, q, w, p) in &bytes {
        println!("| {name} | {c:.1} | {q:.1} | {w:.1} | {p:.1} |");
    }
    println!();
    let worst = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let mark = |ok: bool| if ok { "met" } else { "missed" };
    let (fc, ap) = (worst(&first_contact), worst(&all_pairs));
    let b = bytes
        .iter()
        .map(|x| x.1.max(x.2).max(x.3))
        .fold(0.0, f64::max);
    println!("Targets (worst scene, bvkit's fastest layout; bytes: the largest layout):");
    println!(
        "- first contact ≥ 5× parry: {:.1}× — {}",
        fc,
        mark(fc >= 5.0)
    );
    println!("- all pairs ≥ 10× parry: {:.1}× — {}", ap, mark(ap >= 10.0));
    println!("- ≤ 32 bytes per triangle: {:.1} — {}", b, mark(b <= 32.0));
}

/// The fastest of the three layouts' times, named.
fn fastest_of(
    compact: Duration,
    quantized: Duration,
    paired: Duration,
) -> (&'static str, Duration) {
    [
        ("compact", compact),
        ("quantized", quantized),
        ("paired", paired),
    ]
    .into_iter()
    .min_by_key(|&(_, d)| d)
    .unwrap_or(("compact", compact))
}
