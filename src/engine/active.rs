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
    ///
    /// AoS 3D boxes run a list an entry at a time. Every other layout runs a list of at
    /// least one object in sixteen as the mask it builds from it (an allocation of
    /// `len.div_ceil(64)` words), in lanes, and a sparser one an entry at a time. A dense
    /// set kept as a [`Active::Mask`] skips that step.
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

/// Objects `start..start + count` of which the `active_lanes` bits are active (bit `k` for object
/// `start + k`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Span {
    /// The first object, a multiple of the span width.
    pub start: usize,
    /// The objects that exist: the width, or fewer in the last span.
    pub count: usize,
    /// The active ones; never zero.
    pub active_lanes: u64,
}

impl Span {
    /// True when every object of the span is active.
    #[inline(always)]
    pub fn is_full(&self) -> bool {
        self.active_lanes == low_bits(self.count)
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
    const OBJECTS: usize = {
        assert!(L::WIDTH.is_power_of_two() && L::WIDTH <= 64);
        L::WIDTH
    };
}

/// Spans of `N` objects.
pub(crate) struct Width<const N: usize>;

impl<const N: usize> SpanWidth for Width<N> {
    const OBJECTS: usize = {
        assert!(N.is_power_of_two() && N <= 64);
        N
    };
}

/// The span of `W::OBJECTS` objects at `start`, of `len` objects in all, with these
/// candidate lanes.
#[inline(always)]
fn span<W: SpanWidth>(start: usize, len: usize, lanes: u64) -> Span {
    let count = W::OBJECTS.min(len - start);
    Span {
        start,
        count,
        active_lanes: lanes & low_bits(count),
    }
}

/// A scattered active set of one kind, an index list or a mask, checked by
/// [`Active::check`]: its spans and its lookahead. A walk is generic over it, so that
/// each compiled loop decodes one kind. (One loop for both kinds tested the kind on every
/// span and every request, and kept its state on the stack.)
pub(crate) trait Subset: Copy + core::fmt::Debug {
    /// The objects its lookahead has not yet requested.
    type Upcoming: Upcoming;
    /// Its spans of `W::OBJECTS` objects, of `len` objects in all, ascending; spans with
    /// no active object are skipped.
    fn spans<W: SpanWidth>(self, len: usize) -> impl SpanIter;
    /// Its lookahead, nothing requested yet.
    fn lookahead(self) -> Lookahead<Self::Upcoming>;
    /// True when the lane loop walks it an entry at a time (an index list: see
    /// [`dense`]).
    const BY_ENTRY: bool;
}

/// True when `count` objects of `len` are dense enough that the lane loop runs them as a
/// mask, in lanes: at least one object in sixteen. A sparser list runs an entry at a time,
/// in one lane: spans of eight objects would seldom hold two of its objects
/// (`docs/decisions.md`, "When a list runs as a mask").
#[inline(always)]
pub(crate) fn dense(count: usize, len: usize) -> bool {
    count >= len / 16
}

/// The mask of a checked index list (strictly ascending, below `len`), for `len` objects.
/// A word's bits gather in a register and are stored once: setting each bit in memory
/// chained every entry of a dense list through the same word's load and store.
pub(crate) fn mask_of(ix: &[u32], len: usize) -> alloc::vec::Vec<u64> {
    let mut words = alloc::vec![0; len.div_ceil(64)];
    let (mut word, mut bits) = (0, 0);
    for &i in ix {
        let at = i as usize / 64;
        if at != word {
            words[word] = bits;
            (word, bits) = (at, 0);
        }
        bits |= 1 << (i % 64);
    }
    if let Some(last) = words.get_mut(word) {
        *last = bits;
    }
    words
}

/// [`Active::Indices`]: the objects at these indices, strictly ascending.
#[derive(Clone, Copy, Debug)]
pub(crate) struct List<'a>(pub &'a [u32]);

/// [`Active::Mask`]: the objects whose bit is set.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Mask<'a>(pub &'a [u64]);

impl<'a> Subset for List<'a> {
    type Upcoming = ListAhead<'a>;
    const BY_ENTRY: bool = true;
    #[inline(always)]
    fn spans<W: SpanWidth>(self, len: usize) -> impl SpanIter {
        ListSpans::<W> {
            ix: self.0,
            len,
            at: 0,
            width: PhantomData,
        }
    }
    #[inline(always)]
    fn lookahead(self) -> Lookahead<ListAhead<'a>> {
        Lookahead::new(ListAhead(self.0.iter()))
    }
}

