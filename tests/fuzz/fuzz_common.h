/* pdt — shared helpers of the fuzz targets (tests/fuzz/fuzz_*.c).
 *
 * Each target is a static function `fuzz_NAME(data, size)` in its own file.
 * Two programs use them:
 *   - `make fuzz` compiles each file with -DPDT_LIBFUZZER and clang's
 *     -fsanitize=fuzzer,address,undefined: the file then also defines
 *     LLVMFuzzerTestOneInput, and libFuzzer drives it;
 *   - tests/unit/test_fuzz_replay.c includes every target file and runs each
 *     target on its seed corpus (tests/fuzz/corpus/NAME/) and on every crash
 *     kept so far (tests/fuzz/crashes/NAME/), in the release and in the
 *     sanitizer build, without libFuzzer (part of `make test`).
 *
 * The readers have only path APIs, so an input is written to a file in a
 * private temporary folder (on /dev/shm when there is one) and read back. */
#ifndef PDT_FUZZ_COMMON_H
#define PDT_FUZZ_COMMON_H

#include <dirent.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pdt/common.h"

/* A target found a broken property: report and abort (libFuzzer and the
 * replay driver both treat an abort as a crash). */
#define FZ_ASSERT(cond)                                                               \
    do {                                                                              \
        if (!(cond)) {                                                                \
            fprintf(stderr, "%s:%d: fuzz property failed: %s\n", __FILE__, __LINE__, #cond); \
            abort();                                                                  \
        }                                                                             \
    } while (0)

static char fz_root[256];

static void fz_cleanup(void)
{
    if (!fz_root[0]) return;
    DIR *d = opendir(fz_root);
    if (d) {
        struct dirent *e;
        char p[512];
        while ((e = readdir(d)) != NULL) {
            if (e->d_name[0] == '.') continue;
            snprintf(p, sizeof p, "%s/%s", fz_root, e->d_name);
            /* one level of sub-folders (run folders) */
            DIR *s = opendir(p);
            if (s) {
                struct dirent *f;
                char q[768];
                while ((f = readdir(s)) != NULL) {
                    if (f->d_name[0] == '.' && (!f->d_name[1] || f->d_name[1] == '.')) continue;
                    snprintf(q, sizeof q, "%s/%s", p, f->d_name);
                    unlink(q);
                }
                closedir(s);
                rmdir(p);
            } else {
                unlink(p);
            }
        }
        closedir(d);
    }
    rmdir(fz_root);
    fz_root[0] = '\0';
}

/* The private temporary folder (created on first use, removed at exit). */
static const char *fz_dir(void)
{
    if (fz_root[0]) return fz_root;
    struct stat st;
    const char *base = getenv("PDT_FUZZ_TMP");
    if (!base) base = stat("/dev/shm", &st) == 0 && S_ISDIR(st.st_mode) ? "/dev/shm" : "/tmp";
    snprintf(fz_root, sizeof fz_root, "%s/pdt-fuzz.XXXXXX", base);
    if (!mkdtemp(fz_root)) {
        snprintf(fz_root, sizeof fz_root, "/tmp/pdt-fuzz.XXXXXX");
        if (!mkdtemp(fz_root)) {
            perror("mkdtemp");
            abort();
        }
    }
    atexit(fz_cleanup);
    return fz_root;
}

/* fz_dir()/name, in buf. */
static const char *fz_path(char *buf, size_t cap, const char *name)
{
    snprintf(buf, cap, "%s/%s", fz_dir(), name);
    return buf;
}

/* Write len bytes to path (replacing it).  Aborts on a write error: that is
 * the machine's problem, not a finding. */
static void fz_write(const char *path, const void *data, size_t len)
{
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd < 0) {
        perror(path);
        abort();
    }
    const uint8_t *p = data;
    while (len > 0) {
        ssize_t k = write(fd, p, len);
        if (k <= 0) {
            perror(path);
            abort();
        }
        p += k;
        len -= (size_t)k;
    }
    close(fd);
}

/* Little-endian helpers (the trace formats are little-endian). */
static inline uint32_t fz_get32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static inline void fz_put32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) p[i] = (uint8_t)(v >> (8 * i));
}

#endif
