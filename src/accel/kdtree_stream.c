/* kdtree_stream.c - closest and any hit for streams of rays
 * (rt/accel/kdtree_stream.h): the chunks, their memory, the leaf tests and
 * the ray-by-ray walk the stream walk calls, and the choice of SIMD width.
 *
 * A stream is walked params->chunk rays at a time (a chunk's per-ray data,
 * about 150 bytes a ray, stays in the cache while its lists are split).
 * kdtree_stream_walk.c sets each chunk's rays up in lanes as
 * kdtree_trace.c's ray_setup does (the same acceptance tests, cell
 * widening mp, 1/d, parallel axes and t interval in the tree's box) and
 * walks the list of accepted rays, at the widest width the CPU has (16
 * lanes with AVX-512, 8 with AVX2, else 4: __builtin_cpu_supports, once a
 * call, a switch, no table of function pointers; a tree built with
 * params.portable takes 4). Its leaves and thin lists come back here: a
 * leaf is tested for one ray with kdtree_trace.c's leaf test, a thin
 * list's rays walk on alone with kdtree_trace.c's walk from that node
 * (both of the pass the tree uses: AVX2 or portable). A leaf holding
 * instances sends its rays on as sub-streams (kdtree_stream_instances.c,
 * which sets up and walks them with rt_kd_stream_chunk, as here). When
 * the chunk's memory cannot be had, its rays are traced one by one
 * instead.
 */
#include "rt/accel/kdtree_stream.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "kdtree_stream_internal.h"

int rt_kd_stream_lanes_supported(int lanes)
{
    if (lanes == 4)
        return 1;
#ifdef KD_HAVE_AVX2
    if (lanes == 8)
        return __builtin_cpu_supports("avx2");
    if (lanes == 16)
        return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
               __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
#endif
    return 0;
}

int rt_kd_stream_lanes_best(const rt_kdtree *tree)
{
    if (tree->isa == RT_KD_ISA_PORTABLE)
        return 4;
    return rt_kd_stream_lanes_supported(16) ? 16 : rt_kd_stream_lanes_supported(8) ? 8 : 4;
}

bool rt_kd_stream_reserve(kd_stream *s, size_t need)
{
    if (need <= s->cap)
        return true;
    size_t cap = s->cap ? s->cap : 1024;
    while (cap < need)
        cap *= 2;
    uint32_t *lid = realloc(s->lid, cap * sizeof *lid);
    if (!lid)
        return false;
    s->lid = lid;
    float *lo = realloc(s->llo, cap * sizeof *lo);
    if (!lo)
        return false;
    s->llo = lo;
    float *hi = realloc(s->lhi, cap * sizeof *hi);
    if (!hi)
        return false;
    s->lhi = hi;
    s->cap = cap;
    return true;
}

static bool leaf_hit(const rt_kdtree *tree, uint32_t ref, const rt_ray *ray, const rt_tri_ray *tr, float *best,
                     rt_hit *hit, bool any)
{
#ifdef KD_HAVE_AVX2
    if (tree->isa == RT_KD_ISA_AVX2)
        return rt_kd_leaf_hit_avx2(tree, ref, ray, tr, best, hit, any);
#endif
    return rt_kd_leaf_hit_portable(tree, ref, ray, tr, best, hit, any);
}

static bool walk_from(const rt_kdtree *tree, uint32_t ref, float tn, float tf, const rt_ray *ray, rt_hit *hit, bool any)
{
#ifdef KD_HAVE_AVX2
    if (tree->isa == RT_KD_ISA_AVX2)
        return rt_kd_walk_from_avx2(tree, ref, tn, tf, ray, hit, any);
#endif
    return rt_kd_walk_from_portable(tree, ref, tn, tf, ray, hit, any);
}

/* A ray's answer: the closest hit so far, or (occlusion) blocked. */
static void record(kd_stream *s, uint32_t i, const rt_hit *h)
{
    if (s->any) {
        s->best[i] = NAN; /* every later "starts before the closest hit" test fails */
        s->hit[i].prim = 0;
        return;
    }
    s->best[i] = h->t;
    s->hit[i] = *h;
}

void rt_kd_stream_leaf(kd_stream *s, uint32_t ref, uint32_t i)
{
    rt_hit h;
    float b = s->best[i];
    if (leaf_hit(s->tree, ref, &s->ray[i], &s->tr[i], &b, &h, s->any))
        record(s, i, &h);
}

void rt_kd_stream_single(kd_stream *s, uint32_t ref, uint32_t i, float tn, float tf)
{
    rt_ray r = s->ray[i];
    r.tmax = s->best[i];
    rt_hit h;
    if (walk_from(s->tree, ref, tn, tf, &r, &h, s->any))
        record(s, i, &h);
}

