/* image_write.c - framebuffer output (rt/io/image_write.h): PNG (stb_image_write, 8-bit sRGB after
 * exposure and a tone curve, rt/image/tonemap.h), PFM (little-endian float
 * RGB, bottom scanline first, as the format defines), Radiance HDR
 * (stb_image_write) and OpenEXR (exr.c, with extra layers), all written to a
 * temporary file beside the target and renamed into place. The float formats
 * hold the render's linear radiance: exposure and tone mapping are for the
 * 8-bit output only.
 *
 * Where Linux offers it, the temporary file has no name while it is
 * written (open(2) O_TMPFILE on the target's directory); only when it is
 * complete (and closed, through a duplicate descriptor kept for this) is
 * it linked in under a temporary name (linkat(2) through /proc/self/fd,
 * as open(2) describes) and renamed over the target by the very next
 * system call. A process killed during the write (a second Ctrl-C,
 * SIGKILL) leaves no file behind; the one moment that can is a SIGKILL
 * landing between those two calls, which leaves a complete image under
 * .rt-tmp-PID-N (a handled signal removes it: rt_write_temp). Elsewhere,
 * or on a file system without O_TMPFILE, a mkstemp(3) file is written and
 * renamed as before. */
#define _GNU_SOURCE /* O_TMPFILE */
#include "rt/io/image_write.h"

#include <errno.h>
#include <fcntl.h>
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
#include "rt/image/tonemap.h"
#include "rt/io/exr.h"

rt_result rt_output_format(const char *path, rt_image_format *format, rt_error *err)
{
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    if (dot && (!slash || dot > slash)) {
        if (strcasecmp(dot, ".png") == 0) { *format = RT_FORMAT_PNG; return RT_OK; }
        if (strcasecmp(dot, ".pfm") == 0) { *format = RT_FORMAT_PFM; return RT_OK; }
        if (strcasecmp(dot, ".hdr") == 0) { *format = RT_FORMAT_HDR; return RT_OK; }
        if (strcasecmp(dot, ".exr") == 0) { *format = RT_FORMAT_EXR; return RT_OK; }
    }
    return rt_fail(err, RT_ERR_INVALID, "%s: unknown output format (use .png, .pfm, .hdr or .exr)", path);
}

/* A temporary file beside the target: unnamed (O_TMPFILE) when it can be,
 * else named by mkstemp. */
typedef struct temp_file {
    FILE *f;
    bool unnamed;
    char dir[4200];  /* the target's directory, "." for none */
    char name[4300]; /* the mkstemp name, or the name an unnamed file is linked under */
    rt_write_temp *track; /* NULL, or where a signal handler finds the name while one exists */
} temp_file;

/* Tells the signal handler the temporary file's name (or that there is
 * none): `active` is dropped while the path is rewritten, so the handler
 * never reads a half-written name. */
static void publish_name(temp_file *t, const char *name)
{
    if (!t->track)
        return;
    t->track->active = 0;
    if (name) {
        snprintf(t->track->path, sizeof t->track->path, "%s", name);
        t->track->active = 1;
    }
}

static FILE *fdopen_or_close(int fd)
{
    FILE *f = fdopen(fd, "wb");
    if (!f)
        close(fd);
    return f;
}

/* Opens a fresh temporary file in the directory of `path`; with track, its
 * name is published from before mkstemp creates it. */
static bool open_temp_beside(const char *path, temp_file *t, rt_write_temp *track)
{
    t->track = track;
    const char *slash = strrchr(path, '/');
    int n = slash ? snprintf(t->dir, sizeof t->dir, "%.*s", slash == path ? 1 : (int)(slash - path), path)
                  : snprintf(t->dir, sizeof t->dir, ".");
    if (n < 0 || (size_t)n >= sizeof t->dir) {
        errno = ENAMETOOLONG;
        return false;
    }
    t->unnamed = false;
    t->name[0] = 0;
#ifdef O_TMPFILE
    if (access("/proc/self/fd", X_OK) == 0) {
        int fd = open(t->dir, O_TMPFILE | O_RDWR | O_CLOEXEC, 0666); /* read back by rt_write_batch_read */
        if (fd >= 0) {
            t->unnamed = true;
            return (t->f = fdopen_or_close(fd)) != NULL;
        }
        if (errno != EOPNOTSUPP && errno != EISDIR && errno != EINVAL)
            return false; /* no such directory, no permission: the same for mkstemp */
    }
#endif
    n = snprintf(t->name, sizeof t->name, "%s/.rt-tmp-XXXXXX", t->dir);
    if (n < 0 || (size_t)n >= sizeof t->name) {
        errno = ENAMETOOLONG;
        return false;
    }
    int fd;
    if (track) { /* mkstemp fills in the published name itself */
        publish_name(t, t->name);
        fd = mkstemp(track->path);
        snprintf(t->name, sizeof t->name, "%s", track->path);
    } else {
        fd = mkstemp(t->name);
    }
    if (fd < 0) {
        publish_name(t, NULL);
        return false;
    }
    if (!(t->f = fdopen_or_close(fd))) {
        int e = errno;
        unlink(t->name);
        errno = e;
        return false;
    }
    return true;
}

