/* pdt — the tracing hook: names of events, and the in-memory sink. */
#include "pdt/trace.h"

#include <stdlib.h>
#include <time.h>

static const char *const kind_names[PDT_EV_KIND_COUNT] = {
    [PDT_EV_NONE] = "none",          [PDT_EV_PHASE_BEGIN] = "phase-begin",
    [PDT_EV_PHASE_END] = "phase-end", [PDT_EV_PUSH] = "push",
    [PDT_EV_POP] = "pop",            [PDT_EV_LIFT] = "lift",
    [PDT_EV_SORT] = "sort",          [PDT_EV_DELETE] = "delete",
    [PDT_EV_TRI_NEW] = "tri-new",    [PDT_EV_TRI_FINAL] = "tri-final",
    [PDT_EV_RA_DEFER] = "ra-defer",  [PDT_EV_SHIP] = "ship",
    [PDT_EV_DISCARD] = "discard",    [PDT_EV_MERGE_BEGIN] = "merge-begin",
    [PDT_EV_MERGE_END] = "merge-end", [PDT_EV_SEND] = "send",
    [PDT_EV_RECV] = "recv",          [PDT_EV_HULL] = "hull",
    [PDT_EV_EDGE_ADD] = "edge-add",  [PDT_EV_EDGE_DEL] = "edge-del",
    [PDT_EV_INCIRCLE] = "incircle",
};

static const char *const phase_names[PDT_PH_COUNT] = {
    [PDT_PH_RUN] = "run",           [PDT_PH_READ] = "read",
    [PDT_PH_PARTITION] = "partition", [PDT_PH_LIFT] = "lift",
    [PDT_PH_KERNEL] = "kernel",     [PDT_PH_HULL] = "hull",
    [PDT_PH_CLASSIFY] = "classify", [PDT_PH_MERGE] = "merge",
    [PDT_PH_OUTPUT] = "output",     [PDT_PH_GRAHAM_SORT] = "graham-sort",
    [PDT_PH_GRAHAM_SCAN] = "graham-scan", [PDT_PH_ORDER] = "order",
    [PDT_PH_WRITE] = "write",
};

static const char *const stack_names[] = {"graham", "lower", "upper", "merge-lower",
                                          "merge-upper"};

const char *pdt_event_kind_name(int kind)
{
    return kind >= 0 && kind < PDT_EV_KIND_COUNT ? kind_names[kind] : NULL;
}

const char *pdt_phase_name(int phase)
{
    return phase >= 0 && phase < PDT_PH_COUNT ? phase_names[phase] : NULL;
}

const char *pdt_stack_name(int stack)
{
    return stack >= 0 && stack < (int)(sizeof stack_names / sizeof *stack_names)
               ? stack_names[stack] : NULL;
}

static void buf_sink(pdt_trace *tr, const pdt_event *ev)
{
    pdt_trace_buf *b = tr->user;
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 256;
        pdt_event *e = realloc(b->ev, cap * sizeof *e);
        if (!e) {
            b->failed = 1;
            return;
        }
        b->ev = e;
        b->cap = cap;
    }
    pdt_event *dst = &b->ev[b->n];
    *dst = *ev;
    dst->t = b->timed ? pdt_trace_ns() - b->t0 : b->n;
    b->n++;
}

uint64_t pdt_trace_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

void pdt_trace_buf_init(pdt_trace *tr, pdt_trace_buf *buf, int level, int rank)
{
    buf->ev = NULL;
    buf->n = buf->cap = 0;
    buf->failed = 0;
    buf->timed = 0;
    buf->t0 = 0;
    tr->level = level;
    tr->rank = rank;
    tr->gid = NULL;
    tr->sink = buf_sink;
    tr->user = buf;
}

void pdt_trace_buf_init_timed(pdt_trace *tr, pdt_trace_buf *buf, int level, int rank, uint64_t t0)
{
    pdt_trace_buf_init(tr, buf, level, rank);
    buf->timed = 1;
    buf->t0 = t0;
}

void pdt_trace_buf_free(pdt_trace_buf *buf)
{
    free(buf->ev);
    buf->ev = NULL;
    buf->n = buf->cap = 0;
}
