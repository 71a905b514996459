/* exp_cone.c -- the cone K of rim-free initial directions (the paper's
 * first experiment of the module): theta_K of every shipped lens against
 * dT, the collimated case, an off-axis point, and the cone drawn over the
 * lens. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "experiments.h"
#include "plot.h"

#define PI 3.14159265358979323846
#define DEG (180.0 / PI)
#define LAMBDA 587.56
#define N_OFF 72 /* azimuths of the off-axis cone */

static double sag(double r_curv, double h)
{
    if (r_curv == 0.0 || isinf(r_curv))
        return 0.0;
    double c = 1.0 / r_curv;
    return c * h * h / (1.0 + sqrt(fmax(0.0, 1.0 - c * c * h * h)));
}

/* The apex of a lens's cone: on the axis, two diameters in front. */
static lp_vec3 apex_of(const lp_lens_desc *d)
{
    return (lp_vec3){0, 0, -2.0 * d->diameter};
}

static double aperture(const lp_lens_desc *d)
{
    return 0.5 * (d->diameter2 > d->diameter ? d->diameter2 : d->diameter);
}

/* theta_K (rad) on the axis and the normal beam's rho_K (mm) at depth dT. */
static int cone_on_axis(ex_ctx *ctx, const lp_lens *lens, const lp_lens_desc *d, int dT,
                        double *theta, double *omega, double *rho)
{
    lp_cone_args a;
    lp_cone cone;
    lp_beam_region reg;
    lp_error err;
    lp_cone_args_init(&a);
    a.max_depth = dT;
    a.lambda_nm = LAMBDA;
    /* on the axis the cone is circular: one azimuth is the whole cone */
    if (lp_cone_compute(lens, apex_of(d), &a, 1, theta, &cone, &err) != LP_OK ||
        lp_beam_region_compute(lens, (lp_vec3){0, 0, 1}, &a, 1, rho, &reg, &err) != LP_OK) {
        snprintf(ctx->msg, sizeof ctx->msg, "cone: %s", err.message);
        return -1;
    }
    *omega = cone.solid_angle;
    return 0;
}

/* ------------------------------------------------------------------ */
/* the cone drawn over the lens (meridional section)                   */
/* ------------------------------------------------------------------ */

enum { SEC_PTS = 64, CHAIN_MAX = EX_DEPTH_MAX + 2 };

typedef struct section {
    double zf[SEC_PTS], rf[SEC_PTS], zb[SEC_PTS], rb[SEC_PTS];
    double rim_z[2][2], rim_r[2][2];
} section;

static void section_make(const lp_lens_desc *d, section *s)
{
    double h1 = 0.5 * d->diameter, h2 = 0.5 * (d->diameter2 > 0 ? d->diameter2 : d->diameter);
    for (int i = 0; i < SEC_PTS; i++) {
        double u = -1.0 + 2.0 * i / (SEC_PTS - 1);
        s->rf[i] = u * h1;
        s->zf[i] = sag(d->radius1, s->rf[i]);
        s->rb[i] = u * h2;
        s->zb[i] = d->thickness + sag(d->radius2, s->rb[i]);
    }
    for (int k = 0; k < 2; k++) {
        double sg = k ? -1.0 : 1.0;
        s->rim_z[k][0] = sag(d->radius1, h1);
        s->rim_r[k][0] = sg * h1;
        s->rim_z[k][1] = d->thickness + sag(d->radius2, h2);
        s->rim_r[k][1] = sg * h2;
    }
}

/* The chain of the ray from apex along dir in the meridional plane y = 0
 * (x is the drawing's r): the apex, the entry point and the nodes up to
 * depth dT, or fewer where it leaves or meets the rim. */
