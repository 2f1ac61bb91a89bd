/* gltf_material.c - glTF materials into rt_material (gltf_doc.h): the
 * metallic-roughness core, texture infos with KHR_texture_transform, and
 * the KHR_materials_* extensions (emissive_strength, transmission, ior,
 * volume, unlit, clearcoat, specular, sheen, anisotropy, iridescence,
 * dispersion, diffuse_transmission); textures, samplers and images; and,
 * when flattening, each used image decoded once into the scene's image
 * table (rt/io/image_load.h) under the missing-texture rule.
 * Sources: Khronos glTF 2.0 specification ("Materials", "Samplers") and
 * the extension specifications; docs/gltf.md lists the mapping.
 */
#include "gltf_doc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt/base/alloc.h"
#include "rt/base/log.h"
#include "rt/io/image_load.h"
#include "rt/scene/texture.h"

/* A textureInfo: index, texCoord, KHR_texture_transform. */
static rt_result parse_texinfo(gl_doc *d, const char *where, const char *key, int t, rt_texture_slot *slot,
                               float *extra, const char *extra_key)
{
    rt_result r = RT_OK;
    char w[128];
    snprintf(w, sizeof w, "%s.%s", where, key);
    if ((r = gl_expect_object(d, t, w)) != RT_OK)
        return r;
    uint32_t index = RT_NONE;
    int texcoord = 0;
    for (int k_n = 0, k = t + 1, v = t + 2; k_n < d->j.tok[t].size && v < d->j.count;
         k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
        if (KEY(k, "index")) r = gl_get_index(d, w, "index", v, &index);
        else if (KEY(k, "texCoord")) r = gl_get_int(d, w, "texCoord", v, &texcoord);
        else if (extra_key && KEY(k, extra_key))
            r = gl_get_ranged(d, w, extra_key, v, strcmp(extra_key, "strength") == 0 ? 0 : -GL_BIG,
                              strcmp(extra_key, "strength") == 0 ? 1 : GL_BIG, extra);
        else if (KEY(k, "extensions")) {
            int x = rt_json_get(&d->j, v, "KHR_texture_transform");
            if (x < 0)
                continue;
            char wx[200];
            snprintf(wx, sizeof wx, "%s.extensions.KHR_texture_transform", w);
            if ((r = gl_expect_object(d, x, wx)) != RT_OK)
                return r;
            float off[2] = {0, 0}, scale[2] = {1, 1}, rot = 0;
            for (int k2_n = 0, k2 = x + 1, v2 = x + 2; k2_n < d->j.tok[x].size && v2 < d->j.count;
                 k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
                if (KEY(k2, "offset")) r = gl_get_floats(d, wx, "offset", v2, off, 2);
                else if (KEY(k2, "scale")) r = gl_get_floats(d, wx, "scale", v2, scale, 2);
                else if (KEY(k2, "rotation")) r = gl_get_float(d, wx, "rotation", v2, &rot);
                else if (KEY(k2, "texCoord")) r = gl_get_int(d, wx, "texCoord", v2, &texcoord);
                if (r != RT_OK)
                    return r;
            }
            /* matrix = T(offset) * R(rotation) * S(scale) with R, row-major,
             * = [cos sin; -sin cos]: u' = u cos + v sin, v' = -u sin + v cos.
             * This is the direction Babylon.js, three.js, Cesium, Blender and
             * the TextureTransformTest sample agree on ("counter-clockwise" in
             * glTF's v-down UV space); the README's GLSL listing, read as
             * GLSL's column-major, rotates the other way (KhronosGroup/glTF
             * issue 1563). */
            float c = cosf(rot), s = sinf(rot);
            slot->uv_transform[0] = c * scale[0];
            slot->uv_transform[1] = s * scale[1];
            slot->uv_transform[2] = off[0];
            slot->uv_transform[3] = -s * scale[0];
            slot->uv_transform[4] = c * scale[1];
            slot->uv_transform[5] = off[1];
        }
        if (r != RT_OK)
            return r;
    }
    if (index == RT_NONE)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s: index is missing", w);
    if (texcoord < 0)
        return gl_fail_at(d, t, RT_ERR_INVALID, "%s: texCoord %d is negative", w, texcoord);
    if (texcoord > 1) {
        rt_warn("%s: %s uses TEXCOORD_%d; only sets 0 and 1 are loaded, using 0", d->path, w, texcoord);
        texcoord = 0;
    }
    slot->texture = index;
    slot->texcoord = (uint8_t)texcoord;
    return RT_OK;
}

