/* progress.h - the driver's view of a running render (driver-private): a
 * progress bar on stderr and a live preview image of the finished tiles.
 *
 *   progress_view view;
 *   progress_view_init(&view, isatty(2), preview ? output : NULL, preview_seconds, exposure);
 *   rt_render_options ro = {0};
 *   ro.progress = progress_report;              // the bar and the preview, as due
 *   ro.progress_user = &view;
 */
#ifndef RT_DRIVER_PROGRESS_H
#define RT_DRIVER_PROGRESS_H

#include <stdbool.h>

#include "rt/render/render.h"

typedef struct progress_view {
    bool bar;                 /* draw the progress bar on stderr */
    const char *preview_path; /* rewrite this image with the finished tiles; NULL = no preview */
    double preview_seconds;   /* ... this often (0 = 2 s) */
    float exposure;           /* the scene's, for PNG previews */
    double last_preview;      /* elapsed seconds at the last preview */
    rt_write_temp *temp;      /* the preview write's temporary file, for the signal handler; may be NULL */
} progress_view;

void progress_view_init(progress_view *v, bool bar, const char *preview_path, double preview_seconds,
                        float exposure);

/* rt_render_options.progress for a progress_view (the user pointer). */
void progress_report(const rt_render_progress *p, void *view);

#endif
