//! Every method and rounding of the 3D single-box kernels, SIMD and scalar, against the
//! contract: Outward contains the exact box, Nearest within its bound, EMPTY stays EMPTY,
//! NaN gives an invalid box, overflow gives ±inf and never NaN.
#![no_main]

use bvkit::{Method, Rounding};
use bvkit_fuzz::{Floats, affine3, assert_contract, bound};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let p = Floats::new(data).problem::<3>();
    let (b, xf) = affine3(&p);
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let bound = bound(method, rounding, 3);
            let out = b.transformed(&xf, method, rounding);
            assert_contract(&p, out.min.to_array(), out.max.to_array(), bound, "simd");
            let out = b.transformed_scalar(&xf, method, rounding);
            assert_contract(&p, out.min.to_array(), out.max.to_array(), bound, "scalar");
        }
    }
});
