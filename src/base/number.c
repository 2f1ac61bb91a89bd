/* number.c - strict decimal numbers (number.h): the syntax is checked by
 * hand first, so strtoll/strtod only ever see a plain decimal number (no
 * hexadecimal, no `nan`/`inf`, no leading blanks); then the whole string must
 * have been used and the value must fit. */
#include "rt/base/number.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

/* [+-] digits [. digits] [(e|E) [+-] digits], with at least one digit in the
 * mantissa; without allow_fraction only [+-] digits. */
static bool decimal_syntax(const char *s, bool allow_fraction)
{
    const char *c = s;
    int digits = 0;
    if (*c == '+' || *c == '-')
        c++;
    while (*c >= '0' && *c <= '9')
        c++, digits++;
    if (allow_fraction && *c == '.') {
        c++;
        while (*c >= '0' && *c <= '9')
            c++, digits++;
    }
    if (digits == 0)
        return false;
    if (allow_fraction && (*c == 'e' || *c == 'E')) {
        c++;
        if (*c == '+' || *c == '-')
            c++;
        if (!(*c >= '0' && *c <= '9'))
            return false;
        while (*c >= '0' && *c <= '9')
            c++;
    }
    return *c == '\0';
}

rt_number_status rt_parse_int(const char *s, long long *out)
{
    if (!decimal_syntax(s, false))
        return RT_NUMBER_BAD;
    errno = 0;
    char *end = NULL;
    long long v = strtoll(s, &end, 10);
    if (!end || *end != '\0')
        return RT_NUMBER_BAD;
    if (errno == ERANGE)
        return RT_NUMBER_RANGE;
    *out = v;
    return RT_NUMBER_OK;
}

rt_number_status rt_parse_float(const char *s, float *out)
{
    if (!decimal_syntax(s, true))
        return RT_NUMBER_BAD;
    errno = 0;
    char *end = NULL;
    double d = strtod(s, &end);
    if (!end || *end != '\0')
        return RT_NUMBER_BAD;
    if (!isfinite(d) || fabs(d) > (double)FLT_MAX)
        return RT_NUMBER_RANGE;
    *out = (float)d;
    return RT_NUMBER_OK;
}

rt_number_status rt_parse_double(const char *s, double *out)
{
    if (!decimal_syntax(s, true))
        return RT_NUMBER_BAD;
    errno = 0;
    char *end = NULL;
    double d = strtod(s, &end);
    if (!end || *end != '\0')
        return RT_NUMBER_BAD;
    if (!isfinite(d))
        return RT_NUMBER_RANGE;
    *out = d;
    return RT_NUMBER_OK;
}
