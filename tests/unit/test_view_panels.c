/* pdt — the viewer's optional panels: parsing --panels and the layout that
 * gives hidden panels no room. */
#include <string.h>

#include "../harness.h"
#include "pdt/render.h"

TEST(panels_parse)
{
    unsigned p = 0;
    CHECK(pdt_panels_parse("code,stack", &p) == 0 && p == (PDT_PANEL_CODE | PDT_PANEL_STACK));
    CHECK(pdt_panels_parse("all", &p) == 0 && p == PDT_PANEL_ALL);
    CHECK(pdt_panels_parse("none", &p) == 0 && p == 0);
    CHECK(pdt_panels_parse("lifted,timeline", &p) == 0 &&
          p == (PDT_PANEL_LIFTED | PDT_PANEL_TIMELINE));
    CHECK(pdt_panels_parse("code,bogus", &p) == -1);
    CHECK(pdt_panels_parse("stac", &p) == -1);
}

TEST(hidden_panels_get_no_room)
{
    pdt_layout all, some;
    pdt_render_layout(1600, 1000, 4, &all);
    pdt_render_layout_panels(1600, 1000, 4, PDT_PANEL_CODE | PDT_PANEL_STACK, &some);
    CHECK(some.lifted.w == 0 && some.lifted.h == 0);
    CHECK(some.timeline.w == 0 && some.timeline.h == 0);
    CHECK(some.code.h == all.code.h);
    CHECK_MSG(some.stack.h > all.stack.h, "stack %g vs %g", some.stack.h, all.stack.h);
    CHECK_MSG(some.geo.h > all.geo.h, "geometry %g vs %g", some.geo.h, all.geo.h);
    pdt_layout code_only;
    pdt_render_layout_panels(1600, 1000, 4, PDT_PANEL_CODE, &code_only);
    CHECK(code_only.stack.w == 0 && code_only.lifted.w == 0);
    CHECK(code_only.code.h > all.code.h);
    /* the full layout equals the one with every bit set */
    pdt_layout every;
    pdt_render_layout_panels(1600, 1000, 4, PDT_PANEL_ALL, &every);
    CHECK(memcmp(&every, &all, sizeof all) == 0);
}

int main(void)
{
    RUN(panels_parse);
    RUN(hidden_panels_get_no_room);
    return test_summary();
}
