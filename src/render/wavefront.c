/* wavefront.c - the wavefront path tracer (rt/render/wavefront.h): a batch
 * of paths, advanced one bounce at a time by a fixed sequence of stages
 * over the whole batch. Each lane's rt_path_state and random stream are
 * read and written in place by the steps of rt/render/pathtrace.h (no copy
 * in and out); the rays to trace, their hits and the shadow rays are
 * gathered into structure-of-arrays form for the batch traversal:
 *
 *   refill    free lanes take the next camera samples of the work, in
 *             screen-tile order where tiles pay (cam_cursor: a few pixels'
 *             runs of samples)
 *   trace     closest hits for every live path: the new camera rays tile
 *             by tile as frustums (rt_kdtree_intersect_frustum, Reshetov,
 *             Soupikov, Hurley 2005), the other rays as one batch
 *             (rt_kdtree_intersect_batch); both give the single walk's
 *             hits to the bit; repeated (batch) for the lanes whose hit an
 *             alpha cut-out removes
 *   shade     surface records, then per path the steps of
 *             rt/render/pathtrace.h (emission and MIS, the BSDF, one
 *             light-sampling record per light / environment / emitter, BSDF
 *             sampling, Russian roulette), lanes grouped by material kind
 *   shadow    the shadow rays of the new tiles' first hits, light by light,
 *             as frustums (rt_kdtree_occluded_frustum, the single answers),
 *             the other records' as one batch (rt_kdtree_occluded_batch)
 *   resolve   each path adds its light samples, in their order
 *   retire    finished paths write their radiance; survivors stay, in order
 *
 * The structure is pbrt-v4's wavefront integrator (Pharr, Jakob, Humphreys,
 * "Physically Based Rendering", 4th ed., ch. 15: work queues of ray, shadow
 * and material items in structure-of-arrays; per-path random state so the
 * image does not depend on the packing) and Laine, Karras, Aila 2013,
 * "Megakernels Considered Harmful: Wavefront Path Tracing on GPUs" (HPG).
 *
 * Determinism: a path's random numbers come only from its own PCG stream,
 * seeded by (seed, pixel, sample) and carried in its lane, drawn in the order
 * rt_radiance_path draws them, and from the sampler (rt/render/sampler.h),
 * a function of the sample (key and index, in the lane's rt_rng) and the
 * bounce; shading runs the same functions; a vertex's
 * light samples are summed in the same order after their shadow rays come
 * back. So every radiance equals rt_radiance_path's bit for bit, for any
 * batch size, lane assignment and split of the work (tests/test_wavefront.c).
 * Shadow rays are batched when no material needs shading on them (the render
 * state's shadows_need_shading); otherwise each vertex walks its shadow rays
 * at once through rt_path_shadow, as the scalar tracer does.
 */
#include "rt/render/wavefront.h"

#include <stdlib.h>

#include "rt/accel/kdtree_batch.h"
#include "rt/accel/kdtree_frustum.h"
#include "rt/base/alloc.h"
#include "rt/render/environment.h"
#include "rt/render/pathtrace.h"
#include "rt/render/shade_lanes.h"

enum lane_status {
    LANE_TRACE,   /* ray to trace */
    LANE_SURFACE, /* a kept surface in sf */
    LANE_MISS,    /* left the scene */
    LANE_DEEP,    /* every layer cut away */
    LANE_LIVE,    /* shaded, next ray set */
    LANE_DONE,    /* finished: radiance final after its light samples */
};

enum { KIND_BUCKETS = 8 }; /* material kinds (rt_bsdf_model) sorted apart; more fold into the last */
/* light-sampling records a batch holds at most (about 90 bytes each with
 * their shadow rays): the batch shrinks in scenes with many lights */
#define MAX_RECORDS ((size_t)1 << 18)

struct rt_wavefront {
    size_t batch;        /* lanes */
    size_t rec_per_path; /* light samples a vertex can make: lights + environment + emitter */
    /* each lane's path (throughput, eta_scale for the roulette, media
     * stack, ...) and random stream, read and written in place by the
     * steps of rt/render/pathtrace.h */
    rt_path_state *ps;
    rt_rng *rng;
    uint8_t *status, *nee;
    int32_t *layers;
    uint32_t *out;       /* index of the sample in the work */
    /* the camera stage: for the lanes a refill started (active[n_old ..]),
     * the screen tile and sample each camera ray belongs to; rays of one
     * group are traced as one frustum */
    uint32_t *cam_group;
    rt_wavefront_stats stats;
    /* the rays to trace, gathered from the paths, and their hits */
    float *ox, *oy, *oz, *dx, *dy, *dz, *tmin, *tmax;
    float *ht, *hu, *hv;
    uint32_t *hprim, *hinst; /* hinst: rt_hit's inst (instances) */
    /* this bounce's light samples: the lane's first record, how many, the
     * throughput they are weighted by */
    uint32_t *rec_first, *rec_count;
    float *nbr, *nbg, *nbb;
    rt_surface *sf;
    /* records of this bounce: the sample, its visibility, its shadow ray */
    rt_nee_record *rec;
    rt_vec3 *vis;        /* what each record's shadow ray lets through */
    float *sox, *soy, *soz, *sdx, *sdy, *sdz, *stmin, *stmax;
    uint8_t *blocked;
    uint8_t *rec_src;    /* each record's bundle source (shadow_bundles), SRC_NONE: traced in the batch */
    uint32_t *pending;   /* records whose shadow ray is to trace */
    /* lane lists */
    uint32_t *active, *queue, *queue2, *order, *free_lanes;
    /* this bounce's vertices of the kinds sampled in SIMD lanes, each
     * kind's compacted apart (enum lane_kind): their lanes,
     * the random numbers drawn for their BSDF samples, and the arrays the
     * samples are taken in, RT_SHADE_LANES at a time (rt/render/shade_lanes.h) */
    struct kind_lanes {
        size_t n;
        uint32_t *lane;
        rt_path_bsdf_draw *draw;
        rt_shade_lanes *soa;
        /* light sampling deferred to the lanes (not for glass): the 2D
         * value each vertex drew for light j and the record kept for it,
         * at [slot * lights + j] */
        rt_vec2 *lu;
        uint32_t *lrec;
        /* the environment's sample likewise (direction, pdf, whether
         * there is one, its record) */
        rt_vec3 *ed;
        float *epdf;
        uint8_t *eok;
        uint32_t *erec;
    } kl[5];
};

