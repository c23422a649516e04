/* pdt — pdt trace check: the checks of the whole run, after every rank's
 * pass (check.c): the local lift-ups, the strips, the messages paired, the
 * merge steps, a bisection's regions, a hull run's hull; and the summary. */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pdt/hull.h"
#include "pdt/tracefile.h"
#include "check_int.h"
#include "hullcert.h"

pdt_status chk_lifts(chk *c, size_t nu)
{
    if (c->lifts_local == 0 && nu > 0)
        return chk_viol(c, 0, 0, NULL, "no lift-up events (the run has %zu distinct points)", nu);
    for (size_t i = 0; i < c->npts; i++)
        if ((c->mark[i] & M_REP) && !(c->mark[i] & M_LIFTED))
            return chk_viol(c, 0, 0, NULL, "pt %zu was never lifted (%" PRIu64 " local lift-ups "
                                           "for %zu distinct points)", i, c->lifts_local, nu);
    return PDT_OK;
}

/* strips: the ranks' local points are consecutive lexicographic blocks
 * (a bisection's regions: chk_regions, once the merges are sorted) */
pdt_status chk_strips(chk *c)
{
    size_t nr = (size_t)pdt_run_nranks(c->run);
    for (size_t r = 0, prev = SIZE_MAX; r < nr; r++) {
        if (!c->nlocal[r]) continue;
        if (prev != SIZE_MAX && c->kmin[r] <= c->kmax[prev])
            return chk_viol(c, 0, 0, NULL, "the local lift-ups of rank %zu (%" PRIu64 " points) are "
                                           "not a lexicographic block after those of rank %zu: the "
                                           "strips overlap", r, c->nlocal[r], prev);
        prev = r;
    }
    return PDT_OK;
}

/* Append to summary (cap bytes in all) what was done on disk or certified. */
static void summary_notes(const chk *c, char *summary, size_t cap)
{
    size_t len = strlen(summary);
    if (c->tstar_strips)
        len += (size_t)snprintf(summary + len, cap - len, " (T* recomputed on %d strips)",
                                c->tstar_strips);
    if (len < cap && c->edge_spills)
        len += (size_t)snprintf(summary + len, cap - len, " (%" PRIu64 " of them replayed on disk: "
                                "over a quarter of the memory budget)", c->edge_spills);
    if (len < cap && c->certify && c->is_tri) {
        char runs[64] = "", dedup[96] = "";
        if (c->cert_runs)
            snprintf(runs, sizeof runs, " on disk in %" PRIu64 " sorted runs", c->cert_runs);
        if (c->dedup_on_disk)
            snprintf(dedup, sizeof dedup, ", the distinct points found by a sort on disk in %"
                     PRIu64 " runs", c->dedup_runs);
        len += (size_t)snprintf(summary + len, cap - len, " (T* certified side by side%s%s: "
                                "recomputing it would not fit the memory budget)", runs, dedup);
    }
    if (len < cap && c->hull_certify && c->is_hull)
        len += (size_t)snprintf(summary + len, cap - len, " (the hull certified point by point: "
                                "recomputing it would not fit the memory budget)");
    if (len < cap && c->spills)
        snprintf(summary + len, cap - len, " (final triangles sorted on disk in %" PRIu64
                 " runs: over the memory budget)", c->spills);
}

void chk_summary(const chk *c, char *summary, size_t cap)
{
    int p = pdt_run_nranks(c->run);
    snprintf(summary, cap,
             "%d rank%s, %" PRIu64 " events: %" PRIu64 " stack instances (%" PRIu64
             " pushes, %" PRIu64 " pops, %" PRIu64 " chain hulls), %" PRIu64 " local + %" PRIu64
             " merge lift-ups, %zu final triangles%s, %zu merge steps, %zu messages, "
             "%" PRIu64 " kernel runs with edges replayed",
             p, p == 1 ? "" : "s", c->events, c->instances, c->pushes, c->pops, c->hulls,
             c->lifts_local, c->lifts_merge, (size_t)c->totfin, c->is_tri ? " = T*" : "", c->nmg,
             c->nmsg / 2, c->edge_scopes);
    summary_notes(c, summary, cap);
}

