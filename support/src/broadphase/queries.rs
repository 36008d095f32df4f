//! Ray casts and box queries on the trees the broadphase pipelines keep after a run: bvkit's
//! `DynamicTree` (C's), parry3d's `Bvh` over the same fat boxes (B's, kept as rapier keeps
//! its tree: leaves rewritten, optimised and refitted every frame), and obvhs's `Bvh2`
//! (D's, kept as avian keeps its trees) together with the `CwBvh` obvhs builds from it for
//! rays (its compressed wide BVH, converted once after the run). Every leaf test is the
//! box's alone: the closest hit is the least entry of a fat box along the ray.

use bvkit::Aabb3;
use bvkit::broadphase::{CastControl, DynamicTree, Layers, Ray};
use glam::Vec3A;
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::partitioning::Bvh;
use parry3d::query::RayCast;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

use ::obvhs::bvh2::Bvh2;
use ::obvhs::cwbvh::CwBvh;
use ::obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
use ::obvhs::ray::{Ray as ObvhsRay, RayHit};

use super::bvh::{Pipelines, Tuning, Which};
use super::parry_box;
use super::scene::Scene;

/// The three trees over one set of fat boxes.
pub struct Trees {
    pub bvkit: DynamicTree,
    pub parry: Bvh,
    pub obvhs: Bvh2,
    pub cwbvh: CwBvh,
    /// The fat boxes by proxy, in both forms.
    pub fat: Vec<Aabb3>,
    parry_fat: Vec<Aabb>,
    obvhs_fat: Vec<::obvhs::aabb::Aabb>,
    /// The half width of the scene's cube.
    pub half: f32,
    /// The milliseconds of the `CwBvh` conversion.
    pub cwbvh_ms: f64,
}

impl Trees {
    /// The trees after `frames` frames of `scene`.
    pub fn after(scene: Scene, frames: usize) -> Self {
        let mut scene = scene;
        let n = scene.local.len();
        let which = Which {
            models: true,
            obvhs: true,
            rapier: false,
        };
        let mut pipelines = Pipelines::new(&scene, Tuning::default(), which);
        for _ in 0..frames {
            scene.step();
            pipelines.frame(&scene);
        }
        let (bvkit, parry, obvhs, fat) = pipelines.trees(n);
        let start = std::time::Instant::now();
        let cwbvh = bvh2_to_cwbvh(obvhs, 3, true, false);
        let cwbvh_ms = start.elapsed().as_secs_f64() * 1e3;
        Self {
            bvkit: bvkit.clone(),
            parry: parry.clone(),
            obvhs: obvhs.clone(),
            cwbvh,
            parry_fat: fat.iter().map(parry_box).collect(),
            obvhs_fat: fat
                .iter()
                .map(|b| ::obvhs::aabb::Aabb::new(b.min.to_array().into(), b.max.to_array().into()))
                .collect(),
            fat,
            half: 500.0 * (n as f32 / 1e6).cbrt(),
            cwbvh_ms,
        }
    }

    /// `count` rays from random points in the scene's cube, in random unit directions, of
    /// length `length`.
    pub fn rays(&self, count: usize, length: f32, seed: u64) -> Vec<Ray> {
        let mut r = StdRng::seed_from_u64(seed);
        let h = self.half;
        (0..count)
            .map(|_| {
                let o = Vec3A::new(
                    r.random_range(-h..h),
                    r.random_range(-h..h),
                    r.random_range(-h..h),
                );
                let d = loop {
                    let d = Vec3A::new(r.random(), r.random(), r.random()) * 2.0 - 1.0;
                    if (0.01..=1.0).contains(&d.length_squared()) {
                        break d.normalize();
                    }
                };
                Ray::new(o, d, length)
            })
            .collect()
    }

    /// `count` cubes of side `side` at random in the scene's cube.
    pub fn boxes(&self, count: usize, side: f32, seed: u64) -> Vec<Aabb3> {
        let mut r = StdRng::seed_from_u64(seed);
        let h = self.half;
        (0..count)
            .map(|_| {
                let c = Vec3A::new(
                    r.random_range(-h..h),
                    r.random_range(-h..h),
                    r.random_range(-h..h),
                );
                Aabb3::new(c - side / 2.0, c + side / 2.0)
            })
            .collect()
    }

    /// bvkit: the least entry, clipping at each hit.
    #[inline]
    pub fn closest_bvkit(&self, ray: &Ray) -> Option<(u32, f32)> {
        let mut best = None;
        self.bvkit
            .cast_ray(ray, Layers::ALL, |id, t| {
                if best.is_none_or(|(_, b)| t < b) {
                    best = Some((id, t));
                }
                CastControl::Clip(t)
            })
            .expect("a valid ray");
        best
    }

    /// parry3d: `Bvh::cast_ray` with each leaf's box cast as the primitive.
    #[inline]
    pub fn closest_parry(&self, ray: &Ray) -> Option<(u32, f32)> {
        let r = parry3d::query::Ray::new(ray.origin.into(), ray.direction.into());
        self.parry.cast_ray(&r, ray.max, |id, best| {
            self.parry_fat[id as usize].cast_local_ray(&r, best, true)
        })
    }

    /// obvhs: `CwBvh::ray_traverse`, each leaf's box cast as the primitive.
    #[inline]
    pub fn closest_obvhs(&self, ray: &Ray) -> Option<(u32, f32)> {
        let r = ObvhsRay::new(
            ray.origin.to_array().into(),
            ray.direction.to_array().into(),
            0.0,
            ray.max,
        );
        let mut hit = RayHit::none();
        let prims = &self.cwbvh.primitive_indices;
        let fat = &self.obvhs_fat;
        self.cwbvh
            .ray_traverse(r, &mut hit, |r, k| fat[prims[k] as usize].intersect_ray(r))
            .then(|| (prims[hit.primitive_id as usize], hit.t))
    }

    /// bvkit: the proxies whose boxes overlap `b`.
    #[inline]
    pub fn query_bvkit(&self, b: &Aabb3) -> usize {
        let mut n = 0;
        self.bvkit
            .query(b, Layers::ALL, |_| n += 1)
            .expect("a valid box");
        n
    }

    /// parry3d: `Bvh::intersect_aabb` (its leaves are the boxes).
    #[inline]
    pub fn query_parry(&self, b: &Aabb3) -> usize {
        let q = parry_box(b);
        self.parry
            .intersect_aabb(&q)
            .filter(|&id| self.parry_fat[id as usize].intersects(&q))
            .count()
    }

    /// obvhs: `Bvh2::aabb_traverse`, each leaf's boxes tested.
    #[inline]
    pub fn query_obvhs(&self, b: &Aabb3) -> usize {
        let q = ::obvhs::aabb::Aabb::new(b.min.to_array().into(), b.max.to_array().into());
        let mut n = 0;
        let fat = &self.obvhs_fat;
        self.obvhs.aabb_traverse(q, |bvh, node| {
            let node = &bvh.nodes[node as usize];
            for k in node.first_index..node.first_index + node.prim_count {
                let id = bvh.primitive_indices[k as usize];
                n += usize::from(fat[id as usize].intersect_aabb(&q));
            }
            true
        });
        n
    }
}
