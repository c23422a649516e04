/* Unit tests of src/base/safefile.c: the one rule every file pdt writes
 * follows (modes, links, read-only targets, group commits, run folders,
 * leftovers of killed runs, inputs that are never outputs). */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../harness.h"
#include "pdt/safefile.h"

static char dir[40];

static const char *path(const char *name)
{
    static char buf[8][512];
    static int k;
    k = (k + 1) % 8;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

static void put(const char *name, const char *text)
{
    FILE *f = fopen(path(name), "wb");
    if (!f) return;
    fputs(text, f);
    fclose(f);
}

static int has(const char *name, const char *text)
{
    char buf[256] = {0};
    FILE *f = fopen(path(name), "rb");
    if (!f) return 0;
    size_t k = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    return k == strlen(text) && memcmp(buf, text, k) == 0;
}

/* Entries of dir whose name contains `part`. */
static int count(const char *sub, const char *part)
{
    DIR *d = opendir(sub ? path(sub) : dir);
    int n = 0;
    struct dirent *de;
    while (d && (de = readdir(d)))
        if (strstr(de->d_name, part)) n++;
    if (d) closedir(d);
    return n;
}

static void clean(void)
{
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s/* %s/.[!.]*", dir, dir);
    if (system(cmd) != 0) return;
}

/* Replace `name` with `text` through the module; its status. */
static pdt_status replace(const char *name, const char *text, int flags, pdt_err *err)
{
    pdt_safe_file f;
    pdt_err_clear(err);
    pdt_status st = pdt_safe_open(&f, path(name), flags, err);
    if (st != PDT_OK) return st;
    if (write(f.fd, text, strlen(text)) != (ssize_t)strlen(text)) {
        pdt_safe_abort(&f);
        return PDT_ERR_IO;
    }
    return pdt_safe_commit(&f, err);
}

static mode_t mode_of(const char *name)
{
    struct stat sb;
    return lstat(path(name), &sb) == 0 ? sb.st_mode : 0;
}

TEST(mode_600_kept)
{
    clean();
    pdt_err err;
    put("priv.txt", "old\n");
    chmod(path("priv.txt"), 0600);
    CHECK(replace("priv.txt", "new\n", 0, &err) == PDT_OK);
    CHECK(has("priv.txt", "new\n"));
    CHECK_MSG((mode_of("priv.txt") & 07777) == 0600, "mode %o", (unsigned)mode_of("priv.txt"));
    CHECK(count(NULL, "pdt-tmp") == 0);
}

TEST(new_file_takes_the_umask)
{
    clean();
    pdt_err err;
    mode_t um = umask(027);
    CHECK(replace("fresh.txt", "x\n", 0, &err) == PDT_OK);
    umask(um);
    CHECK_MSG((mode_of("fresh.txt") & 07777) == 0640, "mode %o", (unsigned)mode_of("fresh.txt"));
}

TEST(symlink_target_replaced_link_kept)
{
    clean();
    pdt_err err;
    put("real.txt", "old\n");
    CHECK(symlink("real.txt", path("link.txt")) == 0);
    CHECK(replace("link.txt", "new\n", 0, &err) == PDT_OK);
    CHECK(S_ISLNK(mode_of("link.txt")));
    CHECK(has("real.txt", "new\n"));
}

TEST(nofollow_replaces_a_planted_link)
{
    clean();
    pdt_err err;
    put("victim", "keep\n");
    CHECK(symlink(path("victim"), path("frame-000000.png")) == 0);
    CHECK(replace("frame-000000.png", "png\n", PDT_SAFE_NOFOLLOW, &err) == PDT_OK);
    CHECK(has("victim", "keep\n"));
    CHECK(S_ISREG(mode_of("frame-000000.png")) && has("frame-000000.png", "png\n"));
}

TEST(hard_links_kept)
{
    clean();
    pdt_err err;
    put("a.txt", "old\n");
    CHECK(link(path("a.txt"), path("b.txt")) == 0);
    CHECK(replace("a.txt", "new content\n", 0, &err) == PDT_OK);
    struct stat sa, sb;
    CHECK(stat(path("a.txt"), &sa) == 0 && stat(path("b.txt"), &sb) == 0);
    CHECK(sa.st_ino == sb.st_ino && sa.st_nlink == 2);
    CHECK(has("b.txt", "new content\n"));
    CHECK(replace("a.txt", "s\n", 0, &err) == PDT_OK); /* shorter: truncated */
    CHECK(has("b.txt", "s\n"));
    CHECK(count(NULL, "pdt-tmp") == 0);
}

TEST(read_only_refused_with_its_name)
{
    clean();
    pdt_err err;
    put("ro.txt", "old\n");
    chmod(path("ro.txt"), 0444);
    CHECK(replace("ro.txt", "new\n", 0, &err) == PDT_ERR_IO);
    CHECK_MSG(strstr(err.msg, "ro.txt: is read-only") != NULL, "%s", err.msg);
    CHECK(has("ro.txt", "old\n"));
    CHECK(count(NULL, "pdt-tmp") == 0);
}

TEST(folder_refused)
{
    clean();
    pdt_err err;
    mkdir(path("sub"), 0777);
    CHECK(replace("sub", "x\n", 0, &err) == PDT_ERR_IO);
    CHECK_MSG(strstr(err.msg, "is a directory") != NULL, "%s", err.msg);
}

TEST(abort_leaves_the_target)
{
    clean();
    pdt_err err;
    put("k.tri", "old\n");
    pdt_safe_file f;
    CHECK(pdt_safe_open(&f, path("k.tri"), 0, &err) == PDT_OK);
    CHECK(write(f.fd, "partial", 7) == 7);
    CHECK(count(NULL, "pdt-tmp") == 1);
    pdt_safe_abort(&f);
    CHECK(has("k.tri", "old\n"));
    CHECK(count(NULL, "pdt-tmp") == 0);
}

/* The .node became a folder after both temporaries were written: neither
 * file is replaced (the .ele's exchange is undone). */
TEST(ele_and_node_rolled_back_together)
{
    clean();
    pdt_err err;
    pdt_err_clear(&err);
    put("p.ele", "old ele\n");
    put("p.node", "old node\n");
    pdt_safe_file f[2];
    CHECK(pdt_safe_open(&f[0], path("p.ele"), 0, &err) == PDT_OK);
    CHECK(pdt_safe_open(&f[1], path("p.node"), 0, &err) == PDT_OK);
    CHECK(write(f[0].fd, "new ele\n", 8) == 8 && write(f[1].fd, "new node\n", 9) == 9);
    unlink(path("p.node"));
    mkdir(path("p.node"), 0777);
    CHECK(pdt_safe_commit_group(f, 2, &err) == PDT_ERR_IO);
    CHECK_MSG(strstr(err.msg, "p.node") != NULL, "%s", err.msg);
    CHECK(has("p.ele", "old ele\n"));
    CHECK(count(NULL, "pdt-tmp") == 0);
    rmdir(path("p.node"));
    put("p.node", "old node\n");
    CHECK(pdt_safe_open(&f[0], path("p.ele"), 0, &err) == PDT_OK);
    CHECK(pdt_safe_open(&f[1], path("p.node"), 0, &err) == PDT_OK);
    CHECK(write(f[0].fd, "new ele\n", 8) == 8 && write(f[1].fd, "new node\n", 9) == 9);
    pdt_err_clear(&err);
    CHECK(pdt_safe_commit_group(f, 2, &err) == PDT_OK);
    CHECK(has("p.ele", "new ele\n") && has("p.node", "new node\n"));
}

/* A pid no process has: a child that has exited and been reaped. */
static long dead_pid(void)
{
    pid_t p = fork();
    if (p == 0) _exit(0);
    waitpid(p, NULL, 0);
    return (long)p;
}

TEST(stale_temporaries_removed_only_pdts_own)
{
    clean();
    pdt_err err;
    char name[128];
    snprintf(name, sizeof name, ".out.tri.pdt-tmp.%ld.0badf00d", dead_pid());
    put(name, "leftover of a killed run");
    snprintf(name, sizeof name, ".out.tri.pdt-tmp.%ld.0badf00d", (long)getppid());
    put(name, "a live process's temporary");
    put(".out.tri.tmp123", "the user's");
    put(".pdtview-index.tmp123", "the user's");
    CHECK(replace("out.tri", "new\n", 0, &err) == PDT_OK);
    CHECK(count(NULL, "pdt-tmp") == 1); /* the live one stays */
    CHECK(has(name, "a live process's temporary"));
    CHECK(has(".out.tri.tmp123", "the user's") && has(".pdtview-index.tmp123", "the user's"));
}

TEST(run_folder_swapped_in_whole)
{
    clean();
    pdt_err err;
    pdt_err_clear(&err);
    mkdir(path("run"), 0750);
    put("run/manifest", "old manifest");
    put("run/rank-0003.trace", "old rank 3");
    pdt_safe_dir d;
    CHECK(pdt_safe_dir_open(&d, path("run"), &err) == PDT_OK);
    char p[600];
    snprintf(p, sizeof p, "%s/manifest", d.tmp);
    FILE *f = fopen(p, "w");
    if (f) {
        fputs("new manifest", f);
        fclose(f);
    }
    CHECK(has("run/manifest", "old manifest")); /* nothing visible before the commit */
    CHECK(pdt_safe_dir_commit(&d, &err) == PDT_OK);
    CHECK(has("run/manifest", "new manifest"));
    CHECK(access(path("run/rank-0003.trace"), F_OK) != 0);
    CHECK_MSG((mode_of("run") & 07777) == 0750, "mode %o", (unsigned)mode_of("run"));
    CHECK(count(NULL, "pdt-tmp") == 0);
}

TEST(run_folder_abort_leaves_the_old_one)
{
    clean();
    pdt_err err;
    pdt_err_clear(&err);
    mkdir(path("run"), 0777);
    put("run/manifest", "old manifest");
    pdt_safe_dir d;
    CHECK(pdt_safe_dir_open(&d, path("run"), &err) == PDT_OK);
    pdt_safe_dir_abort(&d);
    CHECK(has("run/manifest", "old manifest"));
    CHECK(count(NULL, "pdt-tmp") == 0);
    /* swapped, then not kept: the old folder back */
    CHECK(pdt_safe_dir_open(&d, path("run"), &err) == PDT_OK);
    CHECK(pdt_safe_dir_swap(&d, &err) == PDT_OK);
    CHECK(access(path("run/manifest"), F_OK) != 0);
    pdt_safe_dir_finish(&d, 0);
    CHECK(has("run/manifest", "old manifest"));
    CHECK(count(NULL, "pdt-tmp") == 0);
    /* a new folder that is not kept leaves no folder */
    CHECK(pdt_safe_dir_open(&d, path("new"), &err) == PDT_OK);
    CHECK(pdt_safe_dir_swap(&d, &err) == PDT_OK);
    pdt_safe_dir_finish(&d, 0);
    CHECK(access(path("new"), F_OK) != 0);
}

TEST(run_folder_with_other_files_refused)
{
    clean();
    pdt_err err;
    pdt_err_clear(&err);
    mkdir(path("d"), 0777);
    put("d/points.txt", "0 0\n");
    pdt_safe_dir d;
    CHECK(pdt_safe_dir_open(&d, path("d"), &err) == PDT_ERR_IO);
    CHECK_MSG(strstr(err.msg, "holds points.txt") != NULL, "%s", err.msg);
    CHECK(count(NULL, "pdt-tmp") == 0);
    put("f", "a file");
    pdt_err_clear(&err);
    CHECK(pdt_safe_dir_open(&d, path("f"), &err) == PDT_ERR_IO);
    CHECK_MSG(strstr(err.msg, "not a folder") != NULL, "%s", err.msg);
}

TEST(run_folder_symlink_followed)
{
    clean();
    pdt_err err;
    pdt_err_clear(&err);
    mkdir(path("real"), 0777);
    put("real/manifest", "old");
    CHECK(symlink("real", path("link")) == 0);
    pdt_safe_dir d;
    CHECK(pdt_safe_dir_open(&d, path("link"), &err) == PDT_OK);
    CHECK(pdt_safe_dir_commit(&d, &err) == PDT_OK);
    CHECK(S_ISLNK(mode_of("link")) && S_ISDIR(mode_of("real")));
    CHECK(access(path("real/manifest"), F_OK) != 0);
}

TEST(input_inside_run_folder_detected)
{
    clean();
    mkdir(path("d"), 0777);
    put("d/points.bin", "0 0\n");
    CHECK(pdt_safe_inside(path("d/points.bin"), path("d")));
    CHECK(pdt_safe_inside(path("d/not-yet"), path("d")));
    CHECK(pdt_safe_inside(path("d"), path("d")));
    CHECK(!pdt_safe_inside(path("dd"), path("d")));
    CHECK(symlink("d", path("alias")) == 0);
    CHECK(pdt_safe_inside(path("alias/points.bin"), path("d")));
    CHECK(pdt_safe_touches_run(path("d/manifest"), path("d")));
    CHECK(!pdt_safe_touches_run(path("d/picture.png"), path("d")));
    put("d/manifest", "m");
    CHECK(link(path("d/manifest"), path("hard")) == 0);
    CHECK(pdt_safe_touches_run(path("hard"), path("d")));
    CHECK(pdt_safe_run_name("rank-0012.trace") && !pdt_safe_run_name("rank-x.trace"));
    CHECK(!pdt_safe_run_name(".pdtview-index.tmp123"));
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/pdt-safefile.XXXXXX");
    if (!mkdtemp(dir)) return 1;
    RUN(mode_600_kept);
    RUN(new_file_takes_the_umask);
    RUN(symlink_target_replaced_link_kept);
    RUN(nofollow_replaces_a_planted_link);
    RUN(hard_links_kept);
    RUN(read_only_refused_with_its_name);
    RUN(folder_refused);
    RUN(abort_leaves_the_target);
    RUN(ele_and_node_rolled_back_together);
    RUN(stale_temporaries_removed_only_pdts_own);
    RUN(run_folder_swapped_in_whole);
    RUN(run_folder_abort_leaves_the_old_one);
    RUN(run_folder_with_other_files_refused);
    RUN(run_folder_symlink_followed);
    RUN(input_inside_run_folder_detected);
    clean();
    rmdir(dir);
    return test_summary();
}
