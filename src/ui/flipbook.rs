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
//!
//! Recording (the Export group's PNG of every frame of the range) runs through the same steps:
//! each frame captured at the export's size, with the document's light, and kept as a PNG file
//! instead of a texture (within [`RECORD_CAP`]); the files are handed over when the range is
//! done.

use std::collections::BTreeMap;
use std::hash::Hasher;

use crate::scene::Scene;

/// Bytes the cached frames may hold (RGBA, 4 bytes a pixel).
pub const MEMORY_CAP: usize = 512 << 20;

/// Smallest share of the view's side a frame is cached at.
const MIN_SCALE: f32 = 0.25;

/// Most frames cached (a range of a day at 120 frames a second has ten million).
const MAX_FRAMES: usize = 10_000;

/// Bytes of PNG files a recording holds (the browser's zip download is made from them in
/// pieces, outside the wasm's memory: `export::zip_pieces`).
pub const RECORD_CAP: usize = 768 << 20;

/// Whether a video sink takes a frame now.
// (Only the browser's sink makes one: natively no video sink exists.)
#[allow(dead_code)]
#[derive(Clone, Debug, PartialEq)]
pub enum SinkState {
    /// It takes the next frame.
    Ready,
    /// It is still starting, or holds as many frames as it queues: the next waits.
    Busy,
    /// It cannot encode (its muxer did not load, its encoder refuses the size): before its
    /// first frame the recording goes on as PNGs; after, it ends with this error.
    Refused(String),
}

/// A video encoder a recording hands its frames to (the browser's WebM through WebCodecs).
pub trait VideoSink {
    /// Whether it takes a frame now: a recording captures the next frame only then, so
    /// frames never pile up in memory faster than the encoder takes them.
    fn state(&self) -> SinkState;
    /// Queues frame `index` of the recording (0 first): straight-alpha RGBA at its size.
    /// An error ends the recording.
    fn add(&mut self, rgba: &[u8], index: u32) -> Result<(), String>;
    /// Encodes what is queued and saves the video as `name`, unless `cancelled` is set by
    /// then; `done` gets what was saved (or why not) once it is. A sink dropped without
    /// finishing stops its encoder.
    fn finish(
        self: Box<Self>,
        name: String,
        cancelled: std::sync::Arc<std::sync::atomic::AtomicBool>,
        done: Box<dyn FnOnce(Result<String, String>)>,
    );
}

/// A recording's frames: PNG files, or a video encoder's queue.
pub enum Frames {
    /// The PNG files, `STEM_####.png` (the frame number, zero-padded).
    Pngs(Vec<crate::export::File>),
    /// The encoder (finished by whoever saves it), and the frames handed to it.
    Video(Box<dyn VideoSink>, u32),
}

impl std::fmt::Debug for Frames {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Frames::Pngs(files) => f.debug_tuple("Pngs").field(files).finish(),
            Frames::Video(_, n) => write!(f, "Video({n} frames)"),
        }
    }
}

impl PartialEq for Frames {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (Frames::Pngs(a), Frames::Pngs(b)) => a == b,
            _ => false,
        }
    }
}

