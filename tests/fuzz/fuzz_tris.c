/* pdt — fuzz target tris: the triangle readers (pdt_read_tris on *.tri and
 * *.ele, pdt_read_tris_n with a small point count).
 * Properties besides "no crash, no leak, no undefined behaviour":
 *   - success gives a non-NULL array when ntri > 0, indices < 2^32 - 1, and
 *     with pdt_read_tris_n every index < npts;
 *   - the same text read with and without the range check agrees when every
 *     index is in range;
 *   - a failure names the file; .tri triangles write back and read equal. */
#include "fuzz_common.h"
#include "pdt/io.h"

static void fz_tris_once(const char *path, const char *back)
{
    enum { NPTS = 12 };
    pdt_tri *t = (pdt_tri *)(uintptr_t)1, *tn = NULL;
    size_t nt = 5, nn = 5;
    pdt_err err = {0}, errn = {0};
    pdt_status st = pdt_read_tris(path, &t, &nt, &err);
    pdt_status stn = pdt_read_tris_n(path, NPTS, &tn, &nn, &errn);
    if (st != PDT_OK) {
        FZ_ASSERT(t == NULL && nt == 0 && err.code == st && strstr(err.msg, path));
        FZ_ASSERT(stn != PDT_OK); /* the range check only adds failures */
        FZ_ASSERT(tn == NULL && nn == 0);
        return;
    }
    FZ_ASSERT(nt == 0 || t != NULL);
    int in_range = 1;
    for (size_t i = 0; i < nt; i++)
        for (int k = 0; k < 3; k++) {
            FZ_ASSERT(t[i].v[k] < UINT32_MAX);
            if (t[i].v[k] >= NPTS) in_range = 0;
        }
    if (in_range) {
        FZ_ASSERT(stn == PDT_OK && nn == nt);
        FZ_ASSERT(nt == 0 || memcmp(t, tn, nt * sizeof *t) == 0);
    } else {
        FZ_ASSERT(stn == PDT_ERR_PARSE && strstr(errn.msg, "out of range"));
        FZ_ASSERT(tn == NULL && nn == 0);
    }
    free(tn);
    /* write back as canonical .tri and read again */
    pdt_err werr = {0};
    FZ_ASSERT(pdt_write_tris(back, PDT_FMT_TRI, NULL, 0, t, nt, &werr) == PDT_OK);
    pdt_tri *t2 = NULL;
    size_t n2 = 0;
    pdt_err rerr = {0};
    FZ_ASSERT(pdt_read_tris(back, &t2, &n2, &rerr) == PDT_OK);
    FZ_ASSERT(n2 == nt && (nt == 0 || memcmp(t2, t, nt * sizeof *t) == 0));
    free(t2);
    free(t);
}

static int fuzz_tris(const uint8_t *data, size_t size)
{
    char p1[512], p2[512], back[512];
    fz_path(p1, sizeof p1, "in.tri");
    fz_path(p2, sizeof p2, "in.ele");
    fz_path(back, sizeof back, "back.tri");
    fz_write(p1, data, size);
    fz_write(p2, data, size);
    fz_tris_once(p1, back);
    fz_tris_once(p2, back);
    return 0;
}
