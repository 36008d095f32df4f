//! Lane arrays: the lane types of the batch path.
//!
//! [`F32s`] is plain array code: every operation is a loop over `W` floats that LLVM
//! vectorises for whatever target features the enclosing function enables, which is what
//! lets one generic kernel be compiled for SSE2, AVX2+FMA and AVX-512 and be chosen at
//! run time. `wide::f32x8` is the alternative whose code is fixed at compile time.

use core::ops::{Add, Mul, Neg, Sub};

use crate::lane::Lane;

/// A lane type whose lanes can be built, read and written one at a time.
pub(crate) trait LaneArray: Lane {
    /// The number of lanes.
    const WIDTH: usize;
    /// Lanes `f(0), f(1), ..., f(WIDTH - 1)`.
    fn from_fn(f: impl FnMut(usize) -> f32) -> Self;
    /// Lane `k`.
    fn get(&self, k: usize) -> f32;
    /// Sets lane `k`.
    fn set(&mut self, k: usize, x: f32);
    /// Bit `k` set where lane `k` of `self <= other` (clear where either is NaN).
    fn le_bits(self, other: Self) -> u32;
}

impl LaneArray for f32 {
    const WIDTH: usize = 1;
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> f32) -> Self {
        f(0)
    }
    #[inline(always)]
    fn get(&self, _: usize) -> f32 {
        *self
    }
    #[inline(always)]
    fn set(&mut self, _: usize, x: f32) {
        *self = x;
    }
    #[inline(always)]
    fn le_bits(self, other: Self) -> u32 {
        u32::from(self <= other)
    }
}

/// `W` lanes of `f32` in a plain array; `mul_add` fuses iff `FMA` (set only where the
/// enclosing function enables the FMA instructions).
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub(crate) struct F32s<const W: usize, const FMA: bool>(pub [f32; W]);

impl<const W: usize, const FMA: bool> F32s<W, FMA> {
    #[inline(always)]
    fn zip(self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        F32s(core::array::from_fn(|k| f(self.0[k], o.0[k])))
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
        F32s(self.0.map(|a| -a))
    }
}

impl<const W: usize, const FMA: bool> Lane for F32s<W, FMA> {
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
        F32s(self.0.map(f32::abs))
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        if FMA {
            F32s(core::array::from_fn(|k| self.0[k].mul_add(b.0[k], c.0[k])))
        } else {
            self * b + c
        }
    }
    #[inline(always)]
    fn select_nonneg(self, if_nonneg: Self, otherwise: Self) -> Self {
        F32s(core::array::from_fn(|k| {
            if self.0[k] >= 0.0 {
                if_nonneg.0[k]
            } else {
                otherwise.0[k]
            }
        }))
    }
}

impl<const W: usize, const FMA: bool> LaneArray for F32s<W, FMA> {
    const WIDTH: usize = W;
    #[inline(always)]
    fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
        F32s(core::array::from_fn(f))
    }
    #[inline(always)]
    fn get(&self, k: usize) -> f32 {
        self.0[k]
    }
    #[inline(always)]
    fn set(&mut self, k: usize, x: f32) {
        self.0[k] = x;
    }
    #[inline(always)]
    fn le_bits(self, other: Self) -> u32 {
        (0..W).fold(0, |bits, k| bits | u32::from(self.0[k] <= other.0[k]) << k)
    }
}

impl Lane for wide::f32x8 {
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
    #[inline(always)]
    fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
        wide::f32x8::new(core::array::from_fn(f))
    }
    #[inline(always)]
    fn get(&self, k: usize) -> f32 {
        self.as_array()[k]
    }
    #[inline(always)]
    fn set(&mut self, k: usize, x: f32) {
        self.as_mut_array()[k] = x;
    }
    #[inline(always)]
    fn le_bits(self, other: Self) -> u32 {
        self.simd_le(other).to_bitmask()
    }
}
