/* auto_settings.c -- the choice of --mode auto (see auto_settings.h for
 * the rule). */
#include "auto_settings.h"

#include "args.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera.h"
#include "shapes.h"

#define SHARE_MODEL 0.5   /* of E: fresnel's departure from polarized */
#define SHARE_CUTOFF 0.1  /* of E: the radiance one dropped branch may carry */
#define SHARE_TREE 0.2    /* of E: what the cut-off drops, measured */
#define CUT_FIRST 0.01    /* the cut-off ladder's first rung */
#define CUT_STEP 0.1      /* and its step */
#define DEPTH_MIN 16      /* the depth, unless the scene asks for more */
#define SAFETY 2.0        /* error of N <= SAFETY x the change from N to 2N */
#define N_FIRST 4         /* the ladder's first rung */
#define PROBE_LENS 24     /* probe pixels seeing a lens, at least */
#define PROBE_OTHER 8     /* and the others */
#define EVERY_LENS 4      /* or one in this many of the lens group */
#define EVERY_OTHER 32    /* and of the others */
#define PROBE_MAX 1024    /* but at most this many of each group */
#define LENS_SHARE_MAX 16 /* and lens pixels at most one in this many of all */
#define WAVELENGTHS_MAX RS_ARGS_WAVELENGTHS_MAX /* what lensrender takes */
#define PILOT_STEP 2      /* the pilot renders one pixel of each 2 x 2 cell */
#define PILOT_MAX 4096    /* and at most this many (larger cells beyond) */
#define PILOT_MIN 192     /* but at least this many: every pixel of a small image */
#define MARK_MIN 6        /* marked pixels of each kind, at least */
#define MARK_EVERY 64     /* or one in this many of the pilot's */
#define MARK_MAX 256      /* but at most this many */
#define P_MIN 0.5         /* the extrapolation's exponent, clamped */
#define P_MAX 2.0
#define LAMBDA_BLUE 400.0 /* the span over which dispersion is reported */
#define LAMBDA_RED 700.0

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
    for (size_t i = 0; i < s->n_objects; i++)
        if (s->objects[i].type == RS_OBJ_LENS && s->objects[i].u.lens.desc.uniaxial)
            return "the scene has a crystal lens (birefringence)";
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

/* The largest n(400 nm) - n(700 nm) of the scene's lenses (a crystal's
 * ordinary index), and how many lenses there are. */
static double dispersion_max(const rs_scene *s, int *n_lenses)
{
    double best = 0.0;
    *n_lenses = 0;
    for (size_t i = 0; i < s->n_objects; i++) {
        const lp_lens_desc *d;
        const lp_glass *g;
        if (s->objects[i].type != RS_OBJ_LENS)
            continue;
        d = &s->objects[i].u.lens.desc;
        g = d->uniaxial ? &d->crystal.ordinary : &d->glass;
        (*n_lenses)++;
        double dn = fabs(lp_glass_index(g, LAMBDA_BLUE) - lp_glass_index(g, LAMBDA_RED));
        if (dn == dn)
            best = fmax(best, dn);
    }
    return best;
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

/* The probe: the pixels the pilots mark (below), then the pixels whose
 * camera ray meets a lens (directly or through polarizers, which are thin
 * sheets: where wavelengths and the model matter), and the others, each
 * unmarked group a regular subsample with its share of the image, so that
 * an RMS over the probe estimates the RMS over the image.  A regular
 * subsample misses the few pixels that can carry most of an error: the
 * brightest (crossed_polarizers at 16 x 12: 4 of 192 pixels carry 98 % of
 * what the cut-off 1e-3 drops) and the most saturated (at 4 wavelengths:
 * on mirror_ball 3 pixels of its coloured rings carry all the error, on
 * plan_view 2 pixels).  A cheap pilot of the image finds them (pilot_mark): the
 * brightest and, where it renders in rgb, the most saturated pixels are
 * marked and rendered in every probe, a group of their own with its
 * share. */
enum { G_MARKED, G_LENS, G_OTHER, N_GROUPS };

typedef struct probe_set {
    int *px;                /* 2 per pixel: i, j; G_MARKED first */
    size_t n[N_GROUPS];     /* pixels in each group */
    double share[N_GROUPS]; /* the group's share of the image's pixels */
    double lens_share;      /* of the pixels whose camera ray meets a lens */
    double pop[N_GROUPS];   /* the pixels each group's probe pixels stand for */
} probe_set;

/* Does the camera ray (o, d) meet a lens, through at most a few
 * polarizers? */
static int sees_lens(const rs_scene *s, lp_vec3 o, lp_vec3 d)
{
    double t = 0.0;
    int skip = -1;
    for (int k = 0; k < 8; k++) {
        rs_hit h;
        if (!rs_scene_intersect(s, o, d, t, INFINITY, skip, &h))
            return 0;
        if (s->objects[h.object].type == RS_OBJ_LENS)
            return 1;
        if (s->objects[h.object].type != RS_OBJ_POLARIZER)
            return 0;
        t = h.t;
        skip = h.object;
    }
    return 0;
}

/* Render the n pixels px[2k], px[2k + 1] with opts into out[0..n); count
 * the wavelength samples in *samples. */
static int render_pixels(const rs_scene *s, const rs_render_opts *opts, const int *px,
                         size_t n, rs_color *out, double *samples, char *msg, size_t msg_size)
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
    *samples += (double)n * (opts->mode == RS_MODE_RGB ? 1 : opts->wavelengths);
    return 0;
}

