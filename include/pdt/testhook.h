/* pdt — test fault injection (src/base/testhook.c).
 *
 * pdt_test_hook("PDT_TEST_NAME") is the value of that environment variable
 * in a test build (one that links src/base/testhook.c compiled with
 * -DPDT_TEST_HOOKS: the sanitizer build, bin/test/pdt and the unit tests),
 * and NULL in a production build, which therefore never reads them.  Every
 * fault a test injects goes through it. */
#ifndef PDT_TESTHOOK_H
#define PDT_TESTHOOK_H

const char *pdt_test_hook(const char *name);

#endif
