#!/usr/bin/env bash
# Denoising benchmark (bench/denoise.py): Open Image Denoise on 16 spp against raw 16 and
# 256 spp, each against a 4096-spp reference. Makes target/oidn-venv (pyoidn, numpy,
# flip-evaluator from PyPI) on first use; arguments go to bench/denoise.py.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(dirname "$here")"
venv="$repo/target/oidn-venv"
if ! "$venv/bin/python" -c 'import pyoidn, numpy, flip_evaluator' 2>/dev/null; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet pyoidn numpy flip-evaluator
fi
lib="$("$venv/bin/python" -c 'import importlib.util as u; print(u.find_spec("pyoidn").submodule_search_locations[0])')/oidn"
export OIDN_DIR="$lib"
[[ -x "$repo/target/release/candela" ]] || cargo build --release -p candela-cli --manifest-path "$repo/Cargo.toml"
exec "$venv/bin/python" "$here/denoise.py" "$@"
