/* ref_real.h -- the number type of the tests' high-precision references.
 *
 * The tests check the library (double) against references computed with
 * more precision than double.  `long double` is not a safe choice for that:
 * on x86-64 it is the x87 80-bit format (64-bit significand, only 11 bits
 * more than double), on other targets it is plain double, and valgrind
 * computes it in double precision, so a long-double reference silently
 * stops being one under memcheck.  Where the compiler offers IEEE binary128
 * (GCC's __float128 with libquadmath: 113-bit significand, computed in
 * software that valgrind runs exactly), the references use it; elsewhere
 * they fall back to long double (the build prints which).
 *
 * Use ref_real / ref_complex for reference quantities, REF(1.5) for
 * literals that need full precision, the ref_* functions below for
 * elementary functions, and (double) casts to print.
 *
 * This header does not include <complex.h>: its macro I would clash with
 * the many variables named I (intensities) in the tests.  A test that
 * uses ref_complex and the complex ref_* functions includes <complex.h>
 * itself. */
#ifndef LP_TEST_REF_REAL_H
#define LP_TEST_REF_REAL_H

#include <float.h>
#include <math.h>

#if defined(LP_TEST_QUAD) && LP_TEST_QUAD
#include <quadmath.h>

typedef __float128 ref_real;
typedef __complex128 ref_complex;
#define REF(x) x##Q
#define REF_EPSILON FLT128_EPSILON
#define REF_NAME "binary128 (__float128)"
#define ref_sqrt sqrtq
#define ref_cbrt cbrtq
#define ref_fabs fabsq
#define ref_sin sinq
#define ref_cos cosq
#define ref_tan tanq
#define ref_asin asinq
#define ref_acos acosq
#define ref_atan atanq
#define ref_atan2 atan2q
#define ref_pow powq
#define ref_exp expq
#define ref_log logq
#define ref_hypot hypotq
#define ref_fmax fmaxq
#define ref_fmin fminq
#define ref_copysign copysignq
#define ref_cabs cabsq
#define ref_creal crealq
#define ref_cimag cimagq
#define ref_conj conjq
#define ref_cexp cexpq
#define ref_carg cargq
#define ref_csqrt csqrtq

#else

typedef long double ref_real;
typedef long double _Complex ref_complex;
#define REF(x) x##L
#define REF_EPSILON LDBL_EPSILON
#define REF_NAME "long double"
#define ref_sqrt sqrtl
#define ref_cbrt cbrtl
#define ref_fabs fabsl
#define ref_sin sinl
#define ref_cos cosl
#define ref_tan tanl
#define ref_asin asinl
#define ref_acos acosl
#define ref_atan atanl
#define ref_atan2 atan2l
#define ref_pow powl
#define ref_exp expl
#define ref_log logl
#define ref_hypot hypotl
#define ref_fmax fmaxl
#define ref_fmin fminl
#define ref_copysign copysignl
#define ref_cabs cabsl
#define ref_creal creall
#define ref_cimag cimagl
#define ref_conj conjl
#define ref_cexp cexpl
#define ref_carg cargl
#define ref_csqrt csqrtl

#endif

/* pi to binary128 precision (36 digits) */
#define REF_PI REF(3.14159265358979323846264338327950288)

/* The real roots of A s^2 + 2 B s + C = 0 in the stable form (q = -(B +
 * sign(B) sqrt(B^2 - AC)), roots q/A and C/q; the linear case when A = 0),
 * in no particular order; returns how many (0, 1 or 2). */
static inline int ref_quad_roots(ref_real A, ref_real B, ref_real C, ref_real r[2])
{
    if (A == REF(0.0)) {
        if (B == REF(0.0))
            return 0;
        r[0] = -C / (REF(2.0) * B);
        return 1;
    }
    ref_real disc = B * B - A * C;
    if (disc < REF(0.0))
        return 0;
    ref_real q = -(B + ref_copysign(ref_sqrt(disc), B));
    if (q == REF(0.0)) {
        r[0] = REF(0.0);
        return 1;
    }
    r[0] = q / A;
    r[1] = C / q;
    return 2;
}

#endif /* LP_TEST_REF_REAL_H */
