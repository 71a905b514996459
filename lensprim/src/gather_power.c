/* gather_power.c -- lp_backward_gather_power_many: the power that
 * gathers carry, without their rays, by the Jones matrices of their ways.
 *
 * Light answering query q enters the lens at the query's node k and runs
 * back along the view ray's chain, reflecting inside at nodes k-1 .. 2,
 * to node 1, where it refracts out along the view ray (trace_backward.c).
 * Its field arriving at a node is written on the node's s and p axes,
 * y = (E.s, E.p); the node multiplies it by its Fresnel factors,
 *     z = D y,   D = diag(rs, rp) where it reflects, diag(ts, tp) where
 *                it refracts (fresnel.h: power-normalized, so |z|^2 is
 *                the power leaving),
 * the leaving field being z0 s + z1 ap on the branch's axes (s, ap); on
 * the segment to the next node the glass takes |z|^2 seg_abs of its power
 * and its amplitude falls by seg_att, and there it is written on that
 * node's axes again:
 *     y' = seg_att H z,   H = [[s.s', ap.s'], [s.p', ap.p']].
 * This is the Jones calculus of a ray path (polarization ray tracing: R.
 * A. Chipman, W. S. T. Lam, G. Young, Polarized Light and Optical
 * Systems, 2018, ch. 9-10), in 2 x 2 products where the gathers
 * (trace_backward.c, gather_lanes.c, gather_many.c) project and rebuild
 * 3-vectors; the power leaving is the same to rounding.  The field is
 * real until the first node under total internal reflection (complex rs,
 * rp: complex_at) and complex from there, its real and imaginary parts
 * carried apart (H is real).  A phase jump negates the field and changes
 * no power, so none is counted; nor is the field split into its
 * ellipse's axes, nor are rays stored.  Since every step is linear, a
 * request's way is composed once into the matrices T_m = D_m H_{m+1}
 * ... H_k D_k that take the entering field x = (E.s, E.p) to the field
 * leaving node m, and what a ray needs of them are two quadratic forms:
 * the power leaving, |T_1 x|^2 = x' P x with P = Re(T_1^H T_1), and the
 * power absorbed, x' A x with A = sum over the segments of seg_abs
 * Re(T_m^H T_m) -- a few products a ray, whatever the depth.  For a ray
 * of intensity I and field direction v (world), x = sqrt(I) (v.s, v.p) /
 * |(v.s, v.p)|: s, p and the light's direction are orthonormal, so
 * (v.s, v.p) is v's part across the light, and its length is what
 * lp__bundle_ray_check normalizes; a ray near that check's limit takes
 * the check itself.  A request whose way the steps do
 * not take -- a build that set up no ways (not polarized, a crystal), a
 * node at normal incidence (its s axis follows the field), a total
 * internal reflection where the light refracts -- is gathered by
 * lp_backward_gather and its rays' intensities added up (and the rays
 * taken back off out). */
#include <math.h>

#include "backward.h"
#include "error.h"

/* A 2 x 2 complex matrix, its real and imaginary parts row by row. */
typedef struct cmat2 {
    double re[4], im[4];
} cmat2;

/* A request's way composed: the forms P and A (a00, a01, a11) and the
 * entry's s and p axes in the world. */
typedef struct jones_way {
    double P[3], A[3];
    lp_vec3 s, p;
} jones_way;

/* Re(T^H T) of T, into g: its (0,0), (0,1) and (1,1) entries. */
static void gram(const cmat2 *T, double g[3])
{
    const double *a = T->re, *b = T->im;
    g[0] = a[0] * a[0] + a[2] * a[2] + b[0] * b[0] + b[2] * b[2];
    g[1] = a[0] * a[1] + a[2] * a[3] + b[0] * b[1] + b[2] * b[3];
    g[2] = a[1] * a[1] + a[3] * a[3] + b[1] * b[1] + b[3] * b[3];
}

/* T = D T for the factors of way w (factors_of). */
static void factors_of(const lp__bw_way *w, double *a, double *ai, double *b, double *bi);
static void node_factors(const lp__bw_way *w, cmat2 *T)
{
    double ar, ai, br, bi;
    factors_of(w, &ar, &ai, &br, &bi);
    const double f[4] = {ar, ar, br, br}, g[4] = {ai, ai, bi, bi}; /* row i: (a or b) */
    for (int e = 0; e < 4; e++) {
        double re = T->re[e], im = T->im[e];
        T->re[e] = f[e] * re - g[e] * im;
        T->im[e] = f[e] * im + g[e] * re;
    }
}

