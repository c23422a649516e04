/* pdt — the viewer's SDL2 shell (window, input, clock); private to pdtview. */
#ifndef PDT_VIEW_SHELL_H
#define PDT_VIEW_SHELL_H

#include "pdt/render.h"

typedef struct pdt_shell_opts {
    int w, h;                 /* initial window size (logical pixels) */
    const char *title;
    const char *script;       /* keys to play, or NULL (see docs/viewer.md) */
    const char *screenshot;   /* PNG written at exit (and by `s` if set), or NULL */
    double speed;             /* events per second when playing */
} pdt_shell_opts;

/* Open the window and run until the user (or the script) quits.  The state
 * and the view are the shell's to change.  Returns 0, or 1 if SDL failed
 * (message on stderr: the shell is part of the program, not the library). */
int pdt_shell_run(const pdt_replay *r, pdt_rstate *s, pdt_view *v, const pdt_shell_opts *o);

#endif
