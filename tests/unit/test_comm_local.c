/* pdt — the local communication backend (src/par/comm_local.c): every
 * collective, point-to-point messages, the shared file and a failing rank,
 * with P = 1..5 ranks as threads.  Each rank checks its own results and
 * returns PDT_ERR_CHECK naming the first wrong one. */
#include "../harness.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pdt/par.h"

#define WRONG(...) return pdt_err_set(err, PDT_ERR_CHECK, __VA_ARGS__)

static unsigned char byte_of(int from, int to, size_t k)
{
    return (unsigned char)(from * 37 + to * 11 + (int)(k % 251) + 1);
}

static pdt_status rank_collectives(pdt_comm *c, void *arg, pdt_err *err)
{
    (void)arg;
    int r = pdt_comm_rank(c), P = pdt_comm_size(c);
    pdt_status s;
    if (pdt_comm_is_mpi(c)) WRONG("local rank says MPI");
    if (pdt_comm_node_size(c) != P)
        WRONG("rank %d: %d ranks on the machine, want all %d", r, pdt_comm_node_size(c), P);
    if ((s = pdt_comm_barrier(c, err)) != PDT_OK) return s;
    if ((s = pdt_comm_quiet_barrier(c, err)) != PDT_OK) return s;

    unsigned char b[1000];
    for (size_t k = 0; k < sizeof b; k++) b[k] = r == P - 1 ? byte_of(P - 1, 0, k) : 0;
    if ((s = pdt_comm_bcast(c, b, sizeof b, P - 1, err)) != PDT_OK) return s;
    for (size_t k = 0; k < sizeof b; k++)
        if (b[k] != byte_of(P - 1, 0, k)) WRONG("rank %d: bcast byte %zu", r, k);

    unsigned char g[13], ga[5 * 13];
    for (size_t k = 0; k < 13; k++) g[k] = byte_of(r, 0, k);
    if ((s = pdt_comm_allgather(c, g, 13, ga, err)) != PDT_OK) return s;
    for (int i = 0; i < P; i++)
        for (size_t k = 0; k < 13; k++)
            if (ga[i * 13 + (int)k] != byte_of(i, 0, k)) WRONG("rank %d: allgather from %d", r, i);

    unsigned char a[5 * 7], ar[5 * 7];
    for (int i = 0; i < P; i++)
        for (size_t k = 0; k < 7; k++) a[i * 7 + (int)k] = byte_of(r, i, k);
    if ((s = pdt_comm_alltoall(c, a, 7, ar, err)) != PDT_OK) return s;
    for (int i = 0; i < P; i++)
        for (size_t k = 0; k < 7; k++)
            if (ar[i * 7 + (int)k] != byte_of(i, r, k)) WRONG("rank %d: alltoall from %d", r, i);

    /* alltoallv: rank i sends (i + 2j) % 5 bytes to rank j (some blocks empty) */
    size_t sc[5], rc[5], so = 0, ro = 0;
    unsigned char sv[64], rv[64];
    for (int j = 0; j < P; j++) {
        sc[j] = (size_t)((r + 2 * j) % 5);
        rc[j] = (size_t)((j + 2 * r) % 5);
        for (size_t k = 0; k < sc[j]; k++) sv[so + k] = byte_of(r, j, k);
        so += sc[j];
    }
    if ((s = pdt_comm_alltoallv(c, sv, sc, rv, rc, err)) != PDT_OK) return s;
    for (int j = 0; j < P; j++) {
        for (size_t k = 0; k < rc[j]; k++)
            if (rv[ro + k] != byte_of(j, r, k)) WRONG("rank %d: alltoallv from %d", r, j);
        ro += rc[j];
    }

    /* scatterv from 0: rank i gets 3i + 1 bytes; gatherv at P/2: i sends i + 2 */
    size_t cnt[5], off = 0;
    unsigned char sa[64], sb[16];
    for (int i = 0; i < P; i++) {
        cnt[i] = (size_t)(3 * i + 1);
        for (size_t k = 0; k < cnt[i]; k++) sa[off + k] = byte_of(0, i, k);
        off += cnt[i];
    }
    if ((s = pdt_comm_scatterv(c, sa, cnt, sb, (size_t)(3 * r + 1), 0, err)) != PDT_OK) return s;
    for (size_t k = 0; k < (size_t)(3 * r + 1); k++)
        if (sb[k] != byte_of(0, r, k)) WRONG("rank %d: scatterv byte %zu", r, k);
    unsigned char gs[8], gr[64];
    for (size_t k = 0; k < (size_t)(r + 2); k++) gs[k] = byte_of(r, P / 2, k);
    for (int i = 0; i < P; i++) cnt[i] = (size_t)(i + 2);
    if ((s = pdt_comm_gatherv(c, gs, (size_t)(r + 2), gr, cnt, P / 2, err)) != PDT_OK) return s;
    off = 0;
    for (int i = 0; r == P / 2 && i < P; i++) {
        for (size_t k = 0; k < cnt[i]; k++)
            if (gr[off + k] != byte_of(i, P / 2, k)) WRONG("rank %d: gatherv from %d", r, i);
        off += cnt[i];
    }

    double d[2] = {(double)r, -(double)r};
    if ((s = pdt_comm_allmax(c, d, 2, err)) != PDT_OK) return s;
    if (d[0] != P - 1 || d[1] != 0) WRONG("rank %d: allmax %g %g", r, d[0], d[1]);
    uint64_t u[3] = {(uint64_t)r + 1, (uint64_t)r * 1000000007u, UINT64_MAX - (uint64_t)r};
    uint64_t sum[3], mx[3], mn[3];
    memcpy(sum, u, sizeof u);
    memcpy(mx, u, sizeof u);
    memcpy(mn, u, sizeof u);
    if ((s = pdt_comm_allreduce_u64(c, sum, 3, PDT_COMM_SUM, err)) != PDT_OK) return s;
    if ((s = pdt_comm_allreduce_u64(c, mx, 3, PDT_COMM_MAX, err)) != PDT_OK) return s;
    if ((s = pdt_comm_allreduce_u64(c, mn, 3, PDT_COMM_MIN, err)) != PDT_OK) return s;
    uint64_t p = (uint64_t)P;
    if (sum[0] != p * (p + 1) / 2) WRONG("rank %d: sum %llu", r, (unsigned long long)sum[0]);
    if (mx[1] != (p - 1) * 1000000007u || mx[2] != UINT64_MAX) WRONG("rank %d: max", r);
    if (mn[0] != 1 || mn[2] != UINT64_MAX - (p - 1)) WRONG("rank %d: min", r);
    uint64_t ex = 99;
    if ((s = pdt_comm_exscan_u64(c, (uint64_t)r + 1, &ex, err)) != PDT_OK) return s;
    if (ex != (uint64_t)r * (uint64_t)(r + 1) / 2) WRONG("rank %d: exscan %llu", r, (unsigned long long)ex);
    return PDT_OK;
}

