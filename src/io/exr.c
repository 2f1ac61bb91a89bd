/* exr.c - OpenEXR in and out through the OpenEXR Core C API (openexr.h,
 * OpenEXR 3.1: exr_start_write / exr_add_part /
 * exr_initialize_required_attr_simple / exr_add_channel / exr_write_header,
 * then per chunk exr_write_scanline_chunk_info and the encode pipeline
 * exr_encoding_initialize / _choose_default_routines / _run; reading mirrors
 * it with exr_start_read and the decode pipeline). The file layout and the
 * channel naming (LAYER.R, LAYER.G, LAYER.B; a bare R, G, B for the default
 * layer) follow the OpenEXR documentation, "Technical Introduction" and
 * "Interpreting OpenEXR Deep Pixels"/"Multi-View" naming conventions.
 *
 * The library does the byte work (XDR order, half conversion, ZIP); this file
 * describes the image, points the pipelines at rt's interleaved float pixels
 * and turns the library's error callback into one rt_error message. Reads
 * come from memory through a custom read function, so the same code serves
 * files, textures inside models and the fuzzer. Before the pixels are
 * allocated, the header's chunk table is checked against the bytes present
 * (check_chunks).
 */
#include "rt/io/exr.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <OpenEXR/openexr.h>

#include "rt/base/alloc.h"

/* What the library's callbacks reach through user_data. */
typedef struct exr_stream {
    const unsigned char *data; /* reading */
    size_t size;
    FILE *file;                /* writing */
    char message[200];         /* the library's first error message */
} exr_stream;

static void on_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    void *ud = NULL;
    if (exr_get_user_data(ctxt, &ud) != EXR_ERR_SUCCESS || !ud)
        return;
    exr_stream *s = ud;
    if (!s->message[0])
        snprintf(s->message, sizeof s->message, "%s", msg ? msg : exr_get_default_error_message(code));
}

/* Writing: the library holds the write context's lock while it reports an
 * error, and exr_get_user_data takes that lock again (a non-recursive
 * mutex), so on_error would hang the writer; errors are read from the
 * returned code instead. */
static void on_write_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;
    (void)code;
    (void)msg;
}

static int64_t read_memory(exr_const_context_t ctxt, void *ud, void *buffer, uint64_t sz, uint64_t offset,
                           exr_stream_error_func_ptr_t error_cb)
{
    (void)ctxt;
    (void)error_cb;
    const exr_stream *s = ud;
    if (offset >= s->size)
        return 0;
    uint64_t n = s->size - offset < sz ? s->size - offset : sz;
    memcpy(buffer, s->data + offset, (size_t)n);
    return (int64_t)n;
}

static int64_t size_memory(exr_const_context_t ctxt, void *ud)
{
    (void)ctxt;
    return (int64_t)((const exr_stream *)ud)->size;
}

static int64_t write_file(exr_const_context_t ctxt, void *ud, const void *buffer, uint64_t sz, uint64_t offset,
                          exr_stream_error_func_ptr_t error_cb)
{
    (void)ctxt;
    (void)error_cb;
    const exr_stream *s = ud;
    const unsigned char *p = buffer;
    uint64_t done = 0;
    while (done < sz) {
        ssize_t n = pwrite(fileno(s->file), p + done, (size_t)(sz - done), (off_t)(offset + done));
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return -1;
        done += (uint64_t)n;
    }
    return (int64_t)done;
}

bool rt_exr_is(const void *data, size_t size)
{
    static const unsigned char magic[4] = {0x76, 0x2f, 0x31, 0x01};
    return size >= 4 && memcmp(data, magic, 4) == 0;
}

/* The library's message if it gave one, else its text for the code. */
static rt_result exr_failed(rt_error *err, rt_result kind, const char *name, const char *doing, const exr_stream *s,
                            exr_result_t rv)
{
    if (rv == EXR_ERR_OUT_OF_MEMORY)
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory %s", name, doing);
    return rt_fail(err, kind, "%s: %s: %s", name, doing, s->message[0] ? s->message : exr_get_default_error_message(rv));
}

/* ------------------------------------------------------------ writing */

#define MAX_CHANNELS 256

typedef struct out_channel {
    char name[64];
    const float *data; /* first component of this channel at pixel (0, 0) */
    int stride;        /* floats from one pixel to the next */
} out_channel;

