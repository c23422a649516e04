/* pdt — animation export (include/pdt/view/anim.h): cairo image surfaces in,
 * an animated GIF (giflib) or a video (libavcodec + libavformat +
 * libswscale) out, written atomically through pdt_out_open().
 *
 * GIF: the palette is built once, from the colours counted in sample
 * frames: exact colours by frequency, accepted while they are at least a
 * distance apart (the distance shrinks pass by pass until 255 are taken or
 * none is left), so the few solid colours of the viewer come first and the
 * antialiasing ramps share what remains.  Pixels map to the nearest entry
 * through a lazily filled 2^24 table (one byte per colour, index + 1).
 * Frames after the first keep only the changed rectangle, unchanged pixels
 * inside it transparent (index 255, disposal "leave in place"). */
#include "pdt/view/anim.h"

#include <dlfcn.h>
#include <errno.h>
#include <gif_lib.h>
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/error.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "pdt/io.h"

enum { TRANSPARENT = 255, HASH_BITS = 18, MAX_TOP = 20000 };

typedef struct colour_count {
    uint32_t rgb;     /* 0x00RRGGBB + 1 (0 = empty slot) */
    uint32_t n;
} colour_count;

typedef struct gif_side {
    GifFileType *gif;
    colour_count *hist;   /* 1 << HASH_BITS slots */
    size_t hist_used;
    GifColorType pal[256];
    int npal;             /* 0 until the palette is made */
    uint8_t *near;        /* 1 << 24 entries: index + 1, 0 = not yet known */
    uint8_t *cur, *prev;  /* w * h indices */
    uint8_t *line;
    long cs_done;         /* hundredths of a second written so far */
} gif_side;

typedef struct av_side {
    AVFormatContext *fmt;
    AVIOContext *io;
    AVCodecContext *enc;
    AVStream *st;
    AVFrame *frame;
    AVPacket *pkt;
    struct SwsContext *sws;
    const char *encoder;
} av_side;

struct pdt_anim {
    pdt_anim_format format;
    pdt_outfile out;
    char *path;
    int w, h;
    double fps;
    size_t frames;
    gif_side g;
    av_side v;
};

/* ---- helpers -------------------------------------------------------------- */

int pdt_anim_format_of(const char *path)
{
    const char *dot = path ? strrchr(path, '.') : NULL;
    if (!dot) return -1;
    if (!strcasecmp(dot, ".gif")) return PDT_ANIM_GIF;
    if (!strcasecmp(dot, ".mp4")) return PDT_ANIM_MP4;
    if (!strcasecmp(dot, ".webm")) return PDT_ANIM_WEBM;
    return -1;
}

static pdt_status gif_fail(pdt_anim *a, int code, const char *what, pdt_err *err)
{
    const char *why = GifErrorString(code);
    return pdt_err_set(err, PDT_ERR_IO, "%s: GIF %s failed: %s", a->path, what,
                       why ? why : "unknown giflib error");
}

/* ---- FFmpeg, loaded when a video is written ------------------------------------
 * libavcodec pulls in codec libraries whose start-up code runs at load time
 * (some of it beyond what valgrind can run), so pdtview does not link them:
 * the four libraries of the version this was built against are opened with
 * dlopen on the first video, and their functions called through pointers. */
#define AV_STR2(x) #x
#define AV_STR(x) AV_STR2(x)
enum { AV_C, AV_F, AV_U, AV_S, AV_NLIB };
#define AV_FUNCS(X) \
    X(C, avcodec_find_encoder_by_name) \
    X(C, avcodec_alloc_context3) \
    X(C, avcodec_open2) \
    X(C, avcodec_parameters_from_context) \
    X(C, avcodec_send_frame) \
    X(C, avcodec_receive_packet) \
    X(C, av_packet_alloc) \
    X(C, av_packet_free) \
    X(C, av_packet_rescale_ts) \
    X(C, avcodec_free_context) \
    X(F, avformat_alloc_output_context2) \
    X(F, avio_alloc_context) \
    X(F, avformat_new_stream) \
    X(F, avformat_write_header) \
    X(F, av_interleaved_write_frame) \
    X(F, av_write_trailer) \
    X(F, avio_flush) \
    X(F, avio_context_free) \
    X(F, avformat_free_context) \
    X(U, av_strerror) \
    X(U, av_log_set_callback) \
    X(U, av_malloc) \
    X(U, av_free) \
    X(U, av_freep) \
    X(U, av_opt_set) \
    X(U, av_d2q) \
    X(U, av_frame_alloc) \
    X(U, av_frame_get_buffer) \
    X(U, av_frame_make_writable) \
    X(U, av_frame_free) \
    X(S, sws_getContext) \
    X(S, sws_scale) \
    X(S, sws_freeContext)
