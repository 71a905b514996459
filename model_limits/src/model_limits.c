/* model_limits.c -- where the cheap light models fail.
 *
 * Traces natural light through a flat plate (one, two, three interfaces;
 * air->glass and glass->air), and through a biconvex lens (random rays,
 * tree depth 1..12), for N-BK7 and N-SF11, in every light model, and
 * writes the error of schlick, fresnel and rgb against polarized as CSV
 * tables and PNG plots, with a summary on stdout.  The definitions are in
 * the usage text below and in docs/model-limits.md. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "lensprim.h"
#include "plot.h"
#include "support/cli.h"
#include "support/colorimetry.h"
#include "support/image.h"
#include "support/vec.h"

#define EXIT_USAGE 2
#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

/* Split in parts: C11 compilers need only support 4095-char literals. */
static const char *const usage_text[] = {
"usage: model_limits [--out DIR] [--rays N] [--seed S] [--lambda NM]\n"
"       model_limits --help\n"
"\n"
"Where the light models fail: the error of the cheap models schlick,\n"
"fresnel and rgb against the polarized model, versus incidence angle\n"
"(n1 < n2 and n1 > n2), versus tree depth and versus glass (N-BK7,\n"
"N-SF11).  Writes to DIR (default docs/model-limits):\n"
"  angle.csv  depth.csv  glass.csv\n"
"  angle_air_glass.png  angle_glass_air.png  depth.png  glass.png\n"
"and prints a summary on stdout.  Files are replaced atomically.\n"
"\n"
"  --out DIR     output directory, created if missing (default\n"
"                docs/model-limits, relative to the current directory)\n"
"  --rays N      random rays of the depth comparison (default 2000)\n"
"  --seed S      their seed, an unsigned integer (default 20240605)\n"
"  --lambda NM   monochromatic: every model at this one wavelength, in\n"
"                standard air as glass catalogs give it (587.56 = d line);\n"
"                the rgb model is then undefined (its columns are empty)\n"
"\n"
"LIGHT.  Natural light of power 1: in the polarized model two mutually\n"
"incoherent, orthogonally polarized halves of power 1/2 (traced with\n"
"lp_trace_forward in LP_MODE_POLARIZED and summed; any orthogonal pair\n"
"gives the same powers); fresnel and schlick trace one unpolarized ray\n"
"of power 1 (LP_MODE_FRESNEL: R = (Rs+Rp)/2 at every node; LP_MODE_SCHLICK:\n"
"R0 + (1-R0)(1-cos)^5, with the cosine of the transmitted angle when\n"
"n1 > n2).  P(k) is the power of the outgoing rays of depth k (k\n"
"interfaces met along the path).\n"
"\n"
"SPECTRUM.  Every number is the luminance a white light of unit\n"
"luminance would give: the reference, polarized, and fresnel and schlick\n"
"are averaged over 80 wavelengths (midpoints of 5 nm bands, 380-780 nm),\n"
"weighted by D65 x CIE 1931 ybar, as the spectral renderer sees them;\n"
"rgb is fresnel at the rgb mode's three channel wavelengths (642.4,\n"
"543.0, 440.8 nm) weighted by the luminance coefficients (0.2126,\n"
"0.7152, 0.0722) -- the luminance of the rgb renderer's pixel.  So the\n"
"fresnel and schlick errors are pure light-model errors and the rgb\n"
"error is the fresnel error plus the error of sampling the spectrum at\n"
"three wavelengths.  (CIE wavelengths are in vacuum; the tool converts\n"
"them to standard air for the library.)\n"
"\n",
"ANGLE (angle.csv, angle_*.png).  A flat plate, 10 mm thick and wide\n"
"enough never to reach the rim, lit at incidence 0..89.9 deg (step 0.1;\n"
"the CSV lists every 1 deg and 89.5, 89.9):\n"
"  air_glass  an N-BK7 (or N-SF11) plate in air: n1 < n2 at the entry\n"
"  glass_air  an air gap (lens glass n = 1) in an N-BK7 (or N-SF11)\n"
"             medium: the light meets glass->air first, n1 > n2, with\n"
"             total reflection beyond the critical angle; the angle is\n"
"             measured in the glass.\n"
"  Depth 1 (R1) is the reflection at the first interface, depth 2 (T2)\n"
"  the ray straight through (two interfaces), depth 3 (R3) the ray that\n"
"  reflects once inside and leaves on the incoming side.  At ONE\n"
"  interface natural light gives (Rs+Rp)/2 in both fresnel and polarized:\n"
"  fresnel's R1 error is 0.  After the first interface the light is\n"
"  partly polarized; for the direct ray polarized gives\n"
"  ((1-Rs)^2 + (1-Rp)^2)/2, fresnel (1 - (Rs+Rp)/2)^2, less by\n"
"  (Rs-Rp)^2/4.\n"
"  err = P_model - P_polarized (signed), rel = err / P_polarized (empty\n"
"  when P_polarized = 0 and err != 0).\n"
"\n"
"DEPTH (depth.csv, depth.png).  A biconvex lens R1 = 30, R2 = -30, t = 10,\n"
"D = 25 mm; N rays aimed at points uniform over 95 % of the front\n"
"aperture from directions cosine-distributed over the front hemisphere\n"
"(a uniformly bright sky), tree depth 12.  For each ray, model and depth\n"
"k = 1..12, P(k); errors |P_model(k) - P_polarized(k)| (mean and max)\n"
"and relative ones (mean, median and max), over the rays with\n"
"P_polarized(k) > 0; total_rel_err = (sum P_model - sum P_polarized) /\n"
"sum P_polarized over all rays.  A few rays are off by huge factors\n"
"(polarized light extinguished on skew paths), so the median is the\n"
"typical ray and the mean is not.\n"
"\n"
"GLASS (glass.csv, glass.png).  The same comparisons for N-BK7 and N-SF11\n"
"side by side: for each glass, sweep and quantity the largest |err| and\n"
"|rel| and where, and how far a model stays within 1 %: up to which angle\n"
"|rel| < 1 % at every angle below, or up to which depth the median |rel|\n"
"over the rays is < 1 % at every depth below.\n"
"\n"
"The glasses are made lossless (no internal transmittance): absorption\n"
"scales a path's power by the same factor in every model.\n"
"\n"
"Exit status: 0 done, 1 a file could not be written, 2 bad usage.\n"};

/* ------------------------------------------------------------------ */
/* Models, spectrum                                                    */
/* ------------------------------------------------------------------ */

enum { M_POL, M_FRES, M_SCH, M_RGB, N_MODELS };
static const char *const MODEL_NAME[N_MODELS] = {"polarized", "fresnel", "schlick", "rgb"};
static const unsigned MODEL_COLOR[N_MODELS] = {0x000000u, 0x1F5FBFu, 0xD9541Au, 0x2CA02Cu};
/* Plots draw rgb first and wide, so that fresnel, which it mostly
 * follows, stays visible on top of it, and polarized last. */
