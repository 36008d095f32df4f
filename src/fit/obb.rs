//! Oriented bounding boxes and their fits.

use super::bound::{Bounded, sum_magnitude};
use super::cloud::{self, exact};
use crate::num::pow2;
use alloc::vec;
use alloc::vec::Vec;

use super::eigen::principal_axes;
use super::extremal::{self, frame_from};
use super::hull::{Hull, Solid, convex_hull, direction_key};
use super::rect::{self, rectangle_frame};
use super::search::compass_search;
use super::sweep;
use super::{Fit, FitError};
use crate::aabb::Aabb3;
use glam::{DMat3, DQuat, DVec3, Mat3A, Vec3, Vec3A};

/// An oriented box: the points `x` with `|(x − center)·axis_k| <= half_extents[k]` for each
/// column `axis_k` of `rotation`.
///
/// The statement is exact on the `f32` fields as given: fitted rotations are orthonormal to
/// within `f32` rounding, and the box is the parallelepiped those three slabs cut out.
///
/// **Both readings.** As `f32` axes are never exactly orthonormal, the slab set differs
/// slightly from the set `center + rotation·u` with `|u_k| <= half_extents[k]` (the box
/// whose corners are `c ± R·h`). A fitted box ([`Obb3::fit`], [`Obb3::from_axes`]) contains
/// every input point under both readings, exactly: its half-extents are widened by a proven
/// bound from the measured orthonormality defect of its rotation.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::AnyBitPattern))]
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Obb3 {
    /// The center.
    pub center: Vec3A,
    /// The half-extents along the box axes.
    pub half_extents: Vec3A,
    /// The box axes as columns (orthonormal, right-handed, for fitted boxes).
    pub rotation: Mat3A,
}

/// Where a fitted box is centered.
#[derive(Clone, Copy, Debug)]
enum Center {
    /// Halfway between the extreme projections on each axis (the smallest box).
    Midrange,
    /// At a given point, with symmetric half-extents (the PCA baseline's mean).
    At(DVec3),
}

impl Obb3 {
    /// The box fitted to `points` with the given effort; it contains every point under
    /// both readings (see [`Obb3`]).
    ///
    /// # Errors
    /// [`FitError::Empty`] for no points, [`FitError::NonFinite`] for a non-finite point,
    /// [`FitError::Overflow`] when a half-extent would overflow `f32`.
    pub fn fit(points: &[Vec3], fit: Fit) -> Result<Self, FitError> {
        match fit {
            Fit::Pca => fit_pca(points, &cloud::validate(points)?),
            // The fast fit checks the points in its one sweep.
            Fit::Fast => fit_fast(points, cloud::summarize(points)?),
            Fit::Tight => fit_tight(points, &cloud::validate(points)?),
        }
    }

    /// The smallest box with the axes of `rotation` (rounded outward, midrange center)
    /// holding `points` under both readings (see [`Obb3`]).
    ///
    /// # Errors
    /// [`FitError::Empty`] for no points, [`FitError::NonFinite`] for a non-finite point,
    /// [`FitError::NotOrthonormal`] for a rotation that is not orthonormal to within
    /// `2^-10`, [`FitError::Overflow`] when a half-extent would overflow `f32`.
    pub fn from_axes(points: &[Vec3], rotation: Mat3A) -> Result<Self, FitError> {
        let bounds = cloud::validate(points)?;
        let [obb] = fit_axes(points, &bounds, [rotation], Center::Midrange);
        obb
    }

    /// True when `p` may lie in the box: never false for a point of the box, and true only
    /// within `2^-47·Σ_j |p_j − c_j|` of it (an `f64` evaluation with the lemma of the fit
    /// module's certified rounding). NaN gives false.
    #[inline]
    #[must_use]
    pub fn contains_point(&self, p: Vec3A) -> bool {
        // (p − c)·a_k: 3 subtractions, 3 products, 2 sums: γ(4)·Σ|p_j − c_j|·|a_kj|.
        let d = p.as_dvec3() - self.center.as_dvec3();
        (0..3).all(|k| {
            let axis = self.rotation.col(k).as_dvec3();
            let projection = Bounded {
                value: d.dot(axis).abs(),
                scale: d.abs().dot(axis.abs()),
            };
            projection.lower_f64() <= f64::from(self.half_extents[k])
        })
    }

