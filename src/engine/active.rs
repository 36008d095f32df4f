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
/// objects in advance, one object further as each one runs (a burst of requests stalls
/// the loop once the line fill buffers are full). Runs of whole spans are left to the
/// hardware prefetcher, and so is every object of [`Active::All`].
pub(crate) struct Lookahead<'a> {
    next: Upcoming<'a>,
}

/// The active objects not yet requested, in order.
enum Upcoming<'a> {
    /// [`Active::All`]: none are requested.
    None,
    /// An index list's own entries: a list needs no decoding, and its walk one object at
    /// a time is the hot loop of a sparse update (decoded as spans of one object, it put a
    /// division by the span width in that loop).
    List(core::slice::Iter<'a, u32>),
    /// A mask's set bits.
    Mask(MaskAhead<'a>),
}

/// A mask's set bits from a position on, and how many of those requested lie past the
/// object running. Whole spans cost nothing: the position stays where it is, and the
/// first scattered span after them moves it past itself in one step. (Walked bit by bit
/// across whole spans, as spans of one object, the lookahead took about a third of a
/// dense masked update's time.)
struct MaskAhead<'a> {
    words: &'a [u64],
    /// The word of `bits`.
    word: usize,
    /// The set bits of that word not yet requested.
    bits: u64,
    /// The objects requested past the object running: an estimate after whole spans
    /// (they need not have lain in them), which may then fall short of [`AHEAD`] for a
    /// while.
    pending: usize,
}

impl MaskAhead<'_> {
    /// The first object not yet requested, or a position at or before it.
    #[inline(always)]
    fn position(&self) -> usize {
        64 * self.word
            + match self.bits {
                0 => 64,
                bits => bits.trailing_zeros() as usize,
            }
    }

    /// The next set bit's object.
    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        while self.bits == 0 {
            self.bits = *self.words.get(self.word + 1)?;
            self.word += 1;
        }
        let i = 64 * self.word + self.bits.trailing_zeros() as usize;
        self.bits &= self.bits - 1;
        Some(i)
    }

    /// Requests objects until [`AHEAD`] are pending or the mask ends.
    #[inline(always)]
    fn fill(&mut self, mut prefetch: impl FnMut(usize)) {
        while self.pending < AHEAD {
            let Some(i) = self.next() else { return };
            prefetch(i);
            self.pending += 1;
        }
    }

    /// Before `span` runs: past it if it is whole; if it is scattered and the position
    /// lags behind it, after whole spans, on to its end, nothing then pending (its own
    /// objects follow a run, which the hardware prefetcher was following).
    #[inline(always)]
    fn enter(&mut self, span: Span) {
        if span.is_full() {
            self.pending = self.pending.saturating_sub(span.count);
            return;
        }
        if self.position() < span.start {
            let end = span.start + span.count;
            let word = end / 64;
            if word > self.word {
                self.word = word;
                self.bits = self.words.get(word).copied().unwrap_or(0);
            }
            self.bits &= u64::MAX << (end % 64);
            self.pending = 0;
        }
    }
}

impl<'a> Lookahead<'a> {
    /// The lookahead of `active`, the first objects requested.
    #[inline(always)]
    pub fn new(active: Active<'a>, mut prefetch: impl FnMut(usize)) -> Self {
        let next = match active {
            Active::All => Upcoming::None,
            Active::Indices(ix) => {
                let mut ix = ix.iter();
                ix.by_ref().take(AHEAD).for_each(|&i| prefetch(i as usize));
                Upcoming::List(ix)
            }
            Active::Mask(words) => {
                let bits = words.first().copied().unwrap_or(0);
                let mut mask = MaskAhead {
                    words,
                    word: 0,
                    bits,
                    pending: 0,
                };
                mask.fill(prefetch);
                Upcoming::Mask(mask)
            }
        };
        Self { next }
    }

    /// Before `span` runs, its objects then run one at a time, each after [`Self::one`]:
    /// a whole span is skipped.
    #[inline(always)]
    pub fn enter(&mut self, span: Span) {
        match &mut self.next {
            Upcoming::List(ix) if span.is_full() => {
                ix.nth(span.count - 1);
            }
            Upcoming::Mask(mask) => mask.enter(span),
            _ => {}
        }
    }

    /// Before a scattered object runs: one object further.
    #[inline(always)]
    pub fn one(&mut self, mut prefetch: impl FnMut(usize)) {
        match &mut self.next {
            Upcoming::None => {}
            Upcoming::List(ix) => {
                if let Some(&i) = ix.next() {
                    prefetch(i as usize);
                }
            }
            Upcoming::Mask(mask) => {
                mask.pending = mask.pending.saturating_sub(1);
                mask.fill(prefetch);
            }
        }
    }

    /// Before `span` runs as a whole: [`Self::enter`], and one object further for each
    /// of its active objects where it is scattered.
    #[inline(always)]
    pub fn step(&mut self, span: Span, mut prefetch: impl FnMut(usize)) {
        self.enter(span);
        if !span.is_full() {
            for _ in 0..span.lanes.count_ones() {
                self.one(&mut prefetch);
            }
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

    /// The lookahead requests active objects only, each once, in order, and each object of
    /// a scattered span before it runs (the first [`AHEAD`] of a span run whole), except
    /// just after whole spans.
    #[test]
    fn the_lookahead_requests_each_scattered_object_before_it_runs() {
        let len: usize = 1000;
        // Scattered stretches, whole runs of 64 and 8, and a scattered tail.
        let active = |i: usize| match i {
            0..300 => i % 7 == 2 || i.is_multiple_of(13),
            300..400 => true,
            400..411 => i.is_multiple_of(3),
            411..700 => i % 8 == 5 || (512..520).contains(&i),
            _ => i % 11 == 1,
        };
        let indices: Vec<u32> = (0..len as u32).filter(|&i| active(i as usize)).collect();
        let mut words = alloc::vec![0u64; len.div_ceil(64)];
        for &i in &indices {
            words[i as usize / 64] |= 1 << (i % 64);
        }
        for set in [Active::Indices(&indices), Active::Mask(&words)] {
            // Spans run whole (the lane loop), and scattered objects one at a time.
            for (width, whole) in [(4, true), (8, true), (64, true), (8, false), (64, false)] {
                let mut requested = Vec::new();
                let mut ahead = Lookahead::new(set, |i| requested.push(i));
                // After whole spans, the objects of the next scattered span and the next
                // `AHEAD` objects may run unrequested.
                let (mut excused, mut after_whole) = (0, false);
                for span in Spans::new(set, len, width) {
                    if whole {
                        ahead.step(span, |i| requested.push(i));
                    } else {
                        ahead.enter(span);
                    }
                    if span.is_full() {
                        (excused, after_whole) = (AHEAD, true);
                        continue;
                    }
                    let ones = (0..span.count).filter(|k| span.lanes >> k & 1 != 0);
                    // Whole, a span's objects past the first `AHEAD` may run unrequested.
                    for k in ones.take(if whole { AHEAD } else { 64 }) {
                        if !whole {
                            ahead.one(|i| requested.push(i));
                        }
                        let i = span.start + k;
                        if excused > 0 || after_whole {
                            excused = excused.saturating_sub(1);
                        } else {
                            assert!(requested.contains(&i), "{i} {width} {whole} {set:?}");
                        }
                    }
                    after_whole = false;
                }
                assert!(requested.iter().all(|&i| active(i)));
                assert!(requested.windows(2).all(|w| w[0] < w[1]));
                // The scattered stretches are long: most of their objects were requested.
                assert!(requested.len() > indices.len() / 3, "{set:?} {width}");
            }
        }
    }
}
