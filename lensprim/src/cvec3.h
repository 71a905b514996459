/* cvec3.h -- complex 3-vectors for electric fields (internal). */
#ifndef LP_CVEC3_H
#define LP_CVEC3_H

#include <complex.h>
#include "vec3.h"

typedef struct lp__cvec3 {
    double complex x, y, z;
} lp__cvec3;

static inline lp__cvec3 cv3_real(lp_vec3 a, double s)
{
    lp__cvec3 r = {a.x * s, a.y * s, a.z * s};
    return r;
}
/* a*u + b*w for complex a, b and real vectors u, w */
static inline lp__cvec3 cv3_combine(double complex a, lp_vec3 u, double complex b, lp_vec3 w)
{
    lp__cvec3 r = {a * u.x + b * w.x, a * u.y + b * w.y, a * u.z + b * w.z};
    return r;
}
/* E . u (no conjugation: projection of a complex field on a real axis) */
static inline double complex cv3_dot_real(lp__cvec3 e, lp_vec3 u)
{
    return e.x * u.x + e.y * u.y + e.z * u.z;
}
static inline lp__cvec3 cv3_scale(lp__cvec3 e, double complex s)
{
    lp__cvec3 r = {e.x * s, e.y * s, e.z * s};
    return r;
}
static inline lp__cvec3 cv3_scale_real(lp__cvec3 e, double s)
{
    lp__cvec3 r = {e.x * s, e.y * s, e.z * s};
    return r;
}
/* |E|^2 = power carried */
static inline double cv3_norm2(lp__cvec3 e)
{
    return creal(e.x) * creal(e.x) + cimag(e.x) * cimag(e.x) + creal(e.y) * creal(e.y) +
           cimag(e.y) * cimag(e.y) + creal(e.z) * creal(e.z) + cimag(e.z) * cimag(e.z);
}
/* 1 when every component is real (no imaginary part at all). */
static inline int cv3_is_real(lp__cvec3 e)
{
    return cimag(e.x) == 0.0 && cimag(e.y) == 0.0 && cimag(e.z) == 0.0;
}
static inline lp_vec3 cv3_re(lp__cvec3 e) { return v3(creal(e.x), creal(e.y), creal(e.z)); }
static inline lp_vec3 cv3_im(lp__cvec3 e) { return v3(cimag(e.x), cimag(e.y), cimag(e.z)); }

#endif
