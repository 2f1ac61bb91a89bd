/* kdtree_stream_instances.c - a ray stream at a leaf that holds instances:
 * the rays that reached it go on into each instance's object as one
 * sub-stream, so a stream walks the top level of an instanced tree and
 * the objects' trees as streams (rt/accel/kdtree.h, "Instances").
 *
 * The rays of a leaf list whose interval still starts before their
 * closest hit (the single walk's test at a leaf) take the leaf's
 * primitives in the leaf's order, as each would alone (kdtree_trace.c's
 * test_leaf): a triangle, sphere or quad ray by ray with the single-ray
 * primitive test; an instance as one sub-stream: every ray still live
 * moved into the object's space by the instance's stored inverse with the
 * very operations of rt_kd_instance_hit (rt_mat4_point, rt_mat4_vector;
 * the direction not renormalised, so t is the same in both spaces) on the
 * interval (tmin, closest hit so far), walked through the object's tree
 * by the same stream walk (kdtree_stream_walk.c, the parent's width and
 * thin-list rule), and each hit that comes back merged as
 * rt_kd_instance_hit merges it (t, u, v, the instance's tree id, the
 * object's triangle as a scene id). Each ray so meets the primitives its
 * single walk meets, in its order, on the same intervals, and gets the
 * same answer (same t bits; on an exact tie either primitive, as for
 * every stream). An occlusion ray leaves the leaf at its first hit.
 *
 * Instanced objects hold no instances (their trees are built over views
 * of their own triangles, kdtree_instances.c), so a sub-stream never
 * makes one of its own. Its memory (the per-ray arrays and lists of a
 * kd_stream for the parent's chunk, and the rays in structure-of-arrays
 * for its set-up) is made at the first instance leaf of a stream and kept
 * until the stream ends.
 *
 * Sources: Wald, Gribble, Boulos, Kensler 2007 and Barringer and
 * Akenine-Moller 2014 (the ray streams the sub-stream is); Embree's and
 * pbrt's instances for the transform at the boundary.
 */
#include "kdtree_stream_internal.h"

#include <math.h>
#include <stdlib.h>

#include "rt/scene/instance.h"

/* The sub-stream: a stream over one object's tree at a time, its rays in
 * structure-of-arrays for the set-up, and each of its rays' index in the
 * parent's chunk. */
struct kd_stream_sub {
    kd_stream s;
    float *f; /* ox oy oz dx dy dz tmin tmax, chunk floats each */
    rt_ray_batch rb;
    uint32_t *live;  /* the parent's rays still to test at the leaf */
    uint32_t *enter; /* those of them an instance's sub-stream takes */
};

void rt_kd_stream_sub_free(kd_stream_sub *sub)
{
    if (!sub)
        return;
    rt_kd_stream_close(&sub->s);
    free(sub->f);
    free(sub->live);
    free(sub->enter);
    free(sub);
}

static kd_stream_sub *sub_open(const kd_stream *s)
{
    kd_stream_sub *sub = calloc(1, sizeof *sub);
    if (!sub)
        return NULL;
    size_t c = s->chunk;
    sub->f = malloc(8 * c * sizeof(float));
    sub->live = malloc(c * sizeof(uint32_t));
    sub->enter = malloc(c * sizeof(uint32_t));
    /* (the object's tree is set per instance) */
    if (!rt_kd_stream_open(&sub->s, s->tree, s->any, s->lanes, s->min_rays, c) || !sub->f || !sub->live || !sub->enter) {
        rt_kd_stream_sub_free(sub);
        return NULL;
    }
    float *f = sub->f;
    sub->rb = (rt_ray_batch){f, f + c, f + 2 * c, f + 3 * c, f + 4 * c, f + 5 * c, f + 6 * c, f + 7 * c};
    return sub;
}

/* The m rays listed in sub->live through instance id's object as one
 * sub-stream (those that can reach the instance's world box:
 * rt_kd_ray_may_enter); their hits merged into the parent's. */
static bool sub_stream(kd_stream *s, kd_stream_sub *sub, uint32_t id, size_t m)
{
    const rt_kdtree *tree = s->tree;
    uint32_t first_instance = (uint32_t)(tree->other_base + tree->sphere_count + tree->quad_count);
    const rt_instance *in = &tree->scene->instances[id - first_instance];
    const rt_kdtree *ob = &tree->objects[in->object];
    uint32_t first_triangle = (uint32_t)tree->scene->objects[in->object].first_triangle;
    const rt_mat4 *x = &in->to_object;
    size_t c = sub->s.chunk;
    float *ox = sub->f, *oy = ox + c, *oz = oy + c, *dx = oz + c, *dy = dx + c, *dz = dy + c, *tmin = dz + c,
          *tmax = tmin + c;
    uint32_t *ids = sub->enter;
    size_t n = 0;
    for (size_t k = 0; k < m; k++) {
        uint32_t i = sub->live[k];
        const rt_ray *r = &s->ray[i];
        if (!rt_kd_ray_may_enter(&in->bounds, r, s->best[i]))
            continue;
        size_t j = n++;
        ids[j] = i;
        rt_vec3 o = rt_mat4_point(x, r->org), d = rt_mat4_vector(x, r->dir);
        ox[j] = o.x;
        oy[j] = o.y;
        oz[j] = o.z;
        dx[j] = d.x;
        dy[j] = d.y;
        dz[j] = d.z;
        tmin[j] = r->tmin;
        tmax[j] = s->best[i];
    }
    if (n == 0)
        return true;
    sub->s.tree = ob;
    if (!rt_kd_stream_chunk(&sub->s, &sub->rb, 0, n))
        return false;
    for (size_t j = 0; j < n; j++) {
        const rt_hit *h = &sub->s.hit[j];
        uint32_t i = ids[j];
        if (h->prim == RT_NONE)
            continue;
        if (s->any) { /* blocked (as kdtree_stream.c's record) */
            s->best[i] = NAN;
            s->hit[i].prim = 0;
            continue;
        }
        if (!(h->t < s->best[i]))
            continue;
        s->best[i] = h->t;
        s->hit[i] = (rt_hit){h->t, h->u, h->v, id, rt_kdtree_scene_prim(ob, h->prim) + first_triangle};
    }
    return true;
}

bool rt_kd_stream_instance_leaf(kd_stream *s, uint32_t ref, size_t b, size_t n)
{
    const rt_kdtree *tree = s->tree;
    if (!s->sub && !(s->sub = sub_open(s)))
        return false;
    kd_stream_sub *sub = s->sub;
    size_t m = 0;
    for (size_t k = b; k < b + n; k++) {
        uint32_t i = s->lid[k];
        if (s->llo[k] <= s->best[i])
            sub->live[m++] = i;
    }
    uint32_t one = ref & RT_KD_PAYLOAD;
    const uint32_t *p = ref >= RT_KD_ONE ? &one : tree->prim_ids + (ref & RT_KD_PAYLOAD);
    for (; m > 0; p++) {
        uint32_t id = *p & RT_KD_PAYLOAD;
        if (rt_kd_is_instance(tree, id)) {
            if (!sub_stream(s, sub, id, m))
                return false;
        } else {
            for (size_t j = 0; j < m; j++)
                rt_kd_stream_leaf(s, RT_KD_ONE | id, sub->live[j]);
        }
        if (ref >= RT_KD_ONE || (*p & RT_KD_LAST))
            break;
        if (s->any) { /* the blocked rays are done */
            size_t k = 0;
            for (size_t j = 0; j < m; j++)
                if (!isnan(s->best[sub->live[j]]))
                    sub->live[k++] = sub->live[j];
            m = k;
        }
    }
    return true;
}
