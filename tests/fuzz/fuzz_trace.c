/* pdt — fuzz targets for run folders (src/trace):
 *
 *   manifest    the manifest parser alone (pdt_tf_manifest_parse, the
 *               function pdt_run_open calls on the manifest text);
 *   trace_rank  one rank file: the input is rank-0000.trace of a one-rank
 *               run whose manifest and points.bin are valid;
 *   trace_run   a whole folder: the input is split at the line "==PDT==" into
 *               manifest, points.bin, rank-0000.trace, rank-0001.trace, ...
 *
 * Blocks carry CRC-32C checksums, which random mutations almost never
 * satisfy; so the rank-file targets read every input twice: as it is (the
 * damage paths) and with every checksum recomputed (the event decoder, the
 * cursor and the causal merge; for trace_run also points.bin's checksums and
 * the manifest's point count and input checksum, so that mutated points read
 * as the run's points).  Properties checked besides "no crash, no
 * leak, no undefined behaviour, no hang":
 *   - pdt_run_open fails only with a message, and succeeds whenever the
 *     manifest is valid (damage becomes warnings);
 *   - per rank: the decoded events, the cursor's walk and the rank info agree
 *     on the count; a cursor seek to k then next gives event k;
 *   - the merged order holds every event of every rank exactly once, each
 *     rank's events in their own order;
 *   - pdt_run_check gives a verdict (a failure carries a message), the same
 *     in a tiny budget (on disk, T* certified instead of recomputed) and in
 *     a budget of one byte (a hull run's hull certified instead of
 *     recomputed, every stack in a temporary file). */
#include "fuzz_common.h"
#include "pdt/tracefile.h"

/* private to src/trace, but exported from libpdt (the manifest parser) */
pdt_status pdt_tf_manifest_parse(const char *path, char *text, pdt_manifest *m, pdt_err *err);

static int fuzz_manifest(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    FZ_ASSERT(text);
    memcpy(text, data, size);
    text[size] = '\0';
    pdt_manifest m;
    pdt_err err = {0};
    pdt_status st = pdt_tf_manifest_parse("manifest", text, &m, &err);
    if (st == PDT_OK) {
        FZ_ASSERT(m.format_version >= PDT_TRACE_FORMAT_OLDEST &&
                  m.format_version <= PDT_TRACE_FORMAT_MAJOR);
        FZ_ASSERT(m.input_checksum_kind == PDT_CHECKSUM_CRC64 ||
                  m.input_checksum_kind == PDT_CHECKSUM_FNV1A64);
        FZ_ASSERT(m.nranks >= 1 && m.clock_offset_ns != NULL);
        FZ_ASSERT(memchr(m.program_version, 0, sizeof m.program_version));
        FZ_ASSERT(memchr(m.command, 0, sizeof m.command));
        pdt_manifest_free(&m);
    } else {
        FZ_ASSERT(err.code == st && err.msg[0]);
        FZ_ASSERT(m.command_line == NULL && m.input_name == NULL && m.clock_offset_ns == NULL);
    }
    free(text);
    return 0;
}

/* ---- checksum repair ------------------------------------------------------ */

/* Recompute the header and block checksums of a rank file in place, walking
 * the blocks the way the reader does (stops where the structure breaks). */
static void fz_fix_rank(uint8_t *p, size_t len)
{
    if (len < 32) return;
    fz_put32(p + 28, pdt_crc32c(0, p, 28));
    uint64_t off = fz_get32(p + 12);
    if (off < 32) off = 32;
    while (off + 32 <= len) {
        uint8_t *h = p + off;
        uint32_t blen = fz_get32(h + 4);
        if (blen > len - off - 32) break;
        fz_put32(h + 28, pdt_crc32c(pdt_crc32c(0, h, 28), h + 32, blen));
        off += 32 + (uint64_t)blen;
    }
}

