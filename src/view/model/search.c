/* pdt — searching a replay: events by class, phases by name. */
#include "pdt/view/replay.h"
#include "replay_int.h"
#include "build_int.h"
#include "pdt/bigmem.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <pthread.h>
#include <stdatomic.h>
#include <sys/mman.h>
#include <unistd.h>

/* ---- searching --------------------------------------------------------------- */

static const char *const class_names[PDT_EVC_COUNT] = {"any event", "push/pop", "lift-up",
                                                       "rejection", "merge", "triangle"};

const char *pdt_ev_class_name(int c) { return c >= 0 && c < PDT_EVC_COUNT ? class_names[c] : NULL; }

int pdt_ev_in_class(int kind, int c)
{
    switch (c) {
    case PDT_EVC_ANY: return 1;
    case PDT_EVC_STACK: return kind == PDT_EV_PUSH || kind == PDT_EV_POP;
    case PDT_EVC_LIFT: return kind == PDT_EV_LIFT;
    case PDT_EVC_REJECT: return kind == PDT_EV_RA_DEFER || kind == PDT_EV_DISCARD;
    case PDT_EVC_MERGE: return kind == PDT_EV_MERGE_BEGIN || kind == PDT_EV_MERGE_END;
    case PDT_EVC_TRI: return is_tri_kind(kind);
    default: return 0;
    }
}

size_t pdt_replay_find(const pdt_replay *r, size_t k, int dir, int c, const uint8_t *rank_visible)
{
    if (k > r->m) k = r->m;
    if (dir > 0) {
        for (size_t i = k; i < r->m; i++)
            if (pdt_ev_in_class(kind_at(r, i), c) &&
                (!rank_visible || rank_visible[pdt_replay_rank_of(r, i)]))
                return i + 1;
    } else {
        for (size_t i = k >= 2 ? k - 1 : 0; i-- > 0;)
            if (pdt_ev_in_class(kind_at(r, i), c) &&
                (!rank_visible || rank_visible[pdt_replay_rank_of(r, i)]))
                return i + 1;
        if (k >= 1) return 0;
    }
    return k;
}

size_t pdt_replay_find_phase(const pdt_replay *r, size_t k, int dir)
{
    if (dir > 0) {
        for (size_t p = 0; p < r->nphase; p++)
            if (r->phases[p].first && r->phases[p].phase != PDT_PH_RUN && r->phases[p].begin_ev >= k)
                return (size_t)r->phases[p].begin_ev + 1;
        return r->m;
    }
    for (size_t p = r->nphase; p-- > 0;)
        if (r->phases[p].first && r->phases[p].phase != PDT_PH_RUN && (size_t)r->phases[p].begin_ev + 1 < k)
            return (size_t)r->phases[p].begin_ev + 1;
    return 0;
}

size_t pdt_replay_find_phase_name(const pdt_replay *r, const char *name)
{
    char base[64];
    long level = -1;
    const char *colon = strchr(name, ':');
    size_t len = colon ? (size_t)(colon - name) : strlen(name);
    if (len >= sizeof base) return (size_t)-1;
    memcpy(base, name, len);
    base[len] = 0;
    if (colon) level = strtol(colon + 1, NULL, 10);
    for (size_t i = 0; i < r->m; i++) {
        if (kind_at(r, i) != PDT_EV_PHASE_BEGIN) continue;
        const pdt_event *e = &rec_at(r, i)->ev;
        const char *nm = pdt_phase_name(e->sub);
        if (nm && !strcmp(nm, base) && (level < 0 || (long)e->a == level)) return i + 1;
    }
    return (size_t)-1;
}
