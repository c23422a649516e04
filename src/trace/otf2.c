/* pdt — export a run folder as an OTF2 archive (Vampir, Score-P tools, otf2-print).
 *
 * The mapping (docs/trace-format.md, "Exporting"):
 *   - one location (CPU thread) in one location group (process) per rank;
 *   - a region per phase id ("read", "kernel", "merge", ...) and one per merge
 *     level ("merge step level 2"); PHASE_BEGIN/-END and MERGE_BEGIN/-END
 *     become Enter/Leave records;
 *   - SEND and RECV become MpiSend/MpiRecv records on one communicator of
 *     all ranks (receiver/sender = peer rank, tag, bytes), so OTF2 readers
 *     pair them as MPI point-to-point messages;
 *   - clock properties: 1 ns resolution, the run's aligned time span, and
 *     the manifest's wall_start_ns as the realtime timestamp.
 * Every other event (pushes, lift-ups, triangles, ...) is left out.
 *
 * Memory: the ranks are written one after another through one OTF2 event
 * writer whose buffer is flushed to disk whenever its chunk is full, so it
 * stays O(chunk) whatever the size of the run.  The archive is written into a
 * temporary folder beside DIR and renamed to DIR at the end: a failed export
 * leaves nothing half-written. */
#define _XOPEN_SOURCE 700
#include <errno.h>
#include <ftw.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <otf2/otf2.h>

#include "tf_internal.h"

#define OTF2_CHUNK_EVENTS ((uint64_t)1 << 20)
#define OTF2_CHUNK_DEFS ((uint64_t)4 << 20)
#define REGION_MERGE0 256u          /* region of merge level L: REGION_MERGE0 + L */
#define NREGIONS (REGION_MERGE0 + 256u)
#define COMM_ALL 0u
#define GROUP_LOCATIONS 0u
#define GROUP_RANKS 1u

typedef struct ox {
    pdt_run *run;
    pdt_err *err;
    OTF2_Archive *ar;
    OTF2_GlobalDefWriter *gd;
    uint32_t nstr;               /* strings defined so far */
    uint16_t id[NREGIONS];       /* region key -> OTF2 region id (dense, by first use) */
    uint32_t key[NREGIONS];      /* OTF2 region id -> region key */
    uint32_t nreg;
    uint64_t *nev;               /* per rank: OTF2 events written */
    uint64_t t0, t1;             /* aligned time span of the run */
    pdt_otf2_counts counts;
} ox;

static OTF2_FlushType pre_flush(void *user, OTF2_FileType ft, OTF2_LocationRef loc,
                                   void *callerData, bool final)
{
    (void)user;
    (void)ft;
    (void)loc;
    (void)callerData;
    (void)final;
    return OTF2_FLUSH;
}

static const OTF2_FlushCallbacks flush_cb = {pre_flush, NULL};

/* OTF2 prints its errors to stderr unless told otherwise; we report them
 * through pdt_err instead (the status of the failing call). */
static OTF2_ErrorCode quiet_error(void *user, const char *file, uint64_t line, const char *fn,
                                  OTF2_ErrorCode code, const char *fmt, va_list va)
{
    (void)user;
    (void)file;
    (void)line;
    (void)fn;
    (void)fmt;
    (void)va;
    return code;
}

/* Turn an OTF2 status into ours (the first error sticks in err). */
static pdt_status ck(ox *x, OTF2_ErrorCode code, const char *what)
{
    if (code == OTF2_SUCCESS) return PDT_OK;
    return pdt_err_set(x->err, PDT_ERR_IO, "OTF2: %s: %s (%s)", what, OTF2_Error_GetName(code),
                       OTF2_Error_GetDescription(code));
}

/* Define a string; its id in *id. */
static pdt_status str(ox *x, const char *s, OTF2_StringRef *id)
{
    *id = x->nstr++;
    return ck(x, OTF2_GlobalDefWriter_WriteString(x->gd, *id, s), "string definition");
}

/* The OTF2 region of a phase or merge event.  Readers want region ids
 * dense and defined in order, so ids are handed out by first use. */
static uint32_t region_of(ox *x, const pdt_event *e)
{
    uint32_t k = e->kind == PDT_EV_MERGE_BEGIN || e->kind == PDT_EV_MERGE_END
                     ? REGION_MERGE0 + e->sub
                     : e->sub;
    if (x->id[k] == UINT16_MAX) {
        x->id[k] = (uint16_t)x->nreg;
        x->key[x->nreg++] = k;
    }
    return x->id[k];
}

