/* validate.c - rt_scene_validate: one pass over every table checking
 * what the renderer takes for granted (rt/scene/validate.h lists the
 * rules), in the spirit of cgltf's cgltf_validate: loaders parse, one
 * separate pass checks the cross-references, and the code after it trusts
 * them. Linear in the size of the scene.
 */
#include "rt/scene/validate.h"
#include "rt/scene/instance.h"

#include "rt/base/alloc.h"

#include <math.h>
#include <stdlib.h>

/* "3 materials", "1 texture": a count with its noun. */
#define PLURAL(n) (n), ((n) == 1 ? "" : "s")

static bool finite1(float x) { return isfinite(x) != 0; }

static rt_result check_slot(const rt_scene *s, size_t mi, const rt_texture_slot *slot, const char *what,
                            rt_error *err)
{
    const rt_material *m = &s->materials[mi];
    if (slot->texture != RT_NONE && slot->texture >= s->texture_count)
        return rt_fail(err, RT_ERR_INVALID, "material %zu ('%s'): %s texture %u is out of range (%zu texture%s)", mi,
                       m->name, what, slot->texture, PLURAL(s->texture_count));
    if (slot->texcoord > 1)
        return rt_fail(err, RT_ERR_INVALID, "material %zu ('%s'): %s texture uses UV set %u (only 0 and 1 exist)", mi,
                       m->name, what, (unsigned)slot->texcoord);
    return RT_OK;
}

static float min3(rt_vec3 v) { return fminf(v.x, fminf(v.y, v.z)); }

static rt_result check_materials(const rt_scene *s, rt_error *err)
{
    size_t prims = rt_scene_prim_count(s);
    if (prims > 0 && s->material_count == 0)
        return rt_fail(err, RT_ERR_INVALID, "the scene has %zu primitive%s but no materials", PLURAL(prims));
    for (size_t i = 0; i < s->material_count; i++) {
        const rt_material *m = &s->materials[i];
        if (!rt_finite3(m->color) || !rt_finite3(m->emission) || !finite1(m->emission_strength))
            return rt_fail(err, RT_ERR_INVALID, "material %zu ('%s'): colour or emission is not finite", i, m->name);
        if ((m->interior_medium != RT_NONE && m->interior_medium >= s->medium_count) ||
            (m->exterior_medium != RT_NONE && m->exterior_medium >= s->medium_count))
            return rt_fail(err, RT_ERR_INVALID, "material %zu ('%s'): its medium is out of range (%zu medi%s)", i,
                           m->name, s->medium_count, s->medium_count == 1 ? "um" : "a");
        const struct {
            const rt_texture_slot *slot;
            const char *what;
        } slots[] = {
            {&m->base_color_tex, "base colour"}, {&m->metal_rough_tex, "metallic-roughness"},
            {&m->normal_tex, "normal"},          {&m->occlusion_tex, "occlusion"},
            {&m->emissive_tex, "emissive"},      {&m->transmission_tex, "transmission"},
        };
        for (size_t k = 0; k < sizeof slots / sizeof slots[0]; k++) {
            rt_result r = check_slot(s, i, slots[k].slot, slots[k].what, err);
            if (r != RT_OK)
                return r;
        }
        for (int k = 0; k < RT_XTEX_COUNT; k++) {
            rt_result r = check_slot(s, i, &m->ext_tex[k], "extension", err);
            if (r != RT_OK)
                return r;
        }
    }
    return RT_OK;
}

static rt_result check_textures(const rt_scene *s, rt_error *err)
{
    for (size_t i = 0; i < s->texture_count; i++) {
        const rt_texture *t = &s->textures[i];
        if (t->kind != RT_TEX_IMAGE && t->kind != RT_TEX_CONSTANT && t->kind != RT_TEX_CHECKER)
            return rt_fail(err, RT_ERR_INVALID, "texture %zu: unknown kind %d", i, (int)t->kind);
        if (t->kind == RT_TEX_IMAGE && t->image >= s->image_count)
            return rt_fail(err, RT_ERR_INVALID, "texture %zu: image %u is out of range (%zu image%s)", i, t->image,
                           PLURAL(s->image_count));
    }
    for (size_t i = 0; i < s->image_count; i++) {
        const rt_image *img = &s->images[i];
        if (img->width < 1 || img->height < 1 || (!img->rgba8 && !img->rgbaf))
            return rt_fail(err, RT_ERR_INVALID, "image %zu ('%s'): no pixels (%dx%d)", i, img->name, img->width,
                           img->height);
    }
    return RT_OK;
}

