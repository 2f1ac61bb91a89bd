/* test_spherical.c - solid-angle sampling of rectangles and triangles
 * (rt/render/spherical.h) and of rectangular area lights (rt/render/light.h)
 * against closed forms:
 *   - the solid angle a sampler works with equals Van Oosterom and
 *     Strackee's (1983) formula, tan(O/2) = |a.(b x c)| / (|a||b||c| +
 *     (a.b)|c| + (b.c)|a| + (c.a)|b|), computed here in double (a rectangle
 *     is two triangles);
 *   - every sampled direction hits the polygon, and the directions are
 *     uniform in solid angle: the fraction landing in each of several
 *     sub-polygons equals its share of the solid angle within 4 sigma;
 *   - the irradiance estimate from a uniformly emitting rectangle (an area
 *     light through rt_light_sample_at: three points that see it large and
 *     sample it by solid angle, one that sees it small and samples it by
 *     area) and a triangle matches Lambert's polygon formula
 *     E = L/2 sum_i angle(v_i, v_i+1) n . unit(v_i x v_i+1) within 4 sigma,
 *     and its variance is below half of uniform area sampling's at a point
 *     close to the light (measured 42x and 20x lower standard deviations);
 *   - the light sample's pdf is rt_area_light_pdf's, bit for bit (what MIS
 *     weighs BSDF hits on the light with), with solid-angle sampling and
 *     with the area fallback (a rectangle too small in solid angle, a
 *     parallelogram).
 */
#include "test_util.h"

#include <math.h>
#include <string.h>

#include "rt/render/light.h"
#include "rt/render/spherical.h"

typedef struct dv3 {
    double x, y, z;
} dv3;

