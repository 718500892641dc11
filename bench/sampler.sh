#!/bin/sh
# relMSE of samplers at equal spp (issue 10; default: independent and sobol).
# Usage: bench/sampler.sh [--downscale N] [--spp 4,16,64] [--seeds N] [--ref-spp N]
#                         [--threads N] [--samplers sobol,cmj,...] [--ref-cache DIR]
#                         [SCENE...]   (default scenes: Cornell box, DOF)
# Not run in CI; see crates/candela-bench/src/bin/sampler_relmse.rs for the metric.
set -e
cd "$(dirname "$0")/.."
case " $* " in
*.toml*|*.xml*) ;;
*) set -- "$@" scenes/cornell.toml scenes/dof.toml ;;
esac
exec cargo run --release -q -p candela-bench --bin sampler_relmse -- "$@"
