/* work_cost_fit.c -- fit the automatic mode's cost model (rs_work_cost)
 * to counted instructions.
 *
 * Reads lines from stdin (bench/work_cost_fit.sh writes them), one per
 * render:
 *     SCENE MODE INSTRUCTIONS pixels rays lane_rays builds gathered cost
 * (SCENE a name, MODE polarized, fresnel, schlick or rgb; INSTRUCTIONS callgrind's count
 * of the render's pixels; the counters and cost as bench_render_work
 * prints them, cost the model now in the tree).  For each mode it fits
 *     INSTRUCTIONS ~ a rays + b lane_rays + c builds + d gathered + e pixels
 * with a..e >= 0 by least squares of the relative error (predicted / count
 * - 1; auto compares costs by their ratios), a counter that is zero in
 * every render of the mode left out, and prints the constants, the range
 * of predicted / count and the RMS of the relative error, the same for
 * the model in the tree, and the fitted rs_work_cost body ready to paste.
 * Auto compares the costs of one scene's settings only, so it also prints
 * each scene's factor (the geometric mean of predicted / count over its
 * renders in every mode: what the counters miss of that scene, e.g. its
 * intersections' or its lens builds' cost) and the range and RMS of
 * predicted / count divided by that factor: how well the model ranks one
 * scene's settings.
 * Non-negative least squares of at most 5 unknowns: every subset of the
 * unknowns is solved unconstrained and the best solution with no negative
 * coefficient kept (the optimum is the unconstrained solution on its own
 * support, so this is exact).  Exit status 0, 2 bad input. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NMODES 4
#define NTERMS 5 /* rays, lane_rays, builds, gathered, pixels */
#define MAX_ROWS 100000
#define MAX_SCENES 256

static const char *const mode_names[NMODES] = {"polarized", "fresnel", "schlick", "rgb"};
static const char *const mode_enums[NMODES] = {"RS_MODE_POLARIZED", "RS_MODE_FRESNEL",
                                               "RS_MODE_SCHLICK", "RS_MODE_RGB"};
static const char *const term_names[NTERMS] = {"rays", "lane_rays", "builds", "gathered",
                                               "pixels"};
static const char *const term_exprs[NTERMS] = {"w->rays", "w->lane_rays", "w->builds",
                                               "w->gathered", "pixels"};

typedef struct row {
    int mode, scene;
    double y;          /* instructions */
    double x[NTERMS];  /* the counters */
    double cost;       /* the tree's model */
} row;

/* Solve the n x n system A z = b (A symmetric positive definite, row
 * major, overwritten) by Gaussian elimination with partial pivoting;
 * -1 when singular. */
static int solve(double *A, double *b, int n, double *z)
{
    for (int c = 0; c < n; c++) {
        int p = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(A[r * n + c]) > fabs(A[p * n + c]))
                p = r;
        if (fabs(A[p * n + c]) < 1e-12)
            return -1;
        if (p != c) {
            for (int k = 0; k < n; k++) {
                double t = A[c * n + k];
                A[c * n + k] = A[p * n + k];
                A[p * n + k] = t;
            }
            double t = b[c];
            b[c] = b[p];
            b[p] = t;
        }
        for (int r = c + 1; r < n; r++) {
            double f = A[r * n + c] / A[c * n + c];
            for (int k = c; k < n; k++)
                A[r * n + k] -= f * A[c * n + k];
            b[r] -= f * b[c];
        }
    }
    for (int c = n - 1; c >= 0; c--) {
        double s = b[c];
        for (int k = c + 1; k < n; k++)
            s -= A[c * n + k] * z[k];
        z[c] = s / A[c * n + c];
    }
    return 0;
}

/* Sum of squared relative errors of coefficients a on the mode's rows. */
static double sse(const row *rows, size_t n, int mode, const double *a)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++) {
        if (rows[i].mode != mode)
            continue;
        double p = 0.0;
        for (int t = 0; t < NTERMS; t++)
            p += a[t] * rows[i].x[t];
        s += (p / rows[i].y - 1.0) * (p / rows[i].y - 1.0);
    }
    return s;
}

/* Non-negative least squares of the relative error for one mode, over
 * the terms in `allowed` (a bit mask); a[] gets the coefficients. */
