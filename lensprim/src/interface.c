/* interface.c -- the transformation G: Fresnel's equations on a field.
 *
 * Bases: for each wave of direction k the p axis is k x s (fresnel.h), so
 * the reflected field is rs Es s + rp Ep (r x s) and the transmitted one
 * ts Es s + tp Ep (t x s), with power-normalized ts, tp.  The mirror image
 * of the incident field is Es s - Ep (r x s), hence the jump test
 * Re(rs)|Es|^2 - Re(rp)|Ep|^2 < 0. */
#include <math.h>

#include "interface.h"

int lp__node_setup(lp__node *node, lp_vec3 d, lp_vec3 normal, double n1, double n2,
                   const lp__cvec3 *hint)
{
    double dn = v3_dot(d, normal);
    node->d = d;
    node->n1 = n1;
    node->n2 = n2;
    node->n = dn > 0.0 ? v3_neg(normal) : normal;
    node->cos_i = fmin(1.0, fabs(dn));
    lp__fresnel_eval(node->cos_i, n1, n2, &node->f);

    lp_vec3 s = v3_cross(d, node->n);
    double sl = v3_len(s);
    if (sl > 1e-9) {
        node->s = v3_scale(s, 1.0 / sl);
    } else {
        /* Normal incidence: keep the incoming field's frame. */
        lp_vec3 e = hint ? cv3_re(*hint) : v3(0, 0, 0);
        if (hint && v3_dot(e, e) == 0.0)
            e = cv3_im(*hint);
        e = v3_sub(e, v3_scale(d, v3_dot(e, d)));
        node->s = v3_dot(e, e) > 0.0 ? v3_normalize(e) : v3_any_perp(d);
    }
    return node->f.tir;
}

static lp_vec3 reflect_dir(const lp__node *node)
{
    return v3_normalize(v3_madd(node->d, node->n, 2.0 * node->cos_i));
}

double lp__node_reflectance(const lp__node *node, lp_mode mode)
{
    if (node->f.tir)
        return 1.0;
    if (mode == LP_MODE_SCHLICK)
        return lp__schlick(node->cos_i, node->n1, node->n2);
    return 0.5 * (node->f.Rs + node->f.Rp);
}

void lp__node_reflect(const lp__node *node, lp_mode mode, const lp__cvec3 *E, lp__branch *out)
{
    lp_vec3 r = reflect_dir(node);
    lp_vec3 pi = v3_cross(node->d, node->s), pr = v3_cross(r, node->s);
    double complex es = cv3_dot_real(*E, node->s), ep = cv3_dot_real(*E, pi);

    out->dir = r;
    out->flip = 0;
    if (mode == LP_MODE_POLARIZED) {
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
        out->E = cv3_combine(k * es, node->s, -k * ep, pr);
    }
}

void lp__node_transmit(const lp__node *node, lp_mode mode, const lp__cvec3 *E,
                       lp__branch *out)
{
    double eta = node->n1 / node->n2, ci = node->cos_i, ct = node->f.cos_t;
    lp_vec3 t = v3_normalize(v3_madd(v3_scale(node->d, eta), node->n, eta * ci - ct));
    lp_vec3 pi = v3_cross(node->d, node->s), pt = v3_cross(t, node->s);
    double complex es = cv3_dot_real(*E, node->s), ep = cv3_dot_real(*E, pi);

    out->dir = t;
    out->flip = 0;
    if (mode == LP_MODE_POLARIZED) {
        out->E = cv3_combine(node->f.ts * es, node->s, node->f.tp * ep, pt);
    } else {
        double T = 1.0 - lp__node_reflectance(node, mode);
        double k = sqrt(T > 0.0 ? T : 0.0);
        out->E = cv3_combine(k * es, node->s, k * ep, pt);
    }
}
