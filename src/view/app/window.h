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

/* A resizable window of w x h logical pixels on the first display, never
 * larger than its usable area (the screen less the panels), hidden: shown
 * (SDL_ShowWindow) once it has its renderer, so that it is not mapped, then
 * made again with OpenGL, then mapped again.  NULL on failure (SDL_GetError
 * says why). */
SDL_Window *pdt_window_open(const char *title, int w, int h, pdt_window_saved *sv);

/* Once the window has its renderer (which may make SDL recreate it): wait
 * for a window manager's frame, shrink and move the window so that frame
 * and all lie in the usable area, and go full screen if asked. */
void pdt_window_settle(SDL_Window *win, int fullscreen, pdt_window_saved *sv);

/* Full screen on or off.  With a window manager, SDL's desktop full screen;
 * without one (it would do nothing), a borderless window covering the
 * display, and back. */
void pdt_window_fullscreen(SDL_Window *win, int on, pdt_window_saved *sv);

#endif