    /// The volume `8·h0·h1·h2` (the axes taken as orthonormal).
    #[inline]
    #[must_use]
    pub fn volume(&self) -> f32 {
        (8.0 * self.half_extents.as_dvec3().element_product()) as f32
    }

    /// An axis-aligned box, rounded outward, that contains the whole box.
    ///
    /// The box is `c + Σ_k s_k·b_k` with `|s_k| <= h_k`, where `b_k = (a_{k+1} × a_{k+2}) / det`
    /// is the dual basis (`b_k·a_j = δ_kj`); so its AABB is `c ± e`, `e = Σ_k |b_k|·h_k`.
    /// Error: each cross-product entry is one rounding (its products of `f32` are exact),
    /// `det = a_0·(a_1 × a_2)` is off by `γ(4)·Δ` with `Δ = Σ_j |a_0j|·|(a_1 × a_2)_j|`, so with
    /// `ρ = Δ/|det|` (1 for orthonormal axes) the computed `e` is within `(5 + 4ρ)·u·e` and
    /// `c ∓ e` within `γ(8)·(|c ∓ e| + |c| + (1 + ρ)·e)`: the lemma's form. A singular
    /// rotation bounds no box and gives the whole space; NaN gives [`Aabb3::NAN`]; a
    /// negative half-extent, [`Aabb3::EMPTY`].
    #[must_use]
    pub fn aabb(&self) -> Aabb3 {
        let h = self.half_extents.as_dvec3();
        let c = self.center.as_dvec3();
        if h.is_nan() || c.is_nan() || self.rotation.is_nan() {
            return Aabb3::NAN;
        }
        if h.min_element() < 0.0 {
            return Aabb3::EMPTY;
        }
        let a = [0, 1, 2].map(|k| self.rotation.col(k).as_dvec3());
        let dual = [0, 1, 2].map(|k| a[(k + 1) % 3].cross(a[(k + 2) % 3]));
        let det = a[0].dot(dual[0]).abs();
        let spread = a[0].abs().dot(dual[0].abs()) / det;
        let e: DVec3 = (0..3).map(|k| dual[k].abs() * (h[k] / det)).sum();
        let unbounded = Aabb3::new(Vec3A::NEG_INFINITY, Vec3A::INFINITY);
        if !(e.is_finite() && c.is_finite() && spread.is_finite()) {
            return unbounded;
        }
        let face = |i: usize, sign: f64| Bounded {
            value: c[i] + sign * e[i],
            scale: c[i].abs() + (1.0 + spread) * e[i],
        };
        Aabb3::new(
            Vec3A::from_array([0, 1, 2].map(|i| face(i, -1.0).lower())),
            Vec3A::from_array([0, 1, 2].map(|i| face(i, 1.0).upper())),
        )
    }
}

/// The `f32` rotation nearest to an orthonormal `f64` frame.
fn to_f32(frame: DMat3) -> Mat3A {
    Mat3A::from_cols(
        frame.x_axis.as_vec3a(),
        frame.y_axis.as_vec3a(),
        frame.z_axis.as_vec3a(),
    )
}

/// The boxes with the given axes holding `points`, certified.
///
/// For an axis `a` (exact `f32`), [`sweep::projection_ranges`] gives a range `[lo, hi]` such
/// that every exact projection `p·a` lies in `[lo − γ(2)S, hi + γ(2)S]`, with
/// `S = Σ_j |a_j|·max(|min_j|, |max_j|)` over the bounding box. With the center `c` rounded
/// to `f32` and `c·a` within `γ(2)·C` (`C = Σ_j |c_j a_j|`), every `|(p − c)·a|` is at most
/// `max(hi − c·a, c·a − lo) + γ(2)(S + C)`; one more rounding for that difference, and the
/// lemma's `Bounded::upper` with `scale = S + C` is a certified half-extent.
fn fit_axes<const N: usize>(
    points: &[Vec3],
    bounds: &Aabb3,
    rotations: [Mat3A; N],
    center: Center,
) -> [Result<Obb3, FitError>; N] {
    let ranges = sweep::projection_ranges(points, bounds, rotations);
    core::array::from_fn(|r| {
        let (lo, hi) = ranges[r];
        certified_box(rotations[r], lo, hi, bounds, center)
    })
}

