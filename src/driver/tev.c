/* tev.c - the tev viewer's IPC protocol over TCP (tev.h), written from
 * its description in tev's sources (include/tev/Ipc.h, src/Ipc.cpp,
 * github.com/Tom94/tev): a packet is a little-endian uint32 holding its
 * whole length (these 4 bytes included), a one-byte type, then its fields
 * in order: bools as one byte, strings NUL-terminated, int32 / int64
 * little-endian, floats as IEEE binary32 (little-endian on the hosts tev
 * runs on). rt sends two packets:
 *   CreateImage (4):   grabFocus, name, width, height, nChannels, channel names
 *   UpdateImageV3 (6): grabFocus, name, nChannels, channel names, x, y, w, h,
 *                      int64 offset per channel, int64 stride per channel,
 *                      then the floats; channel c of pixel i (row-major in
 *                      the rectangle) is float offset_c + i * stride_c.
 * The channels are R, G, B: linear radiance, as the PFM holds it (tev
 * applies its own exposure and tone curve), then each extra layer (the
 * --aov images) as LAYER.R, LAYER.G, LAYER.B, or LAYER.Y for a one-channel
 * layer: the names rt's EXR layers have (rt_exr_write), which tev shows as
 * one layer each. One UpdateImageV3 packet carries every channel of a
 * rectangle, each layer's floats in a block of their own (offset of the
 * block plus the component, stride the layer's channel count). Rectangles
 * go in bands of rows of at most 4 MiB, so tev's buffer never has to grow
 * much.
 */
#include "tev.h"

#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <time.h>
#include <unistd.h>

#include "rt/base/clock.h"
#include "rt/base/log.h"

enum { TEV_CREATE_IMAGE = 4, TEV_UPDATE_IMAGE_V3 = 6 };
#define TEV_RETRY_SECONDS 2.0
#define TEV_BAND_BYTES ((size_t)4 << 20)

/* ------------------------------------------------------------ packets */

typedef struct packet {
    unsigned char *data;
    size_t size, cap;
    bool failed; /* out of memory */
} packet;

static void put_bytes(packet *p, const void *bytes, size_t n)
{
    if (p->failed)
        return;
    if (p->size + n > p->cap) {
        size_t cap = p->cap ? p->cap : 256;
        while (cap < p->size + n)
            cap *= 2;
        unsigned char *d = realloc(p->data, cap);
        if (!d) {
            p->failed = true;
            return;
        }
        p->data = d;
        p->cap = cap;
    }
    memcpy(p->data + p->size, bytes, n);
    p->size += n;
}

static void put_u8(packet *p, unsigned v)
{
    unsigned char b = (unsigned char)v;
    put_bytes(p, &b, 1);
}

static void put_le(packet *p, uint64_t v, int bytes)
{
    unsigned char b[8];
    for (int i = 0; i < bytes; i++)
        b[i] = (unsigned char)(v >> (8 * i));
    put_bytes(p, b, (size_t)bytes);
}

static void put_string(packet *p, const char *s)
{
    put_bytes(p, s, strlen(s) + 1);
}

static void put_float(packet *p, float f)
{
    union { float f; uint32_t u; } v = {f};
    put_le(p, v.u, 4);
}

/* Starts a packet of `type`: room for the length, then the type. */
static void begin(packet *p, int type)
{
    p->size = 0;
    p->failed = false;
    put_le(p, 0, 4);
    put_u8(p, (unsigned)type);
}

/* Fills in the length. */
static void finish(packet *p)
{
    if (p->failed)
        return;
    uint32_t n = (uint32_t)p->size;
    for (int i = 0; i < 4; i++)
        p->data[i] = (unsigned char)(n >> (8 * i));
}

/* Channel c of the stream: the beauty's R, G, B, then the layers'. */
static void channel_name(const tev_stream *t, int c, char *buf, size_t size)
{
    static const char *const rgb[3] = {"R", "G", "B"};
    if (c < 3) {
        snprintf(buf, size, "%s", rgb[c]);
        return;
    }
    c -= 3;
    for (int l = 0; l < t->layer_count; l++) {
        const rt_image_layer *L = &t->layers[l];
        if (c < L->channels) {
            snprintf(buf, size, "%s.%s", L->name, L->channels == 1 ? "Y" : rgb[c]);
            return;
        }
        c -= L->channels;
    }
    snprintf(buf, size, "?");
}

static int channel_count(const tev_stream *t)
{
    int n = 3;
    for (int l = 0; l < t->layer_count; l++)
        n += t->layers[l].channels;
    return n;
}