static const int DRAW_ORDER[N_MODELS] = {M_RGB, M_SCH, M_FRES, M_POL};
static const double MODEL_WIDTH[N_MODELS] = {2.5, 2.0, 2.0, 4.5};

enum { N_GLASS = 2 };
static const char *const GLASS_NAME[N_GLASS] = {"N-BK7", "N-SF11"};

enum { MAX_BANDS = 80 };
#define LAMBDA_D 587.5618 /* helium d line in air, nm */

typedef struct spectrum {
    int n;                    /* wavelengths of the reference (1: monochromatic) */
    double lambda[MAX_BANDS]; /* in standard air, nm */
    double w[MAX_BANDS];      /* weights, sum 1 */
    int have_rgb;
    double rgb_lambda[3];     /* in standard air */
    double rgb_w[3];          /* sum 1 */
} spectrum;

static void spectrum_init(spectrum *sp, double mono_nm)
{
    memset(sp, 0, sizeof *sp);
    if (mono_nm > 0.0) {
        sp->n = 1;
        sp->lambda[0] = mono_nm;
        sp->w[0] = 1.0;
        return;
    }
    double sum = 0.0, cmf[3];
    sp->n = MAX_BANDS;
    for (int i = 0; i < sp->n; i++) {
        double lv = RS_LAMBDA_MIN + (RS_LAMBDA_MAX - RS_LAMBDA_MIN) * (i + 0.5) / sp->n;
        rs_cmf(lv, cmf);
        sp->lambda[i] = lv / lp_air_index(lv);
        sp->w[i] = rs_d65(lv) * cmf[1];
        sum += sp->w[i];
    }
    for (int i = 0; i < sp->n; i++)
        sp->w[i] /= sum;
    sp->have_rgb = 1;
    sum = 0.0;
    for (int c = 0; c < 3; c++) {
        rs_color unit = {c == 0, c == 1, c == 2};
        sp->rgb_lambda[c] = RS_RGB_LAMBDA[c] / lp_air_index(RS_RGB_LAMBDA[c]);
        sp->rgb_w[c] = rs_luminance(unit);
        sum += sp->rgb_w[c];
    }
    for (int c = 0; c < 3; c++)
        sp->rgb_w[c] /= sum;
}

/* ------------------------------------------------------------------ */
/* Tracing natural light                                               */
/* ------------------------------------------------------------------ */

/* A unit vector perpendicular to the unit vector d. */
static lp_vec3 perpendicular(lp_vec3 d)
{
    lp_vec3 a = fabs(d.x) < 0.6 ? v3(1, 0, 0) : v3(0, 1, 0);
    lp_vec3 u = v3_cross(d, a);
    double n = sqrt(u.x * u.x + u.y * u.y + u.z * u.z);
    return v3(u.x / n, u.y / n, u.z / n);
}

typedef struct tracer {
    lp_result res;
    lp_trace_args args;
} tracer;

/* Add w times the power of the depth-k outgoing rays (k = 1..max_depth)
 * of natural light of power 1 along (o, d) to P[k], in one model. */
static int trace_natural(tracer *t, const lp_lens *lens, lp_vec3 o, lp_vec3 d, double lambda,
                         lp_mode mode, double w, double *P, lp_error *err)
{
    lp_vec3 u = perpendicular(d);
    lp_ray in;
    int halves = mode == LP_MODE_POLARIZED ? 2 : 1;

    t->args.mode = mode;
    memset(&in, 0, sizeof in);
    in.origin = o;
    in.dir = d;
    in.lambda_nm = lambda;
    in.intensity = 1.0 / halves;
    for (int h = 0; h < halves; h++) {
        in.vp = h == 0 ? u : v3_cross(d, u);
        in.ch = (uint64_t)h;
        if (lp_trace_forward(lens, &in, &t->args, &t->res, err) != LP_OK)
            return -1;
        for (size_t i = 0; i < t->res.count; i++) {
            int k = t->res.rays[i].depth;
            if (k >= 1 && k <= t->args.max_depth)
                P[k] += w * t->res.rays[i].ray.intensity;
        }
    }
    return 0;
}

/* P[k][m], k = 0..max_depth (0 unused), for every model over the spectrum. */
static int trace_models(tracer *t, const spectrum *sp, const lp_lens *lens, lp_vec3 o,
                        lp_vec3 d, int max_depth, double P[][N_MODELS], lp_error *err)
{
    double acc[N_MODELS][LP_MAX_DEPTH + 1];
    static const lp_mode MODE[3] = {LP_MODE_POLARIZED, LP_MODE_FRESNEL, LP_MODE_SCHLICK};

    memset(acc, 0, sizeof acc);
    t->args.max_depth = max_depth;
    for (int i = 0; i < sp->n; i++)
        for (int m = 0; m < 3; m++)
            if (trace_natural(t, lens, o, d, sp->lambda[i], MODE[m], sp->w[i], acc[m], err))
                return -1;
    if (sp->have_rgb)
        for (int c = 0; c < 3; c++)
            if (trace_natural(t, lens, o, d, sp->rgb_lambda[c], LP_MODE_FRESNEL, sp->rgb_w[c],
                              acc[M_RGB], err))
                return -1;
    for (int k = 0; k <= max_depth; k++)
        for (int m = 0; m < N_MODELS; m++)
            P[k][m] = (m == M_RGB && !sp->have_rgb) ? NAN : acc[m][k];
    return 0;
}

/* ------------------------------------------------------------------ */
/* Angle sweeps                                                        */
/* ------------------------------------------------------------------ */

enum { N_ANG = 900, DEPTH_A = 3, N_SETUP = 2 };
enum { S_AIR_GLASS, S_GLASS_AIR };
static const char *const SETUP_NAME[N_SETUP] = {"air_glass", "glass_air"};
static const char *const SETUP_TEXT[N_SETUP] = {"air->glass", "glass->air"};
static const char *const QTY_NAME[DEPTH_A] = {"R1", "T2", "R3"};
static const double PLATE_T = 10.0, PLATE_D = 1e8;

typedef struct sweep {
    double angle[N_ANG];                   /* degrees */
    double P[N_ANG][DEPTH_A + 1][N_MODELS]; /* [angle][depth 1..3][model] */
} sweep;

static double angle_at(int i) { return 0.1 * i; }

/* The plate of a setup: gap == 0: the glass in air; gap == 1: an air gap
 * in the glass. */
