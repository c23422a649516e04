/* pdt — drawing the viewer's picture into a file: PNG, SVG or PDF by the
 * extension. */
#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <strings.h>

#include "render_int.h"

static int ends_with(const char *s, const char *suf)
{
    size_t a = strlen(s), b = strlen(suf);
    return a >= b && !strcasecmp(s + a - b, suf);
}

pdt_status pdt_render_file(const char *path, int w, int h, const pdt_replay *r,
                           const pdt_rstate *s, const pdt_view *v, pdt_err *err)
{
    cairo_surface_t *sf;
    int png = 0;
    if (ends_with(path, ".png")) {
        sf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
        png = 1;
    } else if (ends_with(path, ".svg")) {
        sf = cairo_svg_surface_create(path, w, h);
    } else if (ends_with(path, ".pdf")) {
        sf = cairo_pdf_surface_create(path, w, h);
    } else {
        return pdt_err_set(err, PDT_ERR_ARG, "%s: unknown picture format (use .png, .svg or .pdf)",
                           path);
    }
    if (cairo_surface_status(sf) != CAIRO_STATUS_SUCCESS) {
        pdt_status st = pdt_err_set(err, PDT_ERR_IO, "%s: %s", path,
                                    cairo_status_to_string(cairo_surface_status(sf)));
        cairo_surface_destroy(sf);
        return st;
    }
    cairo_t *cr = cairo_create(sf);
    pdt_status st = pdt_render(cr, w, h, r, s, v, err);
    cairo_destroy(cr);
    if (st == PDT_OK && png) {
        cairo_status_t cs = cairo_surface_write_to_png(sf, path);
        if (cs != CAIRO_STATUS_SUCCESS)
            st = pdt_err_set(err, PDT_ERR_IO, "%s: %s", path, cairo_status_to_string(cs));
    }
    cairo_surface_finish(sf);
    if (st == PDT_OK && cairo_surface_status(sf) != CAIRO_STATUS_SUCCESS)
        st = pdt_err_set(err, PDT_ERR_IO, "%s: %s", path,
                         cairo_status_to_string(cairo_surface_status(sf)));
    cairo_surface_destroy(sf);
    return st;
}