static void put_channel_names(packet *p, const tev_stream *t)
{
    int n = channel_count(t);
    put_le(p, (uint32_t)n, 4);
    for (int c = 0; c < n; c++) {
        char name[80];
        channel_name(t, c, name, sizeof name);
        put_string(p, name);
    }
}

/* ------------------------------------------------------------ the connection */

bool tev_parse_address(const char *address, char *host, size_t host_size, char *port, size_t port_size)
{
    const char *colon = strrchr(address, ':');
    if (!colon || colon == address || !colon[1])
        return false;
    const char *h = address;
    size_t hn = (size_t)(colon - address);
    bool opens = h[0] == '[', closes = hn >= 2 && h[hn - 1] == ']';
    if (opens != closes) /* "[::1:14158", "::1]:14158": a bracket left open or never opened */
        return false;
    if (opens) { /* [::1]:14158 */
        h++;
        hn -= 2;
    }
    size_t pn = strlen(colon + 1);
    if (hn == 0 || hn >= host_size || pn >= port_size)
        return false;
    for (const char *c = colon + 1; *c; c++)
        if (*c < '0' || *c > '9')
            return false;
    long v = strtol(colon + 1, NULL, 10);
    if (v < 1 || v > 65535)
        return false;
    memcpy(host, h, hn);
    host[hn] = 0;
    memcpy(port, colon + 1, pn + 1);
    return true;
}

static void disconnect(tev_stream *t)
{
    if (t->fd >= 0)
        close(t->fd);
    t->fd = -1;
}

/* Connects within a second or gives up (a host that does not answer must
 * not hold up the render's progress reports for long). */
static int connect_to(const char *host, const char *port, char *why, size_t why_size)
{
    struct addrinfo hints, *list = NULL;
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    int e = getaddrinfo(host, port, &hints, &list);
    if (e != 0) {
        snprintf(why, why_size, "%s", gai_strerror(e));
        return -1;
    }
    int fd = -1;
    snprintf(why, why_size, "no address");
    for (struct addrinfo *a = list; a && fd < 0; a = a->ai_next) {
        fd = socket(a->ai_family, a->ai_socktype, a->ai_protocol);
        if (fd < 0) {
            snprintf(why, why_size, "%s", strerror(errno));
            continue;
        }
        int flags = fcntl(fd, F_GETFL, 0);
        fcntl(fd, F_SETFL, flags | O_NONBLOCK);
        int r = connect(fd, a->ai_addr, a->ai_addrlen);
        if (r != 0 && errno == EINPROGRESS) {
            struct pollfd pf = {fd, POLLOUT, 0};
            int soerr = ETIMEDOUT;
            if (poll(&pf, 1, 1000) == 1) {
                socklen_t len = sizeof soerr;
                getsockopt(fd, SOL_SOCKET, SO_ERROR, &soerr, &len);
            }
            r = soerr ? -1 : 0;
            errno = soerr;
        }
        if (r != 0) {
            snprintf(why, why_size, "%s", strerror(errno));
            close(fd);
            fd = -1;
            continue;
        }
        fcntl(fd, F_SETFL, flags); /* blocking sends from here on, */
        struct timeval tv = {5, 0};  /* but a tev that stops reading for 5 s counts as gone */
        setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
    }
    freeaddrinfo(list);
    return fd;
}

static bool send_all(tev_stream *t, const packet *p)
{
    if (t->fd < 0 || p->failed)
        return false;
    size_t off = 0;
    while (off < p->size) {
        ssize_t n = send(t->fd, p->data + off, p->size - off, MSG_NOSIGNAL);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            rt_info("display server %s:%s: connection lost (%s); reconnecting", t->host, t->port,
                    n < 0 ? strerror(errno) : "closed");
            t->lost = true; /* tev closed: said with -v only, as is its coming back */
            disconnect(t);
            return false;
        }
        off += (size_t)n;
    }
    t->bytes_sent += p->size;
    return true;
}

static void send_create(tev_stream *t)
{
    packet p = {0};
    begin(&p, TEV_CREATE_IMAGE);
    put_u8(&p, 0); /* grabFocus */
    put_string(&p, t->name);
    put_le(&p, (uint32_t)t->width, 4);
    put_le(&p, (uint32_t)t->height, 4);
    put_channel_names(&p, t);
    finish(&p);
    send_all(t, &p);
    free(p.data);
}