static int make_plate(const lp_glass *glass, int gap, lp_lens **out, lp_error *err)
{
    lp_lens_desc desc;
    lp_lens_desc_init(&desc);
    desc.radius1 = 0.0;
    desc.radius2 = 0.0;
    desc.thickness = PLATE_T;
    desc.diameter = PLATE_D;
    if (gap) {
        lp_glass_init_constant(&desc.glass, 1.0);
        desc.medium = *glass;
    } else {
        desc.glass = *glass;
    }
    return lp_lens_create(&desc, out, err) == LP_OK ? 0 : -1;
}

static int run_sweep(tracer *t, const spectrum *sp, const lp_lens *plate, sweep *sw,
                     lp_error *err)
{
    for (int i = 0; i < N_ANG; i++) {
        double th = angle_at(i) * DEG;
        lp_vec3 d = v3(sin(th), 0.0, cos(th));
        lp_vec3 o = v3(-PLATE_T * d.x, 0.0, -PLATE_T * d.z); /* enters at the origin */
        sw->angle[i] = angle_at(i);
        if (trace_models(t, sp, plate, o, d, DEPTH_A, sw->P[i], err))
            return -1;
    }
    return 0;
}

/* Relative error: 0 when both are 0, NaN when only the reference is. */
static double rel_err(double got, double ref)
{
    double e = got - ref;
    if (e == 0.0)
        return 0.0;
    return ref != 0.0 ? e / ref : NAN;
}

/* Summary of one (sweep, depth, model) curve. */
typedef struct curve_stats {
    double max_abs, at_abs;
    double max_rel, at_rel;
    double ok_1pct;   /* largest angle with |rel| < 1 % at every angle up to it; -1: none */
    int all_ok;
} curve_stats;

static curve_stats sweep_stats(const sweep *sw, int k, int m)
{
    curve_stats cs = {0.0, 0.0, 0.0, 0.0, -1.0, 1};
    for (int i = 0; i < N_ANG; i++) {
        double ref = sw->P[i][k][M_POL], got = sw->P[i][k][m];
        double e = fabs(got - ref), r = fabs(rel_err(got, ref));
        if (e > cs.max_abs) {
            cs.max_abs = e;
            cs.at_abs = sw->angle[i];
        }
        if (isnan(r))
            r = INFINITY;
        if (r > cs.max_rel) {
            cs.max_rel = r;
            cs.at_rel = sw->angle[i];
        }
        if (cs.all_ok) {
            if (r < 0.01)
                cs.ok_1pct = sw->angle[i];
            else
                cs.all_ok = 0;
        }
    }
    return cs;
}

/* ------------------------------------------------------------------ */
/* Depth comparison                                                    */
/* ------------------------------------------------------------------ */

enum { DEPTH_K = 12 };
static const double LENS_R = 30.0, LENS_T = 10.0, LENS_D = 25.0;

typedef struct depth_stats {
    long rays;
    long with_output[DEPTH_K + 1];
    double sum_P[DEPTH_K + 1][N_MODELS];
    double sum_abs[DEPTH_K + 1][N_MODELS], max_abs[DEPTH_K + 1][N_MODELS];
    double sum_rel[DEPTH_K + 1][N_MODELS], max_rel[DEPTH_K + 1][N_MODELS];
    double median_rel[DEPTH_K + 1][N_MODELS];
} depth_stats;

typedef struct rng {
    uint64_t s;
} rng;

/* splitmix64 */
static uint64_t rng_next(rng *r)
{
    uint64_t z = (r->s += 0x9E3779B97F4A7C15u);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9u;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBu;
    return z ^ (z >> 31);
}

static double rng_unit(rng *r) { return (double)(rng_next(r) >> 11) * (1.0 / 9007199254740992.0); }

