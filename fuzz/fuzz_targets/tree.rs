//! The trees' node-pair box test against the exact rational separating-axis test: two boxes
//! and two rigid poses from the fuzzer (any quaternion, unit or not), and whenever the exact
//! boxes overlap under the query's relative map, the conservative test must say so.
#![no_main]

#[path = "../../tests/sat/mod.rs"]
mod sat;

use bvkit::tree::Relative;
use bvkit::{Aabb3, Rigid3};
use bvkit_fuzz::Floats;
use glam::{Quat, Vec3A};
use libfuzzer_sys::fuzz_target;

fn ordered(f: &mut Floats) -> Aabb3 {
    let (p, q) = (Vec3A::from_array(f.array()), Vec3A::from_array(f.array()));
    Aabb3::new(p.min(q), p.max(q))
}

fn pose(f: &mut Floats) -> Rigid3 {
    Rigid3::new(Quat::from_array(f.array()), Vec3A::from_array(f.array()))
}

fuzz_target!(|data: &[u8]| {
    let mut f = Floats::new(data);
    let (pa, pb) = (pose(&mut f), pose(&mut f));
    let (a, b) = (ordered(&mut f), ordered(&mut f));
    let reach = |x: &Aabb3| x.min.abs().max(x.max.abs()).max_element();
    let rel = Relative::new(&pa, reach(&a), &pb, reach(&b), 0.0);
    let ours = rel.overlaps(&a, &b);
    let finite = [a.min, a.max, b.min, b.max].iter().all(|v| v.is_finite());
    if !rel.is_valid() || !finite {
        return; // nothing placed; the call above must only not panic
    }
    if sat::exact_overlap(&a, &b, rel.matrix(), rel.translation()) {
        assert!(ours, "exact boxes overlap, reported separated: {a:?} {b:?} {pa:?} {pb:?}");
    }
});
