/* material_eval.c - a material evaluated at a hit (see
 * rt/render/material_eval.h): its factors times its textures into the
 * parameters of the lobes of rt/render/bsdf.h, the glTF extensions'
 * textures and frames (the coat's normal, the anisotropy direction), the
 * absorption inside a material, and what a surface record must hold for
 * it (rt_material_needs).
 *
 * Sources: glTF 2.0 (metallic-roughness textures: roughness in G,
 * metallic in B; texture transforms and texcoord sets), the ratified
 * KHR_materials_* extensions for their factors and textures (clearcoat
 * with its own normal map, which inherits no texture of the material
 * below; specular A and colour RGB; sheen colour RGB and roughness A;
 * iridescence R and thickness G between its minimum and maximum; diffuse
 * transmission A and colour RGB; anisotropy's direction as (2 RG - 1)
 * rotated by its rotation, strength in B), KHR_materials_volume
 * (attenuation colour and distance: Beer-Lambert, sigma = -ln(c) / d).
 */
#include "rt/render/material_eval.h"

#include "rt/scene/texture.h"

rt_vec3 rt_material_absorption(const rt_material *m)
{
    rt_vec3 sigma = rt_v3s(0.0f);
    if (m->bsdf == RT_BSDF_DIELECTRIC)
        sigma = m->absorption;
    bool volume = m->bsdf == RT_BSDF_DIELECTRIC ||
                  (m->bsdf == RT_BSDF_GLTF && m->thickness > 0.0f &&
                   (m->transmission > 0.0f || m->diffuse_transmission > 0.0f));
    if (volume && isfinite(m->attenuation_distance) && m->attenuation_distance > 0.0f) {
        rt_vec3 c = rt_vmax(m->attenuation_color, rt_v3s(1e-6f));
        rt_vec3 a = rt_v3(-logf(rt_fminf(c.x, 1.0f)), -logf(rt_fminf(c.y, 1.0f)), -logf(rt_fminf(c.z, 1.0f)));
        sigma = rt_add(sigma, rt_scale(a, 1.0f / m->attenuation_distance));
    }
    return rt_finite3(sigma) ? rt_vmax(sigma, rt_v3s(0.0f)) : rt_v3s(0.0f);
}

void rt_bsdf_ext_of_material(const rt_material *m, rt_bsdf_ext *e)
{
    e->spec_weight = m->specular_weight;
    e->spec_color = m->specular_color;
    e->clearcoat = m->clearcoat;
    e->clearcoat_roughness = m->clearcoat_roughness;
    e->clearcoat_normal = rt_v3(0.0f, 0.0f, 1.0f); /* the shading normal: a coat without a map of its own */
    e->sheen_color = m->sheen_color;
    e->sheen_roughness = m->sheen_roughness;
    e->anisotropy = m->anisotropy;
    e->iridescence = m->iridescence;
    e->iridescence_ior = m->iridescence_ior;
    e->iridescence_thickness = m->iridescence_thickness_max; /* without a thickness texture: the maximum */
    e->diffuse_transmission = m->diffuse_transmission;
    e->diffuse_transmission_color = m->diffuse_transmission_color;
    e->dispersion = m->thin_walled ? 0.0f : m->dispersion; /* a thin wall does not bend light */
}

void rt_bsdf_ext_default(rt_bsdf_ext *e)
{
    rt_material m;
    rt_material_default(&m, NULL);
    rt_bsdf_ext_of_material(&m, e);
}

static rt_vec4 ext_sample(const rt_scene *s, const rt_surface *sf, const rt_material *m, rt_ext_slot k, bool srgb,
                          bool *present)
{
    const rt_texture_slot *slot = &m->ext_tex[k];
    *present = slot->texture != RT_NONE;
    if (!*present)
        return rt_v4(1.0f, 1.0f, 1.0f, 1.0f);
    rt_vec2 uv = rt_texture_slot_uv(slot, slot->texcoord == 1 ? sf->uv1 : sf->uv0);
    return rt_texture_sample(s, slot->texture, uv, srgb);
}

/* A tangent-space normal map's texel as a unit vector (2c - 1, scaled in x, y). */
static rt_vec3 normal_texel(rt_vec4 c, float scale)
{
    rt_vec3 v = rt_v3((2.0f * c.x - 1.0f) * scale, (2.0f * c.y - 1.0f) * scale, 2.0f * c.z - 1.0f);
    float l2 = rt_length2(v);
    return l2 > 1e-12f && isfinite(l2) ? rt_scale(v, 1.0f / sqrtf(l2)) : rt_v3(0.0f, 0.0f, 1.0f);
}

