/* window.c - the --window view (window.h) over SDL2 (libsdl2-dev): a
 * streaming RGB24 texture updated from the image as tiles or passes
 * finish, through the PNG writer's exposure, tone curve and sRGB encoding
 * (rt_tonemap_to_srgb8, rt/image/tonemap.h). The software renderer is
 * asked for, so what the window shows is exactly those bytes (and works
 * under Xvfb). Mouse and keys move the window's camera with the pure
 * functions of rt/render/camera_control.h (a turntable orbit about
 * look_at, as yocto-gl's and pbrt-v4's viewers do) and raise request bits
 * for the driver; a glTF camera, whose look_at is only a direction, moves
 * about the model's depth (rt_camera_depth, given as the pivot).
 * RT_WINDOW_SCRIPT pushes synthetic events into SDL's own queue
 * (SDL_PushEvent), so a test drives the very code a mouse does. SDL's
 * messages go through rt's log (rt/base/log.h): SDL_Log by
 * SDL_LogSetOutputFunction, and what its video backends print straight to
 * stderr while the window opens by catching fd 2 meanwhile. Without SDL2
 * at build time every call is a stub and window_open says why.
 */
#include "window.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rt/base/log.h"
#include "rt/render/camera.h"
#include "rt/render/camera_control.h"

#ifdef RT_HAVE_SDL2
#include <SDL.h>
#endif

#define WINDOW_PI 3.14159265358979323846f

void window_show_rect(window_view *w, const rt_framebuffer *fb, int x0, int y0, int x1, int y1)
{
    if (!w->rgb || x1 <= x0)
        return;
    float e = (w->exposure > 0.0f ? w->exposure : 1.0f) * rt_exposure_scale(w->view_ev);
    for (int y = y0; y < y1; y++) {
        size_t k = 3 * ((size_t)y * (size_t)fb->width + (size_t)x0);
        rt_tonemap_to_srgb8(w->tonemap, e, fb->rgb + k, (size_t)(x1 - x0), w->rgb + k);
    }
}

void window_set_camera(window_view *w, const rt_camera *c, float step, float pivot)
{
    w->interactive = true;
    w->camera = *c;
    w->home = *c;
    w->step = step > 0.0f && isfinite(step) ? step : 1.0f;
    w->pivot = w->home_pivot = pivot > 0.0f && isfinite(pivot) ? pivot : 0.0f;
}

unsigned window_take_requests(window_view *w)
{
    unsigned r = w->requests;
    w->requests = 0;
    return r;
}

#ifdef RT_HAVE_SDL2

/* Parses RT_WINDOW_SCRIPT into w->script; false (and why) when malformed. */
static bool parse_script(window_view *w, const char *text, char *why, size_t why_size)
{
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", text);
    char *save = NULL;
    for (char *step = strtok_r(buf, ";", &save); step; step = strtok_r(NULL, ";", &save)) {
        while (*step == ' ')
            step++;
        if (!*step)
            continue;
        if (w->script_len == WINDOW_SCRIPT_MAX) {
            snprintf(why, why_size, "RT_WINDOW_SCRIPT: more than %d steps", WINDOW_SCRIPT_MAX);
            return false;
        }
        window_step *s = &w->script[w->script_len];
        memset(s, 0, sizeof *s);
        char a[32] = "", b[32] = "";
        int n = 0;
        bool ok = false;
        if (sscanf(step, "wait %31s %n", a, &n) == 1 && !step[n]) {
            s->kind = strcmp(a, "done") == 0 ? 'd' : strcmp(a, "pass") == 0 ? 'p' : 0;
            ok = s->kind != 0;
        } else if (sscanf(step, "drag %31s %d %d %d %d %n", a, &s->v[0], &s->v[1], &s->v[2], &s->v[3], &n) == 5 &&
                   !step[n]) {
            s->kind = 'g';
            s->button = strcmp(a, "left") == 0     ? SDL_BUTTON_LEFT
                        : strcmp(a, "right") == 0  ? SDL_BUTTON_RIGHT
                        : strcmp(a, "middle") == 0 ? SDL_BUTTON_MIDDLE
                                                   : 0;
            ok = s->button != 0;
        } else if (sscanf(step, "sleep %d %n", &s->v[0], &n) == 1 && !step[n]) {
            s->kind = 's';
            ok = s->v[0] >= 0;
        } else if (sscanf(step, "wheel %d %n", &s->v[0], &n) == 1 && !step[n]) {
            s->kind = 'w';
            ok = true;
        } else if (sscanf(step, "key %31s %n", b, &n) == 1 && !step[n]) {
            s->kind = 'k';
            s->key = (int)SDL_GetKeyFromName(b);
            ok = s->key != SDLK_UNKNOWN;
        }
        if (!ok) {
            snprintf(why, why_size, "RT_WINDOW_SCRIPT: cannot read step %d, '%s'", w->script_len + 1, step);
            return false;
        }
        w->script_len++;
    }
    return true;
}

