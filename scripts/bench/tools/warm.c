/* build/bench/warm MB: touch MB megabytes of new memory on every CPU, then
 * give them back: the memory state the benchmarks' MEMSTATE=warm asks for
 * before each timed run (scripts/bench/tools/memstate.sh).
 *
 * On this project's VMs the guest hands memory it has not used for about
 * 2 s back to the host (virtio-balloon free page reporting); touching such
 * memory again costs about 1.25 s per GiB (400 MB: 0.50 s), against 0.02 s
 * for memory freed a moment before.  A run then pays for what the machine
 * did in the seconds before it, not for its own work.  Run just before a
 * timed command, this program leaves MB of backed free memory for it, the
 * state every machine without such reporting is always in. */
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <unistd.h>

enum { STEP = 2 << 20 };

static char *base;
static size_t total;
static atomic_size_t next;

static void *touch(void *arg)
{
    (void)arg;
    for (;;) {
        size_t at = atomic_fetch_add(&next, (size_t)STEP);
        if (at >= total) return NULL;
        size_t len = total - at < STEP ? total - at : STEP;
        for (size_t i = 0; i < len; i += 4096) base[at + i] = 1;
    }
}

int main(int argc, char **argv)
{
    char *end;
    long mb = argc == 2 ? strtol(argv[1], &end, 10) : -1;
    if (argc != 2 || *end || mb < 1) {
        fprintf(stderr, "usage: warm MB\n");
        return 2;
    }
    total = (size_t)mb << 20;
    base = mmap(NULL, total, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (base == MAP_FAILED) {
        perror("warm: mmap");
        return 1;
    }
    madvise(base, total, MADV_HUGEPAGE);
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    if (cpus < 1) cpus = 1;
    if (cpus > 64) cpus = 64;
    pthread_t th[64];
    long started = 0;
    for (long i = 1; i < cpus; i++)
        if (pthread_create(&th[started], NULL, touch, NULL) == 0) started++;
    touch(NULL);
    for (long i = 0; i < started; i++) pthread_join(th[i], NULL);
    munmap(base, total);
    return 0;
}
