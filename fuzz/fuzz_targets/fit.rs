//! The fits against their contract, decided exactly: `Obb3`, `Sphere` and `Capsule::fit` in
//! every mode and `Obb3::from_axes` on up to 8 points from the fuzzer give a volume with
//! finite fields that holds every point (a box under both readings, slabs and `c + R·u`),
//! or the documented error: `Empty`, the first `NonFinite` point, `NotOrthonormal` only
//! for a rotation that is (exactly) not finite or off by more than `2^-10`, `Overflow`
//! only for points spread over at least half the `f32` range. `contains_point` accepts
//! every fitted point, accepts every point of an arbitrary volume, and refuses NaN.
#![no_main]

use bvkit::{Capsule, Fit, FitError, Obb3, Sphere};
use bvkit_fuzz::Floats;
use bvkit_fuzz::volumes::points::{defect_exceeds, in_ball, in_box, in_box_as_corners, in_capsule};
use glam::{Vec3, Vec3A};
use libfuzzer_sys::fuzz_target;

const MODES: [Fit; 3] = [Fit::Pca, Fit::Fast, Fit::Tight];

/// The checks of one volume type: its exact statement, finiteness and `contains_point`.
trait Volume: Copy + core::fmt::Debug {
    fn holds(&self, p: Vec3A) -> bool;
    fn is_finite(&self) -> bool;
    fn contains_point(&self, p: Vec3A) -> bool;
}

impl Volume for Obb3 {
    fn holds(&self, p: Vec3A) -> bool {
        in_box(self, p) && in_box_as_corners(self, p)
    }
    fn is_finite(&self) -> bool {
        self.center.is_finite() && self.half_extents.is_finite() && self.rotation.is_finite()
    }
    fn contains_point(&self, p: Vec3A) -> bool {
        Obb3::contains_point(self, p)
    }
}

impl Volume for Sphere {
    fn holds(&self, p: Vec3A) -> bool {
        in_ball(self, p)
    }
    fn is_finite(&self) -> bool {
        self.center.is_finite() && self.radius.is_finite()
    }
    fn contains_point(&self, p: Vec3A) -> bool {
        Sphere::contains_point(self, p)
    }
}

impl Volume for Capsule {
    fn holds(&self, p: Vec3A) -> bool {
        in_capsule(self, p)
    }
    fn is_finite(&self) -> bool {
        self.a.is_finite() && self.b.is_finite() && self.radius.is_finite()
    }
    fn contains_point(&self, p: Vec3A) -> bool {
        Capsule::contains_point(self, p)
    }
}

/// The largest extent `max − min` of the points over the axes, in `f64`.
fn spread(points: &[Vec3]) -> f64 {
    (0..3)
        .map(|i| {
            let (lo, hi) = points
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                    (l.min(f64::from(p[i])), h.max(f64::from(p[i])))
                });
            hi - lo
        })
        .fold(0.0, f64::max)
}

/// The contract of one fit's result; `Err(NotOrthonormal)` is checked by the caller.
fn check<V: Volume>(points: &[Vec3], result: Result<V, FitError>, what: &str) {
    let first_bad = points.iter().position(|p| !p.is_finite());
    match (result, first_bad) {
        (Err(FitError::Empty), _) => assert!(points.is_empty(), "{what}"),
        (Err(FitError::NonFinite { index, point }), Some(i)) => {
            assert_eq!(index, i, "{what}");
            assert_eq!(
                point.map(f32::to_bits),
                points[i].to_array().map(f32::to_bits)
            );
        }
        (Err(FitError::Overflow), None) => {
            assert!(
                spread(points) >= f64::from(f32::MAX) / 2.0,
                "{what}: overflow {points:?}"
            )
        }
        (Err(FitError::NotOrthonormal { .. }), None) => {}
        (Ok(v), None) if !points.is_empty() => {
            assert!(v.is_finite(), "{what}: {v:?} for {points:?}");
            for &p in points {
                let p = Vec3A::from(p);
                assert!(v.holds(p), "{what}: {p} outside {v:?}, points {points:?}");
                assert!(v.contains_point(p), "{what}: contains_point({p}) of {v:?}");
            }
        }
        (r, _) => panic!("{what}: {r:?} for {points:?}"),
    }
}

/// `contains_point` on an arbitrary volume: never false for an exact point of it, and false
/// for NaN.
fn probe<V: Volume>(v: V, p: Vec3A) {
    if v.is_finite() && p.is_finite() && v.holds(p) {
        assert!(v.contains_point(p), "{v:?} {p}");
    }
    assert!(!v.contains_point(Vec3A::new(p.x, f32::NAN, p.z)), "{v:?}");
}

fuzz_target!(|data: &[u8]| {
    let mut f = Floats::new(data);
    let choice = f.byte();
    let n = (f.byte() % 9) as usize;
    let points: Vec<Vec3> = (0..n).map(|_| Vec3::from_array(f.array())).collect();
    let mode = MODES[usize::from(choice % 3)];
    let what = format!("{mode:?}");
    match choice / 3 % 4 {
        0 => check(&points, Obb3::fit(&points, mode), &format!("box {what}")),
        1 => check(
            &points,
            Sphere::fit(&points, mode),
            &format!("sphere {what}"),
        ),
        2 => check(
            &points,
            Capsule::fit(&points, mode),
            &format!("capsule {what}"),
        ),
        _ => {
            let rotation = f.rotation();
            let result = Obb3::from_axes(&points, rotation);
            if let Err(FitError::NotOrthonormal { defect }) = result {
                let valid = !points.is_empty() && points.iter().all(|p| p.is_finite());
                assert!(valid, "{points:?}");
                // Refused: not finite, or off by more than 2^-10 (its bound rounds up to f32).
                let refused = !rotation.is_finite()
                    || defect_exceeds(rotation, (1.0 - 1.0 / (1u32 << 22) as f32) / 1024.0);
                assert!(refused, "{rotation:?} refused with defect {defect}");
            } else {
                check(&points, result, &format!("from_axes {rotation:?}"));
                // Accepted: off by at most 2^-10, exactly (the bound is never below).
                if result.is_ok() {
                    assert!(!defect_exceeds(rotation, 1.0 / 1024.0), "{rotation:?}");
                }
            }
        }
    }
    let p = f.vec3a();
    match f.byte() % 3 {
        0 => probe(f.obb(), p),
        1 => probe(f.sphere(), p),
        _ => probe(f.capsule(), p),
    }
});
