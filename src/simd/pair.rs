//! Two boxes per vector: the lanes of the AoS loop.
//!
//! A 3D box as glam stores it (`Vec3A` faces) fills a 128-bit lane, so two of them share a
//! 256-bit register without any transposition: each operation of the single-box kernel
//! runs on both, and `Axes::axis` broadcasts a component within each half. The arithmetic
//! of each half is that of `Vec3A`, operation for operation and never fused, so a pair
//! gives the bits of two single-box calls.

use core::ops::{Add, Mul, Neg, Sub};

use glam::{BVec3A, Vec3A};

use crate::lane::{Axes, Lane};

/// Lanes holding two boxes' `Vec3A` values, one per half.
pub(crate) trait BoxPair: Axes {
    /// A mask with a flag per component of each half.
    type Mask: Copy;
    /// `a` in the first half, `b` in the second.
    fn join(a: Vec3A, b: Vec3A) -> Self;
    /// The two halves.
    fn halves(self) -> (Vec3A, Vec3A);
    /// Set in a component where the single-box kernel takes the result of the box
    /// `[lo, hi]`, by its own test: `lo <= hi` and `max − min <= f32::MAX`.
    fn stands(lo: Self, hi: Self, min: Self, max: Self) -> Self::Mask;
    /// Set where both are.
    fn and(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// True when components `x`, `y`, `z` of both halves are set.
    fn all_xyz(m: Self::Mask) -> bool;
    /// Every component set.
    fn all_set() -> Self::Mask;
}

/// Two `Vec3A` side by side: the pair on any target (two SSE registers on x86-64).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Two(Vec3A, Vec3A);

impl Add for Two {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Two(self.0 + o.0, self.1 + o.1)
    }
}

impl Sub for Two {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Two(self.0 - o.0, self.1 - o.1)
    }
}

impl Mul for Two {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Two(self.0 * o.0, self.1 * o.1)
    }
}

impl Neg for Two {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Two(-self.0, -self.1)
    }
}

impl Lane for Two {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        Two(Vec3A::splat(x), Vec3A::splat(x))
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        Two(Lane::min(self.0, o.0), Lane::min(self.1, o.1))
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        Two(Lane::max(self.0, o.0), Lane::max(self.1, o.1))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Two(self.0.abs(), self.1.abs())
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        self * b + c
    }
    #[inline(always)]
    fn select_nonneg(self, if_nonneg: Self, otherwise: Self) -> Self {
        Two(
            self.0.select_nonneg(if_nonneg.0, otherwise.0),
            self.1.select_nonneg(if_nonneg.1, otherwise.1),
        )
    }
}

impl Axes for Two {
    #[inline(always)]
    fn axis(self, j: usize) -> Self {
        Two(self.0.axis(j), self.1.axis(j))
    }
}

impl BoxPair for Two {
    type Mask = (BVec3A, BVec3A);
    #[inline(always)]
    fn join(a: Vec3A, b: Vec3A) -> Self {
        Two(a, b)
    }
    #[inline(always)]
    fn halves(self) -> (Vec3A, Vec3A) {
        (self.0, self.1)
    }
    #[inline(always)]
    fn stands(lo: Self, hi: Self, min: Self, max: Self) -> (BVec3A, BVec3A) {
        let one = |lo: Vec3A, hi: Vec3A, min: Vec3A, max: Vec3A| {
            (max - min).cmple(Vec3A::splat(f32::MAX)) & lo.cmple(hi)
        };
        (one(lo.0, hi.0, min.0, max.0), one(lo.1, hi.1, min.1, max.1))
    }
    #[inline(always)]
    fn and(a: (BVec3A, BVec3A), b: (BVec3A, BVec3A)) -> (BVec3A, BVec3A) {
        (a.0 & b.0, a.1 & b.1)
    }
    #[inline(always)]
    fn all_xyz(m: (BVec3A, BVec3A)) -> bool {
        (m.0 & m.1).all()
    }
    #[inline(always)]
    fn all_set() -> (BVec3A, BVec3A) {
        (BVec3A::TRUE, BVec3A::TRUE)
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use avx::AvxPair;

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)] // the AVX intrinsics, under the invariant of `AvxPair`
mod avx {
    use core::arch::x86_64::{
        __m256, _CMP_GE_OQ, _CMP_LE_OQ, _mm256_add_ps, _mm256_and_ps, _mm256_andnot_ps,
        _mm256_blendv_ps, _mm256_castps128_ps256, _mm256_castps256_ps128, _mm256_cmp_ps,
        _mm256_extractf128_ps, _mm256_insertf128_ps, _mm256_max_ps, _mm256_min_ps,
        _mm256_movemask_ps, _mm256_mul_ps, _mm256_permute_ps, _mm256_set1_ps, _mm256_setzero_ps,
        _mm256_sub_ps, _mm256_xor_ps,
    };
    use core::ops::{Add, Mul, Neg, Sub};

    use glam::Vec3A;

    use super::BoxPair;
    use crate::lane::{Axes, Lane};

