/* rt/job/part_split.h - `--part I/N`: which rows of the image part I of N
 * renders (docs/farm.md, "Parts of similar cost").
 *
 *   rt_render_region band;
 *   if (rt_part_split(&scene, &tree, 2, 7, &band, &err) != RT_OK) ...
 *   ... render options .region = band ...
 */
#ifndef RT_JOB_PART_SPLIT_H
#define RT_JOB_PART_SPLIT_H

#include "rt/accel/kdtree.h"
#include "rt/base/error.h"
#include "rt/render/render.h"
#include "rt/scene/scene.h"

/* Band `index` (0 .. count - 1) of `count` horizontal bands of whole rows
 * of similar estimated cost. Every band has at least one row (count must
 * not exceed the image's height); the bands tile the image. The estimate
 * is a pure function of the scene, the settings and count, so every
 * machine computes the same bands. */
rt_result rt_part_split(const rt_scene *scene, const rt_kdtree *tree, int index, int count, rt_render_region *band,
                     rt_error *err);

#endif
