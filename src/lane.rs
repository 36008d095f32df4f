//! Lane types: the element-wise float arithmetic every kernel is written over.
//!
//! A kernel is written once, generic over a [`Lane`]. Plain `f32` is a lane of width 1
//! and is the scalar reference. glam's `Vec3A` is a lane of width 3 whose lanes are the
//! axes of one box. [`Vector`] stacks `N` lanes into the components of an `N`-vector,
//! so `Vector<f32, 3>` is one box on the scalar path and `Vector<[f32; 8], 3>`-like lane
//! types are eight boxes at once.

use core::ops::{Add, Mul, Neg, Sub};

use glam::Vec3A;

/// Element-wise IEEE-754 single-precision arithmetic over some number of lanes.
///
/// `mul_add` is fused only where the lane type says so at compile time: a default
/// build never calls `fmaf`.
pub trait Lane:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Neg<Output = Self>
{
    /// True when [`Lane::mul_add`] rounds once.
    const FUSES: bool = false;
    /// Every lane set to `x`.
    fn splat(x: f32) -> Self;
    /// Lane-wise minimum as `minps` computes it: `self < other ? self : other`, so equal
    /// zeros give `other` (NaN handling varies by lane type; no caller depends on it).
    fn min(self, other: Self) -> Self;
    /// Lane-wise maximum as `maxps` computes it: `self > other ? self : other`.
    fn max(self, other: Self) -> Self;
    /// Lane-wise absolute value (exact: clears the sign bit).
    fn abs(self) -> Self;
    /// `self * b + c`, with one rounding when the lane type fuses, two otherwise.
    fn mul_add(self, b: Self, c: Self) -> Self;
    /// Lane-wise `if self >= 0 { if_nonneg } else { otherwise }`.
    fn select_nonneg(self, if_nonneg: Self, otherwise: Self) -> Self;

    /// One sign-select step: `self·(self >= 0 ? lo : hi)` added to `min` and
    /// `self·(self >= 0 ? hi : lo)` added to `max` (for `lo <= hi`).
    ///
    /// Unfused, the smaller and the larger of the rounded products `self·lo` and `self·hi`
    /// (rounding is monotone, so they are the products the sign selects, up to the sign of
    /// a zero): two operations in place of a compare and two selects, and SSE2 has no
    /// blend. Every unfused lane type computes this, so all give the same bits. A NaN
    /// product cannot hide a bad map: a NaN entry makes both products NaN, an infinite one
    /// the other product infinite or NaN, and a non-finite face fails the caller's check;
    /// a NaN box fails its own check whatever the faces. Where the lane type
    /// [fuses](Lane::FUSES), the factor is selected by the sign and each face is one fused
    /// multiply-add instead.
    #[inline(always)]
    fn add_signed_products(self, lo: Self, hi: Self, min: Self, max: Self) -> (Self, Self) {
        if Self::FUSES {
            (
                self.mul_add(self.select_nonneg(lo, hi), min),
                self.mul_add(self.select_nonneg(hi, lo), max),
            )
        } else {
            let (p, q) = (self * lo, self * hi);
            (min + p.min(q), max + p.max(q))
        }
    }
}

/// A lane type whose lanes are the components of a vector, able to broadcast one of them.
pub trait Axes: Lane {
    /// The vector with every component equal to component `j` of `self`.
    fn axis(self, j: usize) -> Self;
    /// Components `(y, x, x)` of `self`, as glam's `Vec3A::yxx`.
    fn yxx(self) -> Self;
    /// Components `(z, z, y)` of `self`, as glam's `Vec3A::zzy`.
    fn zzy(self) -> Self;
    /// Component `x` of `x`, `y` of `y` and `z` of `z`.
    fn merge(x: Self, y: Self, z: Self) -> Self;
}

impl Lane for f32 {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        // Compare-select, as `minps` does: equal operands (`±0`) give `other`, so every
        // lane type picks the same zero.
        if self < other { self } else { other }
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        if self > other { self } else { other }
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        // Deliberately unfused: `f32::mul_add` is a libm call without hardware FMA.
        self * b + c
    }
    #[inline(always)]
    fn select_nonneg(self, if_nonneg: Self, otherwise: Self) -> Self {
        // Branch-free: a sign test on random rotations mispredicts half the time.
        let keep = u32::from(self >= 0.0).wrapping_neg();
        f32::from_bits(if_nonneg.to_bits() & keep | otherwise.to_bits() & !keep)
    }
}

