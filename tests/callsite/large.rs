//! One `Batch::update` with `LargeWorld` poses (`f64` positions, boxes relative to an origin).
use bvkit::{Aabb3, Active, Batch, LargeRigid3, LargeWorld, Margin, Method, Moved, Rounding};
use glam::{DVec3, Quat, Vec3A};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let local = vec![Aabb3::new(Vec3A::splat(-0.5), Vec3A::splat(0.5)); 1000];
    let poses: Vec<LargeRigid3> = (0..1000)
        .map(|i| LargeRigid3::new(Quat::IDENTITY, DVec3::X * (1e9 + i as f64)))
        .collect();
    let mut fat = vec![Aabb3::NAN; 1000];
    let mut moved = Moved::new();
    let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
    let poses = LargeWorld {
        poses: &poses,
        origin: DVec3::X * 1e9,
    };
    batch.update(
        Margin::new(0.05, 0.1),
        Active::All,
        &local,
        poses,
        &mut fat,
        &mut moved,
    )?;
    println!("{} moved; {:?}", moved.len(), fat[7]);
    Ok(())
}
