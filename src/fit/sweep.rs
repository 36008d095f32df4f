//! Sweeps: the linear passes of the fits over every input point, in lanes.
//!
//! Each sweep is one pass on the running CPU's best backend
//! ([`Backend::detect`](crate::Backend::detect)), run unfused, so that its result does not
//! depend on the backend: the same bits on every CPU.
//! A sweep is plain array code over groups of [`WIDTH`] points, transposed into coordinate
//! columns and compiled inside the backend's dispatch wrapper, so that it vectorises for
//! its instructions; sums keep [`WIDTH`] partial sums (point `i` goes to sum `i mod WIDTH`),
//! added in order at the end.
//! - [`bounds`]: the bounding box and the finiteness check, in `f32`.
//! - [`summary`]: the extremes on 13 sample directions in `f32`, the bounding box, the
//!   finiteness check and the first two moments in `f64`, in one pass.
//! - [`projection_ranges`]: a box's projection ranges, certified, in `f32` (or `f64` for
//!   points toward `±f32::MAX`), one pass per box.
//!
//! Two lessons of the measurements are kept in the code: a sweep keeps its state in locals
//! that it returns (conditional writes through captured references do not vectorise), and
//! reads full groups in place (a group copied to the stack and read back in another shape
//! stalls store forwarding).

use crate::aabb::Aabb3;
use crate::num::pow2;
use crate::simd;
use alloc::vec::Vec;
use glam::{DMat3, DVec3, Mat3A, Vec3, Vec3A};

/// Points per group.
const WIDTH: usize = 8;

/// The full groups of `points`, then the last, partial one (if any) padded with `pad`, and
/// how many of its points are real. Full groups are read in place: a group copied to the
/// stack and read back in another shape stalls store forwarding.
#[inline(always)]
fn groups(
    points: &[Vec3],
    pad: Vec3,
) -> (impl Iterator<Item = &[Vec3; WIDTH]>, [Vec3; WIDTH], usize) {
    let (full, rest) = points.as_chunks::<WIDTH>();
    let mut tail = [pad; WIDTH];
    tail[..rest.len()].copy_from_slice(rest);
    (full.iter(), tail, rest.len())
}

/// The coordinate columns of [`WIDTH`] points, in plain indexed loops (closures of
/// `array::from_fn` are not always inlined), so that the transposition compiles to vector
/// loads and shuffles.
#[inline(always)]
fn columns(group: &[Vec3; WIDTH]) -> [[f32; WIDTH]; 3] {
    let mut c = [[0.0f32; WIDTH]; 3];
    for j in 0..WIDTH {
        c[0][j] = group[j].x;
        c[1][j] = group[j].y;
        c[2][j] = group[j].z;
    }
    c
}

/// [`columns`] as exact `f64`.
#[inline(always)]
fn columns_f64(group: &[Vec3; WIDTH]) -> [[f64; WIDTH]; 3] {
    let f = columns(group);
    let mut c = [[0.0f64; WIDTH]; 3];
    for i in 0..3 {
        for j in 0..WIDTH {
            c[i][j] = f64::from(f[i][j]);
        }
    }
    c
}

/// The bounding box of the points, or the index of the first point with a NaN or infinite
/// coordinate.
pub(crate) fn bounds(points: &[Vec3]) -> Result<Aabb3, usize> {
    let pad = points.first().copied().unwrap_or(Vec3::ZERO);
    let (lo, hi, finite) = simd::plain(
        #[inline(always)]
        || {
            let mut lo = [[f32::INFINITY; WIDTH]; 3];
            let mut hi = [[f32::NEG_INFINITY; WIDTH]; 3];
            let mut finite = [true; WIDTH];
            let (full, tail, _) = groups(points, pad);
            for group in full.chain([&tail]) {
                let c = columns(group);
                for i in 0..3 {
                    for j in 0..WIDTH {
                        let x = c[i][j];
                        finite[j] &= x.abs() < f32::INFINITY;
                        lo[i][j] = if x < lo[i][j] { x } else { lo[i][j] };
                        hi[i][j] = if x > hi[i][j] { x } else { hi[i][j] };
                    }
                }
            }
            (lo, hi, finite)
        },
    );
    if finite.contains(&false) {
        return Err(points.iter().position(|p| !p.is_finite()).unwrap_or(0));
    }
    let least = lo.map(|l| {
        l.iter()
            .fold(f32::INFINITY, |a, &b| if b < a { b } else { a })
    });
    let greatest = hi.map(|h| {
        h.iter()
            .fold(f32::NEG_INFINITY, |a, &b| if b > a { b } else { a })
    });
    Ok(Aabb3::new(
        Vec3A::from_array(least),
        Vec3A::from_array(greatest),
    ))
}

