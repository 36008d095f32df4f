//! The brute-force referee of the broadphase tree: a list of proxies (state, kind, layers)
//! and every pair and query answer found by checking all of them, and a driver that applies
//! the same operation to a `DynamicTree` and to the referee and checks that they agree.
//! The tests drive it from random sequences, the fuzz target from bytes.

use std::collections::BTreeSet;

use bvkit::Aabb3;
use bvkit::broadphase::{
    BodyKind, BroadphaseError, CastControl, DynamicTree, KindPairs, Layers, Pairs, Ray,
};
use glam::Vec3A;
use num_bigint::BigInt;

use crate::oracle::Exact;

/// What the referee knows of a proxy's box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum State {
    Absent,
    Parked,
    Placed(Aabb3),
}

/// One proxy of the referee.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Proxy {
    pub state: State,
    pub kind: BodyKind,
    pub layers: Layers,
}

/// One operation on a tree.
#[derive(Clone, Debug)]
pub enum Op {
    Insert {
        id: u32,
        fat: Aabb3,
        kind: BodyKind,
        layers: Layers,
    },
    Remove(u32),
    /// New boxes for the ids, which must be ascending.
    Write(Vec<(u32, Aabb3)>),
    /// One proxy's new box, outside a write.
    Move(u32, Aabb3),
    SetKind(u32, BodyKind),
    SetLayers(u32, Layers),
    SetKindPairs(KindPairs),
    Query(Aabb3, Layers),
    QueryPoint(Vec3A, Layers),
    /// A ray cast (all hits), checked against the exact referee.
    CastRay(Ray, Layers),
    /// A box moving along a vector up to a length.
    CastBox(Aabb3, Vec3A, f32, Layers),
    Rebuild,
    /// The upkeep, a rebuild once anything moved, spread over this many calls.
    Maintain(u32),
    Report,
}

/// A box the tree accepts.
pub fn accepted(b: &Aabb3) -> bool {
    b.min.is_finite() && b.max.is_finite() && b.min.cmple(b.max).all()
}

/// True when the closed boxes share a point.
pub fn overlap(a: &Aabb3, b: &Aabb3) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}

/// The kinds' rule: at least one dynamic proxy, or a kinematic pair the switches admit.
pub fn kinds_admit(k: KindPairs, a: BodyKind, b: BodyKind) -> bool {
    use BodyKind::{Dynamic, Kinematic, Static};
    match (a, b) {
        (Dynamic, _) | (_, Dynamic) => true,
        (Kinematic, Kinematic) => k.kinematic_kinematic,
        (Kinematic, Static) | (Static, Kinematic) => k.kinematic_static,
        (Static, Static) => false,
    }
}

/// An exact fraction `n / d`, `d > 0`.
#[derive(Clone, Debug)]
pub struct Frac {
    n: BigInt,
    d: BigInt,
}

impl Frac {
    fn new(n: BigInt, d: BigInt) -> Self {
        if d < BigInt::ZERO {
            Frac { n: -n, d: -d }
        } else {
            Frac { n, d }
        }
    }

    /// The exact value of a finite `f32`.
    pub fn of(x: f32) -> Self {
        Frac::new(big(x), big(1.0))
    }

    /// `self <= other`, exactly.
    pub fn le(&self, other: &Frac) -> bool {
        &self.n * &other.d <= &other.n * &self.d
    }

    /// The nearest `f64` (for messages and tolerances).
    pub fn to_f64(&self) -> f64 {
        use num_traits::ToPrimitive;
        // Both scaled down together until they fit.
        let shift = self
            .d
            .bits()
            .saturating_sub(900)
            .max(self.n.bits().saturating_sub(900));
        let (n, d) = (&self.n >> shift, &self.d >> shift);
        n.to_f64().unwrap_or(f64::NAN) / d.to_f64().unwrap_or(f64::NAN)
    }
}

/// A finite `f32` as an integer, scaled by the oracle's `2^SCALE`.
fn big(x: f32) -> BigInt {
    match Exact::of(x) {
        Exact::Finite(b) => b,
        _ => panic!("a finite value"),
    }
}

