/* pdt — the tracing hook.
 *
 * Algorithm code (hull, kernel, parallel driver) reports what it does through
 * one small API: a pdt_trace context passed in by the caller, and the
 * PDT_TRACE() macro.  The algorithm never knows who listens: a trace-file
 * writer, a test that records events in memory, or nobody (tr == NULL).
 *
 * Cost: with tracing off (tr == NULL or tr->level below the event's level) an
 * event costs one predictable branch.  Compiling with -DPDT_NO_TRACE removes
 * every PDT_TRACE() entirely.
 *
 * Point arguments are reported in the caller's index space and translated to
 * global input indices through tr->gid (if not NULL) by PDT_TRACE_PT().
 *
 * Event catalogue (kind: sub / a / b / c / v).  "pt" = point (global input
 * index after gid translation), "tri" = a,b,c are the three points of a
 * counter-clockwise triangle.
 *
 *  level 1
 *   PHASE_BEGIN   phase id (pdt_phase) / merge level or 0 / - / - / -
 *   PHASE_END     phase id / merge level or 0 / - / - / -
 *   PUSH          stack id (pdt_stack_id) / pt / stack depth after push / - / -
 *   POP           stack id / pt / stack depth after pop / pt that caused the pop
 *                 (the point being added, or UINT32_MAX) / -
 *   LIFT          - / pt / - / - / z = x*x + y*y (uint64 stored in v)
 *   SORT          - / pt / position in Graham's angular order (0 = origin) / - / -
 *   DELETE        reason (pdt_delete_reason) / pt deleted / pt kept instead / - / -
 *   TRI_NEW       run (0 = local kernel, 1 = border kernel at a merge) / tri / -
 *                 (a triangle produced by a kernel run: a candidate)
 *   TRI_FINAL     - / tri / -            (certified: part of the output)
 *   RA_DEFER      - / tri / v = rank whose box the restricted area touches
 *   SHIP          - / tri / v = destination rank (pending triangle sent away)
 *   DISCARD       - / tri / v = witness pt inside the circumcircle, or -1
 *   MERGE_BEGIN   merge level / first rank of G_L / first rank of G_R /
 *                 one past last rank of G_R / v = merge rank
 *   MERGE_END     merge level / shipped triangles |R_L|+|R_R| / |B| / kept /
 *                 v = discarded
 *   SEND          message tag / peer rank / bytes (low 32 bits) / bytes (high
 *                 32 bits: pdt_event_bytes) / v = sequence number of the
 *                 message between this pair of ranks (pairs with RECV)
 *   RECV          message tag / peer rank / bytes (low) / bytes (high) / v =
 *                 sequence number
 *   HULL          - / number of hull vertices / 1 if degenerate / - / -
 *                 (the hull of the current group is on the stack just built)
 *  level 2
 *   EDGE_ADD      - / pt / pt / - / -     (kernel creates an edge)
 *   EDGE_DEL      - / pt / pt / - / -     (kernel deletes an edge)
 *   INCIRCLE      - / tri / v = (tested pt << 2) | (result + 1)   (optional)
 */
#ifndef PDT_TRACE_H
#define PDT_TRACE_H

#include "pdt/common.h"

typedef enum pdt_event_kind {
    PDT_EV_NONE = 0,
    PDT_EV_PHASE_BEGIN,
    PDT_EV_PHASE_END,
    PDT_EV_PUSH,
    PDT_EV_POP,
    PDT_EV_LIFT,
    PDT_EV_SORT,
    PDT_EV_DELETE,
    PDT_EV_TRI_NEW,
    PDT_EV_TRI_FINAL,
    PDT_EV_RA_DEFER,
    PDT_EV_SHIP,
    PDT_EV_DISCARD,
    PDT_EV_MERGE_BEGIN,
    PDT_EV_MERGE_END,
    PDT_EV_SEND,
    PDT_EV_RECV,
    PDT_EV_HULL,
    PDT_EV_EDGE_ADD,
    PDT_EV_EDGE_DEL,
    PDT_EV_INCIRCLE,
    PDT_EV_KIND_COUNT
} pdt_event_kind;

typedef enum pdt_phase {
    PDT_PH_RUN = 0,      /* the whole run */
    PDT_PH_READ,         /* read input */
    PDT_PH_PARTITION,    /* sample sort, dedupe, strips */
    PDT_PH_LIFT,         /* lift-up of the local points */
    PDT_PH_KERNEL,       /* local Delaunay kernel */
    PDT_PH_HULL,         /* strip hull (monotone chain) */
    PDT_PH_CLASSIFY,     /* restricted areas: final or pending */
    PDT_PH_MERGE,        /* one merge step (sub-level in a) */
    PDT_PH_OUTPUT,       /* gather, sort, write */
    PDT_PH_GRAHAM_SORT,  /* Graham Version B: angular sort */
    PDT_PH_GRAHAM_SCAN,  /* Graham Version B: the stack scan */
    PDT_PH_ORDER,        /* canonical order of the final triangles across ranks */
    PDT_PH_WRITE,        /* write this rank's share of the output file */
    PDT_PH_COUNT
} pdt_phase;

