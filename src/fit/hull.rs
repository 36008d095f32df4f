//! The convex hull of points in 3D: quickhull on exact orientation predicates.
//!
//! Points are the exact `f64` values of `f32` inputs, and every side-of-plane decision is
//! Shewchuk's exact `orient3d` (the `robust` crate; exact here, since products of `f32`
//! differences neither overflow nor underflow `f64`). A face sees a point only when the
//! point lies strictly above its plane, so points on a face are dropped, coplanar faces may
//! be adjacent, and the faces visible from a new point form a disk bounded by one simple
//! cycle of horizon edges: each new face `(u, v, eye)` is glued to the face across its
//! horizon edge and to the new faces that start at `v` and end at `u`. Faces keep their
//! three neighbours, so the walks need no map. Exact predicates make the hull correct on
//! planar, collinear and cospherical input, which is reported as [`Hull::Planar`],
//! [`Hull::Segment`] or [`Hull::Point`]. The fits use the hull only to choose directions;
//! containment never depends on it (every fit re-derives its extents from every input
//! point).

use super::sweep::SAMPLE_DIRECTIONS;
use crate::num::pow2;
use alloc::boxed::Box;
use alloc::vec;
use alloc::vec::Vec;
use glam::{DMat3, DVec3};
use robust::{Coord, Coord3D, orient2d, orient3d};

/// The convex hull, by the dimension of the points' affine hull.
#[derive(Clone, Debug)]
pub(crate) enum Hull {
    /// All points coincide.
    Point,
    /// All points lie on a line with this unit direction.
    Segment(DVec3),
    /// All points lie on a plane with this unit normal.
    Planar(DVec3),
    /// A solid hull.
    Solid(Box<Solid>),
}

/// A solid hull: its vertices and its outward (counter-clockwise) triangles into them,
/// with their edges, area vectors and each vertex's neighbours.
#[derive(Clone, Debug)]
pub(crate) struct Solid {
    /// The hull vertices.
    pub vertices: Vec<DVec3>,
    /// Triangles, as indices into `vertices`.
    pub triangles: Vec<[usize; 3]>,
    /// Each triangle's doubled area vector `(b − a) × (c − a)`, outward.
    pub areas: Vec<DVec3>,
    /// Each edge once, with its two triangles, cell by cell of [`Solid::cells`].
    edges: Vec<Edge>,
    /// The edges in cells of nearby face normals, for [`Solid::outline`].
    cells: Vec<Cell>,
    /// The vertices joined to vertex `v` by an edge: `links[starts[v]..starts[v + 1]]`.
    starts: Vec<usize>,
    links: Vec<usize>,
    /// The area vectors' coordinate columns in lanes of [`LANES`] (the last padded with
    /// zeros), for [`Solid::shadow`].
    columns: [Vec<[f64; LANES]>; 3],
    /// The vertices' coordinate columns in lanes of [`LANES`] (the last padded with the last
    /// vertex), for [`Solid::scan`].
    points: [Vec<[f64; LANES]>; 3],
}

/// An edge of a solid hull: its two triangles, and its first vertex as it runs in each
/// (the triangles run it in opposite directions); with copies of the triangles' area vectors
/// and bands, so that [`Solid::outline`] reads a cell's edges in one sweep of memory.
#[derive(Clone, Copy, Debug)]
struct Edge {
    faces: [usize; 2],
    tails: [usize; 2],
    areas: [DVec3; 2],
    bands: [f64; 2],
}

/// Hulls of at most this many vertices are measured by a scan of every vertex, not by
/// climbs ([`Solid::extent`]): the hulls of small meshes (a box's 8 corners).
const SCANNED: usize = 32;

/// Hulls of at most this many vertices are measured along directions far from the last
/// ones by a scan of every vertex in lanes ([`Solid::extents_afar`]): a climb across the
/// hull takes tens of steps of a few neighbours each, with unpredictable branches, where the
/// scan takes about two instructions a vertex. The two cost about the same instructions
/// on the teapot's hull of 878 vertices.
const FAR_SCANNED: usize = 1024;

/// Triangles per lane group of [`Solid::shadow`], and points per lane group of
/// [`first_least_last_greatest`] (four `f64` lanes).
const LANES: usize = 4;

/// A cell of edges ([`Solid::outline`]): those up to `end` in [`Solid::edges`] (from the
/// last cell's end), with bounds `lo <= u <= hi` on the unit normals `u = A/|A|` of their
/// triangles and the largest ratio `band/|A|` among them (infinite when one has no area).
#[derive(Clone, Copy, Debug)]
struct Cell {
    end: usize,
    lo: DVec3,
    hi: DVec3,
    reach: f64,
}

/// About how many edges a cell holds: the outline tests every cell and every edge of the
/// cells it cannot rule out.
const CELL_EDGES: usize = 16;

/// The room an outline starts with ([`Solid::outline`]): the rims of meshes of a few
/// thousand vertices hold a few dozen edges.
const OUTLINE_ROOM: usize = 128;

/// A cell is ruled out when its range of `n·u` clears its `reach` by this much, far more
/// than the rounding of `n·u` and of the triangles' own side tests (a few `2^-53`).
const CELL_MARGIN: f64 = pow2(-30);

/// Sorts `edges` into cells of nearby normals and returns the cells: each edge goes by the
/// sum `m` of its triangles' unit normals to a cell of a grid on the cube's face that `m`
/// points through (`side × side` cells a face, about [`CELL_EDGES`] edges a cell). Only
/// the bounds matter for the outline, not which cell an edge went to: an edge with no
/// direction (a triangle with no area) goes to the first. A hull of few edges gets one cell
/// that is never ruled out.
fn cells(edges: &mut Vec<Edge>, areas: &[DVec3], bands: &[f64]) -> Vec<Cell> {
    if edges.len() <= 6 * CELL_EDGES {
        return vec![Cell {
            end: edges.len(),
            lo: DVec3::NEG_ONE,
            hi: DVec3::ONE,
            reach: f64::INFINITY,
        }];
    }
    let (units, reaches): (Vec<DVec3>, Vec<f64>) = areas
        .iter()
        .zip(bands)
        .map(|(a, band)| {
            let area = a.length();
            if area > 0.0 {
                (*a / area, band / area)
            } else {
                (DVec3::ZERO, f64::INFINITY)
            }
        })
        .unzip();
    // The least side (at most 64) whose cells hold at most `CELL_EDGES` edges each on average.
    let side = (1..64)
        .find(|&side| 6 * side * side * CELL_EDGES >= edges.len())
        .unwrap_or(64);
    let cell_of = |e: &Edge| {
        let m = units[e.faces[0]] + units[e.faces[1]];
        let k = m.abs().max_position();
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        let top = m[k].abs();
        if top == 0.0 {
            return 0;
        }
        let at = |x: f64| (((x / top + 1.0) * 0.5 * side as f64) as usize).min(side - 1);
        let face = 2 * k + usize::from(m[k] < 0.0);
        (face * side + at(m[a])) * side + at(m[b])
    };
    // A counting sort by cell: the cells are few and the edges many.
    let keys: Vec<usize> = edges.iter().map(cell_of).collect();
    let mut ends = vec![0; 6 * side * side];
    for &key in &keys {
        ends[key] += 1;
    }
    for key in 1..ends.len() {
        ends[key] += ends[key - 1];
    }
    let mut sorted = edges.clone();
    for (&key, &edge) in keys.iter().zip(edges.iter()).rev() {
        ends[key] -= 1;
        sorted[ends[key]] = edge;
    }
    *edges = sorted;
    // Now `ends[key]` is where the cell starts; empty cells are left out.
    let starts = ends;
    let mut cells: Vec<Cell> = Vec::new();
    for (key, &start) in starts.iter().enumerate() {
        let end = starts.get(key + 1).copied().unwrap_or(edges.len());
        if start == end {
            continue;
        }
        let mut cell = Cell {
            end,
            lo: DVec3::INFINITY,
            hi: DVec3::NEG_INFINITY,
            reach: 0.0,
        };
        for edge in &edges[start..end] {
            for t in edge.faces {
                cell.lo = cell.lo.min(units[t]);
                cell.hi = cell.hi.max(units[t]);
                cell.reach = cell.reach.max(reaches[t]);
            }
        }
        cells.push(cell);
    }
    cells
}

