/* buildscale - kd-tree build time against triangle count, to check that it
 * grows as N log N (Wald and Havran 2006; see src/accel/kdtree_build.c).
 *
 *   buildscale [--reps K] [--max N] [MODEL.glb ...]
 *
 * Scenes: random triangle soups of 10k to N (default 2M) triangles in the
 * unit cube, each triangle's size scaled with N^(-1/3) so the density of
 * the scene, and hence the tree's shape, stays the same; then every model
 * given on the command line (loaded with rt_load, every mesh use flattened
 * into world-space triangles as the shared rays' FORMAT.md and Embree see
 * them). For each: K (default 3) builds with 1 thread and with 2 threads,
 * interleaved, and their medians: wall time, the process's CPU time, the
 * 2-thread build's serial CPU time (the part with one build thread only,
 * rt_kdtree_stats.serial_cpu_ms) and the speed-up they predict on two free
 * cores; and the 1-thread CPU time divided by N log2 N (in ns), which stays
 * flat when the build is O(N log N). On a shared machine the wall-clock
 * speed-up is what the other load leaves; the predicted one is not.
 * Prints a Markdown table.
 */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rt/base/log.h"
#include "rt/io/load.h"
#include "rt/accel/kdtree.h"
#include "rt/scene/scene.h"

/* xorshift64*: a deterministic soup */
static uint64_t rng_next(uint64_t *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return *s * 2685821657736338717ull;
}
static float rng_float(uint64_t *s) { return (float)(rng_next(s) >> 40) * (1.0f / 16777216.0f); }

static int soup(rt_scene *s, size_t n)
{
    uint64_t st = 0x9e3779b97f4a7c15ull ^ n;
    float size = 2.0f * powf((float)n, -1.0f / 3.0f); /* about a cell of a n^(1/3) grid */
    uint32_t v = rt_scene_add_vertices(s, 3 * n);
    if (v == RT_NONE)
        return -1;
    for (size_t i = 0; i < n; i++) {
        rt_vec3 c = rt_v3(rng_float(&st), rng_float(&st), rng_float(&st));
        for (int k = 0; k < 3; k++)
            s->vertices.position[v + 3 * i + k] =
                rt_add(c, rt_v3(size * (rng_float(&st) - 0.5f), size * (rng_float(&st) - 0.5f),
                                size * (rng_float(&st) - 0.5f)));
        uint32_t a = v + 3 * (uint32_t)i;
        if (rt_scene_add_triangle(s, a, a + 1, a + 2, 0, 0) == RT_NONE)
            return -1;
    }
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double process_cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

static double median(double *t, int n)
{
    qsort(t, (size_t)n, sizeof t[0], cmp_double);
    return t[n / 2];
}

/* Medians of K builds with `threads` build threads: wall ms, the process's
 * CPU ms, and the build's serial CPU ms (rt_kdtree_stats.serial_cpu_ms);
 * false on failure. */
typedef struct build_times {
    double wall, cpu, serial;
} build_times;

static bool build_times_of(const rt_scene *s, int threads, int reps, build_times *bt, rt_kdtree_stats *st)
{
    double wall[64], cpu[64], serial[64];
    for (int r = 0; r < reps; r++) {
        rt_kdtree tree;
        rt_error err = {0};
        rt_kdtree_params p;
        memset(&p, 0, sizeof p);
        p.threads = threads;
        double c0 = process_cpu_ms();
        if (rt_kdtree_build(&tree, s, &p, &err) != RT_OK) {
            fprintf(stderr, "buildscale: %s\n", err.message);
            return false;
        }
        cpu[r] = process_cpu_ms() - c0;
        wall[r] = tree.stats.build_ms;
        serial[r] = tree.stats.serial_cpu_ms;
        *st = tree.stats;
        rt_kdtree_free(&tree);
    }
    *bt = (build_times){median(wall, reps), median(cpu, reps), median(serial, reps)};
    return true;
}

/* One row; with 1 and 2 threads interleaved, A B A B. The predicted
 * speed-up: the 1-thread CPU time over the 2-thread build's serial CPU time
 * plus half the rest of its CPU time (its extra work included): what two
 * free cores would give if the subtrees shared them evenly. */
static void row(const char *name, const rt_scene *s, int reps)
{
    rt_kdtree_stats st;
    double n = (double)s->triangles.count;
    double w1[64], w2[64], c1[64], c2[64], s2[64];
    for (int r = 0; r < reps; r++) {
        build_times a, b;
        if (!build_times_of(s, 1, 1, &a, &st) || !build_times_of(s, 2, 1, &b, &st))
            return;
        w1[r] = a.wall, c1[r] = a.cpu, w2[r] = b.wall, c2[r] = b.cpu, s2[r] = b.serial;
    }
    double t1 = median(w1, reps), t2 = median(w2, reps), cpu1 = median(c1, reps), cpu2 = median(c2, reps),
           ser2 = median(s2, reps);
    printf("| %s | %zu | %.1f | %.1f | %.2f | %.1f | %.1f | %.1f (%.1f%%) | %.2f | %.0f | %.2f | %.1f |\n", name,
           s->triangles.count, t1, t2, t2 > 0 ? t1 / t2 : 0.0, cpu1, cpu2, ser2, 100.0 * ser2 / cpu1,
           cpu1 / (ser2 + 0.5 * (cpu2 - ser2)), 1e6 * cpu1 / (n * log2(n)), (double)st.prim_refs / n,
           (double)st.bytes / n);
    fflush(stdout);
}

int main(int argc, char **argv)
{
    int reps = 3;
    size_t max = 2000000;
    int first_model = argc;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) {
            reps = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--max") == 0 && i + 1 < argc) {
            max = (size_t)atof(argv[++i]);
        } else if (argv[i][0] == '-') {
            fprintf(stderr, "usage: buildscale [--reps K] [--max N] [MODEL.glb ...]\n");
            return 2;
        } else {
            first_model = i;
            break;
        }
    }
    if (reps < 1 || reps > 64)
        reps = 3;
    rt_log_set_level(RT_LOG_QUIET);
    printf("| scene | triangles | 1T wall ms | 2T wall ms | 2T wall speed-up | 1T CPU ms | 2T CPU ms | 2T serial CPU ms "
           "(of 1T CPU) | predicted 2T speed-up | 1T CPU ns / (N log2 N) | refs / tri | bytes / tri |\n");
    printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    static const size_t sizes[] = {10000, 30000, 100000, 300000, 1000000, 2000000, 4000000};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0] && sizes[k] <= max; k++) {
        rt_scene s;
        rt_scene_init(&s);
        if (soup(&s, sizes[k]) != 0) {
            fprintf(stderr, "buildscale: out of memory\n");
            return 1;
        }
        row("random soup", &s, reps);
        rt_scene_free(&s);
    }
    for (int i = first_model; i < argc; i++) {
        rt_scene s;
        rt_scene_init(&s);
        rt_error err = {0};
        rt_load_options lo = {.flatten_instances = true};
        if (rt_load(&s, NULL, argv[i], &lo, NULL, &err) != RT_OK) {
            fprintf(stderr, "buildscale: %s\n", err.message);
            return 2;
        }
        const char *name = strrchr(argv[i], '/');
        row(name ? name + 1 : argv[i], &s, reps);
        rt_scene_free(&s);
    }
    return 0;
}
