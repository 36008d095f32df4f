//! `AabbTree` against its contract: build, refit, query and `leaf_pairs`, in both layouts.
//! A build or refit errs exactly when a box is invalid (NaN or infinite face, `min > max`) or
//! the count differs, and then leaves the tree as it was; a query errs only for a pose that
//! cannot be placed ([`bvkit_fuzz::query_error_justified`]); otherwise `leaf_pairs` holds
//! every pair whose exact boxes overlap under the query's map (the exact rational
//! separating-axis test of `support/src/sat.rs`), each once, and only pairs that pass the box test.
#![no_main]

use bvkit_support::sat;

use bvkit::tree::{AabbTree, Compact, Layout, Paired, Quantized};
use bvkit::{Aabb3, Rigid3};
use bvkit_fuzz::{Floats, query_error_justified};
use glam::{Quat, Vec3A};
use libfuzzer_sys::fuzz_target;

/// `n` boxes, usually ordered (the fuzzer still reaches unordered ones).
fn boxes(f: &mut Floats, n: usize) -> Vec<Aabb3> {
    (0..n)
        .map(|_| {
            let (p, q) = (Vec3A::from_array(f.array()), Vec3A::from_array(f.array()));
            if f.byte() % 8 == 0 {
                Aabb3::new(p, q)
            } else {
                Aabb3::new(p.min(q), p.max(q))
            }
        })
        .collect()
}

fn valid(boxes: &[Aabb3]) -> bool {
    !boxes.is_empty()
        && boxes
            .iter()
            .all(|b| b.min.is_finite() && b.max.is_finite() && b.min.cmple(b.max).all())
}

fn pose(f: &mut Floats) -> Rigid3 {
    Rigid3::new(Quat::from_array(f.array()), Vec3A::from_array(f.array()))
}

fn check<L: Layout>(ba: &[Aabb3], bb: &[Aabb3], refit: Option<&[Aabb3]>, pa: Rigid3, pb: Rigid3) {
    let built = AabbTree::<L>::build(ba);
    assert_eq!(built.is_ok(), valid(ba), "{ba:?}");
    let (Ok(mut ta), Ok(tb)) = (built, AabbTree::<L>::build(bb)) else {
        return;
    };
    let mut ba = ba.to_vec();
    if let Some(new) = refit {
        let before = ta.reach();
        match ta.refit(new) {
            Ok(()) => {
                assert!(new.len() == ba.len() && valid(new), "{new:?}");
                ba = new.to_vec();
            }
            Err(e) => {
                assert!(new.len() != ba.len() || !valid(new), "{e}: {new:?}");
                assert_eq!(ta.reach(), before);
            }
        }
        assert_eq!(ta.boxes(), &ba[..]);
    }
    assert!(ta.reach().is_finite() && tb.reach().is_finite());
    let q = match ta.query(pa, &tb, pb) {
        Ok(q) => q,
        Err(e) => {
            assert!(
                query_error_justified(&pa.into(), &pb.into(), 0.0, e),
                "{e}: {pa:?} {pb:?}"
            );
            return;
        }
    };
    let pairs = q.leaf_pairs();
    let rel = q.relative();
    let mut sorted = pairs.clone();
    sorted.sort_unstable();
    sorted.dedup();
    assert_eq!(
        sorted.len(),
        pairs.len(),
        "a pair reported twice: {pairs:?}"
    );
    for &(i, j) in &pairs {
        assert!(
            rel.overlaps(&ba[i as usize], &bb[j as usize]),
            "({i}, {j}) fails its box test"
        );
    }
    for (i, a) in ba.iter().enumerate() {
        for (j, b) in bb.iter().enumerate() {
            if sat::exact_overlap(a, b, rel.matrix(), rel.translation()) {
                assert!(
                    sorted.binary_search(&(i as u32, j as u32)).is_ok(),
                    "exact boxes {i} and {j} overlap, not reported: {a:?} {b:?} {pa:?} {pb:?}"
                );
            }
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let mut f = Floats::new(data);
    let (n, m) = (f.byte() as usize % 6, 1 + f.byte() as usize % 5);
    let refit = f.byte();
    let (pa, pb) = (pose(&mut f), pose(&mut f));
    let (ba, bb) = (boxes(&mut f, n), boxes(&mut f, m));
    // A refit with the same count most of the time, another count sometimes.
    let new = match refit % 4 {
        0 => None,
        1 => Some(boxes(&mut f, n + 1)),
        _ => Some(boxes(&mut f, n)),
    };
    check::<Compact>(&ba, &bb, new.as_deref(), pa, pb);
    check::<Quantized>(&ba, &bb, new.as_deref(), pa, pb);
    check::<Paired>(&ba, &bb, new.as_deref(), pa, pb);
});