impl Lane for Vec3A {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        Vec3A::splat(x)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        Vec3A::min(self, other)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        Vec3A::max(self, other)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Vec3A::abs(self)
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        // Never fused, whatever the build's target features: the single-box kernel and the
        // AoS loop give the scalar reference's bits, which deterministic mode promises.
        self * b + c
    }
    #[inline(always)]
    fn select_nonneg(self, if_nonneg: Self, otherwise: Self) -> Self {
        Vec3A::select(self.cmpge(Vec3A::ZERO), if_nonneg, otherwise)
    }
}

impl Axes for Vec3A {
    #[inline(always)]
    fn axis(self, j: usize) -> Self {
        match j {
            0 => Vec3A::splat(self.x),
            1 => Vec3A::splat(self.y),
            _ => Vec3A::splat(self.z),
        }
    }
    #[inline(always)]
    fn yxx(self) -> Self {
        glam::Vec3Swizzles::yxx(self)
    }
    #[inline(always)]
    fn zzy(self) -> Self {
        glam::Vec3Swizzles::zzy(self)
    }
    #[inline(always)]
    fn merge(x: Self, y: Self, z: Self) -> Self {
        let keep_x = glam::BVec3A::new(true, false, false);
        let keep_y = glam::BVec3A::new(false, true, false);
        Vec3A::select(keep_x, x, Vec3A::select(keep_y, y, z))
    }
}

/// An `N`-vector whose components are lanes `L`: component `i` of box lane `k` is
/// `self.0[i]` lane `k`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vector<L, const N: usize>(pub [L; N]);

impl<L: Lane, const N: usize> Vector<L, N> {
    // Indexed loops rather than `array::from_fn`/`map`: their closures and internal
    // adapters are not always inlined into a hot loop, and an outlined call there stops
    // LLVM from vectorising the kernel.
    #[inline(always)]
    fn map2(mut self, o: Self, f: impl Fn(L, L) -> L) -> Self {
        for i in 0..N {
            self.0[i] = f(self.0[i], o.0[i]);
        }
        self
    }

    #[inline(always)]
    fn map1(mut self, f: impl Fn(L) -> L) -> Self {
        for i in 0..N {
            self.0[i] = f(self.0[i]);
        }
        self
    }
}

impl<L: Lane, const N: usize> Add for Vector<L, N> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        self.map2(o, |a, b| a + b)
    }
}

impl<L: Lane, const N: usize> Sub for Vector<L, N> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        self.map2(o, |a, b| a - b)
    }
}

impl<L: Lane, const N: usize> Mul for Vector<L, N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        self.map2(o, |a, b| a * b)
    }
}

impl<L: Lane, const N: usize> Neg for Vector<L, N> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self.map1(|a| -a)
    }
}

impl<L: Lane, const N: usize> Lane for Vector<L, N> {
    const FUSES: bool = L::FUSES;
    #[inline(always)]
    fn splat(x: f32) -> Self {
        Vector([L::splat(x); N])
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        self.map2(other, L::min)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        self.map2(other, L::max)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.map1(L::abs)
    }
    #[inline(always)]
    fn mul_add(self, b: Self, mut c: Self) -> Self {
        for i in 0..N {
            c.0[i] = self.0[i].mul_add(b.0[i], c.0[i]);
        }
        c
    }
    #[inline(always)]
    fn select_nonneg(self, if_nonneg: Self, mut otherwise: Self) -> Self {
        for i in 0..N {
            otherwise.0[i] = self.0[i].select_nonneg(if_nonneg.0[i], otherwise.0[i]);
        }
        otherwise
    }
}

/// The swizzles name components of a 3-vector; at other sizes they take the components of
/// the same names cyclically.
impl<L: Lane, const N: usize> Axes for Vector<L, N> {
    #[inline(always)]
    fn axis(self, j: usize) -> Self {
        Vector([self.0[j]; N])
    }
    #[inline(always)]
    fn yxx(self) -> Self {
        Vector(core::array::from_fn(|i| self.0[[1, 0, 0][i % 3] % N]))
    }
    #[inline(always)]
    fn zzy(self) -> Self {
        Vector(core::array::from_fn(|i| self.0[[2, 2, 1][i % 3] % N]))
    }
    #[inline(always)]
    fn merge(x: Self, y: Self, z: Self) -> Self {
        Vector(core::array::from_fn(|i| [x, y, z][i % 3].0[i]))
    }
}