static int chain_points(const lp_lens *lens, double n, lp_vec3 apex, lp_vec3 dir, int dT,
                        double *z, double *r)
{
    lp_hit h;
    int k = 0;
    z[k] = apex.z;
    r[k++] = apex.x;
    if (!lp_lens_intersect(lens, apex, dir, 0.0, INFINITY, &h))
        return k;
    z[k] = h.point.z;
    r[k++] = h.point.x;
    if (h.surface == LP_SURFACE_RIM)
        return k;
    /* Snell into the glass (the normal points out of the glass) */
    double ci = -(dir.x * h.normal.x + dir.y * h.normal.y + dir.z * h.normal.z);
    double eta = 1.0 / n, k2 = 1.0 - eta * eta * (1.0 - ci * ci);
    if (k2 < 0.0)
        return k;
    double f = eta * ci - sqrt(k2);
    lp_vec3 d = {eta * dir.x + f * h.normal.x, eta * dir.y + f * h.normal.y,
                 eta * dir.z + f * h.normal.z};
    for (int depth = 2; depth <= dT; depth++) {
        lp_vec3 p = h.point;
        if (!lp_lens_intersect(lens, p, d, 1e-9, INFINITY, &h))
            break;
        z[k] = h.point.z;
        r[k++] = h.point.x;
        if (h.surface == LP_SURFACE_RIM)
            break;
        double dn = d.x * h.normal.x + d.y * h.normal.y + d.z * h.normal.z;
        d = (lp_vec3){d.x - 2 * dn * h.normal.x, d.y - 2 * dn * h.normal.y,
                      d.z - 2 * dn * h.normal.z};
    }
    return k;
}

static int draw_section(ex_ctx *ctx, rs_image *img, int x0, int y0, int w, int h,
                        const ex_lens *el, const lp_lens *lens, int dT, double theta)
{
    const lp_lens_desc *d = &el->desc;
    section s;
    section_make(d, &s);
    double n = lp_glass_index(&d->glass, LAMBDA);
    lp_vec3 apex = apex_of(d);
    double a = aperture(d);
    /* equal scales on both axes (the frame takes about 90 pixels) */
    double zmid = 0.5 * d->thickness, zhalf = 0.5 * d->thickness + 0.6 * a, rhalf = 1.15 * a;
    double px = (double)(w - 90), py = (double)(h - 90);
    double sc = fmax(2.0 * zhalf / px, 2.0 * rhalf / py);
    double zmin = zmid - 0.5 * sc * px, zmax = zmid + 0.5 * sc * px;
    double rspan = sc * py;

    enum { N_RAYS = 6 };
    static double cz[N_RAYS][CHAIN_MAX + 1], cr[N_RAYS][CHAIN_MAX + 1];
    pl_series ser[8 + N_RAYS];
    size_t ns = 0;
    ser[ns++] = (pl_series){"lens", s.zf, s.rf, SEC_PTS, 0x000000u, PL_SOLID, 2};
    ser[ns++] = (pl_series){NULL, s.zb, s.rb, SEC_PTS, 0x000000u, PL_SOLID, 2};
    ser[ns++] = (pl_series){"rim", s.rim_z[0], s.rim_r[0], 2, 0x8c564bu, PL_SOLID, 5};
    ser[ns++] = (pl_series){NULL, s.rim_z[1], s.rim_r[1], 2, 0x8c564bu, PL_SOLID, 5};
    /* the two edge rays of K (just inside) and rays inside it */
    const double frac[N_RAYS] = {1, -1, 0.66, -0.66, 0.33, -0.33};
    for (int i = 0; i < N_RAYS; i++) {
        double t = frac[i] * theta * (1.0 - 1e-7);
        lp_vec3 dir = {sin(t), 0, cos(t)};
        int m = chain_points(lens, n, apex, dir, dT, cz[i], cr[i]);
        int edge = i < 2;
        ser[ns++] = (pl_series){i == 0 ? "edge of K" : (i == 2 ? "inside K" : NULL), cz[i], cr[i],
                                (size_t)m, edge ? 0xd62728u : 0x1f77b4u,
                                edge ? PL_SOLID : PL_DASHED, edge ? 2 : 1.5};
    }
    char title[160];
    snprintf(title, sizeof title, "%s  dT=%d  theta_K=%.3f\xc2\xb0", el->name, dT, theta * DEG);
    pl_chart ch;
    memset(&ch, 0, sizeof ch);
    ch.title = title;
    ch.xlabel = "z (mm)";
    ch.ylabel = "r (mm)";
    ch.xmin = zmin;
    ch.xmax = zmax;
    ch.ymin = -0.5 * rspan;
    ch.ymax = 0.5 * rspan;
    ch.legend = PL_LEGEND_BOTTOM_RIGHT;
    if (pl_draw(img, x0, y0, w, h, &ch, ser, ns, ctx->msg, sizeof ctx->msg) != 0)
        return -1;
    return 0;
}

