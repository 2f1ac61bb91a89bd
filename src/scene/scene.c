/* scene.c - the scene tables: defaults, appends, marks and rollback, bounds,
 * automatic framing, the environment's defaults and the named metals'
 * constants (sources in rt/scene/scene.h). */
#include "rt/scene/scene.h"

#include "rt/base/alloc.h"
#include "rt/scene/instance.h"

#include <stdlib.h>
#include <string.h>


void rt_texture_slot_none(rt_texture_slot *slot)
{
    slot->texture = RT_NONE;
    slot->texcoord = 0;
    const float id[6] = {1, 0, 0, 0, 1, 0};
    memcpy(slot->uv_transform, id, sizeof id);
}

void rt_material_default(rt_material *m, const char *name)
{
    memset(m, 0, sizeof *m);
    if (name) {
        strncpy(m->name, name, sizeof m->name - 1);
    }
    m->color = rt_v3s(0.8f);
    m->alpha = 1.0f;
    m->ambient = 0.4f;
    m->diffuse = 0.8f;
    m->specular = 0.05f;
    m->shininess = 32.0f;
    m->reflectivity = 0.0f;
    m->transmission = 0.0f;
    m->transmission_color = rt_v3s(1.0f);
    m->ior = 1.5f;
    m->metallic = 0.0f;
    m->roughness = 1.0f;
    m->emission = rt_v3s(0.0f);
    m->emission_strength = 1.0f;
    m->normal_scale = 1.0f;
    m->occlusion_strength = 1.0f;
    m->alpha_mode = RT_ALPHA_OPAQUE;
    m->alpha_cutoff = 0.5f;
    m->double_sided = true;
    m->eta = rt_metals[0].eta; /* Cu */
    m->k = rt_metals[0].k;
    m->alpha_u = m->alpha_v = -1.0f;
    m->smith = RT_SMITH_CORRELATED;
    m->exterior_ior = 1.0f;
    m->priority = 0;
    m->interior_medium = RT_NONE;
    m->exterior_medium = RT_NONE;
    m->absorption = rt_v3s(0.0f);
    m->thickness = 0.0f;
    m->thin_walled = false;
    m->attenuation_color = rt_v3s(1.0f);
    m->attenuation_distance = INFINITY;
    m->subsurface = false;
    m->subsurface_albedo = rt_v3s(0.8f);
    m->subsurface_radius = rt_v3s(0.0f);
    m->subsurface_g = 0.0f;
    rt_texture_slot_none(&m->base_color_tex);
    rt_texture_slot_none(&m->metal_rough_tex);
    rt_texture_slot_none(&m->normal_tex);
    rt_texture_slot_none(&m->occlusion_tex);
    rt_texture_slot_none(&m->emissive_tex);
    rt_texture_slot_none(&m->transmission_tex);
    m->clearcoat = 0.0f;
    m->clearcoat_roughness = 0.0f;
    m->clearcoat_normal_scale = 1.0f;
    m->specular_weight = 1.0f;
    m->specular_color = rt_v3s(1.0f);
    m->sheen_color = rt_v3s(0.0f);
    m->sheen_roughness = 0.0f;
    m->anisotropy = 0.0f;
    m->anisotropy_rotation = 0.0f;
    m->iridescence = 0.0f;
    m->iridescence_ior = 1.3f;
    m->iridescence_thickness_min = 100.0f;
    m->iridescence_thickness_max = 400.0f;
    m->dispersion = 0.0f;
    m->diffuse_transmission = 0.0f;
    m->diffuse_transmission_color = rt_v3s(1.0f);
    for (int i = 0; i < RT_XTEX_COUNT; i++)
        rt_texture_slot_none(&m->ext_tex[i]);
    m->extended = false;
}

bool rt_material_extended(const rt_material *m)
{
    for (int i = 0; i < RT_XTEX_COUNT; i++)
        if (m->ext_tex[i].texture != RT_NONE)
            return true;
    rt_vec3 sc = m->specular_color;
    return m->clearcoat > 0.0f || m->specular_weight != 1.0f || sc.x != 1.0f || sc.y != 1.0f || sc.z != 1.0f ||
           m->sheen_color.x > 0.0f || m->sheen_color.y > 0.0f || m->sheen_color.z > 0.0f || m->anisotropy > 0.0f ||
           m->iridescence > 0.0f || m->diffuse_transmission > 0.0f || (m->dispersion > 0.0f && m->transmission > 0.0f);
}

