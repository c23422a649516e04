/* pdt — drawing the viewer's picture into a file: PNG, SVG or PDF by the
 * extension, written by the rule of pdt/safefile.h (a temporary beside the
 * target, put in place once the picture is complete). */
#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <errno.h>
#include <strings.h>
#include <unistd.h>

#include "pdt/safefile.h"
#include "render_int.h"

static int ends_with(const char *s, const char *suf)
{
    size_t a = strlen(s), b = strlen(suf);
    return a >= b && !strcasecmp(s + a - b, suf);
}

/* Where cairo's bytes go: the temporary's descriptor, and its first error. */
typedef struct sink {
    int fd;
    int err;
} sink;

static cairo_status_t sink_write(void *closure, const unsigned char *data, unsigned int len)
{
    sink *k = closure;
    while (len > 0 && !k->err) {
        ssize_t w = write(k->fd, data, len);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) k->err = w < 0 ? errno : EIO;
        else {
            data += w;
            len -= (unsigned)w;
        }
    }
    return k->err ? CAIRO_STATUS_WRITE_ERROR : CAIRO_STATUS_SUCCESS;
}

/* The surface for path's format, writing into k (PNG: an image, written at
 * the end).  NULL with a message for an unknown format. */
static cairo_surface_t *surface_for(const char *path, int w, int h, sink *k, int *png,
                                    pdt_err *err)
{
    *png = 0;
    if (ends_with(path, ".png")) {
        *png = 1;
        return cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
    }
    if (ends_with(path, ".svg")) return cairo_svg_surface_create_for_stream(sink_write, k, w, h);
    if (ends_with(path, ".pdf")) return cairo_pdf_surface_create_for_stream(sink_write, k, w, h);
    (void)err;
    return NULL;
}

static pdt_status cairo_failed(const char *path, cairo_status_t cs, const sink *k, pdt_err *err)
{
    return pdt_err_set(err, PDT_ERR_IO, "%s: %s", path,
                       k->err ? strerror(k->err) : cairo_status_to_string(cs));
}

pdt_status pdt_render_file_ex(const char *path, int flags, int w, int h, const pdt_replay *r,
                              const pdt_rstate *s, const pdt_view *v, pdt_err *err)
{
    return pdt_render_file_over(path, flags, w, h, r, s, v, NULL, NULL, err);
}

pdt_status pdt_render_file_over(const char *path, int flags, int w, int h, const pdt_replay *r,
                                const pdt_rstate *s, const pdt_view *v, pdt_render_over over,
                                void *user, pdt_err *err)
{
    sink k = {-1, 0};
    int png;
    if (!ends_with(path, ".png") && !ends_with(path, ".svg") && !ends_with(path, ".pdf"))
        return pdt_err_set(err, PDT_ERR_ARG, "%s: unknown picture format (use .png, .svg or "
                           ".pdf)", path);
    pdt_safe_file f;
    pdt_status st = pdt_safe_open(&f, path, flags, err);
    if (st != PDT_OK) return st;
    k.fd = f.fd;
    cairo_surface_t *sf = surface_for(path, w, h, &k, &png, err);
    if (cairo_surface_status(sf) != CAIRO_STATUS_SUCCESS) {
        st = cairo_failed(path, cairo_surface_status(sf), &k, err);
        cairo_surface_destroy(sf);
        pdt_safe_abort(&f);
        return st;
    }
    cairo_t *cr = cairo_create(sf);
    st = pdt_render(cr, w, h, r, s, v, err);
    if (st == PDT_OK && over) over(user, cr, w, h, v);
    cairo_destroy(cr);
    if (st == PDT_OK && png) {
        cairo_status_t cs = cairo_surface_write_to_png_stream(sf, sink_write, &k);
        if (cs != CAIRO_STATUS_SUCCESS) st = cairo_failed(path, cs, &k, err);
    }
    cairo_surface_finish(sf);
    if (st == PDT_OK && (k.err || cairo_surface_status(sf) != CAIRO_STATUS_SUCCESS))
        st = cairo_failed(path, cairo_surface_status(sf), &k, err);
    cairo_surface_destroy(sf);
    if (st == PDT_OK) return pdt_safe_commit(&f, err);
    pdt_safe_abort(&f);
    return st;
}

pdt_status pdt_render_file(const char *path, int w, int h, const pdt_replay *r,
                           const pdt_rstate *s, const pdt_view *v, pdt_err *err)
{
    return pdt_render_file_ex(path, PDT_SAFE_DIRECT, w, h, r, s, v, err);
}
