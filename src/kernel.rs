//! The transform kernels, each written once over a lane type.
//!
//! Every kernel maps a box `[lo, hi]` through `x ↦ M x + t`, where `M` is given by its
//! columns. The kernels are pure round-to-nearest arithmetic: they assume a finite,
//! non-empty box and a finite matrix, and their callers check that the result is finite.
//! Everything outside that domain (empty, unbounded or NaN boxes, overflow, non-finite
//! matrices) is answered by [`crate::extended`].

use core::ops::{Add, Mul, Sub};

use glam::Vec3A;

use crate::lane::{Axes, Lane, Vector};
use crate::method::{Method, REACH_FLOOR, UNIT_ROUNDOFF};

/// A box through a map in lanes: the kernel of one transform class.
pub trait MapKernel<V> {
    /// The fast-path kernel: pure round-to-nearest arithmetic, padded outward when
    /// asked; its callers check that the box is non-empty and the result finite.
    fn transform(&self, lo: V, hi: V, method: Method, outward: bool) -> (V, V);
}

impl AffineLanes<Vec3A, 3> {
    /// `W` maps side by side, every field `join` of the maps' own: the affine class's
    /// [`Transform3::join`](crate::Transform3).
    #[inline(always)]
    pub(crate) fn join<P: Axes, const W: usize>(
        maps: &[Self; W],
        join: impl Fn([Vec3A; W]) -> P,
    ) -> AffineLanes<P, 3> {
        AffineLanes {
            cols: join_cols(maps, |m| &m.cols, &join),
            t: join(gather(|k| maps[k].t)),
        }
    }
}

/// `[f(0), …, f(W − 1)]`, always inlined: the AoS loop builds its groups with this rather
/// than `core::array::from_fn` or `map`, which were compiled out of line, without the
/// dispatch wrapper's features (`docs/decisions.md`, "The AoS loop's groups built by
/// `gather`").
#[inline(always)]
pub(crate) fn gather<const W: usize, X: Copy>(mut f: impl FnMut(usize) -> X) -> [X; W] {
    let mut out = [f(0); W];
    for (k, x) in out.iter_mut().enumerate().skip(1) {
        *x = f(k);
    }
    out
}

/// The three columns of `W` maps side by side, `join` of the maps' own each: the columns
/// of every affine and quaternion map's `join`.
#[inline(always)]
pub(crate) fn join_cols<M, P, const W: usize>(
    maps: &[M; W],
    cols: impl Fn(&M) -> &[Vec3A; 3],
    join: impl Fn([Vec3A; W]) -> P,
) -> [P; 3] {
    let col = |j: usize| join(gather(|k| cols(&maps[k])[j]));
    [col(0), col(1), col(2)]
}

/// An affine map `x ↦ M x + t` in lanes: `cols[j]` is column `j` of `M`.
#[derive(Clone, Copy, Debug)]
pub struct AffineLanes<V, const N: usize> {
    pub cols: [V; N],
    pub t: V,
}

/// The naive baseline: transform all `2^N` corners and take their min and max.
///
/// A corner whose sum overflowed to `±inf` (or to NaN, as `inf − inf`) could be hidden by
/// the min/max reduction, which may drop NaN operands. The running sum of all corners is
/// non-finite whenever any corner is, so it poisons the result to NaN and the caller's
/// finiteness check routes the box to the extended path.
#[inline(always)]
pub(crate) fn naive<V: Axes, const N: usize>(a: &AffineLanes<V, N>, lo: V, hi: V) -> (V, V) {
    let mut min = V::splat(f32::INFINITY);
    let mut max = V::splat(f32::NEG_INFINITY);
    let mut corner_sum = V::splat(0.0);
    for corner in 0..1usize << N {
        let mut p = a.t;
        for j in 0..N {
            let x = if corner >> j & 1 == 0 { lo } else { hi };
            p = a.cols[j].mul_add(x.axis(j), p);
        }
        min = min.min(p);
        max = max.max(p);
        corner_sum = corner_sum + p;
    }
    let poison = corner_sum * V::splat(0.0); // 0 when every corner is finite, else NaN
    (min + poison, max + poison)
}