const rt_metal rt_metals[] = {
    {"Cu", {0.27105f, 0.67693f, 1.31640f}, {3.60920f, 2.62480f, 2.29210f}},
    {"Au", {0.18299f, 0.42108f, 1.37340f}, {3.42420f, 2.34590f, 1.77040f}},
    {"Ag", {0.15943f, 0.14512f, 0.13547f}, {3.92910f, 3.19000f, 2.38080f}},
    {"Al", {1.34560f, 0.96521f, 0.61722f}, {7.47460f, 6.39950f, 5.30310f}},
    {"Ti", {2.74070f, 2.54180f, 2.26700f}, {3.81430f, 3.43450f, 3.03850f}},
    {"Pt", {2.37570f, 2.08470f, 1.84530f}, {4.26550f, 3.71530f, 3.13650f}},
    {"Fe", {2.91140f, 2.94970f, 2.58450f}, {3.08930f, 2.93180f, 2.76700f}},
    {"CuZn", {0.44400f, 0.52700f, 1.09400f}, {3.69500f, 2.76500f, 1.82900f}}, /* brass */
    /* Palik's handbook as tabulated in Mitsuba 0.6's data/ior (Cr.*.spd,
     * Ni_palik.*.spd, W.*.spd), linearly interpolated at 650, 550, 450 nm */
    {"Cr", {3.63755f, 3.11576f, 1.92770f}, {4.36438f, 4.42285f, 4.16754f}},
    {"Ni", {2.01396f, 1.77236f, 1.62880f}, {3.80792f, 3.25260f, 2.65399f}},
    {"W", {3.69245f, 3.50000f, 3.30896f}, {2.93698f, 2.72915f, 2.52585f}},
};
const size_t rt_metal_count = sizeof rt_metals / sizeof *rt_metals;

void rt_scene_environment_default(rt_scene_environment *e)
{
    memset(e, 0, sizeof *e);
    e->background = rt_v3(0, 0, 0);
    e->ambient_light = rt_v3(0, 0, 0);
    e->ambient_light_set = false;
    e->environment_texture = RT_NONE;
    e->environment_strength = 1.0f;
    e->medium = RT_NONE;
}

void rt_scene_init(rt_scene *s)
{
    memset(s, 0, sizeof *s);
    rt_scene_environment_default(&s->environment);
    s->camera.position = rt_v3(0, 0, 5);
    s->camera.look_at = rt_v3(0, 0, 0);
    s->camera.up = rt_v3(0, 1, 0);
    s->camera.vfov_deg = 40.0f;
}

/* Lets go of an image's pixels: freed unless another scene still shares them. */
static void image_release(rt_image *img)
{
    if (img->shares && --*img->shares > 0)
        return;
    free(img->shares);
    free(img->rgba8);
    free(img->rgbaf);
}

void rt_scene_free(rt_scene *s)
{
    for (size_t i = 0; i < s->image_count; i++)
        image_release(&s->images[i]);
    free(s->images);
    free(s->materials);
    free(s->textures);
    free(s->lights);
    free(s->cameras);
    for (size_t i = 0; i < s->medium_count; i++)
        rt_density_grid_free(&s->media[i].grid);
    free(s->media);
    rt_vertices *v = &s->vertices;
    free(v->position); free(v->normal); free(v->uv0); free(v->uv1); free(v->tangent); free(v->color);
    free(s->triangles.index); free(s->triangles.material); free(s->triangles.flags);
    rt_spheres *sp = &s->spheres;
    free(sp->cx); free(sp->cy); free(sp->cz); free(sp->radius); free(sp->material);
    rt_quads *q = &s->quads;
    free(q->px); free(q->py); free(q->pz); free(q->ux); free(q->uy); free(q->uz);
    free(q->vx); free(q->vy); free(q->vz); free(q->material);
    free(s->objects);
    free(s->instances);
    memset(s, 0, sizeof *s);
}

