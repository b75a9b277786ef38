/* binary64.c - the few double operations of the API's boundary (the
 * frame's origin off a pose and back on a vertex, a double narrowed to
 * float, a float widened), done on the doubles' bits with integers and
 * rounded to nearest, ties to even, as IEEE 754 rounds them: the same bits
 * as an FPU's, and no software double routine on a chip whose FPU is
 * single precision (a call of 30-100 instructions each, and the
 * routines' flash). Takes and gives: doubles and floats. NaN in gives a
 * quiet NaN out (its payload is not kept: no caller passes one). */
#include "internal.h"

#include <string.h>

#define SIGN64 (UINT64_C(1) << 63)
#define FRAC64 ((UINT64_C(1) << 52) - 1)
#define EXP64_MAX 0x7ffu
#define QUIET_NAN64 (UINT64_C(0x7ff8) << 48)

/* Both finite. With three bits below the last place (guard, round and a
 * sticky bit for everything shifted out) the sum rounds as if exact. */
static uint64_t add_finite(uint64_t ua, uint64_t ub)
{
    if ((ua & ~SIGN64) < (ub & ~SIGN64)) { /* |a| >= |b| */
        uint64_t t = ua;
        ua = ub;
        ub = t;
    }
    uint64_t sign = ua & SIGN64;
    int32_t ea = (int32_t)((ua >> 52) & EXP64_MAX), eb = (int32_t)((ub >> 52) & EXP64_MAX);
    uint64_t ma = (ua & FRAC64) | (ea ? UINT64_C(1) << 52 : 0);
    uint64_t mb = (ub & FRAC64) | (eb ? UINT64_C(1) << 52 : 0);
    ea = ea ? ea : 1; /* subnormals: the smallest exponent, no hidden bit */
    eb = eb ? eb : 1;
    ma <<= 3;
    mb <<= 3;
    int32_t d = ea - eb;
    if (d >= 58)
        mb = mb != 0;
    else if (d > 0)
        mb = (mb >> d) | ((mb & ((UINT64_C(1) << d) - 1)) != 0);
    uint64_t m;
    int32_t e = ea;
    if ((ua ^ ub) & SIGN64) {
        m = ma - mb;
        if (m == 0)
            return 0; /* x - x is +0 when rounding to nearest */
        while (m < (UINT64_C(1) << 55) && e > 1) {
            m <<= 1;
            e--;
        }
    } else {
        m = ma + mb;
        if (m >= (UINT64_C(1) << 56)) {
            m = (m >> 1) | (m & 1);
            e++;
        }
    }
    unsigned low = (unsigned)(m & 7);
    m >>= 3;
    if (low > 4 || (low == 4 && (m & 1)))
        m++;
    /* m is below 2^52 only for a subnormal (e == 1): the exponent field
     * then comes out 0; a carry of the rounding into 2^53 lifts it */
    uint64_t u = ((uint64_t)(e - 1) << 52) + m;
    if (((u >> 52) & EXP64_MAX) == EXP64_MAX || e > (int32_t)EXP64_MAX)
        u = (uint64_t)EXP64_MAX << 52; /* too large: infinity */
    return sign | u;
}

double polyc__d_add(double a, double b)
{
    uint64_t ua = polyc__bits64(a), ub = polyc__bits64(b);
    int a_special = ((ua >> 52) & EXP64_MAX) == EXP64_MAX, b_special = ((ub >> 52) & EXP64_MAX) == EXP64_MAX;
    if (!a_special && !b_special)
        return polyc__double_of(add_finite(ua, ub));
    if ((a_special && (ua & FRAC64)) || (b_special && (ub & FRAC64)))
        return polyc__double_of(QUIET_NAN64); /* NaN */
    if (a_special && b_special && ((ua ^ ub) & SIGN64))
        return polyc__double_of(QUIET_NAN64); /* inf - inf */
    return a_special ? a : b;
}

double polyc__d_sub(double a, double b)
{
    return polyc__d_add(a, polyc__double_of(polyc__bits64(b) ^ SIGN64));
}

float polyc__d_to_f(double v)
{
    uint64_t u = polyc__bits64(v);
    uint32_t sign = (uint32_t)(u >> 32) & 0x80000000u;
    int32_t e = (int32_t)((u >> 52) & EXP64_MAX);
    uint64_t frac = u & FRAC64;
    if (e == (int32_t)EXP64_MAX)
        return polyc__float_of(sign | 0x7f800000u | (frac ? 0x00400000u : 0u));
    if (e == 0)
        return polyc__float_of(sign); /* a subnormal double is far below float's least */
    uint64_t m = frac | (UINT64_C(1) << 52);
    int32_t fe = e - 1023 + 127;   /* float's biased exponent */
    if (fe >= 0xff)
        return polyc__float_of(sign | 0x7f800000u);
    int k = 29 + (fe < 1 ? 1 - fe : 0); /* bits dropped (more for a subnormal float) */
    k = k > 60 ? 60 : k;
    uint64_t q = m >> k, rem = m & ((UINT64_C(1) << k) - 1), half = UINT64_C(1) << (k - 1);
    if (rem > half || (rem == half && (q & 1)))
        q++;
    /* as in add_finite: a subnormal's field comes out 0, a carry lifts it,
     * and a carry out of the largest float gives infinity */
    uint32_t f = fe < 1 ? (uint32_t)q : ((uint32_t)(fe - 1) << 23) + (uint32_t)q;
    return polyc__float_of(sign | f);
}

double polyc__f_to_d(float v)
{
    uint32_t u = polyc__bits32(v);
    uint64_t sign = (uint64_t)(u & 0x80000000u) << 32;
    int32_t e = (int32_t)((u >> 23) & 0xffu);
    uint64_t frac = u & 0x7fffffu;
    if (e == 0xff)
        return polyc__double_of(sign | ((uint64_t)EXP64_MAX << 52) | (frac << 29) | (frac ? QUIET_NAN64 : 0));
    if (e == 0) {
        if (frac == 0)
            return polyc__double_of(sign);
        e = 1; /* a subnormal float is a normal double: its top bit hidden */
        while (!(frac & 0x800000u)) {
            frac <<= 1;
            e--;
        }
        frac &= 0x7fffffu;
    }
    return polyc__double_of(sign | ((uint64_t)(e - 127 + 1023) << 52) | (frac << 29));
}
