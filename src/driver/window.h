/* window.h - the --window view (driver-private): an SDL2 window showing
 * the image as it renders, 8-bit sRGB through the output's exposure and
 * tone curve, the very values the PNG gets, and an interactive camera.
 *
 *   window_view w;
 *   char why[256];
 *   if (!window_open(&w, width, height, "rt: out.png", why, sizeof why))
 *       ... "--window: cannot open a window: <why>" ...
 *   w.exposure = 1.0f; w.tonemap = RT_TONEMAP_CLAMP;     // the output's
 *   window_set_camera(&w, &scene.camera, step, pivot);   // enables the camera keys and mouse
 *   window_show_rect(&w, fb, x0, y0, x1, y1);            // pixels that are final
 *   window_present(&w);                                  // draws; handles events
 *   unsigned what = window_take_requests(&w);            // WINDOW_CAMERA: w.camera moved, ...
 *   window_wait(&w, &stop);                              // until closed, a request, or stop
 *   window_close(&w);
 *
 * The input (docs/watching.md has the table): left drag orbits about
 * look_at (or, for a camera whose look_at means nothing, a glTF camera's
 * point 1 unit ahead, about the point at `pivot` along the view: the
 * model's depth), right or middle drag (or shift + left) pans, the wheel
 * dollies, W A S D walk, E and C rise and sink, R goes back to the first
 * camera, [ and ] change the view's exposure by 1/3 stop (0 resets it),
 * F12 or Ctrl+S ask for a snapshot, P for the camera line, Esc, Q or the
 * close button close the window. The window only moves its own `camera`
 * and raises request bits; the driver (viewer.c) acts on them.
 *
 * rt builds without SDL2 (the Makefile compiles this with RT_HAVE_SDL2
 * only when pkg-config finds sdl2); window_open then says so. All calls
 * come from the main thread, as SDL wants.
 *
 * For tests: RT_WINDOW_SCREENSHOT=FILE makes window_wait read back what
 * the window shows into FILE (binary PPM) and close the window;
 * RT_WINDOW_SCRIPT="step; step; ..." feeds the window synthetic input
 * through SDL's own event queue, one step after the other:
 *   wait done                      until the render at the current camera has finished
 *   wait pass                      until a new pass (or tile) has been shown
 *   sleep MS                       MS milliseconds (the window idle)
 *   drag left|right|middle X0 Y0 X1 Y1   press, move, release (image pixels)
 *   wheel N                        N wheel notches (> 0: away from the user)
 *   key NAME                       a key press, SDL's key name (P, F12, Escape, [)
 * A malformed script makes window_open fail naming the step.
 */
#ifndef RT_DRIVER_WINDOW_H
#define RT_DRIVER_WINDOW_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>

#include "rt/image/tonemap.h"
#include "rt/image/framebuffer.h"
#include "rt/scene/scene.h"

/* What the user asked for since the driver last looked. */
enum {
    WINDOW_CAMERA = 1u,   /* `camera` moved: restart the render */
    WINDOW_SAVE = 2u,     /* write the image as it is now */
    WINDOW_PRINT = 4u,    /* print the camera as a scene-file line */
    WINDOW_EXPOSURE = 8u, /* the view's exposure changed: show the image again */
};

#define WINDOW_SCRIPT_MAX 64

typedef struct window_step {
    char kind;        /* 'd' wait done, 'p' wait pass, 's' sleep, 'g' drag, 'w' wheel, 'k' key */
    int button;       /* drag: SDL button number */
    int v[4];         /* drag: x0 y0 x1 y1; wheel: notches; sleep: milliseconds */
    int key;          /* key: SDL keycode */
} window_step;

typedef struct window_view {
    void *window, *renderer, *texture; /* SDL objects */
    unsigned char *rgb;                /* the shown image, 8-bit sRGB, 3 bytes a pixel */
    int width, height;
    bool open;                         /* false once the user closed it */
    float exposure;                    /* linear, the output's (scene exposure x 2^--exposure) */
    rt_tonemap tonemap;                /* the output's tone curve */
    float view_ev;                     /* the view's own exposure offset, stops ([ and ]) */
    /* the interactive camera (enabled by window_set_camera) */
    bool interactive;
    rt_camera camera, home;            /* the view asked for; the first one (R) */
    float step;                        /* W A S D E C step, scene units */
    float pivot, home_pivot;           /* > 0: moves start with look_at at this distance along the view
                                        * (the model's depth), for `camera` and for `home` */
    int drag;                          /* 0, or 'o' orbit / 'p' pan while a button is held */
    unsigned requests;                 /* WINDOW_* bits */
    /* what the driver tells the test script */
    bool render_done;                  /* the render at `camera` has finished */
    int shown;                         /* passes or tiles shown so far */
    /* RT_WINDOW_SCRIPT */
    window_step script[WINDOW_SCRIPT_MAX];
    int script_len, script_at, script_mark;
    unsigned script_since;             /* SDL ticks at the step's start */
    bool script_armed;
} window_view;

bool window_open(window_view *w, int width, int height, const char *title, char *why, size_t why_size);
/* Enables the camera input, starting from *c; step: the walking step;
 * pivot: 0, or the distance along the view to orbit about (and to pan and
 * dolly at) instead of look_at's, which then means nothing. */
void window_set_camera(window_view *w, const rt_camera *c, float step, float pivot);
/* Tone-maps fb's pixels [x0, x1) x [y0, y1) into the shown image. */
void window_show_rect(window_view *w, const rt_framebuffer *fb, int x0, int y0, int x1, int y1);
/* Puts the shown image on screen and handles pending events. */
void window_present(window_view *w);
/* The WINDOW_* bits raised since the last call, cleared. */
unsigned window_take_requests(window_view *w);
/* Keeps the window up until the user closes it (Esc, Q or the close
 * button), a request is raised, or *stop becomes non-zero (Ctrl-C). */
void window_wait(window_view *w, const atomic_int *stop);
void window_close(window_view *w);

#endif
