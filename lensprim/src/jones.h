/* jones.h -- the power form of a backward query: the light's 2 x 2 Jones
 * matrix along its way, built node by node as the view ray's chain is
 * walked (internal).
 *
 * Light answering the query of node k enters the lens there, runs back
 * along the view ray's chain -- reflecting inside at nodes k-1 .. 2 --
 * and refracts out at node 1 along the view ray (trace_backward.c).  Its
 * field arriving at node j, written on the light's s and p axes there
 * (s = d x n normalized, p = d x s, d the light's direction, n the
 * surface normal), y = (E.s, E.p), leaves as z = D_j y on the branch's
 * axes (s, ap = o x s, o the light's new direction), D_j = diag(rs, rp)
 * where it reflects and diag(ts, tp) where it refracts (fresnel.h:
 * power-normalized, complex under total internal reflection); on the
 * segment to node j-1 its amplitude falls by seg_att, and there it is
 * written on that node's axes again: y' = seg_att H z, H = [[s.s',
 * ap.s'], [s.p', ap.p']].  The Jones calculus of a ray path (R. A.
 * Chipman, W. S. T. Lam, G. Young, Polarized Light and Optical Systems,
 * 2018, ch. 9-10).
 *
 * The light's way is the view ray's chain walked backwards: at node j the
 * light arrives along -e_j (the view ray's direction leaving node j) and
 * leaves along -e_{j-1} (the one arriving), and its Fresnel factors are
 * the view ray's own there -- the same angle between the same media for a
 * reflection, and power-normalized amplitudes are the same both ways
 * through an interface (ts = 2 sqrt(n1 ci n2 ct) / (n1 ci + n2 ct) is
 * symmetric in the two sides).  So the matrix of the light's way from
 * node j to the exit,
 *     R_j = D_1 H_2 D_2 ... H_j D_j,   R_j = R_{j-1} H_j D_j,
 * grows by one product a node as the view ray's chain is walked, and the
 * query of node k has T = R_{k-1} H_E D_E (its entry E: the light
 * refracting in along -e_{k-1}), T = D_E at node 1 (the reflection off
 * the outside).  Its power form P = Re(T^H T) gives the power leaving of
 * light entering with field x across it (x on the entry's s, p axes):
 * x' P x.  Both builds take these steps -- trace_backward.c one node at a
 * time, backward_many.c in loops over wavelengths -- with the same
 * operations, so their forms are the same bits.  A node at normal
 * incidence (s undefined: |d x n|^2 <= 1e-18) leaves every form through
 * it undefined (ok 0). */
#ifndef LP_JONES_H
#define LP_JONES_H

#include <math.h>

#include "lanes.h"
#include "vec3.h"

/* A complex 2 x 2 matrix, real and imaginary parts row by row. */
typedef struct lp__cm2 {
    double r00, r01, r10, r11;
    double i00, i01, i10, i11;
} lp__cm2;

/* The light's axes at a node: its direction d, the surface normal n (any
 * side), its new direction o: s, p and ap; *ok 0 at normal incidence. */
LP__INLINE void lp__jones_axes(lp_vec3 d, lp_vec3 n, lp_vec3 o, lp_vec3 *s, lp_vec3 *p,
                               lp_vec3 *ap, double *ok)
{
    lp_vec3 c = v3_cross(d, n);
    double l2 = v3_dot(c, c);
    *ok = l2 > 1e-18 ? 1.0 : 0.0;
    *s = v3_scale(c, 1.0 / sqrt(l2 > 1e-18 ? l2 : 1.0));
    *p = v3_cross(d, *s);
    *ap = v3_cross(o, *s);
}

/* The factors of a reflection from n1 into n2 at incidence cosine ci
 * (rs, rp when tir is 0; complex under total internal reflection, as
 * fresnel.h's: rs = (a - iq)/(a + iq), a = n1 ci, rp = (b - i n1 q)/(b +
 * i n1 q), b = n2^2 ci, q = sqrt(n1^2 sin^2 i - n2^2)), into (ar + i ai,
 * br + i bi). */
LP__INLINE void lp__jones_reflection(double rs, double rp, int tir, double ci, double n1,
                                     double n2, double *ar, double *ai, double *br, double *bi)
{
    double sin_i = sqrt((1.0 - ci) * (1.0 + ci));
    double q2 = (n1 * sin_i - n2) * (n1 * sin_i + n2);
    double q = sqrt(q2 > 0.0 ? q2 : 0.0);
    double a = n1 * ci, b = n2 * n2 * ci, c = n1 * q;
    double ia = 1.0 / (a * a + q * q), ib = 1.0 / (b * b + c * c);
    *ar = tir ? (a * a - q * q) * ia : rs;
    *ai = tir ? -2.0 * a * q * ia : 0.0;
    *br = tir ? (b * b - c * c) * ib : rp;
    *bi = tir ? -2.0 * b * c * ib : 0.0;
}

/* H = att [[s.s', ap.s'], [s.p', ap.p']] from a node's (s, ap) to the
 * next node's (s', p'). */
LP__INLINE void lp__jones_between(lp_vec3 s, lp_vec3 ap, lp_vec3 s2, lp_vec3 p2, double att,
                                  double h[4])
{
    h[0] = att * v3_dot(s, s2);
    h[1] = att * v3_dot(ap, s2);
    h[2] = att * v3_dot(s, p2);
    h[3] = att * v3_dot(ap, p2);
}

