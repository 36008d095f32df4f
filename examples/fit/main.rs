//! Fitting report: for every mesh, each shape × mode's volume as a ratio to the best volume
//! found for that shape, and its time per 100k vertices; peers (parry3d's OBB and bounding
//! sphere) and an exhaustive OBB search in the same run. Prints a Markdown table, then the
//! targets of the fitting issues, each met or missed.
//!
//! `cargo run --release --features peers --example fit [--quick]`: with `--quick`, two small meshes and one
//! timed run each, to check that the report runs (CI).

mod capsule_bound;

use bvkit_support::meshes;
use bvkit_support::parry3d;
use bvkit_support::timing::{self, quick};

use bvkit::{Capsule, Fit, Obb3, Sphere};
use glam::{DMat3, DQuat, DVec3, Vec3};
use std::time::Duration;

const MODES: [Fit; 3] = [Fit::Pca, Fit::Fast, Fit::Tight];

/// The fastest of repeated calls (at least 3, for at least 0.2 s in all; one with `--quick`).
fn time<T>(f: impl FnMut() -> T) -> Duration {
    timing::fastest(Duration::from_millis(200), f)
}

/// One fitted volume (or a reference) of one mesh.
struct Row {
    shape: &'static str,
    method: String,
    volume: f64,
    time: Option<Duration>,
}

/// A fixed-seed generator of uniform numbers in `[0, 1)` (xorshift64*).
struct Uniform(u64);

impl Uniform {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A uniformly random rotation (Shoemake's subgroup algorithm).
    fn rotation(&mut self) -> DQuat {
        let (u1, u2, u3) = (
            self.next(),
            self.next() * std::f64::consts::TAU,
            self.next() * std::f64::consts::TAU,
        );
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        DQuat::from_xyzw(a * u2.sin(), a * u2.cos(), b * u3.sin(), b * u3.cos())
    }
}

/// The volume of the midrange box with the axes of `q` around `points`.
fn box_volume(q: DQuat, points: &[DVec3]) -> f64 {
    let frame = DMat3::from_quat(q).transpose();
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for &p in points {
        let x = frame * p;
        lo = lo.min(x);
        hi = hi.max(x);
    }
    (hi - lo).element_product()
}

/// The exhaustive reference: 40,000 uniformly random rotations over the hull vertices
/// (parry3d's hull), then the best 24 refined by a random local search whose step shrinks
/// from 0.05 rad to 1e-7 rad. Returns the best volume.
fn exhaustive_obb(points: &[Vec3]) -> f64 {
    let (hull, _) = parry3d::transformation::convex_hull(points);
    let hull: Vec<DVec3> = hull.iter().map(|p| p.as_dvec3()).collect();
    let mut random = Uniform(0x5eed_0f0b_b0c5_1234);
    let mut samples: Vec<(f64, DQuat)> = (0..40_000)
        .map(|_| {
            let q = random.rotation();
            (box_volume(q, &hull), q)
        })
        .collect();
    samples.sort_by(|a, b| a.0.total_cmp(&b.0));
    samples
        .iter()
        .take(24)
        .map(|&(mut best, mut q)| {
            let mut step = 0.05;
            while step > 1e-7 {
                let mut improved = false;
                for _ in 0..40 {
                    let axis = DVec3::new(
                        random.next() - 0.5,
                        random.next() - 0.5,
                        random.next() - 0.5,
                    );
                    let trial =
                        (q * DQuat::from_scaled_axis(axis.normalize_or_zero() * step)).normalize();
                    let v = box_volume(trial, &hull);
                    if v < best {
                        (best, q, improved) = (v, trial, true);
                    }
                }
                if !improved {
                    step *= 0.5;
                }
            }
            best
        })
        .fold(f64::INFINITY, f64::min)
}

/// A lower bound on the radius of the smallest enclosing ball, from the dual of the
/// problem: for weights `λ >= 0` summing to 1 on any points, `r*² >= Σ λ_i |p_i − m|²`
/// with `m = Σ λ_i p_i`. The weights: the affine coordinates of the fitted center in the
/// points farthest from it (every subset of up to 4 of the 10 farthest), when nonnegative.
fn ball_lower_bound(points: &[Vec3], center: DVec3) -> f64 {
    let mut far: Vec<DVec3> = points.iter().map(|p| p.as_dvec3() - center).collect();
    far.sort_by(|a, b| b.length_squared().total_cmp(&a.length_squared()));
    far.dedup();
    far.truncate(10);
    let n = far.len();
    let mut best = 0.0f64;
    for mask in 1u32..1 << n {
        if mask.count_ones() > 4 {
            continue;
        }
        let set: Vec<DVec3> = (0..n)
            .filter(|i| mask >> i & 1 == 1)
            .map(|i| far[i])
            .collect();
        if let Some(weights) = affine_weights(&set) {
            let m: DVec3 = set.iter().zip(&weights).map(|(p, w)| *p * *w).sum();
            let spread: f64 = set
                .iter()
                .zip(&weights)
                .map(|(p, w)| w * (*p - m).length_squared())
                .sum();
            best = best.max(spread);
        }
    }
    best.sqrt()
}

/// Nonnegative weights summing to 1 whose combination of `set` is closest to the origin
/// (least squares in the affine hull, normal equations padded to 3×3), if they are all
/// nonnegative.
fn affine_weights(set: &[DVec3]) -> Option<Vec<f64>> {
    let (p0, rest) = set.split_first()?;
    let k = rest.len();
    let edge = |i: usize| rest.get(i).map_or(DVec3::ZERO, |p| *p - *p0);
    let gram = DMat3::from_cols_array_2d(&std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            if i < k && j < k {
                edge(i).dot(edge(j))
            } else {
                f64::from(u8::from(i == j))
            }
        })
    }));
    if gram.determinant().abs() <= 1e-300 {
        return None;
    }
    let mu = gram.inverse() * DVec3::from_array(std::array::from_fn(|i| -edge(i).dot(*p0)));
    let mu = &mu.to_array()[..k];
    let weights: Vec<f64> = std::iter::once(1.0 - mu.iter().sum::<f64>())
        .chain(mu.iter().copied())
        .collect();
    weights.iter().all(|&w| w >= 0.0).then_some(weights)
}

