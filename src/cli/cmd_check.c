/* pdt check — verify that a triangle file is exactly T*(points). */
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "pdt/check.h"
#include "pdt/io.h"

static const char help[] =
    "usage: pdt check POINTS TRIANGLES [--scale K]\n"
    "\n"
    "Verify, with exact arithmetic and independently of the triangulator, that\n"
    "TRIANGLES (.tri: 'i j k' per line, 0-based; or Triangle's .ele) is exactly\n"
    "T*, the Delaunay triangulation of POINTS with the lexicographic tie rule:\n"
    "every triangle counter-clockwise, the triangles tile the convex hull, every\n"
    "edge passes the empty-circle test, and the count is 2n - h - 2.\n"
    "\n"
    "POINTS and --scale K: as for pdt triangulate.\n"
    "Exit status: 0 it is T*, 1 it is not (the first violation is printed),\n"
    "2 usage or input error.\n";

int pdt_cmd_check(int argc, char **argv)
{
    double scale = 0;
    const pdt_cli_opt opts[] = {
        { "--scale", NULL, PDT_OPT_POSNUM, &scale },
        { NULL, NULL, PDT_OPT_FLAG, NULL },
    };
    const char *pos[2];
    int npos;
    int rc = pdt_cli_parse("check", help, argc, argv, opts, pos, 2, &npos);
    if (rc == 1) return PDT_EXIT_OK;
    if (rc) return PDT_EXIT_USAGE;
    if (npos != 2) return pdt_cli_usage("check", "needs a POINTS file and a TRIANGLES file");

    pdt_err err = { PDT_OK, "" };
    pdt_point *pts = NULL;
    pdt_tri *tris = NULL;
    size_t n = 0, ntri = 0;
    pdt_status st = pdt_read_points(pos[0], scale, &pts, &n, NULL, &err);
    if (st == PDT_OK) st = pdt_read_tris_n(pos[1], n, &tris, &ntri, &err);
    if (st == PDT_OK) {
        st = pdt_check_delaunay(pts, n, tris, ntri, &err);
        if (st == PDT_OK)
            printf("ok: the %zu triangles of %s are the Delaunay triangulation T* of the %zu "
                   "points of %s\n", ntri, pos[1], n, pos[0]);
        else if (st == PDT_ERR_CHECK) /* the reason names triangles and edges of pos[1] */
            fprintf(stderr, "pdt check: %s is NOT the Delaunay triangulation T* of %s\n"
                    "pdt check: %s: %s\n", pos[1], pos[0], pos[1], err.msg);
    }
    rc = st == PDT_OK ? PDT_EXIT_OK : st == PDT_ERR_CHECK ? PDT_EXIT_CHECK : pdt_cli_fail(&err);
    free(pts);
    free(tris);
    return rc;
}
