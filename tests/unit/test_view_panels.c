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
    CHECK_MSG(some.code.h >= all.code.h, "code %g vs %g", some.code.h, all.code.h);
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

/* A projector at 1024x768: event line >= 20 px, code >= 18 px, every other
 * text >= 16 px; at 1920x1080 larger still. */
TEST(projector_font_sizes)
{
    pdt_layout a, b;
    pdt_render_layout(1024, 768, 4, &a);
    CHECK_MSG(a.font >= 20 && a.body >= 18 && a.label >= 16, "font %g body %g label %g", a.font,
              a.body, a.label);
    pdt_render_layout(1920, 1080, 4, &b);
    CHECK(b.body > a.body && b.label > a.label);
}

static int rect_in(pdt_rect R, double w, double h)
{
    return R.w == 0 || (R.x >= 0 && R.y >= 0 && R.x + R.w <= w && R.y + R.h <= h);
}

static int rects_meet(pdt_rect a, pdt_rect b)
{
    return a.w > 0 && b.w > 0 && a.h > 0 && b.h > 0 && a.x < b.x + b.w && b.x < a.x + a.w &&
           a.y < b.y + b.h && b.y < a.y + a.h;
}

/* At every screen size, font scale and panel choice the panels lie in the
 * frame and do not meet; the code panel keeps four rows and its title. */
TEST(panels_apart_at_every_scale)
{
    static const int sizes[][2] = {{1024, 768}, {1280, 800}, {1600, 1000}, {1920, 1080}};
    static const double scales[] = {1, 1.3, 1.5, 2};
    for (size_t i = 0; i < 4; i++)
        for (size_t j = 0; j < 4; j++)
            for (unsigned p = 0; p <= PDT_PANEL_ALL; p++) {
                pdt_layout L;
                double w = sizes[i][0], h = sizes[i][1];
                pdt_render_layout_scaled(w, h, 4, p, scales[j], &L);
                pdt_rect R[] = {L.top, L.geo, L.legend, L.code, L.stack, L.lifted, L.timeline};
                int bad = 0;
                for (int a = 0; a < 7; a++) {
                    bad |= !rect_in(R[a], w, h);
                    for (int b = a + 1; b < 7; b++) bad |= rects_meet(R[a], R[b]);
                }
                if (p & PDT_PANEL_CODE) bad |= L.code.h < 1.8 * L.font + 4 * 1.4 * L.body - 1;
                CHECK_MSG(!bad, "%gx%g scale %g panels %u", w, h, scales[j], p);
            }
}

/* On a projector with every panel, the lifted view gives way before the
 * code panel loses its lines; at 1600x1000 all stay. */
TEST(lifted_view_gives_way_first)
{
    pdt_layout L;
    pdt_render_layout(1024, 768, 4, &L);
    CHECK_MSG(L.lifted.w == 0 && L.code.h >= 1.8 * L.font + 7 * 1.4 * L.body - 1, "code %g lifted %g",
              L.code.h, L.lifted.h);
    pdt_render_layout(1600, 1000, 4, &L);
    CHECK(L.lifted.w > 0 && L.stack.w > 0 && L.code.w > 0 && L.timeline.w > 0);
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
    /* the legend grows, or becomes a strip across the window, or (when a
     * strip would leave the picture less than its share) is named hidden */
    int legend_ok = b.legend.h > a.legend.h || b.legend.w > a.legend.w ||
                    ((b.hidden & PDT_PANEL_LEGEND) && b.more.w > 0);
    CHECK(b.top.h > a.top.h && legend_ok && b.geo.w * b.geo.h < a.geo.w * a.geo.h);
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
    RUN(panels_apart_at_every_scale);
    RUN(lifted_view_gives_way_first);
    RUN(font_scale_changes_layout);
    RUN(theme_parse);
    RUN(panels_parse);
    RUN(hidden_panels_get_no_room);
    return test_summary();
}
