//! The extremes matrix: every extreme class against every kernel, each cell checked
//! against the contract by the exact oracle and summarised (worst error in `u·S`, mean
//! volume overhead, outcome). `tests/stability.rs` asserts it; `examples/stability.rs`
//! writes it (`python3 scripts/docs.py stability` into `docs/stability.md`).
#![allow(dead_code)]

use bvkit::{
    Aabb2, Aabb3, Aabb3x8, Backend, Batch, Block8, Method, Rounding, Transform2, Transform3,
    Translation2, Translation3,
};
use glam::{Vec2, Vec3A};
use rand::RngExt;
use rand::rngs::StdRng;
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::cases::{Class, Scale, as_translation, bend_quat, problem, rng};
use crate::oracle::{
    Bound, Exactly, Expected, Problem, QuatProblem, affine2, affine3, check, rigid2,
};

/// Cases per cell.
pub const CASES: u64 = 400;

/// A generator of the problems of one extreme class.
type Generator = Box<dyn Fn(&mut StdRng) -> Problem<3> + Send + Sync>;

fn from_class(class: Class) -> impl Fn(&mut StdRng) -> Problem<3> {
    move |r| problem::<3>(class, r)
}

/// Far from the origin: a box of extent up to 1e-2 at translation ±10^e.
fn far(r: &mut StdRng, e: i32) -> Problem<3> {
    let mut p = problem::<3>(Class::Typical, r);
    let s = 10f32.powi(e);
    p.t = core::array::from_fn(|_| if r.random_bool(0.5) { s } else { -s });
    for j in 0..3 {
        let c = r.random_range(-1.0..1.0f32);
        let h = r.random_range(0.0..1e-2f32);
        (p.lo[j], p.hi[j]) = (c - h, c + h);
    }
    p
}

fn huge_scale(r: &mut StdRng) -> Problem<3> {
    let mut p = problem::<3>(Class::Typical, r);
    let s = 10f32.powf(r.random_range(15.0..30.0));
    p.cols.iter_mut().flatten().for_each(|x| *x *= s);
    p
}

/// Rows of the matrix, in the order of the list: the name, the generator of the
/// affine problems, and the class that bends the quaternion classes' rotation and scale.
pub fn rows() -> Vec<(&'static str, Generator, Class)> {
    let class_row = |name, class| (name, Box::new(from_class(class)) as Generator, class);
    vec![
        (
            "far: t = ±1e3",
            Box::new(|r: &mut StdRng| far(r, 3)),
            Class::Typical,
        ),
        (
            "far: t = ±1e5",
            Box::new(|r: &mut StdRng| far(r, 5)),
            Class::Typical,
        ),
        (
            "far: t = ±1e7",
            Box::new(|r: &mut StdRng| far(r, 7)),
            Class::Typical,
        ),
        (
            "far: t = ±1e9",
            Box::new(|r: &mut StdRng| far(r, 9)),
            Class::Typical,
        ),
        class_row("near f32::MAX (overflow included)", Class::NearMax),
        class_row("subnormal boxes and matrices", Class::Subnormal),
        class_row("zero-size boxes", Class::ZeroSize),
        class_row("±0.0", Class::SignedZero),
        class_row("90° rotations + tiny noise", Class::QuarterTurn),
        class_row("rotations drifted off orthonormal", Class::Drifted),
        class_row("reflections (negative scale)", Class::Reflection),
        class_row(
            "near-singular or zero scale (zero quaternion)",
            Class::NearSingular,
        ),
        (
            "huge scale (1e15–1e30)",
            Box::new(huge_scale),
            Class::NearMax,
        ),
        class_row("shear (quaternions far from unit)", Class::Shear),
        class_row("unbounded faces", Class::Unbounded),
        class_row("EMPTY and inverted boxes", Class::Empty),
        class_row("NaN anywhere (infinite quaternion)", Class::Nan),
        class_row("random bit patterns", Class::RandomBits),
    ]
}

