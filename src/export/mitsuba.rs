//! A Mitsuba 3 scene (XML) around the cloud's `.vol` grid: the app's camera, the sun as a
//! directional emitter, the sky's light as a constant emitter, and the grid as the extinction
//! of a non-emissive heterogeneous medium inside a null-surfaced box. Mitsuba renders it with
//! `mitsuba scene.xml` (any variant; `scalar_rgb` on a CPU).
//!
//! The app's light converts by one convention (docs/export-formats.md, "Units"), and by
//! nothing else:
//! - the app's phase function is normalised so isotropic scattering is 1, Mitsuba's so it is
//!   1/4π: the sun's irradiance is 4π × its linear colour × intensity;
//! - the sky's light reaches the cloud from every direction, so the constant emitter's radiance
//!   is the sky colour × ambient (no phase factor: a normalised phase integrates to 1). The
//!   app takes it from above only (its transmittance toward the zenith); the constant emitter
//!   lights the base from below too;
//! - both are scaled by 2^exposure, as the app scales all the cloud's light (its EXR holds the
//!   same exposed light);
//! - the phase is the app's two lobes, Mitsuba's `blendphase` of hg(g) and hg(−g/3), 4:1;
//! - the app's slices scatter all the light they take out (no absorption): albedo 1;
//! - σt is the grid × the scene's opacity, per world unit.
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
    /// The constant emitter's radiance: the sky's light (`Lighting::sky_light`: linear sky colour
    /// × ambient, or ambient × the physical sky's mean) × 2^exposure.
    pub sky_radiance: Vec3,
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
            sky_radiance: light.sky_light() * exposure,
            albedo: 1.0,
            sigma_t_scale: scene.render.opacity,
            g_forward: g,
            g_back: -g / 3.0,
            back_weight: 0.2,
        }
    }
}

/// The scene XML for `scene`, referring to its grid as `vol_name`, rendering `size` pixels
/// with `samples` per pixel.
pub fn write_xml(
    scene: &Scene,
    grid: &DensityGrid,
    vol_name: &str,
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
        "  <emitter type=\"constant\"><rgb name=\"radiance\" value=\"{}\"/></emitter>",
        v3(units.sky_radiance)
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
}