/* Appends one record to an array-of-structs table. */
static uint32_t table_push(void **items, size_t *count, size_t *cap, const void *item, size_t size)
{
    if (*count >= RT_NONE - 1 || !rt_grow(items, cap, *count + 1, size))
        return RT_NONE;
    memcpy((char *)*items + *count * size, item, size);
    return (uint32_t)(*count)++;
}

uint32_t rt_scene_add_material(rt_scene *s, const rt_material *m)
{
    return table_push((void **)&s->materials, &s->material_count, &s->material_cap, m, sizeof *m);
}

uint32_t rt_scene_find_material(const rt_scene *s, const char *name)
{
    for (size_t i = s->material_count; i-- > 0;)
        if (strcmp(s->materials[i].name, name) == 0)
            return (uint32_t)i;
    return RT_NONE;
}

uint32_t rt_scene_add_texture(rt_scene *s, const rt_texture *t)
{
    return table_push((void **)&s->textures, &s->texture_count, &s->texture_cap, t, sizeof *t);
}

uint32_t rt_scene_add_image(rt_scene *s, const rt_image *img)
{
    return table_push((void **)&s->images, &s->image_count, &s->image_cap, img, sizeof *img);
}

bool rt_scene_share_images(rt_scene *s, rt_scene *from)
{
    for (size_t i = 0; i < from->image_count; i++) {
        rt_image *img = &from->images[i];
        if (!img->shares) {
            if (!(img->shares = malloc(sizeof *img->shares)))
                return false;
            *img->shares = 1;
        }
        if (rt_scene_add_image(s, img) == RT_NONE)
            return false;
        ++*img->shares;
    }
    return true;
}

uint32_t rt_scene_add_light(rt_scene *s, const rt_light *l)
{
    return table_push((void **)&s->lights, &s->light_count, &s->light_cap, l, sizeof *l);
}

uint32_t rt_scene_add_medium(rt_scene *s, rt_medium_def *m)
{
    uint32_t i = table_push((void **)&s->media, &s->medium_count, &s->medium_cap, m, sizeof *m);
    if (i == RT_NONE)
        rt_density_grid_free(&m->grid);
    return i;
}

uint32_t rt_scene_find_medium(const rt_scene *s, const char *name)
{
    for (size_t i = s->medium_count; i-- > 0;)
        if (strcmp(s->media[i].name, name) == 0)
            return (uint32_t)i;
    return RT_NONE;
}

bool rt_scene_has_media(const rt_scene *s)
{
    if (s->environment.medium != RT_NONE)
        return true;
    for (size_t i = 0; i < s->material_count; i++) {
        const rt_material *m = &s->materials[i];
        if (m->bsdf == RT_BSDF_NULL || m->interior_medium != RT_NONE || m->exterior_medium != RT_NONE)
            return true;
    }
    return false;
}

uint32_t rt_scene_add_camera(rt_scene *s, const rt_camera *c)
{
    return table_push((void **)&s->cameras, &s->camera_count, &s->camera_cap, c, sizeof *c);
}

uint32_t rt_scene_add_sphere(rt_scene *s, rt_vec3 center, float radius, uint32_t material)
{
    rt_spheres *sp = &s->spheres;
    void **arrays[] = {(void **)&sp->cx, (void **)&sp->cy, (void **)&sp->cz, (void **)&sp->radius,
                       (void **)&sp->material};
    const size_t sizes[] = {4, 4, 4, 4, 4};
    if (sp->count >= RT_NONE - 1 || !rt_soa_reserve(arrays, sizes, 5, &sp->cap, sp->count + 1))
        return RT_NONE;
    size_t i = sp->count++;
    sp->cx[i] = center.x; sp->cy[i] = center.y; sp->cz[i] = center.z;
    sp->radius[i] = radius;
    sp->material[i] = material;
    return (uint32_t)i;
}

