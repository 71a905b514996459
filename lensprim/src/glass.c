/* glass.c -- a glass as plain data: its refractive index by a dispersion
 * formula, its absorption by an internal transmittance table, and the
 * check that a description can be used.
 *
 * Dispersion formulas take lambda in micrometres (as glass makers publish
 * their coefficients); the API takes nanometres.  The transmittance table
 * gives tau(lambda) of a sample of thickness d_ref; the absorption
 * coefficient is alpha = -ln(tau) / d_ref (Beer-Lambert), interpolated
 * linearly in ln(tau), i.e. linearly in alpha, between table wavelengths
 * and held constant past the table's ends. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "error.h"
#include "glass_internal.h"

/* The visible window checked when a glass has no data range. */
#define CHECK_LO_NM 380.0
#define CHECK_HI_NM 780.0
#define CHECK_STEP_NM 5.0
#define CHECK_MAX_SAMPLES 10000 /* a range wider than 50 um is sampled
                                   more coarsely */
#define MIN_INDEX 1e-3

/* n^2 = 1 + sum B_k l^2 / (l^2 - C_k), coef = B1 B2 B3 C1 C2 C3. */
static double sellmeier(const double *c, double l)
{
    /* B l^2/(l^2 - C) written as B/(1 - C/l^2): no overflow of l^2 at
     * absurdly long wavelengths, where n tends to sqrt(1 + B1 + B2 + B3) */
    double m2 = 1.0 / (l * l);
    double n2 = 1.0 + c[0] / (1.0 - c[3] * m2) + c[1] / (1.0 - c[4] * m2)
              + c[2] / (1.0 - c[5] * m2);
    return sqrt(n2); /* NaN between resonances, where n2 < 0 */
}

/* n^2 = a0 + a1 l^2 + a2 l^-2 + a3 l^-4 + a4 l^-6 + a5 l^-8. */
static double schott(const double *a, double l)
{
    double l2 = l * l, m2 = 1.0 / l2;
    double n2 = a[0] + a[1] * l2
              + m2 * (a[2] + m2 * (a[3] + m2 * (a[4] + m2 * a[5])));
    return sqrt(n2);
}

/* n = A + B / l^2 + C / l^4. */
static double cauchy(const double *c, double l)
{
    double m2 = 1.0 / (l * l);
    return c[0] + m2 * (c[1] + m2 * c[2]);
}

/* n = n0 + A / l + B / l^3.5. */
static double conrady(const double *c, double l)
{
    return c[0] + c[1] / l + c[2] / (l * l * l * sqrt(l));
}

double lp_glass_index(const lp_glass *glass, double lambda_nm)
{
    double l;
    if (!glass || !(lambda_nm > 0.0) || !isfinite(lambda_nm))
        return NAN;
    l = lambda_nm * 1e-3;
    switch (glass->formula) {
    case LP_FORMULA_CONSTANT: return glass->coef[0];
    case LP_FORMULA_SELLMEIER: return sellmeier(glass->coef, l);
    case LP_FORMULA_SCHOTT: return schott(glass->coef, l);
    case LP_FORMULA_CAUCHY: return cauchy(glass->coef, l);
    case LP_FORMULA_CONRADY: return conrady(glass->coef, l);
    case LP_FORMULA_UNSUPPORTED: break;
    }
    return NAN;
}

/* log(tau[i]): from the table of logarithms when there is one. */
static double ln_tau_at(const lp_glass *glass, const double *ln_tau, int i)
{
    return ln_tau ? ln_tau[i] : log(glass->tau[i]);
}

double lp__glass_absorption_ln(const lp_glass *glass, const double *ln_tau_table,
                               double lambda_nm)
{
    const double *x;
    double t, ln_tau;
    int n, lo, hi;

    if (!glass || isnan(lambda_nm))
        return NAN;
    n = glass->n_tau;
    if (n <= 0)
        return 0.0;
    if (n > LP_GLASS_TABLE_MAX || !(glass->tau_thickness_mm > 0.0))
        return NAN; /* not a usable table; lp_glass_check says why */
    x = glass->tau_lambda_nm;

    if (lambda_nm <= x[0]) {
        ln_tau = ln_tau_at(glass, ln_tau_table, 0);
    } else if (lambda_nm >= x[n - 1]) {
        ln_tau = ln_tau_at(glass, ln_tau_table, n - 1);
    } else {
        /* x[lo] < lambda_nm < x[hi], hi == lo + 1 */
        lo = 0;
        hi = n - 1;
        while (hi - lo > 1) {
            int mid = lo + (hi - lo) / 2;
            if (x[mid] <= lambda_nm)
                lo = mid;
            else
                hi = mid;
        }
        t = (lambda_nm - x[lo]) / (x[hi] - x[lo]);
        ln_tau = (1.0 - t) * ln_tau_at(glass, ln_tau_table, lo) +
                 t * ln_tau_at(glass, ln_tau_table, hi);
    }
    return -ln_tau / glass->tau_thickness_mm;
}

