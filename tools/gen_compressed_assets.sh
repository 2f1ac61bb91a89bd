#!/bin/sh
# Regenerates the compressed glTF test files in tests/corpus/glb/ from the
# shared sample models, with the standard tools rather than by hand:
#   gltfpack (Debian package gltfpack, meshoptimizer 0.18): EXT_meshopt_compression,
#     with -c (lossless vertex codec, KHR_mesh_quantization off with -noq)
#     and -cc (quantized: KHR_mesh_quantization + filters)
#   gltf-transform (npm @gltf-transform/cli, installed into build/node):
#     draco (KHR_draco_mesh_compression), meshopt, webp (EXT_texture_webp)
# tests/test_gltf_compressed.c checks that each decodes to the triangle
# count and bounds of its original (within the quantization step).
# Usage: sh tools/gen_compressed_assets.sh [SHARED]   (default ../shared)
set -eu
SHARED=${1:-../shared}
S=$SHARED/assets/gltf
OUT=tests/corpus/glb
NODE=build/node
GT_VERSION=4.5.1

[ -d "$S" ] || { echo "gen_compressed_assets: $S not found (pass the shared folder)" >&2; exit 2; }
if ! command -v gltfpack >/dev/null 2>&1; then
    echo "gen_compressed_assets: installing gltfpack (Debian package)" >&2
    SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO=sudo
    $SUDO apt-get install -y -q -o DPkg::Lock::Timeout=300 gltfpack >&2
fi
GT=$NODE/node_modules/.bin/gltf-transform
if [ ! -x "$GT" ]; then
    echo "gen_compressed_assets: installing @gltf-transform/cli@$GT_VERSION into $NODE" >&2
    mkdir -p $NODE
    npm install --prefix $NODE --silent --no-audit --no-fund "@gltf-transform/cli@$GT_VERSION" >&2
fi

mkdir -p $OUT
gltfpack -i "$S/Duck/glTF-Binary/Duck.glb" -o $OUT/compressed-duck-gltfpack-cc.glb -cc >/dev/null
gltfpack -i "$S/BoxTextured/glTF-Binary/BoxTextured.glb" -o $OUT/compressed-boxtextured-gltfpack-c-noq.glb -c -noq >/dev/null
"$GT" draco "$S/Duck/glTF-Binary/Duck.glb" $OUT/compressed-duck-draco.glb >/dev/null
"$GT" draco "$S/BoxVertexColors/glTF-Binary/BoxVertexColors.glb" $OUT/compressed-boxvertexcolors-draco.glb >/dev/null
"$GT" draco "$S/BoxTextured/glTF-Binary/BoxTextured.glb" $OUT/compressed-boxtextured-draco.glb >/dev/null
"$GT" meshopt "$S/BoxTextured/glTF-Binary/BoxTextured.glb" $OUT/compressed-boxtextured-meshopt.glb >/dev/null
"$GT" webp "$S/BoxTextured/glTF-Binary/BoxTextured.glb" $OUT/compressed-boxtextured-webp.glb >/dev/null
ls -l $OUT/compressed-*.glb
