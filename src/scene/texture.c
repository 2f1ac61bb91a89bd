/* texture.c - textures as image + sampler or a procedural pattern, and
 * lookups in the scene's image table (filled by rt/io/image_load.h).
 *
 * Lookups follow the glTF conventions, which are rt's internal ones: UV (0,0)
 * is the top-left corner of the image (row 0 as stored), u grows to the
 * right, v downwards. Texel centres sit at (i + 0.5) / width. Bilinear
 * filtering blends the four nearest texel centres; wrap modes apply per
 * texel index (repeat, clamp to edge, mirrored repeat as in OpenGL).
 * sRGB decoding (IEC 61966-2-1) uses rt/image/srgb.h's 256-entry table, so
 * a colour lookup costs no pow().
 */
#include "rt/scene/texture.h"

#include <math.h>
#include <string.h>

#include "rt/image/srgb.h"

rt_texture rt_texture_image(uint32_t image)
{
    rt_texture t;
    memset(&t, 0, sizeof t);
    t.kind = RT_TEX_IMAGE;
    t.image = image;
    t.wrap_s = t.wrap_t = RT_WRAP_REPEAT;
    t.filter = RT_FILTER_BILINEAR;
    t.color_a = t.color_b = rt_v4(1, 1, 1, 1);
    t.checker_scale = 1.0f;
    return t;
}

rt_texture rt_texture_constant(rt_vec4 color)
{
    rt_texture t = rt_texture_image(RT_NONE);
    t.kind = RT_TEX_CONSTANT;
    t.color_a = t.color_b = color;
    return t;
}

rt_texture rt_texture_checker(rt_vec4 a, rt_vec4 b, float squares_per_unit)
{
    rt_texture t = rt_texture_image(RT_NONE);
    t.kind = RT_TEX_CHECKER;
    t.color_a = a;
    t.color_b = b;
    t.checker_scale = squares_per_unit;
    return t;
}

rt_texture rt_texture_missing(void)
{
    return rt_texture_checker(rt_v4(1.0f, 0.0f, 1.0f, 1.0f), rt_v4(0.0f, 0.0f, 0.0f, 1.0f), 8.0f);
}

rt_vec2 rt_texture_slot_uv(const rt_texture_slot *slot, rt_vec2 uv)
{
    const float *m = slot->uv_transform;
    return rt_v2(m[0] * uv.x + m[1] * uv.y + m[2], m[3] * uv.x + m[4] * uv.y + m[5]);
}

/* Texel index i (any integer) to [0, n) under a wrap mode. */
static inline int wrap_index(int i, int n, rt_wrap mode)
{
    switch (mode) {
    case RT_WRAP_CLAMP:
        return i < 0 ? 0 : (i >= n ? n - 1 : i);
    case RT_WRAP_MIRROR: {
        int period = 2 * n;
        int k = i % period;
        if (k < 0)
            k += period;
        return k < n ? k : period - 1 - k;
    }
    case RT_WRAP_REPEAT:
    default: {
        int k = i % n;
        return k < 0 ? k + n : k;
    }
    }
}

static inline rt_vec4 texel(const rt_image *img, int x, int y, bool srgb)
{
    size_t o = 4 * ((size_t)y * (size_t)img->width + (size_t)x);
    if (img->rgbaf)
        return rt_v4(img->rgbaf[o], img->rgbaf[o + 1], img->rgbaf[o + 2], img->rgbaf[o + 3]);
    const uint8_t *p = img->rgba8 + o;
    if (srgb)
        return rt_v4(rt_srgb8_to_linear[p[0]], rt_srgb8_to_linear[p[1]], rt_srgb8_to_linear[p[2]], p[3] * (1.0f / 255.0f));
    return rt_v4(p[0] * (1.0f / 255.0f), p[1] * (1.0f / 255.0f), p[2] * (1.0f / 255.0f), p[3] * (1.0f / 255.0f));
}

/* Keeps huge or non-finite UVs from overflowing the texel index. */
static inline float sane_coord(float x)
{
    if (!isfinite(x))
        return 0.0f;
    return rt_clampf(x, -1.0e6f, 1.0e6f);
}

rt_vec4 rt_texture_sample(const rt_scene *s, uint32_t t, rt_vec2 uv, bool srgb)
{
    if (t == RT_NONE || t >= s->texture_count)
        return rt_v4(1, 1, 1, 1);
    const rt_texture *tex = &s->textures[t];
    switch (tex->kind) {
    case RT_TEX_CONSTANT:
        return tex->color_a;
    case RT_TEX_CHECKER: {
        float su = floorf(sane_coord(uv.x) * tex->checker_scale);
        float sv = floorf(sane_coord(uv.y) * tex->checker_scale);
        int parity = ((int)su + (int)sv) & 1;
        return parity ? tex->color_b : tex->color_a;
    }
    case RT_TEX_IMAGE:
    default:
        break;
    }
    if (tex->image >= s->image_count)
        return rt_v4(1, 0, 1, 1); /* magenta: a broken reference, visible */
    const rt_image *img = &s->images[tex->image];
    int w = img->width, h = img->height;
    float x = sane_coord(uv.x) * (float)w, y = sane_coord(uv.y) * (float)h;
    if (tex->filter == RT_FILTER_NEAREST) {
        int ix = wrap_index((int)floorf(x), w, tex->wrap_s);
        int iy = wrap_index((int)floorf(y), h, tex->wrap_t);
        return texel(img, ix, iy, srgb);
    }
    x -= 0.5f;
    y -= 0.5f;
    float fx = floorf(x), fy = floorf(y);
    float ax = x - fx, ay = y - fy;
    int x0 = wrap_index((int)fx, w, tex->wrap_s), x1 = wrap_index((int)fx + 1, w, tex->wrap_s);
    int y0 = wrap_index((int)fy, h, tex->wrap_t), y1 = wrap_index((int)fy + 1, h, tex->wrap_t);
    rt_vec4 a = texel(img, x0, y0, srgb), b = texel(img, x1, y0, srgb);
    rt_vec4 c = texel(img, x0, y1, srgb), d = texel(img, x1, y1, srgb);
    float wa = (1 - ax) * (1 - ay), wb = ax * (1 - ay), wc = (1 - ax) * ay, wd = ax * ay;
    return rt_v4(a.x * wa + b.x * wb + c.x * wc + d.x * wd, a.y * wa + b.y * wb + c.y * wc + d.y * wd,
                 a.z * wa + b.z * wb + c.z * wc + d.z * wd, a.w * wa + b.w * wb + c.w * wc + d.w * wd);
}
