/* file.c - whole files into memory and path strings (rt/base/file.h).
 *
 * rt_read_file opens with O_NONBLOCK, so that opening a FIFO nobody writes
 * to returns at once instead of waiting for a writer (open(2), fifo(7)),
 * checks what it opened with fstat, then puts the descriptor back into
 * blocking mode for reading. A regular file's size comes from fstat and is
 * checked against the limit before the buffer is allocated; exactly that
 * many bytes are then read with read(2) (a file that shrinks meanwhile is a
 * read error). A pipe's size is unknown until its end: its buffer doubles
 * from 64 KiB, and reading stops with an error one byte past the limit.
 * Either way the buffer gets a NUL after the last byte, for text parsers.
 */
#include "rt/base/file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* read(2) until count bytes arrived, the end of the file, or an error
 * (-1, errno set); returns the bytes read. */
static long long read_fully(int fd, char *buf, size_t count)
{
    size_t got = 0;
    while (got < count) {
        ssize_t k = read(fd, buf + got, count - got);
        if (k < 0) {
            if (errno == EINTR)
                continue;
            return -1;
        }
        if (k == 0)
            break;
        got += (size_t)k;
    }
    return (long long)got;
}

static rt_result over_limit(const char *path, size_t max_size, rt_error *err)
{
    return rt_fail(err, RT_ERR_LIMIT, "%s: file is over the limit of %zu bytes", path, max_size);
}

static rt_result read_regular(int fd, const char *path, off_t file_size, size_t max_size, char **bytes, size_t *size,
                              rt_error *err)
{
    if (file_size < 0 || (unsigned long long)file_size > (unsigned long long)max_size)
        return over_limit(path, max_size, err);
    size_t n = (size_t)file_size;
    char *buf = malloc(n + 1);
    if (!buf)
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory reading %zu bytes", path, n);
    long long got = read_fully(fd, buf, n);
    if (got < 0) {
        int e = errno;
        free(buf);
        return rt_fail(err, RT_ERR_IO, "%s: read error: %s", path, strerror(e));
    }
    if ((size_t)got != n) {
        free(buf);
        return rt_fail(err, RT_ERR_IO, "%s: read error (got %lld of %zu bytes)", path, got, n);
    }
    buf[n] = 0;
    *bytes = buf;
    *size = n;
    return RT_OK;
}

static rt_result read_stream(int fd, const char *path, size_t max_size, char **bytes, size_t *size, rt_error *err)
{
    char *buf = NULL;
    size_t n = 0, cap = 0;
    for (;;) {
        if (n > max_size) {
            free(buf);
            return over_limit(path, max_size, err);
        }
        if (n == cap) {
            size_t want = cap ? cap * 2 : 65536;
            if (want > max_size + 1)
                want = max_size + 1; /* one byte past the limit shows the stream is over it */
            char *q = realloc(buf, want + 1);
            if (!q) {
                free(buf);
                return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory reading the file (%zu bytes so far)", path, n);
            }
            buf = q;
            cap = want;
        }
        long long got = read_fully(fd, buf + n, cap - n);
        if (got < 0) {
            int e = errno;
            free(buf);
            return rt_fail(err, RT_ERR_IO, "%s: read error: %s", path, strerror(e));
        }
        n += (size_t)got;
        if (n < cap)
            break; /* the end of the stream */
    }
    buf[n] = 0;
    *bytes = buf;
    *size = n;
    return RT_OK;
}

rt_result rt_read_file(const char *path, size_t max_size, char **bytes, size_t *size, rt_error *err)
{
    *bytes = NULL;
    *size = 0;
    if (!path || !path[0])
        return rt_fail(err, RT_ERR_IO, "no file name given");
    if (max_size == 0 || max_size > RT_FILE_MAX_BYTES)
        max_size = RT_FILE_MAX_BYTES;
    int fd = open(path, O_RDONLY | O_NONBLOCK);
    if (fd < 0)
        return rt_fail(err, RT_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    rt_result r;
    int flags;
    if (fstat(fd, &st) != 0)
        r = rt_fail(err, RT_ERR_IO, "%s: cannot stat: %s", path, strerror(errno));
    else if (S_ISDIR(st.st_mode))
        r = rt_fail(err, RT_ERR_IO, "%s: is a directory", path);
    else if (!S_ISREG(st.st_mode) && !S_ISFIFO(st.st_mode))
        r = rt_fail(err, RT_ERR_IO, "%s: not a regular file", path);
    else if ((flags = fcntl(fd, F_GETFL)) < 0 || fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0)
        r = rt_fail(err, RT_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
    else if (S_ISREG(st.st_mode))
        r = read_regular(fd, path, st.st_size, max_size, bytes, size, err);
    else
        r = read_stream(fd, path, max_size, bytes, size, err);
    close(fd);
    return r;
}

/* ---------------------------------------------------------------- paths */

static int ascii_lower(int c) { return c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c; }

const char *rt_path_basename(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

const char *rt_path_ext(const char *path)
{
    const char *base = rt_path_basename(path);
    const char *dot = strrchr(base, '.');
    return dot ? dot : base + strlen(base);
}

bool rt_path_has_ext(const char *path, const char *ext)
{
    const char *e = rt_path_ext(path);
    if (!*e)
        return false;
    for (; *e && *ext; e++, ext++)
        if (ascii_lower((unsigned char)*e) != ascii_lower((unsigned char)*ext))
            return false;
    return *e == 0 && *ext == 0;
}

bool rt_path_dirname(const char *path, char *out, size_t size)
{
    if (!size)
        return false;
    const char *slash = strrchr(path, '/');
    size_t n = slash ? (size_t)(slash - path) + 1 : 0;
    if (n >= size) {
        out[0] = 0;
        return false;
    }
    memcpy(out, path, n);
    out[n] = 0;
    return true;
}

bool rt_path_join(const char *dir, const char *rel, char *out, size_t size)
{
    size_t dl = rel[0] == '/' ? 0 : strlen(dir), rl = strlen(rel);
    bool slash = dl > 0 && dir[dl - 1] != '/';
    if (dl + slash + rl + 1 > size)
        return false;
    memcpy(out, dir, dl);
    if (slash)
        out[dl] = '/';
    memcpy(out + dl + slash, rel, rl + 1);
    return true;
}

bool rt_path_tagged(const char *path, const char *tag, const char *new_ext, char *out, size_t size)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    if (!dot || (slash && dot < slash))
        dot = path + strlen(path);
    int n = snprintf(out, size, "%.*s.%s%s", (int)(dot - path), path, tag, new_ext ? new_ext : dot);
    return n >= 0 && (size_t)n < size;
}

bool rt_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    return a && b && stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

bool rt_file_id(const char *path, uint64_t id[2])
{
    struct stat st;
    if (!path || stat(path, &st) != 0)
        return false;
    id[0] = (uint64_t)st.st_dev;
    id[1] = (uint64_t)st.st_ino;
    return true;
}