/// The exact interval of `t` in `[0, max]` over which the box `[lo, hi]` moving along `d`
/// shares a point with box `p` on every axis that is not parallel to `d` (empty when
/// `enter > exit`; no `exit` when nothing bounds it), or `None` when a parallel axis
/// already keeps them apart. All inputs finite but `max`, which may be `+∞`.
fn exact_interval(
    lo: Vec3A,
    hi: Vec3A,
    d: Vec3A,
    max: f32,
    p: &Aabb3,
) -> Option<(Frac, Option<Frac>)> {
    let mut enter = Frac::of(0.0);
    let mut exit = (max != f32::INFINITY).then(|| Frac::of(max));
    for a in 0..3 {
        if d[a] == 0.0 {
            if !(p.min[a] <= hi[a] && lo[a] <= p.max[a]) {
                return None;
            }
            continue;
        }
        let t0 = Frac::new(big(p.min[a]) - big(hi[a]), big(d[a]));
        let t1 = Frac::new(big(p.max[a]) - big(lo[a]), big(d[a]));
        let (near, far) = if d[a] > 0.0 { (t0, t1) } else { (t1, t0) };
        if enter.le(&near) {
            enter = near;
        }
        exit = match exit {
            Some(e) if e.le(&far) => Some(e),
            _ => Some(far),
        };
    }
    Some((enter, exit))
}

/// The exact entry of the box `[lo, hi]` moving along `d` for `t` in `[0, max]` into box
/// `p` (a ray when `lo = hi`): the least `t` at which they share a point, or `None` when
/// they never do. All inputs finite but `max`, which may be `+∞`.
pub fn exact_entry(lo: Vec3A, hi: Vec3A, d: Vec3A, max: f32, p: &Aabb3) -> Option<Frac> {
    match exact_interval(lo, hi, d, max, p)? {
        (enter, Some(exit)) if !enter.le(&exit) => None,
        (enter, _) => Some(enter),
    }
}

/// True when the exact cast misses `p` only by an empty interval of `t` whose ends differ
/// by at most `2^-19` of their sizes or by at most `2^-99`: what the slab test's widening
/// (four `f32` steps, or `2^-50` in `f64`; `2^-100` near zero) may let through.
pub fn near_miss(lo: Vec3A, hi: Vec3A, d: Vec3A, max: f32, p: &Aabb3) -> bool {
    let Some((enter, Some(exit))) = exact_interval(lo, hi, d, max, p) else {
        return false;
    };
    let gap = &enter.n * &exit.d - &exit.n * &enter.d;
    use num_traits::Signed;
    let size = enter.n.abs() * &exit.d + exit.n.abs() * &enter.d;
    let scale = &enter.d * &exit.d;
    (&gap << 19usize) <= size || gap << 99usize <= scale
}

/// Checks a cast's hits (each proxy and its entry, all hits taken) against the exact
/// referee over the placed proxies whose layers interact with `layers`: every proxy the
/// exact cast meets is hit once, with an entry never beyond the exact one and within eight
/// `f32` steps of it. Returns the hits the exact cast does not meet, each a near miss
/// within the widening (checked).
pub fn check_cast(
    referee: &Referee,
    (lo, hi, d, max): (Vec3A, Vec3A, Vec3A, f32),
    layers: Layers,
    hits: &[(u32, f32)],
) -> usize {
    let mut seen = BTreeSet::new();
    for &(id, entry) in hits {
        assert!(seen.insert(id), "proxy {id} hit twice");
        assert!(entry >= 0.0, "proxy {id}: entry {entry} below 0");
    }
    let mut extra = 0;
    for (id, p) in referee.proxies.iter().enumerate() {
        let State::Placed(b) = p.state else {
            assert!(!seen.contains(&(id as u32)), "proxy {id} without a box hit");
            continue;
        };
        let got = hits.iter().find(|h| h.0 == id as u32).map(|h| h.1);
        let filtered = !p.layers.interacts_with(layers);
        match (exact_entry(lo, hi, d, max, &b), got) {
            (_, Some(_)) if filtered => panic!("proxy {id}: hit through the layers"),
            (Some(_), None) if filtered => {}
            (Some(e), None) => panic!(
                "proxy {id} {b:?} missed: exact entry {} ({lo:?} {hi:?} along {d:?} to {max})",
                e.to_f64()
            ),
            (Some(e), Some(entry)) => {
                assert!(
                    Frac::of(entry).le(&e),
                    "proxy {id}: entry {entry} beyond the exact {}",
                    e.to_f64()
                );
                // Tight: within eight f32 steps below the exact entry (the f32 test widens
                // each bound by four), or both below 2^-99 (where it widens by 2^-100).
                let floor = (0..8).fold(entry, |x, _| x.next_up());
                let tiny = 2f32.powi(-99);
                assert!(
                    floor == f32::INFINITY || e.le(&Frac::of(floor)) || e.le(&Frac::of(tiny)),
                    "proxy {id}: entry {entry} far below the exact {}",
                    e.to_f64()
                );
            }
            (None, Some(_)) => {
                assert!(
                    near_miss(lo, hi, d, max, &b),
                    "proxy {id} {b:?} hit, far from the exact cast ({lo:?} {hi:?} along {d:?} to {max})"
                );
                extra += 1;
            }
            (None, None) => {}
        }
    }
    extra
}

