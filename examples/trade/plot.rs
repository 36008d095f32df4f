//! The plot: speed against worst error, one panel per transform class, as plain SVG
//! (lines, circles, rects, polygons and unrotated text, so that simple renderers draw it
//! faithfully).
//!
//! Each panel shows every kernel of its class as a small pale marker (circle: Nearest,
//! square: Outward), the Pareto front of all its points (nothing else both faster and more
//! accurate) and the front of its Outward kernels (nothing that must contain is both
//! faster and more accurate) as lines through larger markers, and the peers as black
//! diamonds. Every point on a front and every peer is labelled; labels are placed where
//! they overlap no other label, marker or line.

use std::fmt::Write as _;

use bvkit::{Method, Rounding};

use crate::measure::{Kind, Peer, Row, SCALAR, TransformClass, cache};

/// Panels per row.
const COLUMNS: usize = 2;
/// The plot area of one panel.
const PLOT_W: f64 = 560.0;
const PLOT_H: f64 = 250.0;
/// Room around each plot area: y tick labels left, the title and y title above, x tick
/// labels and x title below.
const LEFT: f64 = 58.0;
const RIGHT: f64 = 26.0;
const ABOVE: f64 = 44.0;
const BELOW: f64 = 42.0;
/// Room above the panels for the title and the legend.
const HEADER: f64 = 118.0;
/// Font sizes: labels and ticks, panel titles, the title.
const FONT: f64 = 11.0;
const TITLE_FONT: f64 = 13.0;
const HEADER_FONT: f64 = 16.0;
/// Estimated width of a character, in font sizes (DejaVu Sans averages about this).
const CHAR_WIDTH: f64 = 0.6;
/// Marker half-sizes: off a front, on a front, peers.
const SMALL: f64 = 2.6;
const LARGE: f64 = 4.5;
const PEER: f64 = 5.5;

const NEAREST: &str = "#1f77b4";
const NEAREST_PALE: &str = "#a6c8e4";
const NEAREST_TEXT: &str = "#0b4a80";
const OUTWARD: &str = "#d95f02";
const OUTWARD_PALE: &str = "#f7c29b";
const OUTWARD_TEXT: &str = "#8c3a00";
const GRID: &str = "#e4e4e4";

/// An axis-aligned rectangle in SVG coordinates.
#[derive(Clone, Copy, Debug)]
struct Rect {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

impl Rect {
    fn around(x: f64, y: f64, half: f64) -> Rect {
        Rect {
            x0: x - half,
            y0: y - half,
            x1: x + half,
            y1: y + half,
        }
    }

    fn overlaps(&self, o: &Rect) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }

    fn contains(&self, o: &Rect) -> bool {
        o.x0 >= self.x0 && o.x1 <= self.x1 && o.y0 >= self.y0 && o.y1 <= self.y1
    }

    /// True when the segment from `a` to `b` passes through the rectangle (Liang–Barsky).
    fn crossed_by(&self, (ax, ay): (f64, f64), (bx, by): (f64, f64)) -> bool {
        let (dx, dy) = (bx - ax, by - ay);
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for (p, q) in [
            (-dx, ax - self.x0),
            (dx, self.x1 - ax),
            (-dy, ay - self.y0),
            (dy, self.y1 - ay),
        ] {
            if p == 0.0 {
                if q < 0.0 {
                    return false;
                }
            } else {
                let t = q / p;
                if p < 0.0 {
                    t0 = t0.max(t);
                } else {
                    t1 = t1.min(t);
                }
                if t0 > t1 {
                    return false;
                }
            }
        }
        true
    }

    /// The point of the rectangle nearest to `(x, y)`.
    fn nearest(&self, x: f64, y: f64) -> (f64, f64) {
        (x.clamp(self.x0, self.x1), y.clamp(self.y0, self.y1))
    }
}

/// The estimated box of a text of `chars` characters at `size`.
fn text_size(chars: usize, size: f64) -> (f64, f64) {
    (chars as f64 * CHAR_WIDTH * size, size * 1.25)
}

/// Escapes text for SVG.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The 1-2-5 values from `lo` to `hi`.
fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let mut decade = 10f64.powf(lo.log10().floor());
    while decade <= hi * (1.0 + 1e-9) {
        for m in [1.0, 2.0, 5.0] {
            let v = m * decade;
            if v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9) {
                out.push(v);
            }
        }
        decade *= 10.0;
    }
    out
}

