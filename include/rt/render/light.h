/* rt/render/light.h - light arriving at a surface point: sampling the
 * scene's lights, shadow rays through what lies between, and the path
 * tracer's table of emitters (emissive primitives and the environment
 * image) to sample by power.
 *
 *   rt_light_sample ls;
 *   if (rt_light_sample_at(&ctx, &scene.lights[i], sf.p, u, &ls)) {
 *       rt_vec3 tr = rt_shadow_transmittance(&ctx, &sf, ls.wi, ls.dist);
 *       ... ls.li * tr is the light arriving (radiance / pdf) ...
 *   }
 *
 * Light kinds: point and spot lights (intensity / d^2, spot cones with
 * glTF's smooth falloff, glTF's range window) and directional lights are
 * deltas; area lights (a one-sided parallelogram) that are rectangles are
 * sampled uniformly by the solid angle they subtend (pdf 1 / solid angle,
 * rt/render/spherical.h) from points that see them large (estimated 0.1 sr
 * or more; exactly between 3e-4 and 6.22 sr), otherwise uniformly by area
 * and converted to solid angle (pdf = d^2 / (A cos theta_l)). The table's
 * emissive triangles likewise (rt_tri_solid).
 *
 * The light table is per scene and read-only while rendering: built once
 * before the render threads start (the render state does it for
 * integrators that need it) and read by every thread:
 *
 *   rt_light_table lt;
 *   if (rt_light_table_build(&lt, &scene, &err) != RT_OK) ...
 *   size_t k = rt_light_table_pick(&lt, u);          // emitter k, by power
 *   rt_light_table_free(&lt);
 */
#ifndef RT_LIGHT_H
#define RT_LIGHT_H

#include "rt/base/error.h"
#include "rt/render/spherical.h"
#include "rt/render/surface.h"

typedef struct rt_light_sample {
    rt_vec3 wi;       /* unit direction from the point to the light */
    float dist;       /* distance to the sampled light point, INFINITY for directional */
    rt_vec3 li;       /* incident radiance divided by the sampling pdf (solid angle) */
    float pdf;        /* that pdf for area lights (rt_area_light_pdf's value); unset for deltas */
} rt_light_sample;

/* Samples light l as seen from point p with a 2D sample u. False when the
 * light contributes nothing there (behind a one-sided area light, outside a
 * spot cone). */
bool rt_light_sample_at(const rt_trace_ctx *ctx, const rt_light *l, rt_vec3 p, rt_vec2 u, rt_light_sample *ls);

/* Solid-angle pdf with which rt_light_sample_at samples area light l from
 * point p towards unit direction d (the light at distance dist); 0 when
 * seen from behind. The same bits as rt_light_sample.pdf of a sample from
 * p in direction d. */
float rt_area_light_pdf(const rt_light *l, rt_vec3 p, rt_vec3 d, float dist);

/* Fraction of light arriving along wi from distance dist: 0 when blocked,
 * 1 when clear, and in between through transmissive or alpha-blended
 * surfaces (coloured by their transmission colour). */
rt_vec3 rt_shadow_transmittance(const rt_trace_ctx *ctx, const rt_surface *sf, rt_vec3 wi, float dist);
/* The same for the path tracer, which must count light only as its BSDF
 * sampling would deliver it: alpha cut-outs pass, a blended surface lets
 * 1 - alpha through (the share a path steps past), and, when thin_passes,
 * a smooth thin-walled glTF transmission lets its straight-through lobe
 * through (rt_bsdf_straight_through of the BSDF at the hit: colour,
 * Fresnel, transmission), for the share the blending keeps. Every other
 * transmissive surface blocks: light through glass that bends or blurs it
 * arrives by BSDF sampling. Grey (x = y = z) unless a thin surface
 * coloured it; without thin_passes, x is what the path tracer's
 * visibility always was. */
rt_vec3 rt_shadow_path_transmittance(const rt_trace_ctx *ctx, const rt_surface *sf, rt_vec3 wi, float dist,
                                     bool thin_passes);

/* The shadow ray both use (one ray; past its first hit they walk on from
 * it): from sf's surface, offset to the side of wi, aimed at the sampled
 * point sf->p + wi dist and stopped just short of it (its direction is wi
 * up to the offset; an infinite dist: along wi).
 * When the render state's shadows_need_shading is false, visibility is
 * exactly !rt_kdtree_occluded of this ray (the wavefront tracer batches them). */
rt_ray rt_shadow_ray(const rt_trace_ctx *ctx, const rt_surface *sf, rt_vec3 wi, float dist);

/* ------------------------------------------------------------ light table */

typedef struct rt_light_table {
    size_t count;         /* emissive primitives (area lights' own quads excluded) */
    uint32_t *prim;       /* their primitive ids */
    float *cdf;           /* cumulative selection probability, cdf[count - 1] == 1 */
    float *area;          /* their areas */
    size_t prim_count;    /* primitive ids covered by prim_pdf */
    float *prim_pdf;      /* per primitive id: selection probability / area (0 = not in the table) */
    float *prim_sel;      /* per primitive id: selection probability (0 = not in the table) */
    size_t quad_count;
    uint32_t *quad_light; /* per quad: index of the area light it is the visible quad of, or RT_NONE */
    /* environment image, importance-sampled by luminance x sin(theta) over
     * an env_w x env_h grid of its latitude-longitude cells (0 = none) */
    int env_w, env_h;
    float *env_row_cdf;   /* env_h: cumulative probability of the rows */
    float *env_col_cdf;   /* env_h x env_w: cumulative probability within each row */
    float *env_cell;      /* env_h x env_w: probability of each cell */
} rt_light_table;

rt_result rt_light_table_build(rt_light_table *t, const rt_scene *s, rt_error *err);
void rt_light_table_free(rt_light_table *t);

/* The emitter (index into t->prim) that a uniform u in [0, 1) picks, each
 * with its share of the emitted power; t->count must be > 0. */
size_t rt_light_table_pick(const rt_light_table *t, float u);

/* A direction towards the environment drawn from its distribution with u
 * in [0,1)^2, and its solid-angle pdf; false when none (a pole). Only for
 * a table with an environment (t->env_w > 0). */
bool rt_light_table_sample_env(const rt_light_table *t, rt_vec2 u, rt_vec3 *d, float *pdf);

/* Solid-angle pdf with which the table samples the environment towards
 * unit direction d (0 without an environment image). */
float rt_light_table_env_pdf(const rt_light_table *t, rt_vec3 d);

/* Triangle (a, b, c) of the table, of the given area (the table's
 * prim_sel[prim] / prim_pdf[prim], so that the sampler and MIS decide
 * alike), seen from p, set up in *st for solid-angle sampling: true when p
 * sees it large (area / d^2 from its centroid at least 0.1) and its solid
 * angle from p is in the range where that is used (its pdf is then
 * prim_sel[prim] / st->S), false when it is sampled uniformly by area (pdf
 * prim_pdf[prim] d^2 / cos theta_l). */
bool rt_tri_solid(rt_vec3 a, rt_vec3 b, rt_vec3 c, float area, rt_vec3 p, rt_sph_tri *st);

/* The area light whose visible quad primitive `prim` is, or RT_NONE; from
 * the table when given (NULL: a search of the lights). */
uint32_t rt_area_light_of_prim(const rt_scene *s, const rt_light_table *t, uint32_t prim);

#endif