#define AV_DECL(lib, f) static __typeof__(f) *p_##f;
AV_FUNCS(AV_DECL)
static int av_loaded;

static pdt_status av_load(const char *path, pdt_err *err)
{
    if (av_loaded) return PDT_OK;
    static const char *const so[AV_NLIB] = {
        "libavcodec.so." AV_STR(LIBAVCODEC_VERSION_MAJOR),
        "libavformat.so." AV_STR(LIBAVFORMAT_VERSION_MAJOR),
        "libavutil.so." AV_STR(LIBAVUTIL_VERSION_MAJOR),
        "libswscale.so." AV_STR(LIBSWSCALE_VERSION_MAJOR)};
    void *h[AV_NLIB];
    for (int i = 0; i < AV_NLIB; i++) {
        h[i] = dlopen(so[i], RTLD_NOW | RTLD_LOCAL);
        if (!h[i])
            return pdt_err_set(err, PDT_ERR_IO, "%s: cannot write a video: %s (Debian package "
                               "libavcodec-dev and its libraries, see the Makefile's DEB_BUILD)",
                               path, dlerror());
    }
#define AV_LOAD(lib, f)                                                                    \
    if (!(p_##f = (__typeof__(f) *)dlsym(h[AV_##lib], #f)))                                \
        return pdt_err_set(err, PDT_ERR_IO, "%s: cannot write a video: %s has no %s", path, \
                           so[AV_##lib], #f);
    AV_FUNCS(AV_LOAD)
#undef AV_LOAD
    av_loaded = 1;
    return PDT_OK;
}

/* FFmpeg's own messages: never printed (library code); the last error-level
 * one is kept for our message.  (av_log's callback is process-wide.) */
static _Thread_local char av_last[256];

static void av_keep(void *avcl, int level, const char *fmt, va_list vl)
{
    (void)avcl;
    if (level > AV_LOG_ERROR) return;
    vsnprintf(av_last, sizeof av_last, fmt, vl);
    av_last[strcspn(av_last, "\n")] = 0;
}

static pdt_status av_fail(pdt_anim *a, int code, const char *what, pdt_err *err)
{
    char buf[AV_ERROR_MAX_STRING_SIZE] = "";
    p_av_strerror(code, buf, sizeof buf);
    return pdt_err_set(err, PDT_ERR_IO, "%s: %s failed: %s%s%s%s", a->path, what, buf,
                       av_last[0] ? " (" : "", av_last, av_last[0] ? ")" : "");
}

static pdt_status check_image(const pdt_anim *a, cairo_surface_t *img, pdt_err *err)
{
    if (cairo_surface_status(img) != CAIRO_STATUS_SUCCESS)
        return pdt_err_set(err, PDT_ERR_ARG, "%s: frame: %s", a->path,
                           cairo_status_to_string(cairo_surface_status(img)));
    cairo_format_t f = cairo_image_surface_get_format(img);
    if ((f != CAIRO_FORMAT_RGB24 && f != CAIRO_FORMAT_ARGB32) ||
        cairo_image_surface_get_width(img) != a->w || cairo_image_surface_get_height(img) != a->h)
        return pdt_err_set(err, PDT_ERR_ARG, "%s: frame is not a %dx%d RGB image", a->path, a->w,
                           a->h);
    cairo_surface_flush(img);
    return PDT_OK;
}

/* Pixel (x, y) of an RGB24/ARGB32 image as 0x00RRGGBB. */
static inline uint32_t pixel(const unsigned char *data, int stride, int x, int y)
{
    uint32_t p;
    memcpy(&p, data + (size_t)y * (size_t)stride + 4 * (size_t)x, 4);
    return p & 0xFFFFFFu;
}

/* ---- GIF: palette ---------------------------------------------------------- */

static void hist_add(gif_side *g, uint32_t rgb, uint32_t n)
{
    size_t mask = ((size_t)1 << HASH_BITS) - 1;
    size_t i = (size_t)((rgb * 2654435761u) >> (32 - HASH_BITS)) & mask;
    for (;;) {
        colour_count *c = &g->hist[i];
        if (c->rgb == rgb + 1) {
            c->n += n;
            return;
        }
        if (!c->rgb) {
            if (g->hist_used >= mask / 2) return; /* full: rare colours are left out */
            c->rgb = rgb + 1;
            c->n = n;
            g->hist_used++;
            return;
        }
        i = (i + 1) & mask;
    }
}

static int by_count_desc(const void *x, const void *y)
{
    const colour_count *a = x, *b = y;
    if (a->n != b->n) return a->n < b->n ? 1 : -1;
    return a->rgb < b->rgb ? -1 : a->rgb > b->rgb;
}

static long dist2(uint32_t a, uint32_t b)
{
    long dr = (long)((a >> 16) & 255) - (long)((b >> 16) & 255);
    long dg = (long)((a >> 8) & 255) - (long)((b >> 8) & 255);
    long db = (long)(a & 255) - (long)(b & 255);
    return 2 * dr * dr + 4 * dg * dg + db * db;  /* rough perceptual weights */
}

static uint32_t pal_rgb(const GifColorType *c)
{
    return (uint32_t)c->Red << 16 | (uint32_t)c->Green << 8 | c->Blue;
}

/* Choose up to 255 colours from the histogram (see the file comment). */
static void make_palette(gif_side *g)
{
    size_t n = 0, cap = (size_t)1 << HASH_BITS;
    for (size_t i = 0; i < cap; i++)
        if (g->hist[i].rgb) g->hist[n++] = g->hist[i];
    qsort(g->hist, n, sizeof *g->hist, by_count_desc);
    if (n > MAX_TOP) n = MAX_TOP;
    uint8_t *taken = calloc(n ? n : 1, 1);
    /* pass 0: the solid colours (fills, text, lines: at least 1/2000 of the
     * sampled pixels each), whatever their distance; then the rest, spread */
    static const long min_d[] = {1, 7 * 24 * 24, 7 * 12 * 12, 7 * 6 * 6, 7 * 3 * 3, 0};
    uint64_t total = 0;
    for (size_t i = 0; i < n; i++) total += g->hist[i].n;
    int np = 0;
    for (size_t pass = 0; pass < sizeof min_d / sizeof *min_d && np < 255; pass++) {
        for (size_t i = 0; i < n && np < 255; i++) {
            if (taken && taken[i]) continue;
            if (pass == 0 && (np >= 128 || (uint64_t)g->hist[i].n * 2000 < total)) break;
            uint32_t rgb = g->hist[i].rgb - 1;
            int ok = 1;
            for (int j = 0; j < np && ok; j++) ok = dist2(rgb, pal_rgb(&g->pal[j])) >= min_d[pass];
            if (!ok) continue;
            g->pal[np].Red = (GifByteType)(rgb >> 16);
            g->pal[np].Green = (GifByteType)(rgb >> 8);
            g->pal[np].Blue = (GifByteType)rgb;
            np++;
            if (taken) taken[i] = 1;
        }
    }
    free(taken);
    if (np == 0) np = 1; /* no sample: black */
    for (int j = np; j < 256; j++) g->pal[j] = g->pal[0];
    g->npal = np;
}

static uint8_t nearest(gif_side *g, uint32_t rgb)
{
    uint8_t *slot = &g->near[rgb];
    if (*slot) return (uint8_t)(*slot - 1);
    int best = 0;
    long bd = -1;
    for (int j = 0; j < g->npal; j++) {
        long d = dist2(rgb, pal_rgb(&g->pal[j]));
        if (bd < 0 || d < bd) {
            bd = d;
            best = j;
        }
    }
    *slot = (uint8_t)(best + 1);
    return (uint8_t)best;
}

/* ---- GIF: file --------------------------------------------------------------- */

static int gif_write(GifFileType *gif, const GifByteType *buf, int len)
{
    FILE *fp = gif->UserData;
    return (int)fwrite(buf, 1, (size_t)len, fp);
}

static pdt_status gif_open(pdt_anim *a, pdt_err *err)
{
    gif_side *g = &a->g;
    g->hist = calloc((size_t)1 << HASH_BITS, sizeof *g->hist);
    g->near = calloc((size_t)1 << 24, 1);
    size_t px = (size_t)a->w * (size_t)a->h;
    g->cur = malloc(px);
    g->prev = malloc(px);
    g->line = malloc((size_t)a->w);
    if (!g->hist || !g->near || !g->cur || !g->prev || !g->line)
        return pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory", a->path);
    int code = 0;
    g->gif = EGifOpen(a->out.fp, gif_write, &code);
    if (!g->gif) return gif_fail(a, code, "open", err);
    EGifSetGifVersion(g->gif, true);
    return PDT_OK;
}

/* Screen descriptor with the global palette, then the loop-forever block. */
static pdt_status gif_header(pdt_anim *a, pdt_err *err)
{
    gif_side *g = &a->g;
    make_palette(g);
    free(g->hist);
    g->hist = NULL;
    ColorMapObject *map = GifMakeMapObject(256, g->pal);
    if (!map) return pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory", a->path);
    int rc = EGifPutScreenDesc(g->gif, a->w, a->h, 8, 0, map);
    GifFreeMapObject(map);
    if (rc == GIF_ERROR) return gif_fail(a, g->gif->Error, "screen descriptor", err);
    static const GifByteType loop[3] = {1, 0, 0}; /* sub-block 1: loop count 0 = forever */
    if (EGifPutExtensionLeader(g->gif, APPLICATION_EXT_FUNC_CODE) == GIF_ERROR ||
        EGifPutExtensionBlock(g->gif, 11, "NETSCAPE2.0") == GIF_ERROR ||
        EGifPutExtensionBlock(g->gif, 3, loop) == GIF_ERROR ||
        EGifPutExtensionTrailer(g->gif) == GIF_ERROR)
        return gif_fail(a, g->gif->Error, "loop extension", err);
    return PDT_OK;
}

/* Hundredths of a second for frame number a->frames (delays add up to
 * frames / fps, rounded once, not per frame). */
static int gif_delay(pdt_anim *a)
{
    long end = lround(100.0 * (double)(a->frames + 1) / a->fps);
    int d = (int)(end - a->g.cs_done);
    if (d < 1) d = 1;
    a->g.cs_done += d;
    return d;
}

/* The rectangle of pixels that differ from the previous frame; the whole
 * picture for the first frame; a 1x1 rectangle when nothing changed. */
static void changed_box(const pdt_anim *a, int *x0, int *y0, int *x1, int *y1)
{
    const gif_side *g = &a->g;
    if (a->frames == 0) {
        *x0 = *y0 = 0;
        *x1 = a->w;
        *y1 = a->h;
        return;
    }
    int lx = a->w, ly = a->h, hx = -1, hy = -1;
    for (int y = 0; y < a->h; y++) {
        const uint8_t *c = g->cur + (size_t)y * (size_t)a->w, *p = g->prev + (size_t)y * (size_t)a->w;
        if (!memcmp(c, p, (size_t)a->w)) continue;
        int l = 0, r = a->w - 1;
        while (c[l] == p[l]) l++;
        while (c[r] == p[r]) r--;
        if (l < lx) lx = l;
        if (r > hx) hx = r;
        if (y < ly) ly = y;
        hy = y;
    }
    if (hx < 0) lx = ly = hx = hy = 0;
    *x0 = lx;
    *y0 = ly;
    *x1 = hx + 1;
    *y1 = hy + 1;
}

static pdt_status gif_frame(pdt_anim *a, cairo_surface_t *img, pdt_err *err)
{
    gif_side *g = &a->g;
    pdt_status st = PDT_OK;
    if (!g->npal && (st = gif_header(a, err)) != PDT_OK) return st;
    const unsigned char *data = cairo_image_surface_get_data(img);
    int stride = cairo_image_surface_get_stride(img);
    for (int y = 0; y < a->h; y++)
        for (int x = 0; x < a->w; x++)
            g->cur[(size_t)y * (size_t)a->w + (size_t)x] = nearest(g, pixel(data, stride, x, y));
    int x0, y0, x1, y1;
    changed_box(a, &x0, &y0, &x1, &y1);
    int first = a->frames == 0;
    /* graphics control: disposal 1 (leave in place), transparency after frame 0 */
    int delay = gif_delay(a);
    GifByteType gce[4] = {(GifByteType)(1 << 2 | (first ? 0 : 1)), (GifByteType)(delay & 255),
                          (GifByteType)(delay >> 8), first ? 0 : TRANSPARENT};
    if (EGifPutExtension(g->gif, GRAPHICS_EXT_FUNC_CODE, 4, gce) == GIF_ERROR)
        return gif_fail(a, g->gif->Error, "frame delay", err);
    if (EGifPutImageDesc(g->gif, x0, y0, x1 - x0, y1 - y0, false, NULL) == GIF_ERROR)
        return gif_fail(a, g->gif->Error, "image descriptor", err);
    for (int y = y0; y < y1; y++) {
        const uint8_t *c = g->cur + (size_t)y * (size_t)a->w, *p = g->prev + (size_t)y * (size_t)a->w;
        for (int x = x0; x < x1; x++) g->line[x - x0] = !first && c[x] == p[x] ? TRANSPARENT : c[x];
        if (EGifPutLine(g->gif, g->line, x1 - x0) == GIF_ERROR)
            return gif_fail(a, g->gif->Error, "image data", err);
    }
    uint8_t *t = g->prev;
    g->prev = g->cur;
    g->cur = t;
    return PDT_OK;
}

static pdt_status gif_finish(pdt_anim *a, pdt_err *err)
{
    gif_side *g = &a->g;
    if (a->frames == 0)
        return pdt_err_set(err, PDT_ERR_ARG, "%s: no frames to write", a->path);
    int code = 0;
    int rc = EGifCloseFile(g->gif, &code);
    g->gif = NULL;
    if (rc == GIF_ERROR) return gif_fail(a, code, "close", err);
    return PDT_OK;
}

static void gif_free(gif_side *g)
{
    if (g->gif) EGifCloseFile(g->gif, NULL);
    free(g->hist);
    free(g->near);
    free(g->cur);
    free(g->prev);
    free(g->line);
    memset(g, 0, sizeof *g);
}

/* ---- video ---------------------------------------------------------------------- */

static int io_write(void *opaque, uint8_t *buf, int len)
{
    FILE *fp = opaque;
    if (fwrite(buf, 1, (size_t)len, fp) != (size_t)len) return AVERROR(errno ? errno : EIO);
    return len;
}

static int64_t io_seek(void *opaque, int64_t off, int whence)
{
    FILE *fp = opaque;
    if (whence & AVSEEK_SIZE) return -1;
    whence &= ~AVSEEK_FORCE;
    if (fseeko(fp, (off_t)off, whence) != 0) return AVERROR(errno);
    return (int64_t)ftello(fp);
}

/* The first encoder of the list that this libavcodec has. */
static const AVCodec *find_encoder(pdt_anim_format f, const char **name)
{
    static const char *const mp4[] = {"libx264", "mpeg4", NULL};
    static const char *const webm[] = {"libvpx-vp9", "libvpx", NULL};
    for (const char *const *n = f == PDT_ANIM_MP4 ? mp4 : webm; *n; n++) {
        const AVCodec *c = p_avcodec_find_encoder_by_name(*n);
        if (c) {
            *name = *n;
            return c;
        }
    }
    return NULL;
}

/* Quality settings: sharp lines and text on flat colours. */
static void tune(av_side *v)
{
    void *p = v->enc->priv_data;
    if (!strcmp(v->encoder, "libx264")) {
        p_av_opt_set(p, "preset", "veryfast", 0);
        p_av_opt_set(p, "tune", "animation", 0);
        p_av_opt_set(p, "crf", "20", 0);
    } else if (!strncmp(v->encoder, "libvpx", 6)) {
        p_av_opt_set(p, "deadline", "realtime", 0);
        p_av_opt_set(p, "cpu-used", "8", 0);
        p_av_opt_set(p, "crf", "24", 0);
        v->enc->bit_rate = 0;
        if (strcmp(v->encoder, "libvpx-vp9")) v->enc->bit_rate = 4000000; /* VP8 needs one */
    } else {
        v->enc->bit_rate = 6000000;
        v->enc->qmax = 8;
    }
}

static pdt_status video_open(pdt_anim *a, pdt_err *err)
{
    av_side *v = &a->v;
    int rc;
    pdt_status st = av_load(a->path, err);
    if (st != PDT_OK) return st;
    p_av_log_set_callback(av_keep);
    av_last[0] = 0;
    const AVCodec *codec = find_encoder(a->format, &v->encoder);
    if (!codec)
        return pdt_err_set(err, PDT_ERR_ARG, "%s: this libavcodec has no %s encoder", a->path,
                           a->format == PDT_ANIM_MP4 ? "H.264 or MPEG-4" : "VP9 or VP8");
    const char *mux = a->format == PDT_ANIM_MP4 ? "mp4" : "webm";
    if ((rc = p_avformat_alloc_output_context2(&v->fmt, NULL, mux, a->path)) < 0)
        return av_fail(a, rc, "the muxer", err);
    unsigned char *buf = p_av_malloc(1 << 16);
    if (!buf) return pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory", a->path);
    v->io = p_avio_alloc_context(buf, 1 << 16, 1, a->out.fp, NULL, io_write, io_seek);
    if (!v->io) {
        p_av_free(buf);
        return pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory", a->path);
    }
    v->fmt->pb = v->io;
    v->fmt->flags |= AVFMT_FLAG_CUSTOM_IO;
    v->st = p_avformat_new_stream(v->fmt, NULL);
    v->enc = p_avcodec_alloc_context3(codec);
    v->frame = p_av_frame_alloc();
    v->pkt = p_av_packet_alloc();
    if (!v->st || !v->enc || !v->frame || !v->pkt)
        return pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory", a->path);
    AVRational rate = p_av_d2q(a->fps, 100000);
    v->enc->width = a->w;
    v->enc->height = a->h;
    v->enc->pix_fmt = AV_PIX_FMT_YUV420P;
    v->enc->time_base = av_inv_q(rate);
    v->enc->framerate = rate;
    v->enc->gop_size = 60;
    if (v->fmt->oformat->flags & AVFMT_GLOBALHEADER) v->enc->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    tune(v);
    if ((rc = p_avcodec_open2(v->enc, codec, NULL)) < 0) return av_fail(a, rc, v->encoder, err);
    if ((rc = p_avcodec_parameters_from_context(v->st->codecpar, v->enc)) < 0)
        return av_fail(a, rc, "stream parameters", err);
    v->st->time_base = v->enc->time_base;
    v->st->avg_frame_rate = rate;
    v->frame->format = AV_PIX_FMT_YUV420P;
    v->frame->width = a->w;
    v->frame->height = a->h;
    if ((rc = p_av_frame_get_buffer(v->frame, 0)) < 0) return av_fail(a, rc, "frame buffer", err);
    v->sws = p_sws_getContext(a->w, a->h, AV_PIX_FMT_RGB32, a->w, a->h, AV_PIX_FMT_YUV420P,
                            SWS_BICUBIC, NULL, NULL, NULL);
    if (!v->sws)
        return pdt_err_set(err, PDT_ERR_ARG, "%s: swscale cannot convert %dx%d RGB to YUV 4:2:0",
                           a->path, a->w, a->h);
    if ((rc = p_avformat_write_header(v->fmt, NULL)) < 0) return av_fail(a, rc, "the header", err);
    return PDT_OK;
}

/* Send one frame (NULL: flush) and write every packet the encoder returns. */
static pdt_status video_encode(pdt_anim *a, AVFrame *f, pdt_err *err)
{
    av_side *v = &a->v;
    int rc = p_avcodec_send_frame(v->enc, f);
    if (rc < 0) return av_fail(a, rc, v->encoder, err);
    for (;;) {
        rc = p_avcodec_receive_packet(v->enc, v->pkt);
        if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF) return PDT_OK;
        if (rc < 0) return av_fail(a, rc, v->encoder, err);
        p_av_packet_rescale_ts(v->pkt, v->enc->time_base, v->st->time_base);
        v->pkt->stream_index = v->st->index;
        rc = p_av_interleaved_write_frame(v->fmt, v->pkt);
        if (rc < 0) return av_fail(a, rc, "writing a packet", err);
    }
}

static pdt_status video_frame(pdt_anim *a, cairo_surface_t *img, pdt_err *err)
{
    av_side *v = &a->v;
    int rc = p_av_frame_make_writable(v->frame);
    if (rc < 0) return av_fail(a, rc, "frame buffer", err);
    const uint8_t *src[1] = {cairo_image_surface_get_data(img)};
    const int stride[1] = {cairo_image_surface_get_stride(img)};
    p_sws_scale(v->sws, src, stride, 0, a->h, v->frame->data, v->frame->linesize);
    v->frame->pts = (int64_t)a->frames;
    return video_encode(a, v->frame, err);
}

static pdt_status video_finish(pdt_anim *a, pdt_err *err)
{
    av_side *v = &a->v;
    if (a->frames == 0)
        return pdt_err_set(err, PDT_ERR_ARG, "%s: no frames to write", a->path);
    pdt_status st = video_encode(a, NULL, err);
    if (st != PDT_OK) return st;
    int rc = p_av_write_trailer(v->fmt);
    if (rc < 0) return av_fail(a, rc, "the trailer", err);
    p_avio_flush(v->io);
    if (v->io->error < 0) return av_fail(a, v->io->error, "writing", err);
    return PDT_OK;
}

static void video_free(av_side *v)
{
    if (!av_loaded) return;
    p_sws_freeContext(v->sws);
    p_av_packet_free(&v->pkt);
    p_av_frame_free(&v->frame);
    p_avcodec_free_context(&v->enc);
    if (v->io) {
        p_av_freep(&v->io->buffer);
        p_avio_context_free(&v->io);
    }
    p_avformat_free_context(v->fmt);
    memset(v, 0, sizeof *v);
}

/* ---- the API -------------------------------------------------------------------- */

static void anim_free(pdt_anim *a)
{
    gif_free(&a->g);
    video_free(&a->v);
    free(a->path);
    free(a);
}

pdt_status pdt_anim_open(const char *path, int w, int h, double fps, pdt_anim **out,
                         pdt_err *err)
{
    *out = NULL;
    int f = pdt_anim_format_of(path);
    if (f < 0)
        return pdt_err_set(err, PDT_ERR_ARG, "%s: unknown animation format (want .gif, .mp4 "
                           "or .webm)", path ? path : "(none)");
    if (w < 2 || h < 2 || w > 16384 || h > 16384)
        return pdt_err_set(err, PDT_ERR_ARG, "%s: frame size %dx%d out of range", path, w, h);
    if (f != PDT_ANIM_GIF && (w % 2 || h % 2))
        return pdt_err_set(err, PDT_ERR_ARG, "%s: a video needs an even width and height (got "
                           "%dx%d)", path, w, h);
    double maxfps = f == PDT_ANIM_GIF ? 50 : 240;
    if (!(fps > 0 && fps <= maxfps))
        return pdt_err_set(err, PDT_ERR_ARG, "%s: %g frames per second: want more than 0 and at "
                           "most %g%s", path, fps, maxfps,
                           f == PDT_ANIM_GIF ? " (GIF players slow down shorter frames)" : "");
    pdt_anim *a = calloc(1, sizeof *a);
    if (!a) return pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory", path);
    a->format = (pdt_anim_format)f;
    a->w = w;
    a->h = h;
    a->fps = fps;
    a->path = strdup(path);
    if (!a->path) {
        free(a);
        return pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory", path);
    }
    pdt_status st = pdt_out_open(&a->out, path, err);
    if (st == PDT_OK && !a->out.tmp) {
        /* standard output or a device: an animation needs a file to seek in */
        st = pdt_err_set(err, PDT_ERR_ARG, "%s: write the animation to a regular file", path);
    }
    if (st == PDT_OK) st = f == PDT_ANIM_GIF ? gif_open(a, err) : video_open(a, err);
    if (st != PDT_OK) {
        pdt_anim_abort(a);
        return st;
    }
    *out = a;
    return PDT_OK;
}

pdt_status pdt_anim_sample(pdt_anim *a, cairo_surface_t *img, pdt_err *err)
{
    if (a->format != PDT_ANIM_GIF || a->g.npal) return PDT_OK;
    pdt_status st = check_image(a, img, err);
    if (st != PDT_OK) return st;
    const unsigned char *data = cairo_image_surface_get_data(img);
    int stride = cairo_image_surface_get_stride(img);
    for (int y = 0; y < a->h; y++) {
        uint32_t run = pixel(data, stride, 0, y), n = 0;
        for (int x = 0; x < a->w; x++) {
            uint32_t p = pixel(data, stride, x, y);
            if (p == run) {
                n++;
                continue;
            }
            hist_add(&a->g, run, n);
            run = p;
            n = 1;
        }
        hist_add(&a->g, run, n);
    }
    return PDT_OK;
}

pdt_status pdt_anim_frame(pdt_anim *a, cairo_surface_t *img, pdt_err *err)
{
    pdt_status st = check_image(a, img, err);
    if (st != PDT_OK) return st;
    if (a->format == PDT_ANIM_GIF && !a->g.npal && a->g.hist_used == 0 &&
        (st = pdt_anim_sample(a, img, err)) != PDT_OK)
        return st;
    st = a->format == PDT_ANIM_GIF ? gif_frame(a, img, err) : video_frame(a, img, err);
    if (st == PDT_OK) a->frames++;
    return st;
}

size_t pdt_anim_frames(const pdt_anim *a)
{
    return a->frames;
}

const char *pdt_anim_encoder(const pdt_anim *a)
{
    return a->format == PDT_ANIM_GIF ? "giflib" : a->v.encoder;
}

pdt_status pdt_anim_close(pdt_anim *a, pdt_err *err)
{
    pdt_status st = a->format == PDT_ANIM_GIF ? gif_finish(a, err) : video_finish(a, err);
    gif_free(&a->g);    /* both release their hold on the file before it is closed */
    video_free(&a->v);
    if (st == PDT_OK) st = pdt_out_commit(&a->out, err);
    else pdt_out_abort(&a->out);
    anim_free(a);
    return st;
}

void pdt_anim_abort(pdt_anim *a)
{
    if (!a) return;
    gif_free(&a->g);
    video_free(&a->v);
    pdt_out_abort(&a->out);
    anim_free(a);
}

/* ---- a replay ------------------------------------------------------------------- */

static pdt_status draw(cairo_surface_t *img, const pdt_anim_opts *o, const pdt_replay *r,
                       pdt_rstate *s, const pdt_view *v, size_t k, pdt_err *err)
{
    pdt_replay_seek(r, s, k);
    cairo_t *cr = cairo_create(img);
    pdt_status st = pdt_render(cr, o->w, o->h, r, s, v, err);
    cairo_destroy(cr);
    return st;
}

pdt_status pdt_anim_replay(const char *path, const pdt_anim_opts *o, const pdt_replay *r,
                           pdt_rstate *s, const pdt_view *v, size_t *frames, pdt_err *err)
{
    if (frames) *frames = 0;
    size_t m = pdt_replay_count(r), every = o->every ? o->every : 1;
    if (o->from > o->to || o->to > m)
        return pdt_err_set(err, PDT_ERR_ARG, "%s: events %zu to %zu: want from <= to <= %zu (the "
                           "run's events)", path, o->from, o->to, m);
    pdt_anim *a;
    pdt_status st = pdt_anim_open(path, o->w, o->h, o->fps, &a, err);
    if (st != PDT_OK) return st;
    cairo_surface_t *img = cairo_image_surface_create(CAIRO_FORMAT_RGB24, o->w, o->h);
    if (cairo_surface_status(img) != CAIRO_STATUS_SUCCESS)
        st = pdt_err_set(err, PDT_ERR_NOMEM, "%s: %s", path,
                         cairo_status_to_string(cairo_surface_status(img)));
    size_t n = (o->to - o->from + every - 1) / every + 1; /* from, from+every, ..., to */
    /* the palette from 9 frames spread over the animation */
    for (size_t i = 0; i < 9 && st == PDT_OK && pdt_anim_format_of(path) == PDT_ANIM_GIF; i++) {
        size_t k = o->from + (o->to - o->from) * i / 8;
        st = draw(img, o, r, s, v, k, err);
        if (st == PDT_OK) st = pdt_anim_sample(a, img, err);
    }
    for (size_t i = 0; i < n && st == PDT_OK; i++) {
        size_t k = o->from + i * every;
        if (k > o->to || i == n - 1) k = o->to;
        st = draw(img, o, r, s, v, k, err);
        if (st == PDT_OK) st = pdt_anim_frame(a, img, err);
    }
    /* a GIF loops: it rests PDT_ANIM_GIF_HOLD s on its end unless told */
    double hs = o->hold >= 0 ? o->hold : pdt_anim_format_of(path) == PDT_ANIM_GIF ? PDT_ANIM_GIF_HOLD : 0;
    long hold = hs > 0 ? lround(hs * o->fps) : 0;
    for (long i = 0; i < hold && st == PDT_OK; i++) st = pdt_anim_frame(a, img, err);
    cairo_surface_destroy(img);
    size_t written = st == PDT_OK ? pdt_anim_frames(a) : 0;
    if (st == PDT_OK) st = pdt_anim_close(a, err);
    else pdt_anim_abort(a);
    if (st == PDT_OK && frames) *frames = written;
    return st;
}