uint32_t rt_scene_add_quad(rt_scene *s, rt_vec3 p, rt_vec3 u, rt_vec3 v, uint32_t material)
{
    rt_quads *q = &s->quads;
    void **arrays[] = {(void **)&q->px, (void **)&q->py, (void **)&q->pz, (void **)&q->ux, (void **)&q->uy,
                       (void **)&q->uz, (void **)&q->vx, (void **)&q->vy, (void **)&q->vz, (void **)&q->material};
    const size_t sizes[] = {4, 4, 4, 4, 4, 4, 4, 4, 4, 4};
    if (q->count >= RT_NONE - 1 || !rt_soa_reserve(arrays, sizes, 10, &q->cap, q->count + 1))
        return RT_NONE;
    size_t i = q->count++;
    q->px[i] = p.x; q->py[i] = p.y; q->pz[i] = p.z;
    q->ux[i] = u.x; q->uy[i] = u.y; q->uz[i] = u.z;
    q->vx[i] = v.x; q->vy[i] = v.y; q->vz[i] = v.z;
    q->material[i] = material;
    return (uint32_t)i;
}

static bool vertices_reserve(rt_vertices *v, size_t need)
{
    if (!v->position) {
        /* first use: the always-present arrays must exist before growing */
        v->position = rt_alloc(1, sizeof(rt_vec3));
        v->normal = rt_alloc(1, sizeof(rt_vec3));
        v->uv0 = rt_alloc(1, sizeof(rt_vec2));
        if (!v->position || !v->normal || !v->uv0)
            return false;
        v->cap = 1;
    }
    /* the optional arrays (uv1, tangent, color) grow only once enabled */
    void **arrays[6];
    size_t sizes[6];
    int n = 0;
    arrays[n] = (void **)&v->position, sizes[n++] = sizeof(rt_vec3);
    arrays[n] = (void **)&v->normal, sizes[n++] = sizeof(rt_vec3);
    arrays[n] = (void **)&v->uv0, sizes[n++] = sizeof(rt_vec2);
    if (v->uv1) arrays[n] = (void **)&v->uv1, sizes[n++] = sizeof(rt_vec2);
    if (v->tangent) arrays[n] = (void **)&v->tangent, sizes[n++] = sizeof(rt_vec4);
    if (v->color) arrays[n] = (void **)&v->color, sizes[n++] = sizeof(rt_vec4);
    return rt_soa_reserve(arrays, sizes, n, &v->cap, need);
}

uint32_t rt_scene_add_vertices(rt_scene *s, size_t n)
{
    rt_vertices *v = &s->vertices;
    if (n >= RT_NONE || v->count >= (size_t)RT_NONE - n || !vertices_reserve(v, v->count + n))
        return RT_NONE;
    size_t first = v->count;
    for (size_t i = first; i < first + n; i++) {
        v->position[i] = rt_v3s(0);
        v->normal[i] = rt_v3s(0);
        v->uv0[i] = rt_v2(0, 0);
        if (v->uv1) v->uv1[i] = rt_v2(0, 0);
        if (v->tangent) v->tangent[i] = rt_v4(0, 0, 0, 0);
        if (v->color) v->color[i] = rt_v4(1, 1, 1, 1);
    }
    v->count += n;
    return (uint32_t)first;
}

bool rt_scene_enable_attr(rt_scene *s, unsigned attrs)
{
    rt_vertices *v = &s->vertices;
    size_t cap = v->cap ? v->cap : 1;
    if ((attrs & RT_ATTR_UV1) && !v->uv1) {
        if (!(v->uv1 = rt_alloc(cap, sizeof(rt_vec2))))
            return false;
    }
    if ((attrs & RT_ATTR_TANGENT) && !v->tangent) {
        if (!(v->tangent = rt_alloc(cap, sizeof(rt_vec4))))
            return false;
    }
    if ((attrs & RT_ATTR_COLOR) && !v->color) {
        if (!(v->color = rt_alloc(cap, sizeof(rt_vec4))))
            return false;
        for (size_t i = 0; i < cap; i++)
            v->color[i] = rt_v4(1, 1, 1, 1);
    }
    if (!v->cap && !vertices_reserve(v, 1))
        return false;
    return true;
}

