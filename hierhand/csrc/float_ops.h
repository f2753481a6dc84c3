/* Python's float max, min and modulo in C.
 *
 * The controllers' C laws were written to follow numpy formulations operation by
 * operation (the tests' oracles, tests/hierhand/control/oracles.py), so that they give
 * the same numbers bit for bit where libm does. Where those use Python's builtins, these
 * functions do what the builtins do, NaN and signed zeros included: max(a, b) keeps a
 * unless b > a, min(a, b) keeps a unless b < a, and x % y has the sign of y
 * (CPython's float_rem, which numba and numpy.mod copy).
 */
#ifndef HIERHAND_FLOAT_OPS_H
#define HIERHAND_FLOAT_OPS_H

#include <math.h>

/* Python's max(a, b) for floats. */
static inline double hh_max(double a, double b)
{
    return b > a ? b : a;
}

/* Python's min(a, b) for floats. */
static inline double hh_min(double a, double b)
{
    return b < a ? b : a;
}

/* Python's x % y for floats (y != 0): the remainder of the floored division. */
static inline double hh_floored_mod(double x, double y)
{
    double mod = fmod(x, y);
    if (mod != 0.0) {
        if ((y < 0.0) != (mod < 0.0))
            mod += y;
    } else {
        mod = copysign(0.0, y);
    }
    return mod;
}

#endif
