//! The scenes the link format is measured and tested on (pure, seeded): shared by `tests/`,
//! the unit tests and `bench`, so the sizes they report are of the same scenes.

use glam::{Quat, Vec2, Vec3};

use crate::scene::{DrawingPlane, Preset, Scene};
use crate::seeded::SplitMix;

/// World units per screen pixel at the default view's focus (about 20 units away in an
/// 800-pixel-high view).
const WORLD_PER_PX: f32 = 0.02;

/// Five outlines as a mouse draws them, 200 samples each, on planes facing five views, with
/// the default media: each a lumpy loop 250–450 px across sampled at whole pixels (as pointer
/// events report them), placed around the focus point and snapped to the stroke grid as the
/// app stores a new stroke. Deterministic (seeded).
pub fn hand_drawn() -> Scene {
    let mut scene = Scene::preset(Preset::Empty);
    let mut rng = SplitMix::new(2008);
    let mut r = move |lo: f64, hi: f64| lo + (hi - lo) * rng.next_f64();
    for s in 0..5 {
        let radius = r(125.0, 225.0);
        let bumps: Vec<(f64, f64, f64)> = (2..7)
            .map(|k| (k as f64, r(-0.12, 0.12), r(0.0, std::f64::consts::TAU)))
            .collect();
        let start = r(0.0, std::f64::consts::TAU);
        let px: Vec<Vec2> = (0..200)
            .map(|i| {
                // Uneven speed, as a hand moves: samples bunch where it slows down.
                let u = i as f64 / 200.0;
                let t = start
                    + std::f64::consts::TAU * (u + 0.03 * (3.0 * u * std::f64::consts::TAU).sin());
                let rr = radius
                    * (1.0
                        + bumps
                            .iter()
                            .map(|(k, a, p)| a * (k * t + p).cos())
                            .sum::<f64>());
                Vec2::new((rr * t.cos()).round() as f32, (rr * t.sin()).round() as f32)
            })
            .collect();
        let centre = px.iter().copied().sum::<Vec2>() / px.len() as f32;
        let yaw = s as f32 * 0.7 - 1.4;
        let mut plane = DrawingPlane {
            name: format!("Outline {}", s + 1),
            origin: Vec3::new(r(-3.0, 3.0) as f32, r(2.0, 5.0) as f32, r(-2.0, 2.0) as f32),
            rotation: Quat::from_rotation_y(yaw),
            // Screen y points down, plane y up.
            points: px
                .iter()
                .map(|p| Vec2::new(p.x - centre.x, centre.y - p.y) * WORLD_PER_PX)
                .collect(),
            seed: s as u64 + 1,
            ..Default::default()
        };
        plane.snap_to_grid();
        scene.planes.push(std::sync::Arc::new(plane));
    }
    scene.settle();
    scene
}

