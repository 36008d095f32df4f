//! The relative pose of two trees, `|R|` and the one error pad, computed once per query.
//!
//! # The geometry a query decides
//! Object `A` at pose `pa = (qa, ta)` and object `B` at `pb = (qb, tb)` ([`Rigid3`]; a
//! [`Similarity3`] adds a uniform scale `σ`). `B` is placed in `A`'s frame by the affine map
//! `y ↦ M·y + t` with `M = (σb/σa)·R(qa)ᵀ·R(qb)` and `t = R(qa)ᵀ·(tb − ta)/σa`, evaluated in
//! `f64` from the stored `f32` components (`R(q)` the crate's standard formula on `q` as
//! stored). For unit quaternions this is `pa⁻¹ ∘ pb` to within a few `2^-52` relative; for
//! any finite pose it is one well-defined affine map, and the queries are exact or provably
//! conservative **for it**: triangles of `B` are placed by rounding `M·v + t` to `f64` per
//! vertex, and the leaf test on those `f64` vertices is exact ([`super::triangles_intersect`]).
//!
//! # The node-pair test and its pad
//! A node pair costs two 3-axis tests in `f32` on centers `c` and extents `e`:
//! - `A`'s axes: separated when `|c_a − (M̃·c_b + t̃)| > e_a + |M̃|·e_b + P` on an axis;
//! - `B`'s axes: separated when `|c_b − (Ñ·c_a + t̃_B)| > e_b + |Ñ|·e_a + P`,
//!
//! where `N = (σa/σb)²·Mᵀ` (`= Mᵀ` for rigid poses) stands for `M⁻¹`, and `M̃`, `|M̃|`, `Ñ`,
//! `|Ñ|`, `t̃`, `t̃_B ≈ −N·t` are rounded to `f32` once. `P` is one number per query. Let
//! `R_a`, `R_b` bound `|coordinate|` of every box of each tree (the trees' reach, times
//! `1 + 2^-18`), `m` the largest row or column sum of `|M|` or `|N|`, `T` the largest
//! `|t_i|` or `|(Nt)_i|`, `u = 2^-24`, and `E = N·M − I` (zero for an exact rotation).
//!
//! **Claim.** If a point `x` of box `a` and a point `y` of box `b` have `x = M·y + t + w`
//! with `|w| <= ε₆₄ + d` (`ε₆₄` the `f64` rounding of a placed vertex, `d` the tolerance),
//! neither test reports the pair separated.
//!
//! **Proof, `A`'s axes.** With `ĉ, ê` the exact center and extent of a box and `c, e` the
//! computed ones, `|x_i − c_a,i| <= e_a,i + δ_a` where `δ <= 2u·R + 2^-148` covers a box
//! read back from a triangle (`c = lo/2 + hi/2`, `e = hi/2 − lo/2`, one rounding each) or a
//! quantized node (one rounding of `origin + step·c`); stored compact boxes need none.
//! Writing `M̃ = M + Δ`, `|Δ_ij| <= ε_M = u·max|M_ij| + 2^-150`, and
//! `t̃ = t + τ`, `|τ_i| <= u·T + 2^-150`:
//! `(M̃c_b + t̃ − x)_i = Σ_j M̃_ij (c_b − y)_j + (Δy)_i + τ_i − w_i`, so
//! `|c_a − (M̃c_b + t̃)|_i <= e_a,i + Σ_j |M̃_ij| e_b,j + δ_a + m·δ_b + 3ε_M·R_b + |τ| + |w|`.
//! The `f32` evaluation (3 products, 4 sums and the subtraction for the distance; 3
//! products and 3 sums for the radius; one sum adding `P`) moves each side by at most
//! `γ(5)` of its absolute terms, `<= 6u·(R_a + m·R_b + T)`, plus `u·P`.
//!
//! **`B`'s axes.** From `x = My + t + w`, `N(x − t − w) = NM·y = y + E·y`, so
//! `y = Nx − Nt − Nw − E·y`; `|Nw|_j <= m·|w|` and `|E·y|_j <= ‖E‖_F·√3·R_b`. The rest is
//! the argument above with `A` and `B` exchanged (`ε_M` also bounds the rounding of `Ñ`);
//! `t̃_B` adds the `f64` error of `N·t` (`<= 2^-50·m·T`) to its rounding.
//!
//! **The pad.** With `ε₆₄ = 2^-50·(m·R_b + T)` and `‖E‖_F` computed in `f64` plus its
//! rounding (`9·2^-50·m²`):
//!
//! ```text
//! P = (1 + 2^-20)·[ (1 + m)(δ_a + δ_b + ε₆₄ + d) + 3ε_M·(R_a + R_b) + 2(u + 2^-50·m)·T
//!                   + 2^-148 + ‖E‖_F·√3·R_b + 12u·(1 + m)(R_a + R_b + T) ]
//! ```
//!
//! It exceeds every term of both tests (the factor `1 + 2^-20` absorbs `u·P` and the `f64`
//! rounding of `P` itself, which is rounded up to `f32`). No constant in it is tuned: each
//! term is one step of the proof.
//!
//! **Overflow.** The proof assumes no `f32` operation overflows: every value in the tests is
//! at most `(1 + m)(R_a + R_b + T) + P`. When `(1 + m)(R_a + R_b + T) >= 2^126`, `P` is
//! `+inf` instead and no pair is culled (an infinite radius never separates; NaN never
//! separates); the exact leaf test still decides. Found by the `tree` fuzz target. The
//! reaches are `f64` and finite for every finite tree (a node reaching `±f32::MAX` whose
//! `f32` read-back overflows is such a case: its reach is past `2^126`). What cannot be
//! decided is an error, never "no contact": a non-finite pose, a zero scale, a bad
//! tolerance, or a map that overflows `f64` or places `B` beyond `2^300` (the leaf test's
//! exact range) is a [`QueryError`].
//!
//! At the root the 9 cross axes `e_i × M_j` (`M_j` a column of `M`) are tested as well, in
//! `f64` ([`Relative::roots_separated`]): on axis `L` separated when
//! `|L·D| > Σ|L_k| e_a,k + Σ|(MᵀL)_k| e_b,k + ‖L‖₁·(P + 2^-46(1 + m)(R_a + R_b + T))`,
//! `D = M c_b + t − c_a`: the exact projection identity `L·(My + t + w − x) = 0` bounds `L·D`
//! by the radii plus `‖L‖₁·(δ_a + m·δ_b + |w|) <= ‖L‖₁·P`, and the `f64` evaluation errs by
//! far less than the second term.

