//! Each proxy's partners: the proxies whose fat boxes overlapped its own at the last report.
//!
//! A pair that ends had both boxes overlap at the last report, so it is among the partners
//! of either proxy: a report finds a changed proxy's ended pairs by reading its own
//! partners, in time linear in them, whatever else moved (the sweep over the changed
//! proxies' old boxes it replaces grew with the square of the movers in a dense scene: each
//! box's interval on one axis overlaps a slab of others).
//!
//! The lists are kept in chunks of seven ids, 32 bytes, in one pool, so that a proxy with
//! no partner costs one `u32` and a proxy with a few reads one half cache line; freed chunks
//! are reused.

use alloc::collections::TryReserveError;
use alloc::vec::Vec;

/// An empty place in a chunk, or no chunk.
const NONE: u32 = u32::MAX;
/// The ids a chunk holds.
const IDS: usize = 7;

/// Up to seven partners, and the next chunk of the same proxy's list.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct Chunk {
    ids: [u32; IDS],
    next: u32,
}

/// Every proxy's list of partners (see the [module docs](self)).
#[derive(Clone, Debug)]
pub(super) struct Partners {
    /// Per id: its first chunk, or [`NONE`].
    head: Vec<u32>,
    chunks: Vec<Chunk>,
    /// The first free chunk (the free ones are linked through `next`), or [`NONE`].
    free: u32,
}

impl Default for Partners {
    fn default() -> Self {
        Self {
            head: Vec::new(),
            chunks: Vec::new(),
            free: NONE,
        }
    }
}

impl Partners {
    /// Room for ids below `len` (their lists empty); an error leaves the lists as they were.
    pub(super) fn grow(&mut self, len: usize) -> Result<(), TryReserveError> {
        if self.head.len() < len {
            self.head.try_reserve_exact(len - self.head.len())?;
            self.head.resize(len, NONE);
        }
        Ok(())
    }

    /// True when `id` has no partner.
    #[inline(always)]
    pub(super) fn is_alone(&self, id: u32) -> bool {
        self.head[id as usize] == NONE
    }

    /// `id`'s partners, in a deterministic order (that of the adds and removes so far).
    #[inline(always)]
    pub(super) fn of(&self, id: u32) -> impl Iterator<Item = u32> + '_ {
        let mut chunk = self.head[id as usize];
        let mut k = IDS;
        core::iter::from_fn(move || {
            loop {
                if k == IDS {
                    if chunk == NONE {
                        return None;
                    }
                    k = 0;
                } else {
                    let c = &self.chunks[chunk as usize];
                    let id = c.ids[k];
                    k += 1;
                    if k == IDS {
                        chunk = c.next;
                    }
                    if id != NONE {
                        return Some(id);
                    }
                }
            }
        })
    }

    /// True when `a` and `b` are partners: a look through `a`'s list.
    #[inline(always)]
    pub(super) fn contains(&self, a: u32, b: u32) -> bool {
        self.of(a).any(|x| x == b)
    }

    /// Makes `a` and `b` partners (they must not be already).
    pub(super) fn add(&mut self, a: u32, b: u32) {
        self.link(a, b);
        self.link(b, a);
    }

    /// Makes `a` and `b` partners no more (they must be now).
    pub(super) fn remove(&mut self, a: u32, b: u32) {
        self.unlink(a, b);
        self.unlink(b, a);
    }

    /// Puts `other` in the first empty place of `id`'s list, or in a new chunk at its front.
    fn link(&mut self, id: u32, other: u32) {
        let mut chunk = self.head[id as usize];
        while chunk != NONE {
            let c = &mut self.chunks[chunk as usize];
            if let Some(place) = c.ids.iter_mut().find(|x| **x == NONE) {
                *place = other;
                return;
            }
            chunk = c.next;
        }
        let mut ids = [NONE; IDS];
        ids[0] = other;
        let fresh = Chunk {
            ids,
            next: self.head[id as usize],
        };
        let at = if self.free == NONE {
            self.chunks.push(fresh);
            self.chunks.len() as u32 - 1
        } else {
            let at = self.free;
            self.free = self.chunks[at as usize].next;
            self.chunks[at as usize] = fresh;
            at
        };
        self.head[id as usize] = at;
    }

    /// Takes `other` out of `id`'s list, and frees its chunk if that leaves it empty.
    fn unlink(&mut self, id: u32, other: u32) {
        let (mut chunk, mut before) = (self.head[id as usize], NONE);
        while chunk != NONE {
            let c = &mut self.chunks[chunk as usize];
            if let Some(place) = c.ids.iter_mut().find(|x| **x == other) {
                *place = NONE;
                if c.ids.iter().all(|&x| x == NONE) {
                    let next = c.next;
                    c.next = self.free;
                    self.free = chunk;
                    match before {
                        NONE => self.head[id as usize] = next,
                        b => self.chunks[b as usize].next = next,
                    }
                }
                return;
            }
            (before, chunk) = (chunk, c.next);
        }
        debug_assert!(false, "{other} is not a partner of {id}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::collections::BTreeSet;

    /// Random adds and removes against a set of pairs: every list holds exactly its
    /// proxy's pairs, and freed chunks are reused.
    #[test]
    fn lists_follow_a_set_of_pairs() {
        let mut partners = Partners::default();
        partners.grow(40).unwrap();
        let mut set = BTreeSet::new();
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |n: u32| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % u64::from(n)) as u32
        };
        for step in 0..20_000 {
            let (a, b) = (next(40), next(40));
            if a == b {
                continue;
            }
            let pair = (a.min(b), a.max(b));
            if set.remove(&pair) {
                partners.remove(a, b);
            } else {
                set.insert(pair);
                partners.add(a, b);
            }
            if step % 97 == 0 {
                for id in 0..40 {
                    let mut got: Vec<u32> = partners.of(id).collect();
                    got.sort_unstable();
                    let want: Vec<u32> = set
                        .iter()
                        .filter_map(|&(x, y)| match id {
                            _ if x == id => Some(y),
                            _ if y == id => Some(x),
                            _ => None,
                        })
                        .collect();
                    assert_eq!(got, want, "step {step}, id {id}");
                    assert_eq!(partners.is_alone(id), want.is_empty());
                }
            }
        }
        // At most 39 partners each: 6 chunks a proxy at most, 240 in all.
        assert!(partners.chunks.len() <= 240, "{}", partners.chunks.len());
    }
}