/// The certified box with axes `rotation` whose computed projection range is `[lo, hi]`
/// (see [`fit_axes`]), widened to hold under both readings ([`widened`]); an error for a
/// rotation that is not orthonormal or a half-extent beyond `f32`.
///
/// The center is moved into the points' bounding box before rounding
/// ([`cloud::round_within`]), so it is finite; the half-extents are derived from it.
fn certified_box(
    rotation: Mat3A,
    lo: DVec3,
    hi: DVec3,
    bounds: &Aabb3,
    center: Center,
) -> Result<Obb3, FitError> {
    let defect = orthonormality_defect(rotation)?;
    let axes = [0, 1, 2].map(|k| rotation.col(k).as_dvec3());
    let reach = bounds.min.abs().max(bounds.max.abs()).as_dvec3();
    let c = match center {
        Center::Midrange => (0..3).map(|k| axes[k] * (0.5 * (lo[k] + hi[k]))).sum(),
        Center::At(c) => c,
    };
    let center = cloud::round_within(c, bounds);
    let cd = center.as_dvec3();
    let half_extent = |k: usize| {
        let cc = cd.dot(axes[k]);
        Bounded {
            value: (hi[k] - cc).max(cc - lo[k]),
            scale: axes[k].abs().dot(reach + cd.abs()),
        }
        .upper()
    };
    let slabs = Vec3A::new(half_extent(0), half_extent(1), half_extent(2));
    let half_extents = widened(slabs, defect);
    if !half_extents.is_finite() {
        return Err(FitError::Overflow);
    }
    Ok(Obb3 {
        center,
        half_extents,
        rotation,
    })
}

/// Columns this far from orthonormal (`max_k Σ_j |a_k·a_j − δ_kj|`) are refused.
const MAX_DEFECT: f32 = 1.0 / 1024.0;

/// Upper bounds `r_k >= Σ_j |E_kj|` on the rows of `E = RᵀR − I`, each 0 when its row is
/// exactly 0; an error when an entry is not finite or `max_k r_k > 2^-10`.
///
/// `E_kj = Σ_i a_ik·a_ij − δ_kj` is a sum of four exact `f64` terms (products of `f32`), so
/// [`sum_magnitude`] bounds `|E_kj|` with 3 roundings; the row's sum of three such adds 2:
/// 11 roundings of non-negative terms, within `γ(11) <= 2·γ(8)` of the real bound, which the
/// lemma covers with `scale = value`.
fn orthonormality_defect(rotation: Mat3A) -> Result<Vec3A, FitError> {
    let a = [0, 1, 2].map(|k| rotation.col(k).as_dvec3());
    let entry = |k: usize, j: usize| {
        let p = a[k] * a[j];
        sum_magnitude([p.x, p.y, p.z, if k == j { -1.0 } else { 0.0 }])
    };
    let row = |k: usize| {
        let value = entry(k, 0) + entry(k, 1) + entry(k, 2);
        Bounded {
            value,
            scale: value,
        }
        .upper()
    };
    let r = Vec3A::new(row(0), row(1), row(2));
    let defect = if rotation.is_finite() {
        r.max_element()
    } else {
        f32::NAN
    };
    if defect <= MAX_DEFECT {
        Ok(r)
    } else {
        Err(FitError::NotOrthonormal { defect })
    }
}

/// Half-extents `h'` that hold under both readings, from slab half-extents `h` and row
/// bounds `r` of `E = RᵀR − I` ([`orthonormality_defect`], `n = max_k r_k <= 2^-10`).
///
/// A point with `s = Rᵀ(p − c)`, `|s_k| <= h_k`, is `p = c + R·u` with `u = (I + E)⁻¹ s`
/// (`R` is invertible as `n < 1`). From `u = s − E·u`: `‖u‖∞ <= ‖s‖∞ + n·‖u‖∞`, so
/// `‖u‖∞ <= H/(1 − n)` with `H = max_j h_j`, and `|u_k| <= h_k + r_k·H/(1 − n)`. That sum
/// rounds 4 times (`1 − n`, the quotient, the product with `r_k`, the sum), all terms
/// positive, so within `γ(4)` of it relative: the lemma with `scale = 0` rounds it up. A row
/// with `r_k = 0` keeps `h_k` as it is.
fn widened(h: Vec3A, r: Vec3A) -> Vec3A {
    let reach = f64::from(h.max_element()) / (1.0 - f64::from(r.max_element()));
    Vec3A::from_array([0, 1, 2].map(|k| {
        if r[k] == 0.0 {
            return h[k];
        }
        Bounded {
            value: f64::from(h[k]) + f64::from(r[k]) * reach,
            scale: 0.0,
        }
        .upper()
    }))
}