impl Solid {
    /// The hull from its vertices, triangles and their neighbours (`neighbors[t][k]`: the
    /// triangle across edge `k` of triangle `t`, from its vertex `k` to its vertex `k + 1`).
    fn new(vertices: Vec<DVec3>, triangles: Vec<[usize; 3]>, neighbors: &[[usize; 3]]) -> Self {
        let (areas, scales): (Vec<DVec3>, Vec<f64>) = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| vertices[i]);
                let (ab, ac) = (b - a, c - a);
                (
                    ab.cross(ac),
                    ab.abs().element_sum() * ac.abs().element_sum(),
                )
            })
            .unzip();
        // Each edge `u → v` of a triangle runs `v → u` in its neighbour: listing every
        // triangle's edges by their first vertex lists each vertex's neighbours once.
        let mut starts = vec![0; vertices.len() + 1];
        for t in &triangles {
            for &u in t {
                starts[u + 1] += 1;
            }
        }
        for v in 0..vertices.len() {
            starts[v + 1] += starts[v];
        }
        let mut links = vec![0; starts[vertices.len()]];
        let mut filled = starts.clone();
        for t in &triangles {
            for k in 0..3 {
                links[filled[t[k]]] = t[(k + 1) % 3];
                filled[t[k]] += 1;
            }
        }
        let lanes = |value: &dyn Fn(usize) -> f64| -> Vec<[f64; LANES]> {
            (0..triangles.len().div_ceil(LANES))
                .map(|g| {
                    core::array::from_fn(|j| {
                        let t = g * LANES + j;
                        if t < triangles.len() { value(t) } else { 0.0 }
                    })
                })
                .collect()
        };
        let columns = [0, 1, 2].map(|k| lanes(&|t| areas[t][k]));
        let last = vertices.len() - 1;
        let points = [0, 1, 2].map(|k| {
            (0..vertices.len().div_ceil(LANES))
                .map(|g| core::array::from_fn(|j| vertices[(g * LANES + j).min(last)][k]))
                .collect()
        });
        // `2^-40` times each triangle's scale `|b − a|₁·|c − a|₁`, which bounds the
        // rounding of its area vector ([`Solid::outline`]).
        let bands: Vec<f64> = scales.iter().map(|&s| pow2(-40) * s).collect();
        // Each edge once, from the triangle of lower index (a closed surface: `3T/2` edges).
        let mut edges = Vec::with_capacity(3 * triangles.len() / 2);
        for (t, triangle) in triangles.iter().enumerate() {
            for k in 0..3 {
                let faces = [t, neighbors[t][k]];
                if faces[0] < faces[1] {
                    edges.push(Edge {
                        faces,
                        tails: [triangle[k], triangle[(k + 1) % 3]],
                        areas: faces.map(|f| areas[f]),
                        bands: faces.map(|f| bands[f]),
                    });
                }
            }
        }
        let cells = cells(&mut edges, &areas, &bands);
        Self {
            vertices,
            triangles,
            areas,
            edges,
            cells,
            starts,
            links,
            columns,
            points,
        }
    }

    /// The area of the hull's shadow on the plane orthogonal to the unit `n`,
    /// `¼·Σ_t |n·A_t|` over the doubled area vectors (the shadow is covered twice, by the
    /// triangles facing `n` and by those facing away), in lanes of [`LANES`] triangles.
    pub fn shadow(&self, n: DVec3) -> f64 {
        let [x, y, z] = &self.columns;
        let sums: [f64; LANES] = crate::simd::plain(
            #[inline(always)]
            || {
                let mut sums = [0.0; LANES];
                for g in 0..x.len() {
                    for j in 0..LANES {
                        sums[j] += (x[g][j] * n.x + y[g][j] * n.y + z[g][j] * n.z).abs();
                    }
                }
                sums
            },
        );
        sums.iter().sum::<f64>() / 4.0
    }

    /// The vertex of greatest projection on `d`, found by climbing from vertex `from` to a
    /// neighbour of greater projection while there is one. On a convex polytope a vertex
    /// that no edge leaves uphill is a highest one (the edges at a vertex span the
    /// polytope's cone there), so the climb visits a path, not the whole hull; each step
    /// strictly gains, so it ends.
    pub fn extreme(&self, d: DVec3, from: usize) -> usize {
        let (mut at, mut height) = (from, self.vertices[from].dot(d));
        loop {
            let here = at;
            for &w in &self.links[self.starts[here]..self.starts[here + 1]] {
                let h = self.vertices[w].dot(d);
                if h > height {
                    (at, height) = (w, h);
                }
            }
            if at == here {
                return at;
            }
        }
    }

    /// The extents `max − min` of the hull along each of `axes`, by a scan of every vertex
    /// in lanes of [`LANES`] (the products and sums of `DVec3::dot`, in its order, so the
    /// values are those of the climbs' last vertices).
    pub fn scan<const N: usize>(&self, axes: [DVec3; N]) -> [f64; N] {
        const { assert!(N <= 3) };
        let [x, y, z] = &self.points;
        // Room for three axes, of which the first `N` are used.
        let (lo, hi) = crate::simd::plain(
            #[inline(always)]
            || {
                let mut lo = [[f64::INFINITY; LANES]; 3];
                let mut hi = [[f64::NEG_INFINITY; LANES]; 3];
                for g in 0..x.len() {
                    for (k, a) in axes.iter().enumerate() {
                        for j in 0..LANES {
                            let h = x[g][j] * a.x + y[g][j] * a.y + z[g][j] * a.z;
                            lo[k][j] = if h < lo[k][j] { h } else { lo[k][j] };
                            hi[k][j] = if h > hi[k][j] { h } else { hi[k][j] };
                        }
                    }
                }
                (lo, hi)
            },
        );
        core::array::from_fn(|k| {
            let low = lo[k].iter().copied().fold(f64::INFINITY, f64::min);
            let high = hi[k].iter().copied().fold(f64::NEG_INFINITY, f64::max);
            (high - low).max(0.0)
        })
    }

    /// The extents on the columns of `frame`, which may lie far from any frame measured
    /// before: a scan of every vertex ([`Solid::scan`]) on hulls of at most [`FAR_SCANNED`]
    /// vertices, else climbs from `from` ([`Solid::extents`]).
    pub fn extents_afar(&self, frame: &DMat3, from: &mut [usize; 6]) -> DVec3 {
        if self.vertices.len() <= FAR_SCANNED {
            return DVec3::from_array(self.scan([frame.x_axis, frame.y_axis, frame.z_axis]));
        }
        self.extents(frame, from)
    }

    /// The extent along `axis`, which may lie far from any direction measured before, as
    /// [`Solid::extents_afar`] measures it.
    pub fn extent_afar(&self, axis: DVec3, from: &mut [usize; 2]) -> f64 {
        if self.vertices.len() <= FAR_SCANNED {
            let [extent] = self.scan([axis]);
            return extent;
        }
        self.extent(axis, from)
    }

    /// The extents `max − min` of the hull on the columns of `frame`, by six climbs
    /// ([`Solid::extreme`]) from the vertices in `from` (the lowest and highest on each
    /// column of a nearby frame), which are updated: a box's size near a known one in a few
    /// steps each.
    pub fn extents(&self, frame: &DMat3, from: &mut [usize; 6]) -> DVec3 {
        let [x, y, z] = [0, 1, 2].map(|k| {
            let mut ends = [from[2 * k], from[2 * k + 1]];
            let extent = self.extent(frame.col(k), &mut ends);
            [from[2 * k], from[2 * k + 1]] = ends;
            extent
        });
        DVec3::new(x, y, z)
    }

    /// The extent `max − min` of the hull along `axis`, by two climbs from the vertices in
    /// `from` (the lowest and the highest along a nearby axis), which are updated.
    ///
    /// A hull of at most [`SCANNED`] vertices is scanned instead: every vertex, in
    /// branch-free order, costs less than a climb's unpredictable steps; `from` is then left
    /// as it is.
    pub fn extent(&self, axis: DVec3, from: &mut [usize; 2]) -> f64 {
        if self.vertices.len() <= SCANNED {
            let [extent] = self.scan([axis]);
            return extent;
        }
        from[0] = self.extreme(-axis, from[0]);
        from[1] = self.extreme(axis, from[1]);
        let [lo, hi] = from.map(|i| self.vertices[i].dot(axis));
        (hi - lo).max(0.0)
    }

    /// The edges of the hull's outline seen along the unit direction `n`, as vertex pairs:
    /// the edges that leave a triangle facing `n` for one that does not, run as in the
    /// triangle facing `n` (they bound those triangles, so they form closed cycles), and the
    /// three edges of every edge-on triangle. Their first vertices are the *outline*, some
    /// more than once: among them, every vertex whose projection on the plane orthogonal to
    /// `n` is a corner of the hull's shadow there, and every side of the shadow lies along
    /// the projection of one of the edges. So the shadow's least rectangle is found from a
    /// few vertices and edges rather than all of them ([`super::rect::least_rectangle`]).
    ///
    /// A triangle faces `n` when `n·A > 2^-40·s` for its area vector `A` and its scale `s`
    /// (the `f64` value of `n·A` is within a few `u = 2^-53` of `s`, so a triangle that faces
    /// `n` really does), and is *edge-on* when `|n·A| <= 2^-40·s`.
    ///
    /// *Proof* that it holds each corner vertex `v`: some direction `d ⟂ n` is maximised at
    /// `v`, so `d` is in the cone spanned by the normals of the triangles around `v`. They
    /// cannot all face `n` (then `n·d > 0`), nor all face strictly away from it (then
    /// `n·d < 0`): so either one is edge-on, or both kinds meet at an edge at `v` (the
    /// triangles around `v` form a cycle).
    ///
    /// Only the edges of cells that `n` may split are tested ([`cells`]): over a cell's box,
    /// `n·u` ranges over `[least, most]`, and `n·A` of its triangles is `|A|·n·u` up to
    /// their rounding; when `least` exceeds the cell's largest `band/|A|` by
    /// [`CELL_MARGIN`], all of its triangles face `n`, and when `most` is below its negative,
    /// all face away: either way it holds no rim edge and no edge-on triangle. Every triangle
    /// has its edges in cells, so the outline is the one a test of every edge gives (a unit
    /// test checks it), at the cost of a few cells' edges: those whose normals lie near the
    /// great circle orthogonal to `n`.
    pub fn outline(&self, n: DVec3) -> Vec<[usize; 2]> {
        // 1 facing `n`, 0 edge-on, -1 facing away.
        let side = |area: DVec3, band: f64| {
            let h = area.dot(n);
            i8::from(h > band) - i8::from(h < -band)
        };
        // Room for a typical rim at once, rather than growing through five reallocations.
        let mut outline = Vec::with_capacity(OUTLINE_ROOM);
        let mut start = 0;
        for cell in &self.cells {
            let edges = &self.edges[start..cell.end];
            start = cell.end;
            // The range of `n·u` over the cell's box, and the side it leaves its triangles on.
            let least = (n * DVec3::select(n.cmpge(DVec3::ZERO), cell.lo, cell.hi)).element_sum();
            let most = (n * DVec3::select(n.cmpge(DVec3::ZERO), cell.hi, cell.lo)).element_sum();
            let clear = cell.reach + CELL_MARGIN;
            if least > clear || most < -clear {
                continue;
            }
            for edge in edges {
                let sides = [0, 1].map(|k| side(edge.areas[k], edge.bands[k]));
                let [u, v] = edge.tails;
                if sides[0] == 1 && sides[1] != 1 {
                    outline.push([u, v]);
                } else if sides[1] == 1 && sides[0] != 1 {
                    outline.push([v, u]);
                }
                // An edge-on triangle, once: from its first edge.
                for ((side, face), tail) in sides.into_iter().zip(edge.faces).zip(edge.tails) {
                    if side == 0 {
                        let [a, b, c] = self.triangles[face];
                        if tail == a {
                            outline.extend([[a, b], [b, c], [c, a]]);
                        }
                    }
                }
            }
        }
        outline
    }
}

