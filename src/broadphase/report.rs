//! A frame's second half: the pairs that began and ended since the last report.
//!
//! The pairs with a changed proxy are searched in the moving hierarchy and between it and
//! the fixed one (two static proxies never pair): once a sixteenth of the moving proxies or
//! more changed, by a traversal of the moving hierarchy against itself and one against the
//! fixed hierarchy, restricted to the changed proxies' paths; below that, by a query of
//! each changed proxy's box. The ended pairs are read from each changed proxy's partners.

use super::hierarchy::{self, Hierarchy, overlap};
use super::partners::Partners;
use super::{Change, DynamicTree, KindPairs, Pairs, Place, Proxy, TRAVERSE_FROM, Tier};
use crate::aabb::Aabb3;
use alloc::vec::Vec;
use core::mem::take;

impl DynamicTree {
    /// The pairs' half of a frame: `pairs` receives the pairs that began (and ended) since
    /// the last report, searched from the proxies written, inserted, removed, parked or
    /// refiltered since, and the proxies refused since.
    pub fn report(&mut self, pairs: &mut Pairs) {
        self.report_on(pairs, false);
    }

    /// [`DynamicTree::report`] on the rayon pool (feature `rayon`): the changed proxies'
    /// searches in ordered parts, whose pairs are joined in part order, so that `pairs` is
    /// the same, in the same order, as [`DynamicTree::report`] gives, on any number of
    /// threads. Parts are at least 512 changed proxies, so a small report runs on the
    /// calling thread.
    #[cfg(feature = "rayon")]
    pub fn report_par(&mut self, pairs: &mut Pairs) {
        self.report_on(pairs, true);
    }

    /// The report, its searches on the rayon pool when `parallel` (and the feature) say so.
    pub(super) fn report_on(&mut self, pairs: &mut Pairs, parallel: bool) {
        pairs.clear();
        core::mem::swap(&mut pairs.refused, &mut self.refused);
        let mut changes = take(&mut self.pending);
        // Once a sixteenth of the moving proxies or more changed, one traversal of each
        // hierarchy pair, restricted to the changed proxies' paths, shares the descents
        // that their queries would each repeat; it needs those paths marked, in any order.
        // The writes marked theirs, unless proxies moved between slots since.
        let traverse = changes.len() * TRAVERSE_FROM >= self.tier_len[Tier::Moving as usize];
        let mut order = take(&mut self.order);
        order.clear();
        if traverse {
            if !self.paths_marked {
                self.moving.clear_marks();
                self.fixed.clear_marks();
                for c in &changes {
                    match self.at[c.id() as usize].slot() {
                        Some((Tier::Moving, slot)) => self.moving.mark_changed(slot),
                        Some((Tier::Fixed, slot)) => self.fixed.mark_changed(slot),
                        None => {}
                    }
                }
            }
        } else {
            // Queries in place order: neighbours in the tree share their paths in the
            // caches; the moving proxies' places come first, then the fixed ones'. The
            // absent and parked proxies (the largest places) come last, and have no box to
            // query with: they are cut off.
            for (i, c) in changes.iter().enumerate() {
                order.push(u64::from(self.at[c.id() as usize].0) << 32 | i as u64);
            }
            order.sort_unstable();
            let queried = order.partition_point(|&key| place_of(key).is_placed());
            order.truncate(queried);
        }
        let (mut tasks, mut cross, mut stack) = (
            take(&mut self.tasks),
            take(&mut self.cross),
            take(&mut self.stack),
        );
        let view = View {
            moving: &self.moving,
            fixed: &self.fixed,
            at: &self.at,
            mark: &self.mark,
            proxies: &self.proxies,
            changes: &changes,
            partners: &self.partners,
            kind_pairs: self.kind_pairs,
            filtered: self.unplain != 0 || !self.common.interacts_with(self.common),
            refiltered: self.refiltered,
        };
        let (begun, ended) = (&mut pairs.begun, &mut pairs.ended);
        const PART: usize = 64 * hierarchy::WIDTH;
        if traverse {
            let (moving, fixed) = (view.moving, view.fixed);
            moving.changed_frontier(&mut tasks, |a, ba, b, bb| view.begun(a, ba, b, bb, begun));
            moving.changed_frontier_with(fixed, &mut cross, |a, ba, b, bb| {
                view.begun(a, ba, b, bb, begun);
            });
            // The traversals' tasks in parts of eight.
            for (tasks, other) in [(&tasks, moving), (&cross, fixed)] {
                in_parts(
                    tasks,
                    8,
                    parallel,
                    &mut stack,
                    begun,
                    |part, stack, found| {
                        crate::simd::plain(
                            #[inline(always)]
                            || {
                                moving.changed_pairs_from(other, part, stack, |a, ba, b, bb| {
                                    view.begun(a, ba, b, bb, found);
                                });
                            },
                        );
                    },
                );
            }
        } else {
            // Every changed proxy against the moving hierarchy, then the moving ones against
            // the fixed hierarchy; whole groups of queries per part, so that each part forms
            // the serial search's groups (whose hits come in the order of their shared
            // descent).
            let moving_end = order.partition_point(|&key| place_of(key).0 & Place::FIXED == 0);
            for (order, target) in [
                (&order[..], view.moving),
                (&order[..moving_end], view.fixed),
            ] {
                in_parts(
                    order,
                    PART,
                    parallel,
                    &mut stack,
                    begun,
                    |part, stack, found| {
                        crate::simd::plain(
                            #[inline(always)]
                            || search(&view, part, target, stack, found),
                        );
                    },
                );
            }
        }
        // The ended pairs are found in every report, wanted or not: the partners must
        // follow every change.
        in_parts(
            &changes,
            PART,
            parallel,
            &mut stack,
            ended,
            |part, _, found| {
                search_ended(&view, part, found);
            },
        );
        self.moving.clear_marks();
        self.fixed.clear_marks();
        self.paths_marked = true;
        self.refiltered = false;
        (self.tasks, self.cross, self.stack) = (tasks, cross, stack);
        for &(a, b) in ended.iter() {
            self.partners.remove(a, b);
        }
        for &(a, b) in begun.iter() {
            self.partners.add(a, b);
        }
        if !pairs.ended_wanted {
            ended.clear();
        }
        for c in &changes {
            self.mark[c.id() as usize] = 0;
        }
        changes.clear();
        (self.pending, self.order) = (changes, order);
    }
}