static dv3 d3(rt_vec3 a) { dv3 r = {a.x, a.y, a.z}; return r; }
static dv3 dsub3(dv3 a, dv3 b) { dv3 r = {a.x - b.x, a.y - b.y, a.z - b.z}; return r; }
static double ddot3(dv3 a, dv3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static dv3 dcross3(dv3 a, dv3 b)
{
    dv3 r = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    return r;
}
static double dlen3(dv3 a) { return sqrt(ddot3(a, a)); }

/* Van Oosterom and Strackee's solid angle of triangle abc from p. */
static double vos_solid_angle(rt_vec3 a, rt_vec3 b, rt_vec3 c, rt_vec3 p)
{
    dv3 A = dsub3(d3(a), d3(p)), B = dsub3(d3(b), d3(p)), C = dsub3(d3(c), d3(p));
    double la = dlen3(A), lb = dlen3(B), lc = dlen3(C);
    double num = fabs(ddot3(A, dcross3(B, C)));
    double den = la * lb * lc + ddot3(A, B) * lc + ddot3(B, C) * la + ddot3(C, A) * lb;
    double o = 2.0 * atan2(num, den);
    return o < 0.0 ? o + 4.0 * 3.14159265358979323846 : o;
}

/* Lambert's irradiance at p (normal n) from a polygon of radiance 1 wholly
 * above p's horizon: 1/2 |sum_i angle_i n . unit(v_i x v_i+1)|. */
static double lambert_irradiance(const rt_vec3 *v, int count, rt_vec3 p, rt_vec3 n)
{
    double sum = 0.0;
    for (int i = 0; i < count; i++) {
        dv3 a = dsub3(d3(v[i]), d3(p)), b = dsub3(d3(v[(i + 1) % count]), d3(p));
        dv3 c = dcross3(a, b);
        double angle = atan2(dlen3(c), ddot3(a, b));
        sum += angle * ddot3(d3(n), c) / dlen3(c);
    }
    return 0.5 * fabs(sum);
}

/* Where the ray p + t w meets the plane of (o, e1, e2), as coordinates
 * (s, t) of o + s e1 + t e2; false when it misses the plane ahead. */
static bool plane_coords(rt_vec3 o, rt_vec3 e1, rt_vec3 e2, rt_vec3 p, rt_vec3 w, double *s, double *t)
{
    dv3 E1 = d3(e1), E2 = d3(e2), W = d3(w), T = dsub3(d3(p), d3(o));
    dv3 pv = dcross3(W, E2);
    double det = ddot3(E1, pv);
    if (fabs(det) < 1e-300)
        return false;
    dv3 qv = dcross3(T, E1);
    *s = ddot3(T, pv) / det;
    *t = ddot3(W, qv) / det;
    return ddot3(E2, qv) / det > 0.0;
}

/* Stratified u over n = side^2 samples, jittered. */
static rt_vec2 strat(int i, int side, test_rng *r)
{
    return rt_v2(((float)(i % side) + test_rng_float(r)) / (float)side,
                 ((float)(i / side) + test_rng_float(r)) / (float)side);
}

/* ------------------------------------------------------------ rectangles */

typedef struct rect_case {
    rt_vec3 corner, ex, ey, p;
} rect_case;

static const rect_case rects[] = {
    {{-1, 1, -1}, {2, 0, 0}, {0, 0, 2}, {0, 0, 0}},        /* centred above, 1 away */
    {{-1, 1, -1}, {2, 0, 0}, {0, 0, 2}, {3, 0.2f, 0.5f}},  /* off to the side, low */
    {{0, 0.05f, 0}, {0.3f, 0, 0}, {0, 0, 0.1f}, {0.2f, 0, 0.04f}}, /* close: 0.05 below */
    {{343, 548.7f, 227}, {0, 0, 105}, {-130, 0, 0}, {278, 548.7f - 1.0f, 280}}, /* the Cornell lamp from 1 below */
    {{343, 548.7f, 227}, {0, 0, 105}, {-130, 0, 0}, {100, 0, 50}},  /* ... from the floor */
};

static void test_rect_solid_angle_and_uniformity(void **state)
{
    (void)state;
    for (size_t k = 0; k < sizeof rects / sizeof rects[0]; k++) {
        const rect_case *c = &rects[k];
        rt_sph_rect r;
        assert_true(rt_sph_rect_init(&r, c->corner, c->ex, c->ey, c->p));
        rt_vec3 v1 = rt_add(c->corner, c->ex), v2 = rt_add(v1, c->ey), v3 = rt_add(c->corner, c->ey);
        double want = vos_solid_angle(c->corner, v1, v2, c->p) + vos_solid_angle(c->corner, v2, v3, c->p);
        if (fabs(r.S - want) > 1e-5 * want + 1e-7)
            fail_msg("rect %zu: solid angle %.9g, Van Oosterom-Strackee %.9g", k, (double)r.S, want);
        /* sub-rectangles of the parameter square and their solid angles */
        const double sub[][4] = {{0, 0.3, 0.2, 0.7}, {0.5, 1, 0, 0.5}, {0.1, 0.9, 0.85, 1}, {0, 1, 0, 0.05}};
        enum { NSUB = 4, SIDE = 200, N = SIDE * SIDE };
        double sub_omega[NSUB];
        for (int j = 0; j < NSUB; j++) {
            rt_vec3 a = rt_add(c->corner, rt_add(rt_scale(c->ex, (float)sub[j][0]), rt_scale(c->ey, (float)sub[j][2])));
            rt_vec3 b = rt_add(c->corner, rt_add(rt_scale(c->ex, (float)sub[j][1]), rt_scale(c->ey, (float)sub[j][2])));
            rt_vec3 cc = rt_add(c->corner, rt_add(rt_scale(c->ex, (float)sub[j][1]), rt_scale(c->ey, (float)sub[j][3])));
            rt_vec3 d = rt_add(c->corner, rt_add(rt_scale(c->ex, (float)sub[j][0]), rt_scale(c->ey, (float)sub[j][3])));
            sub_omega[j] = vos_solid_angle(a, b, cc, c->p) + vos_solid_angle(a, cc, d, c->p);
        }
        int in_sub[NSUB] = {0};
        test_rng tr = {11 + k};
        for (int i = 0; i < N; i++) {
            /* independent numbers: the 4-sigma bound is binomial */
            rt_vec2 u = rt_v2(test_rng_float(&tr), test_rng_float(&tr));
            float dist;
            rt_vec3 w = rt_sph_rect_sample(&r, u, &dist);
            assert_true(fabsf(rt_length(w) - 1.0f) < 1e-5f);
            double s, t;
            assert_true(plane_coords(c->corner, c->ex, c->ey, c->p, w, &s, &t));
            if (!(s > -1e-4 && s < 1 + 1e-4 && t > -1e-4 && t < 1 + 1e-4))
                fail_msg("rect %zu: sample %d misses the rectangle at (%g, %g)", k, i, s, t);
            /* the distance reaches the rectangle */
            rt_vec3 q = rt_madd(c->p, w, dist);
            double s2, t2;
            (void)plane_coords(c->corner, c->ex, c->ey, c->p, w, &s2, &t2);
            rt_vec3 q2 = rt_add(c->corner, rt_add(rt_scale(c->ex, (float)s2), rt_scale(c->ey, (float)t2)));
            assert_true(rt_length(rt_sub(q, q2)) < 1e-4f * (1.0f + rt_length(c->ex) + rt_length(c->ey)));
            for (int j = 0; j < NSUB; j++)
                if (s >= sub[j][0] && s < sub[j][1] && t >= sub[j][2] && t < sub[j][3])
                    in_sub[j]++;
        }
        for (int j = 0; j < NSUB; j++) {
            double pj = sub_omega[j] / want, got = (double)in_sub[j] / N, sd = sqrt(pj * (1 - pj) / N);
            if (fabs(got - pj) > 4 * sd + 1e-6)
                fail_msg("rect %zu, sub-rectangle %d: fraction %.5f, share of the solid angle %.5f (sd %.5f)", k, j,
                         got, pj, sd);
        }
    }
}

/* ------------------------------------------------------------ triangles */

typedef struct tri_case {
    rt_vec3 a, b, c, p;
} tri_case;

static const tri_case tris[] = {
    {{-1, 1, -1}, {1, 1, -1}, {0, 1, 1}, {0, 0, 0}},
    {{-1, 1, -1}, {1, 1, -1}, {0, 1, 1}, {2, 0.1f, -3}},
    {{0, 0.02f, 0}, {0.5f, 0.02f, 0.1f}, {0.1f, 0.02f, 0.4f}, {0.15f, 0, 0.15f}}, /* 0.02 below, inside */
    {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.2f, 0.3f, 0.001f}},  /* a hemisphere almost */
    {{0, 0, 0}, {0.01f, 0, 0}, {0, 0.02f, 0}, {0, 0, 1}},     /* small: 1e-4 sr */
    {{5, 2, 1}, {-3, 4, 2}, {1, -2, 6}, {0, 0, 0}},
};

