/* shade_lanes.c - BSDF sampling and weighting, and light sampling with
 * the BSDF evaluated at the light and the power heuristic, in SIMD lanes
 * over structure-of-arrays paths (rt/render/shade_lanes.h): the
 * wavefront's shading of a material kind, RT_SHADE_LANES paths a step,
 * written once with GCC / clang vector types.
 *
 * The approach is Afra, Benthin, Wald and Munkberg, "Local shading
 * coherence extraction for SIMD-efficient path tracing on CPUs" (HPG
 * 2016): the wavefront sorts its paths by material kind and compacts one
 * kind's into arrays, so a kind's lobes run in full SIMD lanes instead of
 * one path at a time. Each lane repeats the scalar code's operations in
 * its order (rt/render/sampling.h's concentric cosine sampling and
 * rt/base/vec.h's rt_sincosf, bsdf.c's lambert_sample and finish_sample,
 * pathtrace.c's rt_path_vertex_end; light.c's rt_light_sample_at,
 * bsdf.c's evaluations, pathtrace.c's rt_path_nee_light_at), branches as
 * selects: the same bits. The solid-angle sampling of a rectangle seen
 * large (light.c, spherical.c: double precision, atan2) is called per
 * lane from the vector step, so it keeps its bits too.
 */
#include "rt/render/shade_lanes.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#if defined(__SSE__)
#include <immintrin.h>
#endif

#include <math.h>

#include "rt/base/alloc.h"
#include "rt/base/vec.h"

#define W RT_SHADE_LANES
typedef float vf __attribute__((vector_size(4 * W)));
typedef int32_t vi __attribute__((vector_size(4 * W)));

static inline vf load(const float *p)
{
    vf v;
    memcpy(&v, p, sizeof v);
    return v;
}
static inline void store(float *p, vf v) { memcpy(p, &v, sizeof v); }
static inline vf splat(float x) { return x - (vf){0}; }
/* m ? a : b, lane by lane (m all ones or zero) */
static inline vf sel(vi m, vf a, vf b) { return (vf)(((vi)a & m) | ((vi)b & ~m)); }
static inline vf vabs(vf x) { return (vf)((vi)x & 0x7fffffff); }
static inline vi finite(vf x) { return ((vi)x & 0x7fffffff) < 0x7f800000; }
/* rt_fmaxf(a, b): a when a > b or b is NaN */
static inline vf vmax(vf a, vf b) { return sel((a > b) | (b != b), a, b); }

/* sqrtf, lane by lane: IEEE's correctly rounded square root in every
 * instruction set, so the same bits as the scalar sqrtss */
static inline vf vsqrt(vf x)
{
#if W == 16
    return (vf)_mm512_sqrt_ps((__m512)x);
#elif W == 8
    return (vf)_mm256_sqrt_ps((__m256)x);
#elif defined(__SSE__)
    return (vf)_mm_sqrt_ps((__m128)x);
#else
    for (int k = 0; k < W; k++)
        x[k] = __builtin_sqrtf(x[k]);
    return x;
#endif
}

/* rt_sincosf, lane by lane */
static inline void vsincos(vf x, vf *s, vf *c)
{
    vi q = __builtin_convertvector(x * 0.636619772f + sel(x >= 0.0f, splat(0.5f), splat(-0.5f)), vi);
    vf k = __builtin_convertvector(q, vf);
    vf r = ((x - k * 1.5703125f) - k * 4.837512969970703125e-4f) - k * 7.54978995489188216e-8f;
    vf r2 = r * r;
    vf sp = r + r * r2 * (-1.0f / 6.0f + r2 * (1.0f / 120.0f + r2 * (-1.0f / 5040.0f + r2 * (1.0f / 362880.0f))));
    vf cp = 1.0f + r2 * (-0.5f + r2 * (1.0f / 24.0f + r2 * (-1.0f / 720.0f + r2 * (1.0f / 40320.0f +
                                                                                  r2 * (-1.0f / 3628800.0f)))));
    vi qq = q & 3;
    vi q0 = qq == 0, q1 = qq == 1, q2 = qq == 2;
    *s = sel(q0, sp, sel(q1, cp, sel(q2, -sp, -cp)));
    *c = sel(q0, cp, sel(q1, -sp, sel(q2, -cp, sp)));
}

/* rt_sample_cosine_hemisphere, lane by lane */
static inline void vcosine_hemisphere(vf ux, vf uy, vf *x, vf *y, vf *z)
{
    vf a = 2.0f * ux - 1.0f, b = 2.0f * uy - 1.0f;
    vi zero = (a == 0.0f) & (b == 0.0f), wide = vabs(a) > vabs(b);
    vf r = sel(zero, splat(0.0f), sel(wide, a, b));
    vf phi = sel(zero, splat(0.0f), sel(wide, (RT_PI / 4.0f) * (b / a), (RT_PI / 2.0f) - (RT_PI / 4.0f) * (a / b)));
    vf sn, cs;
    vsincos(phi, &sn, &cs);
    *x = r * cs;
    *y = r * sn;
    *z = vsqrt(vmax(splat(0.0f), 1.0f - *x * *x - *y * *y));
}

/* rt_normalize, lane by lane: a zero vector stays zero */
static inline void vnormalize(vf *x, vf *y, vf *z)
{
    vf l2 = *x * *x + *y * *y + *z * *z;
    vi pos = l2 > 0.0f;
    vf s = 1.0f / vsqrt(l2);
    *x = sel(pos, *x * s, *x);
    *y = sel(pos, *y * s, *y);
    *z = sel(pos, *z * s, *z);
}

/* The end of every kind's step: the local direction (x, y, z) taken to
 * the world and normalised, on the geometric surface's side the sample
 * is on (below: refracted), the throughput
 * times the weight (w), finite and positive (rt_path_vertex_end's steps);
 * the results stored, with which samples were deltas. */