/// The place in a key of the query order (a change's place, then its index).
#[inline(always)]
fn place_of(key: u64) -> Place {
    Place((key >> 32) as u32)
}

/// Runs `job` over `items` into `out`: on this thread, or with `parallel` (and the feature
/// `rayon`) in ordered parts of `part` items on the rayon pool, their outputs joined in part
/// order. The output is the same either way, since each job below gives over a run of
/// whole parts the outputs of its parts one after the other.
#[inline(always)]
fn in_parts<T: Sync>(
    items: &[T],
    part: usize,
    parallel: bool,
    stack: &mut Vec<u64>,
    out: &mut Vec<(u32, u32)>,
    job: impl Fn(&[T], &mut Vec<u64>, &mut Vec<(u32, u32)>) + Sync,
) {
    #[cfg(feature = "rayon")]
    if parallel && items.len() > part {
        use rayon::prelude::*;
        let found: Vec<Vec<(u32, u32)>> = items
            .par_chunks(part)
            .map(|part| {
                let (mut stack, mut found) = (Vec::new(), Vec::new());
                job(part, &mut stack, &mut found);
                found
            })
            .collect();
        out.extend(found.into_iter().flatten());
        return;
    }
    let _ = (part, parallel);
    job(items, stack, out);
}

/// What a report reads: the hierarchies, the proxies' places, kinds, layers and change
/// marks, the changes and the partners.
struct View<'a> {
    moving: &'a Hierarchy,
    fixed: &'a Hierarchy,
    at: &'a [Place],
    mark: &'a [u32],
    proxies: &'a [Proxy],
    changes: &'a [Change],
    partners: &'a Partners,
    kind_pairs: KindPairs,
    /// Some proxy is not dynamic in every layer: every pair takes the check of its kinds
    /// and layers.
    filtered: bool,
    /// Some proxy's kind or layers changed since the last report.
    refiltered: bool,
}