rt_result rt_exr_write(FILE *f, const char *path, int width, int height, const rt_exr_layer *layers, int layer_count,
                       bool half, rt_error *err)
{
    static const char *rgb[3] = {"R", "G", "B"};
    out_channel ch[MAX_CHANNELS];
    int nch = 0;
    for (int l = 0; l < layer_count; l++) {
        const rt_exr_layer *L = &layers[l];
        if ((L->channels != 1 && L->channels != 3) || !L->data || nch + L->channels > MAX_CHANNELS)
            return rt_fail(err, RT_ERR_INVALID, "%s: bad EXR layer %d", path, l);
        for (int c = 0; c < L->channels; c++, nch++) {
            const char *suffix = L->channels == 1 ? "Y" : rgb[c];
            if (L->name && L->name[0])
                snprintf(ch[nch].name, sizeof ch[nch].name, "%s.%s", L->name, suffix);
            else
                snprintf(ch[nch].name, sizeof ch[nch].name, "%s", suffix);
            ch[nch].data = L->data + c;
            ch[nch].stride = L->channels;
        }
    }

    for (int a = 0; a < nch; a++) /* the library refuses a channel twice (LAYER named twice) */
        for (int b = 0; b < a; b++)
            if (strcmp(ch[a].name, ch[b].name) == 0)
                return rt_fail(err, RT_ERR_INVALID, "%s: EXR channel %s given twice", path, ch[a].name);
    exr_stream s;
    memset(&s, 0, sizeof s);
    s.file = f;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = on_write_error;
    init.user_data = &s;
    init.write_fn = write_file;
    exr_context_t ctx = NULL;
    exr_result_t rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv != EXR_ERR_SUCCESS)
        return exr_failed(err, RT_ERR_IO, path, "cannot start the EXR file", &s, rv);
    int part = 0;
    rv = exr_add_part(ctx, "beauty", EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(ctx, part, width, height, EXR_COMPRESSION_ZIP);
    for (int c = 0; c < nch && rv == EXR_ERR_SUCCESS; c++)
        rv = exr_add_channel(ctx, part, ch[c].name, half ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT,
                             EXR_PERCEPTUALLY_LINEAR, 1, 1);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_write_header(ctx);
    if (rv != EXR_ERR_SUCCESS) {
        exr_finish(&ctx);
        return exr_failed(err, RT_ERR_IO, path, "cannot write the EXR header", &s, rv);
    }

    int32_t lines = 1;
    exr_get_scanlines_per_chunk(ctx, part, &lines);
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    bool started = false;
    for (int y = 0; y < height && rv == EXR_ERR_SUCCESS; y += lines) {
        exr_chunk_info_t cinfo;
        rv = exr_write_scanline_chunk_info(ctx, part, y, &cinfo);
        if (rv != EXR_ERR_SUCCESS)
            break;
        rv = started ? exr_encoding_update(ctx, part, &cinfo, &enc) : exr_encoding_initialize(ctx, part, &cinfo, &enc);
        if (rv != EXR_ERR_SUCCESS)
            break;
        for (int c = 0; c < enc.channel_count; c++) {
            exr_coding_channel_info_t *oc = &enc.channels[c];
            const out_channel *src = NULL;
            for (int k = 0; k < nch && !src; k++)
                if (strcmp(ch[k].name, oc->channel_name) == 0)
                    src = &ch[k];
            if (!src) { /* cannot happen: the library lists the channels we added */
                rv = EXR_ERR_INVALID_ARGUMENT;
                break;
            }
            oc->user_bytes_per_element = 4;
            oc->user_data_type = EXR_PIXEL_FLOAT;
            oc->user_pixel_stride = src->stride * (int32_t)sizeof(float);
            oc->user_line_stride = width * src->stride * (int32_t)sizeof(float);
            oc->encode_from_ptr = (const uint8_t *)(src->data + (size_t)y * (size_t)width * (size_t)src->stride);
        }
        if (rv != EXR_ERR_SUCCESS)
            break;
        if (!started) {
            rv = exr_encoding_choose_default_routines(ctx, part, &enc);
            started = true;
            if (rv != EXR_ERR_SUCCESS)
                break;
        }
        rv = exr_encoding_run(ctx, part, &enc);
    }
    if (started)
        exr_encoding_destroy(ctx, &enc);
    exr_result_t fin = exr_finish(&ctx);
    if (rv == EXR_ERR_SUCCESS)
        rv = fin;
    if (rv != EXR_ERR_SUCCESS)
        return exr_failed(err, RT_ERR_IO, path, "cannot write the EXR pixels", &s, rv);
    return RT_OK;
}

