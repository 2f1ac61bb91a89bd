/* harness.h - the fuzz targets as plain functions, shared by the libFuzzer
 * binaries (make fuzz) and the corpus regression test (make test).
 *
 *   rt_fuzz_run("gltf", data, size);   // feeds one input to one target
 *
 * Targets: scene (scene text), gltf (a .gltf JSON alone), glb (a .glb
 * container), gltf_bin (a .gltf plus its .bin: u32 little-endian JSON
 * length, the JSON, then the buffer, which the JSON must name
 * "buffer.bin"), obj (u32 OBJ length, the OBJ, then an MTL named
 * "m.mtl"), ply, off, image (any image bytes through our size checks),
 * exr (OpenEXR bytes straight into rt_exr_decode, capped at 4096 a side),
 * meshopt (an EXT_meshopt_compression stream: mode, filter, stride and a
 * u16 count in the first five bytes), draco (a Draco mesh stream, its
 * indices and attributes read back) and part (u32 sidecar length, a
 * part's JSON sidecar, then its EXR image, read by rt_part_read; "@HASH@"
 * in the sidecar becomes the image's hash), image_file (any bytes as an
 * image file through rt_image_read, as rt compare and rt convert read it:
 * PFM besides what image reads), pose (an animation index byte, a signed
 * 16-bit frame time in 1/64 s, then a .glb or a gltf_bin input: loaded
 * posed at that time, so animation sampling, skins and morph targets run)
 * and json (a mode byte, a u16 N, then text for rt_json_parse: as it is,
 * wrapped in N arrays, or repeated N times in one array), nvdb (a NanoVDB
 * file's bytes: the density grid read, then walked by ratio tracking).
 * Every target but image, exr, meshopt, draco, part, image_file, json and nvdb loads through rt_load_memory, as `rt` loads a file
 * of that kind (fuzz.txt, fuzz.gltf, fuzz.obj, ...): the content picks the
 * reader before the name does.
 */
#ifndef RT_FUZZ_HARNESS_H
#define RT_FUZZ_HARNESS_H

#include <stddef.h>
#include <stdint.h>

/* Runs one input through a target; returns -1 for an unknown target, else 0
 * (bad input is expected: only crashes, leaks and hangs are bugs). */
int rt_fuzz_run(const char *target, const uint8_t *data, size_t size);

/* The target names, NULL-terminated. */
extern const char *const rt_fuzz_targets[];

#endif
