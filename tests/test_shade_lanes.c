/* test_shade_lanes.c - the wavefront's BSDF sampling in SIMD lanes
 * (rt/render/shade_lanes.h) against the scalar steps it replaces, bit
 * for bit: for Lambert, rough GGX conductors (isotropic, anisotropic,
 * separable or height-correlated Smith) and the rough opaque glTF BRDF
 * (metallic, dielectric and in between, both lobes), smooth glass
 * (either index ratio, tinted, mirror and refraction, total internal
 * reflection) and the plastic (smooth and rough coats mixed in one
 * batch, either index ratio, black bases; the mirror, specular and
 * diffuse lobes) over random frames, geometric
 * normals that disagree with the shading normal, random and edge sample
 * values (u = (0.5, 0.5), the concentric map's centre; 0 and just below
 * 1), black albedos and grazing views, the lanes' ok flag, direction, pdf,
 * delta flag and throughput equal rt_bsdf_sample_dir's sample taken to the world and
 * normalised, the geometric side test and beta times the weight
 * (rt_path_vertex_end). Counts that are not a multiple of the lane width
 * check the padding. The whole-image equality with path_scalar is
 * test_wavefront.c's. */
#include "test_util.h"

#include <math.h>
#include <string.h>

#include "rt/render/bsdf.h"
#include "rt/render/pathtrace.h"
#include "rt/render/shade_lanes.h"

static rt_vec3 random_dir(test_rng *r)
{
    float z = 2.0f * test_rng_float(r) - 1.0f, phi = 2.0f * RT_PI * test_rng_float(r);
    float s = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    return rt_normalize(rt_v3(s * cosf(phi), s * sinf(phi), z));
}

static float edge_or_random(test_rng *r, int k)
{
    switch (k % 11) {
    case 0: return 0.5f;
    case 1: return 0.0f;
    case 2: return 0x1.fffffep-1f;
    default: return test_rng_float(r);
    }
}

/* The scalar steps for one vertex: false when the path ends there. */
static bool scalar_steps(const rt_bsdf *b, rt_vec3 wo, rt_vec2 u, float ulobe, rt_vec3 beta, rt_vec3 *wi,
                         float *pdf, rt_vec3 *beta_out, bool *down, bool *delta)
{
    rt_bsdf_sample bs;
    if (!rt_bsdf_sample_dir(b, wo, u, ulobe, &bs))
        return false;
    *wi = rt_normalize(rt_bsdf_to_world(b, bs.wi));
    float side = rt_dot(*wi, b->ng);
    if (bs.wi.z > 0.0f ? !(side > 0.0f) : !(side < 0.0f))
        return false;
    *down = bs.wi.z < 0.0f;
    *delta = bs.delta;
    *beta_out = rt_mul(beta, bs.weight);
    *pdf = bs.pdf;
    return rt_finite3(*beta_out) && rt_max3(*beta_out) > 0.0f;
}

/* A random BSDF of this kind (vertex k) with its geometric normal and a
 * view wo above its shading normal. */
