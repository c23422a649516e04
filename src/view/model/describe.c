/* pdt — the viewer's words: the event line and the pseudo-code listings
 * (see pdt/view/describe.h). */
#include "pdt/view/describe.h"

#include <inttypes.h>
#include <stdio.h>

#define NONE32 UINT32_MAX

/* ---- names of points and triangles ---------------------------------------------- */

void pdt_replay_tri_order(const pdt_replay *r, const uint32_t in[3], uint32_t out[3])
{
    size_t n;
    const pdt_point *P = pdt_replay_points(r, &n);
    int k = in[1] < in[0] ? (in[2] < in[1] ? 2 : 1) : (in[2] < in[0] ? 2 : 0);
    out[0] = in[k];
    out[1] = in[(k + 1) % 3];
    out[2] = in[(k + 2) % 3];
    if (out[0] < n && out[1] < n && out[2] < n) {
        pdt_point a = P[out[0]], b = P[out[1]], c = P[out[2]];
        int64_t o = ((int64_t)b.x - a.x) * ((int64_t)c.y - a.y) - ((int64_t)c.x - a.x) * ((int64_t)b.y - a.y);
        if (o < 0) {
            uint32_t t = out[1];
            out[1] = out[2];
            out[2] = t;
        }
    }
}

void pdt_point_label(const pdt_replay *r, const pdt_rstate *s, size_t p, char *buf, size_t cap)
{
    int64_t pos = pdt_replay_sort_pos(r, p);
    if (pos >= 0 && s && (s->pflags[p] & PDT_PF_SORTED))
        snprintf(buf, cap, "%zu=p%lld", p, (long long)pos);
    else
        snprintf(buf, cap, "%zu", p);
}

int pdt_replay_disk_touches(const pdt_replay *r, const uint32_t v[3], int rank)
{
    size_t n;
    const pdt_point *P = pdt_replay_points(r, &n);
    pdt_point lo, hi;
    uint32_t w[3];
    pdt_replay_tri_order(r, v, w);
    if (w[0] >= n || w[1] >= n || w[2] >= n || !pdt_replay_box(r, rank, &lo, &hi)) return 0;
    pdt_point A = P[w[0]], B = P[w[1]], C = P[w[2]];
    double bx = (double)B.x - A.x, by = (double)B.y - A.y, cx = (double)C.x - A.x,
           cy = (double)C.y - A.y;
    double d = 2 * (bx * cy - by * cx);
    if (d == 0) return 0;
    double ux = (cy * (bx * bx + by * by) - by * (cx * cx + cy * cy)) / d;
    double uy = (bx * (cx * cx + cy * cy) - cx * (bx * bx + by * by)) / d;
    double ox = A.x + ux, oy = A.y + uy, rr = ux * ux + uy * uy;
    double qx = ox < lo.x ? lo.x : ox > hi.x ? hi.x : ox;
    double qy = oy < lo.y ? lo.y : oy > hi.y ? hi.y : oy;
    return (qx - ox) * (qx - ox) + (qy - oy) * (qy - oy) <= rr * (1 + 1e-9);
}

/* ---- the event line ------------------------------------------------------------ */

/* "point 7 (0,4)"; a number out of range as it is. */
static const char *pt_str(const pdt_replay *r, uint32_t p, char *b, size_t cap)
{
    size_t n;
    const pdt_point *P = pdt_replay_points(r, &n);
    if (p < n) snprintf(b, cap, "point %u (%d,%d)", p, P[p].x, P[p].y);
    else snprintf(b, cap, "point %u", p);
    return b;
}

/* A point of Graham's scan: "p7 (point 12)" once it has a place in the
 * angular order, else "point 12". */
static const char *gpt(const pdt_replay *r, uint32_t p, char *b, size_t cap)
{
    int64_t pos = pdt_replay_sort_pos(r, p);
    if (pos >= 0) snprintf(b, cap, "p%lld (point %u)", (long long)pos, p);
    else snprintf(b, cap, "point %u", p);
    return b;
}

/* Graham's short name of a point: "p7", or "point 12" before the sort. */
static const char *gshort(const pdt_replay *r, uint32_t p, char *b, size_t cap)
{
    int64_t pos = pdt_replay_sort_pos(r, p);
    if (pos >= 0) snprintf(b, cap, "p%lld", (long long)pos);
    else snprintf(b, cap, "point %u", p);
    return b;
}