static void test_tri_solid_angle_and_uniformity(void **state)
{
    (void)state;
    for (size_t k = 0; k < sizeof tris / sizeof tris[0]; k++) {
        const tri_case *c = &tris[k];
        rt_sph_tri t;
        assert_true(rt_sph_tri_init(&t, c->a, c->b, c->c, c->p));
        double want = vos_solid_angle(c->a, c->b, c->c, c->p);
        if (fabs(t.S - want) > 1e-5 * want + 1e-9)
            fail_msg("triangle %zu: solid angle %.9g, Van Oosterom-Strackee %.9g", k, (double)t.S, want);
        rt_vec3 e1 = rt_sub(c->b, c->a), e2 = rt_sub(c->c, c->a);
        /* sub-triangles: the corner at each vertex cut at the edges' midpoints, and the middle one */
        rt_vec3 mab = rt_lerp3(c->a, c->b, 0.5f), mbc = rt_lerp3(c->b, c->c, 0.5f), mca = rt_lerp3(c->c, c->a, 0.5f);
        rt_vec3 sub[4][3] = {{c->a, mab, mca}, {mab, c->b, mbc}, {mca, mbc, c->c}, {mab, mbc, mca}};
        enum { NSUB = 4, N = 40000 };
        int in_sub[NSUB] = {0};
        test_rng tr = {101 + k};
        for (int i = 0; i < N; i++) {
            rt_vec2 u = rt_v2(test_rng_float(&tr), test_rng_float(&tr));
            rt_vec3 w = rt_sph_tri_sample(&t, u);
            assert_true(fabsf(rt_length(w) - 1.0f) < 1e-5f);
            double s, tt;
            assert_true(plane_coords(c->a, e1, e2, c->p, w, &s, &tt));
            double tol = 1e-4;
            if (!(s > -tol && tt > -tol && s + tt < 1 + tol))
                fail_msg("triangle %zu: sample %d misses it at barycentrics (%g, %g)", k, i, s, tt);
            /* which sub-triangle: by barycentrics, the midpoint triangles */
            int j = s + tt > 0.5 && s < 0.5 && tt < 0.5 ? 3 : (s >= 0.5 ? 1 : (tt >= 0.5 ? 2 : 0));
            in_sub[j]++;
        }
        for (int j = 0; j < NSUB; j++) {
            double pj = vos_solid_angle(sub[j][0], sub[j][1], sub[j][2], c->p) / want;
            double got = (double)in_sub[j] / N, sd = sqrt(pj * (1 - pj) / N);
            if (fabs(got - pj) > 4 * sd + 2e-4)
                fail_msg("triangle %zu, sub-triangle %d: fraction %.5f, share of the solid angle %.5f (sd %.5f)", k,
                         j, got, pj, sd);
        }
    }
}