/* Phong fields from the metallic-roughness model, for the whitted
 * integrator (docs/gltf.md, "Material mapping"). */
void gl_derive_phong(rt_material *m)
{
    float metal = rt_clampf(m->metallic, 0, 1), rough = rt_clampf(m->roughness, 0, 1);
    float f0 = 0.04f + (1.0f - 0.04f) * metal;       /* mean normal-incidence reflectance */
    m->diffuse = 0.8f * (1.0f - metal) + 0.2f * metal; /* metals keep a little colour */
    m->specular = f0 * (1.0f - 0.5f * rough);
    /* KHR_materials_specular scales the dielectric's share of the highlight */
    rt_vec3 sc = m->specular_color;
    if (m->specular_weight != 1.0f || sc.x != 1.0f || sc.y != 1.0f || sc.z != 1.0f) {
        sc = rt_vmin(rt_scale(sc, 0.04f), rt_v3s(1.0f));
        float fd = m->specular_weight * (sc.x + sc.y + sc.z) / 3.0f;
        m->specular = (fd + (1.0f - fd) * metal) * (1.0f - 0.5f * rough);
    }
    float a = rough * rough;                          /* GGX alpha */
    float a2 = a * a;
    m->shininess = a2 > 1e-6f ? rt_clampf(2.0f / a2 - 2.0f, 1.0f, 4096.0f) : 4096.0f;
    float smooth = (1.0f - rough) * (1.0f - rough);
    m->reflectivity = metal * smooth;
}

/* An RGB factor with every component in [lo, hi] (gl_get_floats_ranged). */
static rt_result get_color_ranged(gl_doc *d, const char *where, const char *key, int t, float lo, float hi,
                                  rt_vec3 *out)
{
    float c[3];
    rt_result r = gl_get_floats_ranged(d, where, key, t, 3, lo, hi, c);
    if (r == RT_OK)
        *out = rt_v3(c[0], c[1], c[2]);
    return r;
}

/* The PBR-next material extensions (KHR_materials_clearcoat, specular,
 * sheen, anisotropy, iridescence, dispersion, diffuse_transmission), each
 * into its fields of the material table; *known is false for any other
 * key. Ranges are the extensions' schemas'. */
