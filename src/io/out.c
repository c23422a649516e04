/* pdt — atomic output: a FILE over a pdt/safefile.h temporary, renamed into
 * place only when every byte was written. */
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
    memset(o, 0, sizeof *o);
    o->sf.fd = -1;
    if (!path || strcmp(path, "-") == 0) {
        o->fp = stdout;
        return PDT_OK;
    }
    pdt_status st = pdt_safe_open(&o->sf, path, PDT_SAFE_DIRECT, err);
    if (st != PDT_OK) return st;
    o->fp = fdopen(o->sf.fd, "w");
    if (!o->fp) {
        int e = errno;
        pdt_safe_abort(&o->sf);
        return pdt_err_set(err, PDT_ERR_IO, "%s: cannot create: %s", path, strerror(e));
    }
    o->path = o->sf.name;
    o->tmp = o->sf.tmp;
    return PDT_OK;
}

/* Flush and close o's FILE (the descriptor goes with it); 0 or an errno. */
static int out_close(pdt_outfile *o)
{
    int bad = fflush(o->fp) != 0 || ferror(o->fp);
    int e = bad ? (errno ? errno : EIO) : 0;
    if (fclose(o->fp) != 0 && !e) e = errno ? errno : EIO;
    o->fp = NULL;
    o->sf.fd = -1;
    return e;
}

pdt_status pdt_out_finish_pair(pdt_outfile *a, pdt_outfile *b, pdt_pending_write *pw,
                              pdt_err *err)
{
    pdt_outfile *o[2] = {a, b};
    int n = b ? 2 : 1;
    pw->n = 0;
    for (int k = 0; k < n; k++)
        if (!o[k]->fp) return pdt_err_set(err, PDT_ERR_ARG, "output file is not open");
    if (!a->path) { /* standard output: flush and check */
        int bad = fflush(a->fp) != 0 || ferror(a->fp);
        int e = errno;
        a->fp = NULL;
        if (bad)
            return pdt_err_set(err, PDT_ERR_IO, "standard output: write error: %s", strerror(e));
        return PDT_OK;
    }
    pdt_status st = PDT_OK;
    for (int k = 0; k < n; k++) {
        int e = out_close(o[k]);
        if (e && st == PDT_OK)
            st = pdt_err_set(err, PDT_ERR_IO, "%s: write error: %s", o[k]->path, strerror(e));
    }
    for (int k = 0; k < n; k++) {
        pw->f[k] = o[k]->sf;
        o[k]->path = o[k]->tmp = NULL;
    }
    pw->n = n;
    if (st != PDT_OK) pdt_pending_drop(pw);
    return st;
}

pdt_status pdt_pending_commit(pdt_pending_write *pw, pdt_err *err)
{
    int n = pw->n;
    pw->n = 0;
    return n ? pdt_safe_commit_group(pw->f, n, err) : PDT_OK;
}

void pdt_pending_drop(pdt_pending_write *pw)
{
    for (int k = 0; k < pw->n; k++) pdt_safe_abort(&pw->f[k]);
    pw->n = 0;
}

pdt_status pdt_out_commit_pair(pdt_outfile *a, pdt_outfile *b, pdt_err *err)
{
    pdt_pending_write pw;
    pdt_status st = pdt_out_finish_pair(a, b, &pw, err);
    return st == PDT_OK ? pdt_pending_commit(&pw, err) : st;
}

pdt_status pdt_out_commit(pdt_outfile *o, pdt_err *err)
{
    return pdt_out_commit_pair(o, NULL, err);
}

void pdt_out_abort(pdt_outfile *o)
{
    if (o->path) {
        if (o->fp) fclose(o->fp);
        o->sf.fd = -1;
        pdt_safe_abort(&o->sf);
    } else if (o->fp) {
        fflush(o->fp);
    }
    o->fp = NULL;
    o->path = o->tmp = NULL;
}
