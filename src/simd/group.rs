//! Several boxes per vector: the lanes of the AoS loop.
//!
//! A 3D box as glam stores it (`Vec3A` faces) fills a 128-bit lane, so two of them share a
//! 256-bit register, and four a 512-bit one, without any transposition: each operation of
//! the single-box kernel runs on every part, and `Axes::axis` broadcasts a component within
//! each 128-bit part. The arithmetic of each part is that of `Vec3A`, operation for
//! operation and never fused, so a group gives the bits of as many single-box calls.

use core::ops::{Add, Mul, Neg, Sub};

use glam::{BVec3A, Vec3A};

use crate::lane::{Axes, Lane};

/// Lanes holding `W` boxes' `Vec3A` values, one per 128-bit part.
pub(crate) trait BoxGroup<const W: usize>: Axes {
    /// A mask with a flag per component of each part.
    type Mask: Copy;
    /// `parts[k]` in part `k`.
    fn join(parts: [Vec3A; W]) -> Self;
    /// The parts.
    fn parts(self) -> [Vec3A; W];
    /// Set in a component where the single-box kernel takes the result of the box
    /// `[lo, hi]`, by its own test: `lo <= hi` and `max − min <= f32::MAX`.
    fn stands(lo: Self, hi: Self, min: Self, max: Self) -> Self::Mask;
    /// Set where both are.
    fn and(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// True when components `x`, `y`, `z` of every part are set.
    fn all_xyz(m: Self::Mask) -> bool;
    /// Every component set.
    fn all_set() -> Self::Mask;
    /// Bit `k` set where part `k` of `a` is `<=` part `k` of `b` in `x`, `y` and `z`
    /// (ordered, as glam's `cmple`: false for NaN).
    fn le_xyz(a: Self, b: Self) -> u32;
    /// Part `k` of `a` where bit `k` of `parts` is set, of `b` elsewhere.
    fn pick(parts: u32, a: Self, b: Self) -> Self;
}

/// Bit `k` set where bits `4k`, `4k + 1` and `4k + 2` of `m` are (`x`, `y`, `z` of part
/// `k` in a mask of four bits per part), for parts `0..4`.
#[inline(always)]
fn whole_parts(m: u32) -> u32 {
    let x = m & m >> 1 & m >> 2 & 0x1111;
    (x | x >> 3 | x >> 6 | x >> 9) & 0xF
}

/// Bit `k` of `parts` spread to bits `4k..4k + 4`, for parts `0..4`: the inverse of
/// [`whole_parts`], a mask of four bits per part.
#[inline(always)]
fn spread_parts(parts: u32) -> u32 {
    let x = parts & 1 | (parts & 2) << 3 | (parts & 4) << 6 | (parts & 8) << 9;
    x * 0xF
}

/// Two `Vec3A` side by side: the pair on any target (two SSE registers on x86-64), whose
/// two dependency chains overlap (`docs/decisions.md`, "Two `Vec3A` per group on SSE").
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
    #[inline(always)]
    fn yxx(self) -> Self {
        Two(self.0.yxx(), self.1.yxx())
    }
    #[inline(always)]
    fn zzy(self) -> Self {
        Two(self.0.zzy(), self.1.zzy())
    }
    #[inline(always)]
    fn merge(x: Self, y: Self, z: Self) -> Self {
        Two(Vec3A::merge(x.0, y.0, z.0), Vec3A::merge(x.1, y.1, z.1))
    }
}

