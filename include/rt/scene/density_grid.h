/* rt/scene/density_grid.h - a density field on a regular voxel lattice, the
 * data of a heterogeneous participating medium, with the coarse grid of
 * maxima that lets free-flight sampling take long steps through empty and
 * thin space (pbrt-v4's MajorantGrid; Novak et al., "Monte Carlo methods
 * for volumetric light transport simulation", Eurographics STAR 2018).
 *
 *   rt_density_grid g;
 *   if (rt_density_grid_init(&g, nx, ny, nz, err) != RT_OK) ...   // all zero
 *   g.density[rt_density_grid_index(&g, x, y, z)] = value;         // fill
 *   if (rt_density_grid_finish(&g, "smoke.nvdb", err) != RT_OK) ... // checks, maxima
 *   float d = rt_density_grid_lookup(&g, p);   // p in index space
 *   rt_density_grid_free(&g);
 *
 * Index space: voxel (x, y, z) is the unit cube [x, x+1) x [y, y+1) x
 * [z, z+1), and its value sits at its centre; a lookup interpolates the
 * eight nearest centres trilinearly, voxels outside the lattice counting
 * as 0 (the background of a VDB density grid). So the field is continuous
 * and zero outside [-0.5, n + 0.5) on each axis; the lattice's box for
 * ray clipping is rt_density_grid_bounds. Placing the lattice in the
 * world (a file's index-to-world map, a medium's transform) is the
 * medium's job (rt/render/volume.h).
 *
 * The maxima: blocks of RT_DENSITY_BLOCK^3 voxels, each holding the largest
 * value any lookup inside the block can return (its voxels and the ring of
 * neighbours trilinear filtering reaches into), so a majorant from them
 * bounds the field everywhere inside the block.
 */
#ifndef RT_DENSITY_GRID_H
#define RT_DENSITY_GRID_H

#include <stddef.h>
#include <stdint.h>

#include "rt/base/error.h"
#include "rt/base/vec.h"

#define RT_DENSITY_BLOCK 8
/* Voxels a grid may hold: 2^31 (8 GiB of floats); a file claiming more is
 * refused before anything is allocated. */
#define RT_DENSITY_MAX_VOXELS ((uint64_t)1 << 31)

typedef struct rt_density_grid {
    int nx, ny, nz;       /* voxels on each axis, >= 1 */
    float *density;       /* nx * ny * nz values, x fastest; finite, >= 0 */
    int bx, by, bz;       /* blocks on each axis: ceil(n / RT_DENSITY_BLOCK) */
    float *block_max;     /* bx * by * bz maxima (rt_density_grid_finish) */
    float max_density;    /* the largest value of all */
} rt_density_grid;

/* A zeroed lattice of nx x ny x nz voxels. RT_ERR_INVALID for a size < 1,
 * RT_ERR_LIMIT for more than RT_DENSITY_MAX_VOXELS, RT_ERR_NOMEM. */
rt_result rt_density_grid_init(rt_density_grid *g, int nx, int ny, int nz, rt_error *err);

static inline size_t rt_density_grid_index(const rt_density_grid *g, int x, int y, int z)
{
    return ((size_t)z * (size_t)g->ny + (size_t)y) * (size_t)g->nx + (size_t)x;
}

/* After the values are written: refuses a NaN, infinite or negative value
 * (RT_ERR_INVALID naming `source` and the voxel) and builds the block maxima. */
rt_result rt_density_grid_finish(rt_density_grid *g, const char *source, rt_error *err);

/* The field at p (index space): trilinear, zero outside the lattice. */
float rt_density_grid_lookup(const rt_density_grid *g, rt_vec3 p);

/* Where the field can be nonzero, in index space: [-0.5, n + 0.5) per axis. */
rt_box rt_density_grid_bounds(const rt_density_grid *g);

/* The block holding index-space point p, clamped to the block lattice. */
void rt_density_grid_block_of(const rt_density_grid *g, rt_vec3 p, int block[3]);

static inline float rt_density_grid_block_max(const rt_density_grid *g, int bx, int by, int bz)
{
    return g->block_max[((size_t)bz * (size_t)g->by + (size_t)by) * (size_t)g->bx + (size_t)bx];
}

void rt_density_grid_free(rt_density_grid *g);

#endif