enum lane_kind { LANES_LAMBERT, LANES_CONDUCTOR, LANES_GLTF, LANES_PLASTIC, LANES_DIELECTRIC, LANE_KINDS };

static void *grab(size_t n, size_t size, bool *ok)
{
    void *p = rt_alloc(n, size);
    if (!p)
        *ok = false;
    return p;
}

rt_wavefront *rt_wavefront_new(size_t batch, const rt_render_state *state)
{
    rt_wavefront *wf = rt_alloc(1, sizeof *wf);
    if (!wf)
        return NULL;
    size_t B = batch ? batch : RT_WAVEFRONT_BATCH;
    if (B > ((size_t)1 << 24))
        B = (size_t)1 << 24;
    size_t K = state->scene->light_count + 2;
    if (B * K > MAX_RECORDS) /* many lights: fewer paths, not gigabytes of light samples */
        B = MAX_RECORDS / K > 0 ? MAX_RECORDS / K : 1;
    size_t R = B * K;
    wf->batch = B;
    wf->rec_per_path = K;
    bool ok = true;
    float **fl[] = {&wf->ox, &wf->oy, &wf->oz, &wf->dx, &wf->dy, &wf->dz, &wf->tmin, &wf->tmax, &wf->ht,
                    &wf->hu, &wf->hv, &wf->nbr, &wf->nbg, &wf->nbb};
    for (size_t i = 0; i < sizeof fl / sizeof fl[0]; i++)
        *fl[i] = grab(B, sizeof(float), &ok);
    uint32_t **u32[] = {&wf->hprim, &wf->hinst, &wf->out, &wf->rec_first, &wf->rec_count, &wf->active,
                        &wf->queue, &wf->queue2, &wf->order, &wf->free_lanes, &wf->cam_group};
    for (size_t i = 0; i < sizeof u32 / sizeof u32[0]; i++)
        *u32[i] = grab(B, sizeof(uint32_t), &ok);
    wf->ps = grab(B, sizeof(rt_path_state), &ok);
    wf->rng = grab(B, sizeof(rt_rng), &ok);
    wf->status = grab(B, 1, &ok);
    wf->nee = grab(B, 1, &ok);
    wf->layers = grab(B, sizeof(int32_t), &ok);
    wf->sf = grab(B, sizeof(rt_surface), &ok);
    wf->rec = grab(R, sizeof(rt_nee_record), &ok);
    wf->vis = grab(R, sizeof(rt_vec3), &ok);
    float **sfl[] = {&wf->sox, &wf->soy, &wf->soz, &wf->sdx, &wf->sdy, &wf->sdz, &wf->stmin, &wf->stmax};
    for (size_t i = 0; i < sizeof sfl / sizeof sfl[0]; i++)
        *sfl[i] = grab(R, sizeof(float), &ok);
    wf->blocked = grab(R, 1, &ok);
    wf->rec_src = grab(R, 1, &ok);
    wf->pending = grab(R, sizeof(uint32_t), &ok);
    for (int c = 0; c < LANE_KINDS; c++) {
        wf->kl[c].lane = grab(B, sizeof(uint32_t), &ok);
        wf->kl[c].draw = grab(B, sizeof(rt_path_bsdf_draw), &ok);
        size_t L = state->scene->light_count ? state->scene->light_count : 1;
        wf->kl[c].lu = grab(B * L, sizeof(rt_vec2), &ok);
        wf->kl[c].lrec = grab(B * L, sizeof(uint32_t), &ok);
        wf->kl[c].ed = grab(B, sizeof(rt_vec3), &ok);
        wf->kl[c].epdf = grab(B, sizeof(float), &ok);
        wf->kl[c].eok = grab(B, 1, &ok);
        wf->kl[c].erec = grab(B, sizeof(uint32_t), &ok);
        wf->kl[c].soa = rt_shade_lanes_new(B);
        if (!wf->kl[c].soa)
            ok = false;
    }
    if (!ok) {
        rt_wavefront_free(wf);
        return NULL;
    }
    return wf;
}

void rt_wavefront_free(rt_wavefront *wf)
{
    if (!wf)
        return;
    void *all[] = {wf->ps, wf->rng, wf->ox, wf->oy, wf->oz, wf->dx, wf->dy, wf->dz, wf->tmin, wf->tmax, wf->ht,
                   wf->hu, wf->hv, wf->hprim, wf->hinst, wf->status, wf->nee, wf->layers, wf->out, wf->rec_first,
                   wf->rec_count, wf->nbr, wf->nbg, wf->nbb, wf->sf, wf->rec, wf->vis, wf->sox, wf->soy,
                   wf->soz, wf->sdx, wf->sdy, wf->sdz, wf->stmin, wf->stmax, wf->blocked, wf->rec_src, wf->pending,
                   wf->active, wf->queue, wf->queue2, wf->order, wf->free_lanes, wf->cam_group};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
        free(all[i]);
    for (int c = 0; c < LANE_KINDS; c++) {
        free(wf->kl[c].lane);
        free(wf->kl[c].draw);
        free(wf->kl[c].lu);
        free(wf->kl[c].lrec);
        free(wf->kl[c].ed);
        free(wf->kl[c].epdf);
        free(wf->kl[c].eok);
        free(wf->kl[c].erec);
        rt_shade_lanes_free(wf->kl[c].soa);
    }
    free(wf);
}

