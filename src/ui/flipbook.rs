//! Cached playback (Houdini's flipbook, EmberGen's cache): the frame range rendered once at
//! full quality, a frame at a time in the background through the viewport's own capture (the
//! PNG export's: its slices a chunk a frame, so the app answers input meanwhile), each frame
//! kept as a texture; playing then shows the kept frames at the document's frame rate
//! instead of rendering. Each frame is kept with the key of what it shows (the scene posed at
//! its time, the view and the size), so an edit invalidates only the frames it changes: a
//! key moved at frame 48 leaves the frames its neighbours hold as they were.
//!
//! Within a memory cap ([`MEMORY_CAP`]): a range too long for it at the view's size is cached
//! smaller (down to a quarter of each side), and past that only its first frames, said in a
//! message.

use std::collections::BTreeMap;
use std::hash::Hasher;

use crate::scene::Scene;

/// Bytes the cached frames may hold (RGBA, 4 bytes a pixel).
pub const MEMORY_CAP: usize = 512 << 20;

/// Smallest share of the view's side a frame is cached at.
const MIN_SCALE: f32 = 0.25;

/// Most frames cached (a range of a day at 120 frames a second has ten million).
const MAX_FRAMES: usize = 10_000;

/// One kept frame.
struct Frame {
    key: u64,
    texture: egui::TextureHandle,
    bytes: usize,
}

/// The caching under way.
struct Build {
    /// Frames still to render, in order.
    todo: Vec<u32>,
    /// The frame whose capture is under way, with the key of what it was asked to show.
    waiting: Option<(u32, u64)>,
    /// The time to go back to when done.
    time: f32,
    /// Frames in the range.
    total: usize,
}

/// The cached frames of a document's range.
#[derive(Default)]
pub struct Flipbook {
    frames: BTreeMap<u32, Frame>,
    build: Option<Build>,
    /// The pixel size frames are cached at.
    size: [u32; 2],
    /// The view's size they were cached for.
    view_px: [u32; 2],
    /// Cached frames shown while playing (the page test counts them).
    pub shown: u64,
    /// Whether the last frame drawn was a cached one.
    pub showing: bool,
    /// The frame cached last.
    latest: Option<u32>,
}

/// What the flipbook asks of the app this frame.
#[derive(Debug, Default, PartialEq)]
pub struct Ask {
    /// Set the document's time to this (the next frame to cache, or back after caching).
    pub time: Option<f32>,
    /// Capture the view at this pixel size.
    pub capture: Option<[u32; 2]>,
    /// Something to tell the user.
    pub say: Option<String>,
}

