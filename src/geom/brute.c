/* pdt — the brute-force lift-up oracle, in the spirit of O'Rourke's dt4:
 * a triple is a Delaunay triangle iff the plane through its lifted points has
 * every other lifted point strictly above it under the tie rule
 * (pdt_incircle_sos < 0 for every other point).  O(n^4); for small n only. */
#include "pdt/check.h"
#include "pdt/delaunay.h"
#include "pdt/predicates.h"

#include <stdlib.h>

pdt_status pdt_brute_delaunay(const pdt_point *pts, size_t n, pdt_tri **tris, size_t *ntri)
{
    *tris = NULL;
    *ntri = 0;
    uint32_t *u = malloc((n ? n : 1) * sizeof *u);
    if (!u) return PDT_ERR_NOMEM;
    size_t m;
    pdt_status s = pdt_sort_unique(pts, n, u, &m);
    if (s != PDT_OK) {
        free(u);
        return s;
    }
    size_t cap = 16, nt = 0;
    pdt_tri *t = malloc(cap * sizeof *t);
    if (!t) {
        free(u);
        return PDT_ERR_NOMEM;
    }
    for (size_t i = 0; i < m; i++)
        for (size_t j = i + 1; j < m; j++)
            for (size_t k = j + 1; k < m; k++) {
                uint32_t a = u[i], b = u[j], c = u[k];
                int o = pdt_orient(pts[a], pts[b], pts[c]);
                if (o == 0) continue; /* a vertical plane: never a lower face */
                if (o < 0) {
                    uint32_t x = b;
                    b = c;
                    c = x;
                }
                int lower = 1;
                for (size_t q = 0; q < m && lower; q++) {
                    if (q == i || q == j || q == k) continue;
                    if (pdt_incircle_sos(pts[a], pts[b], pts[c], pts[u[q]]) >= 0) lower = 0;
                }
                if (!lower) continue;
                if (nt == cap) {
                    pdt_tri *g = realloc(t, 2 * cap * sizeof *g);
                    if (!g) {
                        free(t);
                        free(u);
                        return PDT_ERR_NOMEM;
                    }
                    t = g;
                    cap *= 2;
                }
                t[nt].v[0] = a;
                t[nt].v[1] = b;
                t[nt].v[2] = c;
                nt++;
            }
    free(u);
    pdt_tri_canonical(t, nt);
    if (nt == 0) {
        free(t);
        t = NULL;
    }
    *tris = t;
    *ntri = nt;
    return PDT_OK;
}