rt_wavefront_stats rt_wavefront_stats_of(const rt_wavefront *wf) { return wf->stats; }

static inline void put_out(float *out, uint32_t k, rt_vec3 L)
{
    out[3 * (size_t)k] = L.x;
    out[3 * (size_t)k + 1] = L.y;
    out[3 * (size_t)k + 2] = L.z;
}

/* ------------------------------------------------------------ camera tiles */

/* Groups smaller than this go ray by ray (the frustum's set-up does not
 * pay); a group takes up to TILE_SAMPLES samples of each of its pixels
 * (docs/performance.md, "Frustum tiles in the renderer": 2x2 pixels of 16
 * samples cost a third fewer instructions a camera ray than 8x8 pixels of
 * one, whose frustum is wider). */
enum { TILE_MIN_RAYS = 4, TILE_SAMPLES = 16 };

/* The work's camera samples in tile order: the rectangle's rows in bands
 * of th from the work's first row, each band in tiles of tw columns from
 * column 0, each tile in runs of sg sample indices, each run its pixels
 * row by row and each pixel's samples of the run in order (the work's
 * only). Every sample of the work comes once; `group` counts (tile, run)
 * pairs, at most tw x th x sg <= RT_KD_FRUSTUM_MAX rays each: one
 * frustum. Where tiles do not pay (tiles_pay) the samples come in the
 * work's own order (a pixel's samples, then the next pixel's), which the
 * batch traces as packets and which measured faster there than the tile
 * order. */
typedef struct cam_cursor {
    uint64_t first, end;  /* the work's pixels [first, end) of the rectangle */
    uint32_t w, n;        /* rectangle width, samples per pixel in the work */
    uint32_t tw, th, sg;  /* tile width and height in pixels, samples a run */
    uint32_t band, tx;    /* the tile: its first row and column */
    uint32_t s, j;        /* the run's first sample (from 0), the next ray in the group */
    uint32_t group;
    bool done;
    bool linear;          /* no tiles: the work's order, sample k after k - 1 */
    uint64_t next, total; /* (linear) */
} cam_cursor;

static bool tile_has_pixels(const cam_cursor *c)
{
    uint32_t cols = c->w - c->tx < c->tw ? c->w - c->tx : c->tw;
    for (uint64_t r = c->band; r < (uint64_t)c->band + c->th; r++) {
        uint64_t a = r * c->w + c->tx;
        if (a < c->end && a + cols > c->first)
            return true;
    }
    return false;
}

/* The next tile of the work with a pixel in it, or done. */
static void next_tile(cam_cursor *c)
{
    do {
        c->tx += c->tw;
        if (c->tx >= c->w) {
            c->tx = 0;
            c->band += c->th;
            if ((uint64_t)c->band * c->w >= c->end) {
                c->done = true;
                return;
            }
        }
    } while (!tile_has_pixels(c));
}

static void cam_cursor_init(cam_cursor *c, const rt_wavefront_work *wk, bool tiles)
{
    c->linear = !tiles;
    c->next = 0;
    c->total = (uint64_t)wk->count * (wk->s1 - wk->s0);
    c->w = (uint32_t)(wk->x1 - wk->x0);
    c->n = wk->s1 - wk->s0;
    /* up to TILE_SAMPLES samples a run, and as many pixels as fill a frustum */
    c->sg = c->n < TILE_SAMPLES ? c->n : TILE_SAMPLES;
    uint32_t px = c->sg > 0 ? RT_KD_FRUSTUM_MAX / c->sg : 64;
    c->tw = px >= 32 ? 8 : px >= 8 ? 4 : 2; /* 8x8, 8x4, 4x4, 4x2, 2x2 */
    c->th = px >= 64 ? 8 : px >= 16 ? 4 : 2;
    c->first = wk->first;
    c->end = (uint64_t)wk->first + wk->count;
    c->band = c->w > 0 ? wk->first / c->w : 0;
    c->tx = c->s = c->j = c->group = 0;
    c->done = wk->count == 0 || c->n == 0 || c->w == 0;
    if (!c->done && !tile_has_pixels(c))
        next_tile(c);
}

/* The index in the work (pixel-major, as out is laid out) of the next
 * camera sample in tile order; false when every sample has come. */
static bool cam_cursor_next(cam_cursor *c, uint32_t *k)
{
    if (c->linear) {
        if (c->next >= c->total)
            return false;
        *k = (uint32_t)c->next++;
        return true;
    }
    while (!c->done) {
        if (c->j == c->tw * c->th * c->sg) {
            c->j = 0;
            c->group++;
            c->s += c->sg;
            if (c->s >= c->n) {
                c->s = 0;
                next_tile(c);
            }
            continue;
        }
        uint32_t px = c->j / c->sg, s = c->s + c->j % c->sg;
        uint32_t col = c->tx + px % c->tw;
        uint64_t p = ((uint64_t)c->band + px / c->tw) * c->w + col;
        c->j++;
        if (s < c->n && col < c->w && p >= c->first && p < c->end) {
            *k = (uint32_t)((p - c->first) * c->n + s);
            return true;
        }
    }
    return false;
}

