/* pdt — animation export: replay frames (cairo image surfaces) into an
 * animated GIF (giflib) or a video (libavcodec/libavformat: .mp4 as H.264
 * when the installed libavcodec has libx264, else MPEG-4 Part 2; .webm as
 * VP9, else VP8, via libvpx).
 *
 * GIF: one global palette of at most 255 colours built from sample frames
 * (the viewer draws few colours: the most frequent exact colours are kept,
 * spread out so that antialiasing ramps do not crowd out a rank colour;
 * every other colour is mapped to its nearest entry), index 255 is
 * transparent.  Each frame after the first stores only the bounding box of
 * the pixels that changed, with unchanged pixels inside it transparent, so a
 * short run's GIF stays small.  Frame delays are whole hundredths of a
 * second, spread so that the total is frames / fps.
 *
 * Output is atomic: everything goes to a temporary file beside the target,
 * renamed into place by pdt_anim_close(); on any error (or pdt_anim_abort)
 * nothing is left behind.  Library code: no prints; every giflib / FFmpeg
 * status is turned into a pdt_status with a message naming the file. */
#ifndef PDT_ANIM_H
#define PDT_ANIM_H

#include <cairo.h>

#include "pdt/view/render.h"
#include "pdt/view/replay.h"

typedef enum pdt_anim_format {
    PDT_ANIM_GIF = 0,
    PDT_ANIM_MP4,
    PDT_ANIM_WEBM
} pdt_anim_format;

/* The format named by the extension of `path` (.gif, .mp4, .webm; case
 * ignored), or -1. */
int pdt_anim_format_of(const char *path);

typedef struct pdt_anim pdt_anim;

/* Start writing `path` (format from its extension) with frames of w x h
 * pixels at `fps` frames per second.  Requires 0 < fps <= 50 for a GIF
 * (players slow down shorter delays) and <= 240 for a video; even w and h
 * for a video (4:2:0 chroma).  The caller owns *a: pdt_anim_close() or
 * pdt_anim_abort(). */
pdt_status pdt_anim_open(const char *path, int w, int h, double fps, pdt_anim **a,
                         pdt_err *err);
/* GIF: count the colours of a frame that will come (call before the first
 * pdt_anim_frame; frames from across the animation give the best palette).
 * Videos need no palette: a no-op. `img` is CAIRO_FORMAT_RGB24 or ARGB32 of
 * the size given to pdt_anim_open. */
pdt_status pdt_anim_sample(pdt_anim *a, cairo_surface_t *img, pdt_err *err);
/* Append one frame (same requirements as pdt_anim_sample). */
pdt_status pdt_anim_frame(pdt_anim *a, cairo_surface_t *img, pdt_err *err);
/* Frames appended so far. */
size_t pdt_anim_frames(const pdt_anim *a);
/* The encoder in use ("giflib", "libx264", "mpeg4", "libvpx-vp9", ...). */
const char *pdt_anim_encoder(const pdt_anim *a);
/* Finish the file (flush the encoder, write the trailer), rename it into
 * place and free a.  On error nothing is left at `path` and a is freed. */
pdt_status pdt_anim_close(pdt_anim *a, pdt_err *err);
/* Free a and remove the temporary file (a may be NULL). */
void pdt_anim_abort(pdt_anim *a);

/* Seconds a GIF rests on its last frame before it loops, by default. */
#define PDT_ANIM_GIF_HOLD 2.0

/* What part of a replay to animate, and how. */
typedef struct pdt_anim_opts {
    int w, h;           /* frame size in pixels */
    double fps;         /* frames per second */
    size_t from, to;    /* cursors: from <= to <= pdt_replay_count(r) */
    size_t every;       /* events per frame (>= 1) */
    double hold;        /* seconds the last frame stays (0: one frame; < 0: the
                         * default, PDT_ANIM_GIF_HOLD for a GIF, 0 for a video) */
} pdt_anim_opts;

/* Write the replay from cursor o->from to o->to, one frame every o->every
 * events (the last frame is always cursor o->to), drawn by pdt_render() with
 * view v (the event line at the top is the caption), into `path`.  s is
 * used as scratch and left at o->to.  *frames (may be NULL) gets the number
 * of frames written. */
pdt_status pdt_anim_replay(const char *path, const pdt_anim_opts *o, const pdt_replay *r,
                           pdt_rstate *s, const pdt_view *v, size_t *frames, pdt_err *err);

#endif
