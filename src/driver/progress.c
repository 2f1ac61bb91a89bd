/* progress.c - what the terminal shows of a run: one progress line on
 * stderr, rewritten in place, naming the phase (load, kd-tree, render)
 * and, while rendering, a bar of tiles or samples per pixel done, the
 * elapsed time and a linear estimate of the time left (work left times
 * the mean time per unit of work so far, so in passes it settles within a
 * few passes); and the live preview (--preview): the output image
 * rewritten every few seconds with the finished tiles and the others dim
 * grey, for a viewer that reloads it; and the stream to tev (tev.c) for
 * --display-server, and the window (window.c) for --window, whose
 * requests viewer.c answers. rt_render calls progress_report from
 * its own thread about every 50 ms and after each pass
 * (src/render/render.c).
 */
#include "progress.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rt/base/clock.h"
#include "rt/base/log.h"

#include "viewer.h"

/* "load 0.31s, kd-tree 0.12s, " for the phases before rendering. A
 * phase ends where the next begins, the last one where the render after it
 * started (noted at that render's first report): a render started again
 * later (the window's camera moved) leaves the phases' times as they were,
 * so time spent waiting on the window is never counted in them. */
static void phase_times(progress_view *v, char *buf, size_t size, double render_start)
{
    size_t n = 0;
    buf[0] = 0;
    for (int i = 0; i < v->phases && n < size; i++) {
        if (v->phase_end[i] == 0.0)
            v->phase_end[i] = i + 1 < v->phases ? v->phase_start[i + 1] : render_start;
        int k = snprintf(buf + n, size - n, "%s %.2fs, ", v->phase_name[i], v->phase_end[i] - v->phase_start[i]);
        if (k < 0)
            break;
        n += (size_t)k;
    }
}

/* The fraction of the render done: tiles, or samples per pixel counting
 * the pass under way by its finished tiles. */
static double fraction_done(const rt_render_progress *p)
{
    double f;
    if (p->passes) {
        double spp = (double)p->samples_done;
        if (!p->final && p->tiles_total > 0)
            spp += (double)p->pass_samples * p->tiles_done / p->tiles_total;
        f = p->samples_total > 0 ? spp / p->samples_total : 1.0;
    } else {
        f = p->tiles_total ? (double)p->tiles_done / p->tiles_total : 1.0;
    }
    return f < 0.0 ? 0.0 : (f > 1.0 ? 1.0 : f);
}

static void draw_bar(progress_view *v, const rt_render_progress *p)
{
    const int width = 24;
    double f = fraction_done(p);
    char count[64];
    if (p->passes)
        snprintf(count, sizeof count, "%d/%d spp", p->samples_done, p->samples_total);
    else
        snprintf(count, sizeof count, "%d/%d tiles", p->tiles_done, p->tiles_total);
    int bar = (int)(f * width + 0.5);
    char line[64];
    int n = 0;
    line[n++] = '[';
    for (int i = 0; i < width; i++)
        line[n++] = i < bar ? '#' : ' ';
    line[n++] = ']';
    line[n] = 0;
    char phases[160], eta[32] = "";
    phase_times(v, phases, sizeof phases, rt_now_seconds() - p->elapsed);
    if (!p->final && f > 0.0) {
        double left = p->elapsed * (1.0 - f) / f;
        if (v->time_limit > 0.0 && left > v->time_limit - p->elapsed)
            left = v->time_limit > p->elapsed ? v->time_limit - p->elapsed : 0.0;
        snprintf(eta, sizeof eta, "  ETA %6.1fs", left);
    }
    rt_log_status("%srender %s %5.1f%% %s %6.1fs%s", phases, line, 100.0 * f, count, p->elapsed, eta);
    if (p->final)
        rt_log_status_keep();
}

/* Live view: a copy of the image where unfinished tiles are dim grey. */
static bool write_preview(const rt_render_progress *p, const char *path, float exposure, rt_write_temp *temp)
{
    rt_framebuffer copy;
    rt_error err;
    if (rt_framebuffer_init(&copy, p->fb->width, p->fb->height, &err) != RT_OK)
        return false;
    for (int i = 0; i < p->tiles_total; i++) {
        rt_tile t = rt_render_progress_tile(p, i);
        for (int y = t.y0; y < t.y1; y++)
            for (int x = t.x0; x < t.x1; x++) {
                size_t k = 3 * ((size_t)y * (size_t)copy.width + (size_t)x);
                for (int c = 0; c < 3; c++)
                    copy.rgb[k + c] = t.finished ? p->fb->rgb[k + c] : 0.02f;
            }
    }
    rt_image_options opt = {.exposure = exposure};
    bool ok = rt_framebuffer_write_tracked(&copy, path, &opt, temp, &err) == RT_OK;
    if (!ok)
        rt_warn("live preview: %s", err.message);
    rt_framebuffer_free(&copy);
    return ok;
}

