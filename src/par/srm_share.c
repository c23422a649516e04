/* pdt — one merge step shared by several ranks along its seam
 * (docs/algorithm.md §3.13).
 *
 * The merge rank builds the border set B as usual, cuts it along the seam
 * into pieces, and gives each sharing rank one piece with some of its
 * neighbours' points on either side.  A sharing rank triangulates what it
 * got and keeps a triangle when
 *   - its lowest vertex along the seam lies in its own piece (one owner
 *     for every triangle),
 *   - the selection of the Merge Lemma keeps it (vertices in both groups,
 *     or shipped), and
 *   - its closed circumdisk lies inside the open slab across the seam
 *     where the rank knows every point of B: then no point of B is inside
 *     it, so it is a triangle of T*(B) (Proposition R, applied to B).
 * What is kept is therefore part of the merge's selection, each triangle
 * once.  The merge rank knows how many the selection holds, from Euler's
 * formula on the three groups (share_expected); when the ranks together
 * found that many, they found all of it, and each keeps its finals.
 * Otherwise (a circumdisk reached past a piece's neighbours: points on a
 * circle, a very thin group) the merge rank runs the whole step itself and
 * the others drop what they found.  Either way the output is T*(P).
 *
 * No MPI here: the driver (steps.c) moves the pieces and the replies. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "pdt/delaunay.h"
#include "srm_int.h"

#define PIECE_MAGIC 0x45434950u /* "PICE" */
#define REPLY_MAGIC 0x4c504552u /* "REPL" */

/* The points of B shared with a piece's neighbours, on each side: a third
 * of a piece, at least this many. */
#define SHARE_OVERLAP_MIN 48

/* Points per piece when PDT_SHARE_PIECE does not say (0 there: no merge is
 * shared). */
#define SHARE_PIECE_DEFAULT 500

typedef struct piece_head {
    uint32_t magic, level, sax, flags; /* sax: the seam's order (0: key (x, y), 1: (y, x)) */
    int32_t s_lo, s_hi;                /* the open slab's sides (flags PIECE_LO, PIECE_HI) */
    uint64_t split;                    /* the merge's cut */
    int32_t axis, g;                   /* ... its axis; the merge strip */
    uint64_t n, c0, c1, nship;         /* points (seam order), own range, shipped triangles */
} piece_head;

enum { PIECE_LO = 1, PIECE_HI = 2 };

typedef struct reply_head {
    uint32_t magic, pad;
    uint64_t found, kept_shipped, npend;
} reply_head;

/* ---- the plan -------------------------------------------------------------- */

static int share_piece(void)
{
    const char *e = getenv("PDT_SHARE_PIECE");
    if (!e || !*e) return SHARE_PIECE_DEFAULT;
    long v = strtol(e, NULL, 10);
    return v < 0 ? 0 : v > 1 << 24 ? 1 << 24 : (int)v;
}

int pdt_srm_share_plan(const srm_rank *s, int level, srm_share_plan *pl)
{
    memset(pl, 0, sizeof *pl);
    const srm_tree *t = s->tree;
    int piece = share_piece();
    if (!t || s->tr || piece <= 0) return 0;
    int gl, gr, ge;
    if (!pdt_srm_pair_of(t, s->rank, s->p, level, &gl, &gr, &ge)) return 0;
    int k = t->k, rlo = gl / k, nr = (ge - 1) / k + 1 - rlo, m = gr / k;
    if (nr < 2) return 0;
    uint64_t n = 0;
    for (int q = gl; q < ge; q++) n += s->strip[q].count;
    /* a seam's border set holds about 3 sqrt(n) points (docs/simulation.md) */
    double want = 3.0 * sqrt((double)n) / piece;
    int h = want >= PDT_SHARE_MAX ? PDT_SHARE_MAX : (int)want;
    if (h > nr) h = nr;
    if (h < 2) return 0;
    pl->n = h;
    pl->gl = gl;
    pl->gr = gr;
    pl->ge = ge;
    for (int i = 0; i < h; i++)
        pl->rank[i] = rlo + (m - rlo + (int)((int64_t)i * nr / h)) % nr;
    return 1;
}

/* ---- at the merge rank: the pieces --------------------------------------------- */

static uint64_t seam_key(int sax, srm_pt p)
{
    return srm_axis_key(sax, p.x, p.y);
}

