#!/usr/bin/env bash
# Remakes docs/presets/NAME.png: each preset as `cloudsketch new --preset NAME` makes it,
# rendered by the CLI. Needs a built CLI (cargo build --release).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${CLOUDSKETCH:-$ROOT/target/release/cloudsketch}"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
export NODEVICE_SELECT=1
mkdir -p "$ROOT/docs/presets"
for p in cumulus stratus cirrus cumulonimbus sunset; do
  "$BIN" new --preset "$p" -o "$TMP/$p.json"
  "$BIN" render "$TMP/$p.json" -o "$ROOT/docs/presets/$p.png" --size 400x260 --set /render/slices=256
done
