/* embree_instances - Intel Embree 3's instances on the scene and rays that
 * bench/rtbench traces, for make bench-instances (bench/instances.py): the
 * Embree side of rt's instanced kd-tree comparison.
 *
 *   embree_instances SCENE.inst RAYS.rays [--flat] [-t THREADS] [--runs K]
 *                    [--mode single|stream|packets] [--image-width N] [--out HITS.hits]
 *
 * SCENE.inst is what `rtbench MODEL RAYS --instances --write-scene
 * SCENE.inst` writes (rt's loaded scene: world triangles, each object's
 * triangles in object space, each instance's object and rt's to_world
 * matrix, rows 0-2; bench/rtbench.c says the layout); RAYS.rays is
 * ../shared/bench/FORMAT.md's. Each object becomes an Embree scene of one
 * triangle geometry, each instance an RTC_GEOMETRY_TYPE_INSTANCE of it
 * with the same transform (RTC_FORMAT_FLOAT3X4_ROW_MAJOR; Embree inverts
 * it itself), in a top-level scene with the world triangles; every scene
 * built with RTC_BUILD_QUALITY_HIGH as the shared Embree anchor's. --flat
 * builds Embree's single-level BVH over every instance's triangles moved
 * to world space instead (Embree's own instanced/flat ratio).
 *
 * The rays are traced closest hit: --mode single with rtcIntersect1,
 * stream with rtcIntersect1M on 4096 rays a call (coherent flag: the
 * primary rays of a camera), packets with rtcIntersect16 on 4x4-pixel
 * tiles of an image --image-width pixels wide (rows of rays); THREADS
 * pthreads take chunks from an atomic counter (as the shared anchor does,
 * with its flush-to-zero settings); K timed runs after a warm-up. Prints
 * `key: value` lines: build_ms, mrays_per_s (median run, wall clock),
 * cpu_mrays_per_s (rays per CPU-second of the median run, summed over
 * threads), hits; --out writes the closest t of each ray (FORMAT.md's
 * .hits, +inf for a miss) for rtbench --ref.
 *
 * Bench code, not part of rt: Embree 3 from Debian's libembree-dev
 * (make bench-instances installs it as make bench-compare does).
 */
#define _GNU_SOURCE
#include <embree3/rtcore.h>
#include <math.h>
#include <pmmintrin.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <xmmintrin.h>

typedef struct RTCRayHit RTCRayHit;
typedef struct RTCRayHit16 RTCRayHit16;
typedef struct RTCIntersectContext RTCIntersectContext;

typedef struct { float ox, oy, oz, dx, dy, dz, tmin, tmax; } ray;

typedef struct tris {
    uint64_t n;
    float *v; /* 9 n */
} tris;

typedef struct inst_scene {
    tris world;
    uint64_t objects, instances;
    tris *object;
    uint32_t *inst_object;
    float *xfm; /* 12 a instance */
} inst_scene;

