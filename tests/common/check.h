/* check.h -- the test suite's tiny assertion kit.
 *
 * Every comparison states its tolerance; the worst relative (or absolute)
 * error seen by each test program is printed at the end, so the accuracy
 * of each physics check is on record in the ctest log.  Expected values
 * come from closed-form physics written in the test, never from the code
 * under test.
 *
 *   CHECK(cond, fmt, ...)                    a property
 *   CHECK_REL(got, want, tol, fmt, ...)      |got-want| <= tol*|want|
 *   CHECK_ABS(got, want, tol, fmt, ...)      |got-want| <= tol
 *   return check_finish("name");             prints the summary, exit code
 */
#ifndef LP_TEST_CHECK_H
#define LP_TEST_CHECK_H

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

static int check__failures;
static long check__count;
static double check__worst_rel;
static char check__worst_rel_what[512];
static double check__worst_abs;
static char check__worst_abs_what[512];

static void check__report(const char *file, int line, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "%s:%d: FAILED: ", file, line);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

#define CHECK(cond, ...)                                                      \
    do {                                                                      \
        check__count++;                                                       \
        if (!(cond)) {                                                        \
            check__failures++;                                                \
            check__report(__FILE__, __LINE__, __VA_ARGS__);                   \
        }                                                                     \
    } while (0)

static inline int check__rel(double got, double want, double tol, const char *what)
{
    double e = fabs(got - want) / (want != 0.0 ? fabs(want) : 1.0);
    check__count++;
    if (!(e <= tol) || !isfinite(got)) {
        check__failures++;
        return 0;
    }
    if (e > check__worst_rel) {
        check__worst_rel = e;
        snprintf(check__worst_rel_what, sizeof check__worst_rel_what, "%s", what);
    }
    return 1;
}

static inline int check__abs(double got, double want, double tol, const char *what)
{
    double e = fabs(got - want);
    check__count++;
    if (!(e <= tol) || !isfinite(got)) {
        check__failures++;
        return 0;
    }
    if (e > check__worst_abs) {
        check__worst_abs = e;
        snprintf(check__worst_abs_what, sizeof check__worst_abs_what, "%s", what);
    }
    return 1;
}

#define CHECK_REL(got, want, tol, ...)                                        \
    do {                                                                      \
        char check__w[512];                                                   \
        double check__g = (got), check__x = (want);                           \
        snprintf(check__w, sizeof check__w, __VA_ARGS__);                     \
        if (!check__rel(check__g, check__x, (tol), check__w))                 \
            check__report(__FILE__, __LINE__, "%s: got %.17g want %.17g (rel tol %g)", \
                          check__w, check__g, check__x, (double)(tol));       \
    } while (0)

#define CHECK_ABS(got, want, tol, ...)                                        \
    do {                                                                      \
        char check__w[512];                                                   \
        double check__g = (got), check__x = (want);                           \
        snprintf(check__w, sizeof check__w, __VA_ARGS__);                     \
        if (!check__abs(check__g, check__x, (tol), check__w))                 \
            check__report(__FILE__, __LINE__, "%s: got %.17g want %.17g (abs tol %g)", \
                          check__w, check__g, check__x, (double)(tol));       \
    } while (0)

static int check_finish(const char *name)
{
    printf("%s: %ld checks, %d failed\n", name, check__count, check__failures);
    if (check__worst_rel > 0.0)
        printf("%s: worst relative error %.3g (%s)\n", name, check__worst_rel,
               check__worst_rel_what);
    if (check__worst_abs > 0.0)
        printf("%s: worst absolute error %.3g (%s)\n", name, check__worst_abs,
               check__worst_abs_what);
    if (check__count == 0) {
        printf("%s: no checks ran\n", name);
        return 1;
    }
    return check__failures ? 1 : 0;
}

#endif
