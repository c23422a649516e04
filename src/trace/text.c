/* pdt — events as readable text (pdt trace dump, the viewer's event list). */
#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "pdt/tracefile.h"

int pdt_event_kind_by_name(const char *name)
{
    for (int k = 0; k < PDT_EV_KIND_COUNT; k++)
        if (!strcmp(pdt_event_kind_name(k), name)) return k;
    return -1;
}

static const char *or_num(const char *name, char *tmp, size_t cap, unsigned v)
{
    if (name) return name;
    snprintf(tmp, cap, "%u", v);
    return tmp;
}

static const char *pt_or_dash(char *tmp, size_t cap, uint32_t v)
{
    if (v == UINT32_MAX) return "-";
    snprintf(tmp, cap, "%" PRIu32, v);
    return tmp;
}

/* A triangle event's corners rotated to start at the smallest index: the one
 * corner order of every text (the events are counter-clockwise already). */
static pdt_event tri_rotated(const pdt_event *e)
{
    pdt_event r = *e;
    if (e->b < e->a && e->b < e->c) {
        r.a = e->b; r.b = e->c; r.c = e->a;
    } else if (e->c < e->a && e->c < e->b) {
        r.a = e->c; r.b = e->a; r.c = e->b;
    }
    return r;
}

/* The triangle events (corners already rotated to start at the least). */
static void format_tri(const pdt_event *e, char *buf, size_t cap)
{
    char t1[24];
    switch (e->kind) {
    case PDT_EV_TRI_NEW:
        snprintf(buf, cap, "tri-new %s %" PRIu32 " %" PRIu32 " %" PRIu32,
                 e->sub == 0 ? "local" : e->sub == 1 ? "border" : or_num(NULL, t1, sizeof t1, e->sub),
                 e->a, e->b, e->c);
        break;
    case PDT_EV_TRI_FINAL:
        snprintf(buf, cap, "tri-final %" PRIu32 " %" PRIu32 " %" PRIu32, e->a, e->b, e->c);
        break;
    case PDT_EV_RA_DEFER:
        snprintf(buf, cap, "ra-defer %" PRIu32 " %" PRIu32 " %" PRIu32 " rank=%" PRId64, e->a, e->b,
                 e->c, e->v);
        break;
    case PDT_EV_SHIP:
        snprintf(buf, cap, "ship %" PRIu32 " %" PRIu32 " %" PRIu32 " to=%" PRId64, e->a, e->b, e->c,
                 e->v);
        break;
    case PDT_EV_DISCARD:
        if (e->v < 0)
            snprintf(buf, cap, "discard %" PRIu32 " %" PRIu32 " %" PRIu32 " witness=-", e->a, e->b,
                     e->c);
        else
            snprintf(buf, cap, "discard %" PRIu32 " %" PRIu32 " %" PRIu32 " witness=%" PRId64, e->a,
                     e->b, e->c, e->v);
        break;
    }
}

/* Phases, the stacks and Graham's points: 1 when e is one of them (then
 * written to buf). */
static int format_local(const pdt_event *e, const char *kn, char *buf, size_t cap)
{
    char t1[24], t2[24];
    switch (e->kind) {
    case PDT_EV_PHASE_BEGIN:
    case PDT_EV_PHASE_END:
        if (e->a)
            snprintf(buf, cap, "%s %s level=%" PRIu32, kn,
                     or_num(pdt_phase_name(e->sub), t1, sizeof t1, e->sub), e->a);
        else
            snprintf(buf, cap, "%s %s", kn, or_num(pdt_phase_name(e->sub), t1, sizeof t1, e->sub));
        break;
    case PDT_EV_PUSH:
        snprintf(buf, cap, "push %s pt=%" PRIu32 " depth=%" PRIu32,
                 or_num(pdt_stack_name(e->sub), t1, sizeof t1, e->sub), e->a, e->b);
        break;
    case PDT_EV_POP:
        snprintf(buf, cap, "pop %s pt=%" PRIu32 " depth=%" PRIu32 " cause=%s",
                 or_num(pdt_stack_name(e->sub), t1, sizeof t1, e->sub), e->a, e->b,
                 pt_or_dash(t2, sizeof t2, e->c));
        break;
    case PDT_EV_LIFT:
        snprintf(buf, cap, "lift pt=%" PRIu32 " z=%" PRIu64, e->a, (uint64_t)e->v);
        break;
    case PDT_EV_SORT:
        snprintf(buf, cap, "sort pt=%" PRIu32 " pos=%" PRIu32, e->a, e->b);
        break;
    case PDT_EV_DELETE:
        snprintf(buf, cap, "delete %s pt=%" PRIu32 " kept=%" PRIu32,
                 e->sub == PDT_DEL_ANGULAR_TIE ? "angular-tie"
                 : e->sub == PDT_DEL_COINCIDENT ? "coincident"
                                                 : or_num(NULL, t1, sizeof t1, e->sub),
                 e->a, e->b);
        break;
    default: return 0;
    }
    return 1;
}

