#!/usr/bin/env bash
# Sets up whatever is missing (scripts/setup.sh) and runs every test: Rust unit and
# integration tests (pure core, naga validation of shaders/, offscreen lavapipe renders, CLI),
# the release web build, and the browser end-to-end tests in headless Chromium (WebGPU on
# SwiftShader, then the WebGL2 fallback). Screenshots: web/test-results/screenshots/.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
log() { printf '\033[1;34m[test]\033[0m %s\n' "$*" >&2; }

bash scripts/setup.sh

log "cargo test (native)"
# Offscreen tests pick their adapter themselves: Mesa's device-select layer would only look for
# a display (and print XDG_RUNTIME_DIR errors on a headless machine). The CLI does the same.
export NODEVICE_SELECT=1
cargo test --locked

log "trunk build --release (wasm)"
trunk build --release

log "browser end-to-end tests (screenshots: web/test-results/screenshots/)"
rm -rf web/test-results
(cd web && npm test)
log "all tests passed"