bool rt_scene_reserve_triangles(rt_scene *s, size_t n)
{
    rt_triangles *t = &s->triangles;
    if (t->count > SIZE_MAX / 4 - n)
        return false;
    void **arrays[] = {(void **)&t->index, (void **)&t->material, (void **)&t->flags};
    const size_t sizes[] = {3 * sizeof *t->index, sizeof *t->material, sizeof *t->flags};
    return rt_soa_reserve(arrays, sizes, 3, &t->cap, t->count + n);
}

uint32_t rt_scene_add_triangle(rt_scene *s, uint32_t a, uint32_t b, uint32_t c, uint32_t material, uint8_t flags)
{
    rt_triangles *t = &s->triangles;
    if (t->count >= RT_NONE - 1 || !rt_scene_reserve_triangles(s, 1))
        return RT_NONE;
    size_t i = t->count++;
    t->index[3 * i] = a;
    t->index[3 * i + 1] = b;
    t->index[3 * i + 2] = c;
    t->material[i] = material;
    t->flags[i] = flags;
    return (uint32_t)i;
}

rt_scene_mark rt_scene_mark_of(const rt_scene *s)
{
    rt_scene_mark m;
    memset(&m, 0, sizeof m);
    m.materials = s->material_count;
    m.textures = s->texture_count;
    m.images = s->image_count;
    m.lights = s->light_count;
    m.cameras = s->camera_count;
    m.media = s->medium_count;
    m.vertices = s->vertices.count;
    m.triangles = s->triangles.count;
    m.spheres = s->spheres.count;
    m.quads = s->quads.count;
    m.objects = s->object_count;
    m.instances = s->instance_count;
    m.vertex_attrs = (s->vertices.uv1 ? RT_ATTR_UV1 : 0u) | (s->vertices.tangent ? RT_ATTR_TANGENT : 0u) |
                     (s->vertices.color ? RT_ATTR_COLOR : 0u);
    m.camera_set = s->camera_set;
    m.camera = s->camera;
    m.environment = s->environment;
    return m;
}

/* Truncates a count to its mark (a table never grows back). */
static void truncate_to(size_t *count, size_t mark)
{
    if (*count > mark)
        *count = mark;
}

void rt_scene_rollback(rt_scene *s, const rt_scene_mark *m)
{
    for (size_t i = m->images; i < s->image_count; i++)
        image_release(&s->images[i]);
    truncate_to(&s->image_count, m->images);
    truncate_to(&s->material_count, m->materials);
    truncate_to(&s->texture_count, m->textures);
    truncate_to(&s->light_count, m->lights);
    truncate_to(&s->camera_count, m->cameras);
    for (size_t i = m->media; i < s->medium_count; i++)
        rt_density_grid_free(&s->media[i].grid);
    truncate_to(&s->medium_count, m->media);
    truncate_to(&s->vertices.count, m->vertices);
    truncate_to(&s->triangles.count, m->triangles);
    truncate_to(&s->spheres.count, m->spheres);
    truncate_to(&s->quads.count, m->quads);
    truncate_to(&s->object_count, m->objects);
    truncate_to(&s->instance_count, m->instances);
    rt_vertices *v = &s->vertices;
    if (!(m->vertex_attrs & RT_ATTR_UV1)) {
        free(v->uv1);
        v->uv1 = NULL;
    }
    if (!(m->vertex_attrs & RT_ATTR_TANGENT)) {
        free(v->tangent);
        v->tangent = NULL;
    }
    if (!(m->vertex_attrs & RT_ATTR_COLOR)) {
        free(v->color);
        v->color = NULL;
    }
    s->camera_set = m->camera_set;
    s->camera = m->camera;
    s->environment = m->environment;
}

