#!/usr/bin/env python3
"""Remakes docs/presets/NAME-traced.png: Mitsuba 3's path trace (`volpath`) of each preset's
own export (`cloudsketch export --format mitsuba`), shown as the app shows light: laid in
linear light over the app's sky without the cloud, then the app's one tone map
(check_exports.display). Beside docs/presets/NAME.png in the README, it shows where the
real-time light and the path trace part. Needs the built CLI and the export venv (mitsuba,
numpy): `target/export-venv/bin/python scripts/docs_presets_traced.py`. About two minutes a preset
on 2 cores.
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
import mitsuba as mi

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_exports import display, light_of  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.environ.get("CLOUDSKETCH", os.path.join(ROOT, "target/release/cloudsketch"))
SIZE = (400, 260)
SAMPLES = 256

mi.set_variant("scalar_rgb")
env = dict(os.environ, NODEVICE_SELECT="1")


def run(*args):
    subprocess.run([BIN, *args], check=True, env=env, stdout=subprocess.DEVNULL)


with tempfile.TemporaryDirectory() as tmp:
    for name in ["cumulus", "stratus", "cirrus", "cumulonimbus", "sunset"]:
        scene = os.path.join(tmp, f"{name}.json")
        run("new", "--preset", name, "-o", scene)
        size = f"{SIZE[0]}x{SIZE[1]}"
        xml = os.path.join(tmp, f"{name}.xml")
        run("export", scene, "--format", "mitsuba", "--size", size, "--samples", str(SAMPLES),
            "--resolution", "96", "-o", xml)
        # The app's sky alone (the same scene without its ellipsoids), as display colour.
        doc = json.load(open(scene))
        doc["ellipsoids"] = []
        empty = os.path.join(tmp, f"{name}-sky.json")
        json.dump(doc, open(empty, "w"))
        sky_png = os.path.join(tmp, f"{name}-sky.png")
        run("render", empty, "--size", size, "-o", sky_png)
        sky = np.array(mi.Bitmap(sky_png), dtype=np.float64)[:, :, :3] / 255.0
        trace = np.array(mi.render(mi.load_file(xml), seed=1), dtype=np.float64)
        alpha = np.clip(trace[:, :, 3:4], 0, 1)
        linear = trace[:, :, :3] + (1 - alpha) * light_of(sky)
        rgb = np.clip(np.round(display(linear)), 0, 255).astype(np.uint8)
        out = os.path.join(ROOT, "docs/presets", f"{name}-traced.png")
        mi.util.write_bitmap(out, mi.Bitmap(rgb))
        print(f"traced {name} → {out}", flush=True)
