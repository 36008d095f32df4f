//! Every method and rounding of the 2D rigid kernels (Eberly's sign branch included)
//! against the contract of the matrix `[[cos, -sin], [sin, cos]]`.
#![no_main]

use bvkit::{Method, Rounding};
use bvkit_fuzz::{Floats, assert_contract, bound, rigid2};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (p, b, xf) = rigid2(&Floats::new(data).problem::<2>());
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let out = b.transformed_rigid(&xf, method, rounding);
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