static rt_result parse_material_ext(gl_doc *d, const char *wx, int k2, int v2, rt_material *m, bool *known)
{
    rt_result r = RT_OK;
    char we[160];
    const float big = GL_BIG;
    *known = true;
    if (KEY(k2, "KHR_materials_clearcoat")) {
        snprintf(we, sizeof we, "%s.KHR_materials_clearcoat", wx);
        if ((r = gl_expect_object(d, v2, we)) != RT_OK)
            return r;
        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
            if (KEY(k3, "clearcoatFactor")) r = gl_get_ranged(d, we, "clearcoatFactor", v3, 0, 1, &m->clearcoat);
            else if (KEY(k3, "clearcoatRoughnessFactor"))
                r = gl_get_ranged(d, we, "clearcoatRoughnessFactor", v3, 0, 1, &m->clearcoat_roughness);
            else if (KEY(k3, "clearcoatTexture"))
                r = parse_texinfo(d, we, "clearcoatTexture", v3, &m->ext_tex[RT_XTEX_CLEARCOAT], NULL, NULL);
            else if (KEY(k3, "clearcoatRoughnessTexture"))
                r = parse_texinfo(d, we, "clearcoatRoughnessTexture", v3, &m->ext_tex[RT_XTEX_CLEARCOAT_ROUGHNESS],
                                  NULL, NULL);
            else if (KEY(k3, "clearcoatNormalTexture"))
                r = parse_texinfo(d, we, "clearcoatNormalTexture", v3, &m->ext_tex[RT_XTEX_CLEARCOAT_NORMAL],
                                  &m->clearcoat_normal_scale, "scale");
            if (r != RT_OK)
                return r;
        }
    } else if (KEY(k2, "KHR_materials_specular")) {
        snprintf(we, sizeof we, "%s.KHR_materials_specular", wx);
        if ((r = gl_expect_object(d, v2, we)) != RT_OK)
            return r;
        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
            if (KEY(k3, "specularFactor")) r = gl_get_ranged(d, we, "specularFactor", v3, 0, 1, &m->specular_weight);
            else if (KEY(k3, "specularColorFactor"))
                r = get_color_ranged(d, we, "specularColorFactor", v3, 0, big, &m->specular_color);
            else if (KEY(k3, "specularTexture"))
                r = parse_texinfo(d, we, "specularTexture", v3, &m->ext_tex[RT_XTEX_SPECULAR], NULL, NULL);
            else if (KEY(k3, "specularColorTexture"))
                r = parse_texinfo(d, we, "specularColorTexture", v3, &m->ext_tex[RT_XTEX_SPECULAR_COLOR], NULL,
                                  NULL);
            if (r != RT_OK)
                return r;
        }
    } else if (KEY(k2, "KHR_materials_sheen")) {
        snprintf(we, sizeof we, "%s.KHR_materials_sheen", wx);
        if ((r = gl_expect_object(d, v2, we)) != RT_OK)
            return r;
        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
            if (KEY(k3, "sheenColorFactor")) r = get_color_ranged(d, we, "sheenColorFactor", v3, 0, 1, &m->sheen_color);
            else if (KEY(k3, "sheenRoughnessFactor"))
                r = gl_get_ranged(d, we, "sheenRoughnessFactor", v3, 0, 1, &m->sheen_roughness);
            else if (KEY(k3, "sheenColorTexture"))
                r = parse_texinfo(d, we, "sheenColorTexture", v3, &m->ext_tex[RT_XTEX_SHEEN_COLOR], NULL, NULL);
            else if (KEY(k3, "sheenRoughnessTexture"))
                r = parse_texinfo(d, we, "sheenRoughnessTexture", v3, &m->ext_tex[RT_XTEX_SHEEN_ROUGHNESS], NULL,
                                  NULL);
            if (r != RT_OK)
                return r;
        }
    } else if (KEY(k2, "KHR_materials_anisotropy")) {
        snprintf(we, sizeof we, "%s.KHR_materials_anisotropy", wx);
        if ((r = gl_expect_object(d, v2, we)) != RT_OK)
            return r;
        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
            if (KEY(k3, "anisotropyStrength")) r = gl_get_ranged(d, we, "anisotropyStrength", v3, 0, 1, &m->anisotropy);
            else if (KEY(k3, "anisotropyRotation"))
                r = gl_get_ranged(d, we, "anisotropyRotation", v3, -big, big, &m->anisotropy_rotation);
            else if (KEY(k3, "anisotropyTexture"))
                r = parse_texinfo(d, we, "anisotropyTexture", v3, &m->ext_tex[RT_XTEX_ANISOTROPY], NULL, NULL);
            if (r != RT_OK)
                return r;
        }
    } else if (KEY(k2, "KHR_materials_iridescence")) {
        snprintf(we, sizeof we, "%s.KHR_materials_iridescence", wx);
        if ((r = gl_expect_object(d, v2, we)) != RT_OK)
            return r;
        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
            if (KEY(k3, "iridescenceFactor")) r = gl_get_ranged(d, we, "iridescenceFactor", v3, 0, 1, &m->iridescence);
            else if (KEY(k3, "iridescenceIor"))
                r = gl_get_ranged(d, we, "iridescenceIor", v3, 1, big, &m->iridescence_ior);
            else if (KEY(k3, "iridescenceThicknessMinimum"))
                r = gl_get_ranged(d, we, "iridescenceThicknessMinimum", v3, 0, big, &m->iridescence_thickness_min);
            else if (KEY(k3, "iridescenceThicknessMaximum"))
                r = gl_get_ranged(d, we, "iridescenceThicknessMaximum", v3, 0, big, &m->iridescence_thickness_max);
            else if (KEY(k3, "iridescenceTexture"))
                r = parse_texinfo(d, we, "iridescenceTexture", v3, &m->ext_tex[RT_XTEX_IRIDESCENCE], NULL, NULL);
            else if (KEY(k3, "iridescenceThicknessTexture"))
                r = parse_texinfo(d, we, "iridescenceThicknessTexture", v3,
                                  &m->ext_tex[RT_XTEX_IRIDESCENCE_THICKNESS], NULL, NULL);
            if (r != RT_OK)
                return r;
        }
    } else if (KEY(k2, "KHR_materials_dispersion")) {
        snprintf(we, sizeof we, "%s.KHR_materials_dispersion", wx);
        if ((r = gl_expect_object(d, v2, we)) != RT_OK)
            return r;
        int s = rt_json_get(&d->j, v2, "dispersion");
        if (s >= 0)
            r = gl_get_ranged(d, we, "dispersion", s, 0, big, &m->dispersion);
        if (r != RT_OK)
            return r;
    } else if (KEY(k2, "KHR_materials_diffuse_transmission")) {
        snprintf(we, sizeof we, "%s.KHR_materials_diffuse_transmission", wx);
        if ((r = gl_expect_object(d, v2, we)) != RT_OK)
            return r;
        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
            if (KEY(k3, "diffuseTransmissionFactor"))
                r = gl_get_ranged(d, we, "diffuseTransmissionFactor", v3, 0, 1, &m->diffuse_transmission);
            else if (KEY(k3, "diffuseTransmissionColorFactor"))
                r = get_color_ranged(d, we, "diffuseTransmissionColorFactor", v3, 0, 1,
                                     &m->diffuse_transmission_color);
            else if (KEY(k3, "diffuseTransmissionTexture"))
                r = parse_texinfo(d, we, "diffuseTransmissionTexture", v3,
                                  &m->ext_tex[RT_XTEX_DIFFUSE_TRANSMISSION], NULL, NULL);
            else if (KEY(k3, "diffuseTransmissionColorTexture"))
                r = parse_texinfo(d, we, "diffuseTransmissionColorTexture", v3,
                                  &m->ext_tex[RT_XTEX_DIFFUSE_TRANSMISSION_COLOR], NULL, NULL);
            if (r != RT_OK)
                return r;
        }
    } else {
        *known = false;
    }
    return RT_OK;
}