/* Closes the file and forgets it: a named one is removed. */
static void discard_temp(temp_file *t)
{
    if (t->f)
        fclose(t->f);
    t->f = NULL;
    if (!t->unnamed)
        unlink(t->name);
    publish_name(t, NULL);
}

/* Gives a complete temporary file a name beside the target: an unnamed
 * one is linked in now through `fd`, an open descriptor of it (a fresh
 * name, retried if taken). */
static bool name_temp(temp_file *t, int fd)
{
    if (!t->unnamed)
        return true;
    char proc[64];
    snprintf(proc, sizeof proc, "/proc/self/fd/%d", fd);
    for (int attempt = 0; attempt < 100; attempt++) {
        snprintf(t->name, sizeof t->name, "%s/.rt-tmp-%ld-%d", t->dir, (long)getpid(), attempt);
        publish_name(t, t->name);
        if (linkat(AT_FDCWD, proc, AT_FDCWD, t->name, AT_SYMLINK_FOLLOW) == 0) {
            t->unnamed = false; /* from here on it is a named file like mkstemp's */
            return true;
        }
        if (errno != EEXIST)
            return false;
    }
    return false;
}

/* What a file is renamed over must be a regular file or nothing: a
 * directory there (or a device, a FIFO) would fail only at the rename. */
static rt_result check_target(const char *path, rt_error *err)
{
    struct stat st;
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return rt_fail(err, RT_ERR_IO, "%s: is a directory; give a file name", path);
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode))
        return rt_fail(err, RT_ERR_IO, "%s: not a regular file; give a file name", path);
    return RT_OK;
}

rt_result rt_output_check_file(const char *path, rt_error *err)
{
    rt_result r = check_target(path, err);
    if (r != RT_OK)
        return r;
    temp_file t;
    if (!open_temp_beside(path, &t, NULL))
        return rt_fail(err, RT_ERR_IO, "%s: cannot write there: %s", path, strerror(errno));
    discard_temp(&t);
    return RT_OK;
}

