/* pdt — writing the user's files without losing any: the rule of
 * include/pdt/safefile.h, in one place.
 *
 * Why each step is as it is:
 *   - The temporary is created beside the target (same file system, so the
 *     final rename is atomic) with O_EXCL|O_NOFOLLOW: a name planted in the
 *     folder, link or file, is never opened.
 *   - Its name, ".BASE.pdt-tmp.PID.RAND", says whose it is: a run killed
 *     during its write leaves one, and the next write into the same place
 *     removes it when process PID is gone.  A file of the user's that only
 *     looks alike (".pdtview-index.tmp123") does not match.
 *   - An existing target is replaced by an exchange of the two names
 *     (renameat2 RENAME_EXCHANGE) and the old file removed afterwards: on
 *     ext4 a plain rename over a file starts writing the new one back to
 *     disk inside the call; and an exchange can be undone, which is what a
 *     group commit needs.
 *   - The target is looked at again just before the exchange: if it became
 *     something else (a folder, a device) meanwhile, nothing is replaced.
 *   - Read-only means no write permission for us, or no write bit at all:
 *     root may write anything, but a file of mode 0444 was made read-only
 *     by someone on purpose. */
#include "pdt/safefile.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define TMP_MARK ".pdt-tmp."
enum { MAX_LINKS = 40, BASE_KEEP = 180 };
enum { SWAP_NONE, SWAP_EXCHANGED, SWAP_RENAMED }; /* pdt_safe_file.swapped */

/* ---- names ---------------------------------------------------------------------- */

static char *dup_n(const char *s, size_t n)
{
    char *p = malloc(n + 1);
    if (!p) return NULL;
    memcpy(p, s, n);
    p[n] = '\0';
    return p;
}

/* The folder part of path ("." when none), malloc'd. */
static char *dir_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash) return dup_n(".", 1);
    if (slash == path) return dup_n("/", 1);
    return dup_n(path, (size_t)(slash - path));
}

static const char *base_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

/* `path` with symlinks of its last component followed (up to MAX_LINKS),
 * malloc'd; NULL with errno on a loop or out of memory. */
static char *follow_links(const char *path)
{
    char *p = dup_n(path, strlen(path));
    for (int hops = 0; p && hops < MAX_LINKS; hops++) {
        struct stat sb;
        if (lstat(p, &sb) != 0 || !S_ISLNK(sb.st_mode)) return p;
        char link[PATH_MAX];
        ssize_t k = readlink(p, link, sizeof link - 1);
        if (k < 0) return p;
        link[k] = '\0';
        char *next;
        if (link[0] == '/') {
            next = dup_n(link, (size_t)k);
        } else {
            char *d = dir_of(p);
            size_t len = (d ? strlen(d) : 0) + (size_t)k + 2;
            next = d ? malloc(len) : NULL;
            if (next) snprintf(next, len, "%s/%s", d, link);
            free(d);
        }
        free(p);
        p = next;
    }
    if (p) {
        free(p);
        errno = ELOOP;
    }
    return NULL;
}

/* A fresh name "DIR/.BASE.pdt-tmp.PID.RAND" into buf (RAND: 8 hex digits). */
static void temp_name(char *buf, size_t cap, const char *dir, const char *base)
{
    static unsigned counter;
    uint32_t r = 0;
    if (getrandom(&r, sizeof r, GRND_NONBLOCK) != (ssize_t)sizeof r) {
        struct timespec ts;
        clock_gettime(CLOCK_MONOTONIC, &ts);
        r = (uint32_t)ts.tv_nsec ^ (uint32_t)(++counter * 2654435761u);
    }
    snprintf(buf, cap, "%s/.%.*s" TMP_MARK "%ld.%08x", dir, BASE_KEEP, base, (long)getpid(),
             (unsigned)r);
}

