/* Headless renders: colours of edges by rank, discarded triangles marked,
 * panels present, every file format written. */
#include "../harness.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pdt/view/query.h"
#include "pdt/view/render.h"
#include "pdt/view/replay.h"
#include "pdt/view/viewsynth.h"

#define W 1200
#define H 800

typedef struct fixture {
    pdt_synth syn;
    pdt_replay *r;
    pdt_rstate *s;
    pdt_view v;
    cairo_surface_t *sf;
} fixture;

static int setup(fixture *f, int cols, int rows, int ranks)
{
    pdt_err err = {0};
    memset(f, 0, sizeof *f);
    if (pdt_synth_srm(cols, rows, ranks, 2, &f->syn, &err) != PDT_OK) return 0;
    if (pdt_replay_new(f->syn.pts, f->syn.n, f->syn.recs, f->syn.m, ranks, &f->r, &err) != PDT_OK) return 0;
    f->s = pdt_rstate_new(f->r);
    pdt_view_defaults(&f->v);
    f->sf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
    return f->s != NULL;
}

static void teardown(fixture *f)
{
    cairo_surface_destroy(f->sf);
    pdt_rstate_free(f->s);
    pdt_replay_free(f->r);
    pdt_synth_free(&f->syn);
}

static int draw(fixture *f, size_t k)
{
    pdt_replay_seek(f->r, f->s, k);
    cairo_t *cr = cairo_create(f->sf);
    pdt_err err = {0};
    pdt_status st = pdt_render(cr, W, H, f->r, f->s, &f->v, &err);
    cairo_destroy(cr);
    cairo_surface_flush(f->sf);
    return st == PDT_OK;
}

static void pixel(cairo_surface_t *sf, int x, int y, double c[3])
{
    const unsigned char *d = cairo_image_surface_get_data(sf);
    int stride = cairo_image_surface_get_stride(sf);
    uint32_t p = *(const uint32_t *)(d + (size_t)y * (size_t)stride + (size_t)x * 4);
    c[0] = ((p >> 16) & 255) / 255.0;
    c[1] = ((p >> 8) & 255) / 255.0;
    c[2] = (p & 255) / 255.0;
}

static double cdist(const double a[3], const double b[3])
{
    return fabs(a[0] - b[0]) + fabs(a[1] - b[1]) + fabs(a[2] - b[2]);
}

/* Smallest colour distance to `want` in the 3x3 pixels around (x,y). */
static double near_colour(cairo_surface_t *sf, double x, double y, const double want[3])
{
    double best = 9;
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
            double c[3];
            int px = (int)lround(x) + dx, py = (int)lround(y) + dy;
            if (px < 0 || py < 0 || px >= W || py >= H) continue;
            pixel(sf, px, py, c);
            double d = cdist(c, want);
            if (d < best) best = d;
        }
    return best;
}

/* Pixels in a rectangle that are neither white nor the panel background. */
static size_t ink(cairo_surface_t *sf, pdt_rect R)
{
    size_t n = 0;
    for (int y = (int)R.y + 4; y < (int)(R.y + R.h) - 4; y++)
        for (int x = (int)R.x + 4; x < (int)(R.x + R.w) - 4; x++) {
            double c[3];
            pixel(sf, x, y, c);
            if (c[0] + c[1] + c[2] < 2.7) n++;
        }
    return n;
}

/* Midpoint on screen of the diagonal of a final triangle made by `rank`
 * (the diagonal belongs to two triangles of the same cell and rank). */
static int final_diagonal(fixture *f, int rank, double *x, double *y)
{
    size_t nt;
    const pdt_rtri *T = pdt_replay_tris(f->r, &nt);
    const pdt_point *P = f->syn.pts;
    for (size_t t = 0; t < nt; t++) {
        if (T[t].maker != (uint32_t)rank || pdt_rstate_tri_status(f->r, f->s, t) != PDT_TS_FINAL)
            continue;
        /* T1 = (p00, p10, p11): diagonal p00-p11 */
        pdt_point a = P[T[t].v[0]], c = P[T[t].v[2]];
        if (!(c.x > a.x && c.y > a.y)) continue;
        pdt_view_to_screen(f->r, &f->v, W, H, (a.x + c.x) / 2.0, (a.y + c.y) / 2.0, x, y);
        return 1;
    }
    return 0;
}

