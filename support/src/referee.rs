//! The brute-force referee of the broadphase tree: a list of proxies (state, kind, layers)
//! and every pair and query answer found by checking all of them, and a driver that applies
//! the same operation to a `DynamicTree` and to the referee and checks that they agree.
//! The tests drive it from random sequences, the fuzz target from bytes.

use std::collections::BTreeSet;

use bvkit::Aabb3;
use bvkit::broadphase::{BodyKind, BroadphaseError, DynamicTree, KindPairs, Layers, Pairs};
use glam::Vec3A;

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
    SetKind(u32, BodyKind),
    SetLayers(u32, Layers),
    SetKindPairs(KindPairs),
    Query(Aabb3, Layers),
    QueryPoint(Vec3A, Layers),
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

fn any_kind(byte: &mut impl FnMut() -> u8) -> BodyKind {
    match byte() % 4 {
        0 => BodyKind::Static,
        1 => BodyKind::Kinematic,
        _ => BodyKind::Dynamic,
    }
}

impl Op {
    /// An operation on ids `0..ids` (at most 40) from bytes: writes and reports most often.
    pub fn decode(byte: &mut impl FnMut() -> u8, ids: u32) -> Op {
        let id = |byte: &mut dyn FnMut() -> u8| u32::from(byte()) % ids;
        match byte() % 16 {
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
            3..=6 => {
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
            _ => Op::Report,
        }
    }
}