/* The pid of a temporary's name ".BASE.pdt-tmp.PID.RAND" of `base`, or 0. */
static long temp_pid(const char *name, const char *base)
{
    size_t bl = strlen(base);
    if (bl > BASE_KEEP) bl = BASE_KEEP;
    size_t ml = sizeof TMP_MARK - 1;
    if (name[0] != '.' || strncmp(name + 1, base, bl) || strncmp(name + 1 + bl, TMP_MARK, ml))
        return 0;
    const char *s = name + 1 + bl + ml;
    char *end;
    errno = 0;
    long pid = strtol(s, &end, 10);
    if (end == s || *end != '.' || errno || pid <= 0 || strlen(end + 1) != 8) return 0;
    for (const char *h = end + 1; *h; h++)
        if (!strchr("0123456789abcdef", *h)) return 0;
    return pid;
}

int pdt_safe_run_name(const char *name)
{
    if (!strcmp(name, "manifest") || !strcmp(name, "points.bin") ||
        !strcmp(name, ".pdtview-index"))
        return 1;
    unsigned q;
    int used = 0;
    if (sscanf(name, "rank-%u.trace%n", &q, &used) == 1 && used > 0 && !name[used] &&
        !strncmp(name, "rank-", 5) && name[5] >= '0' && name[5] <= '9')
        return 1;
    if (name[0] != '.') return 0;
    /* pdt's temporaries: ".X.pdt-tmp.PID.RAND", and an older release's
     * ".points.bin.tmp.PID" / ".manifest.tmp.PID" */
    const char *m = strstr(name, TMP_MARK);
    if (m && m > name + 1) {
        char base[NAME_MAX + 1];
        snprintf(base, sizeof base, "%.*s", (int)(m - name - 1), name + 1);
        return temp_pid(name, base) > 0;
    }
    const char *old[] = {".points.bin.tmp.", ".manifest.tmp."};
    for (int i = 0; i < 2; i++) {
        size_t k = strlen(old[i]);
        if (!strncmp(name, old[i], k) && name[k] && strspn(name + k, "0123456789") == strlen(name + k))
            return 1;
    }
    return 0;
}

/* ---- leftovers of killed runs ------------------------------------------------------ */

static int pid_gone(long pid)
{
    return pid != (long)getpid() && kill((pid_t)pid, 0) != 0 && errno == ESRCH;
}

/* Remove the run-folder files of folder `path` (and nothing else), then
 * the folder if that left it empty. */
static void remove_run_dir(const char *path)
{
    DIR *d = opendir(path);
    if (d) {
        struct dirent *de;
        while ((de = readdir(d)))
            if (pdt_safe_run_name(de->d_name)) (void)unlinkat(dirfd(d), de->d_name, 0);
        closedir(d);
    }
    (void)rmdir(path);
}

/* Remove pdt's temporaries of `base` in `dir` whose process is gone: files,
 * and run folders (their run files only). */
static void clean_stale(const char *dir, const char *base)
{
    DIR *d = opendir(dir);
    if (!d) return;
    struct dirent *de;
    while ((de = readdir(d))) {
        long pid = temp_pid(de->d_name, base);
        if (pid <= 0 || !pid_gone(pid)) continue;
        struct stat sb;
        if (fstatat(dirfd(d), de->d_name, &sb, AT_SYMLINK_NOFOLLOW) != 0) continue;
        if (S_ISREG(sb.st_mode) || S_ISLNK(sb.st_mode)) {
            (void)unlinkat(dirfd(d), de->d_name, 0);
        } else if (S_ISDIR(sb.st_mode)) {
            size_t len = strlen(dir) + strlen(de->d_name) + 2;
            char *p = malloc(len);
            if (p) {
                snprintf(p, len, "%s/%s", dir, de->d_name);
                remove_run_dir(p);
                free(p);
            }
        }
    }
    closedir(d);
}

/* ---- one file ---------------------------------------------------------------------- */

/* The process's umask (read by setting it back: umask has no getter). */
static mode_t cur_umask(void)
{
    mode_t um = umask(0);
    umask(um);
    return um;
}