fn coord(p: DVec3) -> Coord3D<f64> {
    Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

/// The key that merges the directions of coplanar faces: a unit normal on a grid of
/// `2^-24`, far coarser than the rounding of normals of faces in one plane, far finer than
/// the angles between a mesh's distinct faces. Its three grid coordinates (within `±2^24`
/// for a unit vector), offset by `2^24`, take 32 bits each, so that keys compare as the
/// coordinate triples do, lexicographically, in one comparison.
pub(crate) fn direction_key(unit: DVec3) -> u128 {
    let grid = (unit * f64::from(1u32 << 24)).round() + f64::from(1u32 << 24);
    grid.to_array().iter().fold(0, |key, &c| {
        key << 32 | u128::from(c.clamp(0.0, f64::from(u32::MAX)) as u32)
    })
}

/// Exact: `d` lies strictly above the plane of the counter-clockwise triangle `a, b, c`.
pub(crate) fn above(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> bool {
    orient3d(coord(a), coord(b), coord(c), coord(d)) < 0.0
}

/// Exact: `a`, `b`, `c` are collinear (all three coordinate projections are).
fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    let project = |p: DVec3, i: usize, j: usize| Coord { x: p[i], y: p[j] };
    [(0, 1), (1, 2), (2, 0)]
        .iter()
        .all(|&(i, j)| orient2d(project(a, i, j), project(b, i, j), project(c, i, j)) == 0.0)
}

/// The hull of distinct points, each an `f32` value (as every fit's points are: the
/// extremal filter relies on it).
pub(crate) fn convex_hull(points: &[DVec3]) -> Hull {
    let seed = match tetrahedron(points) {
        Ok(seed) => seed,
        Err(flat) => return flat,
    };
    let kept = outside_extremal_hull(points, seed);
    // `kept` is sorted and holds the seed.
    let seed = seed.map(|i| kept.binary_search(&i).unwrap_or(0));
    let kept: Vec<DVec3> = kept.into_iter().map(|i| points[i]).collect();
    let mut hull = Quickhull::new(&kept, seed);
    hull.run();
    hull.into_hull()
}

/// Four affinely independent points to start from (the first point, the farthest from
/// it, the farthest from their line, the farthest from their plane), or the hull of a set
/// that has none.
///
/// Each pass computes one key per point ([`last_greatest`]). The last one ranks the points by
/// the `f64` value of `n·(p − p₀)`, which only chooses among them: the chosen point is
/// accepted when the exact `orient3d` puts it off the plane, and only when it does not
/// (a set flat to within rounding) are the points scanned with the exact predicate.
pub(crate) fn tetrahedron(points: &[DVec3]) -> Result<[usize; 4], Hull> {
    let Some(&p0) = points.first() else {
        return Err(Hull::Point);
    };
    let farthest = |key: &dyn Fn(DVec3) -> f64| last_greatest(0..points.len(), |i| key(points[i]));
    let i1 = farthest(&|p| p.distance_squared(p0)).unwrap_or(0);
    let p1 = points[i1];
    if p1 == p0 {
        return Err(Hull::Point);
    }
    let axis = (p1 - p0).normalize();
    let Some(i2) = (0..points.len()).find(|&i| !collinear(p0, p1, points[i])) else {
        return Err(Hull::Segment(axis));
    };
    let i2 = farthest(&|p| (p - p0).cross(axis).length_squared())
        .filter(|&i| !collinear(p0, p1, points[i]))
        .unwrap_or(i2);
    let p2 = points[i2];
    // Not collinear, exactly; but the `f64` differences may still round to parallel
    // vectors (as for (1e-30, 2e-30, 0), (1e30, 1e30, 0), (-1e30, -1e30, 0)): with no
    // normal to speak of, the set is a segment for the fits' purposes.
    let Some(normal) = (p1 - p0).cross(p2 - p0).try_normalize() else {
        return Err(Hull::Segment(axis));
    };
    let volume = |p: DVec3| orient3d(coord(p0), coord(p1), coord(p2), coord(p));
    let off_plane = |i: usize| volume(points[i]) != 0.0;
    let i3 = farthest(&|p| (p - p0).dot(normal).abs())
        .filter(|&i| off_plane(i))
        .or_else(|| (0..points.len()).find(|&i| off_plane(i)));
    match i3 {
        Some(i3) => Ok([0, i1, i2, i3]),
        None => Err(Hull::Planar(normal)),
    }
}

/// The index of the greatest `key`, the last among equals (`None` for no indices or NaN
/// keys only): one key per index, where `max_by` computes two per comparison.
fn last_greatest(
    indices: impl Iterator<Item = usize>,
    key: impl Fn(usize) -> f64,
) -> Option<usize> {
    let mut best = (f64::NEG_INFINITY, None);
    for i in indices {
        let k = key(i);
        if k >= best.0 {
            best = (k, Some(i));
        }
    }
    best.1
}

/// The indices of the points that may be vertices of the hull (Akl–Toussaint): every
/// point but those strictly inside the hull of the extremal points along the sample
/// directions ([`SAMPLE_DIRECTIONS`], the fast fit's), which are not (a point inside the
/// hull of others is no vertex of the hull of all). The `seed` points are always kept.
///
/// The test is a floating-point filter that only ever drops a point it has proven inside,
/// run in `f32` lanes ([`FilterPlane`]): a point below every face by more than its pad
/// lies strictly inside. Inputs too small to gain keep every point, and so do those whose
/// faces and spread could overflow or underflow `f32` (the filter only saves time).
fn outside_extremal_hull(points: &[DVec3], seed: [usize; 4]) -> Vec<usize> {
    let all = || (0..points.len()).collect();
    if points.len() < 64 {
        return all();
    }
    // The points in coordinate columns: exact `f64` for the extremes, exact `f32` for the
    // filter.
    let x: Vec<f64> = points.iter().map(|p| p.x).collect();
    let y: Vec<f64> = points.iter().map(|p| p.y).collect();
    let z: Vec<f64> = points.iter().map(|p| p.z).collect();
    let mut extremal: Vec<usize> = seed.to_vec();
    // A plain loop: the closure of `array::map` is not inlined into the backend's wrapper.
    let ends = crate::simd::plain(
        #[inline(always)]
        || {
            let mut ends = [[0; 2]; SAMPLE_DIRECTIONS.len()];
            for (ends, &n) in ends.iter_mut().zip(&SAMPLE_DIRECTIONS) {
                *ends = first_least_last_greatest(&x, &y, &z, n);
            }
            ends
        },
    );
    extremal.extend(ends.into_iter().flatten());
    extremal.sort_unstable();
    extremal.dedup();
    let subset: Vec<DVec3> = extremal.iter().map(|&i| points[i]).collect();
    // The seed is among the extremal points, and affinely independent.
    let inner_seed = seed.map(|i| extremal.binary_search(&i).unwrap_or(0));
    let mut inner = Quickhull::new(&subset, inner_seed);
    inner.run();
    let Hull::Solid(solid) = inner.into_hull() else {
        return all();
    };
    // Every `|p|₁` is at most `reach`: the extremes along the axes are among the subset.
    let reach = (0..3)
        .map(|k| subset.iter().map(|p| p[k].abs()).fold(0.0, f64::max))
        .sum::<f64>();
    let faces: Option<Vec<FilterPlane>> = solid
        .triangles
        .iter()
        .map(|t| FilterPlane::new(t.map(|i| solid.vertices[i]), reach))
        .collect();
    let Some(faces) = faces else {
        return all();
    };
    // Each face tested on all the points in lanes.
    let [x, y, z] = [&x, &y, &z].map(|c| c.iter().map(|&v| v as f32).collect::<Vec<f32>>());
    let inside = crate::simd::plain(
        #[inline(always)]
        || {
            let mut inside = vec![true; points.len()];
            for face in &faces {
                face.below(&x, &y, &z, &mut inside);
            }
            inside
        },
    );
    (0..points.len())
        .filter(|&i| extremal.binary_search(&i).is_ok() || !inside[i])
        .collect()
}

/// The indices of the first least and the last greatest `n·p` over the points given as
/// columns (as the `f64` value of `p.dot(n)`, so the same points as a scan one at a time):
/// plain array code over groups of [`LANES`] points, each lane keeping its own first least
/// and last greatest, merged by index at the end, then the last partial group.
#[inline(always)]
fn first_least_last_greatest(x: &[f64], y: &[f64], z: &[f64], n: [f64; 3]) -> [usize; 2] {
    let height = |i: usize| x[i] * n[0] + y[i] * n[1] + z[i] * n[2];
    let (groups, _) = x.as_chunks::<LANES>();
    let (yg, zg) = (
        &y.as_chunks::<LANES>().0[..groups.len()],
        &z.as_chunks::<LANES>().0[..groups.len()],
    );
    let (mut lo, mut lo_at) = ([f64::INFINITY; LANES], [0usize; LANES]);
    let (mut hi, mut hi_at) = ([f64::NEG_INFINITY; LANES], [0usize; LANES]);
    for (g, xs) in groups.iter().enumerate() {
        let (ys, zs) = (&yg[g], &zg[g]);
        for j in 0..LANES {
            let h = xs[j] * n[0] + ys[j] * n[1] + zs[j] * n[2];
            let at = g * LANES + j;
            let less = h < lo[j];
            lo[j] = if less { h } else { lo[j] };
            lo_at[j] = if less { at } else { lo_at[j] };
            let more = h >= hi[j];
            hi[j] = if more { h } else { hi[j] };
            hi_at[j] = if more { at } else { hi_at[j] };
        }
    }
    // Across lanes: the least value at its first index, the greatest at its last.
    let (mut least, mut greatest) = ((f64::INFINITY, 0), (f64::NEG_INFINITY, 0));
    for j in 0..LANES {
        if lo[j] < least.0 || (lo[j] == least.0 && lo_at[j] < least.1) {
            least = (lo[j], lo_at[j]);
        }
        if hi[j] > greatest.0 || (hi[j] == greatest.0 && hi_at[j] > greatest.1) {
            greatest = (hi[j], hi_at[j]);
        }
    }
    for i in groups.len() * LANES..x.len() {
        let h = height(i);
        if h < least.0 {
            least = (h, i);
        }
        if h >= greatest.0 {
            greatest = (h, i);
        }
    }
    [least.1, greatest.1]
}

/// A face's plane, for a filter on the side of a point: a vertex `a`, the normal
/// `n = (b − a) × (c − a)` and the pad factor `2^-40·|b − a|₁·|c − a|₁`.
///
/// The `f64` value of `n·(p − a)` is within a few `u = 2^-53` times
/// `|b − a|₁·|c − a|₁·|p − a|₁` of the exact one (products of differences of `f32` values
/// neither overflow nor underflow `f64`), far below the pad, `2^-40` times that; beyond the
/// pad its sign is the exact sign.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Plane {
    a: DVec3,
    n: DVec3,
    pad: f64,
}

