//! The broadphase update against the exact oracle: after any update, with any fat box
//! before it, any margin and any pair of rigid poses (one, or swept), the fat box contains
//! the exact image at every pose, or is invalid where a pose or the box holds NaN; an
//! object is reported moved exactly when its fat box changed; a bad margin is refused with
//! nothing written; and an update repeated with unchanged poses, of every pose source
//! (each transform class, AoS and AoSoA, swept pairs, large worlds) and box kind, moves
//! nothing after the first call unless the tight box is invalid.
#![no_main]

use bvkit::{Aabb2, Aabb3, Active, Batch, Block8, Margin, Method, Moved, Rounding};
use bvkit::{LargePose, LargeRigid3, LargeWorld, PoseSource, Rigid2, Swept};
use bvkit_fuzz::Floats;
use bvkit_fuzz::oracle::{Exact, Exactly, Expected, QuatProblem};
use glam::{DAffine3, DVec3, Vec2, Vec3A};
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

/// Two updates with the same poses from `fat0`: the second moves nothing, unless the tight
/// box is invalid (a NaN pose or box), which is reported at every update. AoS boxes, then
/// AoSoA blocks (the lane loop).
fn repeat<P: PoseSource<3> + Copy>(
    batch: &Batch,
    margin: Margin,
    local: &Aabb3,
    fat0: &Aabb3,
    poses: P,
    invalid: bool,
    what: &str,
) {
    let mut moved = Moved::new();
    let mut fat = [*fat0];
    for _ in 0..2 {
        batch
            .update(
                margin,
                Active::All,
                &[*local][..],
                poses,
                &mut fat[..],
                &mut moved,
            )
            .unwrap();
    }
    assert!(
        moved.is_empty() || invalid,
        "{what}: moved again with unchanged poses"
    );
    assert!(
        moved.contains(0) || !invalid,
        "{what}: an invalid box not reported"
    );
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
    let origin = DVec3::new(f64::from(f.next()), 0.0, 0.0);
    let r2 = Rigid2::from_angle_translation(f.next(), Vec2::new(f.next(), f.next()));
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
            let result = batch.update(
                margin,
                Active::All,
                &local[..],
                &now[..],
                &mut fat[..],
                &mut moved,
            );
            if !valid_margin {
                assert!(result.is_err() && bits(&fat[0]) == bits(&fat0), "{what}");
                continue;
            }
            result.unwrap();
            holds(&p, &fat[0], &what);
            // A changed fat box is reported, and a NaN pose always is.
            let changed = bits(&fat[0]) != bits(&fat0);
            assert!(
                moved.contains(0) || !changed,
                "{what}: rewritten but not reported"
            );
            if let Expected::Invalid = p.expected() {
                assert!(moved.contains(0), "{what}: NaN input not reported");
            }
            let mut fat = [fat0];
            let swept = Swept {
                current: &now[..],
                predicted: &next[..],
            };
            batch
                .update(
                    margin,
                    Active::All,
                    &local[..],
                    swept,
                    &mut fat[..],
                    &mut moved,
                )
                .unwrap();
            // NaN at either pose makes the swept box invalid; otherwise it holds both images.
            let nan = |x: &QuatProblem| matches!(x.expected(), Expected::Invalid);
            if nan(&p) || nan(&q) {
                assert!(
                    !fat[0].is_valid(),
                    "{what} swept: NaN input hidden in {:?}",
                    fat[0]
                );
            } else {
                holds(&p, &fat[0], &format!("{what} swept, current"));
                holds(&q, &fat[0], &format!("{what} swept, predicted"));
            }
            // Unchanged poses move nothing after the first update, from every source; the
            // single-box path says which tight boxes are invalid.
            let b = p.aabb();
            let bad = |t: Aabb3| !t.is_valid();
            let r = now[0];
            let large = [LargeRigid3::new(r.rotation, r.translation.as_dvec3())];
            let m = glam::Mat3A::from_quat(r.rotation);
            let daffine = [DAffine3 {
                matrix3: m.as_dmat3(),
                translation: r.translation.as_dvec3(),
            }];
            let world = LargeWorld {
                poses: &large[..],
                origin,
            };
            let dworld = LargeWorld {
                poses: &daffine[..],
                origin,
            };
            let rigid = bad(b.transformed(&r, method, Rounding::Outward));
            let next_bad = bad(b.transformed(&next[0], method, Rounding::Outward));
            let large_bad = bad(large[0].relative_aabb(&b, origin, method));
            let dlarge_bad = bad(daffine[0].relative_aabb(&b, origin, method));
            let swept = Swept {
                current: &now[..],
                predicted: &next[..],
            };
            let large_swept = Swept {
                current: world,
                predicted: dworld,
            };
            let (b0, f0) = (&b, &fat0);
            repeat(
                &batch,
                margin,
                b0,
                f0,
                &now[..],
                rigid,
                &format!("{what} rigid3"),
            );
            repeat(
                &batch,
                margin,
                b0,
                f0,
                swept,
                rigid || next_bad,
                &format!("{what} swept"),
            );
            repeat(
                &batch,
                margin,
                b0,
                f0,
                world,
                large_bad,
                &format!("{what} large rigid3"),
            );
            repeat(
                &batch,
                margin,
                b0,
                f0,
                dworld,
                dlarge_bad,
                &format!("{what} large daffine3"),
            );
            let both = large_bad || dlarge_bad;
            repeat(
                &batch,
                margin,
                b0,
                f0,
                large_swept,
                both,
                &format!("{what} swept large"),
            );
            // AoSoA blocks, which run the lane loop on every backend.
            let (l8, p8) = (Block8::pack(&[b]), Block8::pack(&now[..]));
            let mut f8 = Block8::pack(&[fat0]);
            let mut moved = Moved::new();
            for _ in 0..2 {
                batch
                    .update(
                        margin,
                        Active::All,
                        &l8[..],
                        &p8[..],
                        &mut f8[..],
                        &mut moved,
                    )
                    .unwrap();
            }
            assert!(
                moved.is_empty() || rigid,
                "{what} rigid3x8: moved again with unchanged poses"
            );
            // 2D: the box's x and y, at a rotation about z.
            let b2 = Aabb2::new(Vec2::new(p.lo[0], p.lo[1]), Vec2::new(p.hi[0], p.hi[1]));
            let mut fat2 = [Aabb2::new(fat0.min.truncate(), fat0.max.truncate())];
            for _ in 0..2 {
                batch
                    .update(
                        margin,
                        Active::All,
                        &[b2][..],
                        &[r2][..],
                        &mut fat2[..],
                        &mut moved,
                    )
                    .unwrap();
            }
            let invalid2 = !b2.transformed(&r2, method, Rounding::Outward).is_valid();
            assert!(
                moved.is_empty() || invalid2,
                "{what} rigid2: moved again with unchanged poses"
            );
        }
    }
});
