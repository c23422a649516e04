/* Replay model: seek equals stepping, stepping back undoes stepping forward,
 * on synthetic runs with several ranks (and on hand-made event arrays). */
#include "../harness.h"

#include <stdlib.h>
#include <string.h>

#include "pdt/view/describe.h"
#include "pdt/view/query.h"
#include "pdt/view/replay.h"
#include "pdt/view/viewsynth.h"
#include "../../src/view/model/replay_int.h"

static pdt_rec rec(int rank, int kind, int sub, uint32_t a, uint32_t b, uint32_t c, int64_t v)
{
    pdt_rec r;
    memset(&r, 0, sizeof r);
    r.rank = (uint32_t)rank;
    r.ev.kind = (uint8_t)kind;
    r.ev.sub = (uint8_t)sub;
    r.ev.a = a;
    r.ev.b = b;
    r.ev.c = c;
    r.ev.v = v;
    return r;
}

/* seek(k) == step 0 -> k for every k; step back from the end == seek too. */
static int check_routes(const pdt_replay *r, size_t stride)
{
    size_t m = pdt_replay_count(r);
    pdt_rstate *fw = pdt_rstate_new(r), *sk = pdt_rstate_new(r), *bw = pdt_rstate_new(r);
    int bad = 0;
    if (!fw || !sk || !bw) return 1;
    for (size_t k = 0; k <= m; k++) {
        if (k % stride == 0 || k == m) {
            pdt_replay_seek(r, sk, k);
            if (!pdt_rstate_equal(r, fw, sk)) {
                if (bad++ < 3) printf("#   forward state differs from seek at k=%zu\n", k);
            }
        }
        if (k < m && !pdt_replay_step(r, fw, 1)) bad++;
    }
    pdt_replay_seek(r, bw, m);
    for (size_t k = m + 1; k-- > 0;) {
        if (k % stride == 0) {
            pdt_replay_seek(r, sk, k);
            if (!pdt_rstate_equal(r, bw, sk)) {
                if (bad++ < 3) printf("#   backward state differs from seek at k=%zu\n", k);
            }
        }
        if (k > 0 && !pdt_replay_step(r, bw, -1)) bad++;
    }
    /* a step forward then back is the identity, from scattered positions */
    for (size_t k = 0; k < m; k += 1 + m / 97) {
        pdt_replay_seek(r, sk, k);
        pdt_replay_seek(r, fw, k);
        pdt_replay_step(r, fw, 1);
        pdt_replay_step(r, fw, -1);
        if (!pdt_rstate_equal(r, fw, sk)) bad++;
    }
    pdt_rstate_free(fw);
    pdt_rstate_free(sk);
    pdt_rstate_free(bw);
    return bad;
}

TEST(seek_equals_step_srm_4_ranks)
{
    pdt_synth s;
    pdt_err err = {0};
    CHECK(pdt_synth_srm(12, 7, 4, 2, &s, &err) == PDT_OK);
    pdt_replay *r = NULL;
    CHECK(pdt_replay_new(s.pts, s.n, s.recs, s.m, s.nranks, &r, &err) == PDT_OK);
    if (!r) return;
    CHECK(pdt_replay_skipped(r) == 0);
    CHECK_MSG(check_routes(r, 1) == 0, "m=%zu", s.m);
    pdt_replay_free(r);
    pdt_synth_free(&s);
}

TEST(seek_equals_step_srm_odd_ranks)
{
    for (int p = 1; p <= 7; p += 2) {
        pdt_synth s;
        pdt_err err = {0};
        CHECK(pdt_synth_srm(2 * p + 3, 5, p, 2, &s, &err) == PDT_OK);
        pdt_replay *r = NULL;
        CHECK(pdt_replay_new(s.pts, s.n, s.recs, s.m, 0, &r, &err) == PDT_OK);
        if (!r) return;
        CHECK_MSG(pdt_replay_nranks(r) == p, "nranks %d", pdt_replay_nranks(r));
        CHECK_MSG(check_routes(r, 3) == 0, "p=%d", p);
        pdt_replay_free(r);
        pdt_synth_free(&s);
    }
}

