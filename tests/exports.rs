//! Exports as other tools read them. Here: the glb through the `gltf` crate (every edge shared
//! by two faces of opposite orientation, the enclosed volume the field's), the VDB through the
//! `vdb-rs` crate and Mitsuba's `.vol` as its format is documented (each against the field at
//! probe points), the CPU media they bake against the shader's; and the files that
//! `scripts/check_exports.py` then reads with independent readers (written to
//! `target/export-check/`): VDB grids with probe points whose values come from the field
//! evaluated directly (OpenVDB's Python reader), Mitsuba scenes with and without the noise and
//! the app's own render of that view (Mitsuba renders them), and a glb for the Khronos
//! validator.

use std::collections::HashMap;
use std::path::PathBuf;

use cloudsketch::derive::frame_of;
use cloudsketch::export::{Axes, Format, Options, Up, export};
use cloudsketch::field::media::Media;
use cloudsketch::field::{ISO, bake_fine, density};
use cloudsketch::render::offscreen::{Backdrop, Offscreen, Output};
use cloudsketch::scene::{Preset, Scene};
use glam::Vec3;

fn out_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/export-check");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Positions and triangles of the glb's one primitive, read by the `gltf` crate.
fn read_glb(bytes: &[u8]) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let gltf = gltf::Gltf::from_slice(bytes).expect("a valid glb");
    let blob = gltf.blob.clone();
    let mesh = gltf.meshes().next().expect("one mesh");
    let prim = mesh.primitives().next().expect("one primitive");
    let reader = prim.reader(|b| match b.source() {
        gltf::buffer::Source::Bin => blob.as_deref(),
        _ => None,
    });
    let positions: Vec<Vec3> = reader
        .read_positions()
        .expect("positions")
        .map(Vec3::from)
        .collect();
    let indices: Vec<u32> = reader.read_indices().expect("indices").into_u32().collect();
    let triangles = indices.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    (positions, triangles)
}

fn volume(positions: &[Vec3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize].as_dvec3());
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

#[test]
fn the_glb_is_closed_consistently_oriented_and_holds_the_fields_volume() {
    let scene = Scene::default();
    let options = Options {
        resolution: 96,
        noise: false,
        ..Options::default()
    };
    let files = export(&scene, Format::Glb, &options, "cloud").unwrap();
    std::fs::write(out_dir().join("cloud.glb"), &files[0].bytes).unwrap();
    let (positions, triangles) = read_glb(&files[0].bytes);
    assert!(triangles.len() > 1000, "{} triangles", triangles.len());
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &triangles {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert!(
            n == 1 && directed.get(&(b, a)) == Some(&1),
            "edge {a}–{b}: {n} one way, {:?} the other",
            directed.get(&(b, a))
        );
    }
    // The field's own volume: texels at or above the iso level, on a grid twice as fine
    // (independent of the mesher).
    let fine = bake_fine(&cloudsketch::derive::field_of(&scene), 192);
    let texel = fine.texel_size();
    let inside = fine.values.iter().filter(|&&v| v >= ISO).count() as f64;
    let expected = inside * (texel.x * texel.y * texel.z) as f64;
    let got = volume(&positions, &triangles);
    assert!(
        (got - expected).abs() < 0.03 * expected,
        "mesh volume {got:.3} vs the field's {expected:.3}"
    );
    // Z-up: the same solid turned (its height is now along z), scaled by 2.
    let z = Options {
        axes_up: Up::Z,
        scale: 2.0,
        ..options
    };
    let (pz, tz) = read_glb(&export(&scene, Format::Glb, &z, "cloud").unwrap()[0].bytes);
    let extent = |ps: &[Vec3]| {
        ps.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        })
    };
    let (lo, hi) = extent(&positions);
    let (lz, hz) = extent(&pz);
    assert!(((hz.z - lz.z) - 2.0 * (hi.y - lo.y)).abs() < 1e-3);
    assert!(((hz.y - lz.y) - 2.0 * (hi.z - lo.z)).abs() < 1e-3);
    assert!((volume(&pz, &tz) - 8.0 * got).abs() < 1e-3 * got);
}

