/* The cluster features of the viewer: the timeline's axis is the run's
 * clock (not the order of the events), and following the story zooms the
 * picture and the timeline in on a merge step and back out after it. */
#include "../harness.h"

#include <math.h>
#include <string.h>

#include "pdt/view/ranktree.h"
#include "pdt/view/render.h"
#include "pdt/view/replay.h"
#include "pdt/view/viewsynth.h"

#define W 1024
#define H 768

/* 100 lifts on 10 ranks (a cluster run: the timeline in time): the first
 * 90 within 89 µs, the last 10 a whole millisecond later.  In time, the
 * right half of the axis holds only the last ten; in event order it would
 * hold fifty.  A run of one rank keeps the order of its events. */
TEST(timeline_axis_is_time)
{
    enum { N = 100 };
    pdt_point pts[N];
    pdt_rec recs[N];
    memset(recs, 0, sizeof recs);
    for (int i = 0; i < N; i++) {
        pts[i] = (pdt_point){i * 10, (i * 37) % 100};
        recs[i].ev.kind = PDT_EV_LIFT;
        recs[i].ev.a = (uint32_t)i;
        recs[i].ev.t = i < 90 ? 1000u * (uint64_t)i : 1000000u + 1000u * (uint64_t)i;
        recs[i].rank = (uint32_t)(i % 10);
        recs[i].seq = (uint32_t)(i / 10);
    }
    pdt_replay *r = NULL;
    pdt_err err = {0};
    CHECK(pdt_replay_new(pts, N, recs, N, 10, &r, &err) == PDT_OK);
    if (!r) return;
    pdt_ranktree *t = pdt_ranktree_new(r);
    CHECK(t != NULL);
    if (!t) {
        pdt_replay_free(r);
        return;
    }
    double span = 0;
    CHECK(pdt_ranktree_timed(t, &span) && fabs(span - 1099000) < 1e-6);
    /* events 0 and 89 are 89 µs apart: 89/1099 of the axis */
    CHECK_MSG(fabs(pdt_ranktree_at(t, 89) - pdt_ranktree_at(t, 0) - 89.0 / 1099) < 1e-9, "u(89) = %g",
              pdt_ranktree_at(t, 89));
    CHECK(pdt_ranktree_event_at(t, 0.5) == 90);
    /* a click at 60 % of the timeline's width seeks past event 89 */
    pdt_view v;
    pdt_view_defaults(&v);
    v.panels |= PDT_PANEL_TIMELINE;
    v.tree = t;
    pdt_layout L;
    pdt_render_layout_view(W, H, 10, &v, &L);
    CHECK(L.timeline.w > 0);
    size_t k = pdt_render_timeline_at(r, &v, W, H, L.timeline.x + 0.6 * L.timeline.w,
                                      L.timeline.y + 0.5 * L.timeline.h);
    CHECK_MSG(k >= 90 && k <= N, "clicked at 60 %%: cursor %zu", k);
    pdt_ranktree_free(t);
    pdt_replay_free(r);
    /* the same events on one rank: event order */
    for (int i = 0; i < N; i++) recs[i].rank = 0, recs[i].seq = (uint32_t)i;
    r = NULL;
    CHECK(pdt_replay_new(pts, N, recs, N, 1, &r, &err) == PDT_OK);
    t = r ? pdt_ranktree_new(r) : NULL;
    CHECK(t && !pdt_ranktree_timed(t, NULL) && fabs(pdt_ranktree_at(t, 50) - 0.5) < 1e-9);
    pdt_ranktree_free(t);
    pdt_replay_free(r);
}

/* The first event at or after cursor from of kind, or (size_t)-1. */
static size_t find_kind(const pdt_replay *r, size_t from, int kind)
{
    for (size_t i = from; i < pdt_replay_count(r); i++)
        if (pdt_replay_rec(r, i)->ev.kind == kind) return i;
    return (size_t)-1;
}

/* A synthetic 8-rank run of 9600 points: a lift inside a merge step zooms
 * the picture in until the points are apart on screen and the timeline
 * onto the merge step; the next top-level phase outside the merges
 * (after the last MERGE_END) backs both out. */