/* ------------------------------------------------------------------ */

static int find_lens(const ex_ctx *ctx, const char *name)
{
    for (int i = 0; i < ctx->n_lens; i++)
        if (strcmp(ctx->lens[i].name, name) == 0)
            return i;
    return -1;
}

static int figure_sections(ex_ctx *ctx, lp_lens *const *lenses,
                           double theta[][EX_DEPTH_MAX + 1])
{
    const char *pick[4] = {"default", "meniscus", "conical_rim", "biconcave"};
    const int depth[4] = {4, 4, 4, 4};
    rs_image img;
    int rc = 0;
    if (ex_canvas(ctx, &img, 1200, 900) != 0)
        return -1;
    for (int p = 0; p < 4 && rc == 0; p++) {
        int i = find_lens(ctx, pick[p]);
        if (i < 0)
            continue;
        rc = draw_section(ctx, &img, (p % 2) * 600, (p / 2) * 450, 600, 450, &ctx->lens[i],
                          lenses[i], depth[p], theta[i][depth[p]]);
    }
    if (rc == 0)
        rc = ex_save_png(ctx, "cone_sections.png", &img);
    rs_image_free(&img);
    return rc;
}

static int figure_depth(ex_ctx *ctx, double theta[][EX_DEPTH_MAX + 1],
                        double rho[][EX_DEPTH_MAX + 1])
{
    static double x[EX_DEPTH_MAX], y[2][EX_LENS_MAX][EX_DEPTH_MAX];
    pl_series ser[2][EX_LENS_MAX];
    rs_image img;
    int rc = 0;
    double ymax = 0;
    for (int k = 0; k < EX_DEPTH_MAX; k++)
        x[k] = k + 1;
    for (int i = 0; i < ctx->n_lens; i++) {
        for (int k = 0; k < EX_DEPTH_MAX; k++) {
            y[0][i][k] = theta[i][k + 1] * DEG;
            y[1][i][k] = 100.0 * rho[i][k + 1] / aperture(&ctx->lens[i].desc);
            ymax = fmax(ymax, y[0][i][k]);
        }
        for (int p = 0; p < 2; p++)
            ser[p][i] = (pl_series){ctx->lens[i].name, x, y[p][i], EX_DEPTH_MAX,
                                    ex_palette[i % 12], i < 12 ? PL_SOLID : PL_DASHED, 2};
    }
    if (ex_canvas(ctx, &img, 1100, 900) != 0)
        return -1;
    pl_chart ch;
    memset(&ch, 0, sizeof ch);
    ch.title = "theta_K from the point on the axis two diameters in front";
    ch.xlabel = "tree depth dT";
    ch.ylabel = "theta_K (\xc2\xb0)";
    ch.xmin = 1;
    ch.xmax = EX_DEPTH_MAX;
    ch.xstep = 1;
    ch.ymin = 0;
    ch.ymax = ceil(ymax / 2.0) * 2.0 + 2.0;
    ch.legend = PL_LEGEND_BOTTOM_LEFT;
    ch.legend_columns = 2;
    rc = pl_draw(&img, 0, 0, 1100, 450, &ch, ser[0], (size_t)ctx->n_lens, ctx->msg,
                 sizeof ctx->msg);
    if (rc == 0) {
        ch.title = "collimated light along the axis: rim-free radius of the entry points";
        ch.ylabel = "rho_K / aperture radius (%)";
        ch.ymax = 105;
        ch.yticks_percent = 1;
        rc = pl_draw(&img, 0, 450, 1100, 450, &ch, ser[1], (size_t)ctx->n_lens, ctx->msg,
                     sizeof ctx->msg);
    }
    if (rc == 0)
        rc = ex_save_png(ctx, "theta_vs_depth.png", &img);
    rs_image_free(&img);
    return rc;
}

