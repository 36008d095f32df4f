//! The fast fit's choice of axes from its few extremal points (at most [`POINTS`]): DiTO's
//! frames and the face frames of the points' hull, ranked by the volume they give them.
//!
//! **The hull of a few points.** A hull of at most [`POINTS`] vertices has at most
//! [`FACES`] triangles, so it is built here by incremental insertion into fixed arrays: no
//! allocation, and none of the edges, cells and climbs that [`hull::convex_hull`] builds
//! for the tight fit's large hulls. The side tests are the same exact predicate
//! ([`hull::above`]) behind the same floating-point filter ([`hull::Plane`]), so the
//! triangles are exactly those of a convex polytope:
//! - a triangle sees a point only when the point lies strictly above its plane, so a point
//!   in or on the hull is dropped;
//! - the triangles that see a point outside form a disk bounded by one simple cycle of
//!   horizon edges, each run by a seen triangle and, the other way, by an unseen one;
//! - each horizon edge `u → v` gets the triangle `(u, v, p)`, which has area: `p` lies
//!   strictly above the seen triangle's plane, which holds `u` and `v`.
//!
//! A closed surface of triangles on `V` vertices has `2V − 4` of them, so the arrays never
//! fill; were they to, the hull would give no frame rather than a wrong one. Either way the
//! box is measured afterwards on every input point: the frames only choose its axes.

use super::hull::{self, Plane};
use super::rect;
use super::sweep;
use crate::num::pow2;
use glam::{DMat3, DVec3};

/// At most this many points: the extremes on each sample direction of the summary.
pub(crate) const POINTS: usize = 2 * sweep::DIRECTIONS;

/// At most this many triangles on a hull of [`POINTS`] vertices (`2V − 4`).
const FACES: usize = 2 * POINTS - 4;

/// How many face normals get their rectangle: those of least bound (see [`face_frame`]).
/// On the test meshes the best face frame is always among the first 8 (the first 4 miss
/// the teapot's: 1.18× the tight box instead of 1.05×), and the bound rarely rules out
/// more: a shadow's rectangle exceeds its area by up to `4/π` on round shapes.
const RECTANGLES: usize = 8;

/// The frame of least volume over `points` (distinct, at most [`POINTS`], the first 14
/// paired along DiTO's 7 directions) among DiTO's frames of the first 14 and the face
/// frames of the hull of all ([`face_frame`]); `None` when there is none (fewer than
/// three points, or all on a line) or there are more than [`POINTS`] points.
///
/// DiTO's frames are ranked by the volume of the points' box on their axes, each extent
/// taken in lanes over the points as columns ([`extent`]).
pub(crate) fn best_frame(points: &[DVec3], dito: &[DVec3]) -> Option<DMat3> {
    if points.len() > POINTS {
        return None;
    }
    let (column, m) = columns(points, [true; POINTS]);
    let groups = m.div_ceil(LANES);
    let (frames, count) = dito_frames(dito);
    let best = crate::simd::plain(
        #[inline(always)]
        || {
            let mut best: Option<(f64, DMat3)> = None;
            for frame in &frames[..count] {
                let volume = extent(&column, groups, frame.x_axis)
                    * extent(&column, groups, frame.y_axis)
                    * extent(&column, groups, frame.z_axis);
                if best.is_none_or(|(least, _)| volume.total_cmp(&least).is_lt()) {
                    best = Some((volume, *frame));
                }
            }
            best
        },
    );
    face_frame(points, best).map(|(_, f)| f)
}

/// The extents `max − min` of the projections of `points` on the columns of `frame`.
pub(crate) fn extents(frame: &DMat3, points: &[DVec3]) -> DVec3 {
    let mut lo = DVec3::INFINITY;
    let mut hi = DVec3::NEG_INFINITY;
    for &p in points {
        let q = frame.transpose() * p;
        lo = lo.min(q);
        hi = hi.max(q);
    }
    (hi - lo).max(DVec3::ZERO)
}

