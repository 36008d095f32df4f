//! Two tree queries between two meshes (`intersects` and `overlapping_triangles`, compact
//! trees): the descent is generic over the two shapes, so it compiles in the user's crate.
use bvkit::Rigid3;
use bvkit::tree::TriMesh;
use glam::{Quat, Vec3, Vec3A};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let v = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
    let t = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let a = TriMesh::new(v.clone(), t.clone())?;
    let b = TriMesh::new(v, t)?;
    let pb = Rigid3::new(Quat::from_rotation_z(0.5), Vec3A::splat(0.25));
    let hit = a.intersects(Rigid3::IDENTITY, &b, pb)?;
    let pairs = a.overlapping_triangles(Rigid3::IDENTITY, &b, pb)?;
    println!("{hit}, {} pairs", pairs.len());
    Ok(())
}