/* T = seg_att H T on the way from way w to node `next` (segment). */
static void segment(const lp_backward *bw, const lp__bw_way *w, int next, double h[4]);
static void to_node(const lp_backward *bw, const lp__bw_way *w, int next, cmat2 *T)
{
    double h[4];
    segment(bw, w, next, h);
    cmat2 t = *T;
    for (int r = 0; r < 2; r++)
        for (int c = 0; c < 2; c++) {
            T->re[2 * r + c] = h[2 * r] * t.re[c] + h[2 * r + 1] * t.re[2 + c];
            T->im[2 * r + c] = h[2 * r] * t.im[c] + h[2 * r + 1] * t.im[2 + c];
        }
}

/* The factors of way w: rs, rp where it reflects, ts, tp where it
 * refracts (a + i ai on s, b + i bi on p). */
static void factors_of(const lp__bw_way *w, double *a, double *ai, double *b, double *bi)
{
    const lp__node *nd = &w->node;
    if (w->reflect) {
        *a = creal(nd->f.rs), *ai = cimag(nd->f.rs);
        *b = creal(nd->f.rp), *bi = cimag(nd->f.rp);
    } else {
        *a = nd->f.ts, *ai = 0.0;
        *b = nd->f.tp, *bi = 0.0;
    }
}

/* The way from way w (axes s, ap) to node `next` of bw's chain (axes s',
 * p'): seg_att H, H = [[s.s', ap.s'], [s.p', ap.p']], into h. */
static void segment(const lp_backward *bw, const lp__bw_way *w, int next, double h[4])
{
    const lp__node *nn = &bw->light[next].node;
    double att = bw->optics.alpha > 0.0 ? bw->node[next].seg_att : 1.0;
    h[0] = att * v3_dot(w->node.s, nn->s);
    h[1] = att * v3_dot(w->ax.p, nn->s);
    h[2] = att * v3_dot(w->node.s, nn->p);
    h[3] = att * v3_dot(w->ax.p, nn->p);
}

/* Query q's way composed (complex_at[q] >= 0): from its entry (node k)
 * back through the light's way to node 1.  A way whose field stays real
 * (complex_at 0) in real 2 x 2 products; one with a node under total
 * internal reflection in complex ones (node_factors, to_node, gram). */
static void compose(const lp_backward *bw, size_t q, jones_way *J)
{
    const int k = bw->query[q].depth, absorbs = bw->optics.alpha > 0.0;
    const lp__bw_way *w = &bw->entry[q];
    J->A[0] = J->A[1] = J->A[2] = 0.0;
    J->s = lp__to_world_dir(bw->lens, w->node.s);
    J->p = lp__to_world_dir(bw->lens, w->node.p);
    if (bw->complex_at[q] == 0) {
        double a, ai, b, bi, h[4];
        factors_of(w, &a, &ai, &b, &bi);
        double t00 = a, t01 = 0.0, t10 = 0.0, t11 = b; /* T = D_k */
        for (int m = k; m > 1; m--) {
            if (absorbs) {
                double f = bw->node[m - 1].seg_abs;
                J->A[0] += f * (t00 * t00 + t10 * t10);
                J->A[1] += f * (t00 * t01 + t10 * t11);
                J->A[2] += f * (t01 * t01 + t11 * t11);
            }
            segment(bw, w, m - 1, h);
            w = &bw->light[m - 1];
            factors_of(w, &a, &ai, &b, &bi);
            double u00 = h[0] * t00 + h[1] * t10, u01 = h[0] * t01 + h[1] * t11;
            double u10 = h[2] * t00 + h[3] * t10, u11 = h[2] * t01 + h[3] * t11;
            t00 = a * u00, t01 = a * u01, t10 = b * u10, t11 = b * u11;
        }
        J->P[0] = t00 * t00 + t10 * t10;
        J->P[1] = t00 * t01 + t10 * t11;
        J->P[2] = t01 * t01 + t11 * t11;
        return;
    }
    cmat2 T = {{1.0, 0.0, 0.0, 1.0}, {0.0, 0.0, 0.0, 0.0}};
    for (int m = k;; m--) {
        node_factors(w, &T);
        if (m == 1)
            break;
        if (absorbs) { /* the segment to node m - 1 */
            double g[3], f = bw->node[m - 1].seg_abs;
            gram(&T, g);
            for (int e = 0; e < 3; e++)
                J->A[e] += f * g[e];
        }
        to_node(bw, w, m - 1, &T);
        w = &bw->light[m - 1];
    }
    gram(&T, J->P);
}