/// A right-handed orthonormal frame whose first axis is `axis` and second the part of
/// `toward` orthogonal to it (any orthogonal direction when that part vanishes).
pub(crate) fn frame_from(axis: DVec3, toward: DVec3) -> Option<DMat3> {
    let u = axis.try_normalize()?;
    let v = (toward - u * u.dot(toward))
        .try_normalize()
        .unwrap_or_else(|| u.any_orthonormal_vector());
    Some(DMat3::from_cols(u, v, u.cross(v)))
}

/// DiTO's candidate frames (Larsson & Källberg 2011) from the extremal points, taken in
/// pairs along each sample direction: the base triangle joins the farthest pair to the
/// point farthest from their line; the points farthest above and below its plane add a
/// tetrahedron on each side. Each triangle gives one frame per edge: the edge, the
/// in-plane orthogonal, the normal.
fn dito_frames(extremal: &[DVec3]) -> ([DMat3; DITO_FRAMES], usize) {
    let mut frames = [DMat3::ZERO; DITO_FRAMES];
    let mut count = 0;
    let farthest = |key: &dyn Fn(DVec3) -> f64| {
        extremal
            .iter()
            .copied()
            .max_by(|&a, &b| key(a).total_cmp(&key(b)))
            .unwrap_or(DVec3::ZERO)
    };
    let Some((p0, p1)) = extremal
        .chunks_exact(2)
        .map(|pair| (pair[0], pair[1]))
        .max_by(|a, b| {
            a.0.distance_squared(a.1)
                .total_cmp(&b.0.distance_squared(b.1))
        })
    else {
        return (frames, count);
    };
    let line = (p1 - p0).normalize_or_zero();
    let p2 = farthest(&|p| (p - p0).cross(line).length_squared());
    let normal = (p1 - p0).cross(p2 - p0);
    let [above, below] = [farthest(&|p| p.dot(normal)), farthest(&|p| -p.dot(normal))];
    let triangles = [
        [p0, p1, p2],
        [p0, p1, above],
        [p1, p2, above],
        [p2, p0, above],
        [p0, p1, below],
        [p1, p2, below],
        [p2, p0, below],
    ];
    for t in triangles {
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        for k in 0..3 {
            if let Some(frame) = frame_from(t[(k + 1) % 3] - t[k], n) {
                frames[count] = frame;
                count += 1;
            }
        }
    }
    (frames, count)
}

/// DiTO's frames: 3 for each of its 7 triangles.
const DITO_FRAMES: usize = 21;

/// The triangles of the hull of `points` (distinct, at most [`POINTS`]), outward
/// (counter-clockwise seen from outside), as indices into `points`, and how many there
/// are; `None` for points that span no solid, or arrays that would overflow (see the
/// module doc).
///
/// Each point is tested against every triangle's plane at once, in lanes over the planes
/// held as columns ([`hull::side_code`]), and `orient3d` decides where the pad leaves the
/// side open. The new triangles take the slots of the seen ones, so nothing moves.
fn triangles(points: &[DVec3]) -> Option<([[u8; 3]; FACES], usize)> {
    if points.len() > POINTS {
        return None;
    }
    let [a, b, c, d] = hull::tetrahedron(points).ok()?.map(|i| i as u8);
    let at = |i: u8| points[usize::from(i)];
    let (b, c) = if hull::above(at(a), at(b), at(c), at(d)) {
        (c, b)
    } else {
        (b, c)
    };
    crate::simd::plain(
        #[inline(always)]
        || {
            let mut hull = SmallHull::default();
            for face in [[a, b, c], [b, a, d], [c, b, d], [a, c, d]] {
                hull.put(hull.len, face, points);
                hull.len += 1;
            }
            for (i, &p) in points.iter().enumerate() {
                if ![a, b, c, d].contains(&(i as u8)) && !hull.insert(i as u8, p, points) {
                    return None;
                }
            }
            Some((hull.faces, hull.len))
        },
    )
}

