//! Every method and rounding of the 3D similarity kernels, SIMD and scalar, against the
//! contract through the exact oracle: any quaternion and uniform scale.
#![no_main]

use bvkit::{Method, Rounding, Similarity3, Transform3};
use bvkit_fuzz::{Floats, assert_contract, bound_of};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let p = Floats::new(data).quat_problem(Some(true));
    let (b, xf) = (p.aabb(), p.similarity3());
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let bound = bound_of(Similarity3::nearest_order(method), rounding);
            let out = b.transformed(&xf, method, rounding);
            assert_contract(&p, out.min.to_array(), out.max.to_array(), bound, "simd");
            let out = b.transformed_scalar(&xf, method, rounding);
            assert_contract(&p, out.min.to_array(), out.max.to_array(), bound, "scalar");
        }
    }
});