/* SDL's own log (SDL_Log and its errors) through rt's: "rt: SDL: ..."
 * with -v, or nothing. */
static void sdl_log(void *user, int category, SDL_LogPriority priority, const char *message)
{
    (void)user;
    (void)category;
    (void)priority;
    rt_info("SDL: %s", message);
}

/* What SDL's video backends print straight to stderr while they start
 * (libwayland's "error: XDG_RUNTIME_DIR is invalid or not set in the
 * environment." when SDL tries Wayland, Xlib's complaints): fd 2 goes to
 * a temporary file meanwhile, and its lines then through rt_info, so they
 * carry rt's prefix and are shown only with -v (the reason a window
 * cannot open is said anyway, from SDL_GetError). Only the main thread
 * runs then: no render has started. */
typedef struct stderr_capture {
    FILE *file; /* NULL: not captured */
    int saved;  /* the real stderr, dup'ed */
} stderr_capture;

static void capture_stderr(stderr_capture *c)
{
    c->file = NULL;
    c->saved = -1;
    fflush(stderr);
    FILE *f = tmpfile();
    int saved = f ? dup(2) : -1;
    if (saved < 0 || dup2(fileno(f), 2) < 0) {
        if (saved >= 0)
            close(saved);
        if (f)
            fclose(f);
        return;
    }
    c->file = f;
    c->saved = saved;
}

static void release_stderr(stderr_capture *c)
{
    if (!c->file)
        return;
    fflush(stderr);
    dup2(c->saved, 2);
    close(c->saved);
    rewind(c->file);
    char line[1024];
    while (fgets(line, sizeof line, c->file)) {
        size_t n = strcspn(line, "\r\n");
        line[n] = 0;
        if (n > 0)
            rt_info("SDL: %s", line);
    }
    fclose(c->file);
    c->file = NULL;
}

/* SDL started, the window, its renderer and texture made; false (and why)
 * with everything undone. */
static bool open_video(window_view *w, int width, int height, const char *title, char *why, size_t why_size)
{
    const char *x11 = getenv("DISPLAY"), *wayland = getenv("WAYLAND_DISPLAY"), *chosen = getenv("SDL_VIDEODRIVER");
    if (SDL_Init(SDL_INIT_VIDEO) != 0) {
        snprintf(why, why_size, "%s", SDL_GetError());
        return false;
    }
    /* SDL falls back to drivers that show nothing; only take one if asked to */
    const char *driver = SDL_GetCurrentVideoDriver();
    if (driver && !(chosen && *chosen) && (strcmp(driver, "offscreen") == 0 || strcmp(driver, "dummy") == 0)) {
        snprintf(why, why_size, "no display could be opened (%s%s%s%s%s; SDL fell back to its '%s' driver)",
                 x11 && *x11 ? "DISPLAY=" : "", x11 && *x11 ? x11 : "", x11 && *x11 && wayland && *wayland ? ", " : "",
                 wayland && *wayland ? "WAYLAND_DISPLAY=" : "", wayland && *wayland ? wayland : "", driver);
        SDL_Quit();
        return false;
    }
    /* a window no larger than the screen's usable area, keeping the aspect */
    int ww = width, wh = height;
    SDL_Rect usable;
    if (SDL_GetDisplayUsableBounds(0, &usable) == 0 && usable.w > 0 && usable.h > 0) {
        double s = 1.0;
        if (ww > usable.w)
            s = (double)usable.w / ww;
        if (wh * s > usable.h)
            s = (double)usable.h / wh;
        ww = (int)(ww * s) > 0 ? (int)(ww * s) : 1;
        wh = (int)(wh * s) > 0 ? (int)(wh * s) : 1;
    }
    SDL_Window *win = SDL_CreateWindow(title, SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, ww, wh,
                                       SDL_WINDOW_RESIZABLE);
    SDL_Renderer *ren = win ? SDL_CreateRenderer(win, -1, SDL_RENDERER_SOFTWARE) : NULL;
    SDL_Texture *tex = ren ? SDL_CreateTexture(ren, SDL_PIXELFORMAT_RGB24, SDL_TEXTUREACCESS_STREAMING, width, height)
                           : NULL;
    unsigned char *rgb = tex ? calloc((size_t)width * (size_t)height, 3) : NULL;
    if (!rgb) {
        snprintf(why, why_size, "%s", tex ? "out of memory" : SDL_GetError());
        if (tex)
            SDL_DestroyTexture(tex);
        if (ren)
            SDL_DestroyRenderer(ren);
        if (win)
            SDL_DestroyWindow(win);
        SDL_Quit();
        return false;
    }
    SDL_RenderSetLogicalSize(ren, width, height); /* mouse coordinates in image pixels too */
    w->window = win;
    w->renderer = ren;
    w->texture = tex;
    w->rgb = rgb;
    w->width = width;
    w->height = height;
    return true;
}

