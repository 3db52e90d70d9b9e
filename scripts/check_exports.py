#!/usr/bin/env python3
"""Reads the exports that `cargo test --test exports` wrote to target/export-check/ with
independent readers:

- OpenVDB's own Python module (Debian's python3-openvdb) opens each .vdb: a float fog volume
  named "density"; at every probe point (world coordinates of the file) the grid holds the
  value the field gives there, evaluated directly by the test, to float precision.
- Mitsuba 3 (pip's `mitsuba`, variant scalar_rgb) renders the exported scenes with and without
  the noise, and through an orthographic camera, laid over the app's background: the cloud
  covers the same pixels as the app's own render of that view (coverage IoU >= 0.8; coverage
  = pixels more than 6/255 from the background) and its pixels' contrast with the background
  correlates with the app's (>= 0.9).
- The XML of four lit scenes (the default cloud under three suns, the cumulonimbus at its own
  light) holds the app's light by the documented units (read back with an XML parser), and
  their path traces are compared with the app's linear light inside the cloud at 1,024 samples
  a pixel: mean ratio within 0.8-1.25 (the cumulonimbus 0.9-1.25) and rank correlation >= 0.88
  for each (contrast printed).

- OpenEXR (through Mitsuba's Bitmap) opens the app's EXR of the same view: RGBA half floats
  of the PNG's size, opaque, every PNG pixel the app's one tone map of the EXR's light (within
  4 levels, 0.5 on average), light above 1 inside the cloud (no tone map), and inside the cloud
  the same order of brightness as the PNG.

Usage: check_exports.py DIR. Exits non-zero with a message on the first failure.
"""
import json
import os
import sys


def fail(msg):
    print(f"check_exports: FAIL: {msg}")
    sys.exit(1)


def check_vdb(d):
    import pyopenvdb as vdb
    probes = sorted(f for f in os.listdir(d) if f.endswith(".probes.json"))
    if len(probes) < 2:
        fail(f"expected VDB probe files in {d}, found {probes}")
    for name in probes:
        spec = json.load(open(os.path.join(d, name)))
        path = os.path.join(d, spec["file"])
        grids, _ = vdb.readAll(path)
        if len(grids) != 1:
            fail(f"{path}: {len(grids)} grids")
        g = grids[0]
        if g.name != "density" or g.gridClass != vdb.GridClass.FOG_VOLUME or g.valueTypeName != "float":
            fail(f"{path}: grid {g.name!r} of class {g.gridClass} and type {g.valueTypeName}")
        box = g.evalActiveVoxelBoundingBox()
        if (tuple(g.metadata["file_bbox_min"]), tuple(g.metadata["file_bbox_max"])) != (tuple(box[0]), tuple(box[1])):
            fail(f"{path}: file_bbox metadata {g.metadata['file_bbox_min']}..{g.metadata['file_bbox_max']} vs active voxels {box}")
        voxel = g.transform.voxelSize()
        if any(abs(v - spec["voxel_size"]) > 1e-5 for v in voxel):
            fail(f"{path}: voxel size {voxel}, expected {spec['voxel_size']}")
        acc = g.getConstAccessor()
        worst = 0.0
        for p, want in zip(spec["points"], spec["values"]):
            ijk = g.transform.worldToIndexCellCentered(tuple(p))
            got = acc.getValue(ijk)
            worst = max(worst, abs(got - want))
            if abs(got - want) > 2e-4:
                fail(f"{path}: at {p} (voxel {ijk}) the grid holds {got}, the field gives {want}")
        print(f"check_exports: {spec['file']}: {len(spec['points'])} probes agree "
              f"(worst {worst:.1e}); {g.activeVoxelCount()} active voxels")