TEST(final_edge_has_rank_colour)
{
    fixture f;
    CHECK(setup(&f, 16, 6, 4));
    if (!f.s) return;
    f.v.fade = 1;
    CHECK(draw(&f, pdt_replay_count(f.r)));
    for (int q = 0; q < 4; q++) {
        double x, y, want[3], other[3];
        CHECK(final_diagonal(&f, q, &x, &y));
        pdt_rank_rgb(q, want);
        pdt_rank_rgb((q + 1) % 4, other);
        double d = near_colour(f.sf, x, y, want);
        CHECK_MSG(d < 0.12, "rank %d: colour distance %.3f at (%.0f,%.0f)", q, d, x, y);
        CHECK_MSG(near_colour(f.sf, x, y, other) > 0.3, "rank %d edge looks like rank %d", q, (q + 1) % 4);
    }
    teardown(&f);
}

TEST(discarded_drawn_differently)
{
    fixture f;
    CHECK(setup(&f, 16, 6, 4));
    if (!f.s) return;
    /* (at this size the lifted view gets no room: not asked for, it is not
     * named on a line at the bottom, and the picture keeps its place) */
    f.v.panels = PDT_PANEL_ALL & ~PDT_PANEL_LIFTED;
    /* the cursor just after the first discard: a red cross at its centroid */
    size_t m = pdt_replay_count(f.r), k = 0;
    for (size_t i = 0; i < m && !k; i++)
        if (pdt_replay_rec(f.r, i)->ev.kind == PDT_EV_DISCARD) k = i + 1;
    CHECK(k > 0);
    CHECK(draw(&f, k + 3));
    const pdt_event *e = &pdt_replay_rec(f.r, k - 1)->ev;
    const pdt_point *P = f.syn.pts;
    double cx = (P[e->a].x + P[e->b].x + P[e->c].x) / 3.0, cy = (P[e->a].y + P[e->b].y + P[e->c].y) / 3.0;
    double x, y, red[3] = {0.85, 0, 0};
    pdt_view_to_screen(f.r, &f.v, W, H, cx, cy, &x, &y);
    CHECK_MSG(near_colour(f.sf, x, y, red) < 0.35, "no red mark on the discarded triangle at (%.0f,%.0f)", x, y);
    /* a final triangle's centroid has no red mark */
    CHECK(draw(&f, m));
    size_t nt;
    const pdt_rtri *T = pdt_replay_tris(f.r, &nt);
    int checked = 0;
    for (size_t t = 0; t < nt && checked < 20; t++) {
        if (pdt_rstate_tri_status(f.r, f.s, t) != PDT_TS_FINAL) continue;
        double fx = (P[T[t].v[0]].x + P[T[t].v[1]].x + P[T[t].v[2]].x) / 3.0;
        double fy = (P[T[t].v[0]].y + P[T[t].v[1]].y + P[T[t].v[2]].y) / 3.0;
        pdt_view_to_screen(f.r, &f.v, W, H, fx, fy, &x, &y);
        CHECK(near_colour(f.sf, x, y, red) > 0.5);
        checked++;
    }
    /* and the discarded one is gone (faded) at the end, the final one drawn */
    pdt_view_to_screen(f.r, &f.v, W, H, cx, cy, &x, &y);
    CHECK(near_colour(f.sf, x, y, red) > 0.5);
    teardown(&f);
}