static inline void world_and_weigh(rt_shade_lanes *l, size_t k, vf x, vf y, vf z, vf pdf, vf wr, vf wg, vf wb, vi ok,
                                   vi below, vi delta)
{
    vf tx = load(l->tx + k), ty = load(l->ty + k), tz = load(l->tz + k);
    vf bx = load(l->bx + k), by = load(l->by + k), bz = load(l->bz + k);
    vf nx = load(l->nx + k), ny = load(l->ny + k), nz = load(l->nz + k);
    vf ox = tx * x + bx * y + nx * z, oy = ty * x + by * y + ny * z, oz = tz * x + bz * y + nz * z;
    vnormalize(&ox, &oy, &oz);
    vf side = ox * load(l->gx + k) + oy * load(l->gy + k) + oz * load(l->gz + k);
    ok &= (below & (side < 0.0f)) | (~below & (side > 0.0f));
    vf br = load(l->br + k) * wr, bg = load(l->bg + k) * wg, bb = load(l->bb + k) * wb;
    ok &= finite(br) & finite(bg) & finite(bb) & ((br > 0.0f) | (bg > 0.0f) | (bb > 0.0f));
    store(l->wx + k, ox);
    store(l->wy + k, oy);
    store(l->wz + k, oz);
    store(l->pdf + k, pdf);
    store(l->br + k, br);
    store(l->bg + k, bg);
    store(l->bb + k, bb);
    for (int j = 0; j < W; j++) {
        l->ok[k + (size_t)j] = ok[j] != 0;
        l->down[k + (size_t)j] = below[j] != 0;
        l->delta[k + (size_t)j] = delta[j] != 0;
    }
}

/* One SIMD step of Lambert: paths k .. k + W - 1 (bsdf.c's lambert_sample). */
static void lambert_step(rt_shade_lanes *l, size_t k)
{
    vf dr = load(l->dr + k), dg = load(l->dg + k), db = load(l->db + k);
    /* lambert_sample: a black albedo scatters nothing */
    vi ok = (dr + dg + db) * (1.0f / 3.0f) > 0.0f;
    vf x, y, z;
    vcosine_hemisphere(load(l->ux + k), load(l->uy + k), &x, &y, &z);
    ok &= (z > 0.0f) & finite(x) & finite(y) & finite(z);
    vnormalize(&x, &y, &z);
    ok &= z > 0.0f;
    /* finish_sample: f = albedo / pi, pdf = cos / pi, weight f cos / pdf */
    vf pdf = z * RT_INV_PI;
    ok &= (pdf > 0.0f) & finite(pdf);
    vf c = z / pdf;
    vf wr = dr * RT_INV_PI * c, wg = dg * RT_INV_PI * c, wb = db * RT_INV_PI * c;
    ok &= finite(wr) & finite(wg) & finite(wb);
    world_and_weigh(l, k, x, y, z, pdf, wr, wg, wb, ok, (vi){0}, (vi){0});
}

/* The last step's unused lanes (n .. the next multiple of W): zeros in
 * every input, so they compute something harmless that nobody reads. */
static size_t pad(rt_shade_lanes *l, size_t n)
{
    size_t end = (n + W - 1) / W * W;
    float *in[] = {l->tx, l->ty, l->tz, l->bx, l->by, l->bz, l->nx, l->ny, l->nz, l->gx, l->gy, l->gz,
                   l->br, l->bg, l->bb, l->ux, l->uy, l->dr, l->dg, l->db, l->ox, l->oy, l->oz, l->ax,
                   l->ay, l->sep, l->er, l->eg, l->eb, l->kr, l->kg, l->kb, l->cr, l->cg, l->cb, l->metal,
                   l->f0, l->pd, l->ps, l->ulobe, l->pt, l->eta, l->smooth, l->px, l->py, l->pz, l->lux,
                   l->luy};
    for (size_t a = 0; a < sizeof in / sizeof in[0]; a++)
        for (size_t k = n; k < end; k++)
            in[a][k] = 0.0f;
    return end;
}

void rt_lambert_sample_lanes(rt_shade_lanes *l, size_t n)
{
    size_t end = pad(l, n);
    for (size_t k = 0; k < end; k += W)
        lambert_step(l, k);
}

/* ------------------------------------------------------------ GGX conductor */

static inline vf vclamp01(vf x) { return sel(x < 0.0f, splat(0.0f), sel(x > 1.0f, splat(1.0f), x)); }

/* microfacet.h's rt_ggx_lambda_xy (its isotropic rt_ggx_lambda where
 * ax == ay), lane by lane; INFINITY at or below the horizon */
static inline vf vlambda(vf x, vf y, vf z, vf ax, vf ay)
{
    vf c2 = z * z;
    vf s2 = x * x + y * y;
    vf t2 = sel(ax == ay, ax * ax * s2 / c2, (ax * ax * x * x + ay * ay * y * y) / c2);
    vf l = 0.5f * t2 / (vsqrt(1.0f + t2) + 1.0f);
    return sel(c2 > 0.0f, l, splat(INFINITY));
}

/* rt_ggx_d_xy (rt_ggx_d where ax == ay) at the unit half vector h */
static inline vf vggx_d(vf hx, vf hy, vf hz, vf ax, vf ay)
{
    vf a2 = ax * ax;
    vf k_iso = a2 * (hz * hz) + (hx * hx + hy * hy);
    vf d_iso = a2 / (RT_PI * k_iso * k_iso);
    vf x = hx / ax, y = hy / ay;
    vf k = x * x + y * y + hz * hz;
    vf d_xy = 1.0f / (RT_PI * ax * ay * k * k);
    vf d = sel(ax == ay, d_iso, d_xy);
    return sel((hz > 0.0f) & finite(d), d, splat(0.0f));
}

/* microfacet.c's fresnel_conductor1, one channel in every lane */
static inline vf vfresnel_conductor(vf c, vf eta, vf k)
{
    c = vclamp01(c);
    vf c2 = c * c, s2 = 1.0f - c2;
    vf eta2 = eta * eta, k2 = k * k;
    vf t0 = eta2 - k2 - s2;
    vf a2b2 = vsqrt(vmax(splat(0.0f), t0 * t0 + 4.0f * eta2 * k2));
    vf t1 = a2b2 + c2;
    vf a = vsqrt(vmax(splat(0.0f), 0.5f * (a2b2 + t0)));
    vf t2 = 2.0f * c * a;
    vf rs = (t1 - t2) / (t1 + t2);
    vf t3 = c2 * a2b2 + s2 * s2;
    vf t4 = t2 * s2;
    vf rp = rs * (t3 - t4) / (t3 + t4);
    vf f = 0.5f * (rs + rp);
    return sel(finite(f), vclamp01(f), splat(1.0f));
}