TEST(seek_equals_step_graham)
{
    pdt_synth s;
    pdt_err err = {0};
    CHECK(pdt_synth_graham(60, 7, &s, &err) == PDT_OK);
    pdt_replay *r = NULL;
    CHECK(pdt_replay_new(s.pts, s.n, s.recs, s.m, 1, &r, &err) == PDT_OK);
    if (!r) return;
    CHECK(check_routes(r, 1) == 0);
    pdt_replay_free(r);
    pdt_synth_free(&s);
}

/* The kept index's checkpoints hold the triangles born before their cursor
 * only (triangles are numbered by their first event): at every cursor, the
 * born triangles are exactly those whose first event is before it, and a
 * state written that short and read back over another state is the same
 * state. */
TEST(checkpoint_blob_born_triangles)
{
    pdt_synth s;
    pdt_err err = {0};
    CHECK(pdt_synth_srm(12, 7, 4, 2, &s, &err) == PDT_OK);
    pdt_replay *r = NULL;
    CHECK(pdt_replay_new(s.pts, s.n, s.recs, s.m, s.nranks, &r, &err) == PDT_OK);
    if (!r) return;
    size_t m = pdt_replay_count(r), ntri;
    const pdt_rtri *tris = pdt_replay_tris(r, &ntri);
    const pdt_rtri_hist *hist = pdt_replay_tri_hist(r);
    pdt_rstate *a = pdt_rstate_new(r), *b = pdt_rstate_new(r);
    uint8_t *blob = malloc(pdt_rstate_blob_bytes(r, ntri));
    CHECK(a && b && blob && ntri > 10);
    if (!a || !b || !blob) return;
    int bad = 0;
    size_t prev = 0;
    for (size_t k = 0; k <= m; k += 1 + m / 37) {
        pdt_replay_seek(r, a, k);
        size_t born = pdt_rstate_born(r, a), want = 0;
        for (size_t t = 0; t < ntri; t++) want += hist[tris[t].h0].ev < k;
        if (born != want || born < prev) {
            if (bad++ < 3) printf("#   k=%zu: born %zu, want %zu (before: %zu)\n", k, born, want, prev);
        }
        prev = born;
        pdt_rstate_to_blob(r, a, born, blob);
        pdt_replay_seek(r, b, m - k / 2);  /* anything else */
        pdt_rstate_from_blob(r, b, blob, born, k);
        if (!pdt_rstate_equal(r, a, b) && bad++ < 3) printf("#   k=%zu: restored state differs\n", k);
    }
    CHECK_MSG(bad == 0, "%d cursors wrong", bad);
    CHECK(pdt_rstate_blob_bytes(r, 0) < pdt_rstate_blob_bytes(r, ntri));
    pdt_replay_seek(r, a, 0);
    CHECK(pdt_rstate_born(r, a) == 0);
    free(blob);
    pdt_rstate_free(a);
    pdt_rstate_free(b);
    pdt_replay_free(r);
    pdt_synth_free(&s);
}

/* The end state of an SRM run: every triangle final or discarded, nothing in
 * flight, no open merge. */
