//! The active set: which objects a run visits, checked once, and decoded in one place
//! into aligned spans of objects.

use crate::error::BatchError;

/// The objects an update visits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Active<'a> {
    /// Every object.
    All,
    /// The objects at these indices, strictly ascending.
    Indices(&'a [u32]),
    /// The objects whose bit is set: bit `i % 64` of word `i / 64`, with `len.div_ceil(64)`
    /// words and no bit at or past `len`.
    Mask(&'a [u64]),
}

impl Active<'_> {
    /// Refuses indices out of range or out of order, and masks of the wrong shape, for
    /// `len` objects.
    pub(crate) fn check(self, len: usize) -> Result<(), BatchError> {
        let refuse = |why| Err(BatchError::InvalidActive(why));
        match self {
            Active::All => Ok(()),
            Active::Indices(ix) => {
                if ix.last().is_some_and(|&i| i as usize >= len) {
                    return refuse("an index is past the last object");
                }
                if ix.windows(2).any(|w| w[0] >= w[1]) {
                    return refuse("the indices are not strictly ascending");
                }
                Ok(())
            }
            Active::Mask(words) => {
                if words.len() != len.div_ceil(64) {
                    return refuse("the mask does not have len.div_ceil(64) words");
                }
                let tail = len % 64;
                if tail != 0 && words.last().is_some_and(|w| w >> tail != 0) {
                    return refuse("the mask has a bit past the last object");
                }
                Ok(())
            }
        }
    }
}

/// Objects `start..start + count` of which the `lanes` bits are active (bit `k` for object
/// `start + k`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Span {
    /// The first object, a multiple of the span width.
    pub start: usize,
    /// The objects that exist: the width, or fewer in the last span.
    pub count: usize,
    /// The active ones; never zero.
    pub lanes: u64,
}

impl Span {
    /// True when every object of the span is active.
    #[inline(always)]
    pub fn is_full(&self) -> bool {
        self.lanes == low_bits(self.count)
    }
}

/// The mask of bits `0..count`, for `count <= 64`.
#[inline(always)]
fn low_bits(count: usize) -> u64 {
    u64::MAX >> (64 - count)
}

/// The active set's spans of `width` objects (1 to 64), ascending: the one decoder of
/// [`Active`]. Spans with no active object are skipped, a whole empty mask word at a time.
pub(crate) struct Spans<'a> {
    active: Active<'a>,
    len: usize,
    width: usize,
    /// The next span's start, or the next position in an index list.
    at: usize,
}

impl<'a> Spans<'a> {
    /// The spans of `active` over `len` objects (the set checked by [`Active::check`]).
    pub fn new(active: Active<'a>, len: usize, width: usize) -> Self {
        debug_assert!((1..=64).contains(&width));
        Self {
            active,
            len,
            width,
            at: 0,
        }
    }

    /// The span at `start` with these candidate lanes.
    #[inline(always)]
    fn span(&self, start: usize, lanes: u64) -> Span {
        let count = self.width.min(self.len - start);
        Span {
            start,
            count,
            lanes: lanes & low_bits(count),
        }
    }
}

impl Iterator for Spans<'_> {
    type Item = Span;
    #[inline(always)]
    fn next(&mut self) -> Option<Span> {
        match self.active {
            Active::All => {
                let start = self.at;
                if start >= self.len {
                    return None;
                }
                self.at += self.width;
                Some(self.span(start, u64::MAX))
            }
            Active::Mask(words) => loop {
                let start = self.at;
                if start >= self.len {
                    return None;
                }
                // Straight to the span of the next set bit, a whole empty word at a time.
                let word = words[start / 64];
                let rest = word >> (start % 64);
                if rest == 0 {
                    self.at = (start / 64 + 1) * 64;
                    continue;
                }
                let next = start + rest.trailing_zeros() as usize;
                let first = next - next % self.width;
                self.at = first + self.width;
                return Some(self.span(first, word >> (first % 64)));
            },
            Active::Indices(ix) => {
                let first = *ix.get(self.at)? as usize;
                let start = first - first % self.width;
                let end = start + self.width;
                let mut lanes = 0;
                while let Some(&i) = ix.get(self.at).filter(|&&i| (i as usize) < end) {
                    lanes |= 1 << (i as usize - start);
                    self.at += 1;
                }
                Some(self.span(start, lanes))
            }
        }
    }
}

