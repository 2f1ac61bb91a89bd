/* framebuffer.c - framebuffer output: PNG (stb_image_write, 8-bit sRGB with
 * exposure), PFM (little-endian float RGB, bottom scanline first, as the
 * format defines) and Radiance HDR (stb_image_write), all written to a
 * temporary file beside the target and renamed into place. */
#include "rt/io/framebuffer.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include <stb/stb_image_write.h>

#include "rt/base/alloc.h"
#include "rt/scene/texture.h"

rt_result rt_framebuffer_init(rt_framebuffer *fb, int width, int height, rt_error *err)
{
    fb->width = fb->height = 0;
    fb->rgb = NULL;
    if (width <= 0 || height <= 0 || width > 65536 || height > 65536)
        return rt_fail(err, RT_ERR_LIMIT, "image size %dx%d is out of range (1..65536 a side)", width, height);
    fb->rgb = rt_alloc((size_t)width * (size_t)height, 3 * sizeof(float));
    if (!fb->rgb)
        return rt_fail(err, RT_ERR_NOMEM, "out of memory for a %dx%d image", width, height);
    fb->width = width;
    fb->height = height;
    return RT_OK;
}

void rt_framebuffer_free(rt_framebuffer *fb)
{
    free(fb->rgb);
    fb->rgb = NULL;
    fb->width = fb->height = 0;
}

rt_result rt_output_format(const char *path, rt_image_format *format, rt_error *err)
{
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    if (dot && (!slash || dot > slash)) {
        if (strcasecmp(dot, ".png") == 0) { *format = RT_FORMAT_PNG; return RT_OK; }
        if (strcasecmp(dot, ".pfm") == 0) { *format = RT_FORMAT_PFM; return RT_OK; }
        if (strcasecmp(dot, ".hdr") == 0) { *format = RT_FORMAT_HDR; return RT_OK; }
    }
    return rt_fail(err, RT_ERR_INVALID, "%s: unknown output format (use .png, .pfm or .hdr)", path);
}

/* Opens a fresh temporary file in the directory of `path`. With `temp`,
 * its name is published before mkstemp creates the file. */
static FILE *open_temp_beside(const char *path, char *tmp, size_t tmp_size, rt_write_temp *temp)
{
    const char *slash = strrchr(path, '/');
    int n;
    if (slash)
        n = snprintf(tmp, tmp_size, "%.*s/.rt-tmp-XXXXXX", (int)(slash - path), path);
    else
        n = snprintf(tmp, tmp_size, ".rt-tmp-XXXXXX");
    if (n < 0 || (size_t)n >= tmp_size) {
        errno = ENAMETOOLONG;
        return NULL;
    }
    if (temp)
        temp->active = 1;
    int fd = mkstemp(tmp);
    if (fd < 0)
        return NULL;
    FILE *f = fdopen(fd, "wb");
    if (!f) {
        close(fd);
        unlink(tmp);
    }
    return f;
}

rt_result rt_output_check(const char *path, rt_error *err)
{
    rt_image_format fmt;
    rt_result r = rt_output_format(path, &fmt, err);
    if (r != RT_OK)
        return r;
    char tmp[4200];
    FILE *f = open_temp_beside(path, tmp, sizeof tmp, NULL);
    if (!f)
        return rt_fail(err, RT_ERR_IO, "%s: cannot write there: %s", path, strerror(errno));
    fclose(f);
    unlink(tmp);
    return RT_OK;
}

/* stb_image_write builds a PNG in memory with int sizes: the filtered rows
 * ((3w + 1) h bytes) and their zlib stream must stay well below 2 GiB. */
#define MAX_PNG_RAW_BYTES ((uint64_t)1 << 30)

rt_result rt_output_check_size(const char *path, int width, int height, rt_error *err)
{
    rt_image_format fmt;
    rt_result r = rt_output_format(path, &fmt, err);
    if (r != RT_OK)
        return r;
    if (fmt == RT_FORMAT_PNG && ((uint64_t)width * 3 + 1) * (uint64_t)(height > 0 ? height : 0) > MAX_PNG_RAW_BYTES)
        return rt_fail(err, RT_ERR_LIMIT,
                       "%s: a %dx%d PNG is over the PNG writer's limit of 1 GiB of pixel data; write .pfm or .hdr", path,
                       width, height);
    return RT_OK;
}

static void write_to_file(void *context, void *data, int size)
{
    FILE *f = context;
    if (size > 0)
        fwrite(data, 1, (size_t)size, f);
}

static int write_pfm(FILE *f, const rt_framebuffer *fb)
{
    fprintf(f, "PF\n%d %d\n-1.0\n", fb->width, fb->height);
    float *row = malloc((size_t)fb->width * 3 * sizeof(float));
    if (!row)
        return 0;
    for (int y = fb->height - 1; y >= 0; y--) {
        const float *src = fb->rgb + (size_t)y * (size_t)fb->width * 3;
        for (size_t i = 0; i < (size_t)fb->width * 3; i++) {
            /* little-endian float32 on any host */
            union { float f; uint32_t u; } v = {src[i]};
            unsigned char b[4] = {(unsigned char)v.u, (unsigned char)(v.u >> 8), (unsigned char)(v.u >> 16),
                                  (unsigned char)(v.u >> 24)};
            memcpy(&row[i], b, 4);
        }
        fwrite(row, sizeof(float), (size_t)fb->width * 3, f);
    }
    free(row);
    return 1;
}

