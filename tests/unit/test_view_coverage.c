/* Level of detail: pdt_replay_coverage counts the visible triangles of a
 * state in every grid cell they touch, by status and by maker rank (mixed where makers
 * differ), follows the cursor, and leaves out hidden ranks and everything
 * outside the box.  A synthetic multi-rank run: every triangle counted once. */
#include "../harness.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "pdt/view/replay.h"
#include "pdt/view/viewsynth.h"
#include "../../src/view/model/replay_int.h"

static pdt_rec rec(int rank, int kind, uint32_t a, uint32_t b, uint32_t c, int64_t v)
{
    pdt_rec r;
    memset(&r, 0, sizeof r);
    r.rank = (uint32_t)rank;
    r.ev.kind = (uint8_t)kind;
    r.ev.a = a;
    r.ev.b = b;
    r.ev.c = c;
    r.ev.v = v;
    return r;
}

/* Points: a 4 x 4 unit grid, 0..15 row by row ((x, y) = (i % 4, i / 4)). */
static pdt_point grid_pt(int i)
{
    pdt_point p = {i % 4, i / 4};
    return p;
}

TEST(cells_by_status_and_rank)
{
    pdt_point pts[16];
    for (int i = 0; i < 16; i++) pts[i] = grid_pt(i);
    /* a 3 x 3 grid of cells over [0, 3.5)^2 (cells of 7/6): lower-left
     * triangles 0 1 4 (rank 0) and 1 5 4 (rank 1) both touch cell (0, 0) only;
     * 10 11 14 (rank 1) cells (1, 1), (2, 1), (1, 2), (2, 2), later discarded;
     * 2 3 6 (rank 0) cells (1, 0) and (2, 0), final. */
    pdt_rec ev[] = {
        rec(0, PDT_EV_TRI_NEW, 0, 1, 4, 0),  rec(1, PDT_EV_TRI_NEW, 1, 5, 4, 0),
        rec(1, PDT_EV_TRI_NEW, 10, 11, 14, 0), rec(0, PDT_EV_TRI_NEW, 2, 3, 6, 0),
        rec(0, PDT_EV_TRI_FINAL, 2, 3, 6, 0),  rec(1, PDT_EV_DISCARD, 10, 11, 14, 5),
    };
    size_t m = sizeof ev / sizeof ev[0];
    pdt_replay *r;
    pdt_err err = {0};
    CHECK(pdt_replay_new(pts, 16, ev, m, 2, &r, &err) == PDT_OK);
    if (!r) return;
    pdt_rstate *s = pdt_rstate_new(r);
    pdt_cov_cell cells[9];
    CHECK(pdt_replay_coverage(r, s, 0, 0, 3.5, 3.5, 3, 3, NULL, 0, cells) == 0);  /* cursor 0 */
    pdt_replay_seek(r, s, m);
    CHECK(pdt_replay_coverage(r, s, 0, 0, 3.5, 3.5, 3, 3, NULL, 0, cells) == 4);
    CHECK(cells[0].n == 2 && cells[0].rank == PDT_COV_MIXED &&
          cells[0].by_status[PDT_TS_CANDIDATE] == 2);
    CHECK(cells[0].rank_lo == 0 && cells[0].rank_hi == 1);  /* the makers' range */
    CHECK(cells[2].rank_lo == 0 && cells[2].rank_hi == 0);
    CHECK(cells[2].n == 1 && cells[2].rank == 0 && cells[2].by_status[PDT_TS_FINAL] == 1);
    CHECK(cells[1].n == 1 && cells[1].rank == 0);
    CHECK(cells[8].n == 1 && cells[8].rank == 1 && cells[8].by_status[PDT_TS_DISCARDED] == 1);
    CHECK(cells[4].n == 1 && cells[3].n == 0 && cells[6].n == 0);
    /* the discard (event 5) one event back: kept while the fade is longer,
     * left out once it has faded */
    CHECK(pdt_replay_coverage(r, s, 0, 0, 3.5, 3.5, 3, 3, NULL, 2, cells) == 4);
    CHECK(cells[8].by_status[PDT_TS_DISCARDED] == 1);
    CHECK(pdt_replay_coverage(r, s, 0, 0, 3.5, 3.5, 3, 3, NULL, 1, cells) == 3);
    CHECK(cells[8].n == 0 && cells[2].by_status[PDT_TS_FINAL] == 1);
    /* the cursor before the final and the discard: candidates */
    pdt_replay_seek(r, s, 4);
    pdt_replay_coverage(r, s, 0, 0, 3.5, 3.5, 3, 3, NULL, 0, cells);
    CHECK(cells[2].by_status[PDT_TS_CANDIDATE] == 1 && cells[2].by_status[PDT_TS_FINAL] == 0);
    CHECK(cells[8].by_status[PDT_TS_CANDIDATE] == 1);
    /* rank 1 hidden: cell (0, 0) holds rank 0's triangle alone */
    pdt_replay_seek(r, s, m);
    uint8_t vis[2] = {1, 0};
    CHECK(pdt_replay_coverage(r, s, 0, 0, 3.5, 3.5, 3, 3, vis, 0, cells) == 2);
    CHECK(cells[0].n == 1 && cells[0].rank == 0 && cells[8].n == 0 && cells[4].n == 0);
    /* a box holding only the upper right: the rest left out */
    CHECK(pdt_replay_coverage(r, s, 2.5, 2.5, 3.5, 3.5, 1, 1, NULL, 0, cells) == 1);
    CHECK(cells[0].n == 1 && cells[0].rank == 1);
    /* an empty box or grid bins nothing */
    CHECK(pdt_replay_coverage(r, s, 1, 1, 1, 2, 2, 2, NULL, 0, cells) == 0);
    CHECK(pdt_replay_coverage(r, s, 0, 0, 3, 3, 0, 3, NULL, 0, cells) == 0);
    pdt_rstate_free(s);
    pdt_replay_free(r);
}