bool window_open(window_view *w, int width, int height, const char *title, char *why, size_t why_size)
{
    memset(w, 0, sizeof *w);
    w->exposure = 1.0f;
    const char *script = getenv("RT_WINDOW_SCRIPT");
    if (script && *script && !parse_script(w, script, why, why_size))
        return false;
    const char *x11 = getenv("DISPLAY"), *wayland = getenv("WAYLAND_DISPLAY"), *chosen = getenv("SDL_VIDEODRIVER");
    if (!(x11 && *x11) && !(wayland && *wayland) && !(chosen && *chosen)) {
        snprintf(why, why_size, "no display (DISPLAY and WAYLAND_DISPLAY are not set)");
        return false;
    }
    /* a plain X11/Wayland surface, never an OpenGL one: nothing to gain for
     * one texture a pass, and Mesa's threads are then out of the process */
    SDL_SetHint(SDL_HINT_FRAMEBUFFER_ACCELERATION, "0");
    SDL_SetHint(SDL_HINT_RENDER_DRIVER, "software");
    SDL_LogSetOutputFunction(sdl_log, NULL);
    stderr_capture cap;
    capture_stderr(&cap);
    bool ok = open_video(w, width, height, title, why, why_size);
    release_stderr(&cap);
    if (!ok)
        return false;
    w->open = true;
    window_present(w);
    return true;
}

/* ------------------------------------------------------------ input */

/* The camera a move starts from: the current one, with look_at put at the
 * model's depth while it is still a point that means nothing (a glTF
 * camera's, 1 unit ahead: window_set_camera's pivot), so that orbit, pan
 * and dolly turn about, follow and approach the model. */
static rt_camera move_start(const window_view *w)
{
    return w->pivot > 0.0f ? rt_camera_look_at_depth(w->camera, w->pivot) : w->camera;
}

static void camera_moved(window_view *w, rt_camera c)
{
    rt_camera_frame cf;
    if (!rt_camera_frame_init(&cf, &c, w->width, w->height) || memcmp(&c, &w->camera, sizeof c) == 0)
        return; /* a move that would break the camera, or none */
    w->camera = c;
    w->pivot = 0.0f; /* look_at is the pivot from now on */
    w->requests |= WINDOW_CAMERA;
    w->render_done = false;
}

/* A mouse move of (dx, dy) image pixels with a button held: orbit (a drag
 * across the image's width turns half a turn; the scene follows the
 * mouse) or pan (the point at look_at's distance stays under the mouse). */
static void drag_by(window_view *w, int dx, int dy)
{
    rt_camera c = move_start(w);
    if (w->drag == 'o') {
        float rate = WINDOW_PI / (float)(w->width > w->height ? w->width : w->height);
        c = rt_camera_orbit(c, c.look_at, -(float)dx * rate, (float)dy * rate);
    } else {
        float s = rt_camera_pan_scale(&c, w->height);
        c = rt_camera_pan(c, -(float)dx * s, (float)dy * s);
    }
    camera_moved(w, c);
}