/// Arvo's abs-matrix method in doubled form: `2c = lo + hi`, `2e = hi − lo`,
/// `2c' = M·2c + 2t`, `2e' = |M|·2e`, faces `(2c' ∓ 2e') / 2`; padded outward by
/// `k·u·(S + 2^-80)` when `pad_factor` is `Some(k)`.
///
/// Halving last keeps subnormal boxes exact up to the final rounding (halving first
/// would flush the half-width of a one-ulp subnormal box to zero). Doubling can overflow
/// for faces beyond `f32::MAX / 2`; the result is then non-finite and the caller routes the
/// box to the extended path.
///
/// Error: `2c` and `2e` round once each, the dot products of `N` terms (onto `2t`) at most
/// `N + 1` times, the final difference once; halving is exact above the subnormal range
/// and costs at most `2^-150` below it. With `|c_j| + e_j = max(|lo_j|, |hi_j|)` the face
/// error is at most `γ(N+3)·S + TINY_ERROR`.
///
/// The pad reuses what the method has, `2S' = |2t| + 2^-79 + |M|·(|2c| + 2e)`, applied to
/// `2c' ∓ 2e'` before the halving:
/// - where the lanes fuse, `N` more multiply-adds on the `|M|` of `2e'`. The computed
///   `|2c| + 2e` is at least `(1 − u)²·2·max(|lo|, |hi|)` and the dot product of positive
///   terms loses at most `γ(N + 1)`;
/// - unfused, `|M|·|2c|` is the sum of the centre's own rounded products `|m_ij·2c_j|`
///   (the absolute value of a rounded product is the rounded product of the absolute
///   values), and `|M|·2e` is `2e'` itself: `(|2t| + 2^-79) + Σ_j |m_ij·2c_j| + 2e'_i`,
///   `N + 2` additions and no multiplication. A term `|m_ij·2c_j|` rounds twice (`2c`,
///   the product) and meets `N + 1` additions; a term of `2e'` rounds twice and meets at
///   most `N` (`N − 1` inside `2e'`, then one);
///
/// so either way the computed `2S'` is at least `2S'·(1 − γ(N + 3))` (less `2N·2^-150` if
/// products underflow, which the `2^-79` floor covers many times over), and the argument of
/// [`outward_pad`] then applies with doubled terms.
/// The doubled pad is at least `2^-79·k·u >= 2^-101` (`k >= 7`), so on normal-range input
/// `2c' ∓ 2e' ∓ pad` is a multiple of `2^-125` and its half a multiple of `2^-126`: zero
/// or normal (see [`outward_pad`]).
#[inline(always)]
pub(crate) fn abs_matrix<V: Axes, const N: usize>(
    a: &AffineLanes<V, N>,
    lo: V,
    hi: V,
    pad_factor: Option<u32>,
) -> (V, V) {
    let center2 = lo + hi;
    let extent2 = hi - lo;
    let t2 = a.t + a.t;
    let mut world_center2 = t2;
    // Unfused, the centre's products, which the pad reuses.
    let mut products = [V::splat(0.0); N];
    let mut world_extent2 = a.cols[0].abs() * extent2.axis(0);
    for (j, product) in products.iter_mut().enumerate() {
        if V::FUSES {
            world_center2 = a.cols[j].mul_add(center2.axis(j), world_center2);
        } else {
            *product = a.cols[j] * center2.axis(j);
            world_center2 = *product + world_center2;
        }
        if j > 0 {
            world_extent2 = a.cols[j].abs().mul_add(extent2.axis(j), world_extent2);
        }
    }
    let (mut min2, mut max2) = (world_center2 - world_extent2, world_center2 + world_extent2);
    if let Some(k) = pad_factor {
        let mut magnitude2 = t2.abs() + V::splat(2.0 * REACH_FLOOR);
        if V::FUSES {
            let reach2 = center2.abs() + extent2;
            for j in 0..N {
                magnitude2 = a.cols[j].abs().mul_add(reach2.axis(j), magnitude2);
            }
        } else {
            for p in products {
                magnitude2 = magnitude2 + p.abs();
            }
            magnitude2 = magnitude2 + world_extent2;
        }
        let pad2 = magnitude2 * V::splat(k as f32 * UNIT_ROUNDOFF);
        (min2, max2) = (min2 - pad2, max2 + pad2);
    }
    let half = V::splat(0.5);
    (min2 * half, max2 * half)
}

/// Sign-select: face `i` of the minimum is `t_i + sum_j m_ij * (m_ij >= 0 ? lo_j : hi_j)`,
/// and the maximum takes the other face. No center/extent round trip.
///
/// Each step is [`Lane::add_signed_products`]: unfused, the smaller and the larger of the
/// two products, the same operations in every lane type (so the single-box kernel gives
/// the scalar reference's bits); fused, a sign test, two selects and two multiply-adds.
///
/// Error: `N` products and `N` additions per face, `γ(N+1)·S + TINY_ERROR`.
#[inline(always)]
pub(crate) fn sign_select<V: Axes, const N: usize>(a: &AffineLanes<V, N>, lo: V, hi: V) -> (V, V) {
    let (mut min, mut max) = (a.t, a.t);
    for j in 0..N {
        (min, max) = a.cols[j].add_signed_products(lo.axis(j), hi.axis(j), min, max);
    }
    (min, max)
}

