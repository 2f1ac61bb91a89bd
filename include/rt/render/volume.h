/* rt/render/volume.h - a participating medium as the path tracer samples
 * it: absorption and scattering coefficients (per RGB channel) times a
 * density that is 1 everywhere (homogeneous) or read from a voxel grid
 * (rt/scene/density_grid.h) placed in the world by an affine map; the
 * piecewise-constant majorant along a ray; and the two unbiased estimators
 * every volumetric path tracer is built from (Novak et al., "Monte Carlo
 * methods for volumetric light transport simulation", Eurographics STAR
 * 2018; Miller, Georgiev, Jarosz, "A null-scattering path integral
 * formulation of light transport", SIGGRAPH 2019):
 *
 *   rt_volume fog = rt_volume_homogeneous(sigma_a, sigma_s, g);
 *   rt_volume smoke = rt_volume_grid(sigma_a, sigma_s, g, &grid, &world_to_index);
 *
 *   // transmittance between two points, unbiased per channel (ratio tracking):
 *   rt_vec3 T = rt_volume_ratio_tracking(&smoke, o, d, t_max, &rng);
 *   // the first real collision along a ray in one channel (delta tracking):
 *   float t = rt_volume_delta_tracking(&smoke, o, d, t_max, channel, &rng);
 *   if (t < t_max) ... the path scatters or is absorbed at o + t d
 *
 *   // or walk the majorant yourself (the null-scattering integrator does):
 *   rt_majorant_iter it;
 *   rt_majorant_iter_init(&it, &smoke, o, d, 0, t_max);
 *   float t0, t1; rt_vec3 sigma_maj;
 *   while (rt_majorant_next(&it, &t0, &t1, &sigma_maj)) ...
 *
 * d need not be unit length: distances t are in units of |d| as for rays
 * everywhere in rt, and the coefficients are per world unit, so a
 * transmittance over [0, t] is exp(-sigma_t |d| t) in a homogeneous medium.
 * For the grid the density at a world point p is the grid's lookup at
 * world_to_index(p); segments of the majorant are the grid's blocks the ray
 * crosses (a 3D DDA), each with the block's maximum density times
 * sigma_t, so free flights take long steps through empty space and
 * segments where the majorant is 0 cost nothing.
 */
#ifndef RT_VOLUME_H
#define RT_VOLUME_H

#include <stdbool.h>

#include "rt/base/vec.h"
#include "rt/render/sampling.h"
#include "rt/scene/density_grid.h"

typedef struct rt_volume {
    rt_vec3 sigma_a, sigma_s;     /* per world unit at density 1 */
    float g;                      /* Henyey-Greenstein anisotropy (rt/render/phase.h) */
    const rt_density_grid *grid;  /* NULL: homogeneous, density 1 */
    rt_mat4 world_to_index;       /* the grid's placement, inverted (unused without a grid) */
} rt_volume;

rt_volume rt_volume_homogeneous(rt_vec3 sigma_a, rt_vec3 sigma_s, float g);
rt_volume rt_volume_grid(rt_vec3 sigma_a, rt_vec3 sigma_s, float g, const rt_density_grid *grid,
                         const rt_mat4 *world_to_index);

static inline rt_vec3 rt_volume_sigma_t(const rt_volume *v) { return rt_add(v->sigma_a, v->sigma_s); }

/* The density at a world point (1 in a homogeneous medium). */
float rt_volume_density(const rt_volume *v, rt_vec3 p);

/* Walks the majorant of o + t d over [t_min, t_max) in pieces. */
typedef struct rt_majorant_iter {
    const rt_volume *v;
    float t, t_end;       /* the next piece starts at t; done when t >= t_end */
    rt_vec3 sigma_t;      /* the medium's sigma_t (times |d|: per unit of t) */
    int block[3], step[3], count[3];
    float t_next[3], t_delta[3];
    bool grid;
} rt_majorant_iter;

void rt_majorant_iter_init(rt_majorant_iter *it, const rt_volume *v, rt_vec3 o, rt_vec3 d, float t_min,
                           float t_max);
/* The next piece [*t0, *t1) and its majorant per channel (per unit of t:
 * the coefficients times |d|); false when the ray has left the medium or
 * reached t_max. Pieces are contiguous and in order. */
bool rt_majorant_next(rt_majorant_iter *it, float *t0, float *t1, rt_vec3 *sigma_maj);

/* Transmittance of o + t d over [0, t_max), per channel, by ratio
 * tracking against the largest channel's majorant: unbiased, in [0, 1]. */
rt_vec3 rt_volume_ratio_tracking(const rt_volume *v, rt_vec3 o, rt_vec3 d, float t_max, rt_rng *rng);

/* The first real collision in channel `channel` (0..2) along o + t d, by
 * delta tracking: distributed as the channel's free-flight distance; t_max
 * or more (INFINITY) when the ray passes. */
float rt_volume_delta_tracking(const rt_volume *v, rt_vec3 o, rt_vec3 d, float t_max, int channel, rt_rng *rng);

#endif