static void random_bsdf(rt_bsdf_kind kind, size_t k, test_rng *r, rt_bsdf *b, rt_vec3 *wo_out)
{
    rt_vec3 nn = random_dir(r);
    rt_vec3 ng = k % 7 == 3 ? random_dir(r) : nn; /* now and then a geometric normal elsewhere */
    if (kind == RT_BSDF_KIND_LAMBERT) {
        rt_vec3 albedo = k % 13 == 5 ? rt_v3s(0.0f) : rt_v3(test_rng_float(r), test_rng_float(r), test_rng_float(r));
        rt_bsdf_make(b, nn, albedo, 0.0f, 1.0f, 1.5f, 0.0f, true);
    } else if (kind == RT_BSDF_KIND_GLTF) {
        rt_vec3 base = rt_v3(test_rng_float(r), test_rng_float(r), test_rng_float(r));
        float metallic = k % 4 == 0 ? 0.0f : (k % 4 == 1 ? 1.0f : test_rng_float(r));
        rt_bsdf_make(b, nn, base, metallic, 0.02f + 0.98f * test_rng_float(r), 1.2f + test_rng_float(r), 0.0f,
                     false);
    } else if (kind == RT_BSDF_KIND_DIELECTRIC) {
        rt_bsdf_make_dielectric(b, nn, 0.4f + 2.0f * test_rng_float(r), 0.0f);
        if (k % 5 == 2)
            b->diffuse = rt_v3(test_rng_float(r), test_rng_float(r), test_rng_float(r)); /* a tint */
    } else if (kind == RT_BSDF_KIND_PLASTIC) {
        rt_vec3 albedo = k % 13 == 5 ? rt_v3s(0.0f) : rt_v3(test_rng_float(r), test_rng_float(r), test_rng_float(r));
        float alpha = k % 3 == 0 ? 0.0f : 0.01f + 0.99f * test_rng_float(r); /* a third smooth */
        rt_bsdf_make_plastic(b, nn, albedo, 0.3f + 1.5f * test_rng_float(r), alpha);
    } else {
        float ax = 0.01f + test_rng_float(r), ay = k % 2 ? ax : 0.01f + test_rng_float(r);
        rt_vec3 eta = rt_v3(0.1f + 2.0f * test_rng_float(r), 0.1f + 2.0f * test_rng_float(r), 1.3f);
        rt_vec3 kk = rt_v3(3.0f * test_rng_float(r), 3.0f * test_rng_float(r), 1.7f);
        rt_bsdf_make_conductor(b, nn, eta, kk, ax, ay, k % 3 == 0);
    }
    b->ng = ng;
    /* wo above the shading normal, grazing now and then */
    float ct = k % 17 == 1 ? 1e-4f : 0.02f + 0.98f * test_rng_float(r), phi = 2.0f * RT_PI * test_rng_float(r);
    float st = sqrtf(1.0f - ct * ct);
    rt_vec3 wo = rt_v3(st * cosf(phi), st * sinf(phi), ct);
    if (kind != RT_BSDF_KIND_LAMBERT)
        rt_bsdf_set_wo(b, wo);
    assert_int_equal(rt_shade_lanes_kind(b), (int)kind);
    *wo_out = wo;
}

/* Vertex k's BSDF b and view wo into the lanes, as the wavefront gathers them. */
static void put_bsdf(rt_shade_lanes *l, size_t k, const rt_bsdf *b, rt_vec3 wo)
{
    l->tx[k] = b->t.x, l->ty[k] = b->t.y, l->tz[k] = b->t.z;
    l->bx[k] = b->b.x, l->by[k] = b->b.y, l->bz[k] = b->b.z;
    l->nx[k] = b->n.x, l->ny[k] = b->n.y, l->nz[k] = b->n.z;
    l->gx[k] = b->ng.x, l->gy[k] = b->ng.y, l->gz[k] = b->ng.z;
    l->dr[k] = b->diffuse.x, l->dg[k] = b->diffuse.y, l->db[k] = b->diffuse.z;
    l->ox[k] = wo.x, l->oy[k] = wo.y, l->oz[k] = wo.z;
    l->ax[k] = b->alpha, l->ay[k] = b->alpha_y, l->sep[k] = b->separable ? 1.0f : 0.0f;
    l->er[k] = b->eta_c.x, l->eg[k] = b->eta_c.y, l->eb[k] = b->eta_c.z;
    l->kr[k] = b->k_c.x, l->kg[k] = b->k_c.y, l->kb[k] = b->k_c.z;
    l->cr[k] = b->base.x, l->cg[k] = b->base.y, l->cb[k] = b->base.z;
    l->metal[k] = b->metallic, l->f0[k] = b->f0;
    l->pd[k] = b->p_d, l->ps[k] = b->p_s;
    l->pt[k] = b->p_t, l->eta[k] = b->eta;
    l->smooth[k] = b->delta ? 1.0f : 0.0f;
}