impl Plane {
    pub(crate) fn new(a: DVec3, b: DVec3, c: DVec3) -> Self {
        let (ab, ac) = (b - a, c - a);
        Self {
            a,
            n: ab.cross(ac),
            pad: pow2(-40) * ab.abs().element_sum() * ac.abs().element_sum(),
        }
    }

    /// `Some(true)` when `p` lies strictly above the plane (on the side of `n`),
    /// `Some(false)` strictly below, `None` within the pad (undecided).
    #[inline]
    pub(crate) fn side(&self, p: DVec3) -> Option<bool> {
        match side_code(self.n.to_array(), self.a.to_array(), self.pad, p.to_array()) {
            1 => Some(true),
            -1 => Some(false),
            _ => None,
        }
    }

    /// The normal, the vertex and the pad factor, as arrays (for planes held as columns).
    pub(crate) fn parts(&self) -> ([f64; 3], [f64; 3], f64) {
        (self.n.to_array(), self.a.to_array(), self.pad)
    }
}

/// [`Plane::side`] from the plane's parts (`n`, `a`, `pad`): `1` strictly above, `-1`
/// strictly below, `0` within the pad. Branch-free, so that a loop over planes held as
/// columns runs in lanes.
#[inline(always)]
pub(crate) fn side_code(n: [f64; 3], a: [f64; 3], pad: f64, p: [f64; 3]) -> i8 {
    let d = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let height = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
    let reach = pad * (d[0].abs() + d[1].abs() + d[2].abs());
    i8::from(height > reach) - i8::from(height < -reach)
}

