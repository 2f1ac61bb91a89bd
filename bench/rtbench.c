/* rtbench - ray throughput of rt's kd-tree on the shared benchmark rays,
 * checked against Embree's reference hits.
 *
 *   rtbench MODEL.glb RAYS.rays [--ref HITS.hits] [-t THREADS] [--runs K]
 *           [--build-threads N] [--occluded] [--portable] [--instances] [--write-scene FILE] [--limit N]
 *           [--packets W H [--image-width N] [--lanes 8|16]] [--frustum W H [--image-width N]]
 *           [--stream [--lanes 4|8|16] [--stream-size N] [--min-rays N] [--chunk N]] [--simd 8|16]
 *
 * Loads the model with rt_load, as `rt` does (a glTF: every triangle of
 * the default scene in world space, as ../shared/bench/FORMAT.md defines;
 * any other input rt reads works too), builds the kd-tree (N build threads,
 * default one per core), traces every ray for the closest hit K times and
 * prints `key: value` lines: triangles, load_ms, build_ms, nodes and leaves
 * (of the binary tree the build makes), wide_nodes (the 64-byte nodes of
 * three levels that the traversal reads), bytes_per_triangle, mrays_per_s (median of K runs, wall clock),
 * mrays_per_s_best (the fastest run), cpu_mrays_per_s (rays per CPU-second
 * of the median run, summed over threads: on a shared, loaded machine this
 * is the steadier figure), hits, thread_cpu_s and thread_rays (each
 * thread's CPU seconds and rays over all runs: how evenly the threads
 * shared the work), mismatches. With --occluded the same rays
 * go through the any-hit query (shadow rays) instead, and a mismatch is a
 * ray whose hit/miss differs from the reference. Exits 1 when more than
 * 0.01% of the rays disagree with the reference: speed bought with wrong
 * answers does not count. --portable: the portable traversal even when
 * the CPU has AVX2 (traversal: says which one ran). The model is loaded
 * as ../shared/bench/FORMAT.md defines the rays' scene, every triangle in
 * world space, as Embree's single-level BVH sees it; --instances keeps a
 * glTF's meshes used more than once as objects placed by instances instead
 * (rt/scene/instance.h; packets, frustum tiles and streams enter them as
 * sub-packets and sub-streams); --write-scene FILE writes the loaded
 * scene's triangles, objects and instances' transforms for the Embree
 * side of make bench-instances (bench/embree_instances.c). --limit N keeps N rays spread evenly over the set
 * (every count/N-th, with its reference hit): a fixed small subset for
 * instruction counts under callgrind. --packets W H traces the set (a
 * primary set: one ray per pixel, row by row, N pixels wide, default 640)
 * in tiles of W x H pixels (W H = 4 2 or 4 4; at most 64 rays), 16 rays at
 * a time with rt_kdtree_intersect16 (kdtree_packet.h) when a tile has 16
 * or more, else 8 with rt_kdtree_intersect8 (--lanes 8|16 chooses), or
 * with --occluded the any-hit calls; the answers must be the same.
 * --frustum W H traces the same tiles (at most 64 rays) a tile a call
 * with rt_kdtree_intersect_frustum (kdtree_frustum.h: the tile's rays as
 * one frustum), or with --occluded rt_kdtree_occluded_frustum.
 * --stream traces the set in file order as ray streams
 * (rt_kdtree_intersect_stream / rt_kdtree_occluded_stream,
 * kdtree_stream.h) of N rays a call (--stream-size, default 4096, as
 * Embree's anchor calls rtcIntersect1M), each thread taking the next call's
 * rays; --lanes chooses the SIMD width (default the widest the CPU runs;
 * stream_lanes: says which ran), --min-rays and --chunk the stream's
 * parameters (kd_stream_params). The rays are copied into the stream's
 * arrays before the clock starts. --simd 8|16: the SIMD width of the
 * packets and frustum tiles (rt_kdtree_params.lanes; default the widest
 * the CPU runs; packet_simd: says which ran, 0 for single rays). Exit 2
 * on bad arguments or files.
 */
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rt/base/log.h"
#include "rt/io/load.h"
#include "rt/scene/instance.h"
#include "rt/accel/kdtree.h"
#include "rt/accel/kdtree_frustum.h"
#include "rt/accel/kdtree_packet.h"
#include "rt/accel/kdtree_stream.h"
#include "rt/accel/rayset.h"
#include "rt/scene/scene.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct job {
    const rt_kdtree *tree;
    const rt_rayset *rays;
    float *t_out;
    bool occluded;
    const size_t *order; /* packets: ray indices tile by tile, pack rays a tile (NULL: single rays) */
    size_t pack;
    int lanes; /* packets: rays a call, 8 or 16 */
    bool frustum; /* packets: the whole tile a call as a frustum */
    const rt_ray_batch *stream; /* streams: the rays as arrays (NULL: not streams) */
    rt_hit_batch stream_hits;
    uint8_t *blocked;
    rt_kd_stream_params stream_params;
    size_t step; /* the most rays a thread takes at a time */
    size_t step_min; /* the fewest (at the end of a pass), a multiple of every tile size */
    int threads;
    bool quit; /* the pool's threads return at the next start */
    pthread_barrier_t start, end; /* a pass starts when every thread is running, ends when all are done */
    /* the next ray to hand out, alone on its cache line (the fields above
     * are read all through the pass) */
    _Alignas(64) atomic_size_t next;
    char pad[64 - sizeof(atomic_size_t)];
} job;