void lp__glass_ln_tau(const lp_glass *glass, double ln_tau[LP_GLASS_TABLE_MAX])
{
    int n = glass->n_tau < LP_GLASS_TABLE_MAX ? glass->n_tau : LP_GLASS_TABLE_MAX;
    for (int i = 0; i < LP_GLASS_TABLE_MAX; i++)
        ln_tau[i] = i < n ? log(glass->tau[i]) : 0.0;
}

double lp_glass_absorption(const lp_glass *glass, double lambda_nm)
{
    return lp__glass_absorption_ln(glass, NULL, lambda_nm);
}

int lp_glass_covers(const lp_glass *glass, double lambda_nm)
{
    if (!glass || isnan(lambda_nm))
        return 0;
    if (glass->lambda_min_nm > 0.0 && lambda_nm < glass->lambda_min_nm)
        return 0;
    if (glass->lambda_max_nm > 0.0 && lambda_nm > glass->lambda_max_nm)
        return 0;
    return 1;
}

void lp_glass_init_constant(lp_glass *glass, double n)
{
    if (!glass)
        return;
    memset(glass, 0, sizeof *glass);
    snprintf(glass->name, sizeof glass->name, "n=%.15g", n);
    glass->formula = LP_FORMULA_CONSTANT;
    glass->coef[0] = n;
}

void lp_glass_init_sellmeier(lp_glass *glass, const char *name,
                             const double b[3], const double c[3])
{
    int k;
    if (!glass)
        return;
    memset(glass, 0, sizeof *glass);
    snprintf(glass->name, sizeof glass->name, "%s", name ? name : "sellmeier");
    glass->formula = LP_FORMULA_SELLMEIER;
    for (k = 0; k < 3; k++) {
        /* missing coefficients are NaN, so that lp_glass_check refuses them */
        glass->coef[k] = b ? b[k] : NAN;
        glass->coef[3 + k] = c ? c[k] : NAN;
    }
    glass->lambda_min_nm = CHECK_LO_NM;
    glass->lambda_max_nm = CHECK_HI_NM;
}

/* The formula's name, for messages. */
static const char *formula_name(lp_formula f)
{
    switch (f) {
    case LP_FORMULA_CONSTANT: return "constant";
    case LP_FORMULA_SELLMEIER: return "Sellmeier";
    case LP_FORMULA_SCHOTT: return "Schott";
    case LP_FORMULA_CAUCHY: return "Cauchy";
    case LP_FORMULA_CONRADY: return "Conrady";
    case LP_FORMULA_UNSUPPORTED: break;
    }
    return "unsupported";
}

static lp_status check_formula(const lp_glass *g, lp_error *err)
{
    int k;
    switch (g->formula) {
    case LP_FORMULA_CONSTANT:
    case LP_FORMULA_SELLMEIER:
    case LP_FORMULA_SCHOTT:
    case LP_FORMULA_CAUCHY:
    case LP_FORMULA_CONRADY:
        break;
    case LP_FORMULA_UNSUPPORTED:
        return lp__fail(err, LP_ERROR_UNSUPPORTED,
                        "glass \"%s\": AGF dispersion formula %d is not supported",
                        g->name, g->agf_formula);
    default:
        return lp__fail(err, LP_ERROR_INVALID_GLASS,
                        "glass \"%s\": unknown dispersion formula code %d",
                        g->name, (int)g->formula);
    }
    for (k = 0; k < 10; k++)
        if (!isfinite(g->coef[k]))
            return lp__fail(err, LP_ERROR_INVALID_GLASS,
                            "glass \"%s\": coefficient %d is not finite",
                            g->name, k);
    return LP_OK;
}

static lp_status check_range(const lp_glass *g, lp_error *err)
{
    double lo = g->lambda_min_nm, hi = g->lambda_max_nm;
    if (!isfinite(lo) || !isfinite(hi) || lo < 0.0 || hi < 0.0)
        return lp__fail(err, LP_ERROR_INVALID_GLASS,
                        "glass \"%s\": data range %g..%g nm is not two finite "
                        "wavelengths >= 0", g->name, lo, hi);
    if (lo > 0.0 && hi > 0.0 && !(lo < hi))
        return lp__fail(err, LP_ERROR_INVALID_GLASS,
                        "glass \"%s\": data range %g..%g nm is empty",
                        g->name, lo, hi);
    return LP_OK;
}

