/* pdt — replays every fuzz target on its seed corpus and on every crash kept
 * so far, without libFuzzer (so `make test` stays quick and needs no clang).
 *
 *   tests/fuzz/corpus/NAME/    small seed inputs (`make fuzz` starts from them)
 *   tests/fuzz/crashes/NAME/   inputs that once crashed a target (regressions)
 *
 * One test case per target and folder: it passes when every file was run
 * and no target property failed (a failure aborts with the property, and
 * under the sanitizer build ASan/UBSan abort on memory errors).  With
 * arguments (`test_fuzz_replay NAME FILE...`) it runs one target on the
 * given files: handy for reproducing a crash in gdb or valgrind. */
#include "../fuzz/fuzz_targets.h"
#include "../harness.h"

#include <errno.h>

static const char *root_dir(void)
{
    const char *r = getenv("ROOT");
    return r && *r ? r : ".";
}

/* Run target t on one file; returns 0, or -1 if the file cannot be read. */
static int replay_file(const fz_target *t, const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) return -1;
    size_t cap = 4096, n = 0;
    uint8_t *buf = malloc(cap);
    if (!buf) {
        fclose(fp);
        return -1;
    }
    for (;;) {
        if (n == cap) {
            uint8_t *nb = realloc(buf, cap *= 2);
            if (!nb) {
                free(buf);
                fclose(fp);
                return -1;
            }
            buf = nb;
        }
        size_t k = fread(buf + n, 1, cap - n, fp);
        n += k;
        if (k == 0) break;
    }
    int bad = ferror(fp);
    fclose(fp);
    if (!bad) t->fn(buf, n);
    free(buf);
    return bad ? -1 : 0;
}

static int name_cmp(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Replay every regular file of dir/NAME; *count = files run.  Returns the
 * number of unreadable files; a missing folder counts as empty. */
static int replay_dir(const fz_target *t, const char *sub, size_t *count)
{
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/tests/fuzz/%s/%s", root_dir(), sub, t->name);
    *count = 0;
    DIR *d = opendir(dir);
    if (!d) return errno == ENOENT ? 0 : 1;
    char **names = NULL;
    size_t n = 0, cap = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.') continue;
        if (n == cap) {
            cap = cap ? 2 * cap : 64;
            char **nn = realloc(names, cap * sizeof *nn);
            if (!nn) abort();
            names = nn;
        }
        names[n] = strdup(e->d_name);
        if (!names[n]) abort();
        n++;
    }
    closedir(d);
    if (n > 1) qsort(names, n, sizeof *names, name_cmp);
    int bad = 0;
    for (size_t i = 0; i < n; i++) {
        char path[2048];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        struct stat st;
        if (stat(path, &st) == 0 && S_ISREG(st.st_mode)) {
            if (replay_file(t, path) != 0) {
                printf("#   %s: cannot read\n", path);
                bad++;
            } else {
                (*count)++;
            }
        }
        free(names[i]);
    }
    free(names);
    return bad;
}

int main(int argc, char **argv)
{
    size_t nt = sizeof FZ_TARGETS / sizeof FZ_TARGETS[0];
    (void)th_failed_checks;
    if (argc >= 3) {
        for (size_t i = 0; i < nt; i++) {
            if (strcmp(FZ_TARGETS[i].name, argv[1]) != 0) continue;
            for (int a = 2; a < argc; a++) {
                fprintf(stderr, "replay %s %s\n", argv[1], argv[a]);
                if (replay_file(&FZ_TARGETS[i], argv[a]) != 0) {
                    fprintf(stderr, "%s: cannot read\n", argv[a]);
                    return 2;
                }
            }
            return 0;
        }
        fprintf(stderr, "unknown target %s\n", argv[1]);
        return 2;
    }
    for (size_t i = 0; i < nt; i++) {
        const fz_target *t = &FZ_TARGETS[i];
        size_t nc = 0, nx = 0;
        int bad = replay_dir(t, "corpus", &nc);
        bad += replay_dir(t, "crashes", &nx);
        char name[128];
        snprintf(name, sizeof name, "fuzz_replay_%s", t->name);
        /* reaching this line means no input crashed the target */
        if (bad == 0 && nc > 0) {
            printf("ok - %s (%zu corpus files, %zu crash regressions)\n", name, nc, nx);
        } else {
            printf("not ok - %s (%zu corpus files, %d unreadable: a seed corpus is required)\n",
                   name, nc, bad);
            th_cases_failed++;
            continue;
        }
        th_cases_passed++;
    }
    return test_summary();
}
