/* pdt — the viewer's SDL2 shell (window, input, clock); private to pdtview. */
#ifndef PDT_VIEW_SHELL_H
#define PDT_VIEW_SHELL_H

#include "pdt/view/render.h"

/* Input as the shell saw it, for a hook (the editor): drawable pixels. */
enum { PDT_IN_DOWN = 1, PDT_IN_UP, PDT_IN_MOVE, PDT_IN_KEY };
typedef struct pdt_shell_input {
    int type;        /* PDT_IN_* */
    int button;      /* DOWN / UP: 1 left, 2 middle, 3 right */
    double x, y;     /* mouse position */
    int key;         /* KEY: SDL keycode (the character for letters and digits) */
    int ctrl, shift; /* modifiers held */
} pdt_shell_input;

/* A layer over the replay (the editor, src/view/app/edit.c): it sees input first,
 * may replace the replay the shell shows, and draws over each frame. */
typedef struct pdt_shell_hook {
    void *user;
    /* 1 when it took the input (the shell then ignores it and redraws). */
    int (*input)(void *user, const pdt_shell_input *in, double w, double h, pdt_view *v);
    /* The replay and state to show now; 1 when they changed since the last call. */
    int (*current)(void *user, const pdt_replay **r, pdt_rstate **s);
    /* Draw over the rendered frame (may be NULL). */
    void (*overlay)(void *user, cairo_t *cr, double w, double h, const pdt_view *v);
    /* The window title now, after "pdtview — " (may be NULL: opts.title). */
    const char *(*title)(void *user);
} pdt_shell_hook;

typedef struct pdt_shell_opts {
    int w, h;                 /* initial window size (logical pixels; at most the
                               * screen's usable area) */
    const char *title;
    const char *script;       /* keys to play, or NULL (see docs/viewer.md) */
    const char *screenshot;   /* PNG written at exit (and by `s` if set), or NULL */
    double speed;             /* events per second when playing */
    const char *record;       /* animation written by `r` (.gif/.mp4/.webm), or NULL:
                               * pdtview-rec-NNN.gif */
    double fps;               /* frames per second of a recording (0: 10) */
    int every;                /* events per frame of a recording (0: 1) */
    const pdt_shell_hook *hook; /* or NULL */
    int fullscreen;           /* start full screen (F11 toggles) */
    const char *layout_report;/* the texts of the last frame shown, written at exit
                               * (and by `s`) as JSON (pdt/view/textlog.h), or NULL */
} pdt_shell_opts;

/* Open the window and run until the user (or the script) quits.  The state
 * and the view are the shell's to change.  Returns 0, or 1 if SDL failed
 * (message on stderr: the shell is part of the program, not the library). */
int pdt_shell_run(const pdt_replay *r, pdt_rstate *s, pdt_view *v, const pdt_shell_opts *o);

/* SDL's video on a display a window can be seen on (pdt_shell_run's first
 * step; callers that must not touch a file before the window can open call
 * it first): 1, or 0 with a message on stderr naming the display tried. */
int pdt_shell_video_init(void);

#endif
