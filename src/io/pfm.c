/* pfm.c - reading PFM files (rt_pfm_read, rt/io/image_read.h).
 *
 * The format (Paul Debevec's "PFM Portable Float Map" note, as Netpbm and
 * pbrt read it): "PF" (RGB) or "Pf" (grey), white space, the width, white
 * space, the height, white space, a scale whose sign gives the byte order
 * (negative: little-endian), one white-space byte, then the rows of 32-bit
 * floats from the bottom of the image up. rt ignores the scale's magnitude,
 * as it always has (its own files say -1.0).
 *
 * The header is parsed by hand (no scanf: a number past INT_MAX is caught
 * here) and the pixel bytes it declares are checked against the file's size
 * before any pixel memory is allocated, so a header claiming 65536x65536
 * (48 GiB) on a small file is one clear error, not an allocation. */
#include "rt/io/image_read.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define PFM_MAX_SIDE 65536   /* rt_framebuffer_init's limit */
#define PFM_HEADER_BYTES 128 /* "PF", two sizes and a scale fit many times over */

static bool is_space(unsigned char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

typedef struct pfm_header {
    int width, height, channels;
    bool big_endian;
    size_t data_at; /* byte offset of the first pixel */
} pfm_header;

/* A size in 1..PFM_MAX_SIDE after white space, at *at. */
static rt_result header_size(const unsigned char *p, size_t n, size_t *at, const char *what, const char *path,
                             int *out, rt_error *err)
{
    size_t start = *at;
    while (*at < n && is_space(p[*at]))
        (*at)++;
    if (*at == start && *at < n)
        return rt_fail(err, RT_ERR_PARSE, "%s: PFM header: expected white space before the %s at byte %zu", path,
                       what, *at);
    size_t digits_at = *at;
    long v = 0;
    while (*at < n && p[*at] >= '0' && p[*at] <= '9') {
        v = v * 10 + (p[*at] - '0');
        if (v > PFM_MAX_SIDE)
            return rt_fail(err, RT_ERR_LIMIT, "%s: PFM %s at byte %zu is over %d", path, what, digits_at,
                           PFM_MAX_SIDE);
        (*at)++;
    }
    if (*at == digits_at)
        return rt_fail(err, RT_ERR_PARSE, "%s: PFM header: expected the %s (a whole number) at byte %zu", path, what,
                       digits_at);
    if (v == 0)
        return rt_fail(err, RT_ERR_PARSE, "%s: PFM %s at byte %zu is 0", path, what, digits_at);
    *out = (int)v;
    return RT_OK;
}

static rt_result parse_header(const unsigned char *p, size_t n, const char *path, pfm_header *h, rt_error *err)
{
    if (n < 2 || p[0] != 'P' || (p[1] != 'F' && p[1] != 'f'))
        return rt_fail(err, RT_ERR_PARSE, "%s: not a PFM file (no \"PF\" or \"Pf\" at byte 0)", path);
    h->channels = p[1] == 'F' ? 3 : 1;
    size_t at = 2;
    rt_result r = header_size(p, n, &at, "width", path, &h->width, err);
    if (r == RT_OK)
        r = header_size(p, n, &at, "height", path, &h->height, err);
    if (r != RT_OK)
        return r;
    while (at < n && is_space(p[at]))
        at++;
    size_t scale_at = at;
    char token[40];
    size_t len = 0;
    while (at < n && !is_space(p[at]) && len + 1 < sizeof token)
        token[len++] = (char)p[at++];
    token[len] = 0;
    char *end = NULL;
    double scale = len ? strtod(token, &end) : 0.0;
    if (!len || *end || !isfinite(scale) || scale == 0.0)
        return rt_fail(err, RT_ERR_PARSE, "%s: PFM header: expected the scale (a non-zero number) at byte %zu", path,
                       scale_at);
    if (at >= n || !is_space(p[at]))
        return rt_fail(err, RT_ERR_PARSE, "%s: PFM header: expected one white-space byte after the scale at byte %zu",
                       path, at);
    h->big_endian = scale > 0.0;
    h->data_at = at + 1;
    return RT_OK;
}

rt_result rt_pfm_read(const char *path, rt_framebuffer *fb, rt_error *err)
{
    fb->width = fb->height = 0;
    fb->rgb = NULL;
    FILE *f = fopen(path, "rb");
    if (!f)
        return rt_fail(err, RT_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode)) {
        bool dir = fstat(fileno(f), &st) == 0 && S_ISDIR(st.st_mode);
        fclose(f);
        return rt_fail(err, RT_ERR_IO, "%s: %s", path, dir ? "is a directory" : "not a regular file");
    }
    unsigned char head[PFM_HEADER_BYTES];
    size_t got = fread(head, 1, sizeof head, f);
    pfm_header h;
    rt_result r = parse_header(head, got, path, &h, err);
    if (r != RT_OK) {
        fclose(f);
        return r;
    }
    const uint64_t row_bytes = (uint64_t)h.width * (uint64_t)h.channels * 4u;
    const uint64_t need = row_bytes * (uint64_t)h.height, have = (uint64_t)st.st_size - h.data_at;
    if ((uint64_t)st.st_size < h.data_at || have < need) {
        fclose(f);
        return rt_fail(err, RT_ERR_PARSE,
                       "%s: PFM data ends at byte %llu, but its %dx%d header needs %llu bytes of pixels from byte %zu "
                       "(to byte %llu)",
                       path, (unsigned long long)st.st_size, h.width, h.height, (unsigned long long)need, h.data_at,
                       (unsigned long long)(h.data_at + need));
    }
    if ((r = rt_framebuffer_init(fb, h.width, h.height, err)) != RT_OK) {
        fclose(f);
        return r; /* out of memory: the message says for what size */
    }
    unsigned char *row = malloc((size_t)row_bytes);
    if (!row || fseek(f, (long)h.data_at, SEEK_SET) != 0) {
        free(row);
        fclose(f);
        rt_framebuffer_free(fb);
        return rt_fail(err, row ? RT_ERR_IO : RT_ERR_NOMEM, "%s: cannot read the PFM pixels", path);
    }
    for (int y = h.height - 1; y >= 0; y--) { /* bottom row first */
        if (fread(row, 1, (size_t)row_bytes, f) != (size_t)row_bytes) {
            long at = ftell(f);
            free(row);
            fclose(f);
            rt_framebuffer_free(fb);
            return rt_fail(err, RT_ERR_IO, "%s: PFM data ends early at byte %ld (the file shrank while read?)", path,
                           at);
        }
        float *dst = fb->rgb + (size_t)y * (size_t)h.width * 3;
        for (size_t x = 0; x < (size_t)h.width; x++)
            for (int c = 0; c < 3; c++) {
                const unsigned char *b = row + 4 * (x * (size_t)h.channels + (size_t)(h.channels == 3 ? c : 0));
                uint32_t u = h.big_endian
                                 ? ((uint32_t)b[0] << 24 | (uint32_t)b[1] << 16 | (uint32_t)b[2] << 8 | b[3])
                                 : ((uint32_t)b[3] << 24 | (uint32_t)b[2] << 16 | (uint32_t)b[1] << 8 | b[0]);
                memcpy(&dst[3 * x + (size_t)c], &u, 4);
            }
    }
    free(row);
    fclose(f);
    return RT_OK;
}
