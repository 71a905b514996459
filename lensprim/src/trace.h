/* trace.h -- what forward and backward tracing share (internal). */
#ifndef LP_TRACE_H
#define LP_TRACE_H

#include "cvec3.h"
#include "error.h"
#include "lens_internal.h"
#include "polarization.h"
#include "result.h"

/* The lens's optics at one wavelength. */
typedef struct lp__optics {
    double lambda_nm;
    double n_glass, n_medium;
    double alpha;       /* absorption coefficient of the glass, 1/mm */
    unsigned warnings;  /* LP_WARN_EXTRAPOLATED */
} lp__optics;

lp_status lp__optics_at(const lp_lens *lens, double lambda_nm, lp__optics *o, lp_error *err);

/* Validate args (NULL gives the defaults) into *out. */
lp_status lp__args_resolve(const lp_trace_args *args, lp_trace_args *out, lp_error *err);

/* Does the application want an outgoing ray?  Applies flags and filter. */
int lp__args_keep(const lp_trace_args *a, const lp_branch_info *info);

/* The branch of the given depth, kind and surface leaving the lens's
 * local point p along the local direction dir with this bound, as the
 * application sees it (*info, in world space); nonzero when the flags and
 * filter keep it (lp__args_keep). */
int lp__branch_keep(const lp_lens *lens, const lp_trace_args *a, int depth, lp_kind kind,
                    int surface, lp_vec3 p, lp_vec3 dir, double bound, lp_branch_info *info);

/* The payload an outgoing field continues with. */
typedef struct lp__payload {
    double lambda_nm;
    int kphi;
    double op;
    double phase;   /* phase the field's complex amplitude is relative to */
    uint64_t ch;
} lp__payload;

/* Where an outgoing ray leaves: its local unit direction d, and its world
 * origin and direction. */
typedef struct lp__exit {
    lp_vec3 d;
    lp_vec3 world_origin, world_dir;
} lp__exit;

/* The exit of a ray leaving the lens's local point p along the local unit
 * direction d. */
lp__exit lp__exit_at(const lp_lens *lens, lp_vec3 p, lp_vec3 d);

/* Append the field E leaving the lens at x to res as one or two linear
 * rays.  Returns LP_ERROR_NO_MEMORY or LP_OK; adds their power to
 * res->out. */
lp_status lp__emit(const lp_lens *lens, lp_result *res, const lp__cvec3 *E, const lp__exit *x,
                   const lp__payload *pl, int depth, lp_kind kind, int surface, uint64_t path,
                   lp_error *err);

/* lp__emit for a field whose power cv3_norm2(*E) is known already. */
lp_status lp__emit_power(const lp_lens *lens, lp_result *res, const lp__cvec3 *E, double power,
                         const lp__exit *x, const lp__payload *pl, int depth, lp_kind kind,
                         int surface, uint64_t path, lp_error *err);

/* x wrapped into [-pi, pi] (x itself when it lies there already). */
static inline double lp__wrap_phase(double x)
{
    return fabs(x) <= LP_PI ? x : remainder(x, 2.0 * LP_PI);
}

/* Send one outgoing field (branch b, leaving the local point p) to the
 * result, or count its power as skipped when args' flags or filter
 * decline it. */
struct lp__branch;
lp_status lp__leave(const lp_lens *lens, const lp_trace_args *a, lp_result *res,
                    const struct lp__branch *b, lp_vec3 p, const lp__payload *pl, int depth,
                    lp_kind kind, int surface, uint64_t path, lp_error *err);


/* Store the outgoing ray k (intensity, world field direction vp, phase
 * relative to the payload's) of a field leaving at x, with the wave bits
 * `waves`, and add its power to res->out. */