/// A mesh of the plain field samples only the bricks its surface can cross: the mesh (and so
/// the file) is the one marching cubes makes from the whole grid's field.
#[test]
fn a_plain_mesh_is_the_whole_grids_mesh() {
    use cloudsketch::export::{sample, surface};
    for scene in [
        Scene::default(),
        Scene::preset(cloudsketch::scene::Preset::Cumulonimbus),
    ] {
        let options = Options {
            resolution: 112,
            noise: false,
            ..Options::default()
        };
        let near = sample(&scene, Format::Glb, &options).unwrap();
        let whole = sample(&scene, Format::Vdb, &options).unwrap();
        assert!(near.values.is_empty() && !whole.values.is_empty());
        let mesh = surface(&near, false);
        assert!(
            mesh.triangles.len() > 1000,
            "{} triangles",
            mesh.triangles.len()
        );
        assert!(mesh == surface(&whole, false), "the meshes differ");
    }
}

#[test]
fn obj_and_ply_hold_the_same_mesh() {
    let scene = Scene::default();
    let options = Options {
        resolution: 48,
        ..Options::default()
    };
    let (positions, triangles) =
        read_glb(&export(&scene, Format::Glb, &options, "c").unwrap()[0].bytes);
    let obj = String::from_utf8(
        export(&scene, Format::Obj, &options, "c").unwrap()[0]
            .bytes
            .clone(),
    )
    .unwrap();
    let v: Vec<Vec3> = obj
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let c: Vec<f32> = l.split(' ').map(|x| x.parse().unwrap()).collect();
            Vec3::new(c[0], c[1], c[2])
        })
        .collect();
    let f: Vec<[u32; 3]> = obj
        .lines()
        .filter_map(|l| l.strip_prefix("f "))
        .map(|l| {
            let i: Vec<u32> = l
                .split(' ')
                .map(|x| x.split("//").next().unwrap().parse::<u32>().unwrap() - 1)
                .collect();
            [i[0], i[1], i[2]]
        })
        .collect();
    assert_eq!((v.len(), f.len()), (positions.len(), triangles.len()));
    assert_eq!(f, triangles);
    let ply = export(&scene, Format::Ply, &options, "c").unwrap()[0]
        .bytes
        .clone();
    let header_end = ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = String::from_utf8_lossy(&ply[..header_end]);
    assert!(header.contains(&format!("element vertex {}", positions.len())));
    assert!(header.contains(&format!("element face {}", triangles.len())));
    assert_eq!(
        ply.len() - header_end,
        positions.len() * 24 + triangles.len() * 13
    );
}

#[test]
fn vdb_grids_and_probes_for_openvdbs_own_reader() {
    let scene = Scene::default();
    let field = cloudsketch::derive::field_of(&scene);
    let media = Media::new(&scene);
    let softness = scene.render.softness;
    for (up, noise) in [(Up::Y, false), (Up::Z, true)] {
        let options = Options {
            resolution: 64,
            axes_up: up,
            scale: 0.5,
            noise,
            ..Options::default()
        };
        let name = format!(
            "cloud_{}_{}",
            up.name(),
            if noise { "noise" } else { "plain" }
        );
        let files = export(&scene, Format::Vdb, &options, &name).unwrap();
        std::fs::write(out_dir().join(&files[0].name), &files[0].bytes).unwrap();
        // Probes at the grid's texel centres (where the file's voxels sit), with the value
        // the field and media give there, evaluated directly; and points far outside.
        let grid = cloudsketch::export::sample(&scene, Format::Vdb, &options).unwrap();
        let axes = Axes { up, scale: 0.5 };
        let mut probes = Vec::new();
        let mut rng = 0x9e37_79b9_u64;
        let mut next = |n: u32| {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng % n as u64) as u32
        };
        let mut inside = 0;
        while probes.len() < 400 {
            let (x, y, z) = (next(grid.dims.x), next(grid.dims.y), next(grid.dims.z));
            let p = grid.center(x, y, z);
            let f = field.value(p);
            let want = if noise {
                media.density(f, p)
            } else {
                density(f, softness)
            };
            inside += (want > 0.0) as usize;
            probes.push((axes.point(p), want));
        }
        for far in [Vec3::new(100.0, 0.0, 0.0), Vec3::new(0.0, -50.0, 30.0)] {
            probes.push((axes.point(far), 0.0));
        }
        assert!(inside > 40, "{inside} probes in the cloud");
        vdb_holds_the_probes(&files[0].bytes, &probes);
        let json = serde_json::json!({
            "file": files[0].name,
            "points": probes.iter().map(|(p, _)| p.to_array()).collect::<Vec<_>>(),
            "values": probes.iter().map(|(_, v)| v).collect::<Vec<_>>(),
            "voxel_size": grid.h * 0.5,
        });
        std::fs::write(
            out_dir().join(format!("{name}.probes.json")),
            json.to_string(),
        )
        .unwrap();
    }
}