/// The referee: every proxy, by id.
#[derive(Clone, Debug)]
pub struct Referee {
    pub proxies: Vec<Proxy>,
    pub kind_pairs: KindPairs,
}

impl Referee {
    /// Ids `0..ids`, all absent.
    pub fn new(ids: usize) -> Self {
        let absent = Proxy {
            state: State::Absent,
            kind: BodyKind::Dynamic,
            layers: Layers::ALL,
        };
        Self {
            proxies: vec![absent; ids],
            kind_pairs: KindPairs::default(),
        }
    }

    /// True when proxies `a` and `b` pair now: both placed, boxes overlapping, kinds and
    /// layers admitting.
    pub fn pairs_with(&self, a: usize, b: usize) -> bool {
        let (p, q) = (&self.proxies[a], &self.proxies[b]);
        match (p.state, q.state) {
            (State::Placed(x), State::Placed(y)) => {
                overlap(&x, &y)
                    && kinds_admit(self.kind_pairs, p.kind, q.kind)
                    && p.layers.interacts_with(q.layers)
            }
            _ => false,
        }
    }

    /// Every pair now, by brute force.
    pub fn pairs(&self) -> BTreeSet<(u32, u32)> {
        let n = self.proxies.len();
        let mut set = BTreeSet::new();
        for a in 0..n {
            for b in a + 1..n {
                if self.pairs_with(a, b) {
                    set.insert((a as u32, b as u32));
                }
            }
        }
        set
    }

    /// The placed proxies whose boxes overlap `q` and whose layers interact with `layers`.
    pub fn query(&self, q: &Aabb3, layers: Layers) -> BTreeSet<u32> {
        (0..self.proxies.len())
            .filter(|&i| {
                let p = &self.proxies[i];
                matches!(p.state, State::Placed(b) if overlap(q, &b))
                    && p.layers.interacts_with(layers)
            })
            .map(|i| i as u32)
            .collect()
    }
}

/// A tree and its referee, driven together.
pub struct Check {
    pub tree: DynamicTree,
    pub referee: Referee,
    /// The fat boxes a write reads, by id.
    fat: Vec<Aabb3>,
    /// The pairs at the last report, and the refusals since.
    last: BTreeSet<(u32, u32)>,
    refused: BTreeSet<u32>,
    out: Pairs,
    /// Reports checked, and the begun and ended pairs they held.
    pub reports: usize,
    pub begun: usize,
    pub ended: usize,
    /// Cast hits checked, and those the exact cast does not meet.
    pub hits: usize,
    pub extra_hits: usize,
}

fn same(a: &Aabb3, b: &Aabb3) -> bool {
    let bits = |x: &Aabb3| [x.min.to_array(), x.max.to_array()].map(|v| v.map(f32::to_bits));
    bits(a) == bits(b)
}

impl Check {
    /// An empty tree over ids `0..ids`.
    pub fn new(ids: usize) -> Self {
        Self {
            tree: DynamicTree::new(),
            referee: Referee::new(ids),
            fat: vec![Aabb3::EMPTY; ids],
            last: BTreeSet::new(),
            refused: BTreeSet::new(),
            out: Pairs::with_ended(),
            reports: 0,
            begun: 0,
            ended: 0,
            hits: 0,
            extra_hits: 0,
        }
    }

