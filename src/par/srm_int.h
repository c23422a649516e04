/* pdt — the merge step's state and stages, shared by srm.c (the merge at
 * one rank) and srm_share.c (one merge shared by several ranks along its
 * seam).  Private to src/par. */
#ifndef PDT_SRM_INT_H
#define PDT_SRM_INT_H

#include "srm.h"

typedef srm_gtri gtri;

/* The state of one merge step at the merge rank, phase by phase. */
struct srm_job {
    srm_rank *s;
    int level, gl, gr, ge, nm;
    pdt_err *err;
    srm_msg_view *mv;            /* the decoded blobs of this level, nmv of them */
    int nmv;
    int *mv_from;            /* the rank of the pair each came from */
    int hl, hr;              /* message holding the hull of G_L / G_R, or -1 */
    double t0, c0;           /* the step's start (wall, CPU) */
    double cp_in, cpu_in;    /* longest critical path among the senders */
    gtri *shipped;           /* R_L ∪ R_R, canonical (sorted when traced) */
    srm_tset sset, tset;     /* the shipped set and T*(B), for look-ups */
    size_t ns;
    srm_pt *B;               /* the border set, key-sorted, distinct */
    size_t nb;
    pdt_point *bp;           /* B as points, and their global indices */
    uint32_t *bg;
    pdt_tri *tris;           /* T*(B), indices into B */
    size_t ntri;
    gtri *tb;                /* T*(B) as canonical global triangles */
    size_t ntb, kept, kept_shipped, ndisc;
    int share;               /* a shared merge: ship_lo wanted */
    uint64_t *ship_lo;       /* (share) each shipped triangle's lowest seam key */
};

/* The cut between the groups of a merge (its in_left rule). */
enum { CUT_ALL_LEFT = 2 };

static inline int srm_in_left(srm_cut c, srm_pt p)
{
    return c.axis == CUT_ALL_LEFT || srm_axis_key(c.axis, p.x, p.y) < c.split;
}

/* The order along a merge's seam: the key (y, x) for a cut across x (axis
 * 1), else the key (x, y). */
static inline int srm_seam_axis(srm_cut cut)
{
    return cut.axis == 0 ? 1 : 0;
}

/* Rotated so that the smallest gid comes first (orientation kept). */
static inline gtri srm_canon3(uint32_t a, uint32_t b, uint32_t c)
{
    gtri t;
    if (a < b && a < c) t = (gtri){{a, b, c}};
    else if (b < c) t = (gtri){{b, c, a}};
    else t = (gtri){{c, a, b}};
    return t;
}

/* srm.c's stages, in the order pdt_srm_merge runs them. */
pdt_status pdt_srm_job_open(srm_job *j, srm_rank *s, int level, void *const *msg,
                            const size_t *len, int share, pdt_err *err); /* read, border set */
pdt_status pdt_srm_job_kernel(srm_job *j);                  /* T*(B) */
pdt_status pdt_srm_job_select(srm_job *j);                  /* kept: final or pending */
pdt_status pdt_srm_job_discards(srm_job *j);
pdt_status pdt_srm_job_hulls(srm_job *j);                   /* hull(G), held here */
void pdt_srm_job_close(srm_job *j, pdt_status st);          /* counts, free */
srm_cut pdt_srm_job_cut(const srm_job *j);

/* A final triangle or a pending one (level) kept at s; n finals a merge
 * made, untraced (counted as final_merge). */
pdt_status pdt_srm_add_final(srm_rank *s, srm_pt a, srm_pt b, srm_pt c);
pdt_status pdt_srm_add_finals(srm_rank *s, const pdt_tri *t, size_t n);
pdt_status pdt_srm_add_pending(srm_rank *s, srm_pt a, srm_pt b, srm_pt c, int level);
/* The classification of a triangle held at strip h whose group has level
 * `from`: -1 final, else its send level (*who: a rank whose box it touches). */
int pdt_srm_send_level(const srm_rank *s, int h, int from, srm_pt a, srm_pt b, srm_pt c,
                       int *who);

#endif
