/* pdt — test fault injection: the environment in a test build, nothing in a
 * production one (see include/pdt/testhook.h).  Only this one function in
 * this file: a test program links its hooked object ahead of libpdt.a, so
 * the archive's copy is never pulled in beside it. */
#include <stdlib.h>

#include "pdt/testhook.h"

const char *pdt_test_hook(const char *name)
{
#ifdef PDT_TEST_HOOKS
    return getenv(name);
#else
    (void)name;
    return NULL;
#endif
}