/// Eberly's sign branch for a 2D rotation `[[c, −s], [s, c]]` plus translation.
///
/// The signs of `cos` and `sin` (two comparisons) pick one of four cases, each fixing which
/// face of the box minimises every term; the faces are then 8 multiplications and 8
/// additions. With `L = f32` each `select_nonneg` is that branch; in wider lanes it is a
/// blend. Same error as [`sign_select`] in 2D: `γ(3)·S + TINY_ERROR`.
#[inline(always)]
pub(crate) fn sign_branch_rigid2<L: Lane>(
    cos: L,
    sin: L,
    t: [L; 2],
    lo: [L; 2],
    hi: [L; 2],
) -> ([L; 2], [L; 2]) {
    let [lx, ly] = lo;
    let [hx, hy] = hi;
    // Faces that minimise c·x, c·y, s·x and −s·y.
    let (cx_min, cx_max) = (cos.select_nonneg(lx, hx), cos.select_nonneg(hx, lx));
    let (cy_min, cy_max) = (cos.select_nonneg(ly, hy), cos.select_nonneg(hy, ly));
    let (sx_min, sx_max) = (sin.select_nonneg(lx, hx), sin.select_nonneg(hx, lx));
    let (sy_min, sy_max) = (sin.select_nonneg(hy, ly), sin.select_nonneg(ly, hy));
    let neg_sin = -sin;
    (
        [
            cos.mul_add(cx_min, neg_sin.mul_add(sy_min, t[0])),
            sin.mul_add(sx_min, cos.mul_add(cy_min, t[1])),
        ],
        [
            cos.mul_add(cx_max, neg_sin.mul_add(sy_max, t[0])),
            sin.mul_add(sx_max, cos.mul_add(cy_max, t[1])),
        ],
    )
}

/// The Outward pad `k·u·(S + 2^-80)`, with `S_i = |t_i| + sum_j |m_ij|·max(|lo_j|, |hi_j|)`
/// computed in the same lanes (`max(hi, −lo)` equals `max(|lo|, |hi|)` when `lo <= hi`).
///
/// Why `k = n + 2` suffices for a Nearest bound `γ(n)·S + TINY_ERROR`: the computed
/// `S + 2^-80` (positive terms only) is at least `(S + 2^-80)·(1 − γ(N+1))` (less `N·2^-150`
/// if products underflow), the pad's own product rounds once, and the padded face
/// `fl(face ∓ pad)` rounds once more by at most `u·(|face| + pad)` (and is exact if
/// subnormal). Hence `pad − error − rounding >= (k − n − 1)·u·S − O(u²·S) > 0` for the
/// relative part, and the absolute part `k·u·2^-80 >= 2^-102` covers `TINY_ERROR = 2^-148`
/// and the underflow of `S` many times over.
///
/// Why nothing is subnormal on normal-range input (every nonzero value multiplied at least
/// `2^-32`; see [`crate::Method`]): such a value is a multiple of `2^-55`, so every exact
/// product of two is a multiple of `2^-110`, and so is every exact sum of those. Rounding
/// keeps a multiple of `2^-110` one (above `2^-87` the `f32` spacing is a multiple of
/// `2^-110`; below, the value is representable), so every face is zero or at least
/// `2^-110`. The pad is at least `k·u·2^-80 >= 2^-102`, so its spacing is a multiple of
/// `2^-125` and so is `face ∓ pad`: zero or normal. The constant `2^-80` itself is normal,
/// and FTZ and DAZ change no bit of the result.
#[inline(always)]
pub(crate) fn outward_pad<V: Axes, const N: usize>(
    a: &AffineLanes<V, N>,
    lo: V,
    hi: V,
    k: u32,
) -> V {
    let magnitude = hi.max(-lo);
    let mut s = a.t.abs() + V::splat(REACH_FLOOR);
    for j in 0..N {
        s = a.cols[j].abs().mul_add(magnitude.axis(j), s);
    }
    s * V::splat(k as f32 * UNIT_ROUNDOFF)
}

/// One box through one method, round to nearest.
#[inline(always)]
pub(crate) fn bound<V: Axes, const N: usize>(
    a: &AffineLanes<V, N>,
    lo: V,
    hi: V,
    method: Method,
) -> (V, V) {
    match method {
        Method::Naive => naive(a, lo, hi),
        Method::AbsMatrix => abs_matrix(a, lo, hi, None),
        Method::SignSelect => sign_select(a, lo, hi),
    }
}

