/* tonemap.c - exposure and tone curves for 8-bit output (rt/image/tonemap.h).
 *
 * Sources of the curves (their published constants, re-derived nowhere):
 * - filmic: John Hable, "Uncharted 2: HDR Lighting", GDC 2010, and his post
 *   "Filmic Tonemapping Operators" (2010): f(x) = (x(Ax + CB) + DE) /
 *   (x(Ax + B) + DF) - E/F with A 0.15, B 0.50, C 0.10, D 0.20, E 0.02,
 *   F 0.30, applied to 2x (his exposure bias) and divided by f(W), W = 11.2.
 * - aces: Krzysztof Narkowicz, "ACES Filmic Tone Mapping Curve" (2016):
 *   x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14) on 0.6x, a per-channel fit of
 *   the Academy's RRT+ODT for an sRGB display.
 * - agx: Troy Sobotka's AgX (2022), as fitted by Benjamin Wrensch, "Minimal
 *   AgX implementation" (iolite engine blog, 2023): the inset matrix, log2
 *   encoding between -12.47393 and 4.026069 EV, a 6th-order polynomial for
 *   the sigmoid, the inverse matrix, then the 2.2 power to display-linear.
 * The sRGB encoding is IEC 61966-2-1 (rt_linear_to_srgb).
 */
#include "rt/image/tonemap.h"

#include <math.h>
#include <string.h>

#include "rt/image/srgb.h"

static const char *const names[] = {"clamp", "filmic", "aces", "agx"};

bool rt_tonemap_parse(const char *name, rt_tonemap *out)
{
    for (int i = 0; i < 4; i++)
        if (strcmp(name, names[i]) == 0) {
            *out = (rt_tonemap)i;
            return true;
        }
    return false;
}

const char *rt_tonemap_name(rt_tonemap tm)
{
    return (unsigned)tm < 4 ? names[tm] : "?";
}

float rt_exposure_scale(float ev)
{
    return exp2f(ev);
}

static float hable(float x)
{
    const float A = 0.15f, B = 0.50f, C = 0.10f, D = 0.20f, E = 0.02f, F = 0.30f;
    return (x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F) - E / F;
}

static float aces(float x)
{
    x *= 0.6f;
    return (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
}

static float agx_contrast(float x)
{
    float x2 = x * x, x4 = x2 * x2;
    return 15.5f * x4 * x2 - 40.14f * x4 * x + 31.96f * x4 - 6.868f * x2 * x + 0.4298f * x2 + 0.1191f * x - 0.00232f;
}

static void agx(const float in[3], float out[3])
{
    /* rows of the inset matrix and of its inverse (Wrensch's GLSL mat3s are
     * column-major: these are their transposes, read row by row) */
    static const float inset[3][3] = {{0.842479062253094f, 0.0784335999999992f, 0.0792237451477643f},
                                      {0.0423282422610123f, 0.878468636469772f, 0.0791661274605434f},
                                      {0.0423756549057051f, 0.0784336f, 0.879142973793104f}};
    static const float outset[3][3] = {{1.19687900512017f, -0.0980208811401368f, -0.0990297440797205f},
                                       {-0.0528968517574562f, 1.15190312990417f, -0.0989611768448433f},
                                       {-0.0529716355144438f, -0.0980434501171241f, 1.15107367264116f}};
    const float min_ev = -12.47393f, max_ev = 4.026069f;
    float v[3];
    for (int i = 0; i < 3; i++) {
        float x = inset[i][0] * in[0] + inset[i][1] * in[1] + inset[i][2] * in[2];
        x = log2f(fmaxf(x, 1e-10f));
        x = (fminf(fmaxf(x, min_ev), max_ev) - min_ev) / (max_ev - min_ev);
        v[i] = agx_contrast(x);
    }
    for (int i = 0; i < 3; i++) {
        float x = outset[i][0] * v[0] + outset[i][1] * v[1] + outset[i][2] * v[2];
        out[i] = powf(fmaxf(x, 0.0f), 2.2f);
    }
}

void rt_tonemap_rgb(rt_tonemap tm, const float in[3], float out[3])
{
    float c[3];
    for (int i = 0; i < 3; i++)
        c[i] = in[i] > 0.0f ? in[i] : 0.0f; /* also NaN -> 0 */
    switch (tm) {
    case RT_TONEMAP_FILMIC: {
        float white = 1.0f / hable(11.2f);
        for (int i = 0; i < 3; i++)
            out[i] = hable(2.0f * fminf(c[i], 1e30f)) * white;
        break;
    }
    case RT_TONEMAP_ACES:
        for (int i = 0; i < 3; i++)
            out[i] = aces(fminf(c[i], 1e15f));
        break;
    case RT_TONEMAP_AGX:
        agx(c, out);
        break;
    case RT_TONEMAP_CLAMP:
    default:
        for (int i = 0; i < 3; i++)
            out[i] = c[i];
        break;
    }
    for (int i = 0; i < 3; i++)
        out[i] = out[i] > 0.0f ? (out[i] < 1.0f ? out[i] : 1.0f) : 0.0f;
}

void rt_tonemap_to_srgb8(rt_tonemap tm, float exposure, const float *rgb, size_t pixels, unsigned char *out)
{
    if (tm == RT_TONEMAP_CLAMP) { /* the plain path, as rt's PNGs always were */
        for (size_t i = 0; i < pixels * 3; i++)
            out[i] = (unsigned char)(rt_linear_to_srgb(rgb[i] * exposure) * 255.0f + 0.5f);
        return;
    }
    for (size_t p = 0; p < pixels; p++) {
        float in[3] = {rgb[3 * p] * exposure, rgb[3 * p + 1] * exposure, rgb[3 * p + 2] * exposure}, d[3];
        rt_tonemap_rgb(tm, in, d);
        for (int i = 0; i < 3; i++)
            out[3 * p + i] = (unsigned char)(rt_linear_to_srgb(d[i]) * 255.0f + 0.5f);
    }
}
