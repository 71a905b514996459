/* integrator.c -- Whitted-style backward tracing with lenses as single
 * primitives, in four light models.
 *
 * Spectral modes trace one wavelength at a time ("a band"); the rgb mode
 * traces three colour channels.  The unpolarized modes (fresnel, schlick,
 * rgb) carry one number per ray; a lens hit becomes lp_backward_build and
 * the sum of each query's exact weight times what its query ray sees.
 * The polarized mode carries bundles of linearly polarized rays (lp_ray,
 * origin and dir unused: they all arrive along the ray being traced): a
 * lens hit becomes build -> trace every query ray -> gather its bundle;
 * a polarizer projects each ray on its axis (Malus); a diffuse or
 * emissive surface sends natural light as two orthogonal, mutually
 * incoherent halves.  Each source has its own channel id ch (two per
 * source, one per half); at the pixel, rays of a coherent source add as
 * complex amplitudes sqrt(I) vp exp(i(2 pi op/lambda - pi kphi + phase)),
 * all others as intensities.
 *
 * Optical path outside lenses: every segment of length t adds n t (the
 * scene medium is air, n = 1), so a ray's op is referred to the origin of
 * the ray being traced, as lp_backward_gather expects of a bundle.  Where
 * a traced ray meets a source (an emitting or diffusing surface, or the
 * background), its last segment is recorded as a wavelet (coherence.h)
 * and its rays start with op = 0 there; rs_coherent_power joins the
 * wavelets of each pair of beams to one common source point.
 *
 * Camera: a pinhole (aperture 0) traces one ray per pixel; with an
 * aperture the pixel is the mean power of the camera's aperture rays,
 * all through the pixel's point on the focal surface (camera.h), so what
 * lies off the focal surface -- fringes included -- is blurred.
 *
 * Levels follow POV-Ray: the camera ray is level 1; a query ray of depth
 * k from a lens hit at level L is level L + k; a ray that needs a level
 * beyond max_trace_level is black.  A branch whose bound on its weight
 * falls below the cut-off is not traced. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "camera.h"
#include "coherence.h"
#include "integrator.h"
#include "packet.h"
#include "quadrature.h"
#include "shapes.h"
#include "emitter.h"
#include "support/vec.h"
#include "wide.h"

#define RS_MAX_FRAMES 400
#define RS_PI 3.14159265358979323846
#define BUILD_CHUNK 64 /* a lens hit's sub-packets built at once (build_chunk) */

enum { BAND_CONTINUUM, BAND_LINE, BAND_RGB };

typedef struct band {
    int kind;
    double lambda;  /* continuum/line: the wavelength; rgb: the channel's */
    int light;      /* BAND_LINE: the light */
    int channel;    /* BAND_RGB */
    double weight;  /* BAND_CONTINUUM: its cell's width, nm (quadrature.h) */
} band;

/* Rays of the polarized mode.  A packet's bundle holds every lane's rays:
 * ray i belongs to lane lane[i] (an index of it->lanes) when that is >= 0;
 * otherwise it is a shared ray, the same light in several lanes of equal
 * optics that differ only in its intensity: vector s = -1 - lane[i] gives
 * per lane whether the lane has the ray (has[s * nl + lane]) and its
 * intensity there (I[s * nl + lane]); r[i].intensity is that of its first
 * lane.  Rays may share a vector (a vector is never changed once made).
 * Each lane's rays, in bundle order, are those tracing the lane alone
 * would give, in that order. */
typedef struct bundle {
    lp_ray *r;
    int *lane;
    size_t n, cap;
    double *I;
    unsigned char *has;
    size_t ns, scap; /* shared vectors used, allocated */
} bundle;

struct rs_integrator {
    const rs_scene *scene;
    rs_render_opts opts;
    rs_view view;
    int max_level;
    double cutoff;
    int n_sources;              /* 2 + lights + objects */
    unsigned char *coherent;    /* per source */
    double *coherence;          /* per source: coherence length, 0 = infinite */
    double *light_norm;         /* per light: rs_spectrum_norm of its spectrum */
    rs_color *light_rgb;        /* per light: its colour in the rgb mode (a
                                   line's or black body's own colour) */
    double correction[3][3];    /* C^-1: makes every RGB emitter exact */
    band *lanes;                /* a pixel's bands: the rgb mode's three
                                   channels, or the continuum wavelengths
                                   then the lights' lines */
    int n_lanes;
    rs_lane_classes *classes;   /* lanes with equal optics per lens */
    double *lane_light;         /* [k * n_lanes + lane]: band_light of light
                                   k in each lane, once per render */
    double *lane_background;    /* per lane: the background's emission */
    double *background_half;    /* per lane: the shared vector of its halves */
    unsigned char *background_has; /* (halves_every_lane) */
    int interferes;             /* some rays may add as amplitudes: a coherent
                                   source or a crystal lens */
    double *lane_xyz;           /* [lane * 3 + c]: what one unit of the lane's
                                   value adds to the pixel's XYZ (a continuum
                                   wavelength's CIE value times its cell's
                                   width, a line's XYZ) */
    rs_integrator *finer;       /* the refinement's next count (twice the
                                   wavelengths), or NULL */
};

/* What a colour is in each lane (band_emission or band_reflectance of
 * it), kept per worker for the colours met last: a shaded point's
 * pigment, emission, ambient and mirror colours are few per scene, and
 * the spectral evaluation of one costs more than the rest of the shading.
 * One table per use, so that the colours of a shaded point stay in place
 * together; a lane's value is evaluated when a packet with the lane first
 * asks for it (a packet split at a dispersive lens has one lane).  An entry's
 * lane values are valid where their stamp is the entry's generation. */
enum { CC_EMISSION, CC_AMBIENT, CC_PIGMENT, CC_MIRROR_MAX, CC_MIRROR_MIN, CC_KINDS };
#define CC_HALVES 2 /* the uses that emit (CC_EMISSION, CC_AMBIENT): halves kept */
#define RS_COLOUR_CACHE 64      /* most entries per table, a power of 2 */
#define RS_COLOUR_CACHE_LANES 16384 /* entries x lanes per table at most */

typedef struct colour_entry {
    rs_color c;
    unsigned gen; /* 0: unused */
    int n_valid;  /* lanes of this generation evaluated */
    int dark;     /* 1: every lane is evaluated, and is 0 */
    /* an emission's or ambient colour's shared vector of halves in every
     * lane (halves_every_lane), once every lane is evaluated; else NULL */
    const double *half;
    const unsigned char *half_has;
} colour_entry;



/* The scene hit of a lens hit's depth-1 query, kept for the next
 * sub-packet (query_hit), and room for another query's hit. */
typedef struct query_memo {
    int valid, found;
    lp_vec3 origin, dir;
    rs_hit h, h_other;
} query_memo;

typedef struct frame {
    lp_backward *bw; /* the build of the sub-packet being traced: one of bws */
    /* A lens hit's sub-packets (lens_builds): sub-packet s has the lanes
     * sub_lane[sub_at[s] .. sub_at[s + 1]), at those positions sub_pos of
     * the packet; they are built BUILD_CHUNK at a time (build_chunk), the
     * sub-packets [built_at, built_end) in bws[0 ..), sub-packet s's build
     * in bws[s - built_at] where sub_ok[s] */
    lp_backward **bws;
    int n_bws;       /* builders created */
    int built_at, built_end;
    const lp_lens *b_lens; /* what the builds are of */
    lp_vec3 b_o, b_d;
    lp_trace_args b_args;
    int *sub_at, *sub_lane, *sub_pos;
    double *sub_lambda;
    unsigned char *sub_ok;
    int *sub_of, *slot; /* rs_packet_split's scratch (slot: all -1) */
    int n_sub, sub_next;
    query_memo qm;
    bundle child;
    lp_result res;
    /* Shared gathers (gather_shared): per ray of child its group; per
     * group its first ray and the range of its outputs in res. */
    size_t *g_of, *g_ray, *g_start, *g_count, g_cap;
    lp_ray *g_rays; /* the groups' first rays, side by side */
    size_t g_rcap;
    unsigned char *bad; /* per lane: a gather failed */
    /* A dispersive lens hit's gathers in one call (gather_all): per
     * gather, in order, its query's traced bundle and the call's
     * arguments, the lane it belongs to and where its outputs start */
    bundle *kids;
    size_t n_kids; /* bundles allocated */
    const lp_backward **gm_bw;
    const lp_ray **gm_b;
    size_t *gm_q, *gm_n, *gm_start;
    int *gm_lane;
    double *gm_power; /* the power each carries out (camera_power) */
    size_t gm_cap;
    /* A spectral packet's split at this level (n_lanes entries each). */
    int *lane, *pos;
    double *val, *acc;
    unsigned char *done;
    double *reach;  /* per light: light_reach memo of one shaded point */
    double *cb, *hs; /* per light: shade_point's cosine terms and highlights */
    double *light_v; /* per lane: a light's radiance (shade_packet) */
    unsigned char *light_got; /* per lane: whether the light adds any */
} frame;

struct rs_worker {
    const rs_integrator *it;
    frame *frames[RS_MAX_FRAMES];
    int *lane_all;       /* 0 .. n_lanes - 1 */
    double *lane_value;  /* a pixel's value per lane */
    double *pixel_power; /* a pixel's power per lane that came without
                            rays (camera_power), added to its rays' */
    bundle pixel;
    const lp_ray **one;  /* pixel's rays by lane (pol_values) */
    double *one_i;       /* and their intensities in that lane */
    size_t one_cap;
    size_t *lane_at;     /* n_lanes + 1: where each lane's rays are in one */
    rs_wavelets wavelets; /* of the band being traced (coherence.h) */
    uint64_t splits;      /* crystal lens hits, for rs_coherence_split */
    colour_entry cc[CC_KINDS][RS_COLOUR_CACHE];
    size_t cc_n;          /* entries used per table */
    double *cc_val;       /* [(kind * cc_n + entry) * n_lanes + lane] */
    unsigned *cc_stamp;   /* the same */
    double *cc_half;      /* the same, of CC_EMISSION and CC_AMBIENT */
    unsigned char *cc_half_has; /* the same */
    rs_work work;         /* what this worker has traced (rs_worker_work) */
    unsigned long long lane_splits; /* rs_worker_splits */
    rs_worker *finer;     /* the next count's, made when first needed */
    rs_integrator *own_finer; /* the next count past the integrator's own
                             counts (refine_outlier), this worker's */
    int finer_failed;     /* it could not be made: no refinement */
};

/* Source ids: 0 ambient, 1 background, 2 + k light k, 2 + L + i object i. */
static int src_light(const rs_integrator *it, int k) { (void)it; return 2 + k; }
static int src_object(const rs_integrator *it, int i) { return 2 + (int)it->scene->n_lights + i; }

void rs_render_opts_init(rs_render_opts *o)
{
    o->mode = RS_MODE_POLARIZED;
    o->depth = 0;
    o->wavelengths = 16;
    o->cutoff = -1.0;
    o->width = 320;
    o->height = 240;
    o->aa = 1;
    o->refine_tol = 0.0;
    o->refine_max = 0;
    o->refine_outlier = 0.0;
    o->refine_limit = 0;
}

/* The linear sRGB colour of a light's spectrum (negative components of
 * out-of-gamut lines clipped): what the rgb mode lights the scene with. */
static rs_color light_colour(const rs_spectrum *s, double norm)
{
    double xyz[3] = {0, 0, 0}, cmf[3];
    rs_color c;
    if (s->type == RS_SPECTRUM_RGB)
        return s->rgb;
    if (s->type == RS_SPECTRUM_LINE) {
        rs_spectrum_line_xyz(s, xyz);
    } else {
        for (double l = RS_LAMBDA_MIN + 0.5; l < RS_LAMBDA_MAX; l += 1.0) {
            double e = rs_spectrum_emission_norm(s, norm, l);
            rs_cmf(l, cmf);
            for (int k = 0; k < 3; k++)
                xyz[k] += e * cmf[k];
        }
    }
    rs_xyz_to_linear_srgb(xyz, &c);
    c.r = c.r > 0.0 ? c.r : 0.0;
    c.g = c.g > 0.0 ? c.g : 0.0;
    c.b = c.b > 0.0 ? c.b : 0.0;
    return c;
}

/* Invert a 3x3 matrix; 0 if singular. */
static int invert3(const double a[3][3], double out[3][3])
{
    double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                 a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                 a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    if (!(fabs(det) > 1e-12))
        return 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
            out[i][j] = (a[i1][j1] * a[i2][j2] - a[i1][j2] * a[i2][j1]) / det;
        }
    return 1;
}

static int make_lane_tables(rs_integrator *it);