/// The largest 1-2-5 value at most `v`.
fn nice_below(v: f64) -> f64 {
    let decade = 10f64.powf(v.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|&x| x <= v)
        .unwrap_or(decade)
}

/// The smallest 1-2-5 value at least `v`.
fn nice_above(v: f64) -> f64 {
    let decade = 10f64.powf(v.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|&x| x >= v)
        .unwrap_or(10.0 * decade)
}

/// A tick value with as many decimals as it needs.
fn tick_label(v: f64) -> String {
    let decimals = (-v.log10()).ceil().max(0.0) as usize;
    format!("{v:.decimals$}")
}

/// The short label of a kernel or peer, or `None` for a row the plot leaves out.
fn label(row: &Row) -> Option<String> {
    match row.kind {
        Kind::Kernel(method, rounding) => {
            let m = match method {
                Method::Naive => "naive",
                Method::AbsMatrix => "abs",
                Method::SignSelect => "sign",
            };
            let r = match rounding {
                Rounding::Nearest => "near",
                Rounding::Outward => "out",
            };
            let backend = if row.backend == SCALAR { " scalar" } else { "" };
            Some(format!("{m}/{r} {}{backend}", row.layout.name()))
        }
        // parry3d in another class than rigid ran on that scene's rigid poses: no peer
        // of the class.
        Kind::Peer(Peer::Parry) if row.class != TransformClass::Rigid3 => None,
        Kind::Peer(peer) => Some(
            match peer {
                Peer::Parry => "parry3d loop (error n/a)",
                Peer::GlamCorners => "glam 8-corner loop",
                Peer::GlamAbsMatrix => "glam abs-matrix loop",
                Peer::GlamRigid => "glam from_quat loop",
            }
            .into(),
        ),
        Kind::Roofline => None,
    }
}

/// One plotted row.
struct Point<'a> {
    row: &'a Row,
    label: String,
    ns: f64,
    /// The worst error in `u·S`; `None` for a peer the oracle cannot judge.
    error: Option<f64>,
}

impl Point<'_> {
    fn outward(&self) -> bool {
        matches!(self.row.kind, Kind::Kernel(_, Rounding::Outward))
    }

    fn peer(&self) -> bool {
        matches!(self.row.kind, Kind::Peer(_))
    }
}

/// The indices of the points on the Pareto front of `candidates` (no other candidate both
/// at least as fast and at least as accurate, and better in one), by speed.
fn pareto<'a>(points: &[Point<'a>], candidates: impl Fn(&Point<'a>) -> bool) -> Vec<usize> {
    let on: Vec<usize> = (0..points.len())
        .filter(|&i| candidates(&points[i]) && points[i].error.is_some())
        .collect();
    let mut front: Vec<usize> = on
        .iter()
        .copied()
        .filter(|&i| {
            let (ns, e) = (points[i].ns, points[i].error.unwrap());
            !on.iter().any(|&j| {
                let (nj, ej) = (points[j].ns, points[j].error.unwrap());
                nj <= ns && ej <= e && (nj < ns || ej < e)
            })
        })
        .collect();
    front.sort_by(|&a, &b| points[a].ns.total_cmp(&points[b].ns));
    front
}

/// One panel's coordinate mapping.
struct Axes {
    area: Rect,
    x: (f64, f64),
    y: (f64, f64),
}

impl Axes {
    fn px(&self, ns: f64) -> f64 {
        let (lo, hi) = (self.x.0.log10(), self.x.1.log10());
        self.area.x0 + (ns.log10() - lo) / (hi - lo) * (self.area.x1 - self.area.x0)
    }

    fn py(&self, error: f64) -> f64 {
        let (lo, hi) = (self.y.0.log10(), self.y.1.log10());
        let e = error.max(self.y.0).log10();
        self.area.y1 - (e - lo) / (hi - lo) * (self.area.y1 - self.area.y0)
    }
}

/// What labels must not cover.
#[derive(Default)]
struct Obstacles {
    rects: Vec<Rect>,
    segments: Vec<((f64, f64), (f64, f64))>,
}

