//! What a report hands the engine: the pairs that began and ended, and the refused proxies.

use alloc::vec::Vec;

/// What a frame of [`DynamicTree::update`](super::DynamicTree::update) found. Each pair is `(smaller id, larger id)`,
/// once; the order of the pairs is deterministic but unspecified. A pair is counted only
/// where the proxies' kinds and layers admit it ([`BodyKind`](super::BodyKind),
/// [`Layers`](super::Layers)).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Pairs {
    /// The admitted pairs whose fat boxes overlap now, and did not (or were not admitted)
    /// at the last report.
    pub begun: Vec<(u32, u32)>,
    /// The pairs reported at the last report whose fat boxes do not overlap now, or which
    /// their kinds or layers no longer admit (filled only when made by
    /// [`Pairs::with_ended`]).
    pub ended: Vec<(u32, u32)>,
    /// Moved proxies whose new box was refused (NaN, infinite or inverted) since the last
    /// report, once per refusal; each was parked then (a later good box or a remove may
    /// have changed that since).
    pub refused: Vec<u32>,
    pub(super) ended_wanted: bool,
}

impl Pairs {
    /// Begun pairs only.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Begun and ended pairs. The tree finds the ended ones in every report (it keeps each
    /// proxy's partners, the proxies whose boxes overlapped its own at the last report, and
    /// reads a changed proxy's), so asking for them costs only their list.
    #[must_use]
    pub fn with_ended() -> Self {
        Self {
            ended_wanted: true,
            ..Self::default()
        }
    }

    pub(super) fn clear(&mut self) {
        self.begun.clear();
        self.ended.clear();
        self.refused.clear();
    }
}