/// For each rotation, a range `[lo, hi]` such that every exact projection `a_k·p` of the
/// points on its columns `a_k` lies in `[lo − γ(2)·S, hi + γ(2)·S]`, where
/// `S = Σ_j |a_j|·reach_j` and `reach` holds the largest magnitudes of the bounding box
/// `bounds`. One pass per rotation: the state of one stays in registers.
///
/// **In `f32` lanes**, twice as wide as `f64` ones, when `S <= 2^100`, about the center `o`
/// of `bounds` (rounded to `f32`): each `a·(p − o)` is evaluated as
/// `(a_x·(x − o_x) + a_y·(y − o_y)) + a_z·(z − o_z)`, three differences, three products and
/// two sums rounded in `f32`, within `γ₃₂(5)·T + 3·2^-150` of exact, where
/// `T = Σ_j |a_j|·r_j` and `r_j = max |p_j − o_j|` over the box (`γ₃₂(5) = 5·2^-24/(1 −
/// 5·2^-24) < 2^-21.6`; `2^-150` bounds the error of a product that underflows; a difference
/// that underflows is exact). No value can overflow, as each is at most about `S`. So the
/// error is relative to the points' spread, not to their distance from the origin. The
/// extremes are shifted by `a·o`, which `f64` evaluates within `γ(2)·S` (the allowance
/// above), and moved out by `2^-21·T + 2^-147`, each sum rounded outward (`next_down`,
/// `next_up` of the rounded sum).
///
/// **In `f64` lanes** otherwise: the products of `f32` values are exact and the two sums
/// round, so each projection is within `γ(2)·S` of the computed extremes.
pub(crate) fn projection_ranges<const N: usize>(
    points: &[Vec3],
    bounds: &Aabb3,
    rotations: [Mat3A; N],
) -> [(DVec3, DVec3); N] {
    let (min, max) = (bounds.min.as_dvec3(), bounds.max.as_dvec3());
    let reach = min.abs().max(max.abs());
    let o = (0.5 * (min + max)).as_vec3();
    let r = (max - o.as_dvec3()).max(o.as_dvec3() - min);
    rotations.map(|rotation| {
        let axes = [0, 1, 2].map(|k| rotation.col(k).as_dvec3());
        let scale = axes.map(|a| a.abs().dot(reach));
        if !scale.iter().all(|&s| s <= pow2(100)) {
            return ranges_f64(points, rotation);
        }
        let (lo, hi) = ranges_f32(points, o, rotation);
        let pad = |k: usize| pow2(-21) * axes[k].abs().dot(r) + pow2(-147);
        let shift = |k: usize| axes[k].dot(o.as_dvec3());
        let ends = |k: usize| {
            let low = (f64::from(lo[k]) + shift(k)).next_down();
            let high = (f64::from(hi[k]) + shift(k)).next_up();
            ((low - pad(k)).next_down(), (high + pad(k)).next_up())
        };
        let [x, y, z] = [0, 1, 2].map(ends);
        (DVec3::new(x.0, y.0, z.0), DVec3::new(x.1, y.1, z.1))
    })
}

/// The least and greatest projections `a·(p − o)` of the points on the columns of
/// `rotation`, in `f32` (see [`projection_ranges`]).
fn ranges_f32(points: &[Vec3], o: Vec3, rotation: Mat3A) -> ([f32; 3], [f32; 3]) {
    let a = [0, 1, 2].map(|k| rotation.col(k).to_array());
    let o = o.to_array();
    let about_o = |group: &[Vec3; WIDTH]| {
        let mut c = columns(group);
        for (column, o) in c.iter_mut().zip(o) {
            for x in column {
                *x -= o;
            }
        }
        c
    };
    simd::plain(
        #[inline(always)]
        || extremes_on_axes(points, a, about_o, [f32::INFINITY, f32::NEG_INFINITY]),
    )
}

