//! Numeric primitives: powers of two, Knuth's TwoSum, directed rounding of `f64` to `f32`,
//! and the float functions `core` lacks: the standard library's where it is linked (feature
//! `std`), `libm`'s otherwise. Both are correctly rounded where the callers need it
//! (`sqrt`, `mul_add`, `ceil`, `round`); `hypot` and `sin_cos` feed no bound.

/// `2^k` for `-1022 <= k <= 1023`, exactly. Always inlined: at a run-time call site with a
/// constant `k` it folds to a constant (out of line, every fat box of a broadphase update
/// paid a call for its `2^-22`).
#[inline(always)]
pub(crate) const fn pow2(k: i32) -> f64 {
    assert!(-1022 <= k && k <= 1023);
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// The smallest power of two not below `x`, for a positive normal `x`, exactly.
pub(crate) fn pow2_at_least(x: f64) -> f64 {
    let below = f64::from_bits(x.to_bits() & (0x7ff << 52));
    if below < x { below * 2.0 } else { below }
}

// Directed rounding and exact sums: the one home of each.

/// Knuth's TwoSum in `f64`: `(s, e)` with `s = fl(a + b)` and `s + e = a + b` exactly.
#[inline]
pub(crate) fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let b_virtual = s - a;
    let a_virtual = s - b_virtual;
    (s, (a - a_virtual) + (b - b_virtual))
}

/// The largest `f32` not above `x` (`-inf` below the range): directed rounding of `f64` to
/// `f32`.
#[inline]
pub(crate) fn round_down(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) > x { y.next_down() } else { y }
}

/// The smallest `f32` not below `x` (`+inf` above the range).
#[inline]
pub(crate) fn round_up(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x { y.next_up() } else { y }
}

macro_rules! forward {
    ($($(#[$doc:meta])* fn $name:ident($($arg:ident: $t:ty),*) -> $r:ty = $libm:ident;)*) => {$(
        $(#[$doc])*
        #[inline(always)]
        pub(crate) fn $name($($arg: $t),*) -> $r {
            #[cfg(feature = "std")]
            return forward!(@std $name $($arg),*);
            #[cfg(not(feature = "std"))]
            return libm::$libm($($arg),*);
        }
    )*};
    (@std $name:ident $first:ident $(, $rest:ident)*) => { $first.$name($($rest),*) };
}

forward! {
    /// The correctly rounded square root.
    fn sqrt(x: f64) -> f64 = sqrt;
    /// The smallest integer not below `x`.
    fn ceil(x: f64) -> f64 = ceil;
    /// `x` rounded to the nearest integer, ties away from zero.
    fn round(x: f64) -> f64 = round;
    /// `sqrt(x² + y²)` without undue overflow.
    fn hypot(x: f64, y: f64) -> f64 = hypot;
    /// `a·b + c` with one rounding.
    fn mul_add(a: f32, b: f32, c: f32) -> f32 = fmaf;
}

/// The sine and cosine of `x` radians.
#[inline]
pub(crate) fn sin_cos(x: f32) -> (f32, f32) {
    #[cfg(feature = "std")]
    return x.sin_cos();
    #[cfg(not(feature = "std"))]
    return libm::sincosf(x);
}

/// A test's fixed-seed stream of uniform `f64` values in `[-1, 1)`: xorshift64 (13, 7, 17),
/// its top 53 bits.
#[cfg(test)]
pub(crate) fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}
