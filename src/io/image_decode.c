/* image_decode.c - one decoder for every image format rt reads
 * (rt/io/image_decode.h), chosen by the first bytes: OpenEXR (exr.c),
 * WebP (webp.c), then stb_image (PNG, JPEG, Radiance HDR, BMP, TGA, ...)
 * behind size checks made on the header before any pixel allocation
 * (stbi_info, and PNG's IHDR read directly) and, for Radiance HDR, a walk
 * over its scanlines (radiance.c) that stb's reader would otherwise trust;
 * binary PNM must hold the pixels its header declares.
 *
 * Sources: the PNG specification (ISO/IEC 15948, sections 5, 7 and 8:
 * chunks, scanline filter bytes, Adam7 interlacing) for the declared size
 * of the pixel data; RFC 1951 (deflate) for the largest ratio a deflate
 * stream can reach, 258 bytes from 2 bits.
 */
#include "rt/io/image_decode.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb/stb_image.h>

#include "rt/io/exr.h"
#include "rt/io/radiance.h"
#include "rt/io/webp.h"

/* PNG pixel data is a zlib stream whose decoded length the header fixes
 * exactly (PNG spec, sections 7 and 8: one filter byte per scanline, per
 * Adam7 pass when interlaced). stb_image grows its output buffer without
 * bound while inflating, so a small file whose stream never ends (or runs
 * on past the pixels) could take gigabytes. Before handing a PNG to stb we
 * therefore (1) refuse a declared size that deflate's 1032:1 maximum ratio
 * cannot produce from the bytes present, and (2) inflate the stream once
 * into a buffer of exactly the declared size, which stb's fixed-buffer
 * decoder refuses to overrun. Non-PNG data returns RT_OK untouched. */
static uint32_t be32(const unsigned char *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | (uint32_t)p[3];
}

static uint64_t png_rows_bytes(uint64_t w, uint64_t h, uint64_t bits_per_pixel)
{
    if (w == 0 || h == 0)
        return 0;
    return h * (1 + (w * bits_per_pixel + 7) / 8);
}

static rt_result png_precheck(const unsigned char *p, size_t size, const char *name, int max_side, rt_error *err)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (size < 8 || memcmp(p, sig, 8) != 0)
        return RT_OK;
    uint32_t w = 0, h = 0;
    int depth = 0, color = -1, interlace = 0;
    bool iphone = false, ihdr = false;
    size_t idat_len = 0, off = 8;
    /* pass 1: header fields and the total IDAT length */
    while (off + 12 <= size) {
        uint32_t len = be32(p + off);
        const unsigned char *type = p + off + 4;
        if (len > size - off - 12)
            break; /* truncated chunk: stb reports it */
        const unsigned char *d = p + off + 8;
        if (memcmp(type, "CgBI", 4) == 0)
            iphone = true;
        else if (memcmp(type, "IHDR", 4) == 0 && len >= 13 && !ihdr) {
            ihdr = true;
            w = be32(d);
            h = be32(d + 4);
            depth = d[8];
            color = d[9];
            interlace = d[12];
        } else if (memcmp(type, "IDAT", 4) == 0)
            idat_len += len;
        else if (memcmp(type, "IEND", 4) == 0)
            break;
        off += 12 + (size_t)len;
    }
    if (!ihdr || idat_len == 0 || w == 0 || h == 0 || w > (uint32_t)max_side || h > (uint32_t)max_side)
        return RT_OK; /* stb (or our size check) rejects these with its own reason */
    int channels = color == 0 ? 1 : color == 2 ? 3 : color == 3 ? 1 : color == 4 ? 2 : color == 6 ? 4 : 0;
    if (!channels || (depth != 1 && depth != 2 && depth != 4 && depth != 8 && depth != 16) || interlace > 1)
        return RT_OK;
    uint64_t bpp = (uint64_t)channels * (uint64_t)depth, need = 0;
    if (!interlace) {
        need = png_rows_bytes(w, h, bpp);
    } else { /* Adam7: origin and step of each pass */
        static const int x0[7] = {0, 4, 0, 2, 0, 1, 0}, y0[7] = {0, 0, 4, 0, 2, 0, 1};
        static const int dx[7] = {8, 8, 4, 4, 2, 2, 1}, dy[7] = {8, 8, 8, 4, 4, 2, 2};
        for (int k = 0; k < 7; k++) {
            uint64_t pw = w > (uint32_t)x0[k] ? (w - (uint32_t)x0[k] + (uint32_t)dx[k] - 1) / (uint32_t)dx[k] : 0;
            uint64_t ph = h > (uint32_t)y0[k] ? (h - (uint32_t)y0[k] + (uint32_t)dy[k] - 1) / (uint32_t)dy[k] : 0;
            need += png_rows_bytes(pw, ph, bpp);
        }
    }
    /* deflate emits at most 258 bytes per 2 bits (a ratio under 1032:1) */
    if (need > (uint64_t)idat_len * 1032u + 1024u)
        return rt_fail(err, RT_ERR_INVALID,
                       "%s: PNG declares %ux%u pixels but holds only %zu bytes of compressed data, too few for them",
                       name, w, h, idat_len);
    if (need > (uint64_t)INT32_MAX || idat_len > (size_t)INT32_MAX)
        return rt_fail(err, RT_ERR_LIMIT, "%s: PNG pixel data is over 2 GiB", name);
    /* pass 2: the stream in one piece, inflated into a buffer of its exact size */
    unsigned char *z = malloc(idat_len);
    unsigned char *out = malloc((size_t)need);
    if (!z || !out) {
        free(z);
        free(out);
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory checking the PNG data (%zu bytes)", name, (size_t)need);
    }
    size_t zn = 0;
    for (off = 8; off + 12 <= size;) {
        uint32_t len = be32(p + off);
        if (len > size - off - 12)
            break;
        if (memcmp(p + off + 4, "IDAT", 4) == 0) {
            memcpy(z + zn, p + off + 8, len);
            zn += len;
        } else if (memcmp(p + off + 4, "IEND", 4) == 0)
            break;
        off += 12 + (size_t)len;
    }
    int got = iphone ? stbi_zlib_decode_noheader_buffer((char *)out, (int)need, (const char *)z, (int)zn)
                     : stbi_zlib_decode_buffer((char *)out, (int)need, (const char *)z, (int)zn);
    free(z);
    free(out);
    if (got < 0 || (uint64_t)got != need)
        return rt_fail(err, RT_ERR_INVALID,
                       "%s: PNG pixel data does not inflate to the %llu bytes its %ux%u header declares", name,
                       (unsigned long long)need, w, h);
    return RT_OK;
}