static int32_t seam_coord(int sax, srm_pt p)
{
    return sax ? p.y : p.x;
}

pdt_status pdt_srm_share_open(srm_rank *s, int level, void *const *msg, const size_t *len,
                              srm_job **job, pdt_err *err)
{
    *job = calloc(1, sizeof **job);
    if (!*job) return pdt_err_set(err, PDT_ERR_NOMEM, "%s: merge: out of memory", s->who);
    pdt_status st = pdt_srm_job_open(*job, s, level, msg, len, 1, err);
    return st == PDT_OK ? pdt_srm_job_hulls(*job) : st;
}

/* The first place of piece i of n over nb points. */
static size_t piece_start(size_t nb, int n, int i)
{
    return (size_t)((unsigned __int128)nb * (unsigned)i / (unsigned)n);
}

/* B in the seam's order (B itself when that is the key's): *bs, and *own
 * the piece of each shipped triangle (the piece of its lowest vertex along
 * the seam), cnt[i] how many piece i owns. */
static pdt_status seam_order(srm_job *j, int sax, int n, srm_pt **bs, int **own, size_t *cnt)
{
    size_t nb = j->nb, ns = j->ns;
    *own = malloc((ns + 1) * sizeof **own);
    *bs = sax ? malloc((nb + 1) * sizeof **bs) : j->B;
    srm_rec *r = sax ? malloc((2 * nb + 1) * sizeof *r) : NULL;
    if (!*own || !*bs || (sax && !r)) {
        free(r);
        return PDT_ERR_NOMEM;
    }
    if (sax) {
        for (size_t i = 0; i < nb; i++) r[i] = (srm_rec){seam_key(sax, j->B[i]), (uint32_t)i, 0};
        pdt_srm_radix_sort(r, r + nb, nb);
        for (size_t i = 0; i < nb; i++) (*bs)[i] = j->B[r[i].idx];
        free(r);
    }
    uint64_t first[PDT_SHARE_MAX];
    for (int i = 0; i < n; i++) {
        size_t c0 = piece_start(nb, n, i);
        first[i] = c0 < nb ? seam_key(sax, (*bs)[c0]) : UINT64_MAX;
    }
    for (size_t t = 0; t < ns; t++) {
        int i = n - 1;
        while (i > 0 && first[i] > j->ship_lo[t]) i--;
        (*own)[t] = i;
        cnt[i]++;
    }
    return PDT_OK;
}

pdt_status pdt_srm_share_pieces(srm_job *j, int n, void **piece, size_t *plen)
{
    srm_cut cut = pdt_srm_job_cut(j);
    int sax = srm_seam_axis(cut);
    size_t nb = j->nb, ns = j->ns, cnt[PDT_SHARE_MAX] = {0};
    srm_pt *bs = NULL;
    int *own = NULL;
    for (int i = 0; i < n; i++) piece[i] = NULL;
    pdt_status st = seam_order(j, sax, n, &bs, &own, cnt);
    for (int i = 0; i < n && st == PDT_OK; i++) {
        size_t c0 = piece_start(nb, n, i), c1 = piece_start(nb, n, i + 1);
        size_t ov = (c1 - c0) / 3 > SHARE_OVERLAP_MIN ? (c1 - c0) / 3 : SHARE_OVERLAP_MIN;
        size_t e0 = c0 > ov ? c0 - ov : 0, e1 = c1 + ov < nb ? c1 + ov : nb;
        piece_head h = {PIECE_MAGIC, (uint32_t)j->level, (uint32_t)sax, 0, 0, 0, cut.split,
                        cut.axis, j->gr, e1 - e0, c0 - e0, c1 - e0, cnt[i]};
        if (e0 > 0) h.flags |= PIECE_LO, h.s_lo = seam_coord(sax, bs[e0]);
        if (e1 < nb) h.flags |= PIECE_HI, h.s_hi = seam_coord(sax, bs[e1 - 1]);
        size_t bytes = sizeof h + h.n * sizeof(srm_pt) + h.nship * sizeof(gtri);
        unsigned char *b = malloc(bytes);
        if (!b) {
            st = PDT_ERR_NOMEM;
            break;
        }
        memcpy(b, &h, sizeof h);
        memcpy(b + sizeof h, bs + e0, h.n * sizeof(srm_pt));
        piece[i] = b;
        plen[i] = bytes;
    }
    size_t at[PDT_SHARE_MAX] = {0};
    for (size_t t = 0; t < ns && st == PDT_OK; t++) {
        unsigned char *b = piece[own[t]];
        const piece_head *h = (const piece_head *)b;
        ((gtri *)(b + sizeof *h + h->n * sizeof(srm_pt)))[at[own[t]]++] = j->shipped[t];
    }
    if (bs != j->B) free(bs);
    free(own);
    if (st != PDT_OK) {
        for (int i = 0; i < n; i++) {
            free(piece[i]);
            piece[i] = NULL;
        }
        return pdt_err_set(j->err, st, "%s: merge: out of memory", j->s->who);
    }
    return PDT_OK;
}