/// One timed row per mode; `fit` returns the fitted volume.
fn mode_rows(shape: &'static str, fit: impl Fn(Fit) -> f32) -> Vec<Row> {
    MODES
        .iter()
        .map(|&mode| Row {
            shape,
            method: format!("{mode:?}"),
            volume: f64::from(fit(mode)),
            time: Some(time(|| fit(mode))),
        })
        .collect()
}

/// An untimed reference row.
fn reference(shape: &'static str, method: &str, volume: f64) -> Row {
    Row {
        shape,
        method: method.into(),
        volume,
        time: None,
    }
}

fn obb_rows(points: &[Vec3]) -> Vec<Row> {
    let mut rows = mode_rows("OBB", |mode| Obb3::fit(points, mode).unwrap().volume());
    let pca = Obb3::fit(points, Fit::Pca).unwrap();
    let midrange = Obb3::from_axes(points, pca.rotation).unwrap();
    let aabb = bvkit::Aabb3::from_points(points.iter().map(|&p| p.into()));
    let (_, cuboid) = parry3d::utils::obb(points);
    rows.extend([
        reference(
            "OBB",
            "PCA axes, midrange center",
            f64::from(midrange.volume()),
        ),
        reference("OBB", "AABB", f64::from(aabb.volume())),
        Row {
            shape: "OBB",
            method: "parry3d utils::obb".into(),
            volume: 8.0
                * f64::from(cuboid.half_extents.x * cuboid.half_extents.y * cuboid.half_extents.z),
            time: Some(time(|| parry3d::utils::obb(points))),
        },
        reference("OBB", "exhaustive search", exhaustive_obb(points)),
    ]);
    rows
}

fn sphere_rows(points: &[Vec3]) -> Vec<Row> {
    let mut rows = mode_rows("sphere", |mode| Sphere::fit(points, mode).unwrap().volume());
    let parry = parry3d::bounding_volume::details::point_cloud_bounding_sphere(points);
    rows.push(Row {
        shape: "sphere",
        method: "parry3d point_cloud_bounding_sphere".into(),
        volume: 4.0 / 3.0 * std::f64::consts::PI * f64::from(parry.radius).powi(3),
        time: Some(time(|| {
            parry3d::bounding_volume::details::point_cloud_bounding_sphere(points)
        })),
    });
    rows
}

fn capsule_rows(points: &[Vec3]) -> Vec<Row> {
    mode_rows("capsule", |mode| {
        Capsule::fit(points, mode).unwrap().volume()
    })
}

/// One target's verdict.
struct Target {
    text: String,
    met: bool,
}

fn main() {
    let mut meshes = meshes::real();
    meshes.extend(meshes::procedural());
    meshes.push((
        "torus 100k",
        meshes::rotated(&meshes::torus(1.0, 0.3, 500, 200), meshes::tilt()),
    ));
    if quick() {
        meshes.sort_by_key(|(_, points)| points.len());
        meshes.truncate(2);
    }
    println!("| mesh | vertices | shape | method | volume / best | time per 100k vertices |");
    println!("|---|---:|---|---|---:|---:|");
    let mut targets: Vec<Target> = Vec::new();
    for (name, points) in &meshes {
        let groups = [obb_rows(points), sphere_rows(points), capsule_rows(points)];
        for rows in &groups {
            let best = rows.iter().map(|r| r.volume).fold(f64::INFINITY, f64::min);
            for r in rows {
                let per_100k = r.time.map_or(String::new(), |t| {
                    format!(
                        "{:.3} ms",
                        t.as_secs_f64() * 1e3 * 1e5 / points.len() as f64
                    )
                });
                println!(
                    "| {name} | {} | {} | {} | {:.4} | {per_100k} |",
                    points.len(),
                    r.shape,
                    r.method,
                    r.volume / best
                );
            }
        }
        targets.extend(check_targets(name, points, &groups));
    }
    println!();
    for t in &targets {
        println!("- {} {}", if t.met { "met:" } else { "MISSED:" }, t.text);
    }
}