/* An off-axis point: theta_K per azimuth. */
static int off_axis(ex_ctx *ctx, const char *name, const lp_lens *lens, const lp_lens_desc *d,
                    FILE *csv)
{
    const int depths[4] = {2, 4, 6, 8};
    static double th[4][N_OFF], px[4][N_OFF + 1], py[4][N_OFF + 1];
    lp_cone cone[4];
    lp_vec3 P = {0.25 * d->diameter, 0, -2.0 * d->diameter};
    char lbl[4][32];
    pl_series ser[4];
    double m = 0;
    for (int j = 0; j < 4; j++) {
        lp_cone_args a;
        lp_error err;
        lp_cone_args_init(&a);
        a.max_depth = depths[j];
        if (lp_cone_compute(lens, P, &a, N_OFF, th[j], &cone[j], &err) != LP_OK) {
            snprintf(ctx->msg, sizeof ctx->msg, "off-axis cone: %s", err.message);
            return -1;
        }
        for (int k = 0; k <= N_OFF; k++) {
            double ph = 2 * PI * (k % N_OFF) / N_OFF, t = th[j][k % N_OFF] * DEG;
            px[j][k] = t * cos(ph);
            py[j][k] = t * sin(ph);
            m = fmax(m, t);
        }
        for (int k = 0; k < N_OFF; k++)
            fprintf(csv, "%s (off axis),%d,%.6f,%.12g\n", name, depths[j], 360.0 * k / N_OFF,
                    th[j][k] * DEG);
        snprintf(lbl[j], sizeof lbl[j], "dT = %d", depths[j]);
        ser[j] = (pl_series){lbl[j], px[j], py[j], N_OFF + 1, ex_palette[j], PL_SOLID, 2};
    }
    rs_image img;
    if (ex_canvas(ctx, &img, 700, 700) != 0)
        return -1;
    pl_chart ch;
    memset(&ch, 0, sizeof ch);
    char title[128];
    snprintf(title, sizeof title, "%s, apex (%g, 0, %g): edge of K", name, P.x, P.z);
    ch.title = title;
    ch.xlabel = "theta_K cos(phi) (\xc2\xb0)";
    ch.ylabel = "theta_K sin(phi) (\xc2\xb0)";
    m = ceil(m / 5.0) * 5.0;
    ch.xmin = ch.ymin = -m;
    ch.xmax = ch.ymax = m;
    ch.legend = PL_LEGEND_TOP_RIGHT;
    int rc = pl_draw(&img, 0, 0, 700, 700, &ch, ser, 4, ctx->msg, sizeof ctx->msg);
    if (rc == 0)
        rc = ex_save_png(ctx, "cone_off_axis.png", &img);
    rs_image_free(&img);
    if (rc != 0)
        return rc;

    fprintf(ctx->md,
            "### Off the axis\n\n"
            "From the point (%g, 0, %g) of the %s lens's frame (a quarter diameter off "
            "the axis) the cone is not circular: θ_K per azimuth φ about the axis from the "
            "point to the front vertex (φ = 0 along +x's part perpendicular to it), %d "
            "azimuths:\n\n"
            "| dT | θ_K min (°) | θ_K max (°) | solid angle (sr) |\n|---|---|---|---|\n",
            P.x, P.z, name, N_OFF);
    for (int j = 0; j < 4; j++)
        fprintf(ctx->md, "| %d | %.4f | %.4f | %.5f |\n", depths[j], cone[j].theta_min * DEG,
                cone[j].theta_max * DEG, cone[j].solid_angle);
    fprintf(ctx->md, "\n![off-axis cone](%s/cone_off_axis.png)\n\n", ctx->fig_rel);
    return 0;
}

/* A beam tilted in the x-z plane: the rim-free region of the entry
 * points is not a disc. */