TEST(srm_end_state)
{
    pdt_synth s;
    pdt_err err = {0};
    CHECK(pdt_synth_srm(16, 6, 4, 1, &s, &err) == PDT_OK);
    pdt_replay *r = NULL;
    CHECK(pdt_replay_new(s.pts, s.n, s.recs, s.m, 4, &r, &err) == PDT_OK);
    if (!r) return;
    pdt_rstate *st = pdt_rstate_new(r);
    pdt_replay_seek(r, st, pdt_replay_count(r));
    size_t nt, nfinal = 0, ndisc = 0, nother = 0;
    pdt_replay_tris(r, &nt);
    for (size_t t = 0; t < nt; t++) {
        pdt_tri_status ts = pdt_rstate_tri_status(r, st, t);
        if (ts == PDT_TS_FINAL) nfinal++;
        else if (ts == PDT_TS_DISCARDED) ndisc++;
        else nother++;
    }
    /* a 16 x 6 grid has 2 * 15 * 5 = 150 triangles in any triangulation */
    CHECK_MSG(nfinal == 150, "final %zu", nfinal);
    CHECK_MSG(ndisc > 0, "discarded %zu", ndisc);
    CHECK_MSG(nother == 0, "other %zu", nother);
    size_t nm;
    const pdt_rmsg *msg = pdt_replay_msgs(r, &nm);
    CHECK(nm > 0);
    for (size_t g = 0; g < nm; g++) {
        CHECK(st->mflight[g] == 0);
        CHECK(msg[g].send_ev < msg[g].recv_ev && msg[g].recv_ev != UINT32_MAX);
    }
    size_t ng;
    const pdt_rmerge *mg = pdt_replay_merges(r, &ng);
    CHECK_MSG(ng == 3, "merges %zu", ng);  /* 4 ranks: two at level 0, one at level 1 */
    for (size_t i = 0; i < ng; i++) CHECK(mg[i].end_ev != UINT32_MAX && mg[i].discarded > 0);
    for (int q = 0; q < 4; q++) {
        CHECK(pdt_rstate_slot(r, st, q, PDT_SLOT_MERGE) == -1);
        CHECK(pdt_rstate_slot(r, st, q, PDT_SLOT_PHASE) == -1);
        pdt_point lo, hi;
        CHECK(pdt_replay_box(r, q, &lo, &hi));
        CHECK_MSG(lo.x == q * 40 && hi.x == q * 40 + 30, "rank %d box x %d..%d", q, lo.x, hi.x);
    }
    /* PgDn: lift, kernel, hull, classify, merge 0, merge 1, output, end */
    static const int want[] = {PDT_PH_LIFT, PDT_PH_KERNEL, PDT_PH_HULL, PDT_PH_CLASSIFY,
                               PDT_PH_MERGE, PDT_PH_MERGE, PDT_PH_OUTPUT};
    size_t k = 0;
    for (int i = 0; i < 7; i++) {
        size_t k2 = pdt_replay_find_phase(r, k, 1);
        CHECK(k2 > k);
        const pdt_rec *e = pdt_replay_rec(r, k2 - 1);
        CHECK_MSG(e->ev.kind == PDT_EV_PHASE_BEGIN && e->ev.sub == want[i], "step %d: kind %d phase %d", i,
                  e->ev.kind, e->ev.sub);
        if (i == 5) CHECK(e->ev.a == 1);
        CHECK(pdt_replay_find_phase(r, k2, -1) == (i ? k : 0));
        k = k2;
    }
    CHECK(pdt_replay_find_phase(r, k, 1) == pdt_replay_count(r));
    pdt_rstate_free(st);
    pdt_replay_free(r);
    pdt_synth_free(&s);
}

/* Hand-made events: stacks, phases, messages and triangle statuses. */
/* Two ranks out of step: rank 0 runs ahead into classify while rank 1 has
 * not lifted.  A stop is where the last rank begins the phase; PgDn goes
 * through them in order; a rank's box is drawn from its partition on. */
