/* compare.c - error metrics between two linear RGB float images: MSE, RMSE,
 * relative MSE, mean absolute error and each image's per-channel mean, all
 * accumulated in double. relMSE is the relative MSE common in
 * rendering papers and tools, mean((c - r)^2 / (r^2 + eps)) with the
 * reference r in the denominator and eps = 1e-2 so that black pixels do not
 * divide by zero. */
#include "rt/image/compare.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

rt_result rt_image_metrics(const float *candidate, const float *reference, int width, int height, rt_metrics *m,
                           rt_error *err)
{
    if (!candidate || !reference || !m)
        return rt_fail(err, RT_ERR_INVALID, "image metrics: no image given");
    if (width <= 0 || height <= 0 || (size_t)width > SIZE_MAX / 3 / (size_t)height)
        return rt_fail(err, RT_ERR_INVALID, "image metrics: image size %dx%d is out of range", width, height);
    memset(m, 0, sizeof *m);
    size_t pixels = (size_t)width * (size_t)height;
    double se = 0, rel = 0, ae = 0;
    double sum_c[3] = {0, 0, 0}, sum_r[3] = {0, 0, 0};
    for (size_t i = 0; i < pixels; i++) {
        for (int k = 0; k < 3; k++) {
            double c = candidate[3 * i + (size_t)k], r = reference[3 * i + (size_t)k];
            double d = c - r;
            se += d * d;
            rel += d * d / (r * r + RT_RELMSE_EPSILON);
            ae += fabs(d);
            sum_c[k] += c;
            sum_r[k] += r;
        }
    }
    double n = 3.0 * (double)pixels;
    m->mse = se / n;
    m->rmse = sqrt(m->mse);
    m->relmse = rel / n;
    m->mae = ae / n;
    for (int k = 0; k < 3; k++) {
        m->mean_candidate[k] = sum_c[k] / (double)pixels;
        m->mean_reference[k] = sum_r[k] / (double)pixels;
    }
    return RT_OK;
}