/// The VDB read by an independent reader (the `vdb-rs` crate: the tree, the transform, the
/// voxels), its `density` grid checked at every probe (file coordinates, the value the field
/// and media give there): under `cargo test`, before `scripts/check_exports.py` reads the same
/// file with OpenVDB's own Python module.
fn vdb_holds_the_probes(bytes: &[u8], probes: &[(Vec3, f32)]) {
    let mut reader = vdb_rs::VdbReader::new(std::io::Cursor::new(bytes)).expect("a VDB file");
    let grid = reader
        .read_grid::<f32>("density")
        .expect("its density grid");
    let (translation, voxel) = match &grid.transform {
        vdb_rs::Map::ScaleTranslateMap {
            translation,
            voxel_size,
            ..
        } => (
            Vec3::new(
                translation.x as f32,
                translation.y as f32,
                translation.z as f32,
            ),
            Vec3::new(
                voxel_size.x as f32,
                voxel_size.y as f32,
                voxel_size.z as f32,
            ),
        ),
        other => panic!("an unexpected transform {other:?}"),
    };
    let voxels: HashMap<[i32; 3], f32> = grid
        .iter()
        .filter(|(_, _, level)| *level == vdb_rs::VdbLevel::Voxel)
        .map(|(c, v, _)| ([c.x, c.y, c.z].map(|x| x.round() as i32), v))
        .collect();
    assert!(!voxels.is_empty(), "no voxels");
    let mut worst = 0.0f32;
    for &(q, want) in probes {
        let ijk = ((q - translation) / voxel).round().as_ivec3().to_array();
        let got = voxels.get(&ijk).copied().unwrap_or(0.0);
        worst = worst.max((got - want).abs());
    }
    assert!(
        worst < 1e-5,
        "the VDB is off the field by {worst} at a probe"
    );
}

/// A Mitsuba 3 grid volume read as its format is documented (`VOL`, version 3, float32, the
/// resolution, one channel, the box, then x fastest), checked against the field (and with
/// `noise` the media) evaluated directly at voxel centres placed by the file's own box: the
/// values the renderer will read are the cloud's.
fn vol_holds_the_field(scene: &Scene, vol: &[u8], noise: bool) {
    let int = |at: usize| i32::from_le_bytes(vol[at..at + 4].try_into().unwrap());
    let float = |at: usize| f32::from_le_bytes(vol[at..at + 4].try_into().unwrap());
    assert_eq!(&vol[..4], b"VOL\x03");
    assert_eq!(int(4), 1, "float32 encoding");
    let res = [int(8), int(12), int(16)].map(|r| r as usize);
    assert_eq!(int(20), 1, "one channel");
    let lo = Vec3::new(float(24), float(28), float(32));
    let hi = Vec3::new(float(36), float(40), float(44));
    assert_eq!(vol.len(), 48 + 4 * res[0] * res[1] * res[2]);
    let field = cloudsketch::derive::field_of(scene);
    let media = Media::new(scene);
    let step = (hi - lo) / Vec3::new(res[0] as f32, res[1] as f32, res[2] as f32);
    let (mut inside, mut worst) = (0, 0.0f32);
    for k in 0..500usize {
        let (x, y, z) = (
            (k * 7919) % res[0],
            (k * 104_729) % res[1],
            (k * 1_299_709) % res[2],
        );
        let p = lo + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * step;
        let f = field.value(p);
        let want = if noise {
            media.density(f, p)
        } else {
            density(f, scene.render.softness)
        };
        let got = float(48 + 4 * ((z * res[1] + y) * res[0] + x));
        inside += (want > 0.0) as usize;
        worst = worst.max((got - want).abs());
    }
    assert!(inside > 40, "{inside} probes in the cloud");
    assert!(worst < 1e-4, "the .vol is off the field by {worst}");
}

