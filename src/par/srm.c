/* pdt — SRM per rank: local phase, classification, merge steps
 * (docs/algorithm.md §3.3–3.8).  No MPI here: messages are byte buffers that the
 * driver moves.
 *
 * Correctness rests on the Merge Lemma (§3.8): at the merge of G_L and G_R the
 * border set B must contain every vertex of every shipped triangle AND the
 * endpoints of every hull edge of G_L whose restricted area (the closed
 * half-plane outside the edge) meets a box of G_R (all of G_L if its hull is
 * degenerate), and symmetrically.  Then T*(G) = (unshipped triangles) ∪
 * {t in T*(B) : t has vertices in both groups, or t was shipped}. */
#include "srm_int.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "pdt/delaunay.h"
#include "pdt/hull.h"
#include "pdt/predicates.h"

/* ---- small helpers ------------------------------------------------------- */

static int msb(unsigned v)
{
    return 31 - __builtin_clz(v);
}

static double now(const srm_rank *s)
{
    return s->clock ? s->clock(s->clock_user) : 0.0;
}

/* CPU seconds of this thread (pdt_srm_local and pdt_srm_merge never wait for
 * messages, so this is their compute time whatever the machine's load). */
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static pdt_status nomem(pdt_err *err, const char *who, const char *what)
{
    return pdt_err_set(err, PDT_ERR_NOMEM, "%s: %s: out of memory", who, what);
}

/* realloc for arrays that may be large: a large new block is advised
 * (srm_big) BEFORE the old contents are copied into it (realloc would copy
 * first and advise after). */
static void *big_realloc(void *p, size_t old_bytes, size_t bytes)
{
    if (bytes < ((size_t)2 << 20)) return realloc(p, bytes);
    void *q = srm_big(bytes);
    if (!q) return NULL;
    if (old_bytes) memcpy(q, p, old_bytes < bytes ? old_bytes : bytes);
    free(p);
    return q;
}

static pdt_status grow(void **p, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap) return PDT_OK;
    size_t c = *cap ? *cap : 64;
    while (c < need) c *= 2;
    void *q = big_realloc(*p, *cap * size, c * size);
    if (!q) return PDT_ERR_NOMEM;
    *p = q;
    *cap = c;
    return PDT_OK;
}

pdt_status pdt_srm_add_final(srm_rank *s, srm_pt a, srm_pt b, srm_pt c)
{
    if (grow((void **)&s->more, &s->capmore, s->nmore + 1, sizeof *s->more))
        return PDT_ERR_NOMEM;
    s->more[s->nmore++] = (pdt_tri){{a.gid, b.gid, c.gid}};
    PDT_TRACE(s->tr, 1, PDT_EV_TRI_FINAL, 0, a.gid, b.gid, c.gid, 0);
    return PDT_OK;
}

pdt_status pdt_srm_add_finals(srm_rank *s, const pdt_tri *t, size_t n)
{
    if (grow((void **)&s->more, &s->capmore, s->nmore + n, sizeof *s->more))
        return PDT_ERR_NOMEM;
    if (n) memcpy(s->more + s->nmore, t, n * sizeof *t);
    s->nmore += n;
    s->cnt.final_merge += n;
    return PDT_OK;
}

pdt_status pdt_srm_add_pending(srm_rank *s, srm_pt a, srm_pt b, srm_pt c, int level)
{
    if (grow((void **)&s->pend, &s->cappend, s->npend + 1, sizeof *s->pend))
        return PDT_ERR_NOMEM;
    srm_tri *t = &s->pend[s->npend++];
    t->p[0] = a;
    t->p[1] = b;
    t->p[2] = c;
    t->level = level;
    return PDT_OK;
}

/* The classification of a triangle held at rank h whose group has level
 * `from`: -1 if its restricted area misses every box outside that group
 * (final), else the first merge level whose partner group holds a box it
 * touches (*who = that rank). */
static int send_level_tree(const srm_rank *s, int h, int from, const srm_disk *d, int *who);

int pdt_srm_send_level(const srm_rank *s, int h, int from, srm_pt a, srm_pt b, srm_pt c,
                       int *who)
{
    srm_disk d;
    pdt_srm_disk_of(&d, a, b, c);
    if (s->tree) return send_level_tree(s, h, from, &d, who);
    double lo, hi;
    pdt_srm_disk_xrange(&d, &lo, &hi);
    /* boxes of non-empty strips are ordered in x: binary search the first
     * whose xmax reaches lo, walk while xmin <= hi */
    int l = 0, r = s->nne;
    while (l < r) {
        int mid = (l + r) / 2;
        if ((double)s->strip[s->nonempty[mid]].xmax < lo) l = mid + 1;
        else r = mid;
    }
    int best = -1;
    *who = -1;
    for (int i = l; i < s->nne; i++) {
        int q = s->nonempty[i];
        const srm_strip *bx = &s->strip[q];
        if ((double)bx->xmin > hi) break;
        if (q == h) continue;
        int lev = msb((unsigned)(q ^ h));
        if (lev < from) continue;                  /* inside the group already */
        if (best >= 0 && lev >= best) continue;    /* cannot improve */
        if (pdt_srm_disk_touch(&d, bx)) {
            best = lev;
            *who = q;
        }
    }
    return best;
}

