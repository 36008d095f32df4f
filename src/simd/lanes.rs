//! The lane types of the batch path.
//!
//! [`F32s`] is plain array code: every operation is a loop over `W` floats that LLVM
//! vectorises for whatever target features the enclosing function enables, which is what
//! lets one generic kernel be compiled for SSE2 and AVX-512 and be chosen at run time.
//! [`Avx8`], the AVX2 backend's lanes, holds one `__m256` instead, so that its code does
//! not depend on the vectoriser. `wide::f32x8` is the alternative whose code is fixed at
//! compile time.

use core::ops::{Add, Mul, Neg, Sub};

use crate::lane::{Lane, Vector};

/// A lane type whose lanes can be built, read and written one at a time.
pub trait LaneArray: Lane {
    /// The number of lanes.
    const WIDTH: usize;
    /// One lane with the same arithmetic (fused exactly when `Self` fuses): the lane type
    /// of an index list's entries, run one at a time, so that every box is rounded the same
    /// whichever way it runs.
    type One: LaneArray;
    /// Lane `k`.
    fn get(&self, k: usize) -> f32;
    /// Sets lane `k`.
    fn set(&mut self, k: usize, x: f32);
    /// Lanes from `src[..WIDTH]` (one vector load).
    fn load(src: &[f32]) -> Self;
    /// Writes the lanes to `dst[..WIDTH]` (one vector store).
    fn store(self, dst: &mut [f32]);
    /// [`LaneArray::store`] past the caches (non-temporal), where the lanes fill whole
    /// 16-byte-aligned vectors; otherwise an ordinary store. The caller fences
    /// ([`super::store_fence`]) before the batch returns.
    #[inline(always)]
    fn store_streaming(self, dst: &mut [f32]) {
        self.store(dst);
    }
    /// True when any lane is not zero (NaN included).
    fn any_nonzero(self) -> bool;
    /// Bit `k` set where lane `k` is not zero (NaN included).
    fn nonzero_mask(self) -> u32;
    /// The same lanes, with the same arithmetic, as a type that any code may hold: the
    /// lanes handed to a function that runs out of line, compiled without the dispatch
    /// wrapper's target features, where an explicit vector type's operations would each
    /// become a call.
    type Portable: LaneArray;
    /// The lanes as [`LaneArray::Portable`].
    fn portable(self) -> Self::Portable;
    /// Each component of `v` as [`LaneArray::Portable`].
    #[inline(always)]
    fn portable_vector<const N: usize>(v: Vector<Self, N>) -> Vector<Self::Portable, N> {
        let mut p = Vector([<Self::Portable as Lane>::splat(0.0); N]);
        for a in 0..N {
            p.0[a] = v.0[a].portable();
        }
        p
    }
}

impl LaneArray for f32 {
    const WIDTH: usize = 1;
    type One = f32;
    #[inline(always)]
    fn get(&self, _: usize) -> f32 {
        *self
    }
    #[inline(always)]
    fn set(&mut self, _: usize, x: f32) {
        *self = x;
    }
    #[inline(always)]
    fn load(src: &[f32]) -> Self {
        src[0]
    }
    #[inline(always)]
    fn store(self, dst: &mut [f32]) {
        dst[0] = self;
    }
    #[inline(always)]
    fn any_nonzero(self) -> bool {
        self != 0.0
    }
    #[inline(always)]
    fn nonzero_mask(self) -> u32 {
        u32::from(self != 0.0)
    }
    type Portable = f32;
    #[inline(always)]
    fn portable(self) -> f32 {
        self
    }
}

/// `W` lanes of `f32` in a plain array; `mul_add` fuses iff `FMA` (set only where the
/// enclosing function enables the FMA instructions).
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct F32s<const W: usize, const FMA: bool>(pub [f32; W]);

impl<const W: usize, const FMA: bool> F32s<W, FMA> {
    // Plain indexed loops rather than `array::from_fn`/`map`: their closures and
    // internal adapters are not always inlined into the hot loop, which stops LLVM
    // from vectorising the kernel.
    #[inline(always)]
    fn zip(mut self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        for k in 0..W {
            self.0[k] = f(self.0[k], o.0[k]);
        }
        self
    }

    #[inline(always)]
    fn each(mut self, f: impl Fn(f32) -> f32) -> Self {
        for k in 0..W {
            self.0[k] = f(self.0[k]);
        }
        self
    }
}

impl<const W: usize, const FMA: bool> Add for F32s<W, FMA> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        self.zip(o, |a, b| a + b)
    }
}

