/* pdt — the viewer's palette checked, not claimed: every pair of colours a
 * screen can show together (the eight group hues and the status colours,
 * pdt_palette_screen) at least CIEDE2000 10 apart, for normal vision and
 * for simulated deuteranopia and protanopia.
 *
 * Simulation: Machado, Oliveira and Fernandes (2009), "A physiologically-
 * based model for simulation of color vision deficiency", severity 1.0,
 * applied to linear RGB; colour difference: CIEDE2000 (Sharma, Wu and
 * Dalal 2005) in CIELAB under D65. */
#include <math.h>
#include <string.h>

#include "../harness.h"
#include "pdt/view/render.h"

static const double NORMAL[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
static const double DEUTAN[3][3] = {{0.367322, 0.860646, -0.227968},
                                    {0.280085, 0.672501, 0.047413},
                                    {-0.011820, 0.042940, 0.968881}};
static const double PROTAN[3][3] = {{0.152286, 1.052583, -0.204868},
                                    {0.114503, 0.786281, 0.099216},
                                    {-0.003882, -0.048116, 1.051998}};

static double linear(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static double lab_f(double t)
{
    return t > 216.0 / 24389 ? cbrt(t) : (24389.0 / 27 * t + 16) / 116;
}

/* sRGB in [0,1] as seen through matrix M, into CIELAB (D65). */
static void to_lab(const double rgb[3], const double M[3][3], double lab[3])
{
    double l[3], s[3];
    for (int i = 0; i < 3; i++) l[i] = linear(rgb[i]);
    for (int i = 0; i < 3; i++) {
        s[i] = M[i][0] * l[0] + M[i][1] * l[1] + M[i][2] * l[2];
        s[i] = s[i] < 0 ? 0 : s[i] > 1 ? 1 : s[i];
    }
    double X = 0.4124564 * s[0] + 0.3575761 * s[1] + 0.1804375 * s[2];
    double Y = 0.2126729 * s[0] + 0.7151522 * s[1] + 0.0721750 * s[2];
    double Z = 0.0193339 * s[0] + 0.1191920 * s[1] + 0.9503041 * s[2];
    double fx = lab_f(X / 0.95047), fy = lab_f(Y), fz = lab_f(Z / 1.08883);
    lab[0] = 116 * fy - 16;
    lab[1] = 500 * (fx - fy);
    lab[2] = 200 * (fy - fz);
}

static double deg(double r)
{
    return r * 180 / M_PI;
}

static double rad(double d)
{
    return d * M_PI / 180;
}

/* Mean hue of h1, h2 (degrees) and their difference, as CIEDE2000 wants. */
static void hue_terms(double c1, double c2, double h1, double h2, double *dh, double *hb)
{
    if (c1 * c2 == 0) {
        *dh = 0;
        *hb = h1 + h2;
        return;
    }
    *dh = h2 - h1;
    if (*dh > 180) *dh -= 360;
    else if (*dh < -180) *dh += 360;
    if (fabs(h1 - h2) <= 180) *hb = (h1 + h2) / 2;
    else *hb = h1 + h2 < 360 ? (h1 + h2 + 360) / 2 : (h1 + h2 - 360) / 2;
}

static double ciede2000(const double a[3], const double b[3])
{
    double c1 = hypot(a[1], a[2]), c2 = hypot(b[1], b[2]), cb = (c1 + c2) / 2;
    double g = 0.5 * (1 - sqrt(pow(cb, 7) / (pow(cb, 7) + pow(25, 7))));
    double a1 = (1 + g) * a[1], a2 = (1 + g) * b[1];
    double c1p = hypot(a1, a[2]), c2p = hypot(a2, b[2]);
    double h1 = c1p == 0 ? 0 : fmod(deg(atan2(a[2], a1)) + 360, 360);
    double h2 = c2p == 0 ? 0 : fmod(deg(atan2(b[2], a2)) + 360, 360);
    double dh, hb;
    hue_terms(c1p, c2p, h1, h2, &dh, &hb);
    double dL = b[0] - a[0], dC = c2p - c1p, dH = 2 * sqrt(c1p * c2p) * sin(rad(dh / 2));
    double Lb = (a[0] + b[0]) / 2, Cb = (c1p + c2p) / 2;
    double T = 1 - 0.17 * cos(rad(hb - 30)) + 0.24 * cos(rad(2 * hb)) + 0.32 * cos(rad(3 * hb + 6)) -
               0.20 * cos(rad(4 * hb - 63));
    double dth = 30 * exp(-pow((hb - 275) / 25, 2));
    double RC = 2 * sqrt(pow(Cb, 7) / (pow(Cb, 7) + pow(25, 7)));
    double SL = 1 + 0.015 * pow(Lb - 50, 2) / sqrt(20 + pow(Lb - 50, 2));
    double SC = 1 + 0.045 * Cb, SH = 1 + 0.015 * Cb * T, RT = -sin(rad(2 * dth)) * RC;
    return sqrt(pow(dL / SL, 2) + pow(dC / SC, 2) + pow(dH / SH, 2) + RT * (dC / SC) * (dH / SH));
}

/* The closest pair of cols[0..n) under any of the three visions: its
 * distance, and which pair and vision in *i, *j, *v. */
static double closest(const double (*cols)[3], size_t n, size_t *ci, size_t *cj, int *cv)
{
    const double(*M[3])[3] = {NORMAL, DEUTAN, PROTAN};
    double best = 1e9;
    for (int v = 0; v < 3; v++)
        for (size_t i = 0; i < n; i++)
            for (size_t j = i + 1; j < n; j++) {
                double la[3], lb[3];
                to_lab(cols[i], M[v], la);
                to_lab(cols[j], M[v], lb);
                double d = ciede2000(la, lb);
                if (d < best) best = d, *ci = i, *cj = j, *cv = v;
            }
    return best;
}

TEST(ciede2000_matches_sharma_test_data)
{
    static const double pairs[][7] = { /* L a b, L a b, dE00 (Sharma et al., table 1) */
        {50, 2.6772, -79.7751, 50, 0, -82.7485, 2.0425},
        {50, 0, 0, 50, -1, 2, 2.3669},
        {50, 2.5, 0, 73, 25, -18, 27.1492},
    };
    for (size_t i = 0; i < sizeof pairs / sizeof *pairs; i++) {
        double d = ciede2000(pairs[i], pairs[i] + 3);
        CHECK_MSG(fabs(d - pairs[i][6]) < 1e-3, "pair %zu: %.4f, want %.4f", i, d, pairs[i][6]);
    }
}

TEST(palette_colours_on_one_screen_are_delta_e00_10_apart_for_normal_deutan_protan)
{
    double cols[32][3];
    size_t n = pdt_palette_screen(cols, 32), i = 0, j = 0;
    int v = 0;
    static const char *const vision[] = {"normal", "deuteranope", "protanope"};
    CHECK(n >= PDT_PALETTE_HUES + 3);
    double d = closest((const double(*)[3])cols, n, &i, &j, &v);
    CHECK_MSG(d >= 10, "colours %zu and %zu are dE00 %.1f apart for a %s viewer", i, j, d, vision[v]);
}

TEST(okabe_ito_ranks_1_and_6_fail_for_deuteranopes)
{
    /* the check can fail: the palette before this one (Okabe-Ito, yellow
     * darkened) had orange and dark yellow dE00 1.4 apart for deuteranopes */
    static const double old[2][3] = {{0.902, 0.624, 0.000}, {0.741, 0.690, 0.000}};
    size_t i, j;
    int v;
    double d = closest(old, 2, &i, &j, &v);
    CHECK_MSG(d < 10 && v == 1, "dE00 %.1f (vision %d)", d, v);
}

TEST(group_hues_differ_in_lightness_from_their_neighbours)
{
    for (int i = 0; i + 1 < PDT_PALETTE_HUES; i++) {
        double a[3], b[3], la[3], lb[3];
        pdt_palette_rgb(i, a);
        pdt_palette_rgb(i + 1, b);
        to_lab(a, NORMAL, la);
        to_lab(b, NORMAL, lb);
        CHECK_MSG(fabs(la[0] - lb[0]) >= 12, "hues %d and %d: L* %.0f and %.0f", i, i + 1, la[0], lb[0]);
    }
}

int main(void)
{
    RUN(ciede2000_matches_sharma_test_data);
    RUN(palette_colours_on_one_screen_are_delta_e00_10_apart_for_normal_deutan_protan);
    RUN(okabe_ito_ranks_1_and_6_fail_for_deuteranopes);
    RUN(group_hues_differ_in_lightness_from_their_neighbours);
    return test_summary();
}
