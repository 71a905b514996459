/* trace_common.c -- wavelength set-up, argument checks and emitting
 * outgoing rays, shared by forward and backward tracing. */
#include <math.h>

#include "error.h"
#include "glass_internal.h"
#include "polarization.h"
#include "result.h"
#include "trace.h"
#include "interface.h"

lp_status lp__optics_at(const lp_lens *lens, double lambda_nm, lp__optics *o, lp_error *err)
{
    const lp_lens_desc *d = &lens->desc;
    if (!isfinite(lambda_nm) || !(lambda_nm > 0.0))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "wavelength %g nm must be a finite number > 0", lambda_nm);
    /* a crystal's ordinary glass stands for it here (trace_crystal.c
     * adds the extraordinary one) */
    const lp_glass *g = d->uniaxial ? &d->crystal.ordinary : &d->glass;
    o->lambda_nm = lambda_nm;
    o->n_glass = lp_glass_index(g, lambda_nm);
    o->n_medium = lp_glass_index(&d->medium, lambda_nm);
    o->alpha = lp__glass_absorption_ln(g, lens->ln_tau, lambda_nm);
    if (!isfinite(o->n_glass) || !(o->n_glass > 0.0))
        return lp__fail(err, LP_ERROR_INVALID_GLASS, "glass %s has no valid index at %g nm",
                        g->name, lambda_nm);
    if (!isfinite(o->n_medium) || !(o->n_medium > 0.0))
        return lp__fail(err, LP_ERROR_INVALID_GLASS,
                        "medium %s has no valid index at %g nm", d->medium.name, lambda_nm);
    if (!isfinite(o->alpha) || o->alpha < 0.0)
        o->alpha = 0.0;
    o->warnings = 0;
    if (!lp_glass_covers(g, lambda_nm) || !lp_glass_covers(&d->medium, lambda_nm))
        o->warnings |= LP_WARN_EXTRAPOLATED;
    return LP_OK;
}

void lp_trace_args_init(lp_trace_args *args)
{
    if (!args)
        return;
    args->mode = LP_MODE_POLARIZED;
    args->max_depth = 5;
    args->min_weight = 0.0;
    args->flags = 0;
    args->filter = NULL;
    args->user = NULL;
}

lp_status lp__args_resolve(const lp_trace_args *args, lp_trace_args *out, lp_error *err)
{
    if (!args) {
        lp_trace_args_init(out);
        return LP_OK;
    }
    *out = *args;
    if (args->mode != LP_MODE_POLARIZED && args->mode != LP_MODE_FRESNEL &&
        args->mode != LP_MODE_SCHLICK)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "unknown mode %d", (int)args->mode);
    if (args->max_depth < 1 || args->max_depth > LP_MAX_DEPTH)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "depth %d must be in 1..%d",
                        args->max_depth, LP_MAX_DEPTH);
    if (!(args->min_weight >= 0.0) || !isfinite(args->min_weight))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "min_weight %g must be a finite number >= 0", args->min_weight);
    return LP_OK;
}

int lp__args_keep(const lp_trace_args *a, const lp_branch_info *info)
{
    if (info->kind == LP_KIND_REFLECT) {
        if (a->flags & LP_SKIP_REFLECTED)
            return 0;
        if ((a->flags & LP_SKIP_EXTERNAL_REFLECTION) && info->depth == 1)
            return 0;
    }
    return a->filter ? a->filter(info, a->user) != 0 : 1;
}

int lp__branch_keep(const lp_lens *lens, const lp_trace_args *a, int depth, lp_kind kind,
                    int surface, lp_vec3 p, lp_vec3 dir, double bound, lp_branch_info *info)
{
    info->depth = depth;
    info->kind = kind;
    info->surface = surface;
    info->origin = lp__to_world_point(lens, p);
    info->dir = lp__to_world_dir(lens, dir);
    info->bound = bound;
    return lp__args_keep(a, info);
}

lp__exit lp__exit_at(const lp_lens *lens, lp_vec3 p, lp_vec3 d)
{
    lp__exit x = {d, lp__to_world_point(lens, p), lp__to_world_dir(lens, d)};
    return x;
}

lp_status lp__emit_power(const lp_lens *lens, lp_result *res, const lp__cvec3 *E, double power,
                         const lp__exit *x, const lp__payload *pl, int depth, lp_kind kind,
                         int surface, uint64_t path, lp_error *err)
{
    return lp__emit_parts(lens, res, E, power, x, pl, depth, kind, surface, path, 0, err);
}

lp_status lp__emit(const lp_lens *lens, lp_result *res, const lp__cvec3 *E, const lp__exit *x,
                   const lp__payload *pl, int depth, lp_kind kind, int surface, uint64_t path,
                   lp_error *err)
{
    return lp__emit_power(lens, res, E, cv3_norm2(*E), x, pl, depth, kind, surface, path, err);
}

/* Send one outgoing field to the result, or count it as skipped. */
lp_status lp__leave(const lp_lens *lens, const lp_trace_args *a, lp_result *res,
                    const lp__branch *b, lp_vec3 p, const lp__payload *pl, int depth,
                    lp_kind kind, int surface, uint64_t path, lp_error *err)
{
    lp_branch_info info;
    lp__exit x = lp__exit_at(lens, p, b->dir);
    double power = cv3_norm2(b->E);

    info.depth = depth;
    info.kind = kind;
    info.surface = surface;
    info.origin = x.world_origin;
    info.dir = x.world_dir;
    info.bound = power;
    if (!lp__args_keep(a, &info)) {
        res->skipped += power;
        return LP_OK;
    }
    return lp__emit_power(lens, res, &b->E, power, &x, pl, depth, kind, surface, path, err);
}

void lp__bundle_ray_fail(int what, lp_error *err)
{
    if (what == 0)
        lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                 "bundle ray intensity, op and phase must be finite (intensity >= 0)");
    else
        lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                 "bundle ray polarization must be finite and not parallel to the query ray");
}
