/* cone.c -- the cone K of rim-free initial directions, and its collimated
 * counterpart, the rim-free region of a parallel beam's entry points.
 *
 * A direction is tested on the library's own chain: lp_backward_build
 * traces the view ray's internal chain and lp_backward_rim_depth says
 * whether it met the rim.  Along one azimuth the set of rim-free polar
 * angles starts at the axis; its first end is found by a uniform scan of
 * the bracket and a bisection of the scan step where the first failure
 * happens.  Everything is computed in the lens's local frame and given to
 * the chain in the world frame. */
#include <math.h>
#include <string.h>

#include "error.h"
#include "lens_internal.h"
#include "vec3.h"

#define SCAN_STEPS_MAX 1000000

void lp_cone_args_init(lp_cone_args *args)
{
    if (!args)
        return;
    args->max_depth = 5;
    args->lambda_nm = 587.56;
    args->tolerance = 1e-9;
    args->scan_steps = 2048;
    args->frame = LP_FRAME_LOCAL;
}

static lp_status resolve(const lp_cone_args *args, lp_cone_args *out, lp_error *err)
{
    if (!args) {
        lp_cone_args_init(out);
        return LP_OK;
    }
    *out = *args;
    if (args->max_depth < 1 || args->max_depth > LP_MAX_DEPTH)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "depth %d must be in 1..%d",
                        args->max_depth, LP_MAX_DEPTH);
    if (!isfinite(args->lambda_nm) || !(args->lambda_nm > 0.0))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "wavelength %g nm must be a finite number > 0", args->lambda_nm);
    if (!isfinite(args->tolerance) || !(args->tolerance > 0.0))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "tolerance %g must be a finite number > 0", args->tolerance);
    if (args->scan_steps < 1 || args->scan_steps > SCAN_STEPS_MAX)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "scan_steps %d must be in 1..%d",
                        args->scan_steps, SCAN_STEPS_MAX);
    if (args->frame != LP_FRAME_LOCAL && args->frame != LP_FRAME_WORLD)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "unknown frame %d", (int)args->frame);
    return LP_OK;
}

/* One test of the chain: the local ray p + s d. */
typedef struct chain_test {
    const lp_lens *lens;
    lp_backward *bw;
    lp_trace_args targs;
    double lambda_nm;
} chain_test;

static lp_status chain_free(chain_test *c, lp_vec3 p, lp_vec3 d, int *ok, lp_error *err)
{
    lp_vec3 o = lp__to_world_point(c->lens, p), w = lp__to_world_dir(c->lens, d);
    lp_status st = lp_backward_build(c->bw, c->lens, o, w, c->lambda_nm, &c->targs, err);
    if (st != LP_OK)
        return st;
    *ok = 0;
    if (lp_backward_rim_depth(c->bw) != 0 || lp_backward_query_count(c->bw) == 0)
        return LP_OK; /* the rim, or no entry node (the ray missed) */
    /* A chain that found no surface is reported through the gather's
     * warnings; gathering nothing reads them. */
    lp_result r;
    lp_result_init(&r);
    st = lp_backward_gather(c->bw, 0, NULL, 0, &r, err);
    if (st != LP_OK)
        return st;
    *ok = !(r.warnings & LP_WARN_LEAK);
    return LP_OK;
}

static lp_status chain_open(chain_test *c, const lp_lens *lens, const lp_cone_args *a,
                            lp_error *err)
{
    c->lens = lens;
    c->lambda_nm = a->lambda_nm;
    lp_trace_args_init(&c->targs);
    c->targs.max_depth = a->max_depth;
    c->targs.mode = LP_MODE_FRESNEL; /* the chain's geometry is the same in every mode */
    c->bw = NULL;
    return lp_backward_create(&c->bw, err);
}

static void chain_close(chain_test *c)
{
    lp_backward_destroy(c->bw);
    c->bw = NULL;
}

/* A line of tests parametrized by x >= 0: the local ray of parameter x. */
typedef struct line {
    int beam;       /* 0: directions from apex at polar angle x; 1: parallel rays at offset x */
    lp_vec3 apex;   /* local */
    lp_vec3 axis;   /* local, unit */
    lp_vec3 e;      /* local, unit, perpendicular to axis: the azimuth's direction */
    double back;    /* beam: how far behind the entry plane the rays start */
} line;

