/* pdt — writing the user's files without losing any (docs/files.md).
 *
 * One rule for every file pdt and pdtview write:
 *   - the new content goes to a temporary beside the target, created with
 *     O_CREAT|O_EXCL|O_NOFOLLOW under a name that marks it as pdt's own,
 *     ".BASE.pdt-tmp.PID.RAND"; a later write into the same place removes
 *     the ones whose process is gone, and nothing else;
 *   - the target's mode (and owner, where the process may) is kept;
 *   - a read-only target, or one in a folder we cannot write, is refused
 *     before anything is written, with a message naming it;
 *   - a target that is a symbolic link is followed: the real file is
 *     replaced and the link stays (PDT_SAFE_NOFOLLOW: files inside a folder
 *     pdt owns, such as frames, replace a planted link instead of writing
 *     through it);
 *   - a target with other hard links is written in place once the whole
 *     temporary is complete and the space for it is reserved, so every name
 *     sees the new content (a crash during that copy can leave it mixed:
 *     the one case that is not atomic, docs/files.md);
 *   - the temporary takes the target's place (rename) only when everything
 *     succeeded; otherwise it is removed and the target is untouched.
 * Files that must change together (an .ele and its .node) are committed as
 * a group: all temporaries complete, then all exchanged, and the exchanges
 * undone if one fails.  A run folder is written whole under a temporary
 * folder beside it and swapped in at the end. */
#ifndef PDT_SAFEFILE_H
#define PDT_SAFEFILE_H

#include "pdt/common.h"

/* Flags of pdt_safe_open. */
enum {
    PDT_SAFE_DIRECT = 1,    /* a device or a pipe (/dev/null, a fifo) is written
                             * directly instead of refused */
    PDT_SAFE_NOFOLLOW = 2   /* a symlink at the target is replaced, not followed;
                             * hard links are not written in place */
};

/* One file being replaced. */
typedef struct pdt_safe_file {
    int fd;          /* write here (read-write); -1 once closed */
    char *name;      /* the caller's name for it (messages) */
    char *target;    /* the file replaced (symlinks followed) */
    char *tmp;       /* the temporary beside target; NULL: written directly */
    int in_place;    /* target has other hard links: copied into it at commit */
    int exists;      /* target existed at open */
    int swapped;     /* (group commit) exchanged with the target */
} pdt_safe_file;

/* Open `path` for replacing (flags: PDT_SAFE_*).  On success f->fd is the
 * temporary (or the device).  Refused (PDT_ERR_IO, message naming path): a
 * folder, a read-only file, a folder we cannot write, a device or pipe
 * without PDT_SAFE_DIRECT. */
pdt_status pdt_safe_open(pdt_safe_file *f, const char *path, int flags, pdt_err *err);
/* Close f->fd (unless the caller already did and set it to -1), then put
 * the temporary in the target's place.  On failure the temporary is removed
 * and the target is as it was.  Frees f's names either way. */
pdt_status pdt_safe_commit(pdt_safe_file *f, pdt_err *err);
/* Commit n files together: every one is replaced, or none (an exchange
 * that fails undoes the ones before it). */
pdt_status pdt_safe_commit_group(pdt_safe_file *f, int n, pdt_err *err);
/* Close and remove the temporary; the target is untouched. */
void pdt_safe_abort(pdt_safe_file *f);

/* ---- run folders ---------------------------------------------------------------- */

/* A folder written whole: everything goes into d->tmp (a folder this
 * process created beside the target, so nothing planted in the user's
 * folder is followed), then swapped in. */
typedef struct pdt_safe_dir {
    char *name;    /* the caller's name (messages) */
    char *target;  /* the folder replaced (a symlink to a folder is followed) */
    char *tmp;     /* write here */
    int exists;    /* target existed at open */
    int swapped;   /* the new folder is in place (pdt_safe_dir_swap) */
} pdt_safe_dir;

/* Check `dir` and create the temporary folder beside it.  Refused: a
 * target that is not a folder, one holding files that are not a run
 * folder's (they would be lost), a folder we cannot write. */
pdt_status pdt_safe_dir_open(pdt_safe_dir *d, const char *dir, pdt_err *err);
/* Swap the temporary folder in (an exchange when the target exists; the old
 * folder is then removed), frees d's names. */
pdt_status pdt_safe_dir_commit(pdt_safe_dir *d, pdt_err *err);
/* Remove the temporary folder and what was written in it. */
void pdt_safe_dir_abort(pdt_safe_dir *d);
/* The commit in two steps, for a folder that goes in place with other files
 * (a traced run's output): swap the new folder in, keeping the old one under
 * the temporary name; then finish: keep (remove the old folder) or not (the
 * old folder back, the new one removed).  Frees d's names. */
pdt_status pdt_safe_dir_swap(pdt_safe_dir *d, pdt_err *err);
void pdt_safe_dir_finish(pdt_safe_dir *d, int keep);

/* 1 if `name` (a file name without folder) is one a run folder holds:
 * manifest, points.bin, rank-NNNN.trace, the kept index, pdt's temporaries. */
int pdt_safe_run_name(const char *name);

/* ---- an input is never an output -------------------------------------------------- */

/* 1 if `a` and `b` name the same existing file (symlinks followed). */
int pdt_safe_same_file(const char *a, const char *b);
/* 1 if `path` (existing or not) is `dir` or lies inside it (symlinks of
 * both followed). */
int pdt_safe_inside(const char *path, const char *dir);
/* 1 if writing `path` would replace a file of run folder `rundir`: it names
 * one of the run's files there, or is the same file as one of them. */
int pdt_safe_touches_run(const char *path, const char *rundir);

#endif
