/* window.h - the --window view (driver-private): an SDL2 window showing
 * the image as it renders, 8-bit sRGB with the scene's exposure, the very
 * values the PNG gets.
 *
 *   window_view w;
 *   char why[256];
 *   if (!window_open(&w, width, height, "rt: out.png", why, sizeof why))
 *       ... "--window: cannot open a window: <why>" ...
 *   window_show_rect(&w, fb, exposure, x0, y0, x1, y1);  // pixels that are final
 *   window_present(&w);                                  // draws; handles events
 *   window_wait(&w, &stop);                              // after the render: until closed (or stop)
 *   window_close(&w);
 *
 * rt builds without SDL2 (the Makefile compiles this with RT_HAVE_SDL2
 * only when pkg-config finds sdl2); window_open then says so. All calls
 * come from the main thread, as SDL wants.
 *
 * For tests, RT_WINDOW_SCREENSHOT=FILE makes window_wait read back what
 * the window shows into FILE (binary PPM) and return at once.
 */
#ifndef RT_DRIVER_WINDOW_H
#define RT_DRIVER_WINDOW_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>

#include "rt/io/framebuffer.h"

typedef struct window_view {
    void *window, *renderer, *texture; /* SDL objects */
    unsigned char *rgb;                /* the shown image, 8-bit sRGB, 3 bytes a pixel */
    int width, height;
    bool open;                         /* false once the user closed it */
} window_view;

bool window_open(window_view *w, int width, int height, const char *title, char *why, size_t why_size);
/* Tone-maps fb's pixels [x0, x1) x [y0, y1) into the shown image. */
void window_show_rect(window_view *w, const rt_framebuffer *fb, float exposure, int x0, int y0, int x1, int y1);
/* Puts the shown image on screen and handles pending events. */
void window_present(window_view *w);
/* Keeps the window up until the user closes it (Esc, q, or the close
 * button) or *stop becomes non-zero (Ctrl-C). */
void window_wait(window_view *w, const atomic_int *stop);
void window_close(window_view *w);

#endif
