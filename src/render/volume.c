/* volume.c - participating media along a ray: the density, the majorant in
 * pieces (one piece for a homogeneous medium, the grid's blocks by a 3D
 * DDA, Amanatides and Woo 1987, for a grid), and ratio and delta tracking
 * over it (see rt/render/volume.h; the estimators as surveyed by Novak et
 * al., Eurographics STAR 2018).
 */
#include "rt/render/volume.h"

#include <math.h>

rt_volume rt_volume_homogeneous(rt_vec3 sigma_a, rt_vec3 sigma_s, float g)
{
    return (rt_volume){.sigma_a = sigma_a, .sigma_s = sigma_s, .g = g, .grid = NULL,
                       .world_to_index = rt_mat4_identity()};
}

rt_volume rt_volume_grid(rt_vec3 sigma_a, rt_vec3 sigma_s, float g, const rt_density_grid *grid,
                         const rt_mat4 *world_to_index)
{
    return (rt_volume){.sigma_a = sigma_a, .sigma_s = sigma_s, .g = g, .grid = grid,
                       .world_to_index = *world_to_index};
}

float rt_volume_density(const rt_volume *v, rt_vec3 p)
{
    if (!v->grid)
        return 1.0f;
    return rt_density_grid_lookup(v->grid, rt_mat4_point(&v->world_to_index, p));
}

/* Clips [*t0, *t1) to the box along o + t d (the slab test); false when
 * nothing is left. */
static bool clip_to_box(rt_box b, rt_vec3 o, rt_vec3 d, float *t0, float *t1)
{
    const float lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
    const float org[3] = {o.x, o.y, o.z}, dir[3] = {d.x, d.y, d.z};
    for (int a = 0; a < 3; a++) {
        if (dir[a] == 0.0f) {
            if (!(org[a] >= lo[a] && org[a] < hi[a]))
                return false;
            continue;
        }
        float inv = 1.0f / dir[a];
        float ta = (lo[a] - org[a]) * inv, tb = (hi[a] - org[a]) * inv;
        if (ta > tb) {
            float s = ta;
            ta = tb;
            tb = s;
        }
        *t0 = ta > *t0 ? ta : *t0;
        *t1 = tb < *t1 ? tb : *t1;
    }
    return *t0 < *t1;
}

void rt_majorant_iter_init(rt_majorant_iter *it, const rt_volume *v, rt_vec3 o, rt_vec3 d, float t_min,
                           float t_max)
{
    *it = (rt_majorant_iter){.v = v, .t = t_min, .t_end = t_max, .grid = v->grid != NULL};
    it->sigma_t = rt_scale(rt_volume_sigma_t(v), rt_length(d));
    if (!it->grid)
        return;
    const rt_density_grid *g = v->grid;
    rt_vec3 oi = rt_mat4_point(&v->world_to_index, o), di = rt_mat4_vector(&v->world_to_index, d);
    if (!clip_to_box(rt_density_grid_bounds(g), oi, di, &it->t, &it->t_end)) {
        it->t_end = it->t; /* misses the grid: no pieces */
        return;
    }
    rt_density_grid_block_of(g, rt_madd(oi, di, it->t), it->block);
    const float org[3] = {oi.x, oi.y, oi.z}, dir[3] = {di.x, di.y, di.z};
    const int counts[3] = {g->bx, g->by, g->bz};
    const float B = (float)RT_DENSITY_BLOCK;
    for (int a = 0; a < 3; a++) {
        it->count[a] = counts[a];
        /* The first and last blocks reach out to the field's edge (half a
         * voxel past the lattice), so a ray only crosses inner planes. */
        if (dir[a] > 0.0f) {
            it->step[a] = 1;
            it->t_delta[a] = B / dir[a];
            it->t_next[a] = it->block[a] + 1 < counts[a] ? ((float)(it->block[a] + 1) * B - org[a]) / dir[a] : INFINITY;
        } else if (dir[a] < 0.0f) {
            it->step[a] = -1;
            it->t_delta[a] = -B / dir[a];
            it->t_next[a] = it->block[a] > 0 ? ((float)it->block[a] * B - org[a]) / dir[a] : INFINITY;
        } else {
            it->step[a] = 0;
            it->t_delta[a] = INFINITY;
            it->t_next[a] = INFINITY;
        }
    }
}

