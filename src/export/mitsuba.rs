//! A Mitsuba 3 scene (XML) around the cloud's `.vol` grid: the app's camera, the sun as a
//! directional emitter, the sky's light as an environment map (`STEM.sky.pfm`: the physical
//! sky's radiance over every direction, or the picked sky colour everywhere), and the grid as
//! the extinction
//! of a non-emissive heterogeneous medium inside a null-surfaced box. Mitsuba renders it with
//! `mitsuba scene.xml` (any variant; `scalar_rgb` on a CPU).
//!
//! The app's light converts by one convention (docs/export-formats.md, "Units"), and by
//! nothing else:
//! - the app's phase function is normalised so isotropic scattering is 1, Mitsuba's so it is
//!   1/4π: the sun's irradiance is 4π × its linear colour × intensity;
//! - the sky's light reaches the cloud from every direction, so the environment map's radiance
//!   is the sky's light × ambient (no phase factor: a normalised phase integrates to 1): the
//!   linear sky colour, or the physical sky's radiance × 4π × the sun's intensity. The app
//!   takes it from above only (its transmittance toward the zenith), as the sky's mean; the
//!   map lights the base from below too, and from each direction with its own colour;
//! - both are scaled by 2^exposure, as the app scales all the cloud's light (its EXR holds the
//!   same exposed light);
//! - the phase is the app's two lobes, Mitsuba's `blendphase` of hg(g) and hg(−g/3), 4:1;
//! - the app's slices scatter all the light they take out (no absorption): albedo 1;
//! - σt is the grid × the scene's opacity, per world unit.
//!
//! The emitters are hidden from the camera (`hide_emitters`) and the film keeps alpha: the
//! image is the cloud alone, premultiplied, as the app's transparent export, to lay over any
//! backdrop (the app's background colour is a backdrop, not light).

use std::fmt::Write as _;

use glam::Vec3;

use super::formats::grid_box;
use super::grid::DensityGrid;
use crate::scene::Scene;

/// `text` as an XML attribute value: `&`, `<`, `>`, `"` and `'` escaped, and control characters
/// (which XML 1.0 cannot hold) as `?`.
pub fn xml_attribute(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' | '\n' | '\r' => out.push_str(&format!("&#{};", c as u32)),
            c if c.is_control() => out.push('?'),
            c => out.push(c),
        }
    }
    out
}

fn v3(v: Vec3) -> String {
    format!("{:.6}, {:.6}, {:.6}", v.x, v.y, v.z)
}

/// Paths longer than this many scatterings are cut (a dense cloud's light at albedo 1 needs
/// many).
const MAX_DEPTH: u32 = 256;

/// The app's light in Mitsuba's units (the conversions of docs/export-formats.md, "Units").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Units {
    /// The directional emitter's irradiance: 4π × the sun's light (`Lighting::sun_light`: the
    /// linear sun colour × intensity, or the physical sky's) × 2^exposure.
    pub sun_irradiance: Vec3,
    /// The environment map's scale: ambient × 2^exposure (the map holds the sky's light).
    pub sky_scale: f32,
    /// The medium's single-scattering albedo (the app absorbs nothing).
    pub albedo: f32,
    /// σt per world unit at density 1: the scene's opacity.
    pub sigma_t_scale: f32,
    /// The forward lobe's asymmetry: the scene's forward scattering g.
    pub g_forward: f32,
    /// The backward lobe's asymmetry: −g/3.
    pub g_back: f32,
    /// `blendphase`'s weight, the backward lobe's share: 0.2 (the app mixes 4:1).
    pub back_weight: f32,
}

impl Units {
    /// `scene`'s light, converted.
    pub fn of(scene: &Scene) -> Self {
        let light = &scene.light;
        let exposure = light.exposure.exp2();
        let g = light.forward_scattering;
        Self {
            sun_irradiance: light.sun_light() * (4.0 * std::f32::consts::PI * exposure),
            sky_scale: light.ambient * exposure,
            albedo: 1.0,
            sigma_t_scale: scene.render.opacity,
            g_forward: g,
            g_back: -g / 3.0,
            back_weight: 0.2,
        }
    }
}