/* Rank r sends to r+1 a small message (tag 1) then a large one (tag 2); the
 * receiver takes tag 2 first. */
static pdt_status rank_messages(pdt_comm *c, void *arg, pdt_err *err)
{
    (void)arg;
    int r = pdt_comm_rank(c), P = pdt_comm_size(c);
    if (P == 1) return PDT_OK;
    int to = (r + 1) % P, from = (r + P - 1) % P;
    size_t big = (size_t)1 << 20;
    unsigned char *m = malloc(big);
    if (!m) WRONG("out of memory");
    for (size_t k = 0; k < big; k++) m[k] = byte_of(r, to, k);
    pdt_status s = pdt_comm_send(c, to, 1, m, 5, err);
    if (s == PDT_OK) s = pdt_comm_send(c, to, 2, m, big, err);
    free(m);
    if (s != PDT_OK) return s;
    void *b2, *b1;
    size_t n2, n1;
    if ((s = pdt_comm_recv(c, from, 2, &b2, &n2, err)) != PDT_OK) return s;
    if ((s = pdt_comm_recv(c, from, 1, &b1, &n1, err)) != PDT_OK) {
        free(b2);
        return s;
    }
    int bad = n2 != big || n1 != 5;
    for (size_t k = 0; !bad && k < big; k++) bad = ((unsigned char *)b2)[k] != byte_of(from, r, k);
    for (size_t k = 0; !bad && k < 5; k++) bad = ((unsigned char *)b1)[k] != byte_of(from, r, k);
    free(b1);
    free(b2);
    if (bad) WRONG("rank %d: message from %d", r, from);
    return PDT_OK;
}

