/* medium.c - nested dielectrics by a priority stack of media (see
 * rt/render/medium.h for the rules).
 *
 * Sources: C. M. Schmidt and B. Budge, "Simple Nested Dielectrics in Ray
 * Traced Images", Journal of Graphics Tools 7(1), 2002: each dielectric
 * has a priority, the path keeps the list of objects it is inside, the
 * highest-priority one is the medium, and intersections with the surfaces
 * of lower-priority objects inside it are false (skipped); the index ratio
 * at a true interface is taken between the medium left and the medium
 * entered. Beer-Lambert absorption exp(-sigma d) along each segment in the
 * current medium (rt_material_absorption). The stack is a fixed array of
 * material ids so that a path can carry it by value.
 */
#include "rt/render/medium.h"

#include "rt/render/material_eval.h"

void rt_medium_stack_init(rt_medium_stack *st) { st->depth = 0; }

bool rt_medium_is_medium(const rt_material *m) { return m->bsdf == RT_BSDF_DIELECTRIC; }

/* Index of the entry that is the medium among the first n (skipping index
 * skip), or -1: the highest priority, the last entered among equals. */
static int top_of(const rt_medium_stack *st, const rt_material *mats, int skip)
{
    int best = -1;
    for (int i = 0; i < st->depth; i++)
        if (i != skip && (best < 0 || mats[st->material[i]].priority >= mats[st->material[best]].priority))
            best = i;
    return best;
}

/* Index of the last entry holding mat, or -1. */
static int find_last(const rt_medium_stack *st, uint32_t mat)
{
    for (int i = st->depth - 1; i >= 0; i--)
        if (st->material[i] == mat)
            return i;
    return -1;
}

uint32_t rt_medium_current(const rt_medium_stack *st, const rt_material *mats)
{
    int t = top_of(st, mats, -1);
    return t < 0 ? RT_NONE : st->material[t];
}

uint32_t rt_medium_of_segment(const rt_medium_stack *st, const rt_material *mats, uint32_t mat, bool front)
{
    const rt_material *m = &mats[mat];
    if (!front && !rt_medium_is_medium(m) && m->thickness > 0.0f)
        return mat; /* a glTF volume: closed, not nested */
    if (!front && rt_medium_is_medium(m) && find_last(st, mat) < 0)
        return mat; /* underflow: inside it, unknown to the stack */
    return rt_medium_current(st, mats);
}

rt_vec3 rt_medium_transmittance(const rt_material *mats, uint32_t medium, float d)
{
    if (medium == RT_NONE)
        return rt_v3s(1.0f);
    rt_vec3 sigma = rt_material_absorption(&mats[medium]);
    if (!(rt_max3(sigma) > 0.0f))
        return rt_v3s(1.0f);
    return rt_v3(expf(-sigma.x * d), expf(-sigma.y * d), expf(-sigma.z * d));
}

bool rt_medium_false_hit(const rt_medium_stack *st, const rt_material *mats, uint32_t mat, bool front)
{
    return rt_medium_is_medium(&mats[mat]) && rt_medium_stack_false_hit(st, mats, mat, front);
}

bool rt_medium_stack_false_hit(const rt_medium_stack *st, const rt_material *mats, uint32_t mat, bool front)
{
    if (front) {
        int t = top_of(st, mats, -1);
        return t >= 0 && mats[mat].priority < mats[st->material[t]].priority;
    }
    /* leaving: false unless mat is the current medium (a higher priority
     * one, or an equal one entered later, still fills this point) */
    int self = find_last(st, mat);
    return self >= 0 && top_of(st, mats, -1) != self;
}

float rt_medium_outside_ior(const rt_medium_stack *st, const rt_material *mats, uint32_t mat, bool front)
{
    int t = front ? top_of(st, mats, -1) : top_of(st, mats, find_last(st, mat));
    return t < 0 ? mats[mat].exterior_ior : mats[st->material[t]].ior;
}

bool rt_medium_index_matched(const rt_medium_stack *st, const rt_material *mats, uint32_t mat, bool front)
{
    const rt_material *m = &mats[mat];
    float alpha = m->alpha_u >= 0.0f ? m->alpha_u : m->roughness * m->roughness; /* as the dielectric BSDF's */
    return m->bsdf == RT_BSDF_DIELECTRIC && alpha == 0.0f && rt_medium_outside_ior(st, mats, mat, front) == m->ior;
}

void rt_medium_cross(rt_medium_stack *st, const rt_material *mats, uint32_t mat, bool front)
{
    if (rt_medium_is_medium(&mats[mat]))
        rt_medium_stack_cross(st, mat, front);
}

void rt_medium_stack_cross(rt_medium_stack *st, uint32_t mat, bool front)
{
    if (front) {
        if (st->depth >= RT_MEDIUM_STACK_MAX) { /* overflow: drop the outermost */
            for (int i = 1; i < RT_MEDIUM_STACK_MAX; i++)
                st->material[i - 1] = st->material[i];
            st->depth = RT_MEDIUM_STACK_MAX - 1;
        }
        st->material[st->depth++] = mat;
        return;
    }
    int i = find_last(st, mat);
    if (i < 0)
        return; /* underflow: nothing to remove */
    for (int j = i + 1; j < st->depth; j++)
        st->material[j - 1] = st->material[j];
    st->depth--;
}