/// The sky environment map's size (latitude-longitude) with the physical sky.
pub const SKY_MAP_SIZE: [usize; 2] = [256, 128];

/// The direction of texel (u, v) of a latitude-longitude map as Mitsuba's `envmap` reads it
/// (y up; u = atan2(x, −z) / 2π, v = θ / π from the zenith). Mitsuba takes a map's columns as
/// cells (texel i at u = (i + ½) / w) and its rows as grid points, the first at the zenith
/// and the last at the nadir (row j at v = j / (h − 1)).
pub fn sky_map_direction(u: f32, v: f32) -> Vec3 {
    let (phi, theta) = (std::f32::consts::TAU * u, std::f32::consts::PI * v);
    Vec3::new(
        theta.sin() * phi.sin(),
        theta.cos(),
        -theta.sin() * phi.cos(),
    )
}

/// The sky's light over every direction (before ambient and exposure, which the XML's scale
/// applies) as a PFM latitude-longitude map for Mitsuba's `envmap`: the physical sky's
/// radiance in the app's units ([`SKY_MAP_SIZE`]), or the picked sky colour's light
/// everywhere (8 × 4 texels).
pub fn write_sky(scene: &Scene) -> Vec<u8> {
    let light = &scene.light;
    let ([w, h], texels): ([usize; 2], Vec<Vec3>) = if light.physical_sky {
        let tables = crate::atmosphere::sky(light.sun_elevation_deg);
        let (scale, azimuth) = (light.physical_scale(), light.sun_azimuth_deg.to_radians());
        let [w, h] = SKY_MAP_SIZE;
        let texels = (0..h)
            .flat_map(|j| (0..w).map(move |i| (i, j)))
            .map(|(i, j)| {
                let d = sky_map_direction((i as f32 + 0.5) / w as f32, j as f32 / (h - 1) as f32);
                tables.radiance(d, azimuth) * scale
            })
            .collect();
        (SKY_MAP_SIZE, texels)
    } else {
        let sky = crate::scene::srgb_to_linear(light.sky_color);
        // (Mitsuba takes no map under 2 × 3 texels.)
        ([8, 4], vec![sky; 32])
    };
    write_pfm(w, h, &texels)
}

