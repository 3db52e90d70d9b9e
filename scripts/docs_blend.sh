#!/usr/bin/env bash
# Remakes docs/blend-*.png: one sketched cumulus outline rendered with the plain union of its
# spheres (soft blend 0) and with the default soft blend, from the drawing view and from 60° to
# the side, without noise so the shape itself shows. Needs a built CLI (cargo build --release).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${CLOUDSKETCH:-$ROOT/target/release/cloudsketch}"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
export NODEVICE_SELECT=1
python3 - "$TMP/stroke.json" <<'PY'
import json, math, sys
pts = [[100 + i * 5.0, 300.0] for i in range(61)]
for i in range(1, 160):
    a = i / 160 * math.pi
    bump = 1 + 0.18 * abs(math.sin(a * 6))
    pts.append([250 + 150 * math.cos(a), 300 - 110 * math.sin(a) * bump])
json.dump({"points": pts, "closed": True}, open(sys.argv[1], "w"))
PY
"$BIN" sketch "$TMP/stroke.json" -o "$TMP/scene.json"
for blend in 0 0.4; do
  name=$([ "$blend" = 0 ] && echo hard || echo soft)
  for yaw in 0 60; do
    "$BIN" render "$TMP/scene.json" -o "$ROOT/docs/blend-$name-$yaw.png" --size 480x320 \
      --set "/planes/0/sketch/blend=$blend" --set /render/noise_amount=0 \
      --set "/camera/yaw_deg=$yaw" --set /camera/distance=14 --set /render/slices=256
  done
done
echo "wrote docs/blend-{hard,soft}-{0,60}.png"