/// A face's plane for [`outside_extremal_hull`]'s filter, in `f32`: a vertex `a` (the
/// points are `f32` values, so it is exact), the normal `n = (b − a) × (c − a)` computed in
/// `f64` and rounded to `f32`, and the pad factor `2^-20·|b − a|₁·|c − a|₁` rounded up.
///
/// **The bound.** With `D = p − a` exact and `H = ((b − a) × (c − a))·D` exact, each
/// `|n_i| <= |b − a|₁·|c − a|₁`, so `S = |b − a|₁·|c − a|₁·|D|₁` bounds `Σ|n_i·D_i|`. The
/// `f64` normal errs by a few `2^-53·|b − a|₁·|c − a|₁` per component; rounding it to `f32`,
/// the three differences `d = fl(p − a)`, the three products and the two sums add at most
/// `γ₃₂(6) < 2^-21.4` of `S` and, where products underflow, `3·2^-150`. The computed height
/// `h` is therefore within `2^-21·S + 2^-147` of `H`. The computed reach
/// `pad·(|d₀| + |d₁| + |d₂|)` is at least `2^-20·S·(1 − 2^-21)` less `2^-147` (where it
/// underflows), above `2^-21·S`; the filter drops a point only when
/// `h < −(reach + 2^-140)`, which proves `H < 0`. The pad itself must be a normal `f32`:
/// below `2^-120` the plane is refused.
///
/// **No overflow.** A plane is also refused (`None`) unless, with `R` a bound on every
/// `|p|₁`, `2R < 2^120` and `pad·2R < 2^100`: then every difference, product, sum and
/// reach stays inside `f32`'s range (`|D|₁ <= 2R`, `|n_i| <= 2^20·pad`).
#[derive(Clone, Copy, Debug)]
struct FilterPlane {
    a: [f32; 3],
    n: [f32; 3],
    pad: f32,
}

impl FilterPlane {
    fn new([a, b, c]: [DVec3; 3], reach: f64) -> Option<Self> {
        let (ab, ac) = (b - a, c - a);
        let n = ab.cross(ac);
        // Rounding up by a relative `2^-20` covers the product's rounding and the
        // conversion's.
        let pad = pow2(-20) * ab.abs().element_sum() * ac.abs().element_sum() * (1.0 + pow2(-20));
        let fits = pad >= pow2(-120) && 2.0 * reach < pow2(120) && pad * 2.0 * reach < pow2(100);
        fits.then(|| Self {
            a: a.to_array().map(|v| v as f32),
            n: n.to_array().map(|v| v as f32),
            pad: pad as f32 * (1.0 + pow2(-20) as f32),
        })
    }

    /// Clears `inside[i]` unless the point `(x[i], y[i], z[i])` lies below the plane by
    /// more than the pad: plain array code, for lanes.
    #[inline(always)]
    fn below(&self, x: &[f32], y: &[f32], z: &[f32], inside: &mut [bool]) {
        let Self { a, n, pad } = *self;
        let least = pow2(-140) as f32;
        for (i, inside) in inside.iter_mut().enumerate() {
            let d = [x[i] - a[0], y[i] - a[1], z[i] - a[2]];
            let height = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
            let reach = pad * (d[0].abs() + d[1].abs() + d[2].abs());
            *inside &= height < -(reach + least);
        }
    }
}

/// No face or point: the end of an outside list, a point on no list.
const NONE: usize = usize::MAX;

/// The working state: faces with their outside sets and their neighbours.
///
/// An outside set is a list threaded through the points (`first`, `last` per face, `next`
/// per point), in the order the points were assigned; the walks keep their lists in scratch
/// vectors that live as long as the hull. So a run allocates only as the faces grow.
struct Quickhull<'a> {
    points: &'a [DVec3],
    faces: Vec<[usize; 3]>,
    planes: Vec<Plane>,
    /// `neighbors[f][k]`: the face across edge `k` of face `f`, `faces[f][k] → faces[f][k + 1]`
    /// (it runs the other way).
    neighbors: Vec<[usize; 3]>,
    alive: Vec<bool>,
    /// The first and last point of each face's outside set ([`NONE`] when it is empty).
    first: Vec<usize>,
    last: Vec<usize>,
    /// The point after each point in its face's outside set.
    next: Vec<usize>,
    /// Dead faces' slots, for new faces.
    free: Vec<usize>,
    /// `visible[f] == step` marks the faces that the current eye sees.
    visible: Vec<usize>,
    step: usize,
    /// Scratch: the visible faces in walk order, the horizon, the new faces, the orphans.
    seen: Vec<usize>,
    horizon: Vec<(usize, usize, usize)>,
    cone: Vec<usize>,
    orphans: Vec<usize>,
}

