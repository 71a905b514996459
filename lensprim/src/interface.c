/* interface.c -- the transformation G: Fresnel's equations on a field.
 *
 * Bases: for each wave of direction k the p axis is k x s (fresnel.h), so
 * the reflected field is rs Es s + rp Ep (r x s) and the transmitted one
 * ts Es s + tp Ep (t x s), with power-normalized ts, tp.  The mirror image
 * of the incident field is Es s - Ep (r x s), hence the jump test
 * Re(rs)|Es|^2 - Re(rp)|Ep|^2 < 0. */
#include <math.h>

#include "interface.h"

/* The s axis at normal incidence: the incoming field's own direction
 * (its real part, or its imaginary part if that is all it has), else any
 * axis perpendicular to d. */
lp_vec3 lp__hint_axis(lp_vec3 d, const lp__cvec3 *hint)
{
    lp_vec3 e = hint ? cv3_re(*hint) : v3(0, 0, 0);
    if (hint && v3_dot(e, e) == 0.0)
        e = cv3_im(*hint);
    e = v3_sub(e, v3_scale(d, v3_dot(e, d)));
    return v3_dot(e, e) > 0.0 ? v3_normalize(e) : v3_any_perp(d);
}

void lp__node_refit(lp__node *node, const lp__cvec3 *E)
{
    if (node->normal) {
        node->s = lp__hint_axis(node->d, E);
        node->p = v3_cross(node->d, node->s);
    }
}

double lp__node_reflectance(const lp__node *node, lp_mode mode)
{
    if (node->f.tir)
        return 1.0;
    if (mode == LP_MODE_SCHLICK)
        return lp__schlick(node->cos_i, node->n1, node->n2);
    return 0.5 * (node->f.Rs + node->f.Rp);
}

/* a u + b w, in real arithmetic when a and b are real. */
static lp__cvec3 combine(int real, double complex a, lp_vec3 u, double complex b, lp_vec3 w)
{
    if (real)
        return cv3_real(v3_add(v3_scale(u, creal(a)), v3_scale(w, creal(b))), 1.0);
    return cv3_combine(a, u, b, w);
}

static inline void reflect_on(const lp__node *node, const lp__axes *ax, lp_mode mode,
                              const lp__amp *amp, lp__branch *out)
{
    lp_vec3 pr = ax->p;
    double complex es = amp->es, ep = amp->ep;
    int real = amp->real;

    out->dir = ax->dir;
    out->flip = 0;
    if (mode == LP_MODE_POLARIZED) {
        if (real && !node->f.tir) {
            out->E = cv3_real(lp__node_reflect_real(node, ax, creal(es), creal(ep), &out->flip),
                              1.0);
            return;
        }
        double complex rs = node->f.rs, rp = node->f.rp;
        double mirror = creal(rs) * (creal(es) * creal(es) + cimag(es) * cimag(es)) -
                        creal(rp) * (creal(ep) * creal(ep) + cimag(ep) * cimag(ep));
        if (mirror < 0.0) {
            rs = -rs;
            rp = -rp;
            out->flip = 1;
        }
        out->E = cv3_combine(rs * es, node->s, rp * ep, pr);
    } else {
        /* The mirror image of the field, scaled to the reflected power. */
        double k = sqrt(lp__node_reflectance(node, mode));
        out->E = combine(real, k * es, node->s, -k * ep, pr);
    }
}

static inline void transmit_on(const lp__node *node, const lp__axes *ax, lp_mode mode,
                               const lp__amp *amp, lp__branch *out)
{
    lp_vec3 pt = ax->p;
    double complex es = amp->es, ep = amp->ep;
    int real = amp->real;

    out->dir = ax->dir;
    out->flip = 0;
    if (mode == LP_MODE_POLARIZED) {
        if (real)
            out->E = cv3_real(lp__node_transmit_real(node, ax, creal(es), creal(ep)), 1.0);
        else
            out->E = cv3_combine(node->f.ts * es, node->s, node->f.tp * ep, pt);
    } else {
        double T = 1.0 - lp__node_reflectance(node, mode);
        double k = sqrt(T > 0.0 ? T : 0.0);
        out->E = combine(real, k * es, node->s, k * ep, pt);
    }
}

void lp__node_reflect_on(const lp__node *node, const lp__axes *ax, lp_mode mode,
                         const lp__amp *amp, lp__branch *out)
{
    reflect_on(node, ax, mode, amp, out);
}

void lp__node_transmit_on(const lp__node *node, const lp__axes *ax, lp_mode mode,
                          const lp__amp *amp, lp__branch *out)
{
    transmit_on(node, ax, mode, amp, out);
}

void lp__node_reflect_amp(const lp__node *node, lp_mode mode, const lp__amp *amp,
                          lp__branch *out)
{
    lp__axes ax;
    lp__node_reflect_axes(node, &ax);
    reflect_on(node, &ax, mode, amp, out);
}

void lp__node_transmit_amp(const lp__node *node, lp_mode mode, const lp__amp *amp,
                           lp__branch *out)
{
    lp__axes ax;
    lp__node_transmit_axes(node, &ax);
    transmit_on(node, &ax, mode, amp, out);
}

void lp__node_reflect(const lp__node *node, lp_mode mode, const lp__cvec3 *E, lp__branch *out)
{
    lp__amp amp;
    lp__node_project(node, E, &amp);
    lp__node_reflect_amp(node, mode, &amp, out);
}

void lp__node_transmit(const lp__node *node, lp_mode mode, const lp__cvec3 *E,
                       lp__branch *out)
{
    lp__amp amp;
    lp__node_project(node, E, &amp);
    lp__node_transmit_amp(node, mode, &amp, out);
}
