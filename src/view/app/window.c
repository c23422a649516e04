/* pdt — the viewer's window: opened within the display's usable bounds, and
 * full screen that works with or without a window manager (window.h). */
#include "window.h"

#include <string.h>

/* The display the window is on (or the first), its whole and usable area. */
static void display_of(SDL_Window *win, SDL_Rect *whole, SDL_Rect *usable)
{
    int d = win ? SDL_GetWindowDisplayIndex(win) : 0;
    if (d < 0) d = 0;
    if (SDL_GetDisplayBounds(d, whole) != 0) *whole = (SDL_Rect){0, 0, 1024, 768};
    if (SDL_GetDisplayUsableBounds(d, usable) != 0 || usable->w <= 0 || usable->h <= 0)
        *usable = *whole;
}

/* Let the window system answer (a window manager frames and places a new
 * window): events pumped for up to ms milliseconds, or until done(win). */
static void settle(SDL_Window *win, int ms, int (*done)(SDL_Window *))
{
    for (int t = 0; t < ms; t += 10) {
        SDL_PumpEvents();
        if (done && done(win)) return;
        SDL_Delay(10);
    }
}

static int framed(SDL_Window *win)
{
    int t = 0, l = 0, b = 0, r = 0;
    return SDL_GetWindowBordersSize(win, &t, &l, &b, &r) == 0 && (t || l || b || r);
}

/* Shrink and move the window so that it and its frame lie in the usable
 * area. */
static void fit_usable(SDL_Window *win)
{
    SDL_Rect D, U;
    display_of(win, &D, &U);
    int t = 0, l = 0, b = 0, r = 0, w, h, x, y;
    if (SDL_GetWindowBordersSize(win, &t, &l, &b, &r) != 0) t = l = b = r = 0;
    SDL_GetWindowSize(win, &w, &h);
    SDL_GetWindowPosition(win, &x, &y);
    int mw = U.w - l - r, mh = U.h - t - b;
    int nw = w < mw ? w : mw, nh = h < mh ? h : mh;
    if (nw != w || nh != h) SDL_SetWindowSize(win, nw, nh);
    int nx = x - l < U.x ? U.x + l : x + nw + r > U.x + U.w ? U.x + U.w - r - nw : x;
    int ny = y - t < U.y ? U.y + t : y + nh + b > U.y + U.h ? U.y + U.h - b - nh : y;
    if (nx != x || ny != y) SDL_SetWindowPosition(win, nx, ny);
}

SDL_Window *pdt_window_open(const char *title, int w, int h, pdt_window_saved *sv)
{
    SDL_Rect D, U;
    display_of(NULL, &D, &U);
    if (w > U.w) w = U.w;
    if (h > U.h) h = U.h;
    memset(sv, 0, sizeof *sv);
    SDL_Window *win = SDL_CreateWindow(title, U.x + (U.w - w) / 2, U.y + (U.h - h) / 2, w, h,
                                       SDL_WINDOW_RESIZABLE | SDL_WINDOW_ALLOW_HIGHDPI | SDL_WINDOW_HIDDEN);
    return win;
}

void pdt_window_settle(SDL_Window *win, int fullscreen, pdt_window_saved *sv)
{
    settle(win, 300, framed); /* a window manager's frame, if there is one */
    fit_usable(win);
    if (fullscreen) pdt_window_fullscreen(win, 1, sv);
}

static int covers_display(SDL_Window *win)
{
    SDL_Rect D, U;
    int w, h;
    display_of(win, &D, &U);
    SDL_GetWindowSize(win, &w, &h);
    return w == D.w && h == D.h;
}

void pdt_window_fullscreen(SDL_Window *win, int on, pdt_window_saved *sv)
{
    if (!on) {
        SDL_SetWindowFullscreen(win, 0);
        if (sv->borderless) SDL_SetWindowBordered(win, SDL_TRUE);
        sv->borderless = 0;
        if (sv->w <= 0) return; /* opened full screen: the size SDL chose */
        /* without a window manager nobody else puts it back */
        SDL_SetWindowSize(win, sv->w, sv->h);
        SDL_SetWindowPosition(win, sv->x, sv->y);
        return;
    }
    if (!(SDL_GetWindowFlags(win) & SDL_WINDOW_FULLSCREEN) && !sv->borderless) {
        SDL_GetWindowPosition(win, &sv->x, &sv->y);
        SDL_GetWindowSize(win, &sv->w, &sv->h);
    }
    SDL_SetWindowFullscreen(win, SDL_WINDOW_FULLSCREEN_DESKTOP);
    settle(win, 400, covers_display);
    if (covers_display(win)) return;
    /* no window manager took it: a borderless window over the display */
    SDL_Rect D, U;
    display_of(win, &D, &U);
    SDL_SetWindowFullscreen(win, 0);
    SDL_SetWindowBordered(win, SDL_FALSE);
    SDL_SetWindowPosition(win, D.x, D.y);
    SDL_SetWindowSize(win, D.w, D.h);
    SDL_RaiseWindow(win);
    sv->borderless = 1;
}