/* "9 30 28": a triangle in the one corner order (pdt_replay_tri_order). */
static const char *tri_str(const pdt_replay *r, const pdt_event *e, char *b, size_t cap)
{
    uint32_t v[3];
    pdt_replay_tri_order(r, (const uint32_t[3]){e->a, e->b, e->c}, v);
    snprintf(b, cap, "%u %u %u", v[0], v[1], v[2]);
    return b;
}

/* A group of ranks [lo, end): "rank 2" or "ranks 0–1". */
static const char *group_str(uint32_t lo, uint32_t end, char *b, size_t cap)
{
    if (end <= lo + 1) snprintf(b, cap, "rank %u", lo);
    else snprintf(b, cap, "ranks %u–%u", lo, end - 1);
    return b;
}

/* The point below the top of rank q's stack `st` in s (the top after a pop
 * is the point the popped one sat on), or NONE32. */
static uint32_t stack_top(const pdt_replay *r, const pdt_rstate *s, int q, int st)
{
    size_t nn;
    const pdt_rnode *N = pdt_replay_nodes(r, &nn);
    int32_t t = s ? pdt_rstate_slot(r, s, q, PDT_SLOT_STACK0 + st) : -1;
    return t >= 0 && (size_t)t < nn ? N[t].pt : NONE32;
}

/* The innermost phase (not "run") open on rank q in s, and its merge level. */
static int open_phase(const pdt_replay *r, const pdt_rstate *s, int q, uint32_t *level)
{
    size_t np;
    const pdt_rphase *Ph = pdt_replay_phases(r, &np);
    *level = 0;
    for (int32_t p = s ? pdt_rstate_slot(r, s, q, PDT_SLOT_PHASE) : -1; p >= 0 && (size_t)p < np;
         p = Ph[p].parent)
        if (Ph[p].phase != PDT_PH_RUN) {
            *level = Ph[p].sub;
            return (int)Ph[p].phase;
        }
    return -1;
}

/* Why a triangle is final, from where its rank is. */
static const char *final_reason(const pdt_replay *r, const pdt_rstate *s, int q)
{
    uint32_t level;
    int ph = open_phase(r, s, q, &level);
    if (ph == PDT_PH_CLASSIFY) return "its circle misses every foreign box";
    if (ph == PDT_PH_MERGE) {
        size_t ng;
        const pdt_rmerge *M = pdt_replay_merges(r, &ng);
        int32_t g = pdt_rstate_slot(r, s, q, PDT_SLOT_MERGE);
        if (g >= 0 && (size_t)g < ng && M[g].gl == 0 && (int)M[g].gend >= pdt_replay_nranks(r))
            return "the last merge: no rank is left outside";
        return "its circle misses every box outside the merged group";
    }
    if (pdt_replay_nranks(r) <= 1) return "one rank: the kernel's triangles are the output";
    return "certified";
}

/* Area2 of (a, b, c) and its verdict for a pop: "Area2(p1, p2, p3) = 0:
 * collinear" or "... = -26: right turn". */
static void pop_reason(const pdt_replay *r, const pdt_rstate *s, const pdt_rec *rec, char *o,
                       size_t c)
{
    const pdt_event *e = &rec->ev;
    size_t n;
    const pdt_point *P = pdt_replay_points(r, &n);
    uint32_t below = stack_top(r, s, (int)rec->rank, e->sub);
    int gr = e->sub == PDT_STACK_GRAHAM;
    char a[32], b[32], d[32];
    if (below >= n || e->a >= n || e->c >= n) {
        snprintf(o, c, "%s at (%d,%d)", gr ? "no left turn" : "right turn", e->a < n ? P[e->a].x : 0,
                 e->a < n ? P[e->a].y : 0);
        return;
    }
    pdt_point A = P[below], B = P[e->a], C = P[e->c];
    long long v = (long long)(((int64_t)B.x - A.x) * ((int64_t)C.y - A.y) -
                              ((int64_t)C.x - A.x) * ((int64_t)B.y - A.y));
    if (gr)
        snprintf(o, c, "Area2(%s, %s, %s) = %lld: %s", gshort(r, below, a, sizeof a),
                 gshort(r, e->a, b, sizeof b), gshort(r, e->c, d, sizeof d), v,
                 v == 0 ? "collinear, not a strict left turn" : v < 0 ? "right turn" : "left turn?");
    else
        snprintf(o, c, "Area2(%u, %u, %u) = %lld: %s", below, e->a, e->c, v,
                 v == 0 ? "collinear" : v < 0 ? "right turn" : "left turn");
}

