/* trace_batch.c -- many rays of one wavelength given as arrays.
 *
 * The wavelength's optics are computed once for the whole call.  The rays
 * are taken in blocks: one loop over the block, free of branches and
 * calls, normalizes every ray's direction and field direction, puts them
 * in the lens frame and prepares the bounding-sphere test; the compiler
 * vectorizes it across rays (this file is built with -fno-trapping-math,
 * which lets it compute the rejected cases' quotients and drop them; no
 * value changes).  Each ray is then traced by the one-ray code from the same
 * numbers, in order, so the result is the one lp_trace_forward_many gives
 * bit for bit. */
#include <math.h>

#include "error.h"
#include "trace.h"
#include "trace_lanes.h"

#define BLOCK LP__LANES

/* A block of rays, checked and in the lens frame. */
typedef struct block {
    double px[BLOCK], py[BLOCK], pz[BLOCK]; /* local origin */
    double dx[BLOCK], dy[BLOCK], dz[BLOCK]; /* local unit direction */
    double vx[BLOCK], vy[BLOCK], vz[BLOCK]; /* local unit field direction */
    double ok_vp[BLOCK];                    /* 1: the field direction is good */
    double bb[BLOCK], cc[BLOCK];            /* the bounding-sphere test */
    unsigned char take[BLOCK];              /* for the lane engine */
} block;

/* Rays i0 .. i0+m of in into b: the one loop meant to be vectorized. */
static void load_block(const lp_lens *lens, const lp_ray_soa *in, size_t i0, size_t m,
                       block *restrict b)
{
    const double *restrict ox = in->ox + i0, *restrict oy = in->oy + i0,
                           *restrict oz = in->oz + i0;
    const double *restrict dx = in->dx + i0, *restrict dy = in->dy + i0,
                           *restrict dz = in->dz + i0;
    const double *restrict vx = in->vx + i0, *restrict vy = in->vy + i0,
                           *restrict vz = in->vz + i0;
    const lp_vec3 center = lens->bound_center;
    const double r2 = lens->bound_r2;

    for (size_t j = 0; j < m; j++) {
        lp_vec3 o = v3(ox[j], oy[j], oz[j]);
        lp_vec3 dir = v3(dx[j], dy[j], dz[j]);
        lp_vec3 v = v3(vx[j], vy[j], vz[j]);
        lp_vec3 d = v3_normalize(dir);
        double ok_vp;
        lp_vec3 vp = lp__perp_unit_core(v, d, &ok_vp);
        b->ok_vp[j] = ok_vp;
        /* the bounding sphere: outside it when cc > 0, then leaving it
         * when bb > 0, passing it by when bb^2 < cc */
        lp_vec3 oc = v3_sub(o, center);
        b->bb[j] = v3_dot(oc, d);
        b->cc[j] = v3_dot(oc, oc) - r2;
        lp_vec3 p = lp__to_local_point(lens, o), dl = lp__to_local_dir(lens, d),
                vl = lp__to_local_dir(lens, vp);
        b->px[j] = p.x;
        b->py[j] = p.y;
        b->pz[j] = p.z;
        b->dx[j] = dl.x;
        b->dy[j] = dl.y;
        b->dz[j] = dl.z;
        b->vx[j] = vl.x;
        b->vy[j] = vl.y;
        b->vz[j] = vl.z;
    }
}

/* Ray i of in as a one-ray input. */
static lp_ray ray_at(const lp_ray_soa *in, size_t i, double lambda_nm)
{
    lp_ray r;
    r.origin = v3(in->ox[i], in->oy[i], in->oz[i]);
    r.dir = v3(in->dx[i], in->dy[i], in->dz[i]);
    r.lambda_nm = lambda_nm;
    r.intensity = in->intensity[i];
    r.vp = v3(in->vx[i], in->vy[i], in->vz[i]);
    r.kphi = in->kphi ? in->kphi[i] : 0;
    r.op = in->op ? in->op[i] : 0.0;
    r.phase = in->phase ? in->phase[i] : 0.0;
    r.ch = in->ch ? in->ch[i] : 0;
    return r;
}

/* Is ray r (lane j of b) valid by the block's numbers, and does it reach
 * the lens's bounding sphere?  -1: the block's check refused it (the
 * one-ray check words the error); 0: it misses the lens; 1: it is in. */
