//! The broadphase update against the exact oracle: after any update, with any fat box
//! before it, any margin and any pair of rigid poses (one, or swept), the fat box contains
//! the exact image at every pose, or is invalid where a pose or the box holds NaN; an
//! object is reported moved exactly when its fat box changed; a bad margin is refused with
//! nothing written.
#![no_main]

use bvkit::Swept;
use bvkit::{Aabb3, Active, Batch, Margin, Method, Moved, Rounding};
use bvkit_fuzz::Floats;
use bvkit_fuzz::oracle::{Exact, Expected, Exactly, QuatProblem};
use glam::Vec3A;
use libfuzzer_sys::fuzz_target;

fn bits(b: &Aabb3) -> [u32; 6] {
    let [x, y, z] = b.min.to_array().map(f32::to_bits);
    let [u, v, w] = b.max.to_array().map(f32::to_bits);
    [x, y, z, u, v, w]
}

/// The fat box holds the exact image of the problem's box, or is invalid where the
/// problem has no image.
fn holds(p: &QuatProblem, fat: &Aabb3, what: &str) {
    match p.expected() {
        Expected::Invalid => assert!(!fat.is_valid(), "{what}: NaN input hidden in {fat:?}"),
        Expected::Empty => {}
        Expected::Faces { lo, hi, .. } => {
            for a in 0..3 {
                let (min, max) = (fat.min[a], fat.max[a]);
                assert!(
                    !min.is_nan() && Exact::of(min) <= lo[a],
                    "{what}: min {a} {min} misses {}",
                    lo[a].to_f64()
                );
                assert!(
                    !max.is_nan() && Exact::of(max) >= hi[a],
                    "{what}: max {a} {max} misses {}",
                    hi[a].to_f64()
                );
            }
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let mut f = Floats::new(data);
    let p = f.quat_problem(None);
    let mut q = f.quat_problem(None);
    (q.lo, q.hi) = (p.lo, p.hi);
    let fat0 = Aabb3::new(
        Vec3A::new(f.next(), f.next(), f.next()),
        Vec3A::new(f.next(), f.next(), f.next()),
    );
    let margin = Margin::new(f.next(), f.next());
    let valid_margin = [margin.absolute, margin.relative]
        .iter()
        .all(|x| x.is_finite() && *x >= 0.0);
    let local = [p.aabb()];
    let (now, next) = ([p.rigid3()], [q.rigid3()]);
    for method in Method::ALL {
        for deterministic in [false, true] {
            let mut batch = Batch::new(method, Rounding::Outward);
            if deterministic {
                batch = batch.deterministic();
            }
            let what = format!("{method:?} deterministic {deterministic}");
            let mut moved = Moved::new();
            let mut fat = [fat0];
            let result = batch.update(margin, Active::All, &local[..], &now[..], &mut fat[..], &mut moved);
            if !valid_margin {
                assert!(result.is_err() && bits(&fat[0]) == bits(&fat0), "{what}");
                continue;
            }
            result.unwrap();
            holds(&p, &fat[0], &what);
            // A changed fat box is reported, and a NaN pose always is.
            let changed = bits(&fat[0]) != bits(&fat0);
            assert!(moved.contains(0) || !changed, "{what}: rewritten but not reported");
            if let Expected::Invalid = p.expected() {
                assert!(moved.contains(0), "{what}: NaN input not reported");
            }
            let mut fat = [fat0];
            let swept = Swept { current: &now[..], predicted: &next[..] };
            batch.update(margin, Active::All, &local[..], swept, &mut fat[..], &mut moved).unwrap();
            // NaN at either pose makes the swept box invalid; otherwise it holds both images.
            let nan = |x: &QuatProblem| matches!(x.expected(), Expected::Invalid);
            if nan(&p) || nan(&q) {
                assert!(!fat[0].is_valid(), "{what} swept: NaN input hidden in {:?}", fat[0]);
            } else {
                holds(&p, &fat[0], &format!("{what} swept, current"));
                holds(&q, &fat[0], &format!("{what} swept, predicted"));
            }
        }
    }
});
