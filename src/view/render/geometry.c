/* pdt — the world picture of the viewer: strip boxes, triangles by status
 * and rank, kernel edges, hulls and stacks, points and their labels, the
 * merge in progress, the current event's highlight, the selection. */
#include "pdt/view/describe.h"
#include "render_int.h"


/* ---- the geometry --------------------------------------------------------------------- */

static int overlaps(const lbox *B, size_t nb, lbox b);

/* Where a strip's label goes: under the box (y1) for `below`, else above
 * (y0), else the other side, at x; 0 when both would cover a label placed
 * before (the label is left out: thinned).  The box is then taken. */
static int place_box_label(ctx *c, int below, double x, double y0, double y1, double tw, double fs,
                           double *ly)
{
    for (int k = 0; k < 2; k++) {
        int under = k ? !below : below;
        double y = under ? y1 + 1.05 * fs : y0 - 0.3 * fs;
        lbox b = {x - 0.1 * fs, y - 0.95 * fs, x + tw + 0.1 * fs, y + 0.3 * fs};
        const pdt_rect *G = &c->L.geo; /* zoomed in, a side may be off the picture */
        if (b.x0 < G->x || b.x1 > G->x + G->w || b.y0 < G->y || b.y1 > G->y + G->h) continue;
        if (overlaps(c->taken, (size_t)c->ntaken, b)) continue;
        if (c->ntaken < TAKEN_MAX) c->taken[c->ntaken++] = b;
        *ly = y;
        return 1;
    }
    return 0;
}

/* The strip boxes (labels = 0) or their labels (labels = 1, drawn last, on a
 * white ground so that edges and hulls do not hide them). */
static void draw_boxes(ctx *c, int cur_tri_ok, int labels)
{
    cairo_t *cr = c->cr;
    int cur_rank = c->cur ? (int)c->cur->rank : -1;
    if (labels && pdt_draw_group_labels(c)) return;
    for (int q = 0; q < c->nranks; q++) {
        pdt_point lo, hi;
        if (!shown(c, (uint32_t)q) || !pdt_replay_box(c->r, q, &lo, &hi)) continue;
        if (c->s->k < pdt_replay_box_from(c->r, q)) continue; /* not before its partition */
        double x0 = c->X.ox + c->X.s * lo.x, x1 = c->X.ox + c->X.s * hi.x;
        double y0 = c->X.oy - c->X.s * hi.y, y1 = c->X.oy - c->X.s * lo.y;
        double pad = 0.4 * c->L.font;
        /* the same test as the event line's: a deferral names these ranks (on
         * other events, a discard say, nothing is "touched") */
        int touched = cur_tri_ok && c->cur->ev.kind == PDT_EV_RA_DEFER && q != cur_rank &&
                      pdt_replay_disk_touches(c->r, (const uint32_t[3]){c->cur->ev.a, c->cur->ev.b, c->cur->ev.c}, q);
        if (!labels) {
            cairo_rectangle(cr, x0 - pad, y0 - pad, x1 - x0 + 2 * pad, y1 - y0 + 2 * pad);
            /* opaque tint (rank colour over white): much cheaper than alpha on big areas */
            double col[3], a = (touched ? 0.16 : 0.05) * c->T->tint;
            const double *bg = c->T->bg;
            ctx_rank_rgb(c, q, col);
            cairo_set_source_rgb(cr, (1 - a) * bg[0] + a * col[0], (1 - a) * bg[1] + a * col[1],
                                 (1 - a) * bg[2] + a * col[2]);
            cairo_fill_preserve(cr);
            set_rank(c, q, touched ? 0.95 : 0.5);
            double d[2] = {4, 3};
            cairo_set_dash(cr, touched ? NULL : d, touched ? 0 : 2, 0);
            cairo_set_line_width(cr, touched ? 2.5 * c->lw : 1);
            cairo_stroke(cr);
            cairo_set_dash(cr, NULL, 0, 0);
            continue;
        }
        char lab[32];
        double fs = c->L.label;
        /* the label may run past a narrow strip up to the next strip whose
         * label is on the same side (ranks alternate above and below) */
        double room = c->L.geo.x + c->L.geo.w - x0;
        pdt_point lo2, hi2;
        if (q + 2 < c->nranks && pdt_replay_box(c->r, q + 2, &lo2, &hi2))
            room = fmin(room, c->X.ox + c->X.s * lo2.x - x0 - pad);
        room = fmax(room, x1 - x0 + 2 * pad + 0.3 * c->L.font);
        snprintf(lab, sizeof lab, touched ? "rank %d (touched)" : "rank %d", q);
        if (text_wb(cr, SANS, touched, fs, lab) > room)
            snprintf(lab, sizeof lab, touched ? "r%d touched" : "r%d", q);
        if (text_wb(cr, SANS, touched, fs, lab) > room)
            snprintf(lab, sizeof lab, touched ? "r%d!" : "r%d", q); /* very narrow strips */
        double tw = text_wb(cr, SANS, touched, fs, lab);
        double ly;
        if (!place_box_label(c, q % 2, x0 - pad, y0 - pad, y1 + pad, tw, fs, &ly)) continue;
        cairo_rectangle(cr, x0 - pad - 0.1 * fs, ly - 0.85 * fs, tw + 0.2 * fs, 1.1 * fs);
        rgb(cr, c->T->bg, 0.8);
        cairo_fill(cr);
        set_rank(c, q, 1);
        text_at(cr, SANS, touched, fs, x0 - pad, ly, lab);
    }
}

static int cmp_u64(const void *x, const void *y)
{
    uint64_t a = *(const uint64_t *)x, b = *(const uint64_t *)y;
    return (a > b) - (a < b);
}

size_t pdt_unique_edges(uint64_t *e, size_t n)
{
    qsort(e, n, sizeof *e, cmp_u64);
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (!k || e[i] != e[k - 1]) e[k++] = e[i];
    return k;
}

/* The triangles shown, bucketed by (status, maker) so that each bucket is
 * one stroke: bucket b is order[start[b] .. start[b + 1]).  0 when out of
 * memory. */
