/* pdt — the merge step's sorts and look-ups (srm.h): point tables sorted by
 * key with the partition's radix sort, and sets of canonical triangles
 * hashed (a merge asks "was this triangle shipped?" of every one-group
 * triangle of T*(B), and a traced one "is this shipped triangle in T*(B)?"
 * of every shipped one; sorting both sets with qsort and searching them
 * took more of a merge than its kernel). */
#include <string.h>

#include "srm.h"

pdt_status pdt_srm_sort_pts(srm_pt *p, size_t n)
{
    if (n < 2) return PDT_OK;
    srm_rec *r = malloc(2 * n * sizeof *r);
    srm_pt *out = malloc(n * sizeof *out);
    if (!r || !out) {
        free(r);
        free(out);
        return PDT_ERR_NOMEM;
    }
    for (size_t i = 0; i < n; i++)
        r[i] = (srm_rec){srm_key(p[i]), (uint32_t)i, 0};
    pdt_srm_radix_sort(r, r + n, n);
    for (size_t i = 0; i < n; i++) out[i] = p[r[i].idx];
    memcpy(p, out, n * sizeof *p);
    free(r);
    free(out);
    return PDT_OK;
}

/* Two key-sorted runs a[0, na) and b[0, nb) into out. */
static void merge_two(const srm_pt *a, size_t na, const srm_pt *b, size_t nb, srm_pt *out)
{
    size_t i = 0, j = 0, k = 0;
    while (i < na && j < nb) out[k++] = srm_key(b[j]) < srm_key(a[i]) ? b[j++] : a[i++];
    while (i < na) out[k++] = a[i++];
    while (j < nb) out[k++] = b[j++];
}

pdt_status pdt_srm_merge_pt_runs(srm_pt *p, size_t *end, int nrun)
{
    size_t n = nrun > 0 ? end[nrun - 1] : 0;
    if (nrun < 2 || n < 2) return PDT_OK;
    srm_pt *tmp = malloc(n * sizeof *tmp), *src = p, *dst = tmp;
    if (!tmp) return PDT_ERR_NOMEM;
    while (nrun > 1) { /* adjacent pairs, until one run is left */
        int k = 0;
        for (int r = 0; r < nrun; r += 2) {
            size_t lo = r ? end[r - 1] : 0, mid = end[r], hi = r + 1 < nrun ? end[r + 1] : mid;
            merge_two(src + lo, mid - lo, src + mid, hi - mid, dst + lo);
            end[k++] = hi;
        }
        nrun = k;
        srm_pt *t = src;
        src = dst;
        dst = t;
    }
    if (src != p) memcpy(p, src, n * sizeof *p);
    free(tmp);
    return PDT_OK;
}

/* Empty slots: all ones (a triangle's three indices are distinct). */
static int tset_empty(const srm_gtri *t)
{
    return t->v[0] == UINT32_MAX && t->v[1] == UINT32_MAX;
}

static size_t tset_hash(srm_gtri t, size_t mask)
{
    uint64_t h = ((uint64_t)t.v[0] << 32 | t.v[1]) * 0x9E3779B97F4A7C15u;
    h ^= (h >> 29) + (uint64_t)t.v[2] * 0xC2B2AE3D27D4EB4Fu;
    h *= 0x165667B19E3779F9u;
    return (size_t)(h >> 17) & mask;
}

pdt_status pdt_srm_tset_init(srm_tset *s, const srm_gtri *t, size_t n)
{
    size_t cap = 16;
    while (cap < 2 * n) cap *= 2;
    s->slot = malloc(cap * sizeof *s->slot);
    s->mask = cap - 1;
    if (!s->slot) return PDT_ERR_NOMEM;
    memset(s->slot, 0xff, cap * sizeof *s->slot);
    for (size_t i = 0; i < n; i++) {
        size_t h = tset_hash(t[i], s->mask);
        while (!tset_empty(&s->slot[h]) && memcmp(&s->slot[h], &t[i], sizeof t[i]))
            h = (h + 1) & s->mask;
        s->slot[h] = t[i];
    }
    return PDT_OK;
}

int pdt_srm_tset_has(const srm_tset *s, srm_gtri t)
{
    for (size_t h = tset_hash(t, s->mask);; h = (h + 1) & s->mask) {
        const srm_gtri *e = &s->slot[h];
        if (tset_empty(e)) return 0;
        if (e->v[0] == t.v[0] && e->v[1] == t.v[1] && e->v[2] == t.v[2]) return 1;
    }
}

void pdt_srm_tset_free(srm_tset *s)
{
    free(s->slot);
    s->slot = NULL;
}
