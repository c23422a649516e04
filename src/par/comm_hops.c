/* pdt — an all-to-all exchange in two hops, for many ranks (comm_int.h).
 *
 * A direct exchange sends P - 1 messages from every rank.  When the pieces
 * are small (the order's triangles and the partition's points at hundreds
 * of ranks: a few hundred bytes a pair) the messages' latency and overhead,
 * not the bytes, set its cost.  Here the ranks sit in a grid of rows of
 * G = ceil(sqrt(P)), and the piece from src to dst goes through a relay:
 * the rank of src's row in dst's column, or, when the last row is short and
 * that rank does not exist, the rank of dst's row in src's column.  Three
 * rounds of the backend's own exchange follow, in each of which a rank
 * talks to at most 2G - 2 others:
 *
 *   1. counts: src tells each relay the size of every piece it will carry;
 *   2. pieces: src sends each relay its pieces, in dst order;
 *   3. relay:  each relay sends dst its pieces, in src order.
 *
 * The bytes travel twice and a relay holds a copy of what it carries; the
 * messages fall from P - 1 to about 6 sqrt(P) a rank.  The result is the
 * direct exchange's, byte for byte. */
#include "comm_int.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct grid {
    int p, g;    /* ranks, row length */
    int last;    /* the last row */
    int lastlen; /* its ranks */
} grid;

static grid grid_of(int p)
{
    int g = 1;
    while (g * g < p) g++;
    int last = (p - 1) / g;
    return (grid){p, g, last, p - last * g};
}

/* The relay of the piece from src to dst. */
static int relay_of(grid gr, int src, int dst)
{
    int m = src / gr.g * gr.g + dst % gr.g;
    return m < gr.p ? m : dst / gr.g * gr.g + src % gr.g;
}

/* The destinations whose pieces from src relay m carries, ascending, into
 * dst[] (when not NULL); returns their number.  O(1) when there are none. */
static int carried(grid gr, int m, int src, int *dst)
{
    int n = 0, g = gr.g;
    if (src / g == m / g) { /* same row: the column of m */
        for (int d = m % g; d < gr.p; d += g)
            if (dst) dst[n++] = d;
            else n++;
    } else if (src / g == gr.last && src % g == m % g && gr.lastlen < g) {
        /* src on the short last row: dst in m's row, past the last row's length */
        for (int d = m / g * g + gr.lastlen; d < m / g * g + g; d++)
            if (dst) dst[n++] = d;
            else n++;
    }
    return n;
}

typedef struct hops {
    pdt_comm *c;
    grid gr;
    int me;
    int *dl;            /* a list of destinations (G at most) */
    size_t *a, *b;      /* a round's counts: sent to, received from each rank */
    uint64_t *cnt_in;   /* round 1: the pieces' sizes from each src, grouped by src */
    char *s1, *r1, *s2, *r3; /* rounds 2 and 3's buffers */
} hops;

static void hops_free(hops *h)
{
    free(h->dl);
    free(h->a);
    free(h->b);
    free(h->cnt_in);
    free(h->s1);
    free(h->r1);
    free(h->s2);
    free(h->r3);
}

static pdt_status nomem(const hops *h, pdt_err *err)
{
    return pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: alltoallv in two hops: out of memory",
                       h->me);
}

static size_t sum(const size_t *v, int n)
{
    size_t s = 0;
    for (int i = 0; i < n; i++) s += v[i];
    return s;
}

/* Round 1: each relay learns the sizes of the pieces it carries, per src in
 * the order of carried(). */
static pdt_status round_counts(hops *h, const size_t *scount, pdt_err *err)
{
    int P = h->gr.p, me = h->me;
    size_t *at = calloc((size_t)P + 1, sizeof *at);
    uint64_t *out = malloc((size_t)P * sizeof *out);
    pdt_status st = at && out ? PDT_OK : nomem(h, err);
    for (int m = 0; m < P && st == PDT_OK; m++) {
        h->a[m] = (size_t)carried(h->gr, m, me, NULL) * sizeof(uint64_t);
        h->b[m] = (size_t)carried(h->gr, me, m, NULL) * sizeof(uint64_t);
        at[m + 1] = at[m] + h->a[m] / sizeof(uint64_t);
    }
    if (st == PDT_OK) {
        for (int dst = 0; dst < P; dst++) out[at[relay_of(h->gr, me, dst)]++] = scount[dst];
        h->cnt_in = malloc(sum(h->b, P) + 1);
        st = h->cnt_in ? h->c->ops->alltoallv(h->c, out, h->a, h->cnt_in, h->b, err)
                       : nomem(h, err);
    }
    free(at);
    free(out);
    return st;
}

/* Round 2: this rank's pieces to their relays (grouped by relay, in dst
 * order); each relay gets its pieces grouped by src. */