/// The hull being built by [`triangles`]: its triangles, their planes as columns (the
/// slots from `len` on are unused), and the edges the current point's seen triangles run.
struct SmallHull {
    faces: [[u8; 3]; FACES],
    normal: [[f64; FACES]; 3],
    vertex: [[f64; FACES]; 3],
    pad: [f64; FACES],
    len: usize,
    /// `runs[u][v] == stamp` when a triangle that the point with that stamp sees runs
    /// `u → v`.
    runs: [[u8; POINTS]; POINTS],
}

impl Default for SmallHull {
    fn default() -> Self {
        Self {
            faces: [[0; 3]; FACES],
            normal: [[0.0; FACES]; 3],
            vertex: [[0.0; FACES]; 3],
            pad: [0.0; FACES],
            len: 0,
            runs: [[0; POINTS]; POINTS],
        }
    }
}

impl SmallHull {
    /// Puts the triangle `face` (indices into `points`) and its plane in `slot`.
    #[inline(always)]
    fn put(&mut self, slot: usize, face: [u8; 3], points: &[DVec3]) {
        let [u, v, w] = face.map(|i| points[usize::from(i)]);
        let (n, a, pad) = Plane::new(u, v, w).parts();
        for k in 0..3 {
            (self.normal[k][slot], self.vertex[k][slot]) = (n[k], a[k]);
        }
        (self.faces[slot], self.pad[slot]) = (face, pad);
    }

    /// Adds the point `i` (at `p`): the triangles it sees give way to a fan from `i` over
    /// their horizon. `false` when the arrays would overflow.
    #[inline(always)]
    fn insert(&mut self, i: u8, p: DVec3, points: &[DVec3]) -> bool {
        let q = p.to_array();
        let mut code = [0i8; FACES];
        for (f, code) in code.iter_mut().enumerate() {
            let n = [0, 1, 2].map(|k| self.normal[k][f]);
            let a = [0, 1, 2].map(|k| self.vertex[k][f]);
            *code = hull::side_code(n, a, self.pad[f], q);
        }
        let stamp = i + 1;
        let mut seen = [0usize; FACES];
        let mut count = 0;
        for (f, &code) in code.iter().enumerate().take(self.len) {
            let sees = code > 0
                || (code == 0 && {
                    let [u, v, w] = self.faces[f].map(|j| points[usize::from(j)]);
                    hull::above(u, v, w, p)
                });
            if sees {
                seen[count] = f;
                count += 1;
                let [u, v, w] = self.faces[f].map(usize::from);
                (self.runs[u][v], self.runs[v][w], self.runs[w][u]) = (stamp, stamp, stamp);
            }
        }
        if count == 0 {
            return true;
        }
        // A seen triangle's edge is on the horizon when no seen triangle runs it backwards.
        let mut horizon = [[0u8; 2]; 3 * FACES];
        let mut edges = 0;
        for &f in &seen[..count] {
            let face = self.faces[f];
            for k in 0..3 {
                let (u, v) = (face[k], face[(k + 1) % 3]);
                if self.runs[usize::from(v)][usize::from(u)] != stamp {
                    horizon[edges] = [u, v];
                    edges += 1;
                }
            }
        }
        if self.len - count + edges > FACES {
            return false;
        }
        // The fan fills the seen slots, then new ones; seen slots left over (never, for a
        // horizon that is one cycle) take the last triangles, highest slot first.
        for (k, &[u, v]) in horizon[..edges].iter().enumerate() {
            let slot = if k < count {
                seen[k]
            } else {
                self.len + k - count
            };
            self.put(slot, [u, v, i], points);
        }
        self.len += edges.saturating_sub(count);
        for &slot in seen[edges.min(count)..count].iter().rev() {
            self.len -= 1;
            let last = self.len;
            self.faces[slot] = self.faces[last];
            self.pad[slot] = self.pad[last];
            for k in 0..3 {
                self.normal[k][slot] = self.normal[k][last];
                self.vertex[k][slot] = self.vertex[k][last];
            }
        }
        true
    }
}