/* One thread of the pass: the job, the thread's number, and its CPU
 * seconds and rays over the timed passes, on a cache line of its own. */
typedef struct worker {
    _Alignas(64) job *j;
    int index;
    double cpu;
    size_t rays;
} worker;

/* The rays of one tile, j->lanes (8 or 16) at a time. */
static void trace_tile(const job *j, const size_t *idx, size_t n)
{
    if (j->frustum) {
        rt_ray r[RT_KD_FRUSTUM_MAX];
        rt_hit h[RT_KD_FRUSTUM_MAX];
        for (size_t i = 0; i < n; i++)
            r[i] = j->rays->rays[idx[i]];
        uint64_t hit = j->occluded ? rt_kdtree_occluded_frustum(j->tree, r, (int)n)
                                   : rt_kdtree_intersect_frustum(j->tree, r, (int)n, h);
        for (size_t i = 0; i < n; i++) /* occluded: hit/miss only, 0 for a hit */
            j->t_out[idx[i]] = !(hit >> i & 1) ? INFINITY : j->occluded ? 0.0f : h[i].t;
        return;
    }
    for (size_t g = 0; g < n; g += (size_t)j->lanes) {
        int m = n - g < (size_t)j->lanes ? (int)(n - g) : j->lanes;
        rt_ray r[16];
        rt_hit h[16];
        for (int i = 0; i < m; i++)
            r[i] = j->rays->rays[idx[g + (size_t)i]];
        if (j->occluded) { /* hit/miss only: 0 for a hit */
            unsigned hit = m > 8 ? rt_kdtree_occluded16(j->tree, r, m) : rt_kdtree_occluded8(j->tree, r, m);
            for (int i = 0; i < m; i++)
                j->t_out[idx[g + (size_t)i]] = (hit >> i & 1) ? 0.0f : INFINITY;
            continue;
        }
        unsigned hit = m > 8 ? rt_kdtree_intersect16(j->tree, r, m, h) : rt_kdtree_intersect8(j->tree, r, m, h);
        for (int i = 0; i < m; i++)
            j->t_out[idx[g + (size_t)i]] = (hit >> i & 1) ? h[i].t : INFINITY;
    }
}

enum { CHUNK = 1024, CHUNK_MIN = 64 };

static double thread_cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The next rays for a thread, [start, *end): guided, half of what is left
 * shared among the threads, at most j->step and at least j->step_min (a
 * multiple of it), so the threads finish together instead of one running
 * a whole last chunk alone. start == *end: the pass is done. */