/* Whether camera tiles and shadow bundles go as frustums: on a tree with
 * inner nodes, or with instances (whose objects' trees have them), whose
 * rays take the AVX2 walks (the frustum sends an instance's rays on as one
 * sub-packet; the README's forest renders 10% faster with tiles than with
 * the batch). A tree of one leaf and no instances has nothing
 * to cull (every ray tests every primitive: the tiles measured 0.3% more
 * instructions on the Cornell boxes), and the frustum walk traces the
 * other trees' tiles as packets or single rays, as the batch does
 * (docs/performance.md, "Frustum tiles in the renderer"). */
static bool tiles_pay(const rt_kdtree *tree)
{
    return (tree->wide_count > 0 || tree->instance_count > 0) && tree->isa == RT_KD_ISA_AVX2;
}

/* The end of the camera group starting at active position a (at most a
 * frustum's rays). */
static size_t group_end(const rt_wavefront *wf, size_t a, size_t to)
{
    size_t b = a + 1;
    while (b < to && b - a < RT_KD_FRUSTUM_MAX && wf->cam_group[b] == wf->cam_group[a])
        b++;
    return b;
}

/* The camera rays of the lanes at active[from .. to), each group of one
 * tile and sample through rt_kdtree_intersect_frustum (the single walk's
 * hits to the bit), their hits into the lanes' hit arrays as the batch
 * traversal writes them. */
static void trace_camera_tiles(rt_wavefront *wf, const rt_kdtree *tree, size_t from, size_t to)
{
    rt_ray rays[RT_KD_FRUSTUM_MAX];
    rt_hit hits[RT_KD_FRUSTUM_MAX];
    for (size_t a = from; a < to;) {
        size_t b = group_end(wf, a, to);
        int n = (int)(b - a);
        for (int j = 0; j < n; j++)
            rays[j] = wf->ps[wf->active[a + (size_t)j]].r;
        if (n >= TILE_MIN_RAYS) {
            rt_kdtree_intersect_frustum(tree, rays, n, hits);
            wf->stats.tiles++;
            wf->stats.tile_rays += (uint64_t)n;
        } else {
            for (int j = 0; j < n; j++)
                if (!rt_kdtree_intersect(tree, &rays[j], &hits[j]))
                    hits[j].prim = RT_NONE;
        }
        for (int j = 0; j < n; j++) {
            uint32_t i = wf->active[a + (size_t)j];
            wf->hprim[i] = hits[j].prim;
            if (hits[j].prim != RT_NONE)
                wf->ht[i] = hits[j].t, wf->hu[i] = hits[j].u, wf->hv[i] = hits[j].v, wf->hinst[i] = hits[j].inst;
        }
        a = b;
    }
}

/* ------------------------------------------------------------ stages */

/* Camera sample k of the work into lane i; false (radiance 0 written) for
 * a degenerate camera ray. */
static bool start_path(rt_wavefront *wf, const rt_trace_ctx *ctx, const rt_wavefront_work *wk, uint32_t i,
                       uint32_t k, float *out)
{
    uint32_t n = wk->s1 - wk->s0;
    uint32_t px = wk->first + k / n, s = wk->s0 + k % n;
    uint32_t w = (uint32_t)(wk->x1 - wk->x0);
    int x = wk->x0 + (int)(px % w), y = wk->y0 + (int)(px / w);
    rt_ray ray = rt_camera_pixel_sample(wk->camera, wk->width, wk->seed, wk->spp, x, y, s, &wf->rng[i]);
    if (!rt_path_start(ctx, &ray, &wf->ps[i])) {
        put_out(out, k, rt_v3s(0.0f));
        return false;
    }
    wf->out[i] = k;
    wf->status[i] = LANE_TRACE;
    return true;
}

/* Closest kept surface for every lane of the active list: the alpha walk
 * of rt_trace_surface, one batch of rays per layer; the first layer of the
 * camera rays a refill started (active[n_old ..]) as screen tiles. */
static void trace_stage(rt_wavefront *wf, const rt_trace_ctx *ctx, size_t n_active, size_t n_old)
{
    const rt_kdtree *tree = ctx->state->tree;
    const rt_material *materials = ctx->state->scene->materials;
    rt_ray_batch rb = {wf->ox, wf->oy, wf->oz, wf->dx, wf->dy, wf->dz, wf->tmin, wf->tmax};
    rt_hit_batch hb = {wf->ht, wf->hu, wf->hv, wf->hprim, wf->hinst};
    uint32_t *q = wf->queue, *q2 = wf->queue2;
    size_t n = n_active;
    for (size_t k = 0; k < n; k++) { /* the rays, gathered */
        uint32_t i = wf->active[k];
        const rt_ray *r = &wf->ps[i].r;
        q[k] = i;
        wf->layers[i] = RT_PATH_LAYERS;
        wf->ox[i] = r->org.x, wf->oy[i] = r->org.y, wf->oz[i] = r->org.z;
        wf->dx[i] = r->dir.x, wf->dy[i] = r->dir.y, wf->dz[i] = r->dir.z;
        wf->tmin[i] = r->tmin, wf->tmax[i] = r->tmax;
    }
    bool first_layer = true;
    while (n > 0) {
        if (ctx->ray_count)
            *ctx->ray_count += n;
        if (first_layer) { /* q[k] == active[k] */
            rt_kdtree_intersect_batch(tree, &rb, q, n_old, &hb);
            trace_camera_tiles(wf, tree, n_old, n);
            first_layer = false;
        } else {
            rt_kdtree_intersect_batch(tree, &rb, q, n, &hb);
        }
        size_t n2 = 0;
        for (size_t k = 0; k < n; k++) {
            uint32_t i = q[k];
            wf->layers[i]--;
            if (wf->hprim[i] == RT_NONE) {
                wf->status[i] = LANE_MISS;
                continue;
            }
            rt_hit h = {wf->ht[i], wf->hu[i], wf->hv[i], wf->hprim[i], tree->instance_count ? wf->hinst[i] : 0};
            rt_surface *sf = &wf->sf[i];
            rt_surface_at_shading(ctx, &wf->ps[i].r, &h, sf);
            bool cut = false;
            if (materials[sf->material].alpha_mode != RT_ALPHA_OPAQUE) { /* (opaque: never cut, coverage 1) */
                float coverage;
                cut = rt_surface_cut_away(ctx, sf, &coverage);
                if (!cut && coverage < 1.0f && rt_rng_float(&wf->rng[i]) >= coverage)
                    cut = true; /* stochastic alpha blending, from the path's stream */
            }
            wf->tmin[i] = wf->ps[i].r.tmin = h.t;
            if (!cut)
                wf->status[i] = LANE_SURFACE;
            else if (wf->layers[i] <= 0)
                wf->status[i] = LANE_DEEP;
            else
                q2[n2++] = i;
        }
        uint32_t *t = q;
        q = q2;
        q2 = t;
        n = n2;
    }
}

