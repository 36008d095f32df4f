//! Fitting: every input point lies in every fitted volume, decided exactly.
//!
//! **How containment is checked.** Every finite `f32` is an integer multiple of `2^-149`,
//! so `F(x) = x·2^149` is an integer ([`oracle::Exact`] gives it). Each containment
//! statement of the docs is a polynomial inequality in the `f32` fields and coordinates, so
//! it is decided exactly in big integers, with no rounding anywhere:
//! - box: `|Σ_j (F(p_j) − F(c_j))·F(a_kj)| <= F(h_k)·2^149` for each axis `k`;
//! - sphere: `Σ_j (F(p_j) − F(c_j))² <= F(r)²`;
//! - capsule: with `v = F(p) − F(a)`, `w = F(b) − F(a)`: the exact closest point of the
//!   segment is at `t = v·w / w·w`; `t <= 0`: `|v|² <= F(r)²`; `t >= 1`: `|F(p) − F(b)|² <=
//!   F(r)²`; else `|v|²·|w|² − (v·w)² <= F(r)²·|w|²` (the squared distance times `|w|²`).
//!
//! Each check is shown to fail on a volume shrunk by one part in a million.
#![allow(clippy::needless_range_loop)]

mod meshes;
mod oracle;

use bvkit::{Aabb3, Capsule, Fit, FitError, Obb3, Sphere};
use glam::{Mat3A, Quat, Vec3, Vec3A};
use num_bigint::BigInt;
use num_traits::Signed;
use oracle::Exact;

const MODES: [Fit; 3] = [Fit::Pca, Fit::Fast, Fit::Tight];

/// `x·2^149`, exactly.
fn fixed(x: f32) -> BigInt {
    match Exact::of(x) {
        Exact::Finite(v) => v >> 149usize,
        _ => panic!("finite values only"),
    }
}

fn fixed3(v: Vec3A) -> [BigInt; 3] {
    v.to_array().map(fixed)
}

fn sub(a: &[BigInt; 3], b: &[BigInt; 3]) -> [BigInt; 3] {
    core::array::from_fn(|i| &a[i] - &b[i])
}

fn dot(a: &[BigInt; 3], b: &[BigInt; 3]) -> BigInt {
    (0..3).map(|i| &a[i] * &b[i]).sum()
}

fn cross(a: &[BigInt; 3], b: &[BigInt; 3]) -> [BigInt; 3] {
    core::array::from_fn(|i| &a[(i + 1) % 3] * &b[(i + 2) % 3] - &a[(i + 2) % 3] * &b[(i + 1) % 3])
}

/// A fitted volume and its containment statement, decided exactly.
trait Volume: Copy + std::fmt::Debug {
    const NAME: &'static str;
    fn fit(points: &[Vec3], fit: Fit) -> Result<Self, FitError>;
    fn holds_exactly(&self, p: Vec3A) -> bool;
    fn contains_point(&self, p: Vec3A) -> bool;
    fn volume(&self) -> f32;
    fn aabb(&self) -> Aabb3;
    /// True when the AABB contains every point of the volume, exactly.
    fn aabb_holds_exactly(&self) -> bool;
    /// The same volume shrunk by a factor `1 − s` about its center.
    fn shrunk(&self, s: f32) -> Self;
}

/// `F(lo_i) <= F(c_i) − reach_i` and `F(hi_i) >= F(c_i) + reach_i` (all at scale `2^149`).
fn aabb_reaches(aabb: &Aabb3, lo: &[BigInt; 3], hi: &[BigInt; 3], reach: &BigInt) -> bool {
    let (min, max) = (fixed3(aabb.min), fixed3(aabb.max));
    (0..3).all(|i| min[i] <= &lo[i] - reach && max[i] >= &hi[i] + reach)
}

