//! Random boxes and transforms, one generator per extreme class of the contract.
#![allow(dead_code, clippy::needless_range_loop)]

use rand::RngExt;
use rand::SeedableRng;
use rand::rngs::StdRng;

use crate::oracle::{Problem, QuatProblem};

/// The classes of input the contract is tested over.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// Rotation and scale, a box near the origin, a moderate translation.
    Typical,
    /// Small extents far from the origin: `|t|` up to 1e7.
    Far,
    /// Faces and products near `f32::MAX`, overflow included.
    NearMax,
    /// Subnormal boxes, matrices and translations.
    Subnormal,
    /// Zero-size boxes (`min == max` on some or all axes).
    ZeroSize,
    /// Rotations composed with a reflection.
    Reflection,
    /// Sheared matrices.
    Shear,
    /// Non-uniform, near-singular and zero scale.
    NearSingular,
    /// Rotations whose entries drifted off orthonormal.
    Drifted,
    /// 90-degree rotations with tiny off-diagonal noise.
    QuarterTurn,
    /// `±0.0` faces, entries and translations.
    SignedZero,
    /// Faces at `±inf`, with zero matrix entries.
    Unbounded,
    /// Empty boxes (`min > max`, `EMPTY`, faces at the wrong infinity).
    Empty,
    /// A NaN somewhere in the input.
    Nan,
    /// Every value from random bits: any `f32` at all.
    RandomBits,
}

impl Class {
    pub const ALL: [Class; 15] = [
        Class::Typical,
        Class::Far,
        Class::NearMax,
        Class::Subnormal,
        Class::ZeroSize,
        Class::Reflection,
        Class::Shear,
        Class::NearSingular,
        Class::Drifted,
        Class::QuarterTurn,
        Class::SignedZero,
        Class::Unbounded,
        Class::Empty,
        Class::Nan,
        Class::RandomBits,
    ];
}

pub fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

/// A uniformly random rotation in N dimensions, columns rounded from f64.
fn rotation<const N: usize>(rng: &mut StdRng) -> [[f32; N]; N] {
    let mut cols = [[0.0f32; N]; N];
    if N == 2 {
        let a: f64 = rng.random_range(-core::f64::consts::PI..core::f64::consts::PI);
        let (s, c) = a.sin_cos();
        let m = [[c, s], [-s, c]];
        for j in 0..2 {
            for i in 0..2 {
                cols[j][i] = m[j][i] as f32;
            }
        }
    } else {
        // A random unit quaternion to a rotation matrix, in f64.
        let mut q = [0.0f64; 4];
        loop {
            for v in &mut q {
                *v = rng.random_range(-1.0..1.0);
            }
            let n = q.iter().map(|v| v * v).sum::<f64>();
            if n > 1e-3 && n <= 1.0 {
                q.iter_mut().for_each(|v| *v /= n.sqrt());
                break;
            }
        }
        let [w, x, y, z] = q;
        let m = [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y + w * z),
                2.0 * (x * z - w * y),
            ],
            [
                2.0 * (x * y - w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z + w * x),
            ],
            [
                2.0 * (x * z + w * y),
                2.0 * (y * z - w * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ];
        for j in 0..N {
            for i in 0..N {
                cols[j][i] = m[j][i] as f32;
            }
        }
    }
    cols
}

fn scale_cols<const N: usize>(cols: &mut [[f32; N]; N], scale: [f32; N]) {
    for j in 0..N {
        for i in 0..N {
            cols[j][i] *= scale[j];
        }
    }
}

/// `+1.0` or `-1.0`, evenly.
fn sign(rng: &mut StdRng) -> f32 {
    if rng.random_bool(0.5) { 1.0 } else { -1.0 }
}

/// `10^e` with `e` uniform in `[lo, hi]`, random sign.
fn log_uniform(rng: &mut StdRng, lo: f32, hi: f32) -> f32 {
    let e = rng.random_range(lo..=hi);
    sign(rng) * 10f32.powf(e)
}

fn subnormal(rng: &mut StdRng) -> f32 {
    f32::from_bits(rng.random_range(0..0x80_0000)) * sign(rng)
}

fn random_bits(rng: &mut StdRng) -> f32 {
    f32::from_bits(rng.random())
}

/// A box with center `c` in `±center` and half-extents in `[0, extent]`.
fn boxed<const N: usize>(rng: &mut StdRng, center: f32, extent: f32) -> ([f32; N], [f32; N]) {
    let mut lo = [0.0; N];
    let mut hi = [0.0; N];
    for j in 0..N {
        let c = center * rng.random_range(-1.0..=1.0);
        let e = extent * rng.random_range(0.0..=1.0);
        (lo[j], hi[j]) = (c - e, c + e);
    }
    (lo, hi)
}