/* With a bisection tree: whether the disk touches a box of a strip of
 * the ranks [lo, hi) (the range's preorder cut `at`; *who = that strip),
 * ranges whose box it misses skipped whole. */
static int range_touch(const srm_rank *s, const srm_disk *d, int lo, int hi, int at, int *who)
{
    int k = s->tree->k;
    if (hi - lo == 1) {
        for (int q = lo * k; q < lo * k + k; q++)
            if (s->strip[q].count && pdt_srm_disk_touch(d, &s->strip[q])) {
                *who = q;
                return 1;
            }
        return 0;
    }
    if (!s->nbox[at].count || !pdt_srm_disk_touch(d, &s->nbox[at])) return 0;
    int mid = srm_bis_mid(lo, hi);
    return range_touch(s, d, lo, mid, at + 1, who) ||
           range_touch(s, d, mid, hi, at + mid - lo, who);
}

/* send_level on the bisection tree: the ranges met on the way down to h's
 * rank each have a sibling that joins h's group at the range's level; the
 * lowest level from `from` on whose sibling holds a touched box. */
static int send_level_tree(const srm_rank *s, int h, int from, const srm_disk *d, int *who)
{
    const srm_tree *t = s->tree;
    int k = t->k, off = k > 1, r = h / k, lo = 0, hi = t->p, at = 0, n = 0;
    int lev[32], slo[32], shi[32], sat[32];
    *who = -1;
    for (int dep = 0; hi - lo >= 2; dep++, n++) {
        int mid = srm_bis_mid(lo, hi);
        lev[n] = t->levels_p - 1 - dep + off;
        if (r < mid) {
            slo[n] = mid, shi[n] = hi, sat[n] = at + mid - lo;
            hi = mid;
            at += 1;
        } else {
            slo[n] = lo, shi[n] = mid, sat[n] = at + 1;
            at += mid - lo;
            lo = mid;
        }
    }
    if (off && from <= 0) { /* the rank's other strip joins at level 0 */
        const srm_strip *o = &s->strip[h ^ 1];
        if (o->count && pdt_srm_disk_touch(d, o)) {
            *who = h ^ 1;
            return 0;
        }
    }
    for (int i = n - 1; i >= 0; i--)
        if (lev[i] >= from && range_touch(s, d, slo[i], shi[i], sat[i], who)) return lev[i];
    return -1;
}

/* ---- set-up ---------------------------------------------------------------- */

srm_strip pdt_srm_strip_of(const pdt_point *pts, size_t m)
{
    srm_strip st = {m, 0, 0, 0, 0, 0, 0};
    if (m == 0) return st;
    st.first_key = pdt_key(pts[0]);
    st.last_key = pdt_key(pts[m - 1]);
    st.xmin = pts[0].x;
    st.xmax = pts[m - 1].x;
    st.ymin = st.ymax = pts[0].y;
    for (size_t i = 1; i < m; i++) {
        if (pts[i].y < st.ymin) st.ymin = pts[i].y;
        if (pts[i].y > st.ymax) st.ymax = pts[i].y;
    }
    return st;
}

void pdt_srm_name(const srm_rank *s, int r, char *buf, size_t cap)
{
    if (s->as_strips) snprintf(buf, cap, "strip %d of %d", r + 1, s->p);
    else if (s->per_rank > 1)
        snprintf(buf, cap, "rank %d (strip %d of %d)", r / s->per_rank, r % s->per_rank + 1,
                 s->per_rank);
    else snprintf(buf, cap, "rank %d", r);
}

void pdt_srm_per_rank(srm_rank *s, int k)
{
    s->per_rank = k;
    pdt_srm_name(s, s->rank, s->who, sizeof s->who);
}

void pdt_srm_as_strips(srm_rank *s)
{
    s->as_strips = 1;
    pdt_srm_name(s, s->rank, s->who, sizeof s->who);
}

pdt_status pdt_srm_init(srm_rank *s, int rank, int p, const srm_strip *strip, pdt_trace *tr,
                    pdt_err *err)
{
    memset(s, 0, sizeof *s);
    s->rank = rank;
    s->p = p;
    pdt_srm_name(s, rank, s->who, sizeof s->who);
    s->levels = pdt_srm_ceil_log2(p);
    s->strip = strip;
    s->tr = tr;
    s->nonempty = malloc((size_t)p * sizeof *s->nonempty);
    if (!s->nonempty) return nomem(err, s->who, "init");
    for (int q = 0; q < p; q++)
        if (strip[q].count) s->nonempty[s->nne++] = q;
    return PDT_OK;
}

/* b grown to hold box x too (an empty x adds nothing; an empty b takes x). */
static void box_add(srm_strip *b, const srm_strip *x)
{
    if (!x->count) return;
    if (!b->count || x->xmin < b->xmin) b->xmin = x->xmin;
    if (!b->count || x->xmax > b->xmax) b->xmax = x->xmax;
    if (!b->count || x->ymin < b->ymin) b->ymin = x->ymin;
    if (!b->count || x->ymax > b->ymax) b->ymax = x->ymax;
    b->count += x->count;
}

/* The box of every rank range of the tree with two ranks or more (its
 * preorder cut `at`), from the strips' boxes; returns the range's. */