/* ------------------------------------------------------------ reading */

/* The channels a decode fills: want[k] goes to component k of n a pixel. */
typedef struct want_channels {
    const char *const *want;
    int n;
} want_channels;

static int wanted_index(const want_channels *wc, const char *name)
{
    for (int k = 0; k < wc->n; k++)
        if (strcmp(wc->want[k], name) == 0)
            return k;
    return -1;
}

/* Decodes one chunk (a band of scanlines or a tile) at pixel (x0, y0) of the
 * data window into the buffer of wc->n floats a pixel; channels not wanted
 * are skipped. */
static exr_result_t decode_chunk(exr_context_t ctx, const exr_chunk_info_t *cinfo, exr_decode_pipeline_t *dec,
                                 bool *started, float *buf, int w, int x0, int y0, const want_channels *wc)
{
    exr_result_t rv = *started ? exr_decoding_update(ctx, 0, cinfo, dec) : exr_decoding_initialize(ctx, 0, cinfo, dec);
    if (rv != EXR_ERR_SUCCESS)
        return rv;
    int n = wc->n;
    float *at = buf + ((size_t)y0 * (size_t)w + (size_t)x0) * (size_t)n;
    for (int c = 0; c < dec->channel_count; c++) {
        exr_coding_channel_info_t *oc = &dec->channels[c];
        int k = wanted_index(wc, oc->channel_name);
        oc->decode_to_ptr = NULL;
        if (k < 0)
            continue;
        oc->user_bytes_per_element = 4;
        oc->user_data_type = EXR_PIXEL_FLOAT;
        oc->user_pixel_stride = n * (int32_t)sizeof(float);
        oc->user_line_stride = w * n * (int32_t)sizeof(float);
        oc->decode_to_ptr = (uint8_t *)(at + k);
    }
    if (!*started) {
        rv = exr_decoding_choose_default_routines(ctx, 0, dec);
        *started = true;
        if (rv != EXR_ERR_SUCCESS)
            return rv;
    }
    return exr_decoding_run(ctx, 0, dec);
}

/* The decoder both entry points share: channels `channels` (all required
 * when `required`, else the RGBA/Y rules of rt_exr_decode) into
 * n floats a pixel. */
/* The channel list against what the caller asked for: the required
 * channels all present, or (not required) some of R, G, B or Y; no channel
 * read is subsampled. *has_rgb, *has_y: which colour channels there are. */
static rt_result check_channels(const exr_attr_chlist_t *chl, const char *name, const char *const *channels,
                                int nchan, bool required, bool *has_rgb, bool *has_y, rt_error *err)
{
    *has_rgb = *has_y = false;
    int found = 0;
    for (int c = 0; c < chl->num_channels; c++) {
        const exr_attr_chlist_entry_t *e = &chl->entries[c];
        const char *n = e->name.str;
        bool used = required ? false
                             : strcmp(n, "R") == 0 || strcmp(n, "G") == 0 || strcmp(n, "B") == 0 ||
                                   strcmp(n, "A") == 0 || strcmp(n, "Y") == 0;
        for (int k = 0; k < nchan && required; k++)
            if (strcmp(n, channels[k]) == 0) {
                used = true;
                found++;
            }
        if (used && (e->x_sampling != 1 || e->y_sampling != 1))
            return rt_fail(err, RT_ERR_INVALID, "%s: EXR channel %s is subsampled (%dx%d), which rt does not read",
                           name, n, e->x_sampling, e->y_sampling);
        *has_rgb |= strcmp(n, "R") == 0 || strcmp(n, "G") == 0 || strcmp(n, "B") == 0;
        *has_y |= strcmp(n, "Y") == 0;
    }
    if (required && found < nchan) {
        char list[256] = "";
        for (int k = 0; k < nchan; k++) {
            strncat(list, k ? ", " : "", sizeof list - strlen(list) - 1);
            strncat(list, channels[k], sizeof list - strlen(list) - 1);
        }
        return rt_fail(err, RT_ERR_INVALID, "%s: EXR part 0 lacks some of the channels %s", name, list);
    }
    if (!required && !*has_rgb && !*has_y)
        return rt_fail(err, RT_ERR_INVALID, "%s: EXR part 0 has no R, G, B or Y channel", name);
    return RT_OK;
}

/* Every chunk of part 0, scanline or tiled, decoded into rgba (w x h,
 * wc->count floats a pixel); a chunk outside the data window fails. */