/* R H D: R complex, H real, D = diag(ar + i ai, br + i bi). */
LP__INLINE lp__cm2 lp__jones_then(const lp__cm2 *R, const double h[4], double ar, double ai,
                                  double br, double bi)
{
    /* M = R H */
    double m00 = R->r00 * h[0] + R->r01 * h[2], m01 = R->r00 * h[1] + R->r01 * h[3];
    double m10 = R->r10 * h[0] + R->r11 * h[2], m11 = R->r10 * h[1] + R->r11 * h[3];
    double n00 = R->i00 * h[0] + R->i01 * h[2], n01 = R->i00 * h[1] + R->i01 * h[3];
    double n10 = R->i10 * h[0] + R->i11 * h[2], n11 = R->i10 * h[1] + R->i11 * h[3];
    /* M D: column 0 times (ar + i ai), column 1 times (br + i bi) */
    lp__cm2 T;
    T.r00 = m00 * ar - n00 * ai, T.i00 = m00 * ai + n00 * ar;
    T.r10 = m10 * ar - n10 * ai, T.i10 = m10 * ai + n10 * ar;
    T.r01 = m01 * br - n01 * bi, T.i01 = m01 * bi + n01 * br;
    T.r11 = m11 * br - n11 * bi, T.i11 = m11 * bi + n11 * br;
    return T;
}

/* diag(ar + i ai, br + i bi). */
LP__INLINE lp__cm2 lp__jones_diag(double ar, double ai, double br, double bi)
{
    lp__cm2 T = {ar, 0.0, 0.0, br, ai, 0.0, 0.0, bi};
    return T;
}

/* The power form Re(T^H T): its (0,0), (0,1) and (1,1) entries. */
LP__INLINE void lp__jones_form(const lp__cm2 *T, double P[3])
{
    P[0] = T->r00 * T->r00 + T->r10 * T->r10 + T->i00 * T->i00 + T->i10 * T->i10;
    P[1] = T->r00 * T->r01 + T->r10 * T->r11 + T->i00 * T->i01 + T->i10 * T->i11;
    P[2] = T->r01 * T->r01 + T->r11 * T->r11 + T->i01 * T->i01 + T->i11 * T->i11;
}

/* Node 1 of the view chain, entered from outside (index n1) along d at
 * the surface normal n of the glass (n2), reflected along r with the
 * factors rs, rp (complex under total internal reflection, when the
 * medium is the denser: lp__jones_reflection, from tir and cos i = ci)
 * and refracted along t with ts, tp: the light's way from node 1 (it
 * refracts out along -d) as R, the light's axes there (s_prev, p_prev)
 * and ok; the form P of the depth-1 query (the light reflecting off the
 * outside, arriving along -r), its entry axes es, ep and qok. */
LP__INLINE void lp__jones_first(lp_vec3 d, lp_vec3 n, lp_vec3 r, lp_vec3 t, double rs, double rp,
                                int tir, double ci, double n1, double n2, double ts, double tp,
                                lp__cm2 *R, lp_vec3 *s_prev, lp_vec3 *p_prev, double *ok,
                                double P[3], lp_vec3 *es, lp_vec3 *ep, double *qok)
{
    lp_vec3 ap, eap;
    double ar, ai, br, bi;
    lp__jones_reflection(rs, rp, tir, ci, n1, n2, &ar, &ai, &br, &bi);
    lp__jones_axes(v3_neg(t), n, v3_neg(d), s_prev, p_prev, &ap, ok);
    *R = lp__jones_diag(ts, 0.0, tp, 0.0);
    lp__jones_axes(v3_neg(r), n, v3_neg(d), es, ep, &eap, qok);
    lp__cm2 T = lp__jones_diag(ar, ai, br, bi);
    lp__jones_form(&T, P);
}

/* Node j >= 2 of the view chain, reached along d inside the glass (index
 * n1) over a segment of amplitude factor att, at the surface normal n,
 * reflected along r with the factors rs, rp (complex under total internal
 * reflection: lp__jones_reflection, from tir and cos i = ci; n2 the
 * medium's index) and refracted out along t with ts, tp: the form P of
 * the query there (the light refracting in, arriving along -t), its entry
 * axes es, ep and qok; then R, s_prev, p_prev and ok grow by the light's
 * reflection there (arriving along -r), for the queries beyond. */
LP__INLINE void lp__jones_node(lp_vec3 d, lp_vec3 n, lp_vec3 r, lp_vec3 t, double att,
                               double ts, double tp, double rs, double rp, int tir, double ci,
                               double n1, double n2, lp__cm2 *R, lp_vec3 *s_prev,
                               lp_vec3 *p_prev, double *ok, double P[3], lp_vec3 *es,
                               lp_vec3 *ep, double *qok)
{
    double h[4], eok, lok, ar, ai, br, bi;
    lp__jones_reflection(rs, rp, tir, ci, n1, n2, &ar, &ai, &br, &bi);
    lp_vec3 eap, s, p, ap, o = v3_neg(d);
    lp__jones_axes(v3_neg(t), n, o, es, ep, &eap, &eok);
    lp__jones_between(*es, eap, *s_prev, *p_prev, att, h);
    lp__cm2 T = lp__jones_then(R, h, ts, 0.0, tp, 0.0);
    lp__jones_form(&T, P);
    *qok = *ok * eok;
    lp__jones_axes(v3_neg(r), n, o, &s, &p, &ap, &lok);
    lp__jones_between(s, ap, *s_prev, *p_prev, att, h);
    *R = lp__jones_then(R, h, ar, ai, br, bi);
    *s_prev = s, *p_prev = p;
    *ok = *ok * lok;
}

#endif
