/* pdt — what is under the mouse in the viewer's geometry area. */
#include "render_int.h"

void pdt_render_pick(const pdt_replay *r, const pdt_rstate *s, const pdt_view *v, double w,
                     double h, double sx, double sy, double radius, int64_t *point, int64_t *tri,
                     int *edge)
{
    *point = *tri = -1;
    *edge = -1;
    size_t n;
    const pdt_point *P = pdt_replay_points(r, &n);
    xform X = pdt_geo_xform(r, v, w, h);
    double best = radius * radius;
    for (size_t p = 0; p < n; p++) {
        double dx = X.ox + X.s * P[p].x - sx, dy = X.oy - X.s * P[p].y - sy;
        if (dx * dx + dy * dy <= best) {
            best = dx * dx + dy * dy;
            *point = (int64_t)p;
        }
    }
    if (*point >= 0) return;
    double wx = (sx - X.ox) / X.s, wy = (X.oy - sy) / X.s;
    size_t nt;
    const pdt_rtri *T = pdt_replay_tris(r, &nt);
    const pdt_rtri_hist *H = pdt_replay_tri_hist(r);
    int nr = pdt_replay_nranks(r);
    double best_e = radius * radius / 4;
    int64_t inside = -1;
    for (size_t t = 0; t < nt; t++) {
        uint32_t he = pdt_rstate_tri_entry(r, s, t);
        if (he == UINT32_MAX || H[he].status == PDT_TS_DISCARDED) continue;
        if (v->hidden && T[t].maker < (uint32_t)nr && v->hidden[T[t].maker]) continue;
        int pos = 0, neg = 0;
        for (int j = 0; j < 3; j++) {
            pdt_point a = P[T[t].v[j]], b = P[T[t].v[(j + 1) % 3]];
            double o = ((double)b.x - a.x) * (wy - a.y) - ((double)b.y - a.y) * (wx - a.x);
            pos |= o > 0;
            neg |= o < 0;
            /* distance on screen from the click to the segment a-b */
            double ax = X.ox + X.s * a.x, ay = X.oy - X.s * a.y, bx = X.ox + X.s * b.x,
                   by = X.oy - X.s * b.y;
            double ex = bx - ax, ey = by - ay, l2 = ex * ex + ey * ey;
            double u = l2 > 0 ? ((sx - ax) * ex + (sy - ay) * ey) / l2 : 0;
            u = u < 0 ? 0 : u > 1 ? 1 : u;
            double qx = ax + u * ex - sx, qy = ay + u * ey - sy;
            if (qx * qx + qy * qy < best_e) {
                best_e = qx * qx + qy * qy;
                *tri = (int64_t)t;
                *edge = j;
            }
        }
        if (!(pos && neg) && (inside < 0 || H[he].status == PDT_TS_FINAL)) inside = (int64_t)t;
    }
    if (*edge < 0) *tri = inside;
}