static exr_result_t decode_pixels(exr_context_t ctx, exr_storage_t storage, const exr_attr_box2i_t *dw, int w, int h,
                                  float *rgba, const want_channels *wc)
{
    exr_result_t rv = EXR_ERR_SUCCESS;
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    bool started = false;
    if (storage == EXR_STORAGE_SCANLINE) {
        int32_t lines = 1;
        exr_get_scanlines_per_chunk(ctx, 0, &lines);
        for (int64_t y = dw->min.y; y <= dw->max.y && rv == EXR_ERR_SUCCESS; y += lines) {
            exr_chunk_info_t cinfo;
            rv = exr_read_scanline_chunk_info(ctx, 0, (int)y, &cinfo);
            if (rv != EXR_ERR_SUCCESS)
                break;
            int64_t y0 = (int64_t)cinfo.start_y - dw->min.y;
            if (y0 < 0 || y0 + cinfo.height > h || cinfo.width != w) {
                rv = EXR_ERR_BAD_CHUNK_LEADER;
                break;
            }
            rv = decode_chunk(ctx, &cinfo, &dec, &started, rgba, w, 0, (int)y0, wc);
        }
    } else {
        int32_t tw = 0, th = 0;
        rv = exr_get_tile_sizes(ctx, 0, 0, 0, &tw, &th);
        if (rv == EXR_ERR_SUCCESS && (tw <= 0 || th <= 0))
            rv = EXR_ERR_INVALID_ATTR;
        for (int ty = 0; rv == EXR_ERR_SUCCESS && (int64_t)ty * th < h; ty++) {
            for (int tx = 0; rv == EXR_ERR_SUCCESS && (int64_t)tx * tw < w; tx++) {
                exr_chunk_info_t cinfo;
                rv = exr_read_tile_chunk_info(ctx, 0, tx, ty, 0, 0, &cinfo);
                if (rv != EXR_ERR_SUCCESS)
                    break;
                int64_t x0 = (int64_t)tx * tw, y0 = (int64_t)ty * th;
                if (x0 + cinfo.width > w || y0 + cinfo.height > h) {
                    rv = EXR_ERR_BAD_CHUNK_LEADER;
                    break;
                }
                rv = decode_chunk(ctx, &cinfo, &dec, &started, rgba, w, (int)x0, (int)y0, wc);
            }
        }
    }
    if (started)
        exr_decoding_destroy(ctx, &dec);
    return rv;
}

/* The most bytes of pixels one byte of a chunk can unpack to, by
 * compression: none 1; RLE 128 bytes from a 2-byte run (64, rounded up);
 * ZIP, ZIPS and PIZ deflate's 258 bytes from 2 bits (1032) or Huffman
 * runs of at most 258 symbols from 10 bits (about 413); PXR24 deflate over
 * 24 of a float's 32 bits (1376); B44 a flat 4x4 block of halves in 3
 * bytes (11); DWAA/DWAB a DC value per 8x8 block, deflated (64 x 1032).
 * Every bound is rounded up: it only has to refuse what no encoder makes. */
static uint64_t max_unpack_ratio(exr_compression_t c)
{
    switch (c) {
    case EXR_COMPRESSION_NONE: return 1;
    case EXR_COMPRESSION_RLE: return 128;
    case EXR_COMPRESSION_ZIPS: case EXR_COMPRESSION_ZIP: case EXR_COMPRESSION_PIZ: return 1100;
    case EXR_COMPRESSION_PXR24: return 1400;
    case EXR_COMPRESSION_B44: case EXR_COMPRESSION_B44A: return 1100;
    default: return 70000; /* DWAA, DWAB */
    }
}

/* The header's claims against the bytes present, before the pixels are
 * allocated: the chunk offset table (8 bytes a chunk) must fit in the
 * file, every chunk of level 0 must have a leader the library accepts
 * (its offset and packed size inside the file), and the packed bytes must
 * be able to unpack to what the data window needs at the compression's
 * largest ratio. A few hundred bytes declaring 10^8 pixels fail here, not
 * after a gigabyte is allocated and cleared. */