static void check_kind(rt_bsdf_kind kind, size_t n, uint64_t seed)
{
    test_rng r = {seed};
    rt_shade_lanes *l = rt_shade_lanes_new(n);
    assert_non_null(l);
    rt_bsdf *bs = malloc(n * sizeof *bs);
    rt_vec3 *wos = malloc(n * sizeof *wos), *betas = malloc(n * sizeof *betas);
    rt_vec2 *us = malloc(n * sizeof *us);
    float *ulobes = malloc(n * sizeof *ulobes);
    assert_true(bs && wos && betas && us && ulobes);
    size_t live = 0, deltas = 0;
    for (size_t k = 0; k < n; k++) {
        rt_vec3 wo;
        random_bsdf(kind, k, &r, &bs[k], &wo);
        rt_vec2 u = rt_v2(edge_or_random(&r, (int)k), edge_or_random(&r, (int)(k / 11)));
        rt_vec3 beta = rt_v3(test_rng_float(&r), test_rng_float(&r), 2.0f * test_rng_float(&r));
        float ulobe = edge_or_random(&r, (int)(k / 3));
        wos[k] = wo, us[k] = u, betas[k] = beta, ulobes[k] = ulobe;
        put_bsdf(l, k, &bs[k], wo);
        l->br[k] = beta.x, l->bg[k] = beta.y, l->bb[k] = beta.z;
        l->ux[k] = u.x, l->uy[k] = u.y;
        l->ulobe[k] = ulobe;
    }
    if (kind == RT_BSDF_KIND_LAMBERT)
        rt_lambert_sample_lanes(l, n);
    else if (kind == RT_BSDF_KIND_CONDUCTOR)
        rt_conductor_sample_lanes(l, n);
    else if (kind == RT_BSDF_KIND_GLTF)
        rt_gltf_sample_lanes(l, n);
    else if (kind == RT_BSDF_KIND_PLASTIC)
        rt_plastic_sample_lanes(l, n);
    else
        rt_dielectric_sample_lanes(l, n);
    for (size_t k = 0; k < n; k++) {
        rt_vec3 wi = rt_v3s(0.0f), beta = rt_v3s(0.0f);
        float pdf = 0.0f;
        bool down = false, delta = false;
        bool ok = scalar_steps(&bs[k], wos[k], us[k], ulobes[k], betas[k], &wi, &pdf, &beta, &down, &delta);
        if (ok != (l->ok[k] != 0))
            fail_msg("kind %d, path %zu: lanes say %d, scalar %d", (int)kind, k, l->ok[k], ok);
        if (!ok)
            continue;
        live++;
        if (down != (l->down[k] != 0))
            fail_msg("kind %d, path %zu: lanes went %s, scalar %s", (int)kind, k, l->down[k] ? "down" : "up",
                     down ? "down" : "up");
        if (delta != (l->delta[k] != 0))
            fail_msg("kind %d, path %zu: lanes delta %d, scalar %d", (int)kind, k, l->delta[k], delta);
        deltas += delta;
        float got[7] = {l->wx[k], l->wy[k], l->wz[k], l->pdf[k], l->br[k], l->bg[k], l->bb[k]};
        float want[7] = {wi.x, wi.y, wi.z, pdf, beta.x, beta.y, beta.z};
        if (memcmp(got, want, sizeof got) != 0)
            fail_msg("kind %d, path %zu: lanes (%.9g %.9g %.9g) pdf %.9g beta (%.9g %.9g %.9g), scalar (%.9g %.9g "
                     "%.9g) pdf %.9g beta (%.9g %.9g %.9g)",
                     (int)kind, k, got[0], got[1], got[2], got[3], got[4], got[5], got[6], want[0], want[1], want[2],
                     want[3], want[4], want[5], want[6]);
    }
    /* most paths go on, not all (black albedos, the side test) */
    assert_true(live > n / 2 && live < n);
    if (kind == RT_BSDF_KIND_PLASTIC) /* some smooth coats' mirror samples, not only */
        assert_true(deltas > n / 100 && deltas < live / 2);
    free(bs);
    free(wos);
    free(betas);
    free(us);
    free(ulobes);
    rt_shade_lanes_free(l);
}

static void test_lambert_lanes_equal_scalar(void **state)
{
    (void)state;
    const size_t counts[] = {1, RT_SHADE_LANES - 1, RT_SHADE_LANES, 4099};
    for (size_t c = 0; c < sizeof counts / sizeof counts[0]; c++)
        check_kind(RT_BSDF_KIND_LAMBERT, counts[c] < 16 ? 64 + counts[c] : counts[c], 11 + c);
}