/// One problem of the given class.
pub fn problem<const N: usize>(class: Class, rng: &mut StdRng) -> Problem<N> {
    let mut cols = rotation::<N>(rng);
    let scale = core::array::from_fn(|_| rng.random_range(0.1..10.0));
    let mut t: [f32; N] = core::array::from_fn(|_| rng.random_range(-1e3..1e3));
    let (mut lo, mut hi) = boxed::<N>(rng, 100.0, 50.0);
    match class {
        Class::Typical => scale_cols(&mut cols, scale),
        Class::Far => {
            t = core::array::from_fn(|_| log_uniform(rng, 3.0, 7.0));
            let extent = rng.random_range(1e-3..1.0);
            (lo, hi) = boxed(rng, 1.0, extent);
            if rng.random_bool(0.3) {
                // The local box itself far from its origin.
                let shift = log_uniform(rng, 3.0, 7.0);
                lo.iter_mut().chain(hi.iter_mut()).for_each(|x| *x += shift);
            }
        }
        Class::NearMax => {
            let f = f32::MAX * rng.random_range(0.05..1.0);
            (lo, hi) = boxed(rng, f, f * 0.5);
            for j in 0..N {
                (lo[j], hi[j]) = (lo[j].min(hi[j]), hi[j].max(lo[j]));
            }
            if rng.random_bool(0.5) {
                scale_cols(
                    &mut cols,
                    core::array::from_fn(|_| rng.random_range(0.5..4.0)),
                );
            }
            if rng.random_bool(0.3) {
                t = core::array::from_fn(|_| f32::MAX * rng.random_range(0.5..1.0) * sign(rng));
            }
        }
        Class::Subnormal => {
            for j in 0..N {
                let (a, b) = (subnormal(rng), subnormal(rng));
                (lo[j], hi[j]) = (a.min(b), a.max(b));
            }
            t = core::array::from_fn(|_| subnormal(rng));
            match rng.random_range(0..3) {
                0 => {}
                1 => scale_cols(
                    &mut cols,
                    core::array::from_fn(|_| log_uniform(rng, 10.0, 30.0).abs()),
                ),
                _ => cols = core::array::from_fn(|_| core::array::from_fn(|_| subnormal(rng))),
            }
        }
        Class::ZeroSize => {
            scale_cols(&mut cols, scale);
            for j in 0..N {
                if rng.random_bool(0.7) {
                    hi[j] = lo[j];
                }
            }
        }
        Class::Reflection => {
            scale_cols(&mut cols, scale);
            let j = rng.random_range(0..N);
            cols[j] = cols[j].map(|x| -x);
        }
        Class::Shear => {
            scale_cols(&mut cols, scale);
            let (a, b) = (rng.random_range(0..N), rng.random_range(0..N));
            let k = rng.random_range(-5.0..5.0);
            for i in 0..N {
                cols[a][i] += k * cols[b][i];
            }
        }
        Class::NearSingular => {
            let s = core::array::from_fn(|_| match rng.random_range(0..4) {
                0 => 0.0,
                1 => log_uniform(rng, -8.0, -5.0).abs(),
                2 => log_uniform(rng, 5.0, 8.0).abs(),
                _ => 1.0,
            });
            scale_cols(&mut cols, s);
        }
        Class::Drifted => {
            let drift = 10f32.powf(rng.random_range(-7.0..-2.0));
            for v in cols.iter_mut().flatten() {
                *v *= 1.0 + rng.random_range(-drift..drift);
            }
        }
        Class::QuarterTurn => {
            // A signed permutation plus noise of a few ulps off the diagonal.
            cols = [[0.0; N]; N];
            let shift = rng.random_range(0..N);
            for j in 0..N {
                cols[j][(j + shift) % N] = sign(rng);
                for i in 0..N {
                    if cols[j][i] == 0.0 && rng.random_bool(0.5) {
                        cols[j][i] = 10f32.powf(rng.random_range(-8.0..-6.0)) * sign(rng);
                    }
                }
            }
        }
        Class::SignedZero => {
            for v in cols.iter_mut().flatten().chain(&mut t) {
                if rng.random_bool(0.4) {
                    *v = 0.0 * sign(rng);
                }
            }
            for j in 0..N {
                if rng.random_bool(0.5) {
                    (lo[j], hi[j]) = (0.0 * sign(rng), 0.0 * sign(rng));
                } else if rng.random_bool(0.5) {
                    lo[j] = 0.0 * sign(rng);
                    hi[j] = hi[j].abs();
                }
            }
        }
        Class::Unbounded => {
            if rng.random_bool(0.5) {
                // Axis-aligned matrices have exact zeros: 0 · inf must contribute 0.
                cols = [[0.0; N]; N];
                for j in 0..N {
                    cols[j][j] = log_uniform(rng, -2.0, 2.0);
                }
            }
            for j in 0..N {
                match rng.random_range(0..4) {
                    0 => lo[j] = f32::NEG_INFINITY,
                    1 => hi[j] = f32::INFINITY,
                    2 => (lo[j], hi[j]) = (f32::NEG_INFINITY, f32::INFINITY),
                    _ => {}
                }
            }
        }
        Class::Empty => {
            let j = rng.random_range(0..N);
            match rng.random_range(0..4) {
                0 => (lo, hi) = ([f32::INFINITY; N], [f32::NEG_INFINITY; N]),
                1 => (lo[j], hi[j]) = (hi[j] + 1.0, lo[j]),
                2 => (lo[j], hi[j]) = (f32::INFINITY, f32::INFINITY),
                _ => (lo[j], hi[j]) = (f32::NEG_INFINITY, f32::NEG_INFINITY),
            }
        }
        Class::Nan => {
            let k = rng.random_range(0..N * N + 3 * N);
            let slots: Vec<&mut f32> = cols
                .iter_mut()
                .flatten()
                .chain(&mut t)
                .chain(&mut lo)
                .chain(&mut hi)
                .collect();
            *slots.into_iter().nth(k).expect("slot") = f32::NAN;
        }
        Class::RandomBits => {
            for v in cols
                .iter_mut()
                .flatten()
                .chain(&mut t)
                .chain(&mut lo)
                .chain(&mut hi)
            {
                *v = random_bits(rng);
            }
            for j in 0..N {
                if rng.random_bool(0.9) && lo[j] > hi[j] {
                    core::mem::swap(&mut lo[j], &mut hi[j]);
                }
            }
        }
    }
    Problem { cols, t, lo, hi }
}