static srm_strip box_build(srm_rank *s, int lo, int hi, int at)
{
    int k = s->tree->k;
    srm_strip b = {0, 0, 0, 0, 0, 0, 0}, part[2];
    int nparts = 0;
    if (hi - lo == 1) {
        for (int q = lo * k; q < lo * k + k; q++) part[nparts++] = s->strip[q];
    } else {
        int mid = srm_bis_mid(lo, hi);
        part[nparts++] = box_build(s, lo, mid, at + 1);
        part[nparts++] = box_build(s, mid, hi, at + mid - lo);
    }
    for (int i = 0; i < nparts; i++) box_add(&b, &part[i]);
    if (hi - lo >= 2) s->nbox[at] = b;
    return b;
}

pdt_status pdt_srm_use_tree(srm_rank *s, const srm_tree *t, pdt_err *err)
{
    s->tree = t;
    s->relay = 1;
    s->levels = pdt_srm_levels_of(t, s->p);
    free(s->nbox);
    s->nbox = malloc((size_t)t->p * sizeof *s->nbox);
    if (!s->nbox) return nomem(err, s->who, "init");
    box_build(s, 0, t->p, 0);
    return PDT_OK;
}

void pdt_srm_free(srm_rank *s)
{
    free(s->nbox);
    free(s->nonempty);
    free(s->fin);
    free(s->more);
    free(s->pend);
    free(s->hull);
    free(s->fwd);
    memset(s, 0, sizeof *s);
}

/* ---- Phases 1 and 2 ----------------------------------------------------------- */

/* A strip's points during the local phase: pts[j] is called name[j] (its
 * global index); ntri triangles at the block's front name positions j. */
typedef struct strip_pts {
    pdt_point *pts;
    const uint32_t *name;
    size_t m, ntri;
} strip_pts;

/* The lift-up, as events only (the kernel lifts on the fly). */
static void lift_up(srm_rank *s, const pdt_point *pts, const uint32_t *gid, size_t m)
{
    pdt_trace *tr = s->tr;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_LIFT, 0, 0, 0, 0);
    if (PDT_TRACING(tr, 1))
        for (size_t i = 0; i < m; i++) {
            uint64_t z = (uint64_t)((int64_t)pts[i].x * pts[i].x) +
                         (uint64_t)((int64_t)pts[i].y * pts[i].y);
            PDT_TRACE(tr, 1, PDT_EV_LIFT, 0, gid[i], 0, 0, (int64_t)z);
        }
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_LIFT, 0, 0, 0, 0);
}

/* The local kernel, in the block, on the strip's own points (no copy).
 * Traced: the points are put back in their order afterwards, named gid[j],
 * and *kh = NULL (the chain makes the strip hull: its events are part of the
 * lesson).  Untraced: the points stay in the kernel's order, named id[v]
 * (the global indices moved along with them), the triangles come out in that
 * order (read by the classification with the points near each other in
 * memory), and *kh is the triangulation's outer face (NULL for a degenerate
 * strip, whose points are then back in their order). */
static pdt_status local_kernel(srm_rank *s, void *block, const uint32_t *gid, uint32_t *id,
                               strip_pts *sp, uint32_t **kh, size_t *nkh, pdt_err *err)
{
    pdt_trace *tr = s->tr;
    size_t m = sp->m;
    pdt_status st;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_KERNEL, 0, 0, 0, 0);
    if (PDT_TRACING(tr, 1)) {
        const uint32_t *saved = tr->gid;
        tr->gid = gid;
        st = pdt_delaunay_hull_on(sp->pts, m, id, block, PDT_DELAUNAY_WORK(m), &sp->ntri, NULL,
                                  NULL, 0, tr);
        tr->gid = saved;
    } else {
        memcpy(id, gid, m * sizeof *id);
        st = pdt_delaunay_strip(sp->pts, m, id, block, PDT_DELAUNAY_WORK(m), &sp->ntri, kh, nkh);
        sp->name = *kh ? id : gid;
    }
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_KERNEL, 0, 0, 0, 0);
    if (st != PDT_OK)
        return pdt_err_set(err, st, "%s: local kernel failed (%s)", s->who,
                           pdt_status_str(st));
    s->cnt.local_tris = sp->ntri;
    return PDT_OK;
}

/* The strip hull into s->hull: the kernel's (kh, freed here), or the
 * monotone chain's (Graham's scan with the origin at infinity, its stack in
 * the kernel's id scratch) when traced or degenerate (the chain says how). */
static pdt_status strip_hull(srm_rank *s, const strip_pts *sp, const uint32_t *gid, uint32_t *id,
                             uint32_t *kh, size_t nkh, pdt_err *err)
{
    pdt_trace *tr = s->tr;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_HULL, 0, 0, 0, 0);
    uint32_t *h = kh ? kh : id;
    size_t nh = nkh;
    int deg = 0;
    if (!kh) {
        const uint32_t *saved = tr ? tr->gid : NULL;
        if (tr) tr->gid = gid;
        pdt_status st = pdt_hull_chain(sp->pts, sp->m, h, &nh, &deg, PDT_STACK_LOWER,
                                       PDT_STACK_UPPER, tr);
        if (tr) tr->gid = saved;
        if (st != PDT_OK) return pdt_err_set(err, st, "%s: strip hull failed", s->who);
    }
    s->hull = malloc((nh + 1) * sizeof *s->hull);
    if (!s->hull) {
        free(kh);
        return nomem(err, s->who, "hull");
    }
    for (size_t i = 0; i < nh; i++)
        s->hull[i] = (srm_pt){sp->pts[h[i]].x, sp->pts[h[i]].y, sp->name[h[i]]};
    free(kh);
    s->nhull = nh;
    s->hull_degenerate = deg;
    s->holds_hull = 1;
    PDT_TRACE(tr, 1, PDT_EV_HULL, 0, nh, deg, 0, 0);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_HULL, 0, 0, 0, 0);
    return PDT_OK;
}

