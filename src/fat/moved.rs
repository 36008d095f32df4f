//! The moved set: which objects' fat boxes an update rewrote, as a bitset and as indices.

use alloc::vec::Vec;

/// The objects whose fat box the last [`Batch::update`](crate::Batch::update) rewrote:
/// a bitset over all objects (bit `i % 64` of word `i / 64`) and the same set as
/// ascending indices, the list a broadphase reinserts.
///
/// Keep one per scene and pass it to every update: it is cleared and refilled in time
/// proportional to the objects moved, not the scene size.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Moved {
    words: Vec<u64>,
    indices: Vec<u32>,
}

impl Moved {
    /// An empty set.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// The bitset: bit `i % 64` of word `i / 64` is set when object `i` moved. It has
    /// `len.div_ceil(64)` words for `len` objects.
    #[must_use]
    pub fn words(&self) -> &[u64] {
        &self.words
    }

    /// The objects that moved, ascending.
    #[must_use]
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }

    /// The number of objects that moved.
    #[must_use]
    pub fn len(&self) -> usize {
        self.indices.len()
    }

    /// True when no object moved.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// True when object `i` moved.
    #[must_use]
    pub fn contains(&self, i: usize) -> bool {
        self.words
            .get(i / 64)
            .is_some_and(|w| w >> (i % 64) & 1 != 0)
    }

    /// Empties the set for `len` objects, clearing only the words the last update set.
    pub(crate) fn reset(&mut self, len: usize) {
        for &i in &self.indices {
            if let Some(w) = self.words.get_mut(i as usize / 64) {
                *w = 0;
            }
        }
        self.words.resize(len.div_ceil(64), 0);
        self.indices.clear();
    }

    /// Adds the objects of `part`, a set over objects `start..`, as objects `start + i`;
    /// `start` is a multiple of 64 and past every object already in the set, whose words
    /// cover the part's.
    #[cfg(feature = "rayon")]
    pub(crate) fn append(&mut self, start: usize, part: &Moved) {
        for (k, &w) in part.words.iter().enumerate() {
            self.words[start / 64 + k] |= w;
        }
        self.indices
            .extend(part.indices.iter().map(|&i| i + start as u32));
    }

    /// Adds objects `i + k` for every bit `k` of `bits`; `i` is the start of a span, a
    /// multiple of its width, so the bits never straddle two words, and calls come in
    /// ascending order of their objects.
    #[inline(always)]
    pub(crate) fn record(&mut self, i: usize, mut bits: u64) {
        if bits == 0 {
            return;
        }
        self.words[i / 64] |= bits << (i % 64);
        while bits != 0 {
            self.indices
                .push((i + bits.trailing_zeros() as usize) as u32);
            bits &= bits - 1;
        }
    }
}