use crate::kernel;
use crate::num::{pow2, round_up, sqrt};
use glam::{DMat3, DVec3, Quat, Vec3A, Vec4, Vec4Swizzles};

use crate::transform::{Rigid3, Similarity3};

const U: f64 = pow2(-24);

/// `R(q)` in `f64`: the crate's one formula ([`kernel::rotation`]) on `q` as stored.
fn rotation(q: Quat) -> DMat3 {
    let (cols, _) = kernel::rotation(q.to_array().map(f64::from), 1.0);
    DMat3::from_cols_array_2d(&cols)
}

/// Which object of a query an error is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Object {
    /// The first object (`A`, at `pa`).
    A,
    /// The second object (`B`, at `pb`).
    B,
}

/// Why a query (or a [`Relative`]) could not be set up: it would not decide the geometry,
/// so it reports this instead of "no contact".
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum QueryError {
    /// A pose has a NaN or infinite rotation, translation or scale.
    NonFinitePose {
        /// The object whose pose it is.
        object: Object,
    },
    /// A pose has a zero scale: the object is a point, and `B` cannot be placed in a frame
    /// scaled by zero.
    ZeroScale {
        /// The object whose pose it is.
        object: Object,
    },
    /// The tolerance is NaN, infinite or negative.
    InvalidTolerance {
        /// The tolerance given.
        tolerance: f32,
    },
    /// A reach given to [`Relative::new`] is NaN, infinite or negative.
    InvalidReach {
        /// The reach given.
        reach: f64,
    },
    /// The relative map overflows `f64`, or places `B`'s boxes beyond `2^300`, past the range
    /// where the leaf test is exact (non-unit quaternions or scale ratios near the ends of
    /// the `f32` range).
    OutOfRange,
}

impl core::fmt::Display for QueryError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::NonFinitePose { object } => {
                write!(f, "the pose of {object:?} has a NaN or infinite component")
            }
            Self::ZeroScale { object } => write!(f, "the pose of {object:?} has a zero scale"),
            Self::InvalidTolerance { tolerance } => {
                write!(f, "tolerance {tolerance} is NaN, infinite or negative")
            }
            Self::InvalidReach { reach } => write!(f, "reach {reach} is NaN, infinite or negative"),
            Self::OutOfRange => write!(
                f,
                "the relative pose overflows, or places B beyond 2^300 (outside the exact range)"
            ),
        }
    }
}

impl core::error::Error for QueryError {}

/// The largest `|coordinate|` of a placed box the leaf test takes: `2^300`, so that the
/// products of three differences in `orient3d` (at most `2^903`) stay far from overflow.
const PLACED_LIMIT: f64 = pow2(300);

