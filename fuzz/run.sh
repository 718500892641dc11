#!/usr/bin/env bash
# Builds and runs one fuzz target with its seed corpus:
#
#   fuzz/run.sh TARGET 300s      # for 300 seconds
#   fuzz/run.sh TARGET 1000000   # for 10^6 executions (at most MAX_SECONDS, default 480)
#
# Targets are the files in fuzz/fuzz_targets/. Seeds are copied at run time from
# ../shared/data, scenes/ and bench/scenes/ into fuzz/corpus/TARGET (ignored by git);
# crashes, hangs and out-of-memory inputs land in fuzz/artifacts/TARGET/. One job, one
# process: the machine is shared. Extra arguments after the second go to libFuzzer.
set -euo pipefail

usage() { echo "usage: fuzz/run.sh TARGET SECONDS's'|EXECS [libFuzzer args...]" >&2; exit 2; }
[[ $# -ge 2 ]] || usage
target=$1 amount=$2
shift 2
here=$(cd "$(dirname "$0")" && pwd)
repo=$(dirname "$here")
shared=${CANDELA_SHARED_DATA:-$repo/../shared/data}
[[ -f $here/fuzz_targets/$target.rs ]] || { echo "no target $target in fuzz/fuzz_targets" >&2; exit 2; }

# Seeds: the project's own files and the shared real data of the target's kind. A
# target's `seeds_NAME` function prints the files, one a line; the image target's seeds
# are prefixed by the byte that picks their decoder (see fuzz_targets/image.rs).
files() { for pattern in "$@"; do find "$repo/scenes" "$repo/bench/scenes" "$shared" -type f -name "$pattern" 2>/dev/null; done; }
seeds_toml() { files '*.toml'; }
seeds_obj() { files '*.obj'; }
seeds_ply() { files '*.ply'; }
seeds_ies() { files '*.ies'; }
seeds_mitsuba() { files '*.xml'; }
seeds_exr() { files '*.exr'; }
seeds_gltf() { files '*.gltf' '*.glb'; }
seeds_vol() { files '*.vol'; }
seeds_image() { :; }

corpus=$here/corpus/$target
artifacts=$here/artifacts/$target
mkdir -p "$corpus" "$artifacts"
if declare -f "seeds_$target" >/dev/null; then
  # Named with their folder too: the shared scenes are all called scene.xml.
  "seeds_$target" | while read -r f; do cp "$f" "$corpus/seed-$(basename "$(dirname "$f")")-$(basename "$f")"; done
fi
# The scene targets read their input as a file in scenes/ (see src/lib.rs): the
# benchmark scenes' paths into it (../../scenes/media/smoke.vol) are made relative to it.
case $target in
  toml|mitsuba) sed -i 's|\.\./\.\./scenes/||g' "$corpus"/seed-* ;;
esac
# Small hand-made seeds for formats the shared data lacks (binary and ascii PLY,
# TGA, BMP, HDR).
case $target in
  ply)
    printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n0 1 0 0 0 1 0 1\n3 0 1 2\n' >"$corpus/seed-ascii.ply"
    { printf 'ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n'
      printf '\0\0\0\0\0\0\0\0\0\0\0\0\0\0\x80\x3f\0\0\0\0\0\0\0\0\0\0\0\0\0\0\x80\x3f\0\0\0\0'
      printf '\x03\0\0\0\0\x01\0\0\0\x02\0\0\0'; } >"$corpus/seed-binary.ply" ;;
  image)
    # PNG (0), JPEG (1), TGA (2), BMP (3), HDR (4).
    for f in "$repo"/docs/gallery/*.png; do { printf '\x00'; cat "$f"; } >"$corpus/seed-$(basename "$f")"; done
    files '*.jpg' '*.jpeg' | while read -r f; do { printf '\x01'; cat "$f"; } >"$corpus/seed-$(basename "$f")"; done
    printf '\x02\0\0\x02\0\0\0\0\0\0\0\0\0\x02\0\x02\0\x18\x20\xff\0\0\0\xff\0\0\0\xff\xff\xff\xff' >"$corpus/seed-2x2.tga"
    { printf '\x03BM\x46\0\0\0\0\0\0\0\x36\0\0\0\x28\0\0\0\x02\0\0\0\x02\0\0\0\x01\0\x18\0\0\0\0\0\x10\0\0\0'
      printf '\x13\x0b\0\0\x13\x0b\0\0\0\0\0\0\0\0\0\0\xff\0\0\0\xff\0\0\0\0\0\xff\0\xff\xff\0\0'; } >"$corpus/seed-2x2.bmp"
    { printf '\x04#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n'; printf '\x80\x80\x80\x81\x40\x40\x40\x82\x10\x20\x30\x80\xff\xff\xff\x7f'; } >"$corpus/seed-2x2.hdr"
    files '*.hdr' | while read -r f; do { printf '\x04'; head -c 65536 "$f"; } >"$corpus/seed-$(basename "$f")"; done ;;
esac

if [[ $amount == *s ]]; then
  limits=(-max_total_time="${amount%s}")
else
  limits=(-runs="$amount" -max_total_time="${MAX_SECONDS:-480}")
fi

host=$(rustc -vV | sed -n 's/^host: //p')
# Coverage instrumentation that works on stable: the SanitizerCoverage pass with the
# options cargo-fuzz uses, without a sanitizer (those need nightly's -Z sanitizer).
export RUSTFLAGS="--cfg fuzzing -Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=4 \
-Cllvm-args=-sanitizer-coverage-inline-8bit-counters -Cllvm-args=-sanitizer-coverage-pc-table \
-Cllvm-args=-sanitizer-coverage-trace-compares"
cargo build --release --manifest-path "$here/Cargo.toml" --target-dir "$here/target" \
  --target "$host" --bin "$target"

# -timeout: an input taking over 10 s is a hang; -rss_limit_mb: resident memory past 2 GiB
# is an out-of-memory (the budgeted allocator in src/lib.rs catches reservations sooner).
exec "$here/target/$host/release/$target" "$corpus" -artifact_prefix="$artifacts/" \
  -max_len="${MAX_LEN:-65536}" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
  "${limits[@]}" "$@"