static int write_png(FILE *f, const rt_framebuffer *fb, float exposure)
{
    size_t n = (size_t)fb->width * (size_t)fb->height * 3;
    unsigned char *px = malloc(n);
    if (!px)
        return 0;
    for (size_t i = 0; i < n; i++) {
        float v = rt_linear_to_srgb(fb->rgb[i] * exposure);
        px[i] = (unsigned char)(v * 255.0f + 0.5f);
    }
    int ok = stbi_write_png_to_func(write_to_file, f, fb->width, fb->height, 3, px, fb->width * 3);
    free(px);
    return ok;
}

rt_result rt_framebuffer_write(const rt_framebuffer *fb, const char *path, float exposure, rt_error *err)
{
    return rt_framebuffer_write_tracked(fb, path, exposure, NULL, err);
}

static rt_result write_tracked(const rt_framebuffer *fb, const char *path, float exposure, rt_write_temp *temp,
                               rt_error *err);

rt_result rt_framebuffer_write_tracked(const rt_framebuffer *fb, const char *path, float exposure, rt_write_temp *temp,
                                       rt_error *err)
{
    rt_result r = write_tracked(fb, path, exposure, temp, err);
    if (temp)
        temp->active = 0; /* renamed into place or removed */
    return r;
}

static rt_result write_tracked(const rt_framebuffer *fb, const char *path, float exposure, rt_write_temp *temp,
                               rt_error *err)
{
    rt_image_format fmt;
    rt_result r = rt_output_format(path, &fmt, err);
    if (r != RT_OK)
        return r;
    if ((r = rt_output_check_size(path, fb->width, fb->height, err)) != RT_OK)
        return r;
    char local[4200];
    char *tmp = temp ? temp->path : local;
    FILE *f = open_temp_beside(path, tmp, temp ? sizeof temp->path : sizeof local, temp);
    if (!f)
        return rt_fail(err, RT_ERR_IO, "%s: cannot create a file there: %s", path, strerror(errno));
    int ok;
    switch (fmt) {
    case RT_FORMAT_PFM: ok = write_pfm(f, fb); break;
    case RT_FORMAT_HDR: ok = stbi_write_hdr_to_func(write_to_file, f, fb->width, fb->height, 3, fb->rgb); break;
    case RT_FORMAT_PNG:
    default: ok = write_png(f, fb, exposure > 0.0f && isfinite(exposure) ? exposure : 1.0f); break;
    }
    if (fflush(f) != 0 || ferror(f))
        ok = 0;
    int saved = errno;
    if (fclose(f) != 0)
        ok = 0;
    if (!ok) {
        unlink(tmp);
        return rt_fail(err, RT_ERR_IO, "%s: write failed: %s", path, strerror(saved ? saved : EIO));
    }
    /* mkstemp made the file 0600: give it the mode a plain fopen would
     * (0666 less the umask), or keep the mode of the image it replaces */
    struct stat st;
    mode_t mode;
    if (stat(path, &st) == 0) {
        mode = st.st_mode & 07777;
    } else {
        mode_t mask = umask(0);
        umask(mask);
        mode = 0666 & ~mask;
    }
    chmod(tmp, mode);
    if (rename(tmp, path) != 0) {
        saved = errno;
        unlink(tmp);
        return rt_fail(err, RT_ERR_IO, "%s: cannot rename the finished image into place: %s", path, strerror(saved));
    }
    return RT_OK;
}

rt_result rt_pfm_read(const char *path, rt_framebuffer *fb, rt_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return rt_fail(err, RT_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    char magic[3] = {0};
    int w = 0, h = 0;
    float scale = 0;
    if (fscanf(f, "%2s %d %d %f", magic, &w, &h, &scale) != 4 || strcmp(magic, "PF") != 0 || fgetc(f) == EOF) {
        fclose(f);
        return rt_fail(err, RT_ERR_PARSE, "%s: not a colour PFM file", path);
    }
    rt_result r = rt_framebuffer_init(fb, w, h, err);
    if (r != RT_OK) {
        fclose(f);
        return r;
    }
    bool big_endian = scale > 0;
    for (int y = h - 1; y >= 0; y--) {
        float *row = fb->rgb + (size_t)y * (size_t)w * 3;
        if (fread(row, sizeof(float), (size_t)w * 3, f) != (size_t)w * 3) {
            fclose(f);
            rt_framebuffer_free(fb);
            return rt_fail(err, RT_ERR_PARSE, "%s: truncated PFM data", path);
        }
        for (size_t i = 0; i < (size_t)w * 3; i++) {
            unsigned char b[4];
            memcpy(b, &row[i], 4);
            uint32_t u = big_endian ? ((uint32_t)b[0] << 24 | (uint32_t)b[1] << 16 | (uint32_t)b[2] << 8 | b[3])
                                    : ((uint32_t)b[3] << 24 | (uint32_t)b[2] << 16 | (uint32_t)b[1] << 8 | b[0]);
            memcpy(&row[i], &u, 4);
        }
    }
    fclose(f);
    return RT_OK;
}
