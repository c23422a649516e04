/* pdt — a tiny test harness for the unit-test programs in tests/unit.
 *
 *   TEST(grid_cocircular) { CHECK(x == 1); CHECK_MSG(y > 0, "y=%d", y); }
 *   int main(void) { RUN(grid_cocircular); return test_summary(); }
 *
 * Each test case prints "ok - NAME" or "not ok - NAME" with the failed checks;
 * tests/run.sh counts these lines. */
#ifndef PDT_TEST_HARNESS_H
#define PDT_TEST_HARNESS_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

/* One step of the xorshift64 generator the tests draw their random inputs
 * from (each test program keeps its own state, seeded its own way). */
static inline uint64_t th_xorshift(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

static int th_failed_checks;  /* in the current test case */
static int th_cases_passed, th_cases_failed;

#define TEST(name) static void test_##name(void)

#define CHECK_MSG(cond, ...)                                                       \
    do {                                                                           \
        if (!(cond)) {                                                             \
            th_failed_checks++;                                                    \
            if (th_failed_checks <= 5) {                                           \
                fprintf(stdout, "#   %s:%d: check failed: %s: ", __FILE__, __LINE__, #cond); \
                fprintf(stdout, __VA_ARGS__);                                      \
                fputc('\n', stdout);                                               \
            }                                                                      \
        }                                                                          \
    } while (0)

#define CHECK(cond) CHECK_MSG(cond, "%s", "")

#define RUN(name)                                                                  \
    do {                                                                           \
        th_failed_checks = 0;                                                      \
        test_##name();                                                             \
        if (th_failed_checks) {                                                    \
            th_cases_failed++;                                                     \
            printf("not ok - %s (%d failed checks)\n", #name, th_failed_checks);  \
        } else {                                                                   \
            th_cases_passed++;                                                     \
            printf("ok - %s\n", #name);                                            \
        }                                                                          \
        fflush(stdout);                                                            \
    } while (0)

static inline int test_summary(void)
{
    printf("# %d passed, %d failed\n", th_cases_passed, th_cases_failed);
    return th_cases_failed ? 1 : 0;
}

#endif
