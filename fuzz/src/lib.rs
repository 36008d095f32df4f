//! Decoding of fuzz input into boxes and transforms, and the contract checks every fuzz
//! target applies (through the exact oracle of the support crate).

pub use bvkit_support::oracle;

pub use bvkit_support::volumes;

use bvkit::tree::{Object, QueryError};
use bvkit::{Aabb2, Capsule, Method, Obb3, Rigid2, Rounding, Similarity3, Sphere};
use glam::{Mat3A, Quat, Vec3A};
use oracle::{Bound, Exactly, Problem, QuatProblem};

pub use oracle::{affine2, affine3};

/// Values that the extreme classes are made of.
const SPECIALS: [f32; 16] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::NAN,
    f32::MAX,
    -f32::MAX,
    f32::MIN_POSITIVE,
    1e-45,
    -1e-45,
    1e7,
    1e9,
    0.70710677,
    1e-7,
];

/// Reads floats from fuzz bytes: a selector byte then four bytes, so that raw bit
/// patterns, moderate values, the extreme specials and near-rotation entries all occur.
pub struct Floats<'a> {
    bytes: &'a [u8],
}

impl<'a> Floats<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Self { bytes }
    }

    pub fn byte(&mut self) -> u8 {
        match self.bytes.split_first() {
            Some((&b, rest)) => {
                self.bytes = rest;
                b
            }
            None => 0,
        }
    }

    pub fn next(&mut self) -> f32 {
        let selector = self.byte();
        let raw = u32::from_le_bytes([self.byte(), self.byte(), self.byte(), self.byte()]);
        match selector % 5 {
            0 => f32::from_bits(raw),
            1 => (raw as i32 >> 12) as f32 / 64.0,
            2 => SPECIALS[raw as usize % SPECIALS.len()],
            3 => ((raw % 20_001) as f32 - 10_000.0) / 10_000.0, // a rotation-like entry
            _ => SPECIALS[raw as usize % SPECIALS.len()] * (1.0 + (raw >> 8) as f32 * 1e-9),
        }
    }

    pub fn array<const N: usize>(&mut self) -> [f32; N] {
        core::array::from_fn(|_| self.next())
    }

    /// A problem: usually an ordered box (the fuzzer still reaches unordered ones).
    pub fn problem<const N: usize>(&mut self) -> Problem<N> {
        let cols = core::array::from_fn(|_| self.array());
        let t = self.array();
        let (mut lo, mut hi): ([f32; N], [f32; N]) = (self.array(), self.array());
        if self.byte() % 4 != 0 {
            for j in 0..N {
                if lo[j] > hi[j] {
                    core::mem::swap(&mut lo[j], &mut hi[j]);
                }
            }
        }
        Problem { cols, t, lo, hi }
    }

    /// A quaternion problem; `scale` is `None` (unit), `Some(true)` (uniform) or
    /// `Some(false)` (per axis). The quaternion is any four floats: unit, drifted, zero,
    /// huge, NaN or infinite.
    pub fn quat_problem(&mut self, scale: Option<bool>) -> QuatProblem {
        let p = self.problem::<3>();
        let q = self.array();
        let s = match scale {
            None => [1.0; 3],
            Some(true) => [self.next(); 3],
            Some(false) => self.array(),
        };
        QuatProblem {
            q,
            s,
            t: p.t,
            lo: p.lo,
            hi: p.hi,
        }
    }

    /// A point of three floats.
    pub fn vec3a(&mut self) -> Vec3A {
        Vec3A::from_array(self.array())
    }

    /// A rotation: usually `Mat3A::from_quat` of a normalised quaternion (orthonormal to
    /// within `f32` rounding), sometimes one with a drifted entry, sometimes nine raw floats.
    pub fn rotation(&mut self) -> Mat3A {
        let selector = self.byte();
        let turn = Mat3A::from_quat(Quat::from_array(self.array()).normalize());
        match selector % 4 {
            0 | 1 => turn,
            2 => {
                let mut cols = turn.to_cols_array();
                cols[self.byte() as usize % 9] += self.next() * 1e-4;
                Mat3A::from_cols_array(&cols)
            }
            _ => Mat3A::from_cols_array(&self.array()),
        }
    }

    /// A box from raw fields (its rotation from [`Floats::rotation`]).
    pub fn obb(&mut self) -> Obb3 {
        Obb3 {
            center: self.vec3a(),
            half_extents: self.vec3a(),
            rotation: self.rotation(),
        }
    }

    /// A ball from raw fields.
    pub fn sphere(&mut self) -> Sphere {
        Sphere {
            center: self.vec3a(),
            radius: self.next(),
        }
    }

    /// A capsule from raw fields.
    pub fn capsule(&mut self) -> Capsule {
        Capsule {
            a: self.vec3a(),
            b: self.vec3a(),
            radius: self.next(),
        }
    }

    /// A translation problem: the identity matrix.
    pub fn translation_problem<const N: usize>(&mut self) -> Problem<N> {
        let p = self.problem::<N>();
        let mut cols = [[0.0; N]; N];
        for (j, col) in cols.iter_mut().enumerate() {
            col[j] = 1.0;
        }
        Problem { cols, ..p }
    }
}