TEST(panels_present)
{
    fixture f;
    CHECK(setup(&f, 12, 5, 3));
    if (!f.s) return;
    /* a triangle event: the code panel has a highlighted line, the lifted
     * view a plane */
    size_t m = pdt_replay_count(f.r), k = 0;
    for (size_t i = 0; i < m && !k; i++)
        if (pdt_replay_rec(f.r, i)->ev.kind == PDT_EV_RA_DEFER) k = i + 1;
    CHECK(draw(&f, k));
    pdt_layout L;
    pdt_render_layout(W, H, 3, &L);
    CHECK_MSG(ink(f.sf, L.legend) > 2000, "legend %zu", ink(f.sf, L.legend));
    CHECK_MSG(ink(f.sf, L.code) > 2000, "code %zu", ink(f.sf, L.code));
    CHECK_MSG(ink(f.sf, L.stack) > 300, "stack %zu", ink(f.sf, L.stack));
    CHECK_MSG(ink(f.sf, L.lifted) > 2000, "lifted %zu", ink(f.sf, L.lifted));
    CHECK_MSG(ink(f.sf, L.timeline) > 5000, "timeline %zu", ink(f.sf, L.timeline));
    CHECK_MSG(ink(f.sf, L.top) > 500, "event line %zu", ink(f.sf, L.top));
    /* the highlighted code line: yellow pixels in the code panel */
    size_t yellow = 0;
    for (int y = (int)L.code.y; y < (int)(L.code.y + L.code.h); y++)
        for (int x = (int)L.code.x; x < (int)(L.code.x + L.code.w); x++) {
            double c[3];
            pixel(f.sf, x, y, c);
            if (c[0] > 0.9 && c[1] > 0.8 && c[2] < 0.45) yellow++;
        }
    CHECK_MSG(yellow > 500, "highlight %zu", yellow);
    /* the help overlay darkens the picture */
    f.v.help = 1;
    CHECK(draw(&f, k));
    double c[3];
    pixel(f.sf, 3, (int)(L.geo.y + 5), c);
    CHECK_MSG(c[0] < 0.8, "help overlay missing (%.2f)", c[0]);
    teardown(&f);
}

TEST(hidden_rank_not_drawn)
{
    fixture f;
    CHECK(setup(&f, 16, 6, 4));
    if (!f.s) return;
    uint8_t hidden[4] = {0, 0, 1, 0};
    f.v.hidden = hidden;
    f.v.fade = 1;
    CHECK(draw(&f, pdt_replay_count(f.r)));
    double x, y, want[3];
    CHECK(final_diagonal(&f, 2, &x, &y));
    pdt_rank_rgb(2, want);
    CHECK(near_colour(f.sf, x, y, want) > 0.3);
    CHECK(final_diagonal(&f, 1, &x, &y));
    pdt_rank_rgb(1, want);
    CHECK(near_colour(f.sf, x, y, want) < 0.12);
    teardown(&f);
}

static int file_starts(const char *path, const char *magic)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) return 0;
    char b[16] = {0};
    size_t n = fread(b, 1, strlen(magic), fp);
    fclose(fp);
    return n == strlen(magic) && !memcmp(b, magic, n);
}

TEST(files_png_svg_pdf)
{
    fixture f;
    CHECK(setup(&f, 8, 4, 2));
    if (!f.s) return;
    pdt_replay_seek(f.r, f.s, pdt_replay_count(f.r) / 2);
    pdt_err err = {0};
    char dir[] = "/tmp/pdt-view-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char p[3][64];
    const char *ext[3] = {"png", "svg", "pdf"}, *magic[3] = {"\x89PNG", "<?xml", "%PDF"};
    for (int i = 0; i < 3; i++) {
        snprintf(p[i], sizeof p[i], "%s/a.%s", dir, ext[i]);
        CHECK_MSG(pdt_render_file(p[i], 640, 400, f.r, f.s, &f.v, &err) == PDT_OK, "%s", err.msg);
        CHECK_MSG(file_starts(p[i], magic[i]), "%s", p[i]);
        remove(p[i]);
    }
    snprintf(p[0], sizeof p[0], "%s/a.bmp", dir);
    CHECK(pdt_render_file(p[0], 640, 400, f.r, f.s, &f.v, &err) == PDT_ERR_ARG);
    remove(dir);
    teardown(&f);
}

TEST(graham_and_every_cursor)
{
    pdt_synth s;
    pdt_err err = {0};
    CHECK(pdt_synth_graham(50, 3, &s, &err) == PDT_OK);
    pdt_replay *r = NULL;
    CHECK(pdt_replay_new(s.pts, s.n, s.recs, s.m, 1, &r, &err) == PDT_OK);
    if (!r) return;
    pdt_rstate *st = pdt_rstate_new(r);
    pdt_view v;
    pdt_view_defaults(&v);
    cairo_surface_t *sf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, 400, 300);
    int bad = 0;
    for (size_t k = 0; k <= pdt_replay_count(r); k++) { /* small pictures too */
        pdt_replay_seek(r, st, k);
        cairo_t *cr = cairo_create(sf);
        bad += pdt_render(cr, 400, 300, r, st, &v, &err) != PDT_OK;
        cairo_destroy(cr);
    }
    CHECK(bad == 0);
    cairo_surface_destroy(sf);
    pdt_rstate_free(st);
    pdt_replay_free(r);
    pdt_synth_free(&s);
}

