/* pdt — level of detail: a run of millions of triangles drawn as a picture of
 * its coverage instead of one stroke per edge.
 *
 * When the triangles in the geometry area are far more than its pixels can
 * show apart (more than one per LOD_PX_PER_TRI pixels, and at least
 * LOD_MIN_TRIS of them), the area is cut into cells of LOD_CELL_PX pixels,
 * the model aggregates the visible triangles per cell (pdt_replay_coverage:
 * how many, by status, one maker rank or mixed), and each cell is painted:
 * the maker's rank colour (its group's where the makers are ranks of one
 * group, dark grey where groups mix: seams and merge regions), pale while its triangles are mostly candidates, shipped or
 * deferred, red where most were discarded lately (discarded triangles fade
 * out as the edges' do: at a run's end none is left).  Zoomed in far enough, the real
 * edges come back.  Classroom runs (thousands of triangles) never reach
 * LOD_MIN_TRIS: their picture is unchanged. */
#include "render_int.h"

#define LOD_MIN_TRIS 200000u  /* fewer triangles: always drawn one by one */
#define LOD_PX_PER_TRI 6.0    /* denser than a triangle per this many pixels: aggregate */
#define LOD_CELL_PX 2         /* cell size in pixels */

/* Ranks lo and hi in one group of the colours shown (a group is a run of
 * consecutive ranks: a subtree of the merge tree). */
static int same_group(const ctx *cx, uint32_t lo, uint32_t hi)
{
    return cx->hue && hi < (uint32_t)cx->nranks && cx->hue[lo] != 255 && cx->hue[lo] == cx->hue[hi];
}

/* The colour of a cell (premultiplied ARGB32). */
static uint32_t cell_argb(const ctx *cx, const pdt_cov_cell *cell)
{
    double c[3] = {0.25, 0.25, 0.28};
    if (cell->rank != PDT_COV_MIXED) ctx_rank_rgb(cx, (int)cell->rank, c);
    else if (same_group(cx, cell->rank_lo, cell->rank_hi)) ctx_rank_rgb(cx, (int)cell->rank_lo, c);
    double n = cell->n;
    double pale = (cell->by_status[PDT_TS_CANDIDATE] + cell->by_status[PDT_TS_SHIPPED] +
                   cell->by_status[PDT_TS_DEFERRED]) / n;
    double red = cell->by_status[PDT_TS_DISCARDED] / n;
    for (int i = 0; i < 3; i++) c[i] += (1 - c[i]) * 0.55 * pale;
    if (red > 0.5) {
        c[0] = 0.85;
        c[1] = c[2] = 0.1;
    }
    const double a = 0.9;
    uint32_t A = (uint32_t)(255 * a + 0.5);
    uint32_t R = (uint32_t)(255 * a * c[0] + 0.5), G = (uint32_t)(255 * a * c[1] + 0.5),
             B = (uint32_t)(255 * a * c[2] + 0.5);
    return A << 24 | R << 16 | G << 8 | B;
}

int pdt_draw_lod(ctx *c)
{
    size_t nt;
    pdt_replay_tris(c->r, &nt);
    if (nt < LOD_MIN_TRIS) return 0;
    pdt_rect G = c->L.geo;
    int cols = (int)(G.w / LOD_CELL_PX), rows = (int)(G.h / LOD_CELL_PX);
    if (cols < 1 || rows < 1) return 0;
    /* the world box under the area: screen = (ox + s*x, oy - s*y) */
    double x0 = (G.x - c->X.ox) / c->X.s, x1 = (G.x + cols * LOD_CELL_PX - c->X.ox) / c->X.s;
    double y1 = (c->X.oy - G.y) / c->X.s, y0 = (c->X.oy - G.y - rows * LOD_CELL_PX) / c->X.s;
    pdt_cov_cell *cells = malloc((size_t)cols * (size_t)rows * sizeof *cells);
    uint8_t *vis = malloc((size_t)c->nranks + 1);
    if (!cells || !vis) {
        free(cells);
        free(vis);
        return 0;  /* draw the edges instead */
    }
    for (int q = 0; q < c->nranks; q++) vis[q] = !(c->v->hidden && c->v->hidden[q]);
    size_t binned = pdt_replay_coverage(c->r, c->s, x0, y0, x1, y1, cols, rows, vis,
                                        c->v->fade > 0 ? (uint64_t)c->v->fade : 0, cells);
    int drew = 0;
    if ((double)binned * LOD_PX_PER_TRI >= G.w * G.h) {
        cairo_surface_t *img = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, cols, rows);
        if (cairo_surface_status(img) == CAIRO_STATUS_SUCCESS) {
            cairo_surface_flush(img);
            unsigned char *data = cairo_image_surface_get_data(img);
            int stride = cairo_image_surface_get_stride(img);
            for (int j = 0; j < rows; j++) {  /* image row 0 is the top: world row rows-1 */
                uint32_t *px = (uint32_t *)(void *)(data + (size_t)j * (size_t)stride);
                const pdt_cov_cell *row = cells + (size_t)(rows - 1 - j) * (size_t)cols;
                for (int i = 0; i < cols; i++) px[i] = row[i].n ? cell_argb(c, &row[i]) : 0;
            }
            cairo_surface_mark_dirty(img);
            cairo_t *cr = c->cr;
            cairo_save(cr);
            cairo_translate(cr, G.x, G.y);
            cairo_scale(cr, LOD_CELL_PX, LOD_CELL_PX);
            cairo_set_source_surface(cr, img, 0, 0);
            cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
            cairo_paint(cr);
            cairo_restore(cr);
            drew = 1;
        }
        cairo_surface_destroy(img);
    }
    free(cells);
    free(vis);
    return drew;
}