impl Obstacles {
    /// How many obstacles `r` touches (with a pixel of room).
    fn hits(&self, r: &Rect) -> usize {
        let padded = Rect {
            x0: r.x0 - 1.0,
            y0: r.y0 - 1.0,
            x1: r.x1 + 1.0,
            y1: r.y1 + 1.0,
        };
        self.rects.iter().filter(|o| o.overlaps(&padded)).count()
            + self
                .segments
                .iter()
                .filter(|(a, b)| padded.crossed_by(*a, *b))
                .count()
    }
}

/// A label's box for a point at `(x, y)`, `gap` pixels from it in direction `(dx, dy)`
/// (each −1, 0 or 1).
fn candidate(x: f64, y: f64, (w, h): (f64, f64), gap: f64, (dx, dy): (f64, f64)) -> Rect {
    let diagonal = if dx != 0.0 && dy != 0.0 { 0.7 } else { 1.0 };
    let cx = x + dx * (gap * diagonal + w / 2.0);
    let cy = y + dy * (gap * diagonal + h / 2.0);
    Rect {
        x0: cx - w / 2.0,
        y0: cy - h / 2.0,
        x1: cx + w / 2.0,
        y1: cy + h / 2.0,
    }
}

/// Places a label of size `size` for a point at `(x, y)` with marker half-size `half`:
/// the first box, nearest first, inside `area` that touches no obstacle; else the one that
/// touches fewest. Returns the box and whether it lies away from the point (needs a
/// leader line).
fn place(
    (x, y): (f64, f64),
    half: f64,
    size: (f64, f64),
    area: &Rect,
    obstacles: &Obstacles,
) -> (Rect, bool) {
    const DIRECTIONS: [(f64, f64); 8] = [
        (1.0, 0.0),
        (-1.0, 0.0),
        (1.0, -1.0),
        (1.0, 1.0),
        (-1.0, -1.0),
        (-1.0, 1.0),
        (0.0, -1.0),
        (0.0, 1.0),
    ];
    let mut best: Option<(usize, Rect, bool)> = None;
    for (step, extra) in [3.0, 9.0, 16.0, 26.0, 40.0, 58.0, 80.0]
        .into_iter()
        .enumerate()
    {
        for d in DIRECTIONS {
            let r = candidate(x, y, size, half + extra, d);
            if !area.contains(&r) {
                continue;
            }
            let hits = obstacles.hits(&r);
            if hits == 0 {
                return (r, step > 1);
            }
            if best.is_none_or(|(h, _, _)| hits < h) {
                best = Some((hits, r, step > 1));
            }
        }
    }
    let (_, r, leader) = best.unwrap_or((0, candidate(x, y, size, half, (1.0, 0.0)), false));
    (r, leader)
}