rt_result rt_output_check(const char *path, rt_error *err)
{
    rt_image_format fmt;
    rt_result r = rt_output_format(path, &fmt, err);
    return r != RT_OK ? r : rt_output_check_file(path, err);
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

static int write_png(FILE *f, const rt_framebuffer *fb, float exposure, rt_tonemap tonemap)
{
    size_t n = (size_t)fb->width * (size_t)fb->height * 3;
    unsigned char *px = malloc(n);
    if (!px)
        return 0;
    rt_tonemap_to_srgb8(tonemap, exposure, fb->rgb, n / 3, px);
    int ok = stbi_write_png_to_func(write_to_file, f, fb->width, fb->height, 3, px, fb->width * 3);
    free(px);
    return ok;
}

rt_result rt_framebuffer_write(const rt_framebuffer *fb, const char *path, float exposure, rt_error *err)
{
    rt_image_options opt = {.exposure = exposure};
    return rt_framebuffer_write_with(fb, path, &opt, err);
}

rt_result rt_framebuffer_write_with(const rt_framebuffer *fb, const char *path, const rt_image_options *opt,
                                    rt_error *err)
{
    return rt_framebuffer_write_tracked(fb, path, opt, NULL, err);
}

static rt_result finish_temp(temp_file *t, const char *path, int ok, rt_error *err);
static rt_result batch_add(rt_write_batch *b, temp_file *t, const char *path, int ok, rt_error *err);

rt_result rt_framebuffer_write_tracked(const rt_framebuffer *fb, const char *path, const rt_image_options *opt,
                                       rt_write_temp *temp, rt_error *err)
{
    rt_write_batch b;
    rt_write_batch_init(&b, temp);
    rt_result r = rt_framebuffer_write_batched(fb, path, opt, &b, err);
    return r == RT_OK ? rt_write_batch_commit(&b, err) : (rt_write_batch_discard(&b), r);
}

rt_result rt_framebuffer_write_batched(const rt_framebuffer *fb, const char *path, const rt_image_options *opt,
                                       rt_write_batch *batch, rt_error *err)
{
    rt_image_format fmt;
    rt_result r = rt_output_format(path, &fmt, err);
    if (r != RT_OK)
        return r;
    if ((r = rt_output_check_size(path, fb->width, fb->height, err)) != RT_OK)
        return r;
    if ((r = check_target(path, err)) != RT_OK)
        return r;
    temp_file t;
    if (!open_temp_beside(path, &t, batch->track))
        return rt_fail(err, RT_ERR_IO, "%s: cannot create a file there: %s", path, strerror(errno));
    FILE *f = t.f;
    int ok;
    float exposure = opt->exposure;
    switch (fmt) {
    case RT_FORMAT_PFM: ok = write_pfm(f, fb); break;
    case RT_FORMAT_HDR: ok = stbi_write_hdr_to_func(write_to_file, f, fb->width, fb->height, 3, fb->rgb); break;
    case RT_FORMAT_EXR: {
        rt_exr_layer layers[1 + RT_MAX_IMAGE_LAYERS];
        int count = 0;
        layers[count++] = (rt_exr_layer){NULL, 3, fb->rgb};
        for (int i = 0; i < opt->layer_count && i < RT_MAX_IMAGE_LAYERS; i++)
            layers[count++] = (rt_exr_layer){opt->layers[i].name, opt->layers[i].channels, opt->layers[i].data};
        r = rt_exr_write(f, path, fb->width, fb->height, layers, count, opt->half, err);
        if (r != RT_OK) {
            discard_temp(&t);
            return r;
        }
        ok = 1;
        break;
    }
    case RT_FORMAT_PNG:
    default:
        ok = write_png(f, fb, exposure > 0.0f && isfinite(exposure) ? exposure : 1.0f, opt->tonemap);
        break;
    }
    return batch_add(batch, &t, path, ok, err);
}

/* Completes a temporary file's bytes: flushes and closes it and gives it
 * the mode of the file it will replace (or a plain fopen's), keeping a
 * duplicate descriptor in *keep (for linkat, and to read it back); on any
 * failure removes it. The file is closed before it gets a name, so that a
 * failed close (a network file system reports write errors there)
 * replaces nothing. */
static rt_result seal_temp(temp_file *t, const char *path, int ok, int *keep, rt_error *err)
{
    FILE *f = t->f;
    *keep = -1;
    if (fflush(f) != 0 || ferror(f))
        ok = 0;
    int saved = errno;
    if (!ok) {
        discard_temp(t);
        return rt_fail(err, RT_ERR_IO, "%s: write failed: %s", path, strerror(saved ? saved : EIO));
    }
    /* the temporary file is 0600 (mkstemp) or 0666 less the umask (O_TMPFILE):
     * give it the mode a plain fopen would, or keep the mode of the image it
     * replaces */
    struct stat st;
    mode_t mode;
    if (stat(path, &st) == 0) {
        mode = st.st_mode & 07777;
    } else {
        mode_t mask = umask(0);
        umask(mask);
        mode = 0666 & ~mask;
    }
    fchmod(fileno(f), mode);
    if ((*keep = dup(fileno(f))) < 0) {
        saved = errno;
        discard_temp(t);
        return rt_fail(err, RT_ERR_IO, "%s: write failed: %s", path, strerror(saved));
    }
    t->f = NULL;
    if (fclose(f) != 0) {
        saved = errno;
        close(*keep);
        *keep = -1;
        discard_temp(t);
        return rt_fail(err, RT_ERR_IO, "%s: write failed: %s", path, strerror(saved));
    }
    return RT_OK;
}

/* Puts a sealed temporary file in place: the name is renamed over path by
 * the very next system call after it is linked in (a close between the
 * two, where ext4 may wait on the inode's writeback, was a window of
 * milliseconds where SIGKILL left the .rt-tmp name behind); on failure
 * removes it. Closes keep. */
static rt_result place_temp(temp_file *t, const char *path, int keep, rt_error *err)
{
    int saved;
    if (!name_temp(t, keep)) {
        saved = errno;
        close(keep);
        discard_temp(t);
        return rt_fail(err, RT_ERR_IO, "%s: cannot link the finished image in: %s", path, strerror(saved));
    }
    if (rename(t->name, path) != 0) {
        saved = errno;
        close(keep);
        discard_temp(t);
        return rt_fail(err, RT_ERR_IO, "%s: cannot rename the finished image into place: %s", path, strerror(saved));
    }
    publish_name(t, NULL); /* renamed: nothing left to remove */
    close(keep);
    return RT_OK;
}

/* Completes a write at once: seals the temporary file and renames it over path. */
static rt_result finish_temp(temp_file *t, const char *path, int ok, rt_error *err)
{
    int keep;
    rt_result r = seal_temp(t, path, ok, &keep, err);
    return r != RT_OK ? r : place_temp(t, path, keep, err);
}

/* ------------------------------------------------------------ batches */

/* One file of a batch: sealed, waiting for the commit. */
struct rt_write_pending {
    temp_file t;
    int keep;
    char path[4200];
};

void rt_write_batch_init(rt_write_batch *b, rt_write_temp *track)
{
    memset(b, 0, sizeof *b);
    b->track = track;
}

/* Seals t and adds it to the batch under path (a later file for the same
 * path replaces the earlier one). */
static rt_result batch_add(rt_write_batch *b, temp_file *t, const char *path, int ok, rt_error *err)
{
    if (strlen(path) >= sizeof b->items[0].path) {
        discard_temp(t);
        return rt_fail(err, RT_ERR_LIMIT, "%s: path too long", path);
    }
    if (!rt_grow((void **)&b->items, &b->cap, b->count + 1, sizeof *b->items)) {
        discard_temp(t);
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory", path);
    }
    int keep;
    rt_result r = seal_temp(t, path, ok, &keep, err);
    if (r != RT_OK)
        return r;
    for (size_t i = 0; i < b->count; i++)
        if (strcmp(b->items[i].path, path) == 0) {
            close(b->items[i].keep);
            discard_temp(&b->items[i].t);
            b->items[i].t = *t;
            b->items[i].keep = keep;
            return RT_OK;
        }
    struct rt_write_pending *p = &b->items[b->count++];
    p->t = *t;
    p->keep = keep;
    snprintf(p->path, sizeof p->path, "%s", path);
    return RT_OK;
}

rt_result rt_write_batch_read(const rt_write_batch *b, const char *path, char **bytes, size_t *size, rt_error *err)
{
    for (size_t i = 0; i < b->count; i++) {
        if (strcmp(b->items[i].path, path) != 0)
            continue;
        struct stat st;
        int fd = b->items[i].keep;
        if (fstat(fd, &st) != 0 || st.st_size < 0)
            return rt_fail(err, RT_ERR_IO, "%s: cannot read the written file back: %s", path, strerror(errno));
        size_t n = (size_t)st.st_size, got = 0;
        char *buf = malloc(n + 1);
        if (!buf)
            return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory", path);
        while (got < n) {
            ssize_t k = pread(fd, buf + got, n - got, (off_t)got);
            if (k < 0 && errno == EINTR)
                continue;
            if (k <= 0) {
                free(buf);
                return rt_fail(err, RT_ERR_IO, "%s: cannot read the written file back: %s", path,
                               k < 0 ? strerror(errno) : "short read");
            }
            got += (size_t)k;
        }
        buf[n] = 0;
        *bytes = buf;
        *size = n;
        return RT_OK;
    }
    return rt_fail(err, RT_ERR_INVALID, "%s: not written in this batch", path);
}

rt_result rt_write_batch_commit(rt_write_batch *b, rt_error *err)
{
    /* every target first: a directory put in one's place since the check
     * before rendering fails the batch before anything is replaced */
    rt_result r = RT_OK;
    for (size_t i = 0; i < b->count && r == RT_OK; i++)
        r = check_target(b->items[i].path, err);
    size_t placed = 0;
    for (; placed < b->count && r == RT_OK; placed++) {
        struct rt_write_pending *p = &b->items[placed];
        p->t.track = b->track;
        r = place_temp(&p->t, p->path, p->keep, err);
        p->keep = -1;
    }
    for (size_t i = placed; i < b->count; i++) { /* what was not placed is removed */
        if (b->items[i].keep >= 0)
            close(b->items[i].keep);
        discard_temp(&b->items[i].t);
    }
    free(b->items);
    b->items = NULL;
    b->count = b->cap = 0;
    return r;
}

void rt_write_batch_discard(rt_write_batch *b)
{
    for (size_t i = 0; i < b->count; i++) {
        close(b->items[i].keep);
        discard_temp(&b->items[i].t);
    }
    free(b->items);
    b->items = NULL;
    b->count = b->cap = 0;
}

rt_result rt_file_write_atomic(const char *path, const void *bytes, size_t size, rt_write_temp *temp, rt_error *err)
{
    rt_result r = check_target(path, err);
    if (r != RT_OK)
        return r;
    temp_file t;
    if (!open_temp_beside(path, &t, temp))
        return rt_fail(err, RT_ERR_IO, "%s: cannot create a file there: %s", path, strerror(errno));
    int ok = fwrite(bytes, 1, size, t.f) == size;
    return finish_temp(&t, path, ok, err);
}

rt_result rt_file_write_batched(const char *path, const void *bytes, size_t size, rt_write_batch *batch,
                                rt_error *err)
{
    rt_result r = check_target(path, err);
    if (r != RT_OK)
        return r;
    temp_file t;
    if (!open_temp_beside(path, &t, batch->track))
        return rt_fail(err, RT_ERR_IO, "%s: cannot create a file there: %s", path, strerror(errno));
    int ok = fwrite(bytes, 1, size, t.f) == size;
    return batch_add(batch, &t, path, ok, err);
}
