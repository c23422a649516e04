/* pdtview --edit FILE: a click saves FILE by the rule of pdt/safefile.h —
 * its mode, its symlink and its hard links are kept; a read-only file is not
 * written (the change stays in the window and the message says so). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../harness.h"
#include "../../src/view/app/edit.h"

static char dir[] = "/tmp/pdt-edit-files.XXXXXX";

static const char *path(const char *name)
{
    static char buf[4][256];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

static void put(const char *name, const char *text)
{
    FILE *f = fopen(path(name), "w");
    if (!f) return;
    fputs(text, f);
    fclose(f);
}

static long lines(const char *name)
{
    FILE *f = fopen(path(name), "r");
    long n = 0;
    int c;
    while (f && (c = fgetc(f)) != EOF) n += c == '\n';
    if (f) fclose(f);
    return n;
}

/* Open the editor on name and add one point (one click). */
static pdt_status click(const char *name, pdt_err *err)
{
    pdt_live_opts lo = {0, 1, 1, 0};
    pdt_editor *ed = NULL;
    pdt_err_clear(err);
    pdt_status st = pdt_editor_open(path(name), &lo, &ed, err);
    if (st == PDT_OK) st = pdt_editor_add(ed, 7, 3, err);
    pdt_editor_free(ed);
    return st;
}

static const char square[] = "0 0\n10 0\n0 10\n10 10\n";

TEST(edit_keeps_mode_600)
{
    pdt_err err;
    put("priv.txt", square);
    chmod(path("priv.txt"), 0600);
    CHECK_MSG(click("priv.txt", &err) == PDT_OK, "%s", err.msg);
    struct stat sb;
    CHECK(stat(path("priv.txt"), &sb) == 0 && (sb.st_mode & 07777) == 0600);
    CHECK(lines("priv.txt") == 5);
}

TEST(edit_through_symlink_updates_the_real_file)
{
    pdt_err err;
    put("real.txt", square);
    CHECK(symlink("real.txt", path("link.txt")) == 0);
    CHECK_MSG(click("link.txt", &err) == PDT_OK, "%s", err.msg);
    struct stat sb;
    CHECK(lstat(path("link.txt"), &sb) == 0 && S_ISLNK(sb.st_mode));
    CHECK(lines("real.txt") == 5);
}

TEST(edit_keeps_hard_links)
{
    pdt_err err;
    put("h1.txt", square);
    CHECK(link(path("h1.txt"), path("h2.txt")) == 0);
    CHECK_MSG(click("h1.txt", &err) == PDT_OK, "%s", err.msg);
    struct stat a, b;
    CHECK(stat(path("h1.txt"), &a) == 0 && stat(path("h2.txt"), &b) == 0);
    CHECK(a.st_ino == b.st_ino && a.st_nlink == 2 && lines("h2.txt") == 5);
}

TEST(edit_refuses_read_only_file)
{
    pdt_err err;
    put("ro.txt", square);
    chmod(path("ro.txt"), 0444);
    CHECK(click("ro.txt", &err) == PDT_ERR_IO);
    CHECK_MSG(strstr(err.msg, "ro.txt: is read-only") && strstr(err.msg, "kept in the window"),
              "%s", err.msg);
    CHECK(lines("ro.txt") == 4);
}

int main(void)
{
    if (!mkdtemp(dir)) return 1;
    RUN(edit_keeps_mode_600);
    RUN(edit_through_symlink_updates_the_real_file);
    RUN(edit_keeps_hard_links);
    RUN(edit_refuses_read_only_file);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0) return 1;
    return test_summary();
}