TEST(phase_stops_wait_for_every_rank)
{
    pdt_point pts[2] = {{0, 0}, {10, 0}};
    pdt_rec ev[] = {
        rec(0, PDT_EV_PHASE_BEGIN, PDT_PH_PARTITION, 0, 0, 0, 0), /* 0 */
        rec(0, PDT_EV_PHASE_END, PDT_PH_PARTITION, 0, 0, 0, 0),   /* 1 */
        rec(0, PDT_EV_PHASE_BEGIN, PDT_PH_LIFT, 0, 0, 0, 0),      /* 2 */
        rec(0, PDT_EV_LIFT, 0, 0, 0, 0, 0),                       /* 3 */
        rec(0, PDT_EV_PHASE_END, PDT_PH_LIFT, 0, 0, 0, 0),        /* 4 */
        rec(0, PDT_EV_PHASE_BEGIN, PDT_PH_CLASSIFY, 0, 0, 0, 0),  /* 5 */
        rec(1, PDT_EV_PHASE_BEGIN, PDT_PH_PARTITION, 0, 0, 0, 0), /* 6 */
        rec(1, PDT_EV_PHASE_END, PDT_PH_PARTITION, 0, 0, 0, 0),   /* 7 */
        rec(1, PDT_EV_PHASE_BEGIN, PDT_PH_LIFT, 0, 0, 0, 0),      /* 8 */
        rec(1, PDT_EV_LIFT, 0, 1, 0, 0, 0),                       /* 9 */
        rec(1, PDT_EV_PHASE_END, PDT_PH_LIFT, 0, 0, 0, 0),        /* 10 */
        rec(1, PDT_EV_PHASE_BEGIN, PDT_PH_CLASSIFY, 0, 0, 0, 0),  /* 11 */
        rec(0, PDT_EV_PHASE_END, PDT_PH_CLASSIFY, 0, 0, 0, 0),    /* 12 */
        rec(1, PDT_EV_PHASE_END, PDT_PH_CLASSIFY, 0, 0, 0, 0),    /* 13 */
    };
    pdt_replay *r = NULL;
    pdt_err err = {0};
    CHECK(pdt_replay_new(pts, 2, ev, sizeof ev / sizeof *ev, 2, &r, &err) == PDT_OK);
    if (!r) return;
    CHECK(pdt_replay_phase_stop_named(r, "classify") == 12);
    CHECK(pdt_replay_phase_stop_named(r, "lift") == 9);
    CHECK(pdt_replay_phase_stop_named(r, "merge") == (size_t)-1);
    size_t k = 0, want[] = {7, 9, 12, 14};
    for (int i = 0; i < 4; i++) {
        k = pdt_replay_find_phase_stop(r, k, 1);
        CHECK_MSG(k == want[i], "PgDn %d: %zu, want %zu", i + 1, k, want[i]);
    }
    CHECK(pdt_replay_find_phase_stop(r, 12, -1) == 9);
    CHECK(pdt_replay_find_phase_stop(r, 7, -1) == 0);
    CHECK(pdt_replay_box_from(r, 0) == 1 && pdt_replay_box_from(r, 1) == 7);
    pdt_replay_free(r);
}