    /// Applies `op` to both and checks every answer; with `full`, then checks the whole
    /// state (each proxy, the count and every pair).
    pub fn apply(&mut self, op: &Op, full: bool) {
        let r = &mut self.referee;
        match *op {
            Op::Insert {
                id,
                fat,
                kind,
                layers,
            } => {
                let got = self.tree.insert_with(id, fat, kind, layers);
                let p = &mut r.proxies[id as usize];
                if !accepted(&fat) {
                    assert_eq!(got, Err(BroadphaseError::InvalidBox { id }));
                } else if p.state != State::Absent {
                    assert_eq!(got, Err(BroadphaseError::Duplicate { id }));
                } else {
                    assert_eq!(got, Ok(()));
                    *p = Proxy {
                        state: State::Placed(fat),
                        kind,
                        layers,
                    };
                }
            }
            Op::Remove(id) => {
                let p = &mut r.proxies[id as usize];
                assert_eq!(self.tree.remove(id), p.state != State::Absent);
                p.state = State::Absent;
            }
            Op::Write(ref moved) => {
                let ids: Vec<u32> = moved.iter().map(|m| m.0).collect();
                for &(id, b) in moved {
                    self.fat[id as usize] = b;
                }
                self.tree
                    .write(&ids, &self.fat[..])
                    .expect("ascending ids within the boxes");
                for &(id, b) in moved {
                    let p = &mut r.proxies[id as usize];
                    if p.state == State::Absent {
                        continue;
                    }
                    if accepted(&b) {
                        p.state = State::Placed(b);
                    } else {
                        p.state = State::Parked;
                        self.refused.insert(id);
                    }
                }
            }
            Op::Move(id, fat) => {
                let p = &mut r.proxies[id as usize];
                let got = self.tree.move_proxy(id, fat);
                if p.state == State::Absent {
                    assert_eq!(got, Err(BroadphaseError::UnknownId { id }));
                } else if !accepted(&fat) {
                    assert_eq!(got, Err(BroadphaseError::InvalidBox { id }));
                } else {
                    assert_eq!(got, Ok(()));
                    p.state = State::Placed(fat);
                }
            }
            Op::SetKind(id, kind) => {
                let p = &mut r.proxies[id as usize];
                let got = self.tree.set_kind(id, kind);
                if p.state == State::Absent {
                    assert_eq!(got, Err(BroadphaseError::UnknownId { id }));
                } else {
                    assert_eq!(got, Ok(()));
                    p.kind = kind;
                }
            }
            Op::SetLayers(id, layers) => {
                let p = &mut r.proxies[id as usize];
                let got = self.tree.set_layers(id, layers);
                if p.state == State::Absent {
                    assert_eq!(got, Err(BroadphaseError::UnknownId { id }));
                } else {
                    assert_eq!(got, Ok(()));
                    p.layers = layers;
                }
            }
            Op::SetKindPairs(k) => {
                self.tree.set_kind_pairs(k);
                r.kind_pairs = k;
                assert_eq!(self.tree.kind_pairs(), k);
            }
            Op::Query(q, layers) => {
                let mut got = Vec::new();
                let result = self.tree.query(&q, layers, |id| got.push(id));
                if !q.min.cmple(q.max).all() {
                    assert_eq!(result, Err(BroadphaseError::InvalidQuery), "query {q:?}");
                    assert!(got.is_empty());
                } else {
                    assert_eq!(result, Ok(()));
                    let set: BTreeSet<u32> = got.iter().copied().collect();
                    assert_eq!(set.len(), got.len(), "a proxy found twice");
                    assert_eq!(set, r.query(&q, layers), "query {q:?} {layers:?}");
                }
            }
            Op::QueryPoint(p, layers) => {
                let mut got = BTreeSet::new();
                let result = self.tree.query_point(p, layers, |id| {
                    got.insert(id);
                });
                if p.is_nan() {
                    assert_eq!(result, Err(BroadphaseError::InvalidQuery));
                    assert!(got.is_empty());
                } else {
                    assert_eq!(result, Ok(()));
                    assert_eq!(got, r.query(&Aabb3::new(p, p), layers), "point {p:?}");
                }
            }
            Op::CastRay(ray, layers) => {
                let mut hits = Vec::new();
                let result = self.tree.cast_ray(&ray, layers, |id, entry| {
                    hits.push((id, entry));
                    CastControl::Continue
                });
                if ray.is_valid() {
                    assert_eq!(result, Ok(()));
                    let cast = (ray.origin, ray.origin, ray.direction, ray.max);
                    self.extra_hits += check_cast(r, cast, layers, &hits);
                    self.hits += hits.len();
                } else {
                    assert_eq!(result, Err(BroadphaseError::InvalidCast), "ray {ray:?}");
                    assert!(hits.is_empty());
                }
            }
            Op::CastBox(b, motion, max, layers) => {
                let mut hits = Vec::new();
                let result = self.tree.cast_box(&b, motion, max, layers, |id, entry| {
                    hits.push((id, entry));
                    CastControl::Continue
                });
                if accepted(&b) && motion.is_finite() && max >= 0.0 {
                    assert_eq!(result, Ok(()));
                    self.extra_hits += check_cast(r, (b.min, b.max, motion, max), layers, &hits);
                    self.hits += hits.len();
                } else {
                    assert_eq!(result, Err(BroadphaseError::InvalidCast), "box {b:?}");
                    assert!(hits.is_empty());
                }
            }
            Op::Rebuild => self.tree.rebuild(),
            Op::Maintain(frames) => {
                self.tree.set_rebuild_after(0.0);
                self.tree.set_rebuild_frames(frames);
                self.tree.maintain();
            }
            Op::Report => self.report(),
        }
        if full {
            self.check_state();
        }
    }