/// A pose's components are finite and its scale is not zero.
fn check_pose(p: &Similarity3, object: Object) -> Result<(), QueryError> {
    let finite = p.rotation.is_finite() && p.translation.is_finite() && p.scale.is_finite();
    if !finite {
        return Err(QueryError::NonFinitePose { object });
    }
    if p.scale == 0.0 {
        return Err(QueryError::ZeroScale { object });
    }
    Ok(())
}

/// `B`'s frame in `A`'s frame for one query: `M`, `t`, their `f32` copies and the pad.
#[derive(Clone, Copy, Debug)]
pub struct Relative {
    m: DMat3,
    n: DMat3,
    t: DVec3,
    cols: [Vec3A; 3],
    abs_cols: [Vec3A; 3],
    rows: [Vec3A; 3],
    abs_rows: [Vec3A; 3],
    t32: Vec3A,
    t_b: Vec3A,
    pad: f32,
}

impl Relative {
    /// The relative pose of `B` (at `pb`, every box within `reach_b` of its origin on every
    /// axis) in `A`'s frame (at `pa`, `reach_a`), with tolerance `tolerance` (pairs closer
    /// than it count as overlapping). A non-finite pose, a NaN, infinite or negative reach
    /// or tolerance, or a map out of range is a [`QueryError`].
    pub fn new(
        pa: &Rigid3,
        reach_a: f64,
        pb: &Rigid3,
        reach_b: f64,
        tolerance: f32,
    ) -> Result<Self, QueryError> {
        Self::similarity(&(*pa).into(), reach_a, &(*pb).into(), reach_b, tolerance)
    }

    /// The same for poses with a uniform scale: `M = (σb/σa)·R(qa)ᵀ·R(qb)`,
    /// `t = R(qa)ᵀ·(tb − ta)/σa`, and `B`'s axes tested through `N = (σa/σb)²·Mᵀ` (the
    /// inverse of `M` for unit quaternions; for [`Rigid3`], `σ = 1` and `N = Mᵀ`). A zero
    /// scale is [`QueryError::ZeroScale`]; a negative one reflects.
    pub fn similarity(
        pa: &Similarity3,
        reach_a: f64,
        pb: &Similarity3,
        reach_b: f64,
        tolerance: f32,
    ) -> Result<Self, QueryError> {
        check_pose(pa, Object::A)?;
        check_pose(pb, Object::B)?;
        if let Some(&reach) = [reach_a, reach_b]
            .iter()
            .find(|r| !(r.is_finite() && **r >= 0.0))
        {
            return Err(QueryError::InvalidReach { reach });
        }
        if !(tolerance.is_finite() && tolerance >= 0.0) {
            return Err(QueryError::InvalidTolerance { tolerance });
        }
        let (sa, sb) = (f64::from(pa.scale), f64::from(pb.scale));
        let ra_t = rotation(pa.rotation).transpose();
        let m = ra_t * rotation(pb.rotation) * (sb / sa);
        let t = ra_t * (pb.translation.as_dvec3() - pa.translation.as_dvec3()) / sa;
        let n = if sa == sb {
            m.transpose()
        } else {
            m.transpose() * ((sa / sb) * (sa / sb))
        };
        let t_b = -(n * t);
        // Every placed vertex lies within `|M|·reach_b + |t|` (not `<=`-negated: NaN fails).
        let placed = abs_sum(&m) * reach_b + t.abs().max_element();
        let finite = m.is_finite() && n.is_finite() && t.is_finite() && t_b.is_finite();
        if !(finite && placed <= PLACED_LIMIT) {
            return Err(QueryError::OutOfRange);
        }
        let cols = [m.x_axis, m.y_axis, m.z_axis].map(|c| c.as_vec3a());
        // The columns of N (for a rotation, the rows of M).
        let rows = [n.x_axis, n.y_axis, n.z_axis].map(|c| c.as_vec3a());
        Ok(Relative {
            m,
            n,
            t,
            cols,
            abs_cols: cols.map(Vec3A::abs),
            rows,
            abs_rows: rows.map(Vec3A::abs),
            t32: t.as_vec3a(),
            t_b: t_b.as_vec3a(),
            pad: pad(&m, &n, t, t_b, reach_a, reach_b, tolerance),
        })
    }

    /// `M = R(qa)ᵀ·R(qb)` in `f64`.
    #[inline]
    #[must_use]
    pub fn matrix(&self) -> DMat3 {
        self.m
    }