/// The least and greatest projections of the points on the columns of `rotation`, in `f64`
/// (see [`projection_ranges`]).
fn ranges_f64(points: &[Vec3], rotation: Mat3A) -> (DVec3, DVec3) {
    let a = [0, 1, 2].map(|k| rotation.col(k).as_dvec3().to_array());
    let (lo, hi) = simd::plain(
        #[inline(always)]
        || extremes_on_axes(points, a, columns_f64, [f64::INFINITY, f64::NEG_INFINITY]),
    );
    (DVec3::from_array(lo), DVec3::from_array(hi))
}

/// The least and greatest `(a_x·x + a_y·y) + a_z·z` over the points, for each of the three
/// axes `a`, in lanes of `T` from the groups' columns (`columns` of each group); `infinity`
/// is `[+∞, −∞]` in `T`. Plain array code, for the backend's wrapper.
#[inline(always)]
fn extremes_on_axes<T>(
    points: &[Vec3],
    a: [[T; 3]; 3],
    columns: impl Fn(&[Vec3; WIDTH]) -> [[T; WIDTH]; 3],
    [positive, negative]: [T; 2],
) -> ([T; 3], [T; 3])
where
    T: Copy + PartialOrd + core::ops::Add<Output = T> + core::ops::Mul<Output = T>,
{
    let mut lo = [[positive; WIDTH]; 3];
    let mut hi = [[negative; WIDTH]; 3];
    // Padding with a point of the set changes no extreme.
    let pad = points.first().copied().unwrap_or(Vec3::ZERO);
    let (full, tail, _) = groups(points, pad);
    for group in full.chain([&tail]) {
        let [x, y, z] = columns(group);
        for k in 0..3 {
            for j in 0..WIDTH {
                let q = a[k][0] * x[j] + a[k][1] * y[j] + a[k][2] * z[j];
                lo[k][j] = if q < lo[k][j] { q } else { lo[k][j] };
                hi[k][j] = if q > hi[k][j] { q } else { hi[k][j] };
            }
        }
    }
    let least = lo.map(|l| {
        l.into_iter()
            .fold(positive, |a, b| if b < a { b } else { a })
    });
    let greatest = hi.map(|h| {
        h.into_iter()
            .fold(negative, |a, b| if b > a { b } else { a })
    });
    (least, greatest)
}

/// Groups per chunk of [`summary`].
const CHUNK: usize = 32;

/// How many sample directions [`summary`] projects on.
pub(crate) const DIRECTIONS: usize = 13;

/// The sample directions, in the order of [`projections`]: the coordinate axes, the cube
/// diagonals and the face diagonals (unnormalised). The tight fit's hull filter takes its
/// extremes along the same directions, in `f64`.
pub(crate) const SAMPLE_DIRECTIONS: [[f64; 3]; DIRECTIONS] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 1.0, 1.0],
    [1.0, 1.0, -1.0],
    [1.0, -1.0, 1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 0.0, 1.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, 1.0],
    [0.0, 1.0, -1.0],
];

/// The projections of `(x, y, z)` on the sample directions, in this order: the 3
/// coordinate axes, the 4 cube diagonals `(1, ±1, ±1)` (these 7 are DiTO-14's) and the 6
/// face diagonals `(1, ±1, 0)`, `(1, 0, ±1)`, `(0, 1, ±1)` (all 13 are EPOS-26's).
///
/// Each is the signed sum `x ± y ± z` of its nonzero terms, left to right: the value of the
/// dot product `(x·n_x + y·n_y) + z·n_z` (up to the sign of a zero), at the cost of 10 sums.
#[inline(always)]
pub(crate) fn projections(x: f32, y: f32, z: f32) -> [f32; DIRECTIONS] {
    let mut q = [0.0; DIRECTIONS];
    for (k, q) in q.iter_mut().enumerate() {
        *q = projection(k, x, y, z);
    }
    q
}

/// The `k`-th of [`projections`] alone (the sums that it needs, in the same order).
#[inline(always)]
fn projection(k: usize, x: f32, y: f32, z: f32) -> f32 {
    match k {
        0 => x,
        1 => y,
        2 => z,
        3 => (x + y) + z,
        4 => (x + y) - z,
        5 => (x - y) + z,
        6 => (x - y) - z,
        7 => x + y,
        8 => x - y,
        9 => x + z,
        10 => x - z,
        11 => y + z,
        _ => y - z,
    }
}