/* Graham's scan as `pdt hull --trace` records it: no HULL event.  Once the
 * scan phase has ended, the stack is the hull and is drawn closed: the edge
 * from the top back to p0 carries the hull colour. */
TEST(graham_hull_closed_at_end)
{
    pdt_synth s;
    pdt_err err = {0};
    CHECK(pdt_synth_graham(40, 5, &s, &err) == PDT_OK);
    size_t m = 0;
    for (size_t i = 0; i < s.m; i++) /* drop the HULL events */
        if (s.recs[i].ev.kind != PDT_EV_HULL) s.recs[m++] = s.recs[i];
    CHECK(m < s.m);
    pdt_replay *r = NULL;
    CHECK(pdt_replay_new(s.pts, s.n, s.recs, m, 1, &r, &err) == PDT_OK);
    if (!r) return;
    pdt_rstate *st = pdt_rstate_new(r);
    pdt_view v;
    pdt_view_defaults(&v);
    cairo_surface_t *sf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
    pdt_replay_seek(r, st, m);
    int32_t top = pdt_rstate_slot(r, st, 0, PDT_SLOT_STACK0 + PDT_STACK_GRAHAM);
    CHECK(top >= 0);
    size_t nn;
    const pdt_rnode *N = pdt_replay_nodes(r, &nn);
    int32_t bot = top;
    while (bot >= 0 && N[bot].parent >= 0) bot = N[bot].parent;
    CHECK(top >= 0 && N[top].depth >= 3);
    cairo_t *cr = cairo_create(sf);
    CHECK(pdt_render(cr, W, H, r, st, &v, &err) == PDT_OK);
    cairo_destroy(cr);
    cairo_surface_flush(sf);
    if (top >= 0) {
        double ax, ay, bx, by, col[3], want[3];
        pdt_view_to_screen(r, &v, W, H, s.pts[N[top].pt].x, s.pts[N[top].pt].y, &ax, &ay);
        pdt_view_to_screen(r, &v, W, H, s.pts[N[bot].pt].x, s.pts[N[bot].pt].y, &bx, &by);
        pdt_rank_rgb(0, col);
        for (int j = 0; j < 3; j++) want[j] = 0.6 * col[j] * 0.9 + 0.1; /* 0.9 over white */
        double d = 9;
        for (int t = 1; t < 4; t++) { /* a few points along the closing edge */
            double x = ax + (bx - ax) * t / 4, y = ay + (by - ay) * t / 4;
            double e = 9;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    double c[3];
                    pixel(sf, (int)lround(x) + dx, (int)lround(y) + dy, c);
                    if (cdist(c, want) < e) e = cdist(c, want);
                }
            if (t == 1 || e > d) d = e; /* the worst of the three samples */
        }
        CHECK(d < 0.35);
    }
    cairo_surface_destroy(sf);
    pdt_rstate_free(st);
    pdt_replay_free(r);
    pdt_synth_free(&s);
}

/* The lifted view's count: every input point strictly inside the circle,
 * lifted or not, exactly (points on the circle are not counted). */
TEST(inside_count_exact_all_points)
{
    /* triangle (0,0) (10,0) (0,10): circle centre (5,5), r^2 = 50 */
    pdt_point P[] = {{0, 0}, {10, 0}, {0, 10}, {5, 5}, {1, 1}, {9, 8}, {10, 10},
                     {12, 5}, {-2, 5}, {5, 12}, {20, 20}, {5, -3}, {2, 9}};
    size_t n = sizeof P / sizeof P[0];
    pdt_err err = {0};
    pdt_replay *r = NULL;
    CHECK(pdt_replay_new(P, n, NULL, 0, 1, &r, &err) == PDT_OK);
    if (!r) return;
    uint32_t ccw[3] = {0, 1, 2}, cw[3] = {0, 2, 1}, flat[3] = {0, 1, 1};
    /* distance^2 from (5,5): inside (5,5) 0, (1,1) 32, (9,8) 25, (12,5) 49, (-2,5) 49,
     * (5,12) 49, (2,9) 25; on the circle (10,10) 50 and the vertices; outside the rest */
    CHECK_MSG(pdt_replay_inside_count(r, ccw) == 7, "got %zu", pdt_replay_inside_count(r, ccw));
    CHECK(pdt_replay_inside_count(r, cw) == 7);
    CHECK(pdt_replay_inside_count(r, flat) == 0);
    pdt_replay_free(r);
}

