//! A `#![no_std]` static library over bvkit without `std`: it only has to link (see
//! `Cargo.toml`), so its allocator refuses every request and its panic handler spins.
#![no_std]

extern crate alloc;

use alloc::vec::Vec;
use bvkit::glam::{Quat, Vec3};
use bvkit::{Aabb3, Aabb3x8, Batch, Method, Rigid3, Rigid3x8, Rounding, Sphere};
use core::alloc::{GlobalAlloc, Layout};

/// The world box of `local` under the rigid pose `rotation` (x, y, z, w), `translation`,
/// rounded outward; `false` on a length error.
#[unsafe(no_mangle)]
pub extern "C" fn bvkit_world_boxes(
    local: &[Aabb3; 16],
    poses: &[Rigid3; 16],
    out: &mut [Aabb3; 16],
) -> bool {
    // Through the AoSoA blocks (which allocate) and back.
    let local8: Vec<Aabb3x8> = Aabb3x8::pack(local);
    let poses8: Vec<Rigid3x8> = Rigid3x8::pack(poses);
    let mut world8 = alloc::vec![Aabb3x8::default(); local8.len()];
    let batch = Batch::new(Method::SignSelect, Rounding::Outward);
    if batch.transform(&local8, &poses8, &mut world8).is_err() {
        return false;
    }
    for (k, world) in out.iter_mut().enumerate() {
        *world = world8[k / 8].get(k % 8);
    }
    true
}

/// The smallest enclosing sphere of `points` (the maths that needs libm without `std`).
#[unsafe(no_mangle)]
pub extern "C" fn bvkit_sphere(points: &[Vec3; 8], rotation: &[f32; 4]) -> f32 {
    let q = Quat::from_array(*rotation);
    let turned: Vec<Vec3> = points.iter().map(|&p| q * p).collect();
    Sphere::fit(&turned, bvkit::Fit::Tight).map_or(f32::NAN, |s| s.radius)
}

struct Refuse;

// SAFETY: `alloc` returns null, which `GlobalAlloc` allows (an allocation failure); there
// is never memory to release.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Refuse {
    unsafe fn alloc(&self, _: Layout) -> *mut u8 {
        core::ptr::null_mut()
    }
    unsafe fn dealloc(&self, _: *mut u8, _: Layout) {}
}

#[global_allocator]
static ALLOCATOR: Refuse = Refuse;

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