/* ---- at a sharing rank: one piece ----------------------------------------------- */

typedef struct piece {
    piece_head h;
    const srm_pt *pt;   /* h.n points in the seam's order */
    const gtri *ship;   /* h.nship shipped triangles owned here */
    srm_slab slab;      /* where every point of B is known */
    srm_strip below, above; /* the closed half-planes beyond it, as boxes */
} piece;

static pdt_status piece_read(piece *pc, const void *buf, size_t len, pdt_err *err)
{
    if (len < sizeof pc->h) goto bad;
    memcpy(&pc->h, buf, sizeof pc->h);
    const piece_head *h = &pc->h;
    if (h->magic != PIECE_MAGIC || h->sax > 1 || h->c0 > h->c1 || h->c1 > h->n ||
        h->n > (len - sizeof *h) / sizeof(srm_pt) ||
        h->nship > (len - sizeof *h - h->n * sizeof(srm_pt)) / sizeof(gtri) ||
        len != sizeof *h + h->n * sizeof(srm_pt) + h->nship * sizeof(gtri))
        goto bad;
    pc->pt = (const srm_pt *)((const unsigned char *)buf + sizeof *h);
    pc->ship = (const gtri *)(pc->pt + h->n);
    double lo = h->flags & PIECE_LO ? (double)h->s_lo : -INFINITY;
    double hi = h->flags & PIECE_HI ? (double)h->s_hi : INFINITY;
    srm_strip all = {1, 0, 0, INT32_MIN, INT32_MAX, INT32_MIN, INT32_MAX};
    pc->below = pc->above = all;
    if (h->sax) {
        pc->slab = (srm_slab){-INFINITY, INFINITY, lo, hi};
        pc->below.ymax = h->s_lo;
        pc->above.ymin = h->s_hi;
    } else {
        pc->slab = (srm_slab){lo, hi, -INFINITY, INFINITY};
        pc->below.xmax = h->s_lo;
        pc->above.xmin = h->s_hi;
    }
    if (!(h->flags & PIECE_LO)) pc->below.count = 0;
    if (!(h->flags & PIECE_HI)) pc->above.count = 0;
    return PDT_OK;
bad:
    return pdt_err_set(err, PDT_ERR_CORRUPT, "shared merge: bad piece (%zu bytes)", len);
}

/* Whether the closed circumdisk of (a, b, c) lies inside the piece's open
 * slab (sound: never for a disk that reaches a point outside it). */
static int in_slab(const piece *pc, srm_pt a, srm_pt b, srm_pt c)
{
    if (srm_disk_in_slab(&pc->slab, a, b, c)) return 1;
    srm_disk d;
    pdt_srm_disk_of(&d, a, b, c);
    return !d.all && !pdt_srm_disk_touch(&d, &pc->below) && !pdt_srm_disk_touch(&d, &pc->above);
}

typedef struct work {
    srm_rank *s;
    piece pc;
    pdt_point *kp;     /* the points in the kernel's order */
    uint32_t *at;      /* their places in the seam's order */
    pdt_tri *tris;
    size_t ntri;
    srm_tset ship;
    srm_tri *pend;
    size_t npend;
    uint64_t found, kept_shipped;
} work;