/* A material's pbrMetallicRoughness object (where: "materials[i]"). */
static rt_result parse_pbr(gl_doc *d, const char *where, int v, rt_material *m)
{
    rt_result r = RT_OK;
    char wp[80];
    snprintf(wp, sizeof wp, "%s.pbrMetallicRoughness", where);
    if ((r = gl_expect_object(d, v, wp)) != RT_OK)
        return r;
    for (int k2_n = 0, k2 = v + 1, v2 = v + 2; k2_n < d->j.tok[v].size && v2 < d->j.count;
         k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
        if (KEY(k2, "baseColorFactor")) {
            float c[4];
            if ((r = gl_get_floats_ranged(d, wp, "baseColorFactor", v2, 4, 0, 1, c)) != RT_OK)
                return r;
            m->color = rt_v3(c[0], c[1], c[2]);
            m->alpha = c[3];
        } else if (KEY(k2, "metallicFactor")) r = gl_get_ranged(d, wp, "metallicFactor", v2, 0, 1, &m->metallic);
        else if (KEY(k2, "roughnessFactor")) r = gl_get_ranged(d, wp, "roughnessFactor", v2, 0, 1, &m->roughness);
        else if (KEY(k2, "baseColorTexture"))
            r = parse_texinfo(d, wp, "baseColorTexture", v2, &m->base_color_tex, NULL, NULL);
        else if (KEY(k2, "metallicRoughnessTexture"))
            r = parse_texinfo(d, wp, "metallicRoughnessTexture", v2, &m->metal_rough_tex, NULL, NULL);
        if (r != RT_OK)
            return r;
    }
    return RT_OK;
}

/* The extensions glTF materials had first: KHR_materials_emissive_strength,
 * transmission, ior, volume (and the draft volume_scatter) and unlit; any
 * other key k2 is ignored. */
