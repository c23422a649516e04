/* pdt — the replay queries of pdt/view/query.h (no cairo): stacks listed from
 * their top node against stacks kept by hand from the push/pop events,
 * Graham's scan ending, hulls still live, the pseudo-code line of events. */
#include <stdlib.h>
#include <string.h>

#include "../harness.h"
#include "pdt/view/describe.h"
#include "pdt/view/query.h"
#include "pdt/view/viewsynth.h"

typedef struct fix {
    pdt_synth syn;
    pdt_replay *r;
    pdt_rstate *s;
} fix;

static int open_fix(fix *f, int graham)
{
    pdt_err err = {0};
    memset(f, 0, sizeof *f);
    pdt_status st = graham ? pdt_synth_graham(40, 3, &f->syn, &err)
                           : pdt_synth_srm(16, 6, 4, 2, &f->syn, &err);
    if (st != PDT_OK) return 0;
    if (pdt_replay_new(f->syn.pts, f->syn.n, f->syn.recs, f->syn.m, f->syn.nranks, &f->r, &err) !=
        PDT_OK)
        return 0;
    f->s = pdt_rstate_new(f->r);
    return f->s != NULL;
}

static void close_fix(fix *f)
{
    pdt_rstate_free(f->s);
    pdt_replay_free(f->r);
    pdt_synth_free(&f->syn);
}

/* At every cursor, every stack listed from its slot equals the stack kept as
 * a plain array from the events (push: set depth b - 1, append; pop: set
 * depth b). */
static void stacks_match(fix *f)
{
    int p = f->syn.nranks;
    size_t n = f->syn.n, m = pdt_replay_count(f->r);
    uint32_t *mine = calloc((size_t)p * 5 * (n + 1), sizeof *mine);
    size_t *len = calloc((size_t)p * 5, sizeof *len);
    uint32_t *got = malloc((n + 1) * sizeof *got);
    size_t compared = 0, bad = 0;
    for (size_t k = 0; k <= m && mine && len && got; k++) {
        pdt_replay_seek(f->r, f->s, k);
        for (int q = 0; q < p; q++)
            for (int st = 0; st < 5; st++) {
                int32_t top = pdt_rstate_slot(f->r, f->s, q, PDT_SLOT_STACK0 + st);
                size_t g = pdt_replay_stack_list(f->r, top, got, n + 1);
                size_t i = (size_t)q * 5 + (size_t)st;
                if (top < 0 && len[i] == 0) continue;
                compared++;
                bad += g != len[i] || memcmp(got, mine + i * (n + 1), g * sizeof *got) != 0;
            }
        if (k == m) break;
        const pdt_rec *e = pdt_replay_rec(f->r, k);
        if (e->ev.kind != PDT_EV_PUSH && e->ev.kind != PDT_EV_POP) continue;
        size_t i = (size_t)e->rank * 5 + e->ev.sub;
        if (e->ev.kind == PDT_EV_POP) {
            len[i] = e->ev.b;
        } else {
            if (e->ev.b) len[i] = e->ev.b - 1;
            mine[i * (n + 1) + len[i]++] = e->ev.a;
        }
    }
    CHECK(compared > 0);
    CHECK_MSG(bad == 0, "%zu of %zu stacks differ", bad, compared);
    free(mine);
    free(len);
    free(got);
}

TEST(stack_list_graham_equals_events)
{
    fix f;
    CHECK(open_fix(&f, 1));
    stacks_match(&f);
    close_fix(&f);
}

TEST(stack_list_srm_equals_events)
{
    fix f;
    CHECK(open_fix(&f, 0));
    stacks_match(&f);
    close_fix(&f);
}

/* The Graham scan has ended exactly after its PHASE_END; the stack stays
 * a stack is open until a hull event reports it. */
