/* viewer.c - the --window session (viewer.h): the window's requests turned
 * into actions on the render. A camera move or a closed window raise the
 * render's cancel flag (rt_render answers within a pixel); P prints
 * rt_camera_format's line (docs/scene-format.md, section 3) and the
 * equivalent pose flags; F12 / Ctrl+S write a snapshot through the same
 * atomic writer as the output (rt_framebuffer_write_tracked) to the first
 * NAME.K.EXT not taken, so no earlier image is ever replaced; the exposure
 * keys tone-map the image again. Only pixels that are final are read while
 * workers run: the whole image between passes, finished tiles otherwise.
 */
#include "viewer.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rt/base/file.h"
#include "rt/base/log.h"
#include "rt/image/tonemap.h"
#include "rt/render/camera_control.h"

static void print_camera(const window_view *w)
{
    char line[700];
    const rt_camera *c = &w->camera;
    rt_camera_format(c, line, sizeof line);
    rt_log_status_clear(); /* the lines start at the terminal's left edge, not after the progress bar */
    printf("%s\n", line);
    printf("# as flags: --look-from %.9g,%.9g,%.9g --look-at %.9g,%.9g,%.9g --up %.9g,%.9g,%.9g --fov %.9g\n",
           (double)c->position.x, (double)c->position.y, (double)c->position.z, (double)c->look_at.x,
           (double)c->look_at.y, (double)c->look_at.z, (double)c->up.x, (double)c->up.y, (double)c->up.z,
           (double)c->vfov_deg);
    if (w->view_ev != 0.0f)
        printf("# the window's view exposure: %+.3g stops (--exposure adds stops to the output's)\n",
               (double)w->view_ev);
    fflush(stdout);
}

/* Writes `copy` (what the window shows, at `what`) to the first free NAME.K.EXT. */
static void write_snapshot(viewer *v, const rt_framebuffer *copy, const char *what)
{
    char path[4200];
    int k = 1;
    for (; k < 10000; k++) {
        char tag[16];
        snprintf(tag, sizeof tag, "%d", k);
        if (!rt_path_tagged(v->output, tag, NULL, path, sizeof path) || access(path, F_OK) != 0)
            break;
    }
    if (k == 10000) {
        rt_warn("window snapshot: %s.1 to .9999 are all taken; nothing written", v->output);
        return;
    }
    rt_image_options opt = v->image;
    opt.exposure = (opt.exposure > 0.0f ? opt.exposure : 1.0f) * rt_exposure_scale(v->window->view_ev);
    opt.layers = NULL;
    opt.layer_count = 0;
    rt_error err = {0};
    if (rt_framebuffer_write_tracked(copy, path, &opt, v->temp, &err) != RT_OK)
        rt_warn("window snapshot: %s", err.message);
    else { /* asked for by a key: said even with -q */
        rt_log_status_clear();
        fprintf(stderr, "rt: wrote %s: %dx%d, %s (window snapshot)\n", path, copy->width, copy->height, what);
    }
}

/* A snapshot while rendering: the finished tiles, or the image of the last pass. */
static void snapshot_during(viewer *v, const rt_render_progress *p)
{
    if (p->passes && p->samples_done == 0) {
        rt_warn("window snapshot: no pass has finished at this camera yet; nothing written");
        return;
    }
    rt_framebuffer copy;
    rt_error err;
    if (rt_framebuffer_init(&copy, p->fb->width, p->fb->height, &err) != RT_OK) {
        rt_warn("window snapshot: %s", err.message);
        return;
    }
    int done = 0;
    for (int i = 0; i < p->tiles_total; i++) {
        rt_tile t = rt_render_progress_tile(p, i);
        if (!t.finished)
            continue;
        done++;
        for (int y = t.y0; y < t.y1; y++) {
            size_t k = 3 * ((size_t)y * (size_t)copy.width + (size_t)t.x0);
            memcpy(copy.rgb + k, p->fb->rgb + k, 3 * sizeof(float) * (size_t)(t.x1 - t.x0));
        }
    }
    char what[96];
    if (p->passes)
        snprintf(what, sizeof what, "%d of %d spp", p->samples_done, p->samples_total);
    else
        snprintf(what, sizeof what, "%d of %d tiles at %d spp", done, p->tiles_total, p->samples_total);
    write_snapshot(v, &copy, what);
    rt_framebuffer_free(&copy);
}

void viewer_poll(viewer *v, const rt_render_progress *p)
{
    window_view *w = v->window;
    if (!w->open) { /* closed: stop the render, which then writes what it has */
        atomic_store(v->cancel, 1);
        return;
    }
    unsigned req = window_take_requests(w);
    if (req & WINDOW_CAMERA) {
        v->moved = true;
        atomic_store(v->cancel, 1);
    }
    if (req & WINDOW_PRINT)
        print_camera(w);
    if ((req & WINDOW_SAVE) && !v->moved)
        snapshot_during(v, p);
    if ((req & WINDOW_EXPOSURE) && !v->moved) {
        for (int i = 0; i < p->tiles_total; i++) {
            rt_tile t = rt_render_progress_tile(p, i);
            if (t.finished)
                window_show_rect(w, p->fb, t.x0, t.y0, t.x1, t.y1);
        }
        window_present(w);
    }
}

bool viewer_wait(viewer *v, const rt_framebuffer *fb, int samples_done, const atomic_int *stop)
{
    window_view *w = v->window;
    if (v->moved) /* a move answered in the render's last report: render again at once */
        return w->open;
    w->render_done = true;
    for (;;) {
        window_wait(w, stop);
        if (!w->open || (stop && atomic_load(stop)))
            return false;
        unsigned req = window_take_requests(w);
        if (req & WINDOW_PRINT)
            print_camera(w);
        if (req & WINDOW_CAMERA) {
            v->moved = true;
            return true;
        }
        if (req & WINDOW_EXPOSURE) {
            window_show_rect(w, fb, 0, 0, fb->width, fb->height);
            window_present(w);
        }
        if (req & WINDOW_SAVE) {
            char what[64];
            snprintf(what, sizeof what, "%d of %d spp", samples_done, v->samples_total);
            write_snapshot(v, fb, what);
        }
    }
}
