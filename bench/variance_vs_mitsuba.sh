#!/usr/bin/env bash
# Candela's per-pixel variance over seeds against Mitsuba 3's at equal spp, no reference
# needed: see the docstring of bench/variance_vs_mitsuba.py.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
[[ -x "$here/.venv/bin/python" ]] || "$here/setup.sh"
exec "$here/.venv/bin/python" "$here/variance_vs_mitsuba.py" "$@"
