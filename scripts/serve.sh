#!/usr/bin/env bash
# Sets up whatever is missing (scripts/setup.sh), builds the web app and serves it at
# http://127.0.0.1:8080 (rebuilding on changes).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
bash scripts/setup.sh
# Trunk's server sends files uncompressed: no precompressed copies on each rebuild.
CLOUDSKETCH_PRECOMPRESS=0 exec trunk serve --release --address 127.0.0.1 --port 8080
