/* rt/io/nanovdb.h - a float density grid from a NanoVDB file (.nvdb), the
 * data of a heterogeneous medium (issue 28), read through the C header
 * PNanoVDB.h of Debian's libnanovdb-dev with every buffer read bounds
 * checked.
 *
 *   rt_density_grid grid;
 *   rt_mat4 index_to_world;
 *   if (rt_nanovdb_load("smoke.nvdb", "density", &grid, &index_to_world, &err) != RT_OK)
 *       ... err names the file and the byte or the field
 *   ... rt_volume_grid(..., &grid, &world_to_index) with the inverse
 *   rt_density_grid_free(&grid);
 *
 * What it reads: uncompressed files (codec NONE, what `nanovdb_convert`
 * writes without -z or -b) of NanoVDB's file format version 32 (OpenVDB 10),
 * one or more segments; the grid named `grid_name` (NULL: the first float
 * grid); grid type float (32-bit; the quantized FP4/8/16/N types are
 * refused by name); class fog volume or unknown (a level set is a distance,
 * not a density: refused). The active voxels' bounding box becomes a dense
 * rt_density_grid (zero where the file has no value), so the grid's
 * memory is 4 bytes a voxel of that box, capped by RT_DENSITY_MAX_VOXELS;
 * a file claiming more is refused before anything is allocated.
 * index_to_world maps the dense grid's index space (rt/scene/density_grid.h:
 * voxel centres at i + 0.5) to the world by the file's own map, so the
 * grid sits where the tool that wrote it put it.
 *
 * Errors: RT_ERR_IO (the file), RT_ERR_PARSE (bytes that are not a NanoVDB
 * file: the byte offset), RT_ERR_UNSUPPORTED (compressed, another version,
 * another grid type or class), RT_ERR_INVALID (no such grid, a tree that
 * does not fit its buffer, a NaN or negative density), RT_ERR_LIMIT (too
 * many voxels), RT_ERR_NOMEM.
 */
#ifndef RT_NANOVDB_H
#define RT_NANOVDB_H

#include <stddef.h>

#include "rt/base/error.h"
#include "rt/base/vec.h"
#include "rt/scene/density_grid.h"

rt_result rt_nanovdb_load(const char *path, const char *grid_name, rt_density_grid *grid, rt_mat4 *index_to_world,
                          rt_error *err);

/* The same from bytes in memory; `name` is what messages call them. */
rt_result rt_nanovdb_parse(const unsigned char *bytes, size_t size, const char *name, const char *grid_name,
                           rt_density_grid *grid, rt_mat4 *index_to_world, rt_error *err);

#endif
