/* pdt — private interface of the SRM parallel triangulation (src/par).
 *
 * Everything here is free of MPI: the driver (driver.c) moves the byte
 * buffers these functions produce and consume with the pdt_comm wrappers,
 * and a unit test can move them in-process to simulate any number of ranks.
 *
 * Vocabulary (docs/algorithm.md §3): a strip is the lexicographic block of points
 * owned by one rank; a level-l group is the rank block [j 2^l, (j+1) 2^l);
 * the merge rank of a pair (G_L, G_R) is the first rank of G_R; the holder of
 * a group keeps its hull; a pending triangle waits at one rank until the
 * merge at its "send level". */
#ifndef PDT_SRM_H
#define PDT_SRM_H

#include "pdt/common.h"
#include "pdt/par.h"
#include "pdt/trace.h"
#include <stdlib.h>

#include "pdt/bigmem.h"
#include "pdt/delaunay.h"

/* A point with its identity: global input index of its representative. */
typedef struct srm_pt {
    int32_t x, y;
    uint32_t gid;
} srm_pt;

/* The place of gid in p[0..n), sorted by gid (p[place].gid == gid when it is
 * there). */
static inline uint32_t srm_find_gid(const srm_pt *p, size_t n, uint32_t gid)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (p[mid].gid < gid) lo = mid + 1;
        else hi = mid;
    }
    return (uint32_t)lo;
}

/* Strip descriptor of one rank (allgathered after the partition). */
typedef struct srm_strip {
    uint64_t count;              /* distinct points (0 = empty strip: no box) */
    uint64_t first_key, last_key;
    int32_t xmin, xmax, ymin, ymax;
} srm_strip;

/* The regions of a bisection partition (algorithm.md §3.12): the rank
 * range [0, p) is cut into [lo, mid) and [mid, hi), mid = lo + ceil((hi -
 * lo) / 2), recursively; the points of a range with more than one rank are
 * cut by one key: left are those whose axis key is below `split` (axis 0:
 * the key (x, y) of pdt_key; axis 1: the key of (y, x)).  cut[] holds the
 * p - 1 cuts in preorder (a range's cut, then its left subtree's, then its
 * right's).  Every rank holds k strips (1 or 2; two: the rank's points cut
 * lexicographically in two halves, merged first, at level 0).  The merge
 * tree is the bisection tree: a range at depth d merges its two halves at
 * level levels_p - 1 - d (+ 1 with two strips a rank), so the groups of a
 * level are the ranges of one depth, and the merge rank of a range is the
 * first rank of its right half. */
typedef struct srm_cut {
    uint64_t split;
    int axis;
} srm_cut;

typedef struct srm_tree {
    int p, k;          /* ranks, strips a rank */
    int levels_p;      /* ceil(log2 p): the depth of the bisection tree */
    srm_cut *cut;      /* p - 1 cuts, preorder (malloc'd by its maker) */
} srm_tree;

/* The key of a point along a cut's axis. */
static inline uint64_t srm_axis_key(int axis, int32_t x, int32_t y)
{
    pdt_point q = {axis ? y : x, axis ? x : y};
    return pdt_key(q);
}

/* The middle of the rank range [lo, hi) (its left half gets the larger). */
static inline int srm_bis_mid(int lo, int hi)
{
    return lo + (hi - lo + 1) / 2;
}

/* A pending triangle (counter-clockwise) and the merge level it waits for. */
typedef struct srm_tri {
    srm_pt p[3];
    int level;
} srm_tri;

/* ---- partition.c ------------------------------------------------------- */

/* A record of the partition: key and input index. */
/* An array proportional to the input (records, points, triangles): malloc,
 * with huge pages if asked for (pdt_big_advise).  Free with free(). */
static inline void *srm_big(size_t bytes)
{
    void *p = malloc(bytes);
    if (p) pdt_big_advise(p, bytes);
    return p;
}

typedef struct srm_rec {
    uint64_t key;
    uint32_t idx;
    uint32_t pad;
} srm_rec;

/* Stable LSD radix sort of r[0..n) by key (tmp: n scratch records).  (The
 * driver's partition sorts its block with pdt_sort_unique_on; the unit tests
 * that build partitions by hand use this.) */
void pdt_srm_radix_sort(srm_rec *r, srm_rec *tmp, size_t n);

