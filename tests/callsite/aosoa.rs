//! One `Batch::transform` and one `Batch::update` on AoSoA blocks (`Aabb3x8`, `Rigid3x8`),
//! the layout the README recommends for the update.
use bvkit::{
    Aabb3, Aabb3x8, Active, Batch, Block8, Margin, Method, Moved, Rigid3, Rigid3x8, Rounding,
};
use glam::{Quat, Vec3, Vec3A};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let local = vec![Aabb3::new(Vec3A::splat(-0.5), Vec3A::splat(0.5)); 1000];
    let poses: Vec<Rigid3> = (0..1000)
        .map(|i| (Quat::IDENTITY, Vec3::X * i as f32).into())
        .collect();
    let (local, poses): (Vec<Aabb3x8>, Vec<Rigid3x8>) =
        (Block8::pack(&local), Block8::pack(&poses));
    let mut world = vec![Aabb3x8::default(); local.len()];
    let mut fat = vec![Block8::splat(Aabb3::NAN); local.len()];
    let mut moved = Moved::new();
    let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
    batch.transform(&local, &poses, &mut world)?;
    batch.update(
        Margin::new(0.05, 0.1),
        Active::All,
        &local,
        &poses,
        &mut fat,
        &mut moved,
    )?;
    println!("{} moved; {:?}", moved.len(), world[7].get(3));
    Ok(())
}
