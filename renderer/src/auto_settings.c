/* auto_settings.c -- the choice of --mode auto (see auto_settings.h). */
#include "auto_settings.h"

#include "args.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera.h"
#include "shapes.h"

#define SHARE_MODEL 0.3   /* of E: fresnel's departure from polarized */
#define SHARE_CUTOFF 0.1  /* of E: the radiance one dropped branch may carry */
#define PROBE_N 16        /* the probe's wavelength pair: N and 2N */
#define PROBE_GLASS 48    /* probe pixels seeing glass first, at least */
#define PROBE_OTHER 16    /* and the others */
#define PROBE_FRACTION 64 /* or one in this many of each group */
#define WAVELENGTHS_MAX 1024
#define P_MIN 0.5
#define P_MAX 1.0

static double cmax(rs_color c)
{
    return fmax(c.r, fmax(c.g, c.b));
}

/* Does the scene need the polarized model?  why: the reason, or NULL. */
static const char *needs_polarized(const rs_scene *s)
{
    for (size_t i = 0; i < s->n_objects; i++)
        if (s->objects[i].type == RS_OBJ_POLARIZER)
            return "the scene has a polarizer";
    for (size_t k = 0; k < s->n_lights; k++)
        if (s->lights[k].polarized)
            return "the scene has a polarized light";
    if (s->settings.coherent)
        return "the scene is coherent";
    for (size_t k = 0; k < s->n_lights; k++)
        if (s->lights[k].coherent)
            return "the scene has a coherent light";
    return NULL;
}

/* Do rays of some source add as amplitudes? */
static int coherent(const rs_scene *s)
{
    if (s->settings.coherent)
        return 1;
    for (size_t k = 0; k < s->n_lights; k++)
        if (s->lights[k].coherent)
            return 1;
    return 0;
}

/* An upper bound of the radiance any ray can bring back (per band, before
 * colour conversion): the background, or the brightest surface -- its
 * emission, its ambient term and its diffuse response to every light at
 * normal incidence.  A lens path only attenuates (its bound is <= 1). */
static double radiance_max(const rs_scene *s)
{
    double lights = 0.0, best = cmax(s->background);
    for (size_t k = 0; k < s->n_lights; k++)
        lights += cmax(s->lights[k].color);
    for (size_t i = 0; i < s->n_objects; i++) {
        const rs_object *o = &s->objects[i];
        double pig = 0.0;
        if (o->type == RS_OBJ_LENS || o->type == RS_OBJ_POLARIZER)
            continue;
        for (int c = 0; c < 2; c++)
            pig = fmax(pig, cmax(o->pigment.color[c]));
        double l = cmax(o->finish.emission) * pig +
                   cmax(o->finish.ambient) * cmax(s->settings.ambient_light) * pig +
                   o->finish.diffuse * pig * lights;
        best = fmax(best, l);
    }
    return best > 0.0 ? best : 1.0;
}

