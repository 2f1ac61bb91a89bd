#!/bin/sh
# make test-install: installs rt into a temporary DESTDIR and builds
# examples/library.c against the installed headers and library through
# pkg-config, as a user of the library would; then renders the built-in
# scene and a mesh with it. Cleans up after itself, pass or fail.
set -eu
CC=${CC:-cc}
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT INT TERM
prefix=/opt/rt-test
make --no-print-directory install DESTDIR="$stage" PREFIX="$prefix" >/dev/null
for f in bin/rt lib/librtrender.a lib/pkgconfig/rtrender.pc include/rt/io/load.h include/rt/base/error.h; do
    [ -f "$stage$prefix/$f" ] || { echo "test-install: $prefix/$f was not installed" >&2; exit 1; }
done
export PKG_CONFIG_SYSROOT_DIR="$stage" PKG_CONFIG_PATH="$stage$prefix/lib/pkgconfig"
flags=$(pkg-config --cflags --libs rtrender)
# shellcheck disable=SC2086 # the flags are words
"$CC" -std=c11 -Wall -Wextra -Wpedantic -Werror -o "$stage/render" examples/library.c $flags
(cd "$stage" && ./render >/dev/null) || { echo "test-install: the example failed on the built-in scene" >&2; exit 1; }
[ -s "$stage/out.png" ] || { echo "test-install: the example wrote no image" >&2; exit 1; }
"$stage/render" assets/torus.obj "$stage/torus.pfm" >/dev/null || { echo "test-install: the example failed on assets/torus.obj" >&2; exit 1; }
[ -s "$stage/torus.pfm" ] || { echo "test-install: no torus.pfm" >&2; exit 1; }
"$stage$prefix/bin/rt" --version >/dev/null
echo "test-install: 1 passed, 0 failed"