#[test]
fn mitsuba_scenes_and_the_apps_render_of_their_view() {
    // Strong noise, so it shapes the silhouette (what the check compares).
    let mut scene = Scene::default();
    scene.render.noise_amount = 0.7;
    let size = [160, 90];
    for (stem, noise) in [("mitsuba_noise", true), ("mitsuba_plain", false)] {
        let options = Options {
            resolution: 96,
            noise,
            image: size,
            samples: 16,
            ..Options::default()
        };
        for f in export(&scene, Format::Mitsuba, &options, stem).unwrap() {
            std::fs::write(out_dir().join(&f.name), &f.bytes).unwrap();
        }
        let xml = std::fs::read_to_string(out_dir().join(format!("{stem}.xml"))).unwrap();
        assert!(xml.contains(&format!("value=\"{stem}.vol\"")));
        let vol = std::fs::read(out_dir().join(format!("{stem}.vol"))).unwrap();
        vol_holds_the_field(&scene, &vol, noise);
    }
    let mut offscreen = Offscreen::new().expect("an offscreen adapter");
    let image = offscreen
        .render(&frame_of(&scene, None), size[0], size[1], Backdrop::Sky)
        .unwrap();
    std::fs::write(out_dir().join("app_view.png"), image.to_png().unwrap()).unwrap();
    // The same view as linear light, for the check's own EXR reader (OpenEXR, in Mitsuba).
    let linear = Offscreen::with_output(Output::Linear)
        .expect("an offscreen adapter")
        .render_linear(&frame_of(&scene, None), size, Backdrop::Sky, 1, None)
        .unwrap();
    std::fs::write(out_dir().join("app_view.exr"), linear.to_exr().unwrap()).unwrap();
    // The same cloud seen through an orthographic camera (Mitsuba's orthographic sensor).
    let mut ortho = scene.clone();
    ortho.camera.orthographic = true;
    let options = Options {
        resolution: 96,
        image: size,
        samples: 16,
        ..Options::default()
    };
    for f in export(&ortho, Format::Mitsuba, &options, "mitsuba_ortho").unwrap() {
        std::fs::write(out_dir().join(&f.name), &f.bytes).unwrap();
    }
    let image = offscreen
        .render(&frame_of(&ortho, None), size[0], size[1], Backdrop::Sky)
        .unwrap();
    std::fs::write(
        out_dir().join("app_view_ortho.png"),
        image.to_png().unwrap(),
    )
    .unwrap();
    // The light the path trace judges: the cloud alone, in linear light, from three suns (in
    // front, to the side, behind), each beside Mitsuba's scene of the same light; and the
    // cumulonimbus at its own light and framing (the cumulus filter over Worley noise, whose
    // mean is far from a half). Dirtiness 1 and sharpness 0, which have no physical
    // counterpart; the noise exported.
    let mut linear = Offscreen::with_output(Output::Linear).expect("an offscreen adapter");
    let mut suns = serde_json::Map::new();
    let lit_scenes = SUNS
        .iter()
        .map(|&(name, azimuth, elevation, exposure)| {
            let mut lit = scene.clone();
            lit.light.sun_azimuth_deg = azimuth;
            lit.light.sun_elevation_deg = elevation;
            lit.light.exposure = exposure;
            (name, lit)
        })
        .chain([("cumulonimbus", Scene::preset(Preset::Cumulonimbus))]);
    for (name, mut lit) in lit_scenes {
        lit.render.dirtiness = 1.0;
        lit.render.sharpness = 0.0;
        let stem = format!("light_{name}");
        let options = Options {
            resolution: 96,
            image: LIGHT_SIZE,
            samples: LIGHT_SAMPLES,
            ..Options::default()
        };
        for f in export(&lit, Format::Mitsuba, &options, &stem).unwrap() {
            std::fs::write(out_dir().join(&f.name), &f.bytes).unwrap();
        }
        let cloud = linear
            .render_linear(
                &frame_of(&lit, None),
                LIGHT_SIZE,
                Backdrop::Transparent,
                1,
                None,
            )
            .unwrap();
        std::fs::write(
            out_dir().join(format!("{stem}.exr")),
            cloud.to_exr().unwrap(),
        )
        .unwrap();
        let l = &lit.light;
        suns.insert(
            name.to_string(),
            serde_json::json!({
                "sun_color": l.sun_color, "sun_intensity": l.sun_intensity,
                "sky_color": l.sky_color, "ambient": l.ambient, "exposure": l.exposure,
                "forward_scattering": l.forward_scattering, "opacity": lit.render.opacity,
            }),
        );
    }
    // The physical sky: the export's environment map as Mitsuba sees it against the app's own
    // sky in linear light (the sun to the right and behind the viewer, so the sky differs left
    // to right and the sun's disk, which the map leaves to the directional emitter, is out of
    // view), and the cloud alone for where the sky shows.
    let mut physical = scene.clone();
    physical.light.physical_sky = true;
    physical.light.sun_azimuth_deg = 40.0;
    physical.light.sun_elevation_deg = 15.0;
    physical.light.exposure = -0.5;
    physical.light.ambient = 0.7;
    physical.camera.pitch_deg = -8.0;
    let options = Options {
        resolution: 64,
        image: size,
        samples: 4,
        ..Options::default()
    };
    for f in export(&physical, Format::Mitsuba, &options, "sky_physical").unwrap() {
        std::fs::write(out_dir().join(&f.name), &f.bytes).unwrap();
    }
    for (name, backdrop) in [
        ("sky_physical_app.exr", Backdrop::Sky),
        ("sky_physical_cloud.exr", Backdrop::Transparent),
    ] {
        let image = linear
            .render_linear(&frame_of(&physical, None), size, backdrop, 1, None)
            .unwrap();
        std::fs::write(out_dir().join(name), image.to_exr().unwrap()).unwrap();
    }
    let background = scene.light.background.map(|c| (c * 255.0).round() as u8);
    std::fs::write(
        out_dir().join("app_view.json"),
        serde_json::json!({
            "background": background,
            "suns": suns,
            "sky_physical": { "ambient": physical.light.ambient },
        })
        .to_string(),
    )
    .unwrap();
}