impl Volume for Obb3 {
    const NAME: &'static str = "obb";
    fn fit(points: &[Vec3], fit: Fit) -> Result<Self, FitError> {
        Obb3::fit(points, fit)
    }
    fn holds_exactly(&self, p: Vec3A) -> bool {
        let d = sub(&fixed3(p), &fixed3(self.center));
        (0..3).all(|k| {
            let s = dot(&d, &fixed3(self.rotation.col(k)));
            s.abs() <= fixed(self.half_extents[k]) << 149usize
        })
    }
    fn contains_point(&self, p: Vec3A) -> bool {
        Obb3::contains_point(self, p)
    }
    fn volume(&self) -> f32 {
        Obb3::volume(self)
    }
    fn aabb(&self) -> Aabb3 {
        Obb3::aabb(self)
    }
    /// The box is `c + Σ_k s_k b_k`, `|s_k| <= h_k`, with the dual basis `b_k = B_k / D`,
    /// `B_k = a_{k+1} × a_{k+2}`, `D = a_0·B_0`; so face `i` needs
    /// `(F(max_i) − F(c_i))·|D| >= Σ_k |B_ki|·F(h_k)·2^149` (and the same below).
    fn aabb_holds_exactly(&self) -> bool {
        let a = [0, 1, 2].map(|k| fixed3(self.rotation.col(k)));
        let dual = [0, 1, 2].map(|k| cross(&a[(k + 1) % 3], &a[(k + 2) % 3]));
        let det = dot(&a[0], &dual[0]).abs();
        let h = fixed3(self.half_extents);
        let c = fixed3(self.center);
        let (min, max) = (fixed3(self.aabb().min), fixed3(self.aabb().max));
        (0..3).all(|i| {
            let reach: BigInt =
                (0..3).map(|k| dual[k][i].abs() * &h[k]).sum::<BigInt>() << 149usize;
            (&max[i] - &c[i]) * &det >= reach && (&c[i] - &min[i]) * &det >= reach
        })
    }
    fn shrunk(&self, s: f32) -> Self {
        Obb3 {
            half_extents: self.half_extents * (1.0 - s),
            ..*self
        }
    }
}

impl Volume for Sphere {
    const NAME: &'static str = "sphere";
    fn fit(points: &[Vec3], fit: Fit) -> Result<Self, FitError> {
        Sphere::fit(points, fit)
    }
    fn holds_exactly(&self, p: Vec3A) -> bool {
        let d = sub(&fixed3(p), &fixed3(self.center));
        let r = fixed(self.radius);
        dot(&d, &d) <= &r * &r
    }
    fn contains_point(&self, p: Vec3A) -> bool {
        Sphere::contains_point(self, p)
    }
    fn volume(&self) -> f32 {
        Sphere::volume(self)
    }
    fn aabb(&self) -> Aabb3 {
        Sphere::aabb(self)
    }
    fn aabb_holds_exactly(&self) -> bool {
        let c = fixed3(self.center);
        aabb_reaches(&self.aabb(), &c, &c, &fixed(self.radius))
    }
    fn shrunk(&self, s: f32) -> Self {
        Sphere {
            radius: self.radius * (1.0 - s),
            ..*self
        }
    }
}

impl Volume for Capsule {
    const NAME: &'static str = "capsule";
    fn fit(points: &[Vec3], fit: Fit) -> Result<Self, FitError> {
        Capsule::fit(points, fit)
    }
    fn holds_exactly(&self, p: Vec3A) -> bool {
        let (a, b, p) = (fixed3(self.a), fixed3(self.b), fixed3(p));
        let r2 = fixed(self.radius).pow(2);
        let (v, w) = (sub(&p, &a), sub(&b, &a));
        let (vw, ww) = (dot(&v, &w), dot(&w, &w));
        if vw <= BigInt::ZERO || ww == BigInt::ZERO {
            dot(&v, &v) <= r2
        } else if vw >= ww {
            let u = sub(&p, &b);
            dot(&u, &u) <= r2
        } else {
            dot(&v, &v) * &ww - &vw * &vw <= r2 * ww
        }
    }
    fn contains_point(&self, p: Vec3A) -> bool {
        Capsule::contains_point(self, p)
    }
    fn volume(&self) -> f32 {
        Capsule::volume(self)
    }
    fn aabb(&self) -> Aabb3 {
        Capsule::aabb(self)
    }
    fn aabb_holds_exactly(&self) -> bool {
        let (a, b) = (fixed3(self.a), fixed3(self.b));
        let lo = core::array::from_fn(|i| a[i].clone().min(b[i].clone()));
        let hi = core::array::from_fn(|i| a[i].clone().max(b[i].clone()));
        aabb_reaches(&self.aabb(), &lo, &hi, &fixed(self.radius))
    }
    fn shrunk(&self, s: f32) -> Self {
        Capsule {
            radius: self.radius * (1.0 - s),
            ..*self
        }
    }
}