static int bucket_tris(const ctx *c, size_t nt, size_t nb, size_t *start, uint32_t *order)
{
    const pdt_rtri *T = pdt_replay_tris(c->r, &(size_t){0});
    const pdt_rtri_hist *H = pdt_replay_tri_hist(c->r);
    for (size_t t = 0; t < nt; t++) {
        uint32_t h = pdt_rstate_tri_entry(c->r, c->s, t);
        if (h == NONE32 || !shown(c, T[t].maker)) continue;
        start[(size_t)H[h].status * (size_t)c->nranks + T[t].maker + 1]++;
    }
    for (size_t b = 0; b < nb; b++) start[b + 1] += start[b];
    size_t *fill = malloc((nb + 1) * sizeof *fill);
    if (!fill) return 0;
    memcpy(fill, start, (nb + 1) * sizeof *fill);
    for (size_t t = 0; t < nt; t++) {
        uint32_t h = pdt_rstate_tri_entry(c->r, c->s, t);
        if (h == NONE32 || !shown(c, T[t].maker)) continue;
        order[fill[(size_t)H[h].status * (size_t)c->nranks + T[t].maker]++] = (uint32_t)t;
    }
    free(fill);
    return 1;
}

/* Discarded triangles (of rank q, order[from .. to)), fading with age, each
 * with a red cross. */
static void draw_discarded(ctx *c, int q, const uint32_t *order, size_t from, size_t to)
{
    cairo_t *cr = c->cr;
    const pdt_rtri *T = pdt_replay_tris(c->r, &(size_t){0});
    const pdt_rtri_hist *H = pdt_replay_tri_hist(c->r);
    for (size_t i = from; i < to; i++) {
        uint32_t t = order[i];
        double age = (double)c->s->k - H[pdt_rstate_tri_entry(c->r, c->s, t)].ev;
        double a = c->v->fade > 0 ? 1 - age / c->v->fade : 1;
        if (a <= 0.02) continue;
        pdt_status_style(cr, PDT_TS_DISCARDED, c->lw);
        tri_path(c, T[t].v);
        set_rank(c, q, 0.6 * a);
        cairo_stroke(cr);
        double x = 0, y = 0, px, py;
        for (int j = 0; j < 3; j++) {
            wpt(c, T[t].v[j], &px, &py);
            x += px / 3;
            y += py / 3;
        }
        cairo_set_line_width(cr, 1.6 * c->lw);
        cross(cr, x, y, 0.35 * c->L.font);
        rgb(cr, RED, a);
        cairo_stroke(cr);
    }
}

/* The edges of triangles order[from .. to) inside the picture, each once
 * (two triangles of a bucket share most of theirs), as separate segments
 * (no joins) stroked in chunks: much faster than one long path of closed
 * triangles.  edges: room for 3 (to - from). */
static void stroke_bucket_edges(ctx *c, const uint32_t *order, size_t from, size_t to,
                                uint64_t *edges)
{
    cairo_t *cr = c->cr;
    const pdt_rtri *T = pdt_replay_tris(c->r, &(size_t){0});
    double gx0 = c->L.geo.x, gx1 = c->L.geo.x + c->L.geo.w, gy0 = c->L.geo.y, gy1 = c->L.geo.y + c->L.geo.h;
    size_t ne = 0;
    for (size_t i = from; i < to; i++) {
        const uint32_t *v = T[order[i]].v;
        double x[3], y[3];
        for (int j = 0; j < 3; j++) wpt(c, v[j], &x[j], &y[j]);
        if ((x[0] < gx0 && x[1] < gx0 && x[2] < gx0) || (x[0] > gx1 && x[1] > gx1 && x[2] > gx1) ||
            (y[0] < gy0 && y[1] < gy0 && y[2] < gy0) || (y[0] > gy1 && y[1] > gy1 && y[2] > gy1))
            continue;
        for (int j = 0; j < 3; j++) {
            uint32_t a = v[j], e = v[(j + 1) % 3];
            edges[ne++] = a < e ? (uint64_t)a << 32 | e : (uint64_t)e << 32 | a;
        }
    }
    ne = pdt_unique_edges(edges, ne);
    size_t seg = 0;
    for (size_t i = 0; i < ne; i++) {
        double x0, y0, x1, y1;
        wpt(c, (uint32_t)(edges[i] >> 32), &x0, &y0);
        wpt(c, (uint32_t)edges[i], &x1, &y1);
        cairo_move_to(cr, x0, y0);
        cairo_line_to(cr, x1, y1);
        if (++seg >= 3000) {
            cairo_stroke(cr);
            seg = 0;
        }
    }
    cairo_stroke(cr);
}

/* Bucket b (status st, rank q): its triangles in their status' style. */
static void draw_bucket(ctx *c, int st, int q, const uint32_t *order, size_t from, size_t to,
                        int dense, uint64_t *edges)
{
    cairo_t *cr = c->cr;
    if (st == PDT_TS_DISCARDED) {
        draw_discarded(c, q, order, from, to);
        return;
    }
    if (c->v->clean && !dense) { /* T* filled by rank */
        const pdt_rtri *T = pdt_replay_tris(c->r, &(size_t){0});
        for (size_t i = from; i < to; i++) tri_path(c, T[order[i]].v);
        set_rank(c, q, 0.16);
        cairo_fill(cr);
    }
    pdt_status_style(cr, st, dense ? 0.8 : c->lw);
    set_rank(c, q, st == PDT_TS_CANDIDATE ? 0.75 : 1);
    stroke_bucket_edges(c, order, from, to, edges);
}

