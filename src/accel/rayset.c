/* rayset.c - reading the shared .rays / .hits benchmark files, with every
 * count checked against the file size before anything is allocated. */
#include "rt/accel/rayset.h"

#include "rt/base/alloc.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint64_t le64(const unsigned char *b)
{
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--)
        v = v << 8 | b[i];
    return v;
}

static float lef32(const unsigned char *b)
{
    uint32_t u = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
    float f;
    memcpy(&f, &u, 4);
    return f;
}

/* Reads the header of a ray or hit file, checks magic and size, returns the
 * open file positioned at the records. */
static rt_result open_records(const char *path, const char *magic, size_t record, FILE **out, uint64_t *count,
                              rt_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return rt_fail(err, RT_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    unsigned char h[16];
    if (fread(h, 1, 16, f) != 16) {
        fclose(f);
        return rt_fail(err, RT_ERR_PARSE, "%s: byte 0: file is shorter than its 16-byte header", path);
    }
    if (memcmp(h, magic, 8) != 0) {
        fclose(f);
        return rt_fail(err, RT_ERR_PARSE, "%s: byte 0: wrong magic (expected %s)", path, magic);
    }
    uint64_t n = le64(h + 8);
    if (fseek(f, 0, SEEK_END) != 0) {
        fclose(f);
        return rt_fail(err, RT_ERR_IO, "%s: cannot seek", path);
    }
    long size = ftell(f);
    if (size < 16 || n > (uint64_t)(size - 16) / record || (uint64_t)(size - 16) != n * record) {
        fclose(f);
        return rt_fail(err, RT_ERR_INVALID, "%s: byte 8: header says %llu records of %zu bytes but the file has %ld",
                       path, (unsigned long long)n, record, size - 16);
    }
    fseek(f, 16, SEEK_SET);
    *out = f;
    *count = n;
    return RT_OK;
}

rt_result rt_rayset_load(rt_rayset *rs, const char *rays_path, const char *hits_path, rt_error *err)
{
    memset(rs, 0, sizeof *rs);
    FILE *f;
    uint64_t n;
    rt_result r = open_records(rays_path, "RTRAYS01", 32, &f, &n, err);
    if (r != RT_OK)
        return r;
    rs->rays = rt_alloc(n ? (size_t)n : 1, sizeof(rt_ray));
    unsigned char *buf = malloc(32 * 4096);
    if (!rs->rays || !buf) {
        fclose(f);
        free(buf);
        rt_rayset_free(rs);
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for %llu rays", rays_path, (unsigned long long)n);
    }
    for (uint64_t i = 0; i < n;) {
        size_t chunk = n - i < 4096 ? (size_t)(n - i) : 4096;
        if (fread(buf, 32, chunk, f) != chunk) {
            fclose(f);
            free(buf);
            rt_rayset_free(rs);
            return rt_fail(err, RT_ERR_IO, "%s: read error", rays_path);
        }
        for (size_t k = 0; k < chunk; k++) {
            const unsigned char *b = buf + 32 * k;
            rt_ray *ray = &rs->rays[i + k];
            ray->org = rt_v3(lef32(b), lef32(b + 4), lef32(b + 8));
            ray->dir = rt_v3(lef32(b + 12), lef32(b + 16), lef32(b + 20));
            ray->tmin = lef32(b + 24);
            ray->tmax = lef32(b + 28);
        }
        i += chunk;
    }
    free(buf);
    fclose(f);
    rs->count = (size_t)n;
    if (!hits_path)
        return RT_OK;
    uint64_t m;
    r = open_records(hits_path, "RTHITS01", 4, &f, &m, err);
    if (r != RT_OK) {
        rt_rayset_free(rs);
        return r;
    }
    if (m != n) {
        fclose(f);
        rt_rayset_free(rs);
        return rt_fail(err, RT_ERR_INVALID, "%s: has %llu hits for %llu rays in %s", hits_path,
                       (unsigned long long)m, (unsigned long long)n, rays_path);
    }
    rs->ref_t = rt_alloc(n ? (size_t)n : 1, sizeof(float));
    unsigned char *hb = malloc(n ? (size_t)n * 4 : 1);
    if (!rs->ref_t || !hb || fread(hb, 4, (size_t)n, f) != (size_t)n) {
        fclose(f);
        free(hb);
        rt_rayset_free(rs);
        return rt_fail(err, RT_ERR_IO, "%s: cannot read the hits", hits_path);
    }
    for (size_t i = 0; i < (size_t)n; i++)
        rs->ref_t[i] = lef32(hb + 4 * i);
    free(hb);
    fclose(f);
    return RT_OK;
}

void rt_rayset_free(rt_rayset *rs)
{
    free(rs->rays);
    free(rs->ref_t);
    memset(rs, 0, sizeof *rs);
}