static int tilted_beam(ex_ctx *ctx, const char *name, const lp_lens *lens,
                       const lp_lens_desc *desc)
{
    const double tilt[3] = {0, 10, 20};
    fprintf(ctx->md,
            "### Collimated light\n\n"
            "For parallel light the rim-free region is a set of entry points: per azimuth in "
            "the plane perpendicular to the beam, the largest offset ρ_K from the ray "
            "through the front vertex such that every ray closer to it is rim-free "
            "(`lp_beam_region_compute`).  The %s lens, beam tilted from the axis in the "
            "x-z plane, 72 azimuths:\n\n"
            "| tilt | dT | ρ_K min (mm) | ρ_K max (mm) | area (mm²) | share of the aperture |\n"
            "|---|---|---|---|---|---|\n",
            name);
    for (int i = 0; i < 3; i++) {
        for (int dT = 2; dT <= EX_DEPTH_MAX; dT += 3) {
            double r[72];
            lp_beam_region reg;
            lp_cone_args a;
            lp_error err;
            lp_cone_args_init(&a);
            a.max_depth = dT;
            lp_vec3 d = {sin(tilt[i] / DEG), 0, cos(tilt[i] / DEG)};
            if (lp_beam_region_compute(lens, d, &a, 72, r, &reg, &err) != LP_OK) {
                snprintf(ctx->msg, sizeof ctx->msg, "beam: %s", err.message);
                return -1;
            }
            double ap = PI * aperture(desc) * aperture(desc) * cos(tilt[i] / DEG);
            fprintf(ctx->md, "| %g° | %d | %.4f | %.4f | %.2f | %.1f %% |\n", tilt[i], dT,
                    reg.radius_min, reg.radius_max, reg.area, 100.0 * reg.area / ap);
        }
    }
    fprintf(ctx->md, "\n(The share divides by the aperture's projection π (D/2)² cos(tilt).  A "
                     "region is star-shaped about the ray through the front vertex: when "
                     "that ray itself meets the rim, ρ_K is 0 everywhere.)\n\n");
    return 0;
}