bool rt_majorant_next(rt_majorant_iter *it, float *t0, float *t1, rt_vec3 *sigma_maj)
{
    if (!(it->t < it->t_end))
        return false;
    if (!it->grid) {
        *t0 = it->t;
        *t1 = it->t_end;
        *sigma_maj = it->sigma_t;
        it->t = it->t_end;
        return true;
    }
    int a = it->t_next[0] < it->t_next[1] ? (it->t_next[0] < it->t_next[2] ? 0 : 2)
                                          : (it->t_next[1] < it->t_next[2] ? 1 : 2);
    float exit = it->t_next[a] < it->t_end ? it->t_next[a] : it->t_end;
    /* a plane crossed behind t (rounding at the entry) gives an empty piece */
    exit = exit > it->t ? exit : it->t;
    float m = rt_density_grid_block_max(it->v->grid, it->block[0], it->block[1], it->block[2]);
    *t0 = it->t;
    *t1 = exit;
    *sigma_maj = rt_scale(it->sigma_t, m);
    it->t = exit;
    if (it->t < it->t_end) {
        it->block[a] += it->step[a];
        bool inside = it->block[a] + it->step[a] >= 0 && it->block[a] + it->step[a] < it->count[a];
        it->t_next[a] = inside ? it->t_next[a] + it->t_delta[a] : INFINITY;
    }
    return true;
}

static float channel_of(rt_vec3 c, int k)
{
    return k == 0 ? c.x : (k == 1 ? c.y : c.z);
}

/* An exponential step with rate `rate` from u in [0,1). */
static float exp_step(float rate, rt_rng *rng)
{
    return -log1pf(-rt_rng_float(rng)) / rate;
}

rt_vec3 rt_volume_ratio_tracking(const rt_volume *v, rt_vec3 o, rt_vec3 d, float t_max, rt_rng *rng)
{
    rt_vec3 T = rt_v3(1.0f, 1.0f, 1.0f);
    rt_majorant_iter it;
    rt_majorant_iter_init(&it, v, o, d, 0.0f, t_max);
    float t0, t1;
    rt_vec3 maj;
    while (rt_majorant_next(&it, &t0, &t1, &maj)) {
        float rate = rt_fmaxf(maj.x, rt_fmaxf(maj.y, maj.z));
        if (!(rate > 0.0f))
            continue;
        for (float t = t0 + exp_step(rate, rng); t < t1; t += exp_step(rate, rng)) {
            rt_vec3 st = rt_scale(it.sigma_t, rt_volume_density(v, rt_madd(o, d, t)));
            T = rt_mul(T, rt_v3(1.0f - st.x / rate, 1.0f - st.y / rate, 1.0f - st.z / rate));
            if (T.x <= 0.0f && T.y <= 0.0f && T.z <= 0.0f)
                return rt_v3(0.0f, 0.0f, 0.0f);
        }
    }
    return rt_vmax(T, rt_v3(0.0f, 0.0f, 0.0f));
}

float rt_volume_delta_tracking(const rt_volume *v, rt_vec3 o, rt_vec3 d, float t_max, int channel, rt_rng *rng)
{
    rt_majorant_iter it;
    rt_majorant_iter_init(&it, v, o, d, 0.0f, t_max);
    float t0, t1;
    rt_vec3 maj;
    while (rt_majorant_next(&it, &t0, &t1, &maj)) {
        float rate = channel_of(maj, channel);
        if (!(rate > 0.0f))
            continue;
        for (float t = t0 + exp_step(rate, rng); t < t1; t += exp_step(rate, rng)) {
            float st = channel_of(it.sigma_t, channel) * rt_volume_density(v, rt_madd(o, d, t));
            if (rt_rng_float(rng) * rate < st)
                return t; /* a real collision */
        }
    }
    return INFINITY;
}
