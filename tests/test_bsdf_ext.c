/* test_bsdf_ext.c - the glTF PBR-next extension lobes and their layering
 * (rt/render/bsdf_clearcoat.h, bsdf_sheen.h, bsdf_iridescence.h,
 * rt_bsdf_set_ext in rt/render/bsdf.h) against closed forms and
 * independent estimates: a clearcoat of IOR 1.5 reflects 4% at normal
 * incidence; the Charlie sheen distribution is normalised and the albedo
 * table agrees with a quadrature of the lobe; the thin film vanishes at
 * zero thickness; specularFactor 0 leaves exactly Lambert; diffuse
 * transmission of weight 1 passes all the light; every layered BSDF is
 * reciprocal, keeps its albedo at most 1 (white furnace), and samples with
 * the density rt_bsdf_eval reports (mean weight = quadrature of f cos;
 * a histogram of the sampled directions against the pdf). */
#include "test_util.h"
#include "test_bsdf_check.h"

#include <math.h>

#include "rt/render/bsdf.h"
#include "rt/render/bsdf_clearcoat.h"
#include "rt/render/bsdf_iridescence.h"
#include "rt/render/bsdf_sheen.h"
#include "rt/render/material_eval.h"
#include "rt/render/sampling.h"

static rt_vec3 uniform_hemi(test_rng *r) { return dir_from(test_rng_float(r), 2.0f * RT_PI * test_rng_float(r)); }

/* A glTF BSDF (normal z) with the extensions e over it. */
static void make(rt_bsdf *b, rt_vec3 base, float metallic, float roughness, const rt_bsdf_ext *e)
{
    rt_bsdf_make(b, rt_v3(0, 0, 1), base, metallic, roughness, 1.5f, 0.0f, false);
    rt_bsdf_set_ext(b, e);
}

/* Directional albedo at wo: mean sample weight (all lobes, delta ones
 * included) and stratified uniform quadrature of f cos (non-delta lobes). */
static void albedo(const rt_bsdf *b, rt_vec3 wo, int n, double *by_sampling, double *by_quadrature)
{
    double s = 0.0, q = 0.0;
    for (int i = 0; i < n; i++) {
        rt_vec2 u = rt_cmj_sample((uint32_t)i, (uint32_t)n, 4321);
        float ul = rt_cmj_randfloat((uint32_t)i, 91);
        rt_bsdf_sample bs;
        if (rt_bsdf_sample_dir(b, wo, u, ul, &bs))
            s += (bs.weight.x + bs.weight.y + bs.weight.z) / 3.0;
        rt_vec2 v = rt_cmj_sample((uint32_t)i, (uint32_t)n, 4322);
        rt_vec3 wi = dir_from(v.x, 2.0f * RT_PI * v.y);
        rt_vec3 f = rt_bsdf_eval(b, wo, wi, NULL);
        q += (f.x + f.y + f.z) / 3.0 * wi.z * 2.0 * 3.14159265358979323846;
    }
    *by_sampling = s / n;
    *by_quadrature = q / n;
}

typedef struct ext_case {
    const char *label;
    rt_vec3 base;
    float metallic, roughness;
    rt_bsdf_ext e;
} ext_case;