/// The kernels (columns): method × rounding.
pub fn kernels() -> Vec<(Method, Rounding)> {
    Method::ALL
        .into_iter()
        .flat_map(|m| Rounding::ALL.map(|r| (m, r)))
        .collect()
}

/// One cell's summary.
#[derive(Clone, Debug, Default)]
pub struct Cell {
    pub cases: usize,
    pub worst_error_us: f64,
    pub overhead_sum: f64,
    pub overhead_count: usize,
    pub contained: usize,
    pub finite_cases: usize,
    pub empty: usize,
    pub invalid: usize,
    /// Contract failures (empty when the contract holds).
    pub failures: Vec<String>,
}

impl Cell {
    fn add<const N: usize>(
        &mut self,
        p: &impl Exactly<N>,
        min: [f32; N],
        max: [f32; N],
        bound: Bound,
        what: &str,
    ) {
        self.cases += 1;
        match check(p, min, max, bound) {
            Err(e) => self.failures.push(format!("{what}: {e}\n{p:?}")),
            Ok(m) => match p.expected() {
                Expected::Invalid => self.invalid += 1,
                Expected::Empty => self.empty += 1,
                Expected::Faces { .. } => {
                    self.finite_cases += 1;
                    self.worst_error_us = self.worst_error_us.max(m.worst_error_us);
                    self.contained += usize::from(m.contains);
                    if let Some(o) = m.overhead {
                        self.overhead_sum += o;
                        self.overhead_count += 1;
                    }
                }
            },
        }
    }

    /// The cell as table text: worst error, mean overhead and what the contract gave.
    pub fn text(&self) -> String {
        if !self.failures.is_empty() {
            return format!("FAIL ({})", self.failures.len());
        }
        let mut parts = Vec::new();
        if self.finite_cases > 0 {
            let overhead = if self.overhead_count > 0 {
                format!("{:+.1e}", self.overhead_sum / self.overhead_count as f64)
            } else {
                "–".into()
            };
            parts.push(format!(
                "{:.2} u·S, {overhead}, {:.0}% contain",
                self.worst_error_us,
                100.0 * self.contained as f64 / self.finite_cases as f64
            ));
        }
        if self.empty > 0 {
            parts.push(format!("EMPTY×{}", self.empty));
        }
        if self.invalid > 0 {
            parts.push(format!("invalid×{}", self.invalid));
        }
        format!("✓ {}", parts.join("; "))
    }
}

/// The 2D problem on the first two axes of a 3D one.
fn planar(p: &Problem<3>) -> Problem<2> {
    Problem {
        cols: [[p.cols[0][0], p.cols[0][1]], [p.cols[1][0], p.cols[1][1]]],
        t: [p.t[0], p.t[1]],
        lo: [p.lo[0], p.lo[1]],
        hi: [p.hi[0], p.hi[1]],
    }
}

/// The transform classes of the tables.
pub const TABLES: [&str; 8] = [
    "3D affine (Affine3A)",
    "3D translation (Translation3)",
    "3D rigid (Rigid3)",
    "3D similarity (Similarity3)",
    "3D scale-rotation-translation (Trs3)",
    "2D affine (Affine2)",
    "2D rigid (Rigid2)",
    "2D translation (Translation2)",
];

/// One 3D class's cell: the single-box SIMD and scalar paths and the AoSoA batch on every
/// supported backend.
fn cell3<T: Transform3, P: Exactly<3>>(
    cell: &mut Cell,
    ps: &[P],
    inputs: impl Fn(&P) -> (Aabb3, T),
    method: Method,
    rounding: Rounding,
) {
    let bound = Bound::of_order(T::nearest_order(method), rounding);
    let (local, xfs): (Vec<Aabb3>, Vec<T>) = ps.iter().map(inputs).unzip();
    for (k, p) in ps.iter().enumerate() {
        let o = local[k].transformed(&xfs[k], method, rounding);
        cell.add(p, o.min.to_array(), o.max.to_array(), bound, "single simd");
        let o = local[k].transformed_scalar(&xfs[k], method, rounding);
        cell.add(
            p,
            o.min.to_array(),
            o.max.to_array(),
            bound,
            "single scalar",
        );
    }
    let (lb, xb) = (Block8::pack(&local), Block8::pack(&xfs));
    for backend in Backend::supported() {
        let batch = Batch::new(method, rounding).on(backend).expect("supported");
        let mut ob = vec![Aabb3x8::default(); lb.len()];
        batch.transform(&lb, &xb, &mut ob).expect("lengths match");
        for (p, o) in ps.iter().zip(Block8::unpack(&ob, ps.len())) {
            let what = format!("aosoa {backend:?}");
            cell.add(p, o.min.to_array(), o.max.to_array(), bound, &what);
        }
    }
}

