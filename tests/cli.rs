//! The native CLI, driven as a user would: `new`, `render`, `--set` and its errors.

use std::path::PathBuf;
use std::process::{Command, Output};

fn cloudsketch(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cloudsketch"))
        .args(args)
        .output()
        .expect("run cloudsketch")
}

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cloudsketch-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn new_writes_the_default_scene() {
    let path = temp("new.json");
    let out = cloudsketch(&["new", "-o", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let scene = cloudsketch::scene::Scene::from_json(&std::fs::read_to_string(&path).unwrap())
        .unwrap()
        .0;
    assert_eq!(scene, cloudsketch::scene::Scene::default());

    let empty = temp("empty.json");
    let out = cloudsketch(&["new", "--preset", "empty", "-o", empty.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let scene = cloudsketch::scene::Scene::from_json(&std::fs::read_to_string(&empty).unwrap())
        .unwrap()
        .0;
    assert!(scene.ellipsoids.is_empty());

    let out = cloudsketch(&[
        "new",
        "--preset",
        "nimbus9",
        "-o",
        temp("x.json").to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("unknown preset"), "{}", stderr(&out));
}

#[test]
fn render_writes_a_png_of_the_scene() {
    let scene = temp("scene.json");
    assert!(
        cloudsketch(&["new", "-o", scene.to_str().unwrap()])
            .status
            .success()
    );
    let png = temp("out.png");
    let out = cloudsketch(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--size",
        "96x64",
        "--set",
        "/render/slices=32",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    // A successful render says so and nothing that reads like a failure (on a machine with
    // no display, Mesa's device-select layer would print XDG_RUNTIME_DIR errors).
    let err = stderr(&out);
    assert!(err.contains("rendered 96x64"), "{err}");
    assert!(!err.to_lowercase().contains("error"), "{err}");
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
    let reader = decoder.read_info().unwrap();
    let info = reader.info();
    assert_eq!((info.width, info.height), (96, 64));
}

/// Renders the default scene at 96×64 with `sets` applied; the image's RGB bytes.
fn render_with(name: &str, sets: &[&str]) -> Vec<u8> {
    let png = temp(name);
    let mut args = vec!["render", "-o", png.to_str().unwrap(), "--size", "96x64"];
    for s in sets {
        args.extend(["--set", s]);
    }
    args.extend(["--set", "/render/slices=32"]);
    let out = cloudsketch(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    read_rgb(&png)
}

/// A PNG's pixels as RGB bytes.
fn read_rgb(png: &std::path::Path) -> Vec<u8> {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(png).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    buf.chunks(channels).flat_map(|p| p[..3].to_vec()).collect()
}

/// Mean x (pixels) of the pixels that differ from the top-left one (the sky), and their count.
fn cloud_centroid(rgb: &[u8]) -> (f64, usize) {
    let sky = &rgb[..3];
    let (mut sum, mut n) = (0.0, 0);
    for (i, p) in rgb.chunks(3).enumerate() {
        let d: i32 = p
            .iter()
            .zip(sky)
            .map(|(a, b)| (*a as i32 - *b as i32).abs())
            .sum();
        if d > 24 {
            sum += (i % 96) as f64;
            n += 1;
        }
    }
    (sum / n.max(1) as f64, n)
}

#[test]
fn set_moves_and_hides_ellipsoids() {
    let base = cloud_centroid(&render_with("e-base.png", &[]));
    // Every ellipsoid but the first hidden, and the first moved right then left: the cloud goes
    // with it.
    let hide: Vec<String> = (1..6)
        .map(|i| format!("/ellipsoids/{i}/hidden=true"))
        .collect();
    let mut sets: Vec<&str> = hide.iter().map(String::as_str).collect();
    let right = cloud_centroid(&render_with(
        "e-right.png",
        &[&sets[..], &["/ellipsoids/0/center=[5,3,0]"]].concat(),
    ));
    sets.push("/ellipsoids/0/center=[-5,3,0]");
    let left = cloud_centroid(&render_with("e-left.png", &sets));
    assert!(
        base.1 > 300 && right.1 > 50 && left.1 > 50,
        "{base:?} {right:?} {left:?}"
    );
    assert!(
        right.1 < base.1 && left.1 < base.1,
        "one ellipsoid covers less than six"
    );
    assert!(
        right.0 > left.0 + 25.0,
        "moved with its centre: {} vs {}",
        right.0,
        left.0
    );
}

#[test]
fn bad_input_is_a_clear_error() {
    let png = temp("never.png");
    let p = png.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["render", "-o", p, "--set", "/render/nope=3"],
            "/render/nope",
        ),
        (
            &["render", "-o", p, "--set", "/render/slices=\"many\""],
            "/render/slices",
        ),
        (&["render", "-o", p, "--set", "render.slices"], "PATH=VALUE"),
        (&["render", "-o", p, "--size", "0x5"], "WIDTHxHEIGHT"),
        (&["render", "-o", p, "--size", "100000x5"], "WIDTHxHEIGHT"),
        (
            &["render", "/definitely/not/here.json", "-o", p],
            "here.json",
        ),
    ];
    for (args, needle) in cases {
        let out = cloudsketch(args);
        assert!(!out.status.success(), "{args:?} succeeded");
        let err = stderr(&out);
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    assert!(!png.exists());

    let garbage = temp("garbage.json");
    std::fs::write(
        &garbage,
        "{\"version\": 1, \"ellipsoids\": [{\"center\": 5}]}",
    )
    .unwrap();
    let out = cloudsketch(&["render", garbage.to_str().unwrap(), "-o", p]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("garbage.json"), "{}", stderr(&out));
}

fn write_stroke(name: &str, points: &[[f64; 2]], closed: bool) -> PathBuf {
    let path = temp(name);
    std::fs::write(
        &path,
        serde_json::json!({ "points": points, "closed": closed, "pen": "ignored" }).to_string(),
    )
    .unwrap();
    path
}

/// A cloud outline in canvas units (y down): flat base at y = 300, bumps on top.
fn canvas_cloud() -> Vec<[f64; 2]> {
    let mut v: Vec<[f64; 2]> = (0..=60).map(|i| [100.0 + i as f64 * 5.0, 300.0]).collect();
    for i in 1..160 {
        let a = i as f64 / 160.0 * std::f64::consts::PI;
        let bump = 1.0 + 0.15 * (a * 7.0).sin().abs();
        v.push([250.0 + 150.0 * a.cos(), 300.0 - 110.0 * a.sin() * bump]);
    }
    v
}

#[test]
fn sketch_makes_a_scene_and_spheres_that_fit_the_outline() {
    let stroke = write_stroke("cloud.json", &canvas_cloud(), true);
    let scene_path = temp("sketched.json");
    let spheres_path = temp("spheres.json");
    let out = cloudsketch(&[
        "sketch",
        stroke.to_str().unwrap(),
        "-o",
        scene_path.to_str().unwrap(),
        "--spheres-out",
        spheres_path.to_str().unwrap(),
        "--seed",
        "5",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let scene =
        cloudsketch::scene::Scene::from_json(&std::fs::read_to_string(&scene_path).unwrap())
            .unwrap()
            .0;
    assert_eq!(scene.planes.len(), 1);
    assert_eq!(
        scene.planes[0].billows,
        cloudsketch::scene::Billows::NEW,
        "billows, as the app gives a new stroke"
    );
    let spheres: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&spheres_path).unwrap()).unwrap();
    let spheres = spheres["spheres"].as_array().unwrap();
    assert!(spheres.len() > 20);
    // In the stroke's own units and axes: inside the drawn box, with depth toward the viewer.
    let (mut zmin, mut zmax) = (f64::MAX, f64::MIN);
    for s in spheres {
        let c: Vec<f64> = s["center"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let r = s["radius"].as_f64().unwrap();
        assert!(c[0] - r >= 99.0 && c[0] + r <= 401.0, "{c:?} r {r}");
        assert!(
            c[1] + r <= 301.0 && c[1] - r >= 300.0 - 110.0 * 1.16,
            "{c:?} r {r}"
        );
        zmin = zmin.min(c[2] - r);
        zmax = zmax.max(c[2] + r);
    }
    // Deeper than the same stroke without the 3D extension, whose depth is its widest
    // sphere's (measured 132 against 118).
    let flat_path = temp("spheres-flat.json");
    let out = cloudsketch(&[
        "sketch",
        stroke.to_str().unwrap(),
        "-o",
        temp("sketched-flat.json").to_str().unwrap(),
        "--spheres-out",
        flat_path.to_str().unwrap(),
        "--seed",
        "5",
        "--no-extend",
        "--billows",
        "0",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let smooth = cloudsketch::scene::Scene::from_json(
        &std::fs::read_to_string(temp("sketched-flat.json")).unwrap(),
    )
    .unwrap()
    .0;
    assert!(smooth.planes[0].billows.is_off());
    let out = cloudsketch(&[
        "sketch",
        stroke.to_str().unwrap(),
        "-o",
        temp("sketched-bad.json").to_str().unwrap(),
        "--billows",
        "9",
    ]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("--billows 9 is outside 0..=4"),
        "{}",
        stderr(&out)
    );
    let flat: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&flat_path).unwrap()).unwrap();
    let flat_depth = flat["spheres"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| 2.0 * s["radius"].as_f64().unwrap())
        .fold(0.0, f64::max);
    assert!(
        zmax - zmin >= 1.05 * flat_depth,
        "depth {} with the extension, {flat_depth} without",
        zmax - zmin
    );

    // The scene renders: the cloud is where the default camera looks.
    let png = temp("sketched.png");
    let out = cloudsketch(&[
        "render",
        scene_path.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--size",
        "80x60",
        "--set",
        "/render/slices=24",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));

    // --no-extend keeps the spheres in the drawing plane.
    let flat = temp("flat.json");
    let out = cloudsketch(&[
        "sketch",
        stroke.to_str().unwrap(),
        "-o",
        temp("flat-scene.json").to_str().unwrap(),
        "--spheres-out",
        flat.to_str().unwrap(),
        "--no-extend",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let flat: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&flat).unwrap()).unwrap();
    assert!(
        flat["spheres"]
            .as_array()
            .unwrap()
            .iter()
            .all(|s| s["center"][2].as_f64().unwrap() == 0.0)
    );
}

#[test]
fn sketch_repairs_or_refuses_bad_strokes() {
    // Overlapping ends: repaired, exit 0, warning on stderr.
    let mut over = canvas_cloud();
    over.extend(
        canvas_cloud()
            .into_iter()
            .take(40)
            .map(|[x, y]| [x, y + 3.0]),
    );
    over.push([90.0, 320.0]);
    let path = write_stroke("over.json", &over, false);
    let out = cloudsketch(&[
        "sketch",
        path.to_str().unwrap(),
        "-o",
        temp("over-scene.json").to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("warning"), "{}", stderr(&out));

    // A stroke over the point cap is thinned with a warning, and the scene holds the stroke
    // that was used (it used to be thinned, then refused by validation: exit 1).
    let dense: Vec<[f64; 2]> = (0..30_000)
        .map(|i| i as f64 / 30_000.0 * std::f64::consts::TAU)
        .map(|a| [200.0 + 150.0 * a.cos(), 200.0 + 100.0 * a.sin()])
        .collect();
    let path = write_stroke("dense.json", &dense, true);
    let scene_path = temp("dense-scene.json");
    let out = cloudsketch(&[
        "sketch",
        path.to_str().unwrap(),
        "-o",
        scene_path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("thinned to"), "{}", stderr(&out));
    let (scene, _) =
        cloudsketch::scene::Scene::from_json(&std::fs::read_to_string(&scene_path).unwrap())
            .unwrap();
    assert_eq!(
        scene.planes[0].points.len(),
        cloudsketch::limits::MAX_PLANE_POINTS
    );

    for (name, points) in [
        ("line.json", vec![[0.0, 0.0], [10.0, 10.0], [20.0, 20.0]]),
        ("dot.json", vec![[5.0, 5.0]]),
        ("two.json", vec![[0.0, 0.0], [1.0, 0.0]]),
    ] {
        let path = write_stroke(name, &points, true);
        let out = cloudsketch(&[
            "sketch",
            path.to_str().unwrap(),
            "-o",
            temp("never.json").to_str().unwrap(),
        ]);
        assert!(!out.status.success(), "{name} accepted");
        let err = stderr(&out);
        assert_eq!(err.trim().lines().count(), 1, "{name}: {err}");
        assert!(err.contains(name) && !err.contains("panicked"), "{err}");
    }
    let junk = temp("junk.json");
    std::fs::write(&junk, "{\"points\": 3}").unwrap();
    let out = cloudsketch(&[
        "sketch",
        junk.to_str().unwrap(),
        "-o",
        temp("never.json").to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("not a stroke file"));
    assert!(!temp("never.json").exists());
}

#[test]
fn bench_reports_ratios_as_json() {
    // The field group's brute force takes minutes in a debug build: two quick groups here.
    let out = cloudsketch(&["bench", "--json", "--only", "sketch,render"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(report["machine"].as_str().unwrap().contains("adapter"));
    let results = report["results"].as_array().unwrap();
    for name in [
        "render_frame_1280x720_128_slices",
        "sketch_500_point_stroke_to_spheres",
    ] {
        let r = results
            .iter()
            .find(|r| r["name"] == name)
            .unwrap_or_else(|| panic!("{name} missing"));
        let (v, b, ratio) = (
            r["value"].as_f64().unwrap(),
            r["baseline_value"].as_f64().unwrap(),
            r["ratio"].as_f64().unwrap(),
        );
        assert!(v > 0.0 && b > 0.0 && ((b / v) - ratio).abs() < 1e-9 * ratio.max(1.0));
    }
    assert_eq!(results.len(), 2, "only the groups asked for");
}

#[test]
fn link_makes_a_url_that_decodes_and_renders_and_refuses_a_broken_one() {
    let scene = temp("for-link.json");
    let path = scene.to_str().unwrap();
    assert!(
        cloudsketch(&["new", "--preset", "stratus", "-o", path])
            .status
            .success()
    );
    let out = cloudsketch(&["link", path]);
    assert!(out.status.success(), "{}", stderr(&out));
    let url = String::from_utf8_lossy(&out.stdout).trim().to_owned();
    assert!(url.starts_with("http://127.0.0.1:8080/#s="), "{url}");
    assert!(stderr(&out).contains("characters"));
    let out = cloudsketch(&["link", path, "--base", "https://clouds.example/app/"]);
    let other = String::from_utf8(out.stdout).unwrap();
    assert!(
        other.starts_with("https://clouds.example/app/#s="),
        "{other}"
    );

    let back = temp("from-link.json");
    let out = cloudsketch(&["link", "--decode", &url, "-o", back.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let decoded = cloudsketch::scene::Scene::from_json(&std::fs::read_to_string(&back).unwrap())
        .unwrap()
        .0;
    let original = cloudsketch::scene::Scene::preset(cloudsketch::scene::Preset::Stratus);
    assert_eq!(decoded.ellipsoids.len(), original.ellipsoids.len());
    assert_eq!(decoded.render.noise_filter, original.render.noise_filter);

    // `render` takes the link where it takes a file, and draws the same picture.
    let from_url = temp("from-url.png");
    let from_file = temp("from-file.png");
    for (input, png) in [(url.as_str(), &from_url), (path, &from_file)] {
        let out = cloudsketch(&[
            "render",
            input,
            "-o",
            png.to_str().unwrap(),
            "--size",
            "96x64",
            "--set",
            "/render/slices=32",
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let (a, b) = (read_rgb(&from_url), read_rgb(&from_file));
    let worst = a.iter().zip(&b).map(|(x, y)| x.abs_diff(*y)).max().unwrap();
    assert!(worst <= 3, "link and file render {worst} apart");

    // A damaged link is an error that says so, and writes nothing.
    let never = temp("never.json");
    let cut = &url[..url.len() / 2];
    let out = cloudsketch(&["link", "--decode", cut, "-o", never.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("damaged"), "{}", stderr(&out));
    assert!(!never.exists());
    let out = cloudsketch(&[
        "link",
        "--decode",
        "https://example.org/",
        "-o",
        never.to_str().unwrap(),
    ]);
    assert!(stderr(&out).contains("no \"#s=\" part"), "{}", stderr(&out));
}

#[test]
fn export_and_simulate_refuse_bad_requests_clearly_and_write_what_is_asked() {
    let out = temp("bad.vdb");
    for (args, says) in [
        (vec!["export", "--format", "stl"], "unknown format"),
        (
            vec!["export", "--format", "vdb", "--resolution", "9999"],
            "--resolution 9999",
        ),
        (vec!["export", "--format", "vdb", "--up", "x"], "--up"),
        (vec!["export", "--format", "vdb", "--scale=0"], "--scale"),
        (vec!["simulate", "--steps", "999999999"], "--steps"),
    ] {
        let mut a = args.clone();
        a.extend(["-o", out.to_str().unwrap()]);
        let o = cloudsketch(&a);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(stderr(&o).contains(says), "{args:?}: {}", stderr(&o));
        assert!(
            !o.stderr.windows(8).any(|w| w == b"panicked"),
            "{args:?} panicked"
        );
    }
    // A scene without a simulation says so; the default scene's file is not written.
    let scene = temp("plain.json");
    assert!(
        cloudsketch(&["new", "-o", scene.to_str().unwrap()])
            .status
            .success()
    );
    let o = cloudsketch(&[
        "simulate",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(stderr(&o).contains("no simulation"), "{}", stderr(&o));
    assert!(
        !o.status.success(),
        "a scene without a simulation is an error"
    );
    assert!(!out.exists(), "nothing was written");
    // The simulated preset's run writes a VDB that starts with OpenVDB's magic.
    let vdb = temp("sim.vdb");
    let o = cloudsketch(&["simulate", "--steps", "30", "-o", vdb.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&vdb).unwrap();
    assert_eq!(&bytes[..8], &0x5644_4220i64.to_le_bytes());
}

/// The files in a folder, sorted.
fn listing(dir: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A fresh folder of its own under the test's temporary folder.
fn folder(name: &str) -> PathBuf {
    let dir = temp(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn outputs_that_collide_or_cannot_be_written_are_refused_before_any_work() {
    let dir = folder("collide");
    // Leaked: each is one short path, for the lists of arguments below.
    let at = |name: &str| -> &'static str {
        Box::leak(dir.join(name).to_str().unwrap().to_owned().into_boxed_str())
    };
    let scene = at("scene.json");
    assert!(cloudsketch(&["new", "-o", scene]).status.success());
    let scene_text = std::fs::read(scene).unwrap();
    let stroke = write_stroke("collide-stroke.json", &canvas_cloud(), true);
    let stroke = stroke.to_str().unwrap();
    std::fs::create_dir(dir.join("taken.vol")).unwrap();
    std::fs::write(dir.join("taken.vol/inside"), b"x").unwrap();
    let dot_a = format!("{}/./a.json", dir.display());
    let dot_a = dot_a.as_str();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        // Mitsuba's volume would overwrite its own XML.
        (
            vec!["export", &scene, "--format", "mitsuba", "-o", at("foo.vol")],
            "the same file as the output",
        ),
        (
            vec!["sketch", stroke, "-o", at("a.json"), "--spheres-out", dot_a],
            "the same file as the output",
        ),
        (
            vec!["render", &scene, "-o", &scene],
            "the same file as the input",
        ),
        (
            vec!["export", &scene, "--format", "vdb", "-o", &scene],
            "the same file as the input",
        ),
        // Mitsuba's volume cannot be written (a folder holds its name): no XML either.
        (
            vec![
                "export",
                &scene,
                "--format",
                "mitsuba",
                "-o",
                at("taken.xml"),
            ],
            "taken.vol: a folder",
        ),
        (
            vec!["render", &scene, "-o", dir.to_str().unwrap()],
            "a folder",
        ),
    ];
    // A folder nobody may write in, root included (the suite runs as root in CI, where a
    // folder without write permission would take the file): sysfs refuses new files (for want
    // of permission, or mounted read-only in a container; the reason is the OS's either way).
    let sysfs = std::path::Path::new("/sys").is_dir();
    let unwritable: Vec<(Vec<&str>, &str)> = vec![
        // A folder that cannot be made.
        (
            vec!["render", &scene, "-o", "/sys/cloudsketch-new/x.png"],
            "cannot make the folder /sys/cloudsketch-new",
        ),
        (
            vec![
                "render",
                &scene,
                "--size",
                "64x36",
                "-o",
                "/sys/cloudsketch.png",
            ],
            "cannot write /sys/cloudsketch.png",
        ),
        (
            vec![
                "render",
                &scene,
                "--size",
                "64x36",
                "--frames",
                "0..2",
                "-o",
                "/sys/cloudsketch_####.png",
            ],
            "cannot write /sys/cloudsketch_0000.png: ",
        ),
        (
            vec![
                "export",
                &scene,
                "--format",
                "mitsuba",
                "-o",
                "/sys/cloudsketch.xml",
            ],
            "cannot write /sys/cloudsketch.xml",
        ),
        (
            vec![
                "export",
                &scene,
                "--format",
                "glb",
                "--frames",
                "0..1",
                "-o",
                "/sys/cloudsketch_####.glb",
            ],
            "(no frame was written)",
        ),
    ];
    let cases = cases
        .into_iter()
        .chain(unwritable.into_iter().filter(|_| sysfs));
    for (args, says) in cases {
        let o = cloudsketch(&args);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(stderr(&o).contains(says), "{args:?}: {}", stderr(&o));
        assert_eq!(
            listing(&dir),
            ["scene.json", "taken.vol"],
            "{args:?} left files behind"
        );
        assert_eq!(std::fs::read(scene).unwrap(), scene_text, "{args:?}");
    }
    // An output's folder that does not exist yet is made, as a sequence's is, but only by the
    // write: a command refused or failed before it leaves no empty folder.
    let never = dir.join("never/x.png");
    let o = cloudsketch(&[
        "render",
        "no-such-scene.json",
        "-o",
        never.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(
        !dir.join("never").exists(),
        "a failed render made its folder"
    );
    let nested = dir.join("new/folder/x.png");
    let o = cloudsketch(&[
        "render",
        scene,
        "--size",
        "64x36",
        "-o",
        nested.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(&std::fs::read(&nested).unwrap()[1..4], b"PNG");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn what_a_file_holds_is_said_plainly() {
    let dir = folder("plain");
    // Leaked: each is one short path, for the lists of arguments below.
    let at = |name: &str| -> &'static str {
        Box::leak(dir.join(name).to_str().unwrap().to_owned().into_boxed_str())
    };
    let png = at("never.png");
    std::fs::write(at("empty.json"), "{}").unwrap();
    let stroke = write_stroke("plain-stroke.json", &canvas_cloud(), true);
    std::fs::write(
        at("three.json"),
        r#"{"points": [[0, 0, 1], [1, 0], [0, 1]]}"#,
    )
    .unwrap();
    let huge: Vec<[f64; 2]> = canvas_cloud()
        .iter()
        .map(|&[x, y]| [x * 1e200, y * 1e200])
        .collect();
    let huge = write_stroke("plain-huge.json", &huge, true);
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["render", at("empty.json"), "-o", &png],
            "holds none of a scene's members",
        ),
        (
            vec!["render", stroke.to_str().unwrap(), "-o", &png],
            "holds none of a scene's members",
        ),
        (vec!["render", "", "-o", &png], "the path is empty"),
        (
            vec!["sketch", at("three.json"), "-o", at("s.json")],
            "point 0 has 3 numbers",
        ),
        (
            vec!["sketch", huge.to_str().unwrap(), "-o", at("s.json")],
            "a stroke spans",
        ),
        (vec!["bench", "--only", "bogus"], "no bench group bogus"),
        (
            vec![
                "export",
                "--format",
                "obj",
                "--scale",
                "1e38",
                "-o",
                at("big.obj"),
            ],
            "--scale",
        ),
    ];
    for (args, says) in &cases {
        let o = cloudsketch(args);
        assert!(!o.status.success(), "{args:?} succeeded");
        let err = stderr(&o);
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(!err.contains(": :"), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    assert!(!std::path::Path::new(&png).exists());

    // A byte-order mark before a scene is no error; a file whose name holds `#s=` is a file.
    let scene = at("x#s=AQ.json");
    assert!(
        cloudsketch(&["new", "--preset", "empty", "-o", scene])
            .status
            .success()
    );
    let mut bom = b"\xef\xbb\xbf".to_vec();
    bom.extend(std::fs::read(scene).unwrap());
    std::fs::write(scene, bom).unwrap();
    let o = cloudsketch(&["link", scene]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_sketched_scenes_link_holds_its_strokes_exactly() {
    // `sketch` stores strokes on the stroke grid as the app does, so the link of its scene
    // decodes to the very same points (before, they moved by up to half a step).
    let stroke = write_stroke("exact-stroke.json", &canvas_cloud(), true);
    let scene = temp("exact.json");
    let o = cloudsketch(&[
        "sketch",
        stroke.to_str().unwrap(),
        "-o",
        scene.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = cloudsketch(&["link", scene.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        !stderr(&o).contains("off the stroke grid"),
        "{}",
        stderr(&o)
    );
    let url = String::from_utf8_lossy(&o.stdout).trim().to_owned();
    let back = temp("exact-back.json");
    let o = cloudsketch(&["link", "--decode", &url, "-o", back.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let read = |p: &std::path::Path| {
        cloudsketch::scene::Scene::from_json(&std::fs::read_to_string(p).unwrap())
            .unwrap()
            .0
    };
    let (sketched, decoded) = (read(&scene), read(&back));
    assert_eq!(sketched.planes.len(), 1);
    assert_eq!(decoded.planes[0].points, sketched.planes[0].points);
}

#[test]
fn long_work_shows_its_progress_on_a_terminal_and_nowhere_else() {
    // Through a pseudo-terminal (util-linux's `script`), as a person runs it: a progress line
    // that is redrawn in place. Piped (as the other tests run it), not a trace of it.
    let vol = temp("progress.vol");
    let command = format!(
        "'{}' simulate --steps 3000 -o '{}'",
        env!("CARGO_BIN_EXE_cloudsketch"),
        vol.display()
    );
    // The line at once (not after half a second, which a fast machine might beat), on a
    // terminal indicatif draws on (not a dumb one).
    let on_terminal = |command: &str| {
        Command::new("script")
            .args(["-qec", command, "/dev/null"])
            .env("CLOUDSKETCH_PROGRESS_AT_ONCE", "1")
            .env("TERM", "xterm")
            .output()
            .expect("util-linux's script")
    };
    let o = on_terminal(&command);
    let shown = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{shown}");
    // indicatif's line: the label, a share, and a redraw that returns to the margin and clears.
    assert!(
        shown.contains("simulating 3000 steps:") && shown.contains('%'),
        "{shown:?}"
    );
    assert!(shown.contains("\r\x1b[2K"), "redrawn in place: {shown:?}");
    // Piped, nothing of it, even at once.
    let o = Command::new(env!("CARGO_BIN_EXE_cloudsketch"))
        .args(["simulate", "--steps", "3000", "-o", vol.to_str().unwrap()])
        .env("CLOUDSKETCH_PROGRESS_AT_ONCE", "1")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains('%'), "{}", stderr(&o));

    // A sequence counts its frames on the line.
    let out = temp("progress_seq");
    let _ = std::fs::remove_dir_all(&out);
    let pattern = out.join("f_##.png");
    let command = format!(
        "'{}' render --frames 0..11 --size 96x64 -o '{}'",
        env!("CARGO_BIN_EXE_cloudsketch"),
        pattern.display()
    );
    let o = on_terminal(&command);
    let shown = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{shown}");
    assert!(
        shown.contains("frames 0..11:") && shown.contains("/12,"),
        "{shown:?}"
    );
    let _ = std::fs::remove_dir_all(&out);
}

/// `--time` and `--frame` name the same moments on the scene's clock, in `render`, `export`
/// and `simulate` alike (one or the other); a frame past the clock's last is refused.
#[test]
fn time_and_frame_name_the_same_moment_in_every_subcommand() {
    let png = |name: &str, extra: &[&str]| {
        let out = temp(name);
        let mut args = vec!["render", "-o", out.to_str().unwrap(), "--size", "96x64"];
        args.extend(["--set", "/render/slices=32", "--set", "/render/wind=[3,0]"]);
        args.extend(extra);
        let o = cloudsketch(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        read_rgb(&out)
    };
    let frame = png("frame48.png", &["--frame", "48"]);
    assert_eq!(
        frame,
        png("time2.png", &["--time", "2"]),
        "frame 48 at 24 fps is 2 s"
    );
    assert_ne!(
        frame,
        png("time0.png", &["--time", "0"]),
        "the wind moved the noise"
    );
    // At the scene's own rate: 10 frames per second make frame 20 the same 2 s.
    let ten = png("frame20.png", &["--set", "/clock/fps=10", "--frame", "20"]);
    assert_eq!(ten, frame);

    // export: a PNG of the view at a frame is the render at that time.
    let view = temp("view48.png");
    let o = cloudsketch(&[
        "export",
        "--format",
        "png",
        "-o",
        view.to_str().unwrap(),
        "--size",
        "96x64",
        "--frame",
        "48",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let exported = read_rgb(&view);
    let o = cloudsketch(&[
        "render",
        "-o",
        temp("render48.png").to_str().unwrap(),
        "--size",
        "96x64",
        "--time",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(exported, read_rgb(&temp("render48.png")));

    // simulate: a moment is the step at or before it at the simulation's rate (frame 48 is
    // 2 s: twice the preset's steps per second).
    let (by_frame, by_steps) = (temp("f48.vol"), temp("s8.vol"));
    let rate = cloudsketch::scene::Scene::preset(cloudsketch::scene::Preset::Simulated)
        .simulation
        .unwrap()
        .rate;
    assert_eq!(rate.fract(), 0.0, "a whole number of steps per second");
    let steps = (2 * rate as u64).to_string();
    for (out, args) in [
        (&by_frame, ["--frame", "48"]),
        (&by_steps, ["--steps", steps.as_str()]),
    ] {
        let o = cloudsketch(&[&["simulate", "-o", out.to_str().unwrap()][..], &args[..]].concat());
        assert!(o.status.success(), "{}", stderr(&o));
    }
    assert_eq!(
        std::fs::read(&by_frame).unwrap(),
        std::fs::read(&by_steps).unwrap()
    );

    // One or the other, and within the clock.
    let o = cloudsketch(&[
        "render",
        "-o",
        temp("both.png").to_str().unwrap(),
        "--time",
        "1",
        "--frame",
        "2",
    ]);
    assert!(
        !o.status.success() && stderr(&o).contains("--frame"),
        "{}",
        stderr(&o)
    );
    let o = cloudsketch(&[
        "render",
        "-o",
        temp("far.png").to_str().unwrap(),
        "--frame",
        "4000000",
    ]);
    assert!(!o.status.success(), "a frame past a day at 24 fps");
    assert!(
        stderr(&o).contains("--frame 4000000: 0 to 2073600"),
        "{}",
        stderr(&o)
    );
    assert!(!temp("far.png").exists());
}

#[test]
fn render_poses_the_keys_at_the_frame_and_shot_renders_through_the_shot_camera() {
    // One ellipsoid keyed from x = −5 at frame 0 to x = 5 at frame 48 (2 s at 24 fps); a shot
    // camera from behind (yaw 180°: the view's left and right swap).
    let scene = temp("keyed.json");
    std::fs::write(
        &scene,
        r#"{"version": 4,
            "render": {"noise_amount": 0, "slices": 32},
            "ellipsoids": [{"center": [-5, 3, 0], "radii": [2, 1.5, 1.5], "id": 7}],
            "shot": {"target": [0, 3, 0], "yaw_deg": 180, "pitch_deg": 5, "distance": 30,
                     "fov_y_deg": 40, "orthographic": false},
            "animation": [{"channel": {"item": "ellipsoid", "id": 7, "property": "center"},
                           "keys": [{"t": 0, "v": [-5, 3, 0]}, {"t": 2, "v": [5, 3, 0]}]}]}"#,
    )
    .unwrap();
    let at = |frame: &str, shot: bool| {
        let png = temp(&format!("keyed-{frame}-{shot}.png"));
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
            "--size",
            "96x64",
            "--frame",
            frame,
        ];
        if shot {
            args.push("--shot");
        }
        let out = cloudsketch(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        cloud_centroid(&read_rgb(&png))
    };
    let (x0, x24, x48) = (at("0", false), at("24", false), at("48", false));
    assert!(x0.1 > 30 && x48.1 > 30, "{x0:?} {x48:?}");
    assert!(
        x48.0 > x0.0 + 20.0,
        "the keys move it right: {x0:?} → {x48:?}"
    );
    assert!(
        (x24.0 - (x0.0 + x48.0) / 2.0).abs() < 4.0,
        "half way at frame 24: {x0:?} {x24:?} {x48:?}"
    );
    let (s0, s48) = (at("0", true), at("48", true));
    assert!(
        s48.0 < s0.0 - 20.0,
        "through the shot from behind it moves left: {s0:?} → {s48:?}"
    );
    // No shot camera: a clear error, no image.
    let png = temp("no-shot.png");
    let _ = std::fs::remove_file(&png);
    let out = cloudsketch(&["render", "-o", png.to_str().unwrap(), "--shot"]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("no shot camera"), "{}", stderr(&out));
    assert!(!png.exists());
}

/// The JSON lines a `--progress json` run printed.
fn json_lines(o: &Output) -> Vec<serde_json::Value> {
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{l:?}: {e}")))
        .collect()
}

#[test]
fn a_sequence_writes_each_frame_once_and_any_split_of_it_gives_the_same_bytes() {
    let dir = folder("sequence");
    let path = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let scene = preset_scene(&dir, "developing");
    let render = |frames: &str, pattern: &str, extra: &[&str]| {
        let mut args = vec![
            "render",
            &scene,
            "--size",
            "96x54",
            "--set",
            "/render/slices=24",
            "--fps",
            "1",
            "--progress",
            "json",
            "-o",
            pattern,
        ];
        if !frames.is_empty() {
            args.extend(["--frames", frames]);
        }
        args.extend(extra);
        cloudsketch(&args)
    };
    // One run of frames 0..3 (inclusive), the name's #### the zero-padded frame.
    let whole = path("whole/f_####.png");
    let o = render("0..3", &whole, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let lines = json_lines(&o);
    assert_eq!(
        lines
            .iter()
            .map(|l| l["frame"].as_u64().unwrap())
            .collect::<Vec<_>>(),
        [0, 1, 2, 3]
    );
    assert!(
        lines
            .iter()
            .all(|l| l["skipped"] == false && l["total"] == 4)
    );
    let frame = |folder: &str, n: u32| {
        std::fs::read(dir.join(folder).join(format!("f_{n:04}.png"))).unwrap()
    };
    assert_ne!(
        frame("whole", 0),
        frame("whole", 3),
        "the developing cloud did not move"
    );
    // The same frames from another process, split differently, are the same bytes.
    let o = render("2..3", &path("split/f_####.png"), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = render("1", &path("split/f_####.png"), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    for n in 1..=3 {
        assert!(
            frame("whole", n) == frame("split", n),
            "frame {n} differs between runs"
        );
    }
    // Run again: every frame is already there, with the same scene and options.
    let before = std::fs::metadata(dir.join("whole/f_0002.png"))
        .unwrap()
        .modified()
        .unwrap();
    let o = render("0..3", &whole, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        json_lines(&o).iter().all(|l| l["skipped"] == true),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    assert_eq!(
        std::fs::metadata(dir.join("whole/f_0002.png"))
            .unwrap()
            .modified()
            .unwrap(),
        before
    );
    // Other options redo them; so does --overwrite.
    let o = render("0..1", &whole, &["--set", "/render/slices=25"]);
    assert!(json_lines(&o).iter().all(|l| l["skipped"] == false));
    let o = render("0..1", &whole, &["--overwrite"]);
    assert!(json_lines(&o).iter().all(|l| l["skipped"] == false));
    // Without --frames, a name with # is the document's range (the developing preset's 0..480
    // at its rate): here --frame N alone.
    let o = render("", &path("one/f_##.png"), &["--frame", "7"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        listing(&dir.join("one")),
        ["f_07.png", "f_07.png.cloudsketch.json"]
    );

    // Bad requests: a clear error and nothing written.
    let blocker = path("a-file");
    std::fs::write(&blocker, b"x").unwrap();
    for (frames, pattern, says) in [
        ("5..2", path("bad/f_##.png"), "reversed"),
        ("0..x", path("bad/f_##.png"), "whole frame numbers"),
        ("..", path("bad/f_##.png"), "whole frame numbers"),
        ("5..", path("bad/f_##.png"), "whole frame numbers"),
        ("..5", path("bad/f_##.png"), "whole frame numbers"),
        ("0..20000", path("bad/f_##.png"), "at most 10000"),
        ("0..3", path("plain.png"), "no run of #"),
        ("0..3", format!("{blocker}/f_##.png"), "cannot"),
    ] {
        let o = render(frames, &pattern, &[]);
        assert!(!o.status.success(), "{frames} {pattern}");
        assert!(
            stderr(&o).contains(says),
            "{frames} {pattern}: {}",
            stderr(&o)
        );
    }
    assert!(!dir.join("bad").exists() && !dir.join("plain.png").exists());
    // A frame that would overwrite the input scene.
    std::fs::copy(&scene, dir.join("s_1.json")).unwrap();
    let o = cloudsketch(&[
        "render",
        &path("s_1.json"),
        "--frames",
        "0..2",
        "-o",
        &path("s_#.json"),
    ]);
    assert!(
        stderr(&o).contains("would overwrite the input"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.join("s_0.json").exists());
    let o = cloudsketch(&[
        "render",
        &scene,
        "--fps",
        "0",
        "--frames",
        "0..1",
        "-o",
        &path("t/f_#.png"),
    ]);
    assert!(stderr(&o).contains("--fps 0"), "{}", stderr(&o));
}

#[test]
fn a_simulated_vdb_sequence_steps_on_and_equals_each_frame_exported_alone() {
    let dir = folder("vdb-sequence");
    let path = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let scene = preset_scene(&dir, "simulated");
    let export = |extra: &[&str]| {
        let mut args = vec![
            "export",
            &scene,
            "--format",
            "vdb",
            "--resolution",
            "32",
            "--fps",
            "2",
        ];
        args.extend(extra);
        cloudsketch(&args)
    };
    // Its first frames hold no cloud yet: they are written clear, so the sequence is whole.
    let o = export(&["--frames", "0..4", "-o", &path("seq/cloud.####.vdb")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let names: Vec<String> = listing(&dir.join("seq"))
        .into_iter()
        .filter(|n| n.ends_with(".vdb"))
        .collect();
    assert_eq!(
        names,
        [
            "cloud.0000.vdb",
            "cloud.0001.vdb",
            "cloud.0002.vdb",
            "cloud.0003.vdb",
            "cloud.0004.vdb"
        ]
    );
    let seq = |n: u32| std::fs::read(dir.join(format!("seq/cloud.{n:04}.vdb"))).unwrap();
    assert_ne!(seq(0), seq(4), "the simulation did not move");
    // Frame 4 exported alone plays the run from step 0: the same file.
    let alone = path("alone.vdb");
    let o = export(&["--frame", "4", "-o", &alone]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        std::fs::read(&alone).unwrap() == seq(4),
        "frame 4 differs from its sequence's"
    );
}

/// The mesh and Mitsuba exporters make sequences too: one file (and its companions) per
/// frame under the pattern's names, each the file that frame exported alone makes.
#[test]
fn mesh_and_mitsuba_sequences_write_a_file_a_frame_as_each_frame_alone_does() {
    let dir = folder("format-sequences");
    let path = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let scene = preset_scene(&dir, "developing");
    let export = |format: &str, extra: &[&str]| {
        let mut args = vec![
            "export",
            &scene,
            "--format",
            format,
            "--resolution",
            "24",
            "--fps",
            "1",
        ];
        args.extend(extra);
        cloudsketch(&args)
    };
    for (format, extension) in [
        ("glb", "glb"),
        ("obj", "obj"),
        ("ply", "ply"),
        ("mitsuba", "xml"),
    ] {
        let pattern = path(&format!("{format}/cloud.####.{extension}"));
        let o = export(format, &["--frames", "0..2", "-o", &pattern]);
        assert!(o.status.success(), "{format}: {}", stderr(&o));
        let main: Vec<String> = listing(&dir.join(format))
            .into_iter()
            .filter(|n| n.ends_with(&format!(".{extension}")))
            .collect();
        assert_eq!(
            main,
            (0..3)
                .map(|k| format!("cloud.{k:04}.{extension}"))
                .collect::<Vec<_>>(),
            "{format}"
        );
        let frame =
            |k: u32| std::fs::read(dir.join(format!("{format}/cloud.{k:04}.{extension}"))).unwrap();
        // The developing cumulus rises and grows between frames 0 and 2 (2 s apart).
        assert_ne!(frame(0), frame(2), "{format}: the frames are one");
        // Frame 2 alone: the same main file, and the same companions (Mitsuba's grid and sky).
        let alone_dir = dir.join(format!("{format}-alone"));
        std::fs::create_dir_all(&alone_dir).unwrap();
        let alone = alone_dir.join(format!("cloud.0002.{extension}"));
        let o = export(format, &["--frame", "2", "-o", alone.to_str().unwrap()]);
        assert!(o.status.success(), "{format}: {}", stderr(&o));
        assert!(
            std::fs::read(&alone).unwrap() == frame(2),
            "{format}: frame 2 alone differs from its sequence's"
        );
        for name in listing(&alone_dir) {
            assert!(
                std::fs::read(alone_dir.join(&name)).unwrap()
                    == std::fs::read(dir.join(format).join(&name)).unwrap(),
                "{format}: {name} alone differs from its sequence's"
            );
        }
    }
}

#[test]
fn a_chunk_starts_from_the_furthest_checkpoint_and_refuses_another_runs() {
    let dir = folder("checkpoints");
    let path = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let scene = preset_scene(&dir, "simulated");
    let checkpoints = path("ck");
    let export = |frames: &str, out: &str| {
        cloudsketch(&[
            "export",
            &scene,
            "--format",
            "vdb",
            "--resolution",
            "24",
            "--fps",
            "1",
            "--progress",
            "json",
            "--checkpoints",
            &checkpoints,
            "--frames",
            frames,
            "-o",
            out,
        ])
    };
    // The whole range, 10 steps a frame: it passes steps 32, 64 and 96 and writes them.
    let o = export("0..10", &path("whole/cloud.####.vdb"));
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(json_lines(&o)[0]["simulation"], "step 0");
    let mut written: Vec<String> = listing(&dir.join("ck"));
    written.retain(|n| n.ends_with(".ckpt"));
    assert_eq!(written.len(), 3, "{written:?}");
    // A chunk in a fresh process starts from the furthest checkpoint at or before its first
    // frame (step 64 for frame 8), and its frames equal the whole run's.
    let o = export("8..9", &path("chunk/cloud.####.vdb"));
    assert!(o.status.success(), "{}", stderr(&o));
    let said = json_lines(&o)[0]["simulation"].as_str().unwrap().to_owned();
    assert!(said.starts_with("the checkpoint at step 64"), "{said}");
    let file = |folder: &str, n: u32| {
        std::fs::read(dir.join(format!("{folder}/cloud.{n:04}.vdb"))).unwrap()
    };
    for n in [8, 9] {
        assert!(
            file("chunk", n) == file("whole", n),
            "frame {n} from the checkpoint differs"
        );
    }
    // A checkpoint whose hash is another run's is refused, whatever its name: the chunk falls
    // back to the one before it, and its frames are still the same.
    let furthest = dir
        .join("ck")
        .join(written.iter().find(|n| n.ends_with("00064.ckpt")).unwrap());
    let mut bytes = std::fs::read(&furthest).unwrap();
    bytes[8] ^= 0xff;
    std::fs::write(&furthest, &bytes).unwrap();
    let o = export("8..9", &path("again/cloud.####.vdb"));
    assert!(o.status.success(), "{}", stderr(&o));
    let said = json_lines(&o)[0]["simulation"].as_str().unwrap().to_owned();
    assert!(
        said.contains("refused: a checkpoint of another scene") && said.contains("step 32"),
        "{said}"
    );
    assert!(file("again", 9) == file("whole", 9));
}

/// The `developing` preset saved as `developing.json` in `dir`; its path.
fn developing_scene(dir: &std::path::Path) -> String {
    preset_scene(dir, "developing")
}

/// Preset `name` saved as `NAME.json` in `dir`; its path.
fn preset_scene(dir: &std::path::Path, name: &str) -> String {
    let scene = dir
        .join(format!("{name}.json"))
        .to_str()
        .unwrap()
        .to_owned();
    let o = cloudsketch(&["new", "--preset", name, "-o", &scene]);
    assert!(o.status.success(), "{}", stderr(&o));
    scene
}

/// A frame that cannot be written whole: its sidecar's name is taken by a folder, so its image is
/// written and then its sidecar fails. The run fails naming that frame; the frames before it stay
/// with their sidecars; the frame's image is removed (a rerun would redo it anyway) and no
/// temporary file is left.
#[test]
fn a_frame_whose_sidecar_fails_is_removed_and_the_earlier_frames_stay() {
    let dir = folder("sidecar-fails");
    let scene = developing_scene(&dir);
    let scene = scene.as_str();
    let out = dir.join("out");
    std::fs::create_dir_all(out.join("f_0003.png.cloudsketch.json")).unwrap();
    let pattern = out.join("f_####.png");
    let o = cloudsketch(&[
        "render",
        scene,
        "--size",
        "64x36",
        "--set",
        "/render/slices=16",
        "--fps",
        "1",
        "--frames",
        "0..5",
        "--progress",
        "json",
        "-o",
        pattern.to_str().unwrap(),
    ]);
    assert!(!o.status.success(), "frame 3 could not be written whole");
    let err = stderr(&o);
    assert!(err.contains("frame 3:"), "the error names the frame: {err}");
    assert_eq!(json_lines(&o).len(), 3, "frames 0, 1 and 2 reported");
    assert_eq!(
        listing(&out),
        [
            "f_0000.png",
            "f_0000.png.cloudsketch.json",
            "f_0001.png",
            "f_0001.png.cloudsketch.json",
            "f_0002.png",
            "f_0002.png.cloudsketch.json",
            "f_0003.png.cloudsketch.json",
        ],
        "{err}"
    );
    assert!(out.join("f_0003.png.cloudsketch.json").is_dir());
}

/// A disk that fills in the middle of a sequence: a 64 KiB tmpfs, mounted in a mount namespace
/// of the run's own (nothing outside sees it, and it goes when the run ends), takes the first
/// frames and not the rest. The run fails naming the frame it could not write; the frames before
/// it stay whole with their sidecars; nothing of that frame, and no temporary file, is left.
#[test]
fn a_disk_that_fills_mid_sequence_keeps_the_earlier_frames_and_names_the_lost_one() {
    let dir = folder("full-disk");
    let scene = developing_scene(&dir);
    let scene = scene.as_str();
    let disk = dir.join("disk");
    std::fs::create_dir_all(&disk).unwrap();
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout.trim_ascii() == b"0");
    // As root a mount namespace alone; otherwise a user namespace too (where the system allows
    // one: the suite runs as root).
    let mut unshare = Command::new("unshare");
    unshare.arg("--mount");
    if !root {
        unshare.arg("--map-root-user");
    }
    let script = r#"
        mount -t tmpfs -o size=64k tmpfs "$1" || exit 90
        "$2" render "$3" --size 96x54 --set /render/slices=24 --fps 1 --frames 0..11 \
            --progress json -o "$1/f_####.png"
        echo "exit $?" >&2
        find "$1" -mindepth 1 -printf '%f %s\n' >&2
    "#;
    let o = unshare
        .args(["sh", "-c", script, "sh"])
        .arg(&disk)
        .arg(env!("CARGO_BIN_EXE_cloudsketch"))
        .arg(scene)
        .output();
    // Where no mount namespace can be had (no `unshare`, or a container that forbids it), there
    // is no small disk to fill: said, and skipped. The suite's machine has one.
    let o = match o {
        Ok(o) if stderr(&o).contains("exit ") => o,
        Ok(o) => {
            eprintln!(
                "skipped: no mount namespace for a small disk ({})",
                stderr(&o)
            );
            return;
        }
        Err(e) => {
            eprintln!("skipped: no `unshare` ({e})");
            return;
        }
    };
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    let exit = err
        .lines()
        .find_map(|l| l.strip_prefix("exit "))
        .expect("the run's exit code");
    assert_ne!(exit, "0", "the run filled the disk and said nothing: {err}");
    let made: Vec<u64> = json_lines(&o)
        .iter()
        .map(|l| l["frame"].as_u64().unwrap())
        .collect();
    let lost = made.len() as u64;
    assert!(
        (1..12).contains(&lost),
        "the disk should hold some frames and not all: {made:?}\n{err}"
    );
    assert_eq!(made, (0..lost).collect::<Vec<_>>());
    assert!(
        err.contains(&format!("frame {lost}:")) && err.contains("No space left on device"),
        "the error names the frame and the cause: {err}"
    );
    // What is left on the disk: each reported frame and its sidecar, whole, and nothing else.
    let mut left: Vec<(String, u64)> = err
        .lines()
        .skip_while(|l| !l.starts_with("exit "))
        .skip(1)
        .filter_map(|l| l.rsplit_once(' '))
        .map(|(name, size)| (name.to_owned(), size.parse().unwrap()))
        .collect();
    left.sort();
    let mut expected: Vec<String> = (0..lost)
        .flat_map(|n| {
            let png = format!("f_{n:04}.png");
            [format!("{png}.cloudsketch.json"), png]
        })
        .collect();
    expected.sort();
    assert_eq!(
        left.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>(),
        expected,
        "{err}"
    );
    assert!(left.iter().all(|(_, size)| *size > 0), "{left:?}");
}

/// Reads an EXR's first RGBA layer: its size and pixels.
fn read_exr(path: &std::path::Path) -> ((usize, usize), Vec<[f32; 4]>) {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), size.height(), vec![[0.0f32; 4]; size.area()]),
        |(w, _, pixels), at, (r, g, b, a): (f32, f32, f32, f32)| {
            pixels[at.y() * *w + at.x()] = [r, g, b, a]
        },
    )
    .unwrap_or_else(|e| panic!("{} is not an EXR: {e}", path.display()));
    let (w, h, pixels) = image.layer_data.channel_data.pixels;
    ((w, h), pixels)
}

#[test]
fn render_writes_linear_exr_images_and_sequences_the_same_wherever_made() {
    let dir = folder("exr");
    let path = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let small = ["--size", "64x36", "--set", "/render/slices=16"];
    let render = |extra: &[&str]| {
        let mut args = vec!["render"];
        args.extend(small);
        args.extend(extra);
        cloudsketch(&args)
    };
    // An .exr name is enough; --transparent keeps the cloud alone, premultiplied.
    let o = render(&["-o", &path("shot.exr")]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("rendered 64x36 exr"), "{}", stderr(&o));
    let (size, sky) = read_exr(&dir.join("shot.exr"));
    assert_eq!(size, (64, 36));
    assert!(
        sky.iter().all(|p| (p[3] - 1.0).abs() < 1e-3),
        "over the sky every pixel is opaque"
    );
    let o = render(&["--format", "exr", "--transparent", "-o", &path("alone.exr")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, alone) = read_exr(&dir.join("alone.exr"));
    let clear = alone.iter().filter(|p| p[3] == 0.0).count();
    let cloud = alone.iter().filter(|p| p[3] > 0.5).count();
    assert!(
        clear > 100 && cloud > 20,
        "{clear} clear, {cloud} cloud pixels"
    );
    assert!(
        alone
            .iter()
            .all(|p| p[3] > 0.0 || p[..3].iter().all(|&c| c == 0.0)),
        "light where nothing is (shafts are off)"
    );
    // Where the cloud is opaque, the transparent image is the image over the sky.
    for (a, s) in alone.iter().zip(&sky) {
        if a[3] > 0.999 {
            assert!((a[1] - s[1]).abs() < 0.01, "{a:?} over the sky {s:?}");
        }
    }
    // Names and formats that disagree, or formats it does not know, are refused.
    let o = render(&["--format", "exr", "-o", &path("wrong.png")]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("names a .png file"), "{}", stderr(&o));
    let o = render(&["--format", "tiff", "-o", &path("x.tif")]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("png or exr"), "{}", stderr(&o));
    assert!(!dir.join("wrong.png").exists() && !dir.join("x.tif").exists());
    // A sequence of EXRs: the frames of one run equal those of another split, byte for byte.
    let scene = developing_scene(&dir);
    let frames = |frames: &str, pattern: &str| {
        render(&[&scene, "--fps", "1", "--frames", frames, "-o", pattern])
    };
    let o = frames("0..2", &path("whole/f_####.exr"));
    assert!(o.status.success(), "{}", stderr(&o));
    let o = frames("2", &path("split/f_####.exr"));
    assert!(o.status.success(), "{}", stderr(&o));
    let read = |folder: &str, n: u32| {
        std::fs::read(dir.join(folder).join(format!("f_{n:04}.exr"))).unwrap()
    };
    assert!(
        read("whole", 2) == read("split", 2),
        "frame 2 differs between runs"
    );
    assert!(
        read("whole", 0) != read("whole", 2),
        "the developing cloud did not move"
    );
    let (size, _) = read_exr(&dir.join("whole/f_0001.exr"));
    assert_eq!(size, (64, 36));
}