/// The box of least volume, then least surface (for flat sets, whose volumes tie at 0),
/// among the candidates that exist; [`FitError::Overflow`] when none does (every box that
/// is refused overflows: the coordinate axes are always among the candidates).
fn smallest(boxes: impl IntoIterator<Item = Result<Obb3, FitError>>) -> Result<Obb3, FitError> {
    boxes
        .into_iter()
        .filter_map(Result::ok)
        .min_by(|a, b| {
            let (ka, kb) = (key(a), key(b));
            ka.0.total_cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
        })
        .ok_or(FitError::Overflow)
}

/// The order of [`smallest`]: the volume key `h0·h1·h2`, then the surface key
/// `h0·h1 + h1·h2 + h2·h0` (finite in `f64` for the finite half-extents of `f32`).
fn key(b: &Obb3) -> (f64, f64) {
    let h = b.half_extents.as_dvec3();
    (h.element_product(), h.x * h.y + h.y * h.z + h.z * h.x)
}

/// The PCA baseline: eigenvectors of the covariance of the distinct points, centered on
/// their mean, half-extents the largest `|projection|` about it.
fn fit_pca(points: &[Vec3], bounds: &Aabb3) -> Result<Obb3, FitError> {
    let distinct = cloud::unique(points);
    let moments = cloud::summary(&distinct);
    let (mean, axes) = (moments.mean, principal_axes(moments.covariance));
    let [obb] = fit_axes(&distinct, bounds, [to_f32(axes)], Center::At(mean));
    obb
}

/// The fast fit: the smallest midrange box over the coordinate axes, the PCA axes (of the
/// points as given) and the best frame of the extremal points along the 13 sample
/// directions ([`super::sweep::projections`]). Those few points stand in for the points:
/// DiTO's frames of the first 14 and the face frames of the hull of all 26 are ranked by
/// the volume they give them ([`extremal::best_frame`]), and the best is measured on
/// every point.
fn fit_fast(points: &[Vec3], summary: cloud::Summary) -> Result<Obb3, FitError> {
    let bounds = &summary.bounds;
    let pca = principal_axes(summary.covariance);
    let mut extremal = summary.extremal;
    let mut dito = [DVec3::ZERO; 14];
    dito.copy_from_slice(&extremal[..14]);
    extremal.sort_by(|a, b| {
        a.to_array()
            .partial_cmp(&b.to_array())
            .unwrap_or(core::cmp::Ordering::Equal)
    });
    extremal.dedup();
    let best = extremal::best_frame(&extremal, &dito).unwrap_or(pca);
    // The coordinate axes' projection range is the bounding box itself, exactly.
    let aabb = certified_box(
        Mat3A::IDENTITY,
        bounds.min.as_dvec3(),
        bounds.max.as_dvec3(),
        bounds,
        Center::Midrange,
    );
    let [best] = fit_axes(points, bounds, [to_f32(best)], Center::Midrange);
    // The PCA axes are measured on every point only when their box may be the smallest.
    let pca = to_f32(pca);
    let pca = match &best {
        Ok(b) if least_key(pca, &extremal, bounds) > key(b).0 => None,
        _ => Some(fit_axes(points, bounds, [pca], Center::Midrange)[0]),
    };
    smallest(pca.into_iter().chain([best, aabb]))
}