impl<'a> Quickhull<'a> {
    /// The tetrahedron on four affinely independent points, every other point assigned to
    /// a face that sees it.
    fn new(points: &'a [DVec3], [a, b, c, d]: [usize; 4]) -> Self {
        let p = |i: usize| points[i];
        // Make `d` lie below the base (a, b, c) so that all four faces turn outward.
        let (b, c) = if above(p(a), p(b), p(c), p(d)) {
            (c, b)
        } else {
            (b, c)
        };
        // Room for every face: dead faces' slots are reused, and a hull of `n` points has
        // at most `2n − 4` faces (a step's new faces take the slots of those it kills,
        // at least one, before more).
        let faces = 2 * points.len() + 8;
        let mut hull = Self {
            points,
            faces: Vec::with_capacity(faces),
            planes: Vec::with_capacity(faces),
            neighbors: Vec::with_capacity(faces),
            alive: Vec::with_capacity(faces),
            first: Vec::with_capacity(faces),
            last: Vec::with_capacity(faces),
            next: vec![NONE; points.len()],
            free: Vec::new(),
            visible: Vec::with_capacity(faces),
            step: 0,
            seen: Vec::new(),
            horizon: Vec::new(),
            cone: Vec::new(),
            orphans: Vec::new(),
        };
        let new_faces = [[a, b, c], [a, d, b], [b, d, c], [c, d, a]].map(|f| hull.add_face(f));
        // Each edge's twin runs the other way in another of the four faces.
        for f in 0..4 {
            for k in 0..3 {
                let (u, v) = (hull.faces[f][k], hull.faces[f][(k + 1) % 3]);
                hull.neighbors[f][k] = (0..4)
                    .find(|&g| {
                        (0..3).any(|j| hull.faces[g][j] == v && hull.faces[g][(j + 1) % 3] == u)
                    })
                    .unwrap_or(f);
            }
        }
        let rest = (0..points.len()).filter(|i| ![a, b, c, d].contains(i));
        hull.assign(rest, &new_faces);
        hull
    }

    /// A new face, in the slot of a dead one when there is one (so the vectors stay the
    /// size of the hull, not of every face ever made).
    fn add_face(&mut self, face: [usize; 3]) -> usize {
        let [a, b, c] = face.map(|i| self.points[i]);
        let plane = Plane::new(a, b, c);
        if let Some(id) = self.free.pop() {
            self.planes[id] = plane;
            self.faces[id] = face;
            self.neighbors[id] = [id; 3];
            self.alive[id] = true;
            (self.first[id], self.last[id]) = (NONE, NONE);
            self.visible[id] = 0;
            return id;
        }
        let id = self.faces.len();
        self.planes.push(plane);
        self.faces.push(face);
        self.neighbors.push([id; 3]);
        self.alive.push(true);
        self.first.push(NONE);
        self.last.push(NONE);
        self.visible.push(0);
        id
    }

    /// Exact: the face sees the point (it lies strictly above the face's plane); the
    /// plane's filter decides, and `orient3d` when it cannot.
    fn sees(&self, face: usize, point: usize) -> bool {
        let p = self.points[point];
        self.planes[face].side(p).unwrap_or_else(|| {
            let [a, b, c] = self.faces[face].map(|i| self.points[i]);
            above(a, b, c, p)
        })
    }