/* rt_ggx_sample_vndf_xy (Heitz 2018): a visible normal for wo */
static inline void vvndf(vf wx, vf wy, vf wz, vf ax, vf ay, vf ux, vf uy, vf *hx, vf *hy, vf *hz)
{
    vf vx = ax * wx, vy = ay * wy, vz = wz;
    vnormalize(&vx, &vy, &vz);
    vf lensq = vx * vx + vy * vy;
    vi tilted = lensq > 1e-14f;
    vf inv = 1.0f / vsqrt(lensq);
    vf t1x = sel(tilted, -vy * inv, splat(1.0f)), t1y = sel(tilted, vx * inv, splat(0.0f));
    vf t1z = sel(tilted, 0.0f * inv, splat(0.0f));
    vf t2x = vy * t1z - vz * t1y, t2y = vz * t1x - vx * t1z, t2z = vx * t1y - vy * t1x;
    vf r = vsqrt(ux), phi = 2.0f * RT_PI * uy;
    vf sn, cs;
    vsincos(phi, &sn, &cs);
    vf p1 = r * cs, p2 = r * sn;
    vf s = 0.5f * (1.0f + vz);
    p2 = (1.0f - s) * vsqrt(vmax(splat(0.0f), 1.0f - p1 * p1)) + s * p2;
    vf q = vsqrt(vmax(splat(0.0f), 1.0f - p1 * p1 - p2 * p2));
    vf nx = t1x * p1 + t2x * p2 + vx * q, ny = t1y * p1 + t2y * p2 + vy * q, nz = t1z * p1 + t2z * p2 + vz * q;
    *hx = ax * nx;
    *hy = ay * ny;
    *hz = vmax(splat(1e-7f), nz);
    vnormalize(hx, hy, hz);
}

/* bsdf.c's conductor_eval with its one lobe (p_specular 1): f (zero
 * where it is not valid) and the VNDF pdf at wi = (x, y, z) from wo
 * (local, wi unit), and which lanes are valid (both above, not opposite,
 * finite). */
static inline vi vconductor_eval(const rt_shade_lanes *l, size_t k, vf wox, vf woy, vf woz, vf x, vf y, vf z,
                                 vf *fr, vf *fg, vf *fb, vf *pdf)
{
    vf ax = load(l->ax + k), ay = load(l->ay + k);
    vi ok = (woz > 0.0f) & (z > 0.0f);
    vf mx = wox + x, my = woy + y, mz = woz + z;
    vf l2 = mx * mx + my * my + mz * mz;
    ok &= l2 > 1e-20f;
    vf inv = 1.0f / vsqrt(l2);
    mx = mx * inv, my = my * inv, mz = mz * inv;
    vf voh = wox * mx + woy * my + woz * mz;
    vf D = vggx_d(mx, my, mz, ax, ay);
    vf lo = vlambda(wox, woy, woz, ax, ay), li = vlambda(x, y, z, ax, ay);
    vi sep = load(l->sep + k) != 0.0f;
    vf g2 = sel(sep, 1.0f / ((1.0f + lo) * (1.0f + li)), 1.0f / (1.0f + lo + li));
    g2 = sel(finite(lo) & finite(li), g2, splat(0.0f));
    vf spec = D * g2 / (4.0f * woz * z);
    vf g1 = sel(finite(lo), 1.0f / (1.0f + lo), splat(0.0f));
    vf pv = g1 * D / (4.0f * woz);
    ok &= finite(spec) & finite(pv);
    *pdf = sel(ok, 1.0f * pv, splat(0.0f));
    *fr = sel(ok, vfresnel_conductor(voh, load(l->er + k), load(l->kr + k)) * spec, splat(0.0f));
    *fg = sel(ok, vfresnel_conductor(voh, load(l->eg + k), load(l->kg + k)) * spec, splat(0.0f));
    *fb = sel(ok, vfresnel_conductor(voh, load(l->eb + k), load(l->kb + k)) * spec, splat(0.0f));
    return ok;
}

/* One SIMD step of the rough conductor: bsdf.c's conductor_sample with
 * its one lobe (p_specular 1), conductor_eval and finish_sample. */
static void conductor_step(rt_shade_lanes *l, size_t k)
{
    vf wox = load(l->ox + k), woy = load(l->oy + k), woz = load(l->oz + k);
    vf hx, hy, hz;
    vvndf(wox, woy, woz, load(l->ax + k), load(l->ay + k), load(l->ux + k), load(l->uy + k), &hx, &hy, &hz);
    vf c = 2.0f * (wox * hx + woy * hy + woz * hz);
    vf x = hx * c - wox, y = hy * c - woy, z = hz * c - woz;
    vi ok = (z > 0.0f) & finite(x) & finite(y) & finite(z);
    vnormalize(&x, &y, &z);
    vf fr, fg, fb, pdf;
    ok &= vconductor_eval(l, k, wox, woy, woz, x, y, z, &fr, &fg, &fb, &pdf);
    /* finish_sample */
    ok &= pdf > 0.0f;
    vf cw = z / pdf;
    vf wr = fr * cw, wg = fg * cw, wb = fb * cw;
    ok &= finite(wr) & finite(wg) & finite(wb);
    world_and_weigh(l, k, x, y, z, pdf, wr, wg, wb, ok, (vi){0}, (vi){0});
}

void rt_conductor_sample_lanes(rt_shade_lanes *l, size_t n)
{
    size_t end = pad(l, n);
    for (size_t k = 0; k < end; k += W)
        conductor_step(l, k);
}

/* ------------------------------------------------------------ the glTF BRDF */

