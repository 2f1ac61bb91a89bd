/* part_image.c - a part seen as an image (rt/job/part_image.h): the
 * sidecar decides whether a file is a part; its sums are folded and
 * resolved by the renderer's own steps (rt/render/sample_block.h), as
 * rt/job/merge.h does for a whole set of parts. */
#include "rt/job/part_image.h"

#include <string.h>
#include <unistd.h>

#include "rt/base/file.h"
#include "rt/io/image_read.h"
#include "rt/render/sample_block.h"

bool rt_path_is_part(const char *path)
{
    char sidecar[4200];
    if (rt_path_has_ext(path, ".json"))
        return true;
    return rt_part_sidecar_path(path, sidecar, sizeof sidecar) && access(sidecar, F_OK) == 0;
}

static rt_vec3 load3(const float *p) { return rt_v3(p[0], p[1], p[2]); }

rt_result rt_part_image(const rt_part *p, rt_framebuffer *fb, rt_error *err)
{
    const rt_part_info *in = &p->info;
    int w = in->x1 - in->x0, h = in->y1 - in->y0;
    rt_result r = rt_framebuffer_init(fb, w, h, err);
    if (r != RT_OK)
        return r;
    size_t n = (size_t)w * (size_t)h;
    for (size_t i = 0; i < n; i++) {
        rt_vec3 f = rt_sample_fold(rt_v3s(0.0f), load3(p->sum + 3 * i));
        for (int b = 0; b < in->block_count; b++)
            f = rt_sample_fold(f, load3(p->blocks + ((size_t)b * n + i) * 3));
        rt_vec3 v = rt_sample_resolve(f, p->good[i]);
        fb->rgb[3 * i] = v.x, fb->rgb[3 * i + 1] = v.y, fb->rgb[3 * i + 2] = v.z;
    }
    return RT_OK;
}

/* A .pfm part's counts (P.count.pfm) or kept block (P.block.J.pfm): the
 * part P's name into part when its sidecar is there. */
static bool part_companion(const char *path, char *part, size_t size)
{
    size_t n = strlen(path);
    const char *tail = n >= 10 ? path + n - 10 : NULL;
    size_t base = 0;
    if (tail && strcmp(tail, ".count.pfm") == 0) {
        base = n - 10;
    } else {
        const char *b = strstr(path, ".block.");
        for (const char *q = b; q; q = strstr(q + 1, ".block."))
            b = q;
        if (!b || !rt_path_has_ext(path, ".pfm"))
            return false;
        for (const char *d = b + 7; d < path + n - 4; d++)
            if (*d < '0' || *d > '9')
                return false;
        base = (size_t)(b - path);
    }
    if (base + 5 > size)
        return false;
    memcpy(part, path, base);
    memcpy(part + base, ".pfm", 5);
    return rt_path_is_part(part);
}

rt_result rt_image_or_part_read(const char *path, rt_framebuffer *fb, rt_part_info *info, bool *is_part,
                                rt_error *err)
{
    char part[4200];
    if (part_companion(path, part, sizeof part))
        return rt_fail(err, RT_ERR_INVALID, "%s holds the %s of the part %s, not an image; give the part itself",
                       path, strstr(path, ".count.pfm") ? "sample counts" : "block sums", part);
    *is_part = rt_path_is_part(path);
    if (!*is_part)
        return rt_image_read(path, fb, err);
    rt_part p;
    rt_result r = rt_part_read(path, &p, err);
    if (r != RT_OK)
        return r;
    r = rt_part_image(&p, fb, err);
    if (info)
        *info = p.info;
    rt_part_free(&p);
    return r;
}