static size_t grab(job *j, size_t *end)
{
    size_t n = j->rays->count, s = atomic_load_explicit(&j->next, memory_order_relaxed);
    for (;;) {
        if (s >= n) {
            *end = s;
            return s;
        }
        size_t take = (n - s) / (2 * (size_t)j->threads);
        take = take >= j->step ? j->step : take < j->step_min ? j->step_min : take / j->step_min * j->step_min;
        if (atomic_compare_exchange_weak_explicit(&j->next, &s, s + take, memory_order_relaxed,
                                                  memory_order_relaxed)) {
            *end = s + take < n ? s + take : n;
            return s;
        }
    }
}

/* One thread's part of a pass. */
static void trace_part(worker *wk)
{
    job *j = wk->j;
    double c0 = thread_cpu_s();
    for (;;) {
        size_t end, start = grab(j, &end);
        if (start >= end)
            break;
        wk->rays += end - start;
        if (j->stream) { /* one stream call: the arrays from `start` on */
            const rt_ray_batch *b = j->stream;
            rt_ray_batch rb = {b->ox + start, b->oy + start, b->oz + start, b->dx + start, b->dy + start,
                               b->dz + start, b->tmin + start, b->tmax + start};
            if (j->occluded) {
                rt_kdtree_occluded_stream(j->tree, &rb, end - start, j->blocked + start, &j->stream_params);
                for (size_t i = start; i < end; i++)
                    j->t_out[i] = j->blocked[i] ? 0.0f : INFINITY;
            } else {
                const rt_hit_batch *h = &j->stream_hits;
                rt_hit_batch hb = {h->t + start, h->u + start, h->v + start, h->prim + start, NULL};
                rt_kdtree_intersect_stream(j->tree, &rb, end - start, &hb, &j->stream_params);
                for (size_t i = start; i < end; i++)
                    j->t_out[i] = h->prim[i] != RT_NONE ? h->t[i] : INFINITY;
            }
        } else if (j->order) { /* grabs are multiples of every tile size */
            for (size_t i = start; i < end; i += j->pack)
                trace_tile(j, j->order + i, end - i < j->pack ? end - i : j->pack);
        } else if (j->occluded) {
            for (size_t i = start; i < end; i++) /* hit/miss only: 0 for a hit */
                j->t_out[i] = rt_kdtree_occluded(j->tree, &j->rays->rays[i]) ? 0.0f : INFINITY;
        } else {
            for (size_t i = start; i < end; i++) {
                rt_hit h;
                j->t_out[i] = rt_kdtree_intersect(j->tree, &j->rays->rays[i], &h) ? h.t : INFINITY;
            }
        }
    }
    wk->cpu += thread_cpu_s() - c0;
}

/* A thread of the pool: a part of every pass, until quit. */
static void *pool_worker(void *arg)
{
    worker *wk = arg;
    for (;;) {
        pthread_barrier_wait(&wk->j->start);
        if (wk->j->quit)
            return NULL;
        trace_part(wk);
        pthread_barrier_wait(&wk->j->end);
    }
}

/* Wall seconds of one pass, from when every thread runs until all are
 * done; *cpu gets the CPU seconds of the process over it. */