static int build_cases(ext_case *c)
{
    int n = 0;
    rt_bsdf_ext d;
    rt_bsdf_ext_default(&d);
    c[n] = (ext_case){"rough coat over white diffuse", rt_v3s(1), 0, 0.6f, d};
    c[n].e.clearcoat = 1.0f, c[n].e.clearcoat_roughness = 0.3f, n++;
    c[n] = (ext_case){"half coat over gold", rt_v3(1.0f, 0.78f, 0.34f), 1, 0.4f, d};
    c[n].e.clearcoat = 0.5f, c[n].e.clearcoat_roughness = 0.5f, n++;
    c[n] = (ext_case){"tilted coat", rt_v3s(0.5f), 0, 0.5f, d};
    c[n].e.clearcoat = 1.0f, c[n].e.clearcoat_roughness = 0.4f, c[n].e.clearcoat_normal = rt_normalize(rt_v3(0.3f, -0.2f, 1.0f)), n++;
    c[n] = (ext_case){"white sheen over white diffuse", rt_v3s(1), 0, 0.8f, d};
    c[n].e.sheen_color = rt_v3s(1), c[n].e.sheen_roughness = 0.5f, n++;
    c[n] = (ext_case){"sharp red sheen", rt_v3(0.2f, 0.3f, 0.8f), 0, 0.7f, d};
    c[n].e.sheen_color = rt_v3(1, 0.2f, 0.1f), c[n].e.sheen_roughness = 0.1f, n++;
    c[n] = (ext_case){"sheen under a coat", rt_v3s(0.9f), 0, 0.5f, d};
    c[n].e.sheen_color = rt_v3s(0.8f), c[n].e.sheen_roughness = 0.3f, c[n].e.clearcoat = 1.0f,
        c[n].e.clearcoat_roughness = 0.2f, n++;
    c[n] = (ext_case){"anisotropic white metal", rt_v3s(1), 1, 0.3f, d};
    c[n].e.anisotropy = 0.8f, n++;
    c[n] = (ext_case){"anisotropic plastic", rt_v3s(0.7f), 0, 0.4f, d};
    c[n].e.anisotropy = 0.5f, n++;
    c[n] = (ext_case){"coloured specular", rt_v3s(0.5f), 0, 0.3f, d};
    c[n].e.spec_weight = 0.7f, c[n].e.spec_color = rt_v3(2.0f, 1.0f, 0.5f), n++;
    c[n] = (ext_case){"iridescent dielectric", rt_v3s(0.1f), 0, 0.3f, d};
    c[n].e.iridescence = 1.0f, c[n].e.iridescence_thickness = 300.0f, n++;
    c[n] = (ext_case){"iridescent metal", rt_v3(0.9f, 0.9f, 0.9f), 1, 0.3f, d};
    c[n].e.iridescence = 1.0f, c[n].e.iridescence_thickness = 500.0f, n++;
    return n;
}

static void test_clearcoat_four_percent(void **state)
{
    (void)state;
    /* Schlick with F0 = ((1.5 - 1) / (1.5 + 1))^2 */
    assert_true(fabsf(rt_clearcoat_fresnel(1.0f) - 0.04f) < 1e-7f);
    assert_true(fabsf(rt_clearcoat_fresnel(0.0f) - 1.0f) < 1e-7f);
    /* a mirror coat over a black base reflects 4% at normal incidence: the
     * mean sample weight over the lobe choice is 0.04 */
    rt_bsdf_ext e;
    rt_bsdf_ext_default(&e);
    e.clearcoat = 1.0f;
    e.spec_weight = 0.0f; /* no base specular: only the coat reflects */
    rt_bsdf b;
    make(&b, rt_v3s(0), 0, 0.5f, &e);
    assert_true((b.kind == RT_BSDF_KIND_GLTF_LAYERED) && b.cc_delta);
    double s, q;
    albedo(&b, rt_v3(0, 0, 1), 4096, &s, &q);
    assert_true(fabs(s - 0.04) < 1e-4);
    assert_true(q == 0.0); /* nothing but the delta coat */
    /* a nearly smooth rough coat gives the same by quadrature of f cos
     * (alpha 1e-3: the lobe is all but a mirror; sampling integrates it) */
    e.clearcoat_roughness = 0.03f;
    make(&b, rt_v3s(0), 0, 0.5f, &e);
    albedo(&b, dir_from(0.9999f, 0.0f), 16384, &s, &q);
    assert_true(fabs(s - 0.04) < 1e-3);
    /* half a coat: half the reflection */
    e.clearcoat = 0.5f;
    e.clearcoat_roughness = 0.0f;
    make(&b, rt_v3s(0), 0, 0.5f, &e);
    albedo(&b, rt_v3(0, 0, 1), 4096, &s, &q);
    assert_true(fabs(s - 0.02) < 1e-4);
}

static void test_sheen_distribution_normalised(void **state)
{
    (void)state;
    const float alphas[] = {0.07f, 0.2f, 0.5f, 1.0f};
    for (int k = 0; k < 4; k++) {
        /* integral over the hemisphere of D(h) cos(theta_h) = 1 */
        double sum = 0.0;
        const int n = 100000;
        for (int i = 0; i < n; i++) {
            float c = ((float)i + 0.5f) / (float)n;
            sum += (double)rt_sheen_d(c, alphas[k]) * c;
        }
        assert_true(fabs(2.0 * 3.14159265358979323846 * sum / n - 1.0) < 2e-3);
    }
    /* the fitted Lambda is continuous at cos = 0.5, where its two branches meet */
    for (int k = 0; k < 4; k++)
        assert_true(fabsf(rt_sheen_lambda(0.4999f, alphas[k]) - rt_sheen_lambda(0.5001f, alphas[k])) <
                    2e-3f * rt_sheen_lambda(0.5f, alphas[k]) + 1e-5f);
    assert_true(rt_sheen_alpha(0.0f) == RT_SHEEN_MIN_ALPHA && rt_sheen_alpha(2.0f) == 1.0f);
}

