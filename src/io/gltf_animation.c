/* gltf_animation.c - keyframe curves of glTF animations (rt/io/gltf_animation.h).
 *
 * Sources: the glTF 2.0 specification, 3.11 "Animations" (clamping outside
 * the key range, quaternion outputs) and Appendix C (STEP; LINEAR with
 * slerp for rotations; CUBICSPLINE, the cubic Hermite spline whose
 * tangents are stored scaled so that they are multiplied by the key
 * interval t_{k+1} - t_k); slerp after Shoemake, "Animating rotation with
 * quaternion curves" (SIGGRAPH 1985). */
#include "rt/io/gltf_animation.h"

#include <math.h>
#include <string.h>

static void normalise4(float q[4])
{
    float len = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (len > 0) {
        for (int i = 0; i < 4; i++)
            q[i] /= len;
    } else {
        q[0] = q[1] = q[2] = 0;
        q[3] = 1;
    }
}

void rt_quat_slerp(const float a[4], const float b[4], float u, float out[4])
{
    float d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    float s = 1.0f;
    if (d < 0) { /* the shorter arc: q and -q are one rotation */
        d = -d;
        s = -1.0f;
    }
    float wa, wb;
    if (d > 0.9995f) {
        wa = 1.0f - u;
        wb = u;
    } else {
        float theta = acosf(d), sn = sinf(theta);
        wa = sinf((1.0f - u) * theta) / sn;
        wb = sinf(u * theta) / sn;
    }
    for (int i = 0; i < 4; i++)
        out[i] = wa * a[i] + s * wb * b[i];
    normalise4(out);
}

/* The last key k with times[k] <= t (0 <= k < n - 1; t inside the range). */
static size_t find_key(const float *times, size_t n, float t)
{
    size_t lo = 0, hi = n - 1; /* times[lo] <= t < times[hi] */
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (times[mid] <= t)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

void rt_anim_sample(rt_interp interp, const float *times, size_t n, const float *values, int ncomp, bool quat,
                    float t, float *out)
{
    size_t per_key = interp == RT_INTERP_CUBICSPLINE ? 3 * (size_t)ncomp : (size_t)ncomp;
    size_t value_at = interp == RT_INTERP_CUBICSPLINE ? (size_t)ncomp : 0; /* skip the in-tangent */
    if (n == 1 || !(t > times[0]) || t >= times[n - 1]) {
        size_t k = n == 1 || !(t > times[0]) ? 0 : n - 1;
        memcpy(out, values + k * per_key + value_at, (size_t)ncomp * sizeof *out);
    } else {
        size_t k = find_key(times, n, t);
        float td = times[k + 1] - times[k];
        float u = (t - times[k]) / td;
        const float *v0 = values + k * per_key + value_at, *v1 = values + (k + 1) * per_key + value_at;
        switch (interp) {
        case RT_INTERP_STEP:
            memcpy(out, v0, (size_t)ncomp * sizeof *out);
            break;
        case RT_INTERP_LINEAR:
            if (quat && ncomp == 4) {
                rt_quat_slerp(v0, v1, u, out);
                return;
            }
            for (int c = 0; c < ncomp; c++)
                out[c] = v0[c] + u * (v1[c] - v0[c]);
            break;
        case RT_INTERP_CUBICSPLINE: {
            const float *b0 = v0 + ncomp;   /* out-tangent of key k */
            const float *a1 = v1 - ncomp;   /* in-tangent of key k + 1 */
            float u2 = u * u, u3 = u2 * u;
            float h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
            for (int c = 0; c < ncomp; c++)
                out[c] = h00 * v0[c] + h10 * td * b0[c] + h01 * v1[c] + h11 * td * a1[c];
            break;
        }
        }
    }
    if (quat && ncomp == 4)
        normalise4(out);
}
