//! World AABBs of volumes judged exactly, in rationals.
//!
//! **How the exact image is judged.** Every `f32` is a dyadic rational, and so is every
//! entry of the exact map (the oracle's `exact_cols`). A box's exact corners are
//! `c + Σ_j ±h_j·B_j/D` (its dual basis: `B_j = a_{j+1} × a_{j+2}`, `D = a_0·B_0`), rational;
//! their images give the exact faces as rationals. A ball's exact faces are
//! `(M c + t)_i ± r·√(Σ_k m_ik²)`: a face `f` is compared with `C + k·√N` by the sign of
//! `f − C` and the squares, exactly. A capsule's faces are those of its two end balls.

use crate::oracle::{self, Exact, Exactly};
use bvkit::{Aabb3, BoundingVolume, Capsule, Obb3, Rounding, Similarity3, Sphere};
use glam::{Mat3A, Vec3A};
use num_bigint::BigInt;
use num_traits::{Signed, ToPrimitive, Zero};

pub const U: f64 = 1.0 / 16_777_216.0;

// ---------------------------------------------------------------- exact rationals

/// An exact rational `n / d`, `d > 0`.
#[derive(Clone, Debug)]
pub struct Q {
    pub n: BigInt,
    pub d: BigInt,
}

impl Q {
    pub fn int(n: i64) -> Q {
        Q {
            n: BigInt::from(n),
            d: BigInt::from(1),
        }
    }
    /// The exact value of a finite `f32`.
    pub fn f(x: f32) -> Q {
        match Exact::of(x) {
            Exact::Finite(n) => Q {
                n,
                d: BigInt::from(1) << oracle::SCALE as usize,
            },
            _ => panic!("finite values only"),
        }
    }
    /// The exact value of a finite `f64`.
    pub fn f64(x: f64) -> Q {
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
    pub fn exact(e: &Exact) -> Q {
        match e {
            Exact::Finite(n) => Q {
                n: n.clone(),
                d: BigInt::from(1) << oracle::SCALE as usize,
            },
            _ => panic!("finite values only"),
        }
    }
    pub fn add(&self, o: &Q) -> Q {
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
    pub fn neg(&self) -> Q {
        Q {
            n: -&self.n,
            d: self.d.clone(),
        }
    }
    pub fn sub(&self, o: &Q) -> Q {
        self.add(&o.neg())
    }
    pub fn mul(&self, o: &Q) -> Q {
        Q {
            n: &self.n * &o.n,
            d: &self.d * &o.d,
        }
    }
    pub fn div(&self, o: &Q) -> Q {
        assert!(!o.n.is_zero(), "division by zero");
        let s = if o.n.is_negative() { -1 } else { 1 };
        Q {
            n: &self.n * &o.d * s,
            d: &self.d * o.n.abs(),
        }
    }
    pub fn is_neg(&self) -> bool {
        self.n.is_negative()
    }
    pub fn le(&self, o: &Q) -> bool {
        !o.sub(self).is_neg()
    }
    pub fn to_f64(&self) -> f64 {
        let top = |x: &BigInt| {
            let shift = (x.bits() as i64 - 60).max(0);
            ((x >> shift as usize).to_f64().unwrap(), shift)
        };
        let ((n, a), (d, b)) = (top(&self.n), top(&self.d));
        n / d * 2f64.powi((a - b) as i32)
    }
}

pub type V3 = [Q; 3];

pub fn v3(v: Vec3A) -> V3 {
    v.to_array().map(Q::f)
}
pub fn vadd(a: &V3, b: &V3) -> V3 {
    core::array::from_fn(|i| a[i].add(&b[i]))
}
pub fn vsub(a: &V3, b: &V3) -> V3 {
    core::array::from_fn(|i| a[i].sub(&b[i]))
}
pub fn vscale(a: &V3, s: &Q) -> V3 {
    core::array::from_fn(|i| a[i].mul(s))
}
pub fn dot(a: &V3, b: &V3) -> Q {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}
pub fn cross(a: &V3, b: &V3) -> V3 {
    core::array::from_fn(|i| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        a[j].mul(&b[k]).sub(&a[k].mul(&b[j]))
    })
}

/// The exact map `x ↦ M x + t` of a problem, and the weights `μ_ik` of its magnitude.
pub struct XMap {
    pub rows: [V3; 3],
    pub t: V3,
    pub mu: [[f64; 3]; 3],
}

impl XMap {
    pub fn of(p: &impl Exactly<3>) -> XMap {
        let cols = p.exact_cols();
        XMap {
            rows: core::array::from_fn(|i| core::array::from_fn(|k| Q::exact(&cols[k][i]))),
            t: p.t().map(Q::f),
            mu: p.weights(),
        }
    }
    pub fn apply(&self, p: &V3) -> V3 {
        core::array::from_fn(|i| dot(&self.rows[i], p).add(&self.t[i]))
    }
    /// `S_i = |t_i| + Σ_k μ_ik·reach_k`.
    pub fn magnitude(&self, reach: [f64; 3]) -> [f64; 3] {
        core::array::from_fn(|i| {
            self.t[i].to_f64().abs() + (0..3).map(|k| self.mu[i][k] * reach[k]).sum::<f64>()
        })
    }
}

/// The value `C + k·√N`.
#[derive(Clone, Debug)]
pub struct Candidate {
    pub c: Q,
    pub k: Q,
    pub n: Q,
}

impl Candidate {
    pub fn point(c: Q) -> Self {
        Candidate {
            c,
            k: Q::int(0),
            n: Q::int(0),
        }
    }
    pub fn approx(&self) -> f64 {
        self.c.to_f64() + self.k.to_f64() * self.n.to_f64().sqrt()
    }
    /// `f <= C + k·√N`, exactly.
    pub fn above(&self, f: &Q) -> bool {
        let a = f.sub(&self.c);
        let (a2, k2n) = (a.mul(&a), self.k.mul(&self.k).mul(&self.n));
        if self.k.is_neg() {
            a.le(&Q::int(0)) && k2n.le(&a2)
        } else {
            a.le(&Q::int(0)) || a2.le(&k2n)
        }
    }
    /// `f >= C + k·√N`.
    pub fn below(&self, f: &Q) -> bool {
        Candidate {
            c: self.c.neg(),
            k: self.k.neg(),
            n: self.n.clone(),
        }
        .above(&f.neg())
    }
}

/// A volume's exact faces: the candidates of the lower and upper faces, `reach` and `κ`.
pub type Faces = ([Vec<Candidate>; 3], [Vec<Candidate>; 3], [f64; 3], f64);

/// What the contract demands of one volume's world AABB.
pub enum Expected {
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
pub trait Volume: BoundingVolume + Copy + core::fmt::Debug {
    fn fields(&self) -> Vec<f32>;
    fn is_empty(&self) -> bool;
    /// The exact faces' candidates (finite fields, non-empty, not singular), `reach` and `κ`.
    fn faces(&self, map: &XMap) -> Faces;
    /// True for a box whose axes are exactly singular: it bounds no finite set.
    fn is_singular(&self) -> bool {
        false
    }

