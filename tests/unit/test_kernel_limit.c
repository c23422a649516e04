/* The kernel's per-run point limit that the cli names (PDT_KERNEL_MAX_POINTS):
 * one point more is refused by the kernel itself, before it touches the
 * points, so the constant the user reads is the kernel's real limit.  (The
 * cli's message is tested by tests/sh/limits_ranks.sh with a lowered limit.) */
#include "../harness.h"
#include "pdt/delaunay.h"

TEST(kernel_max_points_is_2_pow_29_minus_1)
{
    CHECK(PDT_KERNEL_MAX_POINTS == 536870911u);
}

TEST(one_point_over_the_limit_is_refused)
{
    pdt_point one = {0, 0}; /* never read: the size is refused first */
    pdt_tri *tris = NULL;
    size_t ntri = 7;
    pdt_tri_stats st;
    CHECK(pdt_triangulate(&one, PDT_KERNEL_MAX_POINTS + 1, &tris, &ntri, &st, NULL) ==
          PDT_ERR_ARG);
    CHECK(tris == NULL && ntri == 0);
    ntri = 7;
    CHECK(pdt_delaunay(&one, PDT_KERNEL_MAX_POINTS + 1, &tris, &ntri, 0, NULL) == PDT_ERR_ARG);
    CHECK(tris == NULL && ntri == 0);
}

int main(void)
{
    RUN(kernel_max_points_is_2_pow_29_minus_1);
    RUN(one_point_over_the_limit_is_refused);
    return test_summary();
}
