/* test_volpath_estimate.h - the volumetric path tracer's mean along one
 * camera ray, with its standard error, and the check that holds it to an
 * expected value (test_volpath.c, test_subsurface.c).
 *
 *   test_estimate e = test_estimate_ray(&fixture, org, dir, 100000, seed);
 *   test_expect_near("white furnace", e, rt_v3s(1.0f));   // within 4 se + 0.2%
 */
#ifndef RT_TEST_VOLPATH_ESTIMATE_H
#define RT_TEST_VOLPATH_ESTIMATE_H

#include <math.h>

#include "rt/render/volpath.h"
#include "test_fixture.h"
#include "test_util.h"

typedef struct test_estimate {
    rt_vec3 mean, se; /* per channel: the mean and its standard error */
} test_estimate;

/* The mean of n paths along org -> dir, path i drawing pixel stream i of seed. */
static inline test_estimate test_estimate_ray(const test_fixture *f, rt_vec3 org, rt_vec3 dir, int n, uint64_t seed)
{
    double s[3] = {0, 0, 0}, s2[3] = {0, 0, 0};
    for (int i = 0; i < n; i++) {
        rt_rng rng = rt_rng_for_sample(seed, (uint64_t)i, 0);
        rt_ray r = rt_ray_make(org, rt_normalize(dir), 0.0f, INFINITY);
        rt_vec3 L = rt_radiance_volpath(&f->ctx, &r, &rng);
        assert_true(rt_finite3(L) && L.x >= 0.0f && L.y >= 0.0f && L.z >= 0.0f);
        const double v[3] = {L.x, L.y, L.z};
        for (int k = 0; k < 3; k++) {
            s[k] += v[k];
            s2[k] += v[k] * v[k];
        }
    }
    double m[3], e[3];
    for (int k = 0; k < 3; k++) {
        m[k] = s[k] / n;
        double var = s2[k] / n - m[k] * m[k];
        e[k] = sqrt(var > 0 ? var / n : 0);
    }
    return (test_estimate){rt_v3((float)m[0], (float)m[1], (float)m[2]),
                           rt_v3((float)e[0], (float)e[1], (float)e[2])};
}

/* Fails unless every channel of e is within four standard errors (and
 * 0.2%) of want; prints the figures either way. */
static inline void test_expect_near(const char *what, test_estimate e, rt_vec3 want)
{
    const float got[3] = {e.mean.x, e.mean.y, e.mean.z}, se[3] = {e.se.x, e.se.y, e.se.z};
    const float w[3] = {want.x, want.y, want.z};
    for (int k = 0; k < 3; k++) {
        float tol = 4.0f * se[k] + 0.002f * w[k] + 1e-5f;
        if (!(fabsf(got[k] - w[k]) <= tol))
            fail_msg("%s, channel %d: %.5f, expected %.5f (+- %.5f)", what, k, got[k], w[k], tol);
    }
    print_message("%s: %.4f %.4f %.4f (expected %.4f %.4f %.4f, se %.4f %.4f %.4f)\n", what, e.mean.x, e.mean.y,
                  e.mean.z, want.x, want.y, want.z, e.se.x, e.se.y, e.se.z);
}

#endif