impl View<'_> {
    /// The box at place `at` (the empty box for an absent or parked proxy).
    #[inline(always)]
    fn at(&self, at: Place) -> Aabb3 {
        match at.slot() {
            None => Aabb3::EMPTY,
            Some((Tier::Moving, slot)) => self.moving.get(slot),
            Some((Tier::Fixed, slot)) => self.fixed.get(slot),
        }
    }

    /// Proxy `id`'s box now, or the empty box.
    #[inline(always)]
    fn now(&self, id: u32) -> Aabb3 {
        self.at(self.at[id as usize])
    }

    /// Asks for the cache lines of the node at place `at`, or of its parent.
    #[inline(always)]
    fn prefetch(&self, at: Place, parent: bool) {
        let (h, slot) = match at.slot() {
            None => return,
            Some((Tier::Moving, slot)) => (self.moving, slot),
            Some((Tier::Fixed, slot)) => (self.fixed, slot),
        };
        if parent {
            h.prefetch_parent(slot);
        } else {
            h.prefetch(slot);
        }
    }

    /// True when the kinds and layers of proxies `a` and `b` admit their pair.
    #[inline(always)]
    fn admits(&self, a: u32, b: u32) -> bool {
        let (pa, pb) = (self.proxies[a as usize], self.proxies[b as usize]);
        self.kind_pairs.admit(pa.kind, pb.kind) && pa.layers.interacts_with(pb.layers)
    }

    /// Proxy `id`'s change, if it changed since the last report.
    #[inline(always)]
    fn change(&self, id: u32) -> Option<&Change> {
        match self.mark[id as usize] {
            0 => None,
            m => Some(&self.changes[m as usize - 1]),
        }
    }

    /// True when the pair of `a` and `b` was reported at the last report, given the boxes
    /// each had then, when neither proxy's kind or layers changed since: then it was
    /// admitted, as it is now, and was reported where the boxes overlapped. Otherwise its
    /// partners say.
    #[inline(always)]
    fn was(&self, a: u32, then_a: &Aabb3, b: u32, then_b: &Aabb3) -> bool {
        let refiltered = |id| self.change(id).is_some_and(Change::refiltered);
        if self.refiltered && (refiltered(a) || refiltered(b)) {
            self.partners.contains(a, b)
        } else {
            overlap(then_a, then_b)
        }
    }

    /// Adds the pair of proxies `a` and `b` (with their boxes now, which overlap, and one
    /// of them changed) to `begun` when their kinds and layers admit it and it was not
    /// reported at the last report: a changed proxy's box then is its change's old box, an
    /// unchanged one's is its box now.
    #[inline(always)]
    fn begun(&self, a: u32, ba: &Aabb3, b: u32, bb: &Aabb3, begun: &mut Vec<(u32, u32)>) {
        if self.filtered && !self.admits(a, b) {
            return;
        }
        let then = |id: u32, now: &Aabb3| self.change(id).map_or(*now, Change::old);
        if !self.was(a, &then(a, ba), b, &then(b, bb)) {
            begun.push((a.min(b), a.max(b)));
        }
    }
}