/* The lanes of a pixel (see struct rs_integrator) and their classes. */
static int make_lanes(rs_integrator *it)
{
    const rs_scene *sc = it->scene;
    int n = it->opts.mode == RS_MODE_RGB ? 3 : it->opts.wavelengths;
    if (it->opts.mode != RS_MODE_RGB)
        for (size_t k = 0; k < sc->n_lights; k++)
            n += sc->lights[k].spectrum.type == RS_SPECTRUM_LINE;
    it->lanes = calloc((size_t)n, sizeof *it->lanes);
    double *lambda = calloc((size_t)n, sizeof *lambda);
    if (!it->lanes || !lambda) {
        free(lambda);
        return -1;
    }
    it->n_lanes = n;
    if (it->opts.mode == RS_MODE_RGB) {
        for (int c = 0; c < 3; c++)
            it->lanes[c] = (band){BAND_RGB, RS_RGB_LAMBDA[c], -1, c, 0.0};
    } else {
        int m = it->opts.wavelengths, k = 0;
        double *weight = calloc((size_t)m, sizeof *weight);
        if (!weight) {
            free(lambda);
            return -1;
        }
        rs_quadrature(m, lambda, weight);
        for (; k < m; k++)
            it->lanes[k] = (band){BAND_CONTINUUM, lambda[k], -1, -1, weight[k]};
        free(weight);
        for (size_t l = 0; l < sc->n_lights; l++)
            if (sc->lights[l].spectrum.type == RS_SPECTRUM_LINE)
                it->lanes[k++] =
                    (band){BAND_LINE, sc->lights[l].spectrum.line_nm, (int)l, -1, 0.0};
    }
    for (int k = 0; k < n; k++)
        lambda[k] = it->lanes[k].lambda;
    int rc = rs_lane_classes_create(sc, lambda, n, &it->classes);
    free(lambda);
    return rc;
}