def check_mitsuba(d):
    import mitsuba as mi
    import numpy as np
    mi.set_variant("scalar_rgb")
    background = np.array(json.load(open(os.path.join(d, "app_view.json")))["background"], dtype=np.float64)

    def coverage(rgb8):
        return (np.abs(rgb8 - background) > 6).any(axis=2)

    bg_light = light_of(background / 255)

    def render(stem):
        # The export's image is the cloud alone, premultiplied (its emitters hidden): laid over
        # the light of the app's background (the light its tone map shows as the picked
        # colour) and mapped by the app's one tone map, as the app shows its own.
        rgba = np.array(mi.render(mi.load_file(os.path.join(d, f"{stem}.xml")), seed=1), dtype=np.float64)
        linear = rgba[:, :, :3] + (1 - rgba[:, :, 3:4]) * bg_light
        return np.clip(np.round(display(linear)), 0, 255)

    def contrast(rgb8):
        # How far each pixel stands from the background: where the cloud is, and how dense.
        return np.abs(rgb8 - background).sum(axis=2).ravel()

    ious, corrs = {}, {}
    for stem, app in [("mitsuba_noise", "app_view.png"), ("mitsuba_plain", "app_view.png"),
                      ("mitsuba_ortho", "app_view_ortho.png")]:
        app_rgb = np.array(mi.Bitmap(os.path.join(d, app)), dtype=np.float64)[:, :, :3]
        app_cover = coverage(app_rgb)
        rendered = render(stem)
        cover = coverage(rendered)
        union = (cover | app_cover).sum()
        ious[stem] = (cover & app_cover).sum() / max(union, 1)
        corrs[stem] = np.corrcoef(contrast(rendered), contrast(app_rgb))[0, 1]
        print(f"check_exports: {stem}: coverage {cover.sum()} px vs the app's {app_cover.sum()}, "
              f"IoU {ious[stem]:.3f}, contrast correlation {corrs[stem]:.4f}")
    for stem in ["mitsuba_noise", "mitsuba_ortho"]:
        if ious[stem] < 0.8:
            fail(f"{stem}: Mitsuba's render covers other pixels than the app's (IoU {ious[stem]:.3f} < 0.8)")
    for stem in ious:
        if corrs[stem] < 0.9:
            fail(f"{stem}: Mitsuba's image is not the app's (contrast correlation {corrs[stem]:.3f} < 0.9)")
    # Whether the export holds the noise is checked in its grid (tests/exports.rs: the .vol
    # against the CPU media, which a compute probe holds against the shader's): at 160x90 the
    # noise moves the app's image by under half a level on average, less than the path
    # trace's own noise, so these images cannot tell the two exports apart.


def tone_map(x):
    """The app's one tone map (src/render/tone.rs): ACES's filmic curve, Narkowicz's fit, the
    light scaled by 0.6 first; display light in [0, 1] before sRGB encoding."""
    import numpy as np
    v = np.clip(x, 0, None) * 0.6
    return np.clip((v * (2.51 * v + 0.03)) / (v * (2.43 * v + 0.59) + 0.14), 0, 1)


def light_of(c):
    """The light the app's tone map shows as display colour `c` (sRGB-encoded, 0-1)."""
    import numpy as np
    y = np.clip(srgb_to_linear(c), 0, 1)
    a, b, e = 2.51 - 2.43 * y, 0.03 - 0.59 * y, -0.14 * y
    return (-b + np.sqrt(b * b - 4 * a * e)) / (2 * a) / 0.6


def display(linear):
    """Linear light as the app's PNG shows it (0-255, not rounded): the one tone map, encoded."""
    import numpy as np
    t = tone_map(linear)
    return np.where(t <= 0.0031308, t * 12.92, 1.055 * np.power(t, 1 / 2.4) - 0.055) * 255


def srgb_to_linear(c):
    import numpy as np
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, np.power((np.clip(c, 0, None) + 0.055) / 1.055, 2.4))