static double trace_all(job *j, worker *wk, double *cpu)
{
    atomic_store(&j->next, 0);
    double c0 = cpu_s();
    pthread_barrier_wait(&j->start);
    double t0 = now_s();
    trace_part(&wk[0]);
    pthread_barrier_wait(&j->end);
    double wall = now_s() - t0;
    *cpu = cpu_s() - c0;
    return wall;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* --write-scene FILE: the loaded scene as bench/embree_instances.c reads
 * it (little endian): "RTINST01"; u64 n and n x 9 float32 (the world
 * triangles: those of no object); u64 objects, each u64 n and n x 9
 * float32 (object space); u64 instances, each u32 object, u32 0 and 12
 * float32 (rows 0-2 of to_world, row major). Returns false on a write
 * error. */
static bool write_triangles(FILE *f, const rt_scene *s, size_t first, size_t n)
{
    uint64_t c = n;
    bool ok = fwrite(&c, 8, 1, f) == 1;
    for (size_t t = first; t < first + n && ok; t++)
        for (int k = 0; k < 3 && ok; k++) {
            rt_vec3 v = rt_tri_vertex(s, t, k);
            float xyz[3] = {v.x, v.y, v.z};
            ok = fwrite(xyz, sizeof xyz, 1, f) == 1;
        }
    return ok;
}

static bool write_scene(const char *path, const rt_scene *s)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return false;
    bool ok = fwrite("RTINST01", 1, 8, f) == 8;
    /* the world triangles: objects' triangles are contiguous ranges */
    size_t in_objects = 0;
    for (size_t o = 0; o < s->object_count; o++)
        in_objects += s->objects[o].triangle_count;
    uint64_t world = s->triangles.count - in_objects;
    ok = ok && fwrite(&world, 8, 1, f) == 1;
    for (size_t t = 0; t < s->triangles.count && ok; t++) {
        bool obj = false;
        for (size_t o = 0; o < s->object_count; o++)
            obj |= t >= s->objects[o].first_triangle && t < s->objects[o].first_triangle + s->objects[o].triangle_count;
        for (int k = 0; k < 3 && ok && !obj; k++) {
            rt_vec3 v = rt_tri_vertex(s, t, k);
            float xyz[3] = {v.x, v.y, v.z};
            ok = fwrite(xyz, sizeof xyz, 1, f) == 1;
        }
    }
    uint64_t objects = s->object_count, instances = s->instance_count;
    ok = ok && fwrite(&objects, 8, 1, f) == 1;
    for (size_t o = 0; o < s->object_count && ok; o++)
        ok = write_triangles(f, s, s->objects[o].first_triangle, s->objects[o].triangle_count);
    ok = ok && fwrite(&instances, 8, 1, f) == 1;
    for (size_t i = 0; i < s->instance_count && ok; i++) {
        uint32_t head[2] = {s->instances[i].object, 0};
        float m[12];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 4; c++)
                m[4 * r + c] = s->instances[i].to_world.m[r][c];
        ok = fwrite(head, sizeof head, 1, f) == 1 && fwrite(m, sizeof m, 1, f) == 1;
    }
    return fclose(f) == 0 && ok;
}

static int usage(void)
{
    fprintf(stderr, "usage: rtbench MODEL.glb RAYS.rays [--ref HITS.hits] [-t THREADS] [--runs K] [--build-threads N] "
                    "[--occluded] [--portable] [--instances] [--write-scene FILE] [--limit N] [--packets W H [--image-width N] [--lanes 8|16]] "
                    "[--frustum W H] [--stream [--lanes 4|8|16] [--stream-size N] [--min-rays N] [--chunk N]] [--simd 8|16]\n");
    return 2;
}