/* The table (tools/gen_sheen_table.py, numpy) against this file's own
 * quadrature of rt_sheen_brdf cos, at points between the table's nodes. */
static void test_sheen_albedo_table(void **state)
{
    (void)state;
    const float cs[] = {0.05f, 0.23f, 0.5f, 0.77f, 0.98f};
    const float as[] = {0.1f, 0.33f, 0.61f, 0.9f};
    for (int i = 0; i < 5; i++)
        for (int j = 0; j < 4; j++) {
            rt_vec3 wo = dir_from(cs[i], 0.0f);
            double q = 0.0;
            const int nt = 400, np = 200;
            for (int a = 0; a < nt; a++)
                for (int c = 0; c < np; c++) {
                    float ct = ((float)a + 0.5f) / nt, ph = ((float)c + 0.5f) / np * 2.0f * RT_PI;
                    q += rt_sheen_brdf(wo, dir_from(ct, ph), as[j]) * ct;
                }
            q *= 2.0 * 3.14159265358979323846 / ((double)nt * np);
            float e = rt_sheen_albedo(cs[i], as[j]);
            if (fabs(q - e) > 0.01 + 0.02 * q)
                fail_msg("sheen albedo at cos %.2f alpha %.2f: table %.4f, quadrature %.4f", cs[i], as[j], e, q);
            assert_true(e >= 0.0f && e <= 1.0f);
        }
}

static void test_iridescence(void **state)
{
    (void)state;
    rt_vec3 f0 = rt_v3(0.04f, 0.04f, 0.04f);
    for (int i = 0; i <= 10; i++) {
        float c = (float)i / 10.0f;
        /* no film: the base's Schlick Fresnel */
        rt_vec3 f = rt_iridescence_fresnel(1.0f, 1.3f, f0, 0.0f, c);
        float x = 1.0f - c, sch = 0.04f + 0.96f * x * x * x * x * x;
        assert_true(fabsf(f.x - sch) < 1e-6f && fabsf(f.z - sch) < 1e-6f);
        /* a film of the outside's index is no film either near normal
         * incidence (R12 = 0 there, up to the Airy sum's clamp of R12 R23 at 1e-5; Schlick's R12 grows towards grazing) */
        f = rt_iridescence_fresnel(1.0f, 1.0f, f0, 400.0f, c);
        if (c >= 0.9f)
            assert_true(fabsf(f.x - sch) < 0.01f && fabsf(f.y - sch) < 0.01f && fabsf(f.z - sch) < 0.01f);
    }
    /* a real film: a colour that changes with the thickness, within [0, 1] */
    rt_vec3 a = rt_iridescence_fresnel(1.0f, 1.3f, rt_v3s(0.5f), 250.0f, 1.0f);
    rt_vec3 b = rt_iridescence_fresnel(1.0f, 1.3f, rt_v3s(0.5f), 450.0f, 1.0f);
    assert_true(fabsf(a.x - b.x) + fabsf(a.y - b.y) + fabsf(a.z - b.z) > 0.02f);
    for (int t = 0; t <= 1200; t += 37)
        for (int i = 0; i <= 8; i++) {
            rt_vec3 f = rt_iridescence_fresnel(1.0f, 1.3f, rt_v3(0.04f, 0.5f, 0.9f), (float)t, (float)i / 8.0f);
            assert_true(rt_finite3(f) && f.x >= 0.0f && f.y >= 0.0f && f.z >= 0.0f);
            assert_true(f.x <= 1.05f && f.y <= 1.05f && f.z <= 1.05f);
        }
}

