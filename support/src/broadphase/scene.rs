//! The scene both modes run: N bodies on a seeded random walk, some islands asleep.

use bvkit::{Aabb3, Rigid3};
use glam::{Quat, Vec3A};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

/// Bodies with boxes of 0.2 to 2 units at the density of a million in a 1 km cube (so that a
/// smaller scene has as many overlaps per body), a random velocity of up to 2 m/s and a
/// spin; the bodies of a fraction of the islands never move (their mask bits are clear).
pub struct Scene {
    pub local: Vec<Aabb3>,
    pub poses: Vec<Rigid3>,
    velocity: Vec<Vec3A>,
    /// Bit `i` set where body `i` is awake.
    pub mask: Vec<u64>,
    /// The number of awake bodies.
    pub awake: usize,
    /// The factor on every velocity (1 unless `fast` set it).
    speed: f32,
    /// Which bodies move in `step_some`.
    rng: StdRng,
}

impl Scene {
    /// `n` bodies; `asleep` of the islands of `island` consecutive bodies sleep (as engines
    /// put a resting pile to sleep; an island of 1 puts bodies to sleep one by one).
    pub fn new(n: usize, asleep: f64, island: usize) -> Self {
        let mut r = StdRng::seed_from_u64(0xb0d1e5);
        let half = 500.0 * (n as f32 / 1e6).cbrt();
        let local = (0..n)
            .map(|_| {
                let e = Vec3A::new(
                    r.random_range(0.1..1.0),
                    r.random_range(0.1..1.0),
                    r.random_range(0.1..1.0),
                );
                Aabb3::new(-e, e)
            })
            .collect();
        let poses = (0..n)
            .map(|_| {
                let axis = Vec3A::new(r.random(), r.random(), r.random()).normalize_or(Vec3A::Y);
                let rotation = Quat::from_axis_angle(axis.into(), r.random_range(0.0..6.3));
                let position = Vec3A::new(
                    r.random_range(-half..half),
                    r.random_range(-half..half),
                    r.random_range(-half..half),
                );
                Rigid3::new(rotation, position)
            })
            .collect();
        let velocity = (0..n)
            .map(|_| Vec3A::new(r.random(), r.random(), r.random()) * 4.0 - 2.0)
            .collect();
        let mut mask = vec![0u64; n.div_ceil(64)];
        let mut awake = 0;
        for start in (0..n).step_by(island.max(1)) {
            if r.random::<f64>() >= asleep {
                for i in start..(start + island.max(1)).min(n) {
                    mask[i / 64] |= 1 << (i % 64);
                    awake += 1;
                }
            }
        }
        Self {
            local,
            poses,
            velocity,
            mask,
            awake,
            speed: 1.0,
            rng: StdRng::seed_from_u64(0x5ca1ab1e),
        }
    }

    /// The same bodies packed `factor` times closer together along each axis (so `factor³`
    /// times as dense): at 6, where each body's fat box overlaps several others (a pile, a
    /// stack, a crowd: about 4.5 overlapping fat boxes a body at 6, 20 at 10) rather than far
    /// under one.
    pub fn packed(mut self, factor: f32) -> Self {
        for p in &mut self.poses {
            p.translation /= factor;
        }
        self
    }

    /// The same scene with every velocity `speed` times as large: at 8, a step moves a body
    /// by up to 0.27 units, and most awake bodies leave their fat box every frame (fast
    /// debris, a crowd, an explosion).
    pub fn fast(mut self, speed: f32) -> Self {
        self.speed = speed;
        self
    }

    /// The awake bodies, in ascending order.
    pub fn awake(&self) -> impl Iterator<Item = usize> + '_ {
        self.mask.iter().enumerate().flat_map(|(w, &word)| {
            let mut bits = word;
            core::iter::from_fn(move || {
                (bits != 0).then(|| {
                    let i = 64 * w + bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    i
                })
            })
        })
    }

    /// One simulation step at 60 Hz: the awake bodies move and spin.
    pub fn step(&mut self) {
        self.step_some(1.0);
    }

    /// One step in which each awake body moves with probability `share` (drawn anew each
    /// step; the others keep their pose), so that a frame moves about that share of them.
    pub fn step_some(&mut self, share: f64) {
        let spin = Quat::from_rotation_y(0.02);
        let dt = self.speed / 60.0;
        for w in 0..self.mask.len() {
            let mut bits = self.mask[w];
            while bits != 0 {
                let i = 64 * w + bits.trailing_zeros() as usize;
                bits &= bits - 1;
                if share < 1.0 && self.rng.random::<f64>() >= share {
                    continue;
                }
                let p = &mut self.poses[i];
                p.translation += self.velocity[i] * dt;
                p.rotation = spin * p.rotation;
            }
        }
    }
}