/// A lower bound on the volume key `h0·h1·h2` of the certified box with the axes of
/// `rotation` around any points that include `some` (within `bounds`).
///
/// Such a box's half-extents are at least half the exact extents of `some` on its columns.
/// Each extent is computed from projections within `γ(2)·S` of exact (`S = Σ_j |a_j|·reach_j`,
/// as in [`fit_axes`]), and their difference rounds once: so the computed extent, less
/// `2^-52` of itself and less `2^-40·S`, is below the exact one. The product of three
/// such halves rounds twice more, which the final factor `1 − 2^-40` covers.
fn least_key(rotation: Mat3A, some: &[DVec3], bounds: &Aabb3) -> f64 {
    let frame = DMat3::from_cols(
        rotation.x_axis.as_dvec3(),
        rotation.y_axis.as_dvec3(),
        rotation.z_axis.as_dvec3(),
    );
    let reach = bounds.min.abs().max(bounds.max.abs()).as_dvec3();
    let extents = extremal::extents(&frame, some);
    let half = |k: usize| {
        let pad = pow2(-40) * frame.col(k).abs().dot(reach);
        0.5 * (extents[k] * (1.0 - pow2(-52)) - pad).max(0.0)
    };
    half(0) * half(1) * half(2) * (1.0 - pow2(-40))
}

/// The tight fit's candidate frames and the points that decide them (the hull vertices
/// when the points span 3D, else all of them).
pub(crate) struct TightFrames {
    /// Candidate frames, best first.
    pub frames: Vec<DMat3>,
    /// The hull vertices (or every point for a flat set).
    pub support: Vec<DVec3>,
}

/// How many face normals (largest faces first) get a min-area rectangle.
const MAX_FACE_NORMALS: usize = 100;
/// How many of the best face frames are refined by a local search over rotations.
const REFINED: usize = 4;

/// Candidate frames of the tight fit: for each hull face normal `n`, the minimum-area
/// rectangle of the hull projected along `n`; the best few are refined by a compass search
/// over rotations `R·exp(ω)`. Flat sets: the plane's normal and its min-area rectangle;
/// collinear sets: the line; a single point: the identity.
pub(crate) fn tight_frames(points: &[DVec3]) -> TightFrames {
    let one = |frame: Option<DMat3>| TightFrames {
        frames: vec![frame.unwrap_or(DMat3::IDENTITY)],
        support: points.to_vec(),
    };
    match convex_hull(points) {
        Hull::Point => one(None),
        Hull::Segment(line) => one(frame_from(line, DVec3::ZERO)),
        Hull::Planar(normal) => one(Some(rectangle_frame(normal, points))),
        Hull::Solid(hull) => {
            let scored = face_frames(&hull, MAX_FACE_NORMALS, REFINED);
            let frames = scored
                .iter()
                .take(REFINED)
                .map(|&(_, f)| refine(f, &hull))
                .collect();
            TightFrames {
                frames,
                support: hull.vertices,
            }
        }
    }
}

/// The `keep` best frames among the distinct face normals of a hull (the `normals` of
/// largest area, [`face_normals`]): for each normal, the frame of the minimum-area
/// rectangle around the hull along it (found from the hull's outline along it,
/// [`Solid::outline`]), with the volume of its box; smallest first.
///
/// Most normals are ruled out without their rectangle. The box along `n` holds the hull,
/// so its volume is at least the hull's extent along `n` times the area of the hull's
/// projection on the plane orthogonal to `n`, which for a convex polytope is
/// `½·Σ_f |n·A_f|` over its faces' area vectors `A_f` (the projection is covered twice).
/// Normals are taken in order of that bound, and once it exceeds the `keep`-th best
/// volume found (with a relative margin of `10^-9` for its rounding), none left can enter.
fn face_frames(hull: &Solid, normals: usize, keep: usize) -> Vec<(f64, DMat3)> {
    // Each normal's ends start the climbs of the next.
    let mut ends = [0; 2];
    let mut bounded: Vec<(f64, DVec3)> = face_normals(hull, normals)
        .into_iter()
        .map(|n| (hull.extent_afar(n, &mut ends) * hull.shadow(n), n))
        .collect();
    bounded.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best: Vec<(f64, DMat3)> = Vec::with_capacity(keep + 1);
    // Each box's extremes start the climbs of the next.
    let mut from = [0; 6];
    for (bound, n) in bounded {
        if best.len() == keep && best.last().is_some_and(|b| bound > b.0 * (1.0 + 1e-9)) {
            break;
        }
        let frame = outline_frame(hull, n);
        let volume = hull.extents_afar(&frame, &mut from).element_product();
        let at = best.partition_point(|b| b.0 <= volume);
        best.insert(at, (volume, frame));
        best.truncate(keep);
    }
    best
}

