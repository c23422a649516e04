/* pdt — the viewer's optional panels: parsing --panels and the layout that
 * gives hidden panels no room. */
#include <math.h>
#include <string.h>

#include "../harness.h"
#include "pdt/view/render.h"

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

/* --panels none: the picture takes the whole width (no empty side column),
 * the legend is a strip under it. */
TEST(no_side_panels_picture_takes_width)
{
    pdt_layout L;
    pdt_render_layout_panels(1024, 768, 4, 0, &L);
    CHECK_MSG(L.geo.w == 1024, "geometry %g wide", L.geo.w);
    CHECK(L.legend.w == 1024 && L.legend.y >= L.geo.y + L.geo.h && L.legend.h > 0);
    CHECK(L.legend.y + L.legend.h <= 768);
    pdt_render_layout_panels(1024, 768, 4, PDT_PANEL_TIMELINE, &L);
    CHECK(L.geo.w == 1024 && L.timeline.w == 1024 && L.legend.y + L.legend.h <= L.timeline.y);
}

/* A projector at 1024x768: panel text >= 17 px, labels >= 13 px; at
 * 1920x1080 larger still. */
TEST(projector_font_sizes)
{
    pdt_layout a, b;
    pdt_render_layout(1024, 768, 4, &a);
    CHECK_MSG(a.body >= 17 && a.label >= 13 && a.font >= a.body, "font %g body %g label %g", a.font,
              a.body, a.label);
    pdt_render_layout(1920, 1080, 4, &b);
    CHECK(b.body > a.body && b.label > a.label);
}

/* The font scale scales the text and the panels that hold it. */
TEST(font_scale_changes_layout)
{
    pdt_view v;
    pdt_view_defaults(&v);
    pdt_layout a, b, c;
    pdt_render_layout_view(1600, 1000, 4, &v, &a);
    v.font_scale = 1.5;
    pdt_render_layout_view(1600, 1000, 4, &v, &b);
    CHECK_MSG(fabs(b.font - 1.5 * a.font) < 1e-9, "%g vs %g", b.font, a.font);
    CHECK(b.body > a.body && b.label > a.label);
    CHECK(b.top.h > a.top.h && b.legend.h > a.legend.h && b.geo.h < a.geo.h);
    v.font_scale = 100; /* clamped to 4 */
    pdt_render_layout_view(1600, 1000, 4, &v, &c);
    CHECK(fabs(c.font - 4 * a.font) < 1e-9);
}

TEST(theme_parse)
{
    int t = -1;
    CHECK(pdt_theme_parse("light", &t) == 0 && t == PDT_THEME_LIGHT);
    CHECK(pdt_theme_parse("dark", &t) == 0 && t == PDT_THEME_DARK);
    CHECK(pdt_theme_parse("contrast", &t) == 0 && t == PDT_THEME_CONTRAST);
    CHECK(pdt_theme_parse("Dark", &t) == -1 && pdt_theme_parse("", &t) == -1);
}

int main(void)
{
    RUN(no_side_panels_picture_takes_width);
    RUN(projector_font_sizes);
    RUN(font_scale_changes_layout);
    RUN(theme_parse);
    RUN(panels_parse);
    RUN(hidden_panels_get_no_room);
    return test_summary();
}