/* Remove records with equal keys keeping the first; returns the new count. */
size_t pdt_srm_dedupe(srm_rec *r, size_t n);

/* Number of records of the key-sorted r[0..n) whose key is below `key`. */
size_t pdt_srm_count_lt(const srm_rec *r, size_t n, uint64_t key);

/* Merge the k key-sorted runs r[start[i] .. start[i+1]) (i < k; start has
 * k + 1 entries and is used up) into one key-sorted array, stably: on equal
 * keys run i's records come before run i+1's.  tmp: start[k] scratch
 * records.  Returns the array that holds the result (r or tmp). */
srm_rec *pdt_srm_merge_runs(srm_rec *r, srm_rec *tmp, size_t *start, int k);

/* The same merge (k >= 1 runs) with the duplicates removed (the first of
 * equal keys kept, as pdt_srm_dedupe does), written as the strip's points
 * pt[i] and their global indices g[i] (records' idx) in one last pass, not
 * into records (r, tmp and start are used up; pt and g overlap neither).
 * Returns the number of distinct points. */
size_t pdt_srm_runs_to_strip(srm_rec *r, srm_rec *tmp, size_t *start, int k, pdt_point *pt,
                             uint32_t *g);

/* Point of a key (inverse of pdt_key). */
static inline pdt_point srm_key_point(uint64_t key)
{
    pdt_point p;
    p.x = (int32_t)((uint32_t)(key >> 32) ^ 0x80000000u);
    p.y = (int32_t)((uint32_t)key ^ 0x80000000u);
    return p;
}

static inline uint64_t srm_key(srm_pt p)
{
    pdt_point q = {p.x, p.y};
    return pdt_key(q);
}

/* ---- srm_sets.c: the merge step's sorts and look-ups -------------------- */

/* p[0..n) sorted by key; stable.  PDT_ERR_NOMEM (p unchanged) or PDT_OK. */
pdt_status pdt_srm_sort_pts(srm_pt *p, size_t n);
/* p[end[r-1], end[r]) (end[-1] = 0) are nrun runs, each in key order: p
 * in key order (end is overwritten).  PDT_ERR_NOMEM leaves p as it was. */
pdt_status pdt_srm_merge_pt_runs(srm_pt *p, size_t *end, int nrun);

/* A triangle by its vertices' global indices, rotated to start at the
 * smallest (orientation kept). */
typedef struct srm_gtri {
    uint32_t v[3];
} srm_gtri;

/* A set of such triangles (open addressing; built once, then only asked). */
typedef struct srm_tset {
    srm_gtri *slot;
    size_t mask;
} srm_tset;

/* The set of t[0..n): PDT_OK or PDT_ERR_NOMEM (then free it all the same). */
pdt_status pdt_srm_tset_init(srm_tset *s, const srm_gtri *t, size_t n);
int pdt_srm_tset_has(const srm_tset *s, srm_gtri t);
void pdt_srm_tset_free(srm_tset *s);

/* ---- touch.c: the restricted-area tests (§3.4) ------------------------- */

/* The closed circumdisk of a triangle, as touch.c computes it: centre and a
 * radius enlarged by a bound on every rounding error, so that "misses" is
 * only ever said of a box the exact disk misses (sound).  Deterministic: the
 * result depends only on the three points as a set. */
typedef struct srm_disk {
    double ox, oy;   /* centre, relative to (ax, ay) */
    double r;        /* radius, already enlarged by the error bound */
    int64_t ax, ay;  /* origin: the lexicographically smallest vertex */
    int all;         /* 1: could not bound (degenerate): touches everything */
} srm_disk;

/* The disk of the triangle (a, b, c) (any orientation, not collinear). */
void pdt_srm_disk_of(srm_disk *d, srm_pt a, srm_pt b, srm_pt c);
/* 0 only if the closed disk certainly misses the closed box; an empty
 * strip (count 0) has no box and is never touched. */
int pdt_srm_disk_touch(const srm_disk *d, const srm_strip *box);
/* An x-range certainly containing the disk (for a search by x). */
void pdt_srm_disk_xrange(const srm_disk *d, double *lo, double *hi);