/* Whether we may write into folder `dir` (a message in err if not). */
static pdt_status check_folder(const char *name, const char *dir, pdt_err *err)
{
    struct stat sb;
    if (stat(dir, &sb) != 0)
        return pdt_err_set(err, PDT_ERR_IO, "%s: cannot create: %s", name, strerror(errno));
    if (!S_ISDIR(sb.st_mode))
        return pdt_err_set(err, PDT_ERR_IO, "%s: cannot create: %s", name, strerror(ENOTDIR));
    if (faccessat(AT_FDCWD, dir, W_OK | X_OK, AT_EACCESS) != 0)
        return pdt_err_set(err, PDT_ERR_IO, "%s: cannot write in the folder %s: %s; nothing "
                           "written", name, dir, strerror(errno));
    return PDT_OK;
}

/* What the target is: *sb filled when it exists; *kind 0 absent, 1 regular,
 * 2 device or pipe.  Refuses folders and read-only files. */
static pdt_status look_at_target(pdt_safe_file *f, struct stat *sb, int *kind, pdt_err *err)
{
    if (lstat(f->target, sb) != 0) {
        if (errno != ENOENT)
            return pdt_err_set(err, PDT_ERR_IO, "%s: %s", f->name, strerror(errno));
        *kind = 0;
        return PDT_OK;
    }
    if (S_ISDIR(sb->st_mode)) return pdt_err_set(err, PDT_ERR_IO, "%s: is a directory", f->name);
    if (S_ISLNK(sb->st_mode)) { /* (PDT_SAFE_NOFOLLOW, or a loop) */
        *kind = 0;
        return PDT_OK;
    }
    if (!S_ISREG(sb->st_mode)) {
        *kind = 2;
        return PDT_OK;
    }
    *kind = 1;
    if ((sb->st_mode & 0222) == 0 || faccessat(AT_FDCWD, f->target, W_OK, AT_EACCESS) != 0)
        return pdt_err_set(err, PDT_ERR_IO, "%s: is read-only (mode %03o%s); nothing written",
                           f->name, (unsigned)(sb->st_mode & 07777),
                           sb->st_uid != geteuid() ? ", another user's file" : "");
    return PDT_OK;
}

/* A device or a pipe, written directly. */
static pdt_status open_direct(pdt_safe_file *f, int flags, pdt_err *err)
{
    if (!(flags & PDT_SAFE_DIRECT))
        return pdt_err_set(err, PDT_ERR_IO, "%s: is not a regular file; nothing written", f->name);
    f->fd = open(f->target, O_WRONLY | O_CLOEXEC);
    if (f->fd < 0) return pdt_err_set(err, PDT_ERR_IO, "%s: cannot open: %s", f->name, strerror(errno));
    return PDT_OK;
}