    /// A report, checked: begun = now \ last, ended = last \ now, the refusals since.
    fn report(&mut self) {
        self.tree.report(&mut self.out);
        let now = self.referee.pairs();
        let begun: BTreeSet<_> = now.difference(&self.last).copied().collect();
        let ended: BTreeSet<_> = self.last.difference(&now).copied().collect();
        let as_set = |pairs: &[(u32, u32)], what: &str| {
            let set: BTreeSet<_> = pairs.iter().copied().collect();
            assert_eq!(set.len(), pairs.len(), "a {what} pair twice");
            assert!(
                pairs.iter().all(|(a, b)| a < b),
                "a {what} pair out of order"
            );
            set
        };
        assert_eq!(as_set(&self.out.begun, "begun"), begun, "begun pairs");
        assert_eq!(as_set(&self.out.ended, "ended"), ended, "ended pairs");
        let refused: BTreeSet<u32> = self.out.refused.iter().copied().collect();
        assert_eq!(refused, self.refused, "refused ids");
        self.refused.clear();
        self.reports += 1;
        self.begun += begun.len();
        self.ended += ended.len();
        self.last = now;
    }

    /// Every proxy's state, kind and layers, the count and every pair, against the referee.
    pub fn check_state(&self) {
        let r = &self.referee;
        for (id, p) in r.proxies.iter().enumerate() {
            let id = id as u32;
            let tree = &self.tree;
            assert_eq!(tree.contains(id), p.state != State::Absent, "proxy {id}");
            assert_eq!(tree.is_parked(id), p.state == State::Parked, "proxy {id}");
            match (p.state, tree.get(id)) {
                (State::Placed(b), Some(g)) => assert!(same(&b, &g), "proxy {id}: box"),
                (State::Placed(_), None) => panic!("proxy {id} lost"),
                (_, got) => assert!(got.is_none(), "proxy {id}: a box it should not have"),
            }
            if p.state != State::Absent {
                assert_eq!(tree.kind(id), Some(p.kind), "proxy {id}: kind");
                assert_eq!(tree.layers(id), Some(p.layers), "proxy {id}: layers");
            } else {
                assert_eq!((tree.kind(id), tree.layers(id)), (None, None));
            }
        }
        let count = r
            .proxies
            .iter()
            .filter(|p| p.state != State::Absent)
            .count();
        assert_eq!(self.tree.len(), count);
        let all: BTreeSet<_> = self.tree.overlapping_pairs().into_iter().collect();
        assert_eq!(all, r.pairs(), "all overlapping pairs");
    }
}

/// A float of any bits from four bytes.
fn any_float(byte: &mut impl FnMut() -> u8) -> f32 {
    f32::from_bits(u32::from_le_bytes([byte(), byte(), byte(), byte()]))
}

/// A box: mostly small integer corners (so that boxes overlap and touch), sometimes faces
/// of any bits (NaN, ±∞, ±MAX, subnormals, inverted).
pub fn any_box(byte: &mut impl FnMut() -> u8) -> Aabb3 {
    if byte() < 220 {
        let mut corner = || f32::from(byte() % 8);
        let min = Vec3A::new(corner(), corner(), corner());
        let mut size = || f32::from(byte() % 4);
        let size = Vec3A::new(size(), size(), size());
        Aabb3::new(min, min + size)
    } else {
        let mut v = || Vec3A::new(any_float(byte), any_float(byte), any_float(byte));
        Aabb3::new(v(), v())
    }
}