/* n must be finite and >= MIN_INDEX over the data range (the visible
 * window on a side the range leaves open), sampled every CHECK_STEP_NM
 * nanometres (at most CHECK_MAX_SAMPLES evenly spaced wavelengths) and at
 * both ends. */
static lp_status check_index(const lp_glass *g, lp_error *err)
{
    double lo = g->lambda_min_nm > 0.0 ? g->lambda_min_nm : CHECK_LO_NM;
    double hi = g->lambda_max_nm > 0.0 ? g->lambda_max_nm : CHECK_HI_NM;
    double step = CHECK_STEP_NM;
    long i, steps;
    if (hi < lo)
        hi = lo;
    if ((hi - lo) / step > CHECK_MAX_SAMPLES)
        step = (hi - lo) / CHECK_MAX_SAMPLES;
    steps = (long)ceil((hi - lo) / step);
    for (i = 0; i <= steps; i++) {
        double l = i == steps ? hi : lo + step * (double)i;
        double n = lp_glass_index(g, l);
        if (!isfinite(n) || n < MIN_INDEX)
            return lp__fail(err, LP_ERROR_INVALID_GLASS,
                            "glass \"%s\": %s index is %g at %g nm "
                            "(must be finite and >= %g)",
                            g->name, formula_name(g->formula), n, l, MIN_INDEX);
    }
    return LP_OK;
}

static lp_status check_table(const lp_glass *g, lp_error *err)
{
    int i;
    if (g->n_tau == 0)
        return LP_OK;
    if (g->n_tau < 0 || g->n_tau > LP_GLASS_TABLE_MAX)
        return lp__fail(err, LP_ERROR_INVALID_GLASS,
                        "glass \"%s\": transmittance table size %d is not in "
                        "0..%d", g->name, g->n_tau, LP_GLASS_TABLE_MAX);
    if (!(g->tau_thickness_mm > 0.0) || !isfinite(g->tau_thickness_mm))
        return lp__fail(err, LP_ERROR_INVALID_GLASS,
                        "glass \"%s\": transmittance reference thickness %g mm "
                        "is not > 0", g->name, g->tau_thickness_mm);
    for (i = 0; i < g->n_tau; i++) {
        double l = g->tau_lambda_nm[i], t = g->tau[i];
        if (!(l > 0.0) || !isfinite(l))
            return lp__fail(err, LP_ERROR_INVALID_GLASS,
                            "glass \"%s\": transmittance wavelength %d is %g nm "
                            "(must be finite and > 0)", g->name, i, l);
        if (i > 0 && !(l > g->tau_lambda_nm[i - 1]))
            return lp__fail(err, LP_ERROR_INVALID_GLASS,
                            "glass \"%s\": transmittance wavelengths not "
                            "strictly increasing (%g nm after %g nm)",
                            g->name, l, g->tau_lambda_nm[i - 1]);
        if (!(t > 0.0 && t <= 1.0))
            return lp__fail(err, LP_ERROR_INVALID_GLASS,
                            "glass \"%s\": transmittance %g at %g nm is not in "
                            "(0, 1]", g->name, t, l);
        if (!isfinite(log(t) / g->tau_thickness_mm))
            return lp__fail(err, LP_ERROR_INVALID_GLASS,
                            "glass \"%s\": transmittance %g at %g nm over %g mm "
                            "gives an absorption coefficient that is not finite",
                            g->name, t, l, g->tau_thickness_mm);
    }
    return LP_OK;
}

lp_status lp_glass_check(const lp_glass *glass, lp_error *err)
{
    lp_status s;
    if (!glass)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "glass is NULL");
    if (!memchr(glass->name, '\0', sizeof glass->name))
        return lp__fail(err, LP_ERROR_INVALID_GLASS,
                        "glass name is not NUL-terminated within %d bytes",
                        LP_GLASS_NAME_MAX);
    if ((s = check_formula(glass, err)) != LP_OK ||
        (s = check_range(glass, err)) != LP_OK ||
        (s = check_index(glass, err)) != LP_OK ||
        (s = check_table(glass, err)) != LP_OK)
        return s;
    lp__ok(err);
    return LP_OK;
}