/* Shadow-ray bundles: the shadow rays of one camera tile's first hits to
 * one light (lights 0 .. BUNDLE_SOURCES - 2) or to the sampled emitter
 * (BUNDLE_SOURCES - 1) share an end point or a small end region: one
 * frustum (shadow_bundles). Environment samples scatter and are not
 * bundled. */
enum { BUNDLE_SOURCES = 8, SRC_NONE = 0xff, SRC_DONE = 0xfe };

/* One light-sampling record made at lane i's vertex (from light `src`, or
 * lights: the environment, lights + 1: the emitter table): its visibility
 * now (shadows that need shading) or its shadow ray queued for the batch. */
static void add_record(rt_wavefront *wf, const rt_trace_ctx *ctx, const rt_path_state *ps, const rt_surface *sf,
                       uint32_t r, size_t src, size_t *n_pending)
{
    const rt_nee_record *rec = &wf->rec[r];
    const size_t lights = ctx->state->scene->light_count;
    wf->rec_src[r] = src < lights && src < BUNDLE_SOURCES - 1 ? (uint8_t)src
                     : src == lights + 1                      ? BUNDLE_SOURCES - 1
                                                              : SRC_NONE;
    if (ctx->state->shadows_need_shading) {
        wf->vis[r] = rt_path_shadow(ctx, ps, sf, rec);
        return;
    }
    rt_ray sr = rt_shadow_ray(ctx, sf, rec->wi, rec->dist);
    wf->sox[r] = sr.org.x, wf->soy[r] = sr.org.y, wf->soz[r] = sr.org.z;
    wf->sdx[r] = sr.dir.x, wf->sdy[r] = sr.dir.y, wf->sdz[r] = sr.dir.z;
    wf->stmin[r] = sr.tmin, wf->stmax[r] = sr.tmax;
    wf->pending[(*n_pending)++] = r;
}

/* The shadow rays of the first hits of the camera tiles at active[from ..
 * to), source by source, as frustum bundles (rt_kdtree_occluded_frustum:
 * rt_kdtree_occluded's answers); their visibility is set and they leave
 * the pending list, whose new length is returned. */
static size_t shadow_bundles(rt_wavefront *wf, const rt_kdtree *tree, size_t from, size_t to, size_t n_pending)
{
    uint32_t bucket[BUNDLE_SOURCES][RT_KD_FRUSTUM_MAX];
    rt_ray rays[RT_KD_FRUSTUM_MAX];
    bool any = false;
    for (size_t a = from; a < to;) {
        size_t b = group_end(wf, a, to);
        int cnt[BUNDLE_SOURCES] = {0};
        for (size_t p = a; p < b; p++) {
            uint32_t i = wf->active[p];
            if (!wf->nee[i])
                continue;
            for (uint32_t r = wf->rec_first[i], e = r + wf->rec_count[i]; r < e; r++)
                if (wf->rec_src[r] < BUNDLE_SOURCES)
                    bucket[wf->rec_src[r]][cnt[wf->rec_src[r]]++] = r;
        }
        for (int src = 0; src < BUNDLE_SOURCES; src++) {
            int n = cnt[src];
            if (n < TILE_MIN_RAYS)
                continue;
            for (int j = 0; j < n; j++) {
                uint32_t r = bucket[src][j];
                rays[j] = rt_ray_make(rt_v3(wf->sox[r], wf->soy[r], wf->soz[r]),
                                      rt_v3(wf->sdx[r], wf->sdy[r], wf->sdz[r]), wf->stmin[r], wf->stmax[r]);
            }
            uint64_t blocked = rt_kdtree_occluded_frustum(tree, rays, n);
            for (int j = 0; j < n; j++) {
                uint32_t r = bucket[src][j];
                wf->vis[r] = rt_v3s((blocked >> j) & 1 ? 0.0f : 1.0f);
                wf->rec_src[r] = SRC_DONE;
            }
            wf->stats.bundles++;
            wf->stats.bundle_rays += (uint64_t)n;
            any = true;
        }
        a = b;
    }
    if (!any)
        return n_pending;
    size_t kept = 0;
    for (size_t k = 0; k < n_pending; k++)
        if (wf->rec_src[wf->pending[k]] != SRC_DONE)
            wf->pending[kept++] = wf->pending[k];
    return kept;
}

/* Lane i's vertex into the next slot of its kind's lanes: its frame,
 * geometric normal, throughput and the kind's parameters, and the random
 * numbers of its sample, drawn now as rt_path_vertex_end draws them. */