/* A synthetic 8-rank SRM run on a 40x40 grid (level 1) and its replay;
 * NULL (L freed, the failure counted) when either cannot be made. */
static pdt_replay *synth_replay(pdt_synth *L)
{
    pdt_err err = {0};
    pdt_replay *r = NULL;
    CHECK(pdt_synth_srm(40, 40, 8, 1, L, &err) == PDT_OK);
    if (err.code) return NULL;
    CHECK(pdt_replay_new(L->pts, L->n, L->recs, L->m, L->nranks, &r, &err) == PDT_OK);
    if (!r) pdt_synth_free(L);
    return r;
}

/* A synthetic 8-rank run at its end: every visible triangle touches the grid
 * over the bounding box; with cells smaller than the triangles, a cell is
 * empty only where no triangle is (none here: the grid is triangulated). */
TEST(synthetic_run_counts_add_up)
{
    pdt_synth L;
    pdt_replay *r = synth_replay(&L);
    if (!r) return;
    size_t m = L.m;
    pdt_rstate *s = pdt_rstate_new(r);
    pdt_replay_seek(r, s, m);
    size_t nt, visible = 0;
    pdt_replay_tris(r, &nt);
    for (size_t t = 0; t < nt; t++) visible += pdt_rstate_tri_visible(r, s, t);
    pdt_point lo, hi;
    CHECK(pdt_replay_bbox(r, &lo, &hi));
    enum { C = 97, R = 83 };
    pdt_cov_cell *cells = calloc(C * R, sizeof *cells);
    size_t binned = pdt_replay_coverage(r, s, lo.x, lo.y, hi.x + 1e-9, hi.y + 1e-9, C, R, NULL, 0,
                                        cells);
    size_t sum = 0, sum_st = 0, mixed = 0, empty = 0;
    for (int i = 0; i < C * R; i++) {
        sum += cells[i].n;
        for (int st = 0; st < PDT_TS_COUNT; st++) sum_st += cells[i].by_status[st];
        mixed += cells[i].n && cells[i].rank == PDT_COV_MIXED;
        empty += cells[i].n == 0;
    }
    CHECK_MSG(visible > 1000 && binned == visible && sum >= visible && sum_st == sum,
              "visible %zu binned %zu sum %zu by status %zu", visible, binned, sum, sum_st);
    CHECK_MSG(empty == 0, "%zu empty cells in a triangulated box", empty);
    CHECK_MSG(mixed > 0, "8 strips: cells along the seams hold triangles of two ranks");
    free(cells);
    pdt_rstate_free(s);
    pdt_replay_free(r);
    pdt_synth_free(&L);
}

/* The pass shared between two threads (a frame of millions of triangles)
 * gives the cells one pass gives, cell for cell: counts added, a cell mixed
 * when either share's is or their makers differ. */
TEST(two_threads_same_cells)
{
    pdt_synth L;
    pdt_replay *r = synth_replay(&L);
    if (!r) return;
    pdt_rstate *s = pdt_rstate_new(r);
    pdt_point lo, hi;
    CHECK(pdt_replay_bbox(r, &lo, &hi));
    enum { C = 61, R = 47 };
    pdt_cov_cell *one = calloc(C * R, sizeof *one), *two = calloc(C * R, sizeof *two);
    const size_t at[] = {L.m / 3, L.m / 2, L.m};
    for (size_t k = 0; k < sizeof at / sizeof *at; k++) {
        pdt_replay_seek(r, s, at[k]);
        pdt_replay_set_cov_split(SIZE_MAX);
        size_t b1 = pdt_replay_coverage(r, s, lo.x, lo.y, hi.x + 1e-9, hi.y + 1e-9, C, R, NULL, 0,
                                        one);
        pdt_replay_set_cov_split(1);
        size_t b2 = pdt_replay_coverage(r, s, lo.x, lo.y, hi.x + 1e-9, hi.y + 1e-9, C, R, NULL, 0,
                                        two);
        size_t mixed = 0;
        for (int i = 0; i < C * R; i++) mixed += one[i].n && one[i].rank == PDT_COV_MIXED;
        CHECK_MSG(b1 > 100 && b1 == b2 && memcmp(one, two, C * R * sizeof *one) == 0 &&
                      (at[k] < L.m || mixed > 0),
                  "cursor %zu: binned %zu and %zu, cells %s (%zu mixed)", at[k], b1, b2,
                  memcmp(one, two, C * R * sizeof *one) ? "differ" : "same", mixed);
    }
    pdt_replay_set_cov_split((size_t)1 << 20);
    free(one);
    free(two);
    pdt_rstate_free(s);
    pdt_replay_free(r);
    pdt_synth_free(&L);
}

int main(void)
{
    RUN(cells_by_status_and_rank);
    RUN(synthetic_run_counts_add_up);
    RUN(two_threads_same_cells);
    return test_summary();
}
