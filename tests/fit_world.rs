//! Fitted volumes through transforms, judged exactly: the world AABB of every volume
//! ([`BoundingVolume::transformed_aabb`]) under every 3D class × rounding over every extreme
//! class of inputs, the batch entry point against the single calls, and the images under
//! similarities ([`Obb3::transformed`], …).
//!
//! **How the exact image is judged.** Every `f32` is a dyadic rational, and so is every
//! entry of the exact map (the oracle's `exact_cols`). A box's exact corners are
//! `c + Σ_j ±h_j·B_j/D` (its dual basis: `B_j = a_{j+1} × a_{j+2}`, `D = a_0·B_0`), rational;
//! their images give the exact faces as rationals. A ball's exact faces are
//! `(M c + t)_i ± r·√(Σ_k m_ik²)`: a face `f` is compared with `C + k·√N` by the sign of
//! `f − C` and the squares, exactly. A capsule's faces are those of its two end balls.
#![allow(clippy::needless_range_loop)]

mod cases;
mod oracle;

use bvkit::{
    Aabb3, BatchError, BoundingVolume, Capsule, Obb3, Rigid3, Rounding, Similarity3, Translation3,
    Trs3, transform::Transform3,
};
use glam::{Affine3A, Mat3A, Quat, Vec3A};
use num_bigint::BigInt;
use num_traits::{Signed, ToPrimitive, Zero};
use rand::RngExt;
use rand::rngs::StdRng;

use bvkit::Sphere;
use cases::{Class, Scale, problem, quat_problem, rng, translation_problem};
use oracle::{Exact, Exactly, QuatProblem, affine3};

const U: f64 = 1.0 / 16_777_216.0;

// ---------------------------------------------------------------- exact rationals

/// An exact rational `n / d`, `d > 0`.
#[derive(Clone, Debug)]
struct Q {
    n: BigInt,
    d: BigInt,
}

impl Q {
    fn int(n: i64) -> Q {
        Q {
            n: BigInt::from(n),
            d: BigInt::from(1),
        }
    }
    /// The exact value of a finite `f32`.
    fn f(x: f32) -> Q {
        match Exact::of(x) {
            Exact::Finite(n) => Q {
                n,
                d: BigInt::from(1) << oracle::SCALE as usize,
            },
            _ => panic!("finite values only"),
        }
    }
    /// The exact value of a finite `f64`.
    fn f64(x: f64) -> Q {
        assert!(x.is_finite());
        let bits = x.to_bits();
        let (biased, fraction) = ((bits >> 52 & 0x7ff) as i64, (bits & ((1 << 52) - 1)) as i64);
        let (m, e) = if biased == 0 {
            (fraction, -1074)
        } else {
            (fraction | 1 << 52, biased - 1075)
        };
        let m = BigInt::from(if x < 0.0 { -m } else { m });
        if e >= 0 {
            Q {
                n: m << e as usize,
                d: BigInt::from(1),
            }
        } else {
            Q {
                n: m,
                d: BigInt::from(1) << (-e) as usize,
            }
        }
    }
    fn exact(e: &Exact) -> Q {
        match e {
            Exact::Finite(n) => Q {
                n: n.clone(),
                d: BigInt::from(1) << oracle::SCALE as usize,
            },
            _ => panic!("finite values only"),
        }
    }
    fn add(&self, o: &Q) -> Q {
        if self.d == o.d {
            return Q {
                n: &self.n + &o.n,
                d: self.d.clone(),
            };
        }
        Q {
            n: &self.n * &o.d + &o.n * &self.d,
            d: &self.d * &o.d,
        }
    }
    fn neg(&self) -> Q {
        Q {
            n: -&self.n,
            d: self.d.clone(),
        }
    }
    fn sub(&self, o: &Q) -> Q {
        self.add(&o.neg())
    }
    fn mul(&self, o: &Q) -> Q {
        Q {
            n: &self.n * &o.n,
            d: &self.d * &o.d,
        }
    }
    fn div(&self, o: &Q) -> Q {
        assert!(!o.n.is_zero(), "division by zero");
        let s = if o.n.is_negative() { -1 } else { 1 };
        Q {
            n: &self.n * &o.d * s,
            d: &self.d * o.n.abs(),
        }
    }
    fn is_neg(&self) -> bool {
        self.n.is_negative()
    }
    fn le(&self, o: &Q) -> bool {
        !o.sub(self).is_neg()
    }
    fn to_f64(&self) -> f64 {
        let top = |x: &BigInt| {
            let shift = (x.bits() as i64 - 60).max(0);
            ((x >> shift as usize).to_f64().unwrap(), shift)
        };
        let ((n, a), (d, b)) = (top(&self.n), top(&self.d));
        n / d * 2f64.powi((a - b) as i32)
    }
}

