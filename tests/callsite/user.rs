//! One `Batch::transform` and one `Batch::update` call on AoS slices of `Rigid3`, and the
//! broadphase tree fed by the update (the README's call sequence).
use bvkit::broadphase::{DynamicTree, Pairs};
use bvkit::{Aabb3, Active, Batch, Margin, Method, Moved, Rigid3, Rounding};
use glam::{Quat, Vec3, Vec3A};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let local = vec![Aabb3::new(Vec3A::splat(-0.5), Vec3A::splat(0.5)); 1000];
    let mut poses: Vec<Rigid3> = (0..1000)
        .map(|i| (Quat::IDENTITY, Vec3::X * i as f32).into())
        .collect();
    let mut world = vec![Aabb3::EMPTY; 1000];
    let mut fat = vec![Aabb3::NAN; 1000];
    let mut moved = Moved::new();
    let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
    batch.transform(&local, &poses, &mut world)?;
    poses[7].rotation = Quat::from_rotation_z(0.8);
    let margin = Margin::new(0.05, 0.1);
    batch.update(margin, Active::All, &local, &poses, &mut fat, &mut moved)?;
    let mut tree = DynamicTree::from_boxes(&fat)?;
    let mut pairs = Pairs::new();
    tree.update(moved.indices(), &fat, &mut pairs)?;
    println!(
        "{} moved, {} pairs; {:?}",
        moved.len(),
        pairs.begun.len(),
        world[7]
    );
    Ok(())
}
