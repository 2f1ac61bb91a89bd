/* progress.c - what the terminal shows of a running render: a progress
 * bar on stderr (tiles done, elapsed time, a linear estimate of the time
 * left), and the live preview (--preview): the output image rewritten
 * every few seconds with the finished tiles and the others dim grey, for
 * a viewer that reloads it. rt_render calls progress_report from its own
 * thread about every 50 ms (src/render/render.c).
 */
#include "progress.h"

#include <stdio.h>
#include <string.h>
#include "rt/base/log.h"

static void draw_bar(int done, int total, double elapsed, bool final)
{
    const int width = 30;
    double f = total ? (double)done / total : 1.0;
    int bar = (int)(f * width + 0.5);
    char line[128];
    int n = 0;
    line[n++] = '[';
    for (int i = 0; i < width; i++)
        line[n++] = i < bar ? '#' : ' ';
    line[n++] = ']';
    line[n] = 0;
    double eta = (done > 0 && done < total) ? elapsed * (total - done) / done : 0.0;
    fprintf(stderr, "\r%s %5.1f%%  %6.1fs elapsed", line, 100.0 * f, elapsed);
    if (!final && done > 0)
        fprintf(stderr, "  ETA %6.1fs ", eta);
    else
        fprintf(stderr, "              ");
    if (final)
        fputc('\n', stderr);
    fflush(stderr);
}

/* Live view: a copy of the image where unfinished tiles are dim grey. */
static void write_preview(const rt_render_progress *p, const char *path, float exposure, rt_write_temp *temp)
{
    rt_framebuffer copy;
    rt_error err;
    if (rt_framebuffer_init(&copy, p->fb->width, p->fb->height, &err) != RT_OK)
        return;
    for (int i = 0; i < p->tiles_total; i++) {
        rt_tile t = rt_render_progress_tile(p, i);
        for (int y = t.y0; y < t.y1; y++)
            for (int x = t.x0; x < t.x1; x++) {
                size_t k = 3 * ((size_t)y * (size_t)copy.width + (size_t)x);
                for (int c = 0; c < 3; c++)
                    copy.rgb[k + c] = t.finished ? p->fb->rgb[k + c] : 0.02f;
            }
    }
    if (rt_framebuffer_write_tracked(&copy, path, exposure, temp, &err) != RT_OK)
        rt_warn("live preview: %s", err.message);
    rt_framebuffer_free(&copy);
}

void progress_view_init(progress_view *v, bool bar, const char *preview_path, double preview_seconds,
                        float exposure)
{
    memset(v, 0, sizeof *v);
    v->bar = bar;
    v->preview_path = preview_path;
    v->preview_seconds = preview_seconds > 0.0 ? preview_seconds : 2.0;
    v->exposure = exposure;
}

void progress_report(const rt_render_progress *p, void *view)
{
    progress_view *v = view;
    if (v->bar)
        draw_bar(p->tiles_done, p->tiles_total, p->elapsed, p->final);
    if (!p->final && v->preview_path && p->elapsed - v->last_preview >= v->preview_seconds) {
        write_preview(p, v->preview_path, v->exposure, v->temp);
        v->last_preview = p->elapsed;
    }
}
