/* pdt — the viewer's words: the event line and the pseudo-code listings
 * (see pdt/describe.h). */
#include "pdt/describe.h"

#include <stdio.h>

#define NONE32 UINT32_MAX

/* ---- the event line ------------------------------------------------------------ */

static const char *pt_str(const pdt_replay *r, uint32_t p, char *b, size_t cap)
{
    size_t n;
    const pdt_point *P = pdt_replay_points(r, &n);
    if (p < n) snprintf(b, cap, "%u (%d,%d)", p, P[p].x, P[p].y);
    else snprintf(b, cap, "%u", p);
    return b;
}

/* A point on Graham's stack: "p7 (point 12)" once sorted, else "12". */
static const char *gpt(const pdt_replay *r, uint32_t p, char *b, size_t cap)
{
    int64_t pos = pdt_replay_sort_pos(r, p);
    if (pos >= 0) snprintf(b, cap, "p%lld (point %u)", (long long)pos, p);
    else snprintf(b, cap, "%u", p);
    return b;
}

void pdt_replay_describe(const pdt_replay *r, size_t k, char *buf, size_t cap)
{
    if (!cap) return;
    size_t m = pdt_replay_count(r), npts;
    const pdt_point *P = pdt_replay_points(r, &npts);
    if (k == 0 || k > m) {
        snprintf(buf, cap, "start — %zu events, %d ranks; press Space or → to begin", m,
                 pdt_replay_nranks(r));
        return;
    }
    const pdt_rec *rec = pdt_replay_rec(r, k - 1);
    const pdt_event *e = &rec->ev;
    char p1[64], p2[64];
    int n = snprintf(buf, cap, "rank %u: ", rec->rank);
    if (n < 0 || (size_t)n >= cap) return;
    char *o = buf + n;
    size_t c = cap - (size_t)n;
    const char *stk = pdt_stack_name(e->sub) ? pdt_stack_name(e->sub) : "?";
    const char *ph = pdt_phase_name(e->sub) ? pdt_phase_name(e->sub) : "?";
    switch (e->kind) {
    case PDT_EV_PHASE_BEGIN:
        if (e->sub == PDT_PH_MERGE) snprintf(o, c, "begin phase merge, level %u", e->a);
        else snprintf(o, c, "begin phase %s", ph);
        break;
    case PDT_EV_PHASE_END: snprintf(o, c, "end of phase %s", ph); break;
    case PDT_EV_PUSH:
        if (e->sub == PDT_STACK_GRAHAM)
            snprintf(o, c, "push %s on the Graham stack (depth %u)", gpt(r, e->a, p1, sizeof p1), e->b);
        else
            snprintf(o, c, "push %s on the %s stack (depth %u)", pt_str(r, e->a, p1, sizeof p1), stk, e->b);
        break;
    case PDT_EV_POP:
        if (e->sub == PDT_STACK_GRAHAM && e->c < npts && e->a < npts)
            snprintf(o, c, "pop %s — no left turn at (%d,%d) towards %s", gpt(r, e->a, p1, sizeof p1),
                     P[e->a].x, P[e->a].y, gpt(r, e->c, p2, sizeof p2));
        else if (e->c != NONE32 && e->c < npts)
            snprintf(o, c, "pop %u — %s at (%d,%d) when adding %u", e->a,
                     e->sub == PDT_STACK_GRAHAM ? "no left turn" : "right turn",
                     e->a < npts ? P[e->a].x : 0, e->a < npts ? P[e->a].y : 0, e->c);
        else
            snprintf(o, c, "pop %s from the %s stack", pt_str(r, e->a, p1, sizeof p1), stk);
        break;
    case PDT_EV_LIFT:
        snprintf(o, c, "lift %s to z = %lld", pt_str(r, e->a, p1, sizeof p1), (long long)e->v);
        break;
    case PDT_EV_SORT:
        snprintf(o, c, "%s is number %u in the angular order", pt_str(r, e->a, p1, sizeof p1), e->b);
        break;
    case PDT_EV_DELETE:
        snprintf(o, c, "delete %s — %s %u", pt_str(r, e->a, p1, sizeof p1),
                 e->sub == PDT_DEL_COINCIDENT ? "a copy of" : "same angle as, and closer than,",
                 e->b);
        break;
    case PDT_EV_TRI_NEW:
        snprintf(o, c, "candidate triangle %u %u %u from the %s kernel", e->a, e->b, e->c,
                 e->sub ? "border" : "local");
        break;
    case PDT_EV_TRI_FINAL:
        snprintf(o, c, "triangle %u %u %u is final — its circle misses every foreign box", e->a,
                 e->b, e->c);
        break;
    case PDT_EV_RA_DEFER:
        snprintf(o, c, "defer %u %u %u — its circle touches the box of rank %lld", e->a, e->b, e->c,
                 (long long)e->v);
        break;
    case PDT_EV_SHIP:
        snprintf(o, c, "ship %u %u %u to rank %lld", e->a, e->b, e->c, (long long)e->v);
        break;
    case PDT_EV_DISCARD:
        if (e->v >= 0 && (uint64_t)e->v < npts)
            snprintf(o, c, "discard %u %u %u — not Delaunay: %s is inside its circle", e->a, e->b,
                     e->c, pt_str(r, (uint32_t)e->v, p2, sizeof p2));
        else
            snprintf(o, c, "discard %u %u %u — not Delaunay", e->a, e->b, e->c);
        break;
    case PDT_EV_MERGE_BEGIN:
        snprintf(o, c, "merge level %u: ranks %u–%u with %u–%u at rank %lld", e->sub, e->a,
                 e->b ? e->b - 1 : 0, e->b, e->c ? e->c - 1 : 0, (long long)e->v);
        break;
    case PDT_EV_MERGE_END:
        snprintf(o, c, "merge level %u done: %u shipped, border %u, %u kept, %lld discarded",
                 e->sub, e->a, e->b, e->c, (long long)e->v);
        break;
    case PDT_EV_SEND:
        snprintf(o, c, "send %u bytes to rank %u (tag %u)", e->b, e->a, e->sub);
        break;
    case PDT_EV_RECV:
        snprintf(o, c, "receive %u bytes from rank %u (tag %u)", e->b, e->a, e->sub);
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

/* ---- the pseudo-code listings -------------------------------------------------- */

static const char *const graham_code[] = {
    "1  find the rightmost lowest point p0",
    "2  sort the others by angle about p0",
    "3    tie: delete the closer (or copy)",
    "4  stack S = (p1, p0); t indexes the top",
    "5  i = 2",
    "6  while i < n:",
    "7    if p_i strictly left of (p_t-1, p_t):",
    "8      push p_i; i = i + 1",
    "9    else: pop S",
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
    "11 gather, sort, write",
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
