/* rt/accel/rayset.h - the shared benchmark ray files (.rays, .hits): rays
 * for the kd-tree and the distances a reference tracer found along them.
 *
 * Format (../shared/bench/FORMAT.md), little-endian:
 *   .rays  "RTRAYS01", u64 N, N x float32[8] = ox oy oz dx dy dz tmin tmax
 *   .hits  "RTHITS01", u64 N, N x float32 t (+inf for a miss)
 *
 *   rt_rayset rs;
 *   if (rt_rayset_load(&rs, "a.rays", "a.hits", &err) != RT_OK) ...   // hits may be NULL
 *   for (size_t i = 0; i < rs.count; i++) ... rs.rays[i], rs.ref_t[i]
 *   rt_rayset_free(&rs);
 */
#ifndef RT_RAYSET_H
#define RT_RAYSET_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "rt/accel/ray.h"
#include "rt/base/error.h"

typedef struct rt_rayset {
    rt_ray *rays;
    float *ref_t; /* NULL without a .hits file */
    size_t count;
} rt_rayset;

rt_result rt_rayset_load(rt_rayset *rs, const char *rays_path, const char *hits_path, rt_error *err);
void rt_rayset_free(rt_rayset *rs);

/* Whether a traced distance agrees with the reference: both miss, or both
 * hit with |t - ref| <= 1e-4 * ref + 1e-6 * diagonal (the tolerance the
 * shared FORMAT.md suggests; diagonal = the scene's bounding-box diagonal). */
static inline bool rt_rayset_agrees(float t, float ref, float diagonal)
{
    bool miss = !(t < INFINITY), ref_miss = !(ref < INFINITY);
    if (miss || ref_miss)
        return miss == ref_miss;
    return fabsf(t - ref) <= 1e-4f * fabsf(ref) + 1e-6f * diagonal;
}

#endif
