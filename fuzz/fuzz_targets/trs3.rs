//! Every method and rounding of the scale-rotation-translation kernels, SIMD and scalar, against the
//! contract through the exact oracle: any quaternion and per-axis scale.
#![no_main]

use bvkit::{Method, Rounding, Transform3, Trs3};
use bvkit_fuzz::{Floats, assert_contract, bound_of};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let p = Floats::new(data).quat_problem(Some(false));
    let (b, xf) = (p.aabb(), p.trs3());
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let bound = bound_of(Trs3::nearest_order(method), rounding);
            let out = b.transformed(&xf, method, rounding);
            assert_contract(&p, out.min.to_array(), out.max.to_array(), bound, "simd");
            let out = b.transformed_scalar(&xf, method, rounding);
            assert_contract(&p, out.min.to_array(), out.max.to_array(), bound, "scalar");
        }
    }
});