/* Classification: final at once, or deferred until a merge level (with no
 * other strip at all, everything is final without a test).  The final
 * triangles stay in the kernel's array, renamed to global indices and moved
 * down over the deferred ones (k <= i): s->fin, no second array; with
 * s->order_hist they are rotated and counted for the order phase. */
static pdt_status classify(srm_rank *s, pdt_tri *tris, const strip_pts *sp, pdt_err *err)
{
    pdt_trace *tr = s->tr;
    const pdt_point *pts = sp->pts;
    const uint32_t *name = sp->name;
    size_t ntri = sp->ntri;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_CLASSIFY, 0, 0, 0, 0);
    int alone = s->nne == 0 || (s->nne == 1 && s->nonempty[0] == s->rank);
    srm_slab slab; /* most triangles are settled by the cheap slab test */
    if (s->tree) pdt_srm_cell_of(&slab, s->tree, s->strip, s->rank);
    else pdt_srm_slab_of(&slab, s->strip, s->p, s->rank);
    size_t k = 0;
    uint64_t *hist = s->order_hist;
    int shift = s->order_shift;
    enum { AHEAD = 16 }; /* the triangles are in the kernel's (leaf) order:
                          * fetch ahead (traced: the points in their own) */
    for (size_t i = 0; i < ntri; i++) {
        if (i + AHEAD < ntri)
            for (int e = 0; e < 3; e++) {
                uint32_t j = tris[i + AHEAD].v[e];
                __builtin_prefetch(&pts[j]);
                __builtin_prefetch(&name[j]);
            }
        srm_pt v[3];
        for (int e = 0; e < 3; e++) {
            uint32_t j = tris[i].v[e];
            v[e] = (srm_pt){pts[j].x, pts[j].y, name[j]};
        }
        int who;
        int lev = alone || srm_disk_in_slab(&slab, v[0], v[1], v[2])
                      ? -1
                      : pdt_srm_send_level(s, s->rank, 0, v[0], v[1], v[2], &who);
        if (lev < 0) {
            pdt_tri t = {{v[0].gid, v[1].gid, v[2].gid}};
            if (hist) {
                t = pdt_tri_smallest_first(t);
                hist[t.v[0] >> shift]++;
            }
            tris[k++] = t;
            PDT_TRACE(tr, 1, PDT_EV_TRI_FINAL, 0, v[0].gid, v[1].gid, v[2].gid, 0);
        } else {
            if (pdt_srm_add_pending(s, v[0], v[1], v[2], lev) != PDT_OK)
                return nomem(err, s->who, "classify");
            s->cnt.deferred++;
            PDT_TRACE(tr, 1, PDT_EV_RA_DEFER, 0, v[0].gid, v[1].gid, v[2].gid, who);
        }
    }
    s->cnt.final_at_once = k;
    s->nfin = k;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_CLASSIFY, 0, 0, 0, 0);
    return PDT_OK;
}

pdt_status pdt_srm_local(srm_rank *s, void *block, pdt_point *pts, const uint32_t *gid,
                         uint32_t *id, size_t m, pdt_err *err)
{
    double t0 = now(s), c0 = cpu_now();
    free(s->fin); /* (none: the local phase comes first) */
    s->fin = block; /* the block is this rank's from here on */
    s->nfin = 0;
    s->capfin = PDT_DELAUNAY_WORK(m) / sizeof *s->fin;
    strip_pts sp = {pts, gid, m, 0};
    uint32_t *kh = NULL;
    size_t nkh = 0;
    lift_up(s, pts, gid, m);
    pdt_status st = local_kernel(s, block, gid, id, &sp, &kh, &nkh, err);
    if (st == PDT_OK) st = strip_hull(s, &sp, gid, id, kh, nkh, err);
    if (st == PDT_OK) st = classify(s, s->fin, &sp, err);
    s->cnt.critical_path += now(s) - t0;
    s->cnt.critical_cpu += cpu_now() - c0;
    return st;
}

/* ---- the merge's look-ups ---------------------------------------------------- */

static int cmp_gid(const void *a, const void *b)
{
    uint32_t x = ((const srm_pt *)a)->gid, y = ((const srm_pt *)b)->gid;
    return x < y ? -1 : x > y;
}

/* ---- the merge step ------------------------------------------------------------ */

static int cmp_gtri(const void *x, const void *y)
{
    const gtri *a = x, *b = y;
    for (int k = 0; k < 3; k++)
        if (a->v[k] != b->v[k]) return a->v[k] < b->v[k] ? -1 : 1;
    return 0;
}