static rt_result parse_core_ext(gl_doc *d, const char *wx, int k2, int v2, rt_material *m)
{
    rt_result r = RT_OK;
    char we[160];
    if (KEY(k2, "KHR_materials_emissive_strength")) {
        snprintf(we, sizeof we, "%s.KHR_materials_emissive_strength", wx);
        if ((r = gl_expect_object(d, v2, we)) != RT_OK)
            return r;
        int s = rt_json_get(&d->j, v2, "emissiveStrength");
        if (s >= 0)
            r = gl_get_ranged(d, we, "emissiveStrength", s, 0, GL_BIG, &m->emission_strength);
        if (r != RT_OK)
            return r;
    } else if (KEY(k2, "KHR_materials_transmission")) {
        snprintf(we, sizeof we, "%s.KHR_materials_transmission", wx);
        if ((r = gl_expect_object(d, v2, we)) != RT_OK)
            return r;
        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
            if (KEY(k3, "transmissionFactor"))
                r = gl_get_ranged(d, we, "transmissionFactor", v3, 0, 1, &m->transmission);
            else if (KEY(k3, "transmissionTexture"))
                r = parse_texinfo(d, we, "transmissionTexture", v3, &m->transmission_tex, NULL, NULL);
            if (r != RT_OK)
                return r;
        }
    } else if (KEY(k2, "KHR_materials_ior")) {
        snprintf(we, sizeof we, "%s.KHR_materials_ior", wx);
        if ((r = gl_expect_object(d, v2, we)) != RT_OK)
            return r;
        int s = rt_json_get(&d->j, v2, "ior");
        if (s >= 0)
            r = gl_get_ranged(d, we, "ior", s, 0, GL_BIG, &m->ior);
        if (r != RT_OK)
            return r;
        if (m->ior > 0 && m->ior < 1) /* the schema: 0 (a limit the renderer may treat as 1) or at least 1 */
            return gl_fail_at(d, s, RT_ERR_INVALID, "%s.ior %g is neither 0 nor at least 1", we, (double)m->ior);
    } else if (KEY(k2, "KHR_materials_volume")) {
        snprintf(we, sizeof we, "%s.KHR_materials_volume", wx);
        if ((r = gl_expect_object(d, v2, we)) != RT_OK)
            return r;
        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
            if (KEY(k3, "thicknessFactor"))
                r = gl_get_ranged(d, we, "thicknessFactor", v3, 0, GL_BIG, &m->thickness);
            else if (KEY(k3, "attenuationDistance"))
                r = gl_get_float(d, we, "attenuationDistance", v3, &m->attenuation_distance);
            else if (KEY(k3, "attenuationColor")) {
                float c[3];
                if ((r = gl_get_floats_ranged(d, we, "attenuationColor", v3, 3, 0, 1, c)) != RT_OK)
                    return r;
                m->attenuation_color = rt_v3(c[0], c[1], c[2]);
            }
            if (r != RT_OK)
                return r;
        }
        if (!(m->attenuation_distance > 0))
            return gl_fail_at(d, v2, RT_ERR_INVALID, "%s.attenuationDistance must be positive", we);
    } else if (KEY(k2, "KHR_materials_volume_scatter")) {
        /* the draft (KhronosGroup/glTF pull request 2453): the multiple-
         * scattering albedo and the anisotropy of a medium whose extinction
         * is KHR_materials_volume's attenuation (rt/scene/subsurface.h) */
        snprintf(we, sizeof we, "%s.KHR_materials_volume_scatter", wx);
        if ((r = gl_expect_object(d, v2, we)) != RT_OK)
            return r;
        m->subsurface = true;
        m->subsurface_albedo = rt_v3s(0.0f);
        for (int k3_n = 0, k3 = v2 + 1, v3 = v2 + 2; k3_n < d->j.tok[v2].size && v3 < d->j.count;
             k3_n++, k3 = rt_json_skip(&d->j, v3), v3 = k3 + 1) {
            if (KEY(k3, "multiscatterColor"))
                r = get_color_ranged(d, we, "multiscatterColor", v3, 0, 1, &m->subsurface_albedo);
            else if (KEY(k3, "scatterAnisotropy"))
                r = gl_get_ranged(d, we, "scatterAnisotropy", v3, -1, 1, &m->subsurface_g);
            if (r != RT_OK)
                return r;
        }
    } else if (KEY(k2, "KHR_materials_unlit")) {
        m->unlit = true;
    }
    return RT_OK;
}

/* A material's extensions object: the newer extensions (parse_material_ext),
 * then the first ones (parse_core_ext); others are ignored. */
static rt_result parse_extensions(gl_doc *d, const char *where, int v, rt_material *m)
{
    rt_result r;
    char wx[96];
    snprintf(wx, sizeof wx, "%s.extensions", where);
    if ((r = gl_expect_object(d, v, wx)) != RT_OK)
        return r;
    for (int k2_n = 0, k2 = v + 1, v2 = v + 2; k2_n < d->j.tok[v].size && v2 < d->j.count;
         k2_n++, k2 = rt_json_skip(&d->j, v2), v2 = k2 + 1) {
        bool known;
        if ((r = parse_material_ext(d, wx, k2, v2, m, &known)) != RT_OK)
            return r;
        if (known)
            continue;
        if ((r = parse_core_ext(d, wx, k2, v2, m)) != RT_OK)
            return r;
    }
    return RT_OK;
}