bool tev_stream_connect(tev_stream *t, bool force)
{
    if (t->fd >= 0)
        return true;
    double now = rt_now_seconds();
    if (!force && t->last_try > 0.0 && now - t->last_try < TEV_RETRY_SECONDS)
        return false;
    t->last_try = now;
    char why[256];
    t->fd = connect_to(t->host, t->port, why, sizeof why);
    if (t->fd < 0) {
        if (!t->warned && !t->lost) /* said once a run, without -v: a wrong port is otherwise silent */
            rt_warn("--display-server %s:%s: nothing listens there (%s); rendering on, and trying again every "
                    "%.0f s (start tev, or check the port)",
                    t->host, t->port, why, TEV_RETRY_SECONDS);
        t->warned = true;
        return false;
    }
    if (t->warned && !t->lost)
        rt_note("--display-server %s:%s: connected", t->host, t->port);
    else
        rt_info("display server %s:%s: connected", t->host, t->port);
    t->warned = false;
    t->lost = false;
    send_create(t);
    t->fresh = t->fd >= 0;
    return t->fd >= 0;
}

void tev_stream_open(tev_stream *t, const char *address, const char *name, int width, int height,
                     const rt_image_layer *layers, int layer_count)
{
    memset(t, 0, sizeof *t);
    t->fd = -1;
    if (!tev_parse_address(address, t->host, sizeof t->host, t->port, sizeof t->port))
        return; /* args.c checked it */
    snprintf(t->name, sizeof t->name, "%s", name);
    t->width = width;
    t->height = height;
    for (int l = 0; l < layer_count && t->layer_count < TEV_MAX_LAYERS; l++)
        if (layers[l].data && (layers[l].channels == 1 || layers[l].channels == 3))
            t->layers[t->layer_count++] = layers[l];
    tev_stream_connect(t, true);
}

bool tev_stream_wants_image(const tev_stream *t)
{
    return t->fd >= 0 && t->fresh;
}

void tev_stream_rect(tev_stream *t, const rt_framebuffer *fb, int x0, int y0, int x1, int y1)
{
    if (t->fd < 0 || x1 <= x0 || y1 <= y0)
        return;
    int w = x1 - x0, nch = channel_count(t);
    size_t row_bytes = (size_t)w * (size_t)nch * sizeof(float);
    int band = (int)(TEV_BAND_BYTES / row_bytes);
    band = band < 1 ? 1 : band;
    packet p = {0};
    for (int y = y0; y < y1 && t->fd >= 0; y += band) {
        int h = y + band < y1 ? band : y1 - y;
        begin(&p, TEV_UPDATE_IMAGE_V3);
        put_u8(&p, 0);
        put_string(&p, t->name);
        put_channel_names(&p, t);
        put_le(&p, (uint32_t)x0, 4);
        put_le(&p, (uint32_t)y, 4);
        put_le(&p, (uint32_t)w, 4);
        put_le(&p, (uint32_t)h, 4);
        /* blocks: the beauty's interleaved RGB, then each layer's pixels */
        size_t npx = (size_t)w * (size_t)h, base = 3 * npx;
        for (int c = 0; c < 3; c++)
            put_le(&p, (uint64_t)c, 8); /* offsets */
        for (int l = 0; l < t->layer_count; l++) {
            for (int c = 0; c < t->layers[l].channels; c++)
                put_le(&p, (uint64_t)(base + (size_t)c), 8);
            base += npx * (size_t)t->layers[l].channels;
        }
        for (int c = 0; c < 3; c++)
            put_le(&p, 3, 8); /* strides */
        for (int l = 0; l < t->layer_count; l++)
            for (int c = 0; c < t->layers[l].channels; c++)
                put_le(&p, (uint64_t)t->layers[l].channels, 8);
        for (int yy = y; yy < y + h; yy++) {
            const float *row = fb->rgb + 3 * ((size_t)yy * (size_t)fb->width + (size_t)x0);
            for (size_t i = 0; i < 3 * (size_t)w; i++)
                put_float(&p, row[i]);
        }
        for (int l = 0; l < t->layer_count; l++) {
            size_t k = (size_t)t->layers[l].channels;
            for (int yy = y; yy < y + h; yy++) {
                const float *row = t->layers[l].data + k * ((size_t)yy * (size_t)t->width + (size_t)x0);
                for (size_t i = 0; i < k * (size_t)w; i++)
                    put_float(&p, row[i]);
            }
        }
        finish(&p);
        send_all(t, &p);
    }
    free(p.data);
}

void tev_stream_image(tev_stream *t, const rt_framebuffer *fb, bool force)
{
    if (!tev_stream_connect(t, force))
        return;
    tev_stream_rect(t, fb, 0, 0, fb->width, fb->height);
    if (t->fd >= 0)
        t->fresh = false;
}

void tev_stream_close(tev_stream *t)
{
    disconnect(t);
}
