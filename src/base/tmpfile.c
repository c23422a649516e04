/* pdt — anonymous temporary files in $TMPDIR (else /tmp). */
#include "pdt/tmpfile.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

const char *pdt_tmp_dir(void)
{
    const char *dir = getenv("TMPDIR");
    return dir && *dir ? dir : "/tmp";
}

int pdt_tmp_fd(const char *prefix)
{
    const char *dir = pdt_tmp_dir();
    int fd = open(dir, O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
    if (fd >= 0) return fd;
    /* a file system without O_TMPFILE: a named file, unlinked */
    char path[4096];
    if (snprintf(path, sizeof path, "%s/%s.XXXXXX", dir, prefix) >= (int)sizeof path) {
        errno = ENAMETOOLONG;
        return -1;
    }
    if ((fd = mkostemp(path, O_CLOEXEC)) < 0) return -1;
    unlink(path);
    return fd;
}

FILE *pdt_tmp_file(const char *prefix, size_t buffer)
{
    int fd = pdt_tmp_fd(prefix);
    if (fd < 0) return NULL;
    FILE *f = fdopen(fd, "w+b");
    if (!f) {
        int e = errno;
        close(fd);
        errno = e;
        return NULL;
    }
    if (buffer) setvbuf(f, NULL, _IOFBF, buffer);  /* (before any other operation on it) */
    return f;
}

/* One call a step of at most 1 GiB (what Linux moves in one call at most). */
#define IO_STEP ((size_t)1 << 30)

int pdt_pwrite_all(int fd, const void *p, size_t len, uint64_t off)
{
    const char *b = p;
    while (len) {
        ssize_t k = pwrite(fd, b, len < IO_STEP ? len : IO_STEP, (off_t)off);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) return k == 0 ? (errno = EIO, 0) : 0;
        b += k;
        len -= (size_t)k;
        off += (uint64_t)k;
    }
    return 1;
}

int pdt_pread_all(int fd, uint64_t off, void *p, size_t len)
{
    char *b = p;
    while (len) {
        ssize_t k = pread(fd, b, len < IO_STEP ? len : IO_STEP, (off_t)off);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) return k == 0 ? (errno = EIO, 0) : 0;
        b += k;
        len -= (size_t)k;
        off += (uint64_t)k;
    }
    return 1;
}