/* Create the temporary beside the target with the target's mode and owner. */
static pdt_status open_temp(pdt_safe_file *f, const struct stat *sb, pdt_err *err)
{
    char *dir = dir_of(f->target);
    if (!dir) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    pdt_status st = check_folder(f->name, dir, err);
    if (st == PDT_OK) clean_stale(dir, base_of(f->target));
    size_t cap = strlen(dir) + BASE_KEEP + 64;
    f->tmp = st == PDT_OK ? malloc(cap) : NULL;
    if (st == PDT_OK && !f->tmp) st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    for (int tries = 0; st == PDT_OK && f->fd < 0; tries++) {
        temp_name(f->tmp, cap, dir, base_of(f->target));
        f->fd = open(f->tmp, O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
        if (f->fd < 0 && (errno != EEXIST || tries > 100))
            st = pdt_err_set(err, PDT_ERR_IO, "%s: cannot create a file beside it: %s", f->name,
                             strerror(errno));
    }
    free(dir);
    if (st != PDT_OK) return st;
    if (f->exists) {
        if (sb->st_uid != geteuid() || sb->st_gid != getegid())
            (void)fchown(f->fd, sb->st_uid, sb->st_gid); /* (where permitted) */
        (void)fchmod(f->fd, sb->st_mode & 07777);
    } else {
        (void)fchmod(f->fd, (mode_t)(0666 & ~cur_umask()));
    }
    return PDT_OK;
}

static void free_names(pdt_safe_file *f)
{
    free(f->name);
    free(f->target);
    free(f->tmp);
    f->name = f->target = f->tmp = NULL;
}

pdt_status pdt_safe_open(pdt_safe_file *f, const char *path, int flags, pdt_err *err)
{
    memset(f, 0, sizeof *f);
    f->fd = -1;
    f->name = dup_n(path, strlen(path));
    f->target = flags & PDT_SAFE_NOFOLLOW ? dup_n(path, strlen(path)) : follow_links(path);
    if (!f->name || !f->target) {
        pdt_status st = f->name && errno == ELOOP
                            ? pdt_err_set(err, PDT_ERR_IO, "%s: too many symbolic links", path)
                            : pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
        free_names(f);
        return st;
    }
    struct stat sb;
    int kind = 0;
    pdt_status st = look_at_target(f, &sb, &kind, err);
    f->exists = kind == 1;
    f->in_place = kind == 1 && sb.st_nlink > 1 && !(flags & PDT_SAFE_NOFOLLOW);
    if (st == PDT_OK) st = kind == 2 ? open_direct(f, flags, err) : open_temp(f, &sb, err);
    if (st != PDT_OK) pdt_safe_abort(f);
    return st;
}

void pdt_safe_abort(pdt_safe_file *f)
{
    if (f->fd >= 0) close(f->fd);
    f->fd = -1;
    if (f->tmp) (void)unlink(f->tmp);
    free_names(f);
}

/* Close the temporary, checking that every byte reached the file system. */
static pdt_status close_temp(pdt_safe_file *f, pdt_err *err)
{
    if (f->fd < 0) return PDT_OK;
    int rc = close(f->fd);
    f->fd = -1;
    if (rc != 0) return pdt_err_set(err, PDT_ERR_IO, "%s: write error: %s", f->name, strerror(errno));
    return PDT_OK;
}

/* The target just before it is replaced: still what it was at open? */
static pdt_status still_same(const pdt_safe_file *f, pdt_err *err)
{
    struct stat sb;
    int there = lstat(f->target, &sb) == 0;
    if (f->exists ? there && S_ISREG(sb.st_mode) : !there || S_ISLNK(sb.st_mode)) return PDT_OK;
    return pdt_err_set(err, PDT_ERR_IO, "%s: changed while it was written (now %s); left as it "
                       "is, nothing written", f->name,
                       !there ? "gone" : S_ISDIR(sb.st_mode) ? "a folder" : "another kind of file");
}

/* Copy the complete temporary into the target (it has other hard links),
 * the space reserved first so that a full disk stops before any byte. */
static pdt_status copy_in_place(pdt_safe_file *f, pdt_err *err)
{
    int in = open(f->tmp, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    int out = in >= 0 ? open(f->target, O_WRONLY | O_NOFOLLOW | O_CLOEXEC) : -1;
    struct stat sb;
    int e = 0;
    if (out < 0 || fstat(in, &sb) != 0) e = errno;
    if (!e && sb.st_size > 0 && fallocate(out, FALLOC_FL_KEEP_SIZE, 0, sb.st_size) != 0 &&
        errno != EOPNOTSUPP)
        e = errno;
    char buf[1 << 16];
    for (off_t at = 0; !e && at < sb.st_size;) {
        ssize_t k = pread(in, buf, sizeof buf, at);
        if (k <= 0 || pwrite(out, buf, (size_t)k, at) != k) e = k < 0 ? errno : EIO;
        else at += k;
    }
    if (!e && (ftruncate(out, sb.st_size) != 0 || fsync(out) != 0)) e = errno;
    if (out >= 0 && close(out) != 0 && !e) e = errno;
    if (in >= 0) close(in);
    if (e) return pdt_err_set(err, PDT_ERR_IO, "%s: write error (in place, it has other hard "
                              "links): %s", f->name, strerror(e));
    return PDT_OK;
}

/* The temporary takes the target's name: an exchange when the target
 * exists (f->swapped; the old file is then under the temporary's name),
 * else a rename that never replaces what appeared meanwhile. */
static pdt_status swap_in(pdt_safe_file *f, pdt_err *err)
{
    pdt_status st = still_same(f, err);
    if (st != PDT_OK) return st;
    int rc;
    if (f->exists) {
        rc = renameat2(AT_FDCWD, f->tmp, AT_FDCWD, f->target, RENAME_EXCHANGE);
        if (rc == 0) f->swapped = SWAP_EXCHANGED;
        else if ((errno == EINVAL || errno == ENOSYS) && (rc = rename(f->tmp, f->target)) == 0)
            f->swapped = SWAP_RENAMED;
    } else {
        struct stat sb; /* (a link at the name, PDT_SAFE_NOFOLLOW: replaced) */
        int link = lstat(f->target, &sb) == 0 && S_ISLNK(sb.st_mode);
        rc = link ? -1 : renameat2(AT_FDCWD, f->tmp, AT_FDCWD, f->target, RENAME_NOREPLACE);
        if (link || (rc != 0 && (errno == EINVAL || errno == ENOSYS)))
            rc = rename(f->tmp, f->target);
        if (rc == 0) f->swapped = SWAP_RENAMED;
    }
    if (rc != 0)
        return pdt_err_set(err, PDT_ERR_IO, "%s: cannot be replaced: %s; left as it was",
                           f->name, strerror(errno));
    return PDT_OK;
}

/* Undo swap_in: the old file back, the new one under the temporary's name. */
static void swap_back(pdt_safe_file *f)
{
    if (f->swapped == SWAP_EXCHANGED)
        (void)renameat2(AT_FDCWD, f->tmp, AT_FDCWD, f->target, RENAME_EXCHANGE);
    else if (f->swapped == SWAP_RENAMED)
        (void)rename(f->target, f->tmp);
    f->swapped = 0;
}

pdt_status pdt_safe_commit(pdt_safe_file *f, pdt_err *err)
{
    return pdt_safe_commit_group(f, 1, err);
}

/* Close every member; the first failure is the group's. */
static pdt_status close_all(pdt_safe_file *f, int n, pdt_err *err)
{
    pdt_status st = PDT_OK;
    for (int k = 0; k < n; k++) {
        pdt_status s = close_temp(&f[k], err);
        if (st == PDT_OK) st = s;
    }
    return st;
}

pdt_status pdt_safe_commit_group(pdt_safe_file *f, int n, pdt_err *err)
{
    pdt_status st = close_all(f, n, err);
    for (int k = 0; k < n && st == PDT_OK; k++)
        if (f[k].tmp && !f[k].in_place) st = swap_in(&f[k], err);
    for (int k = 0; k < n && st == PDT_OK; k++)
        if (f[k].tmp && f[k].in_place) st = copy_in_place(&f[k], err);
    for (int k = n - 1; k >= 0 && st != PDT_OK; k--) swap_back(&f[k]);
    for (int k = 0; k < n; k++) {
        /* an exchanged member's temporary name now holds the old file */
        if (f[k].tmp && f[k].swapped != SWAP_RENAMED) (void)unlink(f[k].tmp);
        free_names(&f[k]);
    }
    return st;
}

/* ---- run folders ------------------------------------------------------------------- */

/* A folder's entries are all a run folder's (else the first other one in
 * *other, malloc'd): what replacing it may remove. */
static int only_run_files(const char *dir, char **other)
{
    DIR *d = opendir(dir);
    *other = NULL;
    if (!d) return 0;
    struct dirent *de;
    while ((de = readdir(d)) && !*other)
        if (strcmp(de->d_name, ".") && strcmp(de->d_name, "..") && !pdt_safe_run_name(de->d_name))
            *other = dup_n(de->d_name, strlen(de->d_name));
    closedir(d);
    return !*other;
}

/* Whether the target folder may be replaced (d->exists set). */
static pdt_status look_at_dir(pdt_safe_dir *d, struct stat *sb, pdt_err *err)
{
    if (stat(d->target, sb) != 0) {
        if (errno != ENOENT) return pdt_err_set(err, PDT_ERR_IO, "%s: %s", d->name, strerror(errno));
        d->exists = 0;
        return PDT_OK;
    }
    if (!S_ISDIR(sb->st_mode))
        return pdt_err_set(err, PDT_ERR_IO, "%s: exists and is not a folder; nothing written",
                           d->name);
    d->exists = 1;
    char *other = NULL;
    if (!only_run_files(d->target, &other)) {
        pdt_status st = pdt_err_set(err, PDT_ERR_IO, "%s: holds %s, which is not part of a run "
                                    "folder and would be lost; choose another folder; nothing "
                                    "written", d->name, other ? other : "files we cannot list");
        free(other);
        return st;
    }
    if (faccessat(AT_FDCWD, d->target, W_OK | X_OK, AT_EACCESS) != 0 || (sb->st_mode & 0222) == 0)
        return pdt_err_set(err, PDT_ERR_IO, "%s: is read-only; nothing written", d->name);
    return PDT_OK;
}

/* The temporary folder beside the target, with its mode and owner. */
static pdt_status make_temp_dir(pdt_safe_dir *d, const struct stat *sb, pdt_err *err)
{
    char *dir = dir_of(d->target);
    if (!dir) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    pdt_status st = check_folder(d->name, dir, err);
    if (st == PDT_OK) clean_stale(dir, base_of(d->target));
    size_t cap = strlen(dir) + BASE_KEEP + 64;
    d->tmp = st == PDT_OK ? malloc(cap) : NULL;
    if (st == PDT_OK && !d->tmp) st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    int made = 0;
    for (int tries = 0; st == PDT_OK && !made; tries++) {
        temp_name(d->tmp, cap, dir, base_of(d->target));
        made = mkdir(d->tmp, 0700) == 0;
        if (!made && (errno != EEXIST || tries > 100))
            st = pdt_err_set(err, PDT_ERR_IO, "%s: cannot create a folder beside it: %s", d->name,
                             strerror(errno));
    }
    free(dir);
    if (st != PDT_OK) return st;
    if (d->exists && (sb->st_uid != geteuid() || sb->st_gid != getegid()))
        (void)chown(d->tmp, sb->st_uid, sb->st_gid);
    (void)chmod(d->tmp, d->exists ? sb->st_mode & 07777 : (mode_t)(0777 & ~cur_umask()));
    return PDT_OK;
}

static void free_dir_names(pdt_safe_dir *d)
{
    free(d->name);
    free(d->target);
    free(d->tmp);
    d->name = d->target = d->tmp = NULL;
}

pdt_status pdt_safe_dir_open(pdt_safe_dir *d, const char *dir, pdt_err *err)
{
    memset(d, 0, sizeof *d);
    size_t len = strlen(dir);
    while (len > 1 && dir[len - 1] == '/') len--;
    char *trimmed = dup_n(dir, len);
    d->name = dup_n(dir, strlen(dir));
    d->target = trimmed ? follow_links(trimmed) : NULL;
    free(trimmed);
    if (!d->name || !d->target) {
        free_dir_names(d);
        return pdt_err_set(err, PDT_ERR_IO, "%s: %s", dir, strerror(errno ? errno : ENOMEM));
    }
    struct stat sb;
    pdt_status st = look_at_dir(d, &sb, err);
    if (st == PDT_OK) st = make_temp_dir(d, &sb, err);
    if (st != PDT_OK) pdt_safe_dir_abort(d);
    return st;
}

pdt_status pdt_safe_dir_swap(pdt_safe_dir *d, pdt_err *err)
{
    int rc;
    if (d->exists) {
        rc = renameat2(AT_FDCWD, d->tmp, AT_FDCWD, d->target, RENAME_EXCHANGE);
    } else {
        rc = renameat2(AT_FDCWD, d->tmp, AT_FDCWD, d->target, RENAME_NOREPLACE);
        if (rc != 0 && (errno == EINVAL || errno == ENOSYS)) rc = rename(d->tmp, d->target);
    }
    if (rc != 0)
        return pdt_err_set(err, PDT_ERR_IO, "%s: cannot put the new run folder in place: %s; "
                           "left as it was", d->name, strerror(errno));
    d->swapped = 1;
    return PDT_OK;
}

void pdt_safe_dir_finish(pdt_safe_dir *d, int keep)
{
    if (!d->target) return;
    if (d->swapped && !keep) { /* the old folder back, the new one under the temporary name */
        if (d->exists) (void)renameat2(AT_FDCWD, d->tmp, AT_FDCWD, d->target, RENAME_EXCHANGE);
        else (void)rename(d->target, d->tmp);
    }
    /* the temporary name holds the old folder (kept, exchanged), the new
     * one (not kept), or nothing (kept, renamed) */
    if (d->tmp && (!keep || d->exists)) remove_run_dir(d->tmp);
    free_dir_names(d);
}

void pdt_safe_dir_abort(pdt_safe_dir *d)
{
    pdt_safe_dir_finish(d, 0);
}

pdt_status pdt_safe_dir_commit(pdt_safe_dir *d, pdt_err *err)
{
    pdt_status st = pdt_safe_dir_swap(d, err);
    pdt_safe_dir_finish(d, st == PDT_OK);
    return st;
}

/* ---- an input is never an output ---------------------------------------------------- */

int pdt_safe_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (!a || !b || !strcmp(a, "-") || !strcmp(b, "-")) return 0;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev &&
           sa.st_ino == sb.st_ino;
}

/* The real path of `path`, existing or not (its folder's real path and
 * its name), malloc'd, or NULL. */
static char *real_path_of(const char *path)
{
    char *r = realpath(path, NULL);
    if (r) return r;
    char *d = dir_of(path), *rd = d ? realpath(d, NULL) : NULL;
    free(d);
    if (!rd) return NULL;
    size_t len = strlen(rd) + strlen(base_of(path)) + 2;
    char *p = malloc(len);
    if (p) snprintf(p, len, "%s/%s", strcmp(rd, "/") ? rd : "", base_of(path));
    free(rd);
    return p;
}

int pdt_safe_inside(const char *path, const char *dir)
{
    if (!path || !dir || !strcmp(path, "-")) return 0;
    char *rp = real_path_of(path), *rd = real_path_of(dir);
    int in = 0;
    if (rp && rd) {
        size_t k = strlen(rd);
        in = !strcmp(rd, "/") || (!strncmp(rp, rd, k) && (rp[k] == '/' || rp[k] == '\0'));
    }
    free(rp);
    free(rd);
    return in;
}

int pdt_safe_touches_run(const char *path, const char *rundir)
{
    if (!path || !rundir || !strcmp(path, "-")) return 0;
    if (pdt_safe_inside(path, rundir) && pdt_safe_run_name(base_of(path))) return 1;
    DIR *d = opendir(rundir);
    if (!d) return 0;
    struct stat out, sb;
    int hit = 0;
    if (stat(path, &out) == 0) {
        struct dirent *de;
        while (!hit && (de = readdir(d)))
            hit = pdt_safe_run_name(de->d_name) && fstatat(dirfd(d), de->d_name, &sb, 0) == 0 &&
                  sb.st_dev == out.st_dev && sb.st_ino == out.st_ino;
    }
    closedir(d);
    return hit;
}
