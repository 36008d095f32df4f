//! One `Batch::transform` on SoA columns (`AabbSoa`, `Rigid3Soa`).
use bvkit::{Aabb3, AabbSoa, Batch, Method, Rigid3, Rigid3Soa, Rounding};
use glam::{Quat, Vec3, Vec3A};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let local = AabbSoa::filled(1000, Aabb3::new(Vec3A::splat(-0.5), Vec3A::splat(0.5)));
    let poses: Vec<Rigid3> = (0..1000)
        .map(|i| (Quat::IDENTITY, Vec3::X * i as f32).into())
        .collect();
    let poses = Rigid3Soa::from_slice(&poses);
    let mut world = AabbSoa::filled(1000, Aabb3::EMPTY);
    Batch::new(Method::AbsMatrix, Rounding::Outward).transform(&local, &poses, &mut world)?;
    println!("{:?}", world.get(7));
    Ok(())
}