static void key_down(window_view *w, const SDL_Keysym *k)
{
    bool ctrl = (k->mod & KMOD_CTRL) != 0;
    float s = w->step;
    switch (k->sym) {
    case SDLK_ESCAPE: w->open = false; return;
    case SDLK_q: /* as --help says; Ctrl+Q too */
        w->open = false;
        return;
    case SDLK_F12: w->requests |= WINDOW_SAVE; return;
    case SDLK_p: w->requests |= WINDOW_PRINT; return;
    case SDLK_LEFTBRACKET: w->view_ev -= 1.0f / 3.0f; w->requests |= WINDOW_EXPOSURE; return;
    case SDLK_RIGHTBRACKET: w->view_ev += 1.0f / 3.0f; w->requests |= WINDOW_EXPOSURE; return;
    case SDLK_0: w->view_ev = 0.0f; w->requests |= WINDOW_EXPOSURE; return;
    default: break;
    }
    if (ctrl && k->sym == SDLK_s) {
        w->requests |= WINDOW_SAVE;
        return;
    }
    if (!w->interactive || ctrl)
        return;
    switch (k->sym) {
    case SDLK_w: camera_moved(w, rt_camera_walk(move_start(w), s, 0, 0)); break;
    case SDLK_s: camera_moved(w, rt_camera_walk(move_start(w), -s, 0, 0)); break;
    case SDLK_a: camera_moved(w, rt_camera_walk(move_start(w), 0, -s, 0)); break;
    case SDLK_d: camera_moved(w, rt_camera_walk(move_start(w), 0, s, 0)); break;
    case SDLK_e: camera_moved(w, rt_camera_walk(move_start(w), 0, 0, s)); break;
    case SDLK_c: camera_moved(w, rt_camera_walk(move_start(w), 0, 0, -s)); break;
    case SDLK_r:
        camera_moved(w, w->home);
        w->pivot = w->home_pivot;
        break;
    default: break;
    }
}

static void handle_event(window_view *w, const SDL_Event *ev)
{
    switch (ev->type) {
    case SDL_QUIT: w->open = false; break;
    case SDL_WINDOWEVENT:
        if (ev->window.event == SDL_WINDOWEVENT_CLOSE)
            w->open = false;
        break;
    case SDL_KEYDOWN: key_down(w, &ev->key.keysym); break;
    case SDL_MOUSEBUTTONDOWN:
        if (w->interactive && !w->drag)
            w->drag = ev->button.button == SDL_BUTTON_LEFT && !(SDL_GetModState() & KMOD_SHIFT) ? 'o' : 'p';
        break;
    case SDL_MOUSEBUTTONUP: w->drag = 0; break;
    case SDL_MOUSEMOTION:
        if (w->drag && (ev->motion.xrel || ev->motion.yrel))
            drag_by(w, ev->motion.xrel, ev->motion.yrel);
        break;
    case SDL_MOUSEWHEEL:
        if (w->interactive) {
            int n = ev->wheel.direction == SDL_MOUSEWHEEL_FLIPPED ? -ev->wheel.y : ev->wheel.y;
            if (n)
                camera_moved(w, rt_camera_dolly(move_start(w), powf(0.85f, (float)n)));
        }
        break;
    default: break;
    }
}

/* RT_WINDOW_SCRIPT: pushes the events of the next steps whose wait is
 * over into SDL's queue (at most one input step a call, so the driver
 * answers each before the next). */
static void push(SDL_Event *e)
{
    if (SDL_PushEvent(e) < 0)
        fprintf(stderr, "rt: RT_WINDOW_SCRIPT: SDL_PushEvent: %s\n", SDL_GetError());
}