typedef struct scored {
    double v;
    long k; /* the pixel */
} scored;

static int cmp_scored(const void *a, const void *b)
{
    const scored *x = a, *y = b;
    /* larger first; ties in scan order */
    return x->v != y->v ? (x->v < y->v) - (x->v > y->v) : (x->k > y->k) - (x->k < y->k);
}

/* Mark in mark[] the pilot pixels of the `want` largest scores. */
static void mark_top(scored *sc, size_t n, size_t want, unsigned char *mark)
{
    qsort(sc, n, sizeof *sc, cmp_scored);
    for (size_t m = 0; m < n && m < want; m++)
        if (sc[m].v > 0.0)
            mark[sc[m].k] = 1;
}

/* The pilot (see probe_set): the middle pixel of every step x step cell
 * of the image, rendered with base in rgb -- brightness and saturation
 * at the cost of one lane -- or, where the scene needs the polarized
 * model (rgb does not see what polarizers do), polarized at one
 * wavelength: brightness only.  The brightest and the most saturated are
 * marked in mark[] (by pixel); each stands for its cell. */
static int pilot_mark(const rs_scene *s, const rs_render_opts *base, int polarized, int step,
                      unsigned char *mark, double *samples, char *msg, size_t msg_size)
{
    int width = base->width, height = base->height;
    int nx = (width + step - 1) / step, ny = (height + step - 1) / step;
    size_t n = (size_t)nx * (size_t)ny, want;
    int *px = malloc(sizeof *px * 2 * n);
    rs_color *c = malloc(sizeof *c * n);
    scored *sc = malloc(sizeof *sc * n);
    int rc = -1;
    rs_render_opts f = *base;
    if (!px || !c || !sc) {
        snprintf(msg, msg_size, "out of memory");
        goto out;
    }
    /* the middle of each step x step cell */
    for (size_t m = 0; m < n; m++) {
        int i = (int)(m % (size_t)nx) * step + step / 2, j = (int)(m / (size_t)nx) * step + step / 2;
        px[2 * m] = i < width ? i : width - 1;
        px[2 * m + 1] = j < height ? j : height - 1;
    }
    want = n / MARK_EVERY > MARK_MIN ? n / MARK_EVERY : MARK_MIN;
    want = want < MARK_MAX ? want : MARK_MAX;
    f.mode = polarized ? RS_MODE_POLARIZED : RS_MODE_RGB;
    f.wavelengths = 1;
    if (render_pixels(s, &f, px, n, c, samples, msg, msg_size) != 0)
        goto out;
    for (int pass = 0; pass < (polarized ? 1 : 2); pass++) {
        for (size_t m = 0; m < n; m++) {
            double hi = cmax(c[m]), lo = fmin(c[m].r, fmin(c[m].g, c[m].b));
            sc[m].v = pass == 0 ? hi : hi - lo;
            sc[m].k = (long)px[2 * m + 1] * width + px[2 * m];
            if (!(sc[m].v == sc[m].v))
                sc[m].v = 0.0;
        }
        mark_top(sc, n, want, mark);
    }
    rc = 0;
out:
    free(px);
    free(c);
    free(sc);
    return rc;
}