def check_units(d):
    """The XML holds the app's light by the documented conversions (docs/export-formats.md,
    "Units"), read back with an XML parser."""
    import math
    import xml.etree.ElementTree as ET
    import mitsuba as mi
    import numpy as np
    mi.set_variant("scalar_rgb")
    suns = json.load(open(os.path.join(d, "app_view.json")))["suns"]
    for name, light in suns.items():
        root = ET.parse(os.path.join(d, f"light_{name}.xml")).getroot()
        values = lambda el: np.array([float(v) for v in el.get("value").split(",")])
        exposure = 2.0 ** light["exposure"]
        want_sun = 4 * math.pi * srgb_to_linear(light["sun_color"]) * light["sun_intensity"] * exposure
        want_sky = srgb_to_linear(light["sky_color"]) * light["ambient"] * exposure
        sun = values(root.find("emitter[@type='directional']/rgb[@name='irradiance']"))
        envmap = root.find("emitter[@type='envmap']")
        sky_file = envmap.find("string[@name='filename']").get("value")
        # The map holds the picked sky colour's light everywhere; its scale ambient × 2^exposure.
        sky_map = np.array(mi.Bitmap(os.path.join(d, sky_file)), dtype=np.float64)[:, :, :3].reshape(-1, 3)
        uniform = np.ptp(sky_map, axis=0).max() < 1e-6
        scale = float(envmap.find("float[@name='scale']").get("value"))
        sky = sky_map[0] * scale if uniform else np.full(3, np.nan)
        medium = root.find("shape/medium")
        phase = medium.find("phase")
        # (Mitsuba hands nested objects over in the order of their names.)
        lobes = [float(p.find("float[@name='g']").get("value"))
                 for p in sorted(phase.findall("phase"), key=lambda p: p.get("name", ""))]
        weight = float(phase.find("float[@name='weight']").get("value"))
        albedo = values(medium.find("rgb[@name='albedo']"))
        scale = float(medium.find("float[@name='scale']").get("value"))
        hidden = root.find("integrator/boolean[@name='hide_emitters']").get("value")
        g = light["forward_scattering"]
        checks = {
            "sun irradiance = 4π × linear sun × intensity × 2^exposure": np.allclose(sun, want_sun, rtol=1e-4),
            "sky map = linear sky everywhere, scaled by ambient × 2^exposure": np.allclose(sky, want_sky, rtol=1e-4, atol=1e-6),
            "phase = blendphase of hg(g) and hg(-g/3), weight 0.2": phase.get("type") == "blendphase"
            and np.allclose(lobes, [g, -g / 3], atol=1e-4) and abs(weight - 0.2) < 1e-6,
            "albedo 1": np.allclose(albedo, 1.0),
            "sigma_t scale = opacity": abs(scale - light["opacity"]) < 1e-5,
            "emitters hidden from the camera": hidden == "true",
            "no emission in the medium": medium.find("*[@name='radiance']") is None,
        }
        for what, ok in checks.items():
            if not ok:
                fail(f"light_{name}.xml: not {what}")
    print(f"check_exports: the light of {len(suns)} scenes is written by the documented units")