impl<const W: usize, const FMA: bool> Sub for F32s<W, FMA> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        self.zip(o, |a, b| a - b)
    }
}

impl<const W: usize, const FMA: bool> Mul for F32s<W, FMA> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        self.zip(o, |a, b| a * b)
    }
}

impl<const W: usize, const FMA: bool> Neg for F32s<W, FMA> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self.each(|a| -a)
    }
}

impl<const W: usize, const FMA: bool> Lane for F32s<W, FMA> {
    const FUSES: bool = FMA;
    #[inline(always)]
    fn splat(x: f32) -> Self {
        F32s([x; W])
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        // The compare-select form maps to one `minps`; `f32::min`'s NaN rule would not.
        self.zip(o, |a, b| if a < b { a } else { b })
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        self.zip(o, |a, b| if a > b { a } else { b })
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.each(f32::abs)
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        if FMA {
            let mut r = c;
            for k in 0..W {
                r.0[k] = crate::num::mul_add(self.0[k], b.0[k], c.0[k]);
            }
            r
        } else {
            self * b + c
        }
    }
    #[inline(always)]
    fn select_nonneg(self, if_nonneg: Self, mut otherwise: Self) -> Self {
        for k in 0..W {
            if self.0[k] >= 0.0 {
                otherwise.0[k] = if_nonneg.0[k];
            }
        }
        otherwise
    }
}

impl<const W: usize, const FMA: bool> LaneArray for F32s<W, FMA> {
    const WIDTH: usize = W;
    type One = F32s<1, FMA>;
    #[inline(always)]
    fn get(&self, k: usize) -> f32 {
        self.0[k]
    }
    #[inline(always)]
    fn set(&mut self, k: usize, x: f32) {
        self.0[k] = x;
    }
    #[inline(always)]
    fn load(src: &[f32]) -> Self {
        let mut r = [0.0; W];
        r.copy_from_slice(&src[..W]);
        F32s(r)
    }
    #[inline(always)]
    fn store(self, dst: &mut [f32]) {
        dst[..W].copy_from_slice(&self.0);
    }
    #[inline(always)]
    fn store_streaming(self, dst: &mut [f32]) {
        let dst = &mut dst[..W];
        #[cfg(target_arch = "x86_64")]
        if W.is_multiple_of(4) && dst.as_ptr().align_offset(16) == 0 {
            use core::arch::x86_64::{_mm_loadu_ps, _mm_stream_ps};
            for q in 0..W / 4 {
                #[allow(unsafe_code)]
                // SAFETY: SSE is part of the x86-64 baseline; `dst` holds `W` floats and is
                // 16-byte aligned (checked), so each quarter `4q..4q + 4` is an aligned,
                // in-bounds, exclusively borrowed target; the source is `self.0[4q..]`.
                unsafe {
                    _mm_stream_ps(
                        dst.as_mut_ptr().add(4 * q),
                        _mm_loadu_ps(self.0.as_ptr().add(4 * q)),
                    );
                }
            }
            return;
        }
        dst.copy_from_slice(&self.0);
    }
    #[inline(always)]
    fn any_nonzero(self) -> bool {
        // A non-short-circuiting OR over the lanes: one compare and one mask test.
        let mut any = false;
        for k in 0..W {
            any |= self.0[k] != 0.0;
        }
        any
    }
    #[inline(always)]
    fn nonzero_mask(self) -> u32 {
        // One compare and one `movmskps` where the loop vectorises.
        let mut mask = 0;
        for k in 0..W {
            mask |= u32::from(self.0[k] != 0.0) << k;
        }
        mask
    }
    type Portable = Self;
    #[inline(always)]
    fn portable(self) -> Self {
        self
    }
}

impl Lane for wide::f32x8 {
    // `wide` fuses exactly when FMA is enabled at compile time.
    const FUSES: bool = cfg!(target_feature = "fma");
    #[inline(always)]
    fn splat(x: f32) -> Self {
        wide::f32x8::splat(x)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        self.fast_min(o)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        self.fast_max(o)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        wide::f32x8::abs(self)
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        // `wide` fuses exactly when FMA is enabled at compile time, and never calls `fmaf`.
        wide::f32x8::mul_add(self, b, c)
    }
    #[inline(always)]
    fn select_nonneg(self, if_nonneg: Self, otherwise: Self) -> Self {
        self.simd_ge(wide::f32x8::ZERO).select(if_nonneg, otherwise)
    }
}