/// The scene whose link is stored in `tests/fixtures/` for each link format version: every
/// part of the document away from its default (strokes with and without pressure, a cut, a
/// hidden plane, carving and rotated ellipsoids, a reference picture, media, light, camera
/// and clock), so a change in how any part is written shows as a changed encoding.
pub fn every_part() -> Scene {
    use crate::scene::{Ellipsoid, NoiseBasis, NoiseFilter, ReferenceImage, StrokeKind, Tier};
    use std::sync::Arc;
    let mut scene = hand_drawn();
    scene.seed = 77;
    scene.time = 12.5;
    scene.camera.yaw_deg = 31.0;
    scene.camera.pitch_deg = 12.5;
    scene.camera.distance = 26.0;
    scene.light.sun_azimuth_deg = 200.0;
    scene.light.sun_color = [1.0, 0.8, 0.6];
    scene.render.noise_filter = NoiseFilter::Wispy;
    scene.render.noise_basis = NoiseBasis::Worley;
    scene.render.noise_octaves = 6;
    scene.render.wind = [0.5, -0.25];
    // Every other setting away from the link's base too (a unit test checks), so each one
    // travels in the fixture's link.
    let camera = &mut scene.camera;
    (camera.fov_y_deg, camera.orthographic, camera.target) =
        (40.0, true, Vec3::new(0.5, 2.5, -0.5));
    let light = &mut scene.light;
    light.ambient = 0.3;
    light.background = [0.3, 0.45, 0.7];
    light.exposure = 0.5;
    light.forward_scattering = 0.7;
    light.ground = true;
    light.ground_color = [0.3, 0.35, 0.25];
    light.ground_height = -2.0;
    light.horizon_color = [0.8, 0.8, 0.85];
    light.multiple_scattering = 0.35;
    light.shaft_density = 0.008;
    light.shaft_intensity = 1.5;
    light.shafts = true;
    light.sky_color = [0.5, 0.6, 0.8];
    light.sky_gradient = true;
    light.physical_sky = true;
    light.sun_elevation_deg = 28.0;
    light.sun_intensity = 1.9;
    let render = &mut scene.render;
    render.detail = 2.5;
    render.dirtiness = 0.8;
    render.field_resolution = 80;
    render.light_octaves = 3;
    render.light_resolution = 32;
    render.noise_amount = 0.4;
    render.noise_scale = 2.5;
    render.opacity = 3.0;
    render.sharpness = 0.2;
    render.slices = 160;
    render.softness = 0.15;
    render.tier_blend = 2.0;
    render.tiers = vec![Tier {
        floor: 6.0,
        filter: NoiseFilter::Veined,
        wind: [0.3, 0.1],
        torque: 5.0,
    }];
    render.torque = 3.0;
    {
        let p = Arc::make_mut(&mut scene.planes[3]);
        p.sketch.copies = 3;
        p.sketch.extend = false;
        p.sketch.prune = 0.05;
        p.sketch.simplify = 0.02;
    }
    {
        let p = Arc::make_mut(&mut scene.planes[1]);
        p.kind = StrokeKind::Cut;
        p.closed = false;
        p.pressure = (0..p.points.len())
            .map(|i| 0.3 + 0.5 * (i as f32 / 40.0).sin().abs())
            .collect();
    }
    {
        let p = Arc::make_mut(&mut scene.planes[2]);
        p.hidden = true;
        p.sketch.inflate = 0.6;
        p.sketch.blend = 0.25;
        p.billows = crate::scene::Billows::NEW;
    }
    scene.ellipsoids = vec![
        Arc::new(Ellipsoid {
            billows: crate::scene::Billows {
                levels: 2,
                ratio: 0.4,
                coverage: 0.6,
            },
            ..Ellipsoid::new(Vec3::new(0.0, 1.0, 0.0), Vec3::new(4.0, 2.0, 3.0))
        }),
        Arc::new(Ellipsoid {
            rotation: Quat::from_rotation_z(0.4),
            strength: -0.5,
            hidden: true,
            ..Ellipsoid::new(Vec3::new(1.0, 2.5, 0.5), Vec3::new(1.5, 1.0, 1.0))
        }),
        // Carried by the wind, rising, growing and spreading.
        Arc::new(Ellipsoid {
            motion: Some(crate::scene::Motion {
                carried: true,
                rise: 0.3,
                growth: 0.05,
                spread: 0.1,
                from: Vec3::new(-2.0, 3.0, 1.0),
                size: Vec3::new(1.2, 0.8, 1.0),
            }),
            ..Ellipsoid::new(Vec3::new(-2.0, 3.0, 1.0), Vec3::new(1.2, 0.8, 1.0))
        }),
    ];
    scene.wind_field = crate::scene::WindField {
        velocity: [0.4, -0.1],
        shear: 0.2,
        turbulence: 0.5,
    };
    scene.reference = Some(Arc::new(ReferenceImage {
        name: "sky.jpg".into(),
        data: Arc::new(b"not kept in links".to_vec()),
        size: [800, 600],
        origin: Vec3::new(0.0, 3.0, -5.0),
        height: 9.0,
        opacity: 0.4,
        in_front: true,
        ..Default::default()
    }));
    scene.settle();
    // Keys on each kind of item, with each ease, posed at the scene's time.
    use crate::scene::{Channel, Ease, EllipsoidProperty, LightProperty, MediaProperty};
    let (e0, e1, p0) = (
        scene.ellipsoids[0].id,
        scene.ellipsoids[1].id,
        scene.planes[0].id,
    );
    let mut a = crate::scene::Animation::default();
    let center = Channel::Ellipsoid {
        id: e0,
        property: EllipsoidProperty::Center,
    };
    a.key(center, 0.0, vec![0.0, 1.0, 0.0]);
    a.key(center, 20.0, vec![3.0, 2.0, -1.0]);
    a.set_ease(&[center], 0.0, Ease::EaseInOut);
    let visible = Channel::Ellipsoid {
        id: e1,
        property: EllipsoidProperty::Visible,
    };
    a.key(visible, 0.0, vec![1.0]);
    a.key(visible, 10.0, vec![0.0]);
    let origin = Channel::Plane {
        id: p0,
        property: crate::scene::PlaneProperty::Origin,
    };
    a.key(origin, 5.0, scene.planes[0].origin.to_array().to_vec());
    a.key(
        origin,
        15.0,
        (scene.planes[0].origin + Vec3::X).to_array().to_vec(),
    );
    let azimuth = Channel::Light {
        property: LightProperty::SunAzimuth,
    };
    a.key(azimuth, 0.0, vec![350.0]);
    a.key(azimuth, 20.0, vec![30.0]);
    let opacity = Channel::Media {
        property: MediaProperty::Opacity,
    };
    a.key(opacity, 2.0, vec![3.0]);
    // A key at a frame whose time has no short decimal (frame 7 at 24 fps).
    a.key(opacity, scene.clock.seconds(7), vec![2.5]);
    a.key(opacity, 12.0, vec![2.0]);
    a.set_ease(&[opacity], 2.0, Ease::Constant);
    let noise_size = Channel::Media {
        property: MediaProperty::NoiseScale,
    };
    a.key(noise_size, 0.0, vec![2.5]);
    a.key(noise_size, 20.0, vec![4.0]);
    // A shot camera, its yaw keyed across north (the short way).
    scene.shot = Some(crate::scene::OrbitCamera {
        target: Vec3::new(0.0, 3.0, 0.0),
        yaw_deg: 340.0,
        pitch_deg: 5.0,
        distance: 30.0,
        fov_y_deg: 35.0,
        orthographic: false,
    });
    let yaw = Channel::Shot {
        property: crate::scene::ShotProperty::Yaw,
    };
    a.key(yaw, 0.0, vec![340.0]);
    a.key(yaw, 20.0, vec![20.0]);
    scene.animation = a;
    let t = scene.time;
    scene.pose(t);
    scene
}