/* ------------------------------------------------------------ irradiance */

/* Mean and standard deviation of n estimates. */
typedef struct stats {
    double sum, sum2;
    int n;
} stats;
static void stats_add(stats *s, double x) { s->sum += x, s->sum2 += x * x, s->n++; }
static double stats_mean(const stats *s) { return s->sum / s->n; }
static double stats_var(const stats *s)
{
    double m = stats_mean(s);
    return s->sum2 / s->n - m * m;
}

static rt_light area_light(rt_vec3 corner, rt_vec3 eu, rt_vec3 ev)
{
    rt_light l;
    memset(&l, 0, sizeof l);
    l.kind = RT_LIGHT_AREA;
    l.color = rt_v3s(1.0f);
    l.intensity = 1.0f;
    l.position = corner;
    l.edge_u = eu;
    l.edge_v = ev;
    l.quad = RT_NONE;
    return l;
}

/* The irradiance at p (normal n) from a light of radiance 1 through
 * rt_light_sample_at, with every sample's pdf checked against
 * rt_area_light_pdf; and the same by uniform area sampling. */
static void irradiance(const rt_light *l, rt_vec3 p, rt_vec3 n, int side, stats *sa, stats *area)
{
    test_rng tr = {3};
    rt_vec3 nl = rt_cross(l->edge_u, l->edge_v);
    float A = rt_length(nl);
    nl = rt_scale(nl, 1.0f / A);
    for (int i = 0; i < side * side; i++) {
        rt_vec2 u = strat(i, side, &tr);
        rt_light_sample ls;
        double e = 0.0;
        if (rt_light_sample_at(NULL, l, p, u, &ls)) {
            float pdf = rt_area_light_pdf(l, p, ls.wi, ls.dist);
            if (memcmp(&pdf, &ls.pdf, sizeof pdf) != 0)
                fail_msg("sample %d: pdf %.9g, rt_area_light_pdf %.9g", i, (double)ls.pdf, (double)pdf);
            assert_true(fabsf(ls.li.x * ls.pdf - 1.0f) < 1e-5f); /* li = radiance / pdf */
            e = ls.li.x * fmax(0.0, rt_dot(n, ls.wi));
        }
        stats_add(sa, e);
        /* uniform area sampling: L A cos cos_l / d^2 */
        rt_vec3 q = rt_add(l->position, rt_add(rt_scale(l->edge_u, u.x), rt_scale(l->edge_v, u.y)));
        rt_vec3 d = rt_sub(q, p);
        float d2 = rt_length2(d);
        rt_vec3 w = rt_scale(d, 1.0f / sqrtf(d2));
        stats_add(area, (double)A * fmax(0.0, rt_dot(n, w)) * fmax(0.0, -rt_dot(nl, w)) / d2);
    }
}

