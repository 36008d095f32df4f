//! Every method and rounding of the 2D affine single-box kernels against the contract.
#![no_main]

use bvkit::{Method, Rounding};
use bvkit_fuzz::{Floats, affine2, assert_contract, bound};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let p = Floats::new(data).problem::<2>();
    let (b, xf) = affine2(&p);
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let out = b.transformed(&xf, method, rounding);
            let what = format!("{method:?} {rounding:?}");
            assert_contract(
                &p,
                out.min.to_array(),
                out.max.to_array(),
                bound(method, rounding, 2),
                &what,
            );
        }
    }
});
