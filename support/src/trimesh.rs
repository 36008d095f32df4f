//! Triangle meshes for the tree tests, benches and example: a triangulated torus, and the
//! faces of an OBJ file (spot). Shared by `tests/trees.rs`, `benches/trees.rs` and
//! `examples/trees.rs`.
#![allow(dead_code)]

use glam::Vec3;
use std::f32::consts::TAU;

/// A torus around `z` (major radius `big`, minor `small`), `2·around·across` triangles.
pub fn torus(big: f32, small: f32, around: usize, across: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut vertices = Vec::with_capacity(around * across);
    for i in 0..around {
        let u = TAU * i as f32 / around as f32;
        for j in 0..across {
            let v = TAU * j as f32 / across as f32;
            let radial = big + small * v.cos();
            vertices.push(Vec3::new(
                radial * u.cos(),
                radial * u.sin(),
                small * v.sin(),
            ));
        }
    }
    let id = |i: usize, j: usize| ((i % around) * across + (j % across)) as u32;
    let mut triangles = Vec::with_capacity(2 * around * across);
    for i in 0..around {
        for j in 0..across {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    (vertices, triangles)
}

/// The vertices and triangles of an OBJ text (`v` and `f` lines; polygons are fanned,
/// `v/vt/vn` references keep the vertex index).
pub fn obj(text: &str) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix("v ") {
            let xyz: Vec<f32> = rest
                .split_whitespace()
                .take(3)
                .map(|x| x.parse().expect("an OBJ coordinate"))
                .collect();
            vertices.push(Vec3::new(xyz[0], xyz[1], xyz[2]));
        } else if let Some(rest) = line.strip_prefix("f ") {
            let ids: Vec<u32> = rest
                .split_whitespace()
                .map(|r| {
                    r.split('/')
                        .next()
                        .unwrap()
                        .parse::<u32>()
                        .expect("an OBJ index")
                        - 1
                })
                .collect();
            for k in 1..ids.len().saturating_sub(1) {
                triangles.push([ids[0], ids[k], ids[k + 1]]);
            }
        }
    }
    (vertices, triangles)
}

/// Spot the cow (Keenan Crane, CC0): 2,930 vertices, 5,856 triangles.
pub fn spot() -> (Vec<Vec3>, Vec<[u32; 3]>) {
    obj(include_str!("../data/spot.obj"))
}

/// A fixed-seed generator (xorshift64*), uniform in `[0, 1)`.
pub struct Uniform(pub u64);

impl Uniform {
    pub fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f32 {
        (lo + (hi - lo) * self.next()) as f32
    }
    /// A uniformly random unit quaternion (normalised in f32).
    pub fn rotation(&mut self) -> glam::Quat {
        let (u1, u2, u3) = (
            self.next(),
            self.next() * std::f64::consts::TAU,
            self.next() * std::f64::consts::TAU,
        );
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        glam::Quat::from_xyzw(
            (a * u2.sin()) as f32,
            (a * u2.cos()) as f32,
            (b * u3.sin()) as f32,
            (b * u3.cos()) as f32,
        )
        .normalize()
    }
}

/// `n` seeded poses: random rotations, translations uniform in `[-spread, spread]^3`.
pub fn poses(n: usize, spread: f64, seed: u64) -> Vec<bvkit::Rigid3> {
    let mut g = Uniform(seed);
    (0..n)
        .map(|_| {
            let q = g.rotation();
            let t = glam::Vec3A::new(
                g.range(-spread, spread),
                g.range(-spread, spread),
                g.range(-spread, spread),
            );
            bvkit::Rigid3::new(q, t)
        })
        .collect()
}