/* Recompute points.bin's checksums (data: the bytes after the header). */
static void fz_fix_points(uint8_t *p, size_t len)
{
    if (len < 24) return;
    fz_put32(p + 16, pdt_crc32c(0, p + 24, len - 24));
    fz_put32(p + 20, pdt_crc32c(0, p, 20));
}

/* The manifest text man[0..len) with its lines `n = ...` and `input_checksum
 * = ...` made those of points.bin's data p[0..plen) (a well-formed
 * points.bin: else a copy as it is); a new string (free it), its length in
 * *out_len. */
static char *fz_fix_manifest(const uint8_t *man, size_t len, const uint8_t *p, size_t plen,
                             size_t *out_len)
{
    char *out = malloc(len + 128);
    FZ_ASSERT(out);
    size_t n = 0;
    int points = plen >= 24 && (plen - 24) % 8 == 0;
    size_t np = points ? (plen - 24) / 8 : 0;
    uint64_t crc = points ? pdt_crc64(0, p + 24, plen - 24) : 0;
    for (size_t i = 0; i < len;) {
        const uint8_t *nl = memchr(man + i, '\n', len - i);
        size_t e = nl ? (size_t)(nl - man) + 1 : len;
        if (points && e - i >= 4 && !memcmp(man + i, "n = ", 4))
            n += (size_t)sprintf(out + n, "n = %zu\n", np);
        else if (points && e - i >= 17 && !memcmp(man + i, "input_checksum = ", 17))
            n += (size_t)sprintf(out + n, "input_checksum = crc64:%016llx\n",
                                 (unsigned long long)crc);
        else {
            memcpy(out + n, man + i, e - i);
            n += e - i;
        }
        i = e;
    }
    *out_len = n;
    return out;
}

/* ---- exercising an open run -------------------------------------------------- */