/* The open box xl < x < xr, yl < y < yh around a strip that holds no point
 * of a foreign strip, so no foreign box meets it (infinite on a side with no
 * other points; strips: yl = -inf, yh = +inf, a slab). */
typedef struct srm_slab {
    double xl, xr, yl, yh;
} srm_slab;

/* The slab of rank h: from the nearest non-empty strip on each side (strips
 * are lexicographic blocks, so boxes on the left end at x <= xl). */
void pdt_srm_slab_of(srm_slab *sl, const srm_strip *strip, int p, int h);

/* The open box of strip h of a bisection run: its cell, the cuts on the
 * path to its rank (a cut's own coordinate on each side: a point left of an
 * x-cut at key (sx, sy) has x <= sx, one right of it x >= sx), and with
 * two strips a rank, the other strip's box. */
void pdt_srm_cell_of(srm_slab *sl, const srm_tree *t, const srm_strip *strip, int h);

/* A cheap pre-test, no division and no square root: 1 only if the closed
 * circumdisk of (a, b, c) (not collinear) certainly lies inside the open
 * box, so that it misses every foreign box; 0 says nothing.  The disk lies
 * within 2R of a (R its radius) and 4R^2 = l1 l2 l3 / D^2 (l: squared side
 * lengths, D = twice the signed area, exact in int64 for differences below
 * 2^29), so a.x - 2R > xl, a.x + 2R < xr and the same in y when
 * g^2 D^2 > l1 l2 l3, g the distance from a to the nearest side.  Both sides are products of positive
 * numbers, each computed with a relative error below 8 eps (eps = 2^-53);
 * the factor 1 + 2^-40 on the right makes the computed comparison imply the
 * exact one (sound: never 1 for a disk that meets the slab's outside). */
static inline int srm_disk_in_slab(const srm_slab *sl, srm_pt a, srm_pt b, srm_pt c)
{
    int64_t bx = (int64_t)b.x - a.x, by = (int64_t)b.y - a.y;
    int64_t cx = (int64_t)c.x - a.x, cy = (int64_t)c.y - a.y;
    const int64_t lim = (int64_t)1 << 29;
    if ((uint64_t)(bx + lim) >= (uint64_t)(2 * lim) || (uint64_t)(by + lim) >= (uint64_t)(2 * lim) ||
        (uint64_t)(cx + lim) >= (uint64_t)(2 * lim) || (uint64_t)(cy + lim) >= (uint64_t)(2 * lim))
        return 0;
    double gl = (double)a.x - sl->xl, gr = sl->xr - (double)a.x, g = gl < gr ? gl : gr;
    double gb = (double)a.y - sl->yl, gt = sl->yh - (double)a.y;
    g = gb < g ? gb : g;
    g = gt < g ? gt : g;
    if (!(g > 0)) return 0;
    int64_t D = bx * cy - by * cx, dx = cx - bx, dy = cy - by;
    double l1 = (double)(bx * bx + by * by), l2 = (double)(cx * cx + cy * cy),
           l3 = (double)(dx * dx + dy * dy), dd = (double)D;
    return (g * g) * (dd * dd) > (l1 * l2) * l3 * (1.0 + 0x1p-40);
}

/* Exact: 1 if the closed half-plane right of u->v (the restricted area of
 * the hull edge u->v) meets the closed box. */
int pdt_srm_edge_touch(srm_pt u, srm_pt v, const srm_strip *box);

/* ---- srm.c: the per-rank state machine --------------------------------- */

/* The header of a merge message (native byte order: a homogeneous cluster
 * is assumed); every count and the payload's size in 64 bits. */
#define SRM_MSG_MAGIC 0x4d525350u /* "PSRM" */
typedef struct srm_msg_head {
    uint32_t magic, level, flags, reserved;
    uint64_t npts, ntri, nhull; /* point table, shipped triangles, hull vertices */
    uint64_t payload;           /* bytes after the header */
    double cp, cp_cpu;          /* the sender's critical path (wall, CPU) */
} srm_msg_head;

enum { SRM_MSG_HAS_HULL = 1, SRM_MSG_HULL_DEGENERATE = 2 }; /* srm_msg_head.flags */

/* A decoded blob (srm_codec.c; arrays owned: pdt_srm_msg_free). */
typedef struct srm_msg_view {
    srm_msg_head h;
    srm_pt *pts;
    uint32_t *tri;  /* 3 * ntri positions, then nhull positions */
    uint32_t *hull;
} srm_msg_view;