static void test_defaults_leave_core(void **state)
{
    (void)state;
    rt_bsdf_ext e;
    rt_bsdf_ext_default(&e);
    rt_bsdf b;
    make(&b, rt_v3(0.8f, 0.5f, 0.2f), 0.3f, 0.4f, &e);
    assert_false((b.kind == RT_BSDF_KIND_GLTF_LAYERED));
    /* specularFactor 0 on a dielectric: no specular lobe and no Fresnel loss, exactly Lambert */
    e.spec_weight = 0.0f;
    make(&b, rt_v3(0.8f, 0.5f, 0.2f), 0.0f, 0.4f, &e);
    assert_true((b.kind == RT_BSDF_KIND_GLTF_LAYERED));
    test_rng r = {5};
    for (int i = 0; i < 500; i++) {
        rt_vec3 wo = uniform_hemi(&r), wi = uniform_hemi(&r);
        rt_vec3 f = rt_bsdf_eval(&b, wo, wi, NULL);
        assert_true(fabsf(f.x - 0.8f * RT_INV_PI) < 1e-6f && fabsf(f.z - 0.2f * RT_INV_PI) < 1e-6f);
    }
    /* anisotropy strength 1: alpha along t is 1, along b the material's */
    rt_bsdf_ext_default(&e);
    e.anisotropy = 1.0f;
    make(&b, rt_v3s(1), 1.0f, 0.5f, &e);
    assert_true(b.alpha == 1.0f && fabsf(b.alpha_y - 0.25f) < 1e-7f);
    /* specularColorFactor scales F0 (clamped at 1): the specular lobe at normal incidence grows with it */
    rt_bsdf_ext_default(&e);
    e.spec_color = rt_v3(2.0f, 1.0f, 0.5f);
    make(&b, rt_v3s(0), 0.0f, 0.3f, &e);
    rt_vec3 f = rt_bsdf_eval(&b, rt_v3(0, 0, 1), rt_v3(0, 0, 1), NULL);
    assert_true(fabsf(f.x / f.y - 2.0f) < 1e-3f && fabsf(f.z / f.y - 0.5f) < 1e-3f);
}

static void test_diffuse_transmission(void **state)
{
    (void)state;
    /* weight 1, no specular: every sample goes through, carrying the colour */
    rt_bsdf_ext e;
    rt_bsdf_ext_default(&e);
    e.diffuse_transmission = 1.0f;
    e.diffuse_transmission_color = rt_v3(1.0f, 0.5f, 0.25f);
    e.spec_weight = 0.0f;
    rt_bsdf b;
    make(&b, rt_v3s(0.3f), 0.0f, 0.5f, &e);
    for (int i = 0; i < 256; i++) {
        rt_bsdf_sample s;
        rt_vec3 wo = dir_from(0.2f + 0.003f * (float)i, (float)i);
        assert_true(rt_bsdf_sample_dir(&b, wo, rt_cmj_sample((uint32_t)i, 256, 3), rt_cmj_randfloat((uint32_t)i, 4), &s));
        assert_true(s.delta && s.wi.z < 0.0f);
        assert_true(fabsf(s.weight.x - 1.0f) < 1e-5f && fabsf(s.weight.y - 0.5f) < 1e-5f &&
                    fabsf(s.weight.z - 0.25f) < 1e-5f);
    }
    /* half of it: the reflected diffuse and the transmitted share split the albedo */
    e.diffuse_transmission = 0.5f;
    e.diffuse_transmission_color = rt_v3s(1.0f);
    make(&b, rt_v3s(1.0f), 0.0f, 0.5f, &e);
    double s, q;
    albedo(&b, dir_from(0.7f, 0.3f), 8192, &s, &q);
    assert_true(fabs(q - 0.5) < 0.01);  /* reflected: half of white Lambert */
    assert_true(fabs(s - 1.0) < 0.01);  /* both: all of it */
}

static void test_layered_reciprocal(void **state)
{
    (void)state;
    ext_case cases[16];
    int n = build_cases(cases);
    test_rng r = {17};
    for (int c = 0; c < n; c++) {
        rt_bsdf b;
        make(&b, cases[c].base, cases[c].metallic, cases[c].roughness, &cases[c].e);
        assert_true((b.kind == RT_BSDF_KIND_GLTF_LAYERED));
        for (int i = 0; i < 1000; i++) {
            rt_vec3 wo = uniform_hemi(&r), wi = uniform_hemi(&r);
            rt_vec3 f1 = rt_bsdf_eval(&b, wo, wi, NULL), f2 = rt_bsdf_eval(&b, wi, wo, NULL);
            float d = fabsf(f1.x - f2.x) + fabsf(f1.y - f2.y) + fabsf(f1.z - f2.z);
            if (d > 1e-4f * fmaxf(rt_max3(f1), 1e-2f))
                fail_msg("%s: f(wo, wi) %g differs from f(wi, wo) %g", cases[c].label, f1.x, f2.x);
            assert_true(rt_finite3(f1));
        }
    }
}