/* A hull-only run (no LIFT, no triangle events): the points are drawn as not
 * lifted (hollow), not as filled dots. */
TEST(hull_only_points_not_lifted)
{
    pdt_synth s;
    pdt_err err = {0};
    CHECK(pdt_synth_graham(30, 7, &s, &err) == PDT_OK);
    pdt_replay *r = NULL;
    CHECK(pdt_replay_new(s.pts, s.n, s.recs, s.m, 1, &r, &err) == PDT_OK);
    if (!r) return;
    CHECK(pdt_replay_kind_count(r, PDT_EV_LIFT) == 0);
    pdt_rstate *st = pdt_rstate_new(r);
    pdt_view v;
    pdt_view_defaults(&v);
    cairo_surface_t *sf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
    pdt_replay_seek(r, st, 0); /* nothing drawn over the points yet */
    cairo_t *cr = cairo_create(sf);
    CHECK(pdt_render(cr, W, H, r, st, &v, &err) == PDT_OK);
    cairo_destroy(cr);
    cairo_surface_flush(sf);
    size_t dark = 0;
    for (size_t p = 0; p < s.n; p++) {
        double x, y, c[3];
        pdt_view_to_screen(r, &v, W, H, s.pts[p].x, s.pts[p].y, &x, &y);
        pixel(sf, (int)lround(x), (int)lround(y), c);
        dark += c[0] + c[1] + c[2] < 1.0;
    }
    CHECK_MSG(dark == 0, "%zu of %zu points drawn filled", dark, s.n);
    cairo_surface_destroy(sf);
    pdt_rstate_free(st);
    pdt_replay_free(r);
    pdt_synth_free(&s);
}

/* Pixels of the point-label colour in the geometry area. */
static size_t label_ink(cairo_surface_t *sf)
{
    pdt_layout L;
    pdt_render_layout(W, H, 2, &L);
    const double want[3] = {0.0, 0.25, 0.55};
    size_t n = 0;
    for (int y = (int)L.geo.y; y < (int)(L.geo.y + L.geo.h); y++)
        for (int x = (int)L.geo.x; x < (int)(L.geo.x + L.geo.w); x++) {
            double c[3];
            pixel(sf, x, y, c);
            n += cdist(c, want) < 0.12;
        }
    return n;
}

/* Triangulation runs: input indices beside the points while there is room
 * (crowded labels give way), none when hundreds of points are on screen
 * (only those the current event names, and there is none at cursor 0). */
TEST(point_numbers_when_few)
{
    fixture f;
    CHECK(setup(&f, 6, 4, 2)); /* 24 points */
    CHECK(draw(&f, 0));
    size_t few = label_ink(f.sf);
    teardown(&f);
    CHECK(setup(&f, 30, 20, 2)); /* 600 points */
    CHECK(draw(&f, 0));
    size_t many = label_ink(f.sf);
    teardown(&f);
    CHECK_MSG(few > 200 && many == 0, "label pixels: %zu with 24 points, %zu with 600", few, many);
}