TEST(graham_scan_ended_after_phase_end)
{
    fix f;
    CHECK(open_fix(&f, 1));
    size_t m = pdt_replay_count(f.r), end_ev = m;
    for (size_t i = 0; i < m; i++) {
        const pdt_rec *e = pdt_replay_rec(f.r, i);
        if (e->ev.kind == PDT_EV_PHASE_END && e->ev.sub == PDT_PH_GRAHAM_SCAN) end_ev = i;
    }
    CHECK(end_ev < m);
    pdt_replay_seek(f.r, f.s, end_ev);
    CHECK(!pdt_replay_graham_scan_ended(f.r, f.s, 0));
    pdt_replay_seek(f.r, f.s, end_ev + 1);
    CHECK(pdt_replay_graham_scan_ended(f.r, f.s, 0));
    pdt_replay_seek(f.r, f.s, 0);
    CHECK(!pdt_replay_graham_scan_ended(f.r, f.s, 0));
    size_t nh;
    const pdt_rhull *Hs = pdt_replay_hulls(f.r, &nh);
    for (size_t h = 0; h < nh; h++) {
        pdt_replay_seek(f.r, f.s, Hs[h].ev);
        CHECK(pdt_replay_stack_open(f.r, f.s, Hs[h].top));
        pdt_replay_seek(f.r, f.s, (size_t)Hs[h].ev + 1);
        CHECK(!pdt_replay_stack_open(f.r, f.s, Hs[h].top));
    }
    close_fix(&f);
}

/* SRM: before the first merge every strip hull is live; at the end only the
 * hull reported last (the root merge's) is. */
TEST(hull_live_until_merged)
{
    fix f;
    CHECK(open_fix(&f, 0));
    size_t m = pdt_replay_count(f.r), first_merge = m;
    for (size_t i = 0; i < m && first_merge == m; i++)
        if (pdt_replay_rec(f.r, i)->ev.kind == PDT_EV_MERGE_BEGIN) first_merge = i;
    CHECK(first_merge < m);
    pdt_replay_seek(f.r, f.s, first_merge);
    int live = 0, have = 0;
    for (int q = 0; q < f.syn.nranks; q++) {
        int32_t h = pdt_rstate_slot(f.r, f.s, q, PDT_SLOT_HULL);
        if (h < 0) continue;
        have++;
        live += pdt_replay_hull_live(f.r, f.s, q, h);
    }
    CHECK_MSG(have == f.syn.nranks && live == have, "%d hulls, %d live", have, live);
    pdt_replay_seek(f.r, f.s, m);
    size_t nh;
    const pdt_rhull *Hs = pdt_replay_hulls(f.r, &nh);
    live = 0;
    int live_last = 0;
    for (int q = 0; q < f.syn.nranks; q++) {
        int32_t h = pdt_rstate_slot(f.r, f.s, q, PDT_SLOT_HULL);
        if (h < 0 || !pdt_replay_hull_live(f.r, f.s, q, h)) continue;
        live++;
        live_last += (size_t)h == nh - 1 && Hs[h].ev > first_merge;
    }
    CHECK_MSG(live == 1 && live_last == 1, "%d live at the end (%d the last hull)", live, live_last);
    close_fix(&f);
}

/* The line of an event is one that speaks of it: pops light a "pop" line,
 * pushes past the first two a "push" line, discards a "discard" line. */
static size_t lines_naming(fix *f, int want_id, int kind, const char *word)
{
    size_t m = pdt_replay_count(f->r), hits = 0, bad = 0;
    for (size_t k = 1; k <= m; k++) {
        const pdt_rec *e = pdt_replay_rec(f->r, k - 1);
        if (e->ev.kind != kind || (kind == PDT_EV_PUSH && e->ev.b <= 2)) continue;
        pdt_replay_seek(f->r, f->s, k);
        int id, line = pdt_replay_code_line(f->r, f->s, &id);
        const char *text = line >= 0 ? pdt_code_text(id, (size_t)line) : NULL;
        if (id != want_id || !text) bad++;
        else hits += strstr(text, word) != NULL;
    }
    CHECK_MSG(bad == 0, "%zu events without a line of their listing", bad);
    return hits;
}