typedef struct srm_counts {
    uint64_t local_tris, final_at_once, deferred, shipped, merges, border_max, kept, discarded,
        final_merge;
    uint64_t border_level[PDT_PAR_MAX_LEVELS]; /* largest |B| of a merge here, per level */
    uint64_t shared, share_fallbacks; /* merges here shared along the seam; of those
                                       * planned, the ones this rank did alone */
    double critical_path; /* compute seconds along the longest dependent chain */
    double critical_cpu;  /* the same chain in CPU seconds (insensitive to load) */
} srm_counts;

typedef struct srm_rank {
    int rank, p, levels;          /* levels = ceil(log2 p) */
    int as_strips;                /* 1: the strips of one plain run (plain.c), 0: ranks */
    int per_rank;                 /* strips per rank in an MPI run (0, 1: one) */
    char who[64];                 /* how messages name it (pdt_srm_name) */
    const srm_strip *strip;       /* p descriptors (not owned) */
    const srm_tree *tree;         /* bisection regions (not owned), NULL: strips */
    srm_strip *nbox;              /* with a tree: the box of every rank range, preorder */
    int *nonempty;                /* ranks with points, in order (x-sorted boxes) */
    int nne;
    /* output: final triangles as global indices, CCW: the local phase's in
     * fin (the kernel's own array, no room to spare), the merges' in more */
    pdt_tri *fin;
    size_t nfin, capfin;
    pdt_tri *more;
    size_t nmore, capmore;
    /* pending triangles held here */
    srm_tri *pend;
    size_t npend, cappend;
    /* hull of the group this rank holds (valid if holds_hull) */
    srm_pt *hull;
    size_t nhull;
    int hull_degenerate, holds_hull;
    /* relay (bisection): a group's pending triangles travel up the merge tree
     * with its hull, so that a merge gets two messages, from the holders of
     * its halves; fwd holds the blobs this holder carries for later levels */
    int relay;
    unsigned char *fwd;
    size_t nfwd, capfwd;
    /* the order phase's histogram (not owned; NULL: none): each final
     * triangle of the local phase is rotated to start at its smallest index
     * and counted in bucket v[0] >> order_shift as classify makes it (what
     * pdt_tri_bucket_count would do in a pass of its own, done while the
     * triangle is in the registers) */
    uint64_t *order_hist;
    int order_shift;
    srm_counts cnt;
    pdt_trace *tr;
    double (*clock)(void *);      /* seconds, for the counts */
    void *clock_user;
} srm_rank;

/* The descriptor of a strip of m distinct points in lexicographic order. */
srm_strip pdt_srm_strip_of(const pdt_point *pts, size_t m);

/* How messages name participant r of s's run: "rank R", or "strip R+1 of
 * P" among the strips of a plain run (s->as_strips). */
void pdt_srm_name(const srm_rank *s, int r, char *buf, size_t cap);

/* The strips a rank of an MPI run holds (driver.c: rank_strips), at most: */
#define PDT_RANK_MAX_STRIPS 2

/* After pdt_srm_init in an MPI run whose ranks hold k strips each: s and the
 * others are named by rank and strip ("rank 1 (strip 2 of 2)"). */
void pdt_srm_per_rank(srm_rank *s, int k);

/* After pdt_srm_init in a plain run: s and the others are named as strips. */
void pdt_srm_as_strips(srm_rank *s);

/* Set up (strip: p descriptors, kept by pointer).  Frees with pdt_srm_free. */
pdt_status pdt_srm_init(srm_rank *s, int rank, int p, const srm_strip *strip, pdt_trace *tr,
                    pdt_err *err);
void pdt_srm_free(srm_rank *s);

/* Phases 1 and 2 on the local strip: pts[0..m) distinct and lex-sorted,
 * gid[i] the global index of pts[i].  Lift-up (traced), kernel (run 0),
 * strip hull (traced pushes and pops), classification.  Memory: block, a
 * malloc'd array of at least PDT_DELAUNAY_WORK(m) bytes, becomes s->fin
 * (owned by s from the call on, success or not: the kernel's edges, then the
 * final triangles at its front, capfin triangles of room); pts (given back
 * unchanged), gid and id (m + 1 words of scratch) lie beyond its first
 * PDT_DELAUNAY_WORK(m) bytes (in the same block or elsewhere).  Nothing
 * else of size m is allocated. */