/// One box through one method, padded outward when asked: the fast path of every affine
/// entry point. The caller checks the input box is non-empty and the result finite.
#[inline(always)]
pub(crate) fn transform<V: Axes, const N: usize>(
    a: &AffineLanes<V, N>,
    lo: V,
    hi: V,
    method: Method,
    outward: bool,
) -> (V, V) {
    let pad_factor = outward.then(|| method.outward_factor(N as u32));
    if method == Method::AbsMatrix {
        return abs_matrix(a, lo, hi, pad_factor);
    }
    let (min, max) = bound(a, lo, hi, method);
    match pad_factor {
        Some(k) => {
            let pad = outward_pad(a, lo, hi, k);
            (min - pad, max + pad)
        }
        None => (min, max),
    }
}

impl<V: Axes, const N: usize> MapKernel<V> for AffineLanes<V, N> {
    #[inline(always)]
    fn transform(&self, lo: V, hi: V, method: Method, outward: bool) -> (V, V) {
        transform(self, lo, hi, method, outward)
    }
}

/// A translation: `[lo + t, hi + t]`, every method being the same map.
///
/// Nearest rounds each face once: error at most `u·|face| <= γ(1)·S`. Outward steps every
/// face one ulp outward ([`step_down`]): a sum rounded to nearest errs by at most half the
/// spacing of `f32` at the face, and one step outward is at least that much (at a power of
/// two the spacing on the far side halves, and so does the largest error there). So the
/// face contains the exact one, within `u·|face| + 2u·|face| + 2^-103 <= 3u·S + TINY_PAD`.
/// The step is taken on exact sums too: three operations a face, against seven to find
/// the sum's exact error first. Under FTZ a sum that underflows is flushed to zero, and
/// the step from zero (`2^-104`) still contains it.
#[inline(always)]
pub(crate) fn translate<V: Lane>(t: V, lo: V, hi: V, outward: bool) -> (V, V) {
    let (min, max) = (lo + t, hi + t);
    if !outward {
        return (min, max);
    }
    (step_down(min), -step_down(-max))
}

/// The next `f32` below `x` (finite `x`), or lower, in float arithmetic: `x − (|x|·c +
/// 2^-104)` with `c = 2^-24·(1 + 2^-23)`.
///
/// For `x = ±m·2^k`, `m ∈ [1, 2)`, the ulp is `2^(k−23)` and `|x|·c` rounds to a value in
/// `(ulp/2, ulp·(1 + 2^-23)]`: more than half an ulp, so round to nearest moves `x` down
/// (to `x − ulp/2` when `x = 2^k > 0`, where the spacing below halves), and less than one
/// and a half, so it moves by one step. The normal constant `2^-104` changes neither bound
/// when the ulp is at least `2^-102` (`|x| >= 2^-79`), where the step is exactly one ulp;
/// below, the step is at least `2^-104` and moves `x` further down, by at most `2^-103`.
/// Nothing is subnormal: on normal-range input a nonzero face is at least `2^-55`.
#[inline(always)]
fn step_down<V: Lane>(x: V) -> V {
    const C: f32 = UNIT_ROUNDOFF * (1.0 + f32::EPSILON);
    const FLOOR: f32 = REACH_FLOOR * UNIT_ROUNDOFF; // 2^-104
    x - x.abs().mul_add(V::splat(C), V::splat(FLOOR))
}

