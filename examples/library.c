/* library.c - rt as a library: load a scene or model, validate it, build the
 * kd-tree, render on every core and write the image, in the fewest calls.
 * The `rt` command (src/driver/main.c) is the same pipeline with flags,
 * limits, signals and a progress bar around it.
 *
 *   make install PREFIX=$HOME/.local
 *   cc -std=c11 library.c $(pkg-config --cflags --libs rtrender) -o render
 *   ./render bunny.obj bunny.png        # no arguments: the built-in Cornell box to out.png
 */
#include <stdio.h>

#include "rt/accel/kdtree.h"
#include "rt/io/image_write.h"
#include "rt/io/load.h"
#include "rt/render/render.h"
#include "rt/scene/validate.h"

int main(int argc, char **argv)
{
    const char *input = argc > 1 ? argv[1] : NULL; /* NULL: the built-in scene */
    const char *output = argc > 2 ? argv[2] : "out.png";
    rt_error err = {0};
    rt_scene scene;
    rt_scene_init(&scene);
    rt_load_options lo = {.for_render = true}; /* a bare model gets lights and a camera */
    rt_kdtree tree = {0};
    rt_framebuffer fb = {0};
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
    status = 0;
done:
    if (status)
        fprintf(stderr, "render: %s\n", err.message);
    rt_framebuffer_free(&fb);
    rt_kdtree_free(&tree);
    rt_scene_free(&scene);
    return status;
}