impl<'a> Subset for Mask<'a> {
    type Upcoming = MaskAhead<'a>;
    const BY_ENTRY: bool = false;
    #[inline(always)]
    fn spans<W: SpanWidth>(self, len: usize) -> impl SpanIter {
        MaskSpans::<W> {
            words: self.0,
            len,
            at: 0,
            width: PhantomData,
        }
    }
    #[inline(always)]
    fn lookahead(self) -> Lookahead<MaskAhead<'a>> {
        Lookahead::new(MaskAhead {
            words: self.0,
            word: 0,
            bits: self.0.first().copied().unwrap_or(0),
        })
    }
}

/// A subset's spans, ascending.
pub(crate) trait SpanIter: Iterator<Item = Span> {
    /// Right after a whole span that ends at `end`: the end of the whole words of active
    /// objects that follow it, the spans resuming there. `end` itself unless it starts a
    /// word of 64 active objects, and always for a list.
    #[inline(always)]
    fn whole_words(&mut self, end: usize) -> usize {
        end
    }
}

impl<W: SpanWidth> SpanIter for ListSpans<'_, W> {}

impl<W: SpanWidth> SpanIter for MaskSpans<'_, W> {
    #[inline(always)]
    fn whole_words(&mut self, end: usize) -> usize {
        if !end.is_multiple_of(64) {
            return end;
        }
        let mut word = end / 64;
        while self.words.get(word) == Some(&u64::MAX) {
            word += 1;
        }
        self.at = 64 * word;
        self.at
    }
}

/// An index list's spans.
struct ListSpans<'a, W> {
    ix: &'a [u32],
    len: usize,
    /// The next position in the list.
    at: usize,
    width: PhantomData<W>,
}

impl<W: SpanWidth> Iterator for ListSpans<'_, W> {
    type Item = Span;
    #[inline(always)]
    fn next(&mut self) -> Option<Span> {
        let first = *self.ix.get(self.at)? as usize;
        if W::OBJECTS == 1 {
            // An entry is its span.
            self.at += 1;
            return Some(Span {
                start: first,
                count: 1,
                active_lanes: 1,
            });
        }
        let start = first - first % W::OBJECTS;
        let end = start + W::OBJECTS;
        let mut lanes = 0;
        while let Some(&i) = self.ix.get(self.at).filter(|&&i| (i as usize) < end) {
            lanes |= 1 << (i as usize - start);
            self.at += 1;
        }
        Some(span::<W>(start, self.len, lanes))
    }
}

/// A mask's spans, straight to the span of the next set bit, a whole empty word at a
/// time.
struct MaskSpans<'a, W> {
    words: &'a [u64],
    len: usize,
    /// The next span's start.
    at: usize,
    width: PhantomData<W>,
}

impl<W: SpanWidth> Iterator for MaskSpans<'_, W> {
    type Item = Span;
    #[inline(always)]
    fn next(&mut self) -> Option<Span> {
        loop {
            // Past the last object the word is zero or absent: a checked mask has no bit
            // past it.
            let start = self.at;
            let word = *self.words.get(start / 64)?;
            let rest = word >> (start % 64);
            if rest == 0 {
                self.at = (start / 64 + 1) * 64;
                continue;
            }
            let next = start + rest.trailing_zeros() as usize;
            let first = next - next % W::OBJECTS;
            self.at = first + W::OBJECTS;
            return Some(span::<W>(first, self.len, word >> (first % 64)));
        }
    }
}

/// What the walk of a scattered active set does with its objects ([`walk`]): the lane loop
/// and the AoS loop each implement it once.
pub(crate) trait Visit {
    /// Objects `start..end`, every one active: whole spans that follow each other, whose
    /// memory is left to the hardware prefetcher.
    fn whole(&mut self, start: usize, end: usize);
    /// The active objects of any other span, each requested ahead: before the span runs
    /// (`ahead.advance` by its objects) or one object further as each runs.
    fn part<U: Upcoming>(&mut self, span: Span, ahead: &mut Lookahead<U>);
    /// Asks for object `i`'s memory ahead of a scattered access.
    fn request(&self, i: usize);
}

