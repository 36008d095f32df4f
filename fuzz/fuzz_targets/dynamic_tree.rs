//! The broadphase's dynamic tree against a brute-force reference, over any sequence of
//! inserts, removes, moves (`write`), reports, queries, rebuilds and upkeep (`maintain`, its
//! rebuilds spread over several calls),
//! with any boxes: small integer boxes that overlap often, and faces of any bits (NaN, ±∞, ±MAX,
//! subnormals). After every operation the tree holds what the reference holds (placed,
//! parked or absent, and each box bit for bit); every query finds the placed boxes it
//! overlaps; every report's begun and
//! ended pairs are exactly the differences of the brute-force pair sets since the last
//! report, and its refused ids are the moves whose boxes the reference refuses. Nothing
//! panics.
#![no_main]

use std::collections::BTreeSet;

use bvkit::Aabb3;
use bvkit::broadphase::{BroadphaseError, DynamicTree, Pairs};
use bvkit_fuzz::Floats;
use glam::Vec3A;
use libfuzzer_sys::fuzz_target;

const IDS: usize = 40;

/// What the reference knows of a proxy.
#[derive(Clone, Copy, PartialEq)]
enum Proxy {
    Absent,
    Parked,
    Placed(Aabb3),
}

fn accepted(b: &Aabb3) -> bool {
    b.min.is_finite() && b.max.is_finite() && b.min.cmple(b.max).all()
}

fn overlap(a: &Aabb3, b: &Aabb3) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}

fn pairs(proxies: &[Proxy]) -> BTreeSet<(u32, u32)> {
    let mut set = BTreeSet::new();
    for i in 0..IDS {
        for j in i + 1..IDS {
            if let (Proxy::Placed(a), Proxy::Placed(b)) = (proxies[i], proxies[j])
                && overlap(&a, &b)
            {
                set.insert((i as u32, j as u32));
            }
        }
    }
    set
}

fn same(a: &Aabb3, b: &Aabb3) -> bool {
    let bits = |x: &Aabb3| [x.min.to_array(), x.max.to_array()].map(|v| v.map(f32::to_bits));
    bits(a) == bits(b)
}

/// A box: mostly small integer corners (so that boxes overlap and touch), sometimes faces
/// of any bits.
fn boxed(f: &mut Floats) -> Aabb3 {
    if f.byte() < 220 {
        let mut corner = || f32::from(f.byte() % 8);
        let min = Vec3A::new(corner(), corner(), corner());
        let mut size = || f32::from(f.byte() % 4);
        let size = Vec3A::new(size(), size(), size());
        Aabb3::new(min, min + size)
    } else {
        Aabb3::new(f.vec3a(), f.vec3a())
    }
}

/// Ids from a bitmask of five bytes, ascending.
fn ids(f: &mut Floats) -> Vec<u32> {
    let mask = u64::from_le_bytes([f.byte(), f.byte(), f.byte(), f.byte(), f.byte(), 0, 0, 0]);
    (0..IDS as u32).filter(|&i| mask >> i & 1 != 0).collect()
}

fuzz_target!(|data: &[u8]| {
    let mut f = Floats::new(data);
    let mut tree = DynamicTree::new();
    let mut proxies = [Proxy::Absent; IDS];
    let mut fat = vec![Aabb3::EMPTY; IDS];
    let mut last = BTreeSet::new();
    let mut refused: BTreeSet<u32> = BTreeSet::new();
    let mut out = Pairs::with_ended();
    for step in 0..64 {
        if f.byte() == 0 && step > 0 {
            break;
        }
        let op = f.byte() % 8;
        match op {
            0 => {
                let id = u32::from(f.byte()) % IDS as u32;
                let b = boxed(&mut f);
                let got = tree.insert(id, b);
                if !accepted(&b) {
                    assert_eq!(got, Err(BroadphaseError::InvalidBox { id }));
                } else if proxies[id as usize] != Proxy::Absent {
                    assert_eq!(got, Err(BroadphaseError::Duplicate { id }));
                } else {
                    assert_eq!(got, Ok(()));
                    proxies[id as usize] = Proxy::Placed(b);
                }
            }
            1 => {
                let id = u32::from(f.byte()) % IDS as u32;
                let was = proxies[id as usize] != Proxy::Absent;
                assert_eq!(tree.remove(id), was);
                proxies[id as usize] = Proxy::Absent;
            }
            2 | 7 => {
                let moved = ids(&mut f);
                for &id in &moved {
                    fat[id as usize] = boxed(&mut f);
                }
                tree.write(&moved, &fat[..])
                    .expect("sorted ids within the boxes");
                for &id in &moved {
                    let p = &mut proxies[id as usize];
                    if *p == Proxy::Absent {
                        continue;
                    }
                    let b = fat[id as usize];
                    if accepted(&b) {
                        *p = Proxy::Placed(b);
                    } else {
                        *p = Proxy::Parked;
                        refused.insert(id);
                    }
                }
            }
            3 | 4 => {
                // A query with any box: the placed proxies it overlaps (none for a box
                // with a NaN face).
                let q = boxed(&mut f);
                let mut got = BTreeSet::new();
                tree.query(&q, |id| {
                    got.insert(id);
                });
                let expected: BTreeSet<u32> = (0..IDS as u32)
                    .filter(|&i| matches!(proxies[i as usize], Proxy::Placed(b) if overlap(&q, &b)))
                    .collect();
                assert_eq!(got, expected, "query {q:?}");
            }
            5 => {
                let b = f.byte();
                if b % 2 == 0 {
                    tree.rebuild();
                } else {
                    // The upkeep: a rebuild once anything moved since the last build, spread
                    // over up to eight calls, so that other operations meet it under way.
                    tree.set_rebuild_after(0.0);
                    tree.set_rebuild_frames(u32::from(b / 2 % 8) + 1);
                    tree.maintain();
                }
            }
            _ => {}
        }
        if op == 6 || op == 7 {
            tree.report(&mut out);
            let now = pairs(&proxies);
            let begun: BTreeSet<_> = now.difference(&last).copied().collect();
            let ended: BTreeSet<_> = last.difference(&now).copied().collect();
            let got_begun: BTreeSet<_> = out.begun.iter().copied().collect();
            let got_ended: BTreeSet<_> = out.ended.iter().copied().collect();
            assert_eq!(got_begun.len(), out.begun.len(), "a begun pair twice");
            assert_eq!(got_ended.len(), out.ended.len(), "an ended pair twice");
            assert_eq!(got_begun, begun, "begun pairs");
            assert_eq!(got_ended, ended, "ended pairs");
            let got_refused: BTreeSet<u32> = out.refused.iter().copied().collect();
            assert_eq!(got_refused, refused, "refused ids");
            refused.clear();
            last = now;
        }
        for id in 0..IDS as u32 {
            let p = proxies[id as usize];
            assert_eq!(tree.contains(id), p != Proxy::Absent);
            assert_eq!(tree.is_parked(id), p == Proxy::Parked);
            match (p, tree.get(id)) {
                (Proxy::Placed(b), Some(g)) => assert!(same(&b, &g), "proxy {id}: box"),
                (Proxy::Placed(_), None) => panic!("proxy {id} lost"),
                (_, got) => assert!(got.is_none(), "proxy {id}: a box it should not have"),
            }
        }
        let count = proxies.iter().filter(|p| **p != Proxy::Absent).count();
        assert_eq!(tree.len(), count);
        let all: BTreeSet<_> = tree.overlapping_pairs().into_iter().collect();
        assert_eq!(all, pairs(&proxies), "all overlapping pairs");
    }
});