/// The best face frame of the hull of `points` (distinct, at most [`POINTS`]), with its
/// volume over them, or `best` when none beats it.
///
/// Each direction of the hull's triangles (coplanar ones merged) is a candidate normal `n`,
/// whose frame is that of the minimum-area rectangle of the points projected along `n`
/// ([`shadow_rectangle`]). A box with axis `n` holds the hull, so its volume is at least
/// the hull's extent along `n` times the area of the hull's shadow on the plane orthogonal
/// to `n`, `¼·Σ_t |n·A_t|` over the triangles' doubled area vectors `A_t` (the shadow is
/// covered twice). The first [`RECTANGLES`] normals in order of that bound get their
/// rectangle, until the bound exceeds the best volume (with a relative margin of `10^-9`
/// for its rounding), when no normal left can beat it.
fn face_frame(points: &[DVec3], best: Option<(f64, DMat3)>) -> Option<(f64, DMat3)> {
    let Some((faces, len)) = triangles(points) else {
        return best;
    };
    let faces = &faces[..len];
    let at = |i: u8| points[usize::from(i)];
    // The triangles' doubled area vectors, as columns padded with zero vectors.
    let mut area = [[0.0; FACES]; 3];
    let mut normals = [Normal::default(); FACES];
    let mut count = 0;
    for (t, f) in faces.iter().enumerate() {
        let [u, v, w] = f.map(at);
        let a = (v - u).cross(w - u);
        for (column, value) in area.iter_mut().zip(a.to_array()) {
            column[t] = value;
        }
        let Some(unit) = a.try_normalize() else {
            continue;
        };
        normals[count] = Normal {
            key: hull::direction_key(unit),
            unit,
            ..Normal::default()
        };
        count += 1;
    }
    // Coplanar triangles share a key: one normal each (any of theirs: they differ by
    // rounding).
    let normals = &mut normals[..count];
    normals.sort_unstable_by_key(|normal| normal.key);
    let mut distinct = 0;
    for i in 0..normals.len() {
        if i == 0 || normals[i].key != normals[distinct - 1].key {
            normals[distinct] = normals[i];
            distinct += 1;
        }
    }
    let normals = &mut normals[..distinct];
    // The hull's vertices as columns, padded with the first.
    let mut vertex = [false; POINTS];
    for &i in faces.iter().flatten() {
        vertex[usize::from(i)] = true;
    }
    let (column, m) = columns(points, vertex);
    let groups = m.div_ceil(LANES);
    // Which triangle runs each edge `u → v`, and so which lies across each triangle's edges.
    let mut runs = [[NO_FACE; POINTS]; POINTS];
    for (t, f) in faces.iter().enumerate() {
        for k in 0..3 {
            runs[usize::from(f[k])][usize::from(f[(k + 1) % 3])] = t as u8;
        }
    }
    let mut across = [[NO_FACE; 3]; FACES];
    for (across, f) in across.iter_mut().zip(faces) {
        for k in 0..3 {
            across[k] = runs[usize::from(f[(k + 1) % 3])][usize::from(f[k])];
        }
    }
    crate::simd::plain(
        #[inline(always)]
        || {
            for normal in normals.iter_mut() {
                normal.extent = extent(&column, groups, normal.unit);
                normal.bound = normal.extent * shadow(&area, normal.unit);
            }
        },
    );
    normals.sort_unstable_by(|a, b| a.bound.total_cmp(&b.bound).then(a.key.cmp(&b.key)));
    let mut best = best;
    for normal in normals.iter().take(RECTANGLES) {
        if best.is_some_and(|(volume, _)| normal.bound > volume * (1.0 + 1e-9)) {
            break;
        }
        let n = normal.unit;
        let Some((rectangle, side)) = shadow_rectangle(faces, &across, &area, points, n) else {
            continue;
        };
        let volume = normal.extent * rectangle;
        if best.is_none_or(|(least, _)| volume < least) {
            best = Some((volume, rect::frame(n, side.normalize())));
        }
    }
    best
}