rt_box rt_scene_prim_bounds(const rt_scene *s, uint32_t prim)
{
    uint32_t i;
    rt_box b = rt_box_empty();
    switch (rt_prim_kind_of(s, prim, &i)) {
    case RT_PRIM_TRIANGLE:
        for (int k = 0; k < 3; k++)
            b = rt_box_point(b, rt_tri_vertex(s, i, k));
        break;
    case RT_PRIM_SPHERE: {
        const rt_spheres *sp = &s->spheres;
        float r = fabsf(sp->radius[i]);
        b.lo = rt_v3(sp->cx[i] - r, sp->cy[i] - r, sp->cz[i] - r);
        b.hi = rt_v3(sp->cx[i] + r, sp->cy[i] + r, sp->cz[i] + r);
        break;
    }
    case RT_PRIM_QUAD: {
        const rt_quads *q = &s->quads;
        rt_vec3 p = rt_v3(q->px[i], q->py[i], q->pz[i]);
        rt_vec3 u = rt_v3(q->ux[i], q->uy[i], q->uz[i]);
        rt_vec3 v = rt_v3(q->vx[i], q->vy[i], q->vz[i]);
        b = rt_box_point(b, p);
        b = rt_box_point(b, rt_add(p, u));
        b = rt_box_point(b, rt_add(p, v));
        b = rt_box_point(b, rt_add(rt_add(p, u), v));
        break;
    }
    }
    return b;
}

rt_box rt_scene_bounds(const rt_scene *s)
{
    rt_box b = rt_box_empty();
    size_t n = rt_scene_prim_count(s);
    for (size_t i = 0; i < n; i++)
        if (i >= s->triangles.count || !(s->triangles.flags[i] & RT_TRI_OBJECT))
            b = rt_box_union(b, rt_scene_prim_bounds(s, (uint32_t)i));
    for (size_t i = 0; i < s->instance_count; i++)
        b = rt_box_union(b, s->instances[i].bounds);
    return b;
}

/* The automatic camera's view: from the front (+z), a little above and to
 * the side, the usual product shot; its field of view. */
#define FRAME_FOV 40.0f
static void frame_axes(float aspect, rt_vec3 *dir, rt_vec3 *right, rt_vec3 *up, float *tan_v, float *tan_h)
{
    *tan_v = tanf(0.5f * FRAME_FOV * (RT_PI / 180.0f));
    *tan_h = *tan_v * aspect;
    *dir = rt_normalize(rt_v3(0.35f, 0.3f, 1.0f));
    *right = rt_normalize(rt_cross(rt_neg(*dir), rt_v3(0, 1, 0)));
    *up = rt_cross(*right, rt_neg(*dir));
}

/* How many points the camera must see: the vertices, then 8 corners of
 * each other primitive's box and of each instance's world box. */
static size_t frame_point_count(const rt_scene *s)
{
    return s->vertices.count + 8 * (s->spheres.count + s->quads.count + s->instance_count);
}

/* Point i of those points (i counting up from 0 in one walk: *object is
 * the walk's cursor over the objects, 0 at the start); false when not
 * finite or when the vertex is an object's (object space: its instances'
 * boxes stand for it). */
static bool frame_point(const rt_scene *s, size_t i, size_t *object, rt_vec3 *p)
{
    size_t nv = s->vertices.count, nother = s->spheres.count + s->quads.count;
    if (i < nv) {
        size_t o = *object; /* loaders add objects' vertices in order */
        while (o < s->object_count && s->objects[o].first_vertex + s->objects[o].vertex_count <= i)
            o++;
        *object = o;
        if (o < s->object_count && i >= s->objects[o].first_vertex)
            return false;
        *p = s->vertices.position[i];
    } else {
        size_t k = i - nv;
        rt_box pb = k < 8 * nother ? rt_scene_prim_bounds(s, (uint32_t)(s->triangles.count + k / 8))
                                   : s->instances[(k - 8 * nother) / 8].bounds;
        *p = rt_v3(k & 1 ? pb.hi.x : pb.lo.x, k & 2 ? pb.hi.y : pb.lo.y, k & 4 ? pb.hi.z : pb.lo.z);
    }
    return rt_finite3(*p);
}

void rt_frame_extent_init(rt_frame_extent *e, float aspect)
{
    e->aspect = aspect;
    e->bounds = rt_box_empty();
    for (int k = 0; k < 4; k++)
        e->reach[k] = -INFINITY;
}