/// The least and greatest projections on the sample directions `set` (indices of
/// [`projections`]) of the points of `columns` (groups' coordinate columns), lane by lane,
/// written into `lo` and `hi` at those indices. A set small enough that its lanes stay in
/// registers over all the groups: 13 directions at once need 26 registers, and spill.
#[inline(always)]
fn extremes_of<const N: usize>(
    columns: &[[[f32; WIDTH]; 3]],
    set: [usize; N],
    lo: &mut [[f32; WIDTH]; DIRECTIONS],
    hi: &mut [[f32; WIDTH]; DIRECTIONS],
) {
    let mut least = [[f32::INFINITY; WIDTH]; N];
    let mut greatest = [[f32::NEG_INFINITY; WIDTH]; N];
    for [x, y, z] in columns {
        for j in 0..WIDTH {
            for n in 0..N {
                let q = projection(set[n], x[j], y[j], z[j]);
                least[n][j] = if q < least[n][j] { q } else { least[n][j] };
                greatest[n][j] = if q > greatest[n][j] {
                    q
                } else {
                    greatest[n][j]
                };
            }
        }
    }
    for n in 0..N {
        (lo[set[n]], hi[set[n]]) = (least[n], greatest[n]);
    }
}

/// An extreme projection found so far: its value, and the points among which its first
/// point lies: those of the chunk `start..start + len` in the lanes of the mask `lanes`
/// (point `start + i` is in lane `i mod WIDTH`), or one point of the tail.
#[derive(Clone, Copy, Default)]
struct Extreme {
    value: f32,
    start: usize,
    len: usize,
    lanes: u32,
}

impl Extreme {
    /// The first point among its candidates whose projection `project` is the extreme value;
    /// `None` when none is (an overflowing projection, `inf` or NaN, may match none). Only
    /// the lanes that reached the value are searched, a point in `WIDTH`.
    fn first(&self, points: &[Vec3], project: impl Fn(Vec3) -> f32) -> Option<usize> {
        let candidates = &points[self.start..self.start + self.len];
        (0..WIDTH)
            .filter(|&lane| self.lanes & (1 << lane) != 0)
            .filter_map(|lane| {
                // A plain strided loop: `step_by`'s iterator cost several times the test.
                let mut i = lane;
                while i < candidates.len() {
                    if project(candidates[i]) == self.value {
                        return Some(self.start + i);
                    }
                    i += WIDTH;
                }
                None
            })
            .min()
    }
}

/// What one sweep learns of the points: the extremal points on the sample directions and
/// the first two moments.
pub(crate) struct Summary {
    /// True when every coordinate is finite; nothing else is meaningful otherwise.
    pub finite: bool,
    /// The bounding box (the extremes on the first three directions, the coordinate axes).
    pub bounds: Aabb3,
    /// The points of least and greatest projection on each sample direction
    /// ([`projections`]), as pairs `[min_0, max_0, min_1, max_1, ...]`, the first such
    /// point on ties.
    pub extremal: Vec<DVec3>,
    /// The mean `m`.
    pub mean: DVec3,
    /// The covariance `Σ (p − m)(p − m)ᵀ / n`.
    pub covariance: DMat3,
}