    /// `t = R(qa)ᵀ·(tb − ta)` in `f64`.
    #[inline]
    #[must_use]
    pub fn translation(&self) -> DVec3 {
        self.t
    }

    /// The pad `P` of the node-pair test (see the module docs).
    #[inline]
    #[must_use]
    pub fn pad(&self) -> f32 {
        self.pad
    }

    /// A point of `B`'s frame placed in `A`'s frame, `M·v + t` in `f64`.
    #[inline]
    #[must_use]
    pub fn place(&self, v: glam::Vec3) -> DVec3 {
        self.m * v.as_dvec3() + self.t
    }

    /// [`Relative::place`] on points in lanes, in place: `p[c][l]` is coordinate `c` of
    /// point `l` (an `f32` value in `f64`). The same operations in the same order as
    /// `place` (`((M₀·x + M₁·y) + M₂·z) + t`, unfused), so the same bits, lane by lane.
    #[inline(always)]
    pub(crate) fn place_lanes<const N: usize>(&self, p: &mut [[f64; N]; 3]) {
        let [m0, m1, m2] = [self.m.x_axis, self.m.y_axis, self.m.z_axis];
        let [x, y, z] = *p;
        for (c, out) in p.iter_mut().enumerate() {
            let (a, b, d, t) = (m0[c], m1[c], m2[c], self.t[c]);
            for l in 0..N {
                out[l] = a * x[l] + b * y[l] + d * z[l] + t;
            }
        }
    }

    /// The 6-axis test on `center ± extent` boxes: false only when the boxes, placed by
    /// this pose, are proven apart by more than the tolerance. NaN anywhere (an overflowed
    /// box) never separates.
    #[inline(always)]
    pub(crate) fn overlaps_ce(&self, ca: Vec3A, ea: Vec3A, cb: Vec3A, eb: Vec3A) -> bool {
        !self.apart(&self.on_a(cb, eb), ca, ea) && !self.apart(&self.on_b(ca, ea), cb, eb)
    }

    /// `B`'s box on `A`'s axes: `M·c_b + t` and `|M|·e_b`, in `f32`. A descent computes it
    /// once for a box of `B` tested against several of `A` (the same bits each time).
    #[inline(always)]
    pub(crate) fn on_a(&self, cb: Vec3A, eb: Vec3A) -> Placed {
        let [c0, c1, c2] = self.cols;
        let [a0, a1, a2] = self.abs_cols;
        Placed {
            center: c0 * cb.x + c1 * cb.y + c2 * cb.z + self.t32,
            reach: a0 * eb.x + a1 * eb.y + a2 * eb.z,
        }
    }

    /// `A`'s box on `B`'s axes: `N·c_a + t_b` and `|N|·e_a`, in `f32`.
    #[inline(always)]
    pub(crate) fn on_b(&self, ca: Vec3A, ea: Vec3A) -> Placed {
        let [r0, r1, r2] = self.rows;
        let [b0, b1, b2] = self.abs_rows;
        Placed {
            center: r0 * ca.x + r1 * ca.y + r2 * ca.z + self.t_b,
            reach: b0 * ea.x + b1 * ea.y + b2 * ea.z,
        }
    }

    /// True when the three axes of a box `c ± e` separate it from the other box placed on
    /// them, `placed`, by more than the pad.
    #[inline(always)]
    pub(crate) fn apart(&self, placed: &Placed, c: Vec3A, e: Vec3A) -> bool {
        let d = (placed.center - c).abs();
        let r = placed.reach + e + Vec3A::splat(self.pad);
        d.cmpgt(r).any()
    }

    /// The pose in lanes for the descent's steps: see [`Crosswise`].
    #[inline(always)]
    pub(crate) fn crosswise(&self) -> Crosswise {
        let lanes = |rows: [Vec3A; 3], cols: [Vec3A; 3], t_b: Vec3A, t: Vec3A| {
            // Lanes 0 and 1 take `on_b`'s terms, lanes 2 and 3 `on_a`'s.
            let mix = |b: Vec3A, a: Vec3A| [0, 1, 2].map(|k| Vec4::new(b[k], b[k], a[k], a[k]));
            LanePose {
                w: [0, 1, 2].map(|j| mix(rows[j], cols[j])),
                t: mix(t_b, t),
            }
        };
        let (rows, abs_rows, cols, abs_cols) = (self.rows, self.abs_rows, self.cols, self.abs_cols);
        let (t_b, t) = (self.t_b, self.t32);
        Crosswise {
            mixed: (lanes(rows, cols, t_b, t), lanes(abs_rows, abs_cols, t_b, t)),
            on_a: (lanes(cols, cols, t, t), lanes(abs_cols, abs_cols, t, t)),
            on_b: (
                lanes(rows, rows, t_b, t_b),
                lanes(abs_rows, abs_rows, t_b, t_b),
            ),
            pad: Vec4::splat(self.pad),
        }
    }