TEST(follow_zooms_into_merge_and_out)
{
    pdt_synth syn;
    pdt_err err = {0};
    CHECK(pdt_synth_srm(160, 60, 8, 2, &syn, &err) == PDT_OK);
    pdt_replay *r = NULL;
    CHECK(pdt_replay_new(syn.pts, syn.n, syn.recs, syn.m, 8, &r, &err) == PDT_OK);
    pdt_rstate *s = r ? pdt_rstate_new(r) : NULL;
    pdt_ranktree *t = r ? pdt_ranktree_new(r) : NULL;
    CHECK(s && t);
    if (!s || !t) goto out;
    pdt_view v;
    pdt_view_defaults(&v);
    v.panels |= PDT_PANEL_TIMELINE;
    v.tree = t;
    v.follow = 1;
    size_t mb = find_kind(r, 0, PDT_EV_MERGE_BEGIN), lift = find_kind(r, mb, PDT_EV_LIFT);
    CHECK(mb != (size_t)-1 && lift != (size_t)-1);
    if (lift == (size_t)-1) goto out;
    pdt_replay_seek(r, s, lift + 1);
    CHECK(pdt_view_follow(r, s, &v, W, H));
    CHECK_MSG(v.zoom > 2, "zoom %g after a lift in a merge", v.zoom);
    CHECK_MSG(v.tl_t1 - v.tl_t0 < 0.5, "timeline window %g .. %g", v.tl_t0, v.tl_t1);
    /* the lifted point is in the picture */
    size_t np;
    const pdt_point *P = pdt_replay_points(r, &np);
    pdt_point p = P[pdt_replay_rec(r, lift)->ev.a];
    double sx, sy;
    pdt_view_to_screen(r, &v, W, H, p.x, p.y, &sx, &sy);
    pdt_layout L;
    pdt_render_layout_view(W, H, 8, &v, &L);
    CHECK(sx >= L.geo.x && sx <= L.geo.x + L.geo.w && sy >= L.geo.y && sy <= L.geo.y + L.geo.h);
    /* after the last merge step: a top-level phase begins, all is shown again */
    size_t last = mb, k;
    while ((k = find_kind(r, last + 1, PDT_EV_MERGE_END)) != (size_t)-1) last = k;
    size_t nph;
    const pdt_rphase *Ph = pdt_replay_phases(r, &nph);
    size_t top = (size_t)-1;
    for (size_t i = 0; i < nph && top == (size_t)-1; i++)
        if (Ph[i].begin_ev > last && Ph[i].phase != PDT_PH_MERGE && Ph[i].parent >= 0 &&
            Ph[Ph[i].parent].phase == PDT_PH_RUN)
            top = Ph[i].begin_ev;
    CHECK(top != (size_t)-1);
    if (top == (size_t)-1) goto out;
    pdt_replay_seek(r, s, top + 1);
    pdt_view_follow(r, s, &v, W, H);
    CHECK_MSG(v.zoom == 1 && !v.centred, "zoom %g after a top-level phase", v.zoom);
    CHECK_MSG(v.tl_t0 == 0 && v.tl_t1 == 1, "timeline window %g .. %g", v.tl_t0, v.tl_t1);
out:
    pdt_ranktree_free(t);
    pdt_rstate_free(s);
    pdt_replay_free(r);
    pdt_synth_free(&syn);
}

/* The times the replay's tables hold (phases, merge steps, messages: the
 * clock of the timeline and the merge tree reads them, and a kept index
 * keeps them, so that its opening decodes no event for them) are their
 * events' times. */
TEST(table_times_are_events_times)
{
    pdt_synth syn;
    pdt_err err = {0};
    CHECK(pdt_synth_srm(40, 12, 16, 2, &syn, &err) == PDT_OK);
    pdt_replay *r = NULL;
    CHECK(pdt_replay_new(syn.pts, syn.n, syn.recs, syn.m, 16, &r, &err) == PDT_OK);
    if (!r) {
        pdt_synth_free(&syn);
        return;
    }
    size_t np, nm, ng, bad = 0, ended = 0, both = 0;
    const pdt_rphase *P = pdt_replay_phases(r, &np);
    const pdt_rmerge *M = pdt_replay_merges(r, &nm);
    const pdt_rmsg *G = pdt_replay_msgs(r, &ng);
    CHECK(np > 16 && nm >= 15 && ng > 0);
    for (size_t i = 0; i < np; i++) {
        bad += P[i].begin_t != pdt_replay_rec(r, P[i].begin_ev)->ev.t;
        if (P[i].end_ev != UINT32_MAX) {
            ended++;
            bad += P[i].end_t != pdt_replay_rec(r, P[i].end_ev)->ev.t;
        }
    }
    for (size_t i = 0; i < nm; i++) {
        bad += M[i].begin_t != pdt_replay_rec(r, M[i].begin_ev)->ev.t;
        bad += M[i].end_ev == UINT32_MAX ? M[i].end_t != 0
                                         : M[i].end_t != pdt_replay_rec(r, M[i].end_ev)->ev.t;
    }
    for (size_t i = 0; i < ng; i++) {
        if (G[i].send_ev != UINT32_MAX && G[i].recv_ev != UINT32_MAX) both++;
        bad += G[i].send_ev == UINT32_MAX ? G[i].send_t != 0
                                          : G[i].send_t != pdt_replay_rec(r, G[i].send_ev)->ev.t;
        bad += G[i].recv_ev == UINT32_MAX ? G[i].recv_t != 0
                                          : G[i].recv_t != pdt_replay_rec(r, G[i].recv_ev)->ev.t;
    }
    CHECK_MSG(bad == 0, "%zu times differ from their events'", bad);
    CHECK(ended > 0 && both > 0);
    pdt_replay_free(r);
    pdt_synth_free(&syn);
}

int main(void)
{
    RUN(timeline_axis_is_time);
    RUN(table_times_are_events_times);
    RUN(follow_zooms_into_merge_and_out);
    return test_summary();
}
