/* extinction.c -- the empty polarizing microscope's leak against its
 * numerical aperture, traced and predicted (extinction.h). */
#include "extinction.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lensrender/lensrender.h"

#define EXT_PI 3.14159265358979323846

static double dot(lp_vec3 a, lp_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static lp_vec3 add(lp_vec3 a, lp_vec3 b, double k)
{
    return (lp_vec3){a.x + k * b.x, a.y + k * b.y, a.z + k * b.z};
}
static lp_vec3 unit(lp_vec3 a)
{
    double l = sqrt(dot(a, a));
    return (lp_vec3){a.x / l, a.y / l, a.z / l};
}

void ext_system_free(ext_system *sys)
{
    for (int i = 0; i < sys->n; i++)
        lp_lens_destroy(sys->lens[i]);
    sys->n = 0;
}

int ext_system_from_scene(const char *path, double lambda_nm, ext_system *sys, char *msg,
                          size_t msg_size)
{
    lr_scene *scene = NULL;
    lr_error err;
    const rs_scene *sc = NULL;
    const rs_object *pol[2] = {NULL, NULL};
    int n_pol = 0, rc = -1;

    memset(sys, 0, sizeof *sys);
    sys->lambda_nm = lambda_nm;
    if (lr_scene_load(path, NULL, &scene, &err) != LR_OK) {
        snprintf(msg, msg_size, "%s", err.message);
        goto done;
    }
    sc = lr_scene_description(scene);
    for (size_t j = 0; j < sc->n_objects; j++)
        if (sc->objects[j].type == RS_OBJ_POLARIZER && n_pol++ < 2)
            pol[n_pol - 1] = &sc->objects[j];
    if (n_pol != 2) {
        snprintf(msg, msg_size, "%s: %d polarizers; an instrument has two", path, n_pol);
        goto done;
    }
    lp_vec3 cam = sc->camera.location;
    double z0 = pol[0]->u.polarizer.center.z, z1 = pol[1]->u.polarizer.center.z;
    int first = fabs(z0 - cam.z) > fabs(z1 - cam.z) ? 0 : 1;
    const rs_object *P = pol[first], *A = pol[1 - first];
    for (int k = 0; k < 2; k++) {
        lp_vec3 nrm = unit(pol[k]->u.polarizer.normal);
        if (fabs(fabs(nrm.z) - 1) > 1e-12 || fabs(pol[k]->u.polarizer.axis.z) > 1e-12) {
            snprintf(msg, msg_size, "%s: a polarizer not normal to the z axis", path);
            goto done;
        }
    }
    sys->pol_axis = unit(P->u.polarizer.axis);
    sys->ana_axis = unit(A->u.polarizer.axis);
    if (fabs(dot(sys->pol_axis, sys->ana_axis)) > 1e-12) {
        snprintf(msg, msg_size, "%s: the polarizer and the analyzer are not crossed", path);
        goto done;
    }
    sys->z_start = P->u.polarizer.center.z;
    sys->dir_z = A->u.polarizer.center.z < sys->z_start ? -1.0 : 1.0;
    double zlo = fmin(z0, z1), zhi = fmax(z0, z1);
    for (size_t j = 0; j < sc->n_objects; j++) {
        const rs_object *o = &sc->objects[j];
        if (o->type != RS_OBJ_LENS)
            continue;
        lp_lens_desc d;
        lp_lens_get_desc(o->lens, &d);
        if (!(d.position.z > zlo && d.position.z < zhi))
            continue;
        if (d.uniaxial) {
            snprintf(msg, msg_size, "%s: a crystal between the polarizers: not an empty instrument",
                     path);
            goto done;
        }
        if (sys->n == EXT_LENS_MAX) {
            snprintf(msg, msg_size, "%s: more than %d lenses", path, EXT_LENS_MAX);
            goto done;
        }
        lp_error lerr;
        if (lp_lens_create(&d, &sys->lens[sys->n], &lerr) != LP_OK) {
            snprintf(msg, msg_size, "%s: %s", path, lerr.message);
            goto done;
        }
        sys->n++;
    }
    if (sys->n == 0) {
        snprintf(msg, msg_size, "%s: no lens between the polarizers", path);
        goto done;
    }
    rc = 0;
done:
    if (rc != 0)
        ext_system_free(sys);
    lr_scene_free(scene);
    return rc;
}

/* The lens the ray meets first, or -1. */
static int next_lens(const ext_system *sys, lp_vec3 o, lp_vec3 d, lp_hit *hit)
{
    int best = -1;
    double t = INFINITY;
    for (int i = 0; i < sys->n; i++) {
        lp_hit h;
        if (lp_lens_intersect(sys->lens[i], o, d, 1e-9, t, &h)) {
            t = h.t;
            *hit = h;
            best = i;
        }
    }
    return best;
}

/* Snell's law at a surface of normal nrm (either side) from n1 to n2;
 * the power-normalized amplitude transmissions into *ts, *tp.  0, or -1
 * for total internal reflection. */
static int refract(lp_vec3 d, lp_vec3 nrm, double n1, double n2, lp_vec3 *out, double *ts,
                   double *tp)
{
    double ci = -dot(d, nrm);
    if (ci < 0) {
        nrm = (lp_vec3){-nrm.x, -nrm.y, -nrm.z};
        ci = -ci;
    }
    double r = n1 / n2, k = 1 - r * r * (1 - ci * ci);
    if (k < 0)
        return -1;
    double ct = sqrt(k);
    *out = unit(add((lp_vec3){r * d.x, r * d.y, r * d.z}, nrm, r * ci - ct));
    double as = 2 * n1 * ci / (n1 * ci + n2 * ct), ap = 2 * n1 * ci / (n2 * ci + n1 * ct);
    double g = n2 * ct / (n1 * ci);
    *ts = as * sqrt(g);
    *tp = ap * sqrt(g);
    return 0;
}

/* The predicted field factors P, S (with the glass's absorption, which
 * is the same for both), the exit direction and the steepest sine of the
 * geometric trace. */
static int predict(const ext_system *sys, lp_vec3 o, lp_vec3 d, double *P, double *S,
                   lp_vec3 *dout, double *smax)
{
    *P = *S = 1;
    *smax = 0;
    for (int step = 0; step < 2 * EXT_LENS_MAX; step++) {
        lp_hit h;
        int i = next_lens(sys, o, d, &h);
        if (i < 0)
            break;
        if (h.surface == LP_SURFACE_RIM)
            return -1;
        lp_lens_desc desc;
        lp_lens_get_desc(sys->lens[i], &desc);
        double n = lp_glass_index(&desc.glass, sys->lambda_nm);
        double m = lp_glass_index(&desc.medium, sys->lambda_nm);
        double ts, tp;
        if (refract(d, h.normal, m, n, &d, &ts, &tp) != 0)
            return -1;
        *P *= tp;
        *S *= ts;
        lp_hit h2;
        if (!lp_lens_intersect(sys->lens[i], h.point, d, 1e-9, INFINITY, &h2) ||
            h2.surface == LP_SURFACE_RIM)
            return -1;
        /* the glass's absorption along the segment, the same for s and p */
        double tau = exp(-0.5 * lp_glass_absorption(&desc.glass, sys->lambda_nm) * h2.t);
        *P *= tau;
        *S *= tau;
        if (refract(d, h2.normal, n, m, &d, &ts, &tp) != 0)
            return -1;
        *P *= tp;
        *S *= ts;
        o = h2.point;
        *smax = fmax(*smax, sqrt(d.x * d.x + d.y * d.y));
    }
    *dout = d;
    return 0;
}

int ext_ray_compute(const ext_system *sys, double h, double phi, ext_ray *out, char *msg,
                    size_t msg_size)
{
    /* the polarizer axis p and the in-plane perpendicular q = z x p */
    lp_vec3 p = sys->pol_axis, q = {-p.y, p.x, 0};
    lp_vec3 rhat = add((lp_vec3){cos(phi) * p.x, cos(phi) * p.y, 0}, q, sin(phi));
    lp_vec3 o = {h * rhat.x, h * rhat.y, sys->z_start};
    lp_vec3 d = {0, 0, sys->dir_z};

    /* predicted */
    double P, S, smax;
    lp_vec3 dout;
    if (predict(sys, o, d, &P, &S, &dout, &smax) != 0)
        return -1;
    double cb = fabs(dout.z), c = cos(phi), s = sin(phi);
    out->s = smax;
    out->cross_p = pow(0.5 * sin(2 * phi) * (P * cb - S), 2);
    out->par_p = pow(P * c * c * cb + S * s * s, 2);

    /* traced: the library's polarized forward trace, lens after lens */
    lp_ray r;
    memset(&r, 0, sizeof r);
    r.origin = o;
    r.dir = d;
    r.lambda_nm = sys->lambda_nm;
    r.intensity = 1;
    r.vp = p;
    lp_trace_args a;
    lp_trace_args_init(&a);
    a.mode = LP_MODE_POLARIZED;
    a.max_depth = 2;
    a.flags = LP_SKIP_REFLECTED;
    lp_result res;
    lp_result_init(&res);
    int rc = 0;
    for (int step = 0; step < 2 * EXT_LENS_MAX && rc == 0; step++) {
        lp_hit hit;
        int i = next_lens(sys, r.origin, r.dir, &hit);
        if (i < 0)
            break;
        lp_error err;
        if (lp_trace_forward(sys->lens[i], &r, &a, &res, &err) != LP_OK) {
            snprintf(msg, msg_size, "lens %d: %s", i, err.message);
            rc = -1;
            break;
        }
        int found = 0;
        for (size_t k = 0; k < res.count; k++)
            if (res.rays[k].kind == LP_KIND_TRANSMIT && res.rays[k].depth == 2 &&
                res.rays[k].part == 0) {
                r = res.rays[k].ray;
                found = 1;
            }
        if (!found) {
            snprintf(msg, msg_size, "the ray at h = %g is stopped in lens %d", h, i);
            rc = -1;
        }
    }
    lp_result_release(&res);
    if (rc != 0)
        return -1;
    /* the field E = sqrt(I) vp (a linear field: no TIR on this path) */
    double amp = sqrt(r.intensity);
    double ea = amp * dot(r.vp, sys->ana_axis), ep = amp * dot(r.vp, p);
    out->cross_t = ea * ea;
    out->par_t = ep * ep;
    return 0;
}

int ext_height_of_na(const ext_system *sys, double na, double h_max, double *h)
{
    char msg[256];
    ext_ray r;
    /* scan up from the axis: every ray below the one found passes */
    const int steps = 512;
    double lo = 0, hi = -1;
    for (int k = 1; k <= steps; k++) {
        double hk = h_max * k / steps;
        if (ext_ray_compute(sys, hk, 0.0, &r, msg, sizeof msg) != 0)
            return -1; /* stopped before reaching na */
        if (r.s >= na) {
            hi = hk;
            break;
        }
        lo = hk;
    }
    if (hi < 0)
        return -1;
    for (int k = 0; k < 100 && hi - lo > 1e-13 * h_max; k++) {
        double mid = 0.5 * (lo + hi);
        if (ext_ray_compute(sys, mid, 0.0, &r, msg, sizeof msg) != 0)
            return -1;
        if (r.s >= na)
            hi = mid;
        else
            lo = mid;
    }
    *h = 0.5 * (lo + hi);
    return 0;
}

int ext_point_compute(const ext_system *sys, double na, double h_max, int rings, int azimuths,
                      ext_point *out, char *msg, size_t msg_size)
{
    double h;
    memset(out, 0, sizeof *out);
    out->na = na;
    if (rings < 1 || azimuths < 5) {
        snprintf(msg, msg_size, "rings >= 1 and azimuths >= 5 (got %d, %d)", rings, azimuths);
        return -1;
    }
    if (ext_height_of_na(sys, na, h_max, &h) != 0) {
        snprintf(msg, msg_size, "no ray within h <= %g mm reaches NA %g", h_max, na);
        return -1;
    }
    out->h = h;
    double ct = 0, pt = 0, cp = 0, pp = 0;
    for (int i = 0; i < rings; i++) {
        double hi = h * sqrt((i + 0.5) / rings); /* equal areas */
        for (int k = 0; k < azimuths; k++) {
            ext_ray r;
            if (ext_ray_compute(sys, hi, 2 * EXT_PI * (k + 0.5) / azimuths, &r, msg, msg_size) !=
                0)
                return -1;
            ct += r.cross_t;
            pt += r.par_t;
            cp += r.cross_p;
            pp += r.par_p;
        }
    }
    out->leak_t = ct / pt;
    out->leak_p = cp / pp;
    ext_ray r;
    if (ext_ray_compute(sys, h, EXT_PI / 4, &r, msg, msg_size) != 0)
        return -1;
    out->rim_t = r.cross_t / r.par_t;
    out->rim_p = r.cross_p / r.par_p;
    return 0;
}