/// A key of what `scene` shows at time `t` in a view `size` pixels: the scene posed there,
/// camera included, hashed.
pub fn frame_key(scene: &Scene, t: f32, size: [u32; 2]) -> u64 {
    struct Hashing(std::collections::hash_map::DefaultHasher);
    impl std::io::Write for Hashing {
        fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
            self.0.write(bytes);
            Ok(bytes.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }
    // What the frame shows is the pose, not the keys that made it: a key edit elsewhere in
    // time leaves this frame's key as it was. The noise's drift is kept apart (it integrates
    // the keys of the wind and torque up to `t`).
    let mut at = if scene.time == t {
        scene.clone()
    } else {
        scene.posed_at(t)
    };
    // Looking through a keyed shot camera, the view is the shot's at that time.
    if scene.shot.as_ref() == Some(&scene.camera)
        && let Some(shot) = &at.shot
    {
        at.camera = shot.clone();
    }
    let drift = crate::field::media::Drifts::of(&at);
    // A simulation's run is steered by its parcels' keys from time 0 on: there the keys are
    // part of the frame.
    if at.simulation.is_none() {
        at.animation = Default::default();
    }
    // The picture traced is no part of the frame (and may be megabytes).
    at.reference = None;
    let mut h = Hashing(Default::default());
    // (A scene always serialises; a failure only makes the key differ from every frame's.)
    let _ = serde_json::to_writer(&mut h, &at);
    for v in drift.values() {
        h.0.write_u32(v.to_bits());
    }
    h.0.write_u32(size[0]);
    h.0.write_u32(size[1]);
    h.0.finish()
}

impl Flipbook {
    /// Whether it is caching.
    pub fn building(&self) -> bool {
        self.build.is_some()
    }

    /// Frames kept, and their bytes.
    pub fn kept(&self) -> (usize, usize) {
        (
            self.frames.len(),
            self.frames.values().map(|f| f.bytes).sum(),
        )
    }

    /// Caching's progress: frames done of the range's, while it runs.
    pub fn progress(&self) -> Option<(usize, usize)> {
        self.build.as_ref().map(|b| {
            (
                b.total - b.todo.len() - usize::from(b.waiting.is_some()),
                b.total,
            )
        })
    }

    /// Starts caching `scene`'s frame range as seen in a view `view_px` pixels: the frames
    /// whose kept image no longer matches are rendered again, the rest kept.
    pub fn start(&mut self, scene: &Scene, view_px: [u32; 2]) -> Option<String> {
        let clock = scene.clock;
        let count = (clock.end.saturating_sub(clock.start) as usize).saturating_add(1);
        // Within the memory cap: smaller frames, then fewer (in f64: usize is 32 bits on
        // the web).
        let full = f64::from(view_px[0]) * f64::from(view_px[1]) * 4.0;
        let fit = (MEMORY_CAP as f64 / (full * count as f64).max(1.0)).sqrt() as f32;
        let scale = fit.clamp(MIN_SCALE, 1.0);
        let size = view_px.map(|v| ((v as f32 * scale).round() as u32).max(1));
        let each = f64::from(size[0]) * f64::from(size[1]) * 4.0;
        let room = ((MEMORY_CAP as f64 / each.max(1.0)) as usize).clamp(1, MAX_FRAMES);
        let mut said = None;
        if size != self.size || view_px != self.view_px {
            self.frames.clear();
            self.size = size;
            self.view_px = view_px;
        }
        let last = clock
            .start
            .saturating_add(room.min(count) as u32)
            .saturating_sub(1)
            .min(clock.end);
        let frames: Vec<u32> = (clock.start..=last).collect();
        if frames.len() < count {
            said = Some(format!(
                "Caching the first {} of {} frames at {}×{}: the cache holds at most {} MB",
                frames.len(),
                count,
                size[0],
                size[1],
                MEMORY_CAP >> 20
            ));
        } else if scale < 1.0 {
            said = Some(format!(
                "Caching {} frames at {}×{}: the cache holds at most {} MB",
                frames.len(),
                size[0],
                size[1],
                MEMORY_CAP >> 20
            ));
        }
        self.frames.retain(|f, _| (clock.start..=last).contains(f));
        let todo: Vec<u32> = frames
            .iter()
            .copied()
            .filter(|&f| {
                self.frames
                    .get(&f)
                    .is_none_or(|kept| kept.key != frame_key(scene, clock.seconds(f), size))
            })
            .rev()
            .collect();
        self.build = Some(Build {
            total: frames.len(),
            todo,
            waiting: None,
            time: scene.time,
        });
        said
    }

    /// The pixel size frames are cached at.
    pub fn size(&self) -> [u32; 2] {
        self.size
    }

    /// The time of the frame being cached, if one is.
    pub fn waiting_time(&self, scene: &Scene) -> Option<f32> {
        let (frame, _) = self.build.as_ref()?.waiting?;
        Some(scene.clock.seconds(frame))
    }

    /// Stops caching (the frames kept so far stay); returns the time to go back to.
    pub fn cancel(&mut self) -> Option<f32> {
        self.build.take().map(|b| b.time)
    }

    /// Advances the caching: asks for the next frame's time and capture once the last one
    /// came back (`captured`: its pixels, straight-alpha RGBA at the cache's size).
    pub fn step(
        &mut self,
        ctx: &egui::Context,
        scene: &Scene,
        captured: Option<Result<Vec<u8>, String>>,
    ) -> Ask {
        let Some(build) = self.build.as_mut() else {
            return Ask::default();
        };
        let mut ask = Ask::default();
        if let (Some((frame, asked)), Some(result)) = (build.waiting, captured) {
            build.waiting = None;
            let t = scene.clock.seconds(frame);
            match result {
                // The scene changed while it was drawn (an orbit, an edit): drawn again.
                Ok(_) if frame_key(scene, t, self.size) != asked => build.todo.push(frame),
                Ok(pixels) => {
                    let image = egui::ColorImage::from_rgba_unmultiplied(
                        self.size.map(|v| v as usize),
                        &pixels,
                    );
                    let texture = ctx.load_texture(
                        format!("flipbook frame {frame}"),
                        image,
                        egui::TextureOptions::LINEAR,
                    );
                    self.latest = Some(frame);
                    self.frames.insert(
                        frame,
                        Frame {
                            key: asked,
                            texture,
                            bytes: pixels.len(),
                        },
                    );
                }
                Err(e) => {
                    ask.say = Some(format!("Caching stopped: {e}"));
                    ask.time = self.cancel();
                    return ask;
                }
            }
        }
        let Some(build) = self.build.as_mut() else {
            return ask;
        };
        if build.waiting.is_none() {
            match build.todo.pop() {
                Some(frame) => {
                    let t = scene.clock.seconds(frame);
                    build.waiting = Some((frame, frame_key(scene, t, self.size)));
                    ask.time = Some(t);
                    ask.capture = Some(self.size);
                }
                None => {
                    let (n, bytes) = self.kept();
                    ask.say = Some(format!(
                        "Cached {n} frames ({} MB): Play shows them at {} frames a second",
                        bytes.div_ceil(1 << 20),
                        scene.clock.fps
                    ));
                    ask.time = self.cancel();
                }
            }
        }
        ask
    }

    /// The kept image of the frame `scene`'s time falls in (held until the next frame's
    /// time, as a flipbook holds it), if it is still what the view shows at that frame.
    pub fn frame(&self, scene: &Scene, view_px: [u32; 2]) -> Option<&egui::TextureHandle> {
        if view_px != self.view_px {
            return None;
        }
        let clock = scene.clock;
        let f = (clock.frame(scene.time) + 1e-3).floor();
        if !(0.0..=f64::from(u32::MAX)).contains(&f64::from(f)) {
            return None;
        }
        let kept = self.frames.get(&(f as u32))?;
        (kept.key == frame_key(scene, clock.seconds(f as u32), self.size)).then_some(&kept.texture)
    }

    /// The image cached last (shown while caching goes on).
    pub fn latest(&self) -> Option<&egui::TextureHandle> {
        self.frames.get(&self.latest?).map(|f| &f.texture)
    }

    /// The page state's summary.
    pub fn state(&self) -> serde_json::Value {
        let (frames, bytes) = self.kept();
        serde_json::json!({
            "building": self.building(),
            "progress": self.progress(),
            "frames": frames,
            "bytes": bytes,
            "size": self.size,
            "showing": self.showing,
            "shown": self.shown,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Channel, EllipsoidProperty, Preset};

    /// A scene whose first ellipsoid is keyed at frames 0, 12 and 24 of a 24-frame range.
    fn keyed() -> Scene {
        let mut scene = Scene::preset(Preset::Cumulus);
        scene.clock.end = 24;
        let e = scene.ellipsoids[0].clone();
        let center = Channel::Ellipsoid {
            id: e.id,
            property: EllipsoidProperty::Center,
        };
        for (f, dx) in [(0, 0.0), (12, 2.0), (24, 0.0)] {
            let at = scene.clock.seconds(f);
            let c = e.center + glam::Vec3::X * dx;
            scene.animation.key(center, at, c.to_array().to_vec());
        }
        scene
    }

    /// Caches every frame of `scene` with blank pixels, as captures would come back.
    fn cache_all(book: &mut Flipbook, ctx: &egui::Context, scene: &mut Scene) -> usize {
        assert_eq!(book.start(scene, [8, 6]), None);
        let mut captured = None;
        let mut renders = 0;
        loop {
            let ask = book.step(ctx, scene, captured.take());
            if let Some(t) = ask.time {
                *scene = scene.posed_at(t);
            }
            match ask.capture {
                Some(size) => {
                    renders += 1;
                    captured = Some(Ok(vec![255; size[0] as usize * size[1] as usize * 4]));
                }
                None => break,
            }
        }
        renders
    }

    #[test]
    fn a_cached_range_plays_and_an_edit_invalidates_only_the_frames_it_changes() {
        let ctx = egui::Context::default();
        let mut scene = keyed();
        let mut book = Flipbook::default();
        assert_eq!(cache_all(&mut book, &ctx, &mut scene), 25);
        assert!(!book.building());
        assert_eq!(book.kept(), (25, 25 * 8 * 6 * 4));
        // Each frame's time shows its kept frame, and so does a time between two frames.
        for f in [0, 7, 24] {
            assert!(
                book.frame(&scene.posed_at(scene.clock.seconds(f)), [8, 6])
                    .is_some(),
                "{f}"
            );
        }
        assert!(book.frame(&scene.posed_at(0.51), [8, 6]).is_some());
        // Past the range, nothing.
        assert!(book.frame(&scene.posed_at(1.2), [8, 6]).is_none());
        // The key at frame 12 moved further: frames 1 to 23 change, 0 and 24 keep theirs.
        let center = scene.animation.tracks[0].channel;
        let t12 = scene.clock.seconds(12);
        scene.animation.key(center, t12, vec![9.0, 1.6, 0.0]);
        assert!(book.frame(&scene.posed_at(t12), [8, 6]).is_none());
        assert!(book.frame(&scene.posed_at(0.0), [8, 6]).is_some());
        assert_eq!(
            cache_all(&mut book, &ctx, &mut scene),
            23,
            "only the changed frames"
        );
        // Another light: every frame changes.
        scene.light.sun_elevation_deg += 10.0;
        assert_eq!(cache_all(&mut book, &ctx, &mut scene), 25);
    }

    #[test]
    fn a_range_beyond_the_memory_cap_is_cached_smaller_then_shorter() {
        let ctx = egui::Context::default();
        let mut scene = Scene::preset(Preset::Empty);
        scene.clock.end = 999;
        let mut book = Flipbook::default();
        // 1,000 frames of 1920×1080 would take 8.3 GB: a quarter of each side and a little
        // more fits.
        let said = book.start(&scene, [1920, 1080]).unwrap();
        assert!(said.contains("1000 frames at 488×275"), "{said}");
        let ask = book.step(&ctx, &scene, None);
        assert_eq!(ask.capture, Some([488, 275]));
        assert!(488 * 275 * 4 * 1000 <= MEMORY_CAP);
        book.cancel();
        scene.clock.end = 9_999;
        let said = book.start(&scene, [1920, 1080]).unwrap();
        assert!(
            said.contains("first 1035 of 10000 frames at 480×270"),
            "{said}"
        );
        // Another view size: nothing kept shows.
        assert!(book.frame(&scene, [1920, 1080]).is_none());
    }

    #[test]
    fn a_frame_whose_scene_changed_while_it_was_drawn_is_drawn_again() {
        let ctx = egui::Context::default();
        let mut scene = keyed();
        scene.clock.end = 1;
        let mut book = Flipbook::default();
        book.start(&scene, [8, 6]);
        let ask = book.step(&ctx, &scene, None);
        assert_eq!((ask.time, ask.capture), (Some(0.0), Some([8, 6])));
        // Orbited while frame 0 was captured: its pixels show the old view.
        scene.camera.yaw_deg += 20.0;
        let pixels = Ok(vec![0; 8 * 6 * 4]);
        let ask = book.step(&ctx, &scene, Some(pixels));
        assert_eq!(book.kept().0, 0, "not kept");
        assert_eq!(ask.time, Some(0.0), "asked again");
        assert_eq!(book.progress(), Some((0, 2)));
    }
}