static void test_conductor_lanes_equal_scalar(void **state)
{
    (void)state;
    const size_t counts[] = {RT_SHADE_LANES + 1, 4099, 20000};
    for (size_t c = 0; c < sizeof counts / sizeof counts[0]; c++)
        check_kind(RT_BSDF_KIND_CONDUCTOR, counts[c] < 16 ? 64 + counts[c] : counts[c], 101 + c);
}

static void test_gltf_lanes_equal_scalar(void **state)
{
    (void)state;
    const size_t counts[] = {RT_SHADE_LANES + 3, 4099, 20000};
    for (size_t c = 0; c < sizeof counts / sizeof counts[0]; c++)
        check_kind(RT_BSDF_KIND_GLTF, counts[c] < 16 ? 64 + counts[c] : counts[c], 201 + c);
}

static void test_dielectric_lanes_equal_scalar(void **state)
{
    (void)state;
    const size_t counts[] = {RT_SHADE_LANES + 5, 4099, 20000};
    for (size_t c = 0; c < sizeof counts / sizeof counts[0]; c++)
        check_kind(RT_BSDF_KIND_DIELECTRIC, counts[c] < 16 ? 64 + counts[c] : counts[c], 301 + c);
}

static void test_plastic_lanes_equal_scalar(void **state)
{
    (void)state;
    const size_t counts[] = {RT_SHADE_LANES + 7, 4099, 20000};
    for (size_t c = 0; c < sizeof counts / sizeof counts[0]; c++)
        check_kind(RT_BSDF_KIND_PLASTIC, counts[c] < 16 ? 64 + counts[c] : counts[c], 401 + c);
}

/* ------------------------------------------------------------ light sampling */

enum { LIGHT_CASES = 7 };

/* Test light c: a point light, a spot light with a range, a directional
 * light, a rectangular area light (emitting down, y = 2) with and
 * without a visible quad, a parallelogram (never sampled by solid angle)
 * and a degenerate area light. */
static rt_light test_light(int c)
{
    rt_light l = {.color = rt_v3(1.0f, 0.8f, 0.6f), .intensity = 3.0f, .quad = RT_NONE};
    switch (c) {
    case 0:
        l.kind = RT_LIGHT_POINT, l.position = rt_v3(0.3f, 2.0f, -0.2f);
        break;
    case 1:
        l.kind = RT_LIGHT_SPOT, l.position = rt_v3(0.3f, 2.0f, -0.2f), l.direction = rt_v3(0.1f, -1.0f, 0.2f);
        l.inner_cone = 0.5f, l.outer_cone = 1.2f, l.range = 6.0f;
        break;
    case 2:
        l.kind = RT_LIGHT_DIRECTIONAL, l.direction = rt_v3(0.3f, -1.0f, 0.1f);
        break;
    case 3:
    case 4:
        l.kind = RT_LIGHT_AREA, l.position = rt_v3(-0.5f, 2.0f, -0.4f);
        l.edge_u = rt_v3(1.0f, 0.0f, 0.0f), l.edge_v = rt_v3(0.0f, 0.0f, 0.8f), l.quad = c == 3 ? 7 : RT_NONE;
        break;
    case 5:
        l.kind = RT_LIGHT_AREA, l.position = rt_v3(-0.5f, 2.0f, -0.4f);
        l.edge_u = rt_v3(1.0f, 0.0f, 0.0f), l.edge_v = rt_v3(0.4f, 0.0f, 0.8f), l.quad = 3;
        break;
    default:
        l.kind = RT_LIGHT_AREA, l.position = rt_v3(-0.5f, 2.0f, -0.4f);
        l.edge_u = rt_v3(1.0f, 0.0f, 0.0f), l.edge_v = rt_v3(2.0f, 0.0f, 0.0f);
        break;
    }
    return l;
}

/* A vertex below the lights: mostly under them, some close (the area
 * light seen large: its solid-angle sampling), some level with them or
 * above (behind the one-sided light), one exactly on the point light. */