int rs_integrator_create(const rs_scene *scene, const rs_render_opts *opts, rs_integrator **out,
                         char *msg, size_t msg_size)
{
    rs_integrator *it = calloc(1, sizeof *it);
    *out = NULL;
    if (!it) {
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    it->scene = scene;
    it->opts = *opts;
    if (it->opts.wavelengths < 1)
        it->opts.wavelengths = 1;
    it->max_level = opts->depth > 0 ? opts->depth : scene->settings.max_trace_level;
    it->cutoff = opts->cutoff >= 0.0 ? opts->cutoff : scene->settings.adc_bailout;
    if (rs_camera_setup(&scene->camera, opts->width, opts->height, &it->view, msg, msg_size)) {
        free(it);
        return -1;
    }
    it->n_sources = 2 + (int)scene->n_lights + (int)scene->n_objects;
    it->coherent = calloc((size_t)it->n_sources, 1);
    it->coherence = calloc((size_t)it->n_sources, sizeof *it->coherence);
    it->light_norm = calloc(scene->n_lights + 1, sizeof *it->light_norm);
    it->light_rgb = calloc(scene->n_lights + 1, sizeof *it->light_rgb);
    if (!it->coherent || !it->coherence || !it->light_norm || !it->light_rgb) {
        free(it->coherent);
        free(it->coherence);
        free(it->light_norm);
        free(it->light_rgb);
        free(it);
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    for (int s = 0; s < it->n_sources; s++)
        it->coherent[s] = scene->settings.coherent != 0;
    for (size_t k = 0; k < scene->n_lights; k++) {
        rs_spectrum ls = scene->lights[k].spectrum;
        ls.rgb = scene->lights[k].color;
        it->light_norm[k] = rs_spectrum_norm(&ls);
        it->light_rgb[k] = light_colour(&ls, it->light_norm[k]);
    }
    /* The N wavelengths are the midpoints of N cells over 380-780 nm that
     * keep out of the steps of Smits' spectra (quadrature.h; no jitter: no
     * noise, the same for every pixel).  Emitter spectra are linear in
     * their RGB (rs_emission_shape), so the colour error of this
     * quadrature is one 3x3 matrix C: column k is the linear sRGB the
     * quadrature gives the unit emitter of channel k.  Pixels are
     * multiplied by C^-1, and every RGB emitter seen directly or through
     * clear glass renders as exactly its RGB, white included. */
    {
        double C[3][3], cmf[3];
        int n = it->opts.wavelengths;
        double *node = calloc((size_t)n, sizeof *node), *width = calloc((size_t)n, sizeof *width);
        if (!node || !width) {
            free(node);
            free(width);
            rs_integrator_destroy(it);
            snprintf(msg, msg_size, "out of memory");
            return -1;
        }
        rs_quadrature(n, node, width);
        for (int k = 0; k < 3; k++) {
            rs_color unit = {k == 0, k == 1, k == 2};
            rs_spectrum us = {RS_SPECTRUM_RGB, unit, 0.0, 0.0};
            double xyz[3] = {0, 0, 0};
            rs_color rgb;
            for (int m = 0; m < n; m++) {
                double e = rs_spectrum_emission(&us, node[m]);
                rs_cmf(node[m], cmf);
                for (int c = 0; c < 3; c++)
                    xyz[c] += e * cmf[c] * width[m];
            }
            rs_xyz_to_linear_srgb(xyz, &rgb);
            C[0][k] = rgb.r;
            C[1][k] = rgb.g;
            C[2][k] = rgb.b;
        }
        free(node);
        free(width);
        if (n < 3 || !invert3(C, it->correction)) {
            /* Fewer than three wavelengths cannot carry colour: render the
             * luminance as grey, scaled so that white is exactly 1. */
            double wy = 0.2126 * (C[0][0] + C[0][1] + C[0][2]) +
                        0.7152 * (C[1][0] + C[1][1] + C[1][2]) +
                        0.0722 * (C[2][0] + C[2][1] + C[2][2]);
            for (int r = 0; r < 3; r++)
                for (int c = 0; c < 3; c++)
                    it->correction[r][c] =
                        (c == 0 ? 0.2126 : c == 1 ? 0.7152 : 0.0722) / (wy > 0.0 ? wy : 1.0);
        }
    }
    for (size_t k = 0; k < scene->n_lights; k++)
        if (scene->lights[k].coherent) {
            it->coherent[src_light(it, (int)k)] = 1;
            it->coherence[src_light(it, (int)k)] = scene->lights[k].coherence_length;
        }
    for (int s = 0; s < it->n_sources; s++)
        it->interferes |= it->coherent[s];
    for (size_t i = 0; i < scene->n_objects; i++)
        it->interferes |= scene->objects[i].type == RS_OBJ_LENS && scene->objects[i].u.lens.desc.uniaxial;
    if (make_lanes(it) != 0 || make_lane_tables(it) != 0) {
        rs_integrator_destroy(it);
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    /* The refinement's counts up to refine_max, which most refined
     * pixels reach; past it only a few (refine_outlier), whose worker
     * makes the counts it needs (finer_worker). */
    if (it->opts.refine_tol > 0.0 && it->opts.mode != RS_MODE_RGB &&
        it->opts.wavelengths <= it->opts.refine_max / 2) {
        rs_render_opts f = it->opts;
        f.wavelengths *= 2;
        if (rs_integrator_create(scene, &f, &it->finer, msg, msg_size) != 0) {
            rs_integrator_destroy(it);
            return -1;
        }
    }
    *out = it;
    return 0;
}

void rs_integrator_destroy(rs_integrator *it)
{
    if (!it)
        return;
    free(it->coherent);
    free(it->coherence);
    free(it->light_norm);
    free(it->light_rgb);
    free(it->lanes);
    rs_lane_classes_destroy(it->classes);
    free(it->lane_light);
    free(it->lane_background);
    free(it->background_half);
    free(it->background_has);
    free(it->lane_xyz);
    rs_integrator_destroy(it->finer);
    free(it);
}

rs_worker *rs_worker_create(const rs_integrator *it)
{
    rs_worker *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    w->it = it;
    w->lane_all = calloc((size_t)it->n_lanes, sizeof *w->lane_all);
    w->lane_value = calloc((size_t)it->n_lanes, sizeof *w->lane_value);
    w->pixel_power = calloc((size_t)it->n_lanes, sizeof *w->pixel_power);
    w->lane_at = calloc((size_t)it->n_lanes + 1, sizeof *w->lane_at);
    w->cc_n = RS_COLOUR_CACHE;
    while (w->cc_n > 1 && w->cc_n * (size_t)it->n_lanes > RS_COLOUR_CACHE_LANES)
        w->cc_n /= 2;
    w->cc_val = calloc((size_t)CC_KINDS * w->cc_n * (size_t)it->n_lanes, sizeof *w->cc_val);
    w->cc_stamp = calloc((size_t)CC_KINDS * w->cc_n * (size_t)it->n_lanes, sizeof *w->cc_stamp);
    w->cc_half = calloc((size_t)CC_HALVES * w->cc_n * (size_t)it->n_lanes, sizeof *w->cc_half);
    w->cc_half_has = calloc((size_t)CC_HALVES * w->cc_n * (size_t)it->n_lanes, 1);
    if (!w->lane_all || !w->lane_value || !w->pixel_power || !w->lane_at || !w->cc_val || !w->cc_stamp ||
        !w->cc_half || !w->cc_half_has) {
        rs_worker_destroy(w);
        return NULL;
    }
    for (int k = 0; k < it->n_lanes; k++)
        w->lane_all[k] = k;
    return w;
}

/* Free a frame and all it holds (NULL: no-op). */
static void frame_free(frame *fr)
{
    if (!fr)
        return;
    for (int b = 0; b < fr->n_bws; b++)
        lp_backward_destroy(fr->bws[b]);
    free(fr->bws);
    free(fr->sub_at);
    free(fr->sub_lane);
    free(fr->sub_pos);
    free(fr->sub_lambda);
    free(fr->sub_ok);
    free(fr->sub_of);
    free(fr->slot);
    free(fr->child.r);
    free(fr->child.lane);
    free(fr->child.I);
    free(fr->child.has);
    free(fr->g_of);
    free(fr->g_ray);
    free(fr->g_start);
    free(fr->g_count);
    free(fr->g_rays);
    free(fr->bad);
    for (size_t k = 0; k < fr->n_kids; k++) {
        free(fr->kids[k].r);
        free(fr->kids[k].lane);
        free(fr->kids[k].I);
        free(fr->kids[k].has);
    }
    free(fr->kids);
    free(fr->gm_bw);
    free(fr->gm_b);
    free(fr->gm_q);
    free(fr->gm_n);
    free(fr->gm_start);
    free(fr->gm_lane);
    free(fr->gm_power);
    free(fr->cb);
    free(fr->hs);
    free(fr->light_v);
    free(fr->light_got);
    lp_result_release(&fr->res);
    free(fr->lane);
    free(fr->pos);
    free(fr->val);
    free(fr->acc);
    free(fr->done);
    free(fr->reach);
    free(fr);
}

void rs_worker_destroy(rs_worker *w)
{
    if (!w)
        return;
    rs_worker_destroy(w->finer);
    rs_integrator_destroy(w->own_finer);
    for (int f = 0; f < RS_MAX_FRAMES; f++)
        frame_free(w->frames[f]);
    free(w->lane_all);
    free(w->lane_value);
    free(w->pixel_power);
    free(w->lane_at);
    free(w->cc_val);
    free(w->cc_stamp);
    free(w->cc_half);
    free(w->cc_half_has);
    free(w->pixel.r);
    free(w->pixel.lane);
    free(w->pixel.I);
    free(w->pixel.has);
    free(w->one);
    free(w->one_i);
    rs_wavelets_free(&w->wavelets);
    free(w);
}

static frame *get_frame(rs_worker *w, int f)
{
    if (f < 0 || f >= RS_MAX_FRAMES)
        return NULL;
    if (!w->frames[f]) {
        frame *fr = calloc(1, sizeof *fr);
        size_t n = (size_t)w->it->n_lanes;
        if (!fr)
            return NULL;
        fr->lane = calloc(n, sizeof *fr->lane);
        fr->pos = calloc(n, sizeof *fr->pos);
        fr->val = calloc(n, sizeof *fr->val);
        fr->acc = calloc(n, sizeof *fr->acc);
        fr->done = calloc(n, 1);
        fr->reach = calloc(w->it->scene->n_lights + 1, sizeof *fr->reach);
        fr->bad = calloc(n, 1);
        fr->cb = calloc(w->it->scene->n_lights + 1, sizeof *fr->cb);
        fr->hs = calloc(w->it->scene->n_lights + 1, sizeof *fr->hs);
        fr->light_v = calloc(n, sizeof *fr->light_v);
        fr->light_got = calloc(n, 1);
        fr->bws = calloc(n, sizeof *fr->bws);
        fr->sub_at = calloc(n + 1, sizeof *fr->sub_at);
        fr->sub_lane = calloc(n, sizeof *fr->sub_lane);
        fr->sub_pos = calloc(n, sizeof *fr->sub_pos);
        fr->sub_lambda = calloc(n, sizeof *fr->sub_lambda);
        fr->sub_ok = calloc(n, 1);
        fr->sub_of = calloc(n, sizeof *fr->sub_of);
        fr->slot = malloc(n * sizeof *fr->slot);
        if (fr->slot)
            for (size_t k = 0; k < n; k++)
                fr->slot[k] = -1;
        if (!fr->lane || !fr->pos || !fr->val || !fr->acc || !fr->done || !fr->reach || !fr->bad ||
            !fr->cb || !fr->hs || !fr->light_v || !fr->light_got || !fr->bws || !fr->sub_at ||
            !fr->sub_lane || !fr->sub_pos || !fr->sub_lambda || !fr->sub_ok || !fr->sub_of || !fr->slot ||
            lp_backward_create(&fr->bws[0], NULL) != LP_OK) {
            frame_free(fr);
            return NULL;
        }
        fr->bw = fr->bws[0];
        fr->n_bws = 1;
        lp_result_init(&fr->res);
        w->frames[f] = fr;
    }
    return w->frames[f];
}

/* A new ray of lane `lane` at the end of b (NULL when out of memory). */
static lp_ray *bundle_push(bundle *b, int lane)
{
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 16;
        lp_ray *r = realloc(b->r, cap * sizeof *r);
        if (!r)
            return NULL;
        b->r = r;
        int *l = realloc(b->lane, cap * sizeof *l);
        if (!l)
            return NULL;
        b->lane = l;
        b->cap = cap;
    }
    b->lane[b->n] = lane;
    return &b->r[b->n++];
}

/* A new shared ray at the end of b; its vector in *I and *has (nl
 * entries each).  With clear, no lane has it yet (all 0); without, the
 * caller sets every entry.  A shared vector's intensity is 0 in every
 * lane that does not have the ray, so that a lane's sum may add the whole
 * vector.  NULL when out of memory. */
static inline lp_ray *bundle_push_shared(bundle *b, int nl, int clear, double **I,
                                         unsigned char **has)
{
    if (b->ns == b->scap) {
        size_t cap = b->scap ? 2 * b->scap : 8;
        double *pi = realloc(b->I, cap * (size_t)nl * sizeof *pi);
        if (!pi)
            return NULL;
        b->I = pi;
        unsigned char *ph = realloc(b->has, cap * (size_t)nl);
        if (!ph)
            return NULL;
        b->has = ph;
        b->scap = cap;
    }
    size_t s = b->ns;
    lp_ray *r = bundle_push(b, -1 - (int)s);
    if (!r)
        return NULL;
    b->ns++;
    *I = b->I + s * (size_t)nl;
    *has = b->has + s * (size_t)nl;
    if (clear) {
        memset(*has, 0, (size_t)nl);
        memset(*I, 0, (size_t)nl * sizeof **I);
    }
    return r;
}

static void bundle_clear(bundle *b)
{
    b->n = 0;
    b->ns = 0;
}

/* Append ray i of `from` to `to` (its lane, or a copy of its shared
 * vector), every intensity multiplied by scale; NULL when out of memory. */
static lp_ray *bundle_copy(bundle *to, const bundle *from, size_t i, double scale, int nl)
{
    int l = from->lane[i];
    lp_ray *p;
    if (l >= 0) {
        p = bundle_push(to, l);
    } else {
        double *I;
        unsigned char *has;
        size_t s = (size_t)(-1 - l);
        p = bundle_push_shared(to, nl, 0, &I, &has);
        if (p)
            for (int k = 0; k < nl; k++) {
                has[k] = from->has[s * (size_t)nl + (size_t)k];
                I[k] = has[k] ? from->I[s * (size_t)nl + (size_t)k] * scale : 0.0;
            }
    }
    if (!p)
        return NULL;
    *p = from->r[i];
    p->intensity *= scale;
    return p;
}

/* ---- small colour helpers ---- */
static double chan(rs_color c, int k) { return k == 0 ? c.r : (k == 1 ? c.g : c.b); }
static rs_color mul(rs_color a, rs_color b) { return (rs_color){a.r * b.r, a.g * b.g, a.b * b.b}; }

/* ---- what a band sees of colours, lights and glass ---- */

/* Radiance of an emitter whose colour is c. */
static double band_emission(const band *b, rs_color c)
{
    if (b->kind == BAND_RGB)
        return chan(c, b->channel);
    if (b->kind == BAND_LINE)
        return 0.0;
    rs_spectrum s = {RS_SPECTRUM_RGB, c, 0.0, 0.0};
    return rs_spectrum_emission(&s, b->lambda);
}

static double band_reflectance(const band *b, rs_color c)
{
    if (b->kind == BAND_RGB)
        return chan(c, b->channel);
    return rs_reflectance(c, b->lambda);
}

static double band_light_eval(const rs_integrator *it, const band *b, int k)
{
    const rs_light *l = &it->scene->lights[k];
    if (b->kind == BAND_RGB)
        return chan(it->light_rgb[k], b->channel);
    if (b->kind == BAND_LINE)
        return b->light == k ? 1.0 : 0.0;
    if (l->spectrum.type == RS_SPECTRUM_LINE)
        return 0.0;
    rs_spectrum s = l->spectrum;
    s.rgb = l->color; /* the colour, or the tint of a blackbody */
    return rs_spectrum_emission_norm(&s, it->light_norm[k], b->lambda);
}


/* The shared vector of the halves of a source for every lane 0..nl-1: a
 * lane that emits (lane_emits) has the ray with intensity 0.5 v[l], the
 * others have +0.  Every lane in one pass, the lanes kept by a bit mask
 * (no branch: it vectorizes). */
RS_WIDE static void halves_every_lane(int nl, const double *restrict v,
                                      const unsigned char *restrict got, double *restrict I,
                                      unsigned char *restrict has)
{
    for (int l = 0; l < nl; l++) {
        unsigned char keep = got ? got[l] != 0 : v[l] != 0.0;
        double x = 0.5 * v[l];
        uint64_t bits;
        memcpy(&bits, &x, sizeof bits);
        bits &= (uint64_t)0 - keep;
        has[l] = keep;
        memcpy(&I[l], &bits, sizeof bits);
    }
}

/* The tables of light and background per lane (see struct rs_integrator). */
static int make_lane_tables(rs_integrator *it)
{
    size_t nl = it->scene->n_lights, n = (size_t)it->n_lanes;
    it->lane_light = calloc(nl * n + 1, sizeof *it->lane_light);
    it->lane_background = calloc(n + 1, sizeof *it->lane_background);
    it->background_half = calloc(n + 1, sizeof *it->background_half);
    it->background_has = calloc(n + 1, 1);
    it->lane_xyz = calloc(3 * n + 1, sizeof *it->lane_xyz);
    if (!it->lane_light || !it->lane_background || !it->background_half ||
        !it->background_has || !it->lane_xyz)
        return -1;
    for (size_t k = 0; k < nl; k++)
        for (size_t i = 0; i < n; i++)
            it->lane_light[k * n + i] = band_light_eval(it, &it->lanes[i], (int)k);
    for (size_t i = 0; i < n; i++)
        it->lane_background[i] = band_emission(&it->lanes[i], it->scene->background);
    halves_every_lane(it->n_lanes, it->lane_background, NULL, it->background_half,
                      it->background_has);
    for (size_t i = 0; i < n && it->opts.mode != RS_MODE_RGB; i++) {
        const band *b = &it->lanes[i];
        if (b->kind == BAND_CONTINUUM) {
            rs_cmf(b->lambda, &it->lane_xyz[3 * i]);
            for (int c = 0; c < 3; c++)
                it->lane_xyz[3 * i + c] *= b->weight;
        } else {
            const rs_light *l = &it->scene->lights[b->light];
            rs_spectrum s = l->spectrum;
            s.rgb = l->color; /* the tint of the line */
            rs_spectrum_line_xyz(&s, &it->lane_xyz[3 * i]);
        }
    }
    return 0;
}

/* lane_colour's entry of colour c (in the table of each use): the hash
 * of its bits picks it. */
static size_t colour_slot(const rs_worker *w, rs_color c)
{
    uint64_t u[3], h;
    memcpy(&u[0], &c.r, sizeof u[0]);
    memcpy(&u[1], &c.g, sizeof u[1]);
    memcpy(&u[2], &c.b, sizeof u[2]);
    h = (u[0] * 0x9E3779B97F4A7C15u) ^ (u[1] * 0xC2B2AE3D27D4EB4Fu) ^ (u[2] * 0x165667B19E3779F9u);
    return (size_t)(h >> 58) & (w->cc_n - 1);
}

/* lane_colour where entry e does not yet hold c in every lane. */
static const double *lane_colour_fill(rs_worker *w, int kind, size_t e, rs_color c,
                                      const int *lane, int n)
{
    const rs_integrator *it = w->it;
    colour_entry *ce = &w->cc[kind][e];
    size_t at = ((size_t)kind * w->cc_n + e) * (size_t)it->n_lanes;
    double *v = w->cc_val + at;
    unsigned *stamp = w->cc_stamp + at;
    if (ce->gen == 0 || memcmp(&ce->c, &c, sizeof c) != 0) {
        ce->c = c;
        ce->n_valid = 0;
        ce->dark = 0;
        ce->half = NULL;
        ce->half_has = NULL;
        if (++ce->gen == 0) { /* wrapped: no stamp may match a new generation */
            memset(stamp, 0, (size_t)it->n_lanes * sizeof *stamp);
            ce->gen = 1;
        }
    }
    if (ce->n_valid == it->n_lanes)
        return v;
    int refl = kind == CC_PIGMENT || kind == CC_MIRROR_MAX || kind == CC_MIRROR_MIN;
    for (int k = 0; k < n; k++) {
        int l = lane[k];
        if (stamp[l] == ce->gen)
            continue;
        v[l] = refl ? band_reflectance(&it->lanes[l], c) : band_emission(&it->lanes[l], c);
        stamp[l] = ce->gen;
        ce->n_valid++;
    }
    if (ce->n_valid == it->n_lanes) {
        int dark = 1;
        for (int l = 0; l < it->n_lanes; l++)
            dark &= !(v[l] != 0.0);
        ce->dark = dark;
        if (kind < CC_HALVES) {
            halves_every_lane(it->n_lanes, v, NULL, w->cc_half + at, w->cc_half_has + at);
            ce->half = w->cc_half + at;
            ce->half_has = w->cc_half_has + at;
        }
    }
    return v;
}

/* Colour c for use `kind` (see colour_entry) in lanes lane[0..n), at
 * [lane] of the array returned (the other lanes' values may be stale):
 * band_reflectance for the pigment and mirror colours, band_emission for
 * the others; its entry in *entry.  Valid until the next look-up of this
 * kind.  Inline, the look-up of a colour held in every lane already (the
 * usual case). */
static inline const double *lane_colour_entry(rs_worker *w, int kind, rs_color c,
                                              const int *lane, int n,
                                              const colour_entry **entry)
{
    size_t e = colour_slot(w, c);
    const colour_entry *ce = &w->cc[kind][e];
    *entry = ce;
    if (ce->gen != 0 && ce->n_valid == w->it->n_lanes && memcmp(&ce->c, &c, sizeof c) == 0)
        return w->cc_val + ((size_t)kind * w->cc_n + e) * (size_t)w->it->n_lanes;
    return lane_colour_fill(w, kind, e, c, lane, n);
}

/* lane_colour_entry without the entry. */
static inline const double *lane_colour(rs_worker *w, int kind, rs_color c, const int *lane,
                                        int n)
{
    const colour_entry *ce;
    return lane_colour_entry(w, kind, c, lane, n, &ce);
}

/* The parity (0 or 1) of floor(v + 1e-10) for any v: below 2^62 the
 * integer's own low bit (two's complement: -3 is odd too), the floor
 * taken as the cast's truncation, one less where that lies above (exact:
 * the truncation of a double is a double); beyond, where a cast to long
 * long would overflow, fmod, exact at every magnitude (a double beyond
 * 2^53 is an integer); not finite: 0. */
static int floor_parity(double v)
{
    double x = v + 1e-10;
    if (fabs(x) < 0x1p62) {
        long long i = (long long)x;
        i -= (double)i > x;
        return (int)(i & 1);
    }
    double r = fmod(floor(x), 2.0);
    return r != 0.0 && r == r; /* -1 or 1: odd; NaN: 0 */
}

static rs_color pigment_at(const rs_pigment *p, lp_vec3 x)
{
    if (p->type != RS_PIGMENT_CHECKER)
        return p->color[0];
    lp_vec3 q = rs_xf_point(&p->to_pattern, x);
    int s = floor_parity(q.x) + floor_parity(q.y) + floor_parity(q.z);
    return p->color[s & 1];
}

/* Does the straight segment x + t d, t in (t0, t1), meet the lens's rim?
 * A shadow ray crosses clear glass as a straight segment (POV-Ray: no
 * refraction, no Fresnel loss), so it is blocked only where it meets the
 * rim, from outside or from inside the glass, whatever the caps in front
 * of it.  A lens has at most two cap crossings per cap and two rim
 * crossings, so a handful of steps past the cap hits always ends. */
static int segment_meets_rim(const lp_lens *lens, lp_vec3 x, lp_vec3 d, double t0, double t1)
{
    for (int step = 0; step < 8 && t0 < t1; step++) {
        lp_hit h;
        if (!lp_lens_intersect(lens, x, d, t0, t1, &h))
            return 0;
        if (h.surface == LP_SURFACE_RIM)
            return 1;
        t0 = h.t + 1e-12 * (1.0 + h.t);
    }
    return 0;
}

/* The fraction of light k's power that reaches x along the straight
 * segment between them: 0 where a lens rim or an opaque object is in the
 * way (clear glass casts no shadow, as in POV-Ray), else the product of
 * what the polarizers on the segment pass.  In the polarized mode the
 * light leaves as its own linear polarization (`polarization <v>`, made
 * perpendicular to the segment) or as natural light (two orthogonal
 * incoherent halves), and each polarizer, from the light on, projects it
 * on its axis (Malus's law, the axis taken perpendicular to the segment,
 * as for camera rays); the unpolarized models pass half at each. */
#define RS_SHADOW_POLARIZERS 16

/* What the segment meets: the polarizers on it, sorted from the light
 * (far end) towards x, equal distances in object order. */
typedef struct shadow_seg {
    const rs_scene *sc;
    lp_vec3 x, d;
    double eps, dist;
    size_t pol[RS_SHADOW_POLARIZERS];
    double tpol[RS_SHADOW_POLARIZERS];
    int np;
} shadow_seg;

/* 1 when object i ends the segment (or it meets more polarizers than any
 * stack of ideal polarizers needs); a polarizer it meets is recorded.
 * The result does not depend on the order objects are offered in. */
static int shadow_meets(void *ctx, int i)
{
    shadow_seg *s = ctx;
    const rs_object *o = &s->sc->objects[i];
    rs_hit h;
    if (o->type == RS_OBJ_LENS)
        return o->lens && segment_meets_rim(o->lens, s->x, s->d, s->eps, s->dist);
    if (!rs_object_intersect(o, s->x, s->d, s->eps, s->dist, &h))
        return 0;
    if (o->type != RS_OBJ_POLARIZER || s->np == RS_SHADOW_POLARIZERS)
        return 1;
    int at = s->np++;
    while (at > 0 && (s->tpol[at - 1] < h.t ||
                      (s->tpol[at - 1] == h.t && s->pol[at - 1] > (size_t)i))) {
        s->pol[at] = s->pol[at - 1];
        s->tpol[at] = s->tpol[at - 1];
        at--;
    }
    s->pol[at] = (size_t)i;
    s->tpol[at] = h.t;
    return 0;
}

static double light_reach(const rs_integrator *it, lp_vec3 x, int k)
{
    const rs_scene *sc = it->scene;
    const rs_light *l = &sc->lights[k];
    lp_vec3 d = {l->position.x - x.x, l->position.y - x.y, l->position.z - x.z};
    double dist = sqrt(v3_dot(d, d));
    if (!(dist > 0.0))
        return 1.0;
    d = (lp_vec3){d.x / dist, d.y / dist, d.z / dist};
    shadow_seg sg;
    sg.sc = sc;
    sg.x = x;
    sg.d = d;
    sg.eps = 1e-9 * (1.0 + sqrt(v3_dot(x, x)));
    sg.dist = dist;
    sg.np = 0;
    int blocked = 0;
    if (rs_bvh_serves(sc->bvh, sc)) {
        blocked = rs_bvh_any(sc->bvh, x, d, sg.eps, dist, shadow_meets, &sg);
    } else {
        rs_slab_ray r;
        int boxes = sc->bvh && rs_bvh_object_count(sc->bvh) == sc->n_objects, ready = 0;
        for (size_t i = 0; i < sc->n_objects && !blocked; i++) {
            if (boxes && rs_bvh_culls(sc->bvh, (int)i)) { /* the ray for boxes, once needed */
                if (!ready)
                    rs_slab_ray_init(&r, x, d);
                ready = 1;
                if (!rs_bvh_may_meet(sc->bvh, (int)i, &r, sg.eps, dist))
                    continue;
            }
            blocked = shadow_meets(&sg, (int)i);
        }
    }
    if (blocked)
        return 0.0;
    const size_t *pol = sg.pol;
    int np = sg.np;
    if (np == 0)
        return 1.0;
    if (it->opts.mode != RS_MODE_POLARIZED)
        return ldexp(1.0, -np);
    /* the light's state: up to two linear, mutually incoherent parts */
    double I[2];
    lp_vec3 v[2];
    int nv;
    lp_vec3 pv = l->polarization;
    pv = v3_madd(pv, d, -v3_dot(pv, d));
    if (l->polarized && v3_dot(pv, pv) > 0.0) {
        nv = 1;
        I[0] = 1.0;
        v[0] = v3_unit_or_self(pv);
    } else {
        lp_vec3 hh = fabs(d.y) < 0.9 ? (lp_vec3){0, 1, 0} : (lp_vec3){1, 0, 0};
        nv = 2;
        I[0] = I[1] = 0.5;
        v[0] = v3_unit_or_self(v3_cross(d, hh));
        v[1] = v3_cross(d, v[0]);
    }
    for (int q = 0; q < np; q++) {
        lp_vec3 ax = sc->objects[pol[q]].u.polarizer.axis;
        ax = v3_unit_or_self(v3_madd(ax, d, -v3_dot(ax, d)));
        for (int m = 0; m < nv; m++) {
            double c = v3_dot(v[m], ax);
            I[m] *= c * c;
            v[m] = ax;
        }
    }
    return nv == 1 ? I[0] : I[0] + I[1];
}

/* Light leaving a diffuse/emissive surface towards the viewer, per source:
 * calls emit(source, radiance) for each non-zero source. */
typedef void (*emit_fn)(void *ctx, int source, double radiance);

/* POV-Ray 3.7's highlights for one light (see rs_finish): phong about the
 * mirror direction, specular (Blinn) about the half vector; the light's
 * colour, not the pigment's. */
static double highlight(const rs_finish *f, lp_vec3 n, lp_vec3 d, lp_vec3 l)
{
    double s = 0.0;
    if (f->phong > 0.0) {
        lp_vec3 r = v3_madd(d, n, -2.0 * v3_dot(d, n));
        double c = v3_dot(r, l);
        if (c > 0.0)
            s += f->phong * pow(c, f->phong_size);
    }
    if (f->specular > 0.0) {
        lp_vec3 hv = v3_unit_or_self((lp_vec3){l.x - d.x, l.y - d.y, l.z - d.z});
        double c = v3_dot(hv, n);
        if (c > 0.0)
            s += f->specular * pow(c, 1.0 / f->roughness);
    }
    return s;
}

/* What shading a point needs that no band changes, computed once for all
 * the lanes of a packet: the pigment, the shadow-ray origin, per light
 * the cosine term (c^brilliance, or -1 where the light is behind) and the
 * highlights, and the memo of light_reach. */
typedef struct shade_point {
    const rs_hit *h;
    rs_color pig;
    lp_vec3 x;
    double *cb, *s, *reach; /* per light */
    /* per lane of the packet (lane_colour): valid until the worker shades
     * another point */
    const double *emission, *ambient, *pigment;
    const colour_entry *emission_entry, *ambient_entry; /* their entries */
} shade_point;

static void shade_begin(rs_worker *w, const int *lane, int n, const rs_hit *h, lp_vec3 dir,
                        frame *fr, shade_point *sp)
{
    const rs_integrator *it = w->it;
    const rs_scene *sc = it->scene;
    const rs_object *o = h->surface;
    const rs_finish *f = &o->finish;
    sp->h = h;
    sp->pig = pigment_at(&o->pigment, h->point);
    sp->emission = lane_colour_entry(w, CC_EMISSION, mul(sp->pig, f->emission), lane, n,
                                     &sp->emission_entry);
    sp->ambient = lane_colour_entry(w, CC_AMBIENT,
                                    mul(sp->pig, mul(f->ambient, sc->settings.ambient_light)),
                                    lane, n, &sp->ambient_entry);
    sp->pigment = lane_colour(w, CC_PIGMENT, sp->pig, lane, n);
    sp->x = v3_madd(h->point, h->normal, 1e-9 * (1.0 + sqrt(v3_dot(h->point, h->point))));
    sp->cb = fr->cb;
    sp->s = fr->hs;
    sp->reach = fr->reach;
    for (size_t k = 0; k < sc->n_lights; k++) {
        const rs_light *l = &sc->lights[k];
        lp_vec3 x = sp->x;
        lp_vec3 ld = v3_unit_or_self((lp_vec3){l->position.x - x.x, l->position.y - x.y,
                                    l->position.z - x.z});
        double c = v3_dot(ld, h->normal);
        sp->s[k] = highlight(f, h->normal, dir, ld);
        sp->cb[k] = c > 0.0 ? (f->brilliance == 1.0 ? c : pow(c, f->brilliance)) : -1.0;
        sp->reach[k] = NAN;
    }
}

/* Light leaving the surface at sp towards the viewer, in band b, per
 * source: emission, ambient, and for each visible light diffuse
 * (N.L)^brilliance plus the highlights.  Calls emit(source, radiance) for
 * each non-zero source.  The lanes of a packet share sp, and with it
 * their shadow rays. */
/* What light k adds at sp in lane `lane` to a surface of diffuse
 * reflectance rho there: 1 and the radiance in *v, or 0 where it adds
 * nothing (behind the surface, dark in the lane, or in shadow). */
static int light_term(const rs_integrator *it, shade_point *sp, double rho, size_t lane, size_t k,
                      double *v)
{
    double s = sp->s[k];
    double diff = sp->cb[k] >= 0.0 ? rho * sp->cb[k] : 0.0;
    if (diff + s <= 0.0)
        return 0;
    double p = it->lane_light[k * (size_t)it->n_lanes + lane];
    if (p == 0.0)
        return 0;
    if (isnan(sp->reach[k]))
        sp->reach[k] = light_reach(it, sp->x, (int)k);
    p *= sp->reach[k];
    if (p == 0.0)
        return 0;
    *v = (diff + s) * p;
    return 1;
}

/* Whether a surface of diffuse reflectance rho reflects any light. */
static int lit(const rs_finish *f, double rho)
{
    return !(rho == 0.0 && f->phong == 0.0 && f->specular == 0.0);
}

static void shade(const rs_integrator *it, const band *b, shade_point *sp, emit_fn emit,
                  void *ctx)
{
    const rs_scene *sc = it->scene;
    const rs_hit *h = sp->h;
    const rs_finish *f = &h->surface->finish;
    size_t lane = (size_t)(b - it->lanes);
    double e = sp->emission[lane], v;
    if (e != 0.0)
        emit(ctx, src_object(it, h->object), e);
    double a = sp->ambient[lane];
    if (a != 0.0)
        emit(ctx, 0, a);
    if (sc->n_lights == 0)
        return;
    double rho = sp->pigment[lane] * f->diffuse;
    if (!lit(f, rho))
        return;
    for (size_t k = 0; k < sc->n_lights; k++)
        if (light_term(it, sp, rho, lane, k, &v))
            emit(ctx, src_light(it, (int)k), v);
}

/* The mirror reflectivity of a surface in each lane lane[k] of a packet
 * for a ray along d, into r[k] (0: none): `reflection` as
 * min + (max - min) F, F the unpolarized Fresnel reflectance into the
 * object's ior with fresnel on, else max. */
static void reflectivities(rs_worker *w, const int *lane, int n, const rs_object *o,
                           const rs_hit *h, lp_vec3 d, double *r)
{
    const rs_finish *f = &o->finish;
    const double *rmax = lane_colour(w, CC_MIRROR_MAX, f->reflection_max, lane, n);
    if (!f->fresnel) {
        for (int k = 0; k < n; k++)
            r[k] = rmax[lane[k]];
        return;
    }
    const double *rmin = lane_colour(w, CC_MIRROR_MIN, f->reflection_min, lane, n);
    double ci = -v3_dot(d, h->normal), nn = o->ior;
    double F = 0.0;
    if (ci > 1.0)
        ci = 1.0;
    double st2 = (1.0 - ci * ci) / (nn * nn);
    if (st2 >= 1.0) {
        F = 1.0;
    } else if (nn != 1.0) {
        double ct = sqrt(1.0 - st2);
        double rs = (ci - nn * ct) / (ci + nn * ct), rp = (nn * ci - ct) / (nn * ci + ct);
        F = 0.5 * (rs * rs + rp * rp);
    }
    for (int k = 0; k < n; k++)
        r[k] = rmin[lane[k]] + (rmax[lane[k]] - rmin[lane[k]]) * F;
}

static int has_reflection(const rs_finish *f)
{
    const rs_color a = f->reflection_min, c = f->reflection_max;
    return a.r > 0.0 || a.g > 0.0 || a.b > 0.0 || c.r > 0.0 || c.g > 0.0 || c.b > 0.0;
}

/* ---- the unpolarized modes: one number per ray ---- */

static lp_mode lens_mode(const rs_integrator *it)
{
    return it->opts.mode == RS_MODE_SCHLICK ? LP_MODE_SCHLICK
           : it->opts.mode == RS_MODE_POLARIZED ? LP_MODE_POLARIZED
                                                : LP_MODE_FRESNEL;
}

static void emit_sum(void *ctx, int source, double radiance)
{
    (void)source;
    *(double *)ctx += radiance;
}

/* The arguments of a lens hit's trace at this level and weight; 0 when
 * no level is left for it. */
static int lens_args(const rs_integrator *it, int level, double weight, lp_trace_args *a)
{
    int dT = it->max_level - level;
    if (dT < 1)
        return 0;
    lp_trace_args_init(a);
    a->mode = lens_mode(it);
    a->max_depth = dT < LP_MAX_DEPTH ? dT : LP_MAX_DEPTH;
    a->min_weight = weight > 0.0 ? it->cutoff / weight : INFINITY;
    return 1;
}

/* Whether a packet of n lanes split into ns sub-packets at lens ob has
 * every lane alone (a wavelength of its own), several of them, at a lens
 * that is not a crystal: their gathers then go at once (gather_all). */
static int every_lane_alone(int ns, int n, const rs_object *ob)
{
    return ns == n && n > 1 && !ob->u.lens.desc.uniaxial;
}

/* The builds of sub-packets [from, from + BUILD_CHUNK) of the frame's
 * lens hit (lens_builds) into bws[0 ..): at a dispersive lens one
 * lp_backward_build_many for their wavelengths, each build exactly
 * lp_backward_build's.  A chunk, not all of them: a hit of 1024
 * wavelengths alone would hold 1024 builds, megabytes that no cache
 * keeps (default.scene at 128 x 96, depth 8, cut-off 1e-3, one thread,
 * farm-bench medians: 0.67 s at 256 wavelengths, 4.12 s at 1024, 6.1
 * times for 4 times the wavelengths; in chunks 0.60 s and 2.17 s).
 * Returns -1 when out of memory. */
static int build_chunk(frame *fr, int from)
{
    int to = fr->n_sub - from > BUILD_CHUNK ? from + BUILD_CHUNK : fr->n_sub, nb = to - from;
    for (int s = fr->n_bws; s < nb; s++) {
        if (lp_backward_create(&fr->bws[s], NULL) != LP_OK)
            return -1;
        fr->n_bws++;
    }
    int all = nb > 1 && lp_backward_build_many(fr->bws, (size_t)nb, fr->b_lens, fr->b_o, fr->b_d,
                                               fr->sub_lambda + from, &fr->b_args,
                                               NULL) == LP_OK;
    /* else each alone, to know which build fails (a sub-packet whose
     * build fails sees nothing) */
    for (int s = 0; s < nb; s++)
        fr->sub_ok[from + s] = all || lp_backward_build(fr->bws[s], fr->b_lens, fr->b_o, fr->b_d,
                                                        fr->sub_lambda[from + s], &fr->b_args,
                                                        NULL) == LP_OK;
    fr->built_at = from;
    fr->built_end = to;
    return 0;
}

/* A lens hit of the packet lane[0..n) at lens `object` along (o, d): its
 * sub-packets (lanes of equal optics there, rs_packet_split, in the
 * frame's sub_ arrays) and the builds of the first BUILD_CHUNK of them
 * (build_chunk).  power: the gathers of a hit whose every lane is alone
 * will want their power only (camera_power), so those builds make their
 * queries' power forms (LP_BACKWARD_POWER).  lens_next then hands them
 * out in order, building the next chunk as it comes to it.  Returns -1
 * when out of memory. */
static int lens_builds(rs_worker *w, frame *fr, const rs_object *ob, int object,
                       const int *lane, int n, lp_vec3 o, lp_vec3 d, const lp_trace_args *a,
                       int power)
{
    const rs_integrator *it = w->it;
    int ns = rs_packet_split(it->classes, object, lane, n, fr->sub_at, fr->sub_pos, fr->sub_of,
                             fr->slot);
    lp_trace_args pa;
    w->lane_splits += ns > 1;
    if (power && every_lane_alone(ns, n, ob)) { /* gathered for their power alone */
        pa = *a;
        pa.flags |= LP_BACKWARD_POWER;
        a = &pa;
    }
    for (int s = 0; s < ns; s++) {
        for (int k = fr->sub_at[s]; k < fr->sub_at[s + 1]; k++)
            fr->sub_lane[k] = lane[fr->sub_pos[k]];
        fr->sub_lambda[s] = it->lanes[fr->sub_lane[fr->sub_at[s]]].lambda;
    }
    fr->n_sub = ns;
    fr->sub_next = 0;
    fr->b_lens = ob->lens;
    fr->b_o = o;
    fr->b_d = d;
    fr->b_args = *a;
    return build_chunk(fr, 0);
}

/* The next sub-packet of lens_builds whose build succeeded: its lanes in
 * fr->lane, their positions in the packet in fr->pos, its build in
 * fr->bw; at the end of a chunk it builds the next (the builds before it
 * are then gone), or with hold returns -1 for the caller to call
 * build_chunk once done with them.  Returns how many lanes, 0 when no
 * sub-packet is left (or, out of memory, none can be built: the hit
 * stops there). */
static int lens_next(frame *fr, int hold)
{
    while (fr->sub_next < fr->n_sub) {
        if (fr->sub_next == fr->built_end) {
            if (hold)
                return -1;
            if (build_chunk(fr, fr->sub_next) != 0)
                return 0;
        }
        int s = fr->sub_next++, at = fr->sub_at[s], m = fr->sub_at[s + 1] - at;
        if (!fr->sub_ok[s])
            continue;
        memcpy(fr->lane, fr->sub_lane + at, (size_t)m * sizeof *fr->lane);
        memcpy(fr->pos, fr->sub_pos + at, (size_t)m * sizeof *fr->pos);
        fr->bw = fr->bws[s - fr->built_at];
        return m;
    }
    return 0;
}

/* The radiance of every lane of lane[0..n) (indices of it->lanes) seen
 * along the ray, into out[0..n).  The lanes travel as one spectral packet
 * (packet.h) and split at a lens where their optics differ; each lane's
 * sums are formed in the same order as if it were traced alone. */
static void trace_scalar_hit(rs_worker *w, const int *lane, int n, lp_vec3 o, lp_vec3 d,
                             const rs_hit *hit, int level, double weight, int f, double *out);

static void trace_scalar(rs_worker *w, const int *lane, int n, lp_vec3 o, lp_vec3 d, int level,
                         double weight, int skip, int f, double *out)
{
    rs_hit h;
    int found = rs_scene_intersect(w->it->scene, o, d, 0.0, INFINITY, skip, &h);
    trace_scalar_hit(w, lane, n, o, d, found ? &h : NULL, level, weight, f, out);
}

/* Where query j of a lens hit's sub-packet meets the scene (NULL:
 * nowhere).  The lens hit was object `object` (a lens of the scene's own
 * list, or a CSG's member: -1): where the build certifies that the query
 * ray cannot meet its lens again (lp_backward_query_leaves), the lens is
 * left out of the test, which finds the same hit.  The reflection off the
 * outside (depth 1) does not depend on the wavelength: its hit is kept for
 * the next sub-packet of the same lens hit (a dispersive lens splits every
 * lane off), which meets the scene at the same point when its ray is the
 * same. */
static const rs_hit *query_hit(const rs_scene *sc, frame *fr, const lp_query *q, size_t j,
                               int object)
{
    query_memo *m = &fr->qm;
    q += j;
    if (q->depth != 1) {
        int skip = object >= 0 && lp_backward_query_leaves(fr->bw, j) ? object : -1;
        int found = rs_scene_intersect(sc, q->origin, q->dir, 0.0, INFINITY, skip, &m->h_other);
        return found ? &m->h_other : NULL;
    }
    if (!m->valid || memcmp(&m->origin, &q->origin, sizeof m->origin) != 0 ||
        memcmp(&m->dir, &q->dir, sizeof m->dir) != 0) {
        int skip = object >= 0 && lp_backward_query_leaves(fr->bw, j) ? object : -1;
        m->origin = q->origin;
        m->dir = q->dir;
        m->found = rs_scene_intersect(sc, q->origin, q->dir, 0.0, INFINITY, skip, &m->h);
        m->valid = 1;
    }
    return m->found ? &m->h : NULL;
}

/* The object index of a lens hit h for query_hit: h.object when the lens
 * is that object itself, -1 when it is a member of it (a CSG). */
static int lens_object(const rs_scene *sc, const rs_hit *h)
{
    return &sc->objects[h->object] == h->surface ? h->object : -1;
}

/* trace_scalar once the ray's hit is known (NULL: it meets nothing). */
static void trace_scalar_hit(rs_worker *w, const int *lane, int n, lp_vec3 o, lp_vec3 d,
                             const rs_hit *hit, int level, double weight, int f, double *out)
{
    const rs_integrator *it = w->it;
    const rs_scene *sc = it->scene;

    w->work.rays += 1.0;
    w->work.lane_rays += n;
    if (!hit) {
        for (int k = 0; k < n; k++)
            out[k] = it->lane_background[lane[k]];
        return;
    }
    const rs_hit h = *hit;
    for (int k = 0; k < n; k++)
        out[k] = 0.0;
    const rs_object *ob = h.surface;
    if (ob->type == RS_OBJ_LENS) {
        int m;
        frame *fr = get_frame(w, f);
        lp_trace_args a;
        if (!fr || !lens_args(it, level, weight, &a))
            return;
        fr->qm.valid = 0;
        if (lens_builds(w, fr, ob, h.object, lane, n, o, d, &a, 0) != 0)
            return;
        while ((m = lens_next(fr, 0)) > 0) {
            size_t nq = lp_backward_query_count(fr->bw);
            const lp_query *q = lp_backward_queries(fr->bw);
            w->work.builds += 1.0;
            for (int k = 0; k < m; k++)
                fr->acc[k] = 0.0;
            for (size_t j = 0; j < nq; j++) {
                trace_scalar_hit(w, fr->lane, m, q[j].origin, q[j].dir,
                                 query_hit(sc, fr, q, j, lens_object(sc, &h)),
                                 level + q[j].depth, weight * q[j].weight, f + 1, fr->val);
                for (int k = 0; k < m; k++)
                    fr->acc[k] += q[j].weight * fr->val[k];
            }
            for (int k = 0; k < m; k++)
                out[fr->pos[k]] = fr->acc[k];
        }
        return;
    }
    if (ob->type == RS_OBJ_POLARIZER) {
        /* Natural light through an ideal polarizer: half of it. */
        if (f + 1 >= RS_MAX_FRAMES)
            return;
        trace_scalar(w, lane, n, h.point, d, level, 0.5 * weight, h.object, f + 1, out);
        for (int k = 0; k < n; k++)
            out[k] = 0.5 * out[k];
        return;
    }
    frame *fr = get_frame(w, f);
    if (!fr)
        return;
    shade_point sp;
    shade_begin(w, lane, n, &h, d, fr, &sp);
    for (int k = 0; k < n; k++)
        shade(it, &it->lanes[lane[k]], &sp, emit_sum, &out[k]);
    if (!has_reflection(&ob->finish) || level >= it->max_level || f + 1 >= RS_MAX_FRAMES)
        return;
    lp_vec3 rd = v3_unit_or_self(v3_madd(d, h.normal, -2.0 * v3_dot(d, h.normal)));
    lp_vec3 x = v3_madd(h.point, h.normal, 1e-9 * (1.0 + sqrt(v3_dot(h.point, h.point))));
    /* The mirror ray, shared by the lanes of equal reflectivity (they
     * carry the same weight on). */
    reflectivities(w, lane, n, ob, &h, d, fr->val);
    for (int k = 0; k < n; k++) {
        double r = fr->val[k];
        fr->done[k] = !(r > 0.0 && weight * r >= it->cutoff);
    }
    for (int k = 0; k < n; k++) {
        if (fr->done[k])
            continue;
        double r = fr->val[k];
        int m = 0;
        for (int j = k; j < n; j++)
            if (!fr->done[j] && fr->val[j] == r) {
                fr->done[j] = 1;
                fr->pos[m] = j;
                fr->lane[m++] = lane[j];
            }
        trace_scalar(w, fr->lane, m, x, rd, level + 1, weight * r, -1, f + 1, fr->acc);
        for (int j = 0; j < m; j++)
            out[fr->pos[j]] += r * fr->acc[j];
    }
}

/* ---- the polarized mode: bundles ---- */

typedef struct emit_ctx {
    bundle *out;
    lp_vec3 v1, v2; /* the halves' fields, across the ray's direction */
    long wavelet;   /* its index in the worker's table */
    int lane;
} emit_ctx;

/* An emit_ctx for light leaving along -d into out. */
static emit_ctx emit_ctx_make(bundle *out, lp_vec3 d, long wavelet)
{
    lp_vec3 h = fabs(d.y) < 0.9 ? (lp_vec3){0, 1, 0} : (lp_vec3){1, 0, 0};
    emit_ctx e;
    e.out = out;
    e.v1 = v3_unit_or_self(v3_cross(d, h));
    e.v2 = v3_cross(d, e.v1);
    e.wavelet = wavelet;
    e.lane = 0;
    return e;
}

/* One half of natural light of a source: the ray, its intensity unset. */
static void half_ray(const emit_ctx *e, int source, int half, lp_ray *r)
{
    memset(r, 0, sizeof *r);
    r->vp = half ? e->v2 : e->v1;
    r->op = 0.0;
    r->ch = rs_coherence_ch(e->wavelet, source, half);
}

/* Natural light of one source as two orthogonal incoherent halves, in
 * lane e->lane. */
static void emit_halves(void *ctx, int source, double radiance)
{
    emit_ctx *e = ctx;
    for (int half = 0; half < 2; half++) {
        lp_ray *r = bundle_push(e->out, e->lane);
        if (!r)
            return;
        half_ray(e, source, half, r);
        r->intensity = 0.5 * radiance;
    }
}

/* Whether lane l emits in shared_halves: got[l] set (got NULL: v[l] != 0). */
static inline int lane_emits(const double *v, const unsigned char *got, int l)
{
    return got ? got[l] != 0 : v[l] != 0.0;
}

/* The pair of shared halves (emit_halves for several lanes at once) of
 * one source for the lanes lane[0..n) that emit there: those with
 * got[l] set (got NULL: those with v[l] != 0), l = lane[k], radiance
 * v[l]; none when no lane emits.  The vector of a packet of every lane
 * (n == nl: its lanes are 0..nl-1 in some order) is half and half_has,
 * halves_every_lane of v kept with it, where given (not NULL), else
 * filled in a loop that vectorizes.  Returns -1 when out of memory. */
static int shared_halves(int nl, const emit_ctx *e, int source, const int *lane, int n,
                         const double *v, const unsigned char *got, const double *half,
                         const unsigned char *half_has)
{
    bundle *out = e->out;
    double *I;
    unsigned char *has;
    int every = n == nl, k = 0;
    while (k < n && !lane_emits(v, got, lane[k]))
        k++;
    if (k == n)
        return 0;
    lp_ray *r = bundle_push_shared(out, nl, !every, &I, &has);
    if (!r)
        return -1;
    half_ray(e, source, 0, r);
    r->intensity = 0.5 * v[lane[k]];
    if (every && half) {
        memcpy(I, half, (size_t)nl * sizeof *I);
        memcpy(has, half_has, (size_t)nl);
    } else if (every) {
        halves_every_lane(nl, v, got, I, has);
    } else {
        for (; k < n; k++) {
            int l = lane[k];
            if (lane_emits(v, got, l)) {
                has[l] = 1;
                I[l] = 0.5 * v[l];
            }
        }
    }
    /* the other half: the same lanes and intensities, the same vector */
    double I0 = r->intensity;
    if (!(r = bundle_push(out, -1 - (int)(out->ns - 1))))
        return -1;
    half_ray(e, source, 1, r);
    r->intensity = I0;
    return 0;
}

/* shade() for every lane of lane[0..n) at once, as shared halves (each
 * lane's rays the values shade() and emit_halves give it, in their
 * order): source by source, emission (source0), ambient, then each
 * light.  Returns -1 when out of memory. */
static int shade_packet(const rs_integrator *it, const int *lane, int n, shade_point *sp,
                        int source0, frame *fr, const emit_ctx *e)
{
    const rs_scene *sc = it->scene;
    const rs_finish *f = &sp->h->surface->finish;
    int nl = it->n_lanes;
    /* a colour 0 in every lane emits in none */
    if ((!sp->emission_entry->dark &&
         shared_halves(nl, e, source0, lane, n, sp->emission, NULL, sp->emission_entry->half,
                       sp->emission_entry->half_has) != 0) ||
        (!sp->ambient_entry->dark &&
         shared_halves(nl, e, 0, lane, n, sp->ambient, NULL, sp->ambient_entry->half,
                       sp->ambient_entry->half_has) != 0))
        return -1;
    for (size_t q = 0; q < sc->n_lights; q++) {
        for (int k = 0; k < n; k++) {
            size_t l = (size_t)lane[k];
            double rho = sp->pigment[l] * f->diffuse;
            fr->light_got[l] = lit(f, rho) && light_term(it, sp, rho, l, q, &fr->light_v[l]);
        }
        if (shared_halves(nl, e, src_light(it, (int)q), lane, n, fr->light_v, fr->light_got,
                          NULL, NULL) != 0)
            return -1;
    }
    return 0;
}

static void shift_op(bundle *out, size_t from, double dop)
{
    for (size_t i = from; i < out->n; i++)
        out->r[i].op += dop;
}

/* Record the last segment of a traced ray, from o along d to the source
 * it meets at s (object `emitter`; -1 and s unused for the background);
 * its index, or -1 when out of memory.  In a scene where no rays
 * interfere the table is never read (pol_values adds intensities): 0,
 * nothing recorded. */
static long record_wavelet(rs_worker *w, lp_vec3 o, lp_vec3 d, const rs_hit *h)
{
    if (!w->it->interferes)
        return 0;
    rs_wavelet wl = {o, d, h ? h->point : o, h != NULL, h ? h->object : -1};
    return rs_wavelets_push(&w->wavelets, &wl);
}

static void trace_pol(rs_worker *w, const int *lane, int n, lp_vec3 o, lp_vec3 d, int level,
                      double weight, int skip, int f, bundle *out);

/* A mirror reflection in the polarized mode: the bundle seen along the
 * mirror direction, scaled by the reflectivity, each field mirrored
 * (Householder) with a pi jump (an ideal conductor reverses the tangential
 * field), its optical path referred to the origin of the ray along d.
 * Lanes of equal reflectivity share the mirror ray. */
static void mirror_pol(rs_worker *w, const int *lane, int n, const rs_object *ob,
                       const rs_hit *h, lp_vec3 d, int level, double weight, int f, frame *fr,
                       bundle *out)
{
    const rs_integrator *it = w->it;
    lp_vec3 nv = h->normal;
    lp_vec3 rd = v3_unit_or_self(v3_madd(d, nv, -2.0 * v3_dot(d, nv)));
    lp_vec3 x = v3_madd(h->point, nv, 1e-9 * (1.0 + sqrt(v3_dot(h->point, h->point))));
    reflectivities(w, lane, n, ob, h, d, fr->val);
    for (int k = 0; k < n; k++) {
        double r = fr->val[k];
        fr->done[k] = !(r > 0.0) || weight * r < it->cutoff;
    }
    for (int k = 0; k < n; k++) {
        if (fr->done[k])
            continue;
        double r = fr->val[k];
        int m = 0;
        for (int j = k; j < n; j++)
            if (!fr->done[j] && fr->val[j] == r) {
                fr->done[j] = 1;
                fr->lane[m++] = lane[j];
            }
        bundle_clear(&fr->child);
        trace_pol(w, fr->lane, m, x, rd, level + 1, weight * r, -1, f + 1, &fr->child);
        for (size_t i = 0; i < fr->child.n; i++) {
            lp_ray *p = bundle_copy(out, &fr->child, i, r, it->n_lanes);
            if (!p)
                return;
            p->vp = v3_madd(p->vp, nv, -2.0 * v3_dot(p->vp, nv));
            p->kphi += 1;
            p->op += h->t;
        }
    }
}

/* Whether rays a and b differ in nothing a gather reads but intensity
 * (both non-zero). */
static int same_but_intensity(const lp_ray *a, const lp_ray *b)
{
    return a->ch == b->ch && a->op == b->op && a->kphi == b->kphi && a->phase == b->phase &&
           a->vp.x == b->vp.x && a->vp.y == b->vp.y && a->vp.z == b->vp.z &&
           a->dir.x == b->dir.x && a->dir.y == b->dir.y && a->dir.z == b->dir.z &&
           a->origin.x == b->origin.x && a->origin.y == b->origin.y &&
           a->origin.z == b->origin.z && a->intensity > 0.0 && b->intensity > 0.0;
}

/* Runs BODY for every lane LANE that ray i of bundle b has, with INT its
 * intensity in that lane. */
#define FOR_LANES(b, i, nl, LANE, INT, BODY)                                            \
    do {                                                                                \
        int l_ = (b)->lane[i];                                                          \
        if (l_ >= 0) {                                                                  \
            int LANE = l_;                                                              \
            double INT = (b)->r[i].intensity;                                           \
            (void)INT;                                                                  \
            BODY;                                                                       \
        } else {                                                                        \
            size_t s_ = (size_t)(-1 - l_) * (size_t)(nl);                               \
            for (int LANE = 0; LANE < (nl); LANE++)                                     \
                if ((b)->has[s_ + (size_t)LANE]) {                                      \
                    double INT = (b)->I[s_ + (size_t)LANE];                             \
                    (void)INT;                                                          \
                    BODY;                                                               \
                }                                                                       \
        }                                                                               \
    } while (0)

/* Gather the first ray of each of the n_g groups of fr->child (fr->g_ray)
 * along query j into fr->res: group g's outputs at fr->g_start[g], their
 * count in fr->g_count[g] (SIZE_MAX: its gather failed, no outputs).
 * With batch (a glass lens: each bundle ray's outputs follow one another,
 * the first of them part 0) the groups are gathered in one call, which
 * sets up the path's nodes once for all of them; the outputs are the
 * groups' own gathers' in order, so each group's start is found at its
 * part 0.  Where that cannot tell them apart (a ray that gave no output,
 * a failure), each group is gathered alone.  Returns -1 when out of
 * memory. */
static int gather_groups(frame *fr, size_t j, int batch, size_t n_g)
{
    const bundle *c = &fr->child;
    lp_result_clear(&fr->res);
    if (batch && n_g > 1) {
        const lp_ray *in = c->r;
        if (fr->g_ray[n_g - 1] != n_g - 1) { /* the groups' rays are not c->r[0..n_g) */
            if (n_g > fr->g_rcap) {
                lp_ray *p = realloc(fr->g_rays, n_g * sizeof *p);
                if (!p)
                    return -1;
                fr->g_rays = p;
                fr->g_rcap = n_g;
            }
            for (size_t g = 0; g < n_g; g++)
                fr->g_rays[g] = c->r[fr->g_ray[g]];
            in = fr->g_rays;
        }
        if (lp_backward_gather(fr->bw, j, in, n_g, &fr->res, NULL) == LP_OK) {
            size_t g = 0;
            for (size_t t = 0; t < fr->res.count; t++)
                if (fr->res.rays[t].part == 0) {
                    if (g == n_g)
                        break;
                    fr->g_start[g++] = t;
                }
            if (g == n_g) {
                for (g = 0; g + 1 < n_g; g++)
                    fr->g_count[g] = fr->g_start[g + 1] - fr->g_start[g];
                fr->g_count[n_g - 1] = fr->res.count - fr->g_start[n_g - 1];
                return 0;
            }
        }
        lp_result_clear(&fr->res);
    }
    for (size_t g = 0; g < n_g; g++) {
        size_t before = fr->res.count;
        fr->g_start[g] = before;
        if (lp_backward_gather(fr->bw, j, &c->r[fr->g_ray[g]], 1, &fr->res, NULL) != LP_OK) {
            fr->res.count = before;
            fr->g_count[g] = SIZE_MAX;
        } else {
            fr->g_count[g] = fr->res.count - before;
        }
    }
    return 0;
}

/* A gathered shared ray's vector: per lane k, the output gI of a group
 * whose first ray had intensity I0 scaled to the lane's input cI[k],
 * gI (cI[k] / I0), into Io and has; a lane without the ray, or failed
 * (bad), gets +0.  A group with an output had 0 < I0 < inf, so the
 * quotient is exactly 1 in a lane whose input is I0 and the lane gets gI
 * itself.  Every lane in one pass, the lanes kept by a bit mask (no
 * branch: it vectorizes). */
RS_WIDE static void scale_lanes(int nl, const double *restrict cI,
                                const unsigned char *restrict ch,
                                const unsigned char *restrict bad, double I0, double gI,
                                double *restrict Io, unsigned char *restrict has)
{
    for (int k = 0; k < nl; k++) {
        double v = gI * (cI[k] / I0);
        unsigned char keep = ch[k] & (unsigned char)(bad[k] ^ 1);
        uint64_t bits;
        memcpy(&bits, &v, sizeof bits);
        bits &= (uint64_t)0 - keep;
        has[k] = keep;
        memcpy(&Io[k], &bits, sizeof bits);
    }
}

/* scale_lanes where no lane failed and 0 < gI <= DBL_MAX: every lane's
 * gI (cI[k] / I0) as it stands, has the ray's own (copied by the caller):
 * a lane without the ray has cI[k] = +0 (bundle_push_shared), so it gets
 * gI (+0 / I0) = +0 as scale_lanes gives it. */
RS_WIDE static void scale_kept_lanes(int nl, const double *restrict cI, double I0, double gI,
                                     double *restrict Io)
{
    for (int k = 0; k < nl; k++)
        Io[k] = gI * (cI[k] / I0);
}

/* Gather the rays of fr->child (lanes of equal optics at this lens) along
 * query j, appending the outputs to out, each with its ray's lanes.
 * Rays that differ only in intensity (a shared ray's lanes, and rays of
 * different lanes that carry the same light) form a group gathered once:
 * a gather is linear in the intensity, so each lane's outputs are the
 * group's first ray's scaled by their intensity ratio (a gather of their
 * own gives the same to rounding).  A lane one of whose rays fails to
 * gather gets nothing from this query, as a gather of its rays alone
 * would give.  Returns -1 when out of memory. */
static int gather_shared(rs_worker *w, frame *fr, size_t j, int split, int batch, uint64_t hit,
                         const lp_query *q, bundle *out)
{
    const bundle *c = &fr->child;
    int nl = w->it->n_lanes;
    size_t n = c->n, n_g = 0;
    if (n > fr->g_cap) {
        size_t **arr[4] = {&fr->g_of, &fr->g_ray, &fr->g_start, &fr->g_count};
        for (int k = 0; k < 4; k++) {
            size_t *p = realloc(*arr[k], n * sizeof *p);
            if (!p)
                return -1;
            *arr[k] = p;
        }
        fr->g_cap = n;
    }
    for (size_t i = 0; i < n; i++) {
        /* lanes emit in the same order: try the group after the last one */
        size_t g = i > 0 ? fr->g_of[i - 1] + 1 : 0;
        if (!(g < n_g && same_but_intensity(&c->r[fr->g_ray[g]], &c->r[i])))
            for (g = 0; g < n_g && !same_but_intensity(&c->r[fr->g_ray[g]], &c->r[i]); g++)
                ;
        fr->g_of[i] = g;
        if (g == n_g)
            fr->g_ray[n_g++] = i;
    }
    if (gather_groups(fr, j, batch, n_g) != 0)
        return -1;
    int any_bad = 0;
    for (size_t i = 0; i < n; i++)
        if (fr->g_count[fr->g_of[i]] == SIZE_MAX) {
            FOR_LANES(c, i, nl, k, I, fr->bad[k] = 1);
            any_bad = 1;
        }
    for (size_t i = 0; i < n; i++) {
        size_t g = fr->g_of[i];
        double I0 = c->r[fr->g_ray[g]].intensity;
        for (size_t t = fr->g_start[g]; t < fr->g_start[g] + fr->g_count[g]; t++) {
            const lp_ray *gr = &fr->res.rays[t].ray;
            lp_ray *r = NULL;
            if (c->lane[i] >= 0) {
                if (fr->bad[c->lane[i]])
                    break;
                double I = c->r[i].intensity;
                double scale = I == I0 ? 1.0 : I / I0;
                if (!(r = bundle_push(out, c->lane[i])))
                    return -1;
                *r = *gr;
                if (scale != 1.0)
                    r->intensity *= scale;
            } else {
                double *Io;
                unsigned char *has;
                int first;
                size_t s = (size_t)(-1 - c->lane[i]) * (size_t)nl;
                if (!(r = bundle_push_shared(out, nl, 0, &Io, &has)))
                    return -1;
                if (!any_bad && gr->intensity > 0.0 && gr->intensity <= DBL_MAX) {
                    scale_kept_lanes(nl, c->I + s, I0, gr->intensity, Io);
                    memcpy(has, c->has + s, (size_t)nl);
                } else {
                    scale_lanes(nl, c->I + s, c->has + s, fr->bad, I0, gr->intensity, Io, has);
                }
                for (first = 0; first < nl && !has[first]; first++)
                    ;
                if (first == nl) { /* every lane failed: no ray */
                    out->n--;
                    out->ns--;
                    break;
                }
                *r = *gr;
                r->intensity = Io[first];
            }
            if (split)
                r->ch = rs_coherence_split(r->ch, hit, q[j].depth, q[j].kind != LP_KIND_REFLECT);
        }
    }
    if (any_bad)
        memset(fr->bad, 0, (size_t)nl);
    return 0;
}

/* The bundles of lanes lane[0..n) seen along the ray, appended to out.
 * The lanes travel as one packet and split at a lens where their optics
 * differ, as in trace_scalar; the rays of one lane are those, in the same
 * order, that tracing it alone gives. */
static void trace_pol_hit(rs_worker *w, const int *lane, int n, lp_vec3 o, lp_vec3 d,
                          const rs_hit *hit, int level, double weight, int f, bundle *out);

/* realloc of the array whose pointer is at pp (of any object type, read
 * and written as bytes: no lvalue of another type) to n elements of
 * size; it is left as it was when that fails.  Returns -1 then. */
static int grow(void *pp, size_t n, size_t size)
{
    void *old, *p;
    memcpy(&old, pp, sizeof old);
    p = realloc(old, n * size);
    if (!p)
        return -1;
    memcpy(pp, &p, sizeof p);
    return 0;
}

/* Room in fr for n gathers of gather_all (the bundles kept from one lens
 * hit to the next).  Returns -1 when out of memory. */
static int gather_room(frame *fr, size_t n)
{
    if (n > fr->n_kids) {
        size_t cap = 2 * fr->n_kids > n ? 2 * fr->n_kids : n;
        bundle *kids = realloc(fr->kids, cap * sizeof *kids);
        if (!kids)
            return -1;
        memset(kids + fr->n_kids, 0, (cap - fr->n_kids) * sizeof *kids);
        fr->kids = kids;
        fr->n_kids = cap;
    }
    if (n > fr->gm_cap) {
        size_t cap = 2 * fr->gm_cap > n ? 2 * fr->gm_cap : n;
        if (grow(&fr->gm_bw, cap, sizeof *fr->gm_bw) != 0 ||
            grow(&fr->gm_b, cap, sizeof *fr->gm_b) != 0 ||
            grow(&fr->gm_q, cap, sizeof *fr->gm_q) != 0 ||
            grow(&fr->gm_n, cap, sizeof *fr->gm_n) != 0 ||
            grow(&fr->gm_start, cap, sizeof *fr->gm_start) != 0 ||
            grow(&fr->gm_lane, cap, sizeof *fr->gm_lane) != 0 ||
            grow(&fr->gm_power, cap, sizeof *fr->gm_power) != 0)
            return -1;
        fr->gm_cap = cap;
    }
    return 0;
}

/* Whether every sub-packet of lens_builds of a packet of n lanes is one
 * lane (a wavelength of its own: n of them), and there are several, at a
 * lens that is not a crystal. */
static int lens_single(const frame *fr, const rs_object *ob, int n)
{
    return every_lane_alone(fr->n_sub, n, ob);
}

/* Whether the rays leaving a lens hit at frame f would only be added up
 * as intensities: the camera ray's own hit (frame 0: its rays go into the
 * pixel and nowhere else) in a scene where no rays interfere (pol_values
 * adds their intensities, reading nothing else of them).  Its gathers
 * then need not make the rays, only their power. */
static int camera_power(const rs_integrator *it, int f)
{
    return f == 0 && !it->interferes;
}

/* The nr gathers of gather_all, at the camera ray's hit (camera_power):
 * each one's power alone (lp_backward_gather_power_many: the Jones
 * matrices of its way, no rays made), added to its lane of the pixel.  A
 * gather that fails gives nothing, as there. */
static void gather_power_all(rs_worker *w, frame *fr, size_t nr)
{
    if (lp_backward_gather_power_many(fr->gm_bw, fr->gm_q, fr->gm_b, fr->gm_n, nr, fr->gm_power,
                                      NULL) != LP_OK) {
        for (size_t k = 0; k < nr; k++) /* one by one, to drop the failing ones */
            if (lp_backward_gather_power_many(fr->gm_bw + k, fr->gm_q + k, fr->gm_b + k,
                                              fr->gm_n + k, 1, fr->gm_power + k, NULL) != LP_OK)
                fr->gm_power[k] = 0.0;
    }
    for (size_t k = 0; k < nr; k++)
        w->pixel_power[fr->gm_lane[k]] += fr->gm_power[k];
}

/* The gathers gm_*[0 .. nr) of gather_all, made: their power added to
 * the pixel's lanes (power: camera_power), or their rays appended to out
 * in order.  Returns -1 when out of memory. */
static int gather_flush(rs_worker *w, frame *fr, size_t nr, int power, bundle *out)
{
    lp_result_clear(&fr->res);
    if (power) {
        gather_power_all(w, fr, nr);
        return 0;
    }
    /* a failed gather stops the call: its outputs are dropped, and the
     * gathers after it made by another (it is the last whose start is set) */
    for (size_t from = 0; from < nr;) {
        for (size_t k = from; k < nr; k++)
            fr->gm_start[k] = SIZE_MAX;
        size_t before = fr->res.count;
        if (lp_backward_gather_many(fr->gm_bw + from, fr->gm_q + from, fr->gm_b + from,
                                    fr->gm_n + from, nr - from, &fr->res, fr->gm_start + from,
                                    NULL) == LP_OK)
            break;
        if (fr->gm_start[from] == SIZE_MAX) { /* failed before any gather: none of the rest */
            fr->res.count = before;
            for (size_t k = from; k < nr; k++)
                fr->gm_start[k] = before;
            break;
        }
        size_t k = from;
        while (k + 1 < nr && fr->gm_start[k + 1] != SIZE_MAX)
            k++;
        fr->res.count = fr->gm_start[k];
        from = k + 1;
    }
    for (size_t k = 0; k < nr; k++) {
        size_t end = k + 1 < nr ? fr->gm_start[k + 1] : fr->res.count;
        for (size_t t = fr->gm_start[k]; t < end; t++) {
            lp_ray *r = bundle_push(out, fr->gm_lane[k]);
            if (!r)
                return -1;
            *r = fr->res.rays[t].ray;
        }
    }
    return 0;
}

/* The lens branch of trace_pol_hit where every sub-packet of the hit h
 * (of lens_builds) is one lane and the lens is not a crystal: every
 * query of every sub-packet traced, in order (for each sub-packet, each
 * of its queries, as the loop of trace_pol_hit traces them: the wavelets
 * and the counters come in that order), each into its own bundle; then
 * those of each chunk of builds (build_chunk) gathered in one
 * lp_backward_gather_many, which carries the rays of many wavelengths
 * side by side, and the outputs appended to out in the same order, their
 * optical paths then counted from the ray's origin (shift_op, by h->t)
 * -- or, at the camera ray's own hit where nothing interferes
 * (camera_power: builds made for power alone), their power alone added
 * to the pixel's lanes (gather_power_all), nothing appended to out.  A
 * gather's outputs are lp_backward_gather's whatever the chunk.  A
 * gather that fails gives nothing, as there; out of memory, the branch
 * stops where it is, as there. */
static void gather_all(rs_worker *w, frame *fr, const rs_hit *h, int level, double weight,
                       int f, bundle *out, size_t start)
{
    const rs_scene *sc = w->it->scene;
    size_t nr = 0;
    int m, power = camera_power(w->it, f);
    while ((m = lens_next(fr, 1)) != 0) { /* m is 1, or -1 at a chunk's end */
        if (m < 0) { /* the chunk's gathers, before its builds go */
            if (gather_flush(w, fr, nr, power, out) != 0 || build_chunk(fr, fr->sub_next) != 0)
                return;
            nr = 0;
            continue;
        }
        size_t nq = lp_backward_query_count(fr->bw);
        const lp_query *q = lp_backward_queries(fr->bw);
        ++w->splits; /* a lens hit's id, as trace_pol_hit counts them */
        w->work.builds += 1.0;
        if (gather_room(fr, nr + nq) != 0)
            return;
        for (size_t j = 0; j < nq; j++) {
            bundle *c = &fr->kids[nr];
            bundle_clear(c);
            trace_pol_hit(w, fr->lane, m, q[j].origin, q[j].dir,
                          query_hit(sc, fr, q, j, lens_object(sc, h)), level + q[j].depth,
                          weight * q[j].bound, f + 1, c);
            if (c->n == 0)
                continue;
            if (!power) /* a ray's power alone costs about a multiplication */
                w->work.gathered += (double)c->n;
            fr->gm_bw[nr] = fr->bw;
            fr->gm_q[nr] = j;
            fr->gm_b[nr] = c->r;
            fr->gm_n[nr] = c->n;
            fr->gm_lane[nr] = fr->lane[0];
            nr++;
        }
    }
    if (gather_flush(w, fr, nr, power, out) != 0 || power)
        return;
    shift_op(out, start, h->t);
}

static void trace_pol(rs_worker *w, const int *lane, int n, lp_vec3 o, lp_vec3 d, int level,
                      double weight, int skip, int f, bundle *out)
{
    rs_hit h;
    int found = rs_scene_intersect(w->it->scene, o, d, 0.0, INFINITY, skip, &h);
    trace_pol_hit(w, lane, n, o, d, found ? &h : NULL, level, weight, f, out);
}

/* trace_pol once the ray's hit is known (NULL: it meets nothing). */
static void trace_pol_hit(rs_worker *w, const int *lane, int n, lp_vec3 o, lp_vec3 d,
                          const rs_hit *hit, int level, double weight, int f, bundle *out)
{
    const rs_integrator *it = w->it;
    const rs_scene *sc = it->scene;
    size_t start = out->n;

    w->work.rays += 1.0;
    w->work.lane_rays += n;
    if (!hit) {
        const double *L = it->lane_background;
        int k = 0;
        while (k < n && L[lane[k]] == 0.0)
            k++;
        if (k == n)
            return;
        emit_ctx e = emit_ctx_make(out, d, record_wavelet(w, o, d, NULL));
        if (e.wavelet < 0)
            return;
        if (n > 1) {
            shared_halves(it->n_lanes, &e, 1, lane, n, L, NULL, it->background_half,
                          it->background_has);
        } else {
            e.lane = lane[0];
            emit_halves(&e, 1, L[lane[0]]);
        }
        return;
    }
    const rs_hit h = *hit;
    const rs_object *ob = h.surface;
    frame *fr = get_frame(w, f);
    if (!fr)
        return;

    if (ob->type == RS_OBJ_LENS) {
        int m;
        lp_trace_args a;
        if (!lens_args(it, level, weight, &a))
            return;
        int split = ob->u.lens.desc.uniaxial && it->n_sources < RS_COHERENCE_MAX_SOURCES;
        fr->qm.valid = 0;
        if (lens_builds(w, fr, ob, h.object, lane, n, o, d, &a, camera_power(it, f)) != 0)
            return;
        if (lens_single(fr, ob, n)) { /* their gathers at once */
            gather_all(w, fr, &h, level, weight, f, out, start);
            return;
        }
        while ((m = lens_next(fr, 0)) > 0) {
            size_t nq = lp_backward_query_count(fr->bw);
            const lp_query *q = lp_backward_queries(fr->bw);
            uint64_t hit_id = ++w->splits;
            w->work.builds += 1.0;
            for (size_t j = 0; j < nq; j++) {
                bundle_clear(&fr->child);
                trace_pol_hit(w, fr->lane, m, q[j].origin, q[j].dir,
                              query_hit(sc, fr, q, j, lens_object(sc, &h)),
                              level + q[j].depth, weight * q[j].bound, f + 1, &fr->child);
                if (fr->child.n == 0)
                    continue;
                w->work.gathered += (double)fr->child.n;
                if (m > 1) {
                    if (gather_shared(w, fr, j, split, !ob->u.lens.desc.uniaxial, hit_id, q, out) != 0)
                        return;
                    continue;
                }
                lp_result_clear(&fr->res);
                if (lp_backward_gather(fr->bw, j, fr->child.r, fr->child.n, &fr->res, NULL) !=
                    LP_OK)
                    continue;
                for (size_t i = 0; i < fr->res.count; i++) {
                    lp_ray *r = bundle_push(out, fr->lane[0]);
                    if (!r)
                        return;
                    *r = fr->res.rays[i].ray;
                    if (split)
                        r->ch = rs_coherence_split(r->ch, hit_id, q[j].depth,
                                                   q[j].kind != LP_KIND_REFLECT);
                }
            }
        }
        shift_op(out, start, h.t);
        return;
    }
    if (ob->type == RS_OBJ_POLARIZER) {
        if (f + 1 >= RS_MAX_FRAMES)
            return;
        bundle_clear(&fr->child);
        trace_pol(w, lane, n, h.point, d, level, weight, h.object, f + 1, &fr->child);
        lp_vec3 ax = ob->u.polarizer.axis;
        ax = v3_unit_or_self(v3_madd(ax, d, -v3_dot(ax, d)));
        for (size_t i = 0; i < fr->child.n; i++) {
            double c = v3_dot(fr->child.r[i].vp, ax);
            if (c == 0.0)
                continue;
            lp_ray *p = bundle_copy(out, &fr->child, i, c * c, it->n_lanes);
            if (!p)
                return;
            p->vp = ax;
            if (c < 0.0)
                p->kphi += 1; /* the field now points along -axis */
        }
        shift_op(out, start, h.t);
        return;
    }
    emit_ctx e = emit_ctx_make(out, d, record_wavelet(w, o, d, &h));
    if (e.wavelet >= 0) {
        shade_point sp;
        shade_begin(w, lane, n, &h, d, fr, &sp);
        if (n == 1) {
            e.lane = lane[0];
            shade(it, &it->lanes[lane[0]], &sp, emit_halves, &e);
        } else {
            shade_packet(it, lane, n, &sp, src_object(it, h.object), fr, &e);
        }
    }
    if (has_reflection(&ob->finish) && level < it->max_level && f + 1 < RS_MAX_FRAMES)
        mirror_pol(w, lane, n, ob, &h, d, level, weight, f, fr, out);
}

/* L[k] += I[k] for every lane (vectorized). */
RS_WIDE static void add_lanes(int nl, const double *restrict I, double *restrict L)
{
    for (int k = 0; k < nl; k++)
        L[k] += I[k];
}

/* The polarized mode's power seen along a camera ray in every lane, into
 * L[0..n_lanes): the lanes traced as one packet, each lane's power from
 * its own rays, in their order. */
static void pol_values(rs_worker *w, lp_vec3 o, lp_vec3 d, double *L)
{
    const rs_integrator *it = w->it;
    int nl = it->n_lanes;
    bundle_clear(&w->pixel);
    w->wavelets.n = 0;
    for (int k = 0; k < nl; k++)
        w->pixel_power[k] = 0.0;
    trace_pol(w, w->lane_all, nl, o, d, 1, 1.0, -1, 0, &w->pixel);
    const bundle *p = &w->pixel;
    if (!it->interferes) {
        /* every ray adds as an intensity: each lane's sum in its rays'
         * order, as rs_coherent_power forms it, after the power that came
         * without rays */
        for (int k = 0; k < nl; k++)
            L[k] = w->pixel_power[k];
        for (size_t i = 0; i < p->n; i++) {
            int l = p->lane[i];
            if (l >= 0) {
                L[l] += p->r[i].intensity;
            } else { /* a lane without the ray adds 0 (bundle_push_shared) */
                add_lanes(nl, p->I + (size_t)(-1 - l) * (size_t)nl, L);
            }
        }
        for (int k = 0; k < nl; k++)
            L[k] = L[k] > 0.0 ? L[k] : 0.0;
        return;
    }
    /* each lane's rays, in order, by a counting sort into w->one */
    size_t *at = w->lane_at, total = 0;
    for (int k = 0; k <= nl; k++)
        at[k] = 0;
    for (size_t i = 0; i < p->n; i++)
        FOR_LANES(p, i, nl, k, I, at[k + 1]++);
    for (int k = 0; k < nl; k++)
        at[k + 1] += at[k];
    total = at[nl];
    if (total > w->one_cap) {
        const lp_ray **r = realloc(w->one, total * sizeof *r);
        if (r)
            w->one = r;
        double *ii = r ? realloc(w->one_i, total * sizeof *ii) : NULL;
        if (!r || !ii) {
            for (int k = 0; k < nl; k++)
                L[k] = 0.0;
            return;
        }
        w->one_i = ii;
        w->one_cap = total;
    }
    for (size_t i = 0; i < p->n; i++)
        FOR_LANES(p, i, nl, k, I, {
            w->one[at[k]] = &p->r[i];
            w->one_i[at[k]++] = I;
        });
    /* at[k] is now the end of lane k's rays */
    for (int k = 0; k < nl; k++) {
        size_t from = k ? at[k - 1] : 0;
        /* a lane without rays sees nothing (w->one may not exist yet) */
        L[k] = at[k] == from ? 0.0
                             : rs_coherent_power(w->one + from, w->one_i + from, at[k] - from,
                                                 &w->wavelets, it->coherent, it->coherence,
                                                 it->n_sources, it->lanes[k].lambda);
    }
}

/* Linear sRGB that the camera ray (o, d) brings. */
static void ray_colour(const rs_integrator *it, rs_worker *w, lp_vec3 o, lp_vec3 d, rs_color *out)
{
    double *L = w->lane_value;

    /* Every lane's value: the lanes are traced as one packet. */
    if (it->opts.mode != RS_MODE_POLARIZED)
        trace_scalar(w, w->lane_all, it->n_lanes, o, d, 1, 1.0, -1, 0, L);
    else
        pol_values(w, o, d, L);

    if (it->opts.mode == RS_MODE_RGB) {
        *out = (rs_color){L[0], L[1], L[2]};
        return;
    }
    double xyz[3] = {0, 0, 0}, lines[3] = {0, 0, 0};
    int n = it->opts.wavelengths;
    for (int k = 0; k < n; k++)
        for (int c = 0; c < 3; c++)
            xyz[c] += L[k] * it->lane_xyz[3 * k + c];
    /* Lines are exact deltas: no quadrature, no correction. */
    for (int k = n; k < it->n_lanes; k++)
        for (int c = 0; c < 3; c++)
            lines[c] += L[k] * it->lane_xyz[3 * k + c];
    rs_color raw, rl;
    rs_xyz_to_linear_srgb(xyz, &raw);
    rs_xyz_to_linear_srgb(lines, &rl);
    const double(*M)[3] = it->correction;
    out->r = M[0][0] * raw.r + M[0][1] * raw.g + M[0][2] * raw.b + rl.r;
    out->g = M[1][0] * raw.r + M[1][1] * raw.g + M[1][2] * raw.b + rl.g;
    out->b = M[2][0] * raw.r + M[2][1] * raw.g + M[2][2] * raw.b + rl.b;
}

void rs_worker_work(const rs_worker *w, rs_work *out)
{
    *out = w->work;
    for (const rs_worker *f = w->finer; f; f = f->finer) {
        out->rays += f->work.rays;
        out->lane_rays += f->work.lane_rays;
        out->builds += f->work.builds;
        out->gathered += f->work.gathered;
    }
}

unsigned long long rs_worker_splits(const rs_worker *w)
{
    return w->lane_splits;
}

double rs_work_cost(const rs_work *w, rs_mode mode, double pixels)
{
    /* bench/work_cost_fit.sh prints this body */
    switch (mode) {
    case RS_MODE_POLARIZED:
        return 2024.4 * w->rays + 86.1 * w->lane_rays + 771.6 * w->gathered + 1815.6 * pixels;
    case RS_MODE_FRESNEL:
        return 1503.7 * w->rays + 95.7 * w->lane_rays + 1600.6 * pixels;
    case RS_MODE_SCHLICK:
        return 1501.2 * w->rays + 96.1 * w->lane_rays + 1602.9 * pixels;
    case RS_MODE_RGB:
        return 1896.8 * w->rays + 9.9 * w->lane_rays + 1268.1 * pixels;
    }
    return 0.0;
}

static void pixel_at(const rs_integrator *it, rs_worker *w, int i, int j, rs_color *out)
{
    int aa = it->opts.aa > 1 ? it->opts.aa : 1;
    int n = it->view.samples > 0 ? it->view.samples : 1;
    rs_color sum = {0, 0, 0};
    /* aa x aa points of the pixel (antialiasing), each with the camera's n
     * aperture rays */
    for (int q = 0; q < aa * aa; q++) {
        double px = i + (q % aa + 0.5) / aa, py = j + (q / aa + 0.5) / aa;
        for (int k = 0; k < n; k++) {
            lp_vec3 o, d;
            rs_color c;
            rs_camera_aperture_ray(&it->view, px, py, it->opts.width, it->opts.height, k, &o,
                                   &d);
            ray_colour(it, w, o, d, &c);
            sum.r += c.r;
            sum.g += c.g;
            sum.b += c.b;
        }
    }
    *out = (rs_color){sum.r / (n * aa * aa), sum.g / (n * aa * aa), sum.b / (n * aa * aa)};
}

/* Is there a count past it's for the refinement: its own next, or past
 * refine_max, while a pixel changes by more than refine_outlier, up to
 * refine_limit? */
static int has_finer(const rs_integrator *it)
{
    return it->finer || (it->opts.refine_outlier > 0.0 && it->opts.refine_tol > 0.0 &&
                         it->opts.mode != RS_MODE_RGB &&
                         it->opts.wavelengths >= it->opts.refine_max &&
                         it->opts.wavelengths <= it->opts.refine_limit / 2);
}

/* The worker of the next count beside w, made when first needed: of
 * w->it->finer, or past the integrator's own counts of an integrator of
 * the worker's own (the same options at twice the wavelengths: the same
 * values whoever makes it).  NULL when it cannot be made: the pixel then
 * keeps the value it has. */
static rs_worker *finer_worker(rs_worker *w)
{
    if (!w->finer && !w->finer_failed) {
        const rs_integrator *next = w->it->finer;
        if (!next) {
            char msg[256];
            rs_render_opts f = w->it->opts;
            f.wavelengths *= 2;
            if (rs_integrator_create(w->it->scene, &f, &w->own_finer, msg, sizeof msg) == 0)
                next = w->own_finer;
        }
        w->finer = next ? rs_worker_create(next) : NULL;
        w->finer_failed = !w->finer;
    }
    return w->finer;
}

void rs_integrator_pixel(const rs_integrator *it, rs_worker *w, int i, int j, rs_color *out)
{
    unsigned long long before = w->lane_splits;
    pixel_at(it, w, i, j, out);
    if (!has_finer(it) || w->lane_splits == before)
        return;
    /* The refinement (rs_render_opts.refine_tol): twice the wavelengths
     * until two doublings in a row change no channel by more than the
     * tolerance -- one is not enough: a feature of the spectrum narrower
     * than both grids' spacing (a thin band of wavelengths that a lens
     * sends elsewhere) can leave them equal (default.scene at 128 x 96:
     * two pixels 4.3e-4 apart at 4 and 8 wavelengths, 0.4 at 16). */
    int calm = 0;
    for (;;) {
        rs_worker *fw = finer_worker(w);
        rs_color c;
        if (!fw)
            return;
        const rs_integrator *fi = fw->it;
        pixel_at(fi, fw, i, j, &c);
        double change = rs_refine_change(c, *out);
        *out = c;
        calm = rs_refine_calm(calm, change, it->opts.refine_tol);
        if (!has_finer(fi))
            return;
        if (fi->opts.wavelengths >= it->opts.refine_max) {
            /* past the top, only a pixel that still changes by more than
             * refine_outlier */
            if (!(change > it->opts.refine_outlier))
                return;
        } else if (calm == RS_REFINE_CALM) {
            return;
        }
        it = fi;
        w = fw;
    }
}