TEST(hand_made_story)
{
    pdt_point pts[5] = {{0, 0}, {10, 0}, {5, 8}, {5, 3}, {0, 10}};
    pdt_rec ev[] = {
        rec(0, PDT_EV_PHASE_BEGIN, PDT_PH_HULL, 0, 0, 0, 0),     /* 0 */
        rec(0, PDT_EV_PUSH, PDT_STACK_LOWER, 0, 1, 0, 0),        /* 1 */
        rec(0, PDT_EV_PUSH, PDT_STACK_LOWER, 3, 2, 0, 0),        /* 2 */
        rec(0, PDT_EV_POP, PDT_STACK_LOWER, 3, 1, 1, 0),         /* 3 */
        rec(0, PDT_EV_PUSH, PDT_STACK_LOWER, 1, 2, 0, 0),        /* 4 */
        rec(1, PDT_EV_SEND, 1, 0, 64, 0, 0),                     /* 5 */
        rec(0, PDT_EV_TRI_NEW, 0, 0, 1, 2, 0),                   /* 6 */
        rec(0, PDT_EV_RECV, 1, 1, 64, 0, 0),                     /* 7 */
        rec(0, PDT_EV_RA_DEFER, 0, 1, 2, 0, 1),                  /* 8: same triangle, rotated */
        rec(0, PDT_EV_DISCARD, 0, 2, 0, 1, 3),                   /* 9 */
        rec(0, PDT_EV_PHASE_END, PDT_PH_HULL, 0, 0, 0, 0),       /* 10 */
        rec(0, PDT_EV_PUSH, PDT_STACK_LOWER, 4, 1, 0, 0),        /* 11: a new stack */
    };
    size_t m = sizeof ev / sizeof *ev;
    pdt_replay *r = NULL;
    pdt_err err = {0};
    CHECK(pdt_replay_new(pts, 5, ev, m, 2, &r, &err) == PDT_OK);
    if (!r) return;
    pdt_rstate *s = pdt_rstate_new(r);
    size_t nt, nn;
    pdt_replay_tris(r, &nt);
    const pdt_rnode *nodes = pdt_replay_nodes(r, &nn);
    CHECK_MSG(nt == 1, "one triangle, %zu", nt);
    pdt_replay_seek(r, s, 3);
    int32_t top = pdt_rstate_slot(r, s, 0, PDT_SLOT_STACK0 + PDT_STACK_LOWER);
    CHECK(top >= 0 && nodes[top].pt == 3 && nodes[top].depth == 2);
    pdt_replay_seek(r, s, 4);
    top = pdt_rstate_slot(r, s, 0, PDT_SLOT_STACK0 + PDT_STACK_LOWER);
    CHECK(top >= 0 && nodes[top].pt == 0 && nodes[top].depth == 1);
    pdt_replay_seek(r, s, 5);
    top = pdt_rstate_slot(r, s, 0, PDT_SLOT_STACK0 + PDT_STACK_LOWER);
    CHECK(top >= 0 && nodes[top].pt == 1 && nodes[nodes[top].parent].pt == 0);
    CHECK(s->mflight[0] == 0);
    pdt_replay_step(r, s, 1);
    CHECK(s->mflight[0] == 1);
    CHECK(pdt_rstate_tri_status(r, s, 0) == PDT_TS_NONE);
    pdt_replay_step(r, s, 1);
    CHECK(pdt_rstate_tri_status(r, s, 0) == PDT_TS_CANDIDATE);
    pdt_replay_step(r, s, 1);
    CHECK(s->mflight[0] == 0);
    pdt_replay_step(r, s, 1);
    CHECK(pdt_rstate_tri_status(r, s, 0) == PDT_TS_DEFERRED);
    pdt_replay_step(r, s, 1);
    CHECK(pdt_rstate_tri_status(r, s, 0) == PDT_TS_DISCARDED);
    pdt_replay_step(r, s, -1);
    CHECK(pdt_rstate_tri_status(r, s, 0) == PDT_TS_DEFERRED);
    CHECK(pdt_rstate_slot(r, s, 0, PDT_SLOT_PHASE) == 0);
    pdt_replay_seek(r, s, m);
    CHECK(pdt_rstate_slot(r, s, 0, PDT_SLOT_PHASE) == -1);
    top = pdt_rstate_slot(r, s, 0, PDT_SLOT_STACK0 + PDT_STACK_LOWER);
    CHECK(top >= 0 && nodes[top].pt == 4 && nodes[top].parent == -1);
    CHECK(check_routes(r, 1) == 0);
    char line[256];
    pdt_replay_describe(r, 4, line, sizeof line);
    CHECK_MSG(strstr(line, "rank 0: pop point 3 (5,3)") && strstr(line, "= -30: right turn"), "%s", line);
    pdt_replay_describe(r, 10, line, sizeof line);
    CHECK_MSG(strstr(line, "discard") && strstr(line, "point 3 (5,3) is inside"), "%s", line);
    {   /* the discard names the triangle in the one corner order, as the defer did */
        uint32_t v[3];
        char want[32];
        pdt_replay_tri_order(r, (const uint32_t[3]){2, 0, 1}, v);
        snprintf(want, sizeof want, "discard %u %u %u —", v[0], v[1], v[2]);
        CHECK_MSG(v[0] == 0 && strstr(line, want), "%s", line);
        pdt_replay_describe(r, 9, line, sizeof line);
        snprintf(want, sizeof want, "defer %u %u %u —", v[0], v[1], v[2]);
        CHECK_MSG(strstr(line, want), "%s", line);
    }
    /* searching */
    CHECK(pdt_replay_find(r, 0, 1, PDT_EVC_STACK, NULL) == 2);
    CHECK(pdt_replay_find(r, 5, 1, PDT_EVC_REJECT, NULL) == 9);
    CHECK(pdt_replay_find(r, 9, -1, PDT_EVC_STACK, NULL) == 5);
    CHECK(pdt_replay_find_phase_name(r, "hull") == 1);
    CHECK(pdt_replay_find_phase_name(r, "merge") == (size_t)-1);
    pdt_rstate_free(s);
    pdt_replay_free(r);
}