static rt_vec3 test_point(test_rng *r, size_t k)
{
    if (k % 23 == 7)
        return rt_v3(0.3f, 2.0f, -0.2f);
    float y = k % 5 == 0 ? 1.5f + 0.6f * test_rng_float(r) : 2.0f - 6.0f * test_rng_float(r);
    if (k % 31 == 4)
        y = 2.0f;
    return rt_v3(-3.0f + 6.0f * test_rng_float(r), y, -3.0f + 6.0f * test_rng_float(r));
}

static bool same_bits(const float *a, const float *b, size_t n) { return memcmp(a, b, n * sizeof *a) == 0; }

/* rt_light_sample_lanes against rt_light_sample_at, every output bit,
 * over n vertices; returns how many samples were valid. */
static size_t check_light(const rt_light *lt, rt_shade_lanes *l, size_t n, test_rng *r, size_t *solid)
{
    for (size_t k = 0; k < n; k++) {
        rt_vec3 p = test_point(r, k);
        l->px[k] = p.x, l->py[k] = p.y, l->pz[k] = p.z;
        l->lux[k] = edge_or_random(r, (int)k), l->luy[k] = edge_or_random(r, (int)(k / 11));
    }
    rt_light_sample_lanes(l, NULL, lt, n);
    size_t valid = 0;
    for (size_t k = 0; k < n; k++) {
        rt_light_sample ls = {.pdf = 0.0f};
        rt_vec3 p = rt_v3(l->px[k], l->py[k], l->pz[k]);
        bool ok = rt_light_sample_at(NULL, lt, p, rt_v2(l->lux[k], l->luy[k]), &ls);
        if (ok != (l->lok[k] != 0))
            fail_msg("light kind %d, vertex %zu: lanes say %d, scalar %d", (int)lt->kind, k, l->lok[k], ok);
        if (!ok)
            continue;
        valid++;
        /* nearer the rectangle's centre than its diameter: seen large, the scalar fallback */
        rt_vec3 centre = rt_add(lt->position, rt_scale(rt_add(lt->edge_u, lt->edge_v), 0.5f));
        *solid += lt->kind == RT_LIGHT_AREA && rt_length2(rt_sub(centre, p)) < 1.0f;
        float got[8] = {l->lwx[k], l->lwy[k], l->lwz[k], l->ldist[k], l->lr[k], l->lg[k], l->lb[k], l->lpdf[k]};
        float want[8] = {ls.wi.x, ls.wi.y, ls.wi.z, ls.dist, ls.li.x, ls.li.y, ls.li.z, ls.pdf};
        size_t m = lt->kind == RT_LIGHT_AREA ? 8 : 7; /* (the deltas' pdf is unset) */
        if (!same_bits(got, want, m))
            fail_msg("light kind %d, vertex %zu: lanes wi (%.9g %.9g %.9g) dist %.9g li (%.9g %.9g %.9g) pdf %.9g, "
                     "scalar (%.9g %.9g %.9g) %.9g (%.9g %.9g %.9g) %.9g",
                     (int)lt->kind, k, got[0], got[1], got[2], got[3], got[4], got[5], got[6], got[7], want[0],
                     want[1], want[2], want[3], want[4], want[5], want[6], want[7]);
    }
    return valid;
}

static void test_light_sample_lanes_equal_scalar(void **state)
{
    (void)state;
    const size_t counts[] = {1, RT_SHADE_LANES - 1, RT_SHADE_LANES + 1, 4099};
    for (int c = 0; c < LIGHT_CASES; c++) {
        rt_light lt = test_light(c);
        size_t valid = 0, total = 0, solid = 0;
        for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
            test_rng r = {1000 + 17 * (uint64_t)c + i};
            rt_shade_lanes *l = rt_shade_lanes_new(counts[i]);
            assert_non_null(l);
            valid += check_light(&lt, l, counts[i], &r, &solid);
            total += counts[i];
            rt_shade_lanes_free(l);
        }
        print_message("light case %d: %zu of %zu valid, %zu seen large\n", c, valid, total, solid);
        if (c == 6)
            assert_int_equal(valid, 0); /* a degenerate light gives nothing */
        else
            assert_true(valid > total / 8 && (c == 2 || valid < total)); /* (a directional light lights all) */
        if (c == 3)
            assert_true(solid > 20); /* the scalar fallback was taken */
    }
}