/// A recording's frames so far.
struct Recording {
    frames: Frames,
    /// Bytes of PNG files held.
    bytes: usize,
    stem: String,
    transparent: bool,
    /// The frame recorded last, shown in the view meanwhile.
    latest: Option<egui::TextureHandle>,
}

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
    /// The pixel size frames are captured at.
    size: [u32; 2],
    /// Recording: the frames go to PNG files, not textures.
    record: Option<Recording>,
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
    /// A recording ended: its frames, or why it stopped.
    pub recorded: Option<Result<Frames, String>>,
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
            size,
            record: None,
        });
        said
    }

    /// Starts recording `scene`'s frame range at `size` pixels (over the sky or transparent)
    /// into `video`, or without one as PNG files named `STEM_####.png`; the frames cached stay
    /// as they are. Says what it records.
    pub fn start_record(
        &mut self,
        scene: &Scene,
        size: [u32; 2],
        transparent: bool,
        stem: &str,
        video: Option<Box<dyn VideoSink>>,
    ) -> String {
        let clock = scene.clock;
        let count = (clock.end.saturating_sub(clock.start) as usize).saturating_add(1);
        let last = clock
            .start
            .saturating_add(count.min(MAX_FRAMES) as u32)
            .saturating_sub(1)
            .min(clock.end);
        let frames = (last - clock.start) as usize + 1;
        self.build = Some(Build {
            total: frames,
            todo: (clock.start..=last).rev().collect(),
            waiting: None,
            time: scene.time,
            size,
            record: Some(Recording {
                frames: match video {
                    Some(v) => Frames::Video(v, 0),
                    None => Frames::Pngs(Vec::new()),
                },
                bytes: 0,
                stem: stem.to_owned(),
                transparent,
                latest: None,
            }),
        });
        let what = if self.recording_video() {
            "a WebM"
        } else {
            "PNGs"
        };
        if frames < count {
            format!(
                "Recording the first {frames} of {count} frames at {}×{} as {what}: a recording holds at most {MAX_FRAMES}",
                size[0], size[1]
            )
        } else {
            format!(
                "Recording {frames} frames at {}×{} as {what}",
                size[0], size[1]
            )
        }
    }

    /// Whether it is recording (not caching).
    pub fn recording(&self) -> bool {
        self.build.as_ref().is_some_and(|b| b.record.is_some())
    }

    /// Whether it is recording into a video.
    fn recording_video(&self) -> bool {
        self.build
            .as_ref()
            .and_then(|b| b.record.as_ref())
            .is_some_and(|r| matches!(r.frames, Frames::Video(..)))
    }

    /// The pixel size frames are captured at (cached, or recorded while recording), and
    /// whether over a transparent background.
    pub fn size(&self) -> ([u32; 2], bool) {
        match &self.build {
            Some(b) => (b.size, b.record.as_ref().is_some_and(|r| r.transparent)),
            None => (self.size, false),
        }
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
            let size = build.size;
            match result {
                // The scene changed while it was drawn (an orbit, an edit): drawn again.
                Ok(_) if frame_key(scene, t, size) != asked => build.todo.push(frame),
                Ok(pixels) if build.record.is_some() => {
                    let record = build.record.as_mut().expect("recording");
                    if pixels.len() != size[0] as usize * size[1] as usize * 4 {
                        ask.recorded = Some(Err(format!("frame {frame} came back the wrong size")));
                        ask.time = self.cancel();
                        return ask;
                    }
                    let image =
                        egui::ColorImage::from_rgba_unmultiplied(size.map(|v| v as usize), &pixels);
                    record.latest = Some(ctx.load_texture(
                        "recorded frame",
                        image,
                        egui::TextureOptions::LINEAR,
                    ));
                    if let Frames::Video(video, n) = &mut record.frames {
                        match video.add(&pixels, *n) {
                            Ok(()) => *n += 1,
                            // Nothing was encoded yet: this frame and the rest, as PNGs.
                            Err(e) if *n == 0 => {
                                ask.say = Some(format!("{e}: recording PNGs instead"));
                                record.frames = Frames::Pngs(Vec::new());
                            }
                            Err(e) => {
                                ask.recorded = Some(Err(format!("the video encoder failed: {e}")));
                                ask.time = self.cancel();
                                return ask;
                            }
                        }
                    }
                    if let Frames::Pngs(files) = &mut record.frames {
                        // (The size was checked above: the encoder always writes it.)
                        let png = crate::export::encode_png(size[0], size[1], &pixels)
                            .unwrap_or_default();
                        record.bytes += png.len();
                        files.push(crate::export::File {
                            name: format!("{}_{frame:04}.png", record.stem),
                            bytes: png,
                        });
                        if record.bytes > RECORD_CAP && !build.todo.is_empty() {
                            ask.say = Some(format!(
                                "Recorded the first {} of {} frames: a recording holds at most {} MB",
                                files.len(),
                                build.total,
                                RECORD_CAP >> 20
                            ));
                            build.todo.clear();
                        }
                    }
                }
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
                Err(e) if build.record.is_some() => {
                    ask.recorded = Some(Err(e));
                    ask.time = self.cancel();
                    return ask;
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
        if build.waiting.is_none()
            && let Some(record) = build.record.as_mut()
            && let Frames::Video(video, n) = &record.frames
        {
            match (video.state(), *n) {
                (SinkState::Ready, _) => {}
                (SinkState::Busy, _) => return ask,
                (SinkState::Refused(why), 0) => {
                    // Nothing was encoded yet: the same frames, as PNGs.
                    ask.say = Some(format!("{why}: recording PNGs instead"));
                    record.frames = Frames::Pngs(Vec::new());
                }
                (SinkState::Refused(why), _) => {
                    ask.recorded = Some(Err(format!("the video encoder failed: {why}")));
                    ask.time = self.cancel();
                    return ask;
                }
            }
        }
        if build.waiting.is_none() {
            match build.todo.pop() {
                Some(frame) => {
                    let t = scene.clock.seconds(frame);
                    build.waiting = Some((frame, frame_key(scene, t, build.size)));
                    ask.time = Some(t);
                    ask.capture = Some(build.size);
                }
                None if build.record.is_some() => {
                    let record = build.record.take().expect("recording");
                    ask.recorded = Some(Ok(record.frames));
                    ask.time = self.cancel();
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
        if !(0.0..=f64::from(u32::MAX)).contains(&f) {
            return None;
        }
        let kept = self.frames.get(&(f as u32))?;
        (kept.key == frame_key(scene, clock.seconds(f as u32), self.size)).then_some(&kept.texture)
    }

    /// The image cached last (shown while caching goes on), or recorded last.
    pub fn latest(&self) -> Option<&egui::TextureHandle> {
        if let Some(record) = self.build.as_ref().and_then(|b| b.record.as_ref()) {
            return record.latest.as_ref();
        }
        self.frames.get(&self.latest?).map(|f| &f.texture)
    }

    /// The page state's summary.
    pub fn state(&self) -> serde_json::Value {
        let (frames, bytes) = self.kept();
        serde_json::json!({
            "building": self.building(),
            "recording": self.recording(),
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
        const { assert!(488 * 275 * 4 * 1000 <= MEMORY_CAP) };
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

    /// Steps a PNG recording to its end (see `drive_recording`): its files, and how many
    /// captures it asked for.
    fn record_all(
        book: &mut Flipbook,
        ctx: &egui::Context,
        scene: &mut Scene,
    ) -> (Vec<crate::export::File>, usize) {
        let (recorded, asked) = drive_recording(book, ctx, scene);
        let Ok(Frames::Pngs(files)) = recorded else {
            panic!("{recorded:?}")
        };
        (files, asked)
    }

    /// Steps a recording to its end with captures whose red is the frame's time in tenths;
    /// returns how it ended and how many captures it asked for.
    fn drive_recording(
        book: &mut Flipbook,
        ctx: &egui::Context,
        scene: &mut Scene,
    ) -> (Result<Frames, String>, usize) {
        let mut captured = None;
        let mut asked = 0;
        for _ in 0..100_000 {
            let ask = book.step(ctx, scene, captured.take());
            if let Some(t) = ask.time {
                *scene = scene.posed_at(t);
            }
            if let Some(recorded) = ask.recorded {
                return (recorded, asked);
            }
            // (A busy video sink holds the next capture back.)
            let Some(size) = ask.capture else {
                continue;
            };
            asked += 1;
            let red = (scene.time * 10.0).round() as u8;
            captured = Some(Ok(
                [red, 0, 0, 255].repeat(size[0] as usize * size[1] as usize)
            ));
        }
        panic!("the recording never ended");
    }

    #[test]
    fn a_recording_hands_over_a_png_of_every_frame_and_leaves_the_cache_as_it_was() {
        let ctx = egui::Context::default();
        let mut scene = keyed();
        let mut book = Flipbook::default();
        cache_all(&mut book, &ctx, &mut scene);
        let kept = book.kept();
        scene.clock.start = 3;
        scene.clock.end = 8;
        scene.time = 0.5;
        let said = book.start_record(&scene, [5, 3], true, "storm", None);
        assert_eq!(said, "Recording 6 frames at 5×3 as PNGs");
        assert!(book.recording() && book.size() == ([5, 3], true));
        assert!(book.latest().is_none(), "no frame recorded yet");
        let (files, asked) = record_all(&mut book, &ctx, &mut scene);
        assert_eq!(asked, 6);
        assert!(!book.building() && !book.recording());
        assert_eq!(scene.time, 0.5, "back at the time it began from");
        let names: Vec<&str> = files.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "storm_0003.png",
                "storm_0004.png",
                "storm_0005.png",
                "storm_0006.png",
                "storm_0007.png",
                "storm_0008.png"
            ]
        );
        // Each PNG holds its own frame's capture.
        for (f, file) in (3..=8).zip(&files) {
            let mut reader = png::Decoder::new(std::io::Cursor::new(&file.bytes))
                .read_info()
                .unwrap();
            let mut buf = vec![0; reader.output_buffer_size().unwrap()];
            let info = reader.next_frame(&mut buf).unwrap();
            assert_eq!((info.width, info.height), (5, 3));
            let red = (scene.clock.seconds(f) * 10.0).round() as u8;
            assert_eq!(&buf[..4], &[red, 0, 0, 255], "frame {f}");
        }
        assert_eq!(book.kept(), kept, "the cached frames stay");
    }

    #[test]
    fn a_recording_cancelled_or_failed_hands_over_nothing_but_the_error() {
        let ctx = egui::Context::default();
        let mut scene = keyed();
        let mut book = Flipbook::default();
        book.start_record(&scene, [4, 4], false, "cloud", None);
        let ask = book.step(&ctx, &scene, None);
        assert_eq!(ask.capture, Some([4, 4]));
        assert_eq!(book.cancel(), Some(0.0));
        assert!(!book.building());
        book.start_record(&scene, [4, 4], false, "cloud", None);
        book.step(&ctx, &scene, None);
        let ask = book.step(&ctx, &scene, Some(Err("the device was lost".into())));
        assert_eq!(ask.recorded, Some(Err("the device was lost".into())));
        assert!(!book.building());
        // A capture of the wrong size is refused, not written.
        book.start_record(&scene, [4, 4], false, "cloud", None);
        book.step(&ctx, &scene, None);
        let ask = book.step(&ctx, &scene, Some(Ok(vec![0; 7])));
        assert!(
            matches!(ask.recorded, Some(Err(ref e)) if e.contains("wrong size")),
            "{:?}",
            ask.recorded
        );
        // A range beyond the frame cap is recorded to the cap, and says so.
        scene.clock.end = 20_000;
        let said = book.start_record(&scene, [4, 4], false, "cloud", None);
        assert!(said.contains("first 10000 of 20001"), "{said}");
    }

    /// A video sink for the tests: it keeps each frame's first byte and index and fails at
    /// index `fail_at`; it is busy for its first `starting` calls to `state`, then, with
    /// `hold`, once after each frame it takes (counted in `waits`); once started it refuses
    /// with `refuse`.
    #[derive(Default)]
    struct Probe {
        seen: std::rc::Rc<std::cell::RefCell<Vec<(u8, u32)>>>,
        fail_at: Option<u32>,
        starting: std::cell::Cell<u32>,
        hold: bool,
        pending: std::cell::Cell<bool>,
        waits: std::rc::Rc<std::cell::Cell<u32>>,
        /// Whether the last `state()` said busy.
        busy: std::rc::Rc<std::cell::Cell<bool>>,
        refuse: Option<String>,
    }
    impl Probe {
        /// Always ready; keeps frames in `seen`, fails at `fail_at`.
        fn failing_at(
            seen: &std::rc::Rc<std::cell::RefCell<Vec<(u8, u32)>>>,
            fail_at: Option<u32>,
        ) -> Self {
            Self {
                seen: seen.clone(),
                fail_at,
                ..Self::default()
            }
        }
    }
    impl VideoSink for Probe {
        fn state(&self) -> SinkState {
            let state = if self.starting.get() > 0 {
                self.starting.set(self.starting.get() - 1);
                SinkState::Busy
            } else if let Some(why) = &self.refuse {
                SinkState::Refused(why.clone())
            } else if self.pending.replace(false) {
                self.waits.set(self.waits.get() + 1);
                SinkState::Busy
            } else {
                SinkState::Ready
            };
            self.busy.set(state == SinkState::Busy);
            state
        }
        fn add(&mut self, rgba: &[u8], index: u32) -> Result<(), String> {
            if Some(index) == self.fail_at {
                return Err("out of memory".into());
            }
            self.seen.borrow_mut().push((rgba[0], index));
            self.pending.set(self.hold);
            Ok(())
        }
        fn finish(
            self: Box<Self>,
            name: String,
            _: std::sync::Arc<std::sync::atomic::AtomicBool>,
            done: Box<dyn FnOnce(Result<String, String>)>,
        ) {
            done(Ok(name));
        }
    }

    /// Records `scene`'s range into `probe` at 4×2: what it said, and how it ended.
    fn record_into(
        scene: &mut Scene,
        ctx: &egui::Context,
        probe: Probe,
    ) -> (String, Result<Frames, String>) {
        let mut book = Flipbook::default();
        let said = book.start_record(scene, [4, 2], false, "cloud", Some(Box::new(probe)));
        (said, drive_recording(&mut book, ctx, scene).0)
    }

    #[test]
    fn a_video_recording_hands_its_encoder_every_frame_in_order() {
        let ctx = egui::Context::default();
        let mut scene = keyed();
        scene.clock.start = 2;
        scene.clock.end = 6;
        let seen = std::rc::Rc::new(std::cell::RefCell::new(Vec::new()));
        let (said, ended) = record_into(&mut scene, &ctx, Probe::failing_at(&seen, None));
        assert_eq!(said, "Recording 5 frames at 4×2 as a WebM");
        assert!(matches!(ended, Ok(Frames::Video(_, 5))), "{ended:?}");
        let expected: Vec<(u8, u32)> = (2..=6)
            .zip(0..)
            .map(|(f, i)| ((scene.clock.seconds(f) * 10.0).round() as u8, i))
            .collect();
        assert_eq!(*seen.borrow(), expected);
        // The encoder failing ends the recording with its error.
        let (_, ended) = record_into(&mut scene, &ctx, Probe::failing_at(&seen, Some(2)));
        assert_eq!(ended, Err("the video encoder failed: out of memory".into()));
        // Failing at its first frame (it took none): that frame and the rest as PNGs.
        let (_, ended) = record_into(&mut scene, &ctx, Probe::failing_at(&seen, Some(0)));
        let Ok(Frames::Pngs(files)) = ended else {
            panic!("{ended:?}")
        };
        assert_eq!(files.len(), 5);
        assert_eq!(files[0].name, "cloud_0002.png");
    }

    #[test]
    fn a_busy_encoder_holds_the_next_capture_back_and_a_refusing_one_leaves_pngs() {
        let ctx = egui::Context::default();
        let mut scene = keyed();
        scene.clock.end = 3;
        // Starting (busy for 3 calls), then busy once after each frame: no capture is asked
        // while it is busy, and every frame still reaches it once, in order.
        let seen = std::rc::Rc::new(std::cell::RefCell::new(Vec::new()));
        let waits = std::rc::Rc::new(std::cell::Cell::new(0));
        let busy = std::rc::Rc::new(std::cell::Cell::new(false));
        let slow = |starting: u32, refuse: Option<&str>| {
            Box::new(Probe {
                seen: seen.clone(),
                starting: starting.into(),
                hold: true,
                waits: waits.clone(),
                busy: busy.clone(),
                refuse: refuse.map(str::to_owned),
                ..Probe::default()
            })
        };
        let mut book = Flipbook::default();
        book.start_record(&scene, [4, 2], false, "cloud", Some(slow(3, None)));
        let (mut captured, mut asked, mut held) = (None, 0, 0);
        let ended = loop {
            let ask = book.step(&ctx, &scene, captured.take());
            if busy.get() {
                // Nothing is asked in a step the sink was busy in.
                assert_eq!((ask.time, ask.capture), (None, None), "held while busy");
                held += 1;
            }
            if let Some(t) = ask.time {
                scene = scene.posed_at(t);
            }
            if let Some(ended) = ask.recorded {
                break ended;
            }
            if let Some(size) = ask.capture {
                asked += 1;
                captured = Some(Ok([0u8, 0, 0, 255].repeat((size[0] * size[1]) as usize)));
            }
        };
        assert!(matches!(ended, Ok(Frames::Video(_, 4))), "{ended:?}");
        assert_eq!(asked, 4, "one capture a frame");
        let indices: Vec<u32> = seen.borrow().iter().map(|&(_, i)| i).collect();
        assert_eq!(indices, [0, 1, 2, 3]);
        assert_eq!(waits.get(), 4, "held back after each frame it took");
        assert_eq!(held, 3 + 4, "while starting, and after each frame");
        // Refusing after it took frames ends the recording with the error.
        let mut book = Flipbook::default();
        book.start_record(&scene, [4, 2], false, "cloud", Some(slow(0, None)));
        let ask = book.step(&ctx, &scene, None);
        let t = ask.time.expect("frame 0");
        scene = scene.posed_at(t);
        let ask = book.step(&ctx, &scene, Some(Ok([0u8; 32].to_vec())));
        assert!(ask.recorded.is_none(), "frame 0 taken");
        let Some(Build {
            record:
                Some(Recording {
                    frames: Frames::Video(video, 1),
                    ..
                }),
            ..
        }) = book.build.as_mut()
        else {
            panic!("recording a video, one frame in");
        };
        *video = slow(0, Some("the encoder crashed"));
        let ask = book.step(&ctx, &scene, None);
        assert_eq!(
            ask.recorded.map(|r| r.map(|_| ())),
            Some(Err("the video encoder failed: the encoder crashed".into()))
        );
        // Refused before its first frame (a size VP9 cannot encode): the same frames, as PNGs,
        // and it says so.
        let mut book = Flipbook::default();
        book.start_record(
            &scene,
            [4, 2],
            false,
            "cloud",
            Some(slow(0, Some("this browser cannot encode VP9 at 4×2"))),
        );
        let ask = book.step(&ctx, &scene, None);
        assert_eq!(
            ask.say.as_deref(),
            Some("this browser cannot encode VP9 at 4×2: recording PNGs instead")
        );
        assert_eq!(ask.capture, Some([4, 2]), "the first frame asked at once");
        let mut captured = Some(Ok([0u8, 0, 0, 255].repeat(8)));
        let mut time = ask.time;
        let ended = loop {
            if let Some(t) = time {
                scene = scene.posed_at(t);
            }
            let ask = book.step(&ctx, &scene, captured.take());
            time = ask.time;
            if let Some(ended) = ask.recorded {
                break ended;
            }
            captured = Some(Ok([0u8, 0, 0, 255].repeat(8)));
        };
        let Ok(Frames::Pngs(files)) = ended else {
            panic!("{ended:?}")
        };
        assert_eq!(files.len(), 4);
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