/* Malformed events are skipped, not fatal. */
TEST(malformed_events_skipped)
{
    pdt_point pts[2] = {{0, 0}, {1, 1}};
    pdt_rec ev[] = {
        rec(0, PDT_EV_PUSH, PDT_STACK_LOWER, 7, 1, 0, 0),   /* point out of range */
        rec(0, PDT_EV_PHASE_END, PDT_PH_KERNEL, 0, 0, 0, 0), /* never began */
        rec(0, PDT_EV_TRI_NEW, 0, 0, 1, 9, 0),
        rec(0, PDT_EV_LIFT, 0, 1, 0, 0, 2),
    };
    pdt_replay *r = NULL;
    pdt_err err = {0};
    CHECK(pdt_replay_new(pts, 2, ev, 4, 1, &r, &err) == PDT_OK);
    if (!r) return;
    CHECK_MSG(pdt_replay_skipped(r) == 3, "%zu", pdt_replay_skipped(r));
    CHECK(check_routes(r, 1) == 0);
    pdt_replay_free(r);
}

/* A triangle's state names its history entry in 16 bits: a vertex set with
 * more than PDT_TRI_HIST_MAX events (only a made-up trace has one) is two
 * triangles, and every route (stepping both ways, seeking) agrees. */
TEST(long_history_split)
{
    pdt_point pts[3] = {{0, 0}, {4, 0}, {0, 4}};
    const size_t m = PDT_TRI_HIST_MAX + 4465;
    pdt_rec *ev = malloc(m * sizeof *ev);
    if (!ev) return;
    for (size_t i = 0; i < m; i++)
        ev[i] = rec(0, i % 2 ? PDT_EV_TRI_FINAL : PDT_EV_TRI_NEW, 0, (uint32_t)(i % 3),
                    (uint32_t)((i + 1) % 3), (uint32_t)((i + 2) % 3), 0);
    pdt_replay *r = NULL;
    pdt_err err = {0};
    CHECK(pdt_replay_new(pts, 3, ev, m, 1, &r, &err) == PDT_OK);
    free(ev);
    if (!r) return;
    size_t nt;
    const pdt_rtri *t = pdt_replay_tris(r, &nt);
    CHECK_MSG(nt == 2 && t[0].hn == PDT_TRI_HIST_MAX && t[1].hn == 4465 && t[1].h0 == PDT_TRI_HIST_MAX,
              "%zu triangles, %u and %u entries", nt, t[0].hn, nt > 1 ? t[1].hn : 0);
    pdt_rstate *s = pdt_rstate_new(r);
    pdt_replay_seek(r, s, m);
    CHECK(s && pdt_rstate_tri_entry(r, s, 0) == PDT_TRI_HIST_MAX - 1 &&
          pdt_rstate_tri_entry(r, s, 1) == (uint32_t)(m - 1));
    pdt_rstate_free(s);
    CHECK(check_routes(r, 997) == 0);
    pdt_replay_free(r);
}

/* Graham's words: the sort says which point becomes which p_k, a pop gives
 * Area2 of (below, popped, new) and tells collinear from a right turn
 * (the points of lesson 1, already in angular order). */