/* The aligned times of the first and the last event of all ranks. */
static pdt_status time_span(ox *x)
{
    x->t0 = UINT64_MAX;
    x->t1 = 0;
    for (int r = 0; r < pdt_run_nranks(x->run); r++) {
        pdt_rank_info in;
        pdt_run_rank_info(x->run, r, &in);
        if (!in.events) continue;
        pdt_cursor *c;
        pdt_status st = pdt_cursor_open(x->run, r, &c, x->err);
        if (st != PDT_OK) return st;
        pdt_event e;
        if (pdt_cursor_next(c, &e, NULL) && e.t < x->t0) x->t0 = e.t;
        if (pdt_cursor_seek(c, in.events - 1, x->err) == PDT_OK && pdt_cursor_next(c, &e, NULL) &&
            e.t > x->t1)
            x->t1 = e.t;
        pdt_cursor_close(c);
    }
    if (x->t0 == UINT64_MAX) x->t0 = x->t1 = 0;
    if (x->t1 < x->t0) x->t1 = x->t0;
    return PDT_OK;
}

/* One event of rank r into its event writer (unmapped kinds: nothing). */
static pdt_status put_event(ox *x, OTF2_EvtWriter *w, u32vec *open, const pdt_event *e,
                            uint64_t t)
{
    uint32_t p = (uint32_t)pdt_run_nranks(x->run);
    switch (e->kind) {
    case PDT_EV_PHASE_BEGIN:
    case PDT_EV_MERGE_BEGIN: {
        uint32_t reg = region_of(x, e);
        if (u32_push(open, reg)) return pdt_err_set(x->err, PDT_ERR_NOMEM, "out of memory");
        x->counts.enters++;
        return ck(x, OTF2_EvtWriter_Enter(w, NULL, t, reg), "enter record");
    }
    case PDT_EV_PHASE_END:
    case PDT_EV_MERGE_END: {
        uint32_t reg = region_of(x, e);
        if (!open->n || open->v[open->n - 1] != reg) {  /* unbalanced (damaged run) */
            x->counts.skipped++;
            return PDT_OK;
        }
        open->n--;
        x->counts.leaves++;
        return ck(x, OTF2_EvtWriter_Leave(w, NULL, t, reg), "leave record");
    }
    case PDT_EV_SEND:
    case PDT_EV_RECV:
        if (e->a >= p) {  /* no such peer: not a message OTF2 can name */
            x->counts.skipped++;
            return PDT_OK;
        }
        if (e->kind == PDT_EV_SEND) {
            x->counts.sends++;
            return ck(x, OTF2_EvtWriter_MpiSend(w, NULL, t, e->a, COMM_ALL, e->sub,
                                                 pdt_event_bytes(e)),
                      "send record");
        }
        x->counts.recvs++;
        return ck(x, OTF2_EvtWriter_MpiRecv(w, NULL, t, e->a, COMM_ALL, e->sub,
                                             pdt_event_bytes(e)),
                  "recv record");
    default:
        return PDT_OK;
    }
}

/* All mapped events of rank r; regions still open at the end (a damaged or
 * killed run) are left at the rank's last time. */
static pdt_status put_rank(ox *x, int r)
{
    OTF2_EvtWriter *w = OTF2_Archive_GetEvtWriter(x->ar, (OTF2_LocationRef)r);
    if (!w) return pdt_err_set(x->err, PDT_ERR_IO, "OTF2: no event writer for rank %d", r);
    pdt_cursor *c;
    pdt_status st = pdt_cursor_open(x->run, r, &c, x->err);
    u32vec open = {0}; /* the regions a rank is in: phases and merge steps nest */
    uint64_t last = x->t0;
    pdt_event e;
    while (st == PDT_OK && pdt_cursor_next(c, &e, NULL)) {
        if (e.t > last) last = e.t;  /* OTF2 wants non-decreasing times */
        st = put_event(x, w, &open, &e, last);
    }
    while (st == PDT_OK && open.n) {
        x->counts.leaves++;
        st = ck(x, OTF2_EvtWriter_Leave(w, NULL, last, open.v[--open.n]), "leave record");
    }
    if (st == PDT_OK)
        st = ck(x, OTF2_EvtWriter_GetNumberOfEvents(w, &x->nev[r]), "event count");
    pdt_status cst = ck(x, OTF2_Archive_CloseEvtWriter(x->ar, w), "closing an event writer");
    if (st == PDT_OK) st = cst;
    free(open.v);
    pdt_cursor_close(c);
    return st;
}