static int probe_pick(const rs_scene *s, const rs_render_opts *base, int polarized,
                      probe_set *ps, double *samples, char *msg, size_t msg_size)
{
    rs_view view;
    int width = base->width, height = base->height;
    long count[N_GROUPS] = {0, 0, 0}, total = (long)width * height;
    long every[N_GROUPS];
    int step = PILOT_STEP;
    while ((long)((width + step - 1) / step) * ((height + step - 1) / step) > PILOT_MAX)
        step++;
    if ((long)((width + step - 1) / step) * ((height + step - 1) / step) < PILOT_MIN)
        step = 1;
    if (rs_camera_setup(&s->camera, width, height, &view, msg, msg_size) != 0)
        return -1;
    unsigned char *group = malloc((size_t)total);
    unsigned char *mark = calloc((size_t)total, 1);
    if (!group || !mark) {
        free(group);
        free(mark);
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    if (pilot_mark(s, base, polarized, step, mark, samples, msg, msg_size) != 0) {
        free(group);
        free(mark);
        return -1;
    }
    for (int j = 0; j < height; j++)
        for (int i = 0; i < width; i++) {
            lp_vec3 o, d;
            long k = (long)j * width + i;
            rs_camera_ray(&view, i + 0.5, j + 0.5, width, height, &o, &d);
            int lens = sees_lens(s, o, d);
            int g = mark[k] ? G_MARKED : lens ? G_LENS : G_OTHER;
            group[k] = (unsigned char)g;
            count[g]++;
            ps->lens_share += lens ? 1.0 / (double)total : 0.0;
        }
    /* A marked pixel stands for its pilot cell (at most what there is);
     * the other groups share the rest in proportion. */
    {
        double marked = fmin(1.0, (double)count[G_MARKED] * step * step / (double)total);
        long rest = count[G_LENS] + count[G_OTHER];
        ps->share[G_MARKED] = marked;
        for (int g = G_LENS; g < N_GROUPS; g++)
            ps->share[g] = rest > 0 ? (1.0 - marked) * (double)count[g] / (double)rest : 0.0;
        for (int g = 0; g < N_GROUPS; g++)
            ps->pop[g] = ps->share[g] * (double)total;
    }
    /* Every marked pixel; every k-th pixel of each other group, in scan
     * order. */
    every[G_MARKED] = 1;
    for (int g = G_LENS; g < N_GROUPS; g++) {
        long want = g == G_LENS ? PROBE_LENS : PROBE_OTHER;
        long part = count[g] / (g == G_LENS ? EVERY_LENS : EVERY_OTHER);
        want = want > part ? want : part;
        want = want < PROBE_MAX ? want : PROBE_MAX;
        if (g == G_LENS && want > total / LENS_SHARE_MAX)
            want = total / LENS_SHARE_MAX > PROBE_LENS ? total / LENS_SHARE_MAX : PROBE_LENS;
        every[g] = want > 0 && count[g] > want ? count[g] / want : 1;
    }
    ps->px = malloc(sizeof *ps->px * 2 * (size_t)total);
    if (!ps->px) {
        free(group);
        free(mark);
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    size_t at = 0;
    for (int g = 0; g < N_GROUPS; g++) {
        long seen = 0;
        ps->n[g] = 0;
        for (long k = 0; k < total; k++) {
            /* start half a stride in: the first pixel of a group is its
             * corner, rarely typical */
            if (group[k] != g || (seen++ + every[g] / 2) % every[g] != 0)
                continue;
            ps->px[2 * at] = (int)(k % width);
            ps->px[2 * at + 1] = (int)(k / width);
            at++;
            ps->n[g]++;
        }
    }
    free(group);
    free(mark);
    return 0;
}

/* Render the probe pixels with opts into out[0..n). */
static int probe(const rs_scene *s, const rs_render_opts *opts, const probe_set *ps,
                 rs_color *out, double *samples, char *msg, size_t msg_size)
{
    return render_pixels(s, opts, ps->px, ps->n[G_MARKED] + ps->n[G_LENS] + ps->n[G_OTHER],
                         out, samples, msg, msg_size);
}

/* RMS difference over the image, estimated from the probe: each group's
 * mean square, plus one standard error of it where the group is a
 * subsample (a few pixels that differ much more than the others are
 * what a subsample most often under-counts). */
static double rms_diff(const probe_set *ps, const rs_color *a, const rs_color *b)
{
    double total = 0.0;
    size_t k = 0;
    for (int g = 0; g < N_GROUPS; g++) {
        double s = 0.0, s2 = 0.0, n = (double)ps->n[g];
        for (size_t m = 0; m < ps->n[g]; m++, k++) {
            double dr = a[k].r - b[k].r, dg = a[k].g - b[k].g, db = a[k].b - b[k].b;
            double x = (dr * dr + dg * dg + db * db) / 3.0;
            s += x;
            s2 += x * x;
        }
        if (!ps->n[g])
            continue;
        double mean = s / n, se = 0.0;
        if (ps->n[g] > 1 && ps->pop[g] > n) {
            double var = fmax(0.0, (s2 - n * mean * mean) / (n - 1.0));
            se = sqrt(var / n * (1.0 - n / ps->pop[g]));
        }
        total += ps->share[g] * (mean + se);
    }
    return sqrt(total);
}

int rs_auto_choose(const rs_scene *scene, const rs_auto_request *req, rs_render_opts *out,
                   double *probe_samples, char *why, size_t why_size, char *msg,
                   size_t msg_size)
{
    const double E = req->tolerance;
    const char *pol_reason = needs_polarized(scene);
    double lmax = radiance_max(scene), d_model = -1.0, budget, e_wl, e_at, samples = 0.0;
    double d_prev = -1.0, d_last = -1.0, p = 1.0, d_cut = 0.0, floor_cut;
    int rc = -1, n_lenses, over = 0;
    double dn = dispersion_max(scene, &n_lenses);
    size_t n;
    probe_set ps = {NULL, {0, 0, 0}, {0, 0, 0}, 0.0, {0, 0, 0}};
    rs_color *cur = NULL, *next = NULL, *tmp;
    rs_render_opts o;

    rs_render_opts_init(&o);
    o.width = req->width;
    o.height = req->height;
    o.depth = req->depth > 0 ? req->depth
              : scene->settings.max_trace_level > DEPTH_MIN ? scene->settings.max_trace_level
                                                           : DEPTH_MIN;
    /* The cut-off's floor, from the library's per-branch bounds: an
     * incoherent branch of weight w carries at most w lmax; a coherent
     * one adds up to 2 sqrt(w) lmax through its cross term with a ray of
     * weight 1, so there the weight is squared.  Below the floor no
     * dropped branch carries more than SHARE_CUTOFF E. */
    budget = SHARE_CUTOFF * E / lmax;
    floor_cut = coherent(scene) ? 0.25 * budget * budget : fmin(1.0, budget);

    {
        rs_render_opts pilot = o;
        pilot.cutoff = req->cutoff >= 0.0 ? req->cutoff : CUT_FIRST;
        if (probe_pick(scene, &pilot, pol_reason != NULL, &ps, &samples, msg, msg_size) != 0)
            return -1;
    }
    n = ps.n[G_MARKED] + ps.n[G_LENS] + ps.n[G_OTHER];
    cur = malloc(sizeof *cur * (n + 1));
    next = malloc(sizeof *next * (n + 1));
    if (!cur || !next) {
        snprintf(msg, msg_size, "out of memory");
        goto done;
    }

    /* The cut-off: most dropped branches carry far less than their bound
     * (they see a dark background, or light the image does not reach),
     * so a ladder of cut-offs from CUT_FIRST down by CUT_STEP is measured
     * on the probe (polarized, at the first wavelength rung) and the
     * first whose change to the next is, times SAFETY, within SHARE_TREE
     * of E stands; the floor ends the ladder. */
    o.wavelengths = req->wavelengths > 0 ? req->wavelengths : N_FIRST;
    o.mode = RS_MODE_POLARIZED;
    if (req->cutoff >= 0.0) {
        o.cutoff = req->cutoff;
        if (probe(scene, &o, &ps, cur, &samples, msg, msg_size) != 0)
            goto done;
    } else if (coherent(scene)) {
        /* no ladder: an interfering branch matters far below its weight,
         * and a decade of cut-offs without branches reads as converged
         * (newtons_rings at 12 x 9: the ladder stopped at 0.01, whose
         * next rung renders alike, 6.3e-3 off) */
        o.cutoff = floor_cut;
        d_cut = SHARE_CUTOFF * E / SAFETY;
        if (probe(scene, &o, &ps, cur, &samples, msg, msg_size) != 0)
            goto done;
    } else {
        double c = CUT_FIRST > floor_cut ? CUT_FIRST : floor_cut;
        o.cutoff = c;
        if (probe(scene, &o, &ps, cur, &samples, msg, msg_size) != 0)
            goto done;
        while (c > floor_cut) {
            rs_render_opts f = o;
            f.cutoff = c * CUT_STEP > floor_cut ? c * CUT_STEP : floor_cut;
            if (probe(scene, &f, &ps, next, &samples, msg, msg_size) != 0)
                goto done;
            d_cut = rms_diff(&ps, cur, next);
            if (SAFETY * d_cut <= SHARE_TREE * E)
                break;
            c = f.cutoff;
            o.cutoff = c;
            tmp = cur, cur = next, next = tmp;
        }
        if (o.cutoff <= floor_cut)
            d_cut = SHARE_CUTOFF * E / SAFETY; /* the bound's promise */
    }
    /* The model: polarized where the scene needs it; else fresnel when
     * its departure from polarized, measured on the probe at the first
     * rung, is within its share of E. */
    if (!pol_reason) {
        rs_render_opts f = o;
        f.mode = RS_MODE_FRESNEL;
        if (probe(scene, &f, &ps, next, &samples, msg, msg_size) != 0)
            goto done;
        d_model = rms_diff(&ps, cur, next);
        if (d_model <= SHARE_MODEL * E) {
            o.mode = RS_MODE_FRESNEL;
            tmp = cur, cur = next, next = tmp;
        }
    }
    e_wl = E - SAFETY * d_cut - (o.mode == RS_MODE_FRESNEL ? d_model : 0.0);

    /* The wavelengths: a ladder N, 2N, 4N ... on the probe, climbed until
     * the change from N to 2N, times SAFETY, is within the wavelength
     * budget (without dispersion and pigment spectra the change is 0 and
     * the first rung stands).  Only rungs are chosen: the error of a
     * count between two rungs is not measured, and it is not monotone in
     * N (conical_rim at 12 x 9: 16 wavelengths 3.4e-3 off, 12: 1.3e-2);
     * small odd counts are worse still (biconcave at 32 x 24, fresnel: 4
     * wavelengths 3.5e-3, 5: 4.6e-2, 9: 1.5e-2, 17: 6.7e-3).  At the
     * last rung the error is extrapolated as N^-p, p from the last two
     * changes. */
    if (req->wavelengths > 0) {
        e_at = -1.0; /* the user's: not estimated */
    } else {
        for (;;) {
            rs_render_opts h = o;
            h.wavelengths = 2 * o.wavelengths;
            if (probe(scene, &h, &ps, next, &samples, msg, msg_size) != 0)
                goto done;
            d_prev = d_last;
            d_last = rms_diff(&ps, cur, next);
            if (SAFETY * d_last <= e_wl)
                break;
            o.wavelengths = h.wavelengths;
            tmp = cur, cur = next, next = tmp;
            if (o.wavelengths >= WAVELENGTHS_MAX) {
                over = 1;
                break;
            }
        }
        if (d_prev > 0.0 && d_last > 0.0) {
            p = log2(d_prev / d_last);
            p = p < P_MIN ? P_MIN : p > P_MAX ? P_MAX : p;
        }
        e_at = SAFETY * d_last * (over ? pow(2.0, -p) : 1.0);
    }
    {
        char model[200], lens[160];
        double render = (double)req->width * req->height * o.wavelengths;
        if (pol_reason)
            snprintf(model, sizeof model, "%s", pol_reason);
        else
            snprintf(model, sizeof model,
                     "no polarizer, crystal or coherent light, and fresnel departs from "
                     "polarized by %.2g, %s half of E",
                     d_model, o.mode == RS_MODE_FRESNEL ? "within" : "over");
        if (n_lenses)
            snprintf(lens, sizeof lens, "%d lens%s (largest n(400)-n(700) %.3g) on %.0f %% of the image",
                     n_lenses, n_lenses > 1 ? "es" : "", dn, 100.0 * ps.lens_share);
        else
            snprintf(lens, sizeof lens, "no lens");
        if (e_at >= 0.0)
            snprintf(why, why_size,
                     "%s, %d wavelengths, depth %d, cut-off %.3g for E = %.3g: %s; %s; "
                     "wavelength error %.2g%s, cut-off's %.2g (%zu probe pixels, %.0f %% of the "
                     "render's samples)",
                     rs_mode_name(o.mode), o.wavelengths, o.depth, o.cutoff, E, model, lens,
                     e_at, over ? ", over E: more wavelengths than the limit would be needed" : "",
                     SAFETY * d_cut, n, 100.0 * samples / render);
        else
            snprintf(why, why_size,
                     "%s, %d wavelengths (yours), depth %d, cut-off %.3g for E = %.3g: %s; %s; "
                     "a dropped branch carries < %.2g",
                     rs_mode_name(o.mode), o.wavelengths, o.depth, o.cutoff, E, model, lens,
                     SHARE_CUTOFF * E);
    }
    *out = o;
    if (probe_samples)
        *probe_samples = samples;
    rc = 0;
done:
    free(ps.px);
    free(cur);
    free(next);
    return rc;
}
