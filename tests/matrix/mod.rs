//! The extremes matrix: every extreme class against every kernel, each cell checked
//! against the contract by the exact oracle and summarised (worst error in `u·S`, mean
//! volume overhead, outcome). `tests/stability.rs` asserts it; `examples/stability.rs`
//! writes it to `docs/STABILITY.md`.
#![allow(dead_code)]

use bvkit::{Aabb2, Aabb3, Aabb3x8, Affine3x8, Backend, Batch, Method, Rigid2, Rounding};
use glam::{Affine2, Affine3A, Mat2, Vec2, Vec3A};
use rand::RngExt;
use rand::rngs::StdRng;

use super::cases::{Class, problem, rng};
use super::oracle::{Bound, Expected, Problem, affine3, check};

/// Cases per cell.
pub const CASES: u64 = 400;

/// A generator of the problems of one extreme class.
type Generator = Box<dyn Fn(&mut StdRng) -> Problem<3>>;

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

/// Rows of the matrix, in the order of the list.
pub fn rows() -> Vec<(&'static str, Generator)> {
    vec![
        ("far: t = ±1e3", Box::new(|r: &mut StdRng| far(r, 3))),
        ("far: t = ±1e5", Box::new(|r: &mut StdRng| far(r, 5))),
        ("far: t = ±1e7", Box::new(|r: &mut StdRng| far(r, 7))),
        ("far: t = ±1e9", Box::new(|r: &mut StdRng| far(r, 9))),
        (
            "near f32::MAX (overflow included)",
            Box::new(from_class(Class::NearMax)),
        ),
        (
            "subnormal boxes and matrices",
            Box::new(from_class(Class::Subnormal)),
        ),
        ("zero-size boxes", Box::new(from_class(Class::ZeroSize))),
        ("±0.0", Box::new(from_class(Class::SignedZero))),
        (
            "90° rotations + tiny noise",
            Box::new(from_class(Class::QuarterTurn)),
        ),
        (
            "rotations drifted off orthonormal",
            Box::new(from_class(Class::Drifted)),
        ),
        ("reflections", Box::new(from_class(Class::Reflection))),
        (
            "near-singular scale",
            Box::new(from_class(Class::NearSingular)),
        ),
        ("huge scale (1e15–1e30)", Box::new(huge_scale)),
        ("shear", Box::new(from_class(Class::Shear))),
        ("unbounded faces", Box::new(from_class(Class::Unbounded))),
        (
            "EMPTY and inverted boxes",
            Box::new(from_class(Class::Empty)),
        ),
        ("NaN anywhere", Box::new(from_class(Class::Nan))),
        (
            "random bit patterns",
            Box::new(from_class(Class::RandomBits)),
        ),
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
        p: &Problem<N>,
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

/// The three transform classes of the tables.
pub const TABLES: [&str; 3] = ["3D affine", "2D affine", "2D rigid"];

/// Computes the matrix: `cells[table][row][kernel]`. Every 3D cell covers the single-box
/// SIMD and scalar paths and the AoSoA batch on every supported backend; the 2D cells the
/// single-box path and the AoS batch on every supported backend.
pub fn compute() -> Vec<Vec<Vec<Cell>>> {
    let rows = rows();
    let kernels = kernels();
    let mut cells = vec![vec![vec![Cell::default(); kernels.len()]; rows.len()]; TABLES.len()];
    for (ri, (_, make)) in rows.iter().enumerate() {
        let r = &mut rng(0x57ab ^ ri as u64);
        let ps: Vec<Problem<3>> = (0..CASES).map(|_| make(r)).collect();
        let ps2: Vec<Problem<2>> = ps.iter().map(planar).collect();
        let rigid: Vec<Problem<2>> = ps2
            .iter()
            .map(|p| Problem {
                cols: [[p.cols[0][0], p.cols[0][1]], [-p.cols[0][1], p.cols[0][0]]],
                ..*p
            })
            .collect();
        let (local, xfs): (Vec<Aabb3>, Vec<Affine3A>) = ps.iter().map(affine3).unzip();
        let (l8, x8) = (Aabb3x8::pack(&local), Affine3x8::pack(&xfs));
        let l2: Vec<Aabb2> = ps2
            .iter()
            .map(|p| Aabb2::new(Vec2::from_array(p.lo), Vec2::from_array(p.hi)))
            .collect();
        let a2: Vec<Affine2> = ps2
            .iter()
            .map(|p| {
                Affine2::from_mat2_translation(
                    Mat2::from_cols(p.cols[0].into(), p.cols[1].into()),
                    p.t.into(),
                )
            })
            .collect();
        let r2: Vec<Rigid2> = rigid
            .iter()
            .map(|p| Rigid2::new(p.cols[0][0], p.cols[0][1], p.t.into()))
            .collect();
        for (ki, &(method, rounding)) in kernels.iter().enumerate() {
            let (b3, b2) = (
                Bound::documented(method, rounding, 3),
                Bound::documented(method, rounding, 2),
            );
            for (k, p) in ps.iter().enumerate() {
                let (b, xf) = (local[k], xfs[k]);
                let o = b.transformed(&xf, method, rounding);
                cells[0][ri][ki].add(p, o.min.to_array(), o.max.to_array(), b3, "single simd");
                let o = b.transformed_scalar(&xf, method, rounding);
                cells[0][ri][ki].add(p, o.min.to_array(), o.max.to_array(), b3, "single scalar");
                let o = l2[k].transformed(&a2[k], method, rounding);
                cells[1][ri][ki].add(&ps2[k], o.min.to_array(), o.max.to_array(), b2, "single");
                let o = l2[k].transformed_rigid(&r2[k], method, rounding);
                cells[2][ri][ki].add(&rigid[k], o.min.to_array(), o.max.to_array(), b2, "single");
            }
            for backend in Backend::supported() {
                let batch = Batch::new(method, rounding).on(backend).expect("supported");
                let what = format!("batch {backend:?}");
                let mut o8 = vec![Aabb3x8::EMPTY; l8.len()];
                batch.aosoa(&l8, &x8, &mut o8).expect("lengths match");
                for (p, o) in ps.iter().zip(Aabb3x8::unpack(&o8, ps.len())) {
                    cells[0][ri][ki].add(p, o.min.to_array(), o.max.to_array(), b3, &what);
                }
                let mut o2 = vec![Aabb2::NAN; l2.len()];
                batch.aos2(&l2, &a2, &mut o2).expect("lengths match");
                for (p, o) in ps2.iter().zip(&o2) {
                    cells[1][ri][ki].add(p, o.min.to_array(), o.max.to_array(), b2, &what);
                }
                batch.aos_rigid2(&l2, &r2, &mut o2).expect("lengths match");
                for (p, o) in rigid.iter().zip(&o2) {
                    cells[2][ri][ki].add(p, o.min.to_array(), o.max.to_array(), b2, &what);
                }
            }
        }
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
    writeln!(s, "Each cell: {CASES} seeded cases of the row's class through the column's kernel on every path (3D: single-box SIMD and scalar, AoSoA batch on every backend this CPU supports; 2D: single box and AoS batch on every backend), each checked against the contract by the exact oracle. `✓` means no case broke the contract; then: worst face error in units of u·S over the finite cases, mean volume overhead over the exact box, the share of results containing the exact box, and how many cases correctly gave `EMPTY` or an invalid (NaN) box. Bounds: Nearest `γ(n)·S + 2^-148`, Outward contains and stays within `2·(k·u·S + 2^-146)`; see `bvkit::method`.\n").unwrap();
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
        for (ri, (name, _)) in rows.iter().enumerate() {
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