static int cmp_key(const void *a, const void *b)
{
    uint64_t x = srm_key(*(const srm_pt *)a), y = srm_key(*(const srm_pt *)b);
    return x < y ? -1 : x > y;
}

/* The box around the boxes of strips [q0, q1) (count 0: all empty). */
static srm_strip boxes_around(const srm_rank *s, int q0, int q1)
{
    srm_strip all = {0, 0, 0, 0, 0, 0, 0};
    for (int q = q0; q < q1; q++) box_add(&all, &s->strip[q]);
    return all;
}

/* Collect the facing hull vertices of one side into B: endpoints of every
 * hull edge whose outer half-plane meets a box of the other side (all points
 * if the hull is degenerate).  An edge whose half-plane misses the box
 * around them all misses each of them (a closed half-plane meets a box when
 * it holds a corner): at the top of 1024 ranks most of a side's hull edges
 * face away from the other's 1024 boxes, whose exact tests one by one took
 * 1.4 ms of the top merge step (0.4 ms now). */
static size_t facing(const srm_rank *s, const srm_msg_view *hv, int q0, int q1, srm_pt *out)
{
    size_t n = 0, k = hv->h.nhull;
    const uint32_t *h = hv->hull;
    if (hv->h.flags & SRM_MSG_HULL_DEGENERATE) {
        for (size_t i = 0; i < k; i++) out[n++] = hv->pts[h[i]];
        return n;
    }
    srm_strip around = boxes_around(s, q0, q1);
    for (size_t i = 0; i < k; i++) {
        srm_pt u = hv->pts[h[i]], w = hv->pts[h[(i + 1) % k]];
        if (!pdt_srm_edge_touch(u, w, &around)) continue;
        for (int q = q0; q < q1; q++)
            if (s->strip[q].count && pdt_srm_edge_touch(u, w, &s->strip[q])) {
                out[n++] = u;
                out[n++] = w;
                break;
            }
    }
    return n;
}

static void job_free(srm_job *j)
{
    for (int i = 0; j->mv && i < j->nmv; i++) pdt_srm_msg_free(&j->mv[i]);
    free(j->mv);
    free(j->mv_from);
    free(j->shipped);
    pdt_srm_tset_free(&j->sset);
    pdt_srm_tset_free(&j->tset);
    free(j->tb);
    free(j->B);
    free(j->bp);
    free(j->bg);
    free(j->tris);
    free(j->ship_lo);
}

/* Split the messages into blobs: this level's are decoded into j->mv, a
 * later level's carried on (relay only); a message without relay is one
 * blob, of this level. */
static pdt_status split_messages(srm_job *j, void *const *msg, const size_t *len)
{
    srm_rank *s = j->s;
    int nblob = 0;
    for (int pass = 0; pass < 2; pass++) {
        for (int i = 0; i < j->nm; i++) {
            if (!msg[i] && s->relay) continue;
            char from[40];
            pdt_srm_name(s, j->gl + i, from, sizeof from);
            const unsigned char *b = msg[i];
            size_t left = msg[i] ? len[i] : 0;
            int first = 1;
            do {
                srm_msg_head h;
                if (!pdt_srm_blob_at(b, left, &h) || (!s->relay && (!first || h.level != (uint32_t)j->level)) ||
                    h.level < (uint32_t)j->level || h.level >= (uint32_t)s->levels)
                    return pdt_err_set(j->err, PDT_ERR_CORRUPT, "merge message from %s: bad "
                                       "header", from);
                size_t n = sizeof h + (size_t)h.payload;
                if (h.level != (uint32_t)j->level) {
                    if (pass == 1 && pdt_srm_carry(s, b, n) != PDT_OK) return nomem(j->err, s->who, "merge");
                } else if (pass == 0) {
                    nblob++;
                } else {
                    j->mv_from[j->nmv] = j->gl + i;
                    pdt_status st = pdt_srm_msg_decode(b, n, j->level, from, &j->mv[j->nmv], j->err);
                    if (st != PDT_OK) return st;
                    j->nmv++;
                }
                b += n;
                left -= n;
                first = 0;
            } while (left > 0);
        }
        if (pass == 0) {
            j->mv = calloc((size_t)nblob + 1, sizeof *j->mv);
            j->mv_from = calloc((size_t)nblob + 1, sizeof *j->mv_from);
            if (!j->mv || !j->mv_from) return nomem(j->err, s->who, "merge");
        }
    }
    return PDT_OK;
}

/* Decode every message; find the two hulls and the longest critical path. */
static pdt_status read_messages(srm_job *j, void *const *msg, const size_t *len)
{
    srm_rank *s = j->s;
    j->cp_in = s->cnt.critical_path;
    j->cpu_in = s->cnt.critical_cpu;
    j->hl = j->hr = -1;
    pdt_status st = split_messages(j, msg, len);
    if (st != PDT_OK) return st;
    for (int i = 0; i < j->nmv; i++) {
        const srm_msg_view *v = &j->mv[i];
        if (v->h.cp > j->cp_in) j->cp_in = v->h.cp;
        if (v->h.cp_cpu > j->cpu_in) j->cpu_in = v->h.cp_cpu;
        if (v->h.flags & SRM_MSG_HAS_HULL) {
            int *side = j->mv_from[i] < j->gr ? &j->hl : &j->hr;
            if (*side >= 0)
                return pdt_err_set(j->err, PDT_ERR_CORRUPT, "merge at level %d: two hulls",
                                   j->level);
            *side = i;
        }
    }
    return PDT_OK;
}