rt_result gl_parse_materials(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = gl_alloc_table(d, t, "materials", sizeof(gl_material), (void **)&d->materials,
                            &d->material_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "materials[%d]", i);
        gl_material *gm = &d->materials[i];
        rt_material *m = &gm->m;
        gm->tok = e;
        char name[64];
        snprintf(name, sizeof name, "material%d", i);
        rt_material_default(m, name);
        m->color = rt_v3s(1);
        m->metallic = 1;
        m->roughness = 1;
        m->double_sided = false;
        m->transmission_color = rt_v3s(1);
        if ((r = gl_expect_object(d, e, where)) != RT_OK)
            return r;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "name")) {
                if (rt_json_string(&d->j, v, m->name, sizeof m->name) < 0) /* long names: keep the default */
                    snprintf(m->name, sizeof m->name, "%s", name);
            } else if (KEY(k, "pbrMetallicRoughness")) {
                if ((r = parse_pbr(d, where, v, m)) != RT_OK)
                    return r;
            } else if (KEY(k, "normalTexture")) {
                if ((r = parse_texinfo(d, where, "normalTexture", v, &m->normal_tex, &m->normal_scale,
                                       "scale")) != RT_OK)
                    return r;
            } else if (KEY(k, "occlusionTexture")) {
                if ((r = parse_texinfo(d, where, "occlusionTexture", v, &m->occlusion_tex, &m->occlusion_strength,
                                       "strength")) != RT_OK)
                    return r;
            } else if (KEY(k, "emissiveTexture")) {
                if ((r = parse_texinfo(d, where, "emissiveTexture", v, &m->emissive_tex, NULL, NULL)) != RT_OK)
                    return r;
            } else if (KEY(k, "emissiveFactor")) {
                float c[3];
                if ((r = gl_get_floats_ranged(d, where, "emissiveFactor", v, 3, 0, 1, c)) != RT_OK)
                    return r;
                m->emission = rt_v3(c[0], c[1], c[2]);
            } else if (KEY(k, "alphaMode")) {
                char mode[16];
                if ((r = gl_get_string(d, where, "alphaMode", v, mode, sizeof mode)) != RT_OK)
                    return r;
                if (strcmp(mode, "OPAQUE") == 0) m->alpha_mode = RT_ALPHA_OPAQUE;
                else if (strcmp(mode, "MASK") == 0) m->alpha_mode = RT_ALPHA_MASK;
                else if (strcmp(mode, "BLEND") == 0) m->alpha_mode = RT_ALPHA_BLEND;
                else
                    return gl_fail_at(d, v, RT_ERR_INVALID, "%s.alphaMode \"%s\" is not OPAQUE, MASK or BLEND", where,
                                      mode);
            } else if (KEY(k, "alphaCutoff")) {
                if ((r = gl_get_ranged(d, where, "alphaCutoff", v, 0, GL_BIG, &m->alpha_cutoff)) != RT_OK)
                    return r;
            } else if (KEY(k, "doubleSided")) {
                if ((r = gl_get_bool(d, where, "doubleSided", v, &m->double_sided)) != RT_OK)
                    return r;
            } else if (KEY(k, "extras")) {
                /* extras are free-form: only an object with "bsdf": "lambertian"
                 * means something to rt (a pure Lambertian surface, as the
                 * shared reference scenes use); anything else is ignored */
                int b = rt_json_get(&d->j, v, "bsdf");
                char bsdf[16];
                if (b >= 0 && rt_json_string(&d->j, b, bsdf, sizeof bsdf) >= 0 && strcmp(bsdf, "lambertian") == 0)
                    m->bsdf = RT_BSDF_LAMBERT;
            } else if (KEY(k, "extensions")) {
                if ((r = parse_extensions(d, where, v, m)) != RT_OK)
                    return r;
            }
        }
        /* transmitted light is tinted by the base colour (KHR_materials_transmission) */
        m->transmission_color = m->color;
        /* KHR_materials_volume: thickness 0 (or no volume) is thin-walled */
        m->thin_walled = !(m->thickness > 0.0f);
        m->extended = rt_material_extended(m);
        gl_derive_phong(m);
    }
    return RT_OK;
}

rt_result gl_parse_textures(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = gl_alloc_table(d, t, "textures", sizeof(gl_texture), (void **)&d->textures, &d->texture_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "textures[%d]", i);
        gl_texture *tx = &d->textures[i];
        tx->tok = e;
        tx->source = tx->sampler = RT_NONE;
        if ((r = gl_expect_object(d, e, where)) != RT_OK)
            return r;
        uint32_t webp = RT_NONE;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "source")) r = gl_get_index(d, where, "source", v, &tx->source);
            else if (KEY(k, "sampler")) r = gl_get_index(d, where, "sampler", v, &tx->sampler);
            else if (KEY(k, "extensions")) {
                int ew = rt_json_get(&d->j, v, "EXT_texture_webp");
                int src = ew >= 0 ? rt_json_get(&d->j, ew, "source") : -1;
                if (src >= 0)
                    r = gl_get_index(d, where, "extensions.EXT_texture_webp.source", src, &webp);
                if (r != RT_OK)
                    return r;
                tx->other_source = tx->other_source || rt_json_get(&d->j, v, "KHR_texture_basisu") >= 0 ||
                                   rt_json_get(&d->j, v, "MSFT_texture_dds") >= 0;
            }
            if (r != RT_OK)
                return r;
        }
        if (webp != RT_NONE) /* EXT_texture_webp: the WebP image replaces the fallback source */
            tx->source = webp;
    }
    return RT_OK;
}

