#!/usr/bin/env bash
# CI step: the Python package. Builds it with maturin (pip install of the crate, with
# CARGO_TARGET_DIR shared with the cargo suite so the Rust dependencies are not rebuilt)
# into a virtual environment under the target folder, with NumPy, pytest, Ray and pyoidn
# (Open Image Denoise, for `candela.denoise`), and runs its pytest suite (the Ray and
# denoising tests included) against the CLI the suite built. CANDELA_REQUIRE_OIDN=1 makes
# the denoising tests fail rather than skip if the library does not load.
# Idempotent: the environment is reused and pip skips what it already has.
set -euo pipefail
cd "$(dirname "$0")/../.."
repo=$(pwd)
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$repo/target}
venv=$CARGO_TARGET_DIR/ci-python-venv
start=$(date +%s)
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/pip" install --quiet --upgrade pip
"$venv/bin/pip" install --quiet "./crates/candela-py[ray,test,denoise]"
cargo build --release --quiet -p candela-cli
# OIDN_DIR unset: the package must find the venv's own pyoidn.
env -u OIDN_DIR CANDELA_REQUIRE_OIDN=1 CANDELA_BIN=$CARGO_TARGET_DIR/release/candela \
    "$venv/bin/python" -m pytest -q -rs crates/candela-py/tests
echo "python step: $(( $(date +%s) - start )) s"
