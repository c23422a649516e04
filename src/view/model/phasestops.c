/* pdt — the phase stops of a replay: where PgDn / PgUp, --phase and a
 * lesson's `start = phase NAME` land.
 *
 * The ranks of a parallel run go through the same phases, but the merged
 * order of their events depends on timing: rank 0 may classify while rank 2
 * has not lifted its points yet.  A stop therefore belongs to a phase (its
 * name and merge level), not to one rank's PHASE_BEGIN: it is the cursor just
 * after the last of the ranks that go through that phase has begun it.
 * There every such rank is in it or past it, whatever the timing, so a
 * lesson opens, and PgDn arrives, in the state its text names.  The stops
 * come in the order the phases are first begun by any rank ("run" left out);
 * with one rank they are its phase begins. */
#include "pdt/view/replay.h"

#include <stdlib.h>
#include <string.h>

/* Cursor of the stop of the j-th time phase (id, sub) is begun: after the
 * last rank's j-th begin of it (a rank may go through a phase twice, as the
 * one-rank output does); 0 when no rank begins it j + 1 times. */
static size_t stop_of(const pdt_rphase *P, size_t np, uint32_t id, uint32_t sub, uint32_t j,
                      uint32_t *seen, int nranks)
{
    size_t last = 0;
    memset(seen, 0, (size_t)nranks * sizeof *seen);
    for (size_t i = 0; i < np; i++) {
        if (P[i].phase != id || P[i].sub != sub || P[i].rank >= (uint32_t)nranks) continue;
        if (seen[P[i].rank]++ != j) continue;
        if ((size_t)P[i].begin_ev + 1 > last) last = (size_t)P[i].begin_ev + 1;
    }
    return last;
}

static int cmp_stop(const void *x, const void *y)
{
    const pdt_phase_stop *a = x, *b = y;
    return (a->k > b->k) - (a->k < b->k);
}

/* Is phase p among keys[0..nk)?  If not, adds it. */
static int seen_key(pdt_phase_stop *keys, size_t *nk, const pdt_rphase *p)
{
    for (size_t j = 0; j < *nk; j++)
        if (keys[j].phase == p->phase && keys[j].sub == p->sub) return 1;
    keys[(*nk)++] = (pdt_phase_stop){0, p->phase, p->sub};
    return 0;
}

size_t pdt_replay_phase_stops(const pdt_replay *r, pdt_phase_stop *out, size_t cap)
{
    size_t np, n = 0, nk = 0;
    const pdt_rphase *P = pdt_replay_phases(r, &np);
    int nranks = pdt_replay_nranks(r);
    uint32_t *seen = malloc((nranks > 0 ? (size_t)nranks : 1) * sizeof *seen);
    pdt_phase_stop *keys = malloc((np ? np : 1) * sizeof *keys);
    if (!seen || !keys) {
        free(seen);
        free(keys);
        return 0;
    }
    for (size_t i = 0; i < np; i++) {
        if (P[i].phase == PDT_PH_RUN || seen_key(keys, &nk, &P[i])) continue;
        size_t k;
        for (uint32_t j = 0; (k = stop_of(P, np, P[i].phase, P[i].sub, j, seen, nranks)); j++) {
            if (n < cap) out[n] = (pdt_phase_stop){k, P[i].phase, P[i].sub};
            n++;
        }
    }
    free(seen);
    free(keys);
    qsort(out, n < cap ? n : cap, sizeof *out, cmp_stop);
    return n;
}

/* The stops in a buffer the caller frees (NULL when there are none). */
static pdt_phase_stop *all_stops(const pdt_replay *r, size_t *n)
{
    pdt_phase_stop probe[64];
    *n = pdt_replay_phase_stops(r, probe, 64);
    pdt_phase_stop *s = malloc((*n ? *n : 1) * sizeof *s);
    if (!s) { *n = 0; return NULL; }
    if (*n <= 64) memcpy(s, probe, *n * sizeof *s);
    else pdt_replay_phase_stops(r, s, *n);
    return s;
}

size_t pdt_replay_find_phase_stop(const pdt_replay *r, size_t k, int dir)
{
    size_t n, m = pdt_replay_count(r), to = dir > 0 ? m : 0;
    pdt_phase_stop *s = all_stops(r, &n);
    for (size_t i = 0; s && i < n; i++) {
        size_t j = dir > 0 ? i : n - 1 - i;
        if ((dir > 0 && s[j].k > k) || (dir < 0 && s[j].k < k)) { to = s[j].k; break; }
    }
    free(s);
    return to;
}

size_t pdt_replay_phase_stop_named(const pdt_replay *r, const char *name)
{
    const char *colon = strchr(name, ':');
    size_t len = colon ? (size_t)(colon - name) : strlen(name), n, at = (size_t)-1;
    long level = colon ? strtol(colon + 1, NULL, 10) : 0;
    pdt_phase_stop *s = all_stops(r, &n);
    for (size_t i = 0; s && i < n; i++) {
        const char *nm = pdt_phase_name((int)s[i].phase);
        if (nm && strlen(nm) == len && !strncmp(nm, name, len) && (long)s[i].sub == level) {
            at = s[i].k;
            break;
        }
    }
    free(s);
    return at;
}

size_t pdt_replay_box_from(const pdt_replay *r, int rank)
{
    size_t np;
    const pdt_rphase *P = pdt_replay_phases(r, &np);
    for (size_t i = 0; i < np; i++)
        if (P[i].rank == (uint32_t)rank && P[i].phase == PDT_PH_PARTITION)
            return (size_t)P[i].begin_ev + 1;
    return 0;
}