/// `texels` (`w` × `h`, row-major, the top row first) as a little-endian colour PFM (which
/// stores the bottom row first).
fn write_pfm(w: usize, h: usize, texels: &[Vec3]) -> Vec<u8> {
    let mut out = format!("PF\n{w} {h}\n-1.0\n").into_bytes();
    out.reserve(w * h * 12);
    for row in texels.chunks(w).rev() {
        for t in row {
            for c in t.to_array() {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    out
}

/// The scene XML for `scene`, referring to its grid and its sky's map by `vol_name` and
/// `sky_name`, rendering `size` pixels with `samples` per pixel.
pub fn write_xml(
    scene: &Scene,
    grid: &DensityGrid,
    [vol_name, sky_name]: [&str; 2],
    size: [u32; 2],
    samples: u32,
) -> String {
    let camera = &scene.camera;
    let light = &scene.light;
    let units = Units::of(scene);
    let (lo, hi) = grid_box(grid);
    let center = (lo + hi) * 0.5;
    let half = (hi - lo) * 0.5;
    let (near, far) = camera.clip_range();
    let mut x = String::new();
    let _ = writeln!(x, "<?xml version=\"1.0\" encoding=\"utf-8\"?>");
    let _ = writeln!(x, "<!-- cloudsketch: the cloud as shown, for Mitsuba 3 -->");
    let _ = writeln!(x, "<scene version=\"3.0.0\">");
    let _ = writeln!(
        x,
        "  <integrator type=\"volpath\"><integer name=\"max_depth\" value=\"{MAX_DEPTH}\"/><boolean name=\"hide_emitters\" value=\"true\"/></integrator>"
    );
    if camera.orthographic {
        // Mitsuba's orthographic sensor spans [−1, 1] across the film's width: scaled by the
        // view's half-width, its height follows the film's shape.
        let aspect = size[0] as f32 / size[1].max(1) as f32;
        let h = camera.distance * (camera.fov_y_deg.to_radians() * 0.5).tan() * aspect;
        let _ = writeln!(x, "  <sensor type=\"orthographic\">");
        let _ = writeln!(
            x,
            "    <transform name=\"to_world\"><scale x=\"{h:.6}\" y=\"{h:.6}\"/><lookat origin=\"{}\" target=\"{}\" up=\"{}\"/></transform>",
            v3(camera.eye()),
            v3(camera.target),
            v3(camera.up())
        );
    } else {
        let _ = writeln!(x, "  <sensor type=\"perspective\">");
        let _ = writeln!(
            x,
            "    <float name=\"fov\" value=\"{:.4}\"/>",
            camera.fov_y_deg
        );
        let _ = writeln!(x, "    <string name=\"fov_axis\" value=\"y\"/>");
        let _ = writeln!(
            x,
            "    <transform name=\"to_world\"><lookat origin=\"{}\" target=\"{}\" up=\"{}\"/></transform>",
            v3(camera.eye()),
            v3(camera.target),
            v3(camera.up())
        );
    }
    let _ = writeln!(
        x,
        "    <float name=\"near_clip\" value=\"{near:.6}\"/><float name=\"far_clip\" value=\"{far:.6}\"/>"
    );
    let _ = writeln!(
        x,
        "    <sampler type=\"independent\"><integer name=\"sample_count\" value=\"{samples}\"/></sampler>"
    );
    let _ = writeln!(
        x,
        "    <film type=\"hdrfilm\"><integer name=\"width\" value=\"{}\"/><integer name=\"height\" value=\"{}\"/><string name=\"pixel_format\" value=\"rgba\"/><rfilter type=\"box\"/></film>",
        size[0], size[1]
    );
    let _ = writeln!(x, "  </sensor>");
    let _ = writeln!(
        x,
        "  <emitter type=\"directional\"><vector name=\"direction\" value=\"{}\"/><rgb name=\"irradiance\" value=\"{}\"/></emitter>",
        v3(-light.sun_direction()),
        v3(units.sun_irradiance)
    );
    let _ = writeln!(
        x,
        "  <emitter type=\"envmap\"><string name=\"filename\" value=\"{}\"/><float name=\"scale\" value=\"{:.6}\"/></emitter>",
        xml_attribute(sky_name),
        units.sky_scale
    );
    let _ = writeln!(x, "  <shape type=\"cube\">");
    let _ = writeln!(
        x,
        "    <transform name=\"to_world\"><scale value=\"{}\"/><translate value=\"{}\"/></transform>",
        v3(half),
        v3(center)
    );
    let _ = writeln!(x, "    <bsdf type=\"null\"/>");
    let _ = writeln!(x, "    <medium type=\"heterogeneous\" name=\"interior\">");
    let _ = writeln!(
        x,
        "      <volume type=\"gridvolume\" name=\"sigma_t\"><string name=\"filename\" value=\"{}\"/><transform name=\"to_world\"><scale value=\"{}\"/><translate value=\"{}\"/></transform></volume>",
        xml_attribute(vol_name),
        v3(hi - lo),
        v3(lo)
    );
    let _ = writeln!(
        x,
        "      <float name=\"scale\" value=\"{:.6}\"/>",
        units.sigma_t_scale
    );
    let _ = writeln!(
        x,
        "      <rgb name=\"albedo\" value=\"{a:.4}, {a:.4}, {a:.4}\"/>",
        a = units.albedo
    );
    let _ = writeln!(
        x,
        "      <phase type=\"blendphase\"><float name=\"weight\" value=\"{:.4}\"/><phase type=\"hg\" name=\"phase_0\"><float name=\"g\" value=\"{:.4}\"/></phase><phase type=\"hg\" name=\"phase_1\"><float name=\"g\" value=\"{:.4}\"/></phase></phase>",
        units.back_weight, units.g_forward, units.g_back
    );
    let _ = writeln!(x, "    </medium>");
    let _ = writeln!(x, "  </shape>");
    let _ = writeln!(x, "</scene>");
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::{Format, Options, export};

    #[test]
    fn a_file_name_with_markup_characters_stays_one_attribute() {
        let options = Options {
            resolution: 8,
            ..Default::default()
        };
        let files = export(&Scene::default(), Format::Mitsuba, &options, "a<&\"'>").unwrap();
        let xml = String::from_utf8(files[0].bytes.clone()).unwrap();
        assert!(
            xml.contains("value=\"a&lt;&amp;&quot;&apos;&gt;.vol\""),
            "{xml}"
        );
        assert!(!xml.contains("a<&"), "the raw name leaked into the XML");
        assert_eq!(xml_attribute("x\ny\u{1}"), "x&#10;y?");
    }

    /// A PFM's size and texels, the top row first.
    fn read_pfm(bytes: &[u8]) -> (usize, usize, Vec<Vec3>) {
        let text = |k: usize| bytes.split(|&b| b == b'\n').nth(k).unwrap();
        assert_eq!(text(0), b"PF");
        let size = String::from_utf8(text(1).to_vec()).unwrap();
        let mut it = size.split(' ').map(|v| v.parse::<usize>().unwrap());
        let (w, h) = (it.next().unwrap(), it.next().unwrap());
        assert_eq!(text(2), b"-1.0", "little-endian");
        let start = bytes.len() - w * h * 12;
        let f = |k: usize| {
            f32::from_le_bytes(bytes[start + 4 * k..start + 4 * k + 4].try_into().unwrap())
        };
        let mut rows: Vec<Vec<Vec3>> = (0..h)
            .map(|j| {
                (0..w)
                    .map(|i| {
                        let k = 3 * (j * w + i);
                        Vec3::new(f(k), f(k + 1), f(k + 2))
                    })
                    .collect()
            })
            .collect();
        rows.reverse();
        (w, h, rows.concat())
    }

    #[test]
    fn the_sky_map_is_the_physical_skys_light_with_the_sun_where_the_app_has_it() {
        let mut scene = Scene::default();
        scene.light.physical_sky = true;
        scene.light.sun_elevation_deg = 8.0;
        scene.light.sun_azimuth_deg = 130.0;
        let (w, h, texels) = read_pfm(&write_sky(&scene));
        assert_eq!([w, h], SKY_MAP_SIZE);
        let tables = crate::atmosphere::sky(8.0);
        let scale = scene.light.physical_scale();
        // The top row is the zenith's light, the bottom row the nadir's.
        let zenith = tables.radiance(Vec3::Y, 0.0) * scale;
        assert!(((texels[w / 2] - zenith) / zenith).abs().max_element() < 0.01);
        let nadir = tables.radiance(Vec3::NEG_Y, 0.0) * scale;
        let last = texels[(h - 1) * w + w / 2];
        assert!(((last - nadir) / nadir).abs().max_element() < 0.01);
        // The brightest texel lies toward the sun, in the app's frame: a map mirrored or turned
        // would put it elsewhere.
        let (k, _) = texels
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.element_sum().total_cmp(&b.1.element_sum()))
            .unwrap();
        let d = sky_map_direction(
            ((k % w) as f32 + 0.5) / w as f32,
            (k / w) as f32 / (h - 1) as f32,
        );
        // (Its azimuth: the sky is brightest toward the sun, at the horizon below it.)
        let across = |v: Vec3| Vec3::new(v.x, 0.0, v.z);
        let off = across(d)
            .angle_between(across(scene.light.sun_direction()))
            .to_degrees();
        assert!(
            off < 3.0,
            "the brightest texel is {off:.1}° round from the sun"
        );
        assert!(d.y < scene.light.sun_direction().y + 0.05);
        // Picked colours: the sky colour's light everywhere, in a map Mitsuba takes (at least
        // 2 × 3 texels).
        scene.light.physical_sky = false;
        let (w, h, texels) = read_pfm(&write_sky(&scene));
        assert!(w >= 2 && h >= 3, "{w} × {h}");
        let sky = crate::scene::srgb_to_linear(scene.light.sky_color);
        assert!(texels.iter().all(|t| (*t - sky).abs().max_element() < 1e-6));
    }
}