/* The shipped set and the border set B: the vertices of the shipped
 * triangles and the facing hull vertices (the hull-vertex rule of the Merge
 * Lemma), key-sorted and distinct.  A blob's point table is distinct, in key
 * order, and holds its triangles' vertices and its hull's: the entries its
 * triangles use (marked) go into B once each, in that order, so B is a run
 * per blob and a short run of facing vertices, merged (no sort). */
static pdt_status border_set(srm_job *j)
{
    srm_rank *s = j->s;
    size_t nship = 0, nbmax = 0, most = 0;
    for (int i = 0; i < j->nmv; i++) {
        const srm_msg_head *h = &j->mv[i].h;
        nship += h->ntri;
        nbmax += (size_t)h->npts + 2 * (size_t)h->nhull;
        most = (size_t)h->npts > most ? (size_t)h->npts : most;
    }
    j->shipped = malloc((nship + 1) * sizeof *j->shipped);
    j->B = malloc((nbmax + 1) * sizeof *j->B);
    unsigned char *used = malloc(most + 1);
    int sax = j->share ? srm_seam_axis(pdt_srm_job_cut(j)) : 0;
    if (j->share) j->ship_lo = malloc((nship + 1) * sizeof *j->ship_lo);
    if (!j->shipped || !j->B || !used || (j->share && !j->ship_lo)) {
        free(used);
        return nomem(j->err, s->who, "merge");
    }
    size_t ns = 0, nb = 0, *end = malloc(((size_t)j->nmv + 1) * sizeof *end);
    srm_pt *B = j->B;
    if (!end) {
        free(used);
        return nomem(j->err, s->who, "merge");
    }
    for (int i = 0; i < j->nmv; i++) {
        const srm_msg_view *v = &j->mv[i];
        memset(used, 0, (size_t)v->h.npts);
        for (size_t t = 0; t < v->h.ntri; t++) {
            const uint32_t *c = v->tri + 3 * t;
            if (j->ship_lo) {
                uint64_t k0 = srm_axis_key(sax, v->pts[c[0]].x, v->pts[c[0]].y);
                uint64_t k1 = srm_axis_key(sax, v->pts[c[1]].x, v->pts[c[1]].y);
                uint64_t k2 = srm_axis_key(sax, v->pts[c[2]].x, v->pts[c[2]].y);
                k0 = k1 < k0 ? k1 : k0;
                j->ship_lo[ns] = k2 < k0 ? k2 : k0;
            }
            j->shipped[ns++] = srm_canon3(v->pts[c[0]].gid, v->pts[c[1]].gid, v->pts[c[2]].gid);
            used[c[0]] = used[c[1]] = used[c[2]] = 1;
        }
        for (size_t k = 0; k < v->h.npts; k++) {
            B[nb] = v->pts[k];
            nb += used[k];
        }
        end[i] = nb;
    }
    free(used);
    if (PDT_TRACING(s->tr, 1)) /* (the discards are traced in this order) */
        qsort(j->shipped, ns, sizeof *j->shipped, cmp_gtri);
    size_t nf = nb;
    if (j->hl >= 0) nb += facing(s, &j->mv[j->hl], j->gr, j->ge, B + nb);
    if (j->hr >= 0) nb += facing(s, &j->mv[j->hr], j->gl, j->gr, B + nb);
    end[j->nmv] = nb;
    pdt_status st = !j->share ? pdt_srm_tset_init(&j->sset, j->shipped, ns) : PDT_OK;
    if (st == PDT_OK) st = pdt_srm_sort_pts(B + nf, nb - nf);
    if (st == PDT_OK) st = pdt_srm_merge_pt_runs(B, end, j->nmv + 1);
    free(end);
    if (st != PDT_OK) return nomem(j->err, s->who, "merge");
    size_t u = 0;
    for (size_t i = 0; i < nb; i++)
        if (u == 0 || B[i].gid != B[u - 1].gid) B[u++] = B[i];
    j->ns = ns;
    j->nb = u;
    if (u > s->cnt.border_max) s->cnt.border_max = u;
    if (j->level < PDT_PAR_MAX_LEVELS && u > s->cnt.border_level[j->level])
        s->cnt.border_level[j->level] = u;
    return PDT_OK;
}

/* Lift-up of B (traced) and T*(B) by the kernel (run 1). */
pdt_status pdt_srm_job_kernel(srm_job *j)
{
    srm_rank *s = j->s;
    pdt_trace *tr = s->tr;
    size_t nb = j->nb;
    j->bp = malloc((nb + 1) * sizeof *j->bp);
    j->bg = malloc((nb + 1) * sizeof *j->bg);
    if (!j->bp || !j->bg) return nomem(j->err, s->who, "merge");
    for (size_t i = 0; i < nb; i++) {
        srm_pt b = j->B[i];
        j->bp[i] = (pdt_point){b.x, b.y};
        j->bg[i] = b.gid;
        if (PDT_TRACING(tr, 1)) {
            uint64_t z = (uint64_t)((int64_t)b.x * b.x) + (uint64_t)((int64_t)b.y * b.y);
            PDT_TRACE(tr, 1, PDT_EV_LIFT, 0, b.gid, 0, 0, (int64_t)z);
        }
    }
    const uint32_t *saved = tr ? tr->gid : NULL;
    if (tr) tr->gid = j->bg;
    pdt_status st = pdt_delaunay(j->bp, nb, &j->tris, &j->ntri, 1, tr);
    if (tr) tr->gid = saved;
    if (st != PDT_OK) return pdt_err_set(j->err, st, "%s: border kernel failed (%s)", s->who,
                                         pdt_status_str(st));
    return PDT_OK;
}

