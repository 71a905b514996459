/* quadrature.c -- the spectral quadrature: N cells that keep out of
 * Smits' steps (see quadrature.h). */
#include <math.h>

#include "quadrature.h"
#include "support/colorimetry.h"

#define MAX_PIECES RS_QUADRATURE_MAX_PIECES

int rs_quadrature_pieces(double edge[RS_QUADRATURE_MAX_PIECES + 1])
{
    int p = 0;
    edge[p++] = RS_LAMBDA_MIN;
    for (int k = 1; k < RS_SMITS_BINS; k++) {
        double e = RS_SMITS_FIRST_NM + k * RS_SMITS_BIN_NM;
        if (e > RS_LAMBDA_MIN && e < RS_LAMBDA_MAX)
            edge[p++] = e;
    }
    edge[p] = RS_LAMBDA_MAX;
    return p;
}

/* The total variation over [a, b] of the derivative of D65 times each
 * linear sRGB channel's colour-matching function, summed over the
 * channels: the midpoint rule's error on a cell of width h inside [a, b]
 * is at most h^2 / 8 times this for D65 light (divided differences over
 * 0.25 nm from a whole nm: the tables' kinks are at whole nm). */
static double slope_variation(double a, double b)
{
    const double h = 0.25;
    double tv = 0.0, prev[3] = {0, 0, 0}, f0[3], f1[3];
    rs_color c;
    for (double l = a; l + h <= b + 1e-9; l += h) {
        rs_cmf(l, f0);
        rs_xyz_to_linear_srgb(f0, &c);
        f0[0] = rs_d65(l) * c.r, f0[1] = rs_d65(l) * c.g, f0[2] = rs_d65(l) * c.b;
        rs_cmf(l + h, f1);
        rs_xyz_to_linear_srgb(f1, &c);
        f1[0] = rs_d65(l + h) * c.r, f1[1] = rs_d65(l + h) * c.g, f1[2] = rs_d65(l + h) * c.b;
        for (int k = 0; k < 3; k++) {
            double d = (f1[k] - f0[k]) / h;
            if (l > a)
                tv += fabs(d - prev[k]);
            prev[k] = d;
        }
    }
    return tv;
}

/* N >= pieces: the count of cells of each piece (see quadrature.h). */
static void counts(const double *edge, const double *tv, int np, int n, int *count)
{
    for (int i = 0; i < np; i++)
        count[i] = 1;
    for (int left = n - np; left > 0; left--) {
        int best = 0;
        double gain_best = -1.0;
        for (int i = 0; i < np; i++) {
            double w = edge[i + 1] - edge[i], c = count[i];
            double gain = w * w * tv[i] * (1.0 / (c * c) - 1.0 / ((c + 1) * (c + 1)));
            if (gain > gain_best) {
                gain_best = gain;
                best = i;
            }
        }
        count[best]++;
    }
}

void rs_quadrature(int n, double *lambda, double *weight)
{
    double edge[MAX_PIECES + 1], tv[MAX_PIECES];
    int np = rs_quadrature_pieces(edge), count[MAX_PIECES], m = 0;
    if (n < np) {
        for (int k = 0; k < n; k++) {
            weight[k] = (RS_LAMBDA_MAX - RS_LAMBDA_MIN) / n;
            lambda[k] = RS_LAMBDA_MIN + weight[k] * (k + 0.5);
        }
        return;
    }
    for (int i = 0; i < np; i++)
        tv[i] = slope_variation(edge[i], edge[i + 1]);
    counts(edge, tv, np, n, count);
    for (int i = 0; i < np; i++) {
        double w = (edge[i + 1] - edge[i]) / count[i];
        for (int k = 0; k < count[i]; k++, m++) {
            lambda[m] = edge[i] + w * (k + 0.5);
            weight[m] = w;
        }
    }
}
