/* Whole runs of pdt_par_triangulate on the thread backend (P ranks as
 * threads, no mpirun) with both partitions -- strips, and regions by
 * recursive bisection across the longer side (algorithm.md §3.12) --
 * against the sequential pipeline, triangle for triangle, on every family
 * of `pdt gen` (grids, circles, collinear runs, duplicates among them), for
 * P = 1, 2, 3, 5, 8, 13, 32 (P not a power of two, P larger than the
 * points); and the bisection's seams shrink: its largest border set at
 * P = 16 on 10^5 uniform points is much smaller than the strips'.
 *
 * The code under test comes from libpdtpar.a and libpdt.a. */
#include "../harness.h"

#include <stdlib.h>
#include <string.h>

#include "../../src/par/srm.h"
#include "pdt/delaunay.h"
#include "pdt/gen.h"
#include "pdt/par.h"

/* One run: the input dealt to the ranks in consecutive blocks; every rank
 * puts its block of the canonical output in place in tris. */
typedef struct job {
    const pdt_point *pts;
    size_t n;
    int partition;
    int release;          /* the points may be spent (as for a .tri output) */
    pdt_tri *tris;        /* room for every triangle the sequential run has, + 1 */
    size_t cap;
    uint64_t ntri;        /* (rank 0) triangles in all */
    uint64_t border[PDT_PAR_MAX_LEVELS], border_max;
    int levels;
    uint64_t shared, done_alone; /* shared merges, and those the merge rank finished alone */
    uint64_t fewest, most; /* the points of the smallest and the largest region */
    int bad_place;        /* a rank's block did not fit where it belongs */
} job;

static pdt_status rank_run(pdt_comm *c, void *arg, pdt_err *err)
{
    job *j = arg;
    int r = pdt_comm_rank(c), P = pdt_comm_size(c);
    size_t lo = j->n * (size_t)r / (size_t)P, hi = j->n * (size_t)(r + 1) / (size_t)P;
    pdt_par_input in = {malloc((hi - lo + 1) * sizeof(pdt_point)), hi - lo, lo, j->n, 0,
                        j->release, 0, j->partition};
    if (!in.pts) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    if (hi > lo) memcpy(in.pts, j->pts + lo, (hi - lo) * sizeof *in.pts);
    pdt_par_output out;
    pdt_par_rank_stats me;
    memset(&me, 0, sizeof me);
    pdt_status st = pdt_par_triangulate(c, &in, &out, &me, NULL, err);
    pdt_par_input_free(&in);
    pdt_par_stats all;
    memset(&all, 0, sizeof all);
    if (st == PDT_OK) st = pdt_par_stats_collect(c, &me, j->n, &all, err);
    if (st == PDT_OK) {
        if (out.first + out.ntri <= j->cap) {
            if (out.ntri) memcpy(j->tris + out.first, out.tris, out.ntri * sizeof *out.tris);
        } else {
            j->bad_place = 1;
        }
        if (r == 0) {
            j->ntri = out.n_total;
            j->border_max = all.border_max;
            j->levels = all.levels;
            memcpy(j->border, all.border_level, sizeof j->border);
            j->fewest = UINT64_MAX;
            j->most = 0;
            for (int q = 0; q < P; q++) {
                uint64_t m = all.rank[q].points;
                j->fewest = m < j->fewest ? m : j->fewest;
                j->most = m > j->most ? m : j->most;
                j->shared += all.rank[q].shared;
                j->done_alone += all.rank[q].share_fallbacks;
            }
        }
    }
    pdt_par_stats_free(&all);
    pdt_par_output_free(&out);
    return st;
}

/* Run P ranks on pts with a partition; 1 if the output equals ref. */
static int same_as(const pdt_point *pts, size_t n, int P, int partition, int release,
                   const pdt_tri *ref, size_t nref, job *j, const char *what)
{
    memset(j, 0, sizeof *j);
    j->pts = pts;
    j->n = n;
    j->partition = partition;
    j->release = release;
    j->cap = nref + 1;
    j->tris = calloc(j->cap, sizeof *j->tris);
    pdt_err err = {0};
    pdt_status st = pdt_comm_local_run(P, rank_run, j, &err);
    int same = st == PDT_OK && !j->bad_place && j->ntri == nref &&
               (nref == 0 || memcmp(j->tris, ref, nref * sizeof *ref) == 0);
    if (!same)
        printf("#   %s n=%zu P=%d %s: %s%s, %llu triangles, expected %zu\n", what, n, P,
               partition == PDT_PART_BISECT ? "bisect" : "strips",
               st == PDT_OK ? "" : "failed: ", st == PDT_OK ? "" : err.msg,
               (unsigned long long)j->ntri, nref);
    free(j->tris);
    j->tris = NULL;
    return same;
}