/* microfacet.h's rt_schlick_weight: (1 - c)^5, c clamped to [0, 1] */
static inline vf vschlick_weight(vf c)
{
    vf x = 1.0f - vclamp01(c);
    vf x2 = x * x;
    return x2 * x2 * x;
}

/* One channel of the specular lobe's Fresnel (bsdf.c's
 * fresnel_specular): the mix by metallic m of Schlick on the base colour
 * and the dielectric's fd */
static inline vf vfresnel_specular(vf base, vf m, vf w, vf fd)
{
    vf fm = sel(m > 0.0f, base + (1.0f - base) * w, splat(0.0f));
    return fd * (1.0f - m) + fm * m;
}

/* bsdf.c's dielectric_eval for the rough, opaque glTF BRDF (no
 * transmission): f (zero where not valid) and pdf at wi = (x, y, z) from
 * wo, and which lanes are valid (both above, not opposite). */
static inline vi vgltf_eval(const rt_shade_lanes *l, size_t k, vf wox, vf woy, vf woz, vf x, vf y, vf z, vf *fr,
                            vf *fg, vf *fb, vf *pdf)
{
    vf a = load(l->ax + k), pd = load(l->pd + k), ps = load(l->ps + k);
    vi ok = (woz > 0.0f) & (z > 0.0f);
    vf mx = wox + x, my = woy + y, mz = woz + z;
    vf l2 = mx * mx + my * my + mz * mz;
    ok &= l2 > 1e-20f;
    vf inv = 1.0f / vsqrt(l2);
    mx = mx * inv, my = my * inv, mz = mz * inv;
    vf voh = wox * mx + woy * my + woz * mz;
    vf f0 = load(l->f0 + k), w = vschlick_weight(voh);
    vf fd = f0 + (1.0f - f0) * w;
    /* the diffuse lobe: (1 - fd) (1 - T) diffuse / pi, T = 0 */
    vf tdiff = (1.0f - fd) * 1.0f;
    vf p = pd * z * RT_INV_PI;
    /* the specular lobe: F D G2 / (4 cos cos), VNDF pdf */
    vf D = vggx_d(mx, my, mz, a, a);
    vf lo = vlambda(wox, woy, woz, a, a), li = vlambda(x, y, z, a, a);
    vf g2 = sel(finite(lo) & finite(li), 1.0f / (1.0f + lo + li), splat(0.0f));
    vf spec = D * g2 / (4.0f * woz * z);
    spec = sel(finite(spec), spec, splat(0.0f));
    vf g1 = sel(finite(lo), 1.0f / (1.0f + lo), splat(0.0f));
    vf pv = g1 * D / (4.0f * woz);
    p = sel((ps > 0.0f) & finite(pv), p + ps * pv, p);
    vf m = load(l->metal + k);
    *fr = sel(ok, load(l->dr + k) * (tdiff * RT_INV_PI) + vfresnel_specular(load(l->cr + k), m, w, fd) * spec,
              splat(0.0f));
    *fg = sel(ok, load(l->dg + k) * (tdiff * RT_INV_PI) + vfresnel_specular(load(l->cg + k), m, w, fd) * spec,
              splat(0.0f));
    *fb = sel(ok, load(l->db + k) * (tdiff * RT_INV_PI) + vfresnel_specular(load(l->cb + k), m, w, fd) * spec,
              splat(0.0f));
    *pdf = sel(ok, p, splat(0.0f));
    return ok;
}

/* One SIMD step of the rough, opaque glTF BRDF: bsdf.c's
 * dielectric_sample with no transmission (the diffuse lobe by the cosine
 * or the specular one by its visible normals), dielectric_eval and
 * finish_sample. */
static void gltf_step(rt_shade_lanes *l, size_t k)
{
    vf wox = load(l->ox + k), woy = load(l->oy + k), woz = load(l->oz + k);
    vf a = load(l->ax + k), ay = load(l->ay + k), pd = load(l->pd + k), ps = load(l->ps + k);
    vf ux = load(l->ux + k), uy = load(l->uy + k);
    vi ok = pd + ps > 0.0f;
    vi diffuse = (load(l->ulobe + k) < pd) | ~(ps > 0.0f);
    vf cx, cy, cz, hx, hy, hz;
    vcosine_hemisphere(ux, uy, &cx, &cy, &cz);
    vvndf(wox, woy, woz, a, ay, ux, uy, &hx, &hy, &hz); /* (the glTF BRDF's ay is a: its eval is isotropic) */
    vf c = 2.0f * (wox * hx + woy * hy + woz * hz);
    vf x = sel(diffuse, cx, hx * c - wox), y = sel(diffuse, cy, hy * c - woy), z = sel(diffuse, cz, hz * c - woz);
    ok &= (z > 0.0f) & finite(x) & finite(y) & finite(z);
    vnormalize(&x, &y, &z);
    vf fr, fg, fb, p;
    ok &= vgltf_eval(l, k, wox, woy, woz, x, y, z, &fr, &fg, &fb, &p);
    /* finish_sample */
    ok &= (p > 0.0f) & finite(p);
    vf cw = z / p;
    vf wr = fr * cw, wg = fg * cw, wb = fb * cw;
    ok &= finite(wr) & finite(wg) & finite(wb);
    world_and_weigh(l, k, x, y, z, p, wr, wg, wb, ok, (vi){0}, (vi){0});
}

void rt_gltf_sample_lanes(rt_shade_lanes *l, size_t n)
{
    size_t end = pad(l, n);
    for (size_t k = 0; k < end; k += W)
        gltf_step(l, k);
}

/* ------------------------------------------------------------ smooth dielectric */

/* microfacet.c's rt_fresnel_exact: unpolarised Fresnel reflectance of a
 * smooth dielectric interface, 1 past the critical angle */
static inline vf vfresnel_exact(vf cos_i, vf eta)
{
    vf ci = vclamp01(cos_i);
    vf sin2_t = eta * eta * (1.0f - ci * ci);
    vf ct = vsqrt(1.0f - sin2_t);
    vf rs = (eta * ci - ct) / (eta * ci + ct);
    vf rp = (ci - eta * ct) / (ci + eta * ct);
    vf f = 0.5f * (rs * rs + rp * rp);
    return sel(sin2_t < 1.0f, sel(finite(f), vclamp01(f), splat(1.0f)), splat(1.0f));
}

