#!/bin/sh
# Renders every shipped scene, the built-in scene, each integrator on the
# Cornell box, and a few models (shared assets when present) at a low
# resolution and prints one "sha256  name" line per image. Run it before and
# after a restructuring and diff the two outputs: a pure refactor changes no
# byte of any image.
#
#   sh tools/image-hashes.sh [RT] > before.txt   (RT defaults to ./rt)
# Environment: SHARED (default ../shared), RES (default 64x48), SPP (default 4).
set -u
rt=${1:-./rt}
shared=${SHARED:-../shared}
res=${RES:-64x48}
spp=${SPP:-4}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
render() { # name, args...
    name=$1; shift
    if "$rt" -q -t 2 -r "$res" -s "$spp" -o "$out/$name.pfm" "$@" >/dev/null 2>&1; then
        (cd "$out" && sha256sum "$name.pfm")
    else
        echo "FAILED  $name.pfm"
    fi
}
render builtin
for s in scenes/*.txt; do
    render "$(basename "$s" .txt)" "$s"
done
for i in direct whitted path; do
    render "cornell-$i" --integrator "$i" scenes/cornell.txt
done
for m in assets/*.obj assets/*.gltf; do
    render "asset-$(basename "$m")" "$m"
    render "asset-path-$(basename "$m")" --integrator path "$m"
done
for m in "$shared"/assets/gltf/DamagedHelmet/glTF-Binary/DamagedHelmet.glb "$shared"/assets/meshes/stanford-bunny/stanford-bunny.obj "$shared"/assets/meshes/igea/igea.ply "$shared"/assets/gltf/MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb "$shared"/assets/gltf/AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb "$shared"/assets/gltf/TransmissionTest/glTF-Binary/TransmissionTest.glb; do
    [ -f "$m" ] || continue
    render "shared-$(basename "$m")" "$m"
    render "shared-path-$(basename "$m")" --integrator path "$m"
done