/* Every family, both partitions, every P of ps[0..nps) on every size of
 * ns[0..nns): the sequential run's triangles. */
static void families_both_partitions(int release, const int *ps, size_t nps, const size_t *ns,
                                     size_t nns)
{
    int runs = 0, bad = 0;
    for (const char *const *k = pdt_gen_kinds(); *k; k++)
        for (size_t ni = 0; ni < nns; ni++) {
            size_t n = ns[ni];
            pdt_point *pts = NULL;
            pdt_err err = {0};
            if (pdt_gen(*k, n, 7 + ni, &pts, &err) != PDT_OK) {
                CHECK_MSG(0, "gen %s: %s", *k, err.msg);
                continue;
            }
            pdt_tri *ref = NULL;
            size_t nref = 0;
            CHECK(pdt_triangulate(pts, n, &ref, &nref, NULL, NULL) == PDT_OK);
            for (size_t pi = 0; pi < nps; pi++)
                for (int part = PDT_PART_STRIPS; part <= PDT_PART_BISECT; part++) {
                    if (n > 700 && ps[pi] > 8) continue; /* (time: 32 threads under ASan) */
                    job j;
                    runs++;
                    bad += !same_as(pts, n, ps[pi], part, release, ref, nref, &j, *k);
                }
            free(ref);
            free(pts);
        }
    CHECK_MSG(bad == 0, "%d of %d runs differ from the sequential run", bad, runs);
    printf("# %d runs\n", runs);
}

TEST(every_family_both_partitions_same_as_plain)
{
    static const int ps[] = {1, 2, 3, 5, 8, 13, 32};
    static const size_t ns[] = {0, 1, 2, 3, 5, 40, 700, 3000};
    families_both_partitions(0, ps, 7, ns, 8);
}

/* Two strips a rank (what a large .tri run does to save memory), forced on
 * small inputs: the bisection tree gets a level 0 inside each rank. */
TEST(every_family_two_strips_a_rank_same_as_plain)
{
    static const int ps[] = {2, 3, 5, 13};
    static const size_t ns[] = {0, 3, 5, 40, 700};
    setenv("PDT_RANK_STRIPS", "2", 1);
    families_both_partitions(1, ps, 4, ns, 5);
    unsetenv("PDT_RANK_STRIPS");
}

/* n uniform points (pdt gen, seed) and the sequential run's triangles. */
static pdt_point *uniform_and_plain(size_t n, unsigned seed, pdt_tri **ref, size_t *nref)
{
    pdt_point *pts = NULL;
    pdt_err err = {0};
    CHECK(pdt_gen("uniform", n, seed, &pts, &err) == PDT_OK);
    CHECK(pdt_triangulate(pts, n, ref, nref, NULL, NULL) == PDT_OK);
    return pts;
}

/* The seams shrink: on 10^5 uniform points at P = 16 every strip seam runs
 * the whole height, so the largest border set is about the same at every
 * level; the bisection's top seam spans the input too, but those below it
 * a half, a quarter ... of it: its border sets summed over the levels (the
 * merge path) are under two thirds of the strips', its level-0 ones under
 * a third, and every level's but the top's is smaller. */
