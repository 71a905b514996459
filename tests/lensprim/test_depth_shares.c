/* test_depth_shares.c -- the light a view ray gathers, by depth.
 *
 * A flat plate keeps the plane of incidence and the angles at every node,
 * so with R the reflectance of one face (Fresnel, written here) for s and
 * for p light, natural light of unit intensity answering every query
 * gives, per polarization x in {s, p} and averaged over the two:
 *   depth 1          R_x                      (the external reflection)
 *   depth k >= 2     (1 - R_x)^2 R_x^(k - 2)  (k - 1 internal segments)
 * and, light from behind only (LP_SKIP_REFLECTED), the transmitted series
 * (1 - R_x)^2 R_x^(2j) at depth 2 + 2j.  The shares are these normalised
 * by their sum up to dT.  Checked at normal incidence (Rs = Rp: the
 * issue's series (1 - R)^2 R^(2k) normalised) and at 30 and 69 degrees,
 * for n_d of N-BK7 and N-SF11, dT = 1..8; a view ray that misses adds
 * nothing; bad input is refused. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "lensprim.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static void fresnel_R(double n, double a, double *Rs, double *Rp)
{
    double ci = cos(a), st = sin(a) / n, ct = sqrt(1 - st * st);
    double rs = (ci - n * ct) / (ci + n * ct);
    double rp = (n * ci - ct) / (n * ci + ct);
    *Rs = rs * rs;
    *Rp = rp * rp;
}

/* the closed form for one polarization */
static double want_at(double R, int k, int transmit_only)
{
    if (k == 1)
        return transmit_only ? 0.0 : R;
    if (transmit_only && k % 2 == 1)
        return 0.0;
    return (1 - R) * (1 - R) * pow(R, k - 2);
}

int main(void)
{
    const double glasses[2] = {1.5168, 1.78472};
    const double angles[3] = {0.0, M_PI / 6, 1.2};
    double worst_i = 0, worst_share = 0;
    for (int g = 0; g < 2; g++) {
        lp_lens_desc d;
        lp_lens_desc_init(&d);
        d.radius1 = 0;
        d.radius2 = 0;
        d.thickness = 2;
        d.diameter = 2000; /* wide enough that no chain of dT <= 8 meets the rim */
        lp_glass_init_constant(&d.glass, glasses[g]);
        lp_lens *lens = NULL;
        lp_error err;
        CHECK(lp_lens_create(&d, &lens, &err) == LP_OK, "plate: %s", err.message);
        if (!lens)
            continue;
        for (int ai = 0; ai < 3; ai++) {
            double a = angles[ai], Rs, Rp;
            fresnel_R(glasses[g], a, &Rs, &Rp);
            lp_vec3 o = {-10 * sin(a), 0, -10 * cos(a)}, dir = {sin(a), 0, cos(a)};
            for (int t_only = 0; t_only < 2; t_only++) {
                for (int depth = 1; depth <= 8; depth++) {
                    lp_trace_args ta;
                    lp_trace_args_init(&ta);
                    ta.max_depth = depth;
                    ta.flags = t_only ? LP_SKIP_REFLECTED : 0;
                    double by[LP_MAX_DEPTH + 1] = {0}, want[LP_MAX_DEPTH + 1] = {0};
                    by[0] = -7; /* must stay untouched */
                    lp_status st = lp_bundle_by_depth(lens, o, dir, 587.56, &ta, by, &err);
                    CHECK(st == LP_OK, "lp_bundle_by_depth: %s", err.message);
                    double sum = 0, wsum = 0;
                    for (int k = 1; k <= depth; k++) {
                        want[k] = 0.5 * (want_at(Rs, k, t_only) + want_at(Rp, k, t_only));
                        sum += by[k];
                        wsum += want[k];
                    }
                    CHECK(by[0] == -7, "by_depth[0] untouched");
                    for (int k = 1; k <= depth; k++) {
                        /* measured: 1.1e-15 absolute (rounding of the
                         * Fresnel products) */
                        CHECK_ABS(by[k], want[k], 1e-13, "n=%g a=%g %s dT=%d depth %d intensity",
                                  glasses[g], a, t_only ? "transmit" : "all", depth, k);
                        worst_i = fmax(worst_i, fabs(by[k] - want[k]));
                        if (wsum > 0) {
                            double share = by[k] / sum, wshare = want[k] / wsum;
                            /* measured: 4.4e-16 absolute */
                            CHECK_ABS(share, wshare, 1e-13, "n=%g a=%g dT=%d depth %d share",
                                      glasses[g], a, depth, k);
                            worst_share = fmax(worst_share, fabs(share - wshare));
                        }
                    }
                    if (ai == 0 && t_only && depth == 8)
                        printf("normal incidence n=%g, light from behind, dT=8: shares "
                               "%.6f %.6f %.3g %.3g (depths 2 4 6 8)\n",
                               glasses[g], by[2] / sum, by[4] / sum, by[6] / sum, by[8] / sum);
                }
            }
        }
        /* a view ray that misses adds nothing */
        double by[LP_MAX_DEPTH + 1] = {0};
        lp_vec3 o = {5000, 0, -10}, dir = {0, 0, 1};
        CHECK(lp_bundle_by_depth(lens, o, dir, 587.56, NULL, by, &err) == LP_OK,
              "missing ray: %s", err.message);
        int zero = 1;
        for (int k = 0; k <= LP_MAX_DEPTH; k++)
            zero &= by[k] == 0;
        CHECK(zero, "a view ray that misses adds nothing");
        CHECK(lp_bundle_by_depth(lens, o, dir, -1, NULL, by, &err) == LP_ERROR_INVALID_ARGUMENT,
              "a negative wavelength is refused");
        CHECK(lp_bundle_by_depth(lens, o, dir, 587.56, NULL, NULL, &err) ==
                  LP_ERROR_INVALID_ARGUMENT,
              "NULL by_depth is refused");
        lp_lens_destroy(lens);
    }
    printf("worst |I - closed form| %.3g, |share - closed form| %.3g\n", worst_i, worst_share);
    return check_finish("test_depth_shares");
}