/// Layers of four layers, mostly; sometimes of any bits.
fn any_layers(byte: &mut impl FnMut() -> u8) -> Layers {
    match byte() % 8 {
        0 => Layers::ALL,
        1 => Layers::new(u32::from_le_bytes([byte(), byte(), 0, 0]), u32::MAX),
        _ => Layers::new(1 << (byte() % 4), u32::from(byte() % 16)),
    }
}

/// A point: mostly on the small integer grid of the boxes (on their faces and corners),
/// sometimes a half step off it, sometimes of any bits.
fn any_point(byte: &mut impl FnMut() -> u8) -> Vec3A {
    match byte() % 8 {
        0 => Vec3A::new(any_float(byte), any_float(byte), any_float(byte)),
        1 => Vec3A::new(
            f32::from(byte() % 20) * 0.5 - 1.0,
            f32::from(byte() % 20) * 0.5 - 1.0,
            f32::from(byte() % 20) * 0.5 - 1.0,
        ),
        _ => Vec3A::new(
            f32::from(byte() % 10) - 1.0,
            f32::from(byte() % 10) - 1.0,
            f32::from(byte() % 10) - 1.0,
        ),
    }
}

/// A direction: mostly small integers (axis-parallel, diagonal, through corners, with
/// zero components), sometimes tiny or huge components, sometimes of any bits.
fn any_direction(byte: &mut impl FnMut() -> u8) -> Vec3A {
    let mut c = || match byte() % 16 {
        0..=3 => 0.0,
        4 => -0.0,
        5 => 1e-30 * f32::from(byte()),
        6 => 1e30 * (f32::from(byte()) - 128.0),
        7 => any_float(byte),
        _ => f32::from(byte() % 7) - 3.0,
    };
    Vec3A::new(c(), c(), c())
}

/// A cast's length: mostly small, sometimes none or endless, sometimes of any bits.
fn any_length(byte: &mut impl FnMut() -> u8) -> f32 {
    match byte() % 8 {
        0 => f32::INFINITY,
        1 => 0.0,
        2 => any_float(byte),
        _ => f32::from(byte() % 16) * 0.5,
    }
}

fn any_kind(byte: &mut impl FnMut() -> u8) -> BodyKind {
    match byte() % 4 {
        0 => BodyKind::Static,
        1 => BodyKind::Kinematic,
        _ => BodyKind::Dynamic,
    }
}

impl Op {
    /// An operation on ids `0..ids` (at most 40) from bytes: writes most often.
    pub fn decode(byte: &mut impl FnMut() -> u8, ids: u32) -> Op {
        let id = |byte: &mut dyn FnMut() -> u8| u32::from(byte()) % ids;
        match byte() % 18 {
            0 | 1 => {
                let id = id(byte);
                let fat = any_box(byte);
                let (kind, layers) = (any_kind(byte), any_layers(byte));
                Op::Insert {
                    id,
                    fat,
                    kind,
                    layers,
                }
            }
            2 => Op::Remove(id(byte)),
            3 => {
                let id = id(byte);
                Op::Move(id, any_box(byte))
            }
            4..=6 => {
                let mask = u64::from_le_bytes([byte(), byte(), byte(), byte(), byte(), 0, 0, 0]);
                let moved = (0..ids)
                    .filter(|&i| mask >> i & 1 != 0)
                    .map(|i| (i, any_box(byte)))
                    .collect();
                Op::Write(moved)
            }
            7 => {
                let id = id(byte);
                Op::SetKind(id, any_kind(byte))
            }
            8 => {
                let id = id(byte);
                Op::SetLayers(id, any_layers(byte))
            }
            9 => {
                let b = byte();
                Op::SetKindPairs(KindPairs {
                    kinematic_kinematic: b & 1 != 0,
                    kinematic_static: b & 2 != 0,
                })
            }
            10 => Op::Query(any_box(byte), any_layers(byte)),
            11 => {
                let b = any_box(byte);
                Op::QueryPoint(b.min, any_layers(byte))
            }
            12 => match byte() % 4 {
                0 => Op::Rebuild,
                b => Op::Maintain(u32::from(b) * 3),
            },
            13 => {
                let (origin, direction) = (any_point(byte), any_direction(byte));
                Op::CastRay(
                    Ray::new(origin, direction, any_length(byte)),
                    any_layers(byte),
                )
            }
            14 => {
                let b = any_box(byte);
                let motion = any_direction(byte);
                Op::CastBox(b, motion, any_length(byte), any_layers(byte))
            }
            _ => Op::Report,
        }
    }
}
