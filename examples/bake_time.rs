//! Times baking the field of a sketched cloud (`cargo run --release --example bake_time`).
use std::time::Instant;

use cloudsketch::field::{Field, FieldInputs, bake};
use cloudsketch::scene::{DrawingPlane, Preset, Scene};

fn main() {
    let mut scene = Scene::preset(Preset::Empty);
    let pts: Vec<glam::Vec2> = cloudsketch::bench::bench_outline()
        .iter()
        .map(|&[x, y]| glam::Vec2::new(x as f32, -y as f32))
        .collect();
    scene.planes.push(DrawingPlane {
        points: pts,
        origin: glam::Vec3::new(0.0, 3.0, 0.0),
        ..Default::default()
    });
    let t = Instant::now();
    let field = Field::from_scene(&scene);
    let t_field = t.elapsed();
    let spheres: usize = field.groups.iter().map(|g| g.len()).sum();
    let inputs = FieldInputs::of(&scene);
    let t = Instant::now();
    let grid = bake(&field, &inputs.grid);
    println!(
        "{spheres} spheres; field {:?}; bake {:?} for {:?}",
        t_field,
        t.elapsed(),
        grid.dims
    );
}
