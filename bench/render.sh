#!/bin/sh
# make bench-render: rt against Mitsuba 3 on the shared Cornell box (bench/render.py).
#   sh bench/render.sh [RT_BINARY ...]     default ./rt; several binaries compare rt builds too
# First use sets up Mitsuba, saying so:
#   - build/mitsuba-venv, a project-local virtual environment with the pinned
#     PyPI wheels mitsuba==3.9.1 and drjit==1.5.0 (numpy for mi.Bitmap);
#   - Debian's libllvm19 (apt-get, through sudo when not root) when
#     libLLVM-19.so is missing: Dr.Jit's llvm_* variants JIT-compile with it,
#     and DRJIT_LIBLLVM_PATH points them at it.
# Environment: see bench/render.py (SPP, THREADS, RES, VARIANTS, SCALAR_SPP, SHARED).
set -eu
VENV=${MITSUBA_VENV:-build/mitsuba-venv}
MITSUBA_PIN="mitsuba==3.9.1 drjit==1.5.0 numpy"
LLVM_SO=/usr/lib/x86_64-linux-gnu/libLLVM-19.so

if [ ! -f "$VENV/.installed" ]; then
    echo "bench-render: installing Mitsuba 3 ($MITSUBA_PIN) into $VENV" >&2
    python3 -m venv "$VENV"
    "$VENV/bin/pip" install -q $MITSUBA_PIN
    touch "$VENV/.installed"
fi

if [ ! -e "$LLVM_SO" ]; then
    echo "bench-render: installing libllvm19 (Debian) for Mitsuba's llvm_ad_rgb variant" >&2
    if [ "$(id -u)" -eq 0 ]; then S=""; else S="sudo"; fi
    export DEBIAN_FRONTEND=noninteractive
    $S apt-get install -y -q libllvm19 >&2 || { $S apt-get update -q >&2 && $S apt-get install -y -q libllvm19 >&2; }
fi
if [ ! -e "$LLVM_SO" ]; then
    echo "bench-render: no $LLVM_SO after installing libllvm19" >&2
    exit 2
fi
export DRJIT_LIBLLVM_PATH="$LLVM_SO"
MITSUBA_PYTHON="$VENV/bin/python" exec python3 "$(dirname "$0")/render.py" "$@"