/* Binary PNM (P5 grey, P6 RGB): stb_image 2.27 reads the pixels without
 * checking they are there (stbi__pnm_load ignores stbi__getn's result), so
 * a 12-byte file declaring 664x55372 became 147 MB of uninitialised
 * pixels, seconds of work for a fuzzer. The header is read as stb reads
 * it (white space and # comments between the width, the height and the
 * largest value, then one byte) to find where the pixels start, and the
 * bytes they need (two a sample past a largest value of 255) must be
 * there. */
static int pnm_next(const unsigned char *p, size_t size, size_t *at)
{
    return *at < size ? p[(*at)++] : 0; /* stb's get8: 0 at the end, which stays there */
}

static bool pnm_space(int c) { return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r'; }

static rt_result pnm_precheck(const unsigned char *p, size_t size, const char *name, rt_error *err)
{
    if (size < 2 || p[0] != 'P' || (p[1] != '5' && p[1] != '6'))
        return RT_OK;
    size_t at = 2;
    int c = pnm_next(p, size, &at);
    uint64_t v[3] = {0, 0, 0}; /* width, height, largest value */
    for (int k = 0; k < 3; k++) {
        for (;;) {
            while (at < size && pnm_space(c))
                c = pnm_next(p, size, &at);
            if (at >= size || c != '#') /* as stb: the end stops it, a '#' there too */
                break;
            while (at < size && c != '\n' && c != '\r')
                c = pnm_next(p, size, &at);
        }
        while (c >= '0' && c <= '9') {
            if (v[k] < ((uint64_t)1 << 32))
                v[k] = v[k] * 10 + (uint64_t)(c - '0');
            c = pnm_next(p, size, &at);
        }
    }
    const uint64_t need = v[0] * v[1] * (p[1] == '6' ? 3u : 1u) * (v[2] > 255 ? 2u : 1u);
    if ((uint64_t)(size - at) < need)
        return rt_fail(err, RT_ERR_INVALID,
                       "%s: PNM data ends at byte %zu, but its %llux%llu header needs %llu bytes of pixels from byte "
                       "%zu",
                       name, size, (unsigned long long)v[0], (unsigned long long)v[1], (unsigned long long)need, at);
    return RT_OK;
}

/* The most pixels a byte of any format stb_image decodes can hold: a 1-bit
 * PNG at deflate's 1032:1 (8 x 1032 = 8256). The others hold fewer: JPEG
 * at least a bit per 8x8 block and component (512 for grey), GIF's 12-bit
 * LZW codes at most 4096 pixels each (about 2730), TGA and PSD run lengths
 * 128 pixels per 2 bytes (64), PNM, BMP and uncompressed TGA 1 or less. */
#define PIXELS_PER_BYTE_MAX 8256u

/* stb reports a failed allocation as "outofmem": that is RT_ERR_NOMEM (the
 * driver then names the memory budget), anything else is a bad image. */
static rt_result decode_failed(const char *name, rt_error *err)
{
    const char *why = stbi_failure_reason();
    if (why && strcmp(why, "outofmem") == 0)
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory decoding the image", name);
    return rt_fail(err, RT_ERR_INVALID, "%s: cannot decode image (%s)", name, why ? why : "unknown reason");
}

bool rt_image_is_readable(const void *data, size_t size)
{
    int w = 0, h = 0, comp = 0;
    return size > 0 && size <= (size_t)INT32_MAX &&
           (rt_exr_is(data, size) || rt_webp_is(data, size) || stbi_info_from_memory(data, (int)size, &w, &h, &comp));
}

rt_result rt_image_decode(const void *data, size_t size, const char *name, const rt_image_limits *lim, rt_image *img,
                          rt_error *err)
{
    memset(img, 0, sizeof *img);
    if (size == 0 || size > (size_t)INT32_MAX)
        return rt_fail(err, RT_ERR_INVALID, "%s: image data is %s", name, size ? "over 2 GiB" : "empty");
    const stbi_uc *bytes = data;
    /* stb refuses PNGs over 2^30 bytes of pixels as "unknown image type":
     * read the size from the IHDR chunk ourselves to say what is wrong */
    static const unsigned char png_sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (size >= 24 && memcmp(bytes, png_sig, 8) == 0 && memcmp(bytes + 12, "IHDR", 4) == 0) {
        uint32_t pw = be32(bytes + 16), ph = be32(bytes + 20);
        if (pw > (uint32_t)lim->max_side || ph > (uint32_t)lim->max_side || (uint64_t)pw * ph > lim->max_pixels)
            return rt_fail(err, RT_ERR_LIMIT, "%s: image is %ux%u, over the limit of %dx%d and %llu pixels", name, pw,
                           ph, lim->max_side, lim->max_side, (unsigned long long)lim->max_pixels);
    }
    if (rt_exr_is(bytes, size)) /* linear float, like HDR: 16 bytes a texel */
        return rt_exr_decode(bytes, size, name, lim->max_side, lim->max_float_pixels, &img->rgbaf, &img->width,
                             &img->height, err);
    if (rt_webp_is(bytes, size)) /* 8-bit RGBA like PNG */
        return rt_webp_decode(bytes, size, name, lim->max_side, lim->max_pixels, &img->rgba8, &img->width,
                              &img->height, err);
    int w = 0, h = 0, comp = 0;
    if (!stbi_info_from_memory(bytes, (int)size, &w, &h, &comp))
        return rt_fail(err, RT_ERR_INVALID, "%s: not a readable image (%s; rt reads EXR, HDR, PNG, JPEG, WebP)", name,
                       stbi_failure_reason());
    if (w <= 0 || h <= 0 || w > lim->max_side || h > lim->max_side || (uint64_t)w * (uint64_t)h > lim->max_pixels)
        return rt_fail(err, RT_ERR_LIMIT, "%s: image is %dx%d, over the limit of %dx%d and %llu pixels", name, w, h,
                       lim->max_side, lim->max_side, (unsigned long long)lim->max_pixels);
    bool hdr = stbi_is_hdr_from_memory(bytes, (int)size);
    if (hdr && (uint64_t)w * (uint64_t)h > lim->max_float_pixels)
        return rt_fail(err, RT_ERR_LIMIT, "%s: HDR image is %dx%d, over the limit of %llu pixels for float images",
                       name, w, h, (unsigned long long)lim->max_float_pixels);
    /* stb's HDR reader loops for ever on a run of 0 (a cut file reads as one) */
    if (hdr && rt_radiance_check(bytes, size, name, err) != RT_OK)
        return RT_ERR_INVALID;
    if (pnm_precheck(bytes, size, name, err) != RT_OK)
        return RT_ERR_INVALID;
    rt_result pr = png_precheck(bytes, size, name, lim->max_side, err);
    if (pr != RT_OK)
        return pr;
    /* No format stb reads packs more than PIXELS_PER_BYTE_MAX pixels into a
     * byte (see its definition); stb fills what a header declares past the
     * data with zeros or leftovers, so a 38-byte run-length TGA declaring
     * 8224x8224 took 8 s and 1 GB to read. (After the PNG check, whose
     * message is more precise.) */
    if ((uint64_t)w * (uint64_t)h > PIXELS_PER_BYTE_MAX * (uint64_t)size + 65536u)
        return rt_fail(err, RT_ERR_INVALID,
                       "%s: image declares %dx%d pixels but is only %zu bytes long, too few for any format rt reads",
                       name, w, h, size);
    int lw = 0, lh = 0, lc = 0;
    if (hdr) {
        img->rgbaf = stbi_loadf_from_memory(bytes, (int)size, &lw, &lh, &lc, 4);
        if (!img->rgbaf)
            return decode_failed(name, err);
    } else {
        img->rgba8 = stbi_load_from_memory(bytes, (int)size, &lw, &lh, &lc, 4);
        if (!img->rgba8)
            return decode_failed(name, err);
    }
    if (lw != w || lh != h) {
        free(img->rgba8);
        free(img->rgbaf);
        memset(img, 0, sizeof *img);
        return rt_fail(err, RT_ERR_INVALID, "%s: image size changed while decoding", name);
    }
    img->width = w;
    img->height = h;
    return RT_OK;
}