static struct kind_lanes *kind_lanes_of(rt_wavefront *wf, int kind)
{
    return &wf->kl[kind == RT_BSDF_KIND_LAMBERT     ? LANES_LAMBERT
                   : kind == RT_BSDF_KIND_CONDUCTOR ? LANES_CONDUCTOR
                   : kind == RT_BSDF_KIND_GLTF      ? LANES_GLTF
                   : kind == RT_BSDF_KIND_PLASTIC   ? LANES_PLASTIC
                                                    : LANES_DIELECTRIC];
}

static void lanes_gather(rt_wavefront *wf, const rt_trace_ctx *ctx, uint32_t i, const rt_bsdf *b, rt_vec3 wo,
                         int kind)
{
    struct kind_lanes *kl = kind_lanes_of(wf, kind);
    rt_shade_lanes *l = kl->soa;
    size_t k = kl->n++;
    rt_path_state *ps = &wf->ps[i];
    rt_path_bsdf_draw *d = &kl->draw[k];
    rt_path_bsdf_draw_of(ctx, ps, &wf->rng[i], b->kind, d);
    kl->lane[k] = i;
    l->tx[k] = b->t.x, l->ty[k] = b->t.y, l->tz[k] = b->t.z;
    l->bx[k] = b->b.x, l->by[k] = b->b.y, l->bz[k] = b->b.z;
    l->nx[k] = b->n.x, l->ny[k] = b->n.y, l->nz[k] = b->n.z;
    l->gx[k] = wf->sf[i].ng.x, l->gy[k] = wf->sf[i].ng.y, l->gz[k] = wf->sf[i].ng.z;
    l->br[k] = ps->beta.x, l->bg[k] = ps->beta.y, l->bb[k] = ps->beta.z;
    l->ux[k] = d->u.x, l->uy[k] = d->u.y;
    l->px[k] = wf->sf[i].p.x, l->py[k] = wf->sf[i].p.y, l->pz[k] = wf->sf[i].p.z;
    l->ox[k] = wo.x, l->oy[k] = wo.y, l->oz[k] = wo.z;
    if (kind != RT_BSDF_KIND_CONDUCTOR)
        l->dr[k] = b->diffuse.x, l->dg[k] = b->diffuse.y, l->db[k] = b->diffuse.z;
    if (kind == RT_BSDF_KIND_LAMBERT)
        return;
    l->ax[k] = b->alpha, l->ay[k] = b->alpha_y;
    if (kind == RT_BSDF_KIND_CONDUCTOR) {
        l->sep[k] = b->separable ? 1.0f : 0.0f;
        l->er[k] = b->eta_c.x, l->eg[k] = b->eta_c.y, l->eb[k] = b->eta_c.z;
        l->kr[k] = b->k_c.x, l->kg[k] = b->k_c.y, l->kb[k] = b->k_c.z;
    } else if (kind == RT_BSDF_KIND_GLTF) {
        l->cr[k] = b->base.x, l->cg[k] = b->base.y, l->cb[k] = b->base.z;
        l->metal[k] = b->metallic, l->f0[k] = b->f0;
        l->pd[k] = b->p_d, l->ps[k] = b->p_s, l->ulobe[k] = d->ulobe;
    } else if (kind == RT_BSDF_KIND_PLASTIC) {
        l->pd[k] = b->p_d, l->ps[k] = b->p_s, l->ulobe[k] = d->ulobe;
        l->eta[k] = b->eta, l->smooth[k] = b->delta ? 1.0f : 0.0f;
    } else {
        l->pd[k] = b->p_d, l->ps[k] = b->p_s, l->pt[k] = b->p_t, l->ulobe[k] = d->ulobe;
        l->eta[k] = b->eta;
    }
}

/* One path at its vertex: the scalar tracer's loop body up to its shadow
 * rays, then BSDF sampling (rt/render/pathtrace.h). */
static void shade_lane(rt_wavefront *wf, const rt_trace_ctx *ctx, uint32_t i, size_t *n_rec, size_t *n_pending,
                       bool env, bool emitters)
{
    rt_path_state *ps = &wf->ps[i];
    rt_rng *rng = &wf->rng[i];
    wf->nee[i] = 0;
    uint8_t st = wf->status[i];
    if (st != LANE_SURFACE) {
        if (st == LANE_MISS)
            rt_path_miss(ctx, ps);
        wf->status[i] = LANE_DONE;
        return;
    }
    const rt_surface *sf = &wf->sf[i];
    rt_bsdf b;
    rt_vec3 wo;
    rt_path_vertex v = rt_path_vertex_begin(ctx, ps, sf, &b, &wo);
    if (v != RT_VERTEX_SHADE) { /* the path ends, or passes a false intersection straight on */
        wf->status[i] = v == RT_VERTEX_PASS ? LANE_LIVE : LANE_DONE;
        return;
    }
    size_t first = *n_rec, n = first;
    const size_t lights = ctx->state->scene->light_count;
    int lanes = rt_shade_lanes_kind(&b);
    if (lanes >= 0 && lanes != RT_BSDF_KIND_DIELECTRIC) {
        /* light and environment samples in lanes (nee_lanes): their
         * values drawn now, in order, a record kept for each */
        struct kind_lanes *kl = kind_lanes_of(wf, lanes);
        size_t k = kl->n;
        for (size_t l = 0; l < lights; l++) {
            kl->lu[k * lights + l] = rt_path_light_u(ctx, ps, rng, l);
            kl->lrec[k * lights + l] = (uint32_t)n++;
        }
        if (env) {
            kl->eok[k] = rt_path_env_sample(ctx, ps, rng, &kl->ed[k], &kl->epdf[k]);
            kl->erec[k] = (uint32_t)n++;
        }
    } else {
        for (size_t l = 0; l < lights; l++)
            if (rt_path_nee_light(ctx, ps, sf, &b, wo, rng, l, &wf->rec[n]))
                add_record(wf, ctx, ps, sf, (uint32_t)n++, l, n_pending);
        /* (skipped when they could make nothing: they would draw nothing) */
        if (env && rt_path_nee_env(ctx, ps, &b, wo, rng, &wf->rec[n]))
            add_record(wf, ctx, ps, sf, (uint32_t)n++, lights, n_pending);
    }
    if (emitters && rt_path_nee_emitter(ctx, ps, sf, &b, wo, rng, &wf->rec[n]))
        add_record(wf, ctx, ps, sf, (uint32_t)n++, lights + 1, n_pending);
    *n_rec = n;
    wf->nee[i] = 1;
    wf->rec_first[i] = (uint32_t)first;
    wf->rec_count[i] = (uint32_t)(n - first);
    wf->nbr[i] = ps->beta.x, wf->nbg[i] = ps->beta.y, wf->nbb[i] = ps->beta.z;
    if (lanes >= 0) { /* sampled with the others of its kind, in lanes */
        lanes_gather(wf, ctx, i, &b, wo, lanes);
        return;
    }
    wf->status[i] = rt_path_vertex_end(ctx, ps, sf, &b, wo, rng) ? LANE_LIVE : LANE_DONE;
}