/// The matrix of a rigid 2D transform `(cos, sin)`.
pub fn rigid_cols(cos: f32, sin: f32) -> [[f32; 2]; 2] {
    [[cos, sin], [-sin, cos]]
}

/// A rigid 2D problem of the given class: `(cos, sin)` taken from the class's matrix
/// (its first column), so drift, reflection-free rotation, zeros and NaN carry over.
pub fn rigid_problem(class: Class, rng: &mut StdRng) -> Problem<2> {
    let p = problem::<2>(class, rng);
    let [cos, sin] = p.cols[0];
    Problem {
        cols: rigid_cols(cos, sin),
        ..p
    }
}

/// Which scale a quaternion problem carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// `[1, 1, 1]`: a rigid pose.
    Unit,
    /// `[σ, σ, σ]`: a similarity.
    Uniform,
    /// Any per-axis scale: a scale-rotation-translation.
    PerAxis,
}

/// A random unit quaternion `[x, y, z, w]`, rounded to `f32` (so a few ulps off unit).
fn unit_quat(rng: &mut StdRng) -> [f32; 4] {
    loop {
        let q: [f64; 4] = core::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let n = q.iter().map(|v| v * v).sum::<f64>();
        if n > 1e-3 && n <= 1.0 {
            return q.map(|v| (v / n.sqrt()) as f32);
        }
    }
}

/// A quaternion problem of the given extreme class: the box and translation of the class's
/// affine problem, a rotation and a scale bent the same way.
pub fn quat_problem(class: Class, scale: Scale, rng: &mut StdRng) -> QuatProblem {
    let p = problem::<3>(class, rng);
    bend_quat(p, class, scale, rng)
}

