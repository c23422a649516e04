/* pdt — atomic output: write a temporary file beside the target, rename it
 * into place only when every byte was written. */
#include "pdt/io.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int pdt_replace_file(const char *tmp, const char *path)
{
    struct stat sb;
    if (lstat(path, &sb) == 0 && S_ISREG(sb.st_mode)) {
        if (renameat2(AT_FDCWD, tmp, AT_FDCWD, path, RENAME_EXCHANGE) == 0) {
            (void)unlink(tmp); /* the old file, now under the temporary's name */
            return 0;
        }
        if (errno != EINVAL && errno != ENOSYS && errno != ENOENT) return -1;
        /* (a file system without exchanges, or the target just went away) */
    }
    return rename(tmp, path);
}

pdt_status pdt_out_open(pdt_outfile *o, const char *path, pdt_err *err)
{
    o->fp = NULL;
    o->path = NULL;
    o->tmp = NULL;
    if (!path || strcmp(path, "-") == 0) {
        o->fp = stdout;
        return PDT_OK;
    }
    struct stat sb;
    int exists = stat(path, &sb) == 0;
    if (exists && S_ISDIR(sb.st_mode))
        return pdt_err_set(err, PDT_ERR_IO, "%s: is a directory", path);
    if (exists && !S_ISREG(sb.st_mode)) {
        /* A device or a pipe (/dev/null, /dev/stdout, a fifo): write to it
         * directly; it cannot be replaced atomically, and must not be. */
        o->path = strdup(path);
        if (!o->path) return pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory", path);
        o->fp = fopen(path, "w");
        if (!o->fp) {
            int e = errno;
            free(o->path);
            o->path = NULL;
            return pdt_err_set(err, PDT_ERR_IO, "%s: cannot open: %s", path, strerror(e));
        }
        return PDT_OK; /* tmp == NULL marks the direct mode */
    }
    /* The temporary lives in the target's directory so that rename() is
     * atomic: "DIR/.BASE.tmpXXXXXX". */
    const char *slash = strrchr(path, '/');
    size_t dirlen = slash ? (size_t)(slash - path) + 1 : 0;
    size_t plen = strlen(path);
    o->path = malloc(plen + 1);
    o->tmp = malloc(plen + 16);
    if (!o->path || !o->tmp) {
        free(o->path);
        free(o->tmp);
        o->path = o->tmp = NULL;
        return pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory", path);
    }
    memcpy(o->path, path, plen + 1);
    memcpy(o->tmp, path, dirlen);
    o->tmp[dirlen] = '.';
    memcpy(o->tmp + dirlen + 1, path + dirlen, plen - dirlen);
    memcpy(o->tmp + plen + 1, ".tmpXXXXXX", 11);
    int fd = mkstemp(o->tmp);
    if (fd < 0) {
        int e = errno;
        free(o->path);
        free(o->tmp);
        o->path = o->tmp = NULL;
        return pdt_err_set(err, PDT_ERR_IO, "%s: cannot create: %s", path, strerror(e));
    }
    /* mkstemp makes the file 0600; give it the mode a plain fopen() would. */
    mode_t um = umask(0);
    umask(um);
    (void)fchmod(fd, (mode_t)(0666 & ~um));
    o->fp = fdopen(fd, "w");
    if (!o->fp) {
        int e = errno;
        close(fd);
        unlink(o->tmp);
        free(o->path);
        free(o->tmp);
        o->path = o->tmp = NULL;
        return pdt_err_set(err, PDT_ERR_IO, "%s: cannot create: %s", path, strerror(e));
    }
    return PDT_OK;
}

pdt_status pdt_out_commit(pdt_outfile *o, pdt_err *err)
{
    if (!o->fp) return pdt_err_set(err, PDT_ERR_ARG, "output file is not open");
    if (!o->path) { /* standard output: flush and check */
        int bad = fflush(o->fp) != 0 || ferror(o->fp);
        int e = errno;
        o->fp = NULL;
        if (bad)
            return pdt_err_set(err, PDT_ERR_IO, "standard output: write error: %s", strerror(e));
        return PDT_OK;
    }
    int bad = fflush(o->fp) != 0 || ferror(o->fp);
    int e = errno;
    if (fclose(o->fp) != 0 && !bad) {
        bad = 1;
        e = errno;
    }
    o->fp = NULL;
    if (!bad && o->tmp && pdt_replace_file(o->tmp, o->path) != 0) {
        bad = 1;
        e = errno;
    }
    pdt_status st = PDT_OK;
    if (bad) {
        if (o->tmp) unlink(o->tmp);
        st = pdt_err_set(err, PDT_ERR_IO, "%s: write error: %s", o->path, strerror(e));
    }
    free(o->path);
    free(o->tmp);
    o->path = o->tmp = NULL;
    return st;
}

void pdt_out_abort(pdt_outfile *o)
{
    if (o->path) {
        if (o->fp) fclose(o->fp);
        if (o->tmp) unlink(o->tmp);
    } else if (o->fp) {
        fflush(o->fp);
    }
    free(o->path);
    free(o->tmp);
    o->fp = NULL;
    o->path = o->tmp = NULL;
}