typedef enum pdt_stack_id {
    PDT_STACK_GRAHAM = 0, /* Graham's scan, Version B */
    PDT_STACK_LOWER,      /* monotone chain, lower hull */
    PDT_STACK_UPPER,      /* monotone chain, upper hull */
    PDT_STACK_MERGE_LOWER,/* hull merge at a merge step, lower chain */
    PDT_STACK_MERGE_UPPER /* hull merge at a merge step, upper chain */
} pdt_stack_id;

typedef enum pdt_delete_reason {
    PDT_DEL_ANGULAR_TIE = 1, /* same angle as a farther point: the closer goes */
    PDT_DEL_COINCIDENT = 2   /* a copy of a point already kept */
} pdt_delete_reason;

/* One event, as the hook sees it (the on-disk encoding is the writer's). */
typedef struct pdt_event {
    uint8_t kind;      /* pdt_event_kind */
    uint8_t sub;       /* kind-specific small field */
    uint16_t reserved;
    uint32_t a, b, c;  /* kind-specific */
    int64_t v;         /* kind-specific */
    uint64_t t;        /* nanoseconds on the rank's clock; set by the sink */
} pdt_event;

/* The byte count of a SEND or RECV event: 64-bit, in b (low half) and c
 * (high half; 0 in traces written before it was used, which is right for
 * their counts, all below 2^32). */
static inline uint64_t pdt_event_bytes(const pdt_event *e)
{
    return (uint64_t)e->b | (uint64_t)e->c << 32;
}

typedef struct pdt_trace pdt_trace;
struct pdt_trace {
    int level;               /* 0 = off, 1, 2 */
    int rank;                /* rank that emits (for sinks and messages) */
    const uint32_t *gid;     /* local index -> global input index, or NULL */
    void (*sink)(pdt_trace *tr, const pdt_event *ev);
    void *user;              /* the sink's own state */
};

#define PDT_TRACE_PT(tr, i) ((tr)->gid ? (tr)->gid[(i)] : (uint32_t)(i))

/* Deliver one event.  Not for direct use: call PDT_TRACE(). */
static inline void pdt_trace_emit(pdt_trace *tr, int kind, int sub, uint32_t a, uint32_t b,
                                  uint32_t c, int64_t v)
{
    pdt_event ev;
    ev.kind = (uint8_t)kind;
    ev.sub = (uint8_t)sub;
    ev.reserved = 0;
    ev.a = a;
    ev.b = b;
    ev.c = c;
    ev.v = v;
    ev.t = 0;
    tr->sink(tr, &ev);
}

#ifdef PDT_NO_TRACE
/* Compiled out: the arguments stay "used" (no unused-variable warnings in a
 * TRACE=0 build) but sit in dead code, so no instruction is generated. */
#define PDT_TRACING(tr, lvl) (0 && (tr) != NULL && (lvl))
#define PDT_TRACE(tr, lvl, kind, sub, a, b, c, v)                                          \
    do {                                                                                   \
        if (0)                                                                             \
            pdt_trace_emit((tr), (kind), (sub), (uint32_t)(a), (uint32_t)(b), (uint32_t)(c), \
                           (int64_t)(v));                                                  \
    } while (0)
#else
/* True when an event of level `lvl` would be recorded. */
#define PDT_TRACING(tr, lvl) __builtin_expect((tr) != NULL && (tr)->level >= (lvl), 0)
/* Report an event: PDT_TRACE(tr, 1, PDT_EV_PUSH, PDT_STACK_LOWER, pt, depth, 0, 0). */
#define PDT_TRACE(tr, lvl, kind, sub, a, b, c, v)                                          \
    do {                                                                                   \
        if (PDT_TRACING(tr, lvl))                                                          \
            pdt_trace_emit((tr), (kind), (sub), (uint32_t)(a), (uint32_t)(b), (uint32_t)(c), \
                           (int64_t)(v));                                                  \
    } while (0)
#endif

/* Name of an event kind ("push", "lift", ...), phase, stack; NULL if unknown. */
const char *pdt_event_kind_name(int kind);
const char *pdt_phase_name(int phase);
const char *pdt_stack_name(int stack);

/* An in-memory sink for tests and for replay without files: collects events
 * into a growing array. */
typedef struct pdt_trace_buf {
    pdt_event *ev;
    size_t n, cap;
    int failed; /* allocation failed at some point: events were lost */
    int timed;  /* 0: an event's t is its index (logical time); 1: nanoseconds
                 * on the monotonic clock since t0 */
    uint64_t t0;
} pdt_trace_buf;

/* Initialise `tr` to record every event of level <= `level` into `buf`,
 * each event's t its index in buf (logical time). */
void pdt_trace_buf_init(pdt_trace *tr, pdt_trace_buf *buf, int level, int rank);
/* The same, each event's t the nanoseconds since t0 on the monotonic clock
 * (pdt_trace_ns): several ranks' buffers given one t0 merge by time. */
void pdt_trace_buf_init_timed(pdt_trace *tr, pdt_trace_buf *buf, int level, int rank, uint64_t t0);
/* Nanoseconds on the monotonic clock. */
uint64_t pdt_trace_ns(void);
void pdt_trace_buf_free(pdt_trace_buf *buf);

#endif
