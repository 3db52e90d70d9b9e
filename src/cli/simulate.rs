//! `simulate`: a scene's cloud simulation run headless for N steps, its smoothed density
//! written as a Mitsuba `.vol` or an OpenVDB `.vdb` (the exporters' writers).

use std::path::Path;

use super::{read_scene_or_link, write};
use crate::export::{Axes, DensityGrid, write_vdb, write_vol};
use crate::scene::{Preset, Scene};
use crate::simulate::{Simulation, Sources};

/// Most steps one run may take.
const MAX_STEPS: u64 = 100_000;

/// Steps a run takes when neither a step count nor a moment is given.
const DEFAULT_STEPS: u64 = 100;

/// `cloudsketch simulate [SCENE|URL] [--steps N | --time T | --frame F] [--seed S] -o OUT.vol|OUT.vdb`.
pub fn run(
    scene: Option<&str>,
    steps: Option<u64>,
    at: Option<crate::scene::Moment>,
    seed: Option<u64>,
    output: &Path,
) -> Result<(), String> {
    let ext = output.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !matches!(ext, "vol" | "vdb") {
        return Err(format!(
            "{}: the output is a .vol or a .vdb",
            output.display()
        ));
    }
    super::check_outputs(&scene.into_iter().collect::<Vec<_>>(), &[output])?;
    let scene = match scene {
        Some(arg) => read_scene_or_link(arg)?,
        None => Scene::preset(Preset::Simulated),
    };
    let Some(settings) = &scene.simulation else {
        return Err(
            "this scene has no simulation (try `cloudsketch new --preset simulated`)".into(),
        );
    };
    // A moment is a step count at the simulation's rate: the step at or before it, as the
    // app's player reaches it.
    let steps = match (steps, at) {
        (Some(n), _) => n,
        // The player stops at its last step; so does a moment past it.
        (None, Some(at)) => crate::scene::steps_at(at.seconds(&scene.clock)?, settings.rate)
            .min(crate::simulate::MAX_STEP),
        (None, None) => DEFAULT_STEPS,
    };
    if steps > MAX_STEPS {
        return Err(format!("--steps {steps}: at most {MAX_STEPS}"));
    }
    let mut settings = (**settings).clone();
    if let Some(seed) = seed {
        settings.seed = seed;
    }
    let start = std::time::Instant::now();
    let mut sim = Simulation::steered(&settings, Sources::of(&scene));
    let mut progress = super::progress::Progress::share(format!("simulating {steps} steps"));
    let mut done = 0;
    while done < steps {
        let batch = (steps - done).min(256);
        sim.advance(batch);
        done += batch;
        progress.set(done as f32 / steps as f32);
    }
    drop(progress);
    let volume = sim.density(None, 1.0);
    let h = settings.cell_size;
    let grid = DensityGrid {
        dims: volume.dims,
        min: volume.center(0, 0, 0),
        h,
        values: volume.values.clone(),
        field: volume.values,
    };
    let bytes = if ext == "vol" {
        write_vol(&grid)
    } else {
        write_vdb(&grid, Axes::default(), "density", settings.seed)
    };
    write(output, &bytes)?;
    eprintln!(
        "simulated {steps} steps of {:?} cells ({} with cloud) in {:.2} s → {}",
        settings.dims(),
        sim.automaton().cloud_cells(),
        start.elapsed().as_secs_f64(),
        output.display()
    );
    Ok(())
}
