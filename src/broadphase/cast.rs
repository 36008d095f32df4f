//! Casts through the tree: a ray, a box moving along a vector, and many rays at once, each
//! with a callback that goes on, clips the cast or stops it. Conservative by proof
//! ([`slab`](super::slab)): a cast never misses a box that the exact ray (or moving box)
//! meets within its length, and never reports an entry beyond the exact one.

use super::slab::Sweep;
use super::{BroadphaseError, CastControl, DynamicTree, Layers, Ray};
use crate::aabb::Aabb3;
use glam::Vec3A;

impl DynamicTree {
    /// Casts `ray` through the tree: calls `hit(id, entry)` for every placed proxy, of any
    /// kind, whose fat box the ray may meet within its length and whose layers interact
    /// with `layers`, and follows what `hit` returns. `entry` is a lower bound on the `t` at
    /// which the exact ray enters the box, never beyond it (0 when the origin is in the box
    /// or on its boundary); every proxy the exact ray meets within its (clipped) length is
    /// called, once. Boxes are taken roughly nearest first (the children of each node by
    /// entry), not in a global order. No heap allocation (unless the tree is deeper than 9
    /// levels).
    ///
    /// Closest hit: return `CastControl::Clip(t)` with the exact hit `t` of the shape in
    /// the box (the boxes entered beyond it are then skipped) and keep the least. Any hit:
    /// `Stop`. All hits: `Continue`.
    ///
    /// # Errors
    /// [`BroadphaseError::InvalidCast`] for a NaN or infinite origin or direction, a zero
    /// direction, or a NaN or negative `max` ([`Ray::is_valid`]); nothing is searched then.
    pub fn cast_ray(
        &self,
        ray: &Ray,
        layers: Layers,
        hit: impl FnMut(u32, f32) -> CastControl,
    ) -> Result<(), BroadphaseError> {
        if !ray.is_valid() {
            return Err(BroadphaseError::InvalidCast);
        }
        let sweep = Sweep::new(ray.origin, ray.origin, ray.direction);
        self.cast(&sweep, ray.max, layers, hit);
        Ok(())
    }

    /// Casts box `b` along `motion`: the boxes `b + t·motion` for `t` in `[0, max]`. Calls
    /// `hit(id, entry)` as [`DynamicTree::cast_ray`] does, `entry` a lower bound on the
    /// first `t` at which the moving box touches the proxy's (0 when they overlap at the
    /// start). A zero motion finds the boxes `b` overlaps, at entry 0.
    ///
    /// # Errors
    /// [`BroadphaseError::InvalidCast`] for a box with a NaN or infinite face or a face
    /// below its opposite one, a NaN or infinite motion, or a NaN or negative `max`;
    /// nothing is searched then.
    pub fn cast_box(
        &self,
        b: &Aabb3,
        motion: Vec3A,
        max: f32,
        layers: Layers,
        hit: impl FnMut(u32, f32) -> CastControl,
    ) -> Result<(), BroadphaseError> {
        let valid = b.min.is_finite() && b.max.is_finite() && b.min.cmple(b.max).all();
        if !(valid && motion.is_finite() && max >= 0.0) {
            return Err(BroadphaseError::InvalidCast);
        }
        self.cast(&Sweep::new(b.min, b.max, motion), max, layers, hit);
        Ok(())
    }

    /// Casts each of `rays` in turn ([`DynamicTree::cast_ray`]), `hit(i, id, entry, out_i)`
    /// seeing ray `i`'s hits and its output `out[i]` (say its closest hit so far).
    ///
    /// # Errors
    /// [`BroadphaseError::OutputLength`] when `out` is not as long as `rays`, and
    /// [`BroadphaseError::InvalidCast`] when a ray is not valid: both before any ray is
    /// cast.
    pub fn cast_rays<T>(
        &self,
        rays: &[Ray],
        layers: Layers,
        out: &mut [T],
        mut hit: impl FnMut(usize, u32, f32, &mut T) -> CastControl,
    ) -> Result<(), BroadphaseError> {
        check_rays(rays, out.len())?;
        for (i, (ray, o)) in rays.iter().zip(out).enumerate() {
            let sweep = Sweep::new(ray.origin, ray.origin, ray.direction);
            self.cast(&sweep, ray.max, layers, |id, entry| hit(i, id, entry, o));
        }
        Ok(())
    }

    /// [`DynamicTree::cast_rays`] on the rayon pool (feature `rayon`): each ray is cast on
    /// one thread, so `hit` sees each ray's hits in the same order as `cast_rays` shows them,
    /// and `out` ends the same, on any number of threads.
    ///
    /// # Errors
    /// As [`DynamicTree::cast_rays`].
    #[cfg(feature = "rayon")]
    pub fn cast_rays_par<T: Send>(
        &self,
        rays: &[Ray],
        layers: Layers,
        out: &mut [T],
        hit: impl Fn(usize, u32, f32, &mut T) -> CastControl + Sync,
    ) -> Result<(), BroadphaseError> {
        use rayon::prelude::*;
        check_rays(rays, out.len())?;
        rays.par_iter()
            .zip(out)
            .enumerate()
            .for_each(|(i, (ray, o))| {
                let sweep = Sweep::new(ray.origin, ray.origin, ray.direction);
                self.cast(&sweep, ray.max, layers, |id, entry| hit(i, id, entry, o));
            });
        Ok(())
    }

    /// The cast of `sweep` up to `max` through both hierarchies, the limit carried from one
    /// to the other.
    fn cast(
        &self,
        sweep: &Sweep,
        max: f32,
        layers: Layers,
        mut hit: impl FnMut(u32, f32) -> CastControl,
    ) {
        // While every proxy is in the common layers, one check answers for all.
        let every = self.unplain == 0;
        if every && !layers.interacts_with(self.common) {
            return;
        }
        let proxies = &self.proxies;
        let mut visit = |id: u32, entry: f32, limit: &mut f32| {
            if !every && !proxies[id as usize].layers.interacts_with(layers) {
                return true;
            }
            match hit(id, entry) {
                CastControl::Continue => true,
                CastControl::Clip(t) if t.is_nan() => false,
                CastControl::Clip(t) => {
                    *limit = limit.min(t);
                    // No entry is below 0.
                    *limit >= 0.0
                }
                CastControl::Stop => false,
            }
        };
        let (mut limit, tame) = (max, !self.wild);
        crate::simd::plain(
            #[inline(always)]
            || {
                if self.moving.cast(sweep, tame, &mut limit, &mut visit) {
                    self.fixed.cast(sweep, tame, &mut limit, &mut visit);
                }
            },
        );
    }
}

/// Checks a batch of rays and its output before any is cast.
fn check_rays(rays: &[Ray], out: usize) -> Result<(), BroadphaseError> {
    if out != rays.len() {
        return Err(BroadphaseError::OutputLength {
            rays: rays.len(),
            len: out,
        });
    }
    if !rays.iter().all(Ray::is_valid) {
        return Err(BroadphaseError::InvalidCast);
    }
    Ok(())
}
