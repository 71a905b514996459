/* trace_batch.c -- many rays of one wavelength: lp_trace_forward_soa, and
 * the runs of one wavelength in lp_trace_forward_many.
 *
 * The wavelength's optics are computed once.  The rays are taken in blocks
 * of LP__LANES: one loop over the block, free of branches and calls,
 * checks every ray, normalizes its direction and field direction, puts
 * them in the lens frame and tests the lens's bounding sphere; the
 * compiler vectorizes it across rays (this file is built with
 * -fno-trapping-math, which lets it compute the rejected cases' quotients
 * and drop them; no value changes).  The lane engine (trace_lanes.h) then
 * traces the block's rays; each ray's results are added in order, and a
 * ray the engine hands back (or refused by the check) is traced by the
 * one-ray code from the same numbers, so the result is the one
 * lp_trace_forward_many gives ray by ray, bit for bit. */
#include <math.h>
#include <string.h>

#include "error.h"
#include "trace.h"
#include "trace_lanes.h"

#define BLOCK LP__LANES

/* A block of rays: its payload (0 where an optional array is absent), and
 * the rays checked and in the lens frame. */
typedef struct block {
    double op[BLOCK], phase[BLOCK];
    int kphi[BLOCK];
    uint64_t ch[BLOCK];
    double px[BLOCK], py[BLOCK], pz[BLOCK]; /* local origin */
    double dx[BLOCK], dy[BLOCK], dz[BLOCK]; /* local unit direction */
    double vx[BLOCK], vy[BLOCK], vz[BLOCK]; /* local unit field direction */
    double good[BLOCK]; /* 1: valid (else the one-ray check words the error) */
    double take[BLOCK]; /* 1: valid and reaching the bounding sphere */
} block;

/* isfinite, as a comparison the loop can vectorize */
LP__INLINE int finite3(double x, double y, double z)
{
    return (fabs(x) <= DBL_MAX) & (fabs(y) <= DBL_MAX) & (fabs(z) <= DBL_MAX);
}

