/* trace_forward.c -- one ray from the light through the lens.
 *
 * The entry node splits the ray into the external reflection and one
 * refracted ray; every later node on a cap sends one ray out and reflects
 * one back in (or only reflects it, under TIR), so the rays inside form a
 * chain and the outgoing rays branch off it, one per depth (paper, fig. 3).
 * Between nodes the field loses exp(-alpha s) of its power and gains the
 * optical path n s. */
#include <math.h>

#include "error.h"
#include "interface.h"
#include "trace.h"
#include "trace_crystal.h"
#include "trace_lanes.h"

lp_status lp__ray_check(const lp_ray *in, lp_vec3 *d, lp_vec3 *vp, lp_error *err)
{
    if (!v3_finite(in->origin))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "ray origin is not finite");
    if (!v3_finite(in->dir))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "ray direction is not finite");
    *d = v3_normalize(in->dir);
    if (d->x == 0.0 && d->y == 0.0 && d->z == 0.0)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "ray direction is the zero vector");
    if (!isfinite(in->intensity) || in->intensity < 0.0)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "ray intensity %g must be a finite number >= 0", in->intensity);
    if (!isfinite(in->op) || !isfinite(in->phase))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "ray op/phase is not finite");
    if (!v3_finite(in->vp) || !lp__perp_unit(in->vp, *d, vp))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "polarization vector must be finite and not parallel to the direction");
    return LP_OK;
}

lp_status lp__ray_failed(lp_error *err, lp_status st, size_t i)
{
    if (err) {
        lp_error e = *err;
        lp__fail(err, st, "ray %zu: %s", i, e.message);
    }
    return st;
}

/* Trace one ray; *o holds the optics at the wavelength *o_valid says
 * (NaN: none yet) and is recomputed only when the ray's differs. */
static lp_status trace_one(const lp_lens *lens, const lp_ray *in, const lp_trace_args *a,
                           lp__optics *o, double *o_valid, lp_result *res, lp_error *err)
{
    lp_vec3 dw = {0, 0, 0}, vpw = dw;
    lp_status st;

    if ((st = lp__ray_check(in, &dw, &vpw, err)) != LP_OK)
        return st;
    if (!(in->lambda_nm == *o_valid)) {
        *o_valid = NAN;
        if ((st = lp__optics_at(lens, in->lambda_nm, o, err)) != LP_OK)
            return st;
        *o_valid = in->lambda_nm;
    }
    return lp__trace_checked(lens, in, o, lp__to_local_point(lens, in->origin),
                             lp__to_local_dir(lens, dw), lp__to_local_dir(lens, vpw), a, res,
                             err);
}

