/* viewer.h - the --window session (driver-private): what the window's
 * requests (window.h) do to a render. A camera move raises the render's
 * cancel flag, so rt_render returns early and the driver renders again at
 * the window's camera from sample 0; closing the window raises it too (the
 * driver then writes the image as it stands, like an interrupted render).
 * P prints the camera as a scene-file `camera` line on stdout; F12 writes
 * the image as the window shows it to the first free NAME.1.EXT,
 * NAME.2.EXT ... beside the output.
 *
 *   viewer s = {.window = &w, .cancel = &stop, .output = "out.png", .image = opt, .temp = &temp,
 *               .samples_total = spp};
 *   progress_view.viewer = &s;              // progress_report calls viewer_poll while rendering
 *   r = rt_render(...);                     // returns early when s.moved or the window closed
 *   if (r == RT_OK && viewer_wait(&s, &fb, spp, &sigflag)) ... the camera moved: render again ...
 */
#ifndef RT_DRIVER_VIEWER_H
#define RT_DRIVER_VIEWER_H

#include <stdatomic.h>
#include <stdbool.h>

#include "rt/io/image_write.h"
#include "rt/render/render.h"

#include "window.h"

typedef struct viewer {
    window_view *window;
    atomic_int *cancel;     /* the render's cancel flag */
    const char *output;     /* the output path: snapshots are named after it */
    rt_image_options image; /* the output's exposure, tone curve and --half (snapshots add the view's exposure) */
    rt_write_temp *temp;    /* for the signal handler; may be NULL */
    int samples_total;      /* the render's samples per pixel, for messages */
    bool moved;             /* the render was cancelled because the camera moved */
} viewer;

/* While rendering, after window_present: acts on the window's requests
 * with the render's progress report p (only final pixels are read). */
void viewer_poll(viewer *v, const rt_render_progress *p);

/* After a render finished with fb at samples_done spp: keeps the window up,
 * answering P, F12 and the exposure keys, until the camera moves (true,
 * v->moved set) or the window closes or *stop is raised (false). */
bool viewer_wait(viewer *v, const rt_framebuffer *fb, int samples_done, const atomic_int *stop);

#endif