void pdt_replay_describe(const pdt_replay *r, size_t k, char *buf, size_t cap)
{
    if (!cap) return;
    pdt_rstate *s = NULL;
    const pdt_rec *rec = k && k <= pdt_replay_count(r) ? pdt_replay_rec(r, k - 1) : NULL;
    if (rec) s = pdt_rstate_new(r);
    if (s) pdt_replay_seek(r, s, k);
    pdt_replay_describe_state(r, s, k, buf, cap);
    pdt_rstate_free(s);
}

/* A stack event (push, pop) into o[0..c). */
static void describe_stack(const pdt_replay *r, const pdt_rstate *s, const pdt_rec *rec, char *o,
                           size_t c)
{
    const pdt_event *e = &rec->ev;
    size_t npts;
    pdt_replay_points(r, &npts);
    char p1[64], why[192];
    const char *stk = pdt_stack_name(e->sub) ? pdt_stack_name(e->sub) : "?";
    if (e->kind == PDT_EV_PUSH) {
        if (e->sub == PDT_STACK_GRAHAM)
            snprintf(o, c, "push %s on the Graham stack (depth %u)", gpt(r, e->a, p1, sizeof p1), e->b);
        else
            snprintf(o, c, "push %s on the %s stack (depth %u)", pt_str(r, e->a, p1, sizeof p1), stk, e->b);
    } else if (e->c != NONE32 && e->c < npts) {
        pop_reason(r, s, rec, why, sizeof why);
        if (e->sub == PDT_STACK_GRAHAM)
            snprintf(o, c, "pop %s — %s", gpt(r, e->a, p1, sizeof p1), why);
        else
            snprintf(o, c, "pop %s from the %s stack — %s", pt_str(r, e->a, p1, sizeof p1), stk, why);
    } else {
        snprintf(o, c, "pop %s from the %s stack", pt_str(r, e->a, p1, sizeof p1), stk);
    }
}

/* A deferred triangle: every rank whose box the circle touches (the boxes
 * the picture outlines), and the one the trace records: the merge it
 * waits for. */
static void describe_defer(const pdt_replay *r, const pdt_rec *rec, char *o, size_t c)
{
    const pdt_event *e = &rec->ev;
    char t3[48], why[192];
    uint32_t v[3] = {e->a, e->b, e->c};
    int nr = pdt_replay_nranks(r), cnt = 0, last = -1;
    for (int q = 0; q < nr; q++)
        if (q != (int)rec->rank && pdt_replay_disk_touches(r, v, q)) cnt++, last = q;
    size_t w = 0;
    why[0] = 0;
    for (int q = 0, i = 0; q < nr && w < sizeof why; q++) {
        if (q == (int)rec->rank || !pdt_replay_disk_touches(r, v, q)) continue;
        int d = snprintf(why + w, sizeof why - w, "%s%d", i == 0 ? "" : q == last ? " and " : ", ", q);
        if (d > 0) w += (size_t)d;
        i++;
    }
    if (cnt == 0)
        snprintf(o, c, "defer %s — waits for the merge with rank %lld's group",
                 tri_str(r, e, t3, sizeof t3), (long long)e->v);
    else if (cnt == 1 && last == (int)e->v)
        snprintf(o, c, "defer %s — its circle touches the box of rank %lld",
                 tri_str(r, e, t3, sizeof t3), (long long)e->v);
    else
        snprintf(o, c, "defer %s — its circle touches the box%s of rank%s %s (waits for rank "
                 "%lld's group)",
                 tri_str(r, e, t3, sizeof t3), cnt > 1 ? "es" : "", cnt > 1 ? "s" : "", why,
                 (long long)e->v);
}