TEST(pick_and_zoom)
{
    fixture f;
    CHECK(setup(&f, 8, 4, 2));
    if (!f.s) return;
    pdt_replay_seek(f.r, f.s, pdt_replay_count(f.r));
    double x, y;
    pdt_view_to_screen(f.r, &f.v, W, H, f.syn.pts[5].x, f.syn.pts[5].y, &x, &y);
    int64_t p, t;
    int e;
    pdt_render_pick(f.r, f.s, &f.v, W, H, x + 2, y - 1, 10, &p, &t, &e);
    CHECK_MSG(p == 5, "picked %lld", (long long)p);
    /* zoom at a point keeps that point under the cursor */
    pdt_view_zoom_at(f.r, &f.v, W, H, x, y, 3.0);
    double x2, y2;
    pdt_view_to_screen(f.r, &f.v, W, H, f.syn.pts[5].x, f.syn.pts[5].y, &x2, &y2);
    CHECK_MSG(fabs(x2 - x) < 0.01 && fabs(y2 - y) < 0.01, "moved to %.2f,%.2f from %.2f,%.2f", x2, y2, x, y);
    /* a click in the middle of a cell picks a triangle */
    pdt_view_to_screen(f.r, &f.v, W, H, 12, 10, &x, &y);
    pdt_render_pick(f.r, f.s, &f.v, W, H, x, y, 2, &p, &t, &e);
    CHECK(p == -1 && t >= 0 && e == -1);
    /* a click on the middle of the edge (0,0)-(10,0) picks that edge */
    pdt_view_to_screen(f.r, &f.v, W, H, 5, 0, &x, &y);
    pdt_render_pick(f.r, f.s, &f.v, W, H, x, y + 1, 10, &p, &t, &e);
    size_t nt;
    const pdt_rtri *T = pdt_replay_tris(f.r, &nt);
    CHECK_MSG(p == -1 && t >= 0 && e >= 0, "p %lld t %lld e %d", (long long)p, (long long)t, e);
    if (t >= 0 && e >= 0) {
        pdt_point a = f.syn.pts[T[t].v[e]], b = f.syn.pts[T[t].v[(e + 1) % 3]];
        CHECK(a.y == 0 && b.y == 0 && a.x + b.x == 10);
    }
    /* the timeline maps clicks to cursors */
    pdt_layout L;
    pdt_render_layout(W, H, 2, &L);
    double ty = L.timeline.y + L.timeline.h - 2; /* the axis line, under the rank rows */
    size_t k0 = pdt_render_timeline_at(f.r, NULL, W, H, L.timeline.x + 1, ty);
    size_t k1 = pdt_render_timeline_at(f.r, NULL, W, H, L.timeline.x + L.timeline.w - 1, ty);
    CHECK(k0 == 0 && k1 == pdt_replay_count(f.r));
    CHECK(pdt_render_timeline_at(f.r, NULL, W, H, 5, 5) == (size_t)-1);
    teardown(&f);
}

/* A click in rank q's timeline row lands on an event of rank q, and no
 * event of q is nearer to the clicked time. */
TEST(timeline_click_picks_rank)
{
    fixture f;
    CHECK(setup(&f, 16, 6, 4));
    if (!f.s) return;
    pdt_layout L;
    pdt_render_layout(W, H, 4, &L);
    size_t m = pdt_replay_count(f.r);
    double y0 = L.timeline.y + 0.4 * L.font, y1 = L.timeline.y + L.timeline.h - 1.3 * L.font;
    int checked = 0;
    for (int q = 0; q < 4; q++)
        for (int xi = 1; xi < 10; xi++) {
            double sx = L.timeline.x + L.timeline.w * xi / 10.0, sy = y0 + (y1 - y0) * (q + 0.5) / 4;
            size_t k = pdt_render_timeline_at(f.r, &f.v, W, H, sx, sy);
            size_t kt = pdt_render_timeline_at(f.r, &f.v, W, H, sx, L.timeline.y + L.timeline.h - 2);
            CHECK(k >= 1 && k <= m);
            if (k < 1 || k > m) continue;
            CHECK_MSG((int)pdt_replay_rec(f.r, k - 1)->rank == q, "row %d gave rank %u", q,
                      pdt_replay_rec(f.r, k - 1)->rank);
            size_t e = kt ? kt - 1 : 0, got = k - 1, dist = got > e ? got - e : e - got;
            for (size_t i = 0; i < m; i++)
                if ((int)pdt_replay_rec(f.r, i)->rank == q)
                    CHECK((i > e ? i - e : e - i) >= dist);
            checked++;
        }
    CHECK(checked == 36);
    teardown(&f);
}

/* Themes: the background of the picture and of the event line differ as
 * the theme says; rank colours stay the same. */
