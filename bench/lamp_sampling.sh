#!/usr/bin/env bash
# Efficiency of drawing near lamps in solid angle (--lamp-sampling) against area sampling
# on scenes: see the docstring of bench/lamp_sampling.py. Arguments go to it (e.g.
# --seeds 8 --spp 64 scenes/plastics.toml).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
[[ -x "$here/.venv/bin/python" ]] || "$here/setup.sh"
exec "$here/.venv/bin/python" "$here/lamp_sampling.py" "$@"