/* One SIMD step of smooth glass: bsdf.c's dielectric_sample for a delta
 * interface, refraction about the normal (weight (1 - F) T eta^2 tint /
 * p_t) or the mirror (weight F / p_s), chosen by ulobe. */
static void dielectric_step(rt_shade_lanes *l, size_t k)
{
    vf wox = load(l->ox + k), woy = load(l->oy + k), woz = load(l->oz + k);
    vf pd = load(l->pd + k), ps = load(l->ps + k), pt = load(l->pt + k), ul = load(l->ulobe + k);
    vf eta = load(l->eta + k);
    vi ok = pd + ps + pt + 0.0f > 0.0f;
    vi refract = (pt > 0.0f) & (ul >= pd + ps);
    vi mirror = ~refract & (ps > 0.0f) & (ul >= pd);
    ok &= refract | mirror;
    /* refraction about the macro normal h = (0, 0, 1) */
    vf ci = wox * 0.0f + woy * 0.0f + woz * 1.0f;
    vf sin2_t = eta * eta * vmax(splat(0.0f), 1.0f - ci * ci);
    vf ct = vsqrt(1.0f - sin2_t);
    vf a = eta * ci - ct;
    vf rx = wox * -eta + 0.0f * a, ry = woy * -eta + 0.0f * a, rz = woz * -eta + 1.0f * a;
    ok &= ~refract | ((ci > 0.0f) & ~(sin2_t >= 1.0f) & (rz < 0.0f));
    vnormalize(&rx, &ry, &rz);
    vf tw = (1.0f - vfresnel_exact(ci, eta)) * 1.0f * 1.0f * (eta * eta) / pt;
    /* the mirror */
    vf mw = (vfresnel_exact(woz, eta) * (1.0f - 0.0f) + 0.0f * 0.0f) * (1.0f / ps);
    vf x = sel(refract, rx, -wox), y = sel(refract, ry, -woy), z = sel(refract, rz, woz);
    vf wr = sel(refract, load(l->dr + k) * tw, mw);
    vf wg = sel(refract, load(l->dg + k) * tw, mw);
    vf wb = sel(refract, load(l->db + k) * tw, mw);
    /* delta_sample: finite, some weight */
    ok &= finite(x) & finite(y) & finite(z) & finite(wr) & finite(wg) & finite(wb);
    ok &= (wr > 0.0f) | (wg > 0.0f) | (wb > 0.0f);
    world_and_weigh(l, k, x, y, z, splat(0.0f), wr, wg, wb, ok, refract, (vi){0} - 1);
}

void rt_dielectric_sample_lanes(rt_shade_lanes *l, size_t n)
{
    size_t end = pad(l, n);
    for (size_t k = 0; k < end; k += W)
        dielectric_step(l, k);
}

/* ------------------------------------------------------------ plastic */

/* bsdf.c's dielectric_eval for the plastic: the diffuse base under the
 * coat, (1 - F(wo.z)) (1 - F(wi.z)) diffuse / pi (exact Fresnel), and
 * for a rough coat (smooth 0) the specular lobe F(wo.h) D G2 / (4 cos
 * cos); f (zero where not valid) and pdf at wi = (x, y, z) from wo, and
 * which lanes are valid (both above, not opposite). */
static inline vi vplastic_eval(const rt_shade_lanes *l, size_t k, vf wox, vf woy, vf woz, vf x, vf y, vf z, vf *fr,
                               vf *fg, vf *fb, vf *pdf)
{
    vf a = load(l->ax + k), pd = load(l->pd + k), ps = load(l->ps + k), eta = load(l->eta + k);
    vi rough = load(l->smooth + k) == 0.0f;
    vi ok = (woz > 0.0f) & (z > 0.0f);
    vf mx = wox + x, my = woy + y, mz = woz + z;
    vf l2 = mx * mx + my * my + mz * mz;
    ok &= l2 > 1e-20f;
    vf inv = 1.0f / vsqrt(l2);
    mx = mx * inv, my = my * inv, mz = mz * inv;
    vf voh = wox * mx + woy * my + woz * mz;
    vf fd = vfresnel_exact(voh, eta);
    vf tdiff = (1.0f - vfresnel_exact(woz, eta)) * (1.0f - vfresnel_exact(z, eta));
    vf p = pd * z * RT_INV_PI;
    /* the specular lobe (fresnel_specular with metallic 0: fd) */
    vf F = vfresnel_specular(splat(0.0f), splat(0.0f), splat(0.0f), fd);
    vf D = vggx_d(mx, my, mz, a, a);
    vf lo = vlambda(wox, woy, woz, a, a), li = vlambda(x, y, z, a, a);
    vf g2 = sel(finite(lo) & finite(li), 1.0f / (1.0f + lo + li), splat(0.0f));
    vf spec = D * g2 / (4.0f * woz * z);
    spec = sel(finite(spec), spec, splat(0.0f));
    vf g1 = sel(finite(lo), 1.0f / (1.0f + lo), splat(0.0f));
    vf pv = g1 * D / (4.0f * woz);
    p = sel(rough & (ps > 0.0f) & finite(pv), p + ps * pv, p);
    vf dr = load(l->dr + k) * (tdiff * RT_INV_PI), dg = load(l->dg + k) * (tdiff * RT_INV_PI);
    vf db = load(l->db + k) * (tdiff * RT_INV_PI);
    *fr = sel(ok, sel(rough, dr + F * spec, dr), splat(0.0f));
    *fg = sel(ok, sel(rough, dg + F * spec, dg), splat(0.0f));
    *fb = sel(ok, sel(rough, db + F * spec, db), splat(0.0f));
    *pdf = sel(ok, p, splat(0.0f));
    return ok;
}

/* One SIMD step of the plastic: bsdf.c's dielectric_sample for its kind
 * (no transmission): a smooth coat's mirror (delta, weight F / ps) by
 * ulobe, else the diffuse lobe by the cosine or a rough coat's specular
 * one by its visible normals, dielectric_eval and finish_sample. */
