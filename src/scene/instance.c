/* instance.c - the scene's objects and instances (rt/scene/instance.h):
 * declaring a run of triangles an object, checking and inverting an
 * instance's affine transform, and the counts --info reports.
 *
 * The inverse is the adjugate over the determinant (Cramer's rule), in
 * double, rounded once to float; the normal matrix is
 * rt_mat4_normal_matrix's, the one the glTF loader flattens normals with,
 * so an instance's normals get the same bits as a flattened copy's.
 */
#include "rt/scene/instance.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rt/base/alloc.h"

uint32_t rt_scene_add_object(rt_scene *s, size_t first_triangle, size_t triangle_count, size_t first_vertex,
                             size_t vertex_count)
{
    if (first_triangle + triangle_count > s->triangles.count || first_vertex + vertex_count > s->vertices.count)
        return RT_NONE;
    if (s->object_count >= RT_NONE - 1 ||
        !rt_grow((void **)&s->objects, &s->object_cap, s->object_count + 1, sizeof *s->objects))
        return RT_NONE;
    rt_object o = {first_triangle, triangle_count, first_vertex, vertex_count, rt_box_empty()};
    for (size_t t = first_triangle; t < first_triangle + triangle_count; t++) {
        s->triangles.flags[t] |= RT_TRI_OBJECT;
        for (int k = 0; k < 3; k++) {
            uint32_t v = s->triangles.index[3 * t + (size_t)k];
            if (v < s->vertices.count && rt_finite3(s->vertices.position[v]))
                o.bounds = rt_box_point(o.bounds, s->vertices.position[v]);
        }
    }
    /* in vertex order (the framing walk, rt_scene.c, relies on it): an
     * object over earlier vertices than the last ones goes before them,
     * and the instances of those after it are renumbered */
    size_t at = s->object_count;
    while (at > 0 && s->objects[at - 1].first_vertex > first_vertex)
        at--;
    memmove(s->objects + at + 1, s->objects + at, (s->object_count - at) * sizeof *s->objects);
    s->objects[at] = o;
    s->object_count++;
    for (size_t i = 0; i < s->instance_count && at + 1 < s->object_count; i++)
        if (s->instances[i].object >= at)
            s->instances[i].object++;
    return (uint32_t)at;
}

rt_instance_check rt_instance_check_transform(const rt_mat4 *to_world)
{
    const float(*m)[4] = to_world->m;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            if (!isfinite(m[i][j]))
                return RT_INSTANCE_NOT_FINITE;
    if (m[3][0] != 0.0f || m[3][1] != 0.0f || m[3][2] != 0.0f || m[3][3] != 1.0f)
        return RT_INSTANCE_NOT_AFFINE;
    rt_mat4 n;
    if (!rt_mat4_normal_matrix(to_world, &n))
        return RT_INSTANCE_SINGULAR;
    double a[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            a[i][j] = m[i][j];
    double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                 a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    float inv = (float)(1.0 / det); /* the inverse's scale must be a float */
    if (!(fabs(det) > 0.0) || !isfinite(inv))
        return RT_INSTANCE_SINGULAR;
    return RT_INSTANCE_OK;
}

const char *rt_instance_check_name(rt_instance_check c)
{
    switch (c) {
    case RT_INSTANCE_OK: return "usable";
    case RT_INSTANCE_NOT_FINITE: return "not finite";
    case RT_INSTANCE_NOT_AFFINE: return "not affine (its bottom row is not 0 0 0 1)";
    case RT_INSTANCE_SINGULAR:
    default: return "singular (a zero scale or a flattened axis: determinant 0)";
    }
}

rt_mat4 rt_instance_inverse(const rt_mat4 *to_world)
{
    const float(*m)[4] = to_world->m;
    double a[3][3], c[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            a[i][j] = m[i][j];
    c[0][0] = a[1][1] * a[2][2] - a[1][2] * a[2][1];
    c[0][1] = a[1][2] * a[2][0] - a[1][0] * a[2][2];
    c[0][2] = a[1][0] * a[2][1] - a[1][1] * a[2][0];
    c[1][0] = a[0][2] * a[2][1] - a[0][1] * a[2][2];
    c[1][1] = a[0][0] * a[2][2] - a[0][2] * a[2][0];
    c[1][2] = a[0][1] * a[2][0] - a[0][0] * a[2][1];
    c[2][0] = a[0][1] * a[1][2] - a[0][2] * a[1][1];
    c[2][1] = a[0][2] * a[1][0] - a[0][0] * a[1][2];
    c[2][2] = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    double det = a[0][0] * c[0][0] + a[0][1] * c[0][1] + a[0][2] * c[0][2];
    rt_mat4 r = rt_mat4_identity();
    double inv[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            inv[i][j] = c[j][i] / det; /* the adjugate is the cofactors' transpose */
    for (int i = 0; i < 3; i++) {
        double t = -(inv[i][0] * m[0][3] + inv[i][1] * m[1][3] + inv[i][2] * m[2][3]);
        for (int j = 0; j < 3; j++)
            r.m[i][j] = (float)inv[i][j];
        r.m[i][3] = (float)t;
    }
    return r;
}

uint32_t rt_scene_add_instance(rt_scene *s, uint32_t object, const rt_mat4 *to_world)
{
    if (object >= s->object_count || rt_instance_check_transform(to_world) != RT_INSTANCE_OK)
        return RT_NONE;
    if (s->instance_count >= RT_NONE - 1 ||
        !rt_grow((void **)&s->instances, &s->instance_cap, s->instance_count + 1, sizeof *s->instances))
        return RT_NONE;
    rt_instance in;
    memset(&in, 0, sizeof in);
    in.object = object;
    in.to_world = *to_world;
    in.to_object = rt_instance_inverse(to_world);
    rt_mat4_normal_matrix(to_world, &in.normal);
    in.mirror = rt_mat4_det3(to_world) < 0.0f;
    rt_box ob = s->objects[object].bounds;
    in.bounds = rt_box_empty();
    if (!rt_box_is_empty(ob))
        for (int k = 0; k < 8; k++) {
            rt_vec3 c = rt_v3(k & 1 ? ob.hi.x : ob.lo.x, k & 2 ? ob.hi.y : ob.lo.y, k & 4 ? ob.hi.z : ob.lo.z);
            in.bounds = rt_box_point(in.bounds, rt_mat4_point(to_world, c));
        }
    s->instances[s->instance_count] = in;
    return (uint32_t)s->instance_count++;
}

bool rt_scene_reserve_instances(rt_scene *s, size_t n)
{
    if (n >= RT_NONE - 1 - s->instance_count)
        return false;
    return rt_grow((void **)&s->instances, &s->instance_cap, s->instance_count + n, sizeof *s->instances) != 0;
}

size_t rt_scene_instanced_triangles(const rt_scene *s)
{
    size_t n = 0;
    for (size_t i = 0; i < s->instance_count; i++)
        n += s->objects[s->instances[i].object].triangle_count;
    return n;
}

size_t rt_scene_object_triangles(const rt_scene *s)
{
    size_t n = 0;
    for (size_t i = 0; i < s->object_count; i++)
        n += s->objects[i].triangle_count;
    return n;
}
