//! Inputs, peers and memory rooflines shared by the benches and the trade report; the
//! parry3d peer and the criterion settings with the `peers` feature.
#![allow(dead_code)]

use bvkit::Aabb3;
use glam::{Affine3A, Quat, Vec3, Vec3A};

/// A small deterministic generator (xorshift64*), so inputs need no RNG crate.
pub struct Xorshift(pub u64);

impl Xorshift {
    pub fn next_f32(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40;
        bits as f32 / (1u64 << 24) as f32
    }
    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next_f32()
    }
}

/// `n` local boxes and rigid poses (rotation + translation) of a typical scene.
pub fn scene(n: usize, seed: u64) -> (Vec<Aabb3>, Vec<Affine3A>, Vec<(Quat, Vec3)>) {
    let mut r = Xorshift(seed | 1);
    let mut boxes = Vec::with_capacity(n);
    let mut xfs = Vec::with_capacity(n);
    let mut poses = Vec::with_capacity(n);
    for _ in 0..n {
        let c = Vec3A::new(r.range(-1.0, 1.0), r.range(-1.0, 1.0), r.range(-1.0, 1.0));
        let e = Vec3A::new(r.range(0.1, 2.0), r.range(0.1, 2.0), r.range(0.1, 2.0));
        boxes.push(Aabb3::from_center_half_extents(c, e));
        let axis = Vec3::new(
            r.range(-1.0, 1.0),
            r.range(-1.0, 1.0),
            r.range(-1.0, 1.0) + 2.0,
        )
        .normalize();
        let q = Quat::from_axis_angle(axis, r.range(-3.0, 3.0));
        let t = Vec3::new(
            r.range(-500.0, 500.0),
            r.range(-500.0, 500.0),
            r.range(-500.0, 500.0),
        );
        xfs.push(Affine3A::from_rotation_translation(q, t));
        poses.push((q, t));
    }
    (boxes, xfs, poses)
}

/// The glam 8-corner loop a user would write.
pub fn glam_corners(boxes: &[Aabb3], xfs: &[Affine3A], out: &mut [Aabb3]) {
    for ((b, xf), o) in boxes.iter().zip(xfs).zip(out) {
        let mut min = Vec3A::INFINITY;
        let mut max = Vec3A::NEG_INFINITY;
        for c in b.corners() {
            let p = xf.transform_point3a(c);
            min = min.min(p);
            max = max.max(p);
        }
        *o = Aabb3::new(min, max);
    }
}

/// The glam abs-matrix loop a user would write.
pub fn glam_abs_matrix(boxes: &[Aabb3], xfs: &[Affine3A], out: &mut [Aabb3]) {
    for ((b, xf), o) in boxes.iter().zip(xfs).zip(out) {
        let c = xf.transform_point3a((b.min + b.max) * 0.5);
        let e = (b.max - b.min) * 0.5;
        let m = xf.matrix3;
        let we = m.x_axis.abs() * e.x + m.y_axis.abs() * e.y + m.z_axis.abs() * e.z;
        *o = Aabb3::new(c - we, c + we);
    }
}

/// parry3d's `Aabb::transform_by` over rigid poses.
#[cfg(feature = "peers")]
pub fn parry_transform_by(
    boxes: &[parry3d::bounding_volume::Aabb],
    poses: &[parry3d::math::Pose],
    out: &mut [parry3d::bounding_volume::Aabb],
) {
    for ((b, p), o) in boxes.iter().zip(poses).zip(out) {
        *o = b.transform_by(p);
    }
}

/// The parry3d form of a scene.
#[cfg(feature = "peers")]
pub fn parry_scene(
    boxes: &[Aabb3],
    poses: &[(Quat, Vec3)],
) -> (
    Vec<parry3d::bounding_volume::Aabb>,
    Vec<parry3d::math::Pose>,
) {
    (
        boxes
            .iter()
            .map(|b| parry3d::bounding_volume::Aabb::new(b.min.into(), b.max.into()))
            .collect(),
        poses
            .iter()
            .map(|&(q, t)| parry3d::math::Pose::from_parts(t, q))
            .collect(),
    )
}

/// Memory roofline for SoA columns (6 box columns, 12 transform columns, 6 outputs).
/// Never inlined, like [`roofline_blocks`].
#[inline(never)]
pub fn roofline_soa(boxes: &bvkit::AabbSoa, xfs: &bvkit::Affine3Soa, out: &mut bvkit::AabbSoa) {
    for a in 0..3 {
        let c = &xfs.columns;
        let (c0, c1, c2, t) = (&c[a], &c[3 + a], &c[6 + a], &c[9 + a]);
        let (lo, hi) = (&boxes.columns[a], &boxes.columns[3 + a]);
        let [omin, omax] = out.columns.get_disjoint_mut([a, 3 + a]).expect("distinct");
        for k in 0..lo.len() {
            let m = c0[k] + c1[k] + c2[k] + t[k];
            omin[k] = lo[k] + m;
            omax[k] = hi[k] + m;
        }
    }
}