TEST(bisection_seams_shrink_p16)
{
    size_t n = 100000, nref = 0;
    pdt_tri *ref = NULL;
    pdt_point *pts = uniform_and_plain(n, 3, &ref, &nref);
    job js, jb;
    CHECK(same_as(pts, n, 16, PDT_PART_STRIPS, 0, ref, nref, &js, "uniform"));
    CHECK(same_as(pts, n, 16, PDT_PART_BISECT, 0, ref, nref, &jb, "uniform"));
    printf("# largest border set: strips %llu, bisect %llu; by level:",
           (unsigned long long)js.border_max, (unsigned long long)jb.border_max);
    for (int l = 0; l < js.levels; l++)
        printf(" %llu/%llu", (unsigned long long)js.border[l], (unsigned long long)jb.border[l]);
    printf("\n");
    CHECK(js.levels == 4 && jb.levels == 4);
    uint64_t ss = 0, sb = 0;
    for (int l = 0; l < PDT_PAR_MAX_LEVELS; l++) {
        ss += js.border[l];
        sb += jb.border[l];
    }
    CHECK_MSG(3 * sb < 2 * ss, "summed over the levels: bisect %llu, strips %llu",
              (unsigned long long)sb, (unsigned long long)ss);
    CHECK_MSG(3 * jb.border[0] < js.border[0], "level 0: bisect %llu, strips %llu",
              (unsigned long long)jb.border[0], (unsigned long long)js.border[0]);
    for (int l = 0; l + 1 < jb.levels; l++)
        CHECK_MSG(jb.border[l] < js.border[l], "level %d: bisect %llu, strips %llu", l,
                  (unsigned long long)jb.border[l], (unsigned long long)js.border[l]);
    free(ref);
    free(pts);
}

/* The schedule of the bisection tree: every level's pairs are disjoint
 * rank ranges whose halves are ceil/floor of the range; the last level
 * joins everything; a pair's merge rank holds the group's hull afterwards;
 * two ranks meet at the level of the pair that first holds both. */
TEST(bisection_schedule)
{
    for (int p = 1; p <= 40; p++)
        for (int k = 1; k <= 2; k++) {
            srm_tree t = {p, k, pdt_srm_ceil_log2(p), NULL};
            int np = p * k, L = pdt_srm_levels_of(&t, np), ok = 1;
            for (int level = 0; level < L; level++)
                for (int g = 0; g < np; g++) {
                    int gl, gr, ge;
                    if (!pdt_srm_pair_of(&t, g, np, level, &gl, &gr, &ge)) continue;
                    ok &= gl <= g && g < ge && gl < gr && gr < ge;
                    int s = (ge - gl) / k;
                    ok &= k == 2 && level == 0 ? ge - gl == 2 : (gr - gl) / k == (s + 1) / 2;
                    ok &= pdt_srm_holder_of(&t, g, np, level + 1) == gr;
                    if (level == L - 1) ok &= gl == 0 && ge == np;
                }
            for (int q = 0; q < np; q++)
                for (int h = 0; h < np; h++) {
                    if (q == h) continue;
                    int lv = pdt_srm_meet_of(&t, q, h), gl, gr, ge;
                    ok &= pdt_srm_pair_of(&t, h, np, lv, &gl, &gr, &ge) && gl <= q && q < ge &&
                          (q < gr) != (h < gr);
                }
            CHECK_MSG(ok, "p=%d k=%d", p, k);
        }
}


/* A merge shared by several ranks along its seam (algorithm.md §3.13),
 * forced on small inputs with pieces of a few points: every family, P not
 * a power of two, one and two strips a rank, gives the sequential run's
 * triangles, whether the pieces held the whole selection or the merge rank
 * finished alone. */
TEST(every_family_shared_merges_same_as_plain)
{
    static const int ps[] = {3, 5, 8, 13};
    static const size_t ns[] = {40, 700, 3000};
    static const char *const piece[] = {"2", "5", "30"};
    int runs = 0, bad = 0;
    uint64_t shared = 0, alone = 0;
    for (int two = 0; two < 2; two++) {
        if (two) setenv("PDT_RANK_STRIPS", "2", 1);
        for (const char *const *k = pdt_gen_kinds(); *k; k++) {
            uint64_t ks = 0, ka = 0;
            for (size_t ni = 0; ni < 3; ni++) {
                pdt_point *pts = NULL;
                pdt_err err = {0};
                size_t n = ns[ni];
                if (pdt_gen(*k, n, 11 + ni, &pts, &err) != PDT_OK) {
                    CHECK_MSG(0, "gen %s: %s", *k, err.msg);
                    continue;
                }
                pdt_tri *ref = NULL;
                size_t nref = 0;
                CHECK(pdt_triangulate(pts, n, &ref, &nref, NULL, NULL) == PDT_OK);
                for (size_t pi = 0; pi < 4; pi++) {
                    if (n > 700 && ps[pi] > 8) continue;
                    setenv("PDT_SHARE_PIECE", piece[(ni + pi) % 3], 1);
                    job j;
                    runs++;
                    bad += !same_as(pts, n, ps[pi], PDT_PART_BISECT, two, ref, nref, &j, *k);
                    ks += j.shared;
                    ka += j.done_alone;
                }
                free(ref);
                free(pts);
            }
            printf("# %s%s: %llu merges shared, %llu of them finished alone\n", *k,
                   two ? " (two strips a rank)" : "", (unsigned long long)ks,
                   (unsigned long long)ka);
            shared += ks;
            alone += ka;
        }
    }
    unsetenv("PDT_RANK_STRIPS");
    unsetenv("PDT_SHARE_PIECE");
    CHECK_MSG(bad == 0, "%d of %d runs differ from the sequential run", bad, runs);
    CHECK_MSG(shared > alone, "%llu shared merges, %llu finished alone",
              (unsigned long long)shared, (unsigned long long)alone);
    CHECK_MSG(alone > 0, "no shared merge fell back to the merge rank: that path is untested");
}

