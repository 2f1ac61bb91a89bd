/* mesh_text.c - number parsing and warn-once for the text mesh readers
 * (mesh_text.h).
 *
 * Float parsing: decimal digits are accumulated into a 64-bit integer m with a
 * decimal exponent e. When m <= 2^53 and |e| <= 22, m and 10^|e| are exact
 * doubles and one IEEE multiply or divide gives the correctly rounded double
 * (Clinger, "How to Read Floating Point Numbers Accurately", PLDI 1990). That
 * double rounds to the correctly rounded float unless it lies exactly on a
 * midpoint between two floats (any midpoint strictly between the true value
 * and the double would be a closer double), so only that case, subnormal or
 * huge results and long mantissas fall back to strtof on a bounded copy.
 * rt never calls setlocale(), so strtof sees the "C" locale's '.'.
 */
#include "mesh_text.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int ascii_lower(int c) { return (c >= 'A' && c <= 'Z') ? c - 'A' + 'a' : c; }

bool rt_warn_once_first(rt_warn_once *w, const char *key, size_t len)
{
    const size_t keep = sizeof w->seen[0] - 1;
    if (len > keep)
        len = keep;
    for (int i = 0; i < w->count; i++)
        if (strlen(w->seen[i]) == len && memcmp(w->seen[i], key, len) == 0)
            return false;
    if (w->count >= (int)(sizeof w->seen / sizeof w->seen[0]))
        return false;
    memcpy(w->seen[w->count], key, len);
    w->seen[w->count][len] = 0;
    w->count++;
    return true;
}

/* ------------------------------------------------------------- numbers */

static bool is_digit(char c) { return c >= '0' && c <= '9'; }

const char *rt_mesh_parse_int(const char *p, const char *end, int64_t *out)
{
    bool neg = false;
    if (p < end && (*p == '-' || *p == '+')) {
        neg = *p == '-';
        p++;
    }
    if (p >= end || !is_digit(*p))
        return NULL;
    uint64_t v = 0;
    while (p < end && is_digit(*p)) {
        v = v * 10 + (uint64_t)(*p - '0');
        if (v > ((uint64_t)1 << 62))
            return NULL; /* far beyond any count or index we accept */
        p++;
    }
    *out = neg ? -(int64_t)v : (int64_t)v;
    return p;
}

static const double pow10_exact[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                       1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

static bool word_at(const char *p, const char *end, const char *w)
{
    for (; *w; w++, p++)
        if (p >= end || ascii_lower((unsigned char)*p) != *w)
            return false;
    return true;
}

/* A decimal mantissa as it is read: at most 19 significant digits in m,
 * exp10 the power of ten that scales it. */
typedef struct decimal {
    uint64_t m;
    int digits; /* significant digits kept in m */
    long exp10;
    bool any, inexact;
} decimal;

/* The run of digits at p into d: integer digits past the 19th raise
 * exp10, kept fraction digits lower it; a dropped digit other than 0 makes
 * d inexact. Returns the first byte after the run. */
static inline const char *take_digits(const char *p, const char *end, bool fraction, decimal *d)
{
    for (; p < end && is_digit(*p); p++) {
        d->any = true;
        if (d->digits < 19) {
            d->m = d->m * 10 + (uint64_t)(*p - '0');
            if (d->m)
                d->digits++;
            if (fraction)
                d->exp10--;
        } else {
            if (!fraction)
                d->exp10++;
            if (*p != '0')
                d->inexact = true;
        }
    }
    return p;
}

const char *rt_mesh_parse_float(const char *p, const char *end, float *out, bool *nonfinite)
{
    const char *start = p;
    *nonfinite = false;
    bool neg = false;
    if (p < end && (*p == '-' || *p == '+')) {
        neg = *p == '-';
        p++;
    }
    if (p < end && (word_at(p, end, "nan") || word_at(p, end, "inf"))) {
        *nonfinite = true;
        return NULL;
    }
    decimal dec = {0, 0, 0, false, false};
    p = take_digits(p, end, false, &dec);
    if (p < end && *p == '.')
        p = take_digits(p + 1, end, true, &dec);
    if (!dec.any)
        return NULL;
    uint64_t m = dec.m;
    long exp10 = dec.exp10;
    bool inexact = dec.inexact;
    if (p < end && (*p == 'e' || *p == 'E')) {
        const char *q = p + 1;
        bool eneg = false;
        if (q < end && (*q == '-' || *q == '+')) {
            eneg = *q == '-';
            q++;
        }
        if (q < end && is_digit(*q)) {
            long e = 0;
            while (q < end && is_digit(*q)) {
                if (e < 100000)
                    e = e * 10 + (*q - '0');
                q++;
            }
            exp10 += eneg ? -e : e;
            p = q;
        } /* else: a bare 'e' is not part of the number; the caller sees it */
    }
    if (m == 0) {
        *out = neg ? -0.0f : 0.0f;
        return p;
    }
    if (!inexact && m <= ((uint64_t)1 << 53) && exp10 >= -22 && exp10 <= 22) {
        double d = (double)m;
        d = exp10 < 0 ? d / pow10_exact[-exp10] : d * pow10_exact[exp10];
        if (d >= (double)FLT_MIN && d <= (double)FLT_MAX) {
            uint64_t bits;
            memcpy(&bits, &d, sizeof bits);
            /* a double on a float midpoint has exactly bit 28 set below the float's 24 bits */
            if ((bits & 0x1FFFFFFFu) != 0x10000000u) {
                float f = (float)d;
                *out = neg ? -f : f;
                return p;
            }
        }
    }
    /* slow path: strtof on a bounded NUL-terminated copy */
    char buf[512];
    size_t len = (size_t)(p - start);
    if (len >= sizeof buf)
        return NULL;
    memcpy(buf, start, len);
    buf[len] = 0;
    char *e = NULL;
    errno = 0;
    float f = strtof(buf, &e);
    if (e != buf + len)
        return NULL;
    if (!isfinite(f)) {
        *nonfinite = true;
        return NULL;
    }
    *out = f;
    return p;
}