static pdt_status round_pieces(hops *h, const char *send, const size_t *scount, pdt_err *err)
{
    int P = h->gr.p, me = h->me;
    size_t *at = calloc((size_t)P + 1, sizeof *at);
    if (!at) return nomem(h, err);
    memset(h->a, 0, (size_t)P * sizeof *h->a);
    for (int dst = 0; dst < P; dst++) h->a[relay_of(h->gr, me, dst)] += scount[dst];
    const uint64_t *cnt = h->cnt_in;
    for (int src = 0; src < P; src++) {
        int n = carried(h->gr, me, src, NULL);
        h->b[src] = 0;
        for (int i = 0; i < n; i++) h->b[src] += (size_t)*cnt++;
    }
    for (int m = 0; m < P; m++) at[m + 1] = at[m] + h->a[m];
    h->s1 = malloc(at[P] + 1);
    h->r1 = malloc(sum(h->b, P) + 1);
    pdt_status st = h->s1 && h->r1 ? PDT_OK : nomem(h, err);
    size_t off = 0;
    for (int dst = 0; dst < P && st == PDT_OK; dst++) {
        int m = relay_of(h->gr, me, dst);
        memcpy(h->s1 + at[m], send + off, scount[dst]);
        at[m] += scount[dst];
        off += scount[dst];
    }
    free(at);
    if (st == PDT_OK) st = h->c->ops->alltoallv(h->c, h->s1, h->a, h->r1, h->b, err);
    free(h->s1);
    h->s1 = NULL;
    return st;
}

/* Round 3's send side: what this relay got, regrouped by dst, each dst's
 * pieces in src order; h->a its counts. */
static pdt_status regroup(hops *h, pdt_err *err)
{
    int P = h->gr.p, me = h->me;
    size_t *at = calloc((size_t)P + 1, sizeof *at);
    if (!at) return nomem(h, err);
    memset(h->a, 0, (size_t)P * sizeof *h->a);
    const uint64_t *cnt = h->cnt_in;
    for (int src = 0; src < P; src++) {
        int n = carried(h->gr, me, src, h->dl);
        for (int i = 0; i < n; i++) h->a[h->dl[i]] += (size_t)*cnt++;
    }
    for (int d = 0; d < P; d++) at[d + 1] = at[d] + h->a[d];
    h->s2 = malloc(at[P] + 1);
    if (!h->s2) {
        free(at);
        return nomem(h, err);
    }
    const char *r = h->r1;
    cnt = h->cnt_in;
    for (int src = 0; src < P; src++) {
        int n = carried(h->gr, me, src, h->dl);
        for (int i = 0; i < n; i++) {
            size_t len = (size_t)*cnt++;
            memcpy(h->s2 + at[h->dl[i]], r, len);
            at[h->dl[i]] += len;
            r += len;
        }
    }
    free(at);
    free(h->r1);
    h->r1 = NULL;
    return PDT_OK;
}

/* Round 3: the relays' pieces to their destinations.  A relay's pieces for
 * this rank come from consecutive sources; when the relays in rank order
 * hold the sources in rank order (a full grid, and most ranks of the
 * others) they land in place, else in h->r3 first. */
static pdt_status round_relay(hops *h, char *recv, const size_t *rcount, pdt_err *err)
{
    int P = h->gr.p, me = h->me, in_order = 1, prev = -1;
    memset(h->b, 0, (size_t)P * sizeof *h->b);
    for (int src = 0; src < P; src++) {
        int m = relay_of(h->gr, src, me);
        h->b[m] += rcount[src];
        in_order &= m >= prev;
        prev = m;
    }
    char *into = recv;
    if (!in_order && !(into = h->r3 = malloc(sum(rcount, P) + 1))) return nomem(h, err);
    pdt_status st = h->c->ops->alltoallv(h->c, h->s2, h->a, into, h->b, err);
    if (st != PDT_OK || in_order) return st;
    size_t *at = calloc((size_t)P + 1, sizeof *at);
    if (!at) return nomem(h, err);
    for (int m = 0; m < P; m++) at[m + 1] = at[m] + h->b[m];
    size_t off = 0;
    for (int src = 0; src < P; src++) { /* (a relay's sources arrived in src order) */
        int m = relay_of(h->gr, src, me);
        memcpy(recv + off, h->r3 + at[m], rcount[src]);
        at[m] += rcount[src];
        off += rcount[src];
    }
    free(at);
    return PDT_OK;
}

pdt_status pdt_comm_hops_alltoallv(pdt_comm *c, const void *send, const size_t *scount,
                                   void *recv, const size_t *rcount, pdt_err *err)
{
    hops h = {.c = c, .gr = grid_of(c->size), .me = c->rank};
    h.dl = malloc((size_t)h.gr.g * sizeof *h.dl);
    h.a = calloc((size_t)c->size, sizeof *h.a);
    h.b = calloc((size_t)c->size, sizeof *h.b);
    pdt_status st = h.dl && h.a && h.b ? PDT_OK : nomem(&h, err);
    if (st == PDT_OK) st = round_counts(&h, scount, err);
    if (st == PDT_OK) st = round_pieces(&h, send, scount, err);
    if (st == PDT_OK) st = regroup(&h, err);
    if (st == PDT_OK) st = round_relay(&h, recv, rcount, err);
    hops_free(&h);
    return st;
}