rt_result gl_parse_samplers(gl_doc *d, int t)
{
    rt_result r = RT_OK;
    if ((r = gl_alloc_table(d, t, "samplers", sizeof(gl_sampler), (void **)&d->samplers, &d->sampler_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "samplers[%d]", i);
        gl_sampler *sm = &d->samplers[i];
        sm->tok = e;
        sm->wrap_s = sm->wrap_t = 10497;
        if ((r = gl_expect_object(d, e, where)) != RT_OK)
            return r;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "magFilter")) r = gl_get_int(d, where, "magFilter", v, &sm->mag);
            else if (KEY(k, "minFilter")) r = gl_get_int(d, where, "minFilter", v, &sm->min);
            else if (KEY(k, "wrapS")) r = gl_get_int(d, where, "wrapS", v, &sm->wrap_s);
            else if (KEY(k, "wrapT")) r = gl_get_int(d, where, "wrapT", v, &sm->wrap_t);
            if (r != RT_OK)
                return r;
        }
        int w[2] = {sm->wrap_s, sm->wrap_t};
        for (int k = 0; k < 2; k++)
            if (w[k] != 33071 && w[k] != 33648 && w[k] != 10497)
                return gl_fail_at(d, e, RT_ERR_INVALID, "%s: wrap mode %d is not 33071, 33648 or 10497", where, w[k]);
        if (sm->mag != 0 && sm->mag != 9728 && sm->mag != 9729)
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: magFilter %d is not 9728 or 9729", where, sm->mag);
        if (sm->min != 0 && !(sm->min == 9728 || sm->min == 9729 || (sm->min >= 9984 && sm->min <= 9987)))
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: minFilter %d is not 9728, 9729 or 9984 to 9987", where,
                              sm->min);
    }
    return RT_OK;
}

rt_result gl_parse_images(gl_doc *d, int t)
{
    rt_result r;
    if ((r = gl_alloc_table(d, t, "images", sizeof(gl_image), (void **)&d->images, &d->image_count)) != RT_OK)
        return r;
    for (int i = 0, e = t + 1; i < d->j.tok[t].size && e < d->j.count; i++, e = rt_json_skip(&d->j, e)) {
        char where[48];
        snprintf(where, sizeof where, "images[%d]", i);
        gl_image *im = &d->images[i];
        im->tok = e;
        im->uri = -1;
        im->view = RT_NONE;
        if ((r = gl_expect_object(d, e, where)) != RT_OK)
            return r;
        for (int k_n = 0, k = e + 1, v = e + 2; k_n < d->j.tok[e].size && v < d->j.count;
             k_n++, k = rt_json_skip(&d->j, v), v = k + 1) {
            if (KEY(k, "uri")) {
                if (jtype(d, v) != RT_JSON_STRING)
                    return gl_fail_at(d, v, RT_ERR_INVALID, "%s.uri: expected a string", where);
                im->uri = v;
            } else if (KEY(k, "bufferView")) {
                if ((r = gl_get_index(d, where, "bufferView", v, &im->view)) != RT_OK)
                    return r;
            }
        }
        if ((im->uri < 0) == (im->view == RT_NONE))
            return gl_fail_at(d, e, RT_ERR_INVALID, "%s: needs exactly one of uri and bufferView", where);
    }
    return RT_OK;
}

/* Image ii into the scene. An external file that does not exist is a
 * warning naming the image's JSON path, and *missing (then *out is
 * RT_NONE); any other failure is an error. */
