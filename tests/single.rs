//! The single-box contract, checked against the exact oracle for every method, rounding,
//! dimension and path (glam SIMD and scalar), over every extreme class.

use bvkit_support::cases;
use bvkit_support::oracle;

use bvkit::{Method, Rigid2, Rounding};
use glam::Vec2;
use proptest::prelude::*;

use cases::{Class, problem, rigid_problem, rng};
use oracle::{Bound, Problem, affine2, affine3, check};

fn check_affine3(p: &Problem<3>) -> Result<(), String> {
    let (b, xf) = affine3(p);
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let paths = [
                ("simd", b.transformed(&xf, method, rounding)),
                ("scalar", b.transformed_scalar(&xf, method, rounding)),
            ];
            for (path, out) in paths {
                check(
                    p,
                    out.min.to_array(),
                    out.max.to_array(),
                    Bound::documented(method, rounding, 3),
                )
                .map_err(|e| format!("{method:?} {rounding:?} {path}: {e}\n{p:?}"))?;
            }
        }
    }
    Ok(())
}

fn check_affine2(p: &Problem<2>) -> Result<(), String> {
    let (b, xf) = affine2(p);
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let out = b.transformed(&xf, method, rounding);
            check(
                p,
                out.min.to_array(),
                out.max.to_array(),
                Bound::documented(method, rounding, 2),
            )
            .map_err(|e| format!("{method:?} {rounding:?}: {e}\n{p:?}"))?;
        }
    }
    Ok(())
}

fn check_rigid2(p: &Problem<2>) -> Result<(), String> {
    let (b, _) = affine2(p);
    let xf = Rigid2::new(p.cols[0][0], p.cols[0][1], Vec2::from_array(p.t));
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let out = b.transformed_rigid(&xf, method, rounding);
            check(
                p,
                out.min.to_array(),
                out.max.to_array(),
                Bound::documented(method, rounding, 2),
            )
            .map_err(|e| format!("{method:?} {rounding:?}: {e}\n{p:?}"))?;
        }
    }
    Ok(())
}

fn class() -> impl Strategy<Value = Class> {
    proptest::sample::select(Class::ALL.to_vec())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 6000, ..ProptestConfig::default() })]

    #[test]
    fn affine3_meets_the_contract(class in class(), seed in any::<u64>()) {
        let p = problem::<3>(class, &mut rng(seed));
        check_affine3(&p).map_err(TestCaseError::fail)?;
    }

    #[test]
    fn affine2_meets_the_contract(class in class(), seed in any::<u64>()) {
        let p = problem::<2>(class, &mut rng(seed));
        check_affine2(&p).map_err(TestCaseError::fail)?;
    }

    #[test]
    fn rigid2_meets_the_contract(class in class(), seed in any::<u64>()) {
        let p = rigid_problem(class, &mut rng(seed));
        check_rigid2(&p).map_err(TestCaseError::fail)?;
    }
}

/// Every class, many seeds each: no class is left to the luck of the class draw.
#[test]
fn every_class_meets_the_contract() {
    for class in Class::ALL {
        for seed in 0..500 {
            let r = &mut rng(seed ^ (class as u64) << 32);
            let result = check_affine3(&problem(class, r))
                .and_then(|()| check_affine2(&problem(class, r)))
                .and_then(|()| check_rigid2(&rigid_problem(class, r)));
            if let Err(e) = result {
                panic!("{class:?} seed {seed}: {e}");
            }
        }
    }
}

/// The certified-f64 shortcut of the oracle agrees with the exact oracle wherever it
/// answers, on results that are right and on results nudged to be wrong.
#[test]
fn certified_oracle_agrees_with_exact() {
    let mut answered = 0;
    for class in Class::ALL {
        for seed in 0..300 {
            let p = problem::<3>(class, &mut rng(seed ^ 0xce57));
            let (b, xf) = affine3(&p);
            for method in Method::ALL {
                for rounding in Rounding::ALL {
                    let out = b.transformed(&xf, method, rounding);
                    let bound = Bound::documented(method, rounding, 3);
                    for nudge in [0, 1, 3] {
                        let min = out
                            .min
                            .to_array()
                            .map(|x| (0..nudge).fold(x, |y, _| y.next_up()));
                        let max = out
                            .max
                            .to_array()
                            .map(|x| (0..nudge).fold(x, |y, _| y.next_down()));
                        let fast = check(&p, min, max, bound);
                        let exact = oracle::check_exact(&p, min, max, bound);
                        assert_eq!(
                            fast.is_ok(),
                            exact.is_ok(),
                            "{p:?} {method:?} {rounding:?} nudge {nudge}"
                        );
                        if let (Ok(f), Ok(e)) = (fast, exact) {
                            answered += 1;
                            assert_eq!(f.contains, e.contains, "{p:?}");
                            assert!(
                                (f.worst_error_us - e.worst_error_us).abs()
                                    <= 1e-6 * e.worst_error_us.max(1.0)
                            );
                        }
                    }
                }
            }
        }
    }
    assert!(
        answered > 10_000,
        "the comparison must have run: {answered}"
    );
}