    /// The same test on `min`/`max` boxes (`a` in `A`'s frame, `b` in `B`'s), read back as
    /// center and extent with the rounding the pad covers; for the reaches given to
    /// [`Relative::new`]. An empty box never overlaps; NaN faces always do (conservative).
    #[must_use]
    pub fn overlaps(&self, a: &crate::aabb::Aabb3, b: &crate::aabb::Aabb3) -> bool {
        if a.min.cmpgt(a.max).any() || b.min.cmpgt(b.max).any() {
            return false;
        }
        self.overlaps_ce(a.center(), a.half_extents(), b.center(), b.half_extents())
    }

    /// The 9 cross axes `e_i × M_j` in `f64` on two `center ± extent` boxes (the roots):
    /// true when one of them proves the boxes apart (see the module docs).
    pub(crate) fn roots_separated(
        &self,
        ca: Vec3A,
        ea: Vec3A,
        cb: Vec3A,
        eb: Vec3A,
        margin: f64,
    ) -> bool {
        let (ca, ea, cb, eb) = (ca.as_dvec3(), ea.as_dvec3(), cb.as_dvec3(), eb.as_dvec3());
        let d = self.m * cb + self.t - ca;
        let mt = self.m.transpose();
        let cols = [self.m.x_axis, self.m.y_axis, self.m.z_axis];
        for i in 0..3 {
            let axis = DVec3::AXES[i];
            for col in cols {
                let l = axis.cross(col);
                let norm = l.abs().element_sum();
                let radius = l.abs().dot(ea)
                    + (mt * l).abs().dot(eb)
                    + norm * (f64::from(self.pad) + margin);
                // Not `>`-negated: NaN never separates.
                if l.dot(d).abs() > radius {
                    return true;
                }
            }
        }
        false
    }

    /// The `f64` margin of the root cross-axis test: `2^-46·(1 + m)(R_a + R_b + T)`.
    pub(crate) fn cross_margin(&self, reach_a: f64, reach_b: f64) -> f64 {
        let (m, t) = norms(&self.m, &self.n, self.t, self.t_b.as_dvec3());
        pow2(-46) * (1.0 + m) * (reach_a + reach_b + t)
    }
}

/// The largest row or column sum of `|m|`.
fn abs_sum(m: &DMat3) -> f64 {
    let abs = DMat3::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
    let cols = [abs.x_axis, abs.y_axis, abs.z_axis].map(DVec3::element_sum);
    let rows = (0..3).map(|i| abs.row(i).element_sum());
    rows.chain(cols).fold(0.0, f64::max)
}

/// `m` (largest row or column sum of `|M|` or `|N|`) and `T` (largest `|t_i|` or `|t_B,i|`).
fn norms(m: &DMat3, n: &DMat3, t: DVec3, t_b: DVec3) -> (f64, f64) {
    let m = abs_sum(m).max(abs_sum(n)) * (1.0 + pow2(-40));
    let t = t.abs().max_element().max(t_b.abs().max_element()) * (1.0 + pow2(-40));
    (m, t)
}

/// The pad `P` of the module docs, rounded up to `f32`.
fn pad(
    m: &DMat3,
    n: &DMat3,
    t: DVec3,
    t_b: DVec3,
    reach_a: f64,
    reach_b: f64,
    tolerance: f32,
) -> f32 {
    let (mm, tt) = norms(m, n, t, t_b);
    let grow = 1.0 + pow2(-18);
    let (ra, rb) = (reach_a * grow, reach_b * grow);
    let tiny = pow2(-148);
    let (delta_a, delta_b) = (2.0 * U * ra + tiny, 2.0 * U * rb + tiny);
    let max_entry = [m.x_axis, m.y_axis, m.z_axis, n.x_axis, n.y_axis, n.z_axis]
        .iter()
        .map(|c| c.abs().max_element())
        .fold(0.0, f64::max);
    let eps_m = U * max_entry + pow2(-150);
    let eps_64 = pow2(-50) * (mm * rb + tt);
    // ‖NM − I‖_F computed in f64, plus its own rounding (γ₆₄(3)·m² per entry, 9 entries).
    let e = *n * *m - DMat3::IDENTITY;
    let frob = sqrt(
        [e.x_axis, e.y_axis, e.z_axis]
            .iter()
            .map(|c| c.length_squared())
            .sum::<f64>(),
    ) + 9.0 * pow2(-50) * mm * mm;
    // Past 2^126 the f32 sums of a node-pair test could overflow (an infinite distance
    // against a finite radius would separate): no pair is culled there.
    if (1.0 + mm) * (ra + rb + tt) >= pow2(126) {
        return f32::INFINITY;
    }
    let sum = (1.0 + mm) * (delta_a + delta_b + eps_64 + f64::from(tolerance))
        + 3.0 * eps_m * (ra + rb)
        + 2.0 * (U + pow2(-50) * mm) * tt
        + tiny
        + frob * sqrt(3.0) * rb
        + 12.0 * U * (1.0 + mm) * (ra + rb + tt);
    round_up(sum * (1.0 + pow2(-20)))
}