/* T* of the piece's points (the kernel wants them in key order). */
static pdt_status piece_kernel(work *w)
{
    size_t n = w->pc.h.n;
    const srm_pt *pt = w->pc.pt;
    srm_rec *r = malloc((2 * n + 1) * sizeof *r);
    w->kp = malloc((n + 1) * sizeof *w->kp);
    w->at = malloc((n + 1) * sizeof *w->at);
    if (!r || !w->kp || !w->at) {
        free(r);
        return PDT_ERR_NOMEM;
    }
    for (size_t i = 0; i < n; i++) r[i] = (srm_rec){srm_key(pt[i]), (uint32_t)i, 0};
    if (w->pc.h.sax) pdt_srm_radix_sort(r, r + n, n);
    for (size_t i = 0; i < n; i++) {
        w->at[i] = r[i].idx;
        w->kp[i] = (pdt_point){pt[r[i].idx].x, pt[r[i].idx].y};
    }
    free(r);
    return pdt_delaunay(w->kp, n, &w->tris, &w->ntri, 1, NULL);
}

/* The selection on the triangles this rank owns and can certify: finals
 * into held, pending ones into w->pend. */
static pdt_status piece_select(work *w, srm_held *held)
{
    const piece *pc = &w->pc;
    srm_cut cut = {pc->h.split, pc->h.axis};
    int level = (int)pc->h.level, levels = w->s->levels;
    w->pend = malloc((w->ntri + 1) * sizeof *w->pend);
    held->t = malloc((w->ntri + 1) * sizeof *held->t);
    if (!w->pend || !held->t) return PDT_ERR_NOMEM;
    for (size_t i = 0; i < w->ntri; i++) {
        const uint32_t *v = w->tris[i].v;
        uint32_t a0 = w->at[v[0]], a1 = w->at[v[1]], a2 = w->at[v[2]];
        uint32_t lo = a0 < a1 ? a0 : a1;
        lo = a2 < lo ? a2 : lo;
        if (lo < pc->h.c0 || lo >= pc->h.c1) continue;
        srm_pt a = pc->pt[a0], b = pc->pt[a1], c = pc->pt[a2];
        int nl = srm_in_left(cut, a) + srm_in_left(cut, b) + srm_in_left(cut, c);
        int multi = nl > 0 && nl < 3;
        if (!multi && !pdt_srm_tset_has(&w->ship, srm_canon3(a.gid, b.gid, c.gid))) continue;
        if (!in_slab(pc, a, b, c)) continue;
        w->found++;
        w->kept_shipped += !multi;
        int who;
        int lev = level + 1 < levels ? pdt_srm_send_level(w->s, pc->h.g, level + 1, a, b, c, &who)
                                     : -1;
        if (lev < 0) held->t[held->n++] = (pdt_tri){{a.gid, b.gid, c.gid}};
        else w->pend[w->npend++] = (srm_tri){{a, b, c}, lev};
    }
    return PDT_OK;
}

pdt_status pdt_srm_share_work(srm_rank *s, const void *buf, size_t len, void **reply,
                              size_t *rlen, srm_held *held, pdt_err *err)
{
    work w;
    memset(&w, 0, sizeof w);
    memset(held, 0, sizeof *held);
    *reply = NULL;
    w.s = s;
    pdt_status st = piece_read(&w.pc, buf, len, err);
    if (st != PDT_OK) return st;
    st = pdt_srm_tset_init(&w.ship, w.pc.ship, w.pc.h.nship);
    if (st == PDT_OK) st = piece_kernel(&w);
    if (st == PDT_OK) st = piece_select(&w, held);
    if (st == PDT_OK) {
        reply_head h = {REPLY_MAGIC, 0, w.found, w.kept_shipped, w.npend};
        size_t bytes = sizeof h + w.npend * sizeof *w.pend;
        unsigned char *b = malloc(bytes);
        if (b) {
            memcpy(b, &h, sizeof h);
            if (w.npend) memcpy(b + sizeof h, w.pend, w.npend * sizeof *w.pend);
            *reply = b;
            *rlen = bytes;
        } else {
            st = PDT_ERR_NOMEM;
        }
    }
    pdt_srm_tset_free(&w.ship);
    free(w.kp);
    free(w.at);
    free(w.tris);
    free(w.pend);
    if (st == PDT_ERR_NOMEM) return pdt_err_set(err, st, "%s: shared merge: out of memory", s->who);
    if (st != PDT_OK && st != PDT_ERR_CORRUPT)
        return pdt_err_set(err, st, "%s: shared merge: kernel failed (%s)", s->who,
                           pdt_status_str(st));
    return st;
}