/// Panics with the problem when `min`/`max` break the contract.
pub fn assert_contract<const N: usize>(
    p: &impl Exactly<N>,
    min: [f32; N],
    max: [f32; N],
    bound: Bound,
    what: &str,
) {
    if let Err(e) = oracle::check(p, min, max, bound) {
        panic!("{what}: {e}\n{p:?}");
    }
}

/// A rigid problem: the matrix is rebuilt from its first column as `[[c, -s], [s, c]]`.
pub fn rigid2(p: &Problem<2>) -> (Problem<2>, Aabb2, Rigid2) {
    let [c, s] = p.cols[0];
    let q = Problem {
        cols: [[c, s], [-s, c]],
        ..*p
    };
    let (b, xf) = oracle::rigid2(&q);
    (q, b, xf)
}

/// The bound bvkit documents (see [`Bound::documented`]).
pub fn bound(method: Method, rounding: Rounding, dims: u32) -> Bound {
    Bound::documented(method, rounding, dims)
}

/// The bound of a class of order `n` (its `nearest_order(method)`).
pub fn bound_of(n: u32, rounding: Rounding) -> Bound {
    Bound::of_order(n, rounding)
}

/// True when a tree query's error is justified by its input, checked in the order the query
/// checks it: `A`'s pose (non-finite, then zero scale), `B`'s, the tolerance, then the
/// range. Out of range needs a map far from the unit scale: with `P = (1 + |qa|²)(1 + |qb|²)`,
/// `r` the larger scale ratio and `i = max(1, 1/|σa|)`, every entry of `M` and `N` is at
/// most `12·P·r` and `|t| <= 6·(1 + |qa|²)·i·2^129`; when `P·r·i·(1 + |qa|²) <= 2^100`
/// everything the query checks stays far below `2^300` (trees reach at most `2^129`).
pub fn query_error_justified(
    pa: &Similarity3,
    pb: &Similarity3,
    tolerance: f32,
    e: QueryError,
) -> bool {
    let finite = |p: &Similarity3| {
        p.rotation.is_finite() && p.translation.is_finite() && p.scale.is_finite()
    };
    let ok = |p: &Similarity3| finite(p) && p.scale != 0.0;
    let tolerance_ok = tolerance.is_finite() && tolerance >= 0.0;
    let far = || {
        let n = |p: &Similarity3| 1.0 + f64::from(p.rotation.length_squared());
        let (sa, sb) = (f64::from(pa.scale).abs(), f64::from(pb.scale).abs());
        let ratio = (sa / sb).max(sb / sa);
        n(pa) * n(pb) * ratio * (1.0 / sa).max(1.0) * n(pa) > 2f64.powi(100)
    };
    match e {
        QueryError::NonFinitePose { object: Object::A } => !finite(pa),
        QueryError::ZeroScale { object: Object::A } => finite(pa) && pa.scale == 0.0,
        QueryError::NonFinitePose { object: Object::B } => ok(pa) && !finite(pb),
        QueryError::ZeroScale { object: Object::B } => ok(pa) && finite(pb) && pb.scale == 0.0,
        QueryError::InvalidTolerance { .. } => ok(pa) && ok(pb) && !tolerance_ok,
        QueryError::OutOfRange => ok(pa) && ok(pb) && tolerance_ok && far(),
        QueryError::InvalidReach { .. } => false,
    }
}

/// A similarity pose from the fuzzer: any quaternion and translation, and (when `scaled`)
/// any scale, else 1.
pub fn similarity(f: &mut Floats, scaled: bool) -> Similarity3 {
    let rotation = Quat::from_array(f.array());
    let translation = Vec3A::from_array(f.array());
    let scale = if scaled { f.next() } else { 1.0 };
    Similarity3::new(scale, rotation, translation)
}