/* x' F x of the form F. */
static inline double form(const double F[3], double x0, double x1)
{
    return F[0] * x0 * x0 + 2.0 * F[1] * x0 * x1 + F[2] * x1 * x1;
}

/* Whether the steps take query q of bw. */
static int in_steps(const lp_backward *bw, size_t q)
{
    return bw && bw->ways && q < bw->n_queries && bw->complex_at[q] >= 0;
}

/* Request (bw, q, b[0..n)) through its composed way, its sums into res
 * and the power leaving into *power; a ray that fails its check stops it
 * (with what came before it added). */
static lp_status gather_power(const lp_backward *bw, size_t q, const lp_ray *b, size_t n,
                              lp_result *res, double *power, lp_error *err)
{
    const int k = bw->query[q].depth;
    jones_way J;
    compose(bw, q, &J);
    double sum = 0.0;
    res->warnings |= bw->warnings;
    for (size_t i = 0; i < n; i++) {
        const lp_ray *r = &b[i];
        const double I0 = r->intensity;
        double x0 = v3_dot(r->vp, J.s), x1 = v3_dot(r->vp, J.p);
        double across = x0 * x0 + x1 * x1, all = v3_dot(r->vp, r->vp);
        /* clear of lp__bundle_ray_check's limit (|across| > 1e-12 |v|),
         * and every number finite: its verdict is sure */
        int sure = across > 1e-20 * all && all <= DBL_MAX && isfinite(I0) && I0 >= 0.0 &&
                   isfinite(r->op) && isfinite(r->phase);
        if (!sure) { /* the check itself, in the lens frame */
            lp_vec3 vp;
            lp_status st = lp__bundle_ray_check(bw->lens, r, bw->entry[q].node.d, &vp, err);
            if (st != LP_OK) {
                *power = sum;
                return st;
            }
            x0 = v3_dot(vp, bw->entry[q].node.s), x1 = v3_dot(vp, bw->entry[q].node.p);
            across = x0 * x0 + x1 * x1;
        }
        double scale = I0 / across;
        double out = scale * form(J.P, x0, x1), absorbed = scale * form(J.A, x0, x1);
        sum += out;
        res->in += I0;
        res->out += out;
        res->absorbed_glass += absorbed;
        res->truncated += I0 - out - absorbed;
        res->nodes += (size_t)k;
    }
    *power = sum;
    return LP_OK;
}

lp_status lp_backward_gather_power_many(const lp_backward *const *bw, const size_t *q,
                                        const lp_ray *const *bundle, const size_t *n,
                                        size_t count, lp_result *out, double *power,
                                        lp_error *err)
{
    if (!out || (count > 0 && (!bw || !q || !bundle || !n || !power)))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "lp_backward_gather_power_many: NULL argument");
    for (size_t k = 0; k < count; k++) {
        lp_status st;
        power[k] = 0.0;
        if (in_steps(bw[k], q[k]) && (bundle[k] || n[k] == 0)) {
            st = gather_power(bw[k], q[k], bundle[k], n[k], out, &power[k], err);
        } else { /* its rays, added up and taken back */
            size_t from = out->count;
            st = lp_backward_gather(bw[k], q[k], bundle[k], n[k], out, err);
            for (size_t i = from; i < out->count; i++)
                power[k] += out->rays[i].ray.intensity;
            out->count = from;
        }
        if (st != LP_OK) {
            if (err) {
                lp_error e = *err;
                lp__fail(err, st, "request %zu: %s", k, e.message);
            }
            return st;
        }
    }
    lp__ok(err);
    return LP_OK;
}