/* The extensions' factors x textures at a hit (KHR_materials_*), and the
 * anisotropy direction as the frame's x. The factors come from the
 * material (rt_bsdf_ext_of_material), so its defaults are the only ones. */
static void set_ext_from_surface(const rt_trace_ctx *ctx, const rt_surface *sf, const rt_material *m, rt_bsdf *b)
{
    const rt_scene *s = ctx->state->scene;
    rt_bsdf_ext e;
    bool has;
    rt_bsdf_ext_of_material(m, &e);
    e.clearcoat *= ext_sample(s, sf, m, RT_XTEX_CLEARCOAT, false, &has).x;
    e.clearcoat_roughness *= ext_sample(s, sf, m, RT_XTEX_CLEARCOAT_ROUGHNESS, false, &has).y;
    /* the tangent frame before the coat's map: sf's (t, b, n) made orthonormal about b->n */
    rt_vec3 t = rt_sub(sf->t, rt_scale(b->n, rt_dot(sf->t, b->n)));
    float tl2 = rt_length2(t);
    bool have_t = tl2 > 1e-12f && isfinite(tl2);
    if (have_t)
        t = rt_scale(t, 1.0f / sqrtf(tl2));
    rt_vec3 bt = rt_cross(b->n, t);
    if (have_t && rt_dot(bt, sf->b) < 0.0f)
        bt = rt_neg(bt); /* keep the UV handedness */
    /* the coat's normal: its own map, else the surface's normal without the
     * base's normal map (KHR_materials_clearcoat: the coat inherits no
     * texture of the material below it), in the frame of that normal */
    if (e.clearcoat > 0.0f) {
        rt_vec3 cn = b->n, ct = t, cbt = bt;
        bool have_ct = have_t;
        if (m->normal_tex.texture != RT_NONE && rt_dot(sf->n_unmapped, sf->wo) > 1e-4f &&
            rt_finite3(sf->n_unmapped)) {
            cn = sf->n_unmapped;
            ct = rt_sub(sf->t, rt_scale(cn, rt_dot(sf->t, cn)));
            float cl2 = rt_length2(ct);
            have_ct = cl2 > 1e-12f && isfinite(cl2);
            if (have_ct)
                ct = rt_scale(ct, 1.0f / sqrtf(cl2));
            cbt = rt_cross(cn, ct);
            if (have_ct && rt_dot(cbt, sf->b) < 0.0f)
                cbt = rt_neg(cbt);
            e.clearcoat_normal = rt_bsdf_to_local(b, cn);
        }
        if (have_ct) {
            rt_vec4 c = ext_sample(s, sf, m, RT_XTEX_CLEARCOAT_NORMAL, false, &has);
            if (has) {
                rt_vec3 v = normal_texel(c, m->clearcoat_normal_scale);
                rt_vec3 w = rt_add(rt_add(rt_scale(ct, v.x), rt_scale(cbt, v.y)), rt_scale(cn, v.z));
                e.clearcoat_normal = rt_bsdf_to_local(b, w);
            }
        }
    }
    e.spec_weight *= ext_sample(s, sf, m, RT_XTEX_SPECULAR, false, &has).w;
    rt_vec4 sc = ext_sample(s, sf, m, RT_XTEX_SPECULAR_COLOR, true, &has);
    e.spec_color = rt_mul(e.spec_color, rt_v3(sc.x, sc.y, sc.z));
    rt_vec4 sh = ext_sample(s, sf, m, RT_XTEX_SHEEN_COLOR, true, &has);
    e.sheen_color = rt_mul(e.sheen_color, rt_v3(sh.x, sh.y, sh.z));
    e.sheen_roughness *= ext_sample(s, sf, m, RT_XTEX_SHEEN_ROUGHNESS, false, &has).w;
    e.iridescence *= ext_sample(s, sf, m, RT_XTEX_IRIDESCENCE, false, &has).x;
    rt_vec4 th = ext_sample(s, sf, m, RT_XTEX_IRIDESCENCE_THICKNESS, false, &has);
    if (has)
        e.iridescence_thickness = m->iridescence_thickness_min +
                                  (m->iridescence_thickness_max - m->iridescence_thickness_min) * th.y;
    e.diffuse_transmission *= ext_sample(s, sf, m, RT_XTEX_DIFFUSE_TRANSMISSION, false, &has).w;
    rt_vec4 dc = ext_sample(s, sf, m, RT_XTEX_DIFFUSE_TRANSMISSION_COLOR, true, &has);
    e.diffuse_transmission_color = rt_mul(e.diffuse_transmission_color, rt_v3(dc.x, dc.y, dc.z));
    /* anisotropy: direction (cos r, sin r) in the tangent frame, or the
     * texture's (2 RG - 1) rotated by r; strength x texture B */
    rt_vec4 an = ext_sample(s, sf, m, RT_XTEX_ANISOTROPY, false, &has);
    if (has)
        e.anisotropy *= an.z;
    if (e.anisotropy > 0.0f && have_t) {
        float dx = has ? 2.0f * an.x - 1.0f : 1.0f, dy = has ? 2.0f * an.y - 1.0f : 0.0f;
        float cr = cosf(m->anisotropy_rotation), sr = sinf(m->anisotropy_rotation);
        float x = cr * dx - sr * dy, y = sr * dx + cr * dy;
        rt_vec3 dir = rt_add(rt_scale(t, x), rt_scale(bt, y));
        float l2 = rt_length2(dir);
        if (l2 > 1e-12f && isfinite(l2)) {
            rt_vec3 cn = rt_bsdf_to_world(b, e.clearcoat_normal); /* keep the coat's normal in world space */
            b->t = rt_scale(dir, 1.0f / sqrtf(l2));
            b->b = rt_cross(b->n, b->t);
            e.clearcoat_normal = rt_bsdf_to_local(b, cn);
        }
    }
    rt_bsdf_set_ext(b, &e);
}