static void line_ray(const line *l, double x, lp_vec3 *p, lp_vec3 *d)
{
    if (l->beam) {
        *d = l->axis;
        *p = v3_madd(v3_madd(l->apex, l->e, x), l->axis, -l->back);
    } else {
        *p = l->apex;
        *d = v3_normalize(v3_add(v3_scale(l->axis, cos(x)), v3_scale(l->e, sin(x))));
    }
}

/* The end of the rim-free interval that starts at x = 0, in [0, hi]. */
static lp_status line_limit(chain_test *c, const line *l, double hi, const lp_cone_args *a,
                            double *out, lp_error *err)
{
    lp_vec3 p, d;
    int ok;
    lp_status st;

    line_ray(l, 0.0, &p, &d);
    if ((st = chain_free(c, p, d, &ok, err)) != LP_OK)
        return st;
    if (!ok) {
        *out = 0.0;
        return LP_OK;
    }
    double good = 0.0, bad = -1.0;
    for (int j = 1; j <= a->scan_steps; j++) {
        double x = hi * (double)j / (double)a->scan_steps;
        line_ray(l, x, &p, &d);
        if ((st = chain_free(c, p, d, &ok, err)) != LP_OK)
            return st;
        if (!ok) {
            bad = x;
            break;
        }
        good = x;
    }
    if (bad < 0.0) {
        *out = hi; /* rim-free over the whole bracket */
        return LP_OK;
    }
    while (bad - good > a->tolerance) {
        double mid = 0.5 * (good + bad);
        if (!(mid > good && mid < bad))
            break; /* the bracket is one ulp wide */
        line_ray(l, mid, &p, &d);
        if ((st = chain_free(c, p, d, &ok, err)) != LP_OK)
            return st;
        if (ok)
            good = mid;
        else
            bad = mid;
    }
    *out = good;
    return LP_OK;
}

/* The local centre and radius of a sphere holding the whole lens. */
static void bounding_sphere(const lp_lens *lens, lp_vec3 *centre, double *radius)
{
    double hz = 0.5 * (lens->z_max - lens->z_min);
    *centre = v3(0.0, 0.0, 0.5 * (lens->z_max + lens->z_min));
    *radius = sqrt(lens->h_max * lens->h_max + hz * hz) * (1.0 + 1e-9) + lens->eps;
}

/* The unit vector along the part of local x (or y) perpendicular to axis. */
static lp_vec3 azimuth_ref(lp_vec3 axis)
{
    lp_vec3 r = v3_sub(v3(1, 0, 0), v3_scale(axis, axis.x));
    if (v3_len(r) < 1e-6)
        r = v3_sub(v3(0, 1, 0), v3_scale(axis, axis.y));
    return v3_normalize(r);
}

static lp_vec3 out_point(const lp_lens *lens, const lp_cone_args *a, lp_vec3 p)
{
    return a->frame == LP_FRAME_WORLD ? lp__to_world_point(lens, p) : p;
}

static lp_vec3 out_dir(const lp_lens *lens, const lp_cone_args *a, lp_vec3 d)
{
    return a->frame == LP_FRAME_WORLD ? lp__to_world_dir(lens, d) : d;
}

/* The cone's local frame and scan bracket. */
typedef struct cone_setup {
    lp_cone_args a;
    lp_vec3 apex, axis, ref, ref2; /* local */
    double hi;                     /* polar angles beyond hi miss the lens */
} cone_setup;

