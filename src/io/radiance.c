/* radiance.c - the Radiance HDR check of rt/io/radiance.h.
 *
 * The format (Greg Ward, "Real Pixels", Graphics Gems II, and the Radiance
 * reference manual's "Picture File Format"): text header lines ended by an
 * empty line, a resolution line "-Y H +X W", then H scanlines of W pixels of
 * 4 bytes (R, G, B mantissas and a shared exponent). A scanline is either
 * flat or run-length encoded: 2, 2, then its width in two bytes (high byte
 * under 128), then each of the 4 components in turn as runs (a byte over
 * 128: that many minus 128 copies of the next byte) and dumps (a byte n from
 * 1 to 128: n bytes as they are).
 *
 * The walk below follows stb_image's reader (stbi__hdr_load, stb_image
 * 2.27) step by step, so that what it accepts stb decodes within the file:
 * the header split into lines as stb splits it, flat data for images under
 * 8 or from 32768 pixels wide or whose first scanline is not run-length
 * encoded, run-length scanlines otherwise. It refuses what stb would loop on
 * (a run of 0), read past the end on, or decode into the wrong pixels (a
 * flat scanline after run-length ones, which stb answers by starting again
 * at the second pixel). */
#include "rt/io/radiance.h"

#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* stb's header line buffer (STBI__HDR_BUFLEN): longer lines are cut */
#define LINE_MAX_CHARS 1023

/* The next header line as stb reads it: up to '\n' (consumed), cut to
 * LINE_MAX_CHARS; *at moves past it. */
static void next_line(const unsigned char *p, size_t size, size_t *at, char line[LINE_MAX_CHARS + 1])
{
    size_t n = 0;
    while (*at < size && p[*at] != '\n') {
        if (n < LINE_MAX_CHARS)
            line[n++] = (char)p[*at];
        (*at)++;
    }
    if (*at < size)
        (*at)++; /* the '\n' */
    line[n] = 0;
}

rt_result rt_radiance_check(const void *data, size_t size, const char *name, rt_error *err)
{
    const unsigned char *p = data;
    size_t at = 0;
    char line[LINE_MAX_CHARS + 1];
    next_line(p, size, &at, line);
    if (strcmp(line, "#?RADIANCE") != 0 && strcmp(line, "#?RGBE") != 0)
        return rt_fail(err, RT_ERR_INVALID, "%s: not a Radiance HDR file (no #?RADIANCE line at byte 0)", name);
    do
        next_line(p, size, &at, line);
    while (line[0] && at < size);
    size_t res_at = at;
    next_line(p, size, &at, line);
    /* "-Y H +X W", parsed as stb parses it */
    char *s = line;
    long h = 0, w = 0;
    if (strncmp(s, "-Y ", 3) == 0) {
        s += 3;
        h = strtol(s, &s, 10);
        while (*s == ' ')
            s++;
        if (strncmp(s, "+X ", 3) == 0)
            w = strtol(s + 3, NULL, 10);
    }
    if (w <= 0 || h <= 0 || w > INT32_MAX || h > INT32_MAX)
        return rt_fail(err, RT_ERR_INVALID,
                       "%s: Radiance HDR resolution line at byte %zu is not \"-Y HEIGHT +X WIDTH\" with sizes over 0",
                       name, res_at);
    const uint64_t width = (uint64_t)w, height = (uint64_t)h;
    const size_t data_at = at;
    bool flat = width < 8 || width >= 32768;
    for (uint64_t y = 0; y < height && !flat; y++) {
        const size_t line_at = at;
        if (size - at < 4)
            return rt_fail(err, RT_ERR_INVALID, "%s: Radiance HDR data ends at byte %zu, in scanline %llu of %llu",
                           name, size, (unsigned long long)y, (unsigned long long)height);
        if (p[at] != 2 || p[at + 1] != 2 || (p[at + 2] & 0x80)) {
            if (y == 0) {
                flat = true; /* stb reads the whole image as flat pixels */
                break;
            }
            return rt_fail(err, RT_ERR_INVALID,
                           "%s: Radiance HDR scanline %llu (byte %zu) is flat after run-length encoded ones, which "
                           "rt does not read",
                           name, (unsigned long long)y, line_at);
        }
        uint64_t len = (uint64_t)p[at + 2] << 8 | p[at + 3];
        if (len != width)
            return rt_fail(err, RT_ERR_INVALID,
                           "%s: Radiance HDR scanline %llu (byte %zu) says it is %llu pixels wide, not the image's %llu",
                           name, (unsigned long long)y, line_at, (unsigned long long)len,
                           (unsigned long long)width);
        at += 4;
        for (int c = 0; c < 4; c++) {
            uint64_t x = 0;
            while (x < width) {
                if (at >= size)
                    return rt_fail(err, RT_ERR_INVALID,
                                   "%s: Radiance HDR data ends at byte %zu, in scanline %llu of %llu", name, size,
                                   (unsigned long long)y, (unsigned long long)height);
                const size_t run_at = at;
                unsigned count = p[at++];
                uint64_t n = count > 128 ? count - 128 : count;
                if (n == 0)
                    return rt_fail(err, RT_ERR_INVALID,
                                   "%s: Radiance HDR scanline %llu has a run of length 0 at byte %zu", name,
                                   (unsigned long long)y, run_at);
                if (n > width - x)
                    return rt_fail(err, RT_ERR_INVALID,
                                   "%s: Radiance HDR scanline %llu: the run at byte %zu goes past its %llu pixels",
                                   name, (unsigned long long)y, run_at, (unsigned long long)width);
                uint64_t bytes = count > 128 ? 1 : n;
                if (size - at < bytes)
                    return rt_fail(err, RT_ERR_INVALID,
                                   "%s: Radiance HDR data ends at byte %zu, in scanline %llu of %llu", name, size,
                                   (unsigned long long)y, (unsigned long long)height);
                at += (size_t)bytes;
                x += n;
            }
        }
    }
    if (flat && (uint64_t)(size - data_at) / 4 / width < height)
        return rt_fail(err, RT_ERR_INVALID,
                       "%s: Radiance HDR data ends at byte %zu, before the %llux%llu flat pixels starting at byte %zu "
                       "(%llu bytes)",
                       name, size, (unsigned long long)width, (unsigned long long)height, data_at,
                       (unsigned long long)(width * height * 4));
    return RT_OK;
}