/* The cut between the groups of the merge: a point of the pair is in G_L
 * iff its axis key is below the split (srm_in_left).  Strips (and a rank's
 * two strips): the first key of G_R's first non-empty strip, or with none,
 * CUT_ALL_LEFT (every point in G_L: no key is "below" UINT64_MAX, the key of
 * (2^31 - 1, 2^31 - 1)); a bisection range: its cut. */
srm_cut pdt_srm_job_cut(const srm_job *j)
{
    const srm_rank *s = j->s;
    const srm_tree *t = s->tree;
    if (t && !(t->k > 1 && j->level == 0)) return pdt_srm_cut_of(t, j->gl / t->k, j->ge / t->k);
    for (int q = j->gr; q < j->ge; q++)
        if (s->strip[q].count) return (srm_cut){s->strip[q].first_key, 0};
    return (srm_cut){UINT64_MAX, CUT_ALL_LEFT};
}

/* Selection: keep the triangles of T*(B) with vertices in both groups and
 * the shipped ones it contains; each kept one is final or waits for a later
 * level (reclassified against the boxes outside the merged group). */
pdt_status pdt_srm_job_select(srm_job *j)
{
    srm_rank *s = j->s;
    pdt_trace *tr = s->tr;
    const srm_pt *B = j->B;
    srm_cut cut = pdt_srm_job_cut(j);
    if (PDT_TRACING(tr, 1)) { /* T*(B) kept whole: the discards' witnesses */
        j->tb = malloc((j->ntri + 1) * sizeof *j->tb);
        if (!j->tb) return nomem(j->err, s->who, "merge");
    }
    for (size_t i = 0; i < j->ntri; i++) {
        const uint32_t *v = j->tris[i].v;
        gtri g = srm_canon3(j->bg[v[0]], j->bg[v[1]], j->bg[v[2]]);
        if (j->tb) j->tb[j->ntb++] = g;
        int nl = 0;
        for (int k = 0; k < 3; k++) nl += srm_in_left(cut, B[v[k]]);
        int multi = nl > 0 && nl < 3;
        if (!multi) {
            if (!pdt_srm_tset_has(&j->sset, g)) continue;
            j->kept_shipped++;
        }
        j->kept++;
        int who;
        int lev = j->level + 1 < s->levels
                      ? pdt_srm_send_level(s, s->rank, j->level + 1, B[v[0]], B[v[1]], B[v[2]], &who)
                      : -1;
        pdt_status st;
        if (lev < 0) {
            st = pdt_srm_add_final(s, B[v[0]], B[v[1]], B[v[2]]);
            s->cnt.final_merge++;
        } else {
            st = pdt_srm_add_pending(s, B[v[0]], B[v[1]], B[v[2]], lev);
            PDT_TRACE(tr, 1, PDT_EV_RA_DEFER, 0, B[v[0]].gid, B[v[1]].gid, B[v[2]].gid, who);
        }
        if (st != PDT_OK) return nomem(j->err, s->who, "merge");
    }
    s->cnt.kept += j->kept;
    return PDT_OK;
}

/* A point of B strictly inside the circle of shipped triangle t (tie rule),
 * or -1: a non-border point may be the real cause.  byg: B sorted by gid. */
static int64_t witness(const srm_pt *byg, size_t nb, gtri t)
{
    pdt_point t3[3];
    for (int k = 0; k < 3; k++) {
        srm_pt q = byg[srm_find_gid(byg, nb, t.v[k])];
        t3[k] = (pdt_point){q.x, q.y};
    }
    for (size_t i = 0; i < nb; i++) {
        uint32_t g = byg[i].gid;
        if (g == t.v[0] || g == t.v[1] || g == t.v[2]) continue;
        if (pdt_incircle_sos(t3[0], t3[1], t3[2], (pdt_point){byg[i].x, byg[i].y}) > 0)
            return g;
    }
    return -1;
}

/* Discards: the shipped triangles T*(B) does not contain (traced with a
 * witness when tracing).  A shipped triangle has its three corners in one
 * group, so the selection met every one T*(B) contains among the triangles
 * of one group: untraced, the discards are the rest. */
