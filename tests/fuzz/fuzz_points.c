/* pdt — fuzz targets points_text and points_node: pdt_read_points on a file
 * named *.txt (text, "x y" per line) and *.node (Triangle's node format).
 *
 * Every input is read three times: integers only (scale 0), with an integer
 * scale (exact path) and with a fractional scale (double path).  Properties
 * checked besides "no crash, no leak, no undefined behaviour":
 *   - success gives n < 2^32 and a non-NULL array when n > 0;
 *   - failure gives an error message naming the file and NULL/0 results;
 *   - what was read writes back (pdt_write_points) and reads again equal. */
#include "fuzz_common.h"
#include "pdt/io.h"

static void fz_points_once(const char *path, double scale, const char *back)
{
    pdt_point *pts = (pdt_point *)(uintptr_t)1;
    size_t n = 7, coll = 7;
    pdt_err err = {0};
    pdt_status st = pdt_read_points(path, scale, &pts, &n, &coll, &err);
    if (st != PDT_OK) {
        FZ_ASSERT(pts == NULL && n == 0);
        FZ_ASSERT(err.code == st && err.msg[0] != '\0');
        FZ_ASSERT(strstr(err.msg, path) != NULL || st == PDT_ERR_NOMEM);
        return;
    }
    FZ_ASSERT(n < UINT32_MAX);
    FZ_ASSERT(n == 0 || pts != NULL);
    FZ_ASSERT(scale > 0 || coll == 0);
    FZ_ASSERT(coll <= n);
    /* round trip */
    pdt_err werr = {0};
    st = pdt_write_points(back, pts, n, &werr);
    FZ_ASSERT(st == PDT_OK);
    pdt_point *p2 = NULL;
    size_t n2 = 0;
    pdt_err rerr = {0};
    st = pdt_read_points(back, 0, &p2, &n2, NULL, &rerr);
    FZ_ASSERT(st == PDT_OK);
    FZ_ASSERT(n2 == n);
    FZ_ASSERT(n == 0 || memcmp(p2, pts, n * sizeof *pts) == 0);
    free(p2);
    free(pts);
}

/* Read data as a point file named `name` (its extension picks the format). */
static void fz_points_file(const uint8_t *data, size_t size, const char *name, const char *back)
{
    char path[512], bpath[512];
    fz_path(path, sizeof path, name);
    fz_path(bpath, sizeof bpath, back);
    fz_write(path, data, size);
    fz_points_once(path, 0, bpath);
    fz_points_once(path, 1000, bpath);
    fz_points_once(path, 0.37, bpath);
}

static int fuzz_points_text(const uint8_t *data, size_t size)
{
    fz_points_file(data, size, "in.txt", "back.txt");
    return 0;
}

static int fuzz_points_node(const uint8_t *data, size_t size)
{
    fz_points_file(data, size, "in.node", "back.node");
    return 0;
}