type V3 = [Q; 3];

fn v3(v: Vec3A) -> V3 {
    v.to_array().map(Q::f)
}
fn vadd(a: &V3, b: &V3) -> V3 {
    core::array::from_fn(|i| a[i].add(&b[i]))
}
fn vsub(a: &V3, b: &V3) -> V3 {
    core::array::from_fn(|i| a[i].sub(&b[i]))
}
fn vscale(a: &V3, s: &Q) -> V3 {
    core::array::from_fn(|i| a[i].mul(s))
}
fn dot(a: &V3, b: &V3) -> Q {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}
fn cross(a: &V3, b: &V3) -> V3 {
    core::array::from_fn(|i| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        a[j].mul(&b[k]).sub(&a[k].mul(&b[j]))
    })
}

/// The exact map `x ↦ M x + t` of a problem, and the weights `μ_ik` of its magnitude.
struct XMap {
    rows: [V3; 3],
    t: V3,
    mu: [[f64; 3]; 3],
}

impl XMap {
    fn of(p: &impl Exactly<3>) -> XMap {
        let cols = p.exact_cols();
        XMap {
            rows: core::array::from_fn(|i| core::array::from_fn(|k| Q::exact(&cols[k][i]))),
            t: p.t().map(Q::f),
            mu: p.weights(),
        }
    }
    fn apply(&self, p: &V3) -> V3 {
        core::array::from_fn(|i| dot(&self.rows[i], p).add(&self.t[i]))
    }
    /// `S_i = |t_i| + Σ_k μ_ik·reach_k`.
    fn magnitude(&self, reach: [f64; 3]) -> [f64; 3] {
        core::array::from_fn(|i| {
            self.t[i].to_f64().abs() + (0..3).map(|k| self.mu[i][k] * reach[k]).sum::<f64>()
        })
    }
}

/// The value `C + k·√N`.
#[derive(Clone, Debug)]
struct Candidate {
    c: Q,
    k: Q,
    n: Q,
}

impl Candidate {
    fn point(c: Q) -> Self {
        Candidate {
            c,
            k: Q::int(0),
            n: Q::int(0),
        }
    }
    fn approx(&self) -> f64 {
        self.c.to_f64() + self.k.to_f64() * self.n.to_f64().sqrt()
    }
    /// `f <= C + k·√N`, exactly.
    fn above(&self, f: &Q) -> bool {
        let a = f.sub(&self.c);
        let (a2, k2n) = (a.mul(&a), self.k.mul(&self.k).mul(&self.n));
        if self.k.is_neg() {
            a.le(&Q::int(0)) && k2n.le(&a2)
        } else {
            a.le(&Q::int(0)) || a2.le(&k2n)
        }
    }
    /// `f >= C + k·√N`.
    fn below(&self, f: &Q) -> bool {
        Candidate {
            c: self.c.neg(),
            k: self.k.neg(),
            n: self.n.clone(),
        }
        .above(&f.neg())
    }
}