static int lane_class(const lp_ray *r, const block *b, size_t j)
{
    int good = v3_finite(r->origin) && v3_finite(r->dir) && b->ok_vp[j] != 0.0 &&
               (r->dir.x != 0.0 || r->dir.y != 0.0 || r->dir.z != 0.0) &&
               isfinite(r->intensity) && r->intensity >= 0.0 && isfinite(r->op) &&
               isfinite(r->phase) && v3_finite(r->vp);
    if (!good)
        return -1;
    return !(b->cc[j] > 0.0 && (b->bb[j] > 0.0 || b->bb[j] * b->bb[j] < b->cc[j]));
}

/* One ray of a block: from the lane engine's run, or traced by the
 * one-ray code from the block's numbers, or (a ray the block's check
 * refused) by the one-ray check, which words the error. */
static lp_status trace_lane(const lp_lens *lens, const lp__optics *o, const lp_ray *r,
                            const block *b, const lp__lanes *L, size_t j,
                            const lp_trace_args *a, lp_result *out, lp_error *err)
{
    if (L && lp__lanes_traced(L, j))
        return lp__lanes_emit(L, j, lens, a, r, out, err);
    int cls = lane_class(r, b, j);
    if (cls == 0)
        return LP_OK; /* misses the bounding sphere, so the lens */
    if (cls > 0)
        return lp__trace_checked(lens, r, o, v3(b->px[j], b->py[j], b->pz[j]),
                                 v3(b->dx[j], b->dy[j], b->dz[j]),
                                 v3(b->vx[j], b->vy[j], b->vz[j]), a, out, err);
    lp_vec3 d, vp;
    lp_status st = lp__ray_check(r, &d, &vp, err);
    if (st != LP_OK)
        return st;
    return lp__trace_checked(lens, r, o, lp__to_local_point(lens, r->origin),
                             lp__to_local_dir(lens, d), lp__to_local_dir(lens, vp), a, out, err);
}

lp_status lp_trace_forward_soa(const lp_lens *lens, double lambda_nm, const lp_ray_soa *in,
                               size_t n, const lp_trace_args *args, lp_result *out,
                               size_t *offsets, lp_error *err)
{
    lp_trace_args a;
    lp__optics o;
    lp_status st;
    block b;

    if (!lens || !out || !offsets || (n > 0 && !in))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_trace_forward_soa: NULL argument");
    if (n > 0 && (!in->ox || !in->oy || !in->oz || !in->dx || !in->dy || !in->dz || !in->vx ||
                  !in->vy || !in->vz || !in->intensity))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "lp_trace_forward_soa: NULL origin, direction, field or intensity array");
    lp_result_clear(out);
    if ((st = lp__args_resolve(args, &a, err)) != LP_OK)
        return st;
    if ((st = lp__optics_at(lens, lambda_nm, &o, err)) != LP_OK)
        return st;
    /* the lane engine's scratch; without it every ray takes the one-ray
     * code, with the same results */
    lp__lanes *L = lp__lanes_create(a.max_depth);
    for (size_t i0 = 0; i0 < n; i0 += BLOCK) {
        size_t m = n - i0 < BLOCK ? n - i0 : BLOCK;
        load_block(lens, in, i0, m, &b);
        if (L) {
            for (size_t j = 0; j < m; j++) {
                lp_ray r = ray_at(in, i0 + j, lambda_nm);
                b.take[j] = lane_class(&r, &b, j) > 0;
            }
            lp__lane_in li = {b.px, b.py, b.pz, b.dx, b.dy, b.dz, b.vx, b.vy, b.vz,
                              in->intensity + i0, in->op ? in->op + i0 : NULL, b.take};
            lp__lanes_run(L, lens, &o, &a, &li, m);
        }
        for (size_t j = 0; j < m; j++) {
            size_t i = i0 + j;
            lp_ray r = ray_at(in, i, lambda_nm);
            offsets[i] = out->count;
            if ((st = trace_lane(lens, &o, &r, &b, L, j, &a, out, err)) != LP_OK) {
                lp__lanes_destroy(L);
                return lp__ray_failed(err, st, i);
            }
        }
    }
    lp__lanes_destroy(L);
    offsets[n] = out->count;
    lp__ok(err);
    return LP_OK;
}
