/* gltf_catalog.c - what a glTF file offers besides its geometry
 * (rt_gltf_catalog, rt/io/gltf.h), for `rt --info`: each animation's name
 * and length, the largest key time of its samplers' inputs (glTF 2.0,
 * section 3.11: the input accessor holds the key times in seconds), and
 * the names of KHR_materials_variants. A key time that cannot be read
 * leaves the length unknown (-1) rather than failing a load that does not
 * pose the model. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_doc.h"
#include "rt/base/alloc.h"

/* The last key time of animation a; -1 when a time cannot be read. */
static float animation_seconds(gl_doc *d, const gl_anim *an)
{
    float longest = 0.0f;
    for (uint32_t k = 0; k < an->sampler_count; k++) {
        uint32_t ai = d->asamplers[an->first_sampler + k].input;
        if (ai >= d->accessor_count || d->accessors[ai].ncomp != 1 || d->accessors[ai].count == 0)
            return -1.0f;
        size_t n = d->accessors[ai].count;
        float *t = rt_alloc(n, sizeof(float));
        rt_error quiet = {0}, *kept = d->err;
        d->err = &quiet; /* a failure here is not the load's */
        rt_result r = t ? gl_read_floats(d, ai, t) : RT_ERR_NOMEM;
        d->err = kept;
        for (size_t i = 0; r == RT_OK && i < n; i++)
            if (isfinite(t[i]) && t[i] > longest)
                longest = t[i];
        free(t);
        if (r != RT_OK)
            return -1.0f;
    }
    return longest;
}

/* The string `name` of the object at token obj into out; "" when there is none. */
static void name_of(const gl_doc *d, int obj, char *out, size_t size)
{
    int t = obj >= 0 ? rt_json_get(&d->j, obj, "name") : -1;
    if (t < 0 || rt_json_string(&d->j, t, out, size) < 0)
        out[0] = 0;
}

void gl_catalog(gl_doc *d, rt_gltf_catalog *c)
{
    for (size_t a = 0; a < d->anim_count; a++, c->animations++) {
        if (c->animations >= RT_GLTF_CATALOG_MAX)
            continue;
        name_of(d, d->anims[a].tok, c->animation_name[c->animations], sizeof c->animation_name[0]);
        c->animation_seconds[c->animations] = animation_seconds(d, &d->anims[a]);
    }
    if (d->variants_tok < 0)
        return;
    for (int i = 0, e = d->variants_tok + 1; i < jsize(d, d->variants_tok) && e < d->j.count;
         i++, e = rt_json_skip(&d->j, e), c->variants++)
        if (c->variants < RT_GLTF_CATALOG_MAX)
            name_of(d, e, c->variant_name[c->variants], sizeof c->variant_name[0]);
}
