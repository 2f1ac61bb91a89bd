/* rt/render/spherical.h - sampling a rectangle or a triangle by the solid
 * angle it subtends from a point: every direction towards it equally
 * likely, pdf 1 / (solid angle), instead of uniform points on its area
 * (whose solid-angle pdf d^2 / (A cos theta_l) blows up close to it).
 *
 *   rt_sph_rect r;                       // rectangle corner + edges ex, ey (perpendicular)
 *   if (rt_sph_rect_init(&r, corner, ex, ey, p) && rt_sph_in_range(r.S)) {
 *       float dist;
 *       rt_vec3 wi = rt_sph_rect_sample(&r, u, &dist);   // unit direction, distance to the rectangle
 *       ... pdf = 1 / r.S ...
 *   }
 *
 *   rt_sph_tri t;
 *   if (rt_sph_tri_init(&t, a, b, c, p) && rt_sph_in_range(t.S)) {   // t.S: its solid angle from p
 *       rt_vec3 wi = rt_sph_tri_sample(&t, u);   // unit direction from p into the triangle
 *   }
 *
 * Renderers fall back to area sampling when the solid angle is tiny (the
 * angles lose precision) or close to a hemisphere: RT_SPH_MIN_SOLID_ANGLE
 * and RT_SPH_MAX_SOLID_ANGLE are pbrt-v4's thresholds. Both samplers map
 * [0,1)^2 onto the spherical polygon preserving area, so stratified u give
 * stratified directions. The set-up is in double precision.
 */
#ifndef RT_SPHERICAL_H
#define RT_SPHERICAL_H

#include <stdbool.h>

#include "rt/base/vec.h"

#define RT_SPH_MIN_SOLID_ANGLE 3e-4f /* sr: below it, sample by area */
#define RT_SPH_MAX_SOLID_ANGLE 6.22f /* sr: above it, sample by area */

/* True when a solid angle is in the range where solid-angle sampling is used. */
static inline bool rt_sph_in_range(float solid_angle)
{
    return solid_angle >= RT_SPH_MIN_SOLID_ANGLE && solid_angle <= RT_SPH_MAX_SOLID_ANGLE;
}

/* A rectangle seen from o, set up for sampling (Urena, Fajardo and King
 * 2013): its frame x, y (along the edges), z (away from o's side), the
 * rectangle's extent in it, and the constants of the inversion. */
typedef struct rt_sph_rect {
    rt_vec3 x, y, z;
    double x0, y0, z0, x1, y1;
    double b0, b1, cos_k, sin_k;
    float S; /* the solid angle, sr */
} rt_sph_rect;

/* Sets up the rectangle corner + s ex + t ey (s, t in [0,1]; ex, ey
 * perpendicular) as seen from o. False when o lies in its plane or the
 * rectangle is degenerate (S is then 0). */
bool rt_sph_rect_init(rt_sph_rect *r, rt_vec3 corner, rt_vec3 ex, rt_vec3 ey, rt_vec3 o);

/* The unit direction from o for u in [0,1)^2, uniform in solid angle over
 * the rectangle, and in *dist the distance from o to the rectangle along it. */
rt_vec3 rt_sph_rect_sample(const rt_sph_rect *r, rt_vec2 u, float *dist);

/* A triangle seen from a point, set up for Arvo's sampling (1995,
 * "Stratified sampling of spherical triangles"): the unit directions to its
 * vertices and its angles. */
typedef struct rt_sph_tri {
    double a[3], b[3], c[3];     /* unit directions to the vertices */
    double cos_alpha, sin_alpha, cos_c; /* of the angle at a; cos of the side ab */
    float S;                     /* the solid angle alpha + beta + gamma - pi, sr */
} rt_sph_tri;

/* Sets up triangle (a, b, c) seen from p. False when p lies in its plane
 * or on it, or the triangle is degenerate (S is then 0). */
bool rt_sph_tri_init(rt_sph_tri *t, rt_vec3 a, rt_vec3 b, rt_vec3 c, rt_vec3 p);

/* The unit direction from p for u in [0,1)^2, uniform in solid angle over
 * the triangle. */
rt_vec3 rt_sph_tri_sample(const rt_sph_tri *t, rt_vec2 u);

#endif