static int make_biconvex(const lp_glass *glass, lp_lens **out, lp_error *err)
{
    lp_lens_desc desc;
    lp_lens_desc_init(&desc);
    desc.radius1 = LENS_R;
    desc.radius2 = -LENS_R;
    desc.thickness = LENS_T;
    desc.diameter = LENS_D;
    desc.glass = *glass;
    return lp_lens_create(&desc, out, err) == LP_OK ? 0 : -1;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median of v[0..n) (sorts v); NaN for n == 0. */
static double median(double *v, size_t n)
{
    if (n == 0)
        return NAN;
    qsort(v, n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static int run_depth(tracer *t, const spectrum *sp, const lp_lens *lens, int n_rays,
                     uint64_t seed, depth_stats *ds, lp_error *err)
{
    rng r = {seed};
    double P[DEPTH_K + 1][N_MODELS];
    /* the relative errors of every ray, for the medians */
    double *rel = malloc(sizeof *rel * (size_t)n_rays * (DEPTH_K + 1) * N_MODELS);

    memset(ds, 0, sizeof *ds);
    ds->rays = n_rays;
    if (!rel) {
        snprintf(err->message, sizeof err->message, "out of memory");
        return -1;
    }
    for (int j = 0; j < n_rays; j++) {
        double rho = 0.95 * 0.5 * LENS_D * sqrt(rng_unit(&r)), phi = 2.0 * PI * rng_unit(&r);
        double s2 = rng_unit(&r), psi = 2.0 * PI * rng_unit(&r);
        double st = sqrt(s2), ct = sqrt(1.0 - s2);
        lp_vec3 p = v3(rho * cos(phi), rho * sin(phi), LENS_R - sqrt(LENS_R * LENS_R - rho * rho));
        lp_vec3 d = v3(st * cos(psi), st * sin(psi), ct);
        if (ct < 1e-6)
            d = v3(d.x, d.y, 1e-6); /* keep the ray coming from the front */
        double dn = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        d = v3(d.x / dn, d.y / dn, d.z / dn);
        lp_vec3 o = v3(p.x - 100.0 * d.x, p.y - 100.0 * d.y, p.z - 100.0 * d.z);
        if (trace_models(t, sp, lens, o, d, DEPTH_K, P, err)) {
            free(rel);
            return -1;
        }
        for (int k = 1; k <= DEPTH_K; k++) {
            double ref = P[k][M_POL];
            for (int m = 0; m < N_MODELS; m++)
                ds->sum_P[k][m] += P[k][m];
            if (!(ref > 0.0))
                continue;
            for (int m = 1; m < N_MODELS; m++) {
                double e = fabs(P[k][m] - ref), rr = e / ref;
                rel[((size_t)k * N_MODELS + (size_t)m) * (size_t)n_rays +
                    (size_t)ds->with_output[k]] = rr;
                ds->sum_abs[k][m] += e;
                ds->sum_rel[k][m] += rr;
                if (!(e <= ds->max_abs[k][m]))
                    ds->max_abs[k][m] = e;
                if (!(rr <= ds->max_rel[k][m]))
                    ds->max_rel[k][m] = rr;
            }
            ds->with_output[k]++;
        }
    }
    for (int k = 1; k <= DEPTH_K; k++)
        for (int m = 1; m < N_MODELS; m++)
            ds->median_rel[k][m] =
                median(rel + ((size_t)k * N_MODELS + (size_t)m) * (size_t)n_rays,
                       (size_t)ds->with_output[k]);
    free(rel);
    return 0;
}

static double depth_mean_rel(const depth_stats *ds, int k, int m)
{
    return ds->with_output[k] ? ds->sum_rel[k][m] / ds->with_output[k] : NAN;
}

static double depth_mean_abs(const depth_stats *ds, int k, int m)
{
    return ds->with_output[k] ? ds->sum_abs[k][m] / ds->with_output[k] : NAN;
}

static double depth_total_rel(const depth_stats *ds, int k, int m)
{
    return rel_err(ds->sum_P[k][m], ds->sum_P[k][M_POL]);
}

/* Largest depth with the median |rel| over the rays < 1 % at every depth
 * up to it (0: none). */
static int depth_ok_1pct(const depth_stats *ds, int m)
{
    int ok = 0;
    for (int k = 1; k <= DEPTH_K; k++) {
        double r = ds->median_rel[k][m];
        if (!(r < 0.01) && !(ds->with_output[k] == 0))
            break;
        ok = k;
    }
    return ok;
}

/* ------------------------------------------------------------------ */
/* Files                                                               */
/* ------------------------------------------------------------------ */

typedef struct outfile {
    FILE *f;
    char path[4096], tmp[4200];
} outfile;

static int out_open(outfile *o, const char *dir, const char *name)
{
    if (snprintf(o->path, sizeof o->path, "%s/%s", dir, name) >= (int)sizeof o->path)
        return -1;
    snprintf(o->tmp, sizeof o->tmp, "%s.tmp.%ld", o->path, (long)getpid());
    o->f = fopen(o->tmp, "w");
    return o->f ? 0 : -1;
}

static int out_close(outfile *o)
{
    int bad = ferror(o->f) != 0;
    bad |= fflush(o->f) != 0;
    bad |= fclose(o->f) != 0;
    o->f = NULL;
    if (bad || rename(o->tmp, o->path) != 0) {
        remove(o->tmp);
        return -1;
    }
    return 0;
}

static void csv_num(FILE *f, const char *fmt, double v)
{
    if (isfinite(v))
        fprintf(f, fmt, v);
}

static int csv_row_due(int i)
{
    return (i % 10 == 0) || i == 895 || i == N_ANG - 1;
}

static int write_angle_csv(const char *dir, sweep *sw[N_GLASS][N_SETUP])
{
    outfile o;
    if (out_open(&o, dir, "angle.csv"))
        return -1;
    fprintf(o.f, "glass,setup,angle_deg,depth,ray,polarized,fresnel,schlick,rgb,"
                 "err_fresnel,err_schlick,err_rgb,rel_fresnel,rel_schlick,rel_rgb\n");
    for (int g = 0; g < N_GLASS; g++)
        for (int s = 0; s < N_SETUP; s++)
            for (int i = 0; i < N_ANG; i++) {
                if (!csv_row_due(i))
                    continue;
                for (int k = 1; k <= DEPTH_A; k++) {
                    const double *P = sw[g][s]->P[i][k];
                    fprintf(o.f, "%s,%s,%.1f,%d,%s", GLASS_NAME[g], SETUP_NAME[s],
                            sw[g][s]->angle[i], k, k == 2 ? "transmit" : "reflect");
                    for (int m = 0; m < N_MODELS; m++) {
                        fputc(',', o.f);
                        csv_num(o.f, "%.15g", P[m]);
                    }
                    for (int m = 1; m < N_MODELS; m++) {
                        fputc(',', o.f);
                        csv_num(o.f, "%.6e", P[m] - P[M_POL]);
                    }
                    for (int m = 1; m < N_MODELS; m++) {
                        fputc(',', o.f);
                        csv_num(o.f, "%.6e", rel_err(P[m], P[M_POL]));
                    }
                    fputc('\n', o.f);
                }
            }
    return out_close(&o);
}

static int write_depth_csv(const char *dir, depth_stats *const ds[N_GLASS])
{
    outfile o;
    if (out_open(&o, dir, "depth.csv"))
        return -1;
    fprintf(o.f, "glass,depth,model,rays,rays_with_output,mean_power_polarized,mean_power_model,"
                 "mean_abs_err,max_abs_err,mean_rel_err,median_rel_err,max_rel_err,total_rel_err\n");
    for (int g = 0; g < N_GLASS; g++)
        for (int k = 1; k <= DEPTH_K; k++)
            for (int m = 1; m < N_MODELS; m++) {
                const depth_stats *d = ds[g];
                fprintf(o.f, "%s,%d,%s,%ld,%ld,", GLASS_NAME[g], k, MODEL_NAME[m], d->rays,
                        d->with_output[k]);
                csv_num(o.f, "%.10e", d->sum_P[k][M_POL] / d->rays);
                fputc(',', o.f);
                csv_num(o.f, "%.10e", d->sum_P[k][m] / d->rays);
                fputc(',', o.f);
                csv_num(o.f, "%.6e", depth_mean_abs(d, k, m));
                fputc(',', o.f);
                csv_num(o.f, "%.6e", d->with_output[k] ? d->max_abs[k][m] : NAN);
                fputc(',', o.f);
                csv_num(o.f, "%.6e", depth_mean_rel(d, k, m));
                fputc(',', o.f);
                csv_num(o.f, "%.6e", d->median_rel[k][m]);
                fputc(',', o.f);
                csv_num(o.f, "%.6e", d->with_output[k] ? d->max_rel[k][m] : NAN);
                fputc(',', o.f);
                csv_num(o.f, "%.6e", depth_total_rel(d, k, m));
                fputc('\n', o.f);
            }
    return out_close(&o);
}

static int write_glass_csv(const char *dir, sweep *sw[N_GLASS][N_SETUP],
                           depth_stats *const ds[N_GLASS], const double nd[N_GLASS])
{
    outfile o;
    if (out_open(&o, dir, "glass.csv"))
        return -1;
    fprintf(o.f, "glass,n_d,comparison,quantity,model,max_abs_err,at,max_rel_err,at,"
                 "ok_1pct_up_to,unit\n");
    for (int g = 0; g < N_GLASS; g++) {
        for (int s = 0; s < N_SETUP; s++)
            for (int k = 1; k <= DEPTH_A; k++)
                for (int m = 1; m < N_MODELS; m++) {
                    curve_stats cs = sweep_stats(sw[g][s], k, m);
                    if (m == M_RGB && isnan(sw[g][s]->P[0][k][M_RGB]))
                        continue;
                    fprintf(o.f, "%s,%.5f,%s,%s,%s,%.6e,%.1f,", GLASS_NAME[g], nd[g],
                            SETUP_NAME[s], QTY_NAME[k - 1], MODEL_NAME[m], cs.max_abs, cs.at_abs);
                    if (isfinite(cs.max_rel))
                        fprintf(o.f, "%.6e", cs.max_rel);
                    else
                        fprintf(o.f, "inf");
                    fprintf(o.f, ",%.1f,%.1f,deg\n", cs.at_rel, cs.ok_1pct);
                }
        for (int k = 1; k <= DEPTH_K; k++)
            for (int m = 1; m < N_MODELS; m++) {
                const depth_stats *d = ds[g];
                if (m == M_RGB && isnan(d->sum_P[k][M_RGB]))
                    continue;
                fprintf(o.f, "%s,%.5f,biconvex,P%d,%s,", GLASS_NAME[g], nd[g], k, MODEL_NAME[m]);
                csv_num(o.f, "%.6e", d->with_output[k] ? d->max_abs[k][m] : NAN);
                fprintf(o.f, ",,");
                csv_num(o.f, "%.6e", d->with_output[k] ? d->max_rel[k][m] : NAN);
                fprintf(o.f, ",,%d,depth\n", depth_ok_1pct(d, m));
            }
    }
    return out_close(&o);
}

/* ------------------------------------------------------------------ */
/* Plots                                                               */
/* ------------------------------------------------------------------ */

enum { IMG_W = 900, PANEL_H = 340 };
static const pl_dash DEPTH_DASH[DEPTH_A + 1] = {PL_SOLID, PL_SOLID, PL_DASHED, PL_DOTTED};

typedef struct plot_buf {
    double x[N_ANG];
    double y[N_ANG];
} plot_buf;

/* The legend keys shared by the angle charts: models by colour, depths by
 * line style. */
static size_t angle_keys(pl_series *s, int with_pol, int have_rgb)
{
    static const char *const DEPTH_KEY[DEPTH_A + 1] = {NULL, "depth 1 (R1)", "depth 2 (T2)",
                                                       "depth 3 (R3)"};
    size_t n = 0;
    for (int m = with_pol ? 0 : 1; m < N_MODELS; m++) {
        if (m == M_RGB && !have_rgb)
            continue;
        pl_series e = {MODEL_NAME[m], NULL, NULL, 0, MODEL_COLOR[m], PL_SOLID, MODEL_WIDTH[m]};
        s[n++] = e;
    }
    for (int k = 1; k <= DEPTH_A; k++) {
        pl_series e = {DEPTH_KEY[k], NULL, NULL, 0, 0x808080u, DEPTH_DASH[k], 2.0};
        s[n++] = e;
    }
    return n;
}

static int save_png(const char *dir, const char *name, const rs_image *img)
{
    char path[4096], msg[256];
    if (snprintf(path, sizeof path, "%s/%s", dir, name) >= (int)sizeof path)
        return -1;
    if (rs_png_write(path, img, msg, sizeof msg) != 0) {
        fprintf(stderr, "model_limits: %s\n", msg);
        return -1;
    }
    return 0;
}

static int plot_angle(const char *dir, const char *name, const sweep *sw, int setup,
                      const char *glass, double n_d, int have_rgb)
{
    rs_image img;
    char msg[256], title[3][160];
    int rc = -1;
    plot_buf *buf = calloc((size_t)3 * (DEPTH_A + 1) * N_MODELS, sizeof *buf);
    pl_series series[64];
    pl_marker marks[2];
    size_t nm = 0;

    if (!buf || rs_image_create(&img, IMG_W, 3 * PANEL_H) != 0) {
        free(buf);
        return -1;
    }
    pl_fill(&img, 0xFFFFFFu);
    if (setup == S_AIR_GLASS) {
        marks[nm].x = atan(n_d) / DEG;
        marks[nm++].label = "Brewster";
    } else {
        marks[nm].x = atan(1.0 / n_d) / DEG;
        marks[nm++].label = "Brewster";
        marks[nm].x = asin(1.0 / n_d) / DEG;
        marks[nm++].label = "critical";
    }
    const char *inc = setup == S_AIR_GLASS ? "angle of incidence in air (°)"
                                           : "angle of incidence in the glass (°)";
    snprintf(title[0], sizeof title[0], "%s, %s: power of the depth-1, 2, 3 rays", glass,
             setup == S_AIR_GLASS ? "plate in air (air->glass)" : "air gap in it (glass->air)");
    snprintf(title[1], sizeof title[1], "absolute error |P - P_polarized|  (fresnel R1 = 0)");
    snprintf(title[2], sizeof title[2], "relative error |P - P_polarized| / P_polarized");

    for (int panel = 0; panel < 3; panel++) {
        size_t n = 0;
        for (int k = 1; k <= DEPTH_A; k++)
            for (int o = 0; o < N_MODELS; o++) {
                int m = DRAW_ORDER[o];
                if ((m == M_RGB && !have_rgb) || (m == M_POL && panel > 0))
                    continue;
                plot_buf *b = &buf[((size_t)panel * (DEPTH_A + 1) + (size_t)k) * N_MODELS + (size_t)m];
                for (int i = 0; i < N_ANG; i++) {
                    double ref = sw->P[i][k][M_POL], v = sw->P[i][k][m];
                    b->x[i] = sw->angle[i];
                    b->y[i] = panel == 0 ? v
                              : panel == 1 ? fabs(v - ref)
                                           : 100.0 * fabs(rel_err(v, ref));
                }
                pl_series s = {NULL, b->x, b->y, N_ANG, MODEL_COLOR[m], DEPTH_DASH[k],
                               MODEL_WIDTH[m]};
                series[n++] = s;
            }
        n += angle_keys(series + n, panel == 0, have_rgb);
        pl_chart ch;
        memset(&ch, 0, sizeof ch);
        ch.title = title[panel];
        ch.xlabel = inc;
        ch.xmin = 0.0;
        ch.xmax = 90.0;
        ch.xstep = 10.0;
        ch.markers = marks;
        ch.n_markers = nm;
        ch.legend_columns = 2;
        if (panel == 0) {
            ch.ylabel = "power";
            ch.ymin = 0.0;
            ch.ymax = 1.0;
            ch.legend = setup == S_AIR_GLASS ? PL_LEGEND_LEFT : PL_LEGEND_RIGHT;
        } else if (panel == 1) {
            ch.ylabel = "absolute error";
            ch.ylog = 1;
            ch.ymin = 1e-7;
            ch.ymax = 1.0;
            ch.legend = PL_LEGEND_NONE;
        } else {
            ch.ylabel = "relative error";
            ch.ylog = 1;
            ch.ymin = 1e-5;
            ch.ymax = 100.0;
            ch.yticks_percent = 1;
            ch.legend = PL_LEGEND_NONE;
        }
        if (pl_draw(&img, 0, panel * PANEL_H, IMG_W, PANEL_H, &ch, series, n, msg, sizeof msg)) {
            fprintf(stderr, "model_limits: %s\n", msg);
            goto done;
        }
    }
    rc = save_png(dir, name, &img);
done:
    rs_image_free(&img);
    free(buf);
    return rc;
}

static int plot_depth(const char *dir, depth_stats *const ds[N_GLASS], int have_rgb)
{
    enum { PANELS = 4, STATS = 3 };
    rs_image img;
    char msg[256], title[PANELS][160];
    int rc = -1;
    double x[DEPTH_K], y[PANELS][N_MODELS][STATS][DEPTH_K];
    pl_series series[48];
    const depth_stats *d = ds[0];
    static const pl_dash STAT_DASH[STATS] = {PL_SOLID, PL_DASHED, PL_DOTTED};

    if (rs_image_create(&img, IMG_W, PANELS * PANEL_H) != 0)
        return -1;
    pl_fill(&img, 0xFFFFFFu);
    snprintf(title[0], sizeof title[0], "%s biconvex lens, %ld rays: mean power at depth k",
             GLASS_NAME[0], d->rays);
    snprintf(title[1], sizeof title[1], "rel. error per ray: median (solid), mean (--), max (..)");
    snprintf(title[2], sizeof title[2], "rel. error of the power summed over all rays");
    snprintf(title[3], sizeof title[3], "absolute error per ray: mean (solid), max (--)");
    for (int k = 1; k <= DEPTH_K; k++)
        x[k - 1] = k;
    for (int panel = 0; panel < PANELS; panel++) {
        size_t n = 0;
        int stats = panel == 1 ? 3 : panel == 3 ? 2 : 1;
        for (int o = 0; o < N_MODELS; o++) {
            int m = DRAW_ORDER[o];
            if ((m == M_RGB && !have_rgb) || (m == M_POL && panel > 0))
                continue;
            for (int st = 0; st < stats; st++) {
                double *yy = y[panel][m][st];
                for (int k = 1; k <= DEPTH_K; k++) {
                    int has = d->with_output[k] > 0;
                    double v;
                    if (panel == 0)
                        v = d->sum_P[k][m] / d->rays;
                    else if (panel == 1)
                        v = 100.0 * (st == 0   ? d->median_rel[k][m]
                                     : st == 1 ? depth_mean_rel(d, k, m)
                                               : (has ? d->max_rel[k][m] : NAN));
                    else if (panel == 2)
                        v = 100.0 * fabs(depth_total_rel(d, k, m));
                    else
                        v = st == 0 ? depth_mean_abs(d, k, m) : (has ? d->max_abs[k][m] : NAN);
                    yy[k - 1] = v;
                }
                pl_series sr = {NULL, x, yy, DEPTH_K, MODEL_COLOR[m], STAT_DASH[st],
                                MODEL_WIDTH[m]};
                series[n++] = sr;
            }
        }
        for (int m = panel == 0 ? 0 : 1; m < N_MODELS; m++) {
            if (m == M_RGB && !have_rgb)
                continue;
            pl_series e = {MODEL_NAME[m], NULL, NULL, 0, MODEL_COLOR[m], PL_SOLID, MODEL_WIDTH[m]};
            series[n++] = e;
        }
        pl_chart ch;
        memset(&ch, 0, sizeof ch);
        ch.title = title[panel];
        ch.xlabel = "tree depth k (interfaces along the path)";
        ch.xmin = 1.0;
        ch.xmax = DEPTH_K;
        ch.xstep = 1.0;
        ch.ylog = 1;
        ch.legend = panel == 0 ? PL_LEGEND_TOP_RIGHT : PL_LEGEND_BOTTOM_RIGHT;
        if (panel == 0) {
            ch.ylabel = "mean power";
            ch.ymin = 1e-6;
            ch.ymax = 1.0;
        } else if (panel == 1) {
            ch.ylabel = "relative error";
            ch.ymin = 1e-4;
            ch.ymax = 1e7;
            ch.yticks_percent = 1;
        } else if (panel == 2) {
            ch.ylabel = "relative error";
            ch.ymin = 1e-4;
            ch.ymax = 1e3;
            ch.yticks_percent = 1;
        } else {
            ch.ylabel = "absolute error";
            ch.ymin = 1e-8;
            ch.ymax = 1.0;
        }
        if (pl_draw(&img, 0, panel * PANEL_H, IMG_W, PANEL_H, &ch, series, n, msg, sizeof msg)) {
            fprintf(stderr, "model_limits: %s\n", msg);
            goto done;
        }
    }
    rc = save_png(dir, "depth.png", &img);
done:
    rs_image_free(&img);
    return rc;
}

static int plot_glass(const char *dir, sweep *sw[N_GLASS][N_SETUP],
                      depth_stats *const ds[N_GLASS], const double nd[N_GLASS], int have_rgb)
{
    rs_image img;
    char msg[256];
    int rc = -1;
    /* per panel: (model, glass) curves */
    plot_buf *buf = calloc((size_t)2 * N_MODELS * N_GLASS, sizeof *buf);
    double kx[DEPTH_K], ky[N_MODELS][N_GLASS][DEPTH_K];
    pl_series series[32];
    static const pl_dash GLASS_DASH[N_GLASS] = {PL_SOLID, PL_DASHED};
    static const int QTY[N_MODELS] = {0, 2, 1, 2}; /* fresnel T2, schlick R1, rgb T2 */
    static const char *const LABEL[N_MODELS] = {NULL, "fresnel T2", "schlick R1", "rgb T2"};

    pl_marker crit[N_GLASS];
    char crit_label[N_GLASS][48];
    for (int g = 0; g < N_GLASS; g++) {
        snprintf(crit_label[g], sizeof crit_label[g], "%s critical", GLASS_NAME[g]);
        crit[g].x = asin(1.0 / nd[g]) / DEG;
        crit[g].label = crit_label[g];
    }
    if (!buf || rs_image_create(&img, IMG_W, 3 * PANEL_H) != 0) {
        free(buf);
        return -1;
    }
    pl_fill(&img, 0xFFFFFFu);
    for (int panel = 0; panel < 3; panel++) {
        size_t n = 0;
        for (int o = 0; o < N_MODELS; o++) {
            int m = DRAW_ORDER[o];
            if ((m == M_RGB && !have_rgb) || m == M_POL)
                continue;
            for (int g = 0; g < N_GLASS; g++) {
                pl_series s = {NULL, NULL, NULL, 0, MODEL_COLOR[m], GLASS_DASH[g], MODEL_WIDTH[m]};
                if (panel < 2) {
                    plot_buf *b = &buf[((size_t)panel * N_MODELS + (size_t)m) * N_GLASS + (size_t)g];
                    for (int i = 0; i < N_ANG; i++) {
                        const double *P = sw[g][panel]->P[i][QTY[m]];
                        b->x[i] = sw[g][panel]->angle[i];
                        b->y[i] = 100.0 * fabs(rel_err(P[m], P[M_POL]));
                    }
                    s.x = b->x;
                    s.y = b->y;
                    s.n = N_ANG;
                } else {
                    for (int k = 1; k <= DEPTH_K; k++) {
                        kx[k - 1] = k;
                        ky[m][g][k - 1] = 100.0 * ds[g]->median_rel[k][m];
                    }
                    s.x = kx;
                    s.y = ky[m][g];
                    s.n = DEPTH_K;
                }
                series[n++] = s;
            }
        }
        for (int m = 1; m < N_MODELS; m++) {
            if (m == M_RGB && !have_rgb)
                continue;
            pl_series e = {panel < 2 ? LABEL[m] : MODEL_NAME[m], NULL, NULL, 0, MODEL_COLOR[m],
                           PL_SOLID, MODEL_WIDTH[m]};
            series[n++] = e;
        }
        for (int g = 0; g < N_GLASS; g++) {
            pl_series e = {GLASS_NAME[g], NULL, NULL, 0, 0x808080u, GLASS_DASH[g], 2.0};
            series[n++] = e;
        }
        pl_chart ch;
        memset(&ch, 0, sizeof ch);
        ch.ylabel = "relative error";
        ch.ylog = 1;
        ch.yticks_percent = 1;
        ch.legend_columns = 2;
        if (panel < 2) {
            ch.title = panel == 0 ? "plate in air (air->glass): relative error"
                                  : "air gap in glass (glass->air): relative error";
            ch.xlabel = panel == 0 ? "angle of incidence in air (°)"
                                   : "angle of incidence in the glass (°)";
            ch.xmin = 0.0;
            ch.xmax = 90.0;
            ch.xstep = 10.0;
            ch.ymin = 1e-5;
            ch.ymax = 100.0;
            ch.legend = PL_LEGEND_BOTTOM_RIGHT;
            if (panel == 1) {
                ch.markers = crit;
                ch.n_markers = N_GLASS;
            }
        } else {
            ch.title = "biconvex lens: median relative error per ray at depth k";
            ch.xlabel = "tree depth k";
            ch.xmin = 1.0;
            ch.xmax = DEPTH_K;
            ch.xstep = 1.0;
            ch.ymin = 1e-3;
            ch.ymax = 1e3;
            ch.legend = PL_LEGEND_BOTTOM_RIGHT;
        }
        if (pl_draw(&img, 0, panel * PANEL_H, IMG_W, PANEL_H, &ch, series, n, msg, sizeof msg)) {
            fprintf(stderr, "model_limits: %s\n", msg);
            goto done;
        }
    }
    rc = save_png(dir, "glass.png", &img);
done:
    rs_image_free(&img);
    free(buf);
    return rc;
}

/* ------------------------------------------------------------------ */
/* Summary                                                             */
/* ------------------------------------------------------------------ */

static void print_summary(const spectrum *sp, double mono, sweep *sw[N_GLASS][N_SETUP],
                          depth_stats *const ds[N_GLASS], const double nd[N_GLASS])
{
    if (mono > 0.0)
        printf("model_limits: natural light at %.4g nm (air), every model at that wavelength\n",
               mono);
    else
        printf("model_limits: natural light, luminance of D65 white over 380-780 nm (%d "
               "wavelengths); rgb = fresnel at 642.4/543.0/440.8 nm\n",
               sp->n);
    printf("\nFlat plate, natural light, error against polarized (R1: 1 interface, T2: 2, R3: 3)\n");
    printf("%-7s %-10s %-3s %-8s %10s %6s %10s %6s  %s\n", "glass", "setup", "ray", "model",
           "max|err|", "at°", "max|rel|", "at°", "|rel| < 1 % up to");
    for (int g = 0; g < N_GLASS; g++)
        for (int s = 0; s < N_SETUP; s++)
            for (int k = 1; k <= DEPTH_A; k++)
                for (int m = 1; m < N_MODELS; m++) {
                    if (m == M_RGB && !sp->have_rgb)
                        continue;
                    curve_stats cs = sweep_stats(sw[g][s], k, m);
                    char thr[32];
                    if (cs.all_ok)
                        snprintf(thr, sizeof thr, "all angles");
                    else if (cs.ok_1pct < 0.0)
                        snprintf(thr, sizeof thr, "never");
                    else
                        snprintf(thr, sizeof thr, "%.1f°", cs.ok_1pct);
                    printf("%-7s %-10s %-3s %-8s %10.3g %6.1f %9.3g%% %6.1f  %s\n", GLASS_NAME[g],
                           SETUP_TEXT[s], QTY_NAME[k - 1], MODEL_NAME[m], cs.max_abs, cs.at_abs,
                           100.0 * cs.max_rel, cs.at_rel, thr);
                }
    for (int table = 0; table < 2; table++) {
        printf(table == 0 ? "\nBiconvex lens R1=30 R2=-30 t=10 D=25, %ld random rays: median over the "
                            "rays of |rel. error| of the depth-k power\n"
                          : "\nThe same, relative error of the power summed over the rays "
                            "(signed)\n",
               ds[0]->rays);
        printf("%-7s %-8s", "glass", "model");
        for (int k = 1; k <= DEPTH_K; k++)
            printf(" %6d", k);
        printf(table == 0 ? "   median < 1 %% up to\n" : "\n");
        for (int g = 0; g < N_GLASS; g++)
            for (int m = 1; m < N_MODELS; m++) {
                if (m == M_RGB && !sp->have_rgb)
                    continue;
                printf("%-7s %-8s", GLASS_NAME[g], MODEL_NAME[m]);
                for (int k = 1; k <= DEPTH_K; k++) {
                    double v = 100.0 * (table == 0 ? ds[g]->median_rel[k][m]
                                                   : depth_total_rel(ds[g], k, m));
                    printf(" %5.2g%%", v);
                }
                if (table == 0)
                    printf("   depth %d", depth_ok_1pct(ds[g], m));
                printf("\n");
            }
    }
    printf("\nIn words (n_d: N-BK7 %.4f, N-SF11 %.4f):\n", nd[0], nd[1]);
    for (int g = 0; g < N_GLASS; g++) {
        curve_stats a = sweep_stats(sw[g][S_AIR_GLASS], 1, M_SCH);
        curve_stats b = sweep_stats(sw[g][S_GLASS_AIR], 1, M_SCH);
        curve_stats c = sweep_stats(sw[g][S_AIR_GLASS], 2, M_FRES);
        curve_stats e = sweep_stats(sw[g][S_GLASS_AIR], 2, M_FRES);
        printf("  %s: schlick reflectance within 1 %% up to %.1f° (air->glass) and %.1f° "
               "(glass->air, critical %.1f°);\n"
               "         fresnel transmission through 2 interfaces within 1 %% up to %.1f° "
               "(air->glass), %.1f° (glass->air)\n",
               GLASS_NAME[g], a.ok_1pct, b.ok_1pct, asin(1.0 / nd[g]) / DEG, c.ok_1pct,
               e.ok_1pct);
    }
}

/* ------------------------------------------------------------------ */
/* Main                                                                */
/* ------------------------------------------------------------------ */

typedef struct options {
    const char *out;
    long rays;
    uint64_t seed;
    double lambda;
} options;

static int usage_error(const char *fmt, const char *arg)
{
    fprintf(stderr, "model_limits: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, " (try --help)\n");
    return EXIT_USAGE;
}

/* 0: run; 1: help printed; EXIT_USAGE: bad usage (message printed). */
static int parse_args(int argc, char **argv, options *op)
{
    op->out = "docs/model-limits";
    op->rays = 2000;
    op->seed = 20240605u;
    op->lambda = 0.0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = NULL;
        char name[32];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            (void)sp_print_text(usage_text, sizeof usage_text / sizeof *usage_text);
            return 1;
        }
        const char *eq = strchr(a, '=');
        size_t len = eq ? (size_t)(eq - a) : strlen(a);
        if (len >= sizeof name)
            return usage_error("unknown option '%s'", a);
        memcpy(name, a, len);
        name[len] = '\0';
        if (strcmp(name, "--out") && strcmp(name, "--rays") && strcmp(name, "--seed") &&
            strcmp(name, "--lambda"))
            return usage_error("unknown option '%s'", a);
        if (eq)
            v = eq + 1;
        else if (i + 1 < argc)
            v = argv[++i];
        else
            return usage_error("option '%s' needs a value", a);
        char *end = NULL;
        errno = 0;
        if (strcmp(name, "--out") == 0) {
            if (*v == '\0')
                return usage_error("empty --out%s", "");
            op->out = v;
        } else if (strcmp(name, "--rays") == 0) {
            long n = strtol(v, &end, 10);
            if (errno || end == v || *end || n < 1 || n > 10000000)
                return usage_error("--rays wants an integer 1..10000000, not '%s'", v);
            op->rays = n;
        } else if (strcmp(name, "--seed") == 0) {
            unsigned long long s = strtoull(v, &end, 10);
            if (errno || end == v || *end || *v == '-')
                return usage_error("--seed wants an unsigned integer, not '%s'", v);
            op->seed = (uint64_t)s;
        } else {
            double l = strtod(v, &end);
            if (errno || end == v || *end || !(l >= 200.0 && l <= 2500.0))
                return usage_error("--lambda wants a wavelength in nm, 200..2500, not '%s'", v);
            op->lambda = l;
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    options op;
    int rc = parse_args(argc, argv, &op);
    if (rc == 1)
        return 0;
    if (rc)
        return rc;

    spectrum sp;
    spectrum_init(&sp, op.lambda);
    lp_error err;
    memset(&err, 0, sizeof err);
    tracer t;
    lp_result_init(&t.res);
    lp_trace_args_init(&t.args);

    sweep *sw[N_GLASS][N_SETUP] = {{NULL, NULL}, {NULL, NULL}};
    depth_stats *ds[N_GLASS] = {NULL, NULL};
    double nd[N_GLASS];
    int status = 1;

    for (int g = 0; g < N_GLASS; g++) {
        lp_glass glass;
        if (lp_glass_builtin(GLASS_NAME[g], &glass, &err) != LP_OK)
            goto fail;
        /* lossless: absorption multiplies a path's power by the same
         * factor in every model, so it is left out of the comparison */
        glass.n_tau = 0;
        nd[g] = lp_glass_index(&glass, LAMBDA_D);
        for (int s = 0; s < N_SETUP; s++) {
            lp_lens *plate = NULL;
            sw[g][s] = malloc(sizeof *sw[g][s]);
            if (!sw[g][s]) {
                snprintf(err.message, sizeof err.message, "out of memory");
                goto fail;
            }
            if (make_plate(&glass, s == S_GLASS_AIR, &plate, &err))
                goto fail;
            int bad = run_sweep(&t, &sp, plate, sw[g][s], &err);
            lp_lens_destroy(plate);
            if (bad)
                goto fail;
        }
        lp_lens *lens = NULL;
        ds[g] = malloc(sizeof *ds[g]);
        if (!ds[g]) {
            snprintf(err.message, sizeof err.message, "out of memory");
            goto fail;
        }
        if (make_biconvex(&glass, &lens, &err))
            goto fail;
        int bad = run_depth(&t, &sp, lens, (int)op.rays, op.seed, ds[g], &err);
        lp_lens_destroy(lens);
        if (bad)
            goto fail;
    }

    {
        char msg[4200];
        if (sp_mkdir_p(op.out, msg, sizeof msg)) {
            sp_say("model_limits", "%s", msg);
            goto out;
        }
    }
    if (write_angle_csv(op.out, sw) || write_depth_csv(op.out, ds) ||
        write_glass_csv(op.out, sw, ds, nd)) {
        fprintf(stderr, "model_limits: cannot write the tables in '%s'\n", op.out);
        goto out;
    }
    /* the angle plots show N-BK7; glass.png sets both glasses side by side */
    if (plot_angle(op.out, "angle_air_glass.png", sw[0][S_AIR_GLASS], S_AIR_GLASS, GLASS_NAME[0],
                   nd[0], sp.have_rgb) ||
        plot_angle(op.out, "angle_glass_air.png", sw[0][S_GLASS_AIR], S_GLASS_AIR, GLASS_NAME[0],
                   nd[0], sp.have_rgb) ||
        plot_depth(op.out, ds, sp.have_rgb) || plot_glass(op.out, sw, ds, nd, sp.have_rgb)) {
        fprintf(stderr, "model_limits: cannot write the plots in '%s'\n", op.out);
        goto out;
    }
    print_summary(&sp, op.lambda, sw, ds, nd);
    status = 0;
    goto out;
fail:
    fprintf(stderr, "model_limits: %s\n", err.message);
out:
    for (int g = 0; g < N_GLASS; g++) {
        free(sw[g][0]);
        free(sw[g][1]);
        free(ds[g]);
    }
    lp_result_release(&t.res);
    return status;
}
