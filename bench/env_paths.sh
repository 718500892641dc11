#!/usr/bin/env bash
# Where Candela's error against Mitsuba 3 lies on the sky scenes: see bench/env_paths.py.
#   bench/env_paths.sh --scene bench/scenes/hdr-sky-sun.xml --max-depth 2 8 --candela default=
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
[[ -x "$here/.venv/bin/python" ]] || "$here/setup.sh"
exec "$here/.venv/bin/python" "$here/env_paths.py" "$@"
