#!/bin/sh
# Installs the Debian packages rt builds against, when they are missing.
# Called by `make` (through the build/.deps stamp); safe to run by hand.
#   libstb-dev     stb_image / stb_image_write (PNG, JPEG, HDR in and out)
#   libjsmn-dev    the JSON tokenizer under src/io/json.c (glTF, part sidecars)
#   libcmocka-dev  the test framework
#   libopenexr-dev the OpenEXR Core C API (EXR images in and out)
#   libmeshoptimizer-dev, libdraco-dev, libwebp-dev
#                  compressed glTF: EXT_meshopt_compression,
#                  KHR_draco_mesh_compression (C++; g++ builds src/io/draco.cc),
#                  EXT_texture_webp
#   libnanovdb-dev PNanoVDB.h, the C header rt reads NanoVDB density grids with
# and, optionally (rt builds and runs without them; a failed install is only
# reported): libsdl2-dev for --window, xvfb and xdotool for the tests that
# open it and move its camera with real X input, strace for the test that
# the image writer renames right after it links (test_cli), python3-openvdb
# and libnanovdb-tools for the tests that write NanoVDB grids with
# OpenVDB's own tools (test_nanovdb, make fuzz's seeds).
#
# With arguments PACKAGE:COMMAND or PACKAGE ..., it installs instead just
# the packages whose COMMAND is not on the PATH (or in /usr/sbin), or which
# dpkg does not list as installed, for the launcher tests:
#   sh tools/install-deps.sh slurm-wlm:slurmctld   (make test-slurm)
#   sh tools/install-deps.sh parallel rsync:rsync  (make test-parallel)
#   sh tools/install-deps.sh python3-yaml          (make test-kubernetes)
set -eu
CC=${CC:-cc}
CXX=${CXX:-c++}

# apt-get install PACKAGE..., as root or through sudo; refreshes the package
# lists once if the install fails (a fresh machine has none yet).
apt_install() {
    if [ "$(id -u)" -eq 0 ]; then
        SUDO=""
    elif command -v sudo >/dev/null 2>&1; then
        SUDO="sudo"
        echo "rt: (using sudo for apt-get)" >&2
    else
        echo "rt: error: need root or sudo to install:$*" >&2
        echo "rt: install them yourself with: apt-get install $*" >&2
        exit 1
    fi
    export DEBIAN_FRONTEND=noninteractive
    # (DPkg::Lock::Timeout: waiting up to 5 minutes for another apt-get or dpkg)
    if ! $SUDO apt-get install -o DPkg::Lock::Timeout=300 -y -q "$@" >&2; then
        $SUDO apt-get update -o DPkg::Lock::Timeout=300 -q >&2
        $SUDO apt-get install -o DPkg::Lock::Timeout=300 -y -q "$@" >&2
    fi
}

if [ $# -gt 0 ]; then
    tools=""
    for a in "$@"; do
        case " $tools " in *" ${a%%:*} "*) continue ;; esac
        case $a in
            *:*) command -v "${a#*:}" >/dev/null 2>&1 || [ -x "/usr/sbin/${a#*:}" ] || tools="$tools ${a%%:*}" ;;
            *) dpkg-query -W -f '${Status}' "$a" 2>/dev/null | grep -q 'ok installed' || tools="$tools $a" ;;
        esac
    done
    [ -n "$tools" ] || exit 0
    echo "rt: installing missing packages:$tools" >&2
    # shellcheck disable=SC2086 # the package names are words
    apt_install $tools
    echo "rt: installed:$tools" >&2
    exit 0
fi
missing=""
check() { # header package [language]
    if ! printf '#include <%s>\n' "$1" | "${4:-$CC}" -E -x "${3:-c}" - >/dev/null 2>&1; then
        missing="$missing $2"
    fi
}
check stb/stb_image.h libstb-dev
check jsmn.h libjsmn-dev
check cmocka.h libcmocka-dev
check OpenEXR/openexr.h libopenexr-dev
check meshoptimizer.h libmeshoptimizer-dev
check webp/decode.h libwebp-dev
command -v "$CXX" >/dev/null 2>&1 || missing="$missing g++"
check draco/compression/decode.h libdraco-dev c++ "$CXX"
check nanovdb/PNanoVDB.h libnanovdb-dev

install_optional() {
    optional=""
    pkg-config --exists sdl2 2>/dev/null || optional="$optional libsdl2-dev"
    [ -x /usr/bin/Xvfb ] || optional="$optional xvfb"
    command -v xdotool >/dev/null 2>&1 || optional="$optional xdotool"
    [ -x /usr/bin/strace ] || optional="$optional strace" # test_write_renames_right_after_link
    command -v nanovdb_convert >/dev/null 2>&1 || optional="$optional libnanovdb-tools" # test_nanovdb
    /usr/bin/python3 -c 'import pyopenvdb' >/dev/null 2>&1 || optional="$optional python3-openvdb"
    [ -n "$optional" ] || return 0
    if [ "$(id -u)" -eq 0 ]; then
        S=""
    elif sudo -n true 2>/dev/null; then
        S="sudo -n"
    else
        echo "rt: optional packages not installed:$optional (for --window and its tests, strace for a test of the image writer, OpenVDB's tools for the NanoVDB tests)" >&2
        return 0
    fi
    echo "rt: installing optional packages:$optional" >&2
    DEBIAN_FRONTEND=noninteractive $S apt-get install -y -q $optional >&2 ||
        echo "rt: could not install$optional; rt builds and tests without them (--window needs libsdl2-dev)" >&2
}

if [ -z "$missing" ]; then
    install_optional
    exit 0
fi

echo "rt: installing missing build packages:$missing" >&2
# shellcheck disable=SC2086 # the package names are words
apt_install $missing
echo "rt: installed:$missing" >&2
install_optional