static rt_result check_chunks(exr_context_t ctx, exr_storage_t storage, const exr_attr_box2i_t *dw, int w, int h,
                              size_t size, const char *name, const exr_stream *s, rt_error *err)
{
    int32_t chunks = 0;
    exr_compression_t comp = EXR_COMPRESSION_NONE;
    exr_result_t rv = exr_get_chunk_count(ctx, 0, &chunks);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_compression(ctx, 0, &comp);
    if (rv != EXR_ERR_SUCCESS || chunks <= 0)
        return exr_failed(err, RT_ERR_INVALID, name, "no EXR chunk count", s, rv ? rv : EXR_ERR_INVALID_ATTR);
    if ((uint64_t)chunks * 8u > size)
        return rt_fail(err, RT_ERR_INVALID,
                       "%s: byte %zu: EXR file ends, but its header declares %d chunks (an %llu-byte offset table)",
                       name, size, chunks, (unsigned long long)chunks * 8u);
    uint64_t packed = 0, unpacked = 0;
    if (storage == EXR_STORAGE_SCANLINE) {
        int32_t lines = 1;
        exr_get_scanlines_per_chunk(ctx, 0, &lines);
        for (int64_t y = dw->min.y; y <= dw->max.y && rv == EXR_ERR_SUCCESS; y += lines > 0 ? lines : 1) {
            exr_chunk_info_t ci;
            if ((rv = exr_read_scanline_chunk_info(ctx, 0, (int)y, &ci)) == EXR_ERR_SUCCESS) {
                packed += ci.packed_size;
                unpacked += ci.unpacked_size;
            }
        }
    } else {
        int32_t tw = 0, th = 0;
        rv = exr_get_tile_sizes(ctx, 0, 0, 0, &tw, &th);
        if (rv == EXR_ERR_SUCCESS && (tw <= 0 || th <= 0))
            rv = EXR_ERR_INVALID_ATTR;
        for (int ty = 0; rv == EXR_ERR_SUCCESS && (int64_t)ty * th < h; ty++)
            for (int tx = 0; rv == EXR_ERR_SUCCESS && (int64_t)tx * tw < w; tx++) {
                exr_chunk_info_t ci;
                if ((rv = exr_read_tile_chunk_info(ctx, 0, tx, ty, 0, 0, &ci)) == EXR_ERR_SUCCESS) {
                    packed += ci.packed_size;
                    unpacked += ci.unpacked_size;
                }
            }
    }
    if (rv != EXR_ERR_SUCCESS)
        return exr_failed(err, RT_ERR_INVALID, name, "bad EXR chunk table", s, rv);
    if (packed > size || unpacked > packed * max_unpack_ratio(comp))
        return rt_fail(err, RT_ERR_INVALID,
                       "%s: byte %zu: EXR file ends, but its %dx%d data window needs %llu bytes of pixels and its "
                       "chunks hold %llu packed bytes (compression %d unpacks at most %llu:1)",
                       name, size, w, h, (unsigned long long)unpacked, (unsigned long long)packed, (int)comp,
                       (unsigned long long)max_unpack_ratio(comp));
    return RT_OK;
}