/// Memory roofline for AoS slices.
/// Never inlined, like [`roofline_blocks`].
#[inline(never)]
pub fn roofline_aos(boxes: &[Aabb3], xfs: &[Affine3A], out: &mut [Aabb3]) {
    for ((b, x), o) in boxes.iter().zip(xfs).zip(out) {
        let m = x.matrix3.x_axis + x.matrix3.y_axis + x.matrix3.z_axis + x.translation;
        *o = Aabb3::new(b.min + m, b.max + m);
    }
}

/// One scene in every transform class: the same boxes, and poses that differ only in what
/// each class can hold (a translation, then a rotation, a uniform scale, a per-axis scale).
pub struct ClassScene {
    pub boxes: Vec<Aabb3>,
    pub translation: Vec<bvkit::Translation3>,
    pub rigid: Vec<bvkit::Rigid3>,
    pub similarity: Vec<bvkit::Similarity3>,
    pub trs: Vec<bvkit::Trs3>,
    /// The scale-rotation-translation poses as glam affine maps (the general class).
    pub affine: Vec<Affine3A>,
    /// The rigid poses, for the peers.
    pub poses: Vec<(Quat, Vec3)>,
}

/// `n` boxes and poses of a typical scene in every class.
pub fn class_scene(n: usize, seed: u64) -> ClassScene {
    let (boxes, _, poses) = scene(n, seed);
    let mut r = Xorshift(seed ^ 0x9e37_79b9_7f4a_7c15 | 1);
    let scales: Vec<Vec3A> = (0..n)
        .map(|_| Vec3A::new(r.range(0.5, 2.0), r.range(0.5, 2.0), r.range(0.5, 2.0)))
        .collect();
    let rigid: Vec<bvkit::Rigid3> = poses.iter().map(|&p| p.into()).collect();
    let trs: Vec<bvkit::Trs3> = rigid
        .iter()
        .zip(&scales)
        .map(|(p, &s)| bvkit::Trs3::new(s, p.rotation, p.translation))
        .collect();
    ClassScene {
        translation: rigid
            .iter()
            .map(|p| bvkit::Translation3(p.translation))
            .collect(),
        similarity: rigid
            .iter()
            .zip(&scales)
            .map(|(p, s)| bvkit::Similarity3::new(s.x, p.rotation, p.translation))
            .collect(),
        affine: trs.iter().map(|&p| p.into()).collect(),
        boxes,
        rigid,
        trs,
        poses,
    }
}

/// The glam loop a user writes for rigid poses: the rotation matrix, then abs-matrix.
pub fn glam_rigid_abs_matrix(boxes: &[Aabb3], poses: &[bvkit::Rigid3], out: &mut [Aabb3]) {
    for ((b, p), o) in boxes.iter().zip(poses).zip(out) {
        let m = glam::Mat3A::from_quat(p.rotation);
        let c = m * ((b.min + b.max) * 0.5) + p.translation;
        let e = (b.max - b.min) * 0.5;
        let we = m.x_axis.abs() * e.x + m.y_axis.abs() * e.y + m.z_axis.abs() * e.z;
        *o = Aabb3::new(c - we, c + we);
    }
}

/// Memory roofline for AoSoA blocks of any class with `F` fields: reads every byte of the
/// boxes and transforms and writes every byte of the output, with one addition per input
/// float.
///
/// Never inlined, like every roofline here: each bench then measures the same code whatever
/// the bench around it inlines (inlined into one build's bench closure, the in-cache AoSoA
/// roofline ran 2.7-4x slower).
#[inline(never)]
pub fn roofline_blocks<const F: usize>(
    boxes: &[[[f32; 8]; 6]],
    xfs: &[[[f32; 8]; F]],
    out: &mut [[[f32; 8]; 6]],
) {
    for ((b, x), o) in boxes.iter().zip(xfs).zip(out) {
        let mut m = [0.0f32; 8];
        for field in x {
            for k in 0..8 {
                m[k] += field[k];
            }
        }
        for n in 0..6 {
            for k in 0..8 {
                o[n][k] = b[n][k] + m[k];
            }
        }
    }
}