/* The per-ray arrays of a chunk of up to `chunk` rays, in one block. */
static bool stream_alloc(kd_stream *s, size_t chunk)
{
    size_t floats = 10 * chunk, ints = 3 * chunk;
    size_t bytes = floats * sizeof(float) + ints * sizeof(int32_t) + chunk * (sizeof(rt_ray) + sizeof(rt_tri_ray) +
                                                                            sizeof(rt_hit)) + 64;
    char *p = malloc(bytes);
    s->block = p;
    if (!p)
        return false;
    /* the structs first (their alignment), then the floats and ints */
    s->ray = (rt_ray *)(void *)p;
    p += chunk * sizeof(rt_ray);
    s->tr = (rt_tri_ray *)(void *)p;
    p += chunk * sizeof(rt_tri_ray);
    s->hit = (rt_hit *)(void *)p;
    p += chunk * sizeof(rt_hit);
    float *f = (float *)(void *)p;
    for (int k = 0; k < 3; k++) {
        s->o[k] = f + (size_t)k * chunk;
        s->inv[k] = f + (size_t)(3 + k) * chunk;
        s->ma[k] = f + (size_t)(6 + k) * chunk;
    }
    s->mp = f + 9 * chunk;
    int32_t *q = (int32_t *)(void *)(f + floats);
    for (int k = 0; k < 3; k++)
        s->par[k] = q + (size_t)k * chunk;
    s->best = malloc(chunk * sizeof(float));
    return s->best != NULL;
}

bool rt_kd_stream_open(kd_stream *s, const rt_kdtree *tree, bool any, int lanes, int min_rays, size_t chunk)
{
    memset(s, 0, sizeof *s);
    s->tree = tree;
    s->any = any;
    s->lanes = lanes;
    s->min_rays = min_rays;
    s->chunk = chunk;
    return stream_alloc(s, chunk) && rt_kd_stream_reserve(s, chunk);
}

void rt_kd_stream_close(kd_stream *s)
{
    rt_kd_stream_sub_free(s->sub);
    free(s->block);
    free(s->best);
    free(s->lid);
    free(s->llo);
    free(s->lhi);
    memset(s, 0, sizeof *s);
}

bool rt_kd_stream_chunk(kd_stream *s, const rt_ray_batch *rb, size_t g0, size_t m)
{
    s->any_par = false;
    switch (s->lanes) {
#ifdef KD_HAVE_AVX2
    case 16:
        return rt_kd_stream_walk16(s, rt_kd_stream_setup16(s, rb, g0, m));
    case 8:
        return rt_kd_stream_walk8(s, rt_kd_stream_setup8(s, rb, g0, m));
#endif
    default:
        return rt_kd_stream_walk4(s, rt_kd_stream_setup4(s, rb, g0, m));
    }
}

static inline rt_ray ray_at(const rt_ray_batch *rb, size_t i)
{
    return rt_ray_make(rt_v3(rb->ox[i], rb->oy[i], rb->oz[i]), rt_v3(rb->dx[i], rb->dy[i], rb->dz[i]), rb->tmin[i],
                       rb->tmax[i]);
}

/* Both queries: hits (closest) or blocked (any); returns how many hit. */
static size_t trace_stream(const rt_kdtree *tree, const rt_ray_batch *rays, size_t n, rt_hit_batch *hits,
                           uint8_t *blocked, const rt_kd_stream_params *params)
{
    bool any = blocked != NULL;
    int lanes = params && params->lanes ? params->lanes : 0;
    if (!lanes || !rt_kd_stream_lanes_supported(lanes) || (lanes != 4 && tree->isa == RT_KD_ISA_PORTABLE))
        lanes = rt_kd_stream_lanes_best(tree);
    size_t chunk = params && params->chunk > 0 ? (size_t)params->chunk : RT_KD_STREAM_CHUNK;
    if (chunk > n)
        chunk = n ? n : 1;
    kd_stream s;
    int min_rays = params && params->min_rays > 0 ? params->min_rays : RT_KD_STREAM_MIN_RAYS;
    bool ok = rt_kd_stream_open(&s, tree, any, lanes, min_rays, chunk);
    size_t found = 0;
    for (size_t c0 = 0; c0 < n; c0 += chunk) {
        size_t m = n - c0 < chunk ? n - c0 : chunk;
        bool done = ok && rt_kd_stream_chunk(&s, rays, c0, m);
        for (size_t i = 0; i < m; i++) {
            size_t g = c0 + i;
            rt_hit h = {0.0f, 0.0f, 0.0f, RT_NONE, 0};
            if (!done) { /* no memory for the lists: one by one */
                rt_ray r = ray_at(rays, g);
                if (any)
                    h.prim = rt_kdtree_occluded(tree, &r) ? 0 : RT_NONE;
                else if (!rt_kdtree_intersect(tree, &r, &h))
                    h.prim = RT_NONE;
            } else {
                h = s.hit[i];
                if (!any && h.prim != RT_NONE)
                    rt_kd_finish_hit(tree, &h);
            }
            bool hit = h.prim != RT_NONE;
            found += hit;
            if (any) {
                blocked[g] = hit;
                continue;
            }
            hits->prim[g] = h.prim;
            if (hit) {
                if (hits->inst)
                    hits->inst[g] = h.inst;
                hits->t[g] = h.t;
                hits->u[g] = h.u;
                hits->v[g] = h.v;
            }
        }
    }
    rt_kd_stream_close(&s);
    return found;
}

size_t rt_kdtree_intersect_stream(const rt_kdtree *tree, const rt_ray_batch *rays, size_t n, rt_hit_batch *hits,
                                  const rt_kd_stream_params *params)
{
    return trace_stream(tree, rays, n, hits, NULL, params);
}

size_t rt_kdtree_occluded_stream(const rt_kdtree *tree, const rt_ray_batch *rays, size_t n, uint8_t *blocked,
                                 const rt_kd_stream_params *params)
{
    return trace_stream(tree, rays, n, NULL, blocked, params);
}
