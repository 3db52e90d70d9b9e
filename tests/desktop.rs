//! The desktop window, opened as a user opens it (`cloudsketch [SCENE]`) on a virtual X display
//! (Xvfb, which scripts/setup.sh installs) with lavapipe drawing through a real window surface.
//! `--screenshot` saves the window's first full-quality image and `--state-out` the app's state,
//! the page's test contract natively; xdotool (also from setup.sh) drives the pointer and the
//! keyboard, and the scene the window saves (Ctrl+S) shows what the input did.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Mutex;

use serde_json::Value;

/// `xvfb-run -a` picks a free display number racily: one window at a time.
static DISPLAY: Mutex<()> = Mutex::new(());

/// The virtual display: room for a 1280×800-point window at 2 pixels a point.
const SCREEN: &str = "-screen 0 2600x1700x24";

/// Fails with what to install when `tool` (from Debian's `package`) is missing.
fn require(tool: &str, package: &str) {
    let found = Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .output()
        .is_ok_and(|o| o.status.success());
    assert!(
        found,
        "{tool} is missing: scripts/setup.sh installs it (Debian's {package})"
    );
}

/// Runs `program` with `args` under `xvfb-run` with a 2600×1700 screen at `scale` device pixels
/// per point (winit's X11 scale factor, as a HiDPI desktop sets it), one display at a time; no
/// autosave of the user's is read or written (`data` is a fresh data folder per run). `env`
/// adds variables.
fn under_xvfb(
    program: &str,
    args: &[&str],
    data: &Path,
    scale: usize,
    env: &[(&str, &OsStr)],
) -> Output {
    let _one = DISPLAY.lock().unwrap_or_else(|e| e.into_inner());
    require("xvfb-run", "xvfb");
    Command::new("timeout")
        .args(["300", "xvfb-run", "-a", "-s", SCREEN, program])
        .args(args)
        .envs(env.iter().copied())
        .env("XDG_DATA_HOME", data)
        .env("WINIT_X11_SCALE_FACTOR", scale.to_string())
        // As a user's shell on a machine without a graphical login has it (scripts/test.sh
        // switches Mesa's device-select layer off for the offscreen tests; the app must itself).
        .env_remove("NODEVICE_SELECT")
        .env_remove("XDG_RUNTIME_DIR")
        .output()
        .expect("run under xvfb-run")
}

/// Runs the binary with `args` in a window (see [`under_xvfb`]).
fn in_window(args: &[&str], data: &Path, scale: usize) -> Output {
    under_xvfb(env!("CARGO_BIN_EXE_cloudsketch"), args, data, scale, &[])
}

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cloudsketch-desktop-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// An RGBA8 image read from a PNG.
struct Rgba {
    width: usize,
    height: usize,
    data: Vec<u8>,
}

impl Rgba {
    fn read(path: &Path) -> Rgba {
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut data = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut data).unwrap();
        assert_eq!(info.color_type, png::ColorType::Rgba);
        Rgba {
            width: info.width as usize,
            height: info.height as usize,
            data,
        }
    }

    fn at(&self, x: usize, y: usize) -> [u8; 3] {
        let i = 4 * (y * self.width + x);
        [self.data[i], self.data[i + 1], self.data[i + 2]]
    }

    /// Pixels in `[x0, x1) × [y0, y1)` farther than `tol` (sum over channels) from `rgb`,
    /// leaving out those `skip` says to.
    fn differing(
        &self,
        (x0, x1): (usize, usize),
        (y0, y1): (usize, usize),
        rgb: [u8; 3],
        tol: u32,
        skip: impl Fn(usize, usize) -> bool,
    ) -> usize {
        let mut n = 0;
        for y in y0..y1 {
            for x in x0..x1 {
                let p = self.at(x, y);
                let d: u32 = (0..3).map(|c| p[c].abs_diff(rgb[c]) as u32).sum();
                if d > tol && !skip(x, y) {
                    n += 1;
                }
            }
        }
        n
    }
}

/// What a `--screenshot` run left: the window's image and the app's state.
struct Shot {
    /// Device pixels per point.
    scale: usize,
    image: Rgba,
    state: Value,
    stdout: String,
}