    /// Two boxes' `Vec3A` values in one AVX register, one per 128-bit half. Each operation
    /// is the instruction `Vec3A` runs, at twice the width: `vminps`/`vmaxps` are its
    /// compare-selects, the select is ordered `>=` as glam's, nothing is fused.
    ///
    /// Invariant, on which every intrinsic below relies: a value of this type exists only
    /// on a CPU that has AVX2 and FMA. Only `simd::dispatch_pairs` names it, as the lanes of
    /// the `run_avx2_pairs` wrapper that it calls once `Backend::Avx2` or `Backend::Avx512`
    /// is known to be supported (both include AVX2 and FMA).
    #[derive(Clone, Copy, Debug)]
    #[repr(transparent)]
    pub(crate) struct AvxPair(__m256);

    /// One AVX operation: sound by the invariant of [`AvxPair`].
    macro_rules! avx {
        ($e:expr) => {
            // SAFETY: by the invariant of `AvxPair`, the CPU has AVX2 and FMA; the
            // intrinsic touches no memory.
            unsafe { $e }
        };
    }

    impl Add for AvxPair {
        type Output = Self;
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            AvxPair(avx!(_mm256_add_ps(self.0, o.0)))
        }
    }

    impl Sub for AvxPair {
        type Output = Self;
        #[inline(always)]
        fn sub(self, o: Self) -> Self {
            AvxPair(avx!(_mm256_sub_ps(self.0, o.0)))
        }
    }

    impl Mul for AvxPair {
        type Output = Self;
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            AvxPair(avx!(_mm256_mul_ps(self.0, o.0)))
        }
    }

    impl Neg for AvxPair {
        type Output = Self;
        #[inline(always)]
        fn neg(self) -> Self {
            AvxPair(avx!(_mm256_xor_ps(self.0, _mm256_set1_ps(-0.0))))
        }
    }

    impl Lane for AvxPair {
        #[inline(always)]
        fn splat(x: f32) -> Self {
            AvxPair(avx!(_mm256_set1_ps(x)))
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            AvxPair(avx!(_mm256_min_ps(self.0, o.0)))
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            AvxPair(avx!(_mm256_max_ps(self.0, o.0)))
        }
        #[inline(always)]
        fn abs(self) -> Self {
            AvxPair(avx!(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0)))
        }
        #[inline(always)]
        fn mul_add(self, b: Self, c: Self) -> Self {
            self * b + c
        }
        #[inline(always)]
        fn select_nonneg(self, if_nonneg: Self, otherwise: Self) -> Self {
            // `self >= 0`, false for NaN (ordered, quiet), as glam's `cmpge`.
            let nonneg = avx!(_mm256_cmp_ps::<_CMP_GE_OQ>(self.0, _mm256_setzero_ps()));
            AvxPair(avx!(_mm256_blendv_ps(otherwise.0, if_nonneg.0, nonneg)))
        }
    }

    impl Axes for AvxPair {
        #[inline(always)]
        fn axis(self, j: usize) -> Self {
            // Component `j` of each half, in every lane of that half (`vpermilps`).
            AvxPair(match j {
                0 => avx!(_mm256_permute_ps::<0x00>(self.0)),
                1 => avx!(_mm256_permute_ps::<0x55>(self.0)),
                _ => avx!(_mm256_permute_ps::<0xAA>(self.0)),
            })
        }
    }

    impl BoxPair for AvxPair {
        type Mask = __m256;
        #[inline(always)]
        fn join(a: Vec3A, b: Vec3A) -> Self {
            AvxPair(avx!(_mm256_insertf128_ps::<1>(
                _mm256_castps128_ps256(a.into()),
                b.into()
            )))
        }
        #[inline(always)]
        fn halves(self) -> (Vec3A, Vec3A) {
            avx!((
                _mm256_castps256_ps128(self.0).into(),
                _mm256_extractf128_ps::<1>(self.0).into()
            ))
        }
        #[inline(always)]
        fn stands(lo: Self, hi: Self, min: Self, max: Self) -> __m256 {
            // glam's `cmple` is ordered `<=`: false for NaN.
            let spread = avx!(_mm256_sub_ps(max.0, min.0));
            let finite = avx!(_mm256_cmp_ps::<_CMP_LE_OQ>(
                spread,
                _mm256_set1_ps(f32::MAX)
            ));
            let ordered = avx!(_mm256_cmp_ps::<_CMP_LE_OQ>(lo.0, hi.0));
            avx!(_mm256_and_ps(finite, ordered))
        }
        #[inline(always)]
        fn and(a: __m256, b: __m256) -> __m256 {
            avx!(_mm256_and_ps(a, b))
        }
        #[inline(always)]
        fn all_xyz(m: __m256) -> bool {
            avx!(_mm256_movemask_ps(m)) & 0x77 == 0x77
        }
        #[inline(always)]
        fn all_set() -> __m256 {
            avx!(_mm256_set1_ps(f32::from_bits(u32::MAX)))
        }
    }
}
