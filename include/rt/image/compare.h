/* rt/image/compare.h - error metrics between two linear RGB float images.
 *
 * Both images are interleaved RGB floats (3 a pixel, row-major), the same
 * width and height. Every sum is accumulated in double, so a 4K image's
 * metrics do not depend on summation order to any printed digit.
 *
 *   rt_metrics m;
 *   if (rt_image_metrics(candidate, reference, width, height, &m, &err) != RT_OK) ...
 *   printf("RMSE: %g\n", m.rmse);
 *
 * With c the candidate, r the reference and the means over all N = 3 w h
 * channel values (docs/compare.md):
 *   MSE    = mean (c - r)^2                RMSE = sqrt(MSE)
 *   relMSE = mean (c - r)^2 / (r^2 + 0.01) MAE  = mean |c - r|
 * relMSE divides by the reference only (it is not symmetric);
 * RT_RELMSE_EPSILON keeps black pixels from dividing by zero.
 * A NaN or infinity in either image makes the metrics NaN or infinite, so a
 * threshold on them fails.
 */
#ifndef RT_IMAGE_COMPARE_H
#define RT_IMAGE_COMPARE_H

#include "rt/base/error.h"

#define RT_RELMSE_EPSILON 1e-2

typedef struct rt_metrics {
    double mse, rmse, relmse, mae;
    double mean_candidate[3], mean_reference[3]; /* per channel R, G, B */
} rt_metrics;

/* Fills *m. RT_ERR_INVALID for a size under 1x1 or NULL images. */
rt_result rt_image_metrics(const float *candidate, const float *reference, int width, int height, rt_metrics *m,
                           rt_error *err);

#endif