pdt_status pdt_srm_job_discards(srm_job *j)
{
    pdt_trace *tr = j->s->tr;
    if (!PDT_TRACING(tr, 1)) {
        j->ndisc = j->ns - j->kept_shipped;
        j->s->cnt.discarded += j->ndisc;
        return PDT_OK;
    }
    if (pdt_srm_tset_init(&j->tset, j->tb, j->ntb) != PDT_OK)
        return nomem(j->err, j->s->who, "merge");
    srm_pt *byg = malloc((j->nb + 1) * sizeof *byg);
    if (byg) {
        memcpy(byg, j->B, j->nb * sizeof *j->B);
        qsort(byg, j->nb, sizeof *byg, cmp_gid);
    }
    for (size_t i = 0; i < j->ns; i++) {
        gtri t = j->shipped[i];
        if (pdt_srm_tset_has(&j->tset, t)) continue;
        j->ndisc++;
        int64_t wit = byg ? witness(byg, j->nb, t) : -1;
        PDT_TRACE(tr, 1, PDT_EV_DISCARD, 0, t.v[0], t.v[1], t.v[2], wit);
    }
    free(byg);
    j->s->cnt.discarded += j->ndisc;
    return PDT_OK;
}

/* The hull of the merged group: monotone chain over both hulls
 * (lex-sorted union); this rank now holds it. */
pdt_status pdt_srm_job_hulls(srm_job *j)
{
    srm_rank *s = j->s;
    pdt_trace *tr = s->tr;
    const srm_msg_view *ml = j->hl >= 0 ? &j->mv[j->hl] : NULL, *mr = j->hr >= 0 ? &j->mv[j->hr] : NULL;
    size_t n1 = ml ? ml->h.nhull : 0, n2 = mr ? mr->h.nhull : 0, nh = n1 + n2;
    srm_pt *hp = malloc((nh + 1) * sizeof *hp), *nhull = malloc((nh + 1) * sizeof *nhull);
    uint32_t *hidx = malloc((nh + 2) * sizeof *hidx), *pg = malloc((nh + 1) * sizeof *pg);
    pdt_point *pp = malloc((nh + 1) * sizeof *pp);
    pdt_status st = PDT_OK;
    if (!hp || !hidx || !pp || !pg || !nhull) {
        st = nomem(j->err, s->who, "hull merge");
        goto done;
    }
    size_t k = 0;
    for (size_t i = 0; i < n1; i++) hp[k++] = ml->pts[ml->hull[i]];
    for (size_t i = 0; i < n2; i++) hp[k++] = mr->pts[mr->hull[i]];
    qsort(hp, nh, sizeof *hp, cmp_key);
    for (size_t i = 0; i < nh; i++) {
        pp[i] = (pdt_point){hp[i].x, hp[i].y};
        pg[i] = hp[i].gid;
    }
    size_t nout = 0;
    int deg = 0;
    const uint32_t *saved = tr ? tr->gid : NULL;
    if (tr) tr->gid = pg;
    st = pdt_hull_chain(pp, nh, hidx, &nout, &deg, PDT_STACK_MERGE_LOWER, PDT_STACK_MERGE_UPPER,
                        tr);
    if (tr) tr->gid = saved;
    if (st != PDT_OK) {
        pdt_err_set(j->err, st, "%s: hull merge failed", s->who);
        goto done;
    }
    for (size_t i = 0; i < nout; i++) nhull[i] = hp[hidx[i]];
    free(s->hull);
    s->hull = nhull;
    nhull = NULL;
    s->nhull = nout;
    s->hull_degenerate = deg;
    s->holds_hull = 1;
    PDT_TRACE(tr, 1, PDT_EV_HULL, 0, nout, deg, 0, 0);
done:
    free(hp);
    free(nhull);
    free(hidx);
    free(pg);
    free(pp);
    return st;
}

pdt_status pdt_srm_job_open(srm_job *j, srm_rank *s, int level, void *const *msg,
                            const size_t *len, int share, pdt_err *err)
{
    memset(j, 0, sizeof *j);
    j->share = share;
    j->s = s;
    j->level = level;
    j->err = err;
    pdt_srm_pair_of(s->tree, s->rank, s->p, level, &j->gl, &j->gr, &j->ge);
    j->nm = j->ge - j->gl;
    j->t0 = now(s);
    j->c0 = cpu_now();
    PDT_TRACE(s->tr, 1, PDT_EV_MERGE_BEGIN, level, j->gl, j->gr, j->ge, s->rank);
    pdt_status st = read_messages(j, msg, len);
    return st == PDT_OK ? border_set(j) : st;
}

void pdt_srm_job_close(srm_job *j, pdt_status st)
{
    srm_rank *s = j->s;
    if (st == PDT_OK) {
        s->cnt.merges++;
        PDT_TRACE(s->tr, 1, PDT_EV_MERGE_END, j->level, j->ns, j->nb, j->kept, (int64_t)j->ndisc);
        s->cnt.critical_path = j->cp_in + (now(s) - j->t0);
        s->cnt.critical_cpu = j->cpu_in + (cpu_now() - j->c0);
    }
    job_free(j);
}

pdt_status pdt_srm_merge(srm_rank *s, int level, void *const *msg, const size_t *len, pdt_err *err)
{
    srm_job j;
    pdt_status st = pdt_srm_job_open(&j, s, level, msg, len, 0, err);
    if (st == PDT_OK) st = pdt_srm_job_kernel(&j);
    if (st == PDT_OK) st = pdt_srm_job_select(&j);
    if (st == PDT_OK) st = pdt_srm_job_discards(&j);
    if (st == PDT_OK) st = pdt_srm_job_hulls(&j);
    pdt_srm_job_close(&j, st);
    return st;
}
