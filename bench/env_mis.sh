#!/bin/sh
# Environment-light sampling strategies at equal spp against a long reference (issue 12).
# Usage: bench/env_mis.sh [spp (default 16)] [reference spp (default 1024)]
# Not run in CI; see crates/candela-bench/src/bin/env_mis.rs for the scene and the metric.
set -e
cd "$(dirname "$0")/.."
exec cargo run --release -q -p candela-bench --bin env_mis -- "$@"
