//! One `Batch::transform` on 2D AoS slices (`Aabb2`, `Rigid2`).
use bvkit::{Aabb2, Batch, Method, Rigid2, Rounding};
use glam::Vec2;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let local = vec![Aabb2::new(Vec2::splat(-0.5), Vec2::splat(0.5)); 1000];
    let poses: Vec<Rigid2> = (0..1000)
        .map(|i| Rigid2::from_angle_translation(0.1 * i as f32, Vec2::X * i as f32))
        .collect();
    let mut world = vec![Aabb2::EMPTY; 1000];
    Batch::new(Method::AbsMatrix, Rounding::Outward).transform(&local, &poses, &mut world)?;
    println!("{:?}", world[7]);
    Ok(())
}