/// Opens the window (on `scene` when given) at `size` points, `scale` pixels a point, and takes
/// its screenshot.
fn shoot(name: &str, size: &str, scale: usize, scene: Option<&Path>) -> Shot {
    let png = temp(&format!("{name}.png"));
    let json = temp(&format!("{name}.json"));
    let data = temp(&format!("{name}-data"));
    let mut args = vec!["--window", size];
    if let Some(scene) = scene {
        args.push(scene.to_str().unwrap());
    }
    args.extend([
        "--screenshot",
        png.to_str().unwrap(),
        "--state-out",
        json.to_str().unwrap(),
    ]);
    let out = in_window(&args, &data, scale);
    assert!(out.status.success(), "{}", stderr(&out));
    // A run that succeeds prints no line that reads like a failure (Mesa's device-select layer
    // looking for a Wayland session printed `error: XDG_RUNTIME_DIR is invalid…` four times).
    assert!(
        !stderr(&out)
            .lines()
            .any(|l| l.starts_with("error") || l.contains("XDG_RUNTIME_DIR")),
        "{}",
        stderr(&out)
    );
    Shot {
        scale,
        image: Rgba::read(&png),
        state: serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
    }
}

/// The scene's sky colour as the window shows it (sRGB-encoded in the document).
fn sky(state: &Value) -> [u8; 3] {
    let bg = &state["scene"]["light"]["background"];
    [0, 1, 2].map(|i| (bg[i].as_f64().unwrap() * 255.0).round() as u8)
}

/// Pixels of the view that are not sky, leaving out the sun handle's box, the notice line at
/// the view's top and the status line at its foot (the overlays a scene without a cloud still
/// shows).
fn cloud_pixels(shot: &Shot) -> (usize, usize) {
    let view = &shot.state["view"];
    let w = view["viewport"][0].as_u64().unwrap() as usize;
    let h = view["viewport"][1].as_u64().unwrap() as usize;
    // The sun handle's place is in points.
    let handle = &view["sun_handle"];
    let s = shot.scale as f64;
    let (cx, cy, r) = (
        handle["center"][0].as_f64().unwrap() * s,
        handle["center"][1].as_f64().unwrap() * s,
        (handle["radius"].as_f64().unwrap() + 6.0) * s,
    );
    let band = 32 * shot.scale;
    let skip = |x: usize, y: usize| {
        ((x as f64 - cx).abs() <= r && (y as f64 - cy).abs() <= r) || y < band || y + band >= h
    };
    let n = shot
        .image
        .differing((0, w), (0, h), sky(&shot.state), 12, skip);
    (n, w * h)
}

/// The default cloud in a window of `width`×`height` points at `scale` pixels a point: the
/// cloud in the view, the sky around it, the side panel beside it. Returns the shot.
fn default_cloud(width: usize, height: usize, scale: usize) -> Shot {
    let shot = shoot(
        &format!("default-{width}x{height}@{scale}"),
        &format!("{width}x{height}"),
        scale,
        None,
    );
    let (width, height) = (width * scale, height * scale);
    assert_eq!(
        (shot.image.width, shot.image.height),
        (width, height),
        "the window's size"
    );
    let view = &shot.state["view"];
    assert!(
        view["quality"].as_str().unwrap().starts_with("full"),
        "{view}"
    );
    assert_eq!(view["backend"], "vulkan", "{view}");
    assert!(
        shot.stdout.contains(&format!("{width}x{height} pixels")),
        "{}",
        shot.stdout
    );

    // The cloud: at least 3% of the view, and sky in the view's top-left corner.
    let (cloud, area) = cloud_pixels(&shot);
    assert!(cloud * 100 > 3 * area, "{cloud} cloud pixels of {area}");
    assert_eq!(shot.image.at(3, 3), sky(&shot.state), "the sky at (3, 3)");

    // The side panel right of the view: its own flat fill down its left margin, widgets over it.
    let w = view["viewport"][0].as_u64().unwrap() as usize;
    let fill = shot.image.at(w + 4, height / 2);
    assert_eq!(
        shot.image
            .differing((w + 4, w + 6), (100, height - 20), fill, 6, |_, _| false),
        0,
        "the panel's background"
    );
    let sky_distance: u32 = (0..3)
        .map(|c| fill[c].abs_diff(sky(&shot.state)[c]) as u32)
        .sum();
    assert!(sky_distance > 60, "the panel {fill:?} is not the sky");
    let widgets = shot
        .image
        .differing((w + 1, width), (0, height), fill, 24, |_, _| false);
    assert!(widgets > 3000, "{widgets} pixels of the panel's widgets");
    shot
}