/// Outlines of at most this many edges get their rectangle from their edges, in lanes
/// ([`rect::least_rectangle`], `O(E·V)`); longer ones from the calipers around their
/// projected hull ([`rectangle_frame`], `O(V log V)`).
const LANE_RECTANGLE: usize = 96;

/// The frame of the minimum-area rectangle around the hull's shadow along the unit `n`,
/// from its outline ([`Solid::outline`]).
fn outline_frame(hull: &Solid, n: DVec3) -> DMat3 {
    let vertices = &hull.vertices;
    let edges = hull.outline(n);
    if edges.len() <= LANE_RECTANGLE {
        let columns = [0, 1, 2].map(|k| edges.iter().map(|e| vertices[e[0]][k]).collect());
        let [x, y, z]: [Vec<f64>; 3] = columns;
        if let Some((_, side)) = rect::least_rectangle(n, vertices, &edges, [&x, &y, &z]) {
            return rect::frame(n, side.normalize());
        }
    }
    let outline: Vec<DVec3> = edges.iter().map(|e| vertices[e[0]]).collect();
    rectangle_frame(n, &outline)
}

/// The unit normals of the hull faces, coplanar faces merged, largest area first, at most
/// `most` of them.
fn face_normals(hull: &Solid, most: usize) -> Vec<DVec3> {
    let areas = &hull.areas;
    // The directions, each with its summed area (in face order), its key and its first
    // face, which gives its normal. They are found in a hash table with open addressing,
    // keyed by the direction: sorting every face by its key cost more than the rest of the
    // rectangles' bounds.
    let slots = (2 * areas.len()).next_power_of_two().max(2);
    let shift = 64 - slots.trailing_zeros();
    let mut table = vec![usize::MAX; slots];
    let mut normals: Vec<(f64, u128, usize)> = Vec::new();
    for (t, area) in areas.iter().enumerate() {
        let Some(unit) = area.try_normalize() else {
            continue;
        };
        let key = direction_key(unit);
        let hash = [key >> 64, key].iter().fold(0u64, |h, &k| {
            (h ^ k as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
        });
        let mut slot = (hash >> shift) as usize;
        loop {
            match table[slot] {
                usize::MAX => {
                    table[slot] = normals.len();
                    normals.push((area.length(), key, t));
                    break;
                }
                d if normals[d].1 == key => {
                    normals[d].0 += area.length();
                    break;
                }
                _ => slot = (slot + 1) & (slots - 1),
            }
        }
    }
    // Largest first, ties in key order; only the first `most` are sorted.
    let order =
        |a: &(f64, u128, usize), b: &(f64, u128, usize)| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1));
    if normals.len() > most {
        normals.select_nth_unstable_by(most, order);
        normals.truncate(most);
    }
    normals.sort_unstable_by(order);
    normals
        .into_iter()
        .map(|(_, _, t)| areas[t].normalize())
        .collect()
}

/// A local minimum of the volume over rotations `frame·exp(ω)` near `frame`, each volume
/// measured on the hull by climbs from the last box's extremes ([`Solid::extents`]).
fn refine(frame: DMat3, hull: &Solid) -> DMat3 {
    let rotated =
        |w: [f64; 3]| frame * DMat3::from_quat(DQuat::from_scaled_axis(DVec3::from_array(w)));
    let mut from = [0; 6];
    let mut volume = |w| hull.extents(&rotated(w), &mut from).element_product();
    let (w, _) = compass_search(&mut volume, 0.05, 1e-7, 3000);
    rotated(w)
}

/// The tight fit: the smallest midrange box over the refined hull frames and the fast fit.
fn fit_tight(points: &[Vec3], bounds: &Aabb3) -> Result<Obb3, FitError> {
    let distinct = cloud::unique(points);
    let exact_points: Vec<DVec3> = distinct.iter().map(|&p| exact(p)).collect();
    let tight = tight_frames(&exact_points).frames.into_iter().map(|f| {
        let [obb] = fit_axes(&distinct, bounds, [to_f32(f)], Center::Midrange);
        obb
    });
    smallest(tight.chain([fit_fast(points, cloud::summary(points))]))
}
