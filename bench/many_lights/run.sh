#!/usr/bin/env bash
# Many-lights benchmark: build cost for 10⁶ emissive triangles, then equal-time renders
# of two scenes with every light sampler and relMSE against a long reference.
# Usage: bench/many_lights/run.sh [SECONDS_PER_RENDER]   (default 3; not part of CI)
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo run --release -p candela-bench --bin many_lights -- "${1:-3}"
