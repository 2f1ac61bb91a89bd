/* test_scenes.h - scene texts more than one test renders.
 *
 * TEST_EVERY_MATERIAL_SCENE: every material kind and light kind of the
 * path tracer in one small scene (textures, metals, rough and smooth
 * glass, alpha blend and mask, an emissive triangle, unlit, thin-walled
 * panes (one blended) under the area light, a compensated
 * anisotropic conductor, a liquid nested in a glass flask, point, spot,
 * directional and area lights) without its integrator, resolution and
 * samples, which each test puts in front:
 *
 *   static const char *scene = "integrator path\nresolution 24 16\nsamples 6\nbackground 0.2 0.3 0.4\n" TEST_EVERY_MATERIAL_SCENE;
 */
#ifndef RT_TEST_SCENES_H
#define RT_TEST_SCENES_H

#define TEST_EVERY_MATERIAL_SCENE \
    "camera position 0 1.5 6 look_at 0 0.8 0 fov 40\n" \
    "texture checks checker 0.9 0.9 0.9  0.1 0.1 0.1 scale 4\n" \
    "material floor texture checks roughness 0.6\n" \
    "material metal color 0.9 0.6 0.2 metallic 1 roughness 0.05\n" \
    "material rough color 0.9 0.9 0.9 metallic 1 roughness 1\n" \
    "material plastic color 0.2 0.4 0.9 roughness 0.3\n" \
    "material glass color 1 1 1 transmission 1 ior 1.5 roughness 0\n" \
    "material veil color 1 0 0 alpha 0.5 alpha_mode blend\n" \
    "material cut color 0 1 0 alpha 0.2 alpha_mode mask\n" \
    "material lamp color 0 0 0 emission 3 3 2 double_sided false\n" \
    "material flat color 1 1 1 unlit true\n" \
    "material pane color 0.9 0.7 0.5 transmission 1 roughness 0 thin_walled true\n" \
    "material tint color 0.5 0.9 0.5 transmission 0.8 roughness 0 thin_walled true alpha 0.6 alpha_mode blend\n" \
    "energy_compensation on\nmaterial cu bsdf conductor metal Cu ggx_alpha_uv 0.4 0.2\n" \
    "material flask bsdf dielectric ior 1.5 priority 1\n" \
    "material wine bsdf dielectric ior 1.333 priority 2 absorption 1 4 4\n" \
    "sphere -1 1.5 0.5 0.35 cu\nsphere 1 1.5 0.5 0.35 flask\nsphere 1 1.5 0.5 0.3 wine\n" \
    "quad -5 0 5  10 0 0  0 0 -10  floor\n" \
    "sphere -1.5 0.5 0 0.5 metal\nsphere -0.5 0.5 0 0.5 rough\nsphere 0.5 0.5 0 0.5 plastic\n" \
    "sphere 1.5 0.5 0 0.5 glass\nquad -2 0 1  4 0 0  0 2 0  veil\nquad -2 1.2 1.5  4 0 0  0 0.5 0  cut\n" \
    "triangle -1 2 -1  1 2 -1  0 2.5 -1  lamp\nsphere 0 2.2 -2 0.2 flat\n" \
    "quad -1.5 2.7 -1.5  1.5 0 0  0 0 3  pane\nquad 0 2.7 -1.5  1.5 0 0  0 0 3  tint\n" \
    "light point 0 3 2  1 1 1  5\nlight spot 2 3 0  0 -1 0  1 1 1  10  10 30\n" \
    "light directional -1 -1 -1  0.5 0.5 0.5  1\nlight area -1 2.9 -1  2 0 0  0 0 2  2 2 2  1\n"

#endif