static void plastic_step(rt_shade_lanes *l, size_t k)
{
    vf wox = load(l->ox + k), woy = load(l->oy + k), woz = load(l->oz + k);
    vf a = load(l->ax + k), ay = load(l->ay + k), pd = load(l->pd + k), ps = load(l->ps + k);
    vf ux = load(l->ux + k), uy = load(l->uy + k), ul = load(l->ulobe + k);
    vi smooth = load(l->smooth + k) != 0.0f;
    vi any = pd + ps + 0.0f + 0.0f > 0.0f;
    vi mirror = smooth & (ps > 0.0f) & (ul >= pd);
    /* the mirror: delta_sample of (-wo.x, -wo.y, wo.z), weight F(wo.z) / ps */
    vf mw = vfresnel_specular(splat(0.0f), splat(0.0f), splat(0.0f), vfresnel_exact(woz, load(l->eta + k))) *
            (1.0f / ps);
    vi mok = (woz > 0.0f) & finite(wox) & finite(woy) & finite(mw) & (mw > 0.0f);
    /* the diffuse or the specular lobe */
    vi diffuse = (ul < pd) | smooth | ~(ps > 0.0f);
    vf cx, cy, cz, hx, hy, hz;
    vcosine_hemisphere(ux, uy, &cx, &cy, &cz);
    vvndf(wox, woy, woz, a, ay, ux, uy, &hx, &hy, &hz);
    vf c = 2.0f * (wox * hx + woy * hy + woz * hz);
    vf x = sel(diffuse, cx, hx * c - wox), y = sel(diffuse, cy, hy * c - woy), z = sel(diffuse, cz, hz * c - woz);
    vi ok = (z > 0.0f) & finite(x) & finite(y) & finite(z);
    vnormalize(&x, &y, &z);
    vf fr, fg, fb, p;
    ok &= vplastic_eval(l, k, wox, woy, woz, x, y, z, &fr, &fg, &fb, &p);
    /* finish_sample */
    ok &= (p > 0.0f) & finite(p);
    vf cw = z / p;
    vf wr = fr * cw, wg = fg * cw, wb = fb * cw;
    ok &= finite(wr) & finite(wg) & finite(wb);
    x = sel(mirror, -wox, x), y = sel(mirror, -woy, y), z = sel(mirror, woz, z);
    world_and_weigh(l, k, x, y, z, sel(mirror, splat(0.0f), p), sel(mirror, mw, wr), sel(mirror, mw, wg),
                    sel(mirror, mw, wb), any & ((mirror & mok) | (~mirror & ok)), (vi){0}, mirror);
}

void rt_plastic_sample_lanes(rt_shade_lanes *l, size_t n)
{
    size_t end = pad(l, n);
    for (size_t k = 0; k < end; k += W)
        plastic_step(l, k);
}

/* ------------------------------------------------------------ light sampling */

static inline vi mask_of(const uint8_t *p)
{
    vi m;
    for (int j = 0; j < W; j++)
        m[j] = p[j] ? -1 : 0;
    return m;
}

static inline void store_mask(uint8_t *p, vi m)
{
    for (int j = 0; j < W; j++)
        p[j] = m[j] != 0;
}

/* rt_light_sample's fields, stored (pdf 0 for the deltas, whose scalar
 * pdf is unset and never read) */
static inline void store_light(rt_shade_lanes *l, size_t k, vf wx, vf wy, vf wz, vf dist, vf r, vf g, vf b, vf pdf,
                               vi ok)
{
    store(l->lwx + k, wx);
    store(l->lwy + k, wy);
    store(l->lwz + k, wz);
    store(l->ldist + k, dist);
    store(l->lr + k, r);
    store(l->lg + k, g);
    store(l->lb + k, b);
    store(l->lpdf + k, pdf);
    store_mask(l->lok + k, ok);
}

/* light.c's toward(p, q): the unit direction and the distance from p to
 * q, their squared distance; false where they coincide */
static inline vi vtoward(vf px, vf py, vf pz, vf qx, vf qy, vf qz, vf *wx, vf *wy, vf *wz, vf *dist, vf *d2)
{
    vf dx = qx - px, dy = qy - py, dz = qz - pz;
    *d2 = dx * dx + dy * dy + dz * dz;
    *dist = vsqrt(*d2);
    vf inv = 1.0f / *dist;
    *wx = dx * inv, *wy = dy * inv, *wz = dz * inv;
    return *d2 > 0.0f;
}

/* One SIMD step of a point or spot light: rt_light_sample_at's intensity
 * over d^2, the spot's smooth cone (its cosines and unit direction from
 * the caller, computed as the scalar code computes them) and the range
 * window. */
static void point_step(rt_shade_lanes *l, size_t k, const rt_light *lt, rt_vec3 power, rt_vec3 axis, float co,
                       float ci)
{
    vf wx, wy, wz, dist, d2;
    vi ok = vtoward(load(l->px + k), load(l->py + k), load(l->pz + k), splat(lt->position.x), splat(lt->position.y),
                    splat(lt->position.z), &wx, &wy, &wz, &dist, &d2);
    vf atten = 1.0f / d2;
    if (lt->kind == RT_LIGHT_SPOT) {
        vf cd = axis.x * -wx + axis.y * -wy + axis.z * -wz;
        vf x = ci > co ? vclamp01((cd - co) / (ci - co)) : sel(cd >= co, splat(1.0f), splat(0.0f));
        atten = atten * (x * x);
    }
    if (lt->range > 0.0f) {
        vf r = dist / lt->range, r4 = r * r * r * r;
        vf win = vclamp01(1.0f - r4);
        atten = atten * (win * win);
    }
    ok &= atten > 0.0f;
    store_light(l, k, wx, wy, wz, dist, power.x * atten, power.y * atten, power.z * atten, splat(0.0f), ok);
}

/* What an area light's step takes from the light, computed once as the
 * scalar code computes it per sample. */
