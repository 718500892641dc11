#!/usr/bin/env bash
# Candela against Mitsuba 3 llvm_ad_rgb at equal spp over several seeds: see
# bench/equal_spp.py. Arguments go to it, e.g.
#   bench/equal_spp.sh --candela splat="--filter-sampling splat" --candela importance="--filter-sampling importance"
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
[[ -x "$here/.venv/bin/python" ]] || "$here/setup.sh"
exec "$here/.venv/bin/python" "$here/equal_spp.py" "$@"