/* rt_nee_eval_lanes after rt_light_sample_lanes against
 * rt_path_nee_light_at: the record's every bit, for Lambert, conductors,
 * the glTF BRDF and the plastic under each test light (the power heuristic where the
 * area light has a quad). */
static void check_nee(rt_bsdf_kind kind, int c, size_t n, uint64_t seed)
{
    test_rng r = {seed};
    rt_light lt = test_light(c);
    rt_shade_lanes *l = rt_shade_lanes_new(n);
    rt_bsdf *bs = malloc(n * sizeof *bs);
    rt_vec3 *wos = malloc(n * sizeof *wos);
    assert_true(l && bs && wos);
    for (size_t k = 0; k < n; k++) {
        random_bsdf(kind, k, &r, &bs[k], &wos[k]);
        put_bsdf(l, k, &bs[k], wos[k]);
        rt_vec3 p = test_point(&r, k);
        l->px[k] = p.x, l->py[k] = p.y, l->pz[k] = p.z;
        l->lux[k] = edge_or_random(&r, (int)k), l->luy[k] = edge_or_random(&r, (int)(k / 11));
    }
    rt_light_sample_lanes(l, NULL, &lt, n);
    rt_nee_eval_lanes(l, (int)kind, lt.kind == RT_LIGHT_AREA && lt.quad != RT_NONE, n);
    size_t live = 0;
    for (size_t k = 0; k < n; k++) {
        rt_nee_record rec;
        bool ok = rt_path_nee_light_at(NULL, &lt, rt_v3(l->px[k], l->py[k], l->pz[k]), &bs[k], wos[k],
                                       rt_v2(l->lux[k], l->luy[k]), &rec);
        if (ok != (l->rok[k] != 0))
            fail_msg("kind %d, light %d, vertex %zu: lanes say %d, scalar %d", (int)kind, c, k, l->rok[k], ok);
        if (!ok)
            continue;
        live++;
        float got[9] = {l->fr[k], l->fg[k], l->fb[k], l->fcos[k], l->fw[k], l->lwx[k], l->lwy[k], l->lwz[k], l->ldist[k]};
        float want[9] = {rec.fl.x, rec.fl.y, rec.fl.z, rec.cos, rec.w, rec.wi.x, rec.wi.y, rec.wi.z, rec.dist};
        assert_true(rec.pdf == 1.0f);
        if (!same_bits(got, want, 9))
            fail_msg("kind %d, light %d, vertex %zu: lanes fl (%.9g %.9g %.9g) cos %.9g w %.9g, scalar (%.9g %.9g "
                     "%.9g) %.9g %.9g",
                     (int)kind, c, k, got[0], got[1], got[2], got[3], got[4], want[0], want[1], want[2], want[3],
                     want[4]);
    }
    if (c != 6 && n > 100 && !(live > n / 20 && live < n))
        fail_msg("kind %d, light %d: %zu of %zu live", (int)kind, c, live, n);
    free(bs);
    free(wos);
    rt_shade_lanes_free(l);
}

static void test_nee_lanes_equal_scalar(void **state)
{
    (void)state;
    const rt_bsdf_kind kinds[] = {RT_BSDF_KIND_LAMBERT, RT_BSDF_KIND_CONDUCTOR, RT_BSDF_KIND_GLTF,
                                  RT_BSDF_KIND_PLASTIC};
    for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++)
        for (int c = 0; c < LIGHT_CASES; c++) {
            check_nee(kinds[i], c, RT_SHADE_LANES + 3, 5000 + 31 * i + (uint64_t)c);
            check_nee(kinds[i], c, 3001, 6000 + 31 * i + (uint64_t)c);
        }
}