void progress_view_init(progress_view *v, bool bar)
{
    memset(v, 0, sizeof *v);
    v->bar = bar;
    v->exposure = 1.0f;
}

void progress_view_free(progress_view *v)
{
    free(v->tev_sent);
    free(v->win_shown);
    v->tev_sent = NULL;
    v->win_shown = NULL;
}

/* Streams what is new to tev: finished tiles not sent yet, the image
 * after a pass, everything again after a reconnection, and the final
 * image. Only pixels that are final are read while workers run. */
static void stream_to_tev(progress_view *v, const rt_render_progress *p)
{
    tev_stream *t = v->tev;
    if (p->final) {
        tev_stream_image(t, p->fb, true);
        return;
    }
    if (!tev_stream_connect(t, false))
        return;
    bool fresh = tev_stream_wants_image(t);
    if (p->passes) {
        if (p->samples_done > 0 && (fresh || p->samples_done != v->tev_samples)) {
            tev_stream_image(t, p->fb, false);
            v->tev_samples = p->samples_done;
        }
        return;
    }
    if (!v->tev_sent) {
        v->tev_sent = calloc((size_t)p->tiles_total, 1);
        if (!v->tev_sent)
            return;
    }
    if (fresh)
        memset(v->tev_sent, 0, (size_t)p->tiles_total);
    for (int i = 0; i < p->tiles_total; i++) {
        rt_tile tile = rt_render_progress_tile(p, i);
        if (tile.finished && !v->tev_sent[i]) {
            tev_stream_rect(t, p->fb, tile.x0, tile.y0, tile.x1, tile.y1);
            v->tev_sent[i] = 1;
        }
    }
    t->fresh = false;
}

/* The same for the window: finished tiles, the image after each pass;
 * then the window's requests (viewer.c). After a cancel for a camera move
 * the final report is not shown (a tiled image then has holes); the next
 * render's first pass or tiles replace it. */
static void show_in_window(progress_view *v, const rt_render_progress *p)
{
    window_view *w = v->window;
    if (!w->open) {
        if (v->viewer)
            viewer_poll(v->viewer, p);
        return;
    }
    bool moved = v->viewer && v->viewer->moved;
    if ((p->final && !moved) || (p->passes && p->samples_done > 0 && p->samples_done != v->win_samples)) {
        window_show_rect(w, p->fb, 0, 0, p->fb->width, p->fb->height);
        v->win_samples = p->samples_done;
        w->shown++;
    } else if (!p->passes && !moved) {
        if (!v->win_shown && !(v->win_shown = calloc((size_t)p->tiles_total, 1)))
            return;
        for (int i = 0; i < p->tiles_total; i++) {
            rt_tile tile = rt_render_progress_tile(p, i);
            if (tile.finished && !v->win_shown[i]) {
                window_show_rect(w, p->fb, tile.x0, tile.y0, tile.x1, tile.y1);
                v->win_shown[i] = 1;
                w->shown++;
            }
        }
    }
    window_present(w);
    if (v->viewer)
        viewer_poll(v->viewer, p);
}

void progress_restart(progress_view *v, int tiles_total)
{
    v->tev_samples = 0;
    v->win_samples = 0;
    if (v->tev_sent)
        memset(v->tev_sent, 0, (size_t)tiles_total);
    if (v->win_shown)
        memset(v->win_shown, 0, (size_t)tiles_total);
}

void progress_phase(progress_view *v, const char *name, const char *detail)
{
    if (v->phases >= PROGRESS_MAX_PHASES)
        return;
    v->phase_name[v->phases] = name;
    v->phase_start[v->phases] = rt_now_seconds();
    v->phase_end[v->phases] = 0.0;
    v->phases++;
    if (v->bar)
        rt_log_status("%s%s%s ...", name, detail ? " " : "", detail ? detail : "");
}

void progress_clear(progress_view *v)
{
    (void)v;
    rt_log_status_clear(); /* rt/base/log.h knows whether a line is shown */
}

void progress_report(const rt_render_progress *p, void *view)
{
    progress_view *v = view;
    /* a render cancelled because the window's camera moved ends quietly:
     * the next one takes over the line, the window and tev */
    bool restarting = p->final && v->viewer && v->viewer->moved;
    if (v->bar && !restarting)
        draw_bar(v, p);
    if (v->tev && !restarting)
        stream_to_tev(v, p);
    if (v->window)
        show_in_window(v, p);
    double every = v->preview_seconds > 0.0 ? v->preview_seconds : 2.0;
    if (!p->final && v->preview_path && p->elapsed - v->last_preview >= every) {
        if (write_preview(p, v->preview_path, v->exposure, v->temp))
            v->previews++;
        v->last_preview = p->elapsed;
    }
}
