/* pdt — the viewer's window (window.c): opened within the screen's usable
 * area, full screen with or without a window manager.  Private to pdtview. */
#ifndef PDT_VIEW_WINDOW_H
#define PDT_VIEW_WINDOW_H

#include <SDL.h>

/* What full screen replaced, to come back to. */
typedef struct pdt_window_saved {
    int borderless;     /* full screen as a borderless window the display's size */
    int x, y, w, h;     /* the window before */
} pdt_window_saved;

/* A resizable window of w x h logical pixels (fullscreen: the whole display)
 * on the display under the mouse, never larger than that display's usable
 * area (the screen less the panels and the window's frame): a window asked
 * larger is shrunk to it, keeping nothing off-screen.  NULL on failure
 * (SDL_GetError says why). */
SDL_Window *pdt_window_open(const char *title, int w, int h, int fullscreen, pdt_window_saved *sv);

/* Full screen on or off.  With a window manager, SDL's desktop full screen;
 * without one (it would do nothing), a borderless window covering the
 * display, and back. */
void pdt_window_fullscreen(SDL_Window *win, int on, pdt_window_saved *sv);

#endif
