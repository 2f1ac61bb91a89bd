/* library.c - rt as a library, through its installed headers alone: load a
 * scene or model, validate it, build the kd-tree, render on every core and
 * write the image; then the same render as two parts of similar cost (as
 * two machines of a farm would render them, docs/farm.md), each written as
 * a part file, and the parts merged back into the image, which is the
 * single render's, byte for byte. The `rt` command (src/driver/) is the
 * same library with flags, signals, a progress bar and a window around it.
 *
 *   make install PREFIX=$HOME/.local
 *   cc -std=c11 library.c $(pkg-config --cflags --libs rtrender) -o render
 *   ./render bunny.obj bunny.png   # also bunny.png.part0.exr, .part1.exr (+ .json) and bunny.png.merged.pfm
 *   ./render                       # the built-in Cornell box to out.png
 */
#include <stdio.h>
#include <string.h>

#include "rt/accel/kdtree.h"
#include "rt/io/image_write.h"
#include "rt/io/load.h"
#include "rt/job/merge.h"
#include "rt/job/options.h"
#include "rt/job/part_job.h"
#include "rt/job/slices.h"
#include "rt/render/render.h"
#include "rt/scene/validate.h"

/* Part `index` of `count` bands of rows of the render, written to path
 * (a float image of the band's sums, and path.json saying what it is a
 * part of). */
static rt_result render_part(const rt_scene *scene, const rt_kdtree *tree, const char *input, int index, int count,
                             const char *path, rt_error *err)
{
    rt_job_options o = {.input = input, .part_index = index, .part_count = count, .output_is_part = true};
    rt_part_job pj;
    rt_framebuffer fb = {0};
    rt_result r = rt_part_job_init(&pj, &o, scene, tree, err);
    if (r == RT_OK)
        r = rt_framebuffer_init(&fb, pj.region.x1 - pj.region.x0, pj.region.y1 - pj.region.y0, err);
    if (r == RT_OK) {
        rt_render_options ro = {.region = pj.region, .sample_begin = pj.s_begin, .sample_end = pj.s_end,
                                .accum = &pj.accum,
                                .pass_samples = rt_job_pass_samples(0, true, scene->settings.integrator)};
        rt_render_stats st;
        r = rt_render(scene, tree, &ro, &fb, &st, err);
        if (r == RT_OK)
            r = rt_part_job_write(&pj, path, st.samples_done, NULL, err);
    }
    rt_framebuffer_free(&fb);
    rt_part_job_free(&pj);
    return r;
}

/* The parts at paths[0..n) merged into fb (allocated here). */
static rt_result merge_parts(const char *const *paths, int n, rt_framebuffer *fb, rt_error *err)
{
    rt_merge m;
    rt_result r = rt_merge_init(&m, n, err);
    for (int i = 0; i < n && r == RT_OK; i++)
        r = rt_merge_add(&m, paths[i], err);
    if (r == RT_OK)
        r = rt_framebuffer_init(fb, m.parts[0].info.width, m.parts[0].info.height, err);
    if (r == RT_OK)
        r = rt_merge_image(&m, fb, NULL, err);
    rt_merge_free(&m);
    return r;
}

int main(int argc, char **argv)
{
    const char *input = argc > 1 ? argv[1] : NULL; /* NULL: the built-in scene */
    const char *output = argc > 2 ? argv[2] : "out.png";
    rt_error err = {0};
    rt_scene scene;
    rt_scene_init(&scene);
    rt_load_options lo = {.for_render = true}; /* a bare model gets lights and a camera */
    rt_kdtree tree = {0};
    rt_framebuffer fb = {0}, merged = {0};
    char part[2][1100], merged_path[1100];
    const char *parts[2] = {part[0], part[1]};
    int status = 1;
    if (rt_load(&scene, input, &lo, NULL, &err) != RT_OK || rt_scene_validate(&scene, &err) != RT_OK)
        goto done;
    scene.settings.width = 160;
    scene.settings.height = 120;
    if (!scene.camera_set) /* a mesh brings no camera: frame it */
        rt_scene_frame_camera(&scene);
    if (rt_kdtree_build(&tree, &scene, NULL, &err) != RT_OK)
        goto done;
    if (rt_framebuffer_init(&fb, scene.settings.width, scene.settings.height, &err) != RT_OK ||
        rt_render(&scene, &tree, NULL, &fb, NULL, &err) != RT_OK ||
        rt_framebuffer_write(&fb, output, scene.settings.exposure, &err) != RT_OK)
        goto done;
    printf("wrote %s (%dx%d)\n", output, fb.width, fb.height);

    /* the same image from two parts */
    for (int i = 0; i < 2; i++) {
        snprintf(part[i], sizeof part[i], "%s.part%d.exr", output, i);
        if (render_part(&scene, &tree, input, i, 2, part[i], &err) != RT_OK)
            goto done;
        printf("wrote %s and %s.json\n", part[i], part[i]);
    }
    snprintf(merged_path, sizeof merged_path, "%s.merged.pfm", output);
    if (merge_parts(parts, 2, &merged, &err) != RT_OK ||
        rt_framebuffer_write(&merged, merged_path, 1.0f, &err) != RT_OK)
        goto done;
    bool same = memcmp(merged.rgb, fb.rgb, (size_t)fb.width * (size_t)fb.height * 3 * sizeof *fb.rgb) == 0;
    printf("wrote %s: the parts merged, %s the single render\n", merged_path, same ? "identical to" : "NOT");
    status = same ? 0 : 1;
    if (!same)
        snprintf(err.message, sizeof err.message, "the merged parts differ from the single render");
done:
    if (status)
        fprintf(stderr, "render: %s\n", err.message);
    rt_framebuffer_free(&merged);
    rt_framebuffer_free(&fb);
    rt_kdtree_free(&tree);
    rt_scene_free(&scene);
    return status;
}