    /// The points of a face's outside set, in the order they were assigned.
    fn outside(&self, face: usize) -> impl Iterator<Item = usize> + '_ {
        let point = |i: usize| (i != NONE).then_some(i);
        core::iter::successors(point(self.first[face]), move |&i| point(self.next[i]))
    }

    /// Puts each point at the end of the outside set of the first face that sees it; the
    /// others lie inside the hull of the faces (Barber et al. 1996, Lemma 3.1) and are
    /// dropped.
    fn assign(&mut self, points: impl Iterator<Item = usize>, faces: &[usize]) {
        for i in points {
            if let Some(&f) = faces.iter().find(|&&f| self.sees(f, i)) {
                self.next[i] = NONE;
                match self.last[f] {
                    NONE => self.first[f] = i,
                    tail => self.next[tail] = i,
                }
                self.last[f] = i;
            }
        }
    }

    /// The point of the face's outside set farthest from its plane (`f64` is enough: any
    /// point that the face sees is a valid choice); the last of them on ties.
    fn eye(&self, face: usize) -> usize {
        let Plane { a, n, .. } = self.planes[face];
        last_greatest(self.outside(face), |i| (self.points[i] - a).dot(n))
            .unwrap_or(self.first[face])
    }

    /// Adds outside points until no face sees any.
    fn run(&mut self) {
        let mut stack: Vec<usize> = (0..self.faces.len()).collect();
        while let Some(face) = stack.pop() {
            if !self.alive[face] || self.first[face] == NONE {
                continue;
            }
            let eye = self.eye(face);
            self.visible_from(face, eye);
            // The horizon: edges of visible faces whose neighbour is not visible, with it;
            // the orphans: the visible faces' outside points, in order.
            let mut horizon = core::mem::take(&mut self.horizon);
            let mut orphans = core::mem::take(&mut self.orphans);
            let mut cone = core::mem::take(&mut self.cone);
            horizon.clear();
            orphans.clear();
            cone.clear();
            for &f in &self.seen {
                let tri = self.faces[f];
                for k in 0..3 {
                    let g = self.neighbors[f][k];
                    if self.visible[g] != self.step {
                        horizon.push((tri[k], tri[(k + 1) % 3], g));
                    }
                }
                self.alive[f] = false;
                orphans.extend(self.outside(f));
                self.free.push(f);
            }
            // A cone of new faces `(u, v, eye)`: across `(u, v)` the horizon face, across
            // `(v, eye)` the new face that starts at `v`, across `(eye, u)` the one that ends
            // at `u` (the horizon is one simple cycle).
            for &(u, v, g) in &horizon {
                let id = self.add_face([u, v, eye]);
                self.neighbors[id][0] = g;
                if let Some(j) =
                    (0..3).find(|&j| self.faces[g][j] == v && self.faces[g][(j + 1) % 3] == u)
                {
                    self.neighbors[g][j] = id;
                }
                cone.push(id);
            }
            for (n, &(u, v, _)) in horizon.iter().enumerate() {
                let id = cone[n];
                if let Some(m) = horizon.iter().position(|&(s, _, _)| s == v) {
                    self.neighbors[id][1] = cone[m];
                }
                if let Some(m) = horizon.iter().position(|&(_, e, _)| e == u) {
                    self.neighbors[id][2] = cone[m];
                }
            }
            self.assign(orphans.iter().copied().filter(|&i| i != eye), &cone);
            stack.extend(&cone);
            self.horizon = horizon;
            self.orphans = orphans;
            self.cone = cone;
        }
    }

    /// The faces that see `eye` into `seen`: a connected disk, found by a walk from `start`
    /// across neighbours, in walk order (so the hull is the same on every run); each is
    /// marked with a new step number in `visible`.
    fn visible_from(&mut self, start: usize, eye: usize) {
        self.step += 1;
        self.visible[start] = self.step;
        self.seen.clear();
        self.seen.push(start);
        let mut next = 0;
        while let Some(&f) = self.seen.get(next) {
            next += 1;
            for k in 0..3 {
                let g = self.neighbors[f][k];
                if self.visible[g] != self.step && self.sees(g, eye) {
                    self.visible[g] = self.step;
                    self.seen.push(g);
                }
            }
        }
    }

    fn into_hull(self) -> Hull {
        let mut index = vec![NONE; self.points.len()];
        let mut vertices = Vec::new();
        let alive: Vec<usize> = (0..self.faces.len()).filter(|&f| self.alive[f]).collect();
        // The live faces' new numbers, for their neighbours.
        let mut number = vec![NONE; self.faces.len()];
        for (t, &f) in alive.iter().enumerate() {
            number[f] = t;
        }
        let triangles = alive
            .iter()
            .map(|&f| {
                self.faces[f].map(|i| {
                    if index[i] == NONE {
                        index[i] = vertices.len();
                        vertices.push(self.points[i]);
                    }
                    index[i]
                })
            })
            .collect();
        let neighbors: Vec<[usize; 3]> = alive
            .iter()
            .map(|&f| self.neighbors[f].map(|g| number[g]))
            .collect();
        Hull::Solid(Box::new(Solid::new(vertices, triangles, &neighbors)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_of_a_cube_with_inner_and_face_points() {
        let mut points: Vec<DVec3> = (0..8)
            .map(|k| DVec3::new((k & 1) as f64, (k >> 1 & 1) as f64, (k >> 2 & 1) as f64))
            .collect();
        points.extend([
            DVec3::splat(0.5),
            DVec3::new(0.5, 0.5, 1.0),
            DVec3::new(0.25, 0.0, 0.5),
        ]);
        let Hull::Solid(hull) = convex_hull(&points) else {
            panic!("a cube is solid");
        };
        let Solid {
            vertices,
            triangles,
            ..
        } = *hull;
        assert_eq!(vertices.len(), 8);
        assert_eq!(triangles.len(), 12);
        for t in &triangles {
            let [a, b, c] = t.map(|i| vertices[i]);
            assert!(
                points.iter().all(|&p| !above(a, b, c, p)),
                "every point below each face"
            );
        }
        assert!(matches!(convex_hull(&points[..4]), Hull::Planar(n) if n.z.abs() == 1.0));
        let line = [
            DVec3::ZERO,
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(-2.0, -4.0, -6.0),
        ];
        assert!(matches!(convex_hull(&line), Hull::Segment(_)));
        assert!(matches!(convex_hull(&[DVec3::ONE]), Hull::Point));
    }

    /// The filter drops no vertex: the hull of a cloud (points on a sphere and inside it,
    /// one on a segment between two of them) is the hull of all its points.
    #[test]
    fn the_filter_drops_only_points_strictly_below() {
        // Points a hair from random planes (relative distances from 1e-9 to 1e-3), as
        // given and far from the origin: every point the `f32` filter drops is strictly
        // below the plane by the exact predicate, and most of those clearly below are
        // dropped.
        let mut next = crate::num::uniform(0x9e37_79b9_7f4a_7c15);
        let (mut dropped, mut clear) = (0, 0);
        for round in 0..200 {
            let offset = if round % 2 == 0 { 0.0 } else { 3e4 };
            let mut point = || {
                (DVec3::new(next(), next(), next()) + offset)
                    .as_vec3()
                    .as_dvec3()
            };
            let [a, b, c] = [point(), point(), point()];
            let Some(plane) = FilterPlane::new([a, b, c], 4e4 * 3.0) else {
                panic!("a plane of ordinary size");
            };
            let normal = (b - a).cross(c - a).normalize();
            let points: Vec<DVec3> = (0..64)
                .map(|k| {
                    let (u, v) = (next().abs(), next().abs());
                    let height = next() * 10f64.powi(-(k % 7) - 3) * (1.0 + offset);
                    (a + (b - a) * u + (c - a) * v + normal * height)
                        .as_vec3()
                        .as_dvec3()
                })
                .collect();
            let [x, y, z] =
                [0, 1, 2].map(|k| points.iter().map(|p| p[k] as f32).collect::<Vec<_>>());
            let mut inside = vec![true; points.len()];
            plane.below(&x, &y, &z, &mut inside);
            for (p, inside) in points.iter().zip(inside) {
                let below = orient3d(coord(a), coord(b), coord(c), coord(*p)) > 0.0;
                assert!(!inside || below, "{p} dropped but not below {a} {b} {c}");
                dropped += usize::from(inside);
                clear += usize::from((*p - a).dot(normal) < -1e-4 * (1.0 + offset));
            }
        }
        assert!(
            dropped >= clear && clear > 500,
            "{dropped} dropped, {clear} clearly below"
        );
    }

    #[test]
    fn the_lane_scan_finds_the_first_least_and_the_last_greatest() {
        let mut next = crate::num::uniform(0x9e37_79b9_7f4a_7c15);
        // Coordinates from a few values, so that many points tie on every direction; every
        // length up to a few groups, so that each lane and the partial group hold extremes.
        for len in 1..40 {
            let points: Vec<DVec3> = (0..len)
                .map(|_| DVec3::new(next(), next(), next()).map(|v| (v * 2.0).round()))
                .collect();
            let [x, y, z] = [0, 1, 2].map(|k| points.iter().map(|p| p[k]).collect::<Vec<_>>());
            for n in SAMPLE_DIRECTIONS {
                let h = |i: usize| points[i].dot(DVec3::from_array(n));
                let least = (0..len).reduce(|a, i| if h(i) < h(a) { i } else { a });
                let greatest = (0..len).reduce(|a, i| if h(i) >= h(a) { i } else { a });
                assert_eq!(
                    first_least_last_greatest(&x, &y, &z, n),
                    [least.unwrap(), greatest.unwrap()],
                    "{len} points along {n:?}"
                );
            }
        }
    }

    #[test]
    fn the_extremal_filter_keeps_every_vertex() {
        let mut next = crate::num::uniform(0x2545_f491_4f6c_dd1d);
        let mut points: Vec<DVec3> = (0..2000)
            .map(|k| {
                let p = DVec3::new(next(), next(), next());
                // On the unit sphere, or in the cube of half-side 0.5 inside it.
                if k % 3 == 0 { p.normalize() } else { p * 0.5 }
            })
            .map(|p| p.as_vec3().as_dvec3())
            .collect();
        // Points on the segment between two extremal points lie on the filter's hull.
        points.push((points[0] + points[1]) * 0.5);
        let vertices = |hull: Hull| match hull {
            Hull::Solid(hull) => {
                let vertices = hull.vertices;
                let mut v: Vec<[u64; 3]> = vertices
                    .iter()
                    .map(|p| p.to_array().map(f64::to_bits))
                    .collect();
                v.sort_unstable();
                v
            }
            _ => panic!("a ball is solid"),
        };
        // As given, moved far from the origin, and scaled near the bottom of `f32`'s range
        // (where the filter refuses its planes and keeps every point).
        for (scale, offset, drops) in [(1.0, 0.0, true), (3.0, 1e4, true), (1e-36, 0.0, false)] {
            let points: Vec<DVec3> = points
                .iter()
                .map(|&p| (p * scale + DVec3::splat(offset)).as_vec3().as_dvec3())
                .collect();
            let seed = tetrahedron(&points).expect("a solid");
            let kept = outside_extremal_hull(&points, seed).len();
            assert_eq!(
                kept < points.len() / 2,
                drops,
                "{scale} {offset}: {kept} kept"
            );
            let filtered = vertices(convex_hull(&points));
            let mut full = Quickhull::new(&points, seed);
            full.run();
            assert_eq!(filtered, vertices(full.into_hull()), "{scale} {offset}");
            if scale == 1.0 {
                assert_eq!(filtered.len(), 667, "every point on the sphere");
            }
        }
    }

    /// The outline that tests only the cells `n` may split holds the same vertices as a test
    /// of every edge and every triangle, on a ball (many cells), a cube (coplanar faces,
    /// edge-on along the axes) and a sliver-thin slab.
    #[test]
    fn the_outline_of_the_cells_is_that_of_every_edge() {
        let mut next = crate::num::uniform(0x2545_f491_4f6c_dd1d);
        let ball: Vec<DVec3> = (0..1000)
            .map(|_| DVec3::new(next(), next(), next()).normalize())
            .map(|p| p.as_vec3().as_dvec3())
            .collect();
        let cube: Vec<DVec3> = (0..64)
            .map(|k| DVec3::new((k % 4) as f64, (k / 4 % 4) as f64, (k / 16) as f64))
            .collect();
        let slab: Vec<DVec3> = (0..400)
            .map(|_| DVec3::new(next(), next(), 1e-6 * next()))
            .map(|p| p.as_vec3().as_dvec3())
            .collect();
        // The cube's 18 edges make one cell.
        for (points, split) in [(ball, true), (cube, false), (slab, true)] {
            let Hull::Solid(hull) = convex_hull(&points) else {
                panic!("solid");
            };
            assert_eq!(hull.cells.len() > 1, split);
            let mut directions: Vec<DVec3> = hull.areas.iter().map(|a| a.normalize()).collect();
            directions.extend([DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE.normalize()]);
            directions.extend((0..50).map(|_| DVec3::new(next(), next(), next()).normalize()));
            let mut bands = vec![0.0; hull.triangles.len()];
            for edge in &hull.edges {
                for k in 0..2 {
                    bands[edge.faces[k]] = edge.bands[k];
                }
            }
            for n in directions {
                let side = |t: usize| {
                    let h = hull.areas[t].dot(n);
                    i8::from(h > bands[t]) - i8::from(h < -bands[t])
                };
                let mut every: Vec<[usize; 2]> = hull
                    .edges
                    .iter()
                    .filter(|e| (side(e.faces[0]) == 1) != (side(e.faces[1]) == 1))
                    .map(|e| {
                        let [u, v] = e.tails;
                        if side(e.faces[0]) == 1 {
                            [u, v]
                        } else {
                            [v, u]
                        }
                    })
                    .chain(
                        (0..hull.triangles.len())
                            .filter(|&t| side(t) == 0)
                            .flat_map(|t| {
                                let [a, b, c] = hull.triangles[t];
                                [[a, b], [b, c], [c, a]]
                            }),
                    )
                    .collect();
                let mut found = hull.outline(n);
                for list in [&mut every, &mut found] {
                    list.sort_unstable();
                    list.dedup();
                }
                assert_eq!(found, every, "along {n}");
            }
        }
    }

    /// The outline's shadow is the whole hull's: seen along the face normals, the axes
    /// (which leave faces of a cube edge-on) and random directions, every vertex projects
    /// inside the convex hull of the outline's projection; and the climbs reach the
    /// highest vertex along each direction.
    #[test]
    fn the_outline_casts_the_hull_shadow_and_the_climbs_reach_the_top() {
        let mut next = crate::num::uniform(0x9e37_79b9_7f4a_7c15);
        let cube: Vec<DVec3> = (0..27)
            .map(|k| DVec3::new((k % 3) as f64, (k / 3 % 3) as f64, (k / 9) as f64))
            .collect();
        let ball: Vec<DVec3> = (0..300)
            .map(|_| DVec3::new(next(), next(), next()).normalize() * (1.0 + 0.1 * next()))
            .map(|p| p.as_vec3().as_dvec3())
            .collect();
        for (points, round) in [(cube, false), (ball, true)] {
            let Hull::Solid(hull) = convex_hull(&points) else {
                panic!("solid");
            };
            let mut directions: Vec<DVec3> = hull.areas.iter().map(|a| a.normalize()).collect();
            directions.extend([DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE.normalize()]);
            directions.extend((0..50).map(|_| DVec3::new(next(), next(), next()).normalize()));
            for n in directions {
                // The climb reaches the highest vertex, from any vertex.
                let top = hull
                    .vertices
                    .iter()
                    .map(|v| v.dot(n))
                    .fold(f64::MIN, f64::max);
                for from in [0, hull.vertices.len() / 2] {
                    assert_eq!(hull.vertices[hull.extreme(n, from)].dot(n), top);
                }
                // The scan in lanes gives the same extents, to the bit.
                let extent = |d: DVec3| {
                    let h = hull.vertices.iter().map(|v| v.dot(d));
                    h.clone().fold(f64::MIN, f64::max) - h.fold(f64::MAX, f64::min)
                };
                assert_eq!(hull.scan([n]), [extent(n)]);
                let frame = [n, n.any_orthonormal_vector(), DVec3::X];
                assert_eq!(hull.scan(frame), frame.map(extent));
                let (e1, e2) = n.any_orthonormal_pair();
                let flat = |p: DVec3| glam::DVec2::new(p.dot(e1), p.dot(e2));
                let edges = hull.outline(n);
                let outline: Vec<usize> = edges.iter().map(|e| e[0]).collect();
                if round {
                    // The point of it: a rim of the ball, not all of it.
                    let mut distinct = outline.clone();
                    distinct.sort_unstable();
                    distinct.dedup();
                    assert!(
                        distinct.len() * 3 < hull.vertices.len(),
                        "{}",
                        distinct.len()
                    );
                }
                let mut shadow: Vec<_> = outline.iter().map(|&i| flat(hull.vertices[i])).collect();
                let shadow = crate::fit::rect::convex_hull_2d(&mut shadow);
                for &v in &hull.vertices {
                    let q = flat(v);
                    for (k, &a) in shadow.iter().enumerate() {
                        let b = shadow[(k + 1) % shadow.len()];
                        assert!(
                            (b - a).perp_dot(q - a) >= -1e-12,
                            "{q} outside the shadow along {n}"
                        );
                    }
                }
                // A side of the shadow's least rectangle lies along one of the edges.
                let (_, least) = crate::fit::rect::min_area_rectangle(&mut shadow.clone());
                let column = |k: usize| outline.iter().map(|&i| hull.vertices[i][k]).collect();
                let [x, y, z]: [Vec<f64>; 3] = [column(0), column(1), column(2)];
                let (area, _) =
                    crate::fit::rect::least_rectangle(n, &hull.vertices, &edges, [&x, &y, &z])
                        .expect("a rectangle");
                assert!(
                    (area - least).abs() <= 1e-9 * least,
                    "{area} against {least} along {n}"
                );
            }
        }
    }
}