/* Graham's and the lift's point events (lift, sort, delete). */
static void describe_point(const pdt_replay *r, const pdt_event *e, char *o, size_t c)
{
    char p1[64], p2[64];
    if (e->kind == PDT_EV_LIFT)
        snprintf(o, c, "lift %s to z = %lld", pt_str(r, e->a, p1, sizeof p1), (long long)e->v);
    else if (e->kind == PDT_EV_SORT && e->b == 0)
        snprintf(o, c, "sort: %s is the origin p0 (the rightmost lowest point)",
                 pt_str(r, e->a, p1, sizeof p1));
    else if (e->kind == PDT_EV_SORT)
        snprintf(o, c, "sort: %s becomes p%u", pt_str(r, e->a, p1, sizeof p1), e->b);
    else if (e->sub == PDT_DEL_COINCIDENT)
        snprintf(o, c, "delete %s — a copy of %s", gpt(r, e->a, p1, sizeof p1),
                 gpt(r, e->b, p2, sizeof p2));
    else
        snprintf(o, c, "delete %s — same angle as %s, and closer to p0", gpt(r, e->a, p1, sizeof p1),
                 gpt(r, e->b, p2, sizeof p2));
}

/* The triangle events (candidate, final, deferred, shipped, discarded). */
static void describe_tri(const pdt_replay *r, const pdt_rstate *s, const pdt_rec *rec, char *o,
                         size_t c)
{
    const pdt_event *e = &rec->ev;
    size_t npts;
    pdt_replay_points(r, &npts);
    char p2[64], t3[48];
    switch (e->kind) {
    case PDT_EV_TRI_NEW:
        snprintf(o, c, "candidate triangle %s from the %s kernel", tri_str(r, e, t3, sizeof t3),
                 e->sub ? "border" : "local");
        break;
    case PDT_EV_TRI_FINAL:
        snprintf(o, c, "triangle %s is final — %s", tri_str(r, e, t3, sizeof t3),
                 final_reason(r, s, (int)rec->rank));
        break;
    case PDT_EV_RA_DEFER: describe_defer(r, rec, o, c); break;
    case PDT_EV_SHIP:
        snprintf(o, c, "ship %s to rank %lld", tri_str(r, e, t3, sizeof t3), (long long)e->v);
        break;
    default: /* PDT_EV_DISCARD */
        if (e->v >= 0 && (uint64_t)e->v < npts)
            snprintf(o, c, "discard %s — not Delaunay: %s is inside its circle",
                     tri_str(r, e, t3, sizeof t3), pt_str(r, (uint32_t)e->v, p2, sizeof p2));
        else
            snprintf(o, c, "discard %s — not Delaunay", tri_str(r, e, t3, sizeof t3));
        break;
    }
}

/* The other events: phases, merges, messages, the kernel's. */
static void describe_other(const pdt_event *e, char *o, size_t c)
{
    char p1[64], p2[64];
    const char *ph = pdt_phase_name(e->sub) ? pdt_phase_name(e->sub) : "?";
    switch (e->kind) {
    case PDT_EV_PHASE_BEGIN:
        if (e->sub == PDT_PH_MERGE) snprintf(o, c, "begin phase merge, level %u", e->a);
        else snprintf(o, c, "begin phase %s", ph);
        break;
    case PDT_EV_PHASE_END: snprintf(o, c, "end of phase %s", ph); break;
    case PDT_EV_MERGE_BEGIN:
        snprintf(o, c, "merge level %u: %s with %s, at rank %lld", e->sub,
                 group_str(e->a, e->b, p1, sizeof p1), group_str(e->b, e->c, p2, sizeof p2),
                 (long long)e->v);
        break;
    case PDT_EV_MERGE_END:
        snprintf(o, c, "merge level %u done: %u shipped, border %u, %u kept, %lld discarded",
                 e->sub, e->a, e->b, e->c, (long long)e->v);
        break;
    case PDT_EV_SEND:
        snprintf(o, c, "send %" PRIu64 " bytes to rank %u (tag %u)", pdt_event_bytes(e), e->a, e->sub);
        break;
    case PDT_EV_RECV:
        snprintf(o, c, "receive %" PRIu64 " bytes from rank %u (tag %u)", pdt_event_bytes(e), e->a,
                 e->sub);
        break;
    case PDT_EV_HULL:
        snprintf(o, c, "hull of %u vertices%s", e->a, e->b ? " (degenerate)" : "");
        break;
    case PDT_EV_EDGE_ADD: snprintf(o, c, "kernel adds edge %u–%u", e->a, e->b); break;
    case PDT_EV_EDGE_DEL: snprintf(o, c, "kernel deletes edge %u–%u", e->a, e->b); break;
    case PDT_EV_INCIRCLE:
        snprintf(o, c, "incircle %u %u %u with %lld: %s", e->a, e->b, e->c, (long long)(e->v >> 2),
                 (e->v & 3) == 2 ? "inside" : (e->v & 3) == 0 ? "outside" : "on the circle");
        break;
    default: snprintf(o, c, "event of kind %u", e->kind); break;
    }
}

