//! The AoS path of 3D boxes: each box as glam stores it, through the single-box kernel.
//!
//! Gathering AoS boxes and transforms into one-field-per-register lanes costs a shuffle per
//! field per box, more than the kernel itself (measured in `docs/speed.md`). So `&[Aabb3]`
//! to `&mut [Aabb3]`, with AoS or shared transforms, runs [`Aabb3::transformed`] on every
//! box, on glam's `Vec3A`: the same bits as the single-box calls on every SIMD backend
//! (never fused on a default build), and the same contract.

use crate::aabb::Aabb3;
use crate::method::{Method, Rounding};
use crate::simd::Backend;
use crate::transform::{Simd3Job, Transform3};

/// Transforms read as AoS: one per box, or one shared.
#[derive(Clone, Copy)]
pub(crate) enum Maps<'a, T> {
    /// Transform `k` for box `k`.
    Each(&'a [T]),
    /// One transform for every box.
    Shared(&'a T),
}

/// A 3D AoS batch, its lengths already checked equal.
pub(crate) struct Aos3<'a, T> {
    pub local: &'a [Aabb3],
    pub maps: Maps<'a, T>,
    pub out: &'a mut [Aabb3],
    pub method: Method,
    pub rounding: Rounding,
}

impl<T> Simd3Job<T> for Aos3<'_, T> {
    fn run(self, backend: Backend) -> bool
    where
        T: Transform3,
    {
        match backend {
            Backend::Baseline | Backend::Avx2 | Backend::Avx512 => {
                // One loop per method and rounding, each specialised to its kernel.
                match (self.method, self.rounding) {
                    (Method::Naive, Rounding::Nearest) => {
                        self.boxes(Method::Naive, Rounding::Nearest)
                    }
                    (Method::Naive, Rounding::Outward) => {
                        self.boxes(Method::Naive, Rounding::Outward)
                    }
                    (Method::AbsMatrix, Rounding::Nearest) => {
                        self.boxes(Method::AbsMatrix, Rounding::Nearest)
                    }
                    (Method::AbsMatrix, Rounding::Outward) => {
                        self.boxes(Method::AbsMatrix, Rounding::Outward)
                    }
                    (Method::SignSelect, Rounding::Nearest) => {
                        self.boxes(Method::SignSelect, Rounding::Nearest)
                    }
                    (Method::SignSelect, Rounding::Outward) => {
                        self.boxes(Method::SignSelect, Rounding::Outward)
                    }
                }
                true
            }
            Backend::Scalar | Backend::Wide => false,
        }
    }
}

impl<T: Transform3> Aos3<'_, T> {
    #[inline(always)]
    fn boxes(self, method: Method, rounding: Rounding) {
        match self.maps {
            Maps::Each(maps) => {
                for ((out, local), xf) in self.out.iter_mut().zip(self.local).zip(maps) {
                    *out = local.transformed(xf, method, rounding);
                }
            }
            Maps::Shared(xf) => {
                for (out, local) in self.out.iter_mut().zip(self.local) {
                    *out = local.transformed(xf, method, rounding);
                }
            }
        }
    }
}