/* Kind c's vertices' light samples, light by light in SIMD lanes
 * (rt_path_nee_light's steps, the same bits), into the records shade_lane
 * kept for them: a record that can contribute gets its shadow ray (or
 * its visibility), one that cannot gets visibility 0, which
 * rt_path_nee_add skips as the scalar tracer skips a record it never made. */
static void nee_lanes(rt_wavefront *wf, const rt_trace_ctx *ctx, int c, bool env, size_t *n_pending)
{
    static const int kinds[] = {RT_BSDF_KIND_LAMBERT, RT_BSDF_KIND_CONDUCTOR, RT_BSDF_KIND_GLTF, RT_BSDF_KIND_PLASTIC};
    struct kind_lanes *kl = &wf->kl[c];
    rt_shade_lanes *l = kl->soa;
    const size_t lights = ctx->state->scene->light_count;
    if (env) { /* the environment: its radiance 1 here, times the image's after (f 1 Le = f Le) */
        for (size_t k = 0; k < kl->n; k++) {
            l->lwx[k] = kl->ed[k].x, l->lwy[k] = kl->ed[k].y, l->lwz[k] = kl->ed[k].z;
            l->ldist[k] = INFINITY, l->lr[k] = l->lg[k] = l->lb[k] = 1.0f;
            l->lpdf[k] = kl->epdf[k], l->lok[k] = kl->eok[k];
        }
        rt_nee_eval_lanes(l, kinds[c], true, kl->n);
        for (size_t k = 0; k < kl->n; k++) {
            uint32_t i = kl->lane[k], r = kl->erec[k];
            if (!l->rok[k]) {
                wf->vis[r] = rt_v3s(0.0f);
                wf->rec_src[r] = SRC_NONE; /* no shadow ray: not in a bundle */
                continue;
            }
            rt_vec3 Le = rt_environment(ctx->state->scene, kl->ed[k]);
            wf->rec[r] = (rt_nee_record){.fl = rt_mul(rt_v3(l->fr[k], l->fg[k], l->fb[k]), Le), .cos = l->fcos[k],
                                         .w = l->fw[k], .pdf = kl->epdf[k], .wi = kl->ed[k], .dist = INFINITY};
            add_record(wf, ctx, &wf->ps[i], &wf->sf[i], r, lights, n_pending);
        }
    }
    for (size_t j = 0; j < lights; j++) {
        const rt_light *lt = &ctx->state->scene->lights[j];
        for (size_t k = 0; k < kl->n; k++)
            l->lux[k] = kl->lu[k * lights + j].x, l->luy[k] = kl->lu[k * lights + j].y;
        rt_light_sample_lanes(l, ctx, lt, kl->n);
        rt_nee_eval_lanes(l, kinds[c], lt->kind == RT_LIGHT_AREA && lt->quad != RT_NONE, kl->n);
        for (size_t k = 0; k < kl->n; k++) {
            uint32_t i = kl->lane[k], r = kl->lrec[k * lights + j];
            if (!l->rok[k]) {
                wf->vis[r] = rt_v3s(0.0f);
                wf->rec_src[r] = SRC_NONE;
                continue;
            }
            wf->rec[r] = (rt_nee_record){.fl = rt_v3(l->fr[k], l->fg[k], l->fb[k]), .cos = l->fcos[k],
                                         .w = l->fw[k], .pdf = 1.0f, .wi = rt_v3(l->lwx[k], l->lwy[k], l->lwz[k]),
                                         .dist = l->ldist[k]};
            add_record(wf, ctx, &wf->ps[i], &wf->sf[i], r, j, n_pending);
        }
    }
}

/* Each kind's vertices' light samples and BSDF samples in SIMD lanes,
 * then each path's roulette and next ray: rt_path_vertex_end's steps, the
 * same bits. */
