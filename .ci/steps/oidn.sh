#!/usr/bin/env bash
# The tests that need Intel Open Image Denoise 2.x (`--denoise`): installs the `pyoidn`
# wheel from PyPI (libOpenImageDenoise.so.2 with its CPU device) into $CARGO_TARGET_DIR/oidn-venv,
# points OIDN_DIR at its library and runs the denoising tests, failing if they skipped.
# Idempotent (the venv is kept); a few minutes on 2 cores, most of it the 88 MB download
# and one 64² Cornell reference at 1024 spp.
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=${CARGO_TARGET_DIR:-target}/oidn-venv
if ! "$venv/bin/python" -c 'import importlib.util as u; assert u.find_spec("pyoidn")' 2>/dev/null; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet --no-deps pyoidn
fi
pkg="$("$venv/bin/python" -c 'import importlib.util as u; print(u.find_spec("pyoidn").submodule_search_locations[0])')"
export OIDN_DIR="$pkg/oidn"
echo "OIDN_DIR=$OIDN_DIR"
log=$(mktemp)
trap 'rm -f "$log"' EXIT
cargo test --release -p candela-denoise
cargo test --release -p candela-cli --test cli_denoise -- --include-ignored --nocapture 2>&1 | tee "$log"
if grep -q "skipped: Open Image Denoise" "$log"; then
    echo "error: the denoising test skipped although OIDN_DIR=$OIDN_DIR" >&2
    exit 1
fi