/// The suns the path trace compares the app's light under: (name, azimuth, elevation,
/// exposure). The default camera looks toward −z, so azimuth 90° lies behind the viewer. One
/// has an exposure, which the app and the export both scale their light by.
const SUNS: [(&str, f32, f32, f32); 3] = [
    ("front", 90.0, 35.0, 0.0),
    ("side", 10.0, 25.0, 0.5),
    ("behind", -90.0, 20.0, 0.0),
];

/// The path trace's samples a pixel in the light comparison: enough that its noise does not
/// hide the shading it is compared by (at 64 the front-lit rank correlation loses 0.17).
const LIGHT_SAMPLES: u32 = 1024;

/// The size of the light comparison's images.
const LIGHT_SIZE: [u32; 2] = [160, 90];

#[test]
fn a_transparent_png_has_the_clouds_alpha_and_no_sky() {
    let scene = Scene::default();
    let mut offscreen = Offscreen::new().expect("an offscreen adapter");
    let clear = offscreen
        .render(&frame_of(&scene, None), 160, 90, Backdrop::Transparent)
        .unwrap();
    let opaque = offscreen
        .render(&frame_of(&scene, None), 160, 90, Backdrop::Sky)
        .unwrap();
    let alpha: Vec<u8> = clear.rgba.chunks(4).map(|p| p[3]).collect();
    assert_eq!(alpha[0], 0, "the corner is sky: transparent");
    let covered = alpha.iter().filter(|&&a| a > 250).count();
    assert!(covered > 500, "{covered} opaque pixels");
    // Where the cloud is opaque both images agree.
    let centre = (45 * 160 + 80) * 4;
    assert!(alpha[45 * 160 + 80] > 250);
    for c in 0..3 {
        assert!(clear.rgba[centre + c].abs_diff(opaque.rgba[centre + c]) <= 2);
    }
}

