/* exp_shares.c -- backward tracing with initial rays inside K: the share
 * of the outgoing intensity carried by the bundle rays of each depth (the
 * paper's second experiment of the module). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "experiments.h"
#include "plot.h"

#define PI 3.14159265358979323846
#define LAMBDA 587.56
#define DT EX_DEPTH_MAX
#define N_AZ 36
#define N_RING 24

typedef struct shape {
    const char *name;
    double r1, r2, t, d;
} shape;

static const shape shapes[3] = {
    {"biconvex", 50, -50, 8, 25},
    {"meniscus", 30, 60, 6, 25},
    {"flat plate", INFINITY, INFINITY, 5, 25},
};
static const char *const glasses[2] = {"N-BK7", "N-SF11"};

/* Shares by depth over the directions of K from the apex, both lightings
 * (light from every side, and from behind only).  shares[l][k], k = 1..DT. */
static int measure(ex_ctx *ctx, const lp_lens *lens, lp_vec3 apex, double shares[2][DT + 1],
                   double *theta_k)
{
    lp_cone_args ca;
    lp_cone cone;
    lp_error err;
    double theta[N_AZ];
    lp_cone_args_init(&ca);
    ca.max_depth = DT;
    ca.lambda_nm = LAMBDA;
    if (lp_cone_compute(lens, apex, &ca, N_AZ, theta, &cone, &err) != LP_OK) {
        snprintf(ctx->msg, sizeof ctx->msg, "shares: cone: %s", err.message);
        return -1;
    }
    *theta_k = cone.theta_min;
    lp_vec3 a = cone.frame.axis, e1 = cone.frame.ref;
    lp_vec3 e2 = {a.y * e1.z - a.z * e1.y, a.z * e1.x - a.x * e1.z, a.x * e1.y - a.y * e1.x};
    for (int l = 0; l < 2; l++) {
        double sum[DT + 1] = {0}, total = 0;
        lp_trace_args ta;
        lp_trace_args_init(&ta);
        ta.max_depth = DT;
        ta.flags = l ? LP_SKIP_REFLECTED : 0;
        for (int k = 0; k < N_AZ; k++) {
            double ph = 2 * PI * k / N_AZ, c = 1 - cos(theta[k]);
            for (int j = 0; j < N_RING; j++) {
                /* equal solid angle per sample: cos(theta) uniform */
                double ct = 1 - (j + 0.5) / N_RING * c, st = sqrt(fmax(0, 1 - ct * ct));
                lp_vec3 d = {ct * a.x + st * (cos(ph) * e1.x + sin(ph) * e2.x),
                             ct * a.y + st * (cos(ph) * e1.y + sin(ph) * e2.y),
                             ct * a.z + st * (cos(ph) * e1.z + sin(ph) * e2.z)};
                double by[DT + 1] = {0};
                if (lp_bundle_by_depth(lens, apex, d, LAMBDA, &ta, by, &err) != LP_OK) {
                    snprintf(ctx->msg, sizeof ctx->msg, "shares: %s", err.message);
                    return -1;
                }
                for (int m = 1; m <= DT; m++)
                    sum[m] += by[m] * c / N_RING;
            }
        }
        for (int m = 1; m <= DT; m++)
            total += sum[m];
        for (int m = 1; m <= DT; m++)
            shares[l][m] = sum[m] / total;
    }
    return 0;
}