static inline lp_status lp__emit_ray(lp_result *res, const lp__exit *x, const lp__payload *pl,
                                     int depth, lp_kind kind, int surface, uint64_t path,
                                     uint64_t waves, int k, double intensity, lp_vec3 vp,
                                     double phase, lp_error *err)
{
    lp_out_ray *o = lp__result_push(res);
    if (!o)
        return lp__fail(err, LP_ERROR_NO_MEMORY, "out of memory storing outgoing rays");
    o->ray.origin = x->world_origin;
    o->ray.dir = x->world_dir;
    o->ray.lambda_nm = pl->lambda_nm;
    o->ray.intensity = intensity;
    o->ray.vp = vp;
    o->ray.kphi = pl->kphi;
    o->ray.op = pl->op;
    o->ray.phase = lp__wrap_phase(pl->phase + phase);
    o->ray.ch = pl->ch;
    o->depth = depth;
    o->kind = kind;
    o->surface = surface;
    o->part = k;
    o->path = path;
    o->waves = waves;
    res->out += intensity;
    return LP_OK;
}

/* The linear parts part[0..n) of a field leaving at x as rays, each with
 * the wave bits `waves`. */
static inline lp_status lp__emit_linear(const lp_lens *lens, lp_result *res,
                                        const lp__linear_part *part, int n, const lp__exit *x,
                                        const lp__payload *pl, int depth, lp_kind kind,
                                        int surface, uint64_t path, uint64_t waves,
                                        lp_error *err)
{
    for (int k = 0; k < n; k++) {
        lp_status st = lp__emit_ray(res, x, pl, depth, kind, surface, path, waves, k,
                                    part[k].intensity, lp__to_world_dir(lens, part[k].vp),
                                    part[k].phase, err);
        if (st != LP_OK)
            return st;
    }
    return LP_OK;
}

/* The rays of field E (power `power`) leaving at x, each with the wave
 * bits `waves`: lp__emit_power and lp__emit_gathered in one pass. */
static inline lp_status lp__emit_parts(const lp_lens *lens, lp_result *res, const lp__cvec3 *E,
                                       double power, const lp__exit *x, const lp__payload *pl,
                                       int depth, lp_kind kind, int surface, uint64_t path,
                                       uint64_t waves, lp_error *err)
{
    lp__linear_part part[2];
    int n = lp__field_split(E, power, x->d, part);
    return lp__emit_linear(lens, res, part, n, x, pl, depth, kind, surface, path, waves, err);
}

/* The accounts of a gathered bundle ray of power `in` once its rays are
 * stored (res->out was `before`): `absorbed` went into the glass, the rest
 * not leaving is truncated. */
static inline void lp__gathered_rest(lp_result *res, double before, double in, double absorbed)
{
    res->absorbed_glass += absorbed;
    res->truncated += in - (res->out - before) - absorbed;
}

/* Emit the linear parts part[0..n) of a gathered field (of a bundle ray
 * of power `in`, of which `absorbed` went into the glass) as the rays of
 * query q, leaving the lens at x; the rest of `in` is counted as
 * truncated (inline: every gathered ray leaves by it). */
static inline lp_status lp__emit_gathered_parts(const lp_lens *lens, lp_result *res,
                                                const lp__linear_part *part, int n,
                                                const lp__exit *x, const lp__payload *pl,
                                                const lp_query *q, double in, double absorbed,
                                                lp_error *err)
{
    double before = res->out;
    lp_status st = lp__emit_linear(lens, res, part, n, x, pl, q->depth, q->kind, q->surface,
                                   q->path, q->waves, err);
    if (st != LP_OK)
        return st;
    lp__gathered_rest(res, before, in, absorbed);
    return LP_OK;
}

/* lp__emit_gathered_parts of the gathered field E. */
static inline lp_status lp__emit_gathered(const lp_lens *lens, lp_result *res,
                                          const lp__cvec3 *E, const lp__exit *x,
                                          const lp__payload *pl, const lp_query *q, double in,
                                          double absorbed, lp_error *err)
{
    lp__linear_part part[2];
    int n = lp__field_split(E, cv3_norm2(*E), x->d, part);
    return lp__emit_gathered_parts(lens, res, part, n, x, pl, q, in, absorbed, err);
}

/* lp__emit_gathered of a real field e (polarized, before any total
 * internal reflection), without its complex form: the same bits. */