/* Merges, messages, hulls, edges and incircle tests: 1 when e is one of
 * them (then written to buf). */
static int format_global(const pdt_event *e, const char *kn, char *buf, size_t cap)
{
    switch (e->kind) {
    case PDT_EV_MERGE_BEGIN:
        snprintf(buf, cap,
                 "merge-begin level=%u left=%" PRIu32 " right=%" PRIu32 " end=%" PRIu32
                 " at=%" PRId64, e->sub, e->a, e->b, e->c, e->v);
        break;
    case PDT_EV_MERGE_END:
        snprintf(buf, cap,
                 "merge-end level=%u shipped=%" PRIu32 " border=%" PRIu32 " kept=%" PRIu32
                 " discarded=%" PRId64, e->sub, e->a, e->b, e->c, e->v);
        break;
    case PDT_EV_SEND:
        snprintf(buf, cap, "send tag=%u to=%" PRIu32 " bytes=%" PRIu64 " seq=%" PRId64, e->sub, e->a,
                 pdt_event_bytes(e), e->v);
        break;
    case PDT_EV_RECV:
        snprintf(buf, cap, "recv tag=%u from=%" PRIu32 " bytes=%" PRIu64 " seq=%" PRId64, e->sub,
                 e->a, pdt_event_bytes(e), e->v);
        break;
    case PDT_EV_HULL:
        snprintf(buf, cap, "hull vertices=%" PRIu32 "%s", e->a, e->b ? " degenerate" : "");
        break;
    case PDT_EV_EDGE_ADD:
    case PDT_EV_EDGE_DEL:
        snprintf(buf, cap, "%s %" PRIu32 " %" PRIu32, kn, e->a, e->b);
        break;
    case PDT_EV_INCIRCLE:
        snprintf(buf, cap, "incircle %" PRIu32 " %" PRIu32 " %" PRIu32 " pt=%" PRId64 " result=%d",
                 e->a, e->b, e->c, e->v >> 2, (int)(e->v & 3) - 1);
        break;
    default: return 0;
    }
    return 1;
}

/* An event of no kind above: its fields as numbers. */
static void format_other(const pdt_event *e, const char *kn, char *buf, size_t cap)
{
    if (kn)
        snprintf(buf, cap, "%s sub=%u a=%" PRIu32 " b=%" PRIu32 " c=%" PRIu32 " v=%" PRId64, kn,
                 e->sub, e->a, e->b, e->c, e->v);
    else
        snprintf(buf, cap, "kind-%u sub=%u a=%" PRIu32 " b=%" PRIu32 " c=%" PRIu32
                           " v=%" PRId64, e->kind, e->sub, e->a, e->b, e->c, e->v);
}

char *pdt_event_format(const pdt_event *e0, char *buf, size_t cap)
{
    int tri = e0->kind == PDT_EV_TRI_NEW || e0->kind == PDT_EV_TRI_FINAL ||
              e0->kind == PDT_EV_RA_DEFER || e0->kind == PDT_EV_SHIP || e0->kind == PDT_EV_DISCARD;
    pdt_event rot = tri ? tri_rotated(e0) : *e0;
    const pdt_event *e = &rot;
    const char *kn = pdt_event_kind_name(e->kind);
    if (tri) format_tri(e, buf, cap);
    else if (!format_local(e, kn, buf, cap) && !format_global(e, kn, buf, cap))
        format_other(e, kn, buf, cap);
    return buf;
}
