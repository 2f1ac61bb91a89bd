#!/bin/sh
# Installs the Debian packages rt builds against, when they are missing.
# Called by `make` (through the build/.deps stamp); safe to run by hand.
#   libstb-dev     stb_image / stb_image_write (PNG, JPEG, HDR in and out)
#   libjsmn-dev    the JSON tokenizer under src/gltf.c
#   libcmocka-dev  the test framework
#   libopenexr-dev the OpenEXR Core C API (EXR images in and out)
set -eu
CC=${CC:-cc}
missing=""
check() { # header package
    if ! printf '#include <%s>\n' "$1" | "$CC" -E -x c - >/dev/null 2>&1; then
        missing="$missing $2"
    fi
}
check stb/stb_image.h libstb-dev
check jsmn.h libjsmn-dev
check cmocka.h libcmocka-dev
check OpenEXR/openexr.h libopenexr-dev
[ -z "$missing" ] && exit 0

echo "rt: installing missing build packages:$missing" >&2
if [ "$(id -u)" -eq 0 ]; then
    SUDO=""
elif command -v sudo >/dev/null 2>&1; then
    SUDO="sudo"
    echo "rt: (using sudo for apt-get)" >&2
else
    echo "rt: error: need root or sudo to install:$missing" >&2
    echo "rt: install them yourself with: apt-get install$missing" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
# A fresh machine has no package lists yet; refresh them once if the install fails.
if ! $SUDO apt-get install -y -q $missing >&2; then
    $SUDO apt-get update -q >&2
    $SUDO apt-get install -y -q $missing >&2
fi
echo "rt: installed:$missing" >&2
