//! The active set: which objects a run visits, checked once, and decoded in one place
//! into aligned spans of objects.

use crate::error::BatchError;
use crate::simd::LaneArray;
use core::marker::PhantomData;

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

/// The width of a walk's spans, as a constant of a type: a lane type's width, or
/// [`Width`]. (A run-time width was not always propagated into the mask walk, which then
/// divided by it.)
pub(crate) trait SpanWidth {
    /// The objects of a span: a power of two up to 64.
    const OBJECTS: usize;
}

impl<L: LaneArray> SpanWidth for L {
    const OBJECTS: usize = L::WIDTH;
}

/// Spans of `N` objects.
pub(crate) struct Width<const N: usize>;

impl<const N: usize> SpanWidth for Width<N> {
    const OBJECTS: usize = N;
}

/// The active set's spans of `W::OBJECTS` objects, ascending: the one decoder of
/// [`Active`]. Spans with no active object are skipped, a whole empty mask word at a time.
pub(crate) struct Spans<'a, W> {
    active: Active<'a>,
    len: usize,
    /// The next span's start, or the next position in an index list.
    at: usize,
    width: PhantomData<W>,
}

impl<'a, W: SpanWidth> Spans<'a, W> {
    /// Spans of `W::OBJECTS` objects.
    const W: usize = {
        assert!(W::OBJECTS.is_power_of_two() && W::OBJECTS <= 64);
        W::OBJECTS
    };

    /// The spans of `active` over `len` objects (the set checked by [`Active::check`]).
    #[inline(always)]
    pub fn new(active: Active<'a>, len: usize) -> Self {
        Self {
            active,
            len,
            at: 0,
            width: PhantomData,
        }
    }

    /// The span at `start` with these candidate lanes.
    #[inline(always)]
    fn span(&self, start: usize, lanes: u64) -> Span {
        let count = Self::W.min(self.len - start);
        Span {
            start,
            count,
            lanes: lanes & low_bits(count),
        }
    }
}

