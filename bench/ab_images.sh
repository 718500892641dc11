#!/usr/bin/env bash
# Byte-for-byte A/B of two candela binaries over every bundled scene: for a refactor that
# must not change behaviour, every image of NEW must equal OLD's.
#
# Usage: bench/ab_images.sh OLD_BIN NEW_BIN [OUT_DIR]
#
# Renders each scene under scenes/ (TOML, Mitsuba XML, glTF) and bench/scenes/ at 64x48,
# 4 spp, seed 0, 2 threads, to PFM; the light-heavy scenes again under the `power`, `bvh`
# and `ris` light samplers and solid-angle lamp sampling; the Cornell box under every MIS
# mode, sampler and ISA copy; a Gaussian-filtered scene under filter importance sampling
# (its default is splatting); and one render with AOV layers (EXR); the splat in the
# baseline copy, under a tent filter, at 40 spp (passes of two samples) and at 1400 spp
# (sums folded mid-render).
# Each pair is compared with `cmp`; where they differ, the maximum absolute and relative
# pixel difference is printed. Prints one line per case and a last line
# `ab_images: N cases, M differ`; exits 1 if any differ or fail.
set -uo pipefail
old=$1 new=$2
out=${3:-$(mktemp -d)}
mkdir -p "$out/old" "$out/new"
cd "$(dirname "$0")/.."

# The largest absolute and relative difference between two PFMs (relative to the larger
# magnitude of the pair, over pixels where it is not zero).
pfm_diff() {
    python3 - "$1" "$2" <<'PY'
import sys, array
def read(path):
    with open(path, "rb") as f:
        data = f.read()
    # Three header lines: "PF" (or "Pf"), "width height", scale (negative: little-endian).
    lines = data.split(b"\n", 3)
    fields = lines[0].split() + lines[1].split() + lines[2].split()
    pos = sum(len(l) + 1 for l in lines[:3])
    kind, w, h, scale = fields[0], int(fields[1]), int(fields[2]), float(fields[3])
    a = array.array("f")
    a.frombytes(data[pos:pos + 4 * w * h * (3 if kind == b"PF" else 1)])
    if scale > 0 and sys.byteorder == "little":
        a.byteswap()
    return a
a, b = read(sys.argv[1]), read(sys.argv[2])
if len(a) != len(b):
    print(f"sizes {len(a)} vs {len(b)}")
    sys.exit()
abs_d = max((abs(x - y) for x, y in zip(a, b)), default=0.0)
rel_d = max((abs(x - y) / max(abs(x), abs(y)) for x, y in zip(a, b) if max(abs(x), abs(y)) > 0), default=0.0)
print(f"max abs {abs_d:.6g}, max rel {rel_d:.6g}")
PY
}

cases=0 differ=0
run_case() {
    local name=$1 ext=$2 scene=$3
    shift 3
    local args=(render "$scene" --res 64x48 --spp "${SPP:-4}" --seed 0 --threads 2 "$@")
    cases=$((cases + 1))
    if ! "$old" "${args[@]}" -o "$out/old/$name.$ext" >/dev/null 2>"$out/old/$name.log"; then
        echo "FAIL old  $name ($(tail -1 "$out/old/$name.log"))"
        differ=$((differ + 1))
        return
    fi
    if ! "$new" "${args[@]}" -o "$out/new/$name.$ext" >/dev/null 2>"$out/new/$name.log"; then
        echo "FAIL new  $name ($(tail -1 "$out/new/$name.log"))"
        differ=$((differ + 1))
        return
    fi
    if cmp -s "$out/old/$name.$ext" "$out/new/$name.$ext"; then
        echo "same      $name"
    else
        differ=$((differ + 1))
        if [ "$ext" = pfm ]; then
            echo "DIFFERENT $name: $(pfm_diff "$out/old/$name.$ext" "$out/new/$name.$ext")"
        else
            echo "DIFFERENT $name"
        fi
    fi
}

light_heavy="many_lights ies-room textured-light many-lights spot-point-room near-lamp softbox"
for scene in scenes/*.toml scenes/*.xml scenes/gltf/*.gltf bench/scenes/*.xml bench/scenes/*.toml; do
    [ -e "$scene" ] || continue
    base=$(basename "${scene%.*}")
    [ "${scene#bench/}" != "$scene" ] && base="bench-$base"
    run_case "$base" pfm "$scene"
    for l in $light_heavy; do
        if [ "$base" = "$l" ] || [ "$base" = "bench-$l" ]; then
            for sampler in power bvh ris; do
                run_case "$base-$sampler" pfm "$scene" --light-sampler "$sampler"
            done
            run_case "$base-solid-angle" pfm "$scene" --lamp-sampling solid-angle
        fi
    done
done
for mis in balance power none bsdf; do
    run_case "cornell-mis-$mis" pfm scenes/cornell.toml --mis "$mis"
done
for sampler in independent sobol sobol-cmj; do
    run_case "cornell-sampler-$sampler" pfm scenes/cornell.toml --sampler "$sampler"
done
for isa in baseline auto; do
    run_case "cornell-isa-$isa" pfm scenes/cornell.toml --isa "$isa"
done
run_case "cornell-textured-importance" pfm bench/scenes/cornell-textured.xml --filter-sampling importance
run_case "cornell-aov" exr scenes/cornell.toml --aov albedo,normal,depth
# The splat beyond the bundled scenes' Gaussians in the v3 copy: the baseline copy, a tent
# filter (Mitsuba's default radius, 1 px) in both, and passes of more than one sample.
tent="$out/cornell-textured-tent.xml"
sed 's|<rfilter type="gaussian"/>|<rfilter type="tent"/>|' bench/scenes/cornell-textured.xml >"$tent"
run_case "thin-lens-isa-baseline" pfm bench/scenes/thin-lens.xml --isa baseline
run_case "cornell-textured-tent" pfm "$tent"
run_case "cornell-textured-tent-isa-baseline" pfm "$tent" --isa baseline
SPP=40 run_case "thin-lens-spp40" pfm bench/scenes/thin-lens.xml
SPP=40 run_case "cornell-textured-tent-spp40" pfm "$tent"
# Enough samples that the splat folds its pending sums mid-render (every 664 spp here).
SPP=1400 run_case "thin-lens-spp1400" pfm bench/scenes/thin-lens.xml
echo "ab_images: $cases cases, $differ differ (images in $out)"
[ "$differ" -eq 0 ]