/// Documents at the caps built to be slow (every primitive reaches every texel of the grid):
/// what a crafted file or link could hold.
pub fn worst_documents() -> Vec<(&'static str, Scene)> {
    use crate::limits::{MAX_ELLIPSOIDS, MAX_PLANES};
    use crate::scene::{Ellipsoid, StrokeKind};
    use std::sync::Arc;
    let mut huge = Scene::preset(Preset::Empty);
    for i in 0..MAX_ELLIPSOIDS {
        let a = i as f32 * 0.37;
        huge.ellipsoids.push(Arc::new(Ellipsoid {
            center: glam::Vec3::new(a.cos(), a.sin(), (a * 0.3).sin()) * 50.0,
            radii: glam::Vec3::splat(1_000.0),
            ..Default::default()
        }));
    }
    let mut cuts = Scene::preset(Preset::Cumulus);
    for i in 0..MAX_PLANES {
        let y = -3.0 + i as f32 * 0.001;
        cuts.planes.push(Arc::new(DrawingPlane {
            kind: StrokeKind::Cut,
            closed: false,
            points: vec![glam::Vec2::new(-400.0, y), glam::Vec2::new(400.0, y)],
            ..Default::default()
        }));
    }
    vec![("4096_huge_ellipsoids", huge), ("256_cuts", cuts)]
}