/* The material's factors x textures into the BSDF of its model, on the
 * frame rt_bsdf_from_surface set (n its normal): one function a model. */
static void lambert_at(const rt_trace_ctx *ctx, const rt_surface *sf, const rt_material *m, rt_bsdf *b)
{
    /* base colour x texture x vertex colour, nothing else */
    if (m->base_color_tex.texture == RT_NONE) { /* rt_surface_base_color's arithmetic, inline */
        rt_vec4 v = sf->vertex_color;
        rt_bsdf_set_lambert(b, rt_v3(m->color.x * v.x, m->color.y * v.y, m->color.z * v.z));
    } else {
        rt_vec4 c = rt_surface_base_color(ctx, sf);
        rt_bsdf_set_lambert(b, rt_v3(c.x, c.y, c.z));
    }
}

static void conductor_at(const rt_trace_ctx *ctx, const rt_surface *sf, const rt_material *m, rt_vec3 n, rt_bsdf *b)
{
    const rt_scene *s = ctx->state->scene;
    float roughness = m->roughness;
    if (m->metal_rough_tex.texture != RT_NONE) {
        rt_vec2 uv = rt_texture_slot_uv(&m->metal_rough_tex,
                                        m->metal_rough_tex.texcoord == 1 ? sf->uv1 : sf->uv0);
        roughness *= rt_texture_sample(s, m->metal_rough_tex.texture, uv, false).y;
    }
    float ax = m->alpha_u >= 0.0f ? m->alpha_u : roughness * roughness;
    float ay = m->alpha_v >= 0.0f ? m->alpha_v : roughness * roughness;
    if (ax != ay) { /* anisotropic: x along the surface tangent */
        rt_vec3 t = rt_sub(sf->t, rt_scale(n, rt_dot(sf->t, n)));
        float l2 = rt_length2(t);
        if (l2 > 1e-12f && isfinite(l2)) {
            b->t = rt_scale(t, 1.0f / sqrtf(l2));
            b->b = rt_cross(n, b->t);
        }
    }
    rt_bsdf_set_conductor(b, m->eta, m->k, ax, ay, m->smith == RT_SMITH_SEPARABLE);
    if (ctx->state->settings->energy_compensation)
        rt_bsdf_compensate(b);
}

static void dielectric_at(const rt_trace_ctx *ctx, const rt_surface *sf, const rt_material *m, rt_vec3 n, rt_bsdf *b)
{
    /* eta = n_wo / n_wi: exterior over interior entering the front */
    float eta = m->exterior_ior / m->ior;
    float alpha = m->alpha_u >= 0.0f ? m->alpha_u : m->roughness * m->roughness;
    rt_bsdf_make_dielectric(b, n, sf->front ? eta : 1.0f / eta, alpha);
    rt_bsdf_set_frame(b, n, sf->ng);
    if (ctx->state->settings->energy_compensation)
        rt_bsdf_compensate(b);
}

/* opaque: the same from either side */
static void plastic_at(const rt_trace_ctx *ctx, const rt_surface *sf, const rt_material *m, rt_vec3 n, rt_bsdf *b)
{
    rt_vec4 c = rt_surface_base_color(ctx, sf);
    float alpha = m->alpha_u >= 0.0f ? m->alpha_u : m->roughness * m->roughness;
    rt_bsdf_make_plastic(b, n, rt_v3(c.x, c.y, c.z), m->exterior_ior / m->ior, alpha);
    rt_bsdf_set_frame(b, n, sf->ng);
}