/// The one walk of a scattered active set, in spans of `W::OBJECTS` objects: whole spans
/// that follow each other are run together ([`Visit::whole`]), every other span on its own
/// ([`Visit::part`]). A run of whole spans goes on over a mask's whole words a word at a
/// time ([`SpanIter::whole_words`]). Spans of one object are all scattered: an index list
/// is walked one entry at a time (`docs/decisions.md`, "The walk of an active set").
#[inline(always)]
pub(crate) fn walk<W: SpanWidth>(set: impl Subset, len: usize, visit: &mut impl Visit) {
    let mut ahead = set.lookahead();
    for i in ahead.requests() {
        visit.request(i);
    }
    if W::OBJECTS == 1 {
        for span in set.spans::<W>(len) {
            visit.part(span, &mut ahead);
        }
        return;
    }
    let mut spans = set.spans::<W>(len);
    let mut pending = None;
    while let Some(span) = pending.take().or_else(|| spans.next()) {
        ahead.enter(span);
        if span.is_full() {
            let mut end = span.start + span.count;
            loop {
                let words_end = spans.whole_words(end);
                if words_end > end {
                    // Entered as one whole span: the lookahead's requests are due again.
                    ahead.enter(Span {
                        start: end,
                        count: 64,
                        active_lanes: u64::MAX,
                    });
                    end = words_end;
                }
                match spans.next() {
                    Some(next) if next.start == end && next.is_full() => {
                        ahead.enter(next);
                        end += next.count;
                    }
                    next => {
                        pending = next;
                        break;
                    }
                }
            }
            // The next span is past a gap the hardware prefetcher will not cross: its first
            // lines are requested now, to arrive while this run computes.
            if let Some(next) = pending {
                let reach = next.count.min(RUN_AHEAD).min(end - span.start);
                let head = next.active_lanes & (u64::MAX >> (64 - reach));
                let mut bits = head & (head ^ head << 1 | 0x5555_5555_5555_5555);
                while bits != 0 {
                    visit.request(next.start + bits.trailing_zeros() as usize);
                    bits &= bits - 1;
                }
            }
            visit.whole(span.start, end);
        } else {
            visit.part(span, &mut ahead);
        }
    }
}

/// How many scattered objects ahead a run requests memory.
const AHEAD: usize = 16;

/// How far into the next span a run of whole spans requests its active objects before it
/// runs (those at even offsets, and those that follow an inactive one: about a line each
/// of 32-byte objects), and no further than the run is long (`docs/decisions.md`, "How
/// far a run of whole spans requests ahead").
const RUN_AHEAD: usize = 64;

/// The scattered objects a run will visit next, whose memory it requests [`AHEAD`]
/// objects in advance, one object further as each one runs (a burst of requests stalls
/// the loop once the line fill buffers are full). Runs of whole spans are left to the
/// hardware prefetcher, but for the head of the span after each run ([`RUN_AHEAD`]), and
/// so is every object of [`Active::All`].
///
/// The caller requests the objects itself, as [`Self::requests`] yields them, so that its
/// requests are its own inlined code: handed a closure, the lane loop called it out of
/// line, with a third of a 1% update's `perf` samples.
pub(crate) struct Lookahead<U> {
    next: U,
    /// The requests due: [`AHEAD`] at first, one more for each scattered object that
    /// starts running ([`Self::advance`]), and set again around whole spans
    /// ([`Self::enter`]).
    due: usize,
}

/// The active objects of one kind of [`Subset`] that its lookahead has not yet requested,
/// in order.
pub(crate) trait Upcoming {
    /// The next one.
    fn next(&mut self) -> Option<usize>;
    /// Before `span` runs: skips or seeks past it, and sets the requests `due`, as
    /// [`Lookahead::enter`] describes.
    fn enter(&mut self, span: Span, due: &mut usize);
}

/// An index list's own entries: a list needs no decoding, and its walk one object at a
/// time is the hot loop of a sparse update (decoded as spans of one object, it put a
/// division by the span width in that loop).
pub(crate) struct ListAhead<'a>(core::slice::Iter<'a, u32>);

impl Upcoming for ListAhead<'_> {
    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        self.0.next().map(|&i| i as usize)
    }
    #[inline(always)]
    fn enter(&mut self, span: Span, _: &mut usize) {
        if span.is_full() {
            self.0.nth(span.count - 1);
        }
    }
}

/// A mask's set bits from a position on. Whole spans cost nothing: the position stays
/// where it is, and the first scattered span after them moves it past itself in one step.
/// (Walked bit by bit across whole spans, as spans of one object, the lookahead took about
/// a third of a dense masked update's time.)
pub(crate) struct MaskAhead<'a> {
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

impl Upcoming for MaskAhead<'_> {
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
    #[inline(always)]
    fn enter(&mut self, span: Span, due: &mut usize) {
        if span.is_full() {
            *due = AHEAD.min(*due + span.count);
        } else if self.position() < span.start {
            self.seek(span.start + span.count);
            *due = AHEAD;
        }
    }
}

