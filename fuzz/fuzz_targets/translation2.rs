//! Every method and rounding of the 2D translation kernel (the methods coincide) against
//! the contract through the exact oracle.
#![no_main]

use bvkit::{Method, Rounding, Transform2, Translation2};
use bvkit_fuzz::{Floats, affine2, assert_contract, bound_of};
use glam::Vec2;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let p = Floats::new(data).translation_problem::<2>();
    let (b, xf) = (affine2(&p).0, Translation2(Vec2::from_array(p.t)));
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let bound = bound_of(Translation2::nearest_order(method), rounding);
            let out = b.transformed(&xf, method, rounding);
            assert_contract(&p, out.min.to_array(), out.max.to_array(), bound, "single");
        }
    }
});
