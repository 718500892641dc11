#!/usr/bin/env bash
# Cornell box benchmark, Candela vs Mitsuba 3: see bench/README.md. Arguments go to
# bench/cornell.py (e.g. --repeats 5, --variants scalar_rgb, --skip-build).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
[[ -x "$here/.venv/bin/python" ]] || "$here/setup.sh"
exec "$here/.venv/bin/python" "$here/cornell.py" "$@"
