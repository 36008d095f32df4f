//! Backends and run-time dispatch.
//!
//! A batch job is written once, generic over a lane type ([`Job::run`]). Dispatch picks the
//! lane type for the chosen [`Backend`] and, for AVX2+FMA and AVX-512, instantiates the job
//! inside a `#[target_feature]` wrapper so that the lane code is compiled for those
//! instructions, although the crate itself is built for the baseline target. The best
//! backend of the running CPU is detected once and cached. Without the `std` feature there
//! is no run-time detection: a backend is supported when the build's target features
//! guarantee it (`-C target-cpu=…` or `-C target-feature=+avx2,+fma`).

mod group;
mod lanes;

use alloc::vec::Vec;

pub(crate) use group::BoxGroup;
#[cfg(target_arch = "x86_64")]
use lanes::Avx8;
#[cfg(any(test, not(all(target_arch = "x86_64", not(target_feature = "fma")))))]
pub(crate) use lanes::F32s;
pub(crate) use lanes::LaneArray;

/// A code path for the batch kernels.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Backend {
    /// One box at a time in plain `f32`: the reference every other backend is tested against.
    Scalar,
    /// Portable lanes of 8, compiled for the build's baseline (SSE2 on x86-64, NEON on
    /// aarch64), never fused: on x86-64 built without FMA these are [`Backend::Wide`]'s
    /// lanes, which do not fuse there; elsewhere plain arrays that LLVM vectorises.
    Baseline,
    /// 8 lanes in one 256-bit AVX register, compiled for AVX2 with FMA, chosen at run time
    /// (x86-64).
    Avx2,
    /// AVX-512F with AVX2 and FMA, chosen at run time (x86-64): the AoS loop runs four boxes
    /// per 512-bit register, and the lane loop runs [`Backend::Avx2`]'s 8 lanes, faster than
    /// 16 lanes of plain arrays (`docs/decisions.md`, "AVX-512's lane loop on 8 lanes").
    Avx512,
    /// `wide::f32x8`: its instructions fixed at compile time by the build's target
    /// features (two SSE halves on a default x86-64 build, AVX with `target-cpu=native`).
    Wide,
}

impl Backend {
    /// Every backend, in order of preference from the least to the most capable.
    pub const ALL: [Backend; 5] = [
        Backend::Scalar,
        Backend::Wide,
        Backend::Baseline,
        Backend::Avx2,
        Backend::Avx512,
    ];

    /// True when the running CPU can execute this backend: detected at run time with the
    /// `std` feature, and without it true only when the build's target features guarantee
    /// the instructions.
    #[must_use]
    pub fn is_supported(self) -> bool {
        self.features().iter().all(|&f| has_feature(f))
    }

    /// The CPU features this backend's code is compiled with (the `#[target_feature]` set
    /// of its dispatch wrapper): the CPU must have every one of them.
    pub(crate) const fn features(self) -> &'static [&'static str] {
        match self {
            Backend::Scalar | Backend::Baseline | Backend::Wide => &[],
            Backend::Avx2 => &["avx2", "fma"],
            Backend::Avx512 => &["avx512f", "avx2", "fma"],
        }
    }

    /// The backends the running CPU supports, from the least to the most capable.
    #[must_use]
    pub fn supported() -> Vec<Backend> {
        Backend::ALL
            .into_iter()
            .filter(|b| b.is_supported())
            .collect()
    }

    /// The fastest supported backend, detected on first use and cached (without `std`:
    /// the fastest the build's target features guarantee).
    #[must_use]
    pub fn detect() -> Backend {
        let fastest = || {
            [Backend::Avx512, Backend::Avx2, Backend::Baseline]
                .into_iter()
                .find(|b| b.is_supported())
                .unwrap_or(Backend::Scalar)
        };
        #[cfg(feature = "std")]
        {
            static DETECTED: std::sync::OnceLock<Backend> = std::sync::OnceLock::new();
            *DETECTED.get_or_init(fastest)
        }
        #[cfg(not(feature = "std"))]
        fastest()
    }

    /// Boxes per lane vector: the width of the engine's spans.
    #[must_use]
    pub const fn lanes(self) -> usize {
        match self {
            Backend::Scalar => 1,
            Backend::Baseline | Backend::Avx2 | Backend::Avx512 | Backend::Wide => 8,
        }
    }

    /// A short lower-case name, for tables.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Backend::Scalar => "scalar",
            Backend::Baseline => "baseline",
            Backend::Avx2 => "avx2",
            Backend::Avx512 => "avx512",
            Backend::Wide => "wide",
        }
    }
}