static void die(const char *what, const char *path)
{
    fprintf(stderr, "embree_instances: %s%s%s\n", what, path ? ": " : "", path ? path : "");
    exit(2);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double thread_cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void read_exact(FILE *f, void *p, size_t bytes, const char *path)
{
    if (bytes && fread(p, 1, bytes, f) != bytes)
        die("short file", path);
}

static void read_tris(FILE *f, tris *t, const char *path)
{
    read_exact(f, &t->n, 8, path);
    if (t->n > (1ull << 32))
        die("bad triangle count", path);
    t->v = malloc(t->n * 9 * sizeof(float) + 16);
    if (!t->v)
        die("out of memory", NULL);
    read_exact(f, t->v, t->n * 9 * sizeof(float), path);
}

static void read_scene(const char *path, inst_scene *s)
{
    FILE *f = fopen(path, "rb");
    char magic[8];
    if (!f)
        die("cannot open", path);
    read_exact(f, magic, 8, path);
    if (memcmp(magic, "RTINST01", 8))
        die("not a scene written by rtbench --write-scene", path);
    read_tris(f, &s->world, path);
    read_exact(f, &s->objects, 8, path);
    if (s->objects > (1u << 24))
        die("bad object count", path);
    s->object = calloc(s->objects + 1, sizeof *s->object);
    for (uint64_t o = 0; o < s->objects; o++)
        read_tris(f, &s->object[o], path);
    read_exact(f, &s->instances, 8, path);
    if (s->instances > (1u << 26))
        die("bad instance count", path);
    s->inst_object = malloc((s->instances + 1) * sizeof(uint32_t));
    s->xfm = malloc((s->instances + 1) * 12 * sizeof(float));
    if (!s->object || !s->inst_object || !s->xfm)
        die("out of memory", NULL);
    for (uint64_t i = 0; i < s->instances; i++) {
        uint32_t head[2];
        read_exact(f, head, sizeof head, path);
        if (head[0] >= s->objects)
            die("an instance of a missing object", path);
        s->inst_object[i] = head[0];
        read_exact(f, s->xfm + 12 * i, 12 * sizeof(float), path);
    }
    fclose(f);
}

static ray *read_rays(const char *path, uint64_t *n)
{
    FILE *f = fopen(path, "rb");
    char magic[8];
    if (!f)
        die("cannot open", path);
    read_exact(f, magic, 8, path);
    if (memcmp(magic, "RTRAYS01", 8))
        die("not a .rays file", path);
    read_exact(f, n, 8, path);
    if (*n > (1ull << 28))
        die("bad ray count", path);
    ray *r = malloc(*n * sizeof(ray) + 1);
    if (!r)
        die("out of memory", NULL);
    read_exact(f, r, *n * sizeof(ray), path);
    fclose(f);
    return r;
}

static void on_error(void *u, enum RTCError code, const char *str)
{
    (void)u;
    fprintf(stderr, "embree_instances: Embree error %d: %s\n", (int)code, str);
    exit(2);
}

/* One triangle geometry of t's triangles (each moved by x when x is not
 * NULL: rows 0-2 of an affine matrix) into scene sc. */
static void add_triangles(RTCDevice dev, RTCScene sc, const tris *t, const float *x)
{
    if (t->n == 0)
        return;
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
    float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), t->n * 3);
    unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), t->n);
    for (uint64_t i = 0; i < 3 * t->n; i++) {
        const float *p = t->v + 3 * i;
        for (int r = 0; r < 3; r++)
            vb[3 * i + r] = x ? x[4 * r] * p[0] + x[4 * r + 1] * p[1] + x[4 * r + 2] * p[2] + x[4 * r + 3] : p[r];
        ib[i] = (unsigned)i;
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(sc, g);
    rtcReleaseGeometry(g);
}

static RTCScene new_scene(RTCDevice dev)
{
    RTCScene sc = rtcNewScene(dev);
    rtcSetSceneBuildQuality(sc, RTC_BUILD_QUALITY_HIGH);
    return sc;
}

/* The top-level scene (and, with instances, the objects' scenes in
 * objs[]): returns it committed. */
static RTCScene build(RTCDevice dev, const inst_scene *s, int flat, RTCScene *objs)
{
    RTCScene top = new_scene(dev);
    add_triangles(dev, top, &s->world, NULL);
    if (flat) {
        for (uint64_t i = 0; i < s->instances; i++)
            add_triangles(dev, top, &s->object[s->inst_object[i]], s->xfm + 12 * i);
    } else {
        for (uint64_t o = 0; o < s->objects; o++) {
            objs[o] = new_scene(dev);
            add_triangles(dev, objs[o], &s->object[o], NULL);
            rtcCommitScene(objs[o]);
        }
        for (uint64_t i = 0; i < s->instances; i++) {
            RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(g, objs[s->inst_object[i]]);
            rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, s->xfm + 12 * i);
            rtcCommitGeometry(g);
            rtcAttachGeometry(top, g);
            rtcReleaseGeometry(g);
        }
    }
    rtcCommitScene(top);
    return top;
}

enum { MODE_SINGLE, MODE_STREAM, MODE_PACKETS };
#define STREAM_CHUNK 4096
#define SINGLE_CHUNK 1024

typedef struct job {
    RTCScene scene;
    const ray *rays;
    uint64_t n;
    const uint32_t *order; /* packets: tile order */
    float *t;
    int mode;
    atomic_uint_fast64_t next;
    _Atomic double cpu;
} job;