static rt_result load_image(gl_doc *d, rt_scene *s, uint32_t ii, uint32_t *out, bool *missing)
{
    *missing = false;
    if (d->image_map[ii] != RT_NONE) {
        *out = d->image_map[ii];
        return RT_OK;
    }
    const gl_image *im = &d->images[ii];
    char what[48];
    snprintf(what, sizeof what, "images[%u]", ii);
    rt_error inner = {0};
    rt_result r = RT_OK;
    uint32_t img = RT_NONE;
    char label[300];
    if (im->view != RT_NONE) {
        const gl_view *v = &d->views[im->view];
        snprintf(label, sizeof label, "bufferView %u", im->view);
        char name[300];
        snprintf(name, sizeof name, "%.250s#image%u", d->path, ii);
        r = rt_image_load_memory(s, gl_view_ptr(d, im->view, 0), v->length, name, &img, &inner);
    } else {
        char *uri;
        if ((r = gl_token_string(d, im->uri, what, &uri)) != RT_OK)
            return r;
        snprintf(label, sizeof label, "\"%.200s%s\"", uri, strlen(uri) > 200 ? "..." : "");
        if (strncmp(uri, "data:", 5) == 0) {
            uint8_t *bytes = NULL;
            size_t n = 0;
            snprintf(label, sizeof label, "data: URI");
            r = gl_decode_data_uri(d, im->uri, uri, strlen(uri), what, &bytes, &n);
            if (r == RT_OK) {
                char name[300];
                snprintf(name, sizeof name, "%.250s#image%u", d->path, ii);
                r = rt_image_load_memory(s, bytes, n, name, &img, &inner);
            } else {
                inner = *d->err;
            }
            free(bytes);
        } else {
            char *path = NULL;
            r = gl_uri_to_path(d, im->uri, uri, what, &path);
            if (r == RT_OK)
                r = rt_image_load_file(s, path, &img, &inner);
            else
                inner = *d->err;
            if (r != RT_OK && path && rt_image_file_missing(path)) {
                rt_warn("%s: %s (%s): image '%s' not found; %s", d->path, what, label, path,
                        RT_MISSING_TEXTURE_NOTE);
                *missing = true;
                *out = RT_NONE;
                r = RT_OK;
            }
            free(path);
            if (*missing) {
                free(uri);
                return RT_OK;
            }
        }
        free(uri);
    }
    if (r != RT_OK) {
        if (strncmp(inner.message, d->path, strlen(d->path)) == 0)
            return rt_fail(d->err, r, "%s", inner.message); /* already names the file and the image */
        return gl_fail_at(d, im->tok, r, "%s (%s): %s", what, label, inner.message);
    }
    d->image_map[ii] = img;
    *out = img;
    return RT_OK;
}

rt_result gl_load_textures(gl_doc *d, rt_scene *s, rt_gltf_stats *st)
{
    rt_result r;
    d->image_map = rt_alloc(d->image_count, sizeof(uint32_t));
    d->texture_map = rt_alloc(d->texture_count, sizeof(uint32_t));
    d->texture_missing = rt_alloc(d->texture_count, sizeof(bool));
    if (!d->image_map || !d->texture_map || !d->texture_missing)
        return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory", d->path);
    for (size_t i = 0; i < d->image_count; i++)
        d->image_map[i] = RT_NONE;
    for (size_t i = 0; i < d->texture_count; i++) {
        const gl_texture *gt = &d->textures[i];
        d->texture_map[i] = RT_NONE;
        d->texture_missing[i] = false;
        if (gt->source == RT_NONE) {
            rt_warn("%s: textures[%zu] has no source rt can read%s; left untextured", d->path, i,
                    gt->other_source ? " (KHR_texture_basisu / KTX2 and DDS images are not supported)" : "");
            continue;
        }
        bool fresh = d->image_map[gt->source] == RT_NONE, missing;
        uint32_t img = RT_NONE;
        if ((r = load_image(d, s, gt->source, &img, &missing)) != RT_OK)
            return r;
        if (fresh && !missing)
            st->images++;
        d->texture_missing[i] = missing;
        rt_texture tex = missing ? rt_texture_missing() : rt_texture_image(img);
        if (gt->sampler != RT_NONE) {
            const gl_sampler *sm = &d->samplers[gt->sampler];
            int w[2] = {sm->wrap_s, sm->wrap_t};
            rt_wrap wrap[2];
            for (int k = 0; k < 2; k++)
                wrap[k] = w[k] == 33071 ? RT_WRAP_CLAMP : w[k] == 33648 ? RT_WRAP_MIRROR : RT_WRAP_REPEAT;
            tex.wrap_s = wrap[0];
            tex.wrap_t = wrap[1];
            tex.filter = sm->mag == 9728 ? RT_FILTER_NEAREST : RT_FILTER_BILINEAR;
        }
        uint32_t ti = rt_scene_add_texture(s, &tex);
        if (ti == RT_NONE)
            return rt_fail(d->err, RT_ERR_NOMEM, "%s: out of memory adding textures", d->path);
        d->texture_map[i] = ti;
        st->textures++;
    }
    return RT_OK;
}
