/* rt/scene/validate.h - the one check between loading a scene and
 * rendering it: every cross-reference in range and the values the renderer
 * relies on usable, so the render code can trust the tables (it only
 * RT_DCHECKs them).
 *
 *   if (rt_scene_validate(&scene, &err) != RT_OK) {
 *       fprintf(stderr, "rt: %s: %s\n", path, err.message);  // "sphere 3: material 7 is out of range (2 materials)"
 *       ...
 *   }
 *
 * Rules (RT_ERR_INVALID, the message names the record and the problem):
 *   - a scene with primitives has at least one material;
 *   - triangles: vertex indices below the vertex count, material in range,
 *     the tangent and colour flags only where the vertices have those arrays;
 *   - spheres and quads: material in range, finite centre, radius, corner
 *     and edges; vertices: finite positions;
 *   - materials: every texture slot RT_NONE or in range, UV set 0 or 1,
 *     finite colour, emission and emission strength;
 *   - textures: a known kind, an image texture's image in range; images:
 *     a size and pixels;
 *   - lights: a known kind, finite colour, intensity, position, direction
 *     and edges; an area light's quad RT_NONE or in range, and no quad
 *     shared by two area lights; other lights have no quad;
 *   - environment: the environment texture RT_NONE or in range, finite
 *     background and environment strength.
 * The first problem found is reported (RT_ERR_NOMEM only when the quads
 * of area lights cannot be checked for lack of memory). Loaders keep their own located
 * errors (file:line:col); this catches what they cannot see (scenes built
 * in code, merged models) and is the contract the renderer relies on.
 */
#ifndef RT_VALIDATE_H
#define RT_VALIDATE_H

#include "rt/base/error.h"
#include "rt/scene/scene.h"

rt_result rt_scene_validate(const rt_scene *s, rt_error *err);

#endif
