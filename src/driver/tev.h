/* tev.h - streaming the image to the tev HDR viewer (driver-private):
 * --display-server HOST:PORT, as pbrt-v4's option of the same name.
 *
 *   tev_stream t;
 *   if (!tev_parse_address("127.0.0.1:14158", &t_host, &t_port)) ... bad flag ...
 *   rt_image_layer aovs[] = {{"albedo", 3, albedo}, {"depth", 1, depth}};   // extra layers, may be none
 *   tev_stream_open(&t, "127.0.0.1:14158", "out.png", width, height, aovs, 2);   // connects (quietly, may fail)
 *   tev_stream_rect(&t, fb, x0, y0, x1, y1);      // pixels that are final (a finished tile)
 *   tev_stream_image(&t, fb);                     // the whole image (after a pass, at the end)
 *   tev_stream_close(&t);
 *
 * Nothing here fails the render: when nothing listens at the address the
 * stream warns once (a wrong port is otherwise invisible), says so again
 * when it connects after all; when tev goes away mid-render it says so at
 * -v only. Either way it connects again at the next update at most every
 * two seconds (tev_stream_image(..., force) tries at once), sending the
 * image anew; the caller then calls tev_stream_image.
 *
 * The image has the channels R, G, B, then the layers' LAYER.R, LAYER.G,
 * LAYER.B (LAYER.Y for one channel), as rt's EXR output names them; every
 * update sends all of them for its rectangle, the layers read from their
 * `data` (width x height pixels of `channels` floats) under the same rule
 * as fb: only pixels that are final.
 */
#ifndef RT_DRIVER_TEV_H
#define RT_DRIVER_TEV_H

#include <stdbool.h>
#include <stddef.h>

#include "rt/io/image_write.h"

#define TEV_MAX_LAYERS 8

typedef struct tev_stream {
    char host[256], port[16];
    char name[256];     /* the image's name in tev */
    int width, height;
    rt_image_layer layers[TEV_MAX_LAYERS]; /* extra layers (the AOVs) */
    int layer_count;
    int fd;             /* -1 = not connected */
    bool fresh;         /* connected since the last whole image was sent */
    bool warned;        /* said once that tev is not reachable */
    bool lost;          /* the connection was lost (tev closed): quiet retries */
    double last_try;    /* monotonic seconds of the last connection attempt */
    size_t bytes_sent;
} tev_stream;

/* Splits HOST:PORT (the last ':'; [v6]:port too); false when malformed. */
bool tev_parse_address(const char *address, char *host, size_t host_size, char *port, size_t port_size);

void tev_stream_open(tev_stream *t, const char *address, const char *name, int width, int height,
                     const rt_image_layer *layers, int layer_count);
/* Sends fb's pixels [x0, x1) x [y0, y1), and the layers'. */
void tev_stream_rect(tev_stream *t, const rt_framebuffer *fb, int x0, int y0, int x1, int y1);
/* Sends the whole image; force: try to connect now even if a try was
 * made in the last two seconds (the final image). */
void tev_stream_image(tev_stream *t, const rt_framebuffer *fb, bool force);
/* True when connected and the image must be sent whole (new connection). */
bool tev_stream_wants_image(const tev_stream *t);
/* Tries to connect again if it is time (at most every 2 s); true when connected. */
bool tev_stream_connect(tev_stream *t, bool force);
void tev_stream_close(tev_stream *t);

#endif