/// What the contract demands of one volume's world AABB.
enum Expected {
    Invalid,
    Empty,
    Everywhere,
    /// Per axis: the candidates of the lower and upper face, the magnitude `S_i`, and `κ`.
    Faces {
        lo: [Vec<Candidate>; 3],
        hi: [Vec<Candidate>; 3],
        magnitude: [f64; 3],
        kappa: f64,
    },
}

/// A volume under test: its fields and its exact image's faces.
trait Volume: BoundingVolume + Copy + core::fmt::Debug {
    fn fields(&self) -> Vec<f32>;
    fn is_empty(&self) -> bool;
    /// The exact faces' candidates (finite fields, non-empty), `reach` and `κ`.
    fn faces(&self, map: &XMap) -> ([Vec<Candidate>; 3], [Vec<Candidate>; 3], [f64; 3], f64);
    /// A volume built from a problem's box.
    fn from_box(lo: Vec3A, hi: Vec3A, r: &mut StdRng) -> Self;

    fn expected(&self, map: Option<&XMap>) -> Expected {
        let fields = self.fields();
        let Some(map) = map.filter(|_| !fields.iter().any(|x| x.is_nan())) else {
            return Expected::Invalid;
        };
        if self.is_empty() {
            return Expected::Empty;
        }
        if !fields.iter().all(|x| x.is_finite()) {
            return Expected::Everywhere;
        }
        let (lo, hi, reach, kappa) = self.faces(map);
        Expected::Faces {
            lo,
            hi,
            magnitude: map.magnitude(reach),
            kappa,
        }
    }
}

/// The box's dual basis `B_j` and `D`, exactly.
fn dual(rotation: Mat3A) -> ([V3; 3], Q) {
    let a = [0, 1, 2].map(|k| v3(rotation.col(k)));
    let b = [0, 1, 2].map(|j| cross(&a[(j + 1) % 3], &a[(j + 2) % 3]));
    let det = dot(&a[0], &b[0]);
    (b, det)
}

/// The box's 8 exact corners `c + Σ_j ±h_j·B_j/D`.
fn corners(obb: &Obb3) -> Vec<V3> {
    let (b, det) = dual(obb.rotation);
    let (c, h) = (v3(obb.center), v3(obb.half_extents));
    (0..8)
        .map(|s| {
            (0..3).fold(c.clone(), |y, j| {
                let hj = if s >> j & 1 == 0 {
                    h[j].neg()
                } else {
                    h[j].clone()
                };
                vadd(&y, &vscale(&b[j], &hj.div(&det)))
            })
        })
        .collect()
}

fn random_rotation(r: &mut StdRng) -> Mat3A {
    let q = Quat::from_xyzw(
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
    );
    let q = if q.length_squared() > 1e-3 {
        q.normalize()
    } else {
        Quat::IDENTITY
    };
    Mat3A::from_quat(q)
}

impl Volume for Obb3 {
    fn fields(&self) -> Vec<f32> {
        let mut f = self.center.to_array().to_vec();
        f.extend(self.half_extents.to_array());
        f.extend(self.rotation.to_cols_array());
        f
    }
    fn is_empty(&self) -> bool {
        self.half_extents.min_element() < 0.0
    }
    fn faces(&self, map: &XMap) -> ([Vec<Candidate>; 3], [Vec<Candidate>; 3], [f64; 3], f64) {
        let images: Vec<V3> = corners(self).iter().map(|y| map.apply(y)).collect();
        let axis = |i: usize| -> Vec<Candidate> {
            images
                .iter()
                .map(|x| Candidate::point(x[i].clone()))
                .collect()
        };
        let a = self.rotation.as_dmat3();
        let b = [0, 1, 2].map(|j| a.col((j + 1) % 3).cross(a.col((j + 2) % 3)));
        let det = a.x_axis.dot(b[0]).abs();
        let kappa = a.x_axis.abs().dot(b[0].abs()) / det;
        let h = self.half_extents.as_dvec3();
        let reach = core::array::from_fn(|k| {
            f64::from(self.center[k]).abs()
                + (0..3).map(|j| b[j][k].abs() * h[j]).sum::<f64>() / det
        });
        ([0, 1, 2].map(axis), [0, 1, 2].map(axis), reach, kappa)
    }
    fn from_box(lo: Vec3A, hi: Vec3A, r: &mut StdRng) -> Self {
        let rotation = if r.random_range(0..4) == 0 {
            Mat3A::IDENTITY
        } else {
            random_rotation(r)
        };
        Obb3 {
            center: lo,
            half_extents: (hi - lo) * 0.5,
            rotation,
        }
    }
}