static void run_script(window_view *w)
{
    while (w->script_at < w->script_len) {
        const window_step *s = &w->script[w->script_at];
        if (!w->script_armed) { /* the step's start */
            w->script_armed = true;
            w->script_mark = w->shown;
            w->script_since = SDL_GetTicks();
        }
        if ((s->kind == 'd' && !w->render_done) || (s->kind == 'p' && w->shown == w->script_mark) ||
            (s->kind == 's' && SDL_GetTicks() - w->script_since < (Uint32)s->v[0]))
            return;
        SDL_Event e;
        Uint32 id = SDL_GetWindowID((SDL_Window *)w->window);
        if (s->kind == 'g') {
            memset(&e, 0, sizeof e);
            e.type = SDL_MOUSEBUTTONDOWN;
            e.button = (SDL_MouseButtonEvent){.type = SDL_MOUSEBUTTONDOWN, .windowID = id, .button = (Uint8)s->button,
                                              .state = SDL_PRESSED, .clicks = 1, .x = s->v[0], .y = s->v[1]};
            push(&e);
            memset(&e, 0, sizeof e);
            e.motion = (SDL_MouseMotionEvent){.type = SDL_MOUSEMOTION, .windowID = id,
                                              .state = SDL_BUTTON((Uint32)s->button), .x = s->v[2], .y = s->v[3],
                                              .xrel = s->v[2] - s->v[0], .yrel = s->v[3] - s->v[1]};
            push(&e);
            memset(&e, 0, sizeof e);
            e.button = (SDL_MouseButtonEvent){.type = SDL_MOUSEBUTTONUP, .windowID = id, .button = (Uint8)s->button,
                                              .state = SDL_RELEASED, .clicks = 1, .x = s->v[2], .y = s->v[3]};
            push(&e);
        } else if (s->kind == 'w') {
            memset(&e, 0, sizeof e);
            e.wheel = (SDL_MouseWheelEvent){.type = SDL_MOUSEWHEEL, .windowID = id, .y = s->v[0],
                                            .direction = SDL_MOUSEWHEEL_NORMAL};
            push(&e);
        } else if (s->kind == 'k') {
            memset(&e, 0, sizeof e);
            e.key = (SDL_KeyboardEvent){.type = SDL_KEYDOWN, .windowID = id, .state = SDL_PRESSED,
                                        .keysym = {.scancode = SDL_GetScancodeFromKey(s->key), .sym = s->key}};
            push(&e);
            e.key.type = SDL_KEYUP;
            e.key.state = SDL_RELEASED;
            push(&e);
        }
        w->script_at++;
        w->script_armed = false;
        if (s->kind == 'g' || s->kind == 'w' || s->kind == 'k')
            return;
    }
}

static void handle_events(window_view *w)
{
    run_script(w);
    SDL_Event ev;
    while (SDL_PollEvent(&ev))
        handle_event(w, &ev);
}

void window_present(window_view *w)
{
    if (!w->renderer)
        return;
    handle_events(w);
    if (!w->open) {
        window_close(w);
        return;
    }
    SDL_UpdateTexture(w->texture, NULL, w->rgb, 3 * w->width);
    SDL_RenderClear(w->renderer);
    SDL_RenderCopy(w->renderer, w->texture, NULL, NULL);
    SDL_RenderPresent(w->renderer);
}

/* RT_WINDOW_SCREENSHOT: what the renderer shows, read back, as a PPM. */
static void screenshot(window_view *w, const char *path)
{
    window_present(w);
    if (!w->renderer)
        return;
    int ow = 0, oh = 0;
    SDL_GetRendererOutputSize(w->renderer, &ow, &oh);
    unsigned char *px = ow > 0 && oh > 0 ? malloc((size_t)ow * (size_t)oh * 3) : NULL;
    if (px && SDL_RenderReadPixels(w->renderer, NULL, SDL_PIXELFORMAT_RGB24, px, 3 * ow) == 0) {
        FILE *f = fopen(path, "wb");
        if (f) {
            fprintf(f, "P6\n%d %d\n255\n", ow, oh);
            fwrite(px, 3, (size_t)ow * (size_t)oh, f);
            fclose(f);
        }
    }
    free(px);
}

void window_wait(window_view *w, const atomic_int *stop)
{
    const char *shot = getenv("RT_WINDOW_SCREENSHOT");
    if (shot && *shot) {
        screenshot(w, shot);
        w->open = false;
        return;
    }
    while (w->renderer && w->open && !w->requests && !(stop && atomic_load(stop))) {
        window_present(w);
        if (!w->requests)
            SDL_Delay(30);
    }
}

void window_close(window_view *w)
{
    if (w->texture)
        SDL_DestroyTexture(w->texture);
    if (w->renderer)
        SDL_DestroyRenderer(w->renderer);
    if (w->window) {
        SDL_DestroyWindow(w->window);
        SDL_Quit();
    }
    free(w->rgb);
    w->texture = w->renderer = w->window = NULL;
    w->rgb = NULL;
    w->open = false;
}

#else /* no SDL2 */

bool window_open(window_view *w, int width, int height, const char *title, char *why, size_t why_size)
{
    (void)width;
    (void)height;
    (void)title;
    memset(w, 0, sizeof *w);
    snprintf(why, why_size, "this rt was built without SDL2 (install libsdl2-dev and run make again)");
    return false;
}

void window_present(window_view *w)
{
    (void)w;
}

void window_wait(window_view *w, const atomic_int *stop)
{
    (void)w;
    (void)stop;
}

void window_close(window_view *w)
{
    free(w->rgb);
    w->rgb = NULL;
}

#endif