int ex_cone(ex_ctx *ctx)
{
    static double theta[EX_LENS_MAX][EX_DEPTH_MAX + 1], omega[EX_LENS_MAX][EX_DEPTH_MAX + 1],
        rho[EX_LENS_MAX][EX_DEPTH_MAX + 1];
    lp_lens *lenses[EX_LENS_MAX] = {0};
    int rc = 0;
    FILE *csv = ex_open(ctx, "cone.csv");
    if (!csv)
        return -1;
    fprintf(csv, "lens,dT,azimuth_deg,theta_K_deg,solid_angle_sr,beam_rho_K_mm\n");
    for (int i = 0; i < ctx->n_lens && rc == 0; i++) {
        lp_error err;
        if (lp_lens_create(&ctx->lens[i].desc, &lenses[i], &err) != LP_OK) {
            snprintf(ctx->msg, sizeof ctx->msg, "lens %s: %s", ctx->lens[i].name, err.message);
            rc = -1;
            break;
        }
        for (int dT = 1; dT <= EX_DEPTH_MAX && rc == 0; dT++) {
            rc = cone_on_axis(ctx, lenses[i], &ctx->lens[i].desc, dT, &theta[i][dT],
                              &omega[i][dT], &rho[i][dT]);
            if (rc == 0)
                fprintf(csv, "%s,%d,all,%.12g,%.12g,%.12g\n", ctx->lens[i].name, dT,
                        theta[i][dT] * DEG, omega[i][dT], rho[i][dT]);
        }
    }

    if (rc == 0) {
        fprintf(ctx->md,
                "## 1. The cone K of rim-free directions\n\n"
                "The rim holds the mount; a ray that meets it is absorbed and its "
                "polarization cannot be followed.  K is the set of directions of initial "
                "rays from a point whose whole internal chain up to the depth dT — the entry "
                "node and the rays reflected from cap to cap — meets only the caps.  "
                "`lp_cone_compute` finds, per azimuth φ about the axis from the point to the "
                "front vertex, the largest θ_K(φ) such that every direction at a smaller "
                "angle is rim-free: a scan of 2048 steps for the first failure on the "
                "library's own chain (`lp_backward_build`), then a bisection to 1e-9 rad; "
                "the solid angle is Σ (1 − cos θ_K) 2π/K.  (`lenstrace --cone` prints the "
                "same.)  The tests compare θ_K with a meridional trace written in the test "
                "(Spencer–Murty caps, vector Snell, cylindrical and conical rim): within "
                "1e-9 rad.\n\n"
                "Every lens of the shipped scenes (`scenes/*.scene`, each in its own frame), "
                "apex on the axis two diameters in front of the front vertex (z = −2D), "
                "λ = %.2f nm.  θ_K in degrees:\n\n| lens | glass | R1 | R2 | t | D | D2 |",
                LAMBDA);
        for (int dT = 1; dT <= EX_DEPTH_MAX; dT++)
            fprintf(ctx->md, " dT=%d |", dT);
        fprintf(ctx->md, "\n|---|---|---|---|---|---|---|");
        for (int dT = 1; dT <= EX_DEPTH_MAX; dT++)
            fprintf(ctx->md, "---|");
        fprintf(ctx->md, "\n");
        int bic = find_lens(ctx, "biconcave");
        for (int i = 0; i < ctx->n_lens; i++) {
            const lp_lens_desc *d = &ctx->lens[i].desc;
            fprintf(ctx->md, "| %s | %s | %g | %g | %g | %g | %g |", ctx->lens[i].name,
                    ctx->lens[i].glass, d->radius1, d->radius2, d->thickness, d->diameter,
                    d->diameter2 > 0 ? d->diameter2 : d->diameter);
            for (int dT = 1; dT <= EX_DEPTH_MAX; dT++)
                fprintf(ctx->md, " %.4f |", theta[i][dT] * DEG);
            fprintf(ctx->md, "\n");
        }
        fprintf(ctx->md,
                "\nθ_K falls with dT in steps: a deeper node matters only where the chain's "
                "new segment is the first to reach the rim.  Internal rays that walk outwards "
                "cost directions at every depth: the biconcave lens (its cone shrinks from "
                "%.1f° to %.1f° between dT = 1 and 8) and the flat plates of newtons_rings.  "
                "A weakly curved converging lens (default, plano_convex, dispersion, "
                "polariscope #1) keeps its internal rays near the axis: its cone is set by "
                "the first internal segment and changes by less than 0.4° after dT = 2; "
                "strongly curved "
                "or thick ones (crossed_polarizers, polariscope #2 and #3, conical_rim) lose "
                "a step every second or third depth.  Solid angles (sr), and for collimated "
                "light along the axis the rim-free radius ρ_K of the entry points as a share "
                "of the aperture radius:\n\n"
                "| lens | Ω dT=2 | Ω dT=5 | Ω dT=8 | ρ_K dT=2 | ρ_K dT=5 | ρ_K dT=8 |\n"
                "|---|---|---|---|---|---|---|\n",
                bic >= 0 ? theta[bic][1] * DEG : NAN, bic >= 0 ? theta[bic][EX_DEPTH_MAX] * DEG : NAN);
        for (int i = 0; i < ctx->n_lens; i++) {
            double a = aperture(&ctx->lens[i].desc);
            fprintf(ctx->md, "| %s | %.5f | %.5f | %.5f | %.1f %% | %.1f %% | %.1f %% |\n",
                    ctx->lens[i].name, omega[i][2], omega[i][5], omega[i][8],
                    100 * rho[i][2] / a, 100 * rho[i][5] / a, 100 * rho[i][8] / a);
        }
        fprintf(ctx->md, "\n![theta_K against dT](%s/theta_vs_depth.png)\n\n"
                         "The cone drawn over the lens (meridional section, dT = 4): the edge "
                         "rays of K (red, their internal chain up to dT just clears the rim "
                         "corner it would meet next) and rays inside K (blue).\n\n"
                         "![the cone over the lens](%s/cone_sections.png)\n\n",
                ctx->fig_rel, ctx->fig_rel);
        rc = figure_depth(ctx, theta, rho);
    }
    if (rc == 0)
        rc = figure_sections(ctx, lenses, theta);
    /* off the axis and tilted: the lens whose cone depends most on dT */
    int sel = find_lens(ctx, "biconcave");
    if (sel < 0)
        sel = find_lens(ctx, "default");
    if (rc == 0 && sel >= 0)
        rc = off_axis(ctx, ctx->lens[sel].name, lenses[sel], &ctx->lens[sel].desc, csv);
    if (rc == 0 && sel >= 0)
        rc = tilted_beam(ctx, ctx->lens[sel].name, lenses[sel], &ctx->lens[sel].desc);
    for (int i = 0; i < ctx->n_lens; i++)
        lp_lens_destroy(lenses[i]);
    if (ex_close(ctx, csv, "cone.csv") != 0)
        rc = -1;
    return rc;
}