static void gltf_at(const rt_trace_ctx *ctx, const rt_surface *sf, const rt_material *m, rt_bsdf *b)
{
    const rt_scene *s = ctx->state->scene;
    rt_vec4 b4 = rt_surface_base_color(ctx, sf);
    float metallic = m->metallic, roughness = m->roughness, transmission = m->transmission;
    if (m->metal_rough_tex.texture != RT_NONE) {
        rt_vec2 uv = rt_texture_slot_uv(&m->metal_rough_tex, m->metal_rough_tex.texcoord == 1 ? sf->uv1 : sf->uv0);
        rt_vec4 mr = rt_texture_sample(s, m->metal_rough_tex.texture, uv, false);
        metallic *= mr.z;
        roughness *= mr.y;
    }
    if (transmission > 0.0f && m->transmission_tex.texture != RT_NONE) {
        rt_vec2 uv = rt_texture_slot_uv(&m->transmission_tex,
                                        m->transmission_tex.texcoord == 1 ? sf->uv1 : sf->uv0);
        transmission *= rt_texture_sample(s, m->transmission_tex.texture, uv, false).x;
    }
    rt_bsdf_set_gltf(b, rt_v3(b4.x, b4.y, b4.z), metallic, roughness, m->ior, transmission);
    /* a glTF material without a volume (KHR_materials_volume thickness 0) is thin-walled */
    b->thin = m->bsdf == RT_BSDF_GLTF && b->transmission > 0.0f && m->thin_walled;
    if (!sf->front && !b->thin)
        b->eta = 1.0f / b->eta; /* leaving the object through its back (a thin wall has no inside: air on both sides) */
    if (m->extended && m->bsdf == RT_BSDF_GLTF)
        set_ext_from_surface(ctx, sf, m, b);
}

void rt_bsdf_from_surface(const rt_trace_ctx *ctx, const rt_surface *sf, rt_bsdf *b)
{
    const rt_scene *s = ctx->state->scene;
    RT_DCHECK(sf->material < s->material_count); /* rt_scene_validate */
    const rt_material *m = &s->materials[sf->material];
    /* frame: the shading normal, unless wo is not above it (normal maps,
     * interpolated normals at silhouettes); then the geometric normal */
    rt_vec3 n = sf->n;
    if (!(rt_dot(n, sf->wo) > 1e-4f) || !rt_finite3(n))
        n = sf->ng;
    rt_bsdf_set_frame(b, n, sf->ng);
    switch (m->bsdf) { /* no default: a new model is named here by the compiler */
    case RT_BSDF_LAMBERT:
        lambert_at(ctx, sf, m, b);
        return;
    case RT_BSDF_CONDUCTOR:
        conductor_at(ctx, sf, m, n, b);
        return;
    case RT_BSDF_DIELECTRIC:
        dielectric_at(ctx, sf, m, n, b);
        return;
    case RT_BSDF_PLASTIC:
        plastic_at(ctx, sf, m, n, b);
        return;
    case RT_BSDF_GLTF:
    case RT_BSDF_NULL: /* (no surface: the media tracer passes it before any BSDF) */
        break;
    }
    gltf_at(ctx, sf, m, b); /* (and, as before, any value out of the enum) */
}

bool rt_surface_material_reads_frame(const rt_material *m)
{
    return m->normal_tex.texture != RT_NONE || m->bsdf == RT_BSDF_CONDUCTOR || m->extended;
}

uint8_t rt_material_needs(const rt_material *m)
{
    const rt_texture_slot *slots[] = {&m->base_color_tex, &m->metal_rough_tex, &m->normal_tex,
                                      &m->occlusion_tex,  &m->emissive_tex,    &m->transmission_tex};
    bool textured = false;
    for (size_t k = 0; k < sizeof slots / sizeof slots[0]; k++)
        textured = textured || slots[k]->texture != RT_NONE;
    for (size_t k = 0; k < RT_XTEX_COUNT; k++)
        textured = textured || m->ext_tex[k].texture != RT_NONE;
    uint8_t needs = 0;
    if (textured)
        needs |= RT_MATERIAL_TEXTURED;
    if (rt_surface_material_reads_frame(m))
        needs |= RT_MATERIAL_FRAME;
    if (m->emission.x > 0.0f || m->emission.y > 0.0f || m->emission.z > 0.0f) /* rt_surface_emission's test */
        needs |= RT_MATERIAL_EMITS;
    return needs;
}