/// How many scattered objects ahead a run requests memory.
const AHEAD: usize = 16;

/// The scattered objects a run will visit next, whose memory it requests [`AHEAD`]
/// objects in advance. Runs of whole spans are left to the hardware prefetcher, and so is
/// every object of [`Active::All`].
pub(crate) struct Lookahead<'a> {
    next: Upcoming<'a>,
}

/// The active objects one at a time, in order.
enum Upcoming<'a> {
    /// [`Active::All`]: none are requested.
    None,
    /// An index list's own entries: a list needs no decoding, and its walk one object at
    /// a time is the hot loop of a sparse update (decoded as spans of one object, it put a
    /// division by the span width in that loop).
    List(core::slice::Iter<'a, u32>),
    /// A mask's objects: its spans of one object.
    Mask(Spans<'a>),
}

impl Iterator for Upcoming<'_> {
    type Item = usize;
    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        match self {
            Upcoming::None => None,
            Upcoming::List(ix) => ix.next().map(|&i| i as usize),
            Upcoming::Mask(spans) => spans.next().map(|s| s.start),
        }
    }
}

impl<'a> Lookahead<'a> {
    /// The lookahead of `active` over `len` objects, the first objects requested.
    #[inline(always)]
    pub fn new(active: Active<'a>, len: usize, mut prefetch: impl FnMut(usize)) -> Self {
        let mut next = match active {
            Active::All => Upcoming::None,
            Active::Indices(ix) => Upcoming::List(ix.iter()),
            Active::Mask(_) => Upcoming::Mask(Spans::new(active, len, 1)),
        };
        next.by_ref().take(AHEAD).for_each(&mut prefetch);
        Self { next }
    }

    /// Before `span` runs: one object further for each of its active objects, requested
    /// where the span is scattered, skipped where it is a whole run.
    #[inline(always)]
    pub fn step(&mut self, span: Span, mut prefetch: impl FnMut(usize)) {
        if let Upcoming::None = self.next {
            return;
        }
        if span.is_full() {
            self.next.nth(span.count - 1);
            return;
        }
        for _ in 0..span.lanes.count_ones() {
            if let Some(i) = self.next.next() {
                prefetch(i);
            }
        }
    }

    /// Before a scattered object runs alone: one object further.
    #[inline(always)]
    pub fn one(&mut self, prefetch: impl FnOnce(usize)) {
        if let Some(i) = self.next.next() {
            prefetch(i);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec::Vec;

    /// The objects of the spans, in order.
    fn objects(active: Active<'_>, len: usize, width: usize) -> Vec<usize> {
        let mut out = Vec::new();
        for s in Spans::new(active, len, width) {
            assert_eq!(s.start % width, 0);
            assert_eq!(s.count, width.min(len - s.start));
            assert_ne!(s.lanes, 0);
            assert_eq!(s.lanes & !low_bits(s.count), 0);
            out.extend(
                (0..s.count)
                    .filter(|k| s.lanes >> k & 1 != 0)
                    .map(|k| s.start + k),
            );
        }
        out
    }

    #[test]
    fn every_width_decodes_the_same_objects() {
        let len: usize = 300;
        let indices: Vec<u32> = (0..len as u32)
            .filter(|i| i % 7 == 3 || i % 64 < 20)
            .collect();
        let mut words = alloc::vec![0u64; len.div_ceil(64)];
        for &i in &indices {
            words[i as usize / 64] |= 1 << (i % 64);
        }
        let expected: Vec<usize> = indices.iter().map(|&i| i as usize).collect();
        for width in [1, 8, 16, 64] {
            assert_eq!(
                objects(Active::All, len, width),
                (0..len).collect::<Vec<_>>()
            );
            assert_eq!(objects(Active::Indices(&indices), len, width), expected);
            assert_eq!(objects(Active::Mask(&words), len, width), expected);
            assert!(objects(Active::Indices(&[]), len, width).is_empty());
        }
    }
}