typedef struct area_consts {
    rt_vec3 n, unit, centre; /* edge_u x edge_v, it normalised, the centre */
    float area, size2;
    bool rect;               /* edges perpendicular: solid-angle sampling may apply */
    rt_vec3 power;
} area_consts;

/* One SIMD step of an area light sampled by area (rt_light_sample_at's
 * second branch); the lanes that see a rectangle large (looks_large) are
 * flagged in *solid, for the scalar function. */
static vi area_step(rt_shade_lanes *l, size_t k, const rt_light *lt, const area_consts *a)
{
    vf px = load(l->px + k), py = load(l->py + k), pz = load(l->pz + k);
    /* looks_large(n, centre - p, size2) */
    vf dx = a->centre.x - px, dy = a->centre.y - py, dz = a->centre.z - pz;
    vf nd = -(a->n.x * dx + a->n.y * dy + a->n.z * dz), dd2 = dx * dx + dy * dy + dz * dz;
    vi solid = (nd > 0.0f) & ((dd2 <= a->size2) | (nd >= 0.1f * dd2 * vsqrt(dd2)));
    if (!a->rect)
        solid = (vi){0};
    /* the point position + u.x edge_u + u.y edge_v */
    vf ux = load(l->lux + k), uy = load(l->luy + k);
    vf qx = lt->position.x + (lt->edge_u.x * ux + lt->edge_v.x * uy);
    vf qy = lt->position.y + (lt->edge_u.y * ux + lt->edge_v.y * uy);
    vf qz = lt->position.z + (lt->edge_u.z * ux + lt->edge_v.z * uy);
    vf wx, wy, wz, dist, d2;
    vi ok = vtoward(px, py, pz, qx, qy, qz, &wx, &wy, &wz, &dist, &d2);
    vf cos_l = -(a->unit.x * wx + a->unit.y * wy + a->unit.z * wz);
    ok &= cos_l > 0.0f;
    vf s = a->area * cos_l / d2;
    /* area_light_area_pdf */
    vf c2 = -(a->n.x * wx + a->n.y * wy + a->n.z * wz) / a->area;
    vf pdf = dist * dist / (a->area * c2);
    pdf = sel((c2 > 0.0f) & finite(pdf), pdf, splat(0.0f));
    store_light(l, k, wx, wy, wz, dist, a->power.x * s, a->power.y * s, a->power.z * s, pdf, ok);
    return solid;
}

void rt_light_sample_lanes(rt_shade_lanes *l, const rt_trace_ctx *ctx, const rt_light *lt, size_t n)
{
    size_t end = pad(l, n);
    rt_vec3 power = rt_scale(lt->color, lt->intensity);
    if (lt->kind == RT_LIGHT_POINT || lt->kind == RT_LIGHT_SPOT) {
        rt_vec3 axis = rt_normalize(lt->direction);
        float co = cosf(lt->outer_cone), ci = cosf(lt->inner_cone);
        for (size_t k = 0; k < end; k += W)
            point_step(l, k, lt, power, axis, co, ci);
        return;
    }
    if (lt->kind == RT_LIGHT_DIRECTIONAL) {
        rt_vec3 wi = rt_neg(rt_normalize(lt->direction));
        vi ok = (vi){0} + (rt_length2(wi) > 0.0f ? -1 : 0);
        for (size_t k = 0; k < end; k += W)
            store_light(l, k, splat(wi.x), splat(wi.y), splat(wi.z), splat(INFINITY), splat(power.x),
                        splat(power.y), splat(power.z), splat(0.0f), ok);
        return;
    }
    area_consts a;
    a.n = rt_cross(lt->edge_u, lt->edge_v);
    a.area = rt_length(a.n);
    if (!(a.area > 0.0f)) {
        memset(l->lok, 0, end);
        return;
    }
    a.centre = rt_madd(rt_madd(lt->position, lt->edge_u, 0.5f), lt->edge_v, 0.5f);
    float lu = rt_length2(lt->edge_u), lv = rt_length2(lt->edge_v), uv = rt_dot(lt->edge_u, lt->edge_v);
    a.size2 = lu + lv;
    a.rect = uv * uv <= 1e-10f * lu * lv;
    a.unit = rt_scale(a.n, 1.0f / a.area);
    a.power = power;
    for (size_t k = 0; k < end; k += W) {
        vi solid = area_step(l, k, lt, &a);
        for (int j = 0; j < W && k + (size_t)j < n; j++) {
            if (!solid[j])
                continue;
            /* seen large: maybe its solid angle, set up in double precision */
            size_t i = k + (size_t)j;
            rt_light_sample ls = {.pdf = 0.0f};
            l->lok[i] = rt_light_sample_at(ctx, lt, rt_v3(l->px[i], l->py[i], l->pz[i]), rt_v2(l->lux[i], l->luy[i]),
                                           &ls);
            l->lwx[i] = ls.wi.x, l->lwy[i] = ls.wi.y, l->lwz[i] = ls.wi.z, l->ldist[i] = ls.dist;
            l->lr[i] = ls.li.x, l->lg[i] = ls.li.y, l->lb[i] = ls.li.z, l->lpdf[i] = ls.pdf;
        }
    }
}

/* rt_bsdf_eval of Lambert: albedo / pi, pdf cos / pi (0 for a black one) */
static inline vi vlambert_eval(const rt_shade_lanes *l, size_t k, vf woz, vf z, vf *fr, vf *fg, vf *fb, vf *pdf)
{
    vf dr = load(l->dr + k), dg = load(l->dg + k), db = load(l->db + k);
    vi ok = (woz > 0.0f) & (z > 0.0f);
    vf prob = sel((dr + dg + db) * (1.0f / 3.0f) > 0.0f, splat(1.0f), splat(0.0f));
    *pdf = sel(ok, prob * z * RT_INV_PI, splat(0.0f));
    *fr = sel(ok, dr * RT_INV_PI, splat(0.0f));
    *fg = sel(ok, dg * RT_INV_PI, splat(0.0f));
    *fb = sel(ok, db * RT_INV_PI, splat(0.0f));
    return ok;
}

