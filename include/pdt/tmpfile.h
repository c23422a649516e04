/* pdt — temporary files (src/base/tmpfile.c): anonymous scratch files in
 * $TMPDIR (else /tmp), for external sorts, spills and memory the kernel
 * may page to disk. */
#ifndef PDT_TMPFILE_H
#define PDT_TMPFILE_H

#include <stddef.h>
#include <stdio.h>

/* The folder temporary files go to: $TMPDIR when set and not empty, else
 * /tmp (for messages that name it). */
const char *pdt_tmp_dir(void);

/* A new anonymous temporary file in pdt_tmp_dir(), open for reading and
 * writing, close-on-exec, and without a name (O_TMPFILE; on a file system
 * without it, a file named PREFIX.XXXXXX unlinked at once), so nothing is
 * left behind even when the process is killed.  A descriptor, or -1 with
 * errno set. */
int pdt_tmp_fd(const char *prefix);

/* The same as a stdio stream ("w+b") with a buffer of `buffer` bytes (0:
 * stdio's own), or NULL with errno set. */
FILE *pdt_tmp_file(const char *prefix, size_t buffer);

#endif