/* On uniform points the pieces hold the whole selection: every merge whose
 * group is large enough is shared and none falls back (which would mean a
 * wrong count of the selection, or pieces too narrow). */
TEST(uniform_shared_merges_need_no_fallback)
{
    size_t n = 100000, nref = 0;
    pdt_tri *ref = NULL;
    pdt_point *pts = uniform_and_plain(n, 5, &ref, &nref);
    setenv("PDT_SHARE_PIECE", "100", 1);
    job j;
    CHECK(same_as(pts, n, 16, PDT_PART_BISECT, 0, ref, nref, &j, "uniform"));
    printf("# P = 16: %llu merges shared, %llu finished alone\n",
           (unsigned long long)j.shared, (unsigned long long)j.done_alone);
    CHECK(j.shared == 15 && j.done_alone == 0);
    setenv("PDT_SHARE_PIECE", "0", 1);
    CHECK(same_as(pts, n, 16, PDT_PART_BISECT, 0, ref, nref, &j, "uniform"));
    CHECK(j.shared == 0 && j.done_alone == 0);
    unsetenv("PDT_SHARE_PIECE");
    free(ref);
    free(pts);
}

/* The counted cuts even the regions out: on 3 * 10^5 uniform points at
 * P = 128 the sample alone (1,024 of its points a region) leaves the
 * regions up to 7 % from n / P; the counts of every point in each cut's
 * window, depth by depth, halve the spread and put every region within
 * 3.5 % of n / P (a bin of a window is about 1 % of a region here). */
TEST(counted_cuts_even_the_regions)
{
    size_t n = 300000, nref = 0;
    int P = 128;
    pdt_tri *ref = NULL;
    pdt_point *pts = uniform_and_plain(n, 7, &ref, &nref);
    job js, jc;
    setenv("PDT_TEST_BIS_COUNT", "0", 1);
    CHECK(same_as(pts, n, P, PDT_PART_BISECT, 0, ref, nref, &js, "uniform"));
    setenv("PDT_TEST_BIS_COUNT", "1", 1);
    CHECK(same_as(pts, n, P, PDT_PART_BISECT, 0, ref, nref, &jc, "uniform"));
    unsetenv("PDT_TEST_BIS_COUNT");
    double share = (double)n / P;
    printf("# P = %d, n / P = %.0f: sample alone %llu .. %llu, counted %llu .. %llu\n", P, share,
           (unsigned long long)js.fewest, (unsigned long long)js.most,
           (unsigned long long)jc.fewest, (unsigned long long)jc.most);
    CHECK(2 * (jc.most - jc.fewest) < js.most - js.fewest);
    CHECK_MSG((double)jc.most < 1.035 * share && (double)jc.fewest > 0.965 * share,
              "counted: %llu .. %llu", (unsigned long long)jc.fewest,
              (unsigned long long)jc.most);
    free(ref);
    free(pts);
}

int main(void)
{
    RUN(bisection_schedule);
    RUN(every_family_both_partitions_same_as_plain);
    RUN(every_family_two_strips_a_rank_same_as_plain);
    RUN(bisection_seams_shrink_p16);
    RUN(every_family_shared_merges_same_as_plain);
    RUN(uniform_shared_merges_need_no_fallback);
    RUN(counted_cuts_even_the_regions);
    return test_summary();
}
