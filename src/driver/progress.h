/* progress.h - the driver's view of a run (driver-private): a progress
 * line on stderr through the phases of a run (loading, kd-tree build,
 * rendering) and a live preview image.
 *
 *   progress_view view;
 *   progress_view_init(&view, isatty(2));
 *   progress_phase(&view, "loading", "scene.gltf");      // each phase as it starts
 *   ... load ...
 *   progress_phase(&view, "kd-tree", NULL);
 *   ... build ...
 *   view.preview_path = output;  view.preview_seconds = 2;  view.exposure = 1;  // optional
 *   rt_render_options ro = {0};
 *   ro.progress = progress_report;              // the bar and the preview, as due
 *   ro.progress_user = &view;
 *   ...
 *   progress_view_free(&view);
 *
 * With view.tev set (tev.h), progress_report also streams the image to tev:
 * finished tiles as they finish, the whole image after each pass, and the
 * final image (connecting again if tev went away); with view.window set
 * (window.h), it shows the same in the window, and with view.viewer set
 * (viewer.h) it acts on what the window's keys and mouse asked for.
 *
 * The render's line names the phases before it with their times, then the
 * bar: tiles, or samples per pixel when rendering in passes, the elapsed
 * time and an estimate of the time left (linear in the work done, so it
 * settles within a few passes; capped by --time-limit).
 */
#ifndef RT_DRIVER_PROGRESS_H
#define RT_DRIVER_PROGRESS_H

#include <stdbool.h>

#include "rt/io/image_write.h"
#include "rt/render/render.h"

#include "tev.h"
#include "window.h"

#define PROGRESS_MAX_PHASES 4

typedef struct progress_view {
    bool bar;                 /* draw the progress line on stderr */
    const char *preview_path; /* rewrite this image with the finished tiles; NULL = no preview */
    double preview_seconds;   /* ... this often (0 = 2 s) */
    float exposure;           /* the scene's, for PNG previews */
    double time_limit;        /* --time-limit, for the estimate; 0 = none */
    double last_preview;      /* elapsed seconds at the last preview */
    int previews;             /* previews written over the output so far */
    rt_write_temp *temp;      /* the preview write's temporary file, for the signal handler; may be NULL */
    const char *phase_name[PROGRESS_MAX_PHASES]; /* the phases before rendering, in order */
    double phase_start[PROGRESS_MAX_PHASES];     /* monotonic seconds */
    double phase_end[PROGRESS_MAX_PHASES];       /* 0 until the render after it first reports */
    int phases;
    tev_stream *tev;          /* --display-server: stream the image there; NULL = none */
    unsigned char *tev_sent;  /* tiles: per tile, sent to tev since it connected */
    int tev_samples;          /* passes: the samples per pixel last sent */
    window_view *window;      /* --window: show the image there; NULL = none */
    unsigned char *win_shown; /* tiles: per tile, shown in the window */
    int win_samples;          /* passes: the samples per pixel shown */
    struct viewer *viewer;    /* --window: the interactive session (viewer.h); NULL = none */
} progress_view;

void progress_view_init(progress_view *v, bool bar);
void progress_view_free(progress_view *v);

/* Starts a phase (ending the one before); detail may be NULL. Shown at
 * once on the progress line, and with its time on the render's line. */
void progress_phase(progress_view *v, const char *name, const char *detail);

/* Before rendering again (the window's camera moved): the image shown
 * and streamed starts over; tiles_total: the render's tile count. */
void progress_restart(progress_view *v, int tiles_total);

/* Clears the progress line (before a message not written through
 * rt/base/log.h, which clears it itself). */
void progress_clear(progress_view *v);

/* rt_render_options.progress for a progress_view (the user pointer). */
void progress_report(const rt_render_progress *p, void *view);

#endif
