//! `--checkpoints DIR` of `render` and `export` sequences: a simulated scene's run written to
//! files as it passes its snapshot steps, and read back by a chunk that starts mid-way in a
//! fresh process, so the chunk plays from the furthest checkpoint at or before its first
//! frame instead of from step 0. A file is named for the run's hash and its step
//! (`sim-<hash>-<step>.ckpt`) and holds the hash again, which refuses a file of another scene
//! or simulation whatever its name.

use std::path::{Path, PathBuf};

use crate::derive::Derived;
use crate::scene::Scene;

/// Most bytes a checkpoint file may hold (a run's state is far below: its cells are bits).
const MAX_CHECKPOINT_BYTES: u64 = 256 << 20;

/// A sequence's checkpoints as its frames use them (`--checkpoints DIR`, or none): the first
/// frame resumes its run from the furthest checkpoint at or before it, and every frame writes
/// the snapshots its run passed. `render` and `export` sequences share it.
pub struct FrameCheckpoints {
    checkpoints: Option<Checkpoints>,
    first: bool,
}

impl FrameCheckpoints {
    /// The folder `dir` where given (made when missing), or why it cannot be written.
    pub fn open(dir: Option<&Path>) -> Result<Self, String> {
        Ok(Self {
            checkpoints: dir.map(Checkpoints::open).transpose()?,
            first: true,
        })
    }

    /// Before the frame of `scene` at `time` seconds: on the first, reads the furthest
    /// checkpoint into `derived`; what the run starts from, for the frame's progress.
    pub fn before(&mut self, derived: &mut Derived, scene: &Scene, time: f32) -> Option<String> {
        let checkpoints = self.checkpoints.as_mut()?;
        if !std::mem::take(&mut self.first) {
            return None;
        }
        checkpoints.resume(derived, scene, time)
    }

    /// After a frame of `scene`: writes the snapshot its run in `derived` passed.
    pub fn after(&mut self, derived: &mut Derived, scene: &Scene) {
        if let Some(checkpoints) = self.checkpoints.as_mut() {
            checkpoints.save(derived, scene);
        }
    }
}

/// A folder of checkpoints.
pub struct Checkpoints {
    dir: PathBuf,
    /// The furthest step written (or read) so far.
    furthest: Option<u64>,
}

impl Checkpoints {
    /// The folder `dir` (made when missing), or why it cannot be written.
    pub fn open(dir: &Path) -> Result<Self, String> {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("--checkpoints {}: {e}", dir.display()))?;
        crate::files::check_writable(&dir.join(".probe"))
            .map_err(|e| format!("--checkpoints {}: cannot write there: {e}", dir.display()))?;
        Ok(Self {
            dir: dir.to_path_buf(),
            furthest: None,
        })
    }

    fn name(key: u64, step: u64) -> String {
        format!("sim-{key:016x}-{step:05}.ckpt")
    }

    /// Reads into `derived` the furthest checkpoint of `scene`'s run at or before the step of
    /// scene time `time`; says what the run starts from ("step 0", "the checkpoint at step
    /// 640"), with any file refused and why. Nothing for a scene without a simulation.
    pub fn resume(&mut self, derived: &mut Derived, scene: &Scene, time: f32) -> Option<String> {
        let settings = scene.simulation.as_ref()?;
        let target = crate::scene::steps_at(time, settings.rate);
        let player = derived.player_for(settings, scene)?;
        let key = player.run_key();
        let prefix = format!("sim-{key:016x}-");
        let mut found: Vec<(u64, PathBuf)> = std::fs::read_dir(&self.dir)
            .into_iter()
            .flatten()
            .flatten()
            .filter_map(|entry| {
                let name = entry.file_name().into_string().ok()?;
                let step = name.strip_prefix(&prefix)?.strip_suffix(".ckpt")?;
                Some((step.parse().ok()?, entry.path()))
            })
            .filter(|(step, _)| *step <= target)
            .collect();
        found.sort();
        let mut refused = Vec::new();
        while let Some((_, path)) = found.pop() {
            let read = crate::files::read_bounded(&path, MAX_CHECKPOINT_BYTES)
                .map_err(|e| e.at(&path))
                .and_then(|bytes| player.resume(&bytes, target));
            match read {
                Ok(step) => {
                    self.furthest = Some(step);
                    refused.push(format!(
                        "the checkpoint at step {step} ({})",
                        path.display()
                    ));
                    return Some(refused.join("; "));
                }
                Err(e) => refused.push(format!("{} refused: {e}", path.display())),
            }
        }
        refused.push("step 0".into());
        Some(refused.join("; "))
    }

    /// Writes `scene`'s run's furthest snapshot in `derived` when it is past what was written
    /// or read. A checkpoint that cannot be written is a warning: the frame is made.
    pub fn save(&mut self, derived: &mut Derived, scene: &Scene) {
        let Some(settings) = scene.simulation.as_ref() else {
            return;
        };
        let Some(player) = derived.player_for(settings, scene) else {
            return;
        };
        let (step, bytes) = player.checkpoint();
        if step == 0 || self.furthest.is_some_and(|f| f >= step) {
            return;
        }
        let path = self.dir.join(Self::name(player.run_key(), step));
        match super::write(&path, &bytes) {
            Ok(()) => self.furthest = Some(step),
            Err(e) => eprintln!("warning: checkpoint not written: {e}"),
        }
    }
}
