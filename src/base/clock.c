/* pdt — the clock every phase timing reads (common.h). */
#include <time.h>

#include "pdt/common.h"

double pdt_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