void rt_frame_extent_add(rt_frame_extent *e, const rt_scene *s)
{
    rt_vec3 dir, right, up;
    float tan_v, tan_h;
    frame_axes(e->aspect, &dir, &right, &up, &tan_v, &tan_h);
    e->bounds = rt_box_union(e->bounds, rt_scene_bounds(s));
    size_t n = frame_point_count(s), object = 0;
    for (size_t i = 0; i < n; i++) {
        rt_vec3 p;
        if (!frame_point(s, i, &object, &p))
            continue;
        float z = rt_dot(p, dir), x = rt_dot(p, right) / tan_h, y = rt_dot(p, up) / tan_v;
        e->reach[0] = fmaxf(e->reach[0], z + x);
        e->reach[1] = fmaxf(e->reach[1], z - x);
        e->reach[2] = fmaxf(e->reach[2], z + y);
        e->reach[3] = fmaxf(e->reach[3], z - y);
    }
}

/* The camera at distance dist (before the margin) from c along the view. */
static void frame_place(rt_scene *s, rt_vec3 c, rt_vec3 dir, float dist)
{
    if (!(dist > 0.0f) || !isfinite(dist))
        dist = 1.0f;
    dist *= 1.08f; /* a small margin */
    s->camera.position = rt_madd(c, dir, dist);
    s->camera.look_at = c;
    s->camera.up = rt_v3(0, 1, 0);
    s->camera.vfov_deg = FRAME_FOV;
    s->camera.aperture = 0.0f;
    s->camera.focus_distance = 0.0f;
    s->camera_set = true;
}

void rt_scene_frame_camera_extent(rt_scene *s, const rt_frame_extent *e)
{
    rt_box b = e->bounds;
    if (rt_box_is_empty(b) || !rt_finite3(b.lo) || !rt_finite3(b.hi))
        b.lo = rt_v3s(-1), b.hi = rt_v3s(1);
    rt_vec3 c = rt_scale(rt_add(b.lo, b.hi), 0.5f);
    rt_vec3 dir, right, up;
    float tan_v, tan_h;
    frame_axes(e->aspect, &dir, &right, &up, &tan_v, &tan_h);
    /* z_q + |x_q| / tan_h of q = p - c is the larger of (z_p + x_p / tan_h)
     * - (z_c + x_c / tan_h) and the same with the minus signs: the reaches
     * less the centre's */
    float zc = rt_dot(c, dir), xc = rt_dot(c, right) / tan_h, yc = rt_dot(c, up) / tan_v;
    float dist = 0.0f;
    dist = fmaxf(dist, e->reach[0] - (zc + xc));
    dist = fmaxf(dist, e->reach[1] - (zc - xc));
    dist = fmaxf(dist, e->reach[2] - (zc + yc));
    dist = fmaxf(dist, e->reach[3] - (zc - yc));
    frame_place(s, c, dir, dist);
}

void rt_scene_frame_camera(rt_scene *s, float aspect)
{
    rt_box b = rt_scene_bounds(s);
    if (rt_box_is_empty(b) || !rt_finite3(b.lo) || !rt_finite3(b.hi))
        b.lo = rt_v3s(-1), b.hi = rt_v3s(1);
    rt_vec3 c = rt_scale(rt_add(b.lo, b.hi), 0.5f);
    rt_vec3 dir, right, up;
    float tan_v, tan_h;
    frame_axes(aspect, &dir, &right, &up, &tan_v, &tan_h);
    /* the nearest distance at which every vertex (and every corner of the
     * other primitives' boxes) is in view: tighter than fitting the box */
    float dist = 0.0f;
    size_t n = frame_point_count(s), object = 0;
    for (size_t i = 0; i < n; i++) {
        rt_vec3 p;
        if (!frame_point(s, i, &object, &p))
            continue;
        rt_vec3 q = rt_sub(p, c);
        float z = rt_dot(q, dir);
        dist = fmaxf(dist, z + fabsf(rt_dot(q, right)) / tan_h);
        dist = fmaxf(dist, z + fabsf(rt_dot(q, up)) / tan_v);
    }
    frame_place(s, c, dir, dist);
}