/// A candidate normal of [`face_frame`]: its lower bound on the volume, its key, the unit
/// vector and the hull's extent along it.
#[derive(Clone, Copy, Default)]
struct Normal {
    bound: f64,
    key: u128,
    unit: DVec3,
    extent: f64,
}

/// No triangle: an empty entry of the table of edges.
const NO_FACE: u8 = u8::MAX;

/// The minimum-area rectangle around the hull's shadow on the plane orthogonal to the unit
/// `n`: its area and the direction of one of its sides (in that plane, not normalised);
/// `None` when no side is found. `across[t][k]` is the triangle across edge `k` of
/// triangle `t` (from its vertex `k` to the next).
///
/// **The outline.** A triangle faces `n` when `n·A > 2^-40·|A|₁` for its doubled area
/// vector `A` (the `f64` value of `n·A` is within a few `u = 2^-53` of `|A|₁`, so a triangle
/// that faces `n` really does), and is edge-on when `|n·A|` is at most that. The triangles
/// facing `n` cover the shadow but for the slivers of edge-on ones; the edges that leave
/// them for a triangle that does not face `n` bound them, and form closed cycles. So every
/// side of the shadow's polygon lies along the projection of such an edge or of an edge of
/// an edge-on triangle, and every corner is the projection of one of their vertices (the
/// outline, as for [`hull::Solid::outline`]). Those edges and vertices go to
/// [`rect::least_rectangle`].
fn shadow_rectangle(
    faces: &[[u8; 3]],
    across: &[[u8; 3]; FACES],
    area: &[[f64; FACES]; 3],
    points: &[DVec3],
    n: DVec3,
) -> Option<(f64, DVec3)> {
    // 1 facing `n`, 0 edge-on, -1 facing away.
    let mut sides = [0i8; FACES];
    for (t, side) in sides.iter_mut().enumerate().take(faces.len()) {
        let a = DVec3::new(area[0][t], area[1][t], area[2][t]);
        let (h, band) = (a.dot(n), pow2(-40) * a.abs().element_sum());
        *side = i8::from(h > band) - i8::from(h < -band);
    }
    let mut on = [false; POINTS];
    let mut edges = [[0u8; 2]; 3 * FACES];
    let mut count = 0;
    for ((f, side), across) in faces.iter().zip(sides).zip(across) {
        for k in 0..3 {
            if side == 0 || (side == 1 && sides.get(usize::from(across[k])) != Some(&1)) {
                on[usize::from(f[k])] = true;
                edges[count] = [f[k], f[(k + 1) % 3]];
                count += 1;
            }
        }
    }
    let (outline, corners) = columns(points, on);
    rect::least_rectangle(
        n,
        points,
        &edges[..count],
        outline.each_ref().map(|c| &c[..corners]),
    )
}

/// The points of the mask as coordinate columns, padded with the first of them, and how
/// many there are.
fn columns(points: &[DVec3], mask: [bool; POINTS]) -> ([[f64; COLUMN]; 3], usize) {
    let mut column = [[0.0; COLUMN]; 3];
    let mut m = 0;
    for (p, _) in points.iter().zip(mask).filter(|(_, on)| *on) {
        (column[0][m], column[1][m], column[2][m]) = (p.x, p.y, p.z);
        m += 1;
    }
    for c in &mut column {
        let first = c[0];
        c[m..].fill(first);
    }
    (column, m)
}

/// Partial sums and extremes per lane group of [`extent`] and [`shadow`].
const LANES: usize = 4;

/// [`POINTS`] rounded up to whole lane groups.
const COLUMN: usize = POINTS.next_multiple_of(LANES);