pdt_status pdt_srm_share_commit(srm_rank *s, srm_held *held, int ok)
{
    pdt_status st = ok ? pdt_srm_add_finals(s, held->t, held->n) : PDT_OK;
    free(held->t);
    held->t = NULL;
    held->n = 0;
    return st;
}

/* ---- at the merge rank: the verdict ------------------------------------------------ */

/* Triangles of T* on a group of n points whose hull (boundary points
 * included) has h: 2n - h - 2, none when it is degenerate (collinear, or
 * at most two points). */
static uint64_t tri_count(uint64_t n, uint64_t h, int degenerate)
{
    return degenerate || n < 3 || 2 * n < h + 2 ? 0 : 2 * n - h - 2;
}

/* The size of the merge's selection: T*(G) less what G_L and G_R keep,
 * (T*(G_L) less its shipped triangles) and the same for G_R; 0 and *known
 * 0 if a group's hull did not come. */
static uint64_t share_expected(const srm_job *j, int *known)
{
    const srm_rank *s = j->s;
    uint64_t nl = 0, nr = 0;
    for (int q = j->gl; q < j->gr; q++) nl += s->strip[q].count;
    for (int q = j->gr; q < j->ge; q++) nr += s->strip[q].count;
    const srm_msg_view *ml = j->hl >= 0 ? &j->mv[j->hl] : NULL, *mr = j->hr >= 0 ? &j->mv[j->hr] : NULL;
    *known = (ml || nl == 0) && (mr || nr == 0);
    if (!*known) return 0;
    uint64_t tl = ml ? tri_count(nl, ml->h.nhull, ml->h.flags & SRM_MSG_HULL_DEGENERATE) : 0;
    uint64_t tr = mr ? tri_count(nr, mr->h.nhull, mr->h.flags & SRM_MSG_HULL_DEGENERATE) : 0;
    uint64_t tg = tri_count(nl + nr, s->nhull, s->hull_degenerate);
    return tg + j->ns - tl - tr;
}

pdt_status pdt_srm_share_join(srm_job *j, void *const *reply, const size_t *rlen, int n, int *ok)
{
    uint64_t found = 0, kept_shipped = 0;
    int known;
    uint64_t want = share_expected(j, &known);
    for (int i = 0; i < n; i++) {
        reply_head h;
        if (rlen[i] < sizeof h) goto bad;
        memcpy(&h, reply[i], sizeof h);
        if (h.magic != REPLY_MAGIC || h.npend > (rlen[i] - sizeof h) / sizeof(srm_tri) ||
            rlen[i] != sizeof h + h.npend * sizeof(srm_tri))
            goto bad;
        found += h.found;
        kept_shipped += h.kept_shipped;
    }
    *ok = known && found == want;
    if (!*ok) return PDT_OK;
    for (int i = 0; i < n; i++) {
        reply_head h;
        memcpy(&h, reply[i], sizeof h);
        const srm_tri *t = (const srm_tri *)((const unsigned char *)reply[i] + sizeof h);
        for (uint64_t k = 0; k < h.npend; k++)
            if (pdt_srm_add_pending(j->s, t[k].p[0], t[k].p[1], t[k].p[2], t[k].level) != PDT_OK)
                return pdt_err_set(j->err, PDT_ERR_NOMEM, "%s: merge: out of memory", j->s->who);
    }
    j->kept = found;
    j->kept_shipped = kept_shipped;
    j->ndisc = j->ns - kept_shipped;
    j->s->cnt.kept += found;
    j->s->cnt.discarded += j->ndisc;
    return PDT_OK;
bad:
    return pdt_err_set(j->err, PDT_ERR_CORRUPT, "%s: shared merge: bad reply", j->s->who);
}

pdt_status pdt_srm_share_close(srm_job *j, int ok, pdt_status st)
{
    if (st == PDT_OK && !ok) {
        j->s->cnt.share_fallbacks++;
        st = pdt_srm_tset_init(&j->sset, j->shipped, j->ns);
        if (st != PDT_OK) st = pdt_err_set(j->err, st, "%s: merge: out of memory", j->s->who);
        if (st == PDT_OK) st = pdt_srm_job_kernel(j);
        if (st == PDT_OK) st = pdt_srm_job_select(j);
        if (st == PDT_OK) st = pdt_srm_job_discards(j);
    }
    if (st == PDT_OK) j->s->cnt.shared++;
    pdt_srm_job_close(j, st);
    free(j);
    return st;
}