static lp_status cone_setup_make(const lp_lens *lens, lp_vec3 point, const lp_cone_args *args,
                                 cone_setup *s, lp_error *err)
{
    lp_status st;
    if (!lens)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "cone: NULL lens");
    if ((st = resolve(args, &s->a, err)) != LP_OK)
        return st;
    if (!v3_finite(point))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "the point is not finite");
    lp_vec3 p = s->a.frame == LP_FRAME_WORLD ? lp__to_local_point(lens, point) : point;
    if (!v3_finite(p))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "the point is not finite");
    if (lp_lens_contains(lens, lp__to_world_point(lens, p)))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "the point (%g, %g, %g) lies inside the glass", p.x, p.y, p.z);
    double dist = v3_len(p);
    if (!(dist > lens->eps))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "the point is the front vertex, so the cone has no axis");
    s->apex = p;
    s->axis = v3_normalize(v3_neg(p));
    s->ref = azimuth_ref(s->axis);
    s->ref2 = v3_cross(s->axis, s->ref);

    lp_vec3 c;
    double rad;
    bounding_sphere(lens, &c, &rad);
    lp_vec3 pc = v3_sub(c, p);
    double lc = v3_len(pc);
    if (lc <= rad) {
        s->hi = LP_PI;
    } else {
        double cosb = v3_dot(pc, s->axis) / lc;
        double beta = acos(fmax(-1.0, fmin(1.0, cosb)));
        s->hi = fmin(LP_PI, beta + asin(rad / lc));
    }
    return LP_OK;
}

static lp_vec3 azimuth_dir(lp_vec3 ref, lp_vec3 ref2, double phi)
{
    return v3_normalize(v3_add(v3_scale(ref, cos(phi)), v3_scale(ref2, sin(phi))));
}

static void frame_out(const lp_lens *lens, const lp_cone_args *a, lp_vec3 apex, lp_vec3 axis,
                      lp_vec3 ref, lp_cone_frame *f)
{
    f->apex = out_point(lens, a, apex);
    f->axis = out_dir(lens, a, axis);
    f->ref = out_dir(lens, a, ref);
}

lp_status lp_rim_free(const lp_lens *lens, lp_vec3 origin, lp_vec3 dir, const lp_cone_args *args,
                      int *rim_free, lp_error *err)
{
    lp_cone_args a;
    chain_test c;
    lp_status st;

    if (!lens || !rim_free)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_rim_free: NULL argument");
    if ((st = resolve(args, &a, err)) != LP_OK)
        return st;
    if (!v3_finite(origin) || !v3_finite(dir))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_rim_free: the ray is not finite");
    lp_vec3 p = a.frame == LP_FRAME_WORLD ? lp__to_local_point(lens, origin) : origin;
    lp_vec3 d = v3_normalize(a.frame == LP_FRAME_WORLD ? lp__to_local_dir(lens, dir) : dir);
    if (d.x == 0.0 && d.y == 0.0 && d.z == 0.0)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_rim_free: zero direction");
    if ((st = chain_open(&c, lens, &a, err)) != LP_OK)
        return st;
    st = chain_free(&c, p, d, rim_free, err);
    chain_close(&c);
    if (st == LP_OK)
        lp__ok(err);
    return st;
}

lp_status lp_cone_frame_of(const lp_lens *lens, lp_vec3 point, const lp_cone_args *args,
                           lp_cone_frame *out, lp_error *err)
{
    cone_setup s;
    lp_status st;
    if (!out)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_cone_frame_of: NULL argument");
    if ((st = cone_setup_make(lens, point, args, &s, err)) != LP_OK)
        return st;
    frame_out(lens, &s.a, s.apex, s.axis, s.ref, out);
    lp__ok(err);
    return LP_OK;
}

static lp_status cone_theta(const cone_setup *s, chain_test *c, double phi, double *theta,
                            lp_error *err)
{
    line l;
    if (!isfinite(phi))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "azimuth %g is not finite", phi);
    l.beam = 0;
    l.apex = s->apex;
    l.axis = s->axis;
    l.e = azimuth_dir(s->ref, s->ref2, phi);
    l.back = 0.0;
    return line_limit(c, &l, s->hi, &s->a, theta, err);
}

lp_status lp_cone_theta(const lp_lens *lens, lp_vec3 point, double azimuth,
                        const lp_cone_args *args, double *theta, lp_error *err)
{
    cone_setup s;
    chain_test c;
    lp_status st;
    if (!theta)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_cone_theta: NULL argument");
    if ((st = cone_setup_make(lens, point, args, &s, err)) != LP_OK)
        return st;
    if ((st = chain_open(&c, lens, &s.a, err)) != LP_OK)
        return st;
    st = cone_theta(&s, &c, azimuth, theta, err);
    chain_close(&c);
    if (st == LP_OK)
        lp__ok(err);
    return st;
}