/// The candidates of balls of radius `r` about `ends`.
fn swept(
    map: &XMap,
    ends: &[Vec3A],
    radius: f32,
) -> ([Vec<Candidate>; 3], [Vec<Candidate>; 3], [f64; 3], f64) {
    let r = Q::f(radius);
    let norm2 = |i: usize| dot(&map.rows[i], &map.rows[i]);
    let side = |sign: &Q| {
        [0, 1, 2].map(|i| {
            ends.iter()
                .map(|&p| Candidate {
                    c: map.apply(&v3(p))[i].clone(),
                    k: r.mul(sign),
                    n: norm2(i),
                })
                .collect()
        })
    };
    let reach = core::array::from_fn(|k| {
        let m = ends.iter().map(|p| p[k].abs()).fold(0.0f32, f32::max);
        f64::from(m) + f64::from(radius)
    });
    (side(&Q::int(-1)), side(&Q::int(1)), reach, 1.0)
}

impl Volume for Sphere {
    fn fields(&self) -> Vec<f32> {
        let mut f = self.center.to_array().to_vec();
        f.push(self.radius);
        f
    }
    fn is_empty(&self) -> bool {
        self.radius < 0.0
    }
    fn faces(&self, map: &XMap) -> ([Vec<Candidate>; 3], [Vec<Candidate>; 3], [f64; 3], f64) {
        swept(map, &[self.center], self.radius)
    }
    fn from_box(lo: Vec3A, hi: Vec3A, _: &mut StdRng) -> Self {
        Sphere {
            center: hi,
            radius: (hi.x - lo.x) * 0.5,
        }
    }
}

impl Volume for Capsule {
    fn fields(&self) -> Vec<f32> {
        let mut f = self.a.to_array().to_vec();
        f.extend(self.b.to_array());
        f.push(self.radius);
        f
    }
    fn is_empty(&self) -> bool {
        self.radius < 0.0
    }
    fn faces(&self, map: &XMap) -> ([Vec<Candidate>; 3], [Vec<Candidate>; 3], [f64; 3], f64) {
        swept(map, &[self.a, self.b], self.radius)
    }
    fn from_box(lo: Vec3A, hi: Vec3A, _: &mut StdRng) -> Self {
        Capsule {
            a: lo,
            b: hi,
            radius: (hi.y - lo.y) * 0.5,
        }
    }
}

// ---------------------------------------------------------------- the check

/// The documented allowance of a face whose exact value is about `x`.
fn allowance(x: f64, s: f64, kappa: f64, rounding: Rounding) -> f64 {
    let a = match rounding {
        Rounding::Nearest => U * x.abs() + 2f64.powi(-44) * (1.0 + kappa) * s + 2f64.powi(-150),
        Rounding::Outward => {
            2.0 * U * x.abs() + 2f64.powi(-43) * (1.0 + kappa) * s + 2f64.powi(-149)
        }
    };
    a * (1.0 + 1e-6)
}

/// True when the allowance `a` about `x` reaches the end of the `f32` range on the side of `f`.
fn reaches_end(x: f64, a: f64, f: f32) -> bool {
    if f > 0.0 {
        x + a >= f64::from(f32::MAX)
    } else {
        x - a <= -f64::from(f32::MAX)
    }
}