TEST(graham_words)
{
    pdt_point pts[6] = {{10, 0}, {13, 6}, {9, 8}, {5, 10}, {6, 4}, {2, 2}};
    pdt_rec ev[20];
    size_t m = 0;
    for (uint32_t i = 0; i < 6; i++) ev[m++] = rec(0, PDT_EV_SORT, 0, i, i, 0, 0);
    ev[m++] = rec(0, PDT_EV_PUSH, PDT_STACK_GRAHAM, 0, 1, 0, 0);
    ev[m++] = rec(0, PDT_EV_PUSH, PDT_STACK_GRAHAM, 1, 2, 0, 0);
    ev[m++] = rec(0, PDT_EV_PUSH, PDT_STACK_GRAHAM, 2, 3, 0, 0);
    ev[m++] = rec(0, PDT_EV_POP, PDT_STACK_GRAHAM, 2, 2, 3, 0);   /* 10 */
    ev[m++] = rec(0, PDT_EV_PUSH, PDT_STACK_GRAHAM, 3, 3, 0, 0);
    ev[m++] = rec(0, PDT_EV_PUSH, PDT_STACK_GRAHAM, 4, 4, 0, 0);
    ev[m++] = rec(0, PDT_EV_POP, PDT_STACK_GRAHAM, 4, 3, 5, 0);   /* 13 */
    pdt_replay *r = NULL;
    pdt_err err = {0};
    CHECK(pdt_replay_new(pts, 6, ev, m, 1, &r, &err) == PDT_OK);
    if (!r) return;
    char line[256];
    pdt_replay_describe(r, 1, line, sizeof line);
    CHECK_MSG(!strcmp(line, "rank 0: sort: point 0 (10,0) is the origin p0 (the rightmost lowest point)"), "%s", line);
    pdt_replay_describe(r, 3, line, sizeof line);
    CHECK_MSG(!strcmp(line, "rank 0: sort: point 2 (9,8) becomes p2"), "%s", line);
    pdt_replay_describe(r, 10, line, sizeof line);
    CHECK_MSG(!strcmp(line, "rank 0: pop p2 (point 2) — Area2(p1, p2, p3) = 0: collinear, not a strict left turn"), "%s", line);
    pdt_replay_describe(r, 13, line, sizeof line);
    CHECK_MSG(!strcmp(line, "rank 0: pop p4 (point 4) — Area2(p3, p4, p5) = -26: right turn"), "%s", line);
    pdt_rstate *s = pdt_rstate_new(r);
    int id = -1;
    pdt_replay_seek(r, s, 10);  /* a pop: "else: pop" */
    CHECK_MSG(pdt_replay_code_line(r, s, &id) == 8 && id == PDT_CODE_GRAHAM, "id %d", id);
    pdt_replay_seek(r, s, 2);
    pdt_point_label(r, s, 1, line, sizeof line);
    CHECK_MSG(!strcmp(line, "1=p1"), "%s", line);
    pdt_point_label(r, s, 4, line, sizeof line);
    CHECK_MSG(!strcmp(line, "4"), "%s", line);
    pdt_rstate_free(s);
    /* a hull run keeps Graham's listing to its last event (the end of "run") */
    pdt_synth sy;
    CHECK(pdt_synth_graham(30, 3, &sy, &err) == PDT_OK);
    pdt_replay *g = NULL;
    CHECK(pdt_replay_new(sy.pts, sy.n, sy.recs, sy.m, 1, &g, &err) == PDT_OK);
    if (g) {
        pdt_rstate *gs = pdt_rstate_new(g);
        for (size_t k = 1; k <= pdt_replay_count(g); k++) {
            pdt_replay_seek(g, gs, k);
            id = -1;
            pdt_replay_code_line(g, gs, &id);
            CHECK_MSG(id == PDT_CODE_GRAHAM, "event %zu: listing %d", k, id);
        }
        pdt_rstate_free(gs);
        pdt_replay_free(g);
    }
    pdt_synth_free(&sy);
    pdt_replay_free(r);
}