/// True when the running CPU has `feature` (one of [`Backend::features`]): detected at run
/// time with the `std` feature, and without it only when the build guarantees it.
fn has_feature(feature: &str) -> bool {
    #[cfg(all(target_arch = "x86_64", feature = "std"))]
    return match feature {
        "avx2" => std::arch::is_x86_feature_detected!("avx2"),
        "avx512f" => std::arch::is_x86_feature_detected!("avx512f"),
        "fma" => std::arch::is_x86_feature_detected!("fma"),
        _ => false,
    };
    #[cfg(all(target_arch = "x86_64", not(feature = "std")))]
    return match feature {
        "avx2" => cfg!(target_feature = "avx2"),
        "avx512f" => cfg!(target_feature = "avx512f"),
        "fma" => cfg!(target_feature = "fma"),
        _ => false,
    };
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = feature;
        false
    }
}

/// A batch job, written once over a lane type.
pub(crate) trait Job {
    /// Runs the job with lanes `L`; implementations are `#[inline(always)]` so that they
    /// compile for the target features of the dispatch wrapper that calls them.
    fn run<L: LaneArray>(self);
}

/// Runs `job` on `backend`, which the caller has checked is supported; `fused` lets the
/// AVX2 and AVX-512 lanes fuse multiply-adds (with the `std` feature only). Unfused, every
/// backend does the same arithmetic as the scalar reference (`wide` then runs the baseline
/// lanes, since its fusing is fixed at compile time).
#[allow(unsafe_code)] // the one place: calling the `#[target_feature]` wrappers
pub(crate) fn dispatch<J: Job>(backend: Backend, fused: bool, job: J) {
    debug_assert!(backend.is_supported());
    // Without `std` the fused lanes would call libm's software `fmaf`: `core` has no fused
    // multiply-add to compile to. Every backend then runs unfused, as in deterministic mode.
    let fused = fused && cfg!(feature = "std");
    match (backend, fused) {
        (Backend::Scalar, _) => job.run::<f32>(),
        // `wide` fuses exactly where FMA is enabled at compile time (on x86-64): without
        // it, its lanes are the baseline's too, and one copy of the loop serves both. The
        // plain arrays, whose code LLVM's vectoriser builds, then are not compiled as a
        // loop at all: that copy was more than half of a call site's release rebuild, and
        // both are SSE2 code on the same vectors (`docs/decisions.md`, "One baseline loop
        // without FMA").
        #[cfg(all(target_arch = "x86_64", not(target_feature = "fma")))]
        (Backend::Baseline | Backend::Wide, _) => job.run::<wide::f32x8>(),
        #[cfg(not(all(target_arch = "x86_64", not(target_feature = "fma"))))]
        (Backend::Baseline, _) | (Backend::Wide, false) => job.run::<F32s<8, false>>(),
        #[cfg(not(all(target_arch = "x86_64", not(target_feature = "fma"))))]
        (Backend::Wide, true) => job.run::<wide::f32x8>(),
        // The AVX-512 backend runs the AVX2 lanes here: its own width is in the AoS loop
        // (`dispatch_groups`).
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the caller checked that `backend` is supported: the CPU has every feature
        // of `Backend::Avx2.features()`, the set `run_avx2` enables (those of
        // `Backend::Avx512.features()` include them).
        (Backend::Avx2 | Backend::Avx512, true) => unsafe { run_avx2::<J, Avx8<true>>(job) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        (Backend::Avx2 | Backend::Avx512, false) => unsafe { run_avx2::<J, Avx8<false>>(job) },
        #[cfg(not(target_arch = "x86_64"))]
        (Backend::Avx2 | Backend::Avx512, _) => job.run::<F32s<8, false>>(),
    }
}

/// A job over AoS 3D boxes, written once over a [`BoxGroup`] of `W` boxes per vector.
pub(crate) trait GroupJob {
    /// Runs the job with groups `P`; `#[inline(always)]`, as for [`Job::run`].
    fn run<const W: usize, P: BoxGroup<W>>(self);
}

/// Runs `job` on `backend`, which the caller has checked is supported: four boxes per
/// AVX-512 register on the AVX-512 backend, two per AVX register on the AVX2 backend, two
/// SSE registers elsewhere. The arithmetic is `Vec3A`'s in each, so every backend gives
/// the same bits.
#[allow(unsafe_code)] // calling the `#[target_feature]` wrappers
pub(crate) fn dispatch_groups<J: GroupJob>(backend: Backend, job: J) {
    debug_assert!(backend.is_supported());
    match backend {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the caller checked that `backend` is supported: the CPU has every feature
        // of `Backend::Avx2.features()`, the set `run_avx2_pairs` enables.
        Backend::Avx2 => unsafe { run_avx2_pairs(job) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above, with `Backend::Avx512.features()` and `run_avx512_quads`.
        Backend::Avx512 => unsafe { run_avx512_quads(job) },
        _ => job.run::<2, group::Two>(),
    }
}

// Each `#[target_feature]` wrapper lives in a module of its own: rustc compiles each module's
// instances in a codegen unit of its own, so that the wrappers' loops (most of the library's
// code) are optimised on several cores rather than one after another in a single unit.

#[cfg(target_arch = "x86_64")]
use {avx2::run_avx2, pairs::run_avx2_pairs, quads::run_avx512_quads};

#[cfg(target_arch = "x86_64")]
mod pairs {
    use super::{GroupJob, group};

    // The features enabled here are those of `Backend::Avx2.features()` (a test checks they
    // agree).
    #[target_feature(enable = "avx2,fma")]
    pub(super) fn run_avx2_pairs<J: GroupJob>(job: J) {
        job.run::<2, group::AvxPair>();
    }
}

#[cfg(target_arch = "x86_64")]
mod quads {
    use super::{GroupJob, group};

    // The features enabled here are those of `Backend::Avx512.features()` (a test checks
    // they agree).
    #[target_feature(enable = "avx512f,avx2,fma")]
    pub(super) fn run_avx512_quads<J: GroupJob>(job: J) {
        job.run::<4, group::Avx512Quad>();
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{Job, LaneArray};

    // The features enabled here are `Backend::Avx2.features()` (a test checks they agree).
    #[target_feature(enable = "avx2,fma")]
    pub(super) fn run_avx2<J: Job, L: LaneArray>(job: J) {
        job.run::<L>();
    }
}

/// A job that ignores the lane type: plain array code, compiled with the features of the
/// backend's dispatch wrapper; it leaves its result in `out`.
struct Plain<'a, T, F: FnOnce() -> T> {
    f: F,
    out: &'a mut T,
}

impl<T, F: FnOnce() -> T> Job for Plain<'_, T, F> {
    #[inline(always)]
    fn run<L: LaneArray>(self) {
        *self.out = (self.f)();
    }
}

/// Runs plain array code `f` inside the dispatch wrapper of the running CPU's best backend
/// ([`Backend::detect`]), unfused, so that its loops vectorise for that backend's
/// instructions and give the same bits on every backend. `f` keeps its state in locals that
/// it returns: conditional writes through captured references do not vectorise.
#[inline(always)]
pub(crate) fn plain<T: Default>(f: impl FnOnce() -> T) -> T {
    let mut out = T::default();
    dispatch(Backend::detect(), false, Plain { f, out: &mut out });
    out
}

/// Orders every non-temporal store before the stores that follow ([`LaneArray::store_streaming`]
/// is weakly ordered): the last step of a batch that streamed its output.
#[inline(always)]
pub(crate) fn store_fence() {
    #[cfg(target_arch = "x86_64")]
    #[allow(unsafe_code)]
    // SAFETY: `_mm_sfence` only orders stores; its requirement, SSE, is part of the x86-64
    // baseline.
    unsafe {
        core::arch::x86_64::_mm_sfence();
    }
}

/// Asks the CPU to start loading the cache line of `x`: a hint, with no effect on any
/// result. Scattered updates issue it a few objects ahead, since their kernels are too long
/// for the out-of-order window to overlap more than one or two cache misses.
#[inline(always)]
pub(crate) fn prefetch<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    #[allow(unsafe_code)]
    // SAFETY: `_mm_prefetch` reads nothing and never faults, whatever the address (here a
    // live reference); its only requirement, SSE, is part of the x86-64 baseline.
    unsafe {
        core::arch::x86_64::_mm_prefetch::<{ core::arch::x86_64::_MM_HINT_T0 }>(
            (x as *const T).cast(),
        );
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}

/// Four vectors as three lanes of coordinates: `[x, y, z]`, lane `l` of each from `v[l]`.
/// On x86-64 a 4×4 transpose in registers (unpacks and moves); built lane by lane, the
/// vectors would go through memory and their loads wait on the stores.
#[inline(always)]
pub(crate) fn transpose3(v: [glam::Vec3A; 4]) -> [glam::Vec4; 3] {
    let [a, b, c, d] = v;
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{
            __m128, _mm_movehl_ps, _mm_movelh_ps, _mm_unpackhi_ps, _mm_unpacklo_ps,
        };
        let (a, b, c, d) = (
            __m128::from(a),
            __m128::from(b),
            __m128::from(c),
            __m128::from(d),
        );
        #[allow(unsafe_code)]
        // SAFETY: the unpacks and moves need only SSE, part of the x86-64 baseline; they
        // read and write registers, nothing else.
        unsafe {
            let (ab_lo, cd_lo) = (_mm_unpacklo_ps(a, b), _mm_unpacklo_ps(c, d));
            let (ab_hi, cd_hi) = (_mm_unpackhi_ps(a, b), _mm_unpackhi_ps(c, d));
            [
                _mm_movelh_ps(ab_lo, cd_lo).into(),
                _mm_movehl_ps(cd_lo, ab_lo).into(),
                _mm_movelh_ps(ab_hi, cd_hi).into(),
            ]
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    [
        glam::Vec4::new(a.x, b.x, c.x, d.x),
        glam::Vec4::new(a.y, b.y, c.y, d.y),
        glam::Vec4::new(a.z, b.z, c.z, d.z),
    ]
}

/// Two boxes on a 16-bit grid, `q = [c₀, e₀, c₁, e₁]` (three values each; centers signed,
/// stored as their bits, extents unsigned), as `[(c₀, e₀), (c₁, e₁)]` in grid steps,
/// converted exactly to `f32` (the `w` lanes unspecified). On x86-64 four 8-byte loads and
/// SSE2 unpacks; value by value, the vectors would go through memory.
#[inline(always)]
pub(crate) fn grid_pair(q: &[u16; 12]) -> [(glam::Vec3A, glam::Vec3A); 2] {
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{
            __m128i, _mm_cvtepi32_ps, _mm_loadl_epi64, _mm_setzero_si128, _mm_srai_epi32,
            _mm_srli_si128, _mm_unpacklo_epi16,
        };
        #[allow(unsafe_code)]
        // SAFETY: the four loads read `q[0..4]`, `q[3..7]`, `q[6..10]` and `q[8..12]`, all
        // within the live reference (unaligned loads); the rest needs only SSE2, part of
        // the x86-64 baseline.
        unsafe {
            let p = q.as_ptr();
            let at = |k: usize| _mm_loadl_epi64(p.add(k).cast::<__m128i>());
            // Sign extension: each value in the top half of a 32-bit lane, shifted down
            // arithmetically; zero extension: interleaved with zeros.
            let signed = |v: __m128i| {
                glam::Vec3A::from(_mm_cvtepi32_ps(_mm_srai_epi32::<16>(_mm_unpacklo_epi16(
                    v, v,
                ))))
            };
            let unsigned = |v: __m128i| {
                glam::Vec3A::from(_mm_cvtepi32_ps(_mm_unpacklo_epi16(v, _mm_setzero_si128())))
            };
            [
                (signed(at(0)), unsigned(at(3))),
                (signed(at(6)), unsigned(_mm_srli_si128::<2>(at(8)))),
            ]
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let signed = |k: usize| {
            glam::Vec3A::new(
                f32::from(q[k] as i16),
                f32::from(q[k + 1] as i16),
                f32::from(q[k + 2] as i16),
            )
        };
        let unsigned =
            |k: usize| glam::Vec3A::new(f32::from(q[k]), f32::from(q[k + 1]), f32::from(q[k + 2]));
        [(signed(0), unsigned(3)), (signed(6), unsigned(9))]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each dispatch wrapper enables exactly the features its backend checks for: a
    /// backend enabled on a CPU that lacks one of them would run illegal instructions.
    #[test]
    fn backends_check_every_feature_their_code_enables() {
        let source = include_str!("mod.rs");
        for (backend, wrapper) in [
            (Backend::Avx2, "run_avx2"),
            (Backend::Avx2, "run_avx2_pairs"),
            (Backend::Avx512, "run_avx512_quads"),
        ] {
            let at = source
                .find(&alloc::format!("fn {wrapper}<"))
                .expect("the wrapper");
            let attribute = "#[target_feature(enable = \"";
            let start = source[..at].rfind(attribute).expect("its attribute") + attribute.len();
            let enabled = source[start..].split('"').next().unwrap_or_default();
            let mut enabled: Vec<&str> = enabled.split(',').collect();
            let mut checked = backend.features().to_vec();
            enabled.sort_unstable();
            checked.sort_unstable();
            assert_eq!(enabled, checked, "{backend:?}");
        }
        for backend in [Backend::Scalar, Backend::Baseline, Backend::Wide] {
            assert!(backend.features().is_empty() && backend.is_supported());
        }
    }
}