fn volume_of(rows: &[Row], method: &str) -> f64 {
    rows.iter()
        .find(|r| r.method == method)
        .map_or(f64::NAN, |r| r.volume)
}

fn time_of(rows: &[Row], method: &str) -> Duration {
    rows.iter()
        .find(|r| r.method == method)
        .and_then(|r| r.time)
        .unwrap_or_default()
}

/// The targets for one mesh, from the rows just printed.
fn check_targets(
    name: &str,
    points: &[Vec3],
    [obb, sphere, capsule]: &[Vec<Row>; 3],
) -> Vec<Target> {
    let mut out = Vec::new();
    let best_obb = obb.iter().map(|r| r.volume).fold(f64::INFINITY, f64::min);
    let per_100k =
        |method: &str| time_of(obb, method).as_secs_f64() * 1e3 * 1e5 / points.len() as f64;
    // The time targets are per 100k vertices (issue 48's): the tight fit at most 25 ms on
    // the real meshes and 100 ms on the 100k torus, the fast fit at most 0.6 ms on meshes
    // of about 3k vertices and more (spot, at 2,930, is judged too). On the small
    // procedural meshes a fit's fixed per-call cost dominates the scaled figure: their
    // times are not judged.
    let timed = |ms: f64, limit: Option<f64>| match limit {
        Some(limit) => (
            format!("{ms:.3} ms per 100k vertices (<= {limit})"),
            ms <= limit,
        ),
        None => (
            format!("{ms:.3} ms per 100k vertices (time not judged on this mesh)"),
            true,
        ),
    };
    let real = matches!(name, "spot" | "teapot");
    let tight_limit = if real {
        Some(25.0)
    } else {
        (points.len() >= 10_000).then_some(100.0)
    };
    let fast_limit = (points.len() >= 2_500).then_some(0.6);
    let tight = volume_of(obb, "Tight") / best_obb;
    let (tight_time, tight_fast_enough) = timed(per_100k("Tight"), tight_limit);
    out.push(Target {
        text: format!("{name}: Tight OBB / best = {tight:.4} (<= 1.01), {tight_time}"),
        met: tight <= 1.01 && tight_fast_enough,
    });
    let fast = volume_of(obb, "Fast");
    let floor = volume_of(obb, "PCA axes, midrange center").min(volume_of(obb, "AABB"));
    let (fast_time, fast_enough) = timed(per_100k("Fast"), fast_limit);
    out.push(Target {
        text: format!(
            "{name}: Fast OBB / best = {:.4} (<= 1.15), / min(PCA midrange, AABB) = {:.7} (<= 1 + 1e-6), {fast_time}",
            fast / best_obb,
            fast / floor
        ),
        // The PCA axes of the points as given and of the distinct points (the reference's)
        // differ in the last bits on meshes with duplicates: the tests' 1e-6.
        met: fast <= best_obb * 1.15 && fast <= floor * (1.0 + 1e-6) && fast_enough,
    });
    let exact = Sphere::fit(points, Fit::Tight).unwrap();
    let lower = ball_lower_bound(points, exact.center.as_dvec3());
    let gap = f64::from(exact.radius) / lower - 1.0;
    out.push(Target {
        text: format!("{name}: exact sphere radius / dual lower bound − 1 = {gap:.2e} (<= 1e-6)"),
        met: gap <= 1e-6,
    });
    let fast_sphere = volume_of(sphere, "Fast") / volume_of(sphere, "Tight");
    out.push(Target {
        text: format!("{name}: Fast sphere / exact sphere volume = {fast_sphere:.4} (<= 1.05)"),
        met: fast_sphere <= 1.05,
    });
    // Either 0.7 of the PCA capsule, or a proof that the optimum is not much smaller than
    // the tight capsule: a lower bound over all axis directions within 5% of it.
    let (tight, pca) = (volume_of(capsule, "Tight"), volume_of(capsule, "Pca"));
    let work = if quick() { 200_000 } else { 4_000_000_000 };
    let floor = capsule_bound::capsule_lower_bound(points, work);
    out.push(Target {
        text: format!(
            "{name}: Tight capsule / PCA capsule = {:.4} (<= 0.7); no capsule holds the points below {:.4} of the PCA capsule (a bound over all axis directions), so Tight is within {:.4}x of the optimum (<= 1.05)",
            tight / pca,
            floor / pca,
            tight / floor
        ),
        met: tight <= 0.7 * pca || tight <= 1.05 * floor,
    });
    out
}