/* pathtrace.h's rt_mis_power(a, b) */
static inline vf vmis_power(vf a, vf b)
{
    vf a2 = a * a, b2 = b * b;
    vf w = a2 / (a2 + b2);
    w = sel(finite(w), w, sel(a > b, splat(1.0f), splat(0.0f)));
    w = sel(((vi)vabs(a)) == 0x7f800000, splat(1.0f), w);
    return sel(a > 0.0f, w, splat(0.0f));
}

/* One SIMD step of a light sample's record (rt_path_nee_light_at after
 * rt_light_sample_at). */
static void nee_step(rt_shade_lanes *l, size_t k, int kind, bool mis)
{
    vf wx = load(l->lwx + k), wy = load(l->lwy + k), wz = load(l->lwz + k);
    vi ok = mask_of(l->lok + k);
    ok &= wx * load(l->gx + k) + wy * load(l->gy + k) + wz * load(l->gz + k) > 0.0f;
    vf x = wx * load(l->tx + k) + wy * load(l->ty + k) + wz * load(l->tz + k);
    vf y = wx * load(l->bx + k) + wy * load(l->by + k) + wz * load(l->bz + k);
    vf z = wx * load(l->nx + k) + wy * load(l->ny + k) + wz * load(l->nz + k);
    vf wox = load(l->ox + k), woy = load(l->oy + k), woz = load(l->oz + k);
    vf fr, fg, fb, pdf_b;
    if (kind == RT_BSDF_KIND_LAMBERT)
        vlambert_eval(l, k, woz, z, &fr, &fg, &fb, &pdf_b);
    else if (kind == RT_BSDF_KIND_CONDUCTOR)
        vconductor_eval(l, k, wox, woy, woz, x, y, z, &fr, &fg, &fb, &pdf_b);
    else if (kind == RT_BSDF_KIND_GLTF)
        vgltf_eval(l, k, wox, woy, woz, x, y, z, &fr, &fg, &fb, &pdf_b);
    else
        vplastic_eval(l, k, wox, woy, woz, x, y, z, &fr, &fg, &fb, &pdf_b);
    ok &= vmax(fr, vmax(fg, fb)) > 0.0f;
    vf w = mis ? vmis_power(load(l->lpdf + k), pdf_b) : splat(1.0f);
    ok &= w > 0.0f;
    store(l->fr + k, fr * load(l->lr + k));
    store(l->fg + k, fg * load(l->lg + k));
    store(l->fb + k, fb * load(l->lb + k));
    store(l->fcos + k, z);
    store(l->fw + k, w);
    store_mask(l->rok + k, ok);
}

void rt_nee_eval_lanes(rt_shade_lanes *l, int kind, bool mis, size_t n)
{
    size_t end = (n + W - 1) / W * W; /* (lanes past n compute on what they hold; nobody reads them) */
    for (size_t k = 0; k < end; k += W)
        nee_step(l, k, kind, mis);
}

rt_shade_lanes *rt_shade_lanes_new(size_t batch)
{
    rt_shade_lanes *l = rt_alloc(1, sizeof *l);
    if (!l)
        return NULL;
    l->cap = batch;
    size_t room = (batch + W - 1) / W * W;
    float **all[] = {&l->tx, &l->ty, &l->tz, &l->bx, &l->by, &l->bz, &l->nx, &l->ny, &l->nz, &l->gx, &l->gy,
                     &l->gz, &l->br, &l->bg, &l->bb, &l->ux, &l->uy, &l->dr, &l->dg, &l->db, &l->ox, &l->oy,
                     &l->oz, &l->ax, &l->ay, &l->sep, &l->er, &l->eg, &l->eb, &l->kr, &l->kg, &l->kb, &l->cr,
                     &l->cg, &l->cb, &l->metal, &l->f0, &l->pd, &l->ps, &l->ulobe, &l->pt, &l->eta, &l->smooth, &l->wx, &l->wy,
                     &l->wz, &l->pdf, &l->px, &l->py, &l->pz, &l->lux, &l->luy, &l->lwx, &l->lwy, &l->lwz,
                     &l->ldist, &l->lr, &l->lg, &l->lb, &l->lpdf, &l->fr, &l->fg, &l->fb, &l->fcos, &l->fw};
    bool ok = true;
    for (size_t a = 0; a < sizeof all / sizeof all[0]; a++)
        ok = (*all[a] = rt_alloc(room, sizeof(float))) != NULL && ok;
    ok = (l->ok = rt_alloc(room, 1)) != NULL && ok;
    ok = (l->down = rt_alloc(room, 1)) != NULL && ok;
    ok = (l->delta = rt_alloc(room, 1)) != NULL && ok;
    ok = (l->lok = rt_alloc(room, 1)) != NULL && ok;
    ok = (l->rok = rt_alloc(room, 1)) != NULL && ok;
    if (!ok) {
        rt_shade_lanes_free(l);
        return NULL;
    }
    return l;
}

void rt_shade_lanes_free(rt_shade_lanes *l)
{
    if (!l)
        return;
    float *all[] = {l->tx, l->ty, l->tz, l->bx, l->by, l->bz, l->nx, l->ny, l->nz, l->gx, l->gy, l->gz,
                    l->br, l->bg, l->bb, l->ux, l->uy, l->dr, l->dg, l->db, l->ox, l->oy, l->oz, l->ax,
                    l->ay, l->sep, l->er, l->eg, l->eb, l->kr, l->kg, l->kb, l->cr, l->cg, l->cb, l->metal,
                    l->f0, l->pd, l->ps, l->ulobe, l->pt, l->eta, l->smooth, l->wx, l->wy, l->wz, l->pdf,
                    l->px, l->py, l->pz, l->lux, l->luy, l->lwx, l->lwy, l->lwz, l->ldist, l->lr, l->lg,
                    l->lb, l->lpdf, l->fr, l->fg, l->fb, l->fcos, l->fw};
    for (size_t a = 0; a < sizeof all / sizeof all[0]; a++)
        free(all[a]);
    free(l->ok);
    free(l->down);
    free(l->delta);
    free(l->lok);
    free(l->rok);
    free(l);
}