static rt_result check_geometry(const rt_scene *s, rt_error *err)
{
    const rt_vertices *v = &s->vertices;
    for (size_t i = 0; i < v->count; i++)
        if (!rt_finite3(v->position[i]))
            return rt_fail(err, RT_ERR_INVALID, "vertex %zu: position is not finite", i);
    const rt_triangles *t = &s->triangles;
    for (size_t i = 0; i < t->count; i++) {
        for (int c = 0; c < 3; c++)
            if (t->index[3 * i + (size_t)c] >= v->count)
                return rt_fail(err, RT_ERR_INVALID, "triangle %zu: vertex index %u is out of range (%zu vert%s)", i,
                               t->index[3 * i + (size_t)c], v->count, v->count == 1 ? "ex" : "ices");
        if (t->material[i] >= s->material_count)
            return rt_fail(err, RT_ERR_INVALID, "triangle %zu: material %u is out of range (%zu material%s)", i,
                           t->material[i], PLURAL(s->material_count));
        if ((t->flags[i] & RT_TRI_TANGENT) && !v->tangent)
            return rt_fail(err, RT_ERR_INVALID, "triangle %zu: flagged with tangents, but the vertices have none", i);
        if ((t->flags[i] & RT_TRI_COLOR) && !v->color)
            return rt_fail(err, RT_ERR_INVALID, "triangle %zu: flagged with colours, but the vertices have none", i);
    }
    const rt_spheres *sp = &s->spheres;
    for (size_t i = 0; i < sp->count; i++) {
        if (sp->material[i] >= s->material_count)
            return rt_fail(err, RT_ERR_INVALID, "sphere %zu: material %u is out of range (%zu material%s)", i,
                           sp->material[i], PLURAL(s->material_count));
        if (!finite1(sp->cx[i]) || !finite1(sp->cy[i]) || !finite1(sp->cz[i]) || !finite1(sp->radius[i]))
            return rt_fail(err, RT_ERR_INVALID, "sphere %zu: centre or radius is not finite", i);
    }
    const rt_quads *q = &s->quads;
    for (size_t i = 0; i < q->count; i++) {
        if (q->material[i] >= s->material_count)
            return rt_fail(err, RT_ERR_INVALID, "quad %zu: material %u is out of range (%zu material%s)", i,
                           q->material[i], PLURAL(s->material_count));
        if (!rt_finite3(rt_v3(q->px[i], q->py[i], q->pz[i])) || !rt_finite3(rt_v3(q->ux[i], q->uy[i], q->uz[i])) ||
            !rt_finite3(rt_v3(q->vx[i], q->vy[i], q->vz[i])))
            return rt_fail(err, RT_ERR_INVALID, "quad %zu: corner or edges are not finite", i);
    }
    return RT_OK;
}

static rt_result check_lights(const rt_scene *s, rt_error *err)
{
    uint8_t *quad_taken = NULL; /* per quad: already some area light's */
    rt_result r = RT_OK;
    for (size_t i = 0; i < s->light_count && r == RT_OK; i++) {
        const rt_light *l = &s->lights[i];
        if (l->kind != RT_LIGHT_POINT && l->kind != RT_LIGHT_DIRECTIONAL && l->kind != RT_LIGHT_SPOT &&
            l->kind != RT_LIGHT_AREA) {
            r = rt_fail(err, RT_ERR_INVALID, "light %zu: unknown kind %d", i, (int)l->kind);
        } else if (!rt_finite3(l->color) || !finite1(l->intensity) || !rt_finite3(l->position) ||
                   !rt_finite3(l->direction) || !rt_finite3(l->edge_u) || !rt_finite3(l->edge_v)) {
            r = rt_fail(err, RT_ERR_INVALID,
                        "light %zu: a colour, intensity, position, direction or edge is not finite", i);
        } else if (l->quad == RT_NONE) {
            continue;
        } else if (l->kind != RT_LIGHT_AREA) {
            r = rt_fail(err, RT_ERR_INVALID, "light %zu: only area lights have a quad (it names quad %u)", i, l->quad);
        } else if (l->quad >= s->quads.count) {
            r = rt_fail(err, RT_ERR_INVALID, "light %zu: area light's quad %u is out of range (%zu quad%s)", i,
                        l->quad, PLURAL(s->quads.count));
        } else if (!quad_taken && !(quad_taken = rt_alloc(s->quads.count, 1))) {
            r = rt_fail(err, RT_ERR_NOMEM, "out of memory checking the lights of %zu quads", s->quads.count);
        } else if (quad_taken[l->quad]) {
            r = rt_fail(err, RT_ERR_INVALID, "light %zu: quad %u is already another area light's quad", i, l->quad);
        } else {
            quad_taken[l->quad] = 1;
        }
    }
    free(quad_taken);
    return r;
}

