/* near.h - assert_near(a, b, tol) for the cmocka suites: fails the test,
 * naming the expression, its value and the expected one, unless |a - b| <=
 * tol (a NaN fails). Include after <cmocka.h>. */
#ifndef NEAR_H
#define NEAR_H

#include <math.h>

#define assert_near(a, b, tol) \
    near_check((double)(a), (double)(b), (double)(tol), #a, __FILE__, __LINE__)

static inline void near_check(double a, double b, double tol, const char *what,
                              const char *file, int line)
{
    if (!(fabs(a - b) <= tol))
        fail_msg("%s:%d: %s = %.9g, expected %.9g +- %.3g", file, line, what, a, b, tol);
}

#endif /* NEAR_H */