/// The extent `max − min` along `n` of the points in the first `groups` lane groups of
/// `column` (padded with one of them).
///
/// The number of groups is a run-time value on purpose: over a constant count the loop is
/// unrolled whole, and the unrolled code is left in scalar `f64`.
#[inline(always)]
fn extent(column: &[[f64; COLUMN]; 3], groups: usize, n: DVec3) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; LANES], [f64::NEG_INFINITY; LANES]);
    let [xs, ys, zs] = [0, 1, 2].map(|k| &column[k].as_chunks::<LANES>().0[..groups]);
    for ((x, y), z) in xs.iter().zip(ys).zip(zs) {
        for j in 0..LANES {
            let h = x[j] * n.x + y[j] * n.y + z[j] * n.z;
            lo[j] = if h < lo[j] { h } else { lo[j] };
            hi[j] = if h > hi[j] { h } else { hi[j] };
        }
    }
    let lo = lo.into_iter().fold(f64::INFINITY, f64::min);
    let hi = hi.into_iter().fold(f64::NEG_INFINITY, f64::max);
    (hi - lo).max(0.0)
}

/// The area of the hull's shadow on the plane orthogonal to the unit `n`, `¼·Σ_t |n·A_t|`
/// over the doubled area vectors (as columns, padded with zero vectors).
#[inline(always)]
fn shadow(area: &[[f64; FACES]; 3], n: DVec3) -> f64 {
    let mut sums = [0.0; LANES];
    for g in (0..FACES).step_by(LANES) {
        for (j, sum) in sums.iter_mut().enumerate() {
            let t = g + j;
            *sum += (area[0][t] * n.x + area[1][t] * n.y + area[2][t] * n.z).abs();
        }
    }
    sums.iter().sum::<f64>() / 4.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec::Vec;

    /// Points in general position, some inside the hull of the others.
    fn cloud(n: usize) -> Vec<DVec3> {
        (0..n)
            .map(|i| {
                let t = i as f64;
                let r = if i % 4 == 3 { 0.5 } else { 1.0 };
                DVec3::new((t * 2.4).cos(), (t * 1.7).sin(), (t * 0.9).cos() * 0.7) * r
            })
            .collect()
    }

    #[test]
    fn the_triangles_bound_every_point_and_close_up() {
        for n in 4..=POINTS {
            let points = cloud(n);
            let (faces, len) = triangles(&points).expect("a solid");
            assert!(len <= FACES);
            for f in &faces[..len] {
                let [u, v, w] = f.map(|i| points[usize::from(i)]);
                // Every point lies on or below every triangle's plane (exactly).
                assert!(points.iter().all(|&p| !hull::above(u, v, w, p)));
                // Every edge is run once each way: a closed, consistently oriented surface.
                for k in 0..3 {
                    let (a, b) = (f[k], f[(k + 1) % 3]);
                    let twins = faces[..len]
                        .iter()
                        .filter(|g| (0..3).any(|j| g[j] == b && g[(j + 1) % 3] == a))
                        .count();
                    assert_eq!(twins, 1, "n = {n}");
                }
            }
            // Euler: a closed surface of triangles on V vertices has 2V − 4 of them.
            let mut vertices: Vec<u8> = faces[..len].iter().flatten().copied().collect();
            vertices.sort_unstable();
            vertices.dedup();
            assert_eq!(len, 2 * vertices.len() - 4);
        }
    }

    #[test]
    fn the_cube_with_face_points_has_its_corners_for_vertices() {
        let mut points: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2) as f64))
            .collect();
        points.extend([DVec3::new(0.5, 0.5, 0.0), DVec3::new(0.5, 0.5, 0.5)]);
        let (faces, len) = triangles(&points).expect("a solid");
        assert_eq!(len, 12);
        assert!(faces[..len].iter().flatten().all(|&i| i < 8));
        // The cube's face frame is the cube's box.
        let (volume, _) = face_frame(&points, None).expect("a frame");
        assert!((volume - 1.0).abs() < 1e-12, "{volume}");
    }

    #[test]
    fn flat_and_too_many_points_give_no_hull() {
        let flat: Vec<DVec3> = (0..6)
            .map(|i| DVec3::new(i as f64, (i * i) as f64, 0.0))
            .collect();
        assert!(triangles(&flat).is_none());
        assert!(triangles(&cloud(POINTS + 1)).is_none());
        assert!(face_frame(&flat, None).is_none());
    }
}