/// One 2D class's cell: the single-box path and the AoS batch on every supported backend.
fn cell2<T: Transform2>(
    cell: &mut Cell,
    ps: &[Problem<2>],
    inputs: impl Fn(&Problem<2>) -> (Aabb2, T),
    method: Method,
    rounding: Rounding,
) {
    let bound = Bound::of_order(T::nearest_order(method), rounding);
    let (local, xfs): (Vec<Aabb2>, Vec<T>) = ps.iter().map(inputs).unzip();
    for (k, p) in ps.iter().enumerate() {
        let o = local[k].transformed(&xfs[k], method, rounding);
        cell.add(p, o.min.to_array(), o.max.to_array(), bound, "single");
    }
    for backend in Backend::supported() {
        let batch = Batch::new(method, rounding).on(backend).expect("supported");
        let mut out = vec![Aabb2::NAN; local.len()];
        batch
            .transform(&local, &xfs, &mut out)
            .expect("lengths match");
        for (p, o) in ps.iter().zip(&out) {
            let what = format!("aos {backend:?}");
            cell.add(p, o.min.to_array(), o.max.to_array(), bound, &what);
        }
    }
}

/// Computes the matrix: `cells[table][row][kernel]`. The rows are independent (each seeds
/// its own generator), so the available cores take them in turn: the same cells, in less
/// time.
pub fn compute() -> Vec<Vec<Vec<Cell>>> {
    let rows = rows();
    let kernels = kernels();
    let next = AtomicUsize::new(0);
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get());
    let done: Vec<(usize, Vec<Vec<Cell>>)> = std::thread::scope(|s| {
        let take = || {
            let mut done = Vec::new();
            loop {
                let ri = next.fetch_add(1, Ordering::Relaxed);
                let Some(row) = rows.get(ri) else {
                    return done;
                };
                done.push((ri, row_cells(ri, row, &kernels)));
            }
        };
        let handles: Vec<_> = (0..workers.min(rows.len()))
            .map(|_| s.spawn(take))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    let mut cells = vec![vec![Vec::new(); rows.len()]; TABLES.len()];
    for (ri, tables) in done {
        for (table, row) in cells.iter_mut().zip(tables) {
            table[ri] = row;
        }
    }
    cells
}

/// Row `ri`'s cells, `[table][kernel]`.
fn row_cells(
    ri: usize,
    (_, make, class): &(&'static str, Generator, Class),
    kernels: &[(Method, Rounding)],
) -> Vec<Vec<Cell>> {
    let mut cells = vec![vec![Cell::default(); kernels.len()]; TABLES.len()];
    let r = &mut rng(0x57ab ^ ri as u64);
    let ps: Vec<Problem<3>> = (0..CASES).map(|_| make(r)).collect();
    let translations: Vec<Problem<3>> = ps.iter().map(|p| as_translation(*p)).collect();
    let quats = |scale, r: &mut StdRng| -> Vec<QuatProblem> {
        ps.iter().map(|p| bend_quat(*p, *class, scale, r)).collect()
    };
    let (rigid3, similarity3, trs3) = (
        quats(Scale::Unit, r),
        quats(Scale::Uniform, r),
        quats(Scale::PerAxis, r),
    );
    let ps2: Vec<Problem<2>> = ps.iter().map(planar).collect();
    let rigid2s: Vec<Problem<2>> = ps2
        .iter()
        .map(|p| Problem {
            cols: [[p.cols[0][0], p.cols[0][1]], [-p.cols[0][1], p.cols[0][0]]],
            ..*p
        })
        .collect();
    let translations2: Vec<Problem<2>> = ps2.iter().map(|p| as_translation(*p)).collect();
    for (ki, &(m, rd)) in kernels.iter().enumerate() {
        cell3(&mut cells[0][ki], &ps, affine3, m, rd);
        let translation = |p: &Problem<3>| {
            let (b, _) = affine3(p);
            (b, Translation3(Vec3A::from_array(p.t)))
        };
        cell3(&mut cells[1][ki], &translations, translation, m, rd);
        cell3(
            &mut cells[2][ki],
            &rigid3,
            |p| (p.aabb(), p.rigid3()),
            m,
            rd,
        );
        cell3(
            &mut cells[3][ki],
            &similarity3,
            |p| (p.aabb(), p.similarity3()),
            m,
            rd,
        );
        cell3(&mut cells[4][ki], &trs3, |p| (p.aabb(), p.trs3()), m, rd);
        cell2(&mut cells[5][ki], &ps2, affine2, m, rd);
        cell2(&mut cells[6][ki], &rigid2s, rigid2, m, rd);
        let translation2 = |p: &Problem<2>| {
            let (b, _) = affine2(p);
            (b, Translation2(Vec2::from_array(p.t)))
        };
        cell2(&mut cells[7][ki], &translations2, translation2, m, rd);
    }
    cells
}

/// The Mat4 cases: (case, contract, outcome observed, whether it matches the contract).
pub fn mat4_cases() -> Vec<(&'static str, &'static str, String, bool)> {
    use bvkit::TransformError as E;
    use glam::{Mat4, Vec3};
    let unit = Aabb3::new(Vec3A::splat(-1.0), Vec3A::splat(1.0));
    let proj = glam::camera::rh::proj::directx::perspective(1.0, 1.5, 0.1, 100.0);
    let in_front = Aabb3::new(Vec3A::new(-1.0, -1.0, -5.0), Vec3A::new(1.0, 1.0, -2.0));
    let behind = Aabb3::new(Vec3A::new(-1.0, -1.0, -5.0), Vec3A::new(1.0, 1.0, 1.0));
    let unbounded = Aabb3::new(
        Vec3A::new(-1.0, -1.0, f32::NEG_INFINITY),
        Vec3A::new(1.0, 1.0, -1.0),
    );
    let mut non_affine = Mat4::IDENTITY;
    non_affine.x_axis.w = 0.5;
    let mut nan = Mat4::from_translation(Vec3::ONE);
    nan.y_axis.y = f32::NAN;
    let shift = Mat4::from_translation(Vec3::X);
    use glam::Affine3A;
    let (m, r) = (Method::SignSelect, Rounding::Outward);
    let affine = unit.try_transformed_mat4(&shift, m, r);
    let projected = in_front.transformed_projective(&proj);
    let corners_inside = projected.is_ok_and(|b| {
        in_front
            .corners()
            .iter()
            .all(|&c| b.contains_point(proj.project_point3a(c)))
    });
    let cases: Vec<(&str, &str, Result<Aabb3, E>, bool)> = vec![
        (
            "affine Mat4 through try_transformed_mat4",
            "Ok, same as Affine3A",
            affine,
            affine == Ok(unit.transformed(&Affine3A::from_mat4(shift), m, r)),
        ),
        (
            "last row (0.5, 0, 0, 1)",
            "Err(NotAffine)",
            unit.try_transformed_mat4(&non_affine, m, r),
            matches!(
                unit.try_transformed_mat4(&non_affine, m, r),
                Err(E::NotAffine { .. })
            ),
        ),
        (
            "NaN entry",
            "Err(NonFiniteMatrix)",
            unit.try_transformed_mat4(&nan, m, r),
            unit.try_transformed_mat4(&nan, m, r) == Err(E::NonFiniteMatrix),
        ),
        (
            "perspective, box in front of the eye",
            "Ok, contains the projected corners",
            projected,
            corners_inside,
        ),
        (
            "perspective, box reaching behind the eye",
            "Err(NonPositiveW)",
            behind.transformed_projective(&proj),
            matches!(
                behind.transformed_projective(&proj),
                Err(E::NonPositiveW { .. })
            ),
        ),
        (
            "perspective, unbounded box",
            "Err(UnboundedProjective)",
            unbounded.transformed_projective(&proj),
            unbounded.transformed_projective(&proj) == Err(E::UnboundedProjective),
        ),
        (
            "perspective, EMPTY box",
            "Ok(EMPTY)",
            Aabb3::EMPTY.transformed_projective(&proj),
            Aabb3::EMPTY.transformed_projective(&proj) == Ok(Aabb3::EMPTY),
        ),
    ];
    cases
        .into_iter()
        .map(|(case, contract, got, ok)| {
            let shown = match got {
                Ok(b) => format!("Ok({:?}..{:?})", b.min.to_array(), b.max.to_array()),
                Err(e) => format!("Err({e:?})"),
            };
            (case, contract, shown, ok)
        })
        .collect()
}

/// The whole report as Markdown.
pub fn markdown(cells: &[Vec<Vec<Cell>>]) -> String {
    use std::fmt::Write as _;
    let rows = rows();
    let kernels = kernels();
    let mut s = String::new();
    writeln!(s, "# bvkit stability matrix\n").unwrap();
    writeln!(s, "Generated by `cargo run --release --example stability`; do not edit by hand. `cargo test --test stability` asserts every cell.\n").unwrap();
    writeln!(s, "Each cell: {CASES} seeded cases of the row's class through the column's kernel on every path (3D: single-box SIMD and scalar, AoSoA batch on every backend this CPU supports; 2D: single box and AoS batch on every backend), each checked against the contract by the exact oracle. `✓` means no case broke the contract; then: worst face error in units of u·S over the finite cases, mean volume overhead over the exact box, the share of results containing the exact box, and how many cases correctly gave `EMPTY` or an invalid (NaN) box. Bounds: Nearest `γ(n)·S + τ·2^-148`, Outward contains and stays within `2·(k·u·S + τ·2^-100)`, with `n`, `k = n + 2`, `S` and `τ` per class as `bvkit::transform` documents (for the quaternion classes `S` and `τ` carry `ρ = 1 + 2‖q‖²`; worst errors are in units of that `u·S`). The quaternion tables bend the rotation and scale with the row's class as the row names say.\n").unwrap();
    writeln!(
        s,
        "Backends exercised on the machine that generated this file: {:?}.\n",
        Backend::supported()
    )
    .unwrap();
    for (ti, table) in TABLES.iter().enumerate() {
        writeln!(s, "## {table}\n").unwrap();
        write!(s, "| class |").unwrap();
        for (m, r) in &kernels {
            write!(s, " {} {} |", m.name(), r.name()).unwrap();
        }
        writeln!(s).unwrap();
        writeln!(s, "|---|{}", "---|".repeat(kernels.len())).unwrap();
        for (ri, (name, _, _)) in rows.iter().enumerate() {
            write!(s, "| {name} |").unwrap();
            for cell in &cells[ti][ri] {
                write!(s, " {} |", cell.text()).unwrap();
            }
            writeln!(s).unwrap();
        }
        writeln!(s).unwrap();
    }
    writeln!(s, "## Mat4 and projective entry points\n").unwrap();
    writeln!(
        s,
        "| case | contract | observed | outcome |\n|---|---|---|---|"
    )
    .unwrap();
    for (case, expected, observed, ok) in mat4_cases() {
        writeln!(
            s,
            "| {case} | {expected} | `{observed}` | {} |",
            if ok { "✓" } else { "FAIL" }
        )
        .unwrap();
    }
    s
}