#[test]
fn the_window_draws_the_default_cloud_beside_its_panel_and_opens_a_scene_file() {
    default_cloud(1920, 1080, 1);
    // A HiDPI screen: the same window in twice the pixels, the cloud drawn in them at the same
    // share of the view as at one pixel a point (a volume drawn at twice its size, or half,
    // covers another share).
    let (hidpi, area2) = cloud_pixels(&default_cloud(1280, 800, 2));
    let (one, area) = cloud_pixels(&default_cloud(1280, 800, 1));
    let (share2, share1) = (hidpi as f64 / area2 as f64, one as f64 / area as f64);
    assert!(
        (share2 / share1 - 1.0).abs() < 0.1,
        "the cloud covers {:.1}% of the view at 2x and {:.1}% at 1x",
        share2 * 100.0,
        share1 * 100.0
    );

    // The baseline: a scene file without a cloud, with another sky. The window opens the file
    // (its name in the state), shows that sky, and nothing of a cloud.
    let scene_path = temp("empty-scene.json");
    let mut scene: Value = serde_json::from_str(
        &cloudsketch::scene::Scene::preset(cloudsketch::scene::Preset::Empty).to_json(),
    )
    .unwrap();
    scene["light"]["background"] = serde_json::json!([0.8, 0.35, 0.2]);
    std::fs::write(&scene_path, scene.to_string()).unwrap();
    let empty = shoot("empty", "1280x800", 1, Some(&scene_path));
    assert_eq!(sky(&empty.state), [204, 89, 51]);
    assert!(
        empty.state["view"]["file"]
            .as_str()
            .unwrap()
            .ends_with("empty-scene.json"),
        "{}",
        empty.state["view"]
    );
    assert_eq!(empty.image.at(3, 3), sky(&empty.state), "the file's sky");
    let (none, _) = cloud_pixels(&empty);
    assert!(
        none * 10_000 < area,
        "{none} pixels off the sky without a cloud"
    );
}

#[test]
fn the_window_reports_bad_arguments_and_an_unwritable_screenshot() {
    let data = temp("bad-data");
    let out = in_window(&["--window", "0x0"], &data, 1);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("WIDTHxHEIGHT"), "{}", stderr(&out));

    let out = in_window(&["--state-out", "x.json"], &data, 1);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("--screenshot"), "{}", stderr(&out));

    // A folder that cannot be made (sysfs refuses new entries, root included).
    let out = in_window(
        &["--screenshot", "/sys/cloudsketch-new/window.png"],
        &data,
        1,
    );
    assert!(!out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("cannot make the folder /sys/cloudsketch-new"),
        "{}",
        stderr(&out)
    );

    let out = in_window(&["new", "-o", "x.json", "--screenshot", "a.png"], &data, 1);
    assert!(!out.status.success());

    // Two outputs that are one file are refused before the window opens.
    let shot = temp("same.png");
    let shot = shot.to_str().unwrap();
    let out = in_window(&["--screenshot", shot, "--state-out", shot], &data, 1);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("the same file"), "{}", stderr(&out));
    assert!(!Path::new(shot).exists());

    // A screenshot run that cannot open its scene fails, and saves no picture of anything else.
    let bad = temp("bad.json");
    std::fs::write(&bad, "{\"version\": 1, \"ellipsoids\": 5}").unwrap();
    let shot = temp("bad.png");
    let out = in_window(
        &[
            bad.to_str().unwrap(),
            "--screenshot",
            shot.to_str().unwrap(),
        ],
        &data,
        1,
    );
    assert!(!out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("bad.json"), "{}", stderr(&out));
    assert!(!shot.exists(), "a picture was saved");
}

/// Drives an open window with xdotool: the Sketch tool (D), a closed stroke of 60 moves around a
/// circle (`$PACE` between moves: empty sends them all at once, faster than any frame), Ctrl+S;
/// then Ctrl+Z and Ctrl+S again in one call (on a slow frame both land in one frame). Each save
/// is copied aside once the file changes. With `$BUSY` set to 1, a busy loop runs on every core
/// from the window's appearance to the end (a machine doing other work: its frames are slow).
const DRIVE: &str = r#"
set -u
"$BIN" "$SCENE" --window 1280x800 & app=$!
busy=""
trap 'kill $app $busy 2>/dev/null' EXIT INT TERM HUP
alive() { kill -0 "$app" 2>/dev/null || { echo "the app exited" >&2; exit 1; }; }
wid=$(timeout 60 xdotool search --sync --onlyvisible --name '^cloudsketch$' | head -n 1)
[ -n "$wid" ] || { echo "no window appeared" >&2; exit 1; }
if [ "$BUSY" = 1 ]; then
  # Each loop also ends by itself within the test's time, whatever becomes of this script.
  for _ in $(seq 1 "$(nproc)"); do timeout 240 sh -c 'while :; do :; done' & busy="$busy $!"; done
fi
# Events sent before the first frame would wait for it (winit queues them); this only lets the
# window settle so the input meets a running app, as a person's would.
sleep 3
alive
xdotool windowfocus --sync "$wid" mousemove --window "$wid" 400 400 key d || exit 1
sleep 0.5
moves="mousemove --window $wid 520 400 mousedown 1"
for i in $(seq 1 60); do
  xy=$(awk -v i="$i" 'BEGIN { a = i / 60 * 6.2831853; printf "%d %d", 400 + 120 * cos(a), 400 + 120 * sin(a) }')
  moves="$moves mousemove --window $wid $xy $PACE"
