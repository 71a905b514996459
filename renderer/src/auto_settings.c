/* auto_settings.c -- the choice of --mode auto (see auto_settings.h for
 * the rule). */
#include "auto_settings.h"

#include "args.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "camera.h"
#include "shapes.h"

#define SHARE_CUTOFF 0.1  /* of E: the radiance one dropped branch may carry */
#define TOP_SHARE 0.125   /* of E: the ladder's top rung's error, at most */
#define TREE_LADDER 0.25  /* of E: the ladder's tree's error, at most */
#define TREE_COST_MAX 64.0 /* of the cheapest tree's cost: the dearest probed */
#define CLIMB_SHARE 0.05  /* of the best render's cost: a rung the probe may add */
#define DEPTH_MIN 32      /* the deepest tree, unless the scene asks for more */
#define DEEP_CUT_DEPTH 16 /* cut-offs below 1e-6 only at this depth and deeper */
#define N_FIRST 4         /* the ladder's first rung */
#define PROBE_LENS 24     /* probe pixels seeing a lens, at least */
#define PROBE_OTHER 8     /* and the others */
#define EVERY_LENS 32     /* or one in this many of the lens group */
#define EVERY_OTHER 256   /* and of the others */
#define PROBE_MAX 1024    /* but at most this many of each group */
#define LENS_SHARE_MAX 128 /* and lens pixels at most one in this many of all */
#define WAVELENGTHS_MAX RS_ARGS_WAVELENGTHS_MAX /* what lensrender takes */
#define RUNGS_MAX 16      /* 4 .. 16384 wavelengths, doubling */
#define PILOT_EVERY 256   /* the pilot renders about one pixel in this many */
#define PILOT_MIN 192     /* but at least this many: every pixel of a small image */
#define MARK_MIN 6        /* marked pixels of each kind, at least */
#define MARK_EVERY 64     /* or one in this many of the pilot's */
#define MARK_MAX 256      /* but at most this many */
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

/* The lenses' boxes, which a camera ray must meet to see a lens (a hit an
 * object reports lies in its box): a pixel outside every box's projection
 * onto the image (rect) makes no ray at all, and a ray is tested against
 * the boxes before the scene is intersected -- sparing most of the image
 * its ray or its intersections, and changing no pixel's answer.  A lens
 * with no finite box projects onto the whole image; boxed 0: some lens
 * has no box the tree tests (or the scene no tree), so every ray made is
 * intersected. */
typedef struct lens_boxes {
    int *lens;  /* the lenses' object indices */
    int *rect;  /* 4 per lens: the pixels whose ray may meet its box
                   (rs_camera_box_pixels) */
    size_t n;
    int boxed;
} lens_boxes;

static int lens_boxes_init(const rs_scene *s, const rs_view *view, int width, int height,
                           lens_boxes *lb)
{
    lb->n = 0;
    lb->boxed = s->bvh && rs_bvh_object_count(s->bvh) == s->n_objects;
    lb->lens = malloc(sizeof *lb->lens * (s->n_objects + 1));
    lb->rect = malloc(sizeof *lb->rect * 4 * (s->n_objects + 1));
    if (!lb->lens || !lb->rect)
        return -1;
    for (size_t i = 0; i < s->n_objects; i++) {
        lp_vec3 lo, hi;
        int *r = lb->rect + 4 * lb->n;
        if (s->objects[i].type != RS_OBJ_LENS)
            continue;
        lb->lens[lb->n++] = (int)i;
        if (!rs_bvh_culls(s->bvh, (int)i))
            lb->boxed = 0;
        if (!rs_object_bounds(&s->objects[i], &lo, &hi) ||
            !rs_camera_box_pixels(view, width, height, lo, hi, r))
            r[0] = 0, r[1] = width, r[2] = 0, r[3] = height;
    }
    return 0;
}

static void lens_boxes_free(lens_boxes *lb)
{
    free(lb->lens);
    free(lb->rect);
    lb->lens = NULL;
    lb->rect = NULL;
}

/* Might pixel (i, j) see a lens?  0 only when no lens's box projects onto
 * it: its camera ray is not even made. */
static int may_project_lens(const lens_boxes *lb, int i, int j)
{
    for (size_t k = 0; k < lb->n; k++) {
        const int *r = lb->rect + 4 * k;
        if (i >= r[0] && i < r[1] && j >= r[2] && j < r[3])
            return 1;
    }
    return 0;
}

/* Might the camera ray (o, d) meet a lens?  0 only when it cannot. */
static int may_see_lens(const rs_scene *s, const lens_boxes *lb, lp_vec3 o, lp_vec3 d)
{
    rs_slab_ray r;
    if (!lb->boxed)
        return 1;
    rs_slab_ray_init(&r, o, d);
    for (size_t k = 0; k < lb->n; k++)
        if (rs_bvh_may_meet(s->bvh, lb->lens[k], &r, 0.0, INFINITY))
            return 1;
    return 0;
}