impl BoxGroup<2> for Two {
    type Mask = (BVec3A, BVec3A);
    #[inline(always)]
    fn join([a, b]: [Vec3A; 2]) -> Self {
        Two(a, b)
    }
    #[inline(always)]
    fn parts(self) -> [Vec3A; 2] {
        [self.0, self.1]
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
    #[inline(always)]
    fn le_xyz(a: Self, b: Self) -> u32 {
        <Vec3A as BoxGroup<1>>::le_xyz(a.0, b.0) | <Vec3A as BoxGroup<1>>::le_xyz(a.1, b.1) << 1
    }
    #[inline(always)]
    fn pick(parts: u32, a: Self, b: Self) -> Self {
        Two(
            <Vec3A as BoxGroup<1>>::pick(parts, a.0, b.0),
            <Vec3A as BoxGroup<1>>::pick(parts >> 1, a.1, b.1),
        )
    }
}

/// One box per `Vec3A`: the group of an index list, which runs one object at a time.
impl BoxGroup<1> for Vec3A {
    type Mask = BVec3A;
    #[inline(always)]
    fn join([a]: [Vec3A; 1]) -> Self {
        a
    }
    #[inline(always)]
    fn parts(self) -> [Vec3A; 1] {
        [self]
    }
    #[inline(always)]
    fn stands(lo: Self, hi: Self, min: Self, max: Self) -> BVec3A {
        (max - min).cmple(Vec3A::splat(f32::MAX)) & lo.cmple(hi)
    }
    #[inline(always)]
    fn and(a: BVec3A, b: BVec3A) -> BVec3A {
        a & b
    }
    #[inline(always)]
    fn all_xyz(m: BVec3A) -> bool {
        m.all()
    }
    #[inline(always)]
    fn all_set() -> BVec3A {
        BVec3A::TRUE
    }
    #[inline(always)]
    fn le_xyz(a: Self, b: Self) -> u32 {
        u32::from(a.cmple(b).all())
    }
    #[inline(always)]
    fn pick(parts: u32, a: Self, b: Self) -> Self {
        Vec3A::select(BVec3A::splat(parts & 1 != 0), a, b)
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use avx::AvxPair;

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)] // the AVX intrinsics, under the invariant of `AvxPair`
mod avx {
    use core::arch::x86_64::{
        __m256, _CMP_GE_OQ, _CMP_LE_OQ, _mm256_add_ps, _mm256_and_ps, _mm256_and_si256,
        _mm256_andnot_ps, _mm256_blend_ps, _mm256_blendv_ps, _mm256_castps128_ps256,
        _mm256_castps256_ps128, _mm256_castsi256_ps, _mm256_cmp_ps, _mm256_cmpeq_epi32,
        _mm256_extractf128_ps, _mm256_insertf128_ps, _mm256_max_ps, _mm256_min_ps,
        _mm256_movemask_ps, _mm256_mul_ps, _mm256_permute_ps, _mm256_set1_epi32, _mm256_set1_ps,
        _mm256_setr_epi32, _mm256_setzero_ps, _mm256_sub_ps, _mm256_xor_ps,
    };
    use core::ops::{Add, Mul, Neg, Sub};

    use glam::Vec3A;

    use super::BoxGroup;
    use crate::lane::{Axes, Lane};

    /// Two boxes' `Vec3A` values in one AVX register, one per 128-bit half. Each operation
    /// is the instruction `Vec3A` runs, at twice the width: `vminps`/`vmaxps` are its
    /// compare-selects, the select is ordered `>=` as glam's, nothing is fused.
    ///
    /// Invariant, on which every intrinsic below relies: a value of this type exists only
    /// on a CPU that has AVX2 and FMA. Only `simd::dispatch_groups` names it, as the lanes of
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
        #[inline(always)]
        fn yxx(self) -> Self {
            // Lanes (1, 0, 0, 3) of each half.
            AvxPair(avx!(_mm256_permute_ps::<0b11_00_00_01>(self.0)))
        }
        #[inline(always)]
        fn zzy(self) -> Self {
            // Lanes (2, 2, 1, 3) of each half.
            AvxPair(avx!(_mm256_permute_ps::<0b11_01_10_10>(self.0)))
        }
        #[inline(always)]
        fn merge(x: Self, y: Self, z: Self) -> Self {
            // Lane 1 of each half from `y`, then lane 2 from `z`.
            let xy = avx!(_mm256_blend_ps::<0b0010_0010>(x.0, y.0));
            AvxPair(avx!(_mm256_blend_ps::<0b0100_0100>(xy, z.0)))
        }
    }