/* Rays i0 .. i0+m of in into b. */
LP__WIDE static void load_block(const lp_lens *lens, const lp_ray_soa *in, size_t i0, size_t m,
                       block *restrict b)
{
    const double *restrict ox = in->ox + i0, *restrict oy = in->oy + i0,
                           *restrict oz = in->oz + i0;
    const double *restrict dx = in->dx + i0, *restrict dy = in->dy + i0,
                           *restrict dz = in->dz + i0;
    const double *restrict vx = in->vx + i0, *restrict vy = in->vy + i0,
                           *restrict vz = in->vz + i0;
    const double *restrict intensity = in->intensity + i0;
    const lp_vec3 center = lens->bound_center;
    const double r2 = lens->bound_r2;

    for (size_t j = 0; j < m; j++) {
        b->op[j] = in->op ? in->op[i0 + j] : 0.0;
        b->phase[j] = in->phase ? in->phase[i0 + j] : 0.0;
        b->kphi[j] = in->kphi ? in->kphi[i0 + j] : 0;
        b->ch[j] = in->ch ? in->ch[i0 + j] : 0;
    }
    /* the one loop meant to be vectorized */
    for (size_t j = 0; j < m; j++) {
        lp_vec3 o = v3(ox[j], oy[j], oz[j]);
        lp_vec3 dir = v3(dx[j], dy[j], dz[j]);
        lp_vec3 v = v3(vx[j], vy[j], vz[j]);
        lp_vec3 d = v3_normalize(dir);
        double ok_vp, w = intensity[j];
        lp_vec3 vp = lp__perp_unit_core(v, d, &ok_vp);
        /* lp__ray_check's tests */
        int good = finite3(o.x, o.y, o.z) & finite3(dir.x, dir.y, dir.z) & (ok_vp != 0.0) &
                   ((dir.x != 0.0) | (dir.y != 0.0) | (dir.z != 0.0)) &
                   finite3(w, b->op[j], b->phase[j]) & (w >= 0.0) & finite3(v.x, v.y, v.z);
        /* the bounding sphere: outside it when cc > 0, then leaving it
         * when bb > 0, passing it by when bb^2 < cc */
        lp_vec3 oc = v3_sub(o, center);
        double bb = v3_dot(oc, d), cc = v3_dot(oc, oc) - r2;
        int miss = (cc > 0.0) & ((bb > 0.0) | (bb * bb < cc));
        b->good[j] = good ? 1.0 : 0.0;
        b->take[j] = good & !miss ? 1.0 : 0.0;
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

/* One ray of a block that the lane engine did not trace: by the one-ray
 * code from the block's numbers, or (a ray the block's check refused) by
 * the one-ray check, which words the error. */
static lp_status trace_one_ray(const lp_lens *lens, const lp__optics *o, const lp_ray_soa *in,
                               size_t i, const block *b, size_t j, const lp_trace_args *a,
                               lp_result *out, lp_error *err)
{
    if (b->good[j] != 0.0 && b->take[j] == 0.0)
        return LP_OK; /* misses the bounding sphere, so the lens */
    lp_ray r;
    r.origin = v3(in->ox[i], in->oy[i], in->oz[i]);
    r.dir = v3(in->dx[i], in->dy[i], in->dz[i]);
    r.lambda_nm = o->lambda_nm;
    r.intensity = in->intensity[i];
    r.vp = v3(in->vx[i], in->vy[i], in->vz[i]);
    r.kphi = b->kphi[j];
    r.op = b->op[j];
    r.phase = b->phase[j];
    r.ch = b->ch[j];
    if (b->good[j] != 0.0)
        return lp__trace_checked(lens, &r, o, v3(b->px[j], b->py[j], b->pz[j]),
                                 v3(b->dx[j], b->dy[j], b->dz[j]),
                                 v3(b->vx[j], b->vy[j], b->vz[j]), a, out, err);
    lp_vec3 d, vp;
    lp_status st = lp__ray_check(&r, &d, &vp, err);
    if (st != LP_OK)
        return st;
    return lp__trace_checked(lens, &r, o, lp__to_local_point(lens, r.origin),
                             lp__to_local_dir(lens, d), lp__to_local_dir(lens, vp), a, out, err);
}

/* Rays 0..n of in at the optics o: offsets[base + i], and an error names
 * ray base + i.  *L is the lane engine's scratch, made on first use (if
 * that fails, every ray takes the one-ray code, with the same results). */
static lp_status trace_arrays(const lp_lens *lens, const lp__optics *o, const lp_trace_args *a,
                              const lp_ray_soa *in, size_t n, size_t base, lp_result *out,
                              size_t *offsets, lp__lanes **L, lp_error *err)
{
    block b;
    lp_status st;

    if (!*L)
        *L = lp__lanes_create(a->max_depth);
    for (size_t i0 = 0; i0 < n; i0 += BLOCK) {
        size_t m = n - i0 < BLOCK ? n - i0 : BLOCK;
        load_block(lens, in, i0, m, &b);
        if (*L) {
            lp__lane_in li = {b.px, b.py, b.pz, b.dx, b.dy, b.dz, b.vx, b.vy, b.vz,
                              in->intensity + i0, b.op, b.take};
            lp__lanes_run(*L, lens, o, a, &li, m);
        }
        for (size_t j = 0; j < m; j++) {
            size_t i = i0 + j;
            offsets[base + i] = out->count;
            if (*L && lp__lanes_traced(*L, j)) {
                lp__payload pl = {o->lambda_nm, b.kphi[j], b.op[j], b.phase[j], b.ch[j]};
                st = lp__lanes_emit(*L, j, lens, a, in->intensity[i], &pl, out, err);
            } else {
                st = trace_one_ray(lens, o, in, i, &b, j, a, out, err);
            }
            if (st != LP_OK)
                return lp__ray_failed(err, st, base + i);
        }
    }
    return LP_OK;
}

lp_status lp__trace_run(const lp_lens *lens, const lp__optics *o, const lp_trace_args *a,
                        const lp_ray *in, size_t n, size_t base, lp_result *out, size_t *offsets,
                        lp__lanes **L, lp_error *err)
{
    /* the records as arrays, a block at a time */
    double ox[BLOCK], oy[BLOCK], oz[BLOCK], dx[BLOCK], dy[BLOCK], dz[BLOCK];
    double vx[BLOCK], vy[BLOCK], vz[BLOCK], w[BLOCK], op[BLOCK], phase[BLOCK];
    int kphi[BLOCK];
    uint64_t ch[BLOCK];
    lp_ray_soa s = {ox, oy, oz, dx, dy, dz, vx, vy, vz, w, op, phase, kphi, ch};
    lp_status st;

    for (size_t i0 = 0; i0 < n; i0 += BLOCK) {
        size_t m = n - i0 < BLOCK ? n - i0 : BLOCK;
        for (size_t j = 0; j < m; j++) {
            const lp_ray *r = &in[i0 + j];
            ox[j] = r->origin.x, oy[j] = r->origin.y, oz[j] = r->origin.z;
            dx[j] = r->dir.x, dy[j] = r->dir.y, dz[j] = r->dir.z;
            vx[j] = r->vp.x, vy[j] = r->vp.y, vz[j] = r->vp.z;
            w[j] = r->intensity, op[j] = r->op, phase[j] = r->phase;
            kphi[j] = r->kphi, ch[j] = r->ch;
        }
        if ((st = trace_arrays(lens, o, a, &s, m, base + i0, out, offsets, L, err)) != LP_OK)
            return st;
    }
    return LP_OK;
}

lp_status lp_trace_forward_soa(const lp_lens *lens, double lambda_nm, const lp_ray_soa *in,
                               size_t n, const lp_trace_args *args, lp_result *out,
                               size_t *offsets, lp_error *err)
{
    lp_trace_args a;
    lp__optics o;
    lp_status st;

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
    lp__lanes *L = NULL;
    st = trace_arrays(lens, &o, &a, in, n, 0, out, offsets, &L, err);
    lp__lanes_destroy(L);
    if (st != LP_OK)
        return st;
    offsets[n] = out->count;
    lp__ok(err);
    return LP_OK;
}