static void draw_triangles(ctx *c)
{
    cairo_t *cr = c->cr;
    size_t nt;
    pdt_replay_tris(c->r, &nt);
    if (!nt || pdt_draw_lod(c)) return;  /* millions of triangles: their coverage */
    nt = pdt_replay_born_at_most(c->r, c->s->k);  /* none beyond has an entry yet */
    size_t nb = (size_t)PDT_TS_COUNT * (size_t)c->nranks;
    size_t *start = calloc(nb + 1, sizeof *start);
    uint32_t *order = malloc(nt * sizeof *order);
    uint64_t *edges = malloc(3 * nt * sizeof *edges); /* one bucket's edges */
    if (!start || !order || !edges || !bucket_tris(c, nt, nb, start, order)) {
        free(start);
        free(order);
        free(edges);
        return;
    }
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    /* dense pictures: thin lines without antialiasing (a mesh of 10^5 edges
     * looks the same and draws several times faster) */
    int dense = start[nb] > 10000;
    cairo_save(cr);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
    cairo_set_antialias(cr, dense ? CAIRO_ANTIALIAS_NONE : CAIRO_ANTIALIAS_FAST);
    /* discarded first (underneath), fading; then candidate, shipped, deferred, final */
    static const int order_st[] = {PDT_TS_DISCARDED, PDT_TS_CANDIDATE, PDT_TS_SHIPPED,
                                   PDT_TS_DEFERRED, PDT_TS_FINAL};
    for (int oi = 0; oi < 5; oi++) {
        int st = order_st[oi];
        if (c->v->clean && st != PDT_TS_FINAL) continue; /* the clean picture: T* only */
        for (int q = 0; q < c->nranks; q++) {
            size_t b = (size_t)st * (size_t)c->nranks + (size_t)q;
            if (start[b] != start[b + 1]) draw_bucket(c, st, q, order, start[b], start[b + 1], dense, edges);
        }
    }
    cairo_restore(cr);
    cairo_set_dash(cr, NULL, 0, 0);
    free(start);
    free(order);
    free(edges);
}

static void draw_kernel_edges(ctx *c)
{
    size_t ne;
    const pdt_redge *E = pdt_replay_edges(c->r, &ne);
    if (!ne) return;
    cairo_t *cr = c->cr;
    size_t np;
    const pdt_rphase *Ph = pdt_replay_phases(c->r, &np);
    cairo_save(cr);
    cairo_set_line_width(cr, 0.5 * c->lw);
    if (ne > 20000) cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);
    for (int q = 0; q < c->nranks; q++) {
        if (!shown(c, (uint32_t)q)) continue;
        /* the kernel's edges show its progress; once its phase is over the
         * triangles tell the story */
        int in_kernel = 0;
        for (int32_t p = pdt_rstate_slot(c->r, c->s, q, PDT_SLOT_PHASE); p >= 0; p = Ph[p].parent)
            if (Ph[p].phase == PDT_PH_KERNEL || Ph[p].phase == PDT_PH_MERGE) in_kernel = 1;
        if (!in_kernel) continue;
        int any = 0;
        for (size_t e = 0; e < ne; e++) {
            if (!c->s->ealive[e] || E[e].rank != (uint32_t)q) continue;
            double x, y;
            wpt(c, E[e].a, &x, &y);
            cairo_move_to(cr, x, y);
            wpt(c, E[e].b, &x, &y);
            cairo_line_to(cr, x, y);
            any = 1;
        }
        if (any) {
            set_rank(c, q, 0.45);
            cairo_stroke(cr);
        }
    }
    cairo_restore(cr);
}

static void draw_hulls_and_stacks(ctx *c, uint32_t *buf, size_t cap)
{
    cairo_t *cr = c->cr;
    size_t nh;
    const pdt_rhull *Hs = pdt_replay_hulls(c->r, &nh);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
    for (int q = 0; q < c->nranks; q++) {
        if (!shown(c, (uint32_t)q)) continue;
        int32_t h = pdt_rstate_slot(c->r, c->s, q, PDT_SLOT_HULL);
        if (h < 0 || !pdt_replay_hull_live(c->r, c->s, q, h)) continue;
        /* the hull: the first stack bottom..top, then the second (upper chain) */
        size_t k = pdt_replay_stack_list(c->r, Hs[h].top, buf, cap);
        size_t k2 = Hs[h].top2 >= 0 ? pdt_replay_stack_list(c->r, Hs[h].top2, buf + k, cap - k) : 0;
        if (k + k2 < 2) continue;
        double x, y;
        for (size_t i = 0; i < k + k2; i++) {
            wpt(c, buf[i], &x, &y);
            if (i) cairo_line_to(cr, x, y);
            else cairo_move_to(cr, x, y);
        }
        if (!k2) cairo_close_path(cr);
        cairo_set_line_width(cr, 3.2 * c->lw);
        set_hull(c, q, 0.9);
        cairo_stroke(cr);
    }
    /* open stacks (not yet a reported hull): the chain bottom -> top, top marked */
    for (int q = 0; q < c->nranks; q++) {
        if (!shown(c, (uint32_t)q)) continue;
        for (int st = 0; st < 5; st++) {
            int32_t top = pdt_rstate_slot(c->r, c->s, q, PDT_SLOT_STACK0 + st);
            if (top < 0 || !pdt_replay_stack_open(c->r, c->s, top)) continue;
            size_t k = pdt_replay_stack_list(c->r, top, buf, cap);
            int closed = st == PDT_STACK_GRAHAM && k >= 3 && pdt_replay_graham_scan_ended(c->r, c->s, q);
            double x, y;
            for (size_t i = 0; i < k; i++) {
                wpt(c, buf[i], &x, &y);
                if (i) cairo_line_to(cr, x, y);
                else cairo_move_to(cr, x, y);
            }
            if (closed) { /* the scan is over: the stack is the hull, drawn like one */
                cairo_close_path(cr);
                cairo_set_line_width(cr, 3.2 * c->lw);
                set_hull(c, q, 0.9);
                cairo_stroke(cr);
                continue;
            }
            set_rank(c, q, 0.9);
            cairo_set_line_width(cr, 2.6 * c->lw);
            cairo_stroke(cr);
            if (k) { /* top marker: a filled triangle above the top point */
                wpt(c, buf[k - 1], &x, &y);
                double a = 0.55 * c->L.font;
                cairo_move_to(cr, x, y - 0.35 * a);
                cairo_line_to(cr, x - 0.6 * a, y - 1.5 * a);
                cairo_line_to(cr, x + 0.6 * a, y - 1.5 * a);
                cairo_close_path(cr);
                rgb(cr, c->T->ink, 1);
                cairo_fill(cr);
            }
        }
    }
}