static pdt_status put_regions(ox *x)
{
    OTF2_StringRef d_phase, d_merge;
    pdt_status st = str(x, "pdt phase (PHASE_BEGIN .. PHASE_END)", &d_phase);
    if (st == PDT_OK) st = str(x, "pdt merge step (MERGE_BEGIN .. MERGE_END)", &d_merge);
    for (uint32_t id = 0; id < x->nreg && st == PDT_OK; id++) {
        uint32_t reg = x->key[id];
        char name[64];
        const char *pn = reg < REGION_MERGE0 ? pdt_phase_name((int)reg) : NULL;
        if (reg >= REGION_MERGE0)
            snprintf(name, sizeof name, "merge step level %u", reg - REGION_MERGE0);
        else if (pn)
            snprintf(name, sizeof name, "%s", pn);
        else
            snprintf(name, sizeof name, "phase %u", reg);
        OTF2_StringRef s;
        if ((st = str(x, name, &s)) != PDT_OK) break;
        st = ck(x, OTF2_GlobalDefWriter_WriteRegion(x->gd, id, s, s,
                                                    reg >= REGION_MERGE0 ? d_merge : d_phase,
                                                    OTF2_REGION_ROLE_CODE, OTF2_PARADIGM_USER,
                                                    OTF2_REGION_FLAG_NONE, OTF2_UNDEFINED_STRING,
                                                    0, 0),
                "region definition");
    }
    return st;
}

/* Clock, system tree, one location group and location per rank, regions,
 * the communicator of all ranks. */
static pdt_status put_global_defs(ox *x)
{
    const pdt_manifest *m = pdt_run_manifest(x->run);
    int p = pdt_run_nranks(x->run);
    x->gd = OTF2_Archive_GetGlobalDefWriter(x->ar);
    if (!x->gd) return pdt_err_set(x->err, PDT_ERR_IO, "OTF2: no global definition writer");
    pdt_status st = ck(x, OTF2_GlobalDefWriter_WriteClockProperties(
                              x->gd, 1000000000u, x->t0, x->t1 - x->t0, m->wall_start_ns),
                       "clock properties");
    OTF2_StringRef s_node, s_class, s_comm;
    char title[96];
    snprintf(title, sizeof title, "pdt %s, %d rank%s", m->command[0] ? m->command : "run", p,
             p == 1 ? "" : "s");
    if (st == PDT_OK) st = str(x, title, &s_node);
    if (st == PDT_OK) st = str(x, "run", &s_class);
    if (st == PDT_OK)
        st = ck(x, OTF2_GlobalDefWriter_WriteSystemTreeNode(x->gd, 0, s_node, s_class,
                                                              OTF2_UNDEFINED_SYSTEM_TREE_NODE),
                "system tree node");
    for (int r = 0; r < p && st == PDT_OK; r++) {
        char name[32];
        OTF2_StringRef s;
        snprintf(name, sizeof name, "rank %d", r);
        if ((st = str(x, name, &s)) != PDT_OK) break;
        st = ck(x, OTF2_GlobalDefWriter_WriteLocationGroup(x->gd, (OTF2_LocationGroupRef)r, s,
                                                           OTF2_LOCATION_GROUP_TYPE_PROCESS, 0,
                                                           OTF2_UNDEFINED_LOCATION_GROUP),
                "location group");
        if (st == PDT_OK)
            st = ck(x, OTF2_GlobalDefWriter_WriteLocation(x->gd, (OTF2_LocationRef)r, s,
                                                          OTF2_LOCATION_TYPE_CPU_THREAD,
                                                          x->nev[r], (OTF2_LocationGroupRef)r),
                    "location");
    }
    if (st == PDT_OK) st = put_regions(x);
    uint64_t *members = malloc((size_t)(p ? p : 1) * sizeof *members);
    if (st == PDT_OK && !members) st = pdt_err_set(x->err, PDT_ERR_NOMEM, "out of memory");
    for (int r = 0; st == PDT_OK && r < p; r++) members[r] = (uint64_t)r;
    if (st == PDT_OK) st = str(x, "pdt ranks", &s_comm);
    if (st == PDT_OK)
        st = ck(x, OTF2_GlobalDefWriter_WriteGroup(x->gd, GROUP_LOCATIONS, s_comm,
                                                   OTF2_GROUP_TYPE_COMM_LOCATIONS,
                                                   OTF2_PARADIGM_MPI, OTF2_GROUP_FLAG_NONE,
                                                   (uint32_t)p, members),
                "group of locations");
    if (st == PDT_OK)
        st = ck(x, OTF2_GlobalDefWriter_WriteGroup(x->gd, GROUP_RANKS, s_comm,
                                                   OTF2_GROUP_TYPE_COMM_GROUP, OTF2_PARADIGM_MPI,
                                                   OTF2_GROUP_FLAG_NONE, (uint32_t)p, members),
                "communicator group");
    if (st == PDT_OK)
        st = ck(x, OTF2_GlobalDefWriter_WriteComm(x->gd, COMM_ALL, s_comm, GROUP_RANKS,
                                                  OTF2_UNDEFINED_COMM, OTF2_COMM_FLAG_NONE),
                "communicator");
    free(members);
    return st;
}