void pdt_replay_describe_state(const pdt_replay *r, const pdt_rstate *s, size_t k, char *buf,
                               size_t cap)
{
    if (!cap) return;
    if (s) k = s->k;
    size_t m = pdt_replay_count(r);
    if (k == 0 || k > m) {
        int q = pdt_replay_nranks(r);
        snprintf(buf, cap, "start — %zu events, %d rank%s; press Space or → to begin", m, q,
                 q == 1 ? "" : "s");
        return;
    }
    const pdt_rec held = *pdt_replay_rec(r, k - 1); /* (a kept index's pointer is short-lived) */
    const pdt_event *e = &held.ev;
    int n = snprintf(buf, cap, "rank %u: ", held.rank);
    if (n < 0 || (size_t)n >= cap) return;
    char *o = buf + n;
    size_t c = cap - (size_t)n;
    switch (e->kind) {
    case PDT_EV_PUSH:
    case PDT_EV_POP: describe_stack(r, s, &held, o, c); break;
    case PDT_EV_LIFT:
    case PDT_EV_SORT:
    case PDT_EV_DELETE: describe_point(r, e, o, c); break;
    case PDT_EV_TRI_NEW:
    case PDT_EV_TRI_FINAL:
    case PDT_EV_RA_DEFER:
    case PDT_EV_SHIP:
    case PDT_EV_DISCARD: describe_tri(r, s, &held, o, c); break;
    default: describe_other(e, o, c); break;
    }
}

/* ---- the pseudo-code listings -------------------------------------------------- */

static const char *const graham_code[] = {
    "1  p0 := the rightmost lowest point",
    "2  sort the others by angle around p0",
    "3    tie: delete the closer point (or the copy)",
    "4  S := (p0, p1)",
    "5  i := 2",
    "6  while i < n:",
    "7    if Area2(second, top, p_i) > 0:",
    "8      push p_i; i := i + 1",
    "9    else: pop       (not a strict left turn)",
    "10 S is the hull",
};

static const char *const srm_code[] = {
    "1  P_r = partition(input)",
    "2  lift(P_r)           # z = x*x + y*y",
    "3  T = delaunay(P_r); H = hull(P_r)",
    "4  for t in T: if RA(t) misses all",
    "5    foreign boxes: final  else: pending",
    "6  for level in 0 .. L-1:",
    "7    ship pending t touching partner",
    "8    B = border set; lift(B); T_B = DT(B)",
    "9    keep crossing or shipped; discard rest",
    "10   H = merge hulls; reclassify kept",
    "11 count by index range, send, order, write",
};

static const struct {
    const char *title;
    const char *const *lines;
    size_t n;
} listings[PDT_CODE_COUNT] = {
    [PDT_CODE_GRAHAM] = {"Graham's scan, Version B", graham_code,
                         sizeof graham_code / sizeof *graham_code},
    [PDT_CODE_SRM] = {"SRM, per rank (strips, restricted areas, merges)", srm_code,
                      sizeof srm_code / sizeof *srm_code},
};

const char *pdt_code_title(int id)
{
    return id >= 0 && id < PDT_CODE_COUNT ? listings[id].title : NULL;
}

size_t pdt_code_count(int id)
{
    return id >= 0 && id < PDT_CODE_COUNT ? listings[id].n : 0;
}

const char *pdt_code_text(int id, size_t i)
{
    return i < pdt_code_count(id) ? listings[id].lines[i] : NULL;
}
