/* density_grid.c - a density field on a voxel lattice, its trilinear
 * lookup and its coarse grid of block maxima (see rt/scene/density_grid.h;
 * the majorant grid follows pbrt-v4's MajorantGrid and the survey of
 * Novak et al., Eurographics STAR 2018).
 */
#include "rt/scene/density_grid.h"

#include <math.h>
#include <stdlib.h>

#include "rt/base/alloc.h"

static int blocks_for(int n)
{
    return (n + RT_DENSITY_BLOCK - 1) / RT_DENSITY_BLOCK;
}

rt_result rt_density_grid_init(rt_density_grid *g, int nx, int ny, int nz, rt_error *err)
{
    *g = (rt_density_grid){0};
    if (nx < 1 || ny < 1 || nz < 1)
        return rt_fail(err, RT_ERR_INVALID, "density grid of %dx%dx%d voxels: every size must be at least 1",
                       nx, ny, nz);
    uint64_t voxels = (uint64_t)nx * (uint64_t)ny * (uint64_t)nz;
    if (voxels > RT_DENSITY_MAX_VOXELS)
        return rt_fail(err, RT_ERR_LIMIT, "density grid of %dx%dx%d voxels: more than the %llu a grid may hold",
                       nx, ny, nz, (unsigned long long)RT_DENSITY_MAX_VOXELS);
    g->nx = nx;
    g->ny = ny;
    g->nz = nz;
    g->bx = blocks_for(nx);
    g->by = blocks_for(ny);
    g->bz = blocks_for(nz);
    g->density = rt_alloc((size_t)voxels, sizeof *g->density);
    g->block_max = rt_alloc((size_t)g->bx * (size_t)g->by * (size_t)g->bz, sizeof *g->block_max);
    if (!g->density || !g->block_max) {
        rt_density_grid_free(g);
        return rt_fail(err, RT_ERR_NOMEM, "density grid of %dx%dx%d voxels: out of memory", nx, ny, nz);
    }
    return RT_OK;
}

/* The largest value in voxels [x0,x1] x [y0,y1] x [z0,z1], clamped to the
 * lattice. */
static float max_in(const rt_density_grid *g, int x0, int x1, int y0, int y1, int z0, int z1)
{
    x0 = x0 < 0 ? 0 : x0;
    y0 = y0 < 0 ? 0 : y0;
    z0 = z0 < 0 ? 0 : z0;
    x1 = x1 >= g->nx ? g->nx - 1 : x1;
    y1 = y1 >= g->ny ? g->ny - 1 : y1;
    z1 = z1 >= g->nz ? g->nz - 1 : z1;
    float m = 0.0f;
    for (int z = z0; z <= z1; z++)
        for (int y = y0; y <= y1; y++) {
            const float *row = g->density + rt_density_grid_index(g, 0, y, z);
            for (int x = x0; x <= x1; x++)
                m = row[x] > m ? row[x] : m;
        }
    return m;
}

rt_result rt_density_grid_finish(rt_density_grid *g, const char *source, rt_error *err)
{
    size_t voxels = (size_t)g->nx * (size_t)g->ny * (size_t)g->nz;
    for (size_t i = 0; i < voxels; i++) {
        float v = g->density[i];
        if (!(v >= 0.0f) || isinf(v)) {
            int x = (int)(i % (size_t)g->nx), y = (int)(i / (size_t)g->nx % (size_t)g->ny);
            int z = (int)(i / ((size_t)g->nx * (size_t)g->ny));
            return rt_fail(err, RT_ERR_INVALID, "%s: voxel (%d, %d, %d): density %g (must be finite and >= 0)",
                           source, x, y, z, (double)v);
        }
    }
    /* a lookup inside block b reads voxels bB-1 .. bB+B (its own and the
     * ring trilinear filtering reaches into) */
    const int B = RT_DENSITY_BLOCK;
    float all = 0.0f;
    for (int bz = 0; bz < g->bz; bz++)
        for (int by = 0; by < g->by; by++)
            for (int bx = 0; bx < g->bx; bx++) {
                float m = max_in(g, bx * B - 1, bx * B + B, by * B - 1, by * B + B, bz * B - 1, bz * B + B);
                g->block_max[((size_t)bz * (size_t)g->by + (size_t)by) * (size_t)g->bx + (size_t)bx] = m;
                all = m > all ? m : all;
            }
    g->max_density = all;
    return RT_OK;
}

static float voxel(const rt_density_grid *g, int x, int y, int z)
{
    if (x < 0 || y < 0 || z < 0 || x >= g->nx || y >= g->ny || z >= g->nz)
        return 0.0f;
    return g->density[rt_density_grid_index(g, x, y, z)];
}

float rt_density_grid_lookup(const rt_density_grid *g, rt_vec3 p)
{
    /* voxel centres sit at i + 0.5 */
    float ux = p.x - 0.5f, uy = p.y - 0.5f, uz = p.z - 0.5f;
    if (!(ux > -1.0f && uy > -1.0f && uz > -1.0f && ux < (float)g->nx && uy < (float)g->ny && uz < (float)g->nz))
        return 0.0f; /* outside the support (and NaN) */
    float fx = floorf(ux), fy = floorf(uy), fz = floorf(uz);
    int x = (int)fx, y = (int)fy, z = (int)fz;
    float tx = ux - fx, ty = uy - fy, tz = uz - fz;
    float c00 = voxel(g, x, y, z) * (1.0f - tx) + voxel(g, x + 1, y, z) * tx;
    float c10 = voxel(g, x, y + 1, z) * (1.0f - tx) + voxel(g, x + 1, y + 1, z) * tx;
    float c01 = voxel(g, x, y, z + 1) * (1.0f - tx) + voxel(g, x + 1, y, z + 1) * tx;
    float c11 = voxel(g, x, y + 1, z + 1) * (1.0f - tx) + voxel(g, x + 1, y + 1, z + 1) * tx;
    float c0 = c00 * (1.0f - ty) + c10 * ty;
    float c1 = c01 * (1.0f - ty) + c11 * ty;
    return c0 * (1.0f - tz) + c1 * tz;
}

rt_box rt_density_grid_bounds(const rt_density_grid *g)
{
    return (rt_box){rt_v3(-0.5f, -0.5f, -0.5f),
                    rt_v3((float)g->nx + 0.5f, (float)g->ny + 0.5f, (float)g->nz + 0.5f)};
}

static int clamp_block(float v, int count)
{
    float b = floorf(v / (float)RT_DENSITY_BLOCK);
    if (!(b >= 0.0f))
        return 0;
    return b >= (float)count ? count - 1 : (int)b;
}

void rt_density_grid_block_of(const rt_density_grid *g, rt_vec3 p, int block[3])
{
    block[0] = clamp_block(p.x, g->bx);
    block[1] = clamp_block(p.y, g->by);
    block[2] = clamp_block(p.z, g->bz);
}

void rt_density_grid_free(rt_density_grid *g)
{
    free(g->density);
    free(g->block_max);
    *g = (rt_density_grid){0};
}