/// [`roofline_blocks`] with non-temporal stores: each output block goes to memory through
/// `_mm_stream_ps`, bypassing the caches, then one `_mm_sfence`. The experiment behind the
/// question whether bvkit should stream outputs larger than the last-level cache: a kernel
/// can only gain what this roofline gains over the plain one. Never inlined, like
/// [`roofline_blocks`].
#[cfg(target_arch = "x86_64")]
#[inline(never)]
pub fn roofline_blocks_streaming<const F: usize>(
    boxes: &[[[f32; 8]; 6]],
    xfs: &[[[f32; 8]; F]],
    out: &mut [bvkit::Aabb3x8],
) {
    use std::arch::x86_64::{_mm_loadu_ps, _mm_sfence, _mm_stream_ps};
    for ((b, x), o) in boxes.iter().zip(xfs).zip(out) {
        let mut m = [0.0f32; 8];
        for field in x {
            for k in 0..8 {
                m[k] += field[k];
            }
        }
        for (src, dst) in b.iter().zip(&mut o.fields) {
            let mut face = [0.0f32; 8];
            for k in 0..8 {
                face[k] = src[k] + m[k];
            }
            let dst = dst.as_mut_ptr();
            // SAFETY: SSE is part of the x86-64 baseline; `dst` and `dst + 4` point into
            // one field of `o`, eight floats of a 32-byte-aligned block, so both halves are
            // 16-byte aligned, in bounds and exclusively borrowed; `face` has 8 floats.
            unsafe {
                _mm_stream_ps(dst, _mm_loadu_ps(face.as_ptr()));
                _mm_stream_ps(dst.add(4), _mm_loadu_ps(face.as_ptr().add(4)));
            }
        }
    }
    // SAFETY: a store fence, SSE (baseline): orders the streamed stores before any later
    // store, as the plain roofline's stores are ordered.
    unsafe { _mm_sfence() };
}

/// The fields of AoSoA blocks as plain arrays, for [`roofline_blocks`].
pub fn raw<T, const F: usize>(
    blocks: &[T],
    fields: impl Fn(&T) -> [[f32; 8]; F],
) -> Vec<[[f32; 8]; F]> {
    blocks.iter().map(fields).collect()
}

/// Criterion settings for a group of `n` boxes: fewer, longer samples at DRAM sizes.
#[cfg(feature = "peers")]
pub fn configure(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    n: usize,
) {
    use std::time::Duration;
    if n >= 1 << 20 {
        g.sample_size(10)
            .measurement_time(Duration::from_secs(3))
            .warm_up_time(Duration::from_millis(500));
    } else {
        g.sample_size(30)
            .measurement_time(Duration::from_millis(1500))
            .warm_up_time(Duration::from_millis(300));
    }
}

/// `out[k] = boxes[k].transformed(&xfs[k], method, rounding)` as a user writes it, with
/// the method and rounding as constants at the call (each arm is its own loop). Never
/// inlined, like [`roofline_blocks`]: inlined into one build's bench closure and not into
/// another's, the same loop measured up to 5% apart.
#[inline(never)]
pub fn single_loop<T: bvkit::Transform3>(
    boxes: &[Aabb3],
    xfs: &[T],
    out: &mut [Aabb3],
    method: bvkit::Method,
    rounding: bvkit::Rounding,
) {
    use bvkit::{Method as M, Rounding as R};
    macro_rules! each {
        ($m:expr, $r:expr) => {
            for ((b, xf), o) in boxes.iter().zip(xfs).zip(out) {
                *o = b.transformed(xf, $m, $r);
            }
        };
    }
    match (method, rounding) {
        (M::Naive, R::Nearest) => each!(M::Naive, R::Nearest),
        (M::Naive, R::Outward) => each!(M::Naive, R::Outward),
        (M::AbsMatrix, R::Nearest) => each!(M::AbsMatrix, R::Nearest),
        (M::AbsMatrix, R::Outward) => each!(M::AbsMatrix, R::Outward),
        (M::SignSelect, R::Nearest) => each!(M::SignSelect, R::Nearest),
        (M::SignSelect, R::Outward) => each!(M::SignSelect, R::Outward),
    }
}

/// The CPU every figure comes from: the brand string of `/proc/cpuinfo` (Linux), with the
/// backends bvkit supports on it. Intel and AMD cores differ in what is slow (subnormal
/// operands cost Intel a microcode assist), so no figure is printed without it.
pub fn cpu() -> String {
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| {
            info.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, name)| name.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".to_string());
    format!("{model} (backends {:?})", bvkit::Backend::supported())
}

/// Prints the CPU and the backend a bench runs on, before criterion's output.
pub fn announce(bench: &str) {
    eprintln!(
        "{bench}: CPU {}; best backend {:?}",
        cpu(),
        bvkit::Backend::detect()
    );
}
