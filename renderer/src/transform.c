/* transform.c -- affine transforms with POV-Ray's meaning.
 *
 * An rs_transform maps object space to world space, x_world = m x + t, and
 * keeps its exact inverse alongside, built from the inverses of the
 * elementary steps (never by numerical inversion).
 *
 * POV-Ray multiplies row vectors from the left (p' = p M); written for
 * column vectors as here, its elementary matrices are
 *
 *   rotate <a,0,0>:  y' = y cos a - z sin a,  z' = y sin a + z cos a
 *   rotate <0,b,0>:  x' = x cos b + z sin b,  z' = -x sin b + z cos b
 *   rotate <0,0,c>:  x' = x cos c - y sin c,  y' = x sin c + y cos c
 *
 * and rotate <a,b,c> is the x rotation, then the y one, then the z one.
 * In POV-Ray's left-handed frame (x right, y up, z into the screen) these
 * turn by the left-hand rule: rotate <0,90,0> takes +x to -z and +z to +x;
 * rotate <90,0,0> takes +y to +z; rotate <0,0,90> takes +x to +y.
 *
 * rs_transform_translate/rotate/scale APPEND a step, as a keyword in a
 * scene does: the new step applies after the ones already in xf.  On
 * failure (a zero scale component, a non-finite value) xf is unchanged.
 */
#include <math.h>
#include <string.h>

#include "scene.h"
#include "support/vec.h"

static void mat_identity(double m[3][3])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            m[i][j] = (i == j) ? 1.0 : 0.0;
}

/* out = a * b (out may alias neither). */
static void mat_mul(const double a[3][3], const double b[3][3], double out[3][3])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
}

static void mat_apply(const double m[3][3], const double v[3], double out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
}

static lp_vec3 vec_of(const double v[3])
{
    lp_vec3 r = { v[0], v[1], v[2] };
    return r;
}

void rs_transform_identity(rs_transform *xf)
{
    mat_identity(xf->m);
    mat_identity(xf->inv_m);
    for (int i = 0; i < 3; i++)
        xf->t[i] = xf->inv_t[i] = 0.0;
}

lp_vec3 rs_xf_point(const rs_transform *xf, lp_vec3 p)
{
    double v[3] = { p.x, p.y, p.z }, r[3];
    mat_apply(xf->m, v, r);
    for (int i = 0; i < 3; i++)
        r[i] += xf->t[i];
    return vec_of(r);
}

lp_vec3 rs_xf_dir(const rs_transform *xf, lp_vec3 d)
{
    double v[3] = { d.x, d.y, d.z }, r[3];
    mat_apply(xf->m, v, r);
    return vec_of(r);
}

/* The inverse transpose of m times n; not normalized. */
lp_vec3 rs_xf_normal(const rs_transform *xf, lp_vec3 n)
{
    double v[3] = { n.x, n.y, n.z }, r[3];
    for (int i = 0; i < 3; i++)
        r[i] = xf->inv_m[0][i] * v[0] + xf->inv_m[1][i] * v[1] + xf->inv_m[2][i] * v[2];
    return vec_of(r);
}

lp_vec3 rs_xf_inv_point(const rs_transform *xf, lp_vec3 p)
{
    double v[3] = { p.x, p.y, p.z }, r[3];
    mat_apply(xf->inv_m, v, r);
    for (int i = 0; i < 3; i++)
        r[i] += xf->inv_t[i];
    return vec_of(r);
}

lp_vec3 rs_xf_inv_dir(const rs_transform *xf, lp_vec3 d)
{
    double v[3] = { d.x, d.y, d.z }, r[3];
    mat_apply(xf->inv_m, v, r);
    return vec_of(r);
}

/* out: x -> b(a(x)).  Forward: m = mb ma, t = mb ta + tb.
 * Inverse: x = a^-1(b^-1(w)): inv_m = ia ib, inv_t = ia itb + ita. */