static void set_ray(RTCRayHit *rh, const ray *r)
{
    memset(rh, 0, sizeof *rh);
    rh->ray.org_x = r->ox, rh->ray.org_y = r->oy, rh->ray.org_z = r->oz;
    rh->ray.dir_x = r->dx, rh->ray.dir_y = r->dy, rh->ray.dir_z = r->dz;
    rh->ray.tnear = r->tmin, rh->ray.tfar = r->tmax;
    rh->ray.mask = 0xffffffffu;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

static void trace_packets(job *j, RTCIntersectContext *ctx, uint64_t s, uint64_t e)
{
    for (uint64_t k = s; k < e; k += 16) {
        RTCRayHit16 p;
        int valid[16];
        memset(&p, 0, sizeof p);
        for (int l = 0; l < 16; l++) {
            valid[l] = k + (uint64_t)l < e ? -1 : 0;
            const ray *r = &j->rays[j->order[valid[l] ? k + (uint64_t)l : k]];
            p.ray.org_x[l] = r->ox, p.ray.org_y[l] = r->oy, p.ray.org_z[l] = r->oz;
            p.ray.dir_x[l] = r->dx, p.ray.dir_y[l] = r->dy, p.ray.dir_z[l] = r->dz;
            p.ray.tnear[l] = r->tmin, p.ray.tfar[l] = r->tmax, p.ray.mask[l] = 0xffffffffu;
            p.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
            p.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect16(valid, j->scene, ctx, &p);
        for (int l = 0; l < 16 && k + (uint64_t)l < e; l++)
            j->t[j->order[k + (uint64_t)l]] = p.hit.geomID[l] != RTC_INVALID_GEOMETRY_ID ? p.ray.tfar[l] : INFINITY;
    }
}

static void *worker(void *arg)
{
    job *j = arg;
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    if (j->mode != MODE_SINGLE)
        ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    RTCRayHit *stream = j->mode == MODE_STREAM ? malloc(STREAM_CHUNK * sizeof(RTCRayHit)) : NULL;
    if (j->mode == MODE_STREAM && !stream)
        die("out of memory", NULL);
    uint64_t chunk = j->mode == MODE_STREAM ? STREAM_CHUNK : SINGLE_CHUNK;
    double c0 = thread_cpu_s();
    for (;;) {
        uint64_t s = atomic_fetch_add(&j->next, chunk);
        if (s >= j->n)
            break;
        uint64_t e = s + chunk < j->n ? s + chunk : j->n;
        if (j->mode == MODE_SINGLE) {
            for (uint64_t i = s; i < e; i++) {
                RTCRayHit rh;
                set_ray(&rh, &j->rays[i]);
                rtcIntersect1(j->scene, &ctx, &rh);
                j->t[i] = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? rh.ray.tfar : INFINITY;
            }
        } else if (j->mode == MODE_STREAM) {
            for (uint64_t i = s; i < e; i++)
                set_ray(&stream[i - s], &j->rays[i]);
            rtcIntersect1M(j->scene, &ctx, stream, (unsigned)(e - s), sizeof(RTCRayHit));
            for (uint64_t i = s; i < e; i++)
                j->t[i] = stream[i - s].hit.geomID != RTC_INVALID_GEOMETRY_ID ? stream[i - s].ray.tfar : INFINITY;
        } else {
            trace_packets(j, &ctx, s, e);
        }
    }
    double c = thread_cpu_s() - c0, old = atomic_load(&j->cpu);
    while (!atomic_compare_exchange_weak(&j->cpu, &old, old + c))
        ;
    free(stream);
    return NULL;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static int usage(void)
{
    fprintf(stderr, "usage: embree_instances SCENE.inst RAYS.rays [--flat] [-t THREADS] [--runs K] "
                    "[--mode single|stream|packets] [--image-width N] [--out HITS.hits]\n");
    return 2;
}

int main(int argc, char **argv)
{
    const char *scene_path = NULL, *rays_path = NULL, *out = NULL;
    int flat = 0, threads = 1, runs = 5, mode = MODE_SINGLE, width = 640;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--flat"))
            flat = 1;
        else if (!strcmp(argv[i], "-t") && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--runs") && i + 1 < argc)
            runs = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--image-width") && i + 1 < argc)
            width = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--out") && i + 1 < argc)
            out = argv[++i];
        else if (!strcmp(argv[i], "--mode") && i + 1 < argc) {
            i++;
            mode = !strcmp(argv[i], "single") ? MODE_SINGLE : !strcmp(argv[i], "stream") ? MODE_STREAM
                   : !strcmp(argv[i], "packets")                                     ? MODE_PACKETS
                                                                                      : -1;
            if (mode < 0)
                return usage();
        } else if (argv[i][0] == '-')
            return usage();
        else if (!scene_path)
            scene_path = argv[i];
        else if (!rays_path)
            rays_path = argv[i];
        else
            return usage();
    }
    if (!scene_path || !rays_path || threads < 1 || threads > 64 || runs < 1 || runs > 1000 || width < 4)
        return usage();
    inst_scene s;
    memset(&s, 0, sizeof s);
    read_scene(scene_path, &s);
    uint64_t n;
    ray *rays = read_rays(rays_path, &n);
    uint32_t *order = NULL;
    if (mode == MODE_PACKETS) { /* 4x4 tiles, each row by row */
        uint64_t W = (uint64_t)width, H = n / W, k = 0;
        if (H * W != n || W % 4 || H % 4)
            die("the rays are not an image of 4x4 tiles --image-width wide", rays_path);
        order = malloc(n * sizeof *order);
        if (!order)
            die("out of memory", NULL);
        for (uint64_t ty = 0; ty < H; ty += 4)
            for (uint64_t tx = 0; tx < W; tx += 4)
                for (uint64_t y = ty; y < ty + 4; y++)
                    for (uint64_t x = tx; x < tx + 4; x++)
                        order[k++] = (uint32_t)(y * W + x);
    }
    char cfg[64];
    snprintf(cfg, sizeof cfg, "threads=%d", threads);
    RTCDevice dev = rtcNewDevice(cfg);
    if (!dev)
        die("rtcNewDevice failed", NULL);
    rtcSetDeviceErrorFunction(dev, on_error, NULL);
    RTCScene *objs = calloc(s.objects + 1, sizeof *objs);
    double b0 = now_s();
    RTCScene top = build(dev, &s, flat, objs);
    double build_ms = 1e3 * (now_s() - b0);
    float *t = malloc(n * sizeof(float) + 1);
    double *wall = malloc((size_t)runs * sizeof(double)), *cpu = malloc((size_t)runs * sizeof(double));
    if (!t || !wall || !cpu)
        die("out of memory", NULL);
    for (int r = -1; r < runs; r++) { /* run -1: the warm-up */
        job j = {.scene = top, .rays = rays, .n = n, .order = order, .t = t, .mode = mode};
        atomic_init(&j.next, 0);
        atomic_init(&j.cpu, 0.0);
        pthread_t th[64];
        double w0 = now_s();
        for (int k = 1; k < threads; k++)
            if (pthread_create(&th[k], NULL, worker, &j) != 0)
                die("pthread_create failed", NULL);
        worker(&j);
        for (int k = 1; k < threads; k++)
            pthread_join(th[k], NULL);
        if (r >= 0) {
            wall[r] = now_s() - w0;
            cpu[r] = atomic_load(&j.cpu);
        }
    }
    qsort(wall, (size_t)runs, sizeof *wall, cmp_double);
    qsort(cpu, (size_t)runs, sizeof *cpu, cmp_double);
    uint64_t hits = 0, placed = s.world.n;
    for (uint64_t i = 0; i < n; i++)
        hits += t[i] < INFINITY;
    for (uint64_t i = 0; i < s.instances; i++)
        placed += s.object[s.inst_object[i]].n;
    printf("embree: %d.%d.%d\n", RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH);
    printf("scene: %s\n", flat ? "flat" : "instanced");
    printf("mode: %s\n", mode == MODE_SINGLE ? "single" : mode == MODE_STREAM ? "stream" : "packets16");
    printf("threads: %d\n", threads);
    printf("instances: %llu\n", (unsigned long long)s.instances);
    printf("placed_triangles: %llu\n", (unsigned long long)placed);
    printf("rays: %llu\n", (unsigned long long)n);
    printf("build_ms: %.1f\n", build_ms);
    printf("mrays_per_s: %.3f\n", (double)n / wall[runs / 2] * 1e-6);
    printf("cpu_mrays_per_s: %.3f\n", (double)n / cpu[runs / 2] * 1e-6);
    printf("hits: %llu\n", (unsigned long long)hits);
    if (out) {
        FILE *f = fopen(out, "wb");
        if (!f || fwrite("RTHITS01", 1, 8, f) != 8 || fwrite(&n, 8, 1, f) != 1 || fwrite(t, sizeof(float), n, f) != n ||
            fclose(f) != 0)
            die("cannot write", out);
    }
    rtcReleaseScene(top);
    for (uint64_t o = 0; o < s.objects; o++)
        if (objs[o])
            rtcReleaseScene(objs[o]);
    rtcReleaseDevice(dev);
    return 0;
}