static void fz_exercise(pdt_run *run)
{
    const char *w = pdt_run_warnings(run);
    FZ_ASSERT(w != NULL);
    size_t np;
    const pdt_point *pts = pdt_run_points(run, &np);
    FZ_ASSERT(np == 0 || pts != NULL);
    const pdt_manifest *m = pdt_run_manifest(run);
    FZ_ASSERT(m != NULL);
    int R = pdt_run_nranks(run);
    FZ_ASSERT(R >= 1);
    size_t total = 0;
    for (int r = 0; r < R; r++) {
        pdt_rank_info info;
        pdt_run_rank_info(run, r, &info);
        const pdt_event *ev;
        size_t n;
        pdt_err err = {0};
        if (pdt_run_rank_events(run, r, &ev, &n, &err) != PDT_OK) {
            FZ_ASSERT(err.code == PDT_ERR_NOMEM);
            return;
        }
        FZ_ASSERT(n == info.events);
        FZ_ASSERT(info.blocks <= info.events);
        FZ_ASSERT(info.present || info.events == 0);
        total += n;
        char line[160], tiny[8];
        for (size_t i = 0; i < n; i++) {
            pdt_event_format(&ev[i], line, sizeof line);
            pdt_event_format(&ev[i], tiny, sizeof tiny);
            FZ_ASSERT(strlen(tiny) < sizeof tiny);
        }
        pdt_cursor *c;
        FZ_ASSERT(pdt_cursor_open(run, r, &c, &err) == PDT_OK);
        pdt_event e;
        uint64_t seq, k = 0;
        while (pdt_cursor_next(c, &e, &seq)) {
            FZ_ASSERT(seq == k && k < n);
            FZ_ASSERT(memcmp(&e, &ev[k], sizeof e) == 0);
            k++;
        }
        FZ_ASSERT(k == n);
        if (n > 0) {
            uint64_t mid = n / 2;
            FZ_ASSERT(pdt_cursor_seek(c, mid, &err) == PDT_OK);
            FZ_ASSERT(pdt_cursor_next(c, &e, &seq) == 1 && seq == mid);
            FZ_ASSERT(memcmp(&e, &ev[mid], sizeof e) == 0);
            FZ_ASSERT(pdt_cursor_seek(c, 0, &err) == PDT_OK);
            FZ_ASSERT(pdt_cursor_next(c, &e, &seq) == 1 && seq == 0);
        }
        FZ_ASSERT(pdt_cursor_seek(c, n, &err) == PDT_OK);
        FZ_ASSERT(pdt_cursor_next(c, &e, &seq) == 0);
        pdt_err e2 = {0};
        FZ_ASSERT(pdt_cursor_seek(c, (uint64_t)n + 1, &e2) == PDT_ERR_ARG);
        pdt_cursor_close(c);
    }
    const pdt_rec *rec;
    size_t nrec;
    pdt_err err = {0};
    if (pdt_run_merged(run, &rec, &nrec, &err) != PDT_OK) {
        FZ_ASSERT(err.code == PDT_ERR_NOMEM);
        return;
    }
    FZ_ASSERT(nrec == total);
    size_t *next = calloc((size_t)R, sizeof *next);
    FZ_ASSERT(next);
    for (size_t i = 0; i < nrec; i++) {
        FZ_ASSERT(rec[i].rank < (uint32_t)R);
        FZ_ASSERT(rec[i].seq == next[rec[i].rank]);
        next[rec[i].rank]++;
    }
    free(next);
    /* the invariant checker: any verdict, but a message when it fails */
    char summary[256];
    pdt_err cerr = {0};
    pdt_status cst = pdt_run_check(run, summary, sizeof summary, &cerr);
    FZ_ASSERT(cst == PDT_OK || (cerr.code == cst && cerr.msg[0]));
    /* the same check in a budget of 1 KiB (finals and points sorted on disk,
     * T* certified side by side instead of recomputed, kernel edges
     * replayed on disk): the same verdict, whatever the reason it gives */
    pdt_err berr = {0};
    pdt_status bst = pdt_run_check_mem(run, 1024, summary, sizeof summary, &berr);
    FZ_ASSERT(bst == PDT_OK || (berr.code == bst && berr.msg[0]));
    if ((cst == PDT_OK || cst == PDT_ERR_CHECK) && (bst == PDT_OK || bst == PDT_ERR_CHECK))
        FZ_ASSERT(cst == bst);
    /* and in one byte: the hull of a hull run of a point or more certified
     * from the final Graham stack, every stack in a temporary file */
    pdt_err oerr = {0};
    pdt_status ost = pdt_run_check_mem(run, 1, summary, sizeof summary, &oerr);
    FZ_ASSERT(ost == PDT_OK || (oerr.code == ost && oerr.msg[0]));
    if ((cst == PDT_OK || cst == PDT_ERR_CHECK) && (ost == PDT_OK || ost == PDT_ERR_CHECK))
        FZ_ASSERT(cst == ost);
    /* a second call returns the same array */
    const pdt_rec *rec2;
    size_t nrec2;
    FZ_ASSERT(pdt_run_merged(run, &rec2, &nrec2, &err) == PDT_OK && rec2 == rec &&
              nrec2 == nrec);
}

/* Open dir; `must_open`: the manifest is known valid, so the open must
 * succeed whatever the rank files hold. */
static void fz_open_run(const char *dir, int must_open)
{
    pdt_run *run = NULL;
    pdt_err err = {0};
    pdt_status st = pdt_run_open(dir, &run, &err);
    if (st != PDT_OK) {
        FZ_ASSERT(run == NULL && err.code == st && err.msg[0]);
        FZ_ASSERT(!must_open || st == PDT_ERR_FORMAT || st == PDT_ERR_NOMEM);
        return;
    }
    fz_exercise(run);
    pdt_run_close(run);
}

/* ---- trace_rank ----------------------------------------------------------------- */

static char fz_rank_dir[512];

