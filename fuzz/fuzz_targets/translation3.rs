//! Every method and rounding of the 3D translation kernels, SIMD and scalar, against the
//! contract through the exact oracle (the methods coincide).
#![no_main]

use bvkit::{Method, Rounding, Transform3, Translation3};
use bvkit_fuzz::{Floats, assert_contract, bound_of};
use glam::Vec3A;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let p = Floats::new(data).translation_problem::<3>();
    let (b, xf) = (
        bvkit_fuzz::affine3(&p).0,
        Translation3(Vec3A::from_array(p.t)),
    );
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let bound = bound_of(Translation3::nearest_order(method), rounding);
            let out = b.transformed(&xf, method, rounding);
            assert_contract(&p, out.min.to_array(), out.max.to_array(), bound, "simd");
            let out = b.transformed_scalar(&xf, method, rounding);
            assert_contract(&p, out.min.to_array(), out.max.to_array(), bound, "scalar");
        }
    }
});
