#!/usr/bin/env bash
# Two candela binaries render the same expected image (per-tile Welch): see
# bench/welch_ab.py. E.g.
#   bench/welch_ab.sh --a /work/bin/candela-main --b target/release/candela --scene scenes/environment.toml
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
[[ -x "$here/.venv/bin/python" ]] || "$here/setup.sh"
exec "$here/.venv/bin/python" "$here/welch_ab.py" "$@"