/* Which BSDFs the lanes take: Lambert, rough conductors without the
 * multiple-scattering lobe, the rough opaque glTF BRDF once its lobe
 * probabilities are cached, smooth glass and the plastic (smooth or
 * rough) likewise; not a delta conductor,
 * a compensated one, a smooth or transmissive glTF BSDF, rough glass. */
static void test_lanes_kind(void **state)
{
    (void)state;
    rt_bsdf b;
    rt_vec3 n = rt_v3(0.0f, 0.0f, 1.0f), eta = rt_v3(0.2f, 0.4f, 1.4f), k = rt_v3(3.4f, 2.3f, 1.8f);
    rt_bsdf_make(&b, n, rt_v3s(0.5f), 0.0f, 1.0f, 1.5f, 0.0f, true);
    assert_int_equal(rt_shade_lanes_kind(&b), RT_BSDF_KIND_LAMBERT);
    rt_bsdf_make_conductor(&b, n, eta, k, 0.3f, 0.1f, false);
    assert_int_equal(rt_shade_lanes_kind(&b), RT_BSDF_KIND_CONDUCTOR);
    rt_bsdf_compensate(&b);
    assert_true(b.ms);
    assert_int_equal(rt_shade_lanes_kind(&b), -1);
    rt_bsdf_make_conductor(&b, n, eta, k, 0.0f, 0.0f, false);
    assert_int_equal(rt_shade_lanes_kind(&b), -1);
    rt_bsdf_make(&b, n, rt_v3s(0.5f), 0.5f, 0.5f, 1.5f, 0.0f, false);
    assert_int_equal(rt_shade_lanes_kind(&b), -1); /* no lobe probabilities cached yet */
    rt_bsdf_set_wo(&b, rt_v3(0.0f, 0.6f, 0.8f));
    assert_int_equal(rt_shade_lanes_kind(&b), RT_BSDF_KIND_GLTF);
    rt_bsdf_make(&b, n, rt_v3s(0.5f), 0.5f, 0.0f, 1.5f, 0.0f, false); /* smooth: a delta mirror */
    rt_bsdf_set_wo(&b, rt_v3(0.0f, 0.6f, 0.8f));
    assert_int_equal(rt_shade_lanes_kind(&b), -1);
    rt_bsdf_make(&b, n, rt_v3s(0.5f), 0.0f, 0.5f, 1.5f, 0.5f, false); /* transmissive */
    rt_bsdf_set_wo(&b, rt_v3(0.0f, 0.6f, 0.8f));
    assert_int_equal(rt_shade_lanes_kind(&b), -1);
    rt_bsdf_make_dielectric(&b, n, 1.0f / 1.5f, 0.0f); /* smooth glass */
    rt_bsdf_set_wo(&b, rt_v3(0.0f, 0.6f, 0.8f));
    assert_int_equal(rt_shade_lanes_kind(&b), RT_BSDF_KIND_DIELECTRIC);
    rt_bsdf_make_dielectric(&b, n, 1.0f / 1.5f, 0.2f); /* rough glass */
    rt_bsdf_set_wo(&b, rt_v3(0.0f, 0.6f, 0.8f));
    assert_int_equal(rt_shade_lanes_kind(&b), -1);
    for (int rough = 0; rough < 2; rough++) {
        rt_bsdf_make_plastic(&b, n, rt_v3s(0.5f), 1.0f / 1.5f, rough ? 0.2f : 0.0f);
        assert_int_equal(rt_shade_lanes_kind(&b), -1); /* no lobe probabilities cached yet */
        rt_bsdf_set_wo(&b, rt_v3(0.0f, 0.6f, 0.8f));
        assert_int_equal(rt_shade_lanes_kind(&b), RT_BSDF_KIND_PLASTIC);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lambert_lanes_equal_scalar),
        cmocka_unit_test(test_conductor_lanes_equal_scalar),
        cmocka_unit_test(test_gltf_lanes_equal_scalar),
        cmocka_unit_test(test_dielectric_lanes_equal_scalar),
        cmocka_unit_test(test_plastic_lanes_equal_scalar),
        cmocka_unit_test(test_lanes_kind),
        cmocka_unit_test(test_light_sample_lanes_equal_scalar),
        cmocka_unit_test(test_nee_lanes_equal_scalar),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