    impl BoxGroup<2> for AvxPair {
        type Mask = __m256;
        #[inline(always)]
        fn join([a, b]: [Vec3A; 2]) -> Self {
            AvxPair(avx!(_mm256_insertf128_ps::<1>(
                _mm256_castps128_ps256(a.into()),
                b.into()
            )))
        }
        #[inline(always)]
        fn parts(self) -> [Vec3A; 2] {
            avx!([
                _mm256_castps256_ps128(self.0).into(),
                _mm256_extractf128_ps::<1>(self.0).into()
            ])
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
        #[inline(always)]
        fn le_xyz(a: Self, b: Self) -> u32 {
            let le = avx!(_mm256_cmp_ps::<_CMP_LE_OQ>(a.0, b.0));
            super::whole_parts(avx!(_mm256_movemask_ps(le)) as u32)
        }
        #[inline(always)]
        fn pick(parts: u32, a: Self, b: Self) -> Self {
            // Lane `j` takes `a` where bit `j / 4` of `parts` is set: the spread bits
            // broadcast, each lane's own bit tested, as a sign mask for `vblendvps`.
            let bits = avx!(_mm256_set1_epi32(super::spread_parts(parts) as i32));
            let lane = avx!(_mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128));
            let own = avx!(_mm256_and_si256(bits, lane));
            let mask = avx!(_mm256_castsi256_ps(_mm256_cmpeq_epi32(own, lane)));
            AvxPair(avx!(_mm256_blendv_ps(b.0, a.0, mask)))
        }
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use avx512::Avx512Quad;

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)] // the AVX-512 intrinsics, under the invariant of `Avx512Quad`
mod avx512 {
    use core::arch::x86_64::{
        __m512, __mmask16, _CMP_GE_OQ, _CMP_LE_OQ, _mm512_abs_ps, _mm512_add_ps,
        _mm512_castps_si512, _mm512_castps128_ps512, _mm512_castps512_ps128, _mm512_castsi512_ps,
        _mm512_cmp_ps_mask, _mm512_extractf32x4_ps, _mm512_insertf32x4, _mm512_mask_blend_ps,
        _mm512_max_ps, _mm512_min_ps, _mm512_mul_ps, _mm512_permute_ps, _mm512_set1_epi32,
        _mm512_set1_ps, _mm512_setzero_ps, _mm512_sub_ps, _mm512_xor_si512,
    };
    use core::ops::{Add, Mul, Neg, Sub};

    use glam::Vec3A;

    use super::BoxGroup;
    use crate::lane::{Axes, Lane};

    /// Four boxes' `Vec3A` values in one AVX-512 register, one per 128-bit part. Each
    /// operation is the instruction `Vec3A` runs, at four times the width, as for
    /// [`super::AvxPair`]: `vminps`/`vmaxps`, an ordered `>=` select, nothing fused.
    ///
    /// Invariant, on which every intrinsic below relies: a value of this type exists only
    /// on a CPU that has AVX-512F, AVX2 and FMA. Only `simd::dispatch_groups` names it, as
    /// the lanes of the `run_avx512_quads` wrapper that it calls once `Backend::Avx512` is
    /// known to be supported.
    #[derive(Clone, Copy, Debug)]
    #[repr(transparent)]
    pub(crate) struct Avx512Quad(__m512);

    /// One AVX-512 operation: sound by the invariant of [`Avx512Quad`].
    macro_rules! avx512 {
        ($e:expr) => {
            // SAFETY: by the invariant of `Avx512Quad`, the CPU has AVX-512F; the
            // intrinsic touches no memory.
            unsafe { $e }
        };
    }