static int cmp_msg(const void *a, const void *b)
{
    const msg *x = a, *y = b;
    if (x->src != y->src) return x->src < y->src ? -1 : 1;
    if (x->dst != y->dst) return x->dst < y->dst ? -1 : 1;
    if (x->tag != y->tag) return x->tag < y->tag ? -1 : 1;
    if (x->seq_no != y->seq_no) return x->seq_no < y->seq_no ? -1 : 1;
    /* the SEND before the RECV of the same message */
    return (x->ev.kind == PDT_EV_RECV) - (y->ev.kind == PDT_EV_RECV);
}

pdt_status chk_messages(chk *c)
{
    if (c->nmsg) qsort(c->msg, c->nmsg, sizeof *c->msg, cmp_msg);
    for (size_t i = 0; i < c->nmsg;) {
        const msg *m = &c->msg[i];
        const msg *n = i + 1 < c->nmsg ? &c->msg[i + 1] : NULL;
        if (n && !(m->ev.kind == PDT_EV_SEND && n->ev.kind == PDT_EV_RECV && n->src == m->src &&
                   n->dst == m->dst && n->tag == m->tag && n->seq_no == m->seq_no))
            n = NULL;
        if (!n) {
            if (m->ev.kind == PDT_EV_SEND)
                return chk_viol(c, m->rank, m->seq, &m->ev, "no matching recv on rank %" PRIu32,
                            m->dst);
            return chk_viol(c, m->rank, m->seq, &m->ev, "no matching send on rank %" PRIu32, m->src);
        }
        if (n->bytes != m->bytes)
            return chk_viol(c, n->rank, n->seq, &n->ev, "the send (rank %" PRIu32 " event #%" PRIu64
                                                    ") has %" PRIu64 " bytes",
                        m->rank, m->seq, m->bytes);
        i += 2;
    }
    return PDT_OK;
}

static int cmp_merge(const void *a, const void *b)
{
    const merge *x = a, *y = b;
    if (x->level != y->level) return x->level < y->level ? -1 : 1;
    return x->gl < y->gl ? -1 : x->gl > y->gl;
}

pdt_status chk_merges(chk *c)
{
    if (c->nmg) qsort(c->mg, c->nmg, sizeof *c->mg, cmp_merge);
    for (size_t i = 1; i < c->nmg; i++) {
        const merge *a = &c->mg[i - 1], *b = &c->mg[i];
        if (a->level == b->level && b->gl < a->end)
            return chk_viol(c, 0, 0, NULL, "merge steps at level %" PRIu32 " overlap: ranks [%" PRIu32
                                       ", %" PRIu32 ") (rank %" PRIu32 " event #%" PRIu64
                                       ") and [%" PRIu32 ", %" PRIu32 ") (rank %" PRIu32
                                       " event #%" PRIu64 ")",
                        a->level, a->gl, a->end, a->rank, a->seq, b->gl, b->end, b->rank, b->seq);
    }
    int p = pdt_run_nranks(c->run);
    if (c->is_tri && p > 1) {
        const merge *top = c->nmg ? &c->mg[c->nmg - 1] : NULL;
        if (!top || top->gl != 0 || top->end != (uint32_t)p)
            return chk_viol(c, 0, 0, NULL, "no merge step joins all %d ranks (the last merge %s)", p,
                        top ? "covers fewer ranks" : "is missing");
    }
    return PDT_OK;
}

/* A bisection run's regions: at every merge step the local lift-ups of the
 * left group's ranks all come before those of the right group's in one
 * lexicographic order, (x, y) or (y, x) -- one cut separates them. */