/* Render the pixels px[2k], px[2k + 1] of the groups of sizes n[0..ng)
 * (one after another) with opts into out; the cost of each group's
 * renders (rs_work_cost) into gcost[g], their work into gwork[g] (when
 * not NULL) and the costs' sum added to *spent.  When not NULL, pcost[k]
 * gets pixel k's own cost and split[k] whether its spectral packet split
 * at a lens (rs_worker_splits).  pop (when not NULL, with cap > 0): the
 * pixels each group stands for; once the cost over them (each pixel's
 * cost times the pixels it stands for, summed in order) passes cap, the
 * render stops and returns 1 (out, gcost and the rest then undefined;
 * *spent gets what it rendered). */
static int render_pixels(const rs_scene *s, const rs_render_opts *opts, const int *px,
                         const size_t *n, int ng, const double *pop, double cap, rs_color *out,
                         double *gcost, rs_work *gwork, double *pcost, unsigned char *split,
                         double *spent, char *msg, size_t msg_size)
{
    rs_integrator *it;
    rs_worker *w;
    rs_work before = {0, 0, 0, 0}, after;
    size_t k = 0;
    double image = 0.0; /* the cost over the image so far, where capped */
    int rc = 0;
    if (rs_integrator_create(s, opts, &it, msg, msg_size) != 0)
        return -1;
    w = rs_worker_create(it);
    if (!w) {
        rs_integrator_destroy(it);
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    for (int g = 0; g < ng && rc == 0; g++) {
        for (size_t m = 0; m < n[g] && rc == 0; m++, k++) {
            rs_work pb, pa;
            unsigned long long s0 = rs_worker_splits(w);
            rs_worker_work(w, &pb);
            rs_integrator_pixel(it, w, px[2 * k], px[2 * k + 1], &out[k]);
            rs_worker_work(w, &pa);
            rs_work d = {pa.rays - pb.rays, pa.lane_rays - pb.lane_rays, pa.builds - pb.builds,
                         pa.gathered - pb.gathered};
            double c = rs_work_cost(&d, opts->mode, 1.0);
            if (pcost)
                pcost[k] = c;
            if (split)
                split[k] = rs_worker_splits(w) != s0;
            if (pop && cap > 0.0) {
                image += c * pop[g] / (double)n[g];
                rc = image > cap;
            }
        }
        rs_worker_work(w, &after);
        rs_work d = {after.rays - before.rays, after.lane_rays - before.lane_rays,
                     after.builds - before.builds, after.gathered - before.gathered};
        gcost[g] = rs_work_cost(&d, opts->mode, (double)n[g]);
        if (gwork)
            gwork[g] = d;
        *spent += gcost[g];
        before = after;
    }
    rs_worker_destroy(w);
    rs_integrator_destroy(it);
    return rc;
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

/* A fixed scramble of a pixel's index (splitmix64's finalizer). */
static uint64_t mix(uint64_t x)
{
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

/* The pixel that stands for pilot cell m (nx cells a row, step x step
 * pixels each): a scrambled one of the cell, not its middle, which the
 * pilot chose for being extreme -- a pixel picked at random from the
 * cell weighs the cell without bias (mirror_ball at 128 x 96, E = 1e-4:
 * the middle standing only for itself under-counted its coloured rings,
 * 9.1e-5 against 1.4e-4 rendered; standing for the cell, it tripled the
 * error of crossed_polarizers' dispersed edges). */
static long cell_pixel(size_t m, int nx, int step, int width, int height)
{
    uint64_t r = mix((uint64_t)m);
    int i = (int)(m % (size_t)nx) * step + (int)(r % (uint64_t)step);
    int j = (int)(m / (size_t)nx) * step + (int)((r >> 32) % (uint64_t)step);
    i = i < width ? i : width - 1;
    j = j < height ? j : height - 1;
    return (long)j * width + i;
}

/* The pilot (see probe_set): the middle pixel of every step x step cell
 * of the image, rendered with base in rgb -- brightness and saturation
 * at the cost of one lane -- or, where the scene needs the polarized
 * model (rgb does not see what polarizers do), polarized at one
 * wavelength: brightness only.  The brightest and the most saturated are
 * marked in mark[] (by pixel); each stands for its cell. */
static int pilot_mark(const rs_scene *s, const rs_render_opts *base, int polarized, int step,
                      unsigned char *mark, double *spent, char *msg, size_t msg_size)
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
    {
        double gc;
        if (render_pixels(s, &f, px, &n, 1, NULL, 0.0, c, &gc, NULL, NULL, NULL, spent, msg,
                          msg_size) != 0)
            goto out;
    }
    for (int pass = 0; pass < (polarized ? 1 : 2); pass++) {
        for (size_t m = 0; m < n; m++) {
            double hi = cmax(c[m]), lo = fmin(c[m].r, fmin(c[m].g, c[m].b));
            sc[m].v = pass == 0 ? hi : hi - lo;
            sc[m].k = cell_pixel(m, nx, step, width, height);
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
                      probe_set *ps, double *spent, char *msg, size_t msg_size)
{
    rs_view view;
    int width = base->width, height = base->height;
    long count[N_GROUPS] = {0, 0, 0}, total = (long)width * height;
    long every[N_GROUPS];
    /* the largest cells that still give the pilot its pixels */
    long pilot_want = total / PILOT_EVERY > PILOT_MIN ? total / PILOT_EVERY : PILOT_MIN;
    int step = 1;
    while ((long)((width + step) / (step + 1)) * ((height + step) / (step + 1)) >= pilot_want)
        step++;
    if (rs_camera_setup(&s->camera, width, height, &view, msg, msg_size) != 0)
        return -1;
    unsigned char *group = malloc((size_t)total);
    unsigned char *mark = calloc((size_t)total, 1);
    lens_boxes lb = {NULL, NULL, 0, 0};
    if (!group || !mark || lens_boxes_init(s, &view, width, height, &lb) != 0) {
        free(group);
        free(mark);
        lens_boxes_free(&lb);
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    if (pilot_mark(s, base, polarized, step, mark, spent, msg, msg_size) != 0) {
        free(group);
        free(mark);
        lens_boxes_free(&lb);
        return -1;
    }
    for (int j = 0; j < height; j++)
        for (int i = 0; i < width; i++) {
            lp_vec3 o, d;
            long k = (long)j * width + i;
            int lens = 0;
            if (may_project_lens(&lb, i, j)) {
                rs_camera_ray(&view, i + 0.5, j + 0.5, width, height, &o, &d);
                lens = may_see_lens(s, &lb, o, d) && sees_lens(s, o, d);
            }
            int g = mark[k] ? G_MARKED : lens ? G_LENS : G_OTHER;
            group[k] = (unsigned char)g;
            count[g]++;
            ps->lens_share += lens ? 1.0 / (double)total : 0.0;
        }
    lens_boxes_free(&lb);
    /* A marked pixel (cell_pixel) stands for its pilot cell (at most what
     * there is); the other groups share the rest in proportion. */
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
        ps->n[g] = 0;
        for (long k = 0; k < total; k++) {
            if (group[k] != g)
                continue;
            /* one in every[g], scrambled: a regular stride in scan order
             * aliases with the image's stripes and edges (default.scene
             * at 128 x 96: the lens group's sample of a wavelength
             * doubling's change came out 2.2 times the image's) */
            if (mix((uint64_t)k) % (uint64_t)every[g] != 0)
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

/* One probe render: each probe pixel's colour, and the cost the setting
 * would have on the whole image (each group's cost per pixel times the
 * pixels it stands for). */
typedef struct shot {
    rs_color *c;
    double *pc;             /* each probe pixel's own cost */
    unsigned char *split;   /* whether its spectral packet split (rs_worker_splits) */
    double cost;
    rs_work work[N_GROUPS]; /* what each group's render traced */
} shot;

static void shot_free(shot *s)
{
    free(s->c);
    free(s->pc);
    free(s->split);
    s->c = NULL;
    s->pc = NULL;
    s->split = NULL;
}

/* cap > 0: a render whose cost over the image would pass it stops and
 * returns 1, *out left empty. */
static int probe(const rs_scene *s, const rs_render_opts *opts, const probe_set *ps, double cap,
                 shot *out, double *spent, char *msg, size_t msg_size)
{
    int rc;
    double gc[N_GROUPS];
    size_t n = ps->n[G_MARKED] + ps->n[G_LENS] + ps->n[G_OTHER];
    out->c = malloc(sizeof *out->c * (n + 1));
    out->pc = malloc(sizeof *out->pc * (n + 1));
    out->split = malloc(n + 1);
    if (!out->c || !out->pc || !out->split) {
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    rc = render_pixels(s, opts, ps->px, ps->n, N_GROUPS, ps->pop, cap, out->c, gc, out->work,
                       out->pc, out->split, spent, msg, msg_size);
    if (rc != 0) {
        shot_free(out);
        return rc;
    }
    out->cost = 0.0;
    for (int g = 0; g < N_GROUPS; g++)
        if (ps->n[g])
            out->cost += gc[g] * ps->pop[g] / (double)ps->n[g];
    return 0;
}

/* A copy of a probe render into *to (its own colours). */
static int shot_copy(const probe_set *ps, const shot *from, shot *to, char *msg, size_t msg_size)
{
    size_t n = ps->n[G_MARKED] + ps->n[G_LENS] + ps->n[G_OTHER];
    *to = *from;
    to->c = malloc(sizeof *to->c * (n + 1));
    to->pc = malloc(sizeof *to->pc * (n + 1));
    to->split = malloc(n + 1);
    if (!to->c || !to->pc || !to->split) {
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    memcpy(to->c, from->c, sizeof *to->c * n);
    memcpy(to->pc, from->pc, sizeof *to->pc * n);
    memcpy(to->split, from->split, n);
    return 0;
}

static int same_work(const shot *a, const shot *b)
{
    for (int g = 0; g < N_GROUPS; g++)
        if (a->work[g].rays != b->work[g].rays || a->work[g].lane_rays != b->work[g].lane_rays ||
            a->work[g].builds != b->work[g].builds || a->work[g].gathered != b->work[g].gathered)
            return 0;
    return 1;
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

/* The grid's cut-offs, largest first (the sweep's, speed_accuracy). */
static const double CUTOFFS[] = {1e-2, 1e-3, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12};
#define N_CUTOFFS (sizeof CUTOFFS / sizeof *CUTOFFS)
#define TREES_MAX (4 * N_CUTOFFS)

typedef struct tree {
    int depth;
    double cutoff;
    shot s;    /* the ladder's model at the first rung */
    double e;  /* e_tree */
    int over;  /* not probed: it would cost more than TREE_COST_MAX x the
                  cheapest (s empty) */
} tree;

/* Does tree b trace every ray tree a traces?  It does where it is no
 * shallower and cuts no higher: a branch's weight does not depend on the
 * tree, so b stops only where a stops too. */
static int nests(const tree *a, const tree *b)
{
    return a->depth <= b->depth && a->cutoff >= b->cutoff;
}

/* Every tree's probe render with base at its depth and cut-off, but
 * those that would cost more than TREE_COST_MAX times the cheapest (the
 * shallowest, loosest: rendered first), which are marked over.  A tree t
 * between two rendered trees a and b (a nests in t, t in b) that traced
 * the same -- every counter of every group -- traces what a traces and
 * renders as a does: it is copied, not rendered.  So the deepest depth
 * goes first, then the shallowest, then the others shallow to deep (a
 * scene whose light is all traced by depth 8 renders depth 16 as 8 and
 * 32); each depth's cut-offs loosest first, so that a tree's cost is
 * foretold by the two looser ones before it (the growth per decade of
 * cut-off kept): one foretold to pass the cap 4 times over is not
 * started, and the render of one that passes it stops there (a faint
 * branch's descendants can cost a thousand times the main rays: the
 * microscope's ten surfaces at depth 32 and a 4-wavelength probe, 0.05 s
 * for 192 pixels at cut-off 1e-2, 1.1 s at 1e-4, 45 s at 1e-6).  A tree
 * tighter than an over one at its depth is over too. */
static int probe_trees(const rs_scene *s, const rs_render_opts *base, const probe_set *ps,
                       tree *tr, int n_trees, double *spent, char *msg, size_t msg_size)
{
    int first[TREES_MAX + 1], n_depths = 0, order[TREES_MAX], n_order = 0;
    int done[TREES_MAX];
    double cap = 0.0;
    for (int t = 0; t < n_trees; t++) {
        done[t] = 0;
        tr[t].over = 0;
        if (t == 0 || tr[t].depth != tr[t - 1].depth)
            first[n_depths++] = t;
    }
    first[n_depths] = n_trees;
    order[n_order++] = 0; /* the cheapest: the cap's measure */
    for (int k = 0; k < n_depths; k++) {
        int d = k == 0 ? n_depths - 1 : k - 1;
        for (int t = first[d]; t < first[d + 1]; t++)
            if (t != 0)
                order[n_order++] = t;
    }
    for (int k = 0; k < n_order; k++) {
        int t = order[k], a = -1, rc;
        for (int i = 0; i < n_trees && a < 0; i++)
            for (int j = 0; j < n_trees && a < 0; j++)
                if (done[i] && done[j] && !tr[i].over && !tr[j].over && nests(&tr[i], &tr[t]) &&
                    nests(&tr[t], &tr[j]) && same_work(&tr[i].s, &tr[j].s))
                    a = i;
        done[t] = 1;
        if (a >= 0) {
            if (shot_copy(ps, &tr[a].s, &tr[t].s, msg, msg_size) != 0)
                return -1;
            continue;
        }
        /* the looser trees of its depth, rendered before it */
        if (t > 0 && tr[t - 1].depth == tr[t].depth) {
            const tree *p = &tr[t - 1];
            if (p->over) {
                tr[t].over = 1;
                continue;
            }
            if (t > 1 && tr[t - 2].depth == tr[t].depth && !tr[t - 2].over) {
                const tree *q = &tr[t - 2];
                double per = log(p->s.cost / q->s.cost) / log10(q->cutoff / p->cutoff);
                double foretold = p->s.cost * exp(fmax(0.0, per) * log10(p->cutoff / tr[t].cutoff));
                if (cap > 0.0 && foretold > 4.0 * cap) {
                    tr[t].over = 1;
                    continue;
                }
            }
        }
        rs_render_opts f = *base;
        f.depth = tr[t].depth;
        f.cutoff = tr[t].cutoff;
        rc = probe(s, &f, ps, cap, &tr[t].s, spent, msg, msg_size);
        if (rc < 0)
            return -1;
        tr[t].over = rc == 1;
        if (t == 0)
            cap = TREE_COST_MAX * tr[0].s.cost;
    }
    return 0;
}

typedef struct choice {
    rs_mode mode;
    int wavelengths, tree, rung; /* rung -1: rgb */
    double e, e_wl, e_tree, e_model, cost;
    double tau;   /* the refinement's tolerance, 0: none */
    double refined; /* the share of the image it renders again */
} choice;

static void consider(choice *best, int *n_cand, double E, choice c)
{
    (*n_cand)++;
    if (c.e <= E && (best->cost < 0.0 || c.cost < best->cost))
        *best = c;
}

/* The refinement's tolerances tried, in E (rs_render_opts.refine_tol:
 * a pixel's largest channel change on a doubling, where E is an RMS over
 * the image, most of whose pixels never split). */
static const double TAUS[] = {8.0, 4.0, 2.0, 1.0, 0.5, 0.25, 0.125};
#define N_TAUS (sizeof TAUS / sizeof *TAUS)

/* The probe as the refinement renders it from rung k with tolerance tau
 * (the integrator's rule, rs_integrator_pixel, replayed on the ladder's
 * rungs up to the top, the refinement's last count): each pixel's value
 * into sim, and the cost the renders again add over the image (each pixel
 * standing for its group's pixels, as in rms_diff) into *extra, the
 * image's share they render into *share. */
static void refine_replay(const probe_set *ps, const shot *rung, int n_rungs, int k, double tau,
                          rs_color *sim, double *extra, double *share)
{
    size_t p = 0;
    double total = 0.0;
    *extra = 0.0;
    *share = 0.0;
    for (int g = 0; g < N_GROUPS; g++) {
        double pw = ps->n[g] ? ps->pop[g] / (double)ps->n[g] : 0.0;
        for (size_t m = 0; m < ps->n[g]; m++, p++) {
            rs_color v = rung[k].c[p];
            total += pw;
            if (rung[k].split[p] && k + 1 < n_rungs)
                *share += pw;
            for (int r = k + 1, calm = 0; r < n_rungs && rung[k].split[p]; r++) {
                double change = rs_refine_change(rung[r].c[p], v);
                *extra += pw * rung[r].pc[p];
                v = rung[r].c[p];
                calm = rs_refine_calm(calm, change, tau);
                if (calm == RS_REFINE_CALM)
                    break;
            }
            sim[p] = v;
        }
    }
    *share = total > 0.0 ? *share / total : 0.0;
}

/* The cheapest candidate whose estimate is within E (cost < 0: none),
 * from the measurements so far (see auto_settings.h); *n_cand counts
 * the candidates.  sim: room for the probe's pixels. */
static choice choose(const probe_set *ps, double E, int pol_only, rs_mode L,
                     const tree *tr, int n_trees, int t_lad, const shot *rung, const int *rung_n,
                     int n_rungs, double e_top, const double *e_model, const double *mcost,
                     const shot *rgb, rs_color *sim, int *n_cand)
{
    static const rs_mode spectral[3] = {RS_MODE_FRESNEL, RS_MODE_SCHLICK, RS_MODE_POLARIZED};
    choice best = {RS_MODE_POLARIZED, 0, 0, 0, INFINITY, 0, 0, 0, -1.0, 0.0, 0.0};
    const shot *top = &rung[n_rungs - 1];
    /* a single rung has no estimate of its own error */
    double e_t = n_rungs > 1 ? e_top : INFINITY;
    *n_cand = 0;
    for (int k = 0; k < n_rungs; k++) {
        /* without refinement (ti == -1), then with each tolerance */
        for (int ti = -1; ti < (k + 1 < n_rungs ? (int)N_TAUS : 0); ti++) {
            double tau = ti < 0 ? 0.0 : TAUS[ti] * E, extra = 0.0, share = 0.0, e_wl;
            if (ti < 0) {
                e_wl = (k == n_rungs - 1 ? 0.0 : rms_diff(ps, rung[k].c, top->c)) + e_t;
            } else {
                refine_replay(ps, rung, n_rungs, k, tau, sim, &extra, &share);
                if (share <= 0.0)
                    break; /* no pixel split: nothing to refine */
                /* A refined pixel is left within about tau of its
                 * converged value (or at the top's count): over the image
                 * that is at most tau sqrt(share) whatever the probe saw
                 * -- its few split pixels can miss the rare ones a coarse
                 * grid gets most wrong, which a looser tau leaves so. */
                if (tau * sqrt(share) > E)
                    continue;
                e_wl = rms_diff(ps, sim, top->c) + e_t;
            }
            for (int t = 0; t < n_trees; t++) {
                if (tr[t].over)
                    continue;
                double tcost = tr[t].s.cost / tr[t_lad].s.cost;
                for (int m = 0; m < 3; m++) {
                    if (pol_only && spectral[m] != RS_MODE_POLARIZED)
                        continue;
                    choice c = {spectral[m], rung_n[k], t, k, 0, e_wl, tr[t].e,
                                e_model[spectral[m]], 0, tau, share};
                    c.e = hypot(c.e_wl, c.e_model) + c.e_tree;
                    c.cost = (rung[k].cost + extra) * tcost * mcost[spectral[m]];
                    consider(&best, n_cand, E, c);
                }
            }
        }
    }
    if (!pol_only)
        for (int t = 0; t < n_trees; t++) {
            if (!rgb[t].c)
                continue;
            choice c = {RS_MODE_RGB, 0, t, -1, 0, 0, 0, 0, rgb[t].cost, 0.0, 0.0};
            c.e = hypot(rms_diff(ps, rgb[t].c, top->c) + e_t, e_model[L]) + tr[t_lad].e;
            c.e_model = c.e;
            consider(&best, n_cand, E, c);
        }
    return best;
}

int rs_auto_choose(const rs_scene *scene, const rs_auto_request *req, rs_render_opts *out,
                   rs_auto_cost *cost, char *why, size_t why_size, char *msg, size_t msg_size)
{
    const double E = req->tolerance;
    const char *pol_reason = needs_polarized(scene);
    const rs_mode L = pol_reason ? RS_MODE_POLARIZED : RS_MODE_FRESNEL;
    double lmax = radiance_max(scene), spent = 0.0, budget, floor_cut, e_star;
    int rc = -1, n_lenses, n_trees = 0, n_rungs = 0, t_star, t_lad, n_cand = 0, over = 0;
    int n_over = 0; /* trees too dear to probe */
    double dn = dispersion_max(scene, &n_lenses);
    probe_set ps = {NULL, {0, 0, 0}, {0, 0, 0}, 0.0, {0, 0, 0}};
    tree tr[TREES_MAX];
    shot rung[RUNGS_MAX], pol, sch, rgb[TREES_MAX];
    int rung_n[RUNGS_MAX];
    double e_top = INFINITY, e_model[4] = {0, 0, 0, 0}, mcost[4] = {1, 1, 1, 1};
    double rung_spent = 0.0;
    int depths[4], n_depths = 0, depth_max;
    rs_render_opts o;
    choice best = {RS_MODE_POLARIZED, 0, 0, 0, INFINITY, 0, 0, 0, -1.0, 0.0, 0.0};
    rs_color *sim = NULL; /* the probe as a refinement renders it */

    memset(tr, 0, sizeof tr);
    memset(rung, 0, sizeof rung);
    memset(rgb, 0, sizeof rgb);
    memset(&pol, 0, sizeof pol);
    memset(&sch, 0, sizeof sch);
    rs_render_opts_init(&o);
    o.width = req->width;
    o.height = req->height;

    /* The trees: depth 4, 8, 16 and 32 (or the scene's max_trace_level
     * when deeper: crossed_polarizers at 128 x 96 changes by 4.3e-3 RMS
     * from depth 16 to 32, by 3e-8 from 32 to 64); cut-offs of the grid
     * down to the floor (below 1e-6 only from depth 16 on), from the library's per-branch bounds: an incoherent
     * branch of weight w carries at most w lmax; a coherent one adds up
     * to 2 sqrt(w) lmax through its cross term with a ray of weight 1, so
     * there the weight is squared.  Below the floor no dropped branch
     * carries more than SHARE_CUTOFF E. */
    budget = SHARE_CUTOFF * E / lmax;
    floor_cut = coherent(scene) ? 0.25 * budget * budget : fmin(1.0, budget);
    depth_max = req->depth > 0 ? req->depth
                : scene->settings.max_trace_level > DEPTH_MIN ? scene->settings.max_trace_level
                                                             : DEPTH_MIN;
    if (req->depth > 0) {
        depths[n_depths++] = req->depth;
    } else {
        depths[n_depths++] = 4;
        depths[n_depths++] = 8;
        depths[n_depths++] = 16;
        depths[n_depths++] = depth_max;
    }
    for (int d = 0; d < n_depths; d++) {
        if (req->cutoff >= 0.0) {
            tr[n_trees].depth = depths[d];
            tr[n_trees++].cutoff = req->cutoff;
            continue;
        }
        for (size_t c = 0; c < N_CUTOFFS; c++) {
            tr[n_trees].depth = depths[d];
            tr[n_trees++].cutoff = CUTOFFS[c];
            if (CUTOFFS[c] <= floor_cut ||
                (depths[d] < DEEP_CUT_DEPTH && CUTOFFS[c] <= 1e-6))
                break;
        }
    }
    t_star = n_trees - 1; /* the deepest depth's lowest cut-off */
    e_star = req->cutoff >= 0.0 ? 0.0 : SHARE_CUTOFF * E;

    {
        rs_render_opts pilot = o;
        pilot.depth = depth_max;
        pilot.cutoff = req->cutoff >= 0.0 ? req->cutoff : CUTOFFS[0];
        if (probe_pick(scene, &pilot, pol_reason != NULL, &ps, &spent, msg, msg_size) != 0)
            return -1;
    }
    sim = malloc(sizeof *sim * (ps.n[G_MARKED] + ps.n[G_LENS] + ps.n[G_OTHER] + 1));
    if (!sim) {
        snprintf(msg, msg_size, "out of memory");
        goto done;
    }

    /* Every tree, in rgb (cheap, and each an rgb candidate) or, where the
     * scene needs it, polarized at the first rung; e_tree against T*. */
    o.mode = L;
    o.wavelengths = req->wavelengths > 0 ? req->wavelengths : N_FIRST;
    {
        rs_render_opts f = o;
        f.mode = pol_reason ? RS_MODE_POLARIZED : RS_MODE_RGB;
        if (probe_trees(scene, &f, &ps, tr, n_trees, &spent, msg, msg_size) != 0)
            goto done;
    }
    for (int t = 0; t < n_trees && !pol_reason; t++)
        rgb[t] = tr[t].s; /* not owned; empty where over */
    /* T*: the deepest depth's lowest cut-off, or where trees were too
     * dear to probe, the dearest probed (the one that traces the most) */
    for (int t = 0; t < n_trees; t++)
        if (tr[t].over)
            n_over++;
        else if (tr[t_star].over || tr[t].s.cost > tr[t_star].s.cost)
            t_star = t;
    for (int t = 0; t < n_trees; t++)
        if (!tr[t].over)
            tr[t].e = rms_diff(&ps, tr[t].s.c, tr[t_star].s.c) + e_star;
    /* The ladder's tree: the cheapest within TREE_LADDER of E. */
    t_lad = t_star;
    for (int t = 0; t < n_trees; t++)
        if (!tr[t].over && tr[t].e <= TREE_LADDER * E && tr[t].s.cost < tr[t_lad].s.cost)
            t_lad = t;

    /* The ladder's first rung, and the models there: their departure from
     * polarized and their cost relative to L. */
    {
        rs_render_opts f = o;
        f.depth = tr[t_lad].depth;
        f.cutoff = tr[t_lad].cutoff;
        /* where the scene needs polarized, the trees were rendered in L
         * at the first rung: the ladder's tree is that rung already */
        if ((pol_reason ? shot_copy(&ps, &tr[t_lad].s, &rung[0], msg, msg_size)
                        : probe(scene, &f, &ps, 0.0, &rung[0], &spent, msg, msg_size)) != 0)
            goto done;
        if (!pol_reason) {
            f.mode = RS_MODE_POLARIZED;
            if (probe(scene, &f, &ps, 0.0, &pol, &spent, msg, msg_size) != 0)
                goto done;
            f.mode = RS_MODE_SCHLICK;
            if (probe(scene, &f, &ps, 0.0, &sch, &spent, msg, msg_size) != 0)
                goto done;
            e_model[RS_MODE_FRESNEL] = rms_diff(&ps, rung[0].c, pol.c);
            e_model[RS_MODE_SCHLICK] = rms_diff(&ps, sch.c, pol.c);
            mcost[RS_MODE_POLARIZED] = pol.cost / rung[0].cost;
            mcost[RS_MODE_SCHLICK] = sch.cost / rung[0].cost;
        }
    }

    /* The ladder: N, 2N, ... in L at the ladder's tree; the top's error is
     * the last doubling's change.  It climbs until that change is within
     * TOP_SHARE E, or once some candidate meets E, until the next rung
     * would cost the probe more than CLIMB_SHARE of that candidate's
     * render (a rung's estimate can only halve the wavelengths). */
    rung_n[0] = o.wavelengths;
    n_rungs = 1;
    for (;;) {
        double before = spent;
        best = choose(&ps, E, pol_reason != NULL, L, tr, n_trees, t_lad, rung, rung_n,
                      n_rungs, e_top, e_model, mcost, rgb, sim, &n_cand);
        if (req->wavelengths > 0 || rung_n[n_rungs - 1] >= WAVELENGTHS_MAX ||
            n_rungs == RUNGS_MAX || (n_rungs > 1 && e_top <= TOP_SHARE * E) ||
            (best.cost >= 0.0 && 2.0 * rung_spent > CLIMB_SHARE * best.cost))
            break;
        rs_render_opts f = o;
        f.depth = tr[t_lad].depth;
        f.cutoff = tr[t_lad].cutoff;
        f.wavelengths = 2 * rung_n[n_rungs - 1];
        if (probe(scene, &f, &ps, 0.0, &rung[n_rungs], &spent, msg, msg_size) != 0)
            goto done;
        rung_spent = spent - before;
        rung_n[n_rungs] = f.wavelengths;
        e_top = rms_diff(&ps, rung[n_rungs - 1].c, rung[n_rungs].c);
        n_rungs++;
    }
    if (best.cost < 0.0) {
        /* nothing meets E: the most accurate there is */
        best = (choice){RS_MODE_POLARIZED, rung_n[n_rungs - 1], t_star, n_rungs - 1, 0, e_top,
                        tr[t_star].e, 0, 0, 0.0, 0.0};
        best.e = best.e_wl + best.e_tree;
        best.cost = rung[n_rungs - 1].cost * tr[t_star].s.cost / tr[t_lad].s.cost *
                    mcost[RS_MODE_POLARIZED];
        over = 1;
    }

    o.mode = best.mode;
    o.wavelengths = best.mode == RS_MODE_RGB ? o.wavelengths : best.wavelengths;
    o.depth = tr[best.tree].depth;
    o.cutoff = tr[best.tree].cutoff;
    o.refine_tol = best.tau;
    o.refine_max = best.tau > 0.0 ? rung_n[n_rungs - 1] : 0;
    /* A pixel that alone would take 1/16 of the image's squared error
     * (its channels' mean square over the image's pixels, against E^2)
     * is no estimate's to leave: it goes on past the top.  crossed_polarizers
     * at 128 x 96, E = 1e-3: 8 pixels of a light seen through the lens
     * changed by 0.13 from 512 to 1024 wavelengths and were 0.065 off,
     * 1.1e-3 RMS over the image by themselves, and no probe pixel. */
    o.refine_outlier = best.tau > 0.0 ? 0.25 * E * sqrt((double)req->width * req->height) : 0.0;
    o.refine_limit = best.tau > 0.0 ? WAVELENGTHS_MAX : 0;
    {
        char refine[160] = "";
        if (best.tau > 0.0)
            snprintf(refine, sizeof refine,
                     ", refined up to %d where a doubling changes a pixel by more than %.2g "
                     "(%.0f %% of the image split at a lens)",
                     o.refine_max, best.tau, 100.0 * best.refined);
        char model[160], lens[160], parts[160], dear[224] = "";
        size_t n = ps.n[G_MARKED] + ps.n[G_LENS] + ps.n[G_OTHER];
        if (n_over)
            snprintf(dear, sizeof dear,
                     "; %d of %d trees not probed, each over %.0f x the cheapest's cost: the "
                     "trees' error is against depth %d, cut-off %.3g, and what fainter or deeper "
                     "branches add is not in the estimate",
                     n_over, n_trees, TREE_COST_MAX, tr[t_star].depth, tr[t_star].cutoff);
        if (pol_reason)
            snprintf(model, sizeof model, "polarized only: %s", pol_reason);
        else
            snprintf(model, sizeof model, "no polarizer, crystal or coherent light");
        if (n_lenses)
            snprintf(lens, sizeof lens, "%d lens%s (largest n(400)-n(700) %.3g) on %.0f %% of the image",
                     n_lenses, n_lenses > 1 ? "es" : "", dn, 100.0 * ps.lens_share);
        else
            snprintf(lens, sizeof lens, "no lens");
        if (best.mode == RS_MODE_RGB)
            snprintf(parts, sizeof parts, "measured against %d wavelengths", rung_n[n_rungs - 1]);
        else
            snprintf(parts, sizeof parts, "wavelengths %.2g and model %.2g in quadrature, + tree %.2g",
                     best.e_wl, best.e_model, best.e_tree);
        if (best.mode == RS_MODE_RGB)
            snprintf(why, why_size,
                     "rgb, depth %d, cut-off %.3g for E = %.3g: estimated error %.2g (%s), the "
                     "cheapest of %d candidates; %s; %s; probe %zu pixels, %.0f %% of the render's "
                     "cost%s",
                     o.depth, o.cutoff, E, best.e, parts, n_cand, model, lens, n,
                     100.0 * spent / best.cost, dear);
        else
            snprintf(why, why_size,
                     "%s, %d wavelengths%s%s, depth %d, cut-off %.3g for E = %.3g: estimated error "
                     "%.2g (%s)%s, the cheapest of %d candidates; %s; %s; probe %zu pixels, %.0f %% "
                     "of the render's cost%s",
                     rs_mode_name(o.mode), o.wavelengths, req->wavelengths > 0 ? " (yours)" : "",
                     refine, o.depth, o.cutoff, E, best.e, parts,
                     over ? ", over E: no candidate meets it" : "", n_cand, model, lens, n,
                     100.0 * spent / best.cost, dear);
    }
    *out = o;
    if (cost) {
        cost->probe = spent;
        cost->render = best.cost;
    }
    rc = 0;
done:
    free(ps.px);
    free(sim);
    for (int t = 0; t < n_trees; t++)
        shot_free(&tr[t].s);
    for (int k = 0; k < RUNGS_MAX; k++)
        shot_free(&rung[k]);
    shot_free(&pol);
    shot_free(&sch);
    return rc;
}
