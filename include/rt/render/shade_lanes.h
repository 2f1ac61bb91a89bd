/* rt/render/shade_lanes.h - BSDF sampling and weighting, and light
 * sampling with its BSDF evaluation, over arrays of paths,
 * RT_SHADE_LANES paths a SIMD step: the wavefront's shading of one
 * material kind at a time (rt/render/wavefront.h; docs/path-tracer.md,
 * section 8).
 *
 *   rt_shade_lanes *l = rt_shade_lanes_new(batch);    // NULL: out of memory
 *   for each path k < n: l->tx[k] = b.t.x, ... (frame t, b, n; geometric normal g;
 *                        throughput br..bb; u = the direction's 2D value;
 *                        the kind's parameters: Lambert's albedo d = b.diffuse, ...)
 *   rt_lambert_sample_lanes(l, n);                    // or rt_conductor_ / rt_gltf_ / rt_plastic_sample_lanes
 *   // light sampling at the same vertices (p = px..pz, lu = the light's 2D value, wo too for Lambert):
 *   rt_light_sample_lanes(l, ctx, &scene.lights[j], n);  // lwx..lok: rt_light_sample_at's sample
 *   rt_nee_eval_lanes(l, kind, mis, n);                  // fr..rok: rt_path_nee_light_at's record
 *   // (a sample made elsewhere, e.g. the environment's: set lwx..lok yourself, li 1, then
 *   //  rt_nee_eval_lanes(l, kind, true, n) and multiply fr..fb by its radiance)
 *   for each k: l->ok[k] ? (world direction wx..wz, pdf, throughput br..bb updated,
 *                           delta: a delta sample) : the path ends
 *   rt_shade_lanes_free(l);
 *
 * Each path gets bit for bit what the scalar steps give
 * (rt_bsdf_sample_dir of the kind's BSDF, the direction taken
 * to the world and normalised, the geometric side test, beta times the
 * weight, finite and positive: rt_path_vertex_end up to
 * rt_path_vertex_advance): the same float operations in the same order
 * in every lane (the build's -ffp-contract=off keeps them unfused), so
 * the width does not change a bit. RT_SHADE_LANES is the machine's:
 * 16 where the compiler targets AVX-512, 8 for AVX2, 4 otherwise
 * (GCC / clang vector types compile to each).
 */
#ifndef RT_SHADE_LANES_H
#define RT_SHADE_LANES_H

#include <stddef.h>
#include <stdint.h>

#include "rt/render/bsdf.h"
#include "rt/render/light.h"

#if defined(__AVX512F__)
#define RT_SHADE_LANES 16
#elif defined(__AVX2__)
#define RT_SHADE_LANES 8
#else
#define RT_SHADE_LANES 4
#endif

/* Structure-of-arrays lanes of one kind's vertices: room for `batch`
 * paths (and one SIMD step of padding). Every kind reads the frame, the
 * geometric normal, the throughput and u, and writes the outputs; the
 * parameters are each kind's own. */
typedef struct rt_shade_lanes {
    size_t cap;
    float *tx, *ty, *tz, *bx, *by, *bz, *nx, *ny, *nz; /* shading frame (world) */
    float *gx, *gy, *gz;                              /* geometric normal, on the side of wo */
    float *br, *bg, *bb;                              /* throughput: in, and out when ok */
    float *ux, *uy;                                   /* the direction's 2D sample value */
    /* Lambert */
    float *dr, *dg, *db;                              /* albedo (b.diffuse) */
    /* GGX conductor (rough, without energy compensation) and the glTF BRDF */
    float *ox, *oy, *oz;                              /* wo, local */
    float *ax, *ay, *sep;                             /* alphas along t and b (glTF: both alpha);
                                                       * separable Smith: 1, else 0 */
    float *er, *eg, *eb, *kr, *kg, *kb;               /* conductor: complex index eta + i k, per channel */
    /* the glTF BRDF (rough, opaque): albedo above is (1 - m) B */
    float *cr, *cg, *cb;                              /* base colour B */
    float *metal, *f0;                                /* metallic m, the dielectric's F0 */
    float *pd, *ps;                                   /* lobe probabilities at wo (rt_bsdf_set_wo's) */
    float *ulobe;                                     /* the lobe choice's sample value */
    /* the smooth dielectric (glass): albedo above is its tint, pd and ps as above */
    float *pt;                                        /* the refraction's probability */
    float *eta;                                       /* index ratio n_wo / n_wi */
    /* the plastic: albedo above is its diffuse (b.diffuse), ax = ay its
     * alpha, pd, ps and eta as above */
    float *smooth;                                    /* 1: a smooth (delta) coat, 0: rough */
    /* out */
    float *wx, *wy, *wz, *pdf;                        /* world direction (unit), its pdf */
    uint8_t *ok;                                      /* 1 when the path goes on */
    uint8_t *down;                                    /* 1 when it went below the surface (refracted) */
    uint8_t *delta;                                   /* 1 for a delta sample (pdf 0: glass, a smooth
                                                       * plastic's mirror) */
    /* light sampling (next-event estimation) at the vertex: in */
    float *px, *py, *pz;                              /* the vertex (sf.p) */
    float *lux, *luy;                                 /* the light's 2D sample value */
    /* rt_light_sample_lanes' out (rt_light_sample's fields), read by rt_nee_eval_lanes */
    float *lwx, *lwy, *lwz, *ldist, *lr, *lg, *lb, *lpdf;
    uint8_t *lok;                                     /* 1 when rt_light_sample_at is true */
    /* rt_nee_eval_lanes' out: the record (rt_nee_record: fl, cos, w; wi and
     * dist are the sample's, pdf 1) when rok */
    float *fr, *fg, *fb, *fcos, *fw;
    uint8_t *rok;
} rt_shade_lanes;