static inline lp_status lp__emit_gathered_real(const lp_lens *lens, lp_result *res, lp_vec3 e,
                                               const lp__exit *x, const lp__payload *pl,
                                               const lp_query *q, double in, double absorbed,
                                               lp_error *err)
{
    lp__linear_part part[2];
    int n = lp__field_split_real(e, v3_dot(e, e), x->d, part);
    return lp__emit_gathered_parts(lens, res, part, n, x, pl, q, in, absorbed, err);
}

/* The unit vector along the part of v perpendicular to the unit d; *ok
 * is 0.0 when there is none (v parallel to d, zero or not finite), else
 * 1.0.  Free of
 * branches, for loops over many rays. */
static inline lp_vec3 lp__perp_unit_core(lp_vec3 v, lp_vec3 d, double *ok)
{
    lp_vec3 w = v3_sub(v, v3_scale(d, v3_dot(v, d)));
    double l = v3_len(w), lv = v3_len(v);
    *ok = l > 1e-12 * lv ? lp__finite(l) : 0.0;
    return v3_scale(w, 1.0 / l);
}

/* Make v a unit vector perpendicular to the unit d; 0 if impossible. */
static inline int lp__perp_unit(lp_vec3 v, lp_vec3 d, lp_vec3 *out)
{
    double ok;
    lp_vec3 u = lp__perp_unit_core(v, d, &ok);
    if (ok == 0.0)
        return 0;
    *out = u;
    return 1;
}

/* Report in err what is wrong with a bundle ray that fails
 * lp__bundle_ray_check (LP_ERROR_INVALID_ARGUMENT): its intensity, op or
 * phase (what 0), or its polarization (what 1). */
void lp__bundle_ray_fail(int what, lp_error *err);

/* Check a bundle ray of lp_backward_gather and give its field direction
 * in the lens frame, perpendicular to the local light direction (inline:
 * every gathered ray is checked). */
static inline lp_status lp__bundle_ray_check(const lp_lens *lens, const lp_ray *b,
                                             lp_vec3 light, lp_vec3 *vp, lp_error *err)
{
    if (!isfinite(b->intensity) || b->intensity < 0.0 || !isfinite(b->op) ||
        !isfinite(b->phase)) {
        lp__bundle_ray_fail(0, err);
        return LP_ERROR_INVALID_ARGUMENT;
    }
    if (!v3_finite(b->vp) || !lp__perp_unit(lp__to_local_dir(lens, b->vp), light, vp)) {
        lp__bundle_ray_fail(1, err);
        return LP_ERROR_INVALID_ARGUMENT;
    }
    return LP_OK;
}

/* Check a forward input ray: its unit direction *d and the unit field
 * direction *vp perpendicular to it (world). */
lp_status lp__ray_check(const lp_ray *in, lp_vec3 *d, lp_vec3 *vp, lp_error *err);

/* Prefix the message in err with "ray i: " and return st (batch calls). */
lp_status lp__ray_failed(lp_error *err, lp_status st, size_t i);

/* Trace the records in[0..n) of one wavelength, whose optics are o, as
 * lp_trace_forward_many does: offsets[base + i] = out->count before ray
 * i, and an error names ray base + i.  *L is the lane engine's scratch
 * (trace_lanes.h), made on first use; the caller destroys it. */
struct lp__lanes;
lp_status lp__trace_run(const lp_lens *lens, const lp__optics *o, const lp_trace_args *a,
                        const lp_ray *in, size_t n, size_t base, lp_result *out, size_t *offsets,
                        struct lp__lanes **L, lp_error *err);

/* Trace a checked ray (lp__ray_check) at the optics o of its wavelength:
 * local origin p, local unit direction d, local unit field direction vp;
 * its intensity and payload from *in.  Adds to res (not cleared). */
lp_status lp__trace_checked(const lp_lens *lens, const lp_ray *in, const lp__optics *o,
                            lp_vec3 p, lp_vec3 d, lp_vec3 vp, const lp_trace_args *a,
                            lp_result *res, lp_error *err);

#endif