void rs_transform_compose(const rs_transform *a, const rs_transform *b, rs_transform *out)
{
    rs_transform r;
    double tmp[3];
    mat_mul(b->m, a->m, r.m);
    mat_apply(b->m, a->t, tmp);
    for (int i = 0; i < 3; i++)
        r.t[i] = tmp[i] + b->t[i];
    mat_mul(a->inv_m, b->inv_m, r.inv_m);
    mat_apply(a->inv_m, b->inv_t, tmp);
    for (int i = 0; i < 3; i++)
        r.inv_t[i] = tmp[i] + a->inv_t[i];
    *out = r; /* a, b and out may alias */
}

int rs_transform_finite(const rs_transform *xf)
{
    for (int i = 0; i < 3; i++) {
        if (!isfinite(xf->t[i]) || !isfinite(xf->inv_t[i]))
            return 0;
        for (int j = 0; j < 3; j++)
            if (!isfinite(xf->m[i][j]) || !isfinite(xf->inv_m[i][j]))
                return 0;
    }
    return 1;
}

int rs_transform_translate(rs_transform *xf, lp_vec3 v)
{
    rs_transform s;
    if (!v3_finite(v))
        return 0;
    rs_transform_identity(&s);
    s.t[0] = v.x;
    s.t[1] = v.y;
    s.t[2] = v.z;
    s.inv_t[0] = -v.x;
    s.inv_t[1] = -v.y;
    s.inv_t[2] = -v.z;
    rs_transform_compose(xf, &s, xf);
    return 1;
}

/* sin and cos of an angle in degrees, exact at multiples of 90 degrees so
 * that rotate <0,90,0> is an exact permutation. */
static void sincos_deg(double deg, double *s, double *c)
{
    double r = fmod(deg, 360.0); /* exact */
    if (r < 0.0)
        r += 360.0;
    if (r == 0.0) {
        *s = 0.0; *c = 1.0;
    } else if (r == 90.0) {
        *s = 1.0; *c = 0.0;
    } else if (r == 180.0) {
        *s = 0.0; *c = -1.0;
    } else if (r == 270.0) {
        *s = -1.0; *c = 0.0;
    } else {
        double a = r * (3.14159265358979323846 / 180.0);
        *s = sin(a);
        *c = cos(a);
    }
}

int rs_transform_rotate(rs_transform *xf, lp_vec3 degrees)
{
    double sx, cx, sy, cy, sz, cz;
    double rx[3][3], ry[3][3], rz[3][3], tmp[3][3];
    rs_transform s;

    if (!v3_finite(degrees))
        return 0;
    sincos_deg(degrees.x, &sx, &cx);
    sincos_deg(degrees.y, &sy, &cy);
    sincos_deg(degrees.z, &sz, &cz);

    mat_identity(rx);
    rx[1][1] = cx; rx[1][2] = -sx;
    rx[2][1] = sx; rx[2][2] = cx;
    mat_identity(ry);
    ry[0][0] = cy; ry[0][2] = sy;
    ry[2][0] = -sy; ry[2][2] = cy;
    mat_identity(rz);
    rz[0][0] = cz; rz[0][1] = -sz;
    rz[1][0] = sz; rz[1][1] = cz;

    rs_transform_identity(&s);
    /* (the casts only add const, for pre-C23 array qualification rules) */
    mat_mul((const double (*)[3])ry, (const double (*)[3])rx, tmp); /* x, then y */
    mat_mul((const double (*)[3])rz, (const double (*)[3])tmp, s.m); /* then z */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            s.inv_m[i][j] = s.m[j][i]; /* orthogonal */
    rs_transform_compose(xf, &s, xf);
    return 1;
}

int rs_transform_scale(rs_transform *xf, lp_vec3 v)
{
    rs_transform s;
    if (!v3_finite(v) || v.x == 0.0 || v.y == 0.0 || v.z == 0.0)
        return 0;
    rs_transform_identity(&s);
    s.m[0][0] = v.x;
    s.m[1][1] = v.y;
    s.m[2][2] = v.z;
    s.inv_m[0][0] = 1.0 / v.x;
    s.inv_m[1][1] = 1.0 / v.y;
    s.inv_m[2][2] = 1.0 / v.z;
    if (!isfinite(s.inv_m[0][0]) || !isfinite(s.inv_m[1][1]) || !isfinite(s.inv_m[2][2]))
        return 0; /* subnormal scale: its inverse overflows */
    rs_transform_compose(xf, &s, xf);
    return 1;
}