/* Solid-angle sampling's irradiance at point k (sa) against Lambert's
 * (want) within 4 sigma (jittered samples: the i.i.d. sigma is an upper
 * bound), and, when `close`, its variance below half area sampling's (ar). */
static void check_irradiance(const char *what, size_t k, const stats *sa, const stats *ar, double want, bool close)
{
    double sd = sqrt(stats_var(sa) / sa->n);
    fprintf(stderr, "%s point %zu: E %.6f (Lambert %.6f), sd per sample: solid angle %.4g, area %.4g\n", what, k,
            stats_mean(sa), want, sqrt(stats_var(sa)), sqrt(stats_var(ar)));
    if (fabs(stats_mean(sa) - want) > 4 * sd + 1e-5 * want)
        fail_msg("%s point %zu: irradiance %.6f, Lambert %.6f (sd %.6f)", what, k, stats_mean(sa), want, sd);
    if (close && !(stats_var(sa) < 0.5 * stats_var(ar)))
        fail_msg("%s point %zu, close by: solid-angle sampling's variance %.4g is not below area sampling's %.4g / 2",
                 what, k, stats_var(sa), stats_var(ar));
}

static void test_rect_irradiance(void **state)
{
    (void)state;
    /* a 1 x 0.5 light facing down at y = 1, points below it at several
     * heights; the closest one is where area sampling's 1/d^2 hurts */
    rt_vec3 corner = {-0.5f, 1, -0.25f}, eu = {1, 0, 0}, ev = {0, 0, 0.5f};
    rt_light l = area_light(corner, eu, ev);
    rt_vec3 poly[4] = {corner, rt_add(corner, eu), rt_add(rt_add(corner, eu), ev), rt_add(corner, ev)};
    const struct { rt_vec3 p, n; } pts[] = {
        {{0, 0, 0}, {0, 1, 0}},
        {{0.3f, 0.9f, 0.1f}, {0, 1, 0}},          /* 0.1 below */
        {{0.45f, 0.99f, 0.2f}, {0, 1, 0}},        /* 0.01 below, near a corner */
        {{1.5f, 0.5f, 0}, {-0.6f, 0.8f, 0}},      /* tilted, off to the side */
    };
    for (size_t k = 0; k < sizeof pts / sizeof pts[0]; k++) {
        stats sa = {0}, ar = {0};
        irradiance(&l, pts[k].p, pts[k].n, 100, &sa, &ar);
        check_irradiance("rect", k, &sa, &ar, lambert_irradiance(poly, 4, pts[k].p, pts[k].n), k == 2);
    }
}