/// One box placed on the other box's axes ([`Relative::on_a`], [`Relative::on_b`]): its
/// center there and its reach along each axis.
pub(crate) struct Placed {
    center: Vec3A,
    reach: Vec3A,
}

/// Four boxes in lanes: `center[k]` and `extent[k]` hold coordinate `k` of each.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lanes {
    pub center: [Vec4; 3],
    pub extent: [Vec4; 3],
}

impl Lanes {
    /// Four boxes, `center ± extent`, one per lane.
    #[inline(always)]
    pub(crate) fn new(center: [Vec3A; 4], extent: [Vec3A; 4]) -> Self {
        Lanes {
            center: crate::simd::transpose3(center),
            extent: crate::simd::transpose3(extent),
        }
    }
}

/// A linear map and translation with each entry per lane: coordinate `k` of a point in
/// lanes maps to `(w[0][k]·v_0 + w[1][k]·v_1) + w[2][k]·v_2 + t[k]`, the order of the `Vec3A`
/// sums of [`Relative::on_a`] and [`Relative::on_b`] (so, per lane, the same bits).
#[derive(Clone, Copy, Debug)]
struct LanePose {
    w: [[Vec4; 3]; 3],
    t: [Vec4; 3],
}

impl LanePose {
    #[inline(always)]
    fn times(&self, v: &[Vec4; 3]) -> [Vec4; 3] {
        let w = &self.w;
        [0, 1, 2].map(|k| w[0][k] * v[0] + w[1][k] * v[1] + w[2][k] * v[2])
    }
}

/// The relative pose in lanes, built once per query, for the descent's two kinds of step:
/// - a step that splits a node of each tree holds two children of `A` in lanes 0 and 1 and
///   two of `B` in lanes 2 and 3; [`Crosswise::place`] places all four on the other tree's
///   axes at once ([`Relative::on_b`] in lanes 0 and 1, [`Relative::on_a`] in lanes 2 and
///   3), and [`Crosswise::apart_pairs`] tests the four pairs of a child of each;
/// - a step against a primitive holds four boxes of the other tree;
///   [`Crosswise::place_on`] places them and [`Crosswise::apart_from`] tests them against
///   the primitive's box.
///
/// Per lane, the same bits as the one-box test [`Relative::overlaps_ce`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Crosswise {
    /// `(M or N, |M| or |N|)` per lane: `N` in lanes 0 and 1, `M` in lanes 2 and 3.
    mixed: (LanePose, LanePose),
    /// `M` in every lane (boxes of `B` onto `A`'s axes).
    on_a: (LanePose, LanePose),
    /// `N` in every lane (boxes of `A` onto `B`'s axes).
    on_b: (LanePose, LanePose),
    pad: Vec4,
}

/// Which tree's axes boxes in lanes are placed on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum AxesOf {
    /// `A`'s: the boxes are `B`'s.
    A,
    /// `B`'s: the boxes are `A`'s.
    B,
}

/// Boxes `x` placed by `(map, |map|)`.
#[inline(always)]
fn placed_by(pose: &(LanePose, LanePose), x: &Lanes) -> Lanes {
    let c = pose.0.times(&x.center);
    Lanes {
        center: [0, 1, 2].map(|k| c[k] + pose.0.t[k]),
        extent: pose.1.times(&x.extent),
    }
}

impl Crosswise {
    /// Two boxes of `A` (lanes 0, 1) and two of `B` (lanes 2, 3), each placed on the other
    /// tree's axes.
    #[inline(always)]
    pub(crate) fn place(&self, x: &Lanes) -> Lanes {
        placed_by(&self.mixed, x)
    }

    /// Four boxes of one tree placed on `axes`, the other tree's.
    #[inline(always)]
    pub(crate) fn place_on(&self, axes: AxesOf, x: &Lanes) -> Lanes {
        placed_by(
            if axes == AxesOf::A {
                &self.on_a
            } else {
                &self.on_b
            },
            x,
        )
    }