def check_light(d):
    """The app's light against Mitsuba's path trace of its export, in linear light inside the
    cloud (the app's alpha over one half), for suns in front, to the side and behind: luminance
    rank correlation, mean ratio, and the ratio of their 90th/10th-percentile contrasts, the
    trace at 1,024 samples a pixel (at 64 its noise alone costs the front-lit correlation 0.17).
    Held: the mean ratio within #37's 0.8-1.25 for every sun (1.22 / 0.82 / 1.13, front / side /
    behind; 2.68 / 1.89 / 1.59 before the multiple scattering was calibrated), and the rank
    correlation at 0.88 or more (0.904 / 0.940 / 0.946; #37's target is 0.9; front-lit it was
    0.74 before the density around each point scaled the multiple scattering, and 0.25 with no
    diffusion). The contrast is printed (0.86 / 0.89 / 1.13; #37 asks 0.8-1.25).
    And the cumulonimbus at its own light and framing: the cumulus filter (|n|) over Worley
    noise averages a quarter, not a half, so the cloud the noise leaves is thinner than its
    field; the multiple scattering's blur of the density around each point shifts the field by
    the noise's mean. Held: mean ratio 0.9-1.25 (0.95; 0.85 with the blur of the bare field) and
    rank correlation 0.88 (0.913; 0.901 before)."""
    import mitsuba as mi
    import numpy as np
    mi.set_variant("scalar_rgb")
    suns = json.load(open(os.path.join(d, "app_view.json")))["suns"]
    lum = lambda rgb: rgb @ np.array([0.2126, 0.7152, 0.0722])

    def rank(v):
        # Ties (the app's half floats) share their mean rank, so the pixels' order breaks none.
        r = np.empty(len(v))
        r[np.argsort(v, kind="stable")] = np.arange(len(v))
        _, tie, count = np.unique(v, return_inverse=True, return_counts=True)
        return (np.bincount(tie, r) / count)[tie]

    for needed in ("front", "cumulonimbus"):
        if needed not in suns:
            fail(f"app_view.json has no light_{needed} scene")
    mi.file_resolver().prepend(d)
    figures = {}
    for name in suns:
        app = np.array(mi.Bitmap(os.path.join(d, f"light_{name}.exr")), dtype=np.float64)
        # Blocks of a fixed size: Mitsuba seeds each pixel's samples by its block, whose size
        # otherwise follows the machine's thread count.
        xml = open(os.path.join(d, f"light_{name}.xml")).read()
        fixed = xml.replace('<integrator type="volpath">', '<integrator type="volpath"><integer name="block_size" value="32"/>')
        if fixed == xml:
            fail(f"light_{name}.xml: no volpath integrator")
        trace = np.array(mi.render(mi.load_string(fixed), seed=1), dtype=np.float64)
        inside = app[:, :, 3] > 0.5
        if inside.sum() < 200:
            fail(f"light_{name}: the app's cloud covers {inside.sum()} pixels")
        a, t = lum(app[:, :, :3])[inside], lum(trace[:, :, :3])[inside]
        corr = np.corrcoef(rank(a), rank(t))[0, 1]
        mean = t.mean() / a.mean()
        spread = lambda v: np.percentile(v, 90) / max(np.percentile(v, 10), 1e-9)
        contrast = spread(t) / spread(a)
        figures[name] = (corr, mean, contrast)
        print(f"check_exports: light_{name}: {inside.sum()} px inside; the path trace against the app: "
              f"rank correlation {corr:.3f}, mean ratio {mean:.3f}, 90/10 contrast ratio {contrast:.3f}")
    for name, (corr, mean, _) in figures.items():
        low = 0.9 if name == "cumulonimbus" else 0.8
        if not low <= mean <= 1.25:
            fail(f"light_{name}: the path trace's mean light is {mean:.3f}x the app's ({low}-1.25)")
        if corr < 0.88:
            fail(f"light_{name}: rank correlation {corr:.3f} < 0.88")
    return figures


def check_sky(d):
    """The physical sky's environment map, as Mitsuba reads it, is the sky the app draws: the
    export's scene rendered with its emitters visible against the app's linear render of the
    same view, wherever the cloud leaves the sky clear. A map in another orientation (turned,
    mirrored, upside down) or in other units misses by far more than the path trace's noise."""
    import mitsuba as mi
    import numpy as np
    mi.set_variant("scalar_rgb")
    xml = open(os.path.join(d, "sky_physical.xml")).read()
    shown = xml.replace('name="hide_emitters" value="true"', 'name="hide_emitters" value="false"')
    if shown == xml:
        fail("sky_physical.xml: no hidden emitters to show")
    mi.file_resolver().prepend(d)
    # The map is scaled by the ambient setting, as the app scales the sky's light on the cloud
    # (its backdrop shows the sky itself).
    ambient = json.load(open(os.path.join(d, "app_view.json")))["sky_physical"]["ambient"]
    trace = np.array(mi.render(mi.load_string(shown), seed=1), dtype=np.float64)[:, :, :3] / ambient
    app = np.array(mi.Bitmap(os.path.join(d, "sky_physical_app.exr")), dtype=np.float64)[:, :, :3]
    cloud = np.array(mi.Bitmap(os.path.join(d, "sky_physical_cloud.exr")), dtype=np.float64)[:, :, 3]
    # Within three pixels of where the sky changes by over a fifth from one pixel to the next
    # (the horizon's edge) the map's texels (1.4 degrees) are coarser than the pixels (0.5):
    # left out.
    lum = app @ np.array([0.2126, 0.7152, 0.0722])
    step = np.abs(np.diff(lum, axis=0)) > 0.2 * np.minimum(lum[1:], lum[:-1])
    steep = np.zeros(lum.shape, dtype=bool)
    for k in range(4):
        steep[k + 1:] |= step[: step.shape[0] - k]
        steep[: step.shape[0] - k] |= step[k:]
    clear = (cloud < 0.002) & ~steep
    if clear.sum() < 0.3 * clear.size:
        fail(f"sky_physical: only {clear.sum()} px of clear sky")
    ratio = trace[clear] / np.maximum(app[clear], 1e-6)
    mean, worst = np.abs(ratio - 1).mean(), np.percentile(np.abs(ratio - 1), 99)
    # Left against right: the sun is to the right, so a mirrored map is brighter on the left.
    half = app.shape[1] // 2
    side = lambda img: img[:, half:][clear[:, half:]].sum() / max(img[:, :half][clear[:, :half]].sum(), 1e-9)
    print(f"check_exports: sky_physical: {clear.sum()} clear px; Mitsuba's view of the map against "
          f"the app's sky: mean |ratio - 1| {mean:.4f}, 99th percentile {worst:.4f}; "
          f"right/left {side(trace):.3f} (app {side(app):.3f})")
    if mean > 0.03 or worst > 0.1:
        fail(f"sky_physical: Mitsuba's sky is not the app's (mean error {mean:.3f}, 99th percentile {worst:.3f})")