#[test]
fn the_cpu_media_the_exports_bake_agree_with_the_shaders_tiers_and_all() {
    // Two atmospheric tiers with their own filters, winds and torques, at a scene time where
    // they have moved apart; the CPU's media (what VDB and Mitsuba exports hold) against the
    // slices' shader (`shaders/media_probe.wgsl` runs its `noisy_field`) at the same points
    // and field values, across both floors.
    use cloudsketch::scene::{NoiseFilter, Tier};
    let mut scene = Scene::default();
    scene.time = 7.5;
    scene.render.noise_amount = 0.6;
    scene.render.noise_octaves = 5;
    scene.render.tier_blend = 1.0;
    scene.render.tiers = vec![
        Tier {
            floor: 3.0,
            filter: NoiseFilter::Wispy,
            wind: [1.0, 0.2],
            torque: 20.0,
        },
        Tier {
            floor: 5.0,
            filter: NoiseFilter::Veined,
            wind: [-0.5, 0.8],
            torque: -10.0,
        },
    ];
    // Points over 8 × 8 × 8 units about the floors; field values on either side of the
    // iso-level, within what the noise can carry across it.
    let mut rng = 0x2545_f491_u64;
    let mut unit = || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as f32 / (1u64 << 53) as f32
    };
    let probes: Vec<(Vec3, f32)> = (0..3000)
        .map(|_| {
            let p = Vec3::new(unit() * 8.0 - 4.0, unit() * 8.0, unit() * 8.0 - 4.0);
            (p, ISO + 0.6 * (unit() - 0.5))
        })
        .collect();
    let mut offscreen = Offscreen::new().expect("an offscreen adapter");
    let gpu = offscreen
        .media_at(&frame_of(&scene, None), &probes)
        .unwrap();
    assert_eq!(gpu.len(), probes.len());
    let media = Media::new(&scene);
    let cpu: Vec<f32> = probes.iter().map(|&(p, f)| media.density(f, p)).collect();
    let mean_gap = |a: &[f32], b: &[f32]| {
        a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f32>() / a.len() as f32
    };
    let worst = cpu
        .iter()
        .zip(&gpu)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0f32, f32::max);
    let gap = mean_gap(&cpu, &gpu);
    // The baseline: the same media without the tiers, which a CPU path that ignored them
    // (or took the base's transforms for every tier) would give.
    let mut untiered = scene.clone();
    untiered.render.tiers.clear();
    let flat = Media::new(&untiered);
    let flat: Vec<f32> = probes.iter().map(|&(p, f)| flat.density(f, p)).collect();
    let tiers_matter = mean_gap(&cpu, &flat);
    eprintln!(
        "media: CPU against shader {gap:.5} mean, {worst:.4} worst; tiers change them by {tiers_matter:.4}"
    );
    // Measured on lavapipe: 0.0023 on average, 0.088 at worst (a steep soft edge over the
    // sampler's filtering precision); the tiers change them by 0.092.
    assert!(
        gap < 0.01 && worst < 0.25,
        "CPU and shader media differ by {gap:.4} on average, {worst:.3} at worst"
    );
    assert!(
        tiers_matter > 10.0 * gap,
        "the tiers change the media by {tiers_matter:.4}: too little to tell (gap {gap:.4})"
    );
}