lp_status lp__trace_checked(const lp_lens *lens, const lp_ray *in, const lp__optics *op,
                            lp_vec3 p, lp_vec3 d, lp_vec3 vp, const lp_trace_args *a,
                            lp_result *res, lp_error *err)
{
    lp__optics o = *op;
    lp__local_hit h;
    lp__node node;
    lp__branch refl, trans;
    lp_status st;

    if (!lp__lens_hit(lens, p, d, lp__lens_surface_at(lens, p), 0.0, INFINITY, &h))
        return LP_OK; /* missed: the lens received nothing */

    double I0 = in->intensity;
    res->in += I0;
    res->warnings |= o.warnings;
    if (h.surface == LP_SURFACE_RIM) {
        res->absorbed_rim += I0;
        return LP_OK;
    }

    lp__payload pl = {in->lambda_nm, in->kphi, in->op, in->phase, in->ch};
    lp__cvec3 E = cv3_real(vp, sqrt(I0));
    if (lens->desc.uniaxial)
        return lp__crystal_forward(lens, &o, a, &h, d, &E, &pl, res, err);
    int entry = h.surface, depth = 1;
    uint64_t path = 0;

    /* Node 1: from the medium into the glass. */
    int tir = lp__node_setup(&node, d, h.n, o.n_medium, o.n_glass, &E);
    res->nodes++;
    lp__amp amp;
    lp__node_project(&node, &E, &amp);
    lp__node_reflect_amp(&node, a->mode, &amp, &refl);
    {
        lp__payload pr = pl;
        pr.kphi += refl.flip;
        st = lp__leave(lens, a, res, &refl, h.p, &pr, 1, LP_KIND_REFLECT, h.surface, path | 1u, err);
        if (st != LP_OK)
            return st;
    }
    if (tir)
        return LP_OK;
    lp__node_transmit_amp(&node, a->mode, &amp, &trans);
    E = trans.E;
    d = trans.dir;
    p = h.p;
    int surface = h.surface;

    for (;;) {
        double power = cv3_norm2(E);
        if (depth >= a->max_depth || power < a->min_weight * I0) {
            res->truncated += power;
            break;
        }
        if (!lp__lens_hit(lens, p, d, surface, 0.0, INFINITY, &h)) {
            res->absorbed_rim += power; /* cannot happen on a closed surface */
            res->warnings |= LP_WARN_LEAK;
            break;
        }
        /* Along the segment: Beer-Lambert and the optical path. */
        if (o.alpha > 0.0) {
            /* amplitude 1 + m, m = expm1(-alpha t / 2); absorbed power
             * 1 - (1 + m)^2 = -m (2 + m), free of cancellation */
            double m = expm1(-0.5 * o.alpha * h.t);
            res->absorbed_glass += power * (-m * (2.0 + m));
            E = cv3_scale_real(E, 1.0 + m);
        }
        pl.op += o.n_glass * h.t;
        p = h.p;
        surface = h.surface;
        if (surface == LP_SURFACE_RIM) {
            res->absorbed_rim += cv3_norm2(E);
            break;
        }

        depth++;
        tir = lp__node_setup(&node, d, h.n, o.n_glass, o.n_medium, &E);
        res->nodes++;
        lp__node_project(&node, &E, &amp);
        if (!tir) {
            lp__node_transmit_amp(&node, a->mode, &amp, &trans);
            lp_kind kind = surface == entry ? LP_KIND_REFLECT : LP_KIND_TRANSMIT;
            st = lp__leave(lens, a, res, &trans, p, &pl, depth, kind, surface, path, err);
            if (st != LP_OK)
                return st;
        }
        lp__node_reflect_amp(&node, a->mode, &amp, &refl);
        E = refl.E;
        d = refl.dir;
        pl.kphi += refl.flip;
        path |= (uint64_t)1 << (depth - 1);
    }
    return LP_OK;
}

lp_status lp_trace_forward(const lp_lens *lens, const lp_ray *in, const lp_trace_args *args,
                           lp_result *out, lp_error *err)
{
    lp_trace_args a;
    lp_status st;

    if (!lens || !in || !out)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_trace_forward: NULL argument");
    lp_result_clear(out);
    if ((st = lp__args_resolve(args, &a, err)) != LP_OK)
        return st;
    lp__optics o;
    double o_valid = NAN;
    if ((st = trace_one(lens, in, &a, &o, &o_valid, out, err)) != LP_OK)
        return st;
    lp__ok(err);
    return LP_OK;
}

/* Runs of at least this many rays of one wavelength in
 * lp_trace_forward_many are traced as arrays (trace_batch.c). */
#define RUN_MIN 8

lp_status lp_trace_forward_many(const lp_lens *lens, const lp_ray *in, size_t n,
                                const lp_trace_args *args, lp_result *out, size_t *offsets,
                                lp_error *err)
{
    lp_trace_args a;
    lp_status st = LP_OK;

    if (!lens || (!in && n > 0) || !out || !offsets)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_trace_forward_many: NULL argument");
    lp_result_clear(out);
    if ((st = lp__args_resolve(args, &a, err)) != LP_OK)
        return st;
    lp__optics o; /* shared by consecutive rays of one wavelength */
    double o_valid = NAN;
    struct lp__lanes *L = NULL;
    for (size_t i = 0; i < n && st == LP_OK;) {
        size_t run = 1;
        while (i + run < n && in[i + run].lambda_nm == in[i].lambda_nm)
            run++;
        if (run >= RUN_MIN) {
            /* a run's optics, or (a bad wavelength) the ray by ray code
             * below, which words the error at the ray where it arises */
            lp__optics ro;
            if (lp__optics_at(lens, in[i].lambda_nm, &ro, NULL) == LP_OK) {
                st = lp__trace_run(lens, &ro, &a, in + i, run, i, out, offsets, &L, err);
                i += run;
                continue;
            }
        }
        offsets[i] = out->count;
        if ((st = trace_one(lens, &in[i], &a, &o, &o_valid, out, err)) != LP_OK)
            st = lp__ray_failed(err, st, i);
        i++;
    }
    lp__lanes_destroy(L);
    if (st != LP_OK)
        return st;
    offsets[n] = out->count;
    lp__ok(err);
    return LP_OK;
}