static void test_tri_irradiance(void **state)
{
    (void)state;
    rt_vec3 v[3] = {{-0.5f, 1, -0.3f}, {0.6f, 1, -0.2f}, {0, 1, 0.5f}};
    const struct { rt_vec3 p, n; } pts[] = {
        {{0, 0, 0}, {0, 1, 0}},
        {{0.05f, 0.98f, 0}, {0, 1, 0}}, /* 0.02 below */
        {{1, 0.2f, 1}, {-0.48f, 0.6f, -0.64f}},
    };
    for (size_t k = 0; k < sizeof pts / sizeof pts[0]; k++) {
        rt_sph_tri t;
        assert_true(rt_sph_tri_init(&t, v[0], v[1], v[2], pts[k].p));
        stats sa = {0}, ar = {0};
        test_rng tr = {7};
        rt_vec3 ng = rt_cross(rt_sub(v[1], v[0]), rt_sub(v[2], v[0]));
        float A2 = rt_length(ng);
        ng = rt_scale(ng, 1.0f / A2);
        for (int i = 0; i < 100 * 100; i++) {
            rt_vec2 u = strat(i, 100, &tr);
            stats_add(&sa, (double)t.S * fmax(0.0, rt_dot(pts[k].n, rt_sph_tri_sample(&t, u))));
            float su = sqrtf(u.x), b1 = u.y * su, b2 = 1.0f - su;
            rt_vec3 q = rt_add(rt_add(rt_scale(v[0], 1 - b1 - b2), rt_scale(v[1], b1)), rt_scale(v[2], b2));
            rt_vec3 d = rt_sub(q, pts[k].p);
            float d2 = rt_length2(d);
            rt_vec3 w = rt_scale(d, 1.0f / sqrtf(d2));
            stats_add(&ar, 0.5 * A2 * fmax(0.0, rt_dot(pts[k].n, w)) * fabs(rt_dot(ng, w)) / d2);
        }
        check_irradiance("triangle", k, &sa, &ar, lambert_irradiance(v, 3, pts[k].p, pts[k].n), k == 1);
    }
}

/* Outside the range (a rectangle of 1e-4 sr, a sheared parallelogram) the
 * light is sampled by area: the pdf is d^2 / (A cos theta_l), still the one
 * rt_area_light_pdf gives, and the irradiance still Lambert's. */
static void test_area_fallback(void **state)
{
    (void)state;
    rt_vec3 p = {0, 0, 0}, n = {0, 1, 0};
    rt_light small = area_light(rt_v3(-0.005f, 1, -0.005f), rt_v3(0.01f, 0, 0), rt_v3(0, 0, 0.01f));
    rt_light sheared = area_light(rt_v3(-0.5f, 1, -0.5f), rt_v3(1, 0, 0), rt_v3(0.3f, 0, 1));
    const rt_light *ls[] = {&small, &sheared};
    for (int k = 0; k < 2; k++) {
        const rt_light *l = ls[k];
        rt_light_sample s;
        assert_true(rt_light_sample_at(NULL, l, p, rt_v2(0.3f, 0.6f), &s));
        rt_vec3 nl = rt_cross(l->edge_u, l->edge_v);
        float A = rt_length(nl);
        float want_pdf = s.dist * s.dist / (A * (-rt_dot(nl, s.wi) / A));
        assert_true(fabsf(s.pdf - want_pdf) <= 1e-5f * want_pdf);
        stats sa = {0}, ar = {0};
        irradiance(l, p, n, 64, &sa, &ar);
        rt_vec3 poly[4] = {l->position, rt_add(l->position, l->edge_u),
                           rt_add(rt_add(l->position, l->edge_u), l->edge_v), rt_add(l->position, l->edge_v)};
        double want = lambert_irradiance(poly, 4, p, n);
        double sd = sqrt(stats_var(&sa) / sa.n);
        if (fabs(stats_mean(&sa) - want) > 4 * sd + 1e-4 * want)
            fail_msg("fallback %d: irradiance %.7f, Lambert %.7f (sd %.7f)", k, stats_mean(&sa), want, sd);
    }
    /* from behind: nothing, and pdf 0 */
    rt_light_sample s;
    rt_light big = area_light(rt_v3(-0.5f, 1, -0.5f), rt_v3(1, 0, 0), rt_v3(0, 0, 1));
    assert_false(rt_light_sample_at(NULL, &big, rt_v3(0, 2, 0), rt_v2(0.5f, 0.5f), &s));
    assert_true(rt_area_light_pdf(&big, rt_v3(0, 2, 0), rt_v3(0, -1, 0), 1.0f) == 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rect_solid_angle_and_uniformity),
        cmocka_unit_test(test_tri_solid_angle_and_uniformity),
        cmocka_unit_test(test_rect_irradiance),
        cmocka_unit_test(test_tri_irradiance),
        cmocka_unit_test(test_area_fallback),
    };
    return cmocka_run_group_tests_name("spherical", tests, NULL, NULL);
}