int main(int argc, char **argv)
{
    const char *model = NULL, *rays_path = NULL, *hits_path = NULL, *scene_out = NULL;
    int threads = 1, runs = 5, build_threads = 0;
    bool flatten = true; /* FORMAT.md's scene: every triangle in world space */
    long limit = 0;
    int pw = 0, ph = 0, image_width = 640, lanes = 0, simd = 0;
    bool occluded = false, portable = false, stream = false, frustum = false;
    long stream_size = 4096, min_rays = 0, chunk = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--ref") == 0 && i + 1 < argc)
            hits_path = argv[++i];
        else if (strcmp(argv[i], "-t") == 0 && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc)
            runs = atoi(argv[++i]);
        else if (strcmp(argv[i], "--build-threads") == 0 && i + 1 < argc)
            build_threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--limit") == 0 && i + 1 < argc)
            limit = atol(argv[++i]);
        else if ((strcmp(argv[i], "--packets") == 0 || strcmp(argv[i], "--frustum") == 0) && i + 2 < argc) {
            if (pw)
                return usage(); /* one of --packets and --frustum, once */
            frustum = argv[i][2] == 'f';
            pw = atoi(argv[++i]);
            ph = atoi(argv[++i]);
            if (pw < 1 || ph < 1 || pw * ph > 64 || 1024 % (pw * ph) != 0)
                return usage();
        } else if (strcmp(argv[i], "--image-width") == 0 && i + 1 < argc)
            image_width = atoi(argv[++i]);
        else if (strcmp(argv[i], "--lanes") == 0 && i + 1 < argc) {
            lanes = atoi(argv[++i]);
            if (lanes != 4 && lanes != 8 && lanes != 16)
                return usage();
        } else if (strcmp(argv[i], "--simd") == 0 && i + 1 < argc) {
            simd = atoi(argv[++i]);
            if (simd != 8 && simd != 16)
                return usage();
        } else if (strcmp(argv[i], "--stream") == 0)
            stream = true;
        else if (strcmp(argv[i], "--stream-size") == 0 && i + 1 < argc)
            stream_size = atol(argv[++i]);
        else if (strcmp(argv[i], "--min-rays") == 0 && i + 1 < argc)
            min_rays = atol(argv[++i]);
        else if (strcmp(argv[i], "--chunk") == 0 && i + 1 < argc)
            chunk = atol(argv[++i]);
        else if (strcmp(argv[i], "--occluded") == 0)
            occluded = true;
        else if (strcmp(argv[i], "--portable") == 0)
            portable = true;
        else if (strcmp(argv[i], "--instances") == 0)
            flatten = false;
        else if (strcmp(argv[i], "--write-scene") == 0 && i + 1 < argc)
            scene_out = argv[++i];
        else if (argv[i][0] == '-')
            return usage();
        else if (!model)
            model = argv[i];
        else if (!rays_path)
            rays_path = argv[i];
        else
            return usage();
    }
    if (!model || !rays_path || threads < 1 || threads > 256 || runs < 1 || runs > 1000 || build_threads < 0 ||
        build_threads > 64 || limit < 0 || image_width < 1 || (pw && limit) || (lanes && !pw && !stream) || (lanes && frustum) ||
        (stream && pw) || (lanes == 4 && !stream) || stream_size < 1 || stream_size > (1L << 24) || min_rays < 0 ||
        min_rays > (1L << 30) || chunk < 0 || chunk > (1L << 24))
        return usage();
    if (pw && !lanes && !frustum) /* 16-ray calls for tiles of 16 rays or more */
        lanes = pw * ph >= 16 ? 16 : 8;
    rt_log_set_level(RT_LOG_QUIET);

    rt_error err = {0};
    rt_scene scene;
    rt_scene_init(&scene);
    double t0 = now_s();
    rt_load_options lo = {.flatten_instances = flatten};
    if (rt_load(&scene, NULL, model, &lo, NULL, &err) != RT_OK) {
        fprintf(stderr, "rtbench: %s\n", err.message);
        return 2;
    }
    double load_ms = 1e3 * (now_s() - t0);
    if (scene_out && !write_scene(scene_out, &scene)) {
        fprintf(stderr, "rtbench: cannot write %s\n", scene_out);
        return 2;
    }
    rt_rayset rs;
    if (rt_rayset_load(&rs, rays_path, hits_path, &err) != RT_OK) {
        fprintf(stderr, "rtbench: %s\n", err.message);
        return 2;
    }
    if (limit > 0 && (size_t)limit < rs.count) { /* every count/limit-th ray, in place */
        for (size_t i = 0; i < (size_t)limit; i++) {
            size_t k = i * rs.count / (size_t)limit;
            rs.rays[i] = rs.rays[k];
            if (rs.ref_t)
                rs.ref_t[i] = rs.ref_t[k];
        }
        rs.count = (size_t)limit;
    }
    rt_kdtree tree;
    rt_kdtree_params params;
    memset(&params, 0, sizeof params);
    params.threads = build_threads;
    params.portable = portable;
    params.lanes = simd;
    if (rt_kdtree_build(&tree, &scene, &params, &err) != RT_OK) {
        fprintf(stderr, "rtbench: %s\n", err.message);
        return 2;
    }
    size_t *order = NULL;
    if (pw) { /* tile by tile (W x H pixels), each tile's rays row by row */
        size_t W = (size_t)image_width, Hh = rs.count / W, k = 0;
        if (Hh * W != rs.count || W % (size_t)pw || Hh % (size_t)ph) {
            fprintf(stderr, "rtbench: %s: %zu rays are not an image %zu wide in %dx%d tiles\n", rays_path, rs.count, W,
                    pw, ph);
            return 2;
        }
        order = malloc(rs.count * sizeof *order);
        if (!order) {
            fprintf(stderr, "rtbench: out of memory\n");
            return 2;
        }
        for (size_t ty = 0; ty < Hh; ty += (size_t)ph)
            for (size_t tx = 0; tx < W; tx += (size_t)pw)
                for (size_t y = ty; y < ty + (size_t)ph; y++)
                    for (size_t x = tx; x < tx + (size_t)pw; x++)
                        order[k++] = y * W + x;
    }
    float *t_out = malloc((rs.count ? rs.count : 1) * sizeof(float));
    double *times = malloc((size_t)runs * sizeof(double)), *cpus = malloc((size_t)runs * sizeof(double));
    if (!t_out || !times || !cpus) {
        fprintf(stderr, "rtbench: out of memory\n");
        return 2;
    }
    job jb;
    memset(&jb, 0, sizeof jb);
    jb.tree = &tree, jb.rays = &rs, jb.t_out = t_out, jb.occluded = occluded, jb.order = order;
    jb.frustum = frustum;
    jb.pack = (size_t)pw * (size_t)ph, jb.lanes = lanes, jb.threads = threads;
    jb.step = CHUNK, jb.step_min = CHUNK_MIN; /* multiples of every tile size (at most 64 rays, dividing 1024) */
    float *soa = NULL;
    rt_ray_batch rb;
    if (stream) { /* the rays as arrays, and the hits' (before the clock) */
        size_t n = rs.count ? rs.count : 1;
        soa = malloc(11 * n * sizeof(float) + n * sizeof(uint32_t) + n);
        if (!soa) {
            fprintf(stderr, "rtbench: out of memory\n");
            return 2;
        }
        float *c[11];
        for (int k = 0; k < 11; k++)
            c[k] = soa + (size_t)k * n;
        for (size_t i = 0; i < rs.count; i++) {
            const rt_ray *r = &rs.rays[i];
            c[0][i] = r->org.x, c[1][i] = r->org.y, c[2][i] = r->org.z, c[3][i] = r->dir.x, c[4][i] = r->dir.y;
            c[5][i] = r->dir.z, c[6][i] = r->tmin, c[7][i] = r->tmax;
        }
        rb = (rt_ray_batch){c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]};
        jb.stream = &rb;
        jb.stream_hits = (rt_hit_batch){c[8], c[9], c[10], (uint32_t *)(void *)(soa + 11 * n), NULL};
        jb.blocked = (uint8_t *)(void *)(soa + 12 * n);
        jb.stream_params = (rt_kd_stream_params){lanes, (int)min_rays, (int)chunk};
        jb.step = (size_t)stream_size;
        jb.step_min = jb.step / 4 ? jb.step / 4 : 1; /* the last calls of a pass: smaller streams */
    }
    /* the threads, started once: every pass is timed from when all of them
     * run (no thread start-up or join in the window), after one warm-up
     * pass that is not (page faults of the outputs, cold caches), as
     * Embree's anchor warms up */
    static worker wk[256];
    pthread_t th[256];
    if (pthread_barrier_init(&jb.start, NULL, (unsigned)threads) != 0 ||
        pthread_barrier_init(&jb.end, NULL, (unsigned)threads) != 0) {
        fprintf(stderr, "rtbench: cannot set up %d threads\n", threads);
        return 2;
    }
    for (int i = 0; i < threads; i++)
        wk[i] = (worker){.j = &jb, .index = i};
    for (int i = 1; i < threads; i++)
        if (pthread_create(&th[i], NULL, pool_worker, &wk[i]) != 0) {
            fprintf(stderr, "rtbench: cannot start %d threads\n", threads);
            return 2;
        }
    double warm;
    trace_all(&jb, wk, &warm);
    for (int i = 0; i < threads; i++)
        wk[i].cpu = 0.0, wk[i].rays = 0;
    for (int r = 0; r < runs; r++)
        times[r] = trace_all(&jb, wk, &cpus[r]);
    jb.quit = true;
    pthread_barrier_wait(&jb.start);
    for (int i = 1; i < threads; i++)
        pthread_join(th[i], NULL);
    pthread_barrier_destroy(&jb.start);
    pthread_barrier_destroy(&jb.end);
    qsort(times, (size_t)runs, sizeof(double), cmp_double);
    qsort(cpus, (size_t)runs, sizeof(double), cmp_double);
    double median = runs % 2 ? times[runs / 2] : 0.5 * (times[runs / 2 - 1] + times[runs / 2]);
    double cpu_median = runs % 2 ? cpus[runs / 2] : 0.5 * (cpus[runs / 2 - 1] + cpus[runs / 2]);

    size_t hits = 0, mismatches = 0;
    float diag = rt_box_diagonal(tree.bounds);
    for (size_t i = 0; i < rs.count; i++) {
        if (t_out[i] < INFINITY)
            hits++;
        if (rs.ref_t && (occluded ? (t_out[i] < INFINITY) != (rs.ref_t[i] < INFINITY)
                                  : !rt_rayset_agrees(t_out[i], rs.ref_t[i], diag)))
            mismatches++;
    }
    printf("model: %s\n", model);
    printf("rays_file: %s\n", rays_path);
    printf("triangles: %zu\n", scene.triangles.count);
    printf("instances: %zu\n", scene.instance_count);
    printf("load_ms: %.1f\n", load_ms);
    printf("build_ms: %.1f\n", tree.stats.build_ms);
    printf("nodes: %zu\n", tree.stats.nodes);
    printf("leaves: %zu\n", tree.stats.leaves);
    printf("wide_nodes: %zu\n", tree.stats.wide_nodes);
    printf("bytes_per_triangle: %.1f\n",
           scene.triangles.count ? (double)tree.stats.bytes / (double)scene.triangles.count : 0.0);
    printf("traversal: %s\n", tree.isa == RT_KD_ISA_AVX2 ? "avx2" : "portable");
    printf("packet_simd: %d\n", tree.lanes);
    printf("threads: %d\n", threads);
    printf("rays: %zu\n", rs.count);
    printf("query: %s\n", occluded ? "occluded" : "closest");
    if (pw && frustum)
        printf("frustum: %dx%d tiles, a tile a call\n", pw, ph);
    else if (pw)
        printf("packets: %dx%d tiles, %d rays a call\n", pw, ph, lanes);
    if (stream) {
        int sl = lanes && rt_kd_stream_lanes_supported(lanes) && (lanes == 4 || tree.isa != RT_KD_ISA_PORTABLE)
                     ? lanes : rt_kd_stream_lanes_best(&tree);
        printf("stream: %ld rays a call, min_rays %d, chunk %d\n", stream_size,
               min_rays ? (int)min_rays : RT_KD_STREAM_MIN_RAYS, chunk ? (int)chunk : RT_KD_STREAM_CHUNK);
        printf("stream_lanes: %d\n", sl);
    }
    printf("mrays_per_s: %.3f\n", median > 0 ? 1e-6 * (double)rs.count / median : 0.0);
    printf("mrays_per_s_best: %.3f\n", times[0] > 0 ? 1e-6 * (double)rs.count / times[0] : 0.0);
    printf("cpu_mrays_per_s: %.3f\n", cpu_median > 0 ? 1e-6 * (double)rs.count / cpu_median : 0.0);
    printf("hits: %zu\n", hits);
    printf("thread_cpu_s:"); /* each thread's CPU seconds and rays, over all runs: how evenly the work split */
    for (int i = 0; i < threads; i++)
        printf(" %.4f", wk[i].cpu);
    printf("\nthread_rays:");
    for (int i = 0; i < threads; i++)
        printf(" %zu", wk[i].rays);
    printf("\n");
    if (rs.ref_t)
        printf("mismatches: %zu\n", mismatches);
    int status = 0;
    if (rs.ref_t && (double)mismatches > 1e-4 * (double)rs.count) {
        fprintf(stderr, "rtbench: %zu of %zu rays disagree with %s (over 0.01%%)\n", mismatches, rs.count, hits_path);
        status = 1;
    }
    free(order);
    free(soa);
    free(t_out);
    free(times);
    free(cpus);
    rt_kdtree_free(&tree);
    rt_rayset_free(&rs);
    rt_scene_free(&scene);
    return status;
}