static void fit(const row *rows, size_t n, int mode, unsigned allowed, double *a)
{
    double scale[NTERMS] = {0};
    double best = INFINITY;
    /* columns x_t / y, scaled to unit norm for the solve */
    for (size_t i = 0; i < n; i++)
        if (rows[i].mode == mode)
            for (int t = 0; t < NTERMS; t++)
                scale[t] += (rows[i].x[t] / rows[i].y) * (rows[i].x[t] / rows[i].y);
    for (int t = 0; t < NTERMS; t++)
        scale[t] = scale[t] > 0.0 ? sqrt(scale[t]) : 1.0;
    memset(a, 0, sizeof(double) * NTERMS);
    for (unsigned set = 1; set < (1u << NTERMS); set++) {
        int idx[NTERMS], m = 0;
        double A[NTERMS * NTERMS] = {0}, b[NTERMS] = {0}, z[NTERMS], c[NTERMS] = {0};
        if (set & ~allowed)
            continue;
        for (int t = 0; t < NTERMS; t++)
            if (set & (1u << t))
                idx[m++] = t;
        for (size_t i = 0; i < n; i++) {
            if (rows[i].mode != mode)
                continue;
            for (int p = 0; p < m; p++) {
                double up = rows[i].x[idx[p]] / rows[i].y / scale[idx[p]];
                b[p] += up;
                for (int q = 0; q < m; q++)
                    A[p * m + q] += up * rows[i].x[idx[q]] / rows[i].y / scale[idx[q]];
            }
        }
        if (solve(A, b, m, z) != 0)
            continue;
        int ok = 1;
        for (int p = 0; p < m; p++) {
            if (z[p] < 0.0)
                ok = 0;
            c[idx[p]] = z[p] / scale[idx[p]];
        }
        if (!ok)
            continue;
        double s = sse(rows, n, mode, c);
        if (s < best) {
            best = s;
            memcpy(a, c, sizeof c);
        }
    }
}

/* The range of predicted / count and the RMS of predicted / count - 1:
 * from coefficients a, or (a NULL) from the rows' cost. */
static void stats(const row *rows, size_t n, int mode, const double *a, double *lo, double *hi,
                  double *rms)
{
    double s = 0.0;
    size_t k = 0;
    *lo = INFINITY;
    *hi = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        if (rows[i].mode != mode)
            continue;
        double p = 0.0;
        if (a)
            for (int t = 0; t < NTERMS; t++)
                p += a[t] * rows[i].x[t];
        else
            p = rows[i].cost;
        double r = p / rows[i].y;
        *lo = r < *lo ? r : *lo;
        *hi = r > *hi ? r : *hi;
        s += (r - 1.0) * (r - 1.0);
        k++;
    }
    *rms = k ? sqrt(s / (double)k) : 0.0;
}

static double predict(const row *r, const double (*a)[NTERMS])
{
    double p = 0.0;
    if (!a)
        return r->cost;
    for (int t = 0; t < NTERMS; t++)
        p += a[r->mode][t] * r->x[t];
    return p;
}

/* Each scene's factor (the geometric mean of predicted / count over its
 * renders) into f[], and the range and RMS of predicted / count / factor
 * over every render: coefficients a per mode, or (a NULL) the rows'
 * cost. */
static void within(const row *rows, size_t n, int nscenes, const double (*a)[NTERMS], double *f,
                   double *lo, double *hi, double *rms)
{
    double lg[MAX_SCENES] = {0}, s = 0.0;
    size_t cnt[MAX_SCENES] = {0};
    for (size_t i = 0; i < n; i++) {
        lg[rows[i].scene] += log(predict(&rows[i], a) / rows[i].y);
        cnt[rows[i].scene]++;
    }
    for (int k = 0; k < nscenes; k++)
        f[k] = cnt[k] ? exp(lg[k] / (double)cnt[k]) : 1.0;
    *lo = INFINITY;
    *hi = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        double r = predict(&rows[i], a) / rows[i].y / f[rows[i].scene];
        *lo = r < *lo ? r : *lo;
        *hi = r > *hi ? r : *hi;
        s += (r - 1.0) * (r - 1.0);
    }
    *rms = n ? sqrt(s / (double)n) : 0.0;
}