/* The environment (the messages keep their word "settings": the scene
 * format's statements that set it are settings-table entries). */
static rt_result check_environment(const rt_scene *s, rt_error *err)
{
    const rt_scene_environment *st = &s->environment;
    if (st->environment_texture != RT_NONE && st->environment_texture >= s->texture_count)
        return rt_fail(err, RT_ERR_INVALID, "settings: environment texture %u is out of range (%zu texture%s)",
                       st->environment_texture, PLURAL(s->texture_count));
    if (!rt_finite3(st->background) || !finite1(st->environment_strength))
        return rt_fail(err, RT_ERR_INVALID, "settings: background or environment strength is not finite");
    if (st->medium != RT_NONE && st->medium >= s->medium_count)
        return rt_fail(err, RT_ERR_INVALID, "scene_medium %u is out of range (%zu medi%s)", st->medium,
                       s->medium_count, s->medium_count == 1 ? "um" : "a");
    for (size_t i = 0; i < s->medium_count; i++) {
        const rt_medium_def *m = &s->media[i];
        bool ok = rt_finite3(m->sigma_a) && rt_finite3(m->sigma_s) && min3(m->sigma_a) >= 0.0f &&
                  min3(m->sigma_s) >= 0.0f && fabsf(m->g) <= RT_MEDIUM_G_MAX;
        if (!ok || (m->kind == RT_MEDIUM_GRID && !m->grid.block_max))
            return rt_fail(err, RT_ERR_INVALID, "medium %zu ('%s'): coefficients, g or grid out of range", i,
                           m->name);
    }
    return RT_OK;
}

/* Objects lie inside the triangle and vertex tables; instances name an
 * object and have a usable transform (rt/scene/instance.h). */
static rt_result check_instances(const rt_scene *s, rt_error *err)
{
    for (size_t i = 0; i < s->object_count; i++) {
        const rt_object *o = &s->objects[i];
        if (o->first_triangle + o->triangle_count > s->triangles.count ||
            o->first_vertex + o->vertex_count > s->vertices.count)
            return rt_fail(err, RT_ERR_INVALID, "object %zu: its triangles or vertices lie past the tables", i);
    }
    for (size_t i = 0; i < s->instance_count; i++) {
        const rt_instance *in = &s->instances[i];
        if (in->object >= s->object_count)
            return rt_fail(err, RT_ERR_INVALID, "instance %zu: object %u is out of range (%zu objects)", i, in->object,
                           s->object_count);
        rt_instance_check c = rt_instance_check_transform(&in->to_world);
        if (c != RT_INSTANCE_OK)
            return rt_fail(err, RT_ERR_INVALID, "instance %zu: its transform is %s", i, rt_instance_check_name(c));
    }
    return RT_OK;
}

rt_result rt_scene_validate(const rt_scene *s, rt_error *err)
{
    rt_result r;
    if ((r = check_materials(s, err)) != RT_OK || (r = check_textures(s, err)) != RT_OK ||
        (r = check_geometry(s, err)) != RT_OK || (r = check_lights(s, err)) != RT_OK ||
        (r = check_environment(s, err)) != RT_OK || (r = check_instances(s, err)) != RT_OK)
        return r;
    return RT_OK;
}