/// Every mesh the containment tests run on, degenerate ones included.
fn all_meshes() -> Vec<(&'static str, Vec<Vec3>)> {
    let spot = meshes::spot();
    let mut twice = spot.clone();
    twice.extend(spot.iter().rev());
    let mut meshes = meshes::real();
    meshes.extend(meshes::procedural());
    meshes.extend([
        ("planar", meshes::planar(12)),
        (
            "planar tilted",
            meshes::rotated(&meshes::planar(12), meshes::tilt()),
        ),
        ("collinear", meshes::collinear(15)),
        (
            "collinear tilted",
            meshes::rotated(&meshes::collinear(15), meshes::tilt()),
        ),
        ("one point", vec![Vec3::new(1.5, -2.25, 1e-3)]),
        ("two points", vec![Vec3::ZERO, Vec3::new(1e-30, 3.0, -7.0)]),
        (
            "far away",
            meshes::rotated(&meshes::uv_sphere(1e-3, 5, 7), meshes::tilt())
                .iter()
                .map(|&p| p + Vec3::splat(1e4))
                .collect(),
        ),
        ("spot twice", twice),
    ]);
    meshes
}

/// Every point of every mesh lies in the fitted volume (exactly), `contains_point` agrees,
/// and the volume's AABB contains the exact volume.
fn check_containment<V: Volume>() {
    for (name, points) in all_meshes() {
        for mode in MODES {
            let fitted = V::fit(&points, mode).unwrap();
            for &p in &points {
                let p = Vec3A::from(p);
                assert!(
                    fitted.holds_exactly(p),
                    "{} {mode:?} {name}: {p} outside {fitted:?}",
                    V::NAME
                );
                assert!(
                    fitted.contains_point(p),
                    "{} {mode:?} {name}: contains_point({p})",
                    V::NAME
                );
            }
            assert!(
                fitted.aabb_holds_exactly(),
                "{} {mode:?} {name}: {:?}",
                V::NAME,
                fitted.aabb()
            );
            assert!(fitted.volume().is_finite());
        }
    }
}

#[test]
fn every_point_lies_in_every_box() {
    check_containment::<Obb3>();
}

#[test]
fn every_point_lies_in_every_sphere() {
    check_containment::<Sphere>();
}

#[test]
fn every_point_lies_in_every_capsule() {
    check_containment::<Capsule>();
}

/// The exact checks can fail: shrunk by one part in a million, each fitted volume loses a
/// vertex (all fits are tight to far better than that).
fn check_shrunk_fails<V: Volume>() {
    for (name, points) in meshes::real().into_iter().chain(meshes::procedural()) {
        for mode in MODES {
            let smaller = V::fit(&points, mode).unwrap().shrunk(1e-6);
            let lost = points.iter().any(|&p| !smaller.holds_exactly(p.into()));
            assert!(lost, "{} {mode:?} {name}: not tight", V::NAME);
        }
    }
}

#[test]
fn shrunk_volumes_lose_a_vertex() {
    check_shrunk_fails::<Obb3>();
    check_shrunk_fails::<Sphere>();
    check_shrunk_fails::<Capsule>();
}
