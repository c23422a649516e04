/* pdt — the viewer's palette: eight hues for the rank groups a screen shows
 * and the status colours drawn beside them (discarded, selected, the
 * circumdisk).  Every pair of them is at least CIEDE2000 10 apart for normal
 * vision and for simulated deuteranopia and protanopia (Machado, Oliveira
 * and Fernandes 2009, severity 1): tests/unit/test_view_palette.c checks it.
 * The hues alternate dark and light, so that neighbouring groups differ in
 * lightness as well as hue.  A screen never shows more than eight groups
 * (pdt_ranktree_cut), so no hue repeats on it. */
#include "render_int.h"

static const double hues[PDT_PALETTE_HUES][3] = {
    {0.440, 0.484, 0.983}, /* lavender blue, L* 57 */
    {0.571, 0.855, 0.000}, /* yellow green, L* 80 */
    {0.531, 0.054, 0.411}, /* purple, L* 31 */
    {0.003, 0.871, 0.637}, /* mint, L* 79 */
    {0.465, 0.217, 0.228}, /* brown red, L* 32 */
    {0.753, 0.496, 0.632}, /* mauve, L* 61 */
    {0.066, 0.174, 0.928}, /* deep blue, L* 34 */
    {0.804, 0.243, 0.433}, /* rose, L* 49 */
};

const double PDT_RED[3] = {0.698, 0.094, 0.008};     /* discarded, messages in flight */
const double PDT_SELECT[3] = {0.041, 0.793, 0.939};  /* the clicked point, edge, triangle */
const double PDT_DISK[3] = {0.824, 0.395, 0.039};    /* the circumdisk's outline */

void pdt_palette_rgb(int i, double rgb[3])
{
    if (i < 0 || i >= PDT_PALETTE_HUES) {
        rgb[0] = rgb[1] = rgb[2] = 0.6; /* a rank in no group on screen */
        return;
    }
    memcpy(rgb, hues[i], sizeof hues[i]);
}

void pdt_rank_rgb(int rank, double rgb[3])
{
    if (rank < 0) rank = 0;
    pdt_palette_rgb(rank % PDT_PALETTE_HUES, rgb);
    int cycle = (rank / PDT_PALETTE_HUES) % 3; /* 0 as is, 1 darker, 2 lighter */
    for (int i = 0; i < 3; i++)
        rgb[i] = cycle == 0 ? rgb[i] : cycle == 1 ? 0.55 * rgb[i] : rgb[i] + 0.5 * (1 - rgb[i]);
}

size_t pdt_palette_screen(double (*out)[3], size_t cap)
{
    size_t n = 0;
    for (int i = 0; i < PDT_PALETTE_HUES && n < cap; i++) pdt_palette_rgb(i, out[n++]);
    const double *st[] = {PDT_RED, PDT_SELECT, PDT_DISK};
    for (size_t i = 0; i < 3 && n < cap; i++, n++) memcpy(out[n], st[i], sizeof out[n]);
    return n;
}
