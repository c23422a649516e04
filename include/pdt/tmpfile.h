/* pdt — temporary files (src/base/tmpfile.c): anonymous scratch files in
 * $TMPDIR (else /tmp), for external sorts, spills and memory the kernel
 * may page to disk; and whole reads and writes at an offset. */
#ifndef PDT_TMPFILE_H
#define PDT_TMPFILE_H

#include <stddef.h>
#include <stdint.h>
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

/* pwrite and pread of all `len` bytes at offset `off`, in as many calls as
 * the system takes (an interrupted one made again): 1, or 0 with errno set
 * (EIO when a call makes no progress). */
int pdt_pwrite_all(int fd, const void *p, size_t len, uint64_t off);
int pdt_pread_all(int fd, uint64_t off, void *p, size_t len);

#endif
