/* gather_power.c -- lp_backward_gather_power_many: the power that
 * gathers carry out, without their rays.
 *
 * A build made with LP_BACKWARD_POWER holds each query's power form P
 * (jones.h: its way's Jones matrix T, grown node by node along the view
 * ray's chain, and P = Re(T^H T)) and the axes s, p of the light
 * entering.  A bundle ray of intensity I and field direction v then
 * leaves with power I x' P x / x' x, x = (v.s, v.p): s, p and the light's
 * direction are orthonormal, so (v.s, v.p) is v's part across the light
 * and its length what lp__bundle_ray_check normalizes.  A ray clear of
 * that check's limit (its part across the light more than 1e-10 of it,
 * against the check's 1e-12), finite and far from overflowing needs no
 * more; one near it takes the check itself, so every
 * verdict on a ray is lp_backward_gather's.  A request without a form --
 * another build, a crystal, a way with a node at normal incidence -- is
 * gathered by lp_backward_gather and its rays' intensities added up. */
#include <math.h>

#include "backward.h"
#include "error.h"

/* Whether query q of bw has a power form. */
static int has_form(const lp_backward *bw, size_t q)
{
    return bw && q < bw->n_queries && bw->pform_ok[q] && !lp__xback_active(bw->xb);
}

/* Request (bw, q, b[0..n)) by its power form, into *power; a ray that
 * fails its check stops it. */
static lp_status form_power(const lp_backward *bw, size_t q, const lp_ray *b, size_t n,
                            double *power, lp_error *err)
{
    const double *P = bw->pform[q];
    const lp_vec3 s = bw->pform_s[q], p = bw->pform_p[q];
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        const lp_ray *r = &b[i];
        const double I0 = r->intensity;
        double x0 = v3_dot(r->vp, s), x1 = v3_dot(r->vp, p);
        double across = x0 * x0 + x1 * x1, all = v3_dot(r->vp, r->vp);
        /* clear of lp__bundle_ray_check's limit (a part across the light
         * above 1e-12 of v: across > 1e-24 |v|^2) by a factor 1e4 in
         * across, every number finite and |v| far from overflowing in
         * the check's own arithmetic: its verdict is sure */
        int sure = across > 1e-20 * all && all <= 0x1p1000 && isfinite(I0) && I0 >= 0.0 &&
                   isfinite(r->op) && isfinite(r->phase);
        if (!sure) {
            lp_vec3 vp;
            lp_status st = lp__bundle_ray_check(bw->lens, r, v3_neg(bw->query_dir[q]), &vp, err);
            if (st != LP_OK)
                return st;
        }
        sum += I0 * (P[0] * x0 * x0 + 2.0 * P[1] * x0 * x1 + P[2] * x1 * x1) / across;
    }
    *power = sum;
    return LP_OK;
}

lp_status lp_backward_gather_power_many(const lp_backward *const *bw, const size_t *q,
                                        const lp_ray *const *bundle, const size_t *n,
                                        size_t count, double *power, lp_error *err)
{
    if (count > 0 && (!bw || !q || !bundle || !n || !power))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "lp_backward_gather_power_many: NULL argument");
    lp_result rays; /* the gathers without a form, one by one */
    lp_result_init(&rays);
    lp_status st = LP_OK;
    for (size_t k = 0; k < count && st == LP_OK; k++) {
        power[k] = 0.0;
        if (has_form(bw[k], q[k]) && (bundle[k] || n[k] == 0)) {
            st = form_power(bw[k], q[k], bundle[k], n[k], &power[k], err);
        } else {
            lp_result_clear(&rays);
            st = lp_backward_gather(bw[k], q[k], bundle[k], n[k], &rays, err);
            for (size_t i = 0; i < rays.count && st == LP_OK; i++)
                power[k] += rays.rays[i].ray.intensity;
        }
        if (st != LP_OK) {
            power[k] = 0.0;
            if (err) {
                lp_error e = *err;
                lp__fail(err, st, "request %zu: %s", k, e.message);
            }
        }
    }
    lp_result_release(&rays);
    if (st == LP_OK)
        lp__ok(err);
    return st;
}