impl<W: SpanWidth> Iterator for Spans<'_, W> {
    type Item = Span;
    #[inline(always)]
    fn next(&mut self) -> Option<Span> {
        match self.active {
            Active::All => {
                let start = self.at;
                if start >= self.len {
                    return None;
                }
                self.at += Self::W;
                Some(self.span(start, u64::MAX))
            }
            Active::Mask(words) => loop {
                // Straight to the span of the next set bit, a whole empty word at a time.
                // Past the last object the word is zero or absent: a checked mask has no
                // bit past it.
                let start = self.at;
                let word = *words.get(start / 64)?;
                let rest = word >> (start % 64);
                if rest == 0 {
                    self.at = (start / 64 + 1) * 64;
                    continue;
                }
                let next = start + rest.trailing_zeros() as usize;
                let first = next - next % Self::W;
                self.at = first + Self::W;
                return Some(self.span(first, word >> (first % 64)));
            },
            Active::Indices(ix) => {
                let first = *ix.get(self.at)? as usize;
                let start = first - first % Self::W;
                let end = start + Self::W;
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
///
/// The caller requests the objects itself, as [`Self::requests`] yields them, so that its
/// requests are its own inlined code: handed a closure, the lane loop called it out of
/// line, with a third of a 1% update's `perf` samples.
pub(crate) struct Lookahead<'a> {
    next: Upcoming<'a>,
    /// The requests due: [`AHEAD`] at first, one more for each scattered object that
    /// starts running ([`Self::advance`]), and set again around whole spans
    /// ([`Self::enter`]).
    due: usize,
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

/// A mask's set bits from a position on. Whole spans cost nothing: the position stays
/// where it is, and the first scattered span after them moves it past itself in one step.
/// (Walked bit by bit across whole spans, as spans of one object, the lookahead took about
/// a third of a dense masked update's time.)
struct MaskAhead<'a> {
    words: &'a [u64],
    /// The word of `bits`.
    word: usize,
    /// The set bits of that word not yet requested.
    bits: u64,
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

    /// Past `end`, the first object not yet requested.
    #[inline(always)]
    fn seek(&mut self, end: usize) {
        let word = end / 64;
        if word > self.word {
            self.word = word;
            self.bits = self.words.get(word).copied().unwrap_or(0);
        }
        self.bits &= u64::MAX << (end % 64);
    }
}

impl<'a> Lookahead<'a> {
    /// The lookahead of `active`, nothing requested yet.
    #[inline(always)]
    pub fn new(active: Active<'a>) -> Self {
        let next = match active {
            Active::All => Upcoming::None,
            Active::Indices(ix) => Upcoming::List(ix.iter()),
            Active::Mask(words) => Upcoming::Mask(MaskAhead {
                words,
                word: 0,
                bits: words.first().copied().unwrap_or(0),
            }),
        };
        Self { next, due: AHEAD }
    }

    /// The objects to request now: those due, or fewer where the set ends.
    #[inline(always)]
    pub fn requests(&mut self) -> Requests<'_, 'a> {
        Requests(self)
    }

    /// Before `span` runs, its objects then run one at a time, each after
    /// [`Self::advance`]: a whole span is skipped, and a mask's requests that lay in it
    /// are due again, up to [`AHEAD`] (they need not have lain in it). A scattered span
    /// after whole spans, where the position lags behind it, moves the position on to its
    /// end, [`AHEAD`] requests then due (its own objects follow a run, which the hardware
    /// prefetcher was following).
    #[inline(always)]
    pub fn enter(&mut self, span: Span) {
        match &mut self.next {
            Upcoming::None => {}
            Upcoming::List(ix) => {
                if span.is_full() {
                    ix.nth(span.count - 1);
                }
            }
            Upcoming::Mask(mask) => {
                if span.is_full() {
                    self.due = AHEAD.min(self.due + span.count);
                } else if mask.position() < span.start {
                    mask.seek(span.start + span.count);
                    self.due = AHEAD;
                }
            }
        }
    }

    /// Before `objects` scattered objects run: as many more requests due, so that the next
    /// [`Self::requests`] goes as many objects further.
    #[inline(always)]
    pub fn advance(&mut self, objects: usize) {
        self.due += objects;
    }
}

/// The objects a [`Lookahead`] requests now, in order.
pub(crate) struct Requests<'l, 'a>(&'l mut Lookahead<'a>);

impl Iterator for Requests<'_, '_> {
    type Item = usize;
    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        let ahead = &mut *self.0;
        if ahead.due == 0 {
            return None;
        }
        let i = match &mut ahead.next {
            Upcoming::None => None,
            Upcoming::List(ix) => ix.next().map(|&i| i as usize),
            Upcoming::Mask(mask) => mask.next(),
        }?;
        ahead.due -= 1;
        Some(i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec::Vec;

    /// The objects of the spans, in order.
    fn objects<W: SpanWidth>(active: Active<'_>, len: usize) -> Vec<usize> {
        let mut out = Vec::new();
        for s in Spans::<W>::new(active, len) {
            assert_eq!(s.start % W::OBJECTS, 0);
            assert_eq!(s.count, W::OBJECTS.min(len - s.start));
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
        let sets = [Active::All, Active::Indices(&indices), Active::Mask(&words)];
        let every = (0..len).collect::<Vec<_>>();
        for (set, expected) in sets.into_iter().zip([&every, &expected, &expected]) {
            assert_eq!(&objects::<Width<1>>(set, len), expected);
            assert_eq!(&objects::<Width<8>>(set, len), expected);
            assert_eq!(&objects::<Width<16>>(set, len), expected);
            assert_eq!(&objects::<Width<64>>(set, len), expected);
        }
        assert!(objects::<Width<1>>(Active::Indices(&[]), len).is_empty());
        assert!(objects::<Width<8>>(Active::Indices(&[]), len).is_empty());
        assert!(objects::<Width<16>>(Active::Indices(&[]), len).is_empty());
        assert!(objects::<Width<64>>(Active::Indices(&[]), len).is_empty());
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
            let requests = [
                requests::<Width<4>>(set, len, true),
                requests::<Width<8>>(set, len, true),
                requests::<Width<64>>(set, len, true),
                requests::<Width<8>>(set, len, false),
                requests::<Width<64>>(set, len, false),
            ];
            for requested in requests {
                assert!(requested.iter().all(|&i| active(i)));
                assert!(requested.windows(2).all(|w| w[0] < w[1]));
                // The scattered stretches are long: most of their objects were requested.
                assert!(requested.len() > indices.len() / 3, "{set:?}");
            }
        }
    }

    /// The objects requested in a walk of `set` in spans of `W`, the spans run whole or
    /// their objects one at a time, checking that each object of a scattered span was
    /// requested before it runs, except just after whole spans.
    fn requests<W: SpanWidth>(set: Active<'_>, len: usize, whole: bool) -> Vec<usize> {
        let mut requested = Vec::new();
        let mut ahead = Lookahead::new(set);
        requested.extend(ahead.requests());
        // After whole spans, the objects of the next scattered span and the next `AHEAD`
        // objects may run unrequested.
        let (mut excused, mut after_whole) = (0, false);
        for span in Spans::<W>::new(set, len) {
            ahead.enter(span);
            if whole && !span.is_full() {
                ahead.advance(span.lanes.count_ones() as usize);
                requested.extend(ahead.requests());
            }
            if span.is_full() {
                (excused, after_whole) = (AHEAD, true);
                continue;
            }
            let ones = (0..span.count).filter(|k| span.lanes >> k & 1 != 0);
            // Whole, a span's objects past the first `AHEAD` may run unrequested.
            for k in ones.take(if whole { AHEAD } else { 64 }) {
                if !whole {
                    ahead.advance(1);
                    requested.extend(ahead.requests());
                }
                let i = span.start + k;
                if excused > 0 || after_whole {
                    excused = excused.saturating_sub(1);
                } else {
                    assert!(requested.contains(&i), "{i} {} {whole} {set:?}", W::OBJECTS);
                }
            }
            after_whole = false;
        }
        requested
    }
}