    /// The pairs of a child of each tree that the 6-axis test separates, as a mask: bit
    /// `2i + j` for `A`'s child in lane `i` and `B`'s child in lane `2 + j`. `placed` is
    /// [`Crosswise::place`] of `x`.
    #[inline(always)]
    pub(crate) fn apart_pairs(&self, x: &Lanes, placed: &Lanes) -> u32 {
        // Lanes per pair `(i, j)`: `A`'s side repeated (`xxyy`), `B`'s alternated (`zwzw`).
        let mut apart = glam::BVec4A::FALSE;
        for k in 0..3 {
            let (a_c, a_e) = (x.center[k].xxyy(), x.extent[k].xxyy());
            let (b_c, b_e) = (x.center[k].zwzw(), x.extent[k].zwzw());
            // `B`'s children on `A`'s axes, against `A`'s children.
            let (on_a_c, on_a_e) = (placed.center[k].zwzw(), placed.extent[k].zwzw());
            apart |= (on_a_c - a_c).abs().cmpgt(on_a_e + a_e + self.pad);
            // `A`'s children on `B`'s axes, against `B`'s children.
            let (on_b_c, on_b_e) = (placed.center[k].xxyy(), placed.extent[k].xxyy());
            apart |= (on_b_c - b_c).abs().cmpgt(on_b_e + b_e + self.pad);
        }
        apart.bitmask()
    }

