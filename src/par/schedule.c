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

