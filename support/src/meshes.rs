//! Test meshes: the real ones in `support/data` (read with a tiny OBJ `v`-line reader) and
//! procedural ones. Shared by `tests/fit.rs` and `examples/fit.rs`.
#![allow(dead_code)]

use glam::{Quat, Vec3};
use std::f32::consts::TAU;

/// The `v x y z` lines of an OBJ file (everything else is ignored).
pub fn obj_vertices(text: &str) -> Vec<Vec3> {
    text.lines()
        .filter_map(|line| line.strip_prefix("v "))
        .map(|rest| {
            let xyz: Vec<f32> = rest
                .split_whitespace()
                .take(3)
                .map(|x| x.parse().expect("an OBJ coordinate"))
                .collect();
            Vec3::new(xyz[0], xyz[1], xyz[2])
        })
        .collect()
}

/// Spot the cow (Keenan Crane, CC0): 2,930 vertices.
pub fn spot() -> Vec<Vec3> {
    obj_vertices(include_str!("../data/spot.obj"))
}

/// The Utah teapot: 3,644 vertices, 3,241 distinct.
pub fn teapot() -> Vec<Vec3> {
    obj_vertices(include_str!("../data/teapot.obj"))
}

/// A UV sphere of radius `r`: `rings − 1` latitude circles of `segments` points, and poles.
pub fn uv_sphere(r: f32, rings: usize, segments: usize) -> Vec<Vec3> {
    let mut points = vec![Vec3::Z * r, -Vec3::Z * r];
    for i in 1..rings {
        let polar = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let azimuth = TAU * j as f32 / segments as f32;
            let (s, c) = polar.sin_cos();
            points.push(Vec3::new(s * azimuth.cos(), s * azimuth.sin(), c) * r);
        }
    }
    points
}

/// A torus around `z`: major radius `big`, minor radius `small`.
pub fn torus(big: f32, small: f32, around: usize, across: usize) -> Vec<Vec3> {
    let mut points = Vec::new();
    for i in 0..around {
        let u = TAU * i as f32 / around as f32;
        for j in 0..across {
            let v = TAU * j as f32 / across as f32;
            let radial = big + small * v.cos();
            points.push(Vec3::new(
                radial * u.cos(),
                radial * u.sin(),
                small * v.sin(),
            ));
        }
    }
    points
}

/// The surface of the box `[−h, h]`, a grid of `n + 1` points per edge on each face.
pub fn box_surface(h: Vec3, n: usize) -> Vec<Vec3> {
    let t = |i: usize| 2.0 * i as f32 / n as f32 - 1.0;
    let mut points = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            for i in 0..=n {
                for j in 0..=n {
                    let mut p = [0.0; 3];
                    p[axis] = sign;
                    p[(axis + 1) % 3] = t(i);
                    p[(axis + 2) % 3] = t(j);
                    points.push(Vec3::from_array(p) * h);
                }
            }
        }
    }
    points
}

/// A closed cylinder along `z`: radius `r`, half-height `h`, rims and cap centers.
pub fn cylinder(r: f32, h: f32, segments: usize, rings: usize) -> Vec<Vec3> {
    let mut points = vec![Vec3::Z * h, -Vec3::Z * h];
    for i in 0..=rings {
        let z = h * (2.0 * i as f32 / rings as f32 - 1.0);
        for j in 0..segments {
            let a = TAU * j as f32 / segments as f32;
            points.push(Vec3::new(r * a.cos(), r * a.sin(), z));
        }
    }
    points
}

/// An exactly planar set: an irregular grid on `z = 0.25`.
pub fn planar(n: usize) -> Vec<Vec3> {
    (0..n * n)
        .map(|k| {
            let (i, j) = ((k / n) as f32, (k % n) as f32);
            Vec3::new(i + 0.37 * j, 0.5 * j - 0.1 * i * i / n as f32, 0.25)
        })
        .collect()
}

/// An exactly collinear set: multiples of `(1, 2, −3)` (exact in `f32`).
pub fn collinear(n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|i| Vec3::new(1.0, 2.0, -3.0) * (i as f32 - 7.0))
        .collect()
}

/// Every point turned by `q` (rounded to `f32`).
pub fn rotated(points: &[Vec3], q: Quat) -> Vec<Vec3> {
    points.iter().map(|&p| q * p).collect()
}

/// Every point scaled by `s` (rounded to `f32`).
pub fn scaled(points: &[Vec3], s: f32) -> Vec<Vec3> {
    points.iter().map(|&p| p * s).collect()
}

/// A fixed, generic rotation.
pub fn tilt() -> Quat {
    Quat::from_euler(glam::EulerRot::XYZ, 0.4, -0.7, 1.3)
}

/// The named procedural meshes, turned by [`tilt`] where noted.
pub fn procedural() -> Vec<(&'static str, Vec<Vec3>)> {
    vec![
        ("sphere", uv_sphere(1.0, 16, 24)),
        ("torus", rotated(&torus(1.0, 0.3, 32, 12), tilt())),
        (
            "box",
            rotated(&box_surface(Vec3::new(2.0, 1.0, 0.5), 6), tilt()),
        ),
        ("cylinder", rotated(&cylinder(0.5, 2.0, 24, 4), tilt())),
    ]
}

/// Spot and the teapot.
pub fn real() -> Vec<(&'static str, Vec<Vec3>)> {
    vec![("spot", spot()), ("teapot", teapot())]
}