/// A circle of radius `r`; `extra` holds further attributes.
fn circle(x: f64, y: f64, r: f64, fill: &str, extra: &str) -> String {
    format!(r#"<circle cx="{x:.1}" cy="{y:.1}" r="{r:.1}" fill="{fill}"{extra}/>"#)
}

/// A square of half-side `half`; `extra` holds further attributes.
fn square(x: f64, y: f64, half: f64, fill: &str, extra: &str) -> String {
    format!(
        r#"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="{fill}"{extra}/>"#,
        x - half,
        y - half,
        2.0 * half,
        2.0 * half
    )
}

/// A peer's black diamond.
fn diamond(x: f64, y: f64) -> String {
    let h = PEER;
    format!(
        r#"<polygon points="{x:.1},{:.1} {:.1},{y:.1} {x:.1},{:.1} {:.1},{y:.1}" fill="black"/>"#,
        y - h,
        x + h,
        y + h,
        x - h
    )
}

/// A dashed vertical line: the speed of a peer without a measured error.
fn dashed(x: f64, y0: f64, y1: f64) -> String {
    format!(
        r##"<line x1="{x:.1}" y1="{y0:.1}" x2="{x:.1}" y2="{y1:.1}" stroke="#333" stroke-dasharray="5 4"/>"##
    )
}

/// The SVG of one point's marker.
fn marker(p: &Point, x: f64, y: f64, on_front: bool) -> String {
    if p.peer() {
        return diamond(x, y);
    }
    let (color, half) = match (p.outward(), on_front) {
        (false, false) => (NEAREST_PALE, SMALL),
        (false, true) => (NEAREST, LARGE),
        (true, false) => (OUTWARD_PALE, SMALL),
        (true, true) => (OUTWARD, LARGE),
    };
    let stroke = if on_front {
        r#" stroke="white" stroke-width="0.8""#
    } else {
        ""
    };
    if p.outward() {
        square(x, y, half, color, stroke)
    } else {
        circle(x, y, half, color, stroke)
    }
}

/// The half-size of a point's marker.
fn half_size(p: &Point, on_front: bool) -> f64 {
    if p.peer() {
        PEER
    } else if on_front {
        LARGE
    } else {
        SMALL
    }
}

/// Text at `(x, y)` (the baseline), anchored `start`, `middle` or `end`.
fn text(s: &mut String, (x, y): (f64, f64), size: f64, anchor: &str, style: &str, body: &str) {
    write!(
        s,
        r#"<text x="{x:.1}" y="{y:.1}" font-size="{size}" text-anchor="{anchor}"{style}>{}</text>"#,
        escape(body)
    )
    .unwrap();
}

/// Draws one panel into `s`; returns how many labels could not be placed clear.
fn panel(s: &mut String, class: TransformClass, points: &[Point], axes: &Axes) -> usize {
    let a = &axes.area;
    // Title, axis titles, grid, ticks, frame.
    text(
        s,
        ((a.x0 + a.x1) / 2.0, a.y0 - 24.0),
        TITLE_FONT,
        "middle",
        r#" font-weight="bold""#,
        &format!("{} ({})", class.name(), class.pose_type()),
    );
    text(
        s,
        (a.x0 - LEFT + 4.0, a.y0 - 8.0),
        FONT,
        "start",
        "",
        "worst error (u·S)",
    );
    text(
        s,
        ((a.x0 + a.x1) / 2.0, a.y1 + 34.0),
        FONT,
        "middle",
        "",
        "ns per box, in cache",
    );
    for v in ticks(axes.x.0, axes.x.1) {
        let x = axes.px(v);
        write!(
            s,
            r#"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="{GRID}"/>"#,
            a.y0, a.y1
        )
        .unwrap();
        text(s, (x, a.y1 + 15.0), FONT, "middle", "", &tick_label(v));
    }
    let y_ticks = ticks(axes.y.0, axes.y.1);
    // Every 1-2-5 tick is labelled where they are far enough apart; else the decades.
    let crowded = y_ticks
        .windows(2)
        .any(|w| axes.py(w[0]) - axes.py(w[1]) < 1.6 * FONT);
    for v in y_ticks {
        let y = axes.py(v);
        write!(
            s,
            r#"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{GRID}"/>"#,
            a.x0, a.x1
        )
        .unwrap();
        let decade = (v.log10() - v.log10().round()).abs() < 1e-9;
        if !crowded || decade {
            text(s, (a.x0 - 6.0, y + 4.0), FONT, "end", "", &tick_label(v));
        }
    }
    write!(
        s,
        r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="#555"/>"##,
        a.x0,
        a.y0,
        a.x1 - a.x0,
        a.y1 - a.y0
    )
    .unwrap();

    // The fronts, and what labels must avoid: every marker and line.
    let all = pareto(points, |_| true);
    let outward = pareto(points, Point::outward);
    let on_front = |i: usize| all.contains(&i) || outward.contains(&i);
    let xy = |p: &Point| (axes.px(p.ns), p.error.map(|e| axes.py(e)));
    let mut obstacles = Obstacles::default();
    for (i, p) in points.iter().enumerate() {
        match xy(p) {
            (x, Some(y)) => {
                obstacles
                    .rects
                    .push(Rect::around(x, y, half_size(p, on_front(i)) + 1.0))
            }
            (x, None) => obstacles.segments.push(((x, a.y0), (x, a.y1))),
        }
    }
    let mut lines = String::new();
    for (front, color) in [(&outward, OUTWARD), (&all, NEAREST)] {
        if front.len() < 2 {
            continue;
        }
        let vertices: Vec<(f64, f64)> = front
            .iter()
            .map(|&i| (axes.px(points[i].ns), axes.py(points[i].error.unwrap())))
            .collect();
        obstacles
            .segments
            .extend(vertices.windows(2).map(|w| (w[0], w[1])));
        let list: Vec<String> = vertices
            .iter()
            .map(|(x, y)| format!("{x:.1},{y:.1}"))
            .collect();
        write!(
            lines,
            r#"<polyline points="{}" fill="none" stroke="{color}" stroke-width="1.6"/>"#,
            list.join(" ")
        )
        .unwrap();
    }

    // Peers without an error: a dashed vertical line at their speed.
    for p in points.iter().filter(|p| p.error.is_none()) {
        s.push_str(&dashed(axes.px(p.ns), a.y0, a.y1));
    }
    s.push_str(&lines);
    // Off-front markers under front markers under peers.
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&i| points[i].error.is_some())
        .collect();
    order.sort_by_key(|&i| (points[i].peer(), on_front(i)));
    for &i in &order {
        let (x, y) = xy(&points[i]);
        s.push_str(&marker(&points[i], x, y.unwrap(), on_front(i)));
    }

    // Labels: the peers, then the fronts from fast to slow.
    let mut labelled: Vec<usize> = (0..points.len()).filter(|&i| points[i].peer()).collect();
    let mut fronts: Vec<usize> = all.iter().chain(&outward).copied().collect();
    fronts.sort_by(|&a, &b| points[a].ns.total_cmp(&points[b].ns).then(a.cmp(&b)));
    fronts.dedup();
    labelled.extend(fronts.into_iter().filter(|i| !points[*i].peer()));
    let mut unplaced = 0;
    for i in labelled {
        let p = &points[i];
        let size = text_size(p.label.chars().count(), FONT);
        let (x, half, y) = match xy(p) {
            (x, Some(y)) => (x, half_size(p, on_front(i)), y),
            // A peer line is labelled at its top, just off the line.
            (x, None) => (x, 0.0, a.y0 + size.1 / 2.0 + 2.0),
        };
        let (r, leader) = place((x, y), half, size, a, &obstacles);
        if obstacles.hits(&r) > 0 {
            unplaced += 1;
        }
        if leader {
            let (lx, ly) = r.nearest(x, y);
            write!(
                s,
                r##"<line x1="{x:.1}" y1="{y:.1}" x2="{lx:.1}" y2="{ly:.1}" stroke="#777" stroke-width="0.7"/>"##
            )
            .unwrap();
        }
        let color = if p.peer() {
            "black"
        } else if p.outward() {
            OUTWARD_TEXT
        } else {
            NEAREST_TEXT
        };
        write!(
            s,
            r#"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="white" fill-opacity="0.85"/>"#,
            r.x0,
            r.y0,
            r.x1 - r.x0,
            r.y1 - r.y0
        )
        .unwrap();
        text(
            s,
            (r.x0, r.y1 - 0.3 * FONT),
            FONT,
            "start",
            &format!(r#" fill="{color}""#),
            &p.label,
        );
        obstacles.rects.push(r);
    }
    unplaced
}

/// What a legend entry shows.
#[derive(Clone, Copy)]
enum Swatch {
    /// A marker on a front and one off it.
    Nearest,
    Outward,
    Peer,
    /// A front's line, in its colour.
    Front(&'static str),
    /// A peer's dashed line.
    Dashed,
}

/// The legend: the markers and lines of the panels, in two rows.
fn legend(s: &mut String, x0: f64, y0: f64) {
    let items: [[(Swatch, &str); 3]; 2] = [
        [
            (Swatch::Nearest, "Nearest kernel"),
            (Swatch::Outward, "Outward kernel (contains the exact box)"),
            (Swatch::Peer, "peer: the loop a user would write"),
        ],
        [
            (
                Swatch::Front(NEAREST),
                "Pareto front: no other point both faster and more accurate",
            ),
            (
                Swatch::Front(OUTWARD),
                "Pareto front of the Outward kernels",
            ),
            (Swatch::Dashed, "peer whose error the oracle cannot judge"),
        ],
    ];
    for (row, entries) in items.iter().enumerate() {
        let y = y0 + 22.0 * row as f64;
        let mut x = x0;
        for &(swatch, what) in entries {
            s.push_str(&match swatch {
                Swatch::Nearest => {
                    circle(x + 6.0, y, LARGE, NEAREST, "") + &circle(x + 20.0, y, SMALL, NEAREST_PALE, "")
                }
                Swatch::Outward => {
                    square(x + 6.0, y, LARGE, OUTWARD, "") + &square(x + 20.0, y, SMALL, OUTWARD_PALE, "")
                }
                Swatch::Peer => diamond(x + 12.0, y),
                Swatch::Front(color) => format!(
                    r#"<line x1="{x:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{color}" stroke-width="1.6"/>"#,
                    x + 26.0
                ),
                Swatch::Dashed => dashed(x + 12.0, y - 8.0, y + 8.0),
            });
            text(s, (x + 32.0, y + 4.0), FONT, "start", "", what);
            x += 32.0 + text_size(what.chars().count(), FONT).0 + 28.0;
        }
    }
}

/// The SVG, and how many labels overlap something (zero unless a panel is too crowded).
pub fn svg(rows: &[Row], best: &str) -> (String, usize) {
    let panels: Vec<(TransformClass, Vec<Point>)> = TransformClass::ALL
        .into_iter()
        .map(|class| {
            let points = rows
                .iter()
                .filter(|r| r.class == class)
                .filter_map(|row| {
                    Some(Point {
                        label: label(row)?,
                        row,
                        ns: row.ns_cache,
                        error: row.accuracy.map(|a| a.worst_error_us),
                    })
                })
                .collect();
            (class, points)
        })
        .collect();
    // One speed axis for every panel, so that the classes compare at a glance.
    let speeds = panels.iter().flat_map(|(_, p)| p.iter().map(|p| p.ns));
    let (fastest, slowest) =
        speeds.fold((f64::MAX, 0.0f64), |(lo, hi), ns| (lo.min(ns), hi.max(ns)));
    let x = (nice_below(fastest / 1.1), nice_above(slowest * 1.1));

    let rows_of_panels = TransformClass::ALL.len().div_ceil(COLUMNS);
    let (cell_w, cell_h) = (LEFT + PLOT_W + RIGHT, ABOVE + PLOT_H + BELOW);
    let (w, h) = (
        COLUMNS as f64 * cell_w + 20.0,
        HEADER + rows_of_panels as f64 * cell_h,
    );
    // `stroke="none"` at the root: ImageMagick's renderer otherwise outlines every shape
    // and text that names no stroke.
    let mut s = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="DejaVu Sans, Arial, Helvetica, sans-serif" font-size="{FONT}" stroke="none"><rect width="{w}" height="{h}" fill="white"/>"#
    );
    text(
        &mut s,
        (20.0, 28.0),
        HEADER_FONT,
        "start",
        r#" font-weight="bold""#,
        "bvkit: speed against worst error, per transform class",
    );
    text(
        &mut s,
        (20.0, 48.0),
        FONT,
        "start",
        "",
        &format!(
            "x: ns per box over {} boxes in cache (median; {best} and scalar backends, log scale). y: worst face error against the exact oracle, in u·S (log scale).",
            cache()
        ),
    );
    legend(&mut s, 24.0, 76.0);
    let mut unplaced = 0;
    for (k, (class, points)) in panels.iter().enumerate() {
        let (col, row) = (k % COLUMNS, k / COLUMNS);
        let (x0, y0) = (
            10.0 + col as f64 * cell_w + LEFT,
            HEADER + row as f64 * cell_h + ABOVE,
        );
        let errors = points.iter().filter_map(|p| p.error);
        let (lo, hi) = errors.fold((f64::MAX, 0.0f64), |(lo, hi), e| {
            (if e > 0.0 { lo.min(e) } else { lo }, hi.max(e))
        });
        let (mut y_lo, y_hi) = (nice_below(lo / 1.3), nice_above(hi * 1.3));
        if y_hi / y_lo < 10.0 {
            y_lo = nice_below(y_hi / 10.0);
        }
        let axes = Axes {
            area: Rect {
                x0,
                y0,
                x1: x0 + PLOT_W,
                y1: y0 + PLOT_H,
            },
            x,
            y: (y_lo, y_hi),
        };
        unplaced += panel(&mut s, *class, points, &axes);
    }
    s.push_str("</svg>\n");
    (s, unplaced)
}
