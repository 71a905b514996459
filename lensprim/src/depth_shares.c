/* depth_shares.c -- how the light a view ray gathers splits by depth.
 *
 * The paper's second experiment: backward tracing, every query ray of
 * the view ray answered by natural light of unit intensity (two mutually
 * incoherent orthogonal linear halves of 1/2), and the intensity of the
 * gathered bundle rays summed per depth.  Built on lp_backward_build and
 * lp_backward_gather. */
#include <math.h>
#include <string.h>

#include "error.h"
#include "vec3.h"

lp_status lp_bundle_by_depth(const lp_lens *lens, lp_vec3 origin, lp_vec3 dir, double lambda_nm,
                             const lp_trace_args *args, double *by_depth, lp_error *err)
{
    lp_backward *bw = NULL;
    lp_result res;
    lp_status st;

    if (!lens || !by_depth)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_bundle_by_depth: NULL argument");
    if ((st = lp_backward_create(&bw, err)) != LP_OK)
        return st;
    st = lp_backward_build(bw, lens, origin, dir, lambda_nm, args, err);
    if (st != LP_OK) {
        lp_backward_destroy(bw);
        return st;
    }
    lp_result_init(&res);
    const lp_query *q = lp_backward_queries(bw);
    size_t nq = lp_backward_query_count(bw);
    for (size_t i = 0; i < nq && st == LP_OK; i++) {
        lp_vec3 back = v3_neg(q[i].dir);
        lp_ray half[2];
        memset(half, 0, sizeof half);
        half[0].vp = v3_any_perp(back);
        half[1].vp = v3_cross(back, half[0].vp);
        for (int h = 0; h < 2; h++) {
            half[h].origin = q[i].origin;
            half[h].dir = back;
            half[h].lambda_nm = lambda_nm;
            half[h].intensity = 0.5;
        }
        lp_result_clear(&res);
        st = lp_backward_gather(bw, i, half, 2, &res, err);
        for (size_t k = 0; st == LP_OK && k < res.count; k++)
            by_depth[res.rays[k].depth] += res.rays[k].ray.intensity;
    }
    lp_result_release(&res);
    lp_backward_destroy(bw);
    if (st == LP_OK)
        lp__ok(err);
    return st;
}
