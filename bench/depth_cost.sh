#!/usr/bin/env bash
# Time per sample against Mitsuba 3 llvm_ad_rgb, max_depth by max_depth: see
# bench/depth_cost.py. Arguments go to it, e.g.
#   bench/depth_cost.sh --scenes bench/scenes/spot-point-room.xml --depths 1 2 3 5 8
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
[[ -x "$here/.venv/bin/python" ]] || "$here/setup.sh"
exec "$here/.venv/bin/python" "$here/depth_cost.py" "$@"