    fn expected(&self, map: Option<&XMap>) -> Expected {
        let fields = self.fields();
        let Some(map) = map.filter(|_| !fields.iter().any(|x| x.is_nan())) else {
            return Expected::Invalid;
        };
        if self.is_empty() {
            return Expected::Empty;
        }
        if !fields.iter().all(|x| x.is_finite()) || self.is_singular() {
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
pub fn dual(rotation: Mat3A) -> ([V3; 3], Q) {
    let a = [0, 1, 2].map(|k| v3(rotation.col(k)));
    let b = [0, 1, 2].map(|j| cross(&a[(j + 1) % 3], &a[(j + 2) % 3]));
    let det = dot(&a[0], &b[0]);
    (b, det)
}

/// The box's 8 exact corners `c + Σ_j ±h_j·B_j/D`.
pub fn corners(obb: &Obb3) -> Vec<V3> {
    let (b, det) = dual(obb.rotation);
    let (c, h) = (v3(obb.center), v3(obb.half_extents));
    let steps = [0, 1, 2].map(|j| vscale(&b[j], &h[j].div(&det)));
    (0..8)
        .map(|s| {
            (0..3).fold(c.clone(), |y, j| {
                if s >> j & 1 == 0 {
                    vsub(&y, &steps[j])
                } else {
                    vadd(&y, &steps[j])
                }
            })
        })
        .collect()
}

impl Volume for Obb3 {
    fn is_singular(&self) -> bool {
        dual(self.rotation).1.n.is_zero()
    }
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
}

/// The candidates of balls of radius `r` about `ends`.
pub fn swept(map: &XMap, ends: &[Vec3A], radius: f32) -> Faces {
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
}

// ---------------------------------------------------------------- the check

/// The documented allowance of a face whose exact value is about `x`.
pub fn allowance(x: f64, s: f64, kappa: f64, rounding: Rounding) -> f64 {
    let a = match rounding {
        Rounding::Nearest => U * x.abs() + 2f64.powi(-44) * (1.0 + kappa) * s + 2f64.powi(-150),
        Rounding::Outward => {
            2.0 * U * x.abs() + 2f64.powi(-43) * (1.0 + kappa) * s + 2f64.powi(-149)
        }
    };
    a * (1.0 + 1e-6)
}

/// True when the allowance `a` about `x` reaches the end of the `f32` range on the side of `f`.
pub fn reaches_end(x: f64, a: f64, f: f32) -> bool {
    if f > 0.0 {
        x + a >= f64::from(f32::MAX)
    } else {
        x - a <= -f64::from(f32::MAX)
    }
}

/// Checks one face against its candidates: the lower face is the least of them, the upper
/// the greatest. Outward must hold them all; both roundings must be within the allowance.
pub fn check_face(
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

/// The whole space.
pub const EVERYWHERE: Aabb3 = Aabb3::new(Vec3A::NEG_INFINITY, Vec3A::INFINITY);

/// Checks a result against the contract.
pub fn check<V: Volume>(
    v: &V,
    map: Option<&XMap>,
    result: Aabb3,
    rounding: Rounding,
) -> Result<(), String> {
    check_expected(&v.expected(map), result, rounding)
}

/// Checks a result against what the contract demands of it ([`Volume::expected`]).
pub fn check_expected(
    expected: &Expected,
    result: Aabb3,
    rounding: Rounding,
) -> Result<(), String> {
    match expected {
        Expected::Invalid if !result.is_valid() => Ok(()),
        Expected::Empty if result == Aabb3::EMPTY => Ok(()),
        Expected::Everywhere if result == EVERYWHERE => Ok(()),
        // Axes so close to singular (`κ >= 2^40`) that they are taken as singular (documented).
        Expected::Faces { kappa, .. } if result == EVERYWHERE && *kappa >= 2f64.powi(39) => Ok(()),
        Expected::Faces {
            lo,
            hi,
            magnitude,
            kappa,
        } => (0..3).try_for_each(|i| {
            check_face(result.min[i], &lo[i], true, magnitude[i], *kappa, rounding)?;
            check_face(result.max[i], &hi[i], false, magnitude[i], *kappa, rounding)
        }),
        _ => Err(format!("wrong special value {result:?}")),
    }
}

pub fn finite_map(p: &impl Exactly<3>) -> Option<XMap> {
    p.map_values()
        .iter()
        .all(|x| x.is_finite())
        .then(|| XMap::of(p))
}

/// Rational directions on the unit sphere: the axes and `(1, 2, 2)/3`, `(2, 3, 6)/7`,
/// `(1, 4, 8)/9` with every sign and cyclic order.
pub fn unit_directions() -> Vec<V3> {
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
pub fn in_ball(x: &V3, c: Vec3A, r: f32) -> bool {
    let d = vsub(x, &v3(c));
    let r = Q::f(r);
    dot(&d, &d).le(&r.mul(&r))
}

/// The capsule's statement on `x`, exactly.
pub fn in_capsule(x: &V3, cap: &Capsule) -> bool {
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
pub fn in_box(x: &V3, obb: &Obb3) -> bool {
    let d = vsub(x, &v3(obb.center));
    (0..3).all(|k| {
        let s = dot(&d, &v3(obb.rotation.col(k)));
        let h = Q::f(obb.half_extents[k]);
        s.le(&h) && s.neg().le(&h)
    })
}

pub fn finite(values: &[f32]) -> bool {
    values.iter().all(|x| x.is_finite())
}

/// Checks the images of three volumes under the similarity `xf` (exact map `map`, `None`
/// when non-finite): each holds the exact images of the volume's extreme points (the box's
/// corners, points of the balls' spheres along `dirs`), exactly; a NaN or infinite map or
/// volume gives NaN fields; emptiness is kept. Returns how many finite images were checked.
pub fn check_images(
    xf: Similarity3,
    map: Option<&XMap>,
    obb: &Obb3,
    sphere: &Sphere,
    capsule: &Capsule,
    dirs: &[V3],
    context: &str,
) -> usize {
    let (o, s, c) = (
        obb.transformed(xf),
        sphere.transformed(xf),
        capsule.transformed(xf),
    );
    let nan = |fields: Vec<f32>| fields.iter().any(|x| x.is_nan());
    let mut checked = 0;
    // One volume: NaN fields for bad input, else emptiness kept and, when the image is
    // finite and not empty, every extreme point's exact image in it.
    let mut one =
        |input: Vec<f32>, image: Vec<f32>, empty: [bool; 2], holds: &dyn Fn(&XMap)| match map
            .filter(|_| finite(&input))
        {
            None => assert!(nan(image), "{context}"),
            Some(map) => {
                assert_eq!(empty[0], empty[1], "{context}");
                if finite(&image) && !empty[0] {
                    holds(map);
                    checked += 1;
                }
            }
        };
    one(
        obb.fields(),
        o.fields(),
        [obb.is_empty(), o.is_empty()],
        &|map| {
            assert!(!obb.is_singular(), "singular {obb:?} -> {o:?}, {context}");
            for y in corners(obb) {
                assert!(
                    in_box(&map.apply(&y), &o),
                    "box {obb:?} -> {o:?}, {context}"
                );
            }
        },
    );
    one(
        sphere.fields(),
        s.fields(),
        [sphere.is_empty(), s.is_empty()],
        &|map| {
            let rad = Q::f(sphere.radius);
            for d in dirs {
                let y = vadd(&v3(sphere.center), &vscale(d, &rad));
                assert!(
                    in_ball(&map.apply(&y), s.center, s.radius),
                    "ball {sphere:?} -> {s:?}, {context}"
                );
            }
        },
    );
    one(
        capsule.fields(),
        c.fields(),
        [capsule.is_empty(), c.is_empty()],
        &|map| {
            let rad = Q::f(capsule.radius);
            let mid = vscale(
                &vadd(&v3(capsule.a), &v3(capsule.b)),
                &Q::int(1).div(&Q::int(2)),
            );
            for p in [v3(capsule.a), v3(capsule.b), mid] {
                for d in dirs.iter().take(30) {
                    let y = vadd(&p, &vscale(d, &rad));
                    assert!(
                        in_capsule(&map.apply(&y), &c),
                        "capsule {capsule:?} -> {c:?}, {context}"
                    );
                }
            }
        },
    );
    checked
}
