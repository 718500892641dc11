#!/usr/bin/env bash
# Efficiency of Russian roulette's start (--rr-depth) on the example scenes: see the
# docstring of bench/rr_depth.py. Arguments go to it (e.g. --rr 3,4,5,6 --seeds 8).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
[[ -x "$here/.venv/bin/python" ]] || "$here/setup.sh"
exec "$here/.venv/bin/python" "$here/rr_depth.py" "$@"