/* Render the probe pixels with opts into out[0..n). */
static int probe(const rs_scene *s, const rs_render_opts *opts, const int *px, size_t n,
                 rs_color *out, char *msg, size_t msg_size)
{
    rs_integrator *it;
    rs_worker *w;
    if (rs_integrator_create(s, opts, &it, msg, msg_size) != 0)
        return -1;
    w = rs_worker_create(it);
    if (!w) {
        rs_integrator_destroy(it);
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    for (size_t k = 0; k < n; k++)
        rs_integrator_pixel(it, w, px[2 * k], px[2 * k + 1], &out[k]);
    rs_worker_destroy(w);
    rs_integrator_destroy(it);
    return 0;
}

/* The probe: pixels whose camera ray meets a lens or a polarizer first
 * (where wavelengths and the model matter), and the others, each group
 * a regular subsample with its share of the image, so that an RMS over
 * the probe estimates the RMS over the image. */
typedef struct probe_set {
    int *px;         /* 2 per pixel: i, j; group 0 first */
    size_t n[2];     /* pixels in each group */
    double share[2]; /* the group's share of the image's pixels */
} probe_set;

static int probe_pick(const rs_scene *s, int width, int height, probe_set *ps, char *msg,
                      size_t msg_size)
{
    rs_view view;
    long count[2] = {0, 0}, total = (long)width * height;
    long every[2];
    if (rs_camera_setup(&s->camera, width, height, &view, msg, msg_size) != 0)
        return -1;
    unsigned char *glass = malloc((size_t)total);
    if (!glass) {
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    for (int j = 0; j < height; j++)
        for (int i = 0; i < width; i++) {
            lp_vec3 o, d;
            rs_hit h;
            int g = 1;
            rs_camera_ray(&view, i + 0.5, j + 0.5, width, height, &o, &d);
            if (rs_scene_intersect(s, o, d, 0.0, INFINITY, -1, &h) &&
                (s->objects[h.object].type == RS_OBJ_LENS ||
                 s->objects[h.object].type == RS_OBJ_POLARIZER))
                g = 0;
            glass[(long)j * width + i] = (unsigned char)g;
            count[g]++;
        }
    /* Every k-th pixel of each group, in scan order. */
    for (int g = 0; g < 2; g++) {
        long want = g == 0 ? PROBE_GLASS : PROBE_OTHER;
        want = want > count[g] / PROBE_FRACTION ? want : count[g] / PROBE_FRACTION;
        every[g] = want > 0 && count[g] > want ? count[g] / want : 1;
        ps->share[g] = (double)count[g] / (double)total;
    }
    ps->px = malloc(sizeof *ps->px * 2 * (size_t)total);
    if (!ps->px) {
        free(glass);
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    size_t at = 0;
    for (int g = 0; g < 2; g++) {
        long seen = 0;
        ps->n[g] = 0;
        for (long k = 0; k < total; k++) {
            if (glass[k] != g || seen++ % every[g] != 0)
                continue;
            ps->px[2 * at] = (int)(k % width);
            ps->px[2 * at + 1] = (int)(k / width);
            at++;
            ps->n[g]++;
        }
    }
    free(glass);
    return 0;
}

/* RMS difference over the image, estimated from the probe. */
static double rms_diff(const probe_set *ps, const rs_color *a, const rs_color *b)
{
    double total = 0.0;
    size_t k = 0;
    for (int g = 0; g < 2; g++) {
        double s = 0.0;
        for (size_t m = 0; m < ps->n[g]; m++, k++) {
            double dr = a[k].r - b[k].r, dg = a[k].g - b[k].g, db = a[k].b - b[k].b;
            s += dr * dr + dg * dg + db * db;
        }
        if (ps->n[g])
            total += ps->share[g] * s / (3.0 * (double)ps->n[g]);
    }
    return sqrt(total);
}

int rs_auto_choose(const rs_scene *scene, const rs_auto_request *req, rs_render_opts *out,
                   char *why, size_t why_size, char *msg, size_t msg_size)
{
    const double E = req->tolerance;
    const char *pol_reason = needs_polarized(scene);
    double lmax = radiance_max(scene), d_model = 0.0, d1, d2, e_wl, p, k_wl, e_at, d_low[2], budget;
    int rc = -1;
    size_t n;
    probe_set ps = {NULL, {0, 0}, {0, 0}};
    rs_color *a = NULL, *b = NULL, *c = NULL;
    rs_render_opts o;

    rs_render_opts_init(&o);
    o.width = req->width;
    o.height = req->height;
    o.depth = req->depth > 0 ? req->depth : (E >= 1e-3 ? 16 : 32);
    /* The cut-off as a budget: an incoherent branch of weight w carries at
     * most w lmax; a coherent one adds up to 2 sqrt(w) lmax through its
     * cross term with a ray of weight 1, so there the weight is squared. */
    budget = SHARE_CUTOFF * E / lmax;
    o.cutoff = req->cutoff >= 0.0 ? req->cutoff
               : coherent(scene)   ? 0.25 * budget * budget
                                   : fmin(1.0, budget);

    if (probe_pick(scene, req->width, req->height, &ps, msg, msg_size) != 0)
        return -1;
    n = ps.n[0] + ps.n[1];
    a = malloc(sizeof *a * (n + 1));
    b = malloc(sizeof *b * (n + 1));
    c = malloc(sizeof *c * (n + 1));
    if (!a || !b || !c) {
        snprintf(msg, msg_size, "out of memory");
        goto done;
    }

    /* Polarized at N, 2N and 4N: how the wavelength error falls; fresnel
     * at 2N: the model's departure. */
    o.mode = RS_MODE_POLARIZED;
    o.wavelengths = PROBE_N;
    if (probe(scene, &o, ps.px, n, a, msg, msg_size) != 0)
        goto done;
    o.wavelengths = 2 * PROBE_N;
    if (probe(scene, &o, ps.px, n, b, msg, msg_size) != 0)
        goto done;
    d1 = rms_diff(&ps, a, b);
    o.wavelengths = 4 * PROBE_N;
    if (probe(scene, &o, ps.px, n, a, msg, msg_size) != 0)
        goto done;
    d2 = rms_diff(&ps, a, b);
    /* Below the probe's N the error is measured, not extrapolated: 4 and
     * 8 wavelengths against 2N (b). */
    o.wavelengths = PROBE_N / 4;
    if (probe(scene, &o, ps.px, n, a, msg, msg_size) != 0)
        goto done;
    d_low[0] = rms_diff(&ps, a, b);
    o.wavelengths = PROBE_N / 2;
    if (probe(scene, &o, ps.px, n, a, msg, msg_size) != 0)
        goto done;
    d_low[1] = rms_diff(&ps, a, b);
    if (!pol_reason) {
        rs_render_opts f = o;
        f.mode = RS_MODE_FRESNEL;
        f.wavelengths = 2 * PROBE_N;
        if (probe(scene, &f, ps.px, n, c, msg, msg_size) != 0)
            goto done;
        d_model = rms_diff(&ps, b, c);
        if (d_model <= SHARE_MODEL * E)
            o.mode = RS_MODE_FRESNEL;
    }
    /* The change from N to 2N falls as N^-p; the error of N is the sum of
     * all later changes, d(N) / (1 - 2^-p).  p from the two measured
     * changes, kept within [P_MIN, P_MAX] (1: steps; less where many
     * steps crowd a pixel's spectrum). */
    e_wl = E - SHARE_CUTOFF * E - (o.mode == RS_MODE_FRESNEL ? d_model : 0.0);
    p = d1 > 0.0 && d2 > 0.0 ? log2(d1 / d2) : P_MAX;
    p = p < P_MIN ? P_MIN : p > P_MAX ? P_MAX : p;
    k_wl = d2 / (1.0 - pow(2.0, -p)); /* the error at 4 PROBE_N */
    /* Measured errors below 4N: that of 2N is k_wl (the error of 4N) plus
     * the change from 2N to 4N, and so on down. */
    const int cand_n[4] = {PROBE_N / 4, PROBE_N / 2, PROBE_N, 2 * PROBE_N};
    const double cand_e[4] = {d_low[0] + k_wl + d2, d_low[1] + k_wl + d2, d1 + k_wl + d2,
                              k_wl + d2};
    int pick = -1;
    for (int k = 0; k < 4 && pick < 0; k++)
        if (cand_e[k] <= e_wl || (req->wavelengths > 0 && req->wavelengths <= cand_n[k]))
            pick = k;
    if (req->wavelengths > 0 && (pick < 0 || req->wavelengths != cand_n[pick])) {
        o.wavelengths = req->wavelengths;
        e_at = o.wavelengths >= 4 * PROBE_N
                   ? k_wl * pow((double)o.wavelengths / (4.0 * PROBE_N), -p)
                   : pick >= 0 ? cand_e[pick] : k_wl;
    } else if (pick >= 0) {
        o.wavelengths = cand_n[pick];
        e_at = cand_e[pick];
    } else {
        double nw = 4.0 * PROBE_N * pow(k_wl / e_wl, 1.0 / p);
        o.wavelengths = nw > WAVELENGTHS_MAX ? WAVELENGTHS_MAX : (int)ceil(nw);
        e_at = k_wl * pow((double)o.wavelengths / (4.0 * PROBE_N), -p);
    }
    {
        char model[160];
        if (pol_reason)
            snprintf(model, sizeof model, "%s", pol_reason);
        else
            snprintf(model, sizeof model, "fresnel departs from polarized by %.2g, %s 30 %% of E",
                     d_model, o.mode == RS_MODE_FRESNEL ? "within" : "over");
        snprintf(why, why_size,
                 "%s, %d wavelengths, depth %d, cut-off %.3g for E = %.3g: %s; "
                 "wavelength error %.2g%s (falls as N^-%.2f on %zu probe pixels); "
                 "a dropped branch carries < %.2g",
                 rs_mode_name(o.mode), o.wavelengths, o.depth, o.cutoff, E, model, e_at,
                 e_at > e_wl ? ", over E: more wavelengths than the limit would be needed" : "",
                 p, n, SHARE_CUTOFF * E);
    }
    *out = o;
    rc = 0;
done:
    free(ps.px);
    free(a);
    free(b);
    free(c);
    return rc;
}