impl<U: Upcoming> Lookahead<U> {
    /// The lookahead of these objects, nothing requested yet.
    #[inline(always)]
    fn new(next: U) -> Self {
        Self { next, due: AHEAD }
    }

    /// The objects to request now: those due, or fewer where the set ends.
    #[inline(always)]
    pub fn requests(&mut self) -> Requests<'_, U> {
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
        self.next.enter(span, &mut self.due);
    }

    /// Before `objects` scattered objects run: as many more requests due, so that the next
    /// [`Self::requests`] goes as many objects further.
    #[inline(always)]
    pub fn advance(&mut self, objects: usize) {
        self.due += objects;
    }
}

/// The objects a [`Lookahead`] requests now, in order.
pub(crate) struct Requests<'l, U>(&'l mut Lookahead<U>);

impl<U: Upcoming> Iterator for Requests<'_, U> {
    type Item = usize;
    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        let ahead = &mut *self.0;
        if ahead.due == 0 {
            return None;
        }
        let i = ahead.next.next()?;
        ahead.due -= 1;
        Some(i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec::Vec;

    /// The objects of the spans, in order.
    fn objects<W: SpanWidth>(set: impl Subset, len: usize) -> Vec<usize> {
        let mut out = Vec::new();
        for s in set.spans::<W>(len) {
            assert_eq!(s.start % W::OBJECTS, 0);
            assert_eq!(s.count, W::OBJECTS.min(len - s.start));
            assert_ne!(s.active_lanes, 0);
            assert_eq!(s.active_lanes & !low_bits(s.count), 0);
            out.extend(
                (0..s.count)
                    .filter(|k| s.active_lanes >> k & 1 != 0)
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
        assert_eq!(objects::<Width<1>>(List(&indices), len), expected);
        assert_eq!(objects::<Width<8>>(List(&indices), len), expected);
        assert_eq!(objects::<Width<16>>(List(&indices), len), expected);
        assert_eq!(objects::<Width<64>>(List(&indices), len), expected);
        assert_eq!(objects::<Width<1>>(Mask(&words), len), expected);
        assert_eq!(objects::<Width<8>>(Mask(&words), len), expected);
        assert_eq!(objects::<Width<16>>(Mask(&words), len), expected);
        assert_eq!(objects::<Width<64>>(Mask(&words), len), expected);
        assert!(objects::<Width<1>>(List(&[]), len).is_empty());
        assert!(objects::<Width<8>>(List(&[]), len).is_empty());
        assert!(objects::<Width<16>>(List(&[]), len).is_empty());
        assert!(objects::<Width<64>>(List(&[]), len).is_empty());
        let empty = alloc::vec![0u64; len.div_ceil(64)];
        assert!(objects::<Width<1>>(Mask(&empty), len).is_empty());
        assert!(objects::<Width<64>>(Mask(&empty), len).is_empty());
    }

    /// What a walk did: the objects run, in order, whole or in parts, and the requests.
    #[derive(Default)]
    struct Record {
        run: Vec<usize>,
        whole: Vec<(usize, usize)>,
        requested: core::cell::RefCell<Vec<usize>>,
    }

    impl Visit for Record {
        fn whole(&mut self, start: usize, end: usize) {
            self.whole.push((start, end));
            self.run.extend(start..end);
        }
        fn part<U: Upcoming>(&mut self, span: Span, ahead: &mut Lookahead<U>) {
            for k in (0..span.count).filter(|k| span.active_lanes >> k & 1 != 0) {
                ahead.advance(1);
                for i in ahead.requests() {
                    self.request(i);
                }
                self.run.push(span.start + k);
            }
        }
        fn request(&self, i: usize) {
            self.requested.borrow_mut().push(i);
        }
    }

    /// The walk of `set` in spans of `W`: every active object runs once, in order; whole
    /// runs are maximal runs of whole spans; spans of one object are all parts.
    fn check_walk<W: SpanWidth>(set: impl Subset, expected: &[usize], len: usize) {
        let mut record = Record::default();
        walk::<W>(set, len, &mut record);
        assert_eq!(record.run, expected, "{} {set:?}", W::OBJECTS);
        let requested = record.requested.into_inner();
        // In order, but for the head of the span after a whole run, requested before the
        // run: each object at most twice, and only active ones.
        let mut once = requested.clone();
        once.sort_unstable();
        once.dedup();
        assert!(requested.len() <= 2 * once.len());
        assert!(
            once.iter()
                .all(|&i| requested.iter().filter(|&&j| j == i).count() <= 2)
        );
        assert!(requested.iter().all(|i| expected.contains(i)));
        if W::OBJECTS == 1 {
            assert!(record.whole.is_empty());
            assert_eq!(
                requested, expected,
                "a list walked alone requests every object"
            );
        }
        for w in record.whole.windows(2) {
            assert!(
                w[0].1 < w[1].0,
                "two whole runs that follow each other: {w:?}"
            );
        }
        for &(start, end) in &record.whole {
            assert_eq!(start % W::OBJECTS, 0);
            assert!(end % W::OBJECTS == 0 || end == len);
            assert!((start..end).all(|i| expected.contains(&i)));
        }
    }

    #[test]
    fn the_walk_runs_every_active_object_once_in_order() {
        let len: usize = 700;
        let active = |i: usize| match i {
            0..130 => i % 5 == 1,
            130..300 => true,
            300..320 => i != 311,
            320..512 => (320..384).contains(&i) || (448..456).contains(&i) || i.is_multiple_of(9),
            _ => !i.is_multiple_of(3),
        };
        let expected: Vec<usize> = (0..len).filter(|&i| active(i)).collect();
        let indices: Vec<u32> = expected.iter().map(|&i| i as u32).collect();
        let mut words = alloc::vec![0u64; len.div_ceil(64)];
        for &i in &expected {
            words[i / 64] |= 1 << (i % 64);
        }
        for set in [&indices[..], &[]] {
            let want: Vec<usize> = set.iter().map(|&i| i as usize).collect();
            check_walk::<Width<1>>(List(set), &want, len);
            check_walk::<Width<8>>(List(set), &want, len);
            check_walk::<Width<64>>(List(set), &want, len);
        }
        check_walk::<Width<1>>(Mask(&words), &expected, len);
        check_walk::<Width<8>>(Mask(&words), &expected, len);
        check_walk::<Width<64>>(Mask(&words), &expected, len);
        let full = alloc::vec![u64::MAX; 2];
        let mut record = Record::default();
        walk::<Width<8>>(Mask(&full), 128, &mut record);
        assert_eq!(record.whole, [(0, 128)], "whole spans run together");
        // Whole words skipped together, from a run that starts inside a word and up to the
        // last object, or up to a span that is not whole.
        let mut words = alloc::vec![u64::MAX; 5];
        words[0] = u64::MAX << 8;
        // (the last word, the whole run in spans of 8, in spans of 64)
        for (last, by_8, by_64) in [
            (u64::MAX, (8, 320), (64, 320)),
            (u64::MAX >> 1, (8, 312), (64, 256)),
        ] {
            words[4] = last;
            let want: Vec<usize> = (8..320).filter(|&i| i != 319 || last == u64::MAX).collect();
            let mut record = Record::default();
            walk::<Width<8>>(Mask(&words), 320, &mut record);
            assert_eq!(
                (&record.whole[..], &record.run),
                (&[by_8][..], &want),
                "{last:x}"
            );
            let mut record = Record::default();
            walk::<Width<64>>(Mask(&words), 320, &mut record);
            assert_eq!(
                (&record.whole[..], &record.run),
                (&[by_64][..], &want),
                "{last:x}"
            );
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
        // Spans run whole (the lane loop), and scattered objects one at a time.
        check_requests(List(&indices), &active, indices.len(), len);
        check_requests(Mask(&words), &active, indices.len(), len);
    }

    /// The requests of a walk of `set` over `len` objects, `count` of them active (those
    /// for which `active` holds), in spans of several widths.
    fn check_requests(set: impl Subset, active: &dyn Fn(usize) -> bool, count: usize, len: usize) {
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
            assert!(requested.len() > count / 3, "{set:?}");
        }
    }

    /// The objects requested in a walk of `set` in spans of `W`, the spans run whole or
    /// their objects one at a time, checking that each object of a scattered span was
    /// requested before it runs, except just after whole spans.
    fn requests<W: SpanWidth>(set: impl Subset, len: usize, whole: bool) -> Vec<usize> {
        let mut requested = Vec::new();
        let mut ahead = set.lookahead();
        requested.extend(ahead.requests());
        // After whole spans, the objects of the next scattered span and the next `AHEAD`
        // objects may run unrequested.
        let (mut excused, mut after_whole) = (0, false);
        for span in set.spans::<W>(len) {
            ahead.enter(span);
            if whole && !span.is_full() {
                ahead.advance(span.active_lanes.count_ones() as usize);
                requested.extend(ahead.requests());
            }
            if span.is_full() {
                (excused, after_whole) = (AHEAD, true);
                continue;
            }
            let ones = (0..span.count).filter(|k| span.active_lanes >> k & 1 != 0);
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