/* Each rank writes r + 1 copies of 'a' + r at its prefix-sum offset. */
static pdt_status rank_file(pdt_comm *c, void *arg, pdt_err *err)
{
    int r = pdt_comm_rank(c);
    char line[8];
    memset(line, 'a' + r, sizeof line);
    uint64_t off;
    pdt_comm_file *f;
    pdt_status s = pdt_comm_exscan_u64(c, (uint64_t)r + 1, &off, err);
    int p = pdt_comm_size(c);
    if (s == PDT_OK) s = pdt_comm_file_open(c, arg, (uint64_t)p * (uint64_t)(p + 1) / 2, &f, err);
    if (s != PDT_OK) return s;
    s = pdt_comm_file_write_at(f, off, line, (size_t)r + 1, err);
    pdt_status s2 = pdt_comm_file_close(f, err);
    return s != PDT_OK ? s : s2;
}

/* Rank 1 fails before the first barrier: the others must not wait forever. */
static pdt_status rank_fails(pdt_comm *c, void *arg, pdt_err *err)
{
    (void)arg;
    if (pdt_comm_rank(c) == 1) return pdt_err_set(err, PDT_ERR_PARSE, "rank 1 gives up");
    pdt_status s = pdt_comm_barrier(c, err);
    if (s == PDT_OK && pdt_comm_rank(c) == 0) {
        void *b;
        size_t n;
        s = pdt_comm_recv(c, 1, 7, &b, &n, err);
    }
    return s;
}

TEST(every_collective_p1_to_p5)
{
    for (int P = 1; P <= 5; P++) {
        pdt_err err = {0};
        pdt_status s = pdt_comm_local_run(P, rank_collectives, NULL, &err);
        CHECK_MSG(s == PDT_OK, "P=%d: %s", P, err.msg);
        for (int rep = 0; rep < 20 && s == PDT_OK; rep++) /* races show up on repeats */
            s = pdt_comm_local_run(P, rank_collectives, NULL, &err);
        CHECK_MSG(s == PDT_OK, "P=%d (repeat): %s", P, err.msg);
    }
}

TEST(messages_by_tag_p1_to_p5)
{
    for (int P = 1; P <= 5; P++) {
        pdt_err err = {0};
        pdt_status s = pdt_comm_local_run(P, rank_messages, NULL, &err);
        CHECK_MSG(s == PDT_OK, "P=%d: %s", P, err.msg);
    }
}

TEST(one_file_written_by_all_ranks)
{
    char path[] = "/tmp/pdt-comm-local.XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    if (fd < 0) return;
    CHECK(write(fd, "old content that must go away", 29) == 29);
    close(fd);
    for (int P = 1; P <= 5; P++) {
        pdt_err err = {0};
        pdt_status s = pdt_comm_local_run(P, rank_file, path, &err);
        CHECK_MSG(s == PDT_OK, "P=%d: %s", P, err.msg);
        char want[32] = "", got[64] = "";
        for (int r = 0; r < P; r++)
            for (int k = 0; k <= r; k++) want[strlen(want)] = (char)('a' + r);
        FILE *f = fopen(path, "rb");
        size_t n = f ? fread(got, 1, sizeof got - 1, f) : 0;
        if (f) fclose(f);
        CHECK_MSG(n == strlen(want) && memcmp(got, want, n) == 0, "P=%d: file '%s', want '%s'", P,
                  got, want);
    }
    unlink(path);
    pdt_err err = {0};
    pdt_status s = pdt_comm_local_run(3, rank_file, "/nonexistent-dir/x.out", &err);
    CHECK_MSG(s == PDT_ERR_IO && strstr(err.msg, "/nonexistent-dir/x.out"), "status %d: %s",
              (int)s, err.msg);
}

