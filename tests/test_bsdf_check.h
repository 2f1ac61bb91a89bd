/* test_bsdf_check.h - the BSDF tests' check that sampling draws from the
 * density evaluation reports. Include after test_util.h.
 *
 *   rt_vec3 wo = dir_from(0.6f, 0.3f);                 // cos theta, phi about +z
 *   test_pdf_histogram(&b, wo, rt_rng_seed(seed, 7), 200000, "label");
 *
 * test_pdf_histogram draws n samples with rt_bsdf_sample_dir from the
 * given random stream, leaves out delta lobes (a mirror or a smooth glass
 * has no density to compare), and checks that
 *   - every sample's pdf is the one rt_bsdf_eval gives for its direction
 *     (to 1e-4 relative);
 *   - a histogram of the directions over 16 x 16 cells in (cos theta, phi)
 *     matches the pdf integrated over each cell (24 x 24 midpoints) to 5
 *     standard deviations of the binomial count, plus 2% and 2e-5 for the
 *     quadrature;
 *   - the pdf integrates over the sphere to the fraction of samples that
 *     succeed (to 0.01), and to at most 1.01.
 */
#ifndef RT_TEST_BSDF_CHECK_H
#define RT_TEST_BSDF_CHECK_H

#include <math.h>
#include <string.h>

#include "rt/render/bsdf.h"
#include "rt/render/sampling.h"

/* The unit direction at polar cosine cos_t and azimuth phi about +z. */
static inline rt_vec3 dir_from(float cos_t, float phi)
{
    float s = sqrtf(fmaxf(0.0f, 1.0f - cos_t * cos_t));
    return rt_v3(s * cosf(phi), s * sinf(phi), cos_t);
}

static inline void test_pdf_histogram(const rt_bsdf *b, rt_vec3 wo, rt_rng rng, int n, const char *label)
{
    enum { NT = 16, NP = 16, SUB = 24 };
    static double hist[NT][NP];
    memset(hist, 0, sizeof hist);
    int ok = 0;
    for (int i = 0; i < n; i++) {
        rt_bsdf_sample s;
        float ul = rt_rng_float(&rng);
        rt_vec2 u = rt_v2(rt_rng_float(&rng), rt_rng_float(&rng));
        if (!rt_bsdf_sample_dir(b, wo, u, ul, &s) || s.delta)
            continue;
        ok++;
        float pe;
        rt_bsdf_eval(b, wo, s.wi, &pe);
        if (!(fabsf(pe - s.pdf) <= 1e-4f * s.pdf))
            fail_msg("%s: sample pdf %.6g, rt_bsdf_eval's %.6g", label, (double)s.pdf, (double)pe);
        int it = (int)(s.wi.z * NT), ip = (int)((atan2f(s.wi.y, s.wi.x) + RT_PI) / (2.0f * RT_PI) * NP);
        it = it < 0 ? 0 : (it >= NT ? NT - 1 : it);
        ip = ip < 0 ? 0 : (ip >= NP ? NP - 1 : ip);
        hist[it][ip] += 1.0 / n;
    }
    double total = 0.0;
    for (int it = 0; it < NT; it++)
        for (int ip = 0; ip < NP; ip++) {
            double acc = 0.0;
            for (int a = 0; a < SUB; a++)
                for (int c = 0; c < SUB; c++) {
                    float ct = ((float)it + ((float)a + 0.5f) / SUB) / NT;
                    float ph = ((float)ip + ((float)c + 0.5f) / SUB) / NP * 2.0f * RT_PI - RT_PI;
                    float pdf;
                    rt_bsdf_eval(b, wo, dir_from(ct, ph), &pdf);
                    acc += pdf;
                }
            /* the mean pdf times the cell's solid angle */
            double e = acc / (SUB * SUB) * (1.0 / NT) * (2.0 * 3.14159265358979323846 / NP);
            total += e;
            double tol = 5.0 * sqrt(e / n) + 0.02 * e + 2e-5;
            if (fabs(hist[it][ip] - e) > tol)
                fail_msg("%s cell (%d,%d): histogram %.5f, pdf %.5f", label, it, ip, hist[it][ip], e);
        }
    if (fabs(total - (double)ok / n) > 0.01 || total > 1.01)
        fail_msg("%s: pdf integrates to %.4f, samples succeed %.4f", label, total, (double)ok / n);
}

#endif