static void draw_points(ctx *c)
{
    cairo_t *cr = c->cr;
    double rad = fmax(1.5, fmin(0.28 * c->L.font, c->spacing / 5));
    size_t nvis = 0;
    for (size_t p = 0; p < c->n; p++) {
        double x, y;
        wpt(c, (uint32_t)p, &x, &y);
        if (x < c->L.geo.x || x > c->L.geo.x + c->L.geo.w || y < c->L.geo.y ||
            y > c->L.geo.y + c->L.geo.h)
            continue;
        nvis++;
    }
    if (nvis > 4000) rad = fmin(rad, 1.5);
    if (nvis > 4000 && c->spacing < 5) return; /* the points would only hide the edges */
    /* not yet lifted: hollow grey; lifted: filled dark (fast antialiasing:
     * the same dots at a fraction of the cost) */
    cairo_save(cr);
    cairo_set_antialias(cr, CAIRO_ANTIALIAS_FAST);
    for (int pass = 0; pass < 2; pass++) {
        for (size_t p = 0; p < c->n; p++) {
            int lifted = c->all_lifted || (c->s->pflags[p] & PDT_PF_LIFTED) != 0;
            if (lifted != pass) continue;
            double x, y;
            wpt(c, (uint32_t)p, &x, &y);
            if (nvis > 4000) /* pixel-aligned squares: cairo fills them as boxes, fast */
                cairo_rectangle(cr, floor(x) - 1, floor(y) - 1, 2, 2);
            else {
                cairo_new_sub_path(cr);
                cairo_arc(cr, x, y, rad, 0, 2 * M_PI);
            }
        }
        if (pass == 0) {
            rgb(cr, c->T->hollow, 1);
            cairo_set_line_width(cr, 1);
            cairo_stroke(cr);
        } else {
            rgb(cr, c->T->ink, 1);
            cairo_fill(cr);
        }
    }
    cairo_restore(cr);
    /* deleted points (Graham's ties and copies) crossed out */
    if (nvis > 600 || c->v->clean) return;
    double f = c->L.label;
    for (size_t p = 0; p < c->n; p++) {
        if (!(c->s->pflags[p] & PDT_PF_DELETED)) continue;
        double x, y;
        wpt(c, (uint32_t)p, &x, &y);
        cairo_set_line_width(cr, 0.18 * f);
        cross(cr, x, y, 0.55 * f);
        rgb(cr, RED, 1);
        cairo_stroke(cr);
    }
}

/* Text with a halo of the background colour around its glyphs, so that the
 * lines under it do not hide it. */
