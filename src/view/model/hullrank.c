/* pdt — which rank's colour the legend's hull swatch takes (replay.h). */
#include "pdt/view/replay.h"

int pdt_replay_hull_rank(const pdt_replay *r, size_t k)
{
    size_t n;
    const pdt_rhull *H = pdt_replay_hulls(r, &n);
    int q = 0;
    for (size_t i = 0; i < n && H[i].ev < k; i++) q = (int)H[i].rank;
    return q;
}