    /// The boxes `x` of one tree that the 6-axis test separates from the box `c ± e` of
    /// the other, as a lane mask: `x_placed` is `x` placed on the other tree's axes
    /// ([`Crosswise::place_on`]) and `placed` the one box placed on `x`'s tree's axes.
    #[inline(always)]
    pub(crate) fn apart_from(
        &self,
        x: &Lanes,
        x_placed: &Lanes,
        (c, e): (Vec3A, Vec3A),
        placed: &Placed,
    ) -> u32 {
        let mut apart = glam::BVec4A::FALSE;
        for k in 0..3 {
            // `x` on the other tree's axes, against the one box.
            let (c, e) = (Vec4::splat(c[k]), Vec4::splat(e[k]));
            apart |= (x_placed.center[k] - c)
                .abs()
                .cmpgt(x_placed.extent[k] + e + self.pad);
            // The one box on `x`'s tree's axes, against `x`.
            let (pc, pe) = (Vec4::splat(placed.center[k]), Vec4::splat(placed.reach[k]));
            apart |= (pc - x.center[k]).abs().cmpgt(pe + x.extent[k] + self.pad);
        }
        apart.bitmask()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    /// Points placed in lanes are placed one at a time, bit for bit.
    #[test]
    fn points_placed_in_lanes_are_placed_bit_for_bit() {
        let mut next = crate::num::uniform(0x5851_f42d_4c95_7f2d);
        let mut next = move || next() as f32;
        for _ in 0..50 {
            let mut pose = || {
                Similarity3::new(
                    1.0 + next().abs(),
                    Quat::from_xyzw(next(), next(), next(), next()).normalize(),
                    Vec3A::new(next(), next(), next()) * 100.0,
                )
            };
            let (pa, pb) = (pose(), pose());
            let rel = Relative::similarity(&pa, 1e3, &pb, 1e3, 0.0).expect("a finite pose");
            let points: [glam::Vec3; 8] =
                core::array::from_fn(|_| glam::Vec3::new(next(), next(), next()) * 1e3);
            let mut lanes = [0, 1, 2].map(|c| points.map(|p| f64::from(p[c])));
            rel.place_lanes(&mut lanes);
            for (l, &p) in points.iter().enumerate() {
                let placed = rel.place(p);
                for c in 0..3 {
                    assert_eq!(lanes[c][l].to_bits(), placed[c].to_bits());
                }
            }
        }
    }

    /// Two boxes of each tree in lanes, placed crosswise, give lane by lane the placed
    /// bits of `on_b` and `on_a`, and pair by pair the answer of `overlaps_ce`; four boxes
    /// of either tree against one box of the other, the same.
    #[test]
    fn boxes_placed_crosswise_give_the_same_bits() {
        let mut next = crate::num::uniform(0x9e37_79b9_7f4a_7c15);
        let mut next = move || next() as f32;
        let (mut apart, mut near, mut one_near) = (0, 0, 0);
        for _ in 0..200 {
            let mut pose = || Rigid3 {
                rotation: Quat::from_xyzw(next(), next(), next(), next()).normalize(),
                translation: Vec3A::new(next(), next(), next()) * 0.5,
            };
            let (pa, pb) = (pose(), pose());
            let rel = Relative::new(&pa, 4.0, &pb, 4.0, 0.0).expect("a finite pose");
            let mut corner = || Vec3A::new(next(), next(), next());
            // Lanes 0 and 1: boxes of `A`; lanes 2 and 3: boxes of `B`.
            let boxes: [(Vec3A, Vec3A); 4] = core::array::from_fn(|_| (corner(), corner().abs()));
            let x = Lanes::new(boxes.map(|b| b.0), boxes.map(|b| b.1));
            let cross = rel.crosswise();
            let placed = cross.place(&x);
            let lane = |v: &[Vec4; 3], l: usize| Vec3A::new(v[0][l], v[1][l], v[2][l]);
            for (l, &(c, e)) in boxes.iter().enumerate() {
                let p = if l < 2 {
                    rel.on_b(c, e)
                } else {
                    rel.on_a(c, e)
                };
                assert_eq!(lane(&placed.center, l).to_array(), p.center.to_array());
                assert_eq!(lane(&placed.extent, l).to_array(), p.reach.to_array());
            }
            // Four boxes of either tree against one of the other.
            let (c, e) = (corner(), corner().abs());
            for axes in [AxesOf::A, AxesOf::B] {
                let x_placed = cross.place_on(axes, &x);
                let of_a = axes == AxesOf::A;
                let one_placed = if of_a { rel.on_b(c, e) } else { rel.on_a(c, e) };
                let p = |c, e| if of_a { rel.on_a(c, e) } else { rel.on_b(c, e) };
                let mask = cross.apart_from(&x, &x_placed, (c, e), &one_placed);
                for (l, &(cl, el)) in boxes.iter().enumerate() {
                    assert_eq!(
                        lane(&x_placed.center, l).to_array(),
                        p(cl, el).center.to_array()
                    );
                    assert_eq!(
                        lane(&x_placed.extent, l).to_array(),
                        p(cl, el).reach.to_array()
                    );
                    let overlaps = if of_a {
                        rel.overlaps_ce(c, e, cl, el)
                    } else {
                        rel.overlaps_ce(cl, el, c, e)
                    };
                    assert_eq!(mask >> l & 1 == 0, overlaps);
                    one_near += usize::from(overlaps);
                }
            }
            let mask = cross.apart_pairs(&x, &placed);
            for i in 0..2 {
                for j in 0..2 {
                    let ((ca, ea), (cb, eb)) = (boxes[i], boxes[2 + j]);
                    let overlaps = rel.overlaps_ce(ca, ea, cb, eb);
                    assert_eq!(mask >> (2 * i + j) & 1 == 0, overlaps);
                    if overlaps {
                        near += 1;
                    } else {
                        apart += 1;
                    }
                }
            }
        }
        assert!(apart > 100 && near > 100, "{apart} apart, {near} near");
        assert!(
            one_near > 200 && one_near < 1400,
            "{one_near} of 1,600 near one box"
        );
    }

    /// A box placed once gives `overlaps_ce`'s answer on every pair, either side placed.
    #[test]
    fn a_box_placed_once_gives_the_same_answers() {
        let mut next = crate::num::uniform(0x2545_f491_4f6c_dd1d);
        let mut next = move || next() as f32;
        let pose = |x: f32, y: f32, z: f32, w: f32| Rigid3 {
            rotation: Quat::from_xyzw(x, y, z, w).normalize(),
            translation: Vec3A::new(x, y, z) * 0.5,
        };
        let (mut same, mut apart) = (0, 0);
        for _ in 0..200 {
            let pa = pose(next(), next(), next(), next());
            let pb = pose(next(), next(), next(), next());
            let rel = Relative::new(&pa, 4.0, &pb, 4.0, 0.0).expect("a finite pose");
            let mut corner = || Vec3A::new(next(), next(), next());
            let (ca, cb) = (corner(), corner());
            let (ea, eb) = (corner().abs(), corner().abs());
            let expected = rel.overlaps_ce(ca, ea, cb, eb);
            let (b_on_a, a_on_b) = (rel.on_a(cb, eb), rel.on_b(ca, ea));
            assert_eq!(
                !rel.apart(&b_on_a, ca, ea) && !rel.apart(&a_on_b, cb, eb),
                expected
            );
            if expected { same += 1 } else { apart += 1 }
        }
        assert!(
            same > 20 && apart > 20,
            "both answers drawn: {same} {apart}"
        );
    }
}