TEST(failing_rank_ends_the_run)
{
    for (int P = 2; P <= 5; P++) {
        pdt_err err = {0};
        pdt_status s = pdt_comm_local_run(P, rank_fails, NULL, &err);
        CHECK_MSG(s == PDT_ERR_PARSE && strcmp(err.msg, "rank 1 gives up") == 0,
                  "P=%d: status %d: %s", P, (int)s, err.msg);
    }
}

/* The commit point's stop question (pdt_comm_commit_ok): arg says which
 * rank is being stopped (-1: none; 0 late: rank 0 only at its last word,
 * after the others answered).  Every rank checks the status it gets. */
typedef struct stop_case {
    int who, late;
} stop_case;

static int stop_calls[8];

typedef struct stop_ctx {
    int rank;
    stop_case sc;
} stop_ctx;

static int stop_query(void *ctx)
{
    stop_ctx *x = ctx;
    int n = ++stop_calls[x->rank];
    if (x->sc.late) return x->rank == 0 && n == 2;
    return x->rank == x->sc.who;
}

static pdt_status rank_commit(pdt_comm *c, void *arg, pdt_err *err)
{
    stop_ctx x = {pdt_comm_rank(c), *(const stop_case *)arg};
    stop_calls[x.rank] = 0;
    pdt_comm_set_stop_query(c, stop_query, &x);
    pdt_err e = {0};
    pdt_status st = pdt_comm_commit_ok(c, "out.tri", &e);
    int want_fail = x.sc.late ? x.rank == 0 : x.sc.who >= 0;
    pdt_comm_set_stop_query(c, NULL, NULL);
    if ((st != PDT_OK) != want_fail)
        return pdt_err_set(err, PDT_ERR_CHECK, "rank %d: status %d (%s)", x.rank, (int)st, e.msg);
    if (want_fail && !strstr(e.msg, "out.tri: "))
        return pdt_err_set(err, PDT_ERR_CHECK, "rank %d: message '%s'", x.rank, e.msg);
    return PDT_OK;
}

TEST(commit_refused_when_any_rank_is_stopped)
{
    const stop_case cases[] = {{-1, 0}, {0, 0}, {1, 0}, {2, 0}, {-1, 1}};
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        pdt_err err = {0};
        pdt_status s = pdt_comm_local_run(3, rank_commit, (void *)&cases[k], &err);
        CHECK_MSG(s == PDT_OK, "case who=%d late=%d: %s", cases[k].who, cases[k].late, err.msg);
    }
}

/* The partition of pdt_par_triangulate: the input (job->n points, point i
 * at job->pt(i)) dealt in consecutive blocks; every rank checks it got
 * exactly its share of the records when keys are distinct, and the distinct
 * points of all ranks add up (copies of a key on two ranks would count it
 * twice). */
typedef struct part_job {
    size_t n;
    int dups;            /* 1: a third of the points are one point */
    uint64_t distinct;   /* expected distinct points */
    uint64_t *points;    /* per rank, filled by the ranks */
} part_job;

static pdt_point part_pt(const part_job *j, size_t i)
{
    if (j->dups && i % 3 == 1) return (pdt_point){500, 500};
    return (pdt_point){(int32_t)((i * 7919) % 1009), (int32_t)i};
}

static pdt_status rank_partition(pdt_comm *c, void *arg, pdt_err *err)
{
    part_job *j = arg;
    int r = pdt_comm_rank(c), P = pdt_comm_size(c);
    size_t lo = j->n * (size_t)r / (size_t)P, hi = j->n * (size_t)(r + 1) / (size_t)P;
    pdt_par_input in = {malloc((hi - lo + 1) * sizeof(pdt_point)), hi - lo, lo, j->n, 0, 1, 0, PDT_PART_STRIPS};
    if (!in.pts) WRONG("out of memory");
    for (size_t i = lo; i < hi; i++) in.pts[i - lo] = part_pt(j, i);
    pdt_par_output out;
    pdt_par_rank_stats me;
    memset(&me, 0, sizeof me);
    pdt_status s = pdt_par_triangulate(c, &in, &out, &me, NULL, err);
    int released = in.pts == NULL;
    pdt_par_input_free(&in);
    pdt_par_output_free(&out);
    if (s != PDT_OK) return s;
    if (!released) WRONG("rank %d: input points not released", r);
    j->points[r] = me.points;
    if (!j->dups && me.received != hi - lo)
        WRONG("rank %d of %d: %llu records, not %zu", r, P, (unsigned long long)me.received,
              hi - lo);
    return PDT_OK;
}