impl LaneArray for wide::f32x8 {
    const WIDTH: usize = 8;
    type One = F32s<1, { cfg!(target_feature = "fma") }>;
    #[inline(always)]
    fn get(&self, k: usize) -> f32 {
        self.as_array()[k]
    }
    #[inline(always)]
    fn set(&mut self, k: usize, x: f32) {
        self.as_mut_array()[k] = x;
    }
    #[inline(always)]
    fn load(src: &[f32]) -> Self {
        let mut r = [0.0; 8];
        r.copy_from_slice(&src[..8]);
        wide::f32x8::new(r)
    }
    #[inline(always)]
    fn store(self, dst: &mut [f32]) {
        dst[..8].copy_from_slice(self.as_array());
    }
    #[inline(always)]
    fn store_streaming(self, dst: &mut [f32]) {
        F32s::<8, false>(self.to_array()).store_streaming(dst);
    }
    #[inline(always)]
    fn any_nonzero(self) -> bool {
        self.simd_ne(wide::f32x8::ZERO).any()
    }
    #[inline(always)]
    fn nonzero_mask(self) -> u32 {
        self.simd_ne(wide::f32x8::ZERO).to_bitmask()
    }
    // Its instructions are fixed at compile time: any code may hold it.
    type Portable = Self;
    #[inline(always)]
    fn portable(self) -> Self {
        self
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use avx::Avx8;

/// The AVX2 backend's lanes as explicit 256-bit vectors.
///
/// [`F32s`] leaves the vectors to LLVM's SLP vectoriser, which sometimes groups a
/// kernel's scalarised lanes along the wrong dimension (a quaternion's nine matrix entries
/// built in 128-bit and scalar pieces through the stack, then reloaded as one 256-bit
/// vector: a store-forwarding stall). With `__m256` every operation is one instruction on
/// one register from the start, whatever else the loop holds.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)] // the AVX intrinsics, under the invariant of `Avx8`
mod avx {
    use core::arch::x86_64::{
        __m256, _CMP_GE_OQ, _CMP_NEQ_UQ, _mm_stream_ps, _mm256_add_ps, _mm256_andnot_ps,
        _mm256_blendv_ps, _mm256_castps256_ps128, _mm256_cmp_ps, _mm256_extractf128_ps,
        _mm256_fmadd_ps, _mm256_loadu_ps, _mm256_max_ps, _mm256_min_ps, _mm256_movemask_ps,
        _mm256_mul_ps, _mm256_set1_ps, _mm256_setzero_ps, _mm256_storeu_ps, _mm256_sub_ps,
        _mm256_xor_ps,
    };
    use core::ops::{Add, Mul, Neg, Sub};

    use super::{F32s, LaneArray};
    use crate::lane::Lane;

    /// Eight `f32` lanes in one AVX register; `mul_add` fuses iff `FMA`. Bit for bit the
    /// arithmetic of `F32s<8, FMA>`: `vminps`/`vmaxps` are the compare-selects of
    /// [`Lane::min`]/[`Lane::max`], and nothing else is reordered or contracted.
    ///
    /// Invariant, on which every intrinsic below relies: a value of this type exists only
    /// on a CPU that has AVX2 and FMA. The type is private to the crate and only
    /// `dispatch` names it, as the lanes of the `run_avx2` wrapper that it calls once
    /// `Backend::Avx2` is known to be supported. Inlined there, each operation is one
    /// instruction; code that runs out of line (the debug build's `lanes`) is compiled
    /// without the features and calls the intrinsics instead, which is slow but sound on
    /// such a CPU. Out-of-line code on a hot path takes [`LaneArray::Portable`] lanes.
    #[derive(Clone, Copy, Debug)]
    #[repr(transparent)]
    pub(crate) struct Avx8<const FMA: bool>(__m256);

    impl<const FMA: bool> Avx8<FMA> {
        #[inline(always)]
        fn to_array(self) -> [f32; 8] {
            // SAFETY: `__m256` and `[f32; 8]` have the same size and every bit pattern is
            // valid for both.
            unsafe { core::mem::transmute::<__m256, [f32; 8]>(self.0) }
        }
        #[inline(always)]
        fn from_array(a: [f32; 8]) -> Self {
            // SAFETY: as in `to_array`.
            Avx8(unsafe { core::mem::transmute::<[f32; 8], __m256>(a) })
        }
    }

    /// One AVX operation on the lanes: the body is an intrinsic call, sound by the
    /// invariant of [`Avx8`] (the CPU has AVX2 and FMA).
    macro_rules! avx {
        ($e:expr) => {
            // SAFETY: by the invariant of `Avx8`, the CPU has AVX2 and FMA; the
            // intrinsic touches no memory.
            unsafe { $e }
        };
    }

    impl<const FMA: bool> Add for Avx8<FMA> {
        type Output = Self;
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            Avx8(avx!(_mm256_add_ps(self.0, o.0)))
        }
    }

    impl<const FMA: bool> Sub for Avx8<FMA> {
        type Output = Self;
        #[inline(always)]
        fn sub(self, o: Self) -> Self {
            Avx8(avx!(_mm256_sub_ps(self.0, o.0)))
        }
    }

    impl<const FMA: bool> Mul for Avx8<FMA> {
        type Output = Self;
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            Avx8(avx!(_mm256_mul_ps(self.0, o.0)))
        }
    }