done
xdotool $moves mouseup 1 || exit 1
sleep 0.5
# Saves with KEYS and waits (at most 60 s) for the file to change; copies it to $1.
save() {
  before=$(stat -c %y "$SCENE")
  xdotool key --window "$wid" $KEYS ctrl+s || exit 1
  for _ in $(seq 1 120); do
    [ "$(stat -c %y "$SCENE")" != "$before" ] && { cp "$SCENE" "$1"; return 0; }
    alive
    sleep 0.5
  done
  echo "the scene was not saved ($1)" >&2; exit 1
}
KEYS="" save "$SAVED1"
KEYS="ctrl+z" save "$SAVED2"
"#;

/// Sketches a stroke in the window (moves `pace` apart, e.g. `sleep 0.015`, or all at once; with
/// every core `busy`), and returns the scene saved after it and the one saved after undoing it.
fn sketch_in_window(name: &str, pace: &str, busy: bool) -> (Value, Value) {
    require("xdotool", "xdotool");
    let scene = temp(&format!("{name}.json"));
    let empty = cloudsketch::scene::Scene::preset(cloudsketch::scene::Preset::Empty);
    std::fs::write(&scene, empty.to_json()).unwrap();
    let saved = [1, 2].map(|i| temp(&format!("{name}-saved{i}.json")));
    for path in &saved {
        let _ = std::fs::remove_file(path);
    }
    let data = temp(&format!("{name}-data"));
    let out = under_xvfb(
        "sh",
        &["-c", DRIVE],
        &data,
        1,
        &[
            ("BIN", OsStr::new(env!("CARGO_BIN_EXE_cloudsketch"))),
            ("SCENE", scene.as_os_str()),
            ("SAVED1", saved[0].as_os_str()),
            ("SAVED2", saved[1].as_os_str()),
            ("PACE", OsStr::new(pace)),
            ("BUSY", OsStr::new(if busy { "1" } else { "0" })),
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    saved
        .map(|path| serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap())
        .into()
}

/// The points of a saved scene's planes.
fn plane_points(scene: &Value) -> Vec<usize> {
    scene["planes"]
        .as_array()
        .map(|planes| {
            planes
                .iter()
                .map(|p| p["points"].as_array().map_or(0, Vec::len))
                .collect()
        })
        .unwrap_or_default()
}

#[test]
fn the_window_keeps_every_sample_of_a_stroke_and_undoes_it() {
    // 61 samples (the press and 60 moves), every one, whether the moves come 15 ms apart
    // (several frames' worth) or all at once (within a frame or two, which egui sees as neither
    // a drag nor a click: the stroke was lost natively before the press record). Which frames
    // the events fall into is the window's business; `ui::sketch_tool`'s unit test splits them
    // deterministically. The burst runs beside a busy loop on every core, so its frames are slow
    // and the Ctrl+Z, Ctrl+S sent together land in one frame: the save must follow the undo
    // (`ui::app`'s unit test orders them deterministically).
    for (name, pace, busy) in [("paced", "sleep 0.015", false), ("burst", "", true)] {
        let (drawn, undone) = sketch_in_window(name, pace, busy);
        let points = plane_points(&drawn);
        assert_eq!(points, [61], "{name}: one drawing plane with every sample");
        assert_eq!(plane_points(&undone), Vec::<usize>::new(), "{name}: undone");
    }
}

#[test]
fn a_screenshot_run_leaves_the_users_autosave_as_it_was() {
    // A real data folder with a session in it: the screenshot of a file neither writes over
    // that session nor keeps it aside (as opening a file in the app would).
    let data = temp("kept-data");
    let store = data.join("cloudsketch");
    std::fs::create_dir_all(&store).unwrap();
    let session = cloudsketch::scene::Scene::preset(cloudsketch::scene::Preset::Stratus).to_json();
    std::fs::write(store.join("autosave.json"), &session).unwrap();
    let listing = || {
        let mut names: Vec<String> = std::fs::read_dir(&store)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    };
    let scene = temp("kept-scene.json");
    std::fs::write(
        &scene,
        cloudsketch::scene::Scene::preset(cloudsketch::scene::Preset::Empty).to_json(),
    )
    .unwrap();
    let shot = temp("kept.png");
    let out = in_window(
        &[
            scene.to_str().unwrap(),
            "--screenshot",
            shot.to_str().unwrap(),
        ],
        &data,
        1,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(shot.exists());
    assert_eq!(
        std::fs::read_to_string(store.join("autosave.json")).unwrap(),
        session
    );
    assert_eq!(
        listing(),
        ["autosave.json"],
        "nothing was kept aside or left behind"
    );
}