    impl Add for Avx512Quad {
        type Output = Self;
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            Avx512Quad(avx512!(_mm512_add_ps(self.0, o.0)))
        }
    }

    impl Sub for Avx512Quad {
        type Output = Self;
        #[inline(always)]
        fn sub(self, o: Self) -> Self {
            Avx512Quad(avx512!(_mm512_sub_ps(self.0, o.0)))
        }
    }

    impl Mul for Avx512Quad {
        type Output = Self;
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            Avx512Quad(avx512!(_mm512_mul_ps(self.0, o.0)))
        }
    }

    impl Neg for Avx512Quad {
        type Output = Self;
        #[inline(always)]
        fn neg(self) -> Self {
            // The sign bit flipped (AVX-512F has no float `xor`).
            Avx512Quad(avx512!(_mm512_castsi512_ps(_mm512_xor_si512(
                _mm512_castps_si512(self.0),
                _mm512_set1_epi32(i32::MIN)
            ))))
        }
    }

    impl Lane for Avx512Quad {
        #[inline(always)]
        fn splat(x: f32) -> Self {
            Avx512Quad(avx512!(_mm512_set1_ps(x)))
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            Avx512Quad(avx512!(_mm512_min_ps(self.0, o.0)))
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            Avx512Quad(avx512!(_mm512_max_ps(self.0, o.0)))
        }
        #[inline(always)]
        fn abs(self) -> Self {
            Avx512Quad(avx512!(_mm512_abs_ps(self.0)))
        }
        #[inline(always)]
        fn mul_add(self, b: Self, c: Self) -> Self {
            self * b + c
        }
        #[inline(always)]
        fn select_nonneg(self, if_nonneg: Self, otherwise: Self) -> Self {
            // `self >= 0`, false for NaN (ordered, quiet), as glam's `cmpge`.
            let nonneg = avx512!(_mm512_cmp_ps_mask::<_CMP_GE_OQ>(
                self.0,
                _mm512_setzero_ps()
            ));
            Avx512Quad(avx512!(_mm512_mask_blend_ps(
                nonneg,
                otherwise.0,
                if_nonneg.0
            )))
        }
    }

    impl Axes for Avx512Quad {
        #[inline(always)]
        fn axis(self, j: usize) -> Self {
            // Component `j` of each part, in every lane of that part (`vpermilps`).
            Avx512Quad(match j {
                0 => avx512!(_mm512_permute_ps::<0x00>(self.0)),
                1 => avx512!(_mm512_permute_ps::<0x55>(self.0)),
                _ => avx512!(_mm512_permute_ps::<0xAA>(self.0)),
            })
        }
        #[inline(always)]
        fn yxx(self) -> Self {
            // Lanes (1, 0, 0, 3) of each part.
            Avx512Quad(avx512!(_mm512_permute_ps::<0b11_00_00_01>(self.0)))
        }
        #[inline(always)]
        fn zzy(self) -> Self {
            // Lanes (2, 2, 1, 3) of each part.
            Avx512Quad(avx512!(_mm512_permute_ps::<0b11_01_10_10>(self.0)))
        }
        #[inline(always)]
        fn merge(x: Self, y: Self, z: Self) -> Self {
            // Lane 1 of each part from `y`, then lane 2 from `z`.
            let xy = avx512!(_mm512_mask_blend_ps(0x2222, x.0, y.0));
            Avx512Quad(avx512!(_mm512_mask_blend_ps(0x4444, xy, z.0)))
        }
    }

    impl BoxGroup<4> for Avx512Quad {
        type Mask = __mmask16;
        #[inline(always)]
        fn join([a, b, c, d]: [Vec3A; 4]) -> Self {
            let v = avx512!(_mm512_castps128_ps512(a.into()));
            let v = avx512!(_mm512_insertf32x4::<1>(v, b.into()));
            let v = avx512!(_mm512_insertf32x4::<2>(v, c.into()));
            Avx512Quad(avx512!(_mm512_insertf32x4::<3>(v, d.into())))
        }
        #[inline(always)]
        fn parts(self) -> [Vec3A; 4] {
            avx512!([
                _mm512_castps512_ps128(self.0).into(),
                _mm512_extractf32x4_ps::<1>(self.0).into(),
                _mm512_extractf32x4_ps::<2>(self.0).into(),
                _mm512_extractf32x4_ps::<3>(self.0).into(),
            ])
        }
        #[inline(always)]
        fn stands(lo: Self, hi: Self, min: Self, max: Self) -> __mmask16 {
            // glam's `cmple` is ordered `<=`: false for NaN.
            let spread = avx512!(_mm512_sub_ps(max.0, min.0));
            let finite = avx512!(_mm512_cmp_ps_mask::<_CMP_LE_OQ>(
                spread,
                _mm512_set1_ps(f32::MAX)
            ));
            let ordered = avx512!(_mm512_cmp_ps_mask::<_CMP_LE_OQ>(lo.0, hi.0));
            finite & ordered
        }
        #[inline(always)]
        fn and(a: __mmask16, b: __mmask16) -> __mmask16 {
            a & b
        }
        #[inline(always)]
        fn all_xyz(m: __mmask16) -> bool {
            m & 0x7777 == 0x7777
        }
        #[inline(always)]
        fn all_set() -> __mmask16 {
            0xFFFF
        }
        #[inline(always)]
        fn le_xyz(a: Self, b: Self) -> u32 {
            super::whole_parts(u32::from(avx512!(_mm512_cmp_ps_mask::<_CMP_LE_OQ>(
                a.0, b.0
            ))))
        }
        #[inline(always)]
        fn pick(parts: u32, a: Self, b: Self) -> Self {
            let mask = super::spread_parts(parts) as __mmask16;
            Avx512Quad(avx512!(_mm512_mask_blend_ps(mask, b.0, a.0)))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_part_counts_only_with_x_y_and_z_and_spreads_back() {
        for parts in 0..16 {
            assert_eq!(whole_parts(spread_parts(parts)), parts);
        }
        // The fourth component (`w`) is ignored; a part with any of x, y, z clear is out.
        assert_eq!(whole_parts(0b0111), 0b0001);
        assert_eq!(whole_parts(0b1011), 0);
        assert_eq!(whole_parts(0x8888), 0);
        assert_eq!(whole_parts(0x7370), 0b1010);
    }

    #[test]
    fn the_pair_tests_and_picks_part_by_part() {
        let lo = Vec3A::new(0.0, 0.0, 0.0);
        let hi = Vec3A::new(1.0, 1.0, 1.0);
        let nan = Vec3A::new(0.0, f32::NAN, 0.0);
        let le = |a: [Vec3A; 2], b: [Vec3A; 2]| Two::le_xyz(Two::join(a), Two::join(b));
        assert_eq!(le([lo, lo], [hi, hi]), 0b11);
        assert_eq!(le([lo, hi], [hi, lo]), 0b01);
        assert_eq!(le([hi, lo], [lo, hi]), 0b10);
        // Ordered: a NaN component fails the test, on either side.
        assert_eq!(le([nan, lo], [hi, nan]), 0);
        // Only x, y and z count.
        let w = Vec3A::from_vec4(glam::Vec4::new(0.0, 0.0, 0.0, 9.0));
        assert_eq!(le([w, w], [lo, lo]), 0b11);
        for parts in 0..4 {
            let got = Two::pick(parts, Two::join([lo, lo]), Two::join([hi, hi])).parts();
            for (k, got) in got.into_iter().enumerate() {
                let want = if parts >> k & 1 != 0 { lo } else { hi };
                assert_eq!(got, want, "parts {parts:#b}, part {k}");
            }
        }
    }
}
