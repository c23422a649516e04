/* pdt — the merge schedule of SRM (docs/algorithm.md §3.5).
 *
 * Level-l groups are the rank blocks [j 2^l, (j+1) 2^l) ∩ [0, p).  At level l
 * the groups 2i and 2i+1 merge; the merge rank is the first rank of the right
 * group (next to the seam) and becomes the holder of the merged group's hull
 * and of its new pending triangles.  A group without a partner passes through
 * unchanged. */
#include "srm.h"

int pdt_srm_ceil_log2(int p)
{
    int l = 0;
    while ((1 << l) < p) l++;
    return l;
}

int pdt_srm_pair(int r, int p, int level, int *gl, int *gr, int *ge)
{
    int base = (r >> (level + 1)) << (level + 1);
    *gl = base;
    *gr = base + (1 << level);
    *ge = base + (2 << level) < p ? base + (2 << level) : p;
    return *gr < p;
}

int pdt_srm_holder(int r, int p, int level)
{
    if (level == 0) return r;
    int base = (r >> level) << level;
    int right = base + (1 << (level - 1));
    if (right < p) return right;
    return pdt_srm_holder(base, p, level - 1);
}


/* ---- the bisection tree (algorithm.md §3.12) ------------------------------------
 *
 * The range at depth d of the tree merges its halves at level
 * levels_p - 1 - d (every range of two ranks or more has d <= levels_p - 1:
 * halves ceil(s/2) and floor(s/2) give a subtree of depth ceil(log2 s)); a
 * rank's two strips, when it holds two, merge before, at level 0. */

int pdt_srm_levels_of(const srm_tree *t, int np)
{
    return t ? t->levels_p + (t->k > 1) : pdt_srm_ceil_log2(np);
}

int pdt_srm_pair_of(const srm_tree *t, int g, int np, int level, int *gl, int *gr, int *ge)
{
    if (!t) return pdt_srm_pair(g, np, level, gl, gr, ge);
    int k = t->k, off = k > 1;
    if (off && level == 0) {
        *gl = g - g % k;
        *gr = *gl + 1;
        *ge = *gl + 2;
        return 1;
    }
    int r = g / k, want = t->levels_p - 1 - (level - off), lo = 0, hi = t->p;
    for (int dep = 0; hi - lo >= 2; dep++) {
        int mid = srm_bis_mid(lo, hi);
        if (dep == want) {
            *gl = lo * k;
            *gr = mid * k;
            *ge = hi * k;
            return 1;
        }
        if (r < mid) hi = mid;
        else lo = mid;
    }
    return 0;
}

int pdt_srm_holder_of(const srm_tree *t, int g, int np, int level)
{
    if (!t) return pdt_srm_holder(g, np, level);
    for (int lv = level - 1; lv >= 0; lv--) { /* the last merge of g's group before */
        int gl, gr, ge;
        if (pdt_srm_pair_of(t, g, np, lv, &gl, &gr, &ge)) return gr;
    }
    return g;
}

int pdt_srm_meet_of(const srm_tree *t, int q, int h)
{
    if (!t) return 31 - __builtin_clz((unsigned)(q ^ h));
    int k = t->k, off = k > 1, a = q / k, b = h / k, lo = 0, hi = t->p;
    if (a == b) return 0;
    for (int dep = 0;; dep++) {
        int mid = srm_bis_mid(lo, hi);
        if ((a < mid) != (b < mid)) return t->levels_p - 1 - dep + off;
        if (a < mid) hi = mid;
        else lo = mid;
    }
}

srm_cut pdt_srm_cut_of(const srm_tree *t, int lo, int hi)
{
    int a = 0, b = t->p, at = 0;
    while ((a != lo || b != hi) && b - a >= 2) {
        int mid = srm_bis_mid(a, b);
        if (lo < mid) {
            b = mid;
            at += 1;
        } else {
            at += mid - a;
            a = mid;
        }
    }
    return t->cut[at];
}
