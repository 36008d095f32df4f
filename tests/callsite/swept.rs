//! One `Batch::update` with `Swept` poses on AoS slices (continuous collision detection).
use bvkit::{Aabb3, Active, Batch, Margin, Method, Moved, Rigid3, Rounding, Swept};
use glam::{Quat, Vec3, Vec3A};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let local = vec![Aabb3::new(Vec3A::splat(-0.5), Vec3A::splat(0.5)); 1000];
    let now: Vec<Rigid3> = (0..1000)
        .map(|i| (Quat::IDENTITY, Vec3::X * i as f32).into())
        .collect();
    let next: Vec<Rigid3> = (0..1000)
        .map(|i| (Quat::IDENTITY, Vec3::Y + Vec3::X * i as f32).into())
        .collect();
    let mut fat = vec![Aabb3::NAN; 1000];
    let mut moved = Moved::new();
    let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
    let poses = Swept {
        current: &now,
        predicted: &next,
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