/// Checks one face against its candidates: the lower face is the least of them, the upper
/// the greatest. Outward must hold them all; both roundings must be within the allowance.
fn check_face(
    f: f32,
    candidates: &[Candidate],
    lower: bool,
    s: f64,
    kappa: f64,
    rounding: Rounding,
) -> Result<(), String> {
    let approx: Vec<f64> = candidates.iter().map(Candidate::approx).collect();
    let x = if lower {
        approx.iter().copied().fold(f64::INFINITY, f64::min)
    } else {
        approx.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    };
    let a = allowance(x, s, kappa, rounding);
    if f.is_nan() {
        return Err(format!("NaN face for exact {x:e}"));
    }
    if f.is_infinite() {
        // Beyond the range on the side of `f`; Outward only ever rounds away.
        let beyond = reaches_end(x, a, f);
        let outward_side = rounding == Rounding::Nearest || (f < 0.0) == lower;
        return if beyond && outward_side {
            Ok(())
        } else {
            Err(format!(
                "infinite face {f} for exact {x:e} (allowance {a:e})"
            ))
        };
    }
    let fq = Q::f(f);
    let aq = Q::f64(a);
    let (minus, plus) = (fq.sub(&aq), fq.add(&aq));
    // At the end of the range, with the exact face beyond it: no closer f32 exists.
    let at_end = f.abs() == f32::MAX && reaches_end(x, a, f);
    let ok = if lower {
        let outward = rounding == Rounding::Nearest || candidates.iter().all(|c| c.above(&fq));
        let near =
            candidates.iter().all(|c| c.above(&minus)) && candidates.iter().any(|c| c.below(&plus));
        outward && (near || at_end)
    } else {
        let outward = rounding == Rounding::Nearest || candidates.iter().all(|c| c.below(&fq));
        let near =
            candidates.iter().all(|c| c.below(&plus)) && candidates.iter().any(|c| c.above(&minus));
        outward && (near || at_end)
    };
    if ok {
        Ok(())
    } else {
        Err(format!(
            "{} face {f:e} vs exact {x:e}: outside, or off by more than {a:e} (S = {s:e}, κ = {kappa})",
            if lower { "lower" } else { "upper" }
        ))
    }
}

/// Checks a result against the contract.
fn check<V: Volume>(
    v: &V,
    map: Option<&XMap>,
    result: Aabb3,
    rounding: Rounding,
) -> Result<(), String> {
    match v.expected(map) {
        Expected::Invalid if !result.is_valid() => Ok(()),
        Expected::Empty if result == Aabb3::EMPTY => Ok(()),
        Expected::Everywhere if result == Aabb3::new(Vec3A::NEG_INFINITY, Vec3A::INFINITY) => {
            Ok(())
        }
        Expected::Faces {
            lo,
            hi,
            magnitude,
            kappa,
        } => (0..3).try_for_each(|i| {
            check_face(result.min[i], &lo[i], true, magnitude[i], kappa, rounding)?;
            check_face(result.max[i], &hi[i], false, magnitude[i], kappa, rounding)
        }),
        _ => Err(format!("wrong special value {result:?}")),
    }
}

// ---------------------------------------------------------------- classes

/// A transform class under test: a random problem of an extreme class, as bvkit's map
/// and the oracle's exact map (`None` when non-finite).
trait Case: Transform3 + Copy + core::fmt::Debug {
    const NAME: &'static str;
    /// The transform, its exact map, and a box of the class for the volume.
    fn make(class: Class, r: &mut StdRng) -> (Self, Option<XMap>, Vec3A, Vec3A);
}

fn finite_map(p: &impl Exactly<3>) -> Option<XMap> {
    p.map_values()
        .iter()
        .all(|x| x.is_finite())
        .then(|| XMap::of(p))
}

fn quat_case(
    class: Class,
    scale: Scale,
    r: &mut StdRng,
) -> (QuatProblem, Option<XMap>, Vec3A, Vec3A) {
    let p = quat_problem(class, scale, r);
    let map = finite_map(&p);
    (p, map, Vec3A::from_array(p.lo), Vec3A::from_array(p.hi))
}

