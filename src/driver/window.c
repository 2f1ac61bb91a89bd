/* window.c - the --window view (window.h) over SDL2 (libsdl2-dev): a
 * streaming RGB24 texture updated from the image as tiles or passes
 * finish, with the tone curve of the PNG writer (exposure, then the sRGB
 * transfer function, rounded to 8 bits; rt_linear_to_srgb in
 * src/scene/texture.c). The software renderer is asked for, so what the
 * window shows is exactly those bytes (and works under Xvfb). Without
 * SDL2 at build time every call is a stub and window_open says why.
 */
#include "window.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt/scene/texture.h"

#ifdef RT_HAVE_SDL2
#include <SDL.h>
#endif

void window_show_rect(window_view *w, const rt_framebuffer *fb, float exposure, int x0, int y0, int x1, int y1)
{
    if (!w->rgb)
        return;
    float e = exposure > 0.0f ? exposure : 1.0f;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            size_t k = 3 * ((size_t)y * (size_t)fb->width + (size_t)x);
            for (int c = 0; c < 3; c++) {
                float v = rt_linear_to_srgb(fb->rgb[k + (size_t)c] * e);
                w->rgb[k + (size_t)c] = (unsigned char)(v * 255.0f + 0.5f);
            }
        }
}

#ifdef RT_HAVE_SDL2

bool window_open(window_view *w, int width, int height, const char *title, char *why, size_t why_size)
{
    memset(w, 0, sizeof *w);
    const char *x11 = getenv("DISPLAY"), *wayland = getenv("WAYLAND_DISPLAY"), *chosen = getenv("SDL_VIDEODRIVER");
    if (!(x11 && *x11) && !(wayland && *wayland) && !(chosen && *chosen)) {
        snprintf(why, why_size, "no display (DISPLAY and WAYLAND_DISPLAY are not set)");
        return false;
    }
    /* a plain X11/Wayland surface, never an OpenGL one: nothing to gain for
     * one texture a pass, and Mesa's threads are then out of the process */
    SDL_SetHint(SDL_HINT_FRAMEBUFFER_ACCELERATION, "0");
    SDL_SetHint(SDL_HINT_RENDER_DRIVER, "software");
    if (SDL_Init(SDL_INIT_VIDEO) != 0) {
        snprintf(why, why_size, "%s", SDL_GetError());
        return false;
    }
    /* SDL falls back to drivers that show nothing; only take one if asked to */
    const char *driver = SDL_GetCurrentVideoDriver();
    if (driver && !(chosen && *chosen) && (strcmp(driver, "offscreen") == 0 || strcmp(driver, "dummy") == 0)) {
        snprintf(why, why_size, "no display could be opened (SDL fell back to its '%s' driver)", driver);
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
    SDL_RenderSetLogicalSize(ren, width, height);
    w->window = win;
    w->renderer = ren;
    w->texture = tex;
    w->rgb = rgb;
    w->width = width;
    w->height = height;
    w->open = true;
    window_present(w);
    return true;
}

static void handle_events(window_view *w)
{
    SDL_Event ev;
    while (SDL_PollEvent(&ev)) {
        if (ev.type == SDL_QUIT ||
            (ev.type == SDL_WINDOWEVENT && ev.window.event == SDL_WINDOWEVENT_CLOSE) ||
            (ev.type == SDL_KEYDOWN && (ev.key.keysym.sym == SDLK_ESCAPE || ev.key.keysym.sym == SDLK_q)))
            w->open = false;
    }
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
        return;
    }
    while (w->renderer && w->open && !(stop && atomic_load(stop))) {
        window_present(w);
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