/// The quaternion problem on the box and translation of `p`, bent by `class`.
pub fn bend_quat(p: Problem<3>, class: Class, scale: Scale, rng: &mut StdRng) -> QuatProblem {
    let mut q = unit_quat(rng);
    let mut s = match scale {
        Scale::Unit => [1.0; 3],
        Scale::Uniform => [rng.random_range(0.1..10.0) * sign(rng); 3],
        Scale::PerAxis => core::array::from_fn(|_| rng.random_range(0.1..10.0) * sign(rng)),
    };
    let mut t = p.t;
    // The scale a class may bend: per axis, or all three together.
    let bend = |s: &mut [f32; 3], rng: &mut StdRng, f: &dyn Fn(&mut StdRng) -> f32| match scale {
        Scale::Unit => {}
        Scale::Uniform => *s = [f(rng); 3],
        Scale::PerAxis => *s = core::array::from_fn(|_| f(rng)),
    };
    match class {
        Class::Typical | Class::Far | Class::ZeroSize | Class::Empty => {}
        Class::NearMax => {
            // Far from unit: R(q) entries up to ~1e37, or a huge scale.
            if rng.random_bool(0.5) {
                let k = 10f32.powf(rng.random_range(10.0..18.5));
                q = q.map(|c| c * k);
            }
            bend(&mut s, rng, &|r| log_uniform(r, 30.0, 38.0));
        }
        Class::Subnormal => {
            if rng.random_bool(0.5) {
                q = core::array::from_fn(|_| subnormal(rng));
            }
            bend(&mut s, rng, &|r| subnormal(r));
        }
        Class::Reflection => {
            q = q.map(|c| -c); // the same rotation, every sign flipped
            bend(&mut s, rng, &|r| -r.random_range(0.1..10.0));
        }
        Class::Shear | Class::Drifted => {
            // Off unit length: a little (drifted) or a lot (the formula is then no rotation).
            let k = if class == Class::Drifted {
                1.0 + rng.random_range(-1e-2..1e-2)
            } else {
                10f32.powf(rng.random_range(-3.0..3.0))
            };
            q = q.map(|c| c * k);
        }
        Class::NearSingular => {
            if rng.random_bool(0.3) {
                q = [0.0; 4]; // the zero quaternion: R = I
            }
            bend(&mut s, rng, &|r| match r.random_range(0..4) {
                0 => 0.0,
                1 => log_uniform(r, -8.0, -5.0),
                2 => log_uniform(r, 5.0, 8.0),
                _ => 1.0,
            });
        }
        Class::QuarterTurn => {
            // Quarter and half turns: components in {0, ±1/2, ±√½, ±1}, plus noise.
            let h = core::f32::consts::FRAC_1_SQRT_2;
            let choices = [
                [0.0, 0.0, 0.0, 1.0],
                [h, 0.0, 0.0, h],
                [0.0, h, 0.0, h],
                [0.0, 0.0, h, h],
                [0.5, 0.5, 0.5, 0.5],
                [1.0, 0.0, 0.0, 0.0],
                [0.0, h, h, 0.0],
            ];
            q = choices[rng.random_range(0..choices.len())];
            for c in &mut q {
                *c *= sign(rng);
                if *c == 0.0 && rng.random_bool(0.3) {
                    *c = 10f32.powf(rng.random_range(-8.0..-6.0)) * sign(rng);
                }
            }
        }
        Class::SignedZero => {
            for c in &mut q {
                if rng.random_bool(0.3) {
                    *c = 0.0 * sign(rng);
                }
            }
            bend(&mut s, rng, &|r| {
                if r.random_bool(0.5) {
                    0.0 * sign(r)
                } else {
                    1.0
                }
            });
        }
        Class::Unbounded => {
            if rng.random_bool(0.5) {
                q = [[0.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 0.0]][rng.random_range(0..2)];
            }
        }
        Class::Nan => {
            let k = rng.random_range(0..7);
            if k < 4 {
                q[k] = f32::NAN;
            } else if scale != Scale::Unit && k < 6 {
                s = [f32::NAN; 3];
            } else {
                t[rng.random_range(0..3)] = f32::NAN;
            }
            if rng.random_bool(0.3) {
                // An infinity in the map instead.
                q = [f32::INFINITY, 0.0, 0.0, 1.0];
            }
        }
        Class::RandomBits => {
            q = core::array::from_fn(|_| random_bits(rng));
            bend(&mut s, rng, &|r| random_bits(r));
        }
    }
    QuatProblem {
        q,
        s,
        t,
        lo: p.lo,
        hi: p.hi,
    }
}

/// A translation problem of the given class: the identity matrix, the class's box and
/// translation.
pub fn translation_problem<const N: usize>(class: Class, rng: &mut StdRng) -> Problem<N> {
    as_translation(problem::<N>(class, rng))
}

/// The translation problem on the box and translation of `p`.
pub fn as_translation<const N: usize>(p: Problem<N>) -> Problem<N> {
    let mut cols = [[0.0; N]; N];
    for (j, col) in cols.iter_mut().enumerate() {
        col[j] = 1.0;
    }
    // The class's NaN may have gone into the matrix: move it to the translation.
    let mut t = p.t;
    if p.cols.iter().flatten().any(|x| x.is_nan()) {
        t[0] = f32::NAN;
    }
    Problem { cols, t, ..p }
}
