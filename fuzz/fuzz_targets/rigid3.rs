//! Every method and rounding of the rigid 3D (quaternion) kernels, SIMD and scalar, against the
//! contract through the exact oracle: any quaternion, unit or not.
#![no_main]

use bvkit::{Method, Rigid3, Rounding, Transform3};
use bvkit_fuzz::{Floats, assert_contract, bound_of};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let p = Floats::new(data).quat_problem(None);
    let (b, xf) = (p.aabb(), p.rigid3());
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let bound = bound_of(Rigid3::nearest_order(method), rounding);
            let out = b.transformed(&xf, method, rounding);
            assert_contract(&p, out.min.to_array(), out.max.to_array(), bound, "simd");
            let out = b.transformed_scalar(&xf, method, rounding);
            assert_contract(&p, out.min.to_array(), out.max.to_array(), bound, "scalar");
        }
    }
});