/// The standard rotation matrix of a quaternion `[x, y, z, w]`, as glam's `Mat3::from_quat`
/// writes it, with no normalisation: columns `(1 − (yy + zz), xy + wz, xz − wy)`,
/// `(xy − wz, 1 − (xx + zz), yz + wx)`, `(xz + wy, yz − wx, 1 − (xx + yy))` with
/// `xy = x·2y` and so on; and `ρ = 1 + 2‖q‖²`, which bounds every `|R_ij|` (for the
/// diagonal `|1 − 2(y² + z²)| <= 1 + 2‖q‖²`; off it `2|xy| + 2|wz| <= ‖q‖²`). The one
/// formula of `R(q)`: in `f32` lanes for the kernels, in `f64` for the trees' relative
/// pose (`one` is the number 1 in `T`).
///
/// Error, in `f32`: the doublings are exact, each product rounds once, and each entry is a
/// sum of two products (then one more rounding with the `1`): every computed entry is
/// within `γ(3)·ρ` of the exact one. An underflowing product errs by at most `2^-150`
/// absolutely, which is below `2^-126·u·ρ` since `ρ >= 1`. Plain multiplications and
/// additions, never fused: every backend forms the same `R`.
#[inline(always)]
pub(crate) fn rotation<T>([x, y, z, w]: [T; 4], one: T) -> ([[T; 3]; 3], T)
where
    T: Copy + Add<Output = T> + Sub<Output = T> + Mul<Output = T>,
{
    let (x2, y2, z2) = (x + x, y + y, z + z);
    let (xx, yy, zz) = (x * x2, y * y2, z * z2);
    let (xy, xz, yz) = (x * y2, x * z2, y * z2);
    let (wx, wy, wz) = (w * x2, w * y2, w * z2);
    let cols = [
        [one - (yy + zz), xy + wz, xz - wy],
        [xy - wz, one - (xx + zz), yz + wx],
        [xz + wy, yz - wx, one - (xx + yy)],
    ];
    let rho = one + ((xx + yy) + (zz + w * (w + w)));
    (cols, rho)
}

/// The box scaled per axis, `s ∘ [lo, hi]`: each face the smaller (larger) of `s·lo` and
/// `s·hi`, one rounding each (relative `u`, or `2^-150` absolute below the normal range).
#[inline(always)]
pub(crate) fn scale_box<V: Lane>(s: V, lo: V, hi: V) -> (V, V) {
    let (a, b) = (s * lo, s * hi);
    (a.min(b), a.max(b))
}

/// The Outward pad of a quaternion class: `k·u·S'` with
/// `S'_i = |t_i| + ρ·(Σ_j max(|lo_j|, |hi_j|) + 2^-80)` over the (already scaled) box.
///
/// Why `k = n + 2` suffices for the Nearest order `n` of [`rotation`] plus the method: as
/// in [`outward_pad`], the computed `S'` is at least `S'·(1 − γ(N + 6))` (the box's scaling
/// and `ρ`'s five roundings included), which the surplus `u·S` of the pad absorbs.
///
/// The absolute part: the Nearest error carries `2ρ·TINY_ERROR = ρ·2^-147`, and the pad's
/// own rounding and that of the padded face at most `2^-150` each. Folding the absolute
/// term into `S` as `ρ·2^-80` gives `k·ρ·u·2^-80 >= 9ρ·2^-104`, which covers them many times
/// over, and stays below the documented `2ρ·TINY_PAD = ρ·2^-99`. The pad is at least
/// `2^-102`, a normal number, so as in [`outward_pad`] nothing is subnormal on
/// normal-range input.
#[inline(always)]
pub(crate) fn rotation_pad<V: Axes>(rho: V, t: V, lo: V, hi: V, k: u32) -> V {
    let magnitude = hi.max(-lo);
    let sum = magnitude.axis(0) + magnitude.axis(1) + magnitude.axis(2) + V::splat(REACH_FLOOR);
    rho.mul_add(sum, t.abs()) * V::splat(k as f32 * UNIT_ROUNDOFF)
}

/// The boxes `[lo, hi]` through `map` on the fast path, with a lane value `redo` that says
/// where the result does not stand: 0 where the box is non-empty with no NaN and the result
/// finite, NaN elsewhere. Those lanes must be redone by [`crate::extended`]. One float per lane lets a single compare test every lane.
///
/// Per axis: `(hi − lo).select_nonneg(0, NaN)` is 0 for a non-empty axis (an overflowing
/// `hi − lo = +inf` included) and NaN for an empty or NaN one, and `(max − min)·0` is 0
/// for finite faces and NaN for an infinite or NaN one (every kernel gives `min <= max`
/// for a non-empty box; a finite box wider than `f32::MAX` also gives NaN and takes the
/// extended path, as on the single-box path, so that both agree bit for bit).
#[inline(always)]
pub(crate) fn transform_checked<L: Lane, const N: usize, M: MapKernel<Vector<L, N>>>(
    map: &M,
    lo: Vector<L, N>,
    hi: Vector<L, N>,
    method: Method,
    outward: bool,
) -> (Vector<L, N>, Vector<L, N>, L) {
    let (min, max) = map.transform(lo, hi, method, outward);
    let (zero, nan) = (L::splat(0.0), L::splat(f32::NAN));
    let mut redo = zero;
    for i in 0..N {
        let empty = (hi.0[i] - lo.0[i]).select_nonneg(zero, nan);
        let unbounded = (max.0[i] - min.0[i]) * zero;
        redo = redo + empty + unbounded;
    }
    (min, max, redo)
}