pdt_status pdt_srm_local(srm_rank *s, void *block, pdt_point *pts, const uint32_t *gid,
                         uint32_t *id, size_t m, pdt_err *err);

/* Merge schedule.  The pair merged at `level` that contains rank r:
 * G_L = [gl, gr), G_R = [gr, ge); returns 0 if r's group has no partner at
 * this level (nothing happens), else 1.  Merge rank = gr. */
int pdt_srm_pair(int r, int p, int level, int *gl, int *gr, int *ge);
/* The rank holding the hull of the level-`level` group that contains r. */
int pdt_srm_holder(int r, int p, int level);

/* Message from this rank to the merge rank of `level`: its pending
 * triangles waiting for that level (removed here), its hull if it holds the
 * hull of G_L or G_R, and its critical path so far.  *buf malloc'd (caller
 * frees).  Every rank of the pair sends one, possibly empty.
 *
 * A message is a sequence of blobs, each a header and its payload: one
 * without relay (the triangles of `level`).  With relay (s->relay, the
 * bisection's merge tree) only the holders of the pair's two groups send
 * (a rank that holds nothing gets *buf NULL): a blob for `level` (with the
 * hull), one for each later level it has pending triangles for, and the
 * blobs it carries for later levels (s->fwd), as they came. */
pdt_status pdt_srm_pack(srm_rank *s, int level, void **buf, size_t *len, pdt_err *err);

/* Reading a message (srm_codec.c): the blob of `level` of len bytes at buf,
 * decoded into v, or PDT_ERR_CORRUPT naming `from`; freed by
 * pdt_srm_msg_free.  pdt_srm_blob_at: 1 if a whole blob begins at b (left
 * bytes to the message's end), its header in *h.  pdt_srm_carry: keep n
 * bytes of blobs for a later level in s->fwd (relay). */
pdt_status pdt_srm_msg_decode(const void *buf, size_t len, int level, const char *from,
                              srm_msg_view *v, pdt_err *err);
void pdt_srm_msg_free(srm_msg_view *v);
int pdt_srm_blob_at(const unsigned char *b, size_t left, srm_msg_head *h);
pdt_status pdt_srm_carry(srm_rank *s, const unsigned char *b, size_t n);

/* At the merge rank: merge the messages of every rank of the pair
 * (msg[i] from rank gl + i, i = 0 .. ge-gl-1, including this rank's own;
 * with relay NULL but for the two holders, whose blobs for later levels
 * this rank then carries).
 * Shipped sets, border set, lift-up, kernel (run 1), selection, discards,
 * hull merge, reclassification.  The critical path continues from the
 * longest one among the senders (carried in the messages). */
pdt_status pdt_srm_merge(srm_rank *s, int level, void *const *msg, const size_t *len,
                     pdt_err *err);

/* ceil(log2 p): the number of merge levels. */
int pdt_srm_ceil_log2(int p);

/* The schedule of either partition: t NULL for strips (the rank blocks
 * above, np participants), else the bisection tree t (np = t->p * t->k
 * strips).  The same contracts as pdt_srm_pair and pdt_srm_holder. */
int pdt_srm_pair_of(const srm_tree *t, int g, int np, int level, int *gl, int *gr, int *ge);
int pdt_srm_holder_of(const srm_tree *t, int g, int np, int level);
/* The number of merge levels. */
int pdt_srm_levels_of(const srm_tree *t, int np);
/* The level whose merge first puts participants q != h in one group. */
int pdt_srm_meet_of(const srm_tree *t, int q, int h);
/* The cut between the halves of the rank range [lo, hi) of t (a range of
 * the tree with hi - lo >= 2). */
srm_cut pdt_srm_cut_of(const srm_tree *t, int lo, int hi);

/* After pdt_srm_init: s works on the bisection tree t (kept by pointer;
 * t->p * t->k == s->p) instead of strips' rank blocks. */
pdt_status pdt_srm_use_tree(srm_rank *s, const srm_tree *t, pdt_err *err);

/* ---- srm_share.c: one merge shared by several ranks along its seam ----- */