/* An alltoallv with pieces of 0 to 8 bytes, every pair its own size. */
static pdt_status rank_alltoallv(pdt_comm *c, void *arg, pdt_err *err)
{
    (void)arg;
    int r = pdt_comm_rank(c), P = pdt_comm_size(c);
    size_t sc[64], rc[64], so = 0, ro = 0;
    unsigned char sv[64 * 8], rv[64 * 8];
    for (int j = 0; j < P; j++) {
        sc[j] = (size_t)((r * 7 + j * 3 + r * j) % 9);
        rc[j] = (size_t)((j * 7 + r * 3 + r * j) % 9);
        for (size_t k = 0; k < sc[j]; k++) sv[so + k] = byte_of(r, j, k);
        so += sc[j];
    }
    memset(rv, 0, sizeof rv);
    pdt_status s = pdt_comm_alltoallv(c, sv, sc, rv, rc, err);
    if (s != PDT_OK) return s;
    for (int j = 0; j < P; j++) {
        for (size_t k = 0; k < rc[j]; k++)
            if (rv[ro + k] != byte_of(j, r, k))
                WRONG("rank %d of %d: alltoallv from %d, byte %zu", r, P, j, k);
        ro += rc[j];
    }
    return PDT_OK;
}

/* The exchange through relays (src/par/comm_hops.c), forced at every P:
 * full grids (4, 9, 16, 64), short last rows (3, 5, 7, 10, 13, 21, 31) and a
 * last row of one rank (17, 26, 37). */
TEST(alltoallv_in_two_hops)
{
    static const int ps[] = {1, 2, 3, 4, 5, 7, 9, 10, 13, 16, 17, 21, 26, 31, 37, 64};
    setenv("PDT_TEST_COMM_HOPS", "2", 1);
    for (size_t k = 0; k < sizeof ps / sizeof *ps; k++) {
        pdt_err err = {0};
        pdt_status s = pdt_comm_local_run(ps[k], rank_alltoallv, NULL, &err);
        CHECK_MSG(s == PDT_OK, "P=%d: %s", ps[k], err.msg);
    }
    unsetenv("PDT_TEST_COMM_HOPS");
}

/* (P = 33 and 64: many splitters share the selection's first rounds) */
TEST(partition_exact_shares_p2_to_p7_33_64)
{
    static const int ps[] = {2, 3, 4, 5, 6, 7, 33, 64};
    for (int dups = 0; dups <= 1; dups++)
        for (size_t k = 0; k < sizeof ps / sizeof *ps; k++) {
            int P = ps[k];
            uint64_t pts[64] = {0};
            part_job j = {3000, dups, dups ? 2001 : 3000, pts};
            pdt_err err = {0};
            pdt_status s = pdt_comm_local_run(P, rank_partition, &j, &err);
            CHECK_MSG(s == PDT_OK, "P=%d dups=%d: %s", P, dups, err.msg);
            uint64_t sum = 0;
            for (int q = 0; q < P; q++) sum += pts[q];
            CHECK_MSG(s != PDT_OK || sum == j.distinct, "P=%d dups=%d: %llu distinct points",
                      P, dups, (unsigned long long)sum);
        }
}

int main(void)
{
    RUN(every_collective_p1_to_p5);
    RUN(messages_by_tag_p1_to_p5);
    RUN(one_file_written_by_all_ranks);
    RUN(failing_rank_ends_the_run);
    RUN(commit_refused_when_any_rank_is_stopped);
    RUN(partition_exact_shares_p2_to_p7_33_64);
    RUN(alltoallv_in_two_hops);
    return test_summary();
}