lp_status lp_cone_compute(const lp_lens *lens, lp_vec3 point, const lp_cone_args *args, size_t n,
                          double *theta, lp_cone *out, lp_error *err)
{
    cone_setup s;
    chain_test c;
    lp_status st;
    if (!theta || !out || n == 0)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "lp_cone_compute: NULL argument or no azimuths");
    if ((st = cone_setup_make(lens, point, args, &s, err)) != LP_OK)
        return st;
    if ((st = chain_open(&c, lens, &s.a, err)) != LP_OK)
        return st;
    double omega = 0.0, tmin = INFINITY, tmax = -INFINITY;
    for (size_t k = 0; k < n && st == LP_OK; k++) {
        double phi = 2.0 * LP_PI * (double)k / (double)n;
        st = cone_theta(&s, &c, phi, &theta[k], err);
        if (st != LP_OK)
            break;
        /* 1 - cos t = 2 sin^2(t/2), without cancellation for small t */
        double h = sin(0.5 * theta[k]);
        omega += 2.0 * h * h;
        tmin = fmin(tmin, theta[k]);
        tmax = fmax(tmax, theta[k]);
    }
    chain_close(&c);
    if (st != LP_OK)
        return st;
    memset(out, 0, sizeof *out);
    frame_out(lens, &s.a, s.apex, s.axis, s.ref, &out->frame);
    out->depth = s.a.max_depth;
    out->solid_angle = omega * 2.0 * LP_PI / (double)n;
    out->theta_min = tmin;
    out->theta_max = tmax;
    lp__ok(err);
    return LP_OK;
}

lp_status lp_beam_region_compute(const lp_lens *lens, lp_vec3 dir, const lp_cone_args *args,
                                 size_t n, double *radius, lp_beam_region *out, lp_error *err)
{
    lp_cone_args a;
    chain_test c;
    lp_status st;
    if (!lens || !radius || !out || n == 0)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "lp_beam_region_compute: NULL argument or no azimuths");
    if ((st = resolve(args, &a, err)) != LP_OK)
        return st;
    if (!v3_finite(dir))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "beam: the direction is not finite");
    lp_vec3 d = v3_normalize(a.frame == LP_FRAME_WORLD ? lp__to_local_dir(lens, dir) : dir);
    if (d.x == 0.0 && d.y == 0.0 && d.z == 0.0)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "beam: the direction is the zero vector");

    lp_vec3 centre;
    double rad;
    bounding_sphere(lens, &centre, &rad);
    /* the distance of the sphere's centre from the ray through the vertex */
    double along = v3_dot(centre, d);
    double delta = v3_len(v3_madd(centre, d, -along));
    line l;
    l.beam = 1;
    l.apex = v3(0, 0, 0);
    l.axis = d;
    l.back = fabs(along) + 2.0 * rad + 1.0;
    lp_vec3 ref = azimuth_ref(d), ref2 = v3_cross(d, ref);
    double hi = delta + rad;

    if ((st = chain_open(&c, lens, &a, err)) != LP_OK)
        return st;
    double area = 0.0, rmin = INFINITY, rmax = -INFINITY;
    for (size_t k = 0; k < n; k++) {
        double phi = 2.0 * LP_PI * (double)k / (double)n;
        l.e = azimuth_dir(ref, ref2, phi);
        if ((st = line_limit(&c, &l, hi, &a, &radius[k], err)) != LP_OK)
            break;
        area += radius[k] * radius[k];
        rmin = fmin(rmin, radius[k]);
        rmax = fmax(rmax, radius[k]);
    }
    chain_close(&c);
    if (st != LP_OK)
        return st;
    memset(out, 0, sizeof *out);
    frame_out(lens, &a, l.apex, d, ref, &out->frame);
    out->depth = a.max_depth;
    out->area = area * LP_PI / (double)n;
    out->radius_min = rmin;
    out->radius_max = rmax;
    lp__ok(err);
    return LP_OK;
}