/// The changes in `order` (each key a change's place, then its index), with each change's
/// new box read from its place; the changes themselves, scattered in this order, are asked
/// for a few keys ahead.
#[inline(always)]
fn in_order<'c>(
    view: &'c View<'_>,
    order: &'c [u64],
) -> impl Iterator<Item = (&'c Change, Aabb3)> + 'c {
    const AHEAD: usize = 8;
    order.iter().enumerate().map(move |(k, &key)| {
        if let Some(&next) = order.get(k + 2 * AHEAD) {
            view.prefetch(place_of(next), false);
        }
        if let Some(&next) = order.get(k + AHEAD) {
            crate::simd::prefetch(&view.changes[next as u32 as usize]);
            view.prefetch(place_of(next), true);
        }
        (&view.changes[key as u32 as usize], view.at(place_of(key)))
    })
}

/// Up to [`hierarchy::WIDTH`] changes, each with its query box and the box its hits are
/// compared with, taken in slot order, so that they are neighbours in the tree and their
/// queries descend together ([`Hierarchy::query_group`]).
struct Group<'c> {
    changes: [Option<(&'c Change, Aabb3)>; hierarchy::WIDTH],
    boxes: [Aabb3; hierarchy::WIDTH],
    len: usize,
}

impl<'c> Group<'c> {
    fn new() -> Self {
        Self {
            changes: [None; hierarchy::WIDTH],
            boxes: [Aabb3::EMPTY; hierarchy::WIDTH],
            len: 0,
        }
    }

    /// Adds a change, its query box and the box its hits are compared with; true when the
    /// group is full.
    #[inline(always)]
    fn push(&mut self, c: &'c Change, q: Aabb3, against: Aabb3) -> bool {
        self.changes[self.len] = Some((c, against));
        self.boxes[self.len] = q;
        self.len += 1;
        self.len == hierarchy::WIDTH
    }

    /// Calls `hit(change, against, other, box)` for every proxy whose box overlaps a
    /// change's query box, then empties the group.
    #[inline(always)]
    fn query(
        &mut self,
        target: &Hierarchy,
        stack: &mut Vec<u64>,
        mut hit: impl FnMut(&'c Change, &Aabb3, u32, &Aabb3),
    ) {
        if self.len == 0 {
            return;
        }
        let changes = &self.changes;
        target.query_group(&self.boxes[..self.len], stack, |i, other, b| {
            if let Some((c, against)) = &changes[i] {
                hit(c, against, other, b);
            }
        });
        self.len = 0;
    }
}

/// The begun pairs of the changes in `order` against hierarchy `target`: each changed
/// proxy's new box queried. A pair of two changed proxies is taken from the larger id's
/// query (each meets the other: a moving proxy queries both hierarchies, a static one the
/// moving hierarchy), and was reported when their old boxes overlapped; a pair with an
/// unchanged proxy, when the changed one's old box overlapped the other's (unchanged) box
/// (unless a kind or layers changed: [`View::was`]).
#[inline(always)]
fn search(
    view: &View<'_>,
    order: &[u64],
    target: &Hierarchy,
    stack: &mut Vec<u64>,
    begun: &mut Vec<(u32, u32)>,
) {
    let mut hit = |c: &Change, old: &Aabb3, other: u32, b: &Aabb3| {
        let id = c.id();
        if other == id {
            return;
        }
        let then = match view.change(other) {
            None => *b,
            Some(o) if other < id => o.old(),
            Some(_) => return,
        };
        if view.filtered && !view.admits(id, other) {
            return;
        }
        if !view.was(id, old, other, &then) {
            begun.push((id.min(other), id.max(other)));
        }
    };
    let mut group = Group::new();
    for (c, new) in in_order(view, order) {
        if new.min.x <= new.max.x && group.push(c, new, c.old()) {
            group.query(target, stack, &mut hit);
        }
    }
    group.query(target, stack, &mut hit);
}

/// The ended pairs: the partners of each changed proxy (the pairs reported at the last
/// report) whose boxes no longer overlap, or which their kinds or layers no longer admit.
/// A pair of two changed proxies is taken from the smaller id's list. Each proxy's
/// partners are read in change order, so the list is deterministic.
fn search_ended(view: &View<'_>, changes: &[Change], ended: &mut Vec<(u32, u32)>) {
    // Without a change of kind or layers since, every partner pair is still admitted
    // unless some proxy is filtered.
    let check = view.filtered || view.refiltered;
    for c in changes {
        let id = c.id();
        if view.partners.is_alone(id) {
            continue;
        }
        let new = view.now(id);
        for other in view.partners.of(id) {
            if other < id && view.mark[other as usize] != 0 {
                continue;
            }
            if !overlap(&new, &view.now(other)) || (check && !view.admits(id, other)) {
                ended.push((id.min(other), id.max(other)));
            }
        }
    }
}