/* Local definition files (empty: every definition is global), one per rank. */
static pdt_status put_local_defs(ox *x)
{
    pdt_status st = ck(x, OTF2_Archive_OpenDefFiles(x->ar), "opening definition files");
    for (int r = 0; r < pdt_run_nranks(x->run) && st == PDT_OK; r++) {
        OTF2_DefWriter *dw = OTF2_Archive_GetDefWriter(x->ar, (OTF2_LocationRef)r);
        if (!dw) return pdt_err_set(x->err, PDT_ERR_IO, "OTF2: no definition writer for rank %d",
                                    r);
        st = ck(x, OTF2_Archive_CloseDefWriter(x->ar, dw), "closing a definition writer");
    }
    if (st == PDT_OK) st = ck(x, OTF2_Archive_CloseDefFiles(x->ar), "closing definition files");
    return st;
}

static pdt_status write_archive(ox *x, const char *path)
{
    OTF2_Error_RegisterCallback(quiet_error, NULL);
    x->ar = OTF2_Archive_Open(path, "run", OTF2_FILEMODE_WRITE, OTF2_CHUNK_EVENTS,
                              OTF2_CHUNK_DEFS, OTF2_SUBSTRATE_POSIX, OTF2_COMPRESSION_NONE);
    if (!x->ar) return pdt_err_set(x->err, PDT_ERR_IO, "%s: OTF2 cannot create an archive", path);
    pdt_status st = ck(x, OTF2_Archive_SetFlushCallbacks(x->ar, &flush_cb, NULL), "flush setup");
    if (st == PDT_OK)
        st = ck(x, OTF2_Archive_SetSerialCollectiveCallbacks(x->ar), "collective setup");
    if (st == PDT_OK) st = ck(x, OTF2_Archive_SetCreator(x->ar, "pdt " PDT_VERSION), "creator");
    if (st == PDT_OK) st = time_span(x);
    if (st == PDT_OK) st = ck(x, OTF2_Archive_OpenEvtFiles(x->ar), "opening event files");
    for (int r = 0; r < pdt_run_nranks(x->run) && st == PDT_OK; r++) st = put_rank(x, r);
    if (st == PDT_OK) st = ck(x, OTF2_Archive_CloseEvtFiles(x->ar), "closing event files");
    if (st == PDT_OK) st = put_local_defs(x);
    if (st == PDT_OK) st = put_global_defs(x);
    pdt_status cst = ck(x, OTF2_Archive_Close(x->ar), "closing the archive");
    return st == PDT_OK ? cst : st;
}

static int rm_entry(const char *path, const struct stat *sb, int flag, struct FTW *ftw)
{
    (void)sb;
    (void)flag;
    (void)ftw;
    remove(path);
    return 0;
}

/* DIR may be absent or an empty folder; anything else would be lost. */
static pdt_status check_target(const char *dir, pdt_err *err)
{
    struct stat st;
    if (stat(dir, &st) != 0) return PDT_OK;
    if (S_ISDIR(st.st_mode) && rmdir(dir) == 0) return PDT_OK;  /* empty folder */
    return pdt_err_set(err, PDT_ERR_ARG, "%s: exists%s; choose a new folder for the OTF2 archive",
                       dir, S_ISDIR(st.st_mode) ? " and is not empty" : "");
}

pdt_status pdt_run_export_otf2(pdt_run *run, const char *dir, pdt_otf2_counts *counts,
                               pdt_err *err)
{
    if (counts) memset(counts, 0, sizeof *counts);
    pdt_status st = check_target(dir, err);
    if (st != PDT_OK) return st;
    size_t len = strlen(dir);
    while (len > 1 && dir[len - 1] == '/') len--;
    char *tmp = malloc(len + 16);
    ox x;
    memset(&x, 0, sizeof x);
    x.run = run;
    x.err = err;
    memset(x.id, 0xff, sizeof x.id);
    x.nev = calloc((size_t)(pdt_run_nranks(run) > 0 ? pdt_run_nranks(run) : 1), sizeof *x.nev);
    if (!tmp || !x.nev) {
        free(tmp);
        free(x.nev);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    snprintf(tmp, len + 16, "%.*s.tmp-XXXXXX", (int)len, dir);
    if (!mkdtemp(tmp)) {
        st = pdt_err_set(err, PDT_ERR_IO, "%s: cannot create a folder beside it: %s", dir,
                         strerror(errno));
    } else {
        st = write_archive(&x, tmp);
        if (st == PDT_OK && rename(tmp, dir) != 0)
            st = pdt_err_set(err, PDT_ERR_IO, "%s: cannot rename %s to it: %s", dir, tmp,
                             strerror(errno));
        if (st != PDT_OK) nftw(tmp, rm_entry, 16, FTW_DEPTH | FTW_PHYS);
    }
    if (st == PDT_OK && counts) *counts = x.counts;
    free(tmp);
    free(x.nev);
    return st;
}