pdt_status chk_regions(chk *c)
{
    for (size_t i = 0; i < c->nmg; i++) {
        const merge *g = &c->mg[i];
        uint64_t lx = 0, ly = 0, rx = UINT64_MAX, ry = UINT64_MAX;
        int any_l = 0, any_r = 0;
        for (uint32_t q = g->gl; q < g->end; q++) {
            if (!c->nlocal[q]) continue;
            if (q < g->gr) {
                lx = c->kmax[q] > lx ? c->kmax[q] : lx;
                ly = c->ymax[q] > ly ? c->ymax[q] : ly;
                any_l = 1;
            } else {
                rx = c->kmin[q] < rx ? c->kmin[q] : rx;
                ry = c->ymin[q] < ry ? c->ymin[q] : ry;
                any_r = 1;
            }
        }
        if (any_l && any_r && !(lx < rx) && !(ly < ry))
            return chk_viol(c, g->rank, g->seq, NULL, "the merge at level %" PRIu32 " joins ranks [%"
                            PRIu32 ", %" PRIu32 ") and [%" PRIu32 ", %" PRIu32 ") whose local "
                            "points no cut separates (in x nor in y): the regions overlap",
                            g->level, g->gl, g->gr, g->gr, g->end);
    }
    return PDT_OK;
}

/* ---- the hull of a hull run ------------------------------------------------------ */

/* The final Graham stack compared with the hull recomputed in memory. */
static pdt_status hull_recomputed(chk *c)
{
    const chk_stack *g = &c->graham_final;
    uint32_t *hull = malloc((c->npts ? c->npts : 1) * sizeof *hull);
    size_t nh = 0;
    if (!hull) return chk_nomem(c);
    pdt_status st = pdt_hull_graham(c->pts, c->npts, hull, &nh, NULL);
    if (st != PDT_OK) pdt_err_set(c->err, st, "recomputing the hull failed: %s", pdt_status_str(st));
    if (st == PDT_OK && (nh != g->n || (nh && memcmp(hull, g->v, nh * sizeof *hull) != 0))) {
        size_t k = 0;
        while (k < nh && k < g->n && hull[k] == g->v[k]) k++;
        st = chk_viol(c, 0, 0, NULL, "the final Graham stack (%zu points) is not the hull of the "
                                    "run's points (%zu points); first difference at position %zu",
                      g->n, nh, k);
    }
    free(hull);
    return st;
}

/* (pdt_hull_certify's release) */
static void hull_give_back(void *ctx)
{
    chk *c = ctx;
    pdt_run_release_points(c->run);
    chk_stacks_give_back(&c->graham_final, 1);
}

/* The final Graham stack certified in one pass over the points. */
static pdt_status hull_certified(chk *c)
{
    const chk_stack *g = &c->graham_final;
    pdt_err why = {0};
    if (pdt_hull_certify(c->pts, c->npts, g->v, g->n, hull_give_back, c, &why) == PDT_OK)
        return PDT_OK;
    return chk_viol(c, 0, 0, NULL, "the final Graham stack (%zu points) is not the hull of the "
                                  "run's points: %s", g->n, why.msg);
}

/* A hull run: every point sorted, each deleted or pushed, and the final
 * Graham stack is the hull of the run's points, recomputed while that fits
 * the budget (HULL_BYTES_PER_POINT), else certified (hullcert.h). */
pdt_status chk_graham_hull(chk *c)
{
    pdt_status st = PDT_OK;
    for (size_t i = 0; st == PDT_OK && i < c->npts; i++) {
        chk_tick(c);
        if (!(c->mark[i] & M_SORTED))
            st = chk_viol(c, 0, 0, NULL, "pt %zu never appears in the angular order", i);
        else if (!(c->mark[i] & (M_DELETED | M_PUSHED)))
            st = chk_viol(c, 0, 0, NULL, "pt %zu was neither deleted nor pushed", i);
        else if ((c->mark[i] & M_DELETED) && (c->mark[i] & M_PUSHED))
            st = chk_viol(c, 0, 0, NULL, "pt %zu was deleted and also pushed", i);
    }
    if (st != PDT_OK) return st;
    return c->hull_certify ? hull_certified(c) : hull_recomputed(c);
}