/* want_w, want_h: the size the data window must have (0: any within the limits). */
static rt_result decode(const void *data, size_t size, const char *name, int max_dim, uint64_t max_pixels,
                        int want_w, int want_h, const char *const *channels, int nchan, bool required,
                        float **rgba_out, int *width, int *height, rt_error *err)
{
    *rgba_out = NULL;
    *width = *height = 0;
    if (!rt_exr_is(data, size))
        return rt_fail(err, RT_ERR_INVALID, "%s: not an OpenEXR file (no magic number at byte 0)", name);
    exr_stream s;
    memset(&s, 0, sizeof s);
    s.data = data;
    s.size = size;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = on_error;
    init.user_data = &s;
    init.read_fn = read_memory;
    init.size_fn = size_memory;
    /* image size: checked below with a message of ours (the library's own
     * limit would refuse it with a vaguer one); tiles: the library's check */
    init.max_tile_width = max_dim;
    init.max_tile_height = max_dim;
    exr_context_t ctx = NULL;
    exr_result_t rv = exr_start_read(&ctx, name, &init);
    if (rv != EXR_ERR_SUCCESS) {
        exr_finish(&ctx);
        return exr_failed(err, RT_ERR_INVALID, name, "not a readable EXR header", &s, rv);
    }
    rt_result result = RT_OK;
    float *rgba = NULL;
    int parts = 0;
    exr_storage_t storage = EXR_STORAGE_SCANLINE;
    exr_attr_box2i_t dw;
    const exr_attr_chlist_t *chl = NULL;
    if (exr_get_count(ctx, &parts) != EXR_ERR_SUCCESS || parts < 1 ||
        exr_get_storage(ctx, 0, &storage) != EXR_ERR_SUCCESS || exr_get_data_window(ctx, 0, &dw) != EXR_ERR_SUCCESS ||
        exr_get_channels(ctx, 0, &chl) != EXR_ERR_SUCCESS || !chl) {
        result = rt_fail(err, RT_ERR_INVALID, "%s: EXR header lacks a part, data window or channel list", name);
        goto done;
    }
    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED) {
        result = rt_fail(err, RT_ERR_INVALID, "%s: deep EXR images are not supported (only flat scanline or tiled)",
                         name);
        goto done;
    }
    int64_t w64 = (int64_t)dw.max.x - dw.min.x + 1, h64 = (int64_t)dw.max.y - dw.min.y + 1;
    if (want_w > 0 && (w64 != want_w || h64 != want_h)) {
        result = rt_fail(err, RT_ERR_INVALID, "%s: the image is %lldx%lld, not the %dx%d expected", name,
                         (long long)w64, (long long)h64, want_w, want_h);
        goto done;
    }
    if (w64 <= 0 || h64 <= 0 || w64 > max_dim || h64 > max_dim || (uint64_t)w64 * (uint64_t)h64 > max_pixels) {
        result = rt_fail(err, RT_ERR_LIMIT, "%s: EXR image is %lldx%lld, over the limit of %dx%d and %llu pixels",
                         name, (long long)w64, (long long)h64, max_dim, max_dim, (unsigned long long)max_pixels);
        goto done;
    }
    bool has_rgb, has_y;
    if ((result = check_channels(chl, name, channels, nchan, required, &has_rgb, &has_y, err)) != RT_OK)
        goto done;
    int w = (int)w64, h = (int)h64;
    if ((result = check_chunks(ctx, storage, &dw, w, h, size, name, &s, err)) != RT_OK)
        goto done;
    rgba = rt_alloc((size_t)w * (size_t)h, (size_t)nchan * sizeof(float));
    if (!rgba) {
        result = rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for a %dx%d EXR image", name, w, h);
        goto done;
    }
    for (size_t i = 0; i < (size_t)w * (size_t)h * (size_t)nchan; i++)
        rgba[i] = !required && i % 4 == 3 ? 1.0f : 0.0f;
    bool grey = !required && has_y && !has_rgb;
    static const char *const grey_names[4] = {"Y", "-", "-", "-"};
    want_channels wc = {grey ? grey_names : channels, nchan};
    rv = decode_pixels(ctx, storage, &dw, w, h, rgba, &wc);
    if (rv != EXR_ERR_SUCCESS) {
        result = exr_failed(err, RT_ERR_INVALID, name, "cannot decode the EXR pixels", &s, rv);
        goto done;
    }
    if (grey)
        for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
            rgba[4 * i + 1] = rgba[4 * i + 2] = rgba[4 * i];
    *rgba_out = rgba;
    rgba = NULL;
    *width = w;
    *height = h;
done:
    free(rgba);
    exr_finish(&ctx);
    return result;
}

rt_result rt_exr_decode(const void *data, size_t size, const char *name, int max_dim, uint64_t max_pixels,
                        float **rgba, int *width, int *height, rt_error *err)
{
    static const char *const rgba_names[4] = {"R", "G", "B", "A"};
    return decode(data, size, name, max_dim, max_pixels, 0, 0, rgba_names, 4, false, rgba, width, height, err);
}

rt_result rt_exr_decode_channels(const void *data, size_t size, const char *name, int max_dim, uint64_t max_pixels,
                                 const char *const *channels, int count, float **pixels, int *width, int *height,
                                 rt_error *err)
{
    if (count < 1 || count > MAX_CHANNELS)
        return rt_fail(err, RT_ERR_INVALID, "%s: %d EXR channels asked for", name, count);
    return decode(data, size, name, max_dim, max_pixels, 0, 0, channels, count, true, pixels, width, height, err);
}

rt_result rt_exr_decode_channels_sized(const void *data, size_t size, const char *name, int width, int height,
                                       const char *const *channels, int count, float **pixels, rt_error *err)
{
    if (count < 1 || count > MAX_CHANNELS)
        return rt_fail(err, RT_ERR_INVALID, "%s: %d EXR channels asked for", name, count);
    if (width < 1 || height < 1)
        return rt_fail(err, RT_ERR_INVALID, "%s: an EXR image of %dx%d asked for", name, width, height);
    int w, h, side = width > height ? width : height;
    return decode(data, size, name, side, (uint64_t)width * (uint64_t)height, width, height, channels, count, true,
                  pixels, &w, &h, err);
}
