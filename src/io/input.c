/* pdt — opening a user's file for reading (pdt_open_input in pdt/io.h).
 *
 * Every reader of point files, triangle files and run folders opens through
 * here.  The open itself must not block: open(2) of a FIFO waits for a
 * writer, forever if there is none, so the file is opened with O_NONBLOCK
 * and looked at (fstat of the open file, not of the name: no window in
 * which the name can change) before anything is read.  Only a regular file
 * is read: a FIFO, a socket or a device (/dev/zero, a terminal), directly
 * or through a symbolic link, is refused with a message that names it.
 * Standard input is the caller's business ("-" is never passed here). */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pdt/io.h"

const char *pdt_file_kind(unsigned mode)
{
    switch (mode & S_IFMT) {
    case S_IFREG: return "a regular file";
    case S_IFDIR: return "a folder";
    case S_IFIFO: return "a FIFO (named pipe)";
    case S_IFCHR: return "a character device";
    case S_IFBLK: return "a block device";
    case S_IFSOCK: return "a socket";
    case S_IFLNK: return "a symbolic link";
    default: return "not a file";
    }
}

int pdt_open_input(const char *path, char *why, size_t cap)
{
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) {
        int e = errno;
        snprintf(why, cap, "cannot open: %s", strerror(e));
        errno = e;
        return -1;
    }
    struct stat sb;
    if (fstat(fd, &sb) != 0) {
        int e = errno;
        close(fd);
        snprintf(why, cap, "cannot read: %s", strerror(e));
        errno = e;
        return -1;
    }
    if (!S_ISREG(sb.st_mode)) {
        close(fd);
        if (S_ISDIR(sb.st_mode)) {
            snprintf(why, cap, "is a directory");
            errno = EISDIR;
        } else {
            snprintf(why, cap, "is %s, not a regular file (pdt reads regular files only)",
                     pdt_file_kind((unsigned)sb.st_mode));
            errno = EINVAL;
        }
        return -1;
    }
    /* (a regular file never blocks; the flag goes so that nothing later
     * mistakes EAGAIN for an error of its own) */
    int fl = fcntl(fd, F_GETFL);
    if (fl >= 0) fcntl(fd, F_SETFL, fl & ~O_NONBLOCK);
    return fd;
}
