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

/// A volume's exact faces: the candidates of the lower and upper faces, `reach` and `κ`.
type Faces = ([Vec<Candidate>; 3], [Vec<Candidate>; 3], [f64; 3], f64);

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
    fn faces(&self, map: &XMap) -> Faces;
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
    fn faces(&self, map: &XMap) -> Faces {
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
fn swept(map: &XMap, ends: &[Vec3A], radius: f32) -> Faces {
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
    fn faces(&self, map: &XMap) -> Faces {
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
    fn faces(&self, map: &XMap) -> Faces {
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

// ---------------------------------------------------------------- batches and bad input

/// Bit patterns of a box, so that NaN results compare too.
fn bits(b: &Aabb3) -> [u32; 6] {
    let (l, h) = (b.min.to_array(), b.max.to_array());
    [l[0], l[1], l[2], h[0], h[1], h[2]].map(f32::to_bits)
}

/// The batch entry point equals the single calls bitwise, per transform and shared, and
/// checks its lengths before writing anything.
fn batch_matches<V: Volume, T: Case>(seed: u64) {
    let mut r = rng(seed);
    let (mut volumes, mut xfs) = (Vec::new(), Vec::new());
    for class in Class::ALL {
        for _ in 0..3 {
            let (xf, _, lo, hi) = T::make(class, &mut r);
            volumes.push(V::from_box(lo, hi, &mut r));
            xfs.push(xf);
        }
    }
    let n = volumes.len();
    let sentinel = Aabb3::new(Vec3A::splat(7.0), Vec3A::splat(-7.0));
    for rounding in Rounding::ALL {
        let mut out = vec![sentinel; n];
        V::transformed_aabbs(&volumes, &xfs[..], &mut out, rounding).unwrap();
        let mut shared = vec![sentinel; n];
        V::transformed_aabbs(&volumes, &xfs[5], &mut shared, rounding).unwrap();
        for k in 0..n {
            assert_eq!(
                bits(&out[k]),
                bits(&volumes[k].transformed_aabb(&xfs[k], rounding))
            );
            assert_eq!(
                bits(&shared[k]),
                bits(&volumes[k].transformed_aabb(&xfs[5], rounding))
            );
        }
        let mut short = vec![sentinel; n - 1];
        assert_eq!(
            V::transformed_aabbs(&volumes, &xfs[..], &mut short, rounding),
            Err(BatchError::LengthMismatch {
                what: "output",
                expected: n,
                found: n - 1
            })
        );
        let mut untouched = vec![sentinel; n];
        assert_eq!(
            V::transformed_aabbs(&volumes, &xfs[1..], &mut untouched, rounding),
            Err(BatchError::LengthMismatch {
                what: "transforms",
                expected: n,
                found: n - 1
            })
        );
        assert!(short.iter().chain(&untouched).all(|b| *b == sentinel));
    }
}

#[test]
fn batches_equal_single_calls() {
    batch_matches::<Obb3, Rigid3>(21);
    batch_matches::<Obb3, Affine3A>(22);
    batch_matches::<Sphere, Translation3>(23);
    batch_matches::<Sphere, Similarity3>(24);
    batch_matches::<Capsule, Trs3>(25);
    batch_matches::<Capsule, Affine3A>(26);
}

#[test]
fn bad_input_follows_the_contract() {
    let pose = Rigid3::new(Quat::from_rotation_z(0.5), Vec3A::new(1.0, 2.0, 3.0));
    let obb = Obb3 {
        center: Vec3A::ONE,
        half_extents: Vec3A::new(1.0, 2.0, 3.0),
        rotation: Mat3A::from_rotation_x(0.3),
    };
    let sphere = Sphere {
        center: Vec3A::ONE,
        radius: 2.0,
    };
    let capsule = Capsule {
        a: Vec3A::ZERO,
        b: Vec3A::X,
        radius: 1.0,
    };
    let everywhere = Aabb3::new(Vec3A::NEG_INFINITY, Vec3A::INFINITY);
    let nan_pose = Rigid3::new(Quat::from_xyzw(f32::NAN, 0.0, 0.0, 1.0), Vec3A::ZERO);
    let inf_pose = Affine3A::from_translation(glam::Vec3::new(f32::INFINITY, 0.0, 0.0));
    for rounding in Rounding::ALL {
        {
            let v = obb;
            assert!(!v.transformed_aabb(&nan_pose, rounding).is_valid());
            assert!(!v.transformed_aabb(&inf_pose, rounding).is_valid());
            let nan = Obb3 {
                center: Vec3A::new(0.0, f32::NAN, 0.0),
                ..v
            };
            assert!(!nan.transformed_aabb(&pose, rounding).is_valid());
            let empty = Obb3 {
                half_extents: Vec3A::new(1.0, -1.0, 1.0),
                ..v
            };
            assert_eq!(empty.transformed_aabb(&pose, rounding), Aabb3::EMPTY);
            let unbounded = Obb3 {
                half_extents: Vec3A::new(1.0, f32::INFINITY, 1.0),
                ..v
            };
            assert_eq!(unbounded.transformed_aabb(&pose, rounding), everywhere);
            let singular = Obb3 {
                rotation: Mat3A::ZERO,
                ..v
            };
            assert_eq!(singular.transformed_aabb(&pose, rounding), everywhere);
        }
        {
            let v = sphere;
            assert!(!v.transformed_aabb(&nan_pose, rounding).is_valid());
            assert!(!v.transformed_aabb(&inf_pose, rounding).is_valid());
            let nan = Sphere {
                radius: f32::NAN,
                ..v
            };
            assert!(!nan.transformed_aabb(&pose, rounding).is_valid());
            let empty = Sphere { radius: -1.0, ..v };
            assert_eq!(empty.transformed_aabb(&pose, rounding), Aabb3::EMPTY);
            let far = Sphere {
                center: Vec3A::splat(3e38),
                radius: 1e38,
            };
            // Faces at 2e39 and 4e39: +inf, or f32::MAX for an Outward lower face.
            let big = Similarity3::new(10.0, Quat::IDENTITY, Vec3A::ZERO);
            let b = far.transformed_aabb(&big, rounding);
            assert_eq!(b.max, Vec3A::INFINITY);
            assert!(b.min.cmpge(Vec3A::splat(f32::MAX)).all(), "{b:?}");
        }
        {
            let v = capsule;
            assert!(!v.transformed_aabb(&nan_pose, rounding).is_valid());
            let nan = Capsule { b: Vec3A::NAN, ..v };
            assert!(!nan.transformed_aabb(&pose, rounding).is_valid());
            let empty = Capsule { radius: -0.5, ..v };
            assert_eq!(empty.transformed_aabb(&pose, rounding), Aabb3::EMPTY);
            let unbounded = Capsule {
                a: Vec3A::NEG_INFINITY,
                ..v
            };
            assert_eq!(unbounded.transformed_aabb(&pose, rounding), everywhere);
        }
    }
}

// ---------------------------------------------------------------- images under similarities

/// Rational directions on the unit sphere: the axes and `(1, 2, 2)/3`, `(2, 3, 6)/7`,
/// `(1, 4, 8)/9` with every sign and cyclic order.
fn unit_directions() -> Vec<V3> {
    let mut dirs = Vec::new();
    for k in 0..3 {
        for s in [-1, 1] {
            let mut v = [0i64; 3];
            v[k] = s;
            dirs.push(v.map(Q::int));
        }
    }
    for ([a, b, c], m) in [([1, 2, 2], 3), ([2, 3, 6], 7), ([1, 4, 8], 9)] {
        for rot in 0..3 {
            for signs in 0..8 {
                let base = [a, b, c];
                let v: [i64; 3] = core::array::from_fn(|i| {
                    let x = base[(i + rot) % 3];
                    if signs >> i & 1 == 1 { -x } else { x }
                });
                dirs.push(v.map(|x| Q::int(x).div(&Q::int(m))));
            }
        }
    }
    dirs
}

/// `|x − c|² <= r²`, exactly.
fn in_ball(x: &V3, c: Vec3A, r: f32) -> bool {
    let d = vsub(x, &v3(c));
    let r = Q::f(r);
    dot(&d, &d).le(&r.mul(&r))
}

/// The capsule's statement on `x`, exactly.
fn in_capsule(x: &V3, cap: &Capsule) -> bool {
    let (a, b) = (v3(cap.a), v3(cap.b));
    let r = Q::f(cap.radius);
    let r2 = r.mul(&r);
    let (v, w) = (vsub(x, &a), vsub(&b, &a));
    let (vw, ww) = (dot(&v, &w), dot(&w, &w));
    if vw.le(&Q::int(0)) || ww.le(&Q::int(0)) {
        dot(&v, &v).le(&r2)
    } else if ww.le(&vw) {
        let u = vsub(x, &b);
        dot(&u, &u).le(&r2)
    } else {
        dot(&v, &v).mul(&ww).sub(&vw.mul(&vw)).le(&r2.mul(&ww))
    }
}

/// The box's slab statement on `x`, exactly.
fn in_box(x: &V3, obb: &Obb3) -> bool {
    let d = vsub(x, &v3(obb.center));
    (0..3).all(|k| {
        let s = dot(&d, &v3(obb.rotation.col(k)));
        let h = Q::f(obb.half_extents[k]);
        s.le(&h) && s.neg().le(&h)
    })
}

/// A similarity (`Rigid3` when `rigid`) of an extreme class, its exact map (`None` when
/// non-finite), `|σ|` and a box of the class.
fn similarity(
    class: Class,
    rigid: bool,
    r: &mut StdRng,
) -> (Similarity3, Option<XMap>, Vec3A, Vec3A) {
    let scale = if rigid { Scale::Unit } else { Scale::Uniform };
    let (p, map, lo, hi) = quat_case(class, scale, r);
    let xf = if rigid {
        p.rigid3().into()
    } else {
        p.similarity3()
    };
    (xf, map, lo, hi)
}

fn finite(values: &[f32]) -> bool {
    values.iter().all(|x| x.is_finite())
}

/// Every image holds the exact images of the volume's extreme points (the box's corners,
/// points of the balls' spheres), over every extreme class, rigid and similar.
#[test]
fn images_hold_the_exact_images() {
    let mut r = rng(31);
    let dirs = unit_directions();
    let mut checked = 0;
    for class in Class::ALL {
        for n in 0..CASES_PER_CLASS {
            for rigid in [true, false] {
                let (xf, map, lo, hi) = similarity(class, rigid, &mut r);
                let (obb, sphere, capsule) = (
                    Obb3::from_box(lo, hi, &mut r),
                    Sphere::from_box(lo, hi, &mut r),
                    Capsule::from_box(lo, hi, &mut r),
                );
                let context = format!("{class:?} #{n} rigid {rigid}: {xf:?}");
                let images = (
                    obb.transformed(xf),
                    sphere.transformed(xf),
                    capsule.transformed(xf),
                );
                let Some(map) = map.filter(|_| finite(&obb.fields()) && finite(&capsule.fields()))
                else {
                    // NaN or infinite input: NaN fields (or the empty volume's sign kept).
                    assert!(images.0.fields().iter().any(|x| x.is_nan()), "{context}");
                    continue;
                };
                let (o, s, c) = images;
                if finite(&o.fields()) && !obb.is_empty() {
                    for y in corners(&obb) {
                        assert!(
                            in_box(&map.apply(&y), &o),
                            "box {obb:?} -> {o:?}, {context}"
                        );
                    }
                    checked += 1;
                }
                assert_eq!(o.is_empty(), obb.is_empty(), "{context}");
                let rad = Q::f(sphere.radius);
                if finite(&s.fields()) && !sphere.is_empty() {
                    for d in &dirs {
                        let y = vadd(&v3(sphere.center), &vscale(d, &rad));
                        assert!(
                            in_ball(&map.apply(&y), s.center, s.radius),
                            "ball {sphere:?} -> {s:?}, {context}"
                        );
                    }
                    checked += 1;
                }
                assert_eq!(s.is_empty(), sphere.is_empty(), "{context}");
                let rad = Q::f(capsule.radius);
                let mid = vscale(
                    &vadd(&v3(capsule.a), &v3(capsule.b)),
                    &Q::int(1).div(&Q::int(2)),
                );
                if finite(&c.fields()) && !capsule.is_empty() {
                    for p in [v3(capsule.a), v3(capsule.b), mid] {
                        for d in &dirs[..30] {
                            let y = vadd(&p, &vscale(d, &rad));
                            assert!(
                                in_capsule(&map.apply(&y), &c),
                                "capsule {capsule:?} -> {c:?}, {context}"
                            );
                        }
                    }
                    checked += 1;
                }
                assert_eq!(c.is_empty(), capsule.is_empty(), "{context}");
            }
        }
    }
    assert!(checked > 600, "only {checked} finite images checked");
}

/// For unit quaternions and orthonormal axes the images are tight: the half-extents and
/// radii exceed `|σ|` times the old ones by about the rounding of the moved center.
#[test]
fn images_are_tight() {
    let mut r = rng(32);
    for class in [
        Class::Typical,
        Class::Far,
        Class::Reflection,
        Class::ZeroSize,
    ] {
        for _ in 0..50 {
            let (xf, _, lo, hi) = similarity(class, false, &mut r);
            let sigma = xf.scale.abs();
            let slack = |c: Vec3A, size: f32| {
                2f32.powi(-18) * (c.abs().element_sum() + sigma * size) + 1e-30
            };
            let obb = Obb3::from_box(lo, hi, &mut r);
            let o = obb.transformed(xf);
            for k in 0..3 {
                let bound =
                    sigma * obb.half_extents[k] + slack(o.center, obb.half_extents.element_sum());
                assert!(o.half_extents[k] <= bound, "{obb:?} -> {o:?} under {xf:?}");
            }
            let sphere = Sphere::from_box(lo, hi, &mut r);
            let s = sphere.transformed(xf);
            assert!(
                s.radius <= sigma * sphere.radius + slack(s.center, sphere.radius),
                "{s:?}"
            );
            let capsule = Capsule::from_box(lo, hi, &mut r);
            let c = capsule.transformed(xf);
            let reach = c.a.abs().max(c.b.abs());
            assert!(
                c.radius <= sigma * capsule.radius + slack(reach, capsule.radius),
                "{c:?}"
            );
        }
    }
}
