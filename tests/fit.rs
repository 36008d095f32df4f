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
//! - box, read as corners `c + R·u` with `|u_k| <= h_k`: by Cramer's rule
//!   `u_k = d·B_k / D` with `d = F(p) − F(c)`, `B_k = a_{k+1} × a_{k+2}`, `D = a_0·B_0`, so
//!   `|d·B_k|·2^149 <= F(h_k)·|D|` (and `D != 0`).
//!
//! Each check is shown to fail on a volume shrunk by one part in a million.
#![allow(clippy::needless_range_loop)]

use bvkit_support::meshes;
use bvkit_support::volumes;

use bvkit::{Aabb3, Capsule, Fit, FitError, Obb3, Sphere};
use glam::{Mat3A, Quat, Vec3, Vec3A};
use num_bigint::BigInt;
use num_traits::Signed;
use volumes::points::{self, cross, dot, fixed, fixed3};

const MODES: [Fit; 3] = [Fit::Pca, Fit::Fast, Fit::Tight];

/// A fitted volume and its containment statement, decided exactly.
trait Volume: Copy + std::fmt::Debug {
    const NAME: &'static str;
    fn fit(points: &[Vec3], fit: Fit) -> Result<Self, FitError>;
    fn holds_exactly(&self, p: Vec3A) -> bool;
    /// Every field is finite.
    fn is_finite(&self) -> bool;
    fn contains_point(&self, p: Vec3A) -> bool;
    fn volume(&self) -> f32;
    fn aabb(&self) -> Aabb3;
    /// True when the AABB contains every point of the volume, exactly.
    fn aabb_holds_exactly(&self) -> bool;
    /// The same volume shrunk by a factor `1 − s` about its center.
    fn shrunk(&self, s: f32) -> Self;
    /// The volume scaled by `s` about the origin.
    fn scaled(&self, s: f32) -> Self;
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
        points::in_box(self, p)
    }
    fn is_finite(&self) -> bool {
        self.center.is_finite() && self.half_extents.is_finite() && self.rotation.is_finite()
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
    fn scaled(&self, s: f32) -> Self {
        Obb3 {
            center: self.center * s,
            half_extents: self.half_extents * s,
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
        points::in_ball(self, p)
    }
    fn is_finite(&self) -> bool {
        self.center.is_finite() && self.radius.is_finite()
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
    fn scaled(&self, s: f32) -> Self {
        Sphere {
            center: self.center * s,
            radius: self.radius * s,
        }
    }
}

impl Volume for Capsule {
    const NAME: &'static str = "capsule";
    fn fit(points: &[Vec3], fit: Fit) -> Result<Self, FitError> {
        Capsule::fit(points, fit)
    }
    fn holds_exactly(&self, p: Vec3A) -> bool {
        points::in_capsule(self, p)
    }
    fn is_finite(&self) -> bool {
        self.a.is_finite() && self.b.is_finite() && self.radius.is_finite()
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
    fn scaled(&self, s: f32) -> Self {
        Capsule {
            a: self.a * s,
            b: self.b * s,
            radius: self.radius * s,
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

#[test]
fn bad_input_is_an_error() {
    let nan = vec![Vec3::ZERO, Vec3::ONE, Vec3::new(0.0, f32::NAN, 0.0)];
    let inf = vec![Vec3::ZERO, Vec3::new(f32::NEG_INFINITY, 0.0, 0.0)];
    for mode in MODES {
        assert_eq!(Obb3::fit(&[], mode), Err(FitError::Empty));
        assert_eq!(Sphere::fit(&[], mode), Err(FitError::Empty));
        assert_eq!(Capsule::fit(&[], mode), Err(FitError::Empty));
        assert!(matches!(
            Obb3::fit(&nan, mode),
            Err(FitError::NonFinite { index: 2, .. })
        ));
        assert!(matches!(
            Sphere::fit(&inf, mode),
            Err(FitError::NonFinite { index: 1, .. })
        ));
        assert!(matches!(
            Capsule::fit(&inf, mode),
            Err(FitError::NonFinite { index: 1, .. })
        ));
    }
    let error: Box<dyn std::error::Error> = Box::new(Obb3::fit(&nan, Fit::Fast).unwrap_err());
    assert!(error.to_string().contains("point 2 is not finite"));
    assert!(FitError::Empty.to_string().contains("no points"));
    assert_eq!(Fit::default(), Fit::Fast);
}

#[test]
fn degenerate_sets_give_flat_volumes() {
    let p = Vec3::new(1.5, -2.25, 1e-3);
    for mode in MODES {
        let s = Sphere::fit(&[p, p, p], mode).unwrap();
        assert_eq!((s.center, s.radius), (Vec3A::from(p), 0.0), "{mode:?}");
        let c = Capsule::fit(&[p], mode).unwrap();
        assert_eq!((c.a, c.b, c.radius), (p.into(), p.into(), 0.0), "{mode:?}");
        let b = Obb3::fit(&[p], mode).unwrap();
        assert!(b.half_extents.max_element() <= 1e-12, "{mode:?} {b:?}");

        // Collinear: the box and the capsule are thin needles along the line.
        let line = meshes::rotated(&meshes::collinear(15), meshes::tilt());
        let b = Obb3::fit(&line, mode).unwrap();
        let mut h = b.half_extents.to_array();
        h.sort_by(f32::total_cmp);
        assert!(h[1] <= 1e-5 * h[2], "{mode:?} {b:?}");
        let c = Capsule::fit(&line, mode).unwrap();
        assert!(c.radius <= 1e-5 * c.a.distance(c.b), "{mode:?} {c:?}");
    }
    // Exactly planar: the tight box is the plane's minimum-area rectangle, of no thickness.
    let plane = meshes::planar(12);
    let tight = Obb3::fit(&plane, Fit::Tight).unwrap();
    assert!(tight.half_extents.min_element() <= 1e-12, "{tight:?}");
    let area = |b: &Obb3| {
        let mut h = b.half_extents.to_array();
        h.sort_by(f32::total_cmp);
        4.0 * h[1] * h[2]
    };
    let swept = (0..3600)
        .map(|i| {
            let r = Mat3A::from_rotation_z(i as f32 * std::f32::consts::FRAC_PI_2 / 3600.0);
            area(&Obb3::from_axes(&plane, r).unwrap())
        })
        .fold(f32::INFINITY, f32::min);
    assert!(
        area(&tight) <= swept * (1.0 + 1e-5),
        "{} vs swept {swept}",
        area(&tight)
    );
    assert!(area(&tight) >= swept * (1.0 - 1e-3));
}

#[test]
fn duplicates_change_nothing_for_the_distinct_fits() {
    let spot = meshes::spot();
    let mut twice = spot.clone();
    twice.extend(spot.iter().rev());
    assert_eq!(Obb3::fit(&spot, Fit::Pca), Obb3::fit(&twice, Fit::Pca));
    assert_eq!(Sphere::fit(&spot, Fit::Pca), Sphere::fit(&twice, Fit::Pca));
    assert_eq!(
        Sphere::fit(&spot, Fit::Tight),
        Sphere::fit(&twice, Fit::Tight)
    );
    assert_eq!(
        Capsule::fit(&spot, Fit::Pca),
        Capsule::fit(&twice, Fit::Pca)
    );
}

/// The fast box is never worse than the AABB nor the PCA axes with a midrange center; the
/// tight box never worse than the fast one; the tight capsule never worse than the others.
///
/// The fast fit takes the PCA axes of the points as given, the baseline those of the
/// distinct points: on a mesh with duplicates they differ in the last bits, and so do the
/// widenings for the corner reading (about `u` of the largest half-extent), hence `1e-6`.
#[test]
fn each_mode_is_at_least_as_good_as_its_baselines() {
    for (name, points) in meshes::real().into_iter().chain(meshes::procedural()) {
        let pca = Obb3::fit(&points, Fit::Pca).unwrap();
        let fast = Obb3::fit(&points, Fit::Fast).unwrap().volume();
        let aabb = Obb3::from_axes(&points, Mat3A::IDENTITY).unwrap().volume();
        let midrange = Obb3::from_axes(&points, pca.rotation).unwrap().volume();
        assert!(
            fast <= aabb && fast <= midrange * (1.0 + 1e-6),
            "{name}: {fast} vs {aabb}, {midrange}"
        );
        assert!(midrange <= pca.volume(), "{name}");
        let tight = Obb3::fit(&points, Fit::Tight).unwrap().volume();
        assert!(tight <= fast, "{name}: {tight} > {fast}");
        let capsule = |mode| Capsule::fit(&points, mode).unwrap().volume();
        let tight_capsule = capsule(Fit::Tight);
        assert!(tight_capsule <= capsule(Fit::Fast) * (1.0 + 1e-6), "{name}");
        assert!(tight_capsule <= capsule(Fit::Pca) * (1.0 + 1e-6), "{name}");
        let sphere = |mode| Sphere::fit(&points, mode).unwrap().radius;
        assert!(
            sphere(Fit::Tight) <= sphere(Fit::Fast) * (1.0 + 1e-6),
            "{name}"
        );
        assert!(
            sphere(Fit::Fast) <= sphere(Fit::Tight) * 1.05f32.cbrt(),
            "{name}"
        );
        assert!(
            sphere(Fit::Tight) <= sphere(Fit::Pca) * (1.0 + 1e-6),
            "{name}"
        );
    }
}

/// Shapes whose smallest volumes are known.
#[test]
fn known_answers() {
    // A turned box surface: the tight box is the box, 4 × 2 × 1.
    let q = meshes::tilt();
    let turned = meshes::rotated(&meshes::box_surface(Vec3::new(2.0, 1.0, 0.5), 6), q);
    let tight = Obb3::fit(&turned, Fit::Tight).unwrap();
    assert!((tight.volume() / 8.0 - 1.0).abs() <= 1e-5, "{tight:?}");
    // Cube corners ±1, turned: the smallest ball has radius √3.
    let corners: Vec<Vec3> = (0..8)
        .map(|k| {
            q * Vec3::new(
                [-1.0, 1.0][k & 1],
                [-1.0, 1.0][k >> 1 & 1],
                [-1.0, 1.0][k >> 2 & 1],
            )
        })
        .collect();
    let ball = Sphere::fit(&corners, Fit::Tight).unwrap();
    assert!((ball.radius / 3f32.sqrt() - 1.0).abs() <= 1e-6, "{ball:?}");
    // A UV sphere: its own radius, for the exact and the fast fits.
    for mode in [Fit::Fast, Fit::Tight] {
        let r = Sphere::fit(&meshes::uv_sphere(2.0, 16, 24), mode)
            .unwrap()
            .radius;
        assert!((r / 2.0 - 1.0).abs() <= 1e-6, "{mode:?} {r}");
    }
    // A capsule-shaped cloud (a cylinder of radius 0.5 and half-height 2 with hemispheres):
    // the tight capsule is that capsule.
    let mut pill = meshes::cylinder(0.5, 2.0, 24, 4);
    for p in meshes::uv_sphere(0.5, 12, 24) {
        pill.push(p + Vec3::Z * 2.0f32.copysign(p.z));
    }
    let pill = meshes::rotated(&pill, q);
    let c = Capsule::fit(&pill, Fit::Tight).unwrap();
    let exact = std::f32::consts::PI * 0.25 * (4.0 + 4.0 / 3.0 * 0.5);
    assert!(
        (c.volume() / exact - 1.0).abs() <= 1e-3,
        "{c:?}: {} vs {exact}",
        c.volume()
    );
}

/// Every fit of the points scaled by 1024 is the fit scaled by 1024, bit for bit.
fn check_power_of_two_scaling<V: Volume + PartialEq>(points: &[Vec3]) {
    let scaled = meshes::scaled(points, 1024.0);
    for mode in MODES {
        let (fit, fit_scaled) = (
            V::fit(points, mode).unwrap(),
            V::fit(&scaled, mode).unwrap(),
        );
        assert_eq!(fit.scaled(1024.0), fit_scaled, "{} {mode:?}", V::NAME);
    }
}

/// Scaling by a power of two scales every fit exactly; other scales and turns change the
/// volumes of the fits that do not depend on the coordinate axes by at most 1e-5 (the
/// input's own rounding to `f32`).
#[test]
fn invariant_under_scale_and_rotation() {
    let spot = meshes::spot();
    check_power_of_two_scaling::<Obb3>(&spot);
    check_power_of_two_scaling::<Sphere>(&spot);
    check_power_of_two_scaling::<Capsule>(&spot);
    let relative = |a: f32, b: f32| (a / b - 1.0).abs();
    for scale in [1e-4f32, 0.37, 1e4] {
        let s = meshes::scaled(&spot, scale);
        let cube = scale.powi(3);
        for mode in [Fit::Pca, Fit::Tight] {
            let obb = Obb3::fit(&s, mode).unwrap().volume() / cube;
            assert!(
                relative(obb, Obb3::fit(&spot, mode).unwrap().volume()) <= 1e-5,
                "{mode:?} {scale}"
            );
        }
        let r = Sphere::fit(&s, Fit::Tight).unwrap().radius / scale;
        assert!(
            relative(r, Sphere::fit(&spot, Fit::Tight).unwrap().radius) <= 1e-5,
            "{scale}"
        );
    }
    for q in [
        meshes::tilt(),
        Quat::from_rotation_y(2.0),
        Quat::from_rotation_x(-0.9),
    ] {
        let turned = meshes::rotated(&spot, q);
        for mode in [Fit::Pca, Fit::Tight] {
            let v = Obb3::fit(&turned, mode).unwrap().volume();
            assert!(
                relative(v, Obb3::fit(&spot, mode).unwrap().volume()) <= 1e-5,
                "{mode:?} {q}"
            );
        }
        let r = Sphere::fit(&turned, Fit::Tight).unwrap().radius;
        assert!(
            relative(r, Sphere::fit(&spot, Fit::Tight).unwrap().radius) <= 1e-5,
            "{q}"
        );
    }
}

/// Hand-made boxes: a rotation off orthonormal, far from the origin; its AABB still
/// contains the exact parallelepiped, and a singular rotation gives the whole space.
#[test]
fn aabb_of_any_box_contains_it() {
    let skewed = Obb3 {
        center: Vec3A::new(1e4, -3.0, 0.5),
        half_extents: Vec3A::new(1.0, 2.0, 1e-3),
        rotation: Mat3A::from_cols(
            Vec3A::new(1.0, 0.001, 0.0),
            Vec3A::new(0.0, 0.999, 0.002),
            Vec3A::new(0.01, 0.0, 1.0),
        ),
    };
    assert!(skewed.aabb_holds_exactly());
    let flat = Obb3 {
        rotation: Mat3A::from_cols(Vec3A::X, Vec3A::X, Vec3A::Z),
        ..skewed
    };
    assert_eq!(
        flat.aabb(),
        Aabb3::new(Vec3A::NEG_INFINITY, Vec3A::INFINITY)
    );
    assert!(
        !Obb3 {
            center: Vec3A::NAN,
            ..skewed
        }
        .aabb()
        .is_valid()
    );
    assert!(!skewed.contains_point(Vec3A::NAN));
}

/// A fit's result: finite fields and every point in, exactly (for a box, under both
/// readings); or, where `overflow_allowed`, [`FitError::Overflow`]. True for a volume.
fn fits_or_overflows<V: Volume>(points: &[Vec3], fitted: Result<V, FitError>, what: &str) -> bool {
    let v = match fitted {
        Ok(v) => v,
        Err(FitError::Overflow) => return false,
        Err(e) => panic!("{} {what}: {e}", V::NAME),
    };
    assert!(v.is_finite(), "{} {what}: {v:?}", V::NAME);
    for &p in points {
        assert!(
            v.holds_exactly(p.into()),
            "{} {what}: {p} outside {v:?}",
            V::NAME
        );
        assert!(
            v.contains_point(p.into()),
            "{} {what}: contains_point({p})",
            V::NAME
        );
    }
    true
}

/// Both readings of every fitted box, on `points`; the slab reading is `holds_exactly`.
fn check_corners(points: &[Vec3], obb: &Obb3, what: &str) {
    for &p in points {
        assert!(
            points::in_box_as_corners(obb, p.into()),
            "{what}: {p} outside the corners of {obb:?}"
        );
    }
}

/// Issue 20, defect 5: flat sets that are not collinear, exactly, but whose `f64`
/// differences round to parallel vectors gave the tight box a NaN frame, kept as the
/// smallest; every fit now contains every point.
#[test]
fn flat_sets_with_parallel_rounded_differences_fit_every_point() {
    let base = [
        Vec3::new(1e-30, 2e-30, 0.0),
        Vec3::new(1e30, 1e30, 0.0),
        Vec3::new(-1e30, -1e30, 0.0),
    ];
    let turn = |p: Vec3, k: usize| Vec3::from_array(core::array::from_fn(|i| p[(i + k) % 3]));
    for k in 0..3 {
        let mut points: Vec<Vec3> = base.iter().map(|&p| turn(p, k)).collect();
        for extra in [None, Some(Vec3::new(1e-30, 3e-30, 0.0))] {
            points.extend(extra.map(|p| turn(p, k)));
            for mode in MODES {
                let what = format!("{mode:?} {points:?}");
                let obb = Obb3::fit(&points, mode);
                assert!(fits_or_overflows(&points, obb, &what), "{what}");
                check_corners(&points, &obb.unwrap(), &what);
                assert!(fits_or_overflows(
                    &points,
                    Sphere::fit(&points, mode),
                    &what
                ));
                assert!(fits_or_overflows(
                    &points,
                    Capsule::fit(&points, mode),
                    &what
                ));
            }
        }
    }
}

/// Issue 20, defect 6: near `±f32::MAX` a rotated frame put the box's center beyond the
/// range (an infinite center, NaN half-extents), and a radius fold dropped the NaN of an
/// overflowed capsule end. Every fit now gives finite fields holding every point, or
/// [`FitError::Overflow`]; spreads within half the range always fit.
#[test]
fn points_near_the_range_limit_fit_or_overflow() {
    let m = f32::MAX;
    let moderate = [
        vec![
            Vec3::new(m, m, 0.0),
            Vec3::new(m * 0.5, m, m * 0.75),
            Vec3::new(m, m * 0.5, m),
        ],
        vec![
            Vec3::new(m, m * 0.6, m * 0.9),
            Vec3::new(m * 0.55, m * 0.99, m * 0.7),
        ],
        vec![
            Vec3::new(-m, -m, -m),
            Vec3::new(-m * 0.5, -m, -m * 0.6),
            Vec3::new(-m, -m * 0.7, -m * 0.5),
            Vec3::new(-m * 0.8, -m * 0.8, -m),
        ],
    ];
    let wide = [
        vec![Vec3::splat(-m), Vec3::splat(m)],
        vec![
            Vec3::new(m, -m, 0.0),
            Vec3::new(-m, m, 0.0),
            Vec3::new(m, m, m),
        ],
    ];
    let (mut fitted, mut refused) = (0, 0);
    for (set, points) in moderate.iter().chain(&wide).enumerate() {
        let must_fit = set < moderate.len();
        let mut tally = |ok: bool, what: &str| {
            assert!(ok || !must_fit, "{what}: refused");
            if ok { fitted += 1 } else { refused += 1 }
        };
        for mode in MODES {
            let what = format!("{mode:?} {points:?}");
            let obb = Obb3::fit(points, mode);
            let ok = fits_or_overflows(points, obb, &what);
            if ok {
                check_corners(points, &obb.unwrap(), &what);
            }
            tally(ok, &what);
            tally(
                fits_or_overflows(points, Sphere::fit(points, mode), &what),
                &what,
            );
            tally(
                fits_or_overflows(points, Capsule::fit(points, mode), &what),
                &what,
            );
        }
        for i in 0..24 {
            let r = Mat3A::from_quat(Quat::from_euler(
                glam::EulerRot::XYZ,
                0.1 * i as f32,
                0.37 * i as f32,
                0.05,
            ));
            let what = format!("from_axes {r:?} {points:?}");
            let obb = Obb3::from_axes(points, r);
            let ok = fits_or_overflows(points, obb, &what);
            if ok {
                check_corners(points, &obb.unwrap(), &what);
            }
            tally(ok, &what);
        }
    }
    assert!(
        fitted > 0 && refused > 0,
        "{fitted} fitted, {refused} refused"
    );
}

/// Issue 20, defect 6: `from_axes` refuses a rotation that is not orthonormal (NaN,
/// infinite, singular, skewed or scaled beyond `2^-10`), and accepts a drifted one.
#[test]
fn from_axes_refuses_a_rotation_that_is_not_orthonormal() {
    let points = meshes::spot();
    let turn = Mat3A::from_quat(meshes::tilt());
    let refused = [
        Mat3A::NAN,
        Mat3A::from_cols(Vec3A::X, Vec3A::new(0.0, f32::INFINITY, 0.0), Vec3A::Z),
        Mat3A::ZERO,
        Mat3A::from_cols(Vec3A::X, Vec3A::X, Vec3A::Z),
        turn * 1.001,
        Mat3A::from_cols(turn.x_axis, turn.y_axis + turn.x_axis * 0.002, turn.z_axis),
    ];
    for r in refused {
        assert!(
            matches!(
                Obb3::from_axes(&points, r),
                Err(FitError::NotOrthonormal { .. })
            ),
            "{r:?}"
        );
    }
    let error = Obb3::from_axes(&points, Mat3A::ZERO).unwrap_err();
    assert!(error.to_string().contains("not orthonormal"), "{error}");
    assert!(FitError::Overflow.to_string().contains("overflows"));
    for r in [
        turn * 1.0004,
        Mat3A::from_cols(turn.x_axis, turn.y_axis + turn.x_axis * 2e-4, turn.z_axis),
    ] {
        let obb = Obb3::from_axes(&points, r).unwrap();
        assert!(fits_or_overflows(&points, Ok(obb), "drifted"));
    }
}

/// Issue 20, defect 7: every fitted box holds every point read as `c + R·u`, `|u_k| <= h_k`
/// (the box with corners `c ± R·h`), exactly, on every mesh and mode, and for adversarial
/// rotations given to `from_axes` (drifted up to the `2^-10` limit, a reflection); and a
/// box shrunk by one part in a million loses a point under that reading too.
#[test]
fn every_point_lies_in_every_box_as_corners() {
    for (name, points) in all_meshes() {
        for mode in MODES {
            let obb = Obb3::fit(&points, mode).unwrap();
            check_corners(&points, &obb, &format!("{mode:?} {name}"));
        }
    }
    let turn = Mat3A::from_quat(meshes::tilt());
    let frames = [
        turn * (1.0 + 2e-4),
        turn * (1.0 - 3e-4),
        Mat3A::from_cols(
            turn.x_axis,
            turn.y_axis + turn.x_axis * 3e-4,
            turn.z_axis - turn.y_axis * 1e-4,
        ),
        Mat3A::from_cols(-turn.x_axis, turn.y_axis, turn.z_axis * (1.0 + 1e-4)),
        Mat3A::from_cols(Vec3A::X, Vec3A::new(1e-4, 1.0, 0.0), Vec3A::Z),
    ];
    for (name, points) in meshes::real().into_iter().chain(meshes::procedural()) {
        for r in frames {
            let what = format!("{name} {r:?}");
            let obb = Obb3::from_axes(&points, r).unwrap();
            assert!(fits_or_overflows(&points, Ok(obb), &what));
            check_corners(&points, &obb, &what);
        }
    }
    // Fitted boxes stay tight under the corner reading: the widening is about `u`.
    for (name, points) in meshes::real().into_iter().chain(meshes::procedural()) {
        for mode in MODES {
            let smaller = Obb3::fit(&points, mode).unwrap().shrunk(1e-6);
            assert!(
                points
                    .iter()
                    .any(|&p| !points::in_box_as_corners(&smaller, p.into())),
                "{mode:?} {name}: not tight"
            );
        }
    }
}
