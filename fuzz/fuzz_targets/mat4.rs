//! The Mat4 entry points: affine matrices give the Affine3A result, others a clear error;
//! the projective path contains every exactly projected corner or reports w <= 0.
#![no_main]

use bvkit::{Aabb3, Method, Rounding, TransformError};
use bvkit_fuzz::Floats;
use bvkit_fuzz::oracle::Exact;
use glam::{Affine3A, Mat4, Vec3A};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut f = Floats::new(data);
    let mut m = Mat4::from_cols_array(&f.array::<16>());
    if f.byte() % 2 == 0 {
        m = Mat4::from_cols(
            m.x_axis.truncate().extend(0.0),
            m.y_axis.truncate().extend(0.0),
            m.z_axis.truncate().extend(0.0),
            m.w_axis.truncate().extend(1.0),
        );
    }
    let (lo, hi) = (Vec3A::from_array(f.array()), Vec3A::from_array(f.array()));
    let b = Aabb3::new(lo.min(hi), lo.max(hi));
    let affine = m.row(3).to_array() == [0.0, 0.0, 0.0, 1.0];
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let got = b.try_transformed_mat4(&m, method, rounding);
            match got {
                Err(TransformError::NonFiniteMatrix) => assert!(!m.is_finite()),
                Err(TransformError::NotAffine { .. }) => assert!(m.is_finite() && !affine),
                Ok(out) => {
                    assert!(m.is_finite() && affine);
                    let expected = b.transformed(&Affine3A::from_mat4(m), method, rounding);
                    let same = |x: f32, y: f32| x == y || (x.is_nan() && y.is_nan());
                    assert!(
                        (0..3).all(|i| same(out.min[i], expected.min[i])
                            && same(out.max[i], expected.max[i]))
                    );
                }
                Err(e) => panic!("unexpected {e:?}"),
            }
        }
    }
    let rows: [[f32; 4]; 4] = core::array::from_fn(|i| m.row(i).to_array());
    match b.transformed_projective(&m) {
        Ok(out) if b.is_valid() && !b.is_empty() => {
            for corner in b.corners() {
                let p = [corner.x, corner.y, corner.z, 1.0];
                let w = Exact::dot(&rows[3], &p);
                assert!(w > Exact::ZERO, "Ok with a corner at w <= 0");
                for i in 0..3 {
                    let n = Exact::dot(&rows[i], &p);
                    assert!(
                        Exact::face_le_ratio(out.min[i], &n, &w),
                        "min misses a corner"
                    );
                    assert!(
                        Exact::face_ge_ratio(out.max[i], &n, &w),
                        "max misses a corner"
                    );
                }
            }
        }
        Ok(out) => assert!(if b.is_valid() {
            out == Aabb3::EMPTY
        } else {
            !out.is_valid()
        }),
        Err(TransformError::NonPositiveW { corner, .. }) => {
            let c = b.corners()[corner];
            let p = [c.x, c.y, c.z, 1.0];
            let w = Exact::dot(&rows[3], &p).to_f64();
            let magnitude: f64 = rows[3]
                .iter()
                .zip(&p)
                .map(|(a, b)| (f64::from(*a) * f64::from(*b)).abs())
                .sum();
            assert!(w <= 1e-15 * magnitude, "w = {w} was provably positive");
        }
        Err(TransformError::NonFiniteMatrix) => assert!(!m.is_finite()),
        Err(TransformError::UnboundedProjective) => {
            assert!(!(b.min.is_finite() && b.max.is_finite()))
        }
        Err(e) => panic!("unexpected {e:?}"),
    }
});