static void halo_text(ctx *c, int bold, double size, double x, double y, const char *s,
                      const double col[3])
{
    cairo_t *cr = c->cr;
    cairo_select_font_face(cr, SANS, CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
    pdt_text_log_note(cr, size, x, y, s);
    cairo_move_to(cr, x, y);
    cairo_text_path(cr, s);
    rgb(cr, c->T->bg, 0.9);
    cairo_set_line_width(cr, 0.28 * size);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    cairo_stroke_preserve(cr);
    rgb(cr, col, 1);
    cairo_fill(cr);
}

/* The points the current event names, most important first (at most 4). */
static int named_points(const ctx *c, uint32_t out[4])
{
    int k = 0;
    const pdt_rec *e = c->cur;
    if (!e || c->v->clean) return 0;
    const pdt_event *ev = &e->ev;
    uint32_t cand[4] = {NONE32, NONE32, NONE32, NONE32};
    switch (ev->kind) {
    case PDT_EV_PUSH: case PDT_EV_LIFT: case PDT_EV_SORT: cand[0] = ev->a; break;
    case PDT_EV_POP: cand[0] = ev->a; cand[1] = ev->c; break;
    case PDT_EV_DELETE: cand[0] = ev->a; cand[1] = ev->b; break;
    case PDT_EV_EDGE_ADD: case PDT_EV_EDGE_DEL: cand[0] = ev->a; cand[1] = ev->b; break;
    default:
        if (is_tri_event(ev->kind)) {
            cand[0] = ev->a;
            cand[1] = ev->b;
            cand[2] = ev->c;
            if (ev->kind == PDT_EV_DISCARD && ev->v >= 0 && (uint64_t)ev->v < c->n)
                cand[3] = (uint32_t)ev->v;
        }
    }
    for (int i = 0; i < 4; i++)
        if (cand[i] < c->n) out[k++] = cand[i];
    return k;
}

static int overlaps(const lbox *B, size_t nb, lbox b)
{
    for (size_t i = 0; i < nb; i++)
        if (b.x0 < B[i].x1 && B[i].x0 < b.x1 && b.y0 < B[i].y1 && B[i].y0 < b.y1) return 1;
    return 0;
}

/* Point labels, drawn over every line and ring: the input index ("7"), in
 * Graham runs with the angular place once sorted (pdt_point_label).  The
 * points the current event names are placed first (trying four sides), then
 * the selected one, then the others in index order; a label that would
 * overlap one already placed gives way. */
static size_t points_in_view(const ctx *c)
{
    size_t nvis = 0;
    for (size_t p = 0; p < c->n; p++) {
        double x, y;
        wpt(c, (uint32_t)p, &x, &y);
        nvis += x >= c->L.geo.x && x <= c->L.geo.x + c->L.geo.w && y >= c->L.geo.y &&
                y <= c->L.geo.y + c->L.geo.h;
    }
    return nvis;
}

/* Where point p's label (tw wide, at fs) goes beside it at (x, y): the
 * first free spot right-up, left-up (the others' labels); a named point's
 * (prio) also right-down, left-down, above, below, right, left, then as
 * much again one and two font sizes further out, over the points; none
 * when every spot meets a label or a box the picture keeps (the event line
 * names the point).  A label placed is added to B; P (may be NULL): the
 * points, kept clear too. */
static int label_spot(const ctx *c, lbox *B, size_t *nb, const lbox *P, size_t np, uint32_t p,
                      double x, double y, double tw, double fs, int prio, double *lx, double *ly)
{
    double f = c->L.label, th = 0.8 * fs;
    const double ox[8] = {0.55 * f, -0.55 * f - tw, 0.55 * f, -0.55 * f - tw,
                          -0.5 * tw, -0.5 * tw, 0.7 * f, -0.7 * f - tw};
    const double oy[8] = {-0.4 * f, -0.4 * f, 0.4 * f + th, 0.4 * f + th,
                          -0.6 * f, 0.6 * f + th, 0.5 * th, 0.5 * th};
    const double dx[8] = {1, -1, 1, -1, 0, 0, 1, -1}, dy[8] = {-1, -1, 1, 1, -1, 1, 0, 0};
    for (int k = 0; k < (prio ? 24 : 2); k++) {
        double ax = x + ox[k % 8] + (k / 8) * dx[k % 8] * f,
               ay = y + oy[k % 8] + (k / 8) * dy[k % 8] * f;
        lbox b = {ax - 1, ay - th - 1, ax + tw + 1, ay + 0.2 * fs + 1};
        if (overlaps(B, *nb, b) || b.x1 > c->L.geo.x + c->L.geo.w || b.x0 < c->L.geo.x ||
            b.y0 < c->L.geo.y || b.y1 > c->L.geo.y + c->L.geo.h)
            continue;
        int hit = 0; /* not over another point */
        for (size_t q = 0; P && q < np && !hit; q++) hit = q != p && overlaps(&P[q], 1, b);
        if (hit) continue;
        B[(*nb)++] = b;
        *lx = ax;
        *ly = ay;
        return 1;
    }
    return 0;
}

/* The labels of the points the event names and of the selected one, placed
 * before the picture's other labels (strips', groups', merges', points'),
 * which keep off them: only the event line's spill is there before. */
static void place_named_labels(ctx *c)
{
    uint32_t named[5];
    int nn = named_points(c, named);
    if (c->v->sel_point >= 0 && (size_t)c->v->sel_point < c->n) named[nn++] = (uint32_t)c->v->sel_point;
    double fs = 1.15 * c->L.label;
    c->nnamed = 0;
    for (int i = 0; i < nn && c->ntaken < TAKEN_MAX; i++) {
        int dup = 0;
        for (int j = 0; j < i; j++) dup |= named[j] == named[i];
        double x, y, lx, ly;
        wpt(c, named[i], &x, &y);
        if (dup || x < c->L.geo.x || x > c->L.geo.x + c->L.geo.w || y < c->L.geo.y ||
            y > c->L.geo.y + c->L.geo.h)
            continue;
        char lab[48];
        pdt_point_label(c->r, c->s, named[i], lab, sizeof lab);
        double tw = text_wb(c->cr, SANS, 1, fs, lab);
        size_t nt = (size_t)c->ntaken;
        if (!label_spot(c, c->taken, &nt, NULL, 0, named[i], x, y, tw, fs, 1, &lx, &ly)) continue;
        c->ntaken = (int)nt;
        c->named[c->nnamed].p = named[i];
        c->named[c->nnamed].x = lx;
        c->named[c->nnamed++].y = ly;
    }
}

static void draw_labels(ctx *c)
{
    size_t nvis = points_in_view(c);
    uint32_t named[4];
    int nn = named_points(c, named);
    int many = nvis > 400; /* only the named (and selected) points get labels */
    size_t cap = (many ? 0 : c->n) + 6;
    lbox *B = malloc((cap + (size_t)c->ntaken) * sizeof *B); /* the strip labels' boxes too */
    uint32_t *order = malloc(cap * sizeof *order);
    if (!B || !order) {
        free(B);
        free(order);
        return;
    }
    size_t no = 0, nb = 0;
    for (int i = 0; i < c->ntaken; i++) B[nb++] = c->taken[i]; /* the strip labels */
    for (int i = 0; i < nn; i++) order[no++] = named[i];
    if (c->v->sel_point >= 0 && (size_t)c->v->sel_point < c->n) order[no++] = (uint32_t)c->v->sel_point;
    size_t first_other = no;
    if (!many)
        for (size_t p = 0; p < c->n; p++) order[no++] = (uint32_t)p;
    double f = c->L.label, rad = 0.45 * f;
    /* the points themselves are obstacles for the labels of the others */
    lbox *P = NULL;
    size_t np = 0;
    if (!many && (P = malloc(c->n * sizeof *P)) != NULL)
        for (size_t p = 0; p < c->n; p++) {
            double x, y;
            wpt(c, (uint32_t)p, &x, &y);
            P[np++] = (lbox){x - rad, y - rad, x + rad, y + rad};
        }
    for (size_t i = 0; i < no; i++) {
        uint32_t p = order[i];
        int dup = 0;
        for (size_t j = 0; j < i && j < first_other; j++) dup |= order[j] == p;
        if (dup) continue;
        double x, y;
        wpt(c, p, &x, &y);
        if (x < c->L.geo.x || x > c->L.geo.x + c->L.geo.w || y < c->L.geo.y ||
            y > c->L.geo.y + c->L.geo.h)
            continue;
        char lab[48];
        pdt_point_label(c->r, c->s, p, lab, sizeof lab);
        if (i < first_other) { /* (placed before the picture's other labels) */
            for (int k = 0; k < c->nnamed; k++)
                if (c->named[k].p == p)
                    halo_text(c, 1, 1.15 * f, c->named[k].x, c->named[k].y, lab, c->T->ink);
            continue;
        }
        double tw = text_wb(c->cr, SANS, 0, f, lab);
        double lx, ly;
        if (!label_spot(c, B, &nb, P, np, p, x, y, tw, f, 0, &lx, &ly)) continue;
        halo_text(c, 0, f, lx, ly, lab, c->T->label);
    }
    free(P);
    free(B);
    free(order);
}

static void ring(ctx *c, uint32_t p, double rad, const double col[3], double lwf)
{
    double x, y;
    wpt(c, p, &x, &y);
    cairo_new_sub_path(c->cr);
    cairo_arc(c->cr, x, y, rad, 0, 2 * M_PI);
    rgb(c->cr, col, 1);
    cairo_set_line_width(c->cr, lwf);
    cairo_stroke(c->cr);
}

/* A square around point p: the point a pop or a delete keeps (a ring is the
 * point the event names; shape as well as colour tells them apart). */
static void square_mark(ctx *c, uint32_t p, double rad, const double col[3], double lwf)
{
    double x, y;
    wpt(c, p, &x, &y);
    cairo_rectangle(c->cr, x - 0.85 * rad, y - 0.85 * rad, 1.7 * rad, 1.7 * rad);
    rgb(c->cr, col, 1);
    cairo_set_line_width(c->cr, lwf);
    cairo_stroke(c->cr);
}

/* A popped point: its ring crossed out. */
static void popped_cross(ctx *c, uint32_t p, const double col[3])
{
    double x, y;
    wpt(c, p, &x, &y);
    cross(c->cr, x, y, 0.5 * c->L.font);
    rgb(c->cr, col, 1);
    cairo_set_line_width(c->cr, 2);
    cairo_stroke(c->cr);
}

/* Labels placed so far (G_L, G_R of the merges in progress). */
typedef struct mlabels {
    pdt_rect r[64];
    int n;
} mlabels;

static int rect_meets(pdt_rect a, double x0, double y0, double x1, double y1)
{
    return a.x < x1 && x0 < a.x + a.w && a.y < y1 && y0 < a.y + a.h;
}

/* A group's label at (x, y) (right-aligned when right), or a row higher,
 * unless both would overlap one already placed or a label the picture keeps
 * (c->taken: box labels, the event line's spill), or leave the picture:
 * with many merges at once they are thinned. */
static void merge_label(ctx *c, mlabels *P, double x, double y, int right, const char *lab)
{
    double fs = c->L.label, tw = text_wb(c->cr, SANS, 1, fs, lab);
    for (int up = 0; up < 2; up++, y -= 1.3 * fs) {
        pdt_rect a = {right ? x - tw : x, y - fs, tw, 1.2 * fs};
        const pdt_rect G = c->L.geo;
        int hit = a.x < G.x || a.y < G.y || a.x + a.w > G.x + G.w || a.y + a.h > G.y + G.h;
        for (int i = 0; i < P->n && !hit; i++)
            hit = rect_meets(a, P->r[i].x, P->r[i].y, P->r[i].x + P->r[i].w, P->r[i].y + P->r[i].h);
        for (int i = 0; i < c->ntaken && !hit; i++)
            hit = rect_meets(a, c->taken[i].x0, c->taken[i].y0, c->taken[i].x1, c->taken[i].y1);
        if (hit) continue;
        if (P->n < 64) P->r[P->n++] = a;
        if (c->ntaken < TAKEN_MAX) /* the box labels, placed later, keep off it */
            c->taken[c->ntaken++] = (lbox){a.x, a.y, a.x + a.w, a.y + a.h};
        text_at(c->cr, SANS, 1, fs, a.x, y, lab);
        return;
    }
}

/* The merge step in progress on some rank: border set rings and group boxes. */
static void draw_merge(ctx *c)
{
    mlabels P = {.n = 0};
    size_t ng;
    const pdt_rmerge *M = pdt_replay_merges(c->r, &ng);
    for (int q = 0; q < c->nranks; q++) {
        int32_t g = pdt_rstate_slot(c->r, c->s, q, PDT_SLOT_MERGE);
        if (g < 0 || !shown(c, (uint32_t)q)) continue;
        const pdt_rmerge *mg = &M[g];
        /* the two groups' boxes */
        for (int side = 0; side < 2; side++) {
            uint32_t a = side ? mg->gr : mg->gl, b = side ? mg->gend : mg->gr;
            int have = 0;
            pdt_point lo = {0, 0}, hi = {0, 0};
            for (uint32_t o = a; o < b; o++) {
                pdt_point l, h;
                if (!pdt_replay_box(c->r, (int)o, &l, &h)) continue;
                if (!have) lo = l, hi = h, have = 1;
                lo.x = l.x < lo.x ? l.x : lo.x;
                lo.y = l.y < lo.y ? l.y : lo.y;
                hi.x = h.x > hi.x ? h.x : hi.x;
                hi.y = h.y > hi.y ? h.y : hi.y;
            }
            if (!have) continue;
            double pad = 1.6 * c->L.font;
            double x0 = c->X.ox + c->X.s * lo.x - pad, x1 = c->X.ox + c->X.s * hi.x + pad;
            double y0 = c->X.oy - c->X.s * hi.y - pad, y1 = c->X.oy - c->X.s * lo.y + pad;
            cairo_rectangle(c->cr, x0, y0, x1 - x0, y1 - y0);
            rgb(c->cr, c->T->ink, 0.8);
            cairo_set_line_width(c->cr, 1.5);
            double d[2] = {10, 5};
            cairo_set_dash(c->cr, d, 2, 0);
            cairo_stroke(c->cr);
            cairo_set_dash(c->cr, NULL, 0, 0);
            merge_label(c, &P, side ? x1 : x0, y0 - 0.3 * c->L.font, side, side ? "G_R" : "G_L");
        }
        /* the border set B: points the merge rank lifted since the merge began */
        size_t from = mg->begin_ev, to = c->s->k;
        if (to - from > 2000000) from = to - 2000000;
        double col[3] = {0.0, 0.0, 0.0};
        for (size_t i = from; i < to; i++) {
            const pdt_rec *e = pdt_replay_rec(c->r, i);
            if (e->rank == mg->rank && e->ev.kind == PDT_EV_LIFT && e->ev.a < c->n)
                ring(c, e->ev.a, 0.45 * c->L.font, col, 1.4);
        }
    }
}

/* The current event's highlight: circumdisk, turn, point rings. */
static void draw_current(ctx *c, uint32_t *buf, size_t cap)
{
    const pdt_rec *e = c->cur;
    if (!e) return;
    cairo_t *cr = c->cr;
    const pdt_event *ev = &e->ev;
    double hl[3] = {0.85, 0.1, 0.1};
    if (is_tri_event(ev->kind) && ev->a < c->n && ev->b < c->n && ev->c < c->n) {
        uint32_t v[3] = {ev->a, ev->b, ev->c};
        double ox, oy, rr;
        tri_path(c, v);
        set_rank(c, (int)e->rank, 0.25);
        cairo_fill(cr);
        if (circum(c->P, v, &ox, &oy, &rr)) {
            cairo_new_sub_path(cr);
            cairo_arc(cr, c->X.ox + c->X.s * ox, c->X.oy - c->X.s * oy, c->X.s * rr, 0, 2 * M_PI);
            rgb(cr, c->T->mark, 0.18);
            cairo_fill_preserve(cr);
            rgb(cr, c->T->disk, 0.95);
            cairo_set_line_width(cr, 2 * c->lw);
            cairo_stroke(cr);
        }
        if (ev->kind == PDT_EV_DISCARD && ev->v >= 0 && (uint64_t)ev->v < c->n)
            ring(c, (uint32_t)ev->v, 0.7 * c->L.font, hl, 2.5);
        return;
    }
    if ((ev->kind == PDT_EV_PUSH || ev->kind == PDT_EV_POP || ev->kind == PDT_EV_LIFT ||
         ev->kind == PDT_EV_SORT || ev->kind == PDT_EV_DELETE) && ev->a < c->n) {
        ring(c, ev->a, 0.75 * c->L.font, hl, 2.5);
        if (ev->kind == PDT_EV_POP) popped_cross(c, ev->a, hl);
        if (ev->kind == PDT_EV_POP && ev->c < c->n) {
            /* the turn that caused the pop: below -> popped -> new point */
            int32_t top = pdt_rstate_slot(c->r, c->s, (int)e->rank, PDT_SLOT_STACK0 + ev->sub);
            size_t k = pdt_replay_stack_list(c->r, top, buf, cap);
            if (k >= 1) {
                double x, y;
                wpt(c, buf[k - 1], &x, &y);
                cairo_move_to(cr, x, y);
                wpt(c, ev->a, &x, &y);
                cairo_line_to(cr, x, y);
                wpt(c, ev->c, &x, &y);
                cairo_line_to(cr, x, y);
                double d[2] = {5, 4};
                cairo_set_dash(cr, d, 2, 0);
                rgb(cr, hl, 0.9);
                cairo_set_line_width(cr, 2 * c->lw);
                cairo_stroke(cr);
                cairo_set_dash(cr, NULL, 0, 0);
            }
            square_mark(c, ev->c, 0.75 * c->L.font, (double[3]){0.0, 0.45, 0.0}, 2.5);
        }
        if (ev->kind == PDT_EV_DELETE && ev->b < c->n)
            square_mark(c, ev->b, 0.75 * c->L.font, (double[3]){0.0, 0.45, 0.0}, 2.5);
    }
    if ((ev->kind == PDT_EV_EDGE_ADD || ev->kind == PDT_EV_EDGE_DEL) && ev->a < c->n && ev->b < c->n) {
        double x, y;
        wpt(c, ev->a, &x, &y);
        cairo_move_to(cr, x, y);
        wpt(c, ev->b, &x, &y);
        cairo_line_to(cr, x, y);
        rgb(cr, hl, 0.8);
        cairo_set_line_width(cr, 3 * c->lw);
        cairo_stroke(cr);
    }
}

static void draw_selection(ctx *c)
{
    cairo_t *cr = c->cr;
    char lines[5][160];
    int nl = 0;
    if (c->v->sel_point >= 0 && (size_t)c->v->sel_point < c->n) {
        size_t p = (size_t)c->v->sel_point;
        pdt_point q = c->P[p];
        ring(c, (uint32_t)p, 0.8 * c->L.font, c->T->select, 3);
        snprintf(lines[nl++], sizeof lines[0], "point %zu at (%d, %d)", p, q.x, q.y);
        if (pdt_replay_kind_count(c->r, PDT_EV_LIFT) > 0) /* a hull run lifts nothing */
            snprintf(lines[nl++], sizeof lines[0], "lifted z = %lld%s",
                     (long long)((int64_t)q.x * q.x + (int64_t)q.y * q.y),
                     c->s->pflags[p] & PDT_PF_LIFTED ? "" : " (not lifted yet)");
        int64_t pos = pdt_replay_sort_pos(c->r, p);
        if (c->s->pflags[p] & PDT_PF_SORTED)
            snprintf(lines[nl++], sizeof lines[0], "p%lld in the angular order%s", (long long)pos,
                     c->s->pflags[p] & PDT_PF_DELETED ? ", deleted" : "");
        for (int q2 = 0; q2 < c->nranks; q2++) {
            pdt_point lo, hi;
            if (pdt_replay_box(c->r, q2, &lo, &hi) && q.x >= lo.x && q.x <= hi.x && q.y >= lo.y &&
                q.y <= hi.y) {
                snprintf(lines[nl++], sizeof lines[0], "in the box of rank %d", q2);
                break;
            }
        }
    } else if (c->v->sel_tri >= 0) {
        size_t nt;
        const pdt_rtri *T = pdt_replay_tris(c->r, &nt);
        if ((size_t)c->v->sel_tri < nt) {
            const pdt_rtri *t = &T[c->v->sel_tri];
            static const char *const sn[] = {"not created", "candidate", "final", "deferred",
                                             "shipped", "discarded"};
            int e = c->v->sel_edge;
            if (e >= 0 && e < 3) {
                uint32_t a = t->v[e], b = t->v[(e + 1) % 3];
                double x, y;
                wpt(c, a, &x, &y);
                cairo_move_to(cr, x, y);
                wpt(c, b, &x, &y);
                cairo_line_to(cr, x, y);
                rgb(cr, c->T->select, 0.9);
                cairo_set_line_width(cr, 5);
                cairo_stroke(cr);
                double dx = (double)c->P[b].x - c->P[a].x, dy = (double)c->P[b].y - c->P[a].y;
                snprintf(lines[nl++], sizeof lines[0], "edge %u–%u, length %.1f", a, b, sqrt(dx * dx + dy * dy));
            }
            tri_path(c, t->v);
            rgb(cr, c->T->select, 0.9);
            cairo_set_line_width(cr, 3);
            cairo_stroke(cr);
            uint32_t w[3];
            pdt_replay_tri_order(c->r, t->v, w);
            snprintf(lines[nl++], sizeof lines[0], "%s %u %u %u", e >= 0 ? "of triangle" : "triangle",
                     w[0], w[1], w[2]);
            snprintf(lines[nl++], sizeof lines[0], "made by rank %u, now %s", t->maker,
                     pdt_rstate_tri_visible(c->r, c->s, (size_t)c->v->sel_tri)
                         ? sn[pdt_replay_tri_hist(c->r)[pdt_rstate_tri_entry(c->r, c->s, (size_t)c->v->sel_tri)].status]
                         : "dropped by its merge");
            double ox, oy, rr;
            if (circum(c->P, t->v, &ox, &oy, &rr)) {
                double d[2] = {8, 5};
                cairo_new_sub_path(cr);
                cairo_arc(cr, c->X.ox + c->X.s * ox, c->X.oy - c->X.s * oy, c->X.s * rr, 0, 2 * M_PI);
                rgb(cr, c->T->select, 0.9);
                cairo_set_dash(cr, d, 2, 0);
                cairo_set_line_width(cr, 2.5);
                cairo_stroke(cr);
                cairo_set_dash(cr, NULL, 0, 0);
            }
            if (circum(c->P, t->v, &ox, &oy, &rr))
                snprintf(lines[nl++], sizeof lines[0], "circle centre (%.1f, %.1f) radius %.1f", ox,
                         oy, rr);
        }
    }
    if (!nl) return;
    double f = 0.85 * c->L.font, w = 0;
    for (int i = 0; i < nl; i++) w = fmax(w, text_w(cr, SANS, f, lines[i]));
    pdt_rect R = {c->L.geo.x + 0.5 * f, c->L.geo.y + c->L.geo.h - (nl + 0.8) * 1.3 * f, w + 1.2 * f,
                  (nl + 0.5) * 1.3 * f};
    cairo_rectangle(cr, R.x, R.y, R.w, R.h);
    rgb(cr, c->T->bg, 0.92);
    cairo_fill_preserve(cr);
    rgb(cr, c->T->select, 1);
    cairo_set_line_width(cr, 1.5);
    cairo_stroke(cr);
    rgb(cr, c->T->ink, 1);
    for (int i = 0; i < nl; i++) text_at(cr, SANS, i == 0, f, R.x + 0.6 * f, R.y + (i + 1.1) * 1.3 * f, lines[i]);
}

/* The circumcircle of every drawn (not discarded) triangle, thin, in its
 * maker's colour (up to 20000 triangles). */
static void draw_circles(ctx *c)
{
    cairo_t *cr = c->cr;
    size_t nt;
    const pdt_rtri *T = pdt_replay_tris(c->r, &nt);
    const pdt_rtri_hist *H = pdt_replay_tri_hist(c->r);
    cairo_set_line_width(cr, fmax(0.6, 0.5 * c->lw));
    size_t drawn = 0;
    for (int q = 0; q < c->nranks; q++) {
        if (!shown(c, (uint32_t)q)) continue;
        for (size_t t = 0; t < nt && drawn < 20000; t++) {
            uint32_t h = pdt_rstate_tri_entry(c->r, c->s, t);
            if (T[t].maker != (uint32_t)q || h == NONE32 || H[h].status == PDT_TS_DISCARDED) continue;
            if (c->v->clean && H[h].status != PDT_TS_FINAL) continue;
            double ox, oy, rr;
            if (!circum(c->P, T[t].v, &ox, &oy, &rr)) continue;
            cairo_new_sub_path(cr);
            cairo_arc(cr, c->X.ox + c->X.s * ox, c->X.oy - c->X.s * oy, c->X.s * rr, 0, 2 * M_PI);
            drawn++;
        }
        set_rank(c, q, 0.45);
        cairo_stroke(cr);
    }
}

/* The Voronoi diagram of the final triangles (pdt_replay_voronoi): the
 * centres as small dots, the edges dark; rays run past the picture's edge
 * (the clip cuts them). */
static void draw_voronoi(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_vseg *S;
    size_t ns;
    pdt_err err = {0};
    if (pdt_replay_voronoi(c->r, c->s, c->v->hidden, &S, &ns, &err) != PDT_OK) return;
    double far = 4 * (c->L.geo.w + c->L.geo.h) / c->X.s;
    for (size_t i = 0; i < ns; i++) {
        double x1 = S[i].ray ? S[i].x0 + far * S[i].x1 : S[i].x1;
        double y1 = S[i].ray ? S[i].y0 + far * S[i].y1 : S[i].y1;
        cairo_move_to(cr, c->X.ox + c->X.s * S[i].x0, c->X.oy - c->X.s * S[i].y0);
        cairo_line_to(cr, c->X.ox + c->X.s * x1, c->X.oy - c->X.s * y1);
    }
    rgb(cr, c->T->ink, 0.85);
    cairo_set_line_width(cr, fmax(1.2, 1.1 * c->lw));
    cairo_stroke(cr);
    free(S);
}

void pdt_draw_geometry(ctx *c)
{
    cairo_t *cr = c->cr;
    cairo_save(cr);
    clip_rect(cr, c->L.geo);

    size_t cap = c->n + 1;
    uint32_t *buf = malloc(2 * cap * sizeof *buf);
    int cur_tri = 0;
    double ox = 0, oy = 0, rr = 0;
    if (c->cur && is_tri_event(c->cur->ev.kind) && c->cur->ev.a < c->n && c->cur->ev.b < c->n &&
        c->cur->ev.c < c->n) {
        uint32_t v[3] = {c->cur->ev.a, c->cur->ev.b, c->cur->ev.c};
        cur_tri = circum(c->P, v, &ox, &oy, &rr);
    }
    if (c->v->clean) cur_tri = 0;
    place_named_labels(c);
    draw_boxes(c, cur_tri, 0);
    if (!c->v->clean) draw_kernel_edges(c);
    draw_triangles(c);
    if (c->v->circles) draw_circles(c);
    if (c->v->voronoi) draw_voronoi(c);
    if (buf) draw_hulls_and_stacks(c, buf, 2 * cap);
    if (!c->v->clean) draw_merge(c);
    draw_points(c);
    if (buf && !c->v->clean) draw_current(c, buf, 2 * cap);
    draw_boxes(c, cur_tri, 1); /* the strip labels first: the point labels keep off them */
    draw_labels(c);
    draw_selection(c);
    free(buf);
    cairo_restore(cr);
}