TEST(theme_colours)
{
    fixture f;
    CHECK(setup(&f, 8, 4, 2));
    if (!f.s) return;
    pdt_layout L;
    pdt_render_layout(W, H, 2, &L);
    const double white[3] = {1, 1, 1}, black[3] = {0, 0, 0};
    double c[3];
    CHECK(draw(&f, 0));
    pixel(f.sf, (int)L.geo.x + 2, (int)L.geo.y + 2, c);
    CHECK_MSG(cdist(c, white) < 0.02, "light background %g %g %g", c[0], c[1], c[2]);
    f.v.theme = PDT_THEME_DARK;
    CHECK(draw(&f, 0));
    pixel(f.sf, (int)L.geo.x + 2, (int)L.geo.y + 2, c);
    CHECK_MSG(cdist(c, black) < 0.4, "dark background %g %g %g", c[0], c[1], c[2]);
    pixel(f.sf, (int)L.legend.x + (int)L.legend.w / 2, (int)L.legend.y + (int)L.legend.h - 4, c);
    CHECK_MSG(cdist(c, black) < 0.55, "dark panel %g %g %g", c[0], c[1], c[2]);
    double x, y, rk[3];
    pdt_rank_rgb(1, rk);
    pdt_replay_seek(f.r, f.s, pdt_replay_count(f.r));
    if (final_diagonal(&f, 1, &x, &y)) {
        CHECK(draw(&f, pdt_replay_count(f.r)));
        CHECK_MSG(near_colour(f.sf, x, y, rk) < 0.12, "rank 1 colour on dark: %g", near_colour(f.sf, x, y, rk));
    } else CHECK(0);
    f.v.theme = PDT_THEME_CONTRAST;
    CHECK(draw(&f, 0));
    pixel(f.sf, (int)L.top.x + (int)L.top.w - 3, (int)L.top.y + 2, c);
    CHECK_MSG(cdist(c, white) < 0.02, "contrast event bar %g %g %g", c[0], c[1], c[2]);
    teardown(&f);
}

/* Red pixels (the crosses of discarded triangles, deleted points, the
 * current event's marks) in the geometry area. */
static size_t red_ink(cairo_surface_t *sf, int ranks)
{
    pdt_layout L;
    pdt_render_layout(W, H, ranks, &L);
    const double red[3] = {0.85, 0, 0};
    size_t n = 0;
    for (int y = (int)L.geo.y; y < (int)(L.geo.y + L.geo.h); y++)
        for (int x = (int)L.geo.x; x < (int)(L.geo.x + L.geo.w); x++) {
            double c[3];
            pixel(sf, x, y, c);
            n += cdist(c, red) < 0.3;
        }
    return n;
}

/* The clean picture: just after a discard the normal picture has red
 * crosses and marks, the clean one none; its triangles are the final ones,
 * filled, so a final triangle's centroid is tinted by its rank. */
TEST(clean_view_no_crosses)
{
    fixture f;
    CHECK(setup(&f, 16, 6, 4));
    if (!f.s) return;
    size_t m = pdt_replay_count(f.r), k = 0;
    for (size_t i = 0; i < m && !k; i++)
        if (pdt_replay_rec(f.r, i)->ev.kind == PDT_EV_DISCARD) k = i + 1;
    CHECK(k > 0);
    CHECK(draw(&f, k + 3));
    size_t normal = red_ink(f.sf, 4);
    f.v.clean = 1;
    CHECK(draw(&f, k + 3));
    size_t clean = red_ink(f.sf, 4);
    CHECK_MSG(normal > 50 && clean == 0, "red pixels: %zu normal, %zu clean", normal, clean);
    teardown(&f);
}

int main(void)
{
    RUN(clean_view_no_crosses);
    RUN(theme_colours);
    RUN(timeline_click_picks_rank);
    RUN(final_edge_has_rank_colour);
    RUN(discarded_drawn_differently);
    RUN(panels_present);
    RUN(hidden_rank_not_drawn);
    RUN(files_png_svg_pdf);
    RUN(graham_and_every_cursor);
    RUN(graham_hull_closed_at_end);
    RUN(inside_count_exact_all_points);
    RUN(hull_only_points_not_lifted);
    RUN(point_numbers_when_few);
    RUN(pick_and_zoom);
    return test_summary();
}
