//! Exact separating-axis tests in dyadic arithmetic (every finite `f64` is `m·2^e`; sums and
//! products stay dyadic): a box against a box placed by an `f64` affine map, and two
//! triangles. Shared by `tests/trees.rs` and the `tree` fuzz target.
//!
//! The crate's fixed-point oracle (`support/src/oracle.rs`) stops at products of four `f32` values;
//! the relative map here is an `f64` matrix and the cross axes are products of three of its
//! entries, so this module carries its own exponent.
#![allow(dead_code)]

use std::cmp::Ordering;

use bvkit::Aabb3;
use glam::{DMat3, DVec3};
use num_bigint::BigInt;
use num_traits::{Signed, Zero};

#[derive(Clone, Debug)]
pub struct Dy {
    m: BigInt,
    e: i32,
}

impl Dy {
    pub fn of(x: f64) -> Dy {
        assert!(x.is_finite());
        if x == 0.0 {
            return Dy {
                m: BigInt::zero(),
                e: 0,
            };
        }
        let bits = x.to_bits();
        let biased = ((bits >> 52) & 0x7ff) as i32;
        let frac = (bits & ((1u64 << 52) - 1)) as i64;
        let (s, e) = if biased == 0 {
            (frac, -1074)
        } else {
            (frac | (1i64 << 52), biased - 1075)
        };
        Dy {
            m: BigInt::from(if x < 0.0 { -s } else { s }),
            e,
        }
    }
    pub fn mul(&self, o: &Dy) -> Dy {
        Dy {
            m: &self.m * &o.m,
            e: self.e + o.e,
        }
    }
    pub fn add(&self, o: &Dy) -> Dy {
        let e = self.e.min(o.e);
        Dy {
            m: (&self.m << (self.e - e) as usize) + (&o.m << (o.e - e) as usize),
            e,
        }
    }
    pub fn neg(&self) -> Dy {
        Dy {
            m: -&self.m,
            e: self.e,
        }
    }
    pub fn sub(&self, o: &Dy) -> Dy {
        self.add(&o.neg())
    }
    pub fn cmp(&self, o: &Dy) -> Ordering {
        let d = self.sub(o);
        if d.m.is_zero() {
            Ordering::Equal
        } else if d.m.is_positive() {
            Ordering::Greater
        } else {
            Ordering::Less
        }
    }
    pub fn min(self, o: Dy) -> Dy {
        if self.cmp(&o) == Ordering::Greater {
            o
        } else {
            self
        }
    }
    pub fn max(self, o: Dy) -> Dy {
        if self.cmp(&o) == Ordering::Less {
            o
        } else {
            self
        }
    }
    pub fn is_zero(&self) -> bool {
        self.m.is_zero()
    }
}

pub type V3 = [Dy; 3];

pub fn v3(v: DVec3) -> V3 {
    [Dy::of(v.x), Dy::of(v.y), Dy::of(v.z)]
}

pub fn cross(a: &V3, b: &V3) -> V3 {
    [
        a[1].mul(&b[2]).sub(&a[2].mul(&b[1])),
        a[2].mul(&b[0]).sub(&a[0].mul(&b[2])),
        a[0].mul(&b[1]).sub(&a[1].mul(&b[0])),
    ]
}

pub fn dot(a: &V3, b: &V3) -> Dy {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}

/// The exact projection interval of the box `[lo, hi]` on `l`.
pub fn project_box(l: &V3, lo: &V3, hi: &V3) -> (Dy, Dy) {
    let mut a = Dy::of(0.0);
    let mut b = Dy::of(0.0);
    for k in 0..3 {
        let (p, q) = (l[k].mul(&lo[k]), l[k].mul(&hi[k]));
        a = a.add(&p.clone().min(q.clone()));
        b = b.add(&p.max(q));
    }
    (a, b)
}

/// Exact: do the box `a` (in A's frame) and the box `b` placed by `y ↦ M·y + t` share a
/// point? Separating axes of a box and a parallelepiped: A's 3 face normals, the 3
/// cofactor normals `M_k × M_l`, and the 9 crosses `e_i × M_j` (complete, degenerate boxes
/// included; a zero axis never separates and is skipped).
pub fn exact_overlap(a: &Aabb3, b: &Aabb3, m: DMat3, t: DVec3) -> bool {
    let (alo, ahi) = (v3(a.min.as_dvec3()), v3(a.max.as_dvec3()));
    let (blo, bhi) = (v3(b.min.as_dvec3()), v3(b.max.as_dvec3()));
    let cols = [v3(m.x_axis), v3(m.y_axis), v3(m.z_axis)];
    let tt = v3(t);
    let unit =
        |i: usize| -> V3 { core::array::from_fn(|k| Dy::of(if k == i { 1.0 } else { 0.0 })) };
    let mut axes: Vec<V3> = (0..3).map(unit).collect();
    axes.push(cross(&cols[1], &cols[2]));
    axes.push(cross(&cols[2], &cols[0]));
    axes.push(cross(&cols[0], &cols[1]));
    for i in 0..3 {
        for c in &cols {
            axes.push(cross(&unit(i), c));
        }
    }
    for l in axes {
        if l.iter().all(Dy::is_zero) {
            continue;
        }
        let (a0, a1) = project_box(&l, &alo, &ahi);
        // l·(M y + t) = (Mᵀ l)·y + l·t
        let mtl: V3 = core::array::from_fn(|j| dot(&cols[j], &l));
        let (b0, b1) = project_box(&mtl, &blo, &bhi);
        let lt = dot(&l, &tt);
        let (b0, b1) = (b0.add(&lt), b1.add(&lt));
        if a1.cmp(&b0) == Ordering::Less || b1.cmp(&a0) == Ordering::Less {
            return false;
        }
    }
    true
}

/// Exact separating-axis reference for two non-degenerate triangles: both normals, the 9
/// edge crosses and the 6 in-plane edge normals (complete for non-degenerate triangles,
/// coplanar ones included); touching is intersecting.
pub fn exact_triangles(a: &[DVec3; 3], b: &[DVec3; 3]) -> bool {
    let (a, b) = (a.map(v3), b.map(v3));
    let edges = |t: &[V3; 3]| -> [V3; 3] {
        core::array::from_fn(|i| {
            let (p, q) = (&t[i], &t[(i + 1) % 3]);
            core::array::from_fn(|k| q[k].sub(&p[k]))
        })
    };
    let (ea, eb) = (edges(&a), edges(&b));
    let (na, nb) = (cross(&ea[0], &ea[1]), cross(&eb[0], &eb[1]));
    let mut axes = vec![na.clone(), nb.clone()];
    for e in &ea {
        for f in &eb {
            axes.push(cross(e, f));
        }
        axes.push(cross(&na, e));
    }
    for f in &eb {
        axes.push(cross(&nb, f));
    }
    for l in axes {
        if l.iter().all(Dy::is_zero) {
            continue;
        }
        let pa: Vec<Dy> = a.iter().map(|p| dot(&l, p)).collect();
        let pb: Vec<Dy> = b.iter().map(|p| dot(&l, p)).collect();
        let (a0, a1) = (
            pa.iter().cloned().reduce(Dy::min).unwrap(),
            pa.iter().cloned().reduce(Dy::max).unwrap(),
        );
        let (b0, b1) = (
            pb.iter().cloned().reduce(Dy::min).unwrap(),
            pb.iter().cloned().reduce(Dy::max).unwrap(),
        );
        if a1.cmp(&b0) == Ordering::Less || b1.cmp(&a0) == Ordering::Less {
            return false;
        }
    }
    true
}