/* A one-rank run folder with a valid manifest and points.bin (made once). */
static const char *fz_rank_folder(void)
{
    if (fz_rank_dir[0]) return fz_rank_dir;
    fz_path(fz_rank_dir, sizeof fz_rank_dir, "rank-run");
    pdt_point pts[4] = {{0, 0}, {10, 0}, {0, 10}, {7, 7}};
    int64_t off = 0;
    pdt_manifest m = {0};
    m.format_version = PDT_TRACE_FORMAT_MAJOR;
    snprintf(m.program_version, sizeof m.program_version, "%s", PDT_VERSION);
    snprintf(m.command, sizeof m.command, "triangulate");
    m.command_line = (char *)"pdt triangulate in.txt --trace run";
    m.input_name = (char *)"in.txt";
    m.input_checksum = pdt_points_checksum(pts, 4);
    m.n = 4;
    m.nranks = 1;
    m.level = 2;
    m.clock_offset_ns = &off;
    pdt_err err = {0};
    FZ_ASSERT(pdt_run_write_meta(fz_rank_dir, &m, pts, 4, &err) == PDT_OK);
    return fz_rank_dir;
}

static int fuzz_trace_rank(const uint8_t *data, size_t size)
{
    const char *dir = fz_rank_folder();
    char path[600];
    snprintf(path, sizeof path, "%s/rank-0000.trace", dir);
    fz_write(path, data, size);
    fz_open_run(dir, 1);
    uint8_t *copy = malloc(size ? size : 1);
    FZ_ASSERT(copy);
    memcpy(copy, data, size);
    fz_fix_rank(copy, size);
    if (size == 0 || memcmp(copy, data, size) != 0) {
        fz_write(path, copy, size);
        fz_open_run(dir, 1);
    }
    free(copy);
    return 0;
}

/* ---- trace_run ------------------------------------------------------------------ */

#define FZ_SEP "\n==PDT==\n"
enum { FZ_MAX_PARTS = 6 }; /* manifest, points.bin, up to 4 rank files */

static int fuzz_trace_run(const uint8_t *data, size_t size)
{
    char dir[512];
    fz_path(dir, sizeof dir, "run");
    mkdir(dir, 0700);
    const uint8_t *part[FZ_MAX_PARTS] = {0};
    size_t plen[FZ_MAX_PARTS] = {0};
    size_t np = 0, sl = strlen(FZ_SEP);
    const uint8_t *p = data, *end = data + size;
    while (np < FZ_MAX_PARTS) {
        const uint8_t *q = np + 1 < FZ_MAX_PARTS ? memmem(p, (size_t)(end - p), FZ_SEP, sl) : NULL;
        part[np] = p;
        plen[np] = q ? (size_t)(q - p) : (size_t)(end - p);
        np++;
        if (!q) break;
        p = q + sl;
    }
    char path[600];
    for (int fixed = 0; fixed < 2; fixed++) {
        for (size_t i = 0; i < FZ_MAX_PARTS; i++) {
            if (i == 0) snprintf(path, sizeof path, "%s/manifest", dir);
            else if (i == 1) snprintf(path, sizeof path, "%s/points.bin", dir);
            else snprintf(path, sizeof path, "%s/rank-%04zu.trace", dir, i - 2);
            if (i >= np) {
                unlink(path);
                continue;
            }
            size_t len = plen[i];
            uint8_t *copy = malloc(len ? len : 1);
            FZ_ASSERT(copy);
            memcpy(copy, part[i], len);
            if (fixed && i == 0 && np > 1) {
                free(copy);
                copy = (uint8_t *)fz_fix_manifest(part[0], plen[0], part[1], plen[1], &len);
            }
            if (fixed && i == 1) fz_fix_points(copy, len);
            if (fixed && i >= 2) fz_fix_rank(copy, len);
            fz_write(path, copy, len);
            free(copy);
        }
        fz_open_run(dir, 0);
    }
    return 0;
}