static void shade_lanes(rt_wavefront *wf, const rt_trace_ctx *ctx, bool env, size_t *n_pending)
{
    for (int c = 0; c < LANE_KINDS; c++) {
        struct kind_lanes *kl = &wf->kl[c];
        rt_shade_lanes *l = kl->soa;
        if (kl->n == 0)
            continue;
        if (c != LANES_DIELECTRIC)
            nee_lanes(wf, ctx, c, env, n_pending);
        if (c == LANES_LAMBERT)
            rt_lambert_sample_lanes(l, kl->n);
        else if (c == LANES_CONDUCTOR)
            rt_conductor_sample_lanes(l, kl->n);
        else if (c == LANES_GLTF)
            rt_gltf_sample_lanes(l, kl->n);
        else if (c == LANES_PLASTIC)
            rt_plastic_sample_lanes(l, kl->n);
        else
            rt_dielectric_sample_lanes(l, kl->n);
        const rt_material *materials = ctx->state->scene->materials;
        for (size_t k = 0; k < kl->n; k++) {
            uint32_t i = kl->lane[k];
            rt_path_state *ps = &wf->ps[i];
            bool live = false;
            if (l->ok[k]) {
                const rt_surface *sf = &wf->sf[i];
                ps->beta = rt_v3(l->br[k], l->bg[k], l->bb[k]);
                if (l->down[k]) { /* refracted (glass only): into or out of its medium */
                    rt_medium_cross(&ps->media, materials, sf->material, sf->front);
                    ps->eta_scale /= l->eta[k] * l->eta[k];
                }
                live = rt_path_vertex_advance(ctx, ps, sf, &wf->rng[i], &kl->draw[k],
                                              rt_v3(l->wx[k], l->wy[k], l->wz[k]), l->pdf[k], l->delta[k],
                                              false);
            }
            wf->status[i] = live ? LANE_LIVE : LANE_DONE;
        }
        kl->n = 0;
    }
}

/* The active lanes in shading order: surfaces grouped by material kind
 * (a stable counting sort), the rest first. */
static void shading_order(rt_wavefront *wf, const rt_scene *s, size_t n)
{
    size_t count[KIND_BUCKETS + 2] = {0};
    for (size_t k = 0; k < n; k++) {
        uint32_t i = wf->active[k];
        size_t key = 0;
        if (wf->status[i] == LANE_SURFACE) {
            size_t kind = (size_t)s->materials[wf->sf[i].material].bsdf;
            key = 1 + (kind < KIND_BUCKETS ? kind : KIND_BUCKETS - 1);
        }
        wf->queue[k] = (uint32_t)key;
        count[key + 1]++;
    }
    for (size_t b = 1; b < KIND_BUCKETS + 2; b++)
        count[b] += count[b - 1];
    for (size_t k = 0; k < n; k++)
        wf->order[count[wf->queue[k]]++] = wf->active[k];
}

void rt_wavefront_radiance(rt_wavefront *wf, const rt_trace_ctx *ctx, const rt_wavefront_work *wk, float *out)
{
    const rt_scene *s = ctx->state->scene;
    const bool tiles = tiles_pay(ctx->state->tree);
    cam_cursor cam;
    cam_cursor_init(&cam, wk, tiles);
    size_t n_active = 0, n_free = wf->batch;
    for (size_t k = 0; k < wf->batch; k++)
        wf->free_lanes[k] = (uint32_t)(wf->batch - 1 - k);
    rt_ray_batch srb = {wf->sox, wf->soy, wf->soz, wf->sdx, wf->sdy, wf->sdz, wf->stmin, wf->stmax};
    const bool env = rt_path_samples_env(ctx), emitters = rt_path_samples_emitters(ctx);
    for (;;) {
        /* refill: free lanes take the next camera samples, tile by tile */
        const size_t n_old = n_active;
        uint32_t sample;
        while (n_free > 0 && cam_cursor_next(&cam, &sample)) {
            uint32_t i = wf->free_lanes[n_free - 1];
            if (start_path(wf, ctx, wk, i, sample, out)) {
                wf->cam_group[n_active] = cam.group;
                wf->active[n_active++] = i;
                n_free--;
            }
        }
        if (n_active == 0)
            break;
        trace_stage(wf, ctx, n_active, tiles ? n_old : n_active);
        /* shade, grouped by material kind */
        shading_order(wf, s, n_active);
        size_t n_rec = 0, n_pending = 0;
        for (size_t k = 0; k < n_active; k++)
            shade_lane(wf, ctx, wf->order[k], &n_rec, &n_pending, env, emitters);
        shade_lanes(wf, ctx, env, &n_pending);
        /* shadow rays, one batch */
        if (ctx->ray_count)
            *ctx->ray_count += n_pending;
        if (n_pending > 0 && tiles)
            n_pending = shadow_bundles(wf, ctx->state->tree, n_old, n_active, n_pending);
        if (n_pending > 0) {
            rt_kdtree_occluded_batch(ctx->state->tree, &srb, wf->pending, n_pending, wf->blocked);
            for (size_t k = 0; k < n_pending; k++) {
                uint32_t r = wf->pending[k];
                wf->vis[r] = rt_v3s(wf->blocked[r] ? 0.0f : 1.0f);
            }
        }
        /* resolve the light samples, retire finished paths, keep the rest in order */
        size_t kept = 0;
        for (size_t k = 0; k < n_active; k++) {
            uint32_t i = wf->active[k];
            if (wf->nee[i]) {
                rt_vec3 sum = rt_v3s(0.0f);
                for (uint32_t r = wf->rec_first[i], e = r + wf->rec_count[i]; r < e; r++)
                    sum = rt_path_nee_add(sum, &wf->rec[r], wf->vis[r]);
                wf->ps[i].L = rt_path_add_finite(wf->ps[i].L, rt_mul(rt_v3(wf->nbr[i], wf->nbg[i], wf->nbb[i]), sum));
            }
            if (wf->status[i] == LANE_DONE) {
                rt_vec3 L = wf->ps[i].L;
                put_out(out, wf->out[i], rt_finite3(L) ? L : rt_v3s(0.0f));
                wf->free_lanes[n_free++] = i;
            } else {
                wf->status[i] = LANE_TRACE;
                wf->active[kept++] = i;
            }
        }
        n_active = kept;
    }
}