/* The pseudo-code listings: numbered from 1 in order, bad ids and lines NULL. */
TEST(code_listings)
{
    for (int id = 0; id < PDT_CODE_COUNT; id++) {
        CHECK(pdt_code_title(id) && pdt_code_count(id) >= 5);
        for (size_t i = 0; i < pdt_code_count(id); i++) {
            const char *t = pdt_code_text(id, i);
            CHECK_MSG(t && strtoul(t, NULL, 10) == i + 1, "listing %d line %zu: %s", id, i, t ? t : "NULL");
        }
        CHECK(pdt_code_text(id, pdt_code_count(id)) == NULL);
    }
    CHECK(pdt_code_title(PDT_CODE_COUNT) == NULL && pdt_code_count(-1) == 0);
}

/* The kept index's build groups a run's triangle events in buckets, and
 * holds at least one whole bucket: their count grows with the run so that
 * what the grouping holds (one bucket, the buckets' buffers, the spill's
 * chunk table) stays within the budget for every run the format allows (up
 * to 2^32 events), or within 350 MiB under a budget too small for that.
 * With 2^8 buckets always, a run of 2^32 events held 1.6 GB in one bucket. */
TEST(bucket_plan_bounded)
{
    const uint64_t ms[] = {1000, 500000, 50000000, 500000000, 1400000000, 2000000000, 4294967295u};
    const uint64_t budgets[] = {64 << 10, 16 << 20, 64 << 20, 256 << 20, (uint64_t)1 << 30, (uint64_t)8 << 30};
    for (size_t i = 0; i < sizeof ms / sizeof *ms; i++)
        for (size_t k = 0; k < sizeof budgets / sizeof *budgets; k++) {
            size_t fb, cr;
            uint64_t bytes;
            unsigned bits = pdt_replay_plan_buckets(ms[i], budgets[k], &fb, &cr, &bytes);
            uint64_t nf = (uint64_t)1 << bits;
            uint64_t bucket = ((ms[i] >> bits) + 1) * PDT_REPLAY_GROUP_BYTES_PER_EVENT;
            uint64_t buffers = nf * ((uint64_t)fb * 20 + (uint64_t)cr * 24);  /* tri_xrec; tri_first, id, entry */
            uint64_t chunks = (ms[i] / fb + nf) * 16;
            uint64_t bound = budgets[k] > ((uint64_t)350 << 20) ? budgets[k] : (uint64_t)350 << 20;
            CHECK_MSG(bits >= 8 && bits <= 16 && fb >= 32 && fb <= 1024 && cr >= 32 && cr <= 512 &&
                          bucket + buffers + chunks <= bytes && bytes <= bound,
                      "m %llu budget %llu: 2^%u buckets of %llu bytes, buffers %llu, chunks %llu, "
                      "planned %llu", (unsigned long long)ms[i], (unsigned long long)budgets[k], bits,
                      (unsigned long long)bucket, (unsigned long long)buffers,
                      (unsigned long long)chunks, (unsigned long long)bytes);
        }
    /* what the runs made so far get: 2^8 buckets and full buffers */
    size_t fb, cr;
    CHECK(pdt_replay_plan_buckets(50000000, 16 << 20, &fb, &cr, NULL) == 8 && fb == 1024 && cr == 512);
    CHECK(pdt_replay_plan_buckets(500000000, (uint64_t)1 << 30, &fb, &cr, NULL) == 8 && fb == 1024);
    /* and the largest: more buckets */
    CHECK(pdt_replay_plan_buckets(4294967295u, (uint64_t)1 << 30, &fb, &cr, NULL) > 8);
}

int main(void)
{
    RUN(seek_equals_step_srm_4_ranks);
    RUN(seek_equals_step_srm_odd_ranks);
    RUN(seek_equals_step_graham);
    RUN(srm_end_state);
    RUN(checkpoint_blob_born_triangles);
    RUN(hand_made_story);
    RUN(malformed_events_skipped);
    RUN(long_history_split);
    RUN(code_listings);
    RUN(graham_words);
    RUN(bucket_plan_bounded);
    RUN(phase_stops_wait_for_every_rank);
    return test_summary();
}