int main(void)
{
    static char scenes[MAX_SCENES][64];
    int nscenes = 0;
    char scene[64];
    double fa[MAX_SCENES], ft[MAX_SCENES];
    row *rows = malloc(sizeof *rows * MAX_ROWS);
    size_t n = 0, count[NMODES] = {0};
    double a[NMODES][NTERMS] = {{0}};
    double lo, hi, rms, all_lo = INFINITY, all_hi = -INFINITY, all_s = 0.0;
    double cur_lo = INFINITY, cur_hi = -INFINITY, cur_s = 0.0;
    char mode[32];

    if (!rows)
        return 2;
    while (n < MAX_ROWS) {
        row *r = &rows[n];
        int got = scanf("%63s %31s %lf %lf %lf %lf %lf %lf %lf", scene, mode, &r->y, &r->x[4],
                        &r->x[0], &r->x[1], &r->x[2], &r->x[3], &r->cost);
        if (got == EOF)
            break;
        if (got != 9 || !(r->y > 0.0) || !(r->cost > 0.0)) {
            fprintf(stderr, "work_cost_fit: line %zu: expected SCENE MODE INSTRUCTIONS pixels "
                            "rays lane_rays builds gathered cost, INSTRUCTIONS and cost > 0\n",
                    n + 1);
            free(rows);
            return 2;
        }
        r->mode = -1;
        for (int m = 0; m < NMODES; m++)
            if (strcmp(mode, mode_names[m]) == 0)
                r->mode = m;
        if (r->mode < 0) {
            fprintf(stderr, "work_cost_fit: line %zu: unknown mode '%s'\n", n + 1, mode);
            free(rows);
            return 2;
        }
        r->scene = -1;
        for (int k = 0; k < nscenes; k++)
            if (strcmp(scene, scenes[k]) == 0)
                r->scene = k;
        if (r->scene < 0) {
            if (nscenes == MAX_SCENES) {
                fprintf(stderr, "work_cost_fit: more than %d scenes\n", MAX_SCENES);
                free(rows);
                return 2;
            }
            strcpy(scenes[nscenes], scene);
            r->scene = nscenes++;
        }
        count[r->mode]++;
        n++;
    }

    printf("%-10s %5s %9s %9s %9s %9s %9s  %-11s %6s  %-11s %6s\n", "mode", "runs",
           term_names[0], term_names[1], term_names[2], term_names[3], term_names[4],
           "fit ratio", "RMS", "tree ratio", "RMS");
    for (int m = 0; m < NMODES; m++) {
        unsigned allowed = 0;
        double tlo, thi, trms;
        if (!count[m])
            continue;
        for (int t = 0; t < NTERMS; t++)
            for (size_t i = 0; i < n; i++)
                if (rows[i].mode == m && rows[i].x[t] != 0.0)
                    allowed |= 1u << t;
        fit(rows, n, m, allowed, a[m]);
        for (int t = 0; t < NTERMS; t++) /* as printed */
            a[m][t] = round(a[m][t] * 10.0) / 10.0;
        stats(rows, n, m, a[m], &lo, &hi, &rms);
        stats(rows, n, m, NULL, &tlo, &thi, &trms);
        printf("%-10s %5zu %9.1f %9.1f %9.1f %9.1f %9.1f  %.2f-%.2f %5.1f %%  %.2f-%.2f %5.1f %%\n",
               mode_names[m], count[m], a[m][0], a[m][1], a[m][2], a[m][3], a[m][4], lo, hi,
               100.0 * rms, tlo, thi, 100.0 * trms);
        all_lo = lo < all_lo ? lo : all_lo;
        all_hi = hi > all_hi ? hi : all_hi;
        all_s += rms * rms * (double)count[m];
        cur_lo = tlo < cur_lo ? tlo : cur_lo;
        cur_hi = thi > cur_hi ? thi : cur_hi;
        cur_s += trms * trms * (double)count[m];
    }
    printf("all        %5zu %49s  %.2f-%.2f %5.1f %%  %.2f-%.2f %5.1f %%\n", n, "", all_lo,
           all_hi, n ? 100.0 * sqrt(all_s / (double)n) : 0.0, cur_lo, cur_hi,
           n ? 100.0 * sqrt(cur_s / (double)n) : 0.0);

    within(rows, n, nscenes, (const double(*)[NTERMS])a, fa, &lo, &hi, &rms);
    within(rows, n, nscenes, NULL, ft, &all_lo, &all_hi, &all_s);
    printf("within a scene%52s  %.2f-%.2f %5.1f %%  %.2f-%.2f %5.1f %%\n", "", lo, hi,
           100.0 * rms, all_lo, all_hi, 100.0 * all_s);
    printf("\nscene factors, fit (tree):");
    for (int k = 0; k < nscenes; k++)
        printf("%s %s %.2f (%.2f)", k ? "," : "", scenes[k], fa[k], ft[k]);

    printf("\n\nrs_work_cost's body, fitted:\n    switch (mode) {\n");
    for (int m = 0; m < NMODES; m++) {
        int first = 1;
        if (!count[m])
            continue;
        printf("    case %s:\n        return", mode_enums[m]);
        for (int t = 0; t < NTERMS; t++) {
            if (a[m][t] == 0.0)
                continue;
            printf("%s%.1f * %s", first ? " " : " + ", a[m][t], term_exprs[t]);
            first = 0;
        }
        printf("%s;\n", first ? " 0.0" : "");
    }
    printf("    }\n    return 0.0;\n");
    free(rows);
    return 0;
}