impl Case for Translation3 {
    const NAME: &'static str = "translation";
    fn make(class: Class, r: &mut StdRng) -> (Self, Option<XMap>, Vec3A, Vec3A) {
        let p = translation_problem::<3>(class, r);
        let xf = Translation3(Vec3A::from_array(p.t));
        (
            xf,
            finite_map(&p),
            Vec3A::from_array(p.lo),
            Vec3A::from_array(p.hi),
        )
    }
}

impl Case for Rigid3 {
    const NAME: &'static str = "rigid";
    fn make(class: Class, r: &mut StdRng) -> (Self, Option<XMap>, Vec3A, Vec3A) {
        let (p, map, lo, hi) = quat_case(class, Scale::Unit, r);
        (p.rigid3(), map, lo, hi)
    }
}

impl Case for Similarity3 {
    const NAME: &'static str = "similarity";
    fn make(class: Class, r: &mut StdRng) -> (Self, Option<XMap>, Vec3A, Vec3A) {
        let (p, map, lo, hi) = quat_case(class, Scale::Uniform, r);
        (p.similarity3(), map, lo, hi)
    }
}

impl Case for Trs3 {
    const NAME: &'static str = "trs";
    fn make(class: Class, r: &mut StdRng) -> (Self, Option<XMap>, Vec3A, Vec3A) {
        let (p, map, lo, hi) = quat_case(class, Scale::PerAxis, r);
        (p.trs3(), map, lo, hi)
    }
}

impl Case for Affine3A {
    const NAME: &'static str = "affine";
    fn make(class: Class, r: &mut StdRng) -> (Self, Option<XMap>, Vec3A, Vec3A) {
        let p = problem::<3>(class, r);
        let (b, xf) = affine3(&p);
        (xf, finite_map(&p), b.min, b.max)
    }
}

const CASES_PER_CLASS: usize = 12;

/// Every extreme class × rounding for one volume type and one transform class.
fn world_aabbs_hold<V: Volume, T: Case>(seed: u64) {
    let mut r = rng(seed);
    for class in Class::ALL {
        for n in 0..CASES_PER_CLASS {
            let (xf, map, lo, hi) = T::make(class, &mut r);
            let v = V::from_box(lo, hi, &mut r);
            for rounding in Rounding::ALL {
                let result = v.transformed_aabb(&xf, rounding);
                if let Err(e) = check(&v, map.as_ref(), result, rounding) {
                    panic!(
                        "{} {class:?} #{n} {rounding:?}: {e}\n  volume {v:?}\n  map {xf:?}\n  result {result:?}",
                        T::NAME
                    );
                }
            }
        }
    }
}

macro_rules! world_tests {
    ($($name:ident: $v:ty, $t:ty, $seed:expr;)*) => {$(
        #[test]
        fn $name() {
            world_aabbs_hold::<$v, $t>($seed);
        }
    )*};
}

world_tests! {
    obb_translation: Obb3, Translation3, 1;
    obb_rigid: Obb3, Rigid3, 2;
    obb_similarity: Obb3, Similarity3, 3;
    obb_trs: Obb3, Trs3, 4;
    obb_affine: Obb3, Affine3A, 5;
    sphere_translation: Sphere, Translation3, 6;
    sphere_rigid: Sphere, Rigid3, 7;
    sphere_similarity: Sphere, Similarity3, 8;
    sphere_trs: Sphere, Trs3, 9;
    sphere_affine: Sphere, Affine3A, 10;
    capsule_translation: Capsule, Translation3, 11;
    capsule_rigid: Capsule, Rigid3, 12;
    capsule_similarity: Capsule, Similarity3, 13;
    capsule_trs: Capsule, Trs3, 14;
    capsule_affine: Capsule, Affine3A, 15;
}