def check_exr(d):
    import mitsuba as mi
    import numpy as np
    mi.set_variant("scalar_rgb")
    bitmap = mi.Bitmap(os.path.join(d, "app_view.exr"))
    if bitmap.pixel_format() != mi.Bitmap.PixelFormat.RGBA or bitmap.component_format() != mi.Struct.Type.Float16:
        fail(f"app_view.exr is {bitmap.pixel_format()} {bitmap.component_format()}, not RGBA half floats")
    exr = np.array(bitmap, dtype=np.float64)
    png = np.array(mi.Bitmap(os.path.join(d, "app_view.png")), dtype=np.float64)[:, :, :3]
    if exr.shape[:2] != png.shape[:2]:
        fail(f"app_view.exr is {exr.shape[:2]}, the PNG {png.shape[:2]}")
    if np.abs(exr[:, :, 3] - 1).max() > 1e-3:
        fail("app_view.exr over the sky is not opaque")
    background = np.array(json.load(open(os.path.join(d, "app_view.json")))["background"], dtype=np.float64)
    cloud = (np.abs(png - background) > 6).any(axis=2)
    # One tone map: every PNG pixel, sky and cloud alike, is the app's curve of the EXR's light.
    error = np.abs(display(exr[:, :, :3]) - png)
    sky_error, mean_error = error.max(), error.mean()
    if sky_error > 4 or mean_error > 0.5:
        fail(f"app_view.png is not the tone map of app_view.exr (worst {sky_error:.2f}, mean {mean_error:.3f} levels)")
    lum = lambda rgb: rgb @ np.array([0.2126, 0.7152, 0.0722])
    rank = lambda v: np.argsort(np.argsort(v))
    e, p = lum(exr[:, :, :3])[cloud], lum(png)[cloud]
    corr = np.corrcoef(rank(e), rank(p))[0, 1]
    print(f"check_exports: app_view.exr: {cloud.sum()} cloud px, brightest {e.max():.2f}, "
          f"the PNG its tone map within {sky_error:.2f} levels (mean {mean_error:.3f}), "
          f"rank correlation with the PNG {corr:.3f}")
    if e.max() <= 1.0:
        fail("app_view.exr holds no light above 1 in the cloud: tone-mapped already?")
    if corr < 0.95:
        fail(f"app_view.exr's cloud is not the PNG's (rank correlation {corr:.3f} < 0.95)")


def main():
    d = sys.argv[1] if len(sys.argv) > 1 else "target/export-check"
    what = sys.argv[2] if len(sys.argv) > 2 else "all"
    if what in ("all", "vdb"):
        check_vdb(d)
    if what in ("all", "mitsuba"):
        check_mitsuba(d)
    if what in ("all", "exr"):
        check_exr(d)
    if what in ("all", "sky"):
        check_sky(d)
    if what in ("all", "light"):
        check_units(d)
        check_light(d)
    print("check_exports: ok")


if __name__ == "__main__":
    main()
