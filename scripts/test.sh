#!/usr/bin/env bash
# Sets up whatever is missing (scripts/setup.sh) and runs every test: Rust unit and
# integration tests (pure core, naga validation of shaders/, offscreen lavapipe renders, CLI,
# the desktop window under Xvfb, link fixtures), a 30-second fuzz run of the link decoders (nightly + cargo-fuzz, installed
# here when missing), the release web build, and the browser end-to-end tests in headless
# Chromium (WebGPU on SwiftShader, then the WebGL2 fallback), and the exports read back by
# independent readers (OpenVDB's Python module, Mitsuba 3, the Khronos glTF validator), and a
# frame range rendered by a Slurm job array on a one-node cluster (scripts/check_slurm.sh).
# Screenshots: web/test-results/screenshots/.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
# Each stage's line says how long the suite has run (CI stops it at 90 minutes).
START=$SECONDS
log() { printf '\033[1;34m[test %3d:%02d]\033[0m %s\n' $(((SECONDS - START) / 60)) $(((SECONDS - START) % 60)) "$*" >&2; }

bash scripts/setup.sh

log "cargo test (native)"
# Offscreen tests pick their adapter themselves: Mesa's device-select layer would only look for
# a display (and print XDG_RUNTIME_DIR errors on a headless machine). The CLI does the same.
export NODEVICE_SELECT=1
cargo test --locked

# Independent readers of the exports (test-only tools: not in setup.sh): Debian's OpenVDB
# Python module, and Mitsuba 3 with numpy in a virtual environment inside the clone that sees
# the system's site packages (where pyopenvdb lives).
MITSUBA_VERSION=3.9.1
if ! /usr/bin/python3 -c 'import pyopenvdb' 2>/dev/null; then
  log "apt-get install python3-openvdb python3-venv"
  $( [ "$(id -u)" = 0 ] || echo sudo ) apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $( [ "$(id -u)" = 0 ] || echo sudo ) apt-get install -y -qq --no-install-recommends python3-openvdb python3-venv
fi
VENV="$ROOT/target/export-venv"
if ! "$VENV/bin/python" -c "import mitsuba, numpy, pyopenvdb; assert mitsuba.__version__ == '$MITSUBA_VERSION'" 2>/dev/null; then
  log "python venv with mitsuba $MITSUBA_VERSION and numpy (target/export-venv)"
  rm -rf "$VENV"
  /usr/bin/python3 -m venv --system-site-packages "$VENV"
  "$VENV/bin/pip" install -q "mitsuba==$MITSUBA_VERSION" numpy
fi
log "exports read by OpenVDB, Mitsuba and the glTF validator (files: target/export-check/)"
"$VENV/bin/python" scripts/check_exports.py target/export-check
(cd web && node check-glb.mjs ../target/export-check/cloud.glb)

# A frame range as a job array on a real scheduler (Debian's slurm-wlm, installed there when
# missing; a one-node cluster started and stopped inside the check), against one local run.
log "a frame range on a one-node Slurm cluster (scripts/check_slurm.sh, docs/farm.md)"
bash scripts/check_slurm.sh target/debug/cloudsketch

# The fuzz target needs nightly Rust and cargo-fuzz (test-only tools: not in setup.sh).
CARGO_FUZZ_VERSION=0.13.2
if ! rustup run nightly rustc --version >/dev/null 2>&1; then
  log "rustup toolchain install nightly (for cargo-fuzz)"
  rustup toolchain install nightly --profile minimal
fi
if ! cargo fuzz --version 2>/dev/null | grep -q "$CARGO_FUZZ_VERSION"; then
  log "cargo install cargo-fuzz $CARGO_FUZZ_VERSION"
  cargo install --locked cargo-fuzz --version "$CARGO_FUZZ_VERSION"
fi
log "fuzz the link decoders for 30 s (docs/scene-format.md)"
fuzzing="$(mktemp -d)"
mkdir "$fuzzing/corpus"
cp fuzz/corpus/link_decode/* "$fuzzing/corpus/"
if ! cargo +nightly fuzz run -O link_decode "$fuzzing/corpus" -- -max_total_time=30 \
    -rss_limit_mb=2048 -max_len=65536 >"$fuzzing/log" 2>&1; then
  tail -n 60 "$fuzzing/log"
  log "the fuzz run found a failing input (fuzz/artifacts/link_decode/)"
  exit 1
fi
grep -E 'Done [0-9]+ runs' "$fuzzing/log" || true
rm -rf "$fuzzing"

log "trunk build --release (wasm)"
trunk build --release

log "browser end-to-end tests (screenshots: web/test-results/screenshots/)"
rm -rf web/test-results
(cd web && npm test)
log "all tests passed"