/* Which lanes sample b: RT_BSDF_KIND_LAMBERT, RT_BSDF_KIND_CONDUCTOR,
 * RT_BSDF_KIND_GLTF (rough and opaque), RT_BSDF_KIND_DIELECTRIC (smooth
 * glass), RT_BSDF_KIND_PLASTIC (smooth or rough), the last three with
 * their lobe probabilities cached by
 * rt_bsdf_set_wo, or -1 for a BSDF the lanes do not cover (the scalar
 * rt_path_vertex_end). */
static inline int rt_shade_lanes_kind(const rt_bsdf *b)
{
    if (b->kind == RT_BSDF_KIND_LAMBERT)
        return RT_BSDF_KIND_LAMBERT;
    if (b->kind == RT_BSDF_KIND_CONDUCTOR && !b->delta && !b->ms)
        return RT_BSDF_KIND_CONDUCTOR;
    if (b->kind == RT_BSDF_KIND_GLTF && !b->delta && !b->ms && !b->thin && b->transmission == 0.0f &&
        b->wo_z == b->wo_z)
        return RT_BSDF_KIND_GLTF;
    if (b->kind == RT_BSDF_KIND_DIELECTRIC && b->delta && !b->ms && !b->thin && b->wo_z == b->wo_z)
        return RT_BSDF_KIND_DIELECTRIC;
    if (b->kind == RT_BSDF_KIND_PLASTIC && !b->ms && !b->thin && b->transmission == 0.0f && b->metallic == 0.0f &&
        b->alpha == b->alpha_y && b->wo_z == b->wo_z)
        return RT_BSDF_KIND_PLASTIC;
    return -1;
}

rt_shade_lanes *rt_shade_lanes_new(size_t batch);
void rt_shade_lanes_free(rt_shade_lanes *l);
/* Samples, weighs and checks paths 0 .. n - 1 (n <= cap) of a Lambert
 * BSDF (RT_BSDF_KIND_LAMBERT) / of a rough GGX conductor
 * (RT_BSDF_KIND_CONDUCTOR, not delta, no ms lobe: its only lobe is the
 * VNDF-sampled specular one): rt_shade_lanes_kind says which a BSDF is. */
void rt_lambert_sample_lanes(rt_shade_lanes *l, size_t n);
void rt_conductor_sample_lanes(rt_shade_lanes *l, size_t n);
/* The glTF metallic-roughness BRDF, rough and opaque (RT_BSDF_KIND_GLTF,
 * no transmission, roughness above 0): the diffuse or the specular lobe
 * by ulobe, then bsdf.c's dielectric_eval at the direction. */
void rt_gltf_sample_lanes(rt_shade_lanes *l, size_t n);
/* The smooth dielectric (RT_BSDF_KIND_DIELECTRIC, roughness 0, not thin):
 * the mirror or the refraction by ulobe, delta samples (pdf 0); `down`
 * says which. */
void rt_dielectric_sample_lanes(rt_shade_lanes *l, size_t n);
/* The plastic (RT_BSDF_KIND_PLASTIC): a smooth coat's delta mirror
 * (`delta`, pdf 0) or a rough coat's specular lobe by its visible
 * normals, or the diffuse base by the cosine, chosen by ulobe, then
 * bsdf.c's dielectric_eval at the direction. */
void rt_plastic_sample_lanes(rt_shade_lanes *l, size_t n);

/* Light sampling in lanes: rt_light_sample_at(ctx, light, p, lu) for
 * paths 0 .. n - 1 into lwx .. lok, the same bits. Point, spot,
 * directional lights and area lights sampled by area run in lanes; the
 * paths that see a rectangular area light large (its solid-angle
 * sampling, set up in double precision) take the scalar function. */
void rt_light_sample_lanes(rt_shade_lanes *l, const rt_trace_ctx *ctx, const rt_light *light, size_t n);
/* The rest of rt_path_nee_light_at for those samples: the geometric side
 * test, the BSDF of kind (RT_BSDF_KIND_LAMBERT, _CONDUCTOR, _GLTF or _PLASTIC, as
 * rt_shade_lanes_kind says; their inputs above, wo included) evaluated at
 * the light's direction, the power heuristic against its pdf when mis
 * (an area light with a visible quad), into fr .. rok. */
void rt_nee_eval_lanes(rt_shade_lanes *l, int kind, bool mis, size_t n);

#endif