    impl<const FMA: bool> Neg for Avx8<FMA> {
        type Output = Self;
        #[inline(always)]
        fn neg(self) -> Self {
            Avx8(avx!(_mm256_xor_ps(self.0, _mm256_set1_ps(-0.0))))
        }
    }

    impl<const FMA: bool> Lane for Avx8<FMA> {
        const FUSES: bool = FMA;
        #[inline(always)]
        fn splat(x: f32) -> Self {
            Avx8(avx!(_mm256_set1_ps(x)))
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            // `vminps a, b` is `a < b ? a : b`, lane by lane.
            Avx8(avx!(_mm256_min_ps(self.0, o.0)))
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            Avx8(avx!(_mm256_max_ps(self.0, o.0)))
        }
        #[inline(always)]
        fn abs(self) -> Self {
            Avx8(avx!(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0)))
        }
        #[inline(always)]
        fn mul_add(self, b: Self, c: Self) -> Self {
            if FMA {
                Avx8(avx!(_mm256_fmadd_ps(self.0, b.0, c.0)))
            } else {
                self * b + c
            }
        }
        #[inline(always)]
        fn select_nonneg(self, if_nonneg: Self, otherwise: Self) -> Self {
            // `self >= 0`, false for NaN (ordered, quiet).
            let nonneg = avx!(_mm256_cmp_ps::<_CMP_GE_OQ>(self.0, _mm256_setzero_ps()));
            Avx8(avx!(_mm256_blendv_ps(otherwise.0, if_nonneg.0, nonneg)))
        }
    }

    impl<const FMA: bool> LaneArray for Avx8<FMA> {
        const WIDTH: usize = 8;
        type One = F32s<1, FMA>;
        #[inline(always)]
        fn get(&self, k: usize) -> f32 {
            self.to_array()[k]
        }
        #[inline(always)]
        fn set(&mut self, k: usize, x: f32) {
            let mut a = self.to_array();
            a[k] = x;
            *self = Self::from_array(a);
        }
        #[inline(always)]
        fn load(src: &[f32]) -> Self {
            let src = &src[..8];
            // SAFETY: `src` holds eight floats (checked above); the load is unaligned, and
            // AVX is present by the invariant of `Avx8`.
            Avx8(unsafe { _mm256_loadu_ps(src.as_ptr()) })
        }
        #[inline(always)]
        fn store(self, dst: &mut [f32]) {
            let dst = &mut dst[..8];
            // SAFETY: `dst` holds eight exclusively borrowed floats (checked above); the
            // store is unaligned, and AVX is present by the invariant of `Avx8`.
            unsafe { _mm256_storeu_ps(dst.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn store_streaming(self, dst: &mut [f32]) {
            let dst = &mut dst[..8];
            if dst.as_ptr().align_offset(16) != 0 {
                return self.store(dst);
            }
            let (low, high) = avx!((
                _mm256_castps256_ps128(self.0),
                _mm256_extractf128_ps::<1>(self.0)
            ));
            // SAFETY: `dst` holds eight exclusively borrowed floats and is 16-byte aligned
            // (both checked above), so `dst[0..4]` and `dst[4..8]` are aligned, in-bounds
            // targets; SSE is part of the x86-64 baseline.
            unsafe {
                _mm_stream_ps(dst.as_mut_ptr(), low);
                _mm_stream_ps(dst.as_mut_ptr().add(4), high);
            }
        }
        #[inline(always)]
        fn any_nonzero(self) -> bool {
            self.nonzero_mask() != 0
        }
        #[inline(always)]
        fn nonzero_mask(self) -> u32 {
            // `self != 0`, true for NaN (unordered, quiet).
            let nonzero = avx!(_mm256_cmp_ps::<_CMP_NEQ_UQ>(self.0, _mm256_setzero_ps()));
            avx!(_mm256_movemask_ps(nonzero)) as u32
        }
        type Portable = F32s<8, FMA>;
        #[inline(always)]
        fn portable(self) -> F32s<8, FMA> {
            F32s(self.to_array())
        }
    }
}
