/* frames.c - frame names and times for `--frames A:B` (frames.h). A name
 * pattern takes one printf-style integer conversion, %d or %0Nd, as ffmpeg
 * does for image sequences, or a run of N '#' (Blender's `####`, the
 * number zero-padded to N digits); the frame's time is
 * frame / fps, at which main.c poses an animated glTF (as --frame-time
 * does). */
#include "frames.h"

#include <stdio.h>
#include <string.h>

#include "rt/base/file.h"

/* Finds the one conversion: its start, length and zero-padded width (0:
 * none); false when there is none, more than one, or another '%' sequence
 * than "%%". A pattern with a '%' is printf's (a '#' in it is a '#');
 * without one, the one run of '#' is the number (Blender's `####`). */
static bool find_conversion(const char *p, size_t *at, size_t *len, int *width)
{
    int found = 0;
    bool printf_style = strchr(p, '%') != NULL;
    for (size_t i = 0; p[i]; i++) {
        if (!printf_style) {
            if (p[i] != '#')
                continue;
            size_t j = i;
            while (p[j] == '#')
                j++;
            if (j - i > 9)
                return false;
            *at = i;
            *len = j - i;
            *width = (int)(j - i);
            found++;
            i = j - 1;
            continue;
        }
        if (p[i] != '%')
            continue;
        if (p[i + 1] == '%') {
            i++;
            continue;
        }
        size_t j = i + 1;
        *width = 0;
        if (p[j] == '0' && p[j + 1] >= '1' && p[j + 1] <= '9') {
            *width = p[j + 1] - '0';
            j += 2;
        }
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
    int width;
    return find_conversion(pattern, &at, &len, &width);
}

bool frames_name(const char *pattern, int frame, char *out, size_t size)
{
    size_t at, len;
    int width;
    if (!find_conversion(pattern, &at, &len, &width) || size == 0)
        return false;
    bool printf_style = strchr(pattern, '%') != NULL;
    size_t o = 0;
    for (size_t i = 0; pattern[i]; i++) {
        char piece[32];
        size_t n = 1;
        if (i == at) { /* the number, zero-padded to its width */
            int k = snprintf(piece, sizeof piece, "%0*d", width, frame);
            n = k > 0 ? (size_t)k : 0;
            i += len - 1;
        } else {
            piece[0] = pattern[i];
            if (printf_style && pattern[i] == '%')
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

bool frames_default_pattern(const char *name, char *out, size_t size)
{
    /* NAME.png -> NAME.%04d.png, a '%' of NAME written "%%" */
    char escaped[1100];
    size_t o = 0;
    for (size_t i = 0; name[i]; i++) {
        if (o + 3 >= sizeof escaped)
            return false;
        if (name[i] == '%')
            escaped[o++] = '%';
        escaped[o++] = name[i];
    }
    escaped[o] = 0;
    return rt_path_tagged(escaped, "%04d", NULL, out, size);
}

double frames_time(int frame, double fps) { return (double)frame / fps; }
