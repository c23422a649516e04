/* pdt — the cairo renderer (see pdt/view/render.h): one frame, its context and
 * colours.  The parts of the frame are drawn by the files listed in
 * render_int.h. */
#include "render_int.h"

/* ---- colours ------------------------------------------------------------------ */

/* select and disk: PDT_SELECT and PDT_DISK of palette.c, in every theme */
static const pdt_theme themes[PDT_THEME_COUNT] = {
    {   /* light */
        .bg = {1, 1, 1}, .panel = {0.975, 0.975, 0.97}, .border = {0.72, 0.72, 0.72},
        .topbar = {0.93, 0.94, 0.96}, .ink = {0.1, 0.1, 0.12}, .hollow = {0.55, 0.55, 0.55},
        .label = {0.0, 0.25, 0.55}, .select = {0.041, 0.793, 0.939}, .disk = {0.824, 0.395, 0.039},
        .mark = {1.0, 0.85, 0.2}, .hull = 0.4, .tint = 1, .lwf = 1,
    },
    {   /* dark */
        .bg = {0.09, 0.09, 0.11}, .panel = {0.14, 0.14, 0.17}, .border = {0.35, 0.35, 0.4},
        .topbar = {0.17, 0.18, 0.22}, .ink = {0.93, 0.93, 0.9}, .hollow = {0.6, 0.6, 0.62},
        .label = {0.65, 0.85, 1.0}, .select = {0.041, 0.793, 0.939}, .disk = {0.824, 0.395, 0.039},
        .mark = {0.75, 0.6, 0.1}, .hull = 0.35, .tint = 1.6, .lwf = 1.15,
    },
    {   /* contrast */
        .bg = {1, 1, 1}, .panel = {1, 1, 1}, .border = {0, 0, 0},
        .topbar = {1, 1, 1}, .ink = {0, 0, 0}, .hollow = {0.25, 0.25, 0.25},
        .label = {0, 0, 0}, .select = {0.041, 0.793, 0.939}, .disk = {0.824, 0.395, 0.039},
        .mark = {1.0, 0.8, 0.0}, .hull = 0.55, .tint = 0, .lwf = 1.6,
    },
};

const pdt_theme *pdt_theme_get(int id)
{
    return &themes[id >= 0 && id < PDT_THEME_COUNT ? id : 0];
}

/* Line style of a status: width factor and dash. */
void pdt_status_style(cairo_t *cr, int st, double lw)
{
    static const double dash[] = {6, 4}, dot[] = {1.5, 3};
    switch (st) {
    case PDT_TS_CANDIDATE:
        cairo_set_line_width(cr, 0.6 * lw);
        cairo_set_dash(cr, NULL, 0, 0);
        break;
    case PDT_TS_FINAL:
        cairo_set_line_width(cr, 1.3 * lw);
        cairo_set_dash(cr, NULL, 0, 0);
        break;
    case PDT_TS_DEFERRED: {
        double d[2] = {dash[0] * lw, dash[1] * lw};
        cairo_set_line_width(cr, 1.3 * lw);
        cairo_set_dash(cr, d, 2, 0);
        break;
    }
    case PDT_TS_SHIPPED: {
        double d[2] = {dot[0] * lw, dot[1] * lw};
        cairo_set_line_width(cr, 1.6 * lw);
        cairo_set_dash(cr, d, 2, 0);
        break;
    }
    default:
        cairo_set_line_width(cr, 0.8 * lw);
        cairo_set_dash(cr, NULL, 0, 0);
    }
}

/* The parts of the frame, each naming its panel for the layout report. */
static void draw_parts(ctx *c, double w, double h)
{
    cairo_t *cr = c->cr;
    pdt_text_log_panel(cr, "picture");
    if (!c->L.covered) {
        pdt_top_spill(c);
        pdt_draw_geometry(c);
    }
    pdt_text_log_panel(cr, "event");
    pdt_draw_top(c);
    pdt_text_log_panel(cr, "legend");
    pdt_draw_legend(c);
    pdt_text_log_panel(cr, "code");
    if (c->L.code.w > 0) pdt_draw_code(c);
    pdt_text_log_panel(cr, "stack");
    if (c->L.stack.w > 0) pdt_draw_stack_panel(c);
    pdt_text_log_panel(cr, "lifted");
    if (c->L.lifted.w > 0) pdt_draw_lifted(c);
    pdt_text_log_panel(cr, "timeline");
    if (c->L.timeline.w > 0) pdt_draw_timeline(c);
    pdt_text_log_panel(cr, "tree");
    if (c->L.tree.w > 0) pdt_draw_tree(c);
    pdt_text_log_panel(cr, "more");
    if (c->L.more.w > 0) pdt_draw_more(c);
    pdt_text_log_panel(cr, "help");
    if (c->v->help) pdt_draw_help(c, w, h);
}

/* ---- entry points ------------------------------------------------------------------------------ */

pdt_status pdt_render(cairo_t *cr, double w, double h, const pdt_replay *r, const pdt_rstate *s,
                      const pdt_view *v, pdt_err *err)
{
    ctx c;
    memset(&c, 0, sizeof c);
    c.cr = cr;
    c.r = r;
    c.s = s;
    c.v = v;
    c.nranks = pdt_replay_nranks(r);
    c.P = pdt_replay_points(r, &c.n);
    c.T = pdt_theme_get(v->theme);
    pdt_render_layout_view(w, h, c.nranks, v, &c.L);
    c.X = pdt_geo_xform(r, v, w, h);
    if (s->k) {
        c.cur_copy = *pdt_replay_rec(r, s->k - 1);
        c.cur = &c.cur_copy;
    }
    c.all_lifted = pdt_replay_kind_count(r, PDT_EV_LIFT) == 0 &&
                   pdt_replay_kind_count(r, PDT_EV_TRI_NEW) > 0;
    c.no_lift = pdt_replay_kind_count(r, PDT_EV_LIFT) == 0 && !c.all_lifted;
    /* line width: thick on a projector, thinner when edges are dense */
    size_t nt;
    pdt_replay_tris(r, &nt);
    double spacing = c.n ? c.X.s * sqrt(1.0 / (double)c.n) : 10;
    pdt_point lo, hi;
    if (pdt_replay_bbox(r, &lo, &hi))
        spacing = c.X.s * sqrt(fmax(1.0, ((double)hi.x - lo.x) * ((double)hi.y - lo.y)) / (double)(c.n ? c.n : 1));
    c.lw = fmax(0.5, fmin(0.16 * c.L.font, spacing / 9)) * c.T->lwf;
    c.spacing = spacing;
    pdt_frame_groups(&c);

    cairo_save(cr);
    if (v->texts) {
        pdt_text_log_clear(v->texts, w, h);
        pdt_text_log_attach(cr, v->texts);
        pdt_text_log_layout(cr, &c.L);
    }
    cairo_rectangle(cr, 0, 0, w, h);
    rgb(cr, c.T->bg, 1);
    cairo_fill(cr);
    draw_parts(&c, w, h);
    pdt_text_log_panel(cr, NULL); /* a hook's overlay: found from where it lies */
    cairo_restore(cr);
    pdt_frame_groups_done(&c);
    pdt_replay_give_back(r, s);  /* a big run's pages the frame read */
    cairo_status_t cs = cairo_status(cr);
    if (cs != CAIRO_STATUS_SUCCESS)
        return pdt_err_set(err, PDT_ERR_IO, "cairo: %s",
                           cairo_status_to_string(cs));
    return PDT_OK;
}
