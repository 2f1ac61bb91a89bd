/* frames.c - frame names and times for `--frames A:B` (frames.h). A name
 * pattern takes one printf-style integer conversion, %d or %0Nd, as ffmpeg
 * and Blender's `####` do for image sequences; the frame's time is
 * frame / fps. */
#include "frames.h"

#include <stdio.h>
#include <string.h>

/* Finds the one conversion: its start and length; false when there is
 * none, more than one, or another '%' sequence than "%%". */
static bool find_conversion(const char *p, size_t *at, size_t *len)
{
    int found = 0;
    for (size_t i = 0; p[i]; i++) {
        if (p[i] != '%')
            continue;
        if (p[i + 1] == '%') {
            i++;
            continue;
        }
        size_t j = i + 1;
        if (p[j] == '0' && p[j + 1] >= '1' && p[j + 1] <= '9')
            j += 2;
        if (p[j] != 'd')
            return false;
        *at = i;
        *len = j + 1 - i;
        found++;
        i = j;
    }
    return found == 1;
}

bool frames_pattern_ok(const char *pattern)
{
    size_t at, len;
    return find_conversion(pattern, &at, &len);
}

bool frames_name(const char *pattern, int frame, char *out, size_t size)
{
    size_t at, len;
    if (!find_conversion(pattern, &at, &len) || size == 0)
        return false;
    size_t o = 0;
    for (size_t i = 0; pattern[i]; i++) {
        char piece[32];
        size_t n = 1;
        if (i == at) { /* the number, zero-padded to N for %0Nd */
            int width = len == 4 ? pattern[at + 2] - '0' : 0;
            int k = snprintf(piece, sizeof piece, "%0*d", width, frame);
            n = k > 0 ? (size_t)k : 0;
            i += len - 1;
        } else {
            piece[0] = pattern[i];
            if (pattern[i] == '%')
                i++; /* "%%" is one '%' */
        }
        if (o + n >= size)
            return false;
        memcpy(out + o, piece, n);
        o += n;
    }
    out[o] = 0;
    return true;
}

double frames_time(int frame, double fps) { return (double)frame / fps; }

rt_result frames_apply(rt_scene *scene, double t, rt_error *err)
{
    (void)scene;
    (void)t;
    (void)err;
    return RT_OK;
}
