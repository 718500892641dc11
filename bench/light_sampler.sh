#!/usr/bin/env bash
# Light samplers at equal spp: variance ratios with their noise, Welch tiles, CPU time and
# (--ipp) instructions per sample; see the docstring of bench/light_sampler.py.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
[[ -x "$here/.venv/bin/python" ]] || "$here/setup.sh"
exec "$here/.venv/bin/python" "$here/light_sampler.py" "$@"