TEST(code_lines)
{
    fix f;
    CHECK(open_fix(&f, 1));
    int id;
    pdt_replay_seek(f.r, f.s, 0);
    CHECK(pdt_replay_code_line(f.r, f.s, &id) == -1);
    CHECK(lines_naming(&f, PDT_CODE_GRAHAM, PDT_EV_POP, "pop") > 0);
    CHECK(lines_naming(&f, PDT_CODE_GRAHAM, PDT_EV_PUSH, "push") > 0);
    close_fix(&f);
    CHECK(open_fix(&f, 0));
    CHECK(lines_naming(&f, PDT_CODE_SRM, PDT_EV_DISCARD, "discard") > 0);
    close_fix(&f);
}

/* The Voronoi diagram of the final triangulation has one edge per Delaunay
 * edge: n + T - 1 of them (Euler), of which the rays are the hull edges;
 * the finite ones join two circumcentres. */
TEST(voronoi_edges_euler)
{
    fix f;
    CHECK(open_fix(&f, 0));
    pdt_replay_seek(f.r, f.s, pdt_replay_count(f.r));
    size_t nt, T = 0;
    pdt_replay_tris(f.r, &nt);
    for (size_t t = 0; t < nt; t++) T += pdt_rstate_tri_status(f.r, f.s, t) == PDT_TS_FINAL;
    pdt_vseg *S = NULL;
    size_t ns = 0, rays = 0;
    pdt_err err = {0};
    CHECK(pdt_replay_voronoi(f.r, f.s, NULL, &S, &ns, &err) == PDT_OK);
    for (size_t i = 0; i < ns; i++) rays += S[i].ray;
    /* a 16 x 6 grid: 96 points, 150 triangles, hull of 2 * (15 + 5) = 40 edges */
    CHECK_MSG(T == 150 && ns == f.syn.n + T - 1, "n %zu, T %zu, Voronoi edges %zu", f.syn.n, T, ns);
    CHECK_MSG(rays == 40, "rays %zu", rays);
    free(S);
    /* hiding a rank leaves out its triangles' edges */
    uint8_t hidden[4] = {1, 0, 0, 0};
    CHECK(pdt_replay_voronoi(f.r, f.s, hidden, &S, &ns, &err) == PDT_OK && ns < f.syn.n + T - 1);
    free(S);
    /* at cursor 0 there is no final triangle */
    pdt_replay_seek(f.r, f.s, 0);
    CHECK(pdt_replay_voronoi(f.r, f.s, NULL, &S, &ns, &err) == PDT_OK && ns == 0);
    free(S);
    close_fix(&f);
}

/* Stepping by rank: the cursor lands just after an event of that rank, with
 * no event of the rank skipped. */
TEST(find_rank)
{
    fix f;
    CHECK(open_fix(&f, 0));
    size_t m = pdt_replay_count(f.r);
    for (size_t k = 0; k < m; k += 37) {
        size_t nx = pdt_replay_find_rank(f.r, k, 1, 2);
        if (nx == k) continue;
        CHECK(nx > k && pdt_replay_rec(f.r, nx - 1)->rank == 2);
        for (size_t i = k; i + 1 < nx; i++) CHECK(pdt_replay_rec(f.r, i)->rank != 2);
        size_t pv = pdt_replay_find_rank(f.r, nx, -1, 2);
        CHECK(pv == nx || (pv < nx && pdt_replay_rec(f.r, pv - 1)->rank == 2));
    }
    close_fix(&f);
}

int main(void)
{
    RUN(voronoi_edges_euler);
    RUN(find_rank);
    RUN(stack_list_graham_equals_events);
    RUN(stack_list_srm_equals_events);
    RUN(graham_scan_ended_after_phase_end);
    RUN(hull_live_until_merged);
    RUN(code_lines);
    return test_summary();
}