/// The entries of the upper triangle of a symmetric 3×3 matrix.
const ENTRIES: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// The [`Summary`] of the points, in one sweep (the points are read once: on large inputs
/// the sweeps are bound by memory, not arithmetic).
///
/// **Registers.** The 26 extremes and 9 sums, in lanes, would take 44 registers of AVX2's
/// 16, and spill on every group. So each chunk is transposed once into columns
/// (3 KB, in L1 cache), then swept by three sets of directions ([`extremes_of`]) and the
/// two halves of the `f64` sums in turn, each of whose lanes stays in registers. Every sum
/// sees its terms in the same order as in a single pass.
///
/// **Extremes.** The lanes keep only the least and greatest values of each chunk of
/// [`CHUNK`] groups (the last chunk may be shorter; only the last `n mod WIDTH` points go
/// one at a time); a chunk that strictly improves an extreme becomes its chunk, and the
/// first point of that chunk with the extreme value is found at the end, by evaluating the
/// same sums one point at a time (the same bits: IEEE operations in the same order).
///
/// **Moments.** The sums are taken about the first point `s`, `d = p − s` in `f64` (exact
/// for points within a factor `2^29` of each other's magnitude): `m = s + Σd/n` and the
/// covariance is `Σ ddᵀ/n − (Σd/n)(Σd/n)ᵀ`, which cancels only as much as the mean lies off
/// `s`, a point of the set, not as much as the points lie off the origin.
///
/// **Finiteness.** The sums of `d` are finite exactly when every coordinate is: a NaN or an
/// infinity makes its sum NaN or infinite, and sums of finite `f32` values cannot overflow
/// `f64`.
pub(crate) fn summary(points: &[Vec3]) -> Summary {
    let none = |value| Extreme {
        value,
        start: 0,
        len: 0,
        lanes: 0,
    };
    let first = points.first().copied().unwrap_or(Vec3::ZERO);
    let s = first.as_dvec3().to_array();
    let (mut extremes, mut sum, mut products) = simd::plain(
        #[inline(always)]
        || {
            let mut best = [[none(f32::INFINITY), none(f32::NEG_INFINITY)]; DIRECTIONS];
            let mut sum = [[0.0f64; WIDTH]; 3];
            let mut products = [[0.0f64; WIDTH]; 6];
            // Each chunk's groups as columns, swept several times while they are in cache.
            let mut buffer = [[[0.0f32; WIDTH]; 3]; CHUNK];
            // The last chunk may be short; its full groups still run in lanes.
            for (c, chunk) in points.chunks(CHUNK * WIDTH).enumerate() {
                let groups = chunk.as_chunks::<WIDTH>().0;
                for (columns_of, group) in buffer.iter_mut().zip(groups) {
                    *columns_of = columns(group);
                }
                let buffer = &buffer[..groups.len()];
                let mut lo = [[f32::INFINITY; WIDTH]; DIRECTIONS];
                let mut hi = [[f32::NEG_INFINITY; WIDTH]; DIRECTIONS];
                // Each set's least and greatest lanes stay in registers over the chunk.
                extremes_of(buffer, [0, 1, 2, 7, 8], &mut lo, &mut hi);
                extremes_of(buffer, [3, 4, 5, 6], &mut lo, &mut hi);
                extremes_of(buffer, [9, 10, 11, 12], &mut lo, &mut hi);
                for half in [0, WIDTH / 2] {
                    for [x, y, z] in buffer {
                        let mut d = [[0.0f64; WIDTH / 2]; 3];
                        for (i, column) in [x, y, z].iter().enumerate() {
                            for j in 0..WIDTH / 2 {
                                d[i][j] = f64::from(column[half + j]) - s[i];
                                sum[i][half + j] += d[i][j];
                            }
                        }
                        for (e, &(i, k)) in ENTRIES.iter().enumerate() {
                            for j in 0..WIDTH / 2 {
                                products[e][half + j] += d[i][j] * d[k][j];
                            }
                        }
                    }
                }
                for k in 0..DIRECTIONS {
                    let least = lo[k]
                        .iter()
                        .fold(f32::INFINITY, |a, &b| if b < a { b } else { a });
                    let greatest = hi[k]
                        .iter()
                        .fold(f32::NEG_INFINITY, |a, &b| if b > a { b } else { a });
                    let at = |value, lanes: &[f32; WIDTH]| Extreme {
                        value,
                        start: c * CHUNK * WIDTH,
                        len: chunk.len(),
                        lanes: (0..WIDTH)
                            .filter(|&j| lanes[j] == value)
                            .fold(0, |mask, j| mask | 1 << j),
                    };
                    // Strictly better only: the first chunk to reach a value keeps it.
                    if least < best[k][0].value {
                        best[k][0] = at(least, &lo[k]);
                    }
                    if greatest > best[k][1].value {
                        best[k][1] = at(greatest, &hi[k]);
                    }
                }
            }
            (best, sum, products)
        },
    );
    // The tail (fewer than `WIDTH` points), one point at a time: its sums go to lane 0.
    let project = |k: usize, p: Vec3| projection(k, p.x, p.y, p.z);
    let tail = points.len() - points.len() % WIDTH;
    for (i, &p) in points.iter().enumerate().skip(tail) {
        for (q, [lo, hi]) in projections(p.x, p.y, p.z).into_iter().zip(&mut extremes) {
            let here = Extreme {
                value: q,
                start: i,
                len: 1,
                lanes: 1,
            };
            if q < lo.value || lo.len == 0 {
                *lo = here;
            }
            if q > hi.value || hi.len == 0 {
                *hi = here;
            }
        }
        let d = (p.as_dvec3() - DVec3::from_array(s)).to_array();
        for i in 0..3 {
            sum[i][0] += d[i];
        }
        for (e, &(i, k)) in ENTRIES.iter().enumerate() {
            products[e][0] += d[i] * d[k];
        }
    }
    let finite = sum.iter().flatten().all(|x| x.is_finite());
    let bounds = Aabb3::new(
        Vec3A::from_array([0, 1, 2].map(|k| extremes[k][0].value)),
        Vec3A::from_array([0, 1, 2].map(|k| extremes[k][1].value)),
    );
    let extremal = extremes
        .iter()
        .enumerate()
        .flat_map(|(k, ends)| {
            ends.map(|e| {
                // The first point of its chunk with the value; when none has it (an
                // overflowing projection), any point will do.
                let first = e.first(points, |p| project(k, p)).unwrap_or(e.start);
                points.get(first).map_or(DVec3::ZERO, |p| p.as_dvec3())
            })
        })
        .collect();
    let n = points.len().max(1) as f64;
    let offset = DVec3::from_array(sum.map(|x| x.iter().sum::<f64>() / n));
    let c = products.map(|x| x.iter().sum::<f64>() / n);
    let raw =
        DMat3::from_cols_array_2d(&[[c[0], c[1], c[2]], [c[1], c[3], c[4]], [c[2], c[4], c[5]]]);
    let shift = DMat3::from_cols(offset * offset.x, offset * offset.y, offset * offset.z);
    Summary {
        finite,
        bounds,
        extremal,
        mean: DVec3::from_array(s) + offset,
        covariance: raw - shift,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sample directions, as `f32` vectors.
    fn vectors() -> [Vec3; DIRECTIONS] {
        SAMPLE_DIRECTIONS.map(|n| glam::DVec3::from_array(n).as_vec3())
    }

    /// The sign of the exact sum of `f64` terms: a nonoverlapping expansion grown by TwoSum
    /// (Shewchuk 1997), whose largest nonzero component has the sign of the sum.
    fn exact_sign(terms: &[f64]) -> f64 {
        let mut expansion: Vec<f64> = Vec::new();
        for &t in terms {
            let mut carry = t;
            let mut grown = Vec::new();
            for &e in &expansion {
                let (sum, error) = crate::num::two_sum(carry, e);
                if error != 0.0 {
                    grown.push(error);
                }
                carry = sum;
            }
            grown.push(carry);
            expansion = grown;
        }
        expansion
            .iter()
            .rev()
            .find(|&&e| e != 0.0)
            .map_or(0.0, |e| e.signum())
    }

    /// The `f32` sweep's range holds every exact projection (`a_j·p_j` is exact in `f64`;
    /// the sign of `a·p − lo` is taken exactly), and its pad scales with the points'
    /// spread, not their distance from the origin: far from it, near underflow, and for
    /// a single point.
    #[test]
    fn projection_ranges_hold_every_exact_projection_within_the_spread() {
        let mut random = crate::num::uniform(0x5eed_f00d);
        for (offset, spread) in [
            (0.0, 1.0),
            (1.0e4, 1.0),
            (-3.0e6, 0.01),
            (1.0e-36, 1.0e-37),
            (7.0e3, 0.0),
        ] {
            let points: Vec<Vec3> = (0..CHUNK * WIDTH + 5)
                .map(|_| {
                    Vec3::new(
                        (offset + spread * random()) as f32,
                        (offset * 0.5 + spread * random()) as f32,
                        (-offset + spread * random()) as f32,
                    )
                })
                .collect();
            let bounds = bounds(&points).expect("finite");
            let axis = glam::Vec3::new(random() as f32, random() as f32, 0.5).normalize();
            let rotation = Mat3A::from_quat(glam::Quat::from_axis_angle(axis, 0.7));
            let [(lo, hi)] = projection_ranges(&points, &bounds, [rotation]);
            for k in 0..3 {
                let a = rotation.col(k).as_dvec3();
                let (mut least, mut greatest) = (f64::INFINITY, f64::NEG_INFINITY);
                for p in &points {
                    let terms = (a * p.as_dvec3()).to_array();
                    let [x, y, z] = terms;
                    assert!(exact_sign(&[x, y, z, -lo[k]]) >= 0.0, "{offset} {spread}");
                    assert!(exact_sign(&[x, y, z, -hi[k]]) <= 0.0, "{offset} {spread}");
                    let q = (x + y) + z;
                    (least, greatest) = (least.min(q), greatest.max(q));
                }
                // The pad is a few millionths of the spread (and of `f64`'s rounding of a
                // value near the offset), not of the offset.
                let slack = 1e-5 * spread + 1e-15 * offset.abs() + 1e-40;
                assert!(
                    least - lo[k] <= slack,
                    "{offset} {spread}: {}",
                    least - lo[k]
                );
                assert!(
                    hi[k] - greatest <= slack,
                    "{offset} {spread}: {}",
                    hi[k] - greatest
                );
            }
        }
    }

    /// The signed sums are the dot products with the sample directions, and the extremal
    /// points are the first points of least and greatest dot product, as a plain loop finds
    /// them (ties included: the points repeat, and the tail is longer than a group).
    #[test]
    fn extremal_points_are_the_first_extremes_of_the_dot_products() {
        let mut points: Vec<Vec3> = (0..CHUNK * WIDTH * 3 + 13)
            .map(|i| {
                let t = i as f32;
                Vec3::new(
                    (t * 0.37).sin(),
                    (t * 0.11).cos(),
                    ((t * 0.07).sin() * 4.0).round(),
                )
            })
            .collect();
        points.extend_from_within(..100);
        for p in &points {
            for (q, n) in projections(p.x, p.y, p.z).iter().zip(vectors()) {
                assert_eq!(*q, p.dot(n), "{p} {n}");
            }
        }
        let expected: Vec<DVec3> = vectors()
            .iter()
            .flat_map(|n| {
                let first = |better: fn(f32, f32) -> bool| {
                    let mut best = 0;
                    for (i, p) in points.iter().enumerate() {
                        if better(p.dot(*n), points[best].dot(*n)) {
                            best = i;
                        }
                    }
                    points[best].as_dvec3()
                };
                [first(|a, b| a < b), first(|a, b| a > b)]
            })
            .collect();
        let found = summary(&points);
        assert!(found.finite);
        assert_eq!(found.extremal, expected);
        let bounds = Aabb3::from_points(points.iter().map(|&p| p.into()));
        assert_eq!(
            (found.bounds.min, found.bounds.max),
            (bounds.min, bounds.max)
        );
        // A NaN in a chunk, an infinity in the tail.
        let mut bad = points.clone();
        bad[700].y = f32::NAN;
        bad[800].x = f32::INFINITY;
        assert!(!summary(&bad).finite);
        bad[700].y = 0.0;
        assert!(!summary(&bad).finite);
        bad[800].x = 0.0;
        assert!(summary(&bad).finite);
    }

    /// The moments are the sums that [`summary`] documents, bitwise: `d = p − s` about the
    /// first point, point `i` of the full groups into partial sum `i mod WIDTH` and the tail
    /// into the first, each in the points' order, the partial sums added in order.
    #[test]
    fn moments_are_the_partial_sums_in_their_order() {
        let points: Vec<Vec3> = (0..CHUNK * WIDTH * 2 + 77)
            .map(|i| {
                let t = i as f32;
                Vec3::new(
                    (t * 0.3).sin() * 3.0 + 10.0,
                    (t * 0.17).cos() - 2.0,
                    t * 1e-3,
                )
            })
            .collect();
        let s = points[0].as_dvec3();
        let full = points.len() - points.len() % WIDTH;
        let mut sum = [[0.0f64; WIDTH]; 3];
        let mut products = [[0.0f64; WIDTH]; 6];
        for (i, p) in points.iter().enumerate() {
            let lane = if i < full { i % WIDTH } else { 0 };
            let d = (p.as_dvec3() - s).to_array();
            for k in 0..3 {
                sum[k][lane] += d[k];
            }
            for (e, &(a, b)) in ENTRIES.iter().enumerate() {
                products[e][lane] += d[a] * d[b];
            }
        }
        let n = points.len() as f64;
        let offset = DVec3::from_array(sum.map(|x| x.iter().sum::<f64>() / n));
        let c = products.map(|x| x.iter().sum::<f64>() / n);
        let raw = DMat3::from_cols_array_2d(&[
            [c[0], c[1], c[2]],
            [c[1], c[3], c[4]],
            [c[2], c[4], c[5]],
        ]);
        let shift = DMat3::from_cols(offset * offset.x, offset * offset.y, offset * offset.z);
        let found = summary(&points);
        assert_eq!(
            found.mean.to_array().map(f64::to_bits),
            (s + offset).to_array().map(f64::to_bits)
        );
        assert_eq!(
            found.covariance.to_cols_array().map(f64::to_bits),
            (raw - shift).to_cols_array().map(f64::to_bits)
        );
    }
}
