//! Times each stage of the sketch pipeline on the benchmark's 500-point stroke
//! (`cargo run --release --example sketch_stages`).
use std::time::Instant;

use cloudsketch::sketch::{SketchParams, outline, skeleton, spheres};

fn main() {
    let stroke = cloudsketch::bench::bench_outline();
    let params = SketchParams::default();
    let runs = 50;
    let mut t = [0.0f64; 5];
    for _ in 0..runs {
        let s0 = Instant::now();
        let o = outline::clean(&stroke, true, params.simplify).unwrap();
        let s1 = Instant::now();
        let sk = skeleton::chordal_axis(&o, params.prune).unwrap();
        let s2 = Instant::now();
        let mut sp = spheres::sample(&o, &sk);
        let s3 = Instant::now();
        let rf = spheres::feature_radius(&sp);
        spheres::inflate(&o.boundary, &mut sp, rf, params.inflate);
        let s4 = Instant::now();
        let ext = spheres::extend(&o, &sk, &sp, 1, 2);
        let s5 = Instant::now();
        for (k, (a, b)) in [(s0, s1), (s1, s2), (s2, s3), (s3, s4), (s4, s5)]
            .into_iter()
            .enumerate()
        {
            t[k] += (b - a).as_secs_f64();
        }
        if runs == 1 {
            println!(
                "{} outline pts, {} triangles, {} spheres, {} extended",
                o.points.len(),
                sk.triangles.len(),
                sp.len(),
                ext.len()
            );
        }
    }
    let o = outline::clean(&stroke, true, params.simplify).unwrap();
    let sk = skeleton::chordal_axis(&o, params.prune).unwrap();
    let sp = spheres::sample(&o, &sk);
    println!(
        "{} outline pts, {} triangles, {} spheres, {} extended",
        o.points.len(),
        sk.triangles.len(),
        sp.len(),
        spheres::extend(&o, &sk, &sp, 1, 2).len()
    );
    for (name, v) in ["clean", "chordal_axis", "sample", "inflate", "extend"]
        .iter()
        .zip(t)
    {
        println!("{name:>14}: {:.3} ms", v / runs as f64 * 1e3);
    }
}