/* White furnace: albedo at most 1 (a white sheen or coat over white
 * Lambert comes close to 1), and sampling agrees with quadrature. */
static void test_layered_energy(void **state)
{
    (void)state;
    ext_case cases[16];
    int n = build_cases(cases);
    const float cosines[] = {0.05f, 0.3f, 0.7f, 1.0f};
    for (int c = 0; c < n; c++) {
        rt_bsdf b;
        make(&b, cases[c].base, cases[c].metallic, cases[c].roughness, &cases[c].e);
        for (int k = 0; k < 4; k++) {
            double s, q;
            albedo(&b, dir_from(cosines[k], 0.4f), 65536, &s, &q);
            if (!(s <= 1.01 && q <= 1.01))
                fail_msg("%s at cos %.2f: albedo %.4f (sampling), %.4f (quadrature) above 1", cases[c].label,
                         cosines[k], s, q);
            if (fabs(s - q) > 0.02 + 0.03 * q)
                fail_msg("%s at cos %.2f: sampling %.4f, quadrature %.4f", cases[c].label, cosines[k], s, q);
        }
    }
}

/* KHR_materials_dispersion: a dispersive smooth glass refracts one channel
 * per sample with its own index (red bends least, blue most), at 3 times
 * its weight; green follows the material's index exactly. */
static void test_dispersion(void **state)
{
    (void)state;
    rt_bsdf_ext e;
    rt_bsdf_ext_default(&e);
    e.dispersion = 1.0f; /* Abbe number 20 */
    rt_bsdf plain, b;
    rt_bsdf_make(&plain, rt_v3(0, 0, 1), rt_v3s(1), 0.0f, 0.0f, 1.5f, 1.0f, false);
    rt_bsdf_make(&b, rt_v3(0, 0, 1), rt_v3s(1), 0.0f, 0.0f, 1.5f, 1.0f, false);
    rt_bsdf_set_ext(&b, &e);
    assert_true((b.kind == RT_BSDF_KIND_GLTF_LAYERED) && b.dispersive);
    /* n_F - n_C = (n_d - 1) / V */
    float nr = 1.0f / b.eta_rgb.x, ng = 1.0f / b.eta_rgb.y, nb = 1.0f / b.eta_rgb.z;
    assert_true(fabsf(ng - 1.5f) < 1e-6f && nr < ng && ng < nb);
    assert_true(fabsf((nb - nr) - 0.5f / 20.0f) < 2e-4f);
    rt_vec3 wo = dir_from(0.6f, 0.0f);
    float pd, ps, pt;
    rt_bsdf_lobe_probs(&b, wo, &pd, &ps, &pt);
    assert_true(pt > 0.5f);
    rt_vec3 wi[3];
    for (int k = 0; k < 3; k++) {
        rt_bsdf_sample s;
        float ul = pd + ps + pt * ((float)k + 0.5f) / 3.0f;
        assert_true(rt_bsdf_sample_dir(&b, wo, rt_v2(0.5f, 0.5f), ul, &s));
        assert_true(s.delta && s.wi.z < 0.0f);
        float w[3] = {s.weight.x, s.weight.y, s.weight.z};
        for (int c = 0; c < 3; c++)
            assert_true(c == k ? w[c] > 0.0f : w[c] == 0.0f);
        wi[k] = s.wi;
    }
    /* the refracted angle from the normal: sin_t = sin_i / n, smaller for blue */
    assert_true(fabsf(wi[0].x) > fabsf(wi[1].x) && fabsf(wi[1].x) > fabsf(wi[2].x));
    rt_bsdf_sample s0;
    float pd0, ps0, pt0;
    rt_bsdf_lobe_probs(&plain, wo, &pd0, &ps0, &pt0);
    assert_true(rt_bsdf_sample_dir(&plain, wo, rt_v2(0.5f, 0.5f), pd0 + ps0 + 0.5f * pt0, &s0));
    assert_true(fabsf(s0.wi.x - wi[1].x) < 1e-6f && fabsf(s0.wi.z - wi[1].z) < 1e-6f);
}

