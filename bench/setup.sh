#!/usr/bin/env bash
# Sets up everything the benchmarks need beyond the Rust toolchain:
#   * bench/.venv (git-ignored) with mitsuba, drjit and numpy (Mitsuba's own mi.Bitmap
#     reads and writes EXR, so no separate OpenEXR binding is needed), and embreex
#     (Embree 4) for bench/traversal.sh;
#   * Debian's LLVM shared library for Mitsuba's `llvm_ad_rgb` variant (Dr.Jit loads it at
#     run time through DRJIT_LIBLLVM_PATH). `scalar_rgb` needs nothing.
# Idempotent: every step checks whether its result is already there. Safe to re-run.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="$here/.venv"
# Pinned so that timings in RESULTS.md stay comparable between runs.
MITSUBA_VERSION="${MITSUBA_VERSION:-3.9.1}"

log() { printf '[setup] %s\n' "$*"; }

# --- Python venv with Mitsuba -------------------------------------------------------
python="${PYTHON:-}"
if [[ -z "$python" ]]; then
    for candidate in python3.12 python3.11 python3; do
        # `command -v` is not enough: pyenv shims exist for versions that are not active.
        if "$candidate" -c 'import venv' >/dev/null 2>&1; then python="$candidate"; break; fi
    done
fi
if [[ ! -x "$venv/bin/python" ]]; then
    log "creating $venv with $python ($("$python" --version 2>&1))"
    "$python" -m venv "$venv"
fi
if ! "$venv/bin/python" -c "import mitsuba, numpy; assert mitsuba.__version__ == '$MITSUBA_VERSION'" 2>/dev/null; then
    log "installing mitsuba==$MITSUBA_VERSION and numpy into $venv"
    "$venv/bin/python" -m pip install --quiet --upgrade pip
    "$venv/bin/python" -m pip install --quiet "mitsuba==$MITSUBA_VERSION" numpy
else
    log "mitsuba $MITSUBA_VERSION and numpy already in $venv"
fi

# --- Embree 4 for bench/traversal.sh ----------------------------------------------
# embreex ships Embree 4 inside its wheel, so nothing else is needed.
if ! "$venv/bin/python" -c "import embreex" 2>/dev/null; then
    log "installing embreex into $venv"
    "$venv/bin/python" -m pip install --quiet embreex
else
    log "embreex already in $venv"
fi

# --- LLVM for llvm_ad_rgb -----------------------------------------------------------
# Prefer libllvm19 (what the issue names); fall back to the newest libLLVM Debian offers
# on this release, since Dr.Jit works with any LLVM >= 11.
find_libllvm() {
    local f
    for f in /usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 /usr/lib/x86_64-linux-gnu/libLLVM-19.so.1; do
        [[ -e "$f" ]] && { echo "$f"; return 0; }
    done
    # Newest of whatever else is installed.
    ls -1 /usr/lib/x86_64-linux-gnu/libLLVM*.so* 2>/dev/null | sort -V | tail -n 1
}
if [[ -z "$(find_libllvm)" || ! -e /usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 ]]; then
    if command -v apt-get >/dev/null 2>&1 && [[ $(id -u) -eq 0 ]]; then
        log "looking for libllvm19 with apt-get"
        apt-get update -qq || true
        if apt-cache show libllvm19 >/dev/null 2>&1; then
            DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libllvm19
        else
            newest="$(apt-cache search --names-only '^libllvm[0-9]+$' | awk '{print $1}' | sort -V | tail -n 1)"
            if [[ -n "$newest" ]] && ! dpkg -s "$newest" >/dev/null 2>&1; then
                log "libllvm19 not in this Debian release; installing $newest instead"
                DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$newest"
            fi
        fi
    else
        log "not root or no apt-get: install libllvm19 yourself for llvm_ad_rgb"
    fi
fi
libllvm="$(find_libllvm)"
if [[ -n "$libllvm" ]]; then
    echo "$libllvm" > "$venv/libllvm_path"
    log "llvm_ad_rgb will use DRJIT_LIBLLVM_PATH=$libllvm"
else
    rm -f "$venv/libllvm_path"
    log "no libLLVM found: llvm_ad_rgb will be skipped"
fi

# --- Smoke test ---------------------------------------------------------------------
DRJIT_LIBLLVM_PATH="${libllvm:-}" "$venv/bin/python" - <<'PY'
import mitsuba as mi
print("[setup] mitsuba", mi.__version__, "variants:", ", ".join(mi.variants()))
mi.set_variant("scalar_rgb")
try:
    mi.set_variant("llvm_ad_rgb")
    print("[setup] llvm_ad_rgb OK")
except Exception as e:  # reported, not fatal: scalar_rgb still works
    print("[setup] llvm_ad_rgb unavailable:", e)
PY
log "done"