int ex_shares(ex_ctx *ctx)
{
    static double sh[3][2][2][DT + 1]; /* shape, glass, lighting, depth */
    double theta_k[3][2];
    FILE *csv = ex_open(ctx, "shares.csv");
    int rc = 0;
    if (!csv)
        return -1;
    fprintf(csv, "lens,glass,light,depth,share\n");
    for (int s = 0; s < 3 && rc == 0; s++) {
        for (int g = 0; g < 2 && rc == 0; g++) {
            lp_lens *lens = ex_make_lens(ctx, shapes[s].r1, shapes[s].r2, shapes[s].t,
                                         shapes[s].d, 0, glasses[g]);
            if (!lens) {
                rc = -1;
                break;
            }
            rc = measure(ctx, lens, (lp_vec3){0, 0, -2 * shapes[s].d}, sh[s][g], &theta_k[s][g]);
            lp_lens_destroy(lens);
            for (int l = 0; rc == 0 && l < 2; l++)
                for (int m = 1; m <= DT; m++)
                    fprintf(csv, "%s,%s,%s,%d,%.12g\n", shapes[s].name, glasses[g],
                            l ? "behind" : "all", m, sh[s][g][l][m]);
        }
    }
    if (ex_close(ctx, csv, "shares.csv") != 0)
        rc = -1;
    if (rc != 0)
        return rc;

    /* the figure: shares against depth, log scale, both lightings (light
     * from behind has only even depths: those are drawn) */
    static double x[2][DT], y[2][6][DT];
    static char lbl[6][48];
    pl_series ser[2][6];
    for (int m = 0; m < DT; m++) {
        x[0][m] = m + 1;
        x[1][m] = 2 * (m + 1);
    }
    for (int s = 0; s < 3; s++)
        for (int g = 0; g < 2; g++) {
            int i = 2 * s + g;
            snprintf(lbl[i], sizeof lbl[i], "%s %s", shapes[s].name, glasses[g]);
            for (int m = 0; m < DT; m++)
                y[0][i][m] = sh[s][g][0][m + 1];
            for (int m = 0; 2 * (m + 1) <= DT; m++)
                y[1][i][m] = sh[s][g][1][2 * (m + 1)];
            for (int l = 0; l < 2; l++)
                ser[l][i] = (pl_series){lbl[i], x[l], y[l][i], l ? DT / 2 : DT, ex_palette[s],
                                        g ? PL_DASHED : PL_SOLID, 2};
        }
    rs_image img;
    if (ex_canvas(ctx, &img, 1000, 900) != 0)
        return -1;
    pl_chart ch;
    memset(&ch, 0, sizeof ch);
    ch.title = "share of the outgoing intensity by depth: light from every side";
    ch.xlabel = "depth of the bundle ray";
    ch.ylabel = "share";
    ch.xmin = 1;
    ch.xmax = DT;
    ch.xstep = 1;
    ch.ymin = 1e-10;
    ch.ymax = 1;
    ch.ylog = 1;
    ch.legend = PL_LEGEND_BOTTOM_LEFT;
    rc = pl_draw(&img, 0, 0, 1000, 450, &ch, ser[0], 6, ctx->msg, sizeof ctx->msg);
    if (rc == 0) {
        ch.title = "light from behind only (the transmitted rays: even depths)";
        rc = pl_draw(&img, 0, 450, 1000, 450, &ch, ser[1], 6, ctx->msg, sizeof ctx->msg);
    }
    if (rc == 0)
        rc = ex_save_png(ctx, "shares.png", &img);
    rs_image_free(&img);
    if (rc != 0)
        return rc;

    fprintf(ctx->md,
            "## 2. Shares of the outgoing intensity by depth\n\n"
            "Backward tracing (`lp_bundle_by_depth`): view rays from the point on the axis "
            "two diameters in front (z = −50 mm), their directions spread evenly in solid "
            "angle over K at dT = %d (%d azimuths × %d rings, cos θ uniform below θ_K); every "
            "query ray of the tree answered by natural light of unit intensity (two "
            "incoherent orthogonal linear halves); the gathered bundle rays summed by "
            "their depth, as a share of the whole.  λ = %.2f nm, catalog glass with its "
            "absorption.  *All*: light from every side (depth 1 is the external "
            "reflection, odd depths leave towards the eye from the front after internal "
            "reflections); *behind*: light from behind the lens only (the transmitted rays, "
            "even depths).\n\n"
            "| lens | glass | θ_K (°) | light | d=1 | d=2 | d=3 | d=4 | d=5 | d=6 | d=7 | d=8 | "
            "depth ≥ 3 |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
            DT, N_AZ, N_RING, LAMBDA);
    for (int s = 0; s < 3; s++)
        for (int g = 0; g < 2; g++)
            for (int l = 0; l < 2; l++) {
                double deep = 0;
                fprintf(ctx->md, "| %s | %s | %.3f | %s |", shapes[s].name, glasses[g],
                        theta_k[s][g] * 180 / PI, l ? "behind" : "all");
                for (int m = 1; m <= DT; m++) {
                    if (m >= 3)
                        deep += sh[s][g][l][m];
                    if (sh[s][g][l][m] == 0)
                        fprintf(ctx->md, " 0 |");
                    else
                        fprintf(ctx->md, " %.3g |", sh[s][g][l][m]);
                }
                fprintf(ctx->md, " **%.3g %%** |\n", 100 * deep);
            }
    /* one view ray near the edge of K of the N-SF11 biconvex lens */
    double by13[DT + 1] = {0}, t13 = 0;
    {
        lp_lens *lens = ex_make_lens(ctx, shapes[0].r1, shapes[0].r2, shapes[0].t, shapes[0].d,
                                     0, "N-SF11");
        lp_trace_args ta;
        lp_error err;
        lp_trace_args_init(&ta);
        ta.max_depth = DT;
        if (!lens || lp_bundle_by_depth(lens, (lp_vec3){0, 0, -2 * shapes[0].d},
                                        (lp_vec3){sin(13 * PI / 180), 0, cos(13 * PI / 180)},
                                        LAMBDA, &ta, by13, &err) != LP_OK) {
            if (lens)
                snprintf(ctx->msg, sizeof ctx->msg, "shares: %s", err.message);
            lp_lens_destroy(lens);
            return -1;
        }
        lp_lens_destroy(lens);
        for (int m = 1; m <= DT; m++)
            t13 += by13[m];
    }
    /* the plate at normal incidence in closed form, for scale */
    fprintf(ctx->md, "\nFor scale, the flat plate at normal incidence in closed form: "
                     "R = ((n−1)/(n+1))², the transmitted series (1−R)² R^(2k) "
                     "normalised gives a depth ≥ 3 (that is, ≥ 4) share of");
    for (int g = 0; g < 2; g++) {
        lp_glass gl;
        lp_glass_builtin(glasses[g], &gl, NULL);
        double n = lp_glass_index(&gl, LAMBDA), R = (n - 1) / (n + 1);
        R *= R;
        double tot = 0, deep = 0;
        for (int k = 0; 2 + 2 * k <= DT; k++) {
            double v = (1 - R) * (1 - R) * pow(R, 2 * k);
            tot += v;
            if (k > 0)
                deep += v;
        }
        fprintf(ctx->md, "%s %.4g %% (%s, n = %.5f, R = %.5f)", g ? " and" : "",
                100 * deep / tot, glasses[g], n, R);
    }
    fprintf(ctx->md,
            " — the tests check `lp_bundle_by_depth` against that series, and against its "
            "oblique s/p form, to 1e-13.  Over the cone the plate's shares stay close to it "
            "(the table): the oblique rays of K change R little.  The curved lenses follow "
            "the same geometric fall (about R² per two depths) except where total internal "
            "reflection takes over: in the biconvex lens (critical angle 41° in N-BK7, 34° "
            "in N-SF11) the chains near the edge of K are totally reflected at their third to fifth nodes "
            "(no ray leaves there) and reach depth 6 without loss, so in N-SF11 depth 6 "
            "carries more than depth 4 (its view ray at θ = 13°: depths 3, 4, 5 carry %.3g, %.3g, %.3g of "
            "the light, depth 6 %.3g).  The approximation that deep rays do "
            "not matter is a statement about R, and fails where TIR holds light inside.\n\n"
            "![shares by depth](%s/shares.png)\n\n",
            by13[3] / t13, by13[4] / t13, by13[5] / t13, by13[6] / t13, ctx->fig_rel);
    return 0;
}