/* The ranks that share a merge (algorithm.md §3.13): only in a bisection,
 * untraced, when the merged group's points promise a border set of at least
 * two pieces (PDT_SHARE_PIECE points each, 500 unless set; 0: never).
 * rank[0] is the merge rank; the others are ranks of the merged group,
 * spread over it.  Every rank of the group computes the same plan. */
#define PDT_SHARE_MAX 64
typedef struct srm_share_plan {
    int n;                     /* ranks sharing (0: the merge rank alone) */
    int gl, gr, ge;            /* the pair of the level, as pdt_srm_pair_of */
    int rank[PDT_SHARE_MAX];
} srm_share_plan;

/* The plan of the merge at `level` of s's group: 1 if shared, else 0. */
int pdt_srm_share_plan(const srm_rank *s, int level, srm_share_plan *pl);

typedef struct srm_job srm_job;

/* The finals a sharing rank found, kept until the verdict. */
typedef struct srm_held {
    pdt_tri *t;
    size_t n;
} srm_held;

/* At the merge rank: open the merge (messages as pdt_srm_merge; the border
 * set and the merged hull are made), cut B into n pieces (piece[i] for
 * plan.rank[i], malloc'd), read the n replies (*ok: 1 if they hold the
 * whole selection), and close: with !ok the merge rank runs the rest of the
 * step itself.  *job is freed by close, whatever st (the status so far). */
pdt_status pdt_srm_share_open(srm_rank *s, int level, void *const *msg, const size_t *len,
                              srm_job **job, pdt_err *err);
pdt_status pdt_srm_share_pieces(srm_job *j, int n, void **piece, size_t *plen);
pdt_status pdt_srm_share_join(srm_job *j, void *const *reply, const size_t *rlen, int n, int *ok);
pdt_status pdt_srm_share_close(srm_job *j, int ok, pdt_status st);

/* At each sharing rank (the merge rank too): the piece's triangles, the
 * reply for the merge rank (malloc'd) and the finals held; then, told the
 * verdict, the finals kept (ok) or dropped, and held emptied. */
pdt_status pdt_srm_share_work(srm_rank *s, const void *piece, size_t len, void **reply,
                              size_t *rlen, srm_held *held, pdt_err *err);
pdt_status pdt_srm_share_commit(srm_rank *s, srm_held *held, int ok);

/* ---- plain.c: the plain run on strips, one after the other ---------------- */

#define PDT_PLAIN_MAX_STRIPS 16

/* The pipeline of pdt_triangulate_inplace (PDT_PTS_SPEND, untraced) run as
 * SRM on k >= 2 strips of the sorted points, one strip after the other in one
 * block: strip s's kernel writes its final triangles where strip s-1's end,
 * so the block holds the edges of one strip and the triangles found so far
 * instead of the edges of all points (62 bytes per point at the peak instead
 * of 84 with k = 2).  The triangles and stats are those of
 * pdt_triangulate_inplace (the SRM's output is T* for any number of strips);
 * pts[] are spent.  With `prefault` a second thread faults the block in
 * ahead of use. */
pdt_status pdt_srm_plain(pdt_point *pts, size_t n, int k, int prefault, pdt_tri **tris,
                         size_t *ntri, pdt_tri_stats *stats, pdt_err *err);

/* Whether two strips pay on these n input points: 0 when a sample of 4096 of
 * them, triangulated and cut in two by count, leaves more than a quarter of
 * its triangles to the merge (points in convex position, a narrow column:
 * there the merge redoes most of the work, 6x the time and 3.5x the memory
 * of the whole kernel on 2.2*10^6 points of a parabola); 1 otherwise, and
 * for fewer than 16384 points. */
int pdt_srm_plain_pays(const pdt_point *pts, size_t n);

/* The message codec (srm_codec.c): LEB128 varints.  put writes v at b (at
 * most 10 bytes) and returns their count; get reads one at *p (< end) and
 * returns 0 on a truncated or over-long one; zigzag maps a signed value to
 * an unsigned one that is small when |v| is. */
size_t pdt_srm_put_varint(unsigned char *b, uint64_t v);
int pdt_srm_get_varint(const unsigned char **p, const unsigned char *end, uint64_t *v);
uint64_t pdt_srm_zigzag(int64_t v);

#endif
