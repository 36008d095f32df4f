//! The broadphase's dynamic tree against the brute-force referee
//! (`bvkit_support::referee`), over any sequence of inserts of any kind and layers,
//! removes, moves (`write`), changes of kind, layers and kind pairs, reports, box and point
//! queries, ray and box casts, rebuilds and upkeep (`maintain`, its rebuilds spread over several calls), with
//! any boxes: small integer boxes that overlap often, and faces of any bits (NaN, ±∞, ±MAX,
//! subnormals). After every operation the tree holds what the referee holds (placed, parked
//! or absent, each box bit for bit, each kind and layers, every admitted overlapping pair);
//! every query finds exactly the placed boxes it overlaps whose layers interact with its
//! own, or refuses a bad box; every cast meets every box the exact cast meets (rational
//! arithmetic) with an entry never beyond the exact one, or refuses bad input; every report's begun and ended pairs are exactly the
//! differences of the referee's pair sets since the last report, and its refused ids are
//! the moves whose boxes the referee refuses. Nothing panics.
#![no_main]

use bvkit_fuzz::Floats;
use bvkit_support::referee::{Check, Op};
use libfuzzer_sys::fuzz_target;

const IDS: u32 = 40;

fuzz_target!(|data: &[u8]| {
    let mut f = Floats::new(data);
    let mut check = Check::new(IDS as usize);
    for step in 0..64 {
        if f.byte() == 0 && step > 0 {
            break;
        }
        let op = Op::decode(&mut || f.byte(), IDS);
        check.apply(&op, true);
    }
    check.apply(&Op::Report, true);
});