/* KHR_materials_volume thickness 0: a thin wall passes light straight on
 * (smooth) or blurred about -wo (rough), losing what the surface reflects. */
static void test_thin_walled(void **state)
{
    (void)state;
    rt_bsdf b;
    rt_bsdf_make(&b, rt_v3(0, 0, 1), rt_v3(1.0f, 0.8f, 0.6f), 0.0f, 0.0f, 1.5f, 1.0f, false);
    b.thin = true;
    rt_vec3 wo = dir_from(0.5f, 0.7f);
    float pd, ps, pt;
    rt_bsdf_lobe_probs(&b, wo, &pd, &ps, &pt);
    rt_bsdf_sample s;
    assert_true(rt_bsdf_sample_dir(&b, wo, rt_v2(0.3f, 0.6f), pd + ps + 0.5f * pt, &s));
    assert_true(s.delta);
    assert_true(fabsf(s.wi.x + wo.x) < 1e-6f && fabsf(s.wi.y + wo.y) < 1e-6f && fabsf(s.wi.z + wo.z) < 1e-6f);
    /* weight x probability = (1 - F) T c, F the exact Fresnel at 60 degrees */
    float f = rt_fresnel_exact(0.5f, 1.0f / 1.5f);
    assert_true(fabsf(s.weight.x * pt - (1.0f - f)) < 1e-5f && fabsf(s.weight.z * pt - 0.6f * (1.0f - f)) < 1e-5f);
    /* rough: the directions scatter about -wo, all below the surface */
    rt_bsdf_make(&b, rt_v3(0, 0, 1), rt_v3s(1), 0.0f, 0.4f, 1.5f, 1.0f, false);
    b.thin = true;
    rt_bsdf_lobe_probs(&b, wo, &pd, &ps, &pt);
    double mx = 0.0, my = 0.0;
    int n = 0;
    for (int i = 0; i < 1024; i++) {
        if (!rt_bsdf_sample_dir(&b, wo, rt_cmj_sample((uint32_t)i, 1024, 9), pd + ps + 0.999f * pt, &s))
            continue;
        assert_true(s.delta && s.wi.z < 0.0f && rt_max3(s.weight) <= 1.0f / pt + 1e-4f);
        mx += s.wi.x;
        my += s.wi.y;
        n++;
    }
    assert_true(n > 900);
    /* the mean direction leans the way -wo does */
    assert_true(mx / n * -wo.x > 0.0 && my / n * -wo.y > 0.0);
}

/* A histogram of sampled directions against the pdf rt_bsdf_eval reports
 * (test_bsdf_check.h). */
static void pdf_histogram(const rt_bsdf *b, rt_vec3 wo, uint64_t seed, const char *label)
{
    test_pdf_histogram(b, wo, rt_rng_seed(seed, 7), 200000, label);
}

static void test_layered_pdf_histogram(void **state)
{
    (void)state;
    ext_case cases[16];
    int n = build_cases(cases);
    for (int c = 0; c < n; c++) {
        if (cases[c].e.sheen_roughness == 0.1f)
            continue; /* a sharp sheen peaks at grazing, finer than the cells */
        rt_bsdf b;
        make(&b, cases[c].base, cases[c].metallic, cases[c].roughness, &cases[c].e);
        pdf_histogram(&b, dir_from(0.6f, 0.3f), (uint64_t)c + 1, cases[c].label);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_clearcoat_four_percent),
        cmocka_unit_test(test_sheen_distribution_normalised),
        cmocka_unit_test(test_sheen_albedo_table),
        cmocka_unit_test(test_iridescence),
        cmocka_unit_test(test_defaults_leave_core),
        cmocka_unit_test(test_diffuse_transmission),
        cmocka_unit_test(test_dispersion),
        cmocka_unit_test(test_thin_walled),
        cmocka_unit_test(test_layered_reciprocal),
        cmocka_unit_test(test_layered_energy),
        cmocka_unit_test(test_layered_pdf_histogram),
    };
    return cmocka_run_group_tests_name("bsdf_ext", tests, NULL, NULL);
}
