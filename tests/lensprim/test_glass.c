/* test_glass.c -- glasses, the built-in catalog and the AGF reader.
 *
 * Expected indices and Abbe numbers are typed from the makers' catalogs
 * (SCHOTT data sheets / SCHOTT.AGF NM lines: nd and vd; the Zemax MISC.AGF
 * NM lines for fused silica and CaF2), transmittances from the SCHOTT data
 * sheets; formula checks evaluate the formula written out here by hand. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "lensprim.h"
#include "test_files.h"

#ifndef LP_TEST_TMP
#define LP_TEST_TMP "."
#endif

/* The Fraunhofer lines of the catalogs, nm. */
#define LAMBDA_D 587.5618
#define LAMBDA_F 486.1327
#define LAMBDA_C 656.2725

/* Catalog indices are rounded to 1e-5 and Abbe numbers to 1e-2. */
#define TOL_INDEX 5e-6
#define TOL_ABBE 0.01

/* ---- helpers ------------------------------------------------------------ */

static double abbe(const lp_glass *g)
{
    double nd = lp_glass_index(g, LAMBDA_D);
    return (nd - 1.0) / (lp_glass_index(g, LAMBDA_F) - lp_glass_index(g, LAMBDA_C));
}

/* Field-by-field equality of two glasses (no padding compared). */
static int same_glass(const lp_glass *a, const lp_glass *b)
{
    int i;
    if (strcmp(a->name, b->name) || a->formula != b->formula ||
        a->agf_formula != b->agf_formula || a->n_tau != b->n_tau ||
        a->lambda_min_nm != b->lambda_min_nm ||
        a->lambda_max_nm != b->lambda_max_nm ||
        a->tau_thickness_mm != b->tau_thickness_mm)
        return 0;
    for (i = 0; i < 10; i++)
        if (a->coef[i] != b->coef[i])
            return 0;
    for (i = 0; i < a->n_tau; i++)
        if (a->tau_lambda_nm[i] != b->tau_lambda_nm[i] || a->tau[i] != b->tau[i])
            return 0;
    return 1;
}

/* Sellmeier written out, l in um. */
static double sellmeier_by_hand(const double b[3], const double c[3], double l)
{
    double l2 = l * l;
    return sqrt(1.0 + b[0] * l2 / (l2 - c[0]) + b[1] * l2 / (l2 - c[1]) +
                b[2] * l2 / (l2 - c[2]));
}

/* ---- built-in glasses --------------------------------------------------- */

typedef struct sheet {
    const char *name;
    double nd, vd;
} sheet;

/* nd and vd as the makers' catalogs print them:
 *   N-BK7 .. N-SF6: SCHOTT data sheets (= NM lines of SCHOTT.AGF 2016);
 *   FUSED-SILICA:   nd 1.45846 (Malitson 1965 via refractiveindex.info),
 *                   vd 67.821433 (Zemax MISC.AGF, F_SILICA);
 *   CAF2:           nd 1.433849, vd 94.995854 (Zemax MISC.AGF, CAF2). */
static const sheet sheets[] = {
    {"N-BK7", 1.51680, 64.17},
    {"N-SF11", 1.78472, 25.68},
    {"F2", 1.62004, 36.37},
    {"N-BAK4", 1.56883, 55.98},
    {"N-SF6", 1.80518, 25.36},
    {"FUSED-SILICA", 1.45846, 67.821433},
    {"CAF2", 1.433849, 94.995854},
};

static void test_builtin_indices(void)
{
    size_t i;
    lp_glass g;
    lp_error err;

    for (i = 0; i < sizeof sheets / sizeof sheets[0]; i++) {
        lp_status s = lp_glass_builtin(sheets[i].name, &g, &err);
        CHECK(s == LP_OK, "builtin %s: %s", sheets[i].name, err.message);
        if (s != LP_OK)
            continue;
        CHECK(strcmp(g.name, sheets[i].name) == 0, "builtin name %s", g.name);
        s = lp_glass_check(&g, &err);
        CHECK(s == LP_OK, "builtin %s check: %s", g.name, err.message);
        CHECK_ABS(lp_glass_index(&g, LAMBDA_D), sheets[i].nd, TOL_INDEX,
                  "%s nd", g.name);
        CHECK_ABS(abbe(&g), sheets[i].vd, TOL_ABBE, "%s vd", g.name);
    }

    /* N-BK7's F and C lines from its data sheet. */
    lp_glass_builtin("N-BK7", &g, NULL);
    CHECK_ABS(lp_glass_index(&g, LAMBDA_F), 1.52238, TOL_INDEX, "N-BK7 nF");
    CHECK_ABS(lp_glass_index(&g, LAMBDA_C), 1.51432, TOL_INDEX, "N-BK7 nC");
}

static void test_builtin_names(void)
{
    static const char *silica[] = {"SILICA", "F_SILICA", "SIO2", "fused-silica",
                                   "SiO2"};
    lp_glass g;
    lp_error err;
    size_t i;

    for (i = 0; i < sizeof silica / sizeof silica[0]; i++) {
        CHECK(lp_glass_builtin(silica[i], &g, &err) == LP_OK, "alias %s: %s",
              silica[i], err.message);
        CHECK(strcmp(g.name, "FUSED-SILICA") == 0, "alias %s gives %s",
              silica[i], g.name);
    }
    CHECK(lp_glass_builtin("n-bk7", &g, NULL) == LP_OK &&
          strcmp(g.name, "N-BK7") == 0, "lower-case n-bk7");
    CHECK(lp_glass_builtin("caf2", &g, NULL) == LP_OK &&
          strcmp(g.name, "CAF2") == 0, "lower-case caf2");
    CHECK(lp_glass_builtin("N-BK8", &g, &err) == LP_ERROR_UNKNOWN_GLASS &&
          err.status == LP_ERROR_UNKNOWN_GLASS && strstr(err.message, "N-BK8"),
          "unknown built-in: %s", err.message);
    CHECK(lp_glass_builtin(NULL, &g, &err) == LP_ERROR_INVALID_ARGUMENT,
          "builtin NULL name");
    CHECK(lp_glass_builtin("N-BK7", NULL, &err) == LP_ERROR_INVALID_ARGUMENT,
          "builtin NULL out");
}

/* tau at the reference thickness from alpha: exp(-alpha d_ref). */
static double tau_of(const lp_glass *g, double lambda_nm)
{
    return exp(-lp_glass_absorption(g, lambda_nm) * g->tau_thickness_mm);
}

static void test_absorption(void)
{
    lp_glass g;

    /* SCHOTT N-BK7 data sheet, tau_i(10 mm). */
    lp_glass_builtin("N-BK7", &g, NULL);
    CHECK(g.tau_thickness_mm == 10.0, "N-BK7 reference thickness");
    CHECK_REL(tau_of(&g, 300), 0.292, 1e-12, "N-BK7 tau10(300)");
    CHECK_REL(tau_of(&g, 380), 0.993, 1e-12, "N-BK7 tau10(380)");
    CHECK_REL(tau_of(&g, 500), 0.998, 1e-12, "N-BK7 tau10(500)");
    CHECK_REL(tau_of(&g, 1060), 0.999, 1e-12, "N-BK7 tau10(1060)");
    CHECK_REL(tau_of(&g, 2500), 0.665, 1e-12, "N-BK7 tau10(2500)");
    /* alpha itself, and a thickness other than the reference one */
    CHECK_REL(lp_glass_absorption(&g, 400), -log(0.997) / 10.0, 1e-12,
              "N-BK7 alpha(400)");
    CHECK_REL(exp(-lp_glass_absorption(&g, 365) * 25.0), pow(0.988, 2.5), 1e-12,
              "N-BK7 tau25(365) from tau10");
    /* between readings: linear in ln(tau) */
    CHECK_REL(lp_glass_absorption(&g, 385),
              -(0.5 * log(0.993) + 0.5 * log(0.996)) / 10.0, 1e-12,
              "N-BK7 alpha(385)");
    CHECK_REL(lp_glass_absorption(&g, 1295),
              -(0.5 * log(0.999) + 0.5 * log(0.992)) / 10.0, 1e-12,
              "N-BK7 alpha(1295)");
    /* held constant past the ends */
    CHECK_REL(lp_glass_absorption(&g, 200), -log(0.063) / 10.0, 1e-12,
              "N-BK7 alpha(200)");
    CHECK_REL(lp_glass_absorption(&g, 5000), -log(0.665) / 10.0, 1e-12,
              "N-BK7 alpha(5000)");
    CHECK(isnan(lp_glass_absorption(&g, NAN)), "alpha(NaN)");

    /* SCHOTT.AGF IT lines, tau_i(25 mm). */
    lp_glass_builtin("N-SF11", &g, NULL);
    CHECK_REL(tau_of(&g, 400), 0.600, 1e-12, "N-SF11 tau25(400)");
    CHECK_REL(tau_of(&g, 370), 0.002, 1e-12, "N-SF11 tau25(370)");
    lp_glass_builtin("F2", &g, NULL);
    CHECK_REL(tau_of(&g, 334), 0.211, 1e-12, "F2 tau25(334)");
    CHECK_REL(tau_of(&g, 546), 0.998, 1e-12, "F2 tau25(546)");
    lp_glass_builtin("N-BAK4", &g, NULL);
    CHECK_REL(tau_of(&g, 350), 0.550, 1e-12, "N-BAK4 tau25(350)");
    lp_glass_builtin("N-SF6", &g, NULL);
    CHECK_REL(tau_of(&g, 380), 0.160, 1e-12, "N-SF6 tau25(380)");
    CHECK_REL(tau_of(&g, 460), 0.905, 1e-12, "N-SF6 tau25(460)");

    lp_glass_builtin("FUSED-SILICA", &g, NULL);
    CHECK(lp_glass_absorption(&g, 550) == 0.0, "silica alpha(550) = 0");
    lp_glass_builtin("CAF2", &g, NULL);
    CHECK(lp_glass_absorption(&g, 550) == 0.0, "CaF2 alpha(550) = 0");

    lp_glass_init_constant(&g, 1.5);
    CHECK(lp_glass_absorption(&g, 550) == 0.0, "no table: alpha = 0");
}

/* ---- formulas ----------------------------------------------------------- */

static void test_formulas(void)
{
    static const double lambdas[] = {365.0, 450.0, 587.5618, 700.0, 1014.0};
    /* chosen coefficients */
    static const double a[6] = {2.2718929, -1.0108077e-2, 1.0592509e-2,
                                2.0816965e-4, -7.6472538e-6, 4.9240991e-7};
    static const double cy[3] = {1.5046, 4.20e-3, 1.0e-4};
    static const double cr[3] = {1.574103270, 1.397861490e-2, 8.300451100e-4};
    static const double b[3] = {1.2, 0.25, 0.9}, c[3] = {0.008, 0.03, 110.0};
    lp_glass schott, cauchy, conrady, constant, sell;
    size_t i;

    memset(&schott, 0, sizeof schott);
    strcpy(schott.name, "schott");
    schott.formula = LP_FORMULA_SCHOTT;
    memcpy(schott.coef, a, sizeof a);
    memset(&cauchy, 0, sizeof cauchy);
    strcpy(cauchy.name, "cauchy");
    cauchy.formula = LP_FORMULA_CAUCHY;
    memcpy(cauchy.coef, cy, sizeof cy);
    memset(&conrady, 0, sizeof conrady);
    strcpy(conrady.name, "conrady");
    conrady.formula = LP_FORMULA_CONRADY;
    memcpy(conrady.coef, cr, sizeof cr);
    lp_glass_init_constant(&constant, 1.5);
    lp_glass_init_sellmeier(&sell, "mine", b, c);

    for (i = 0; i < sizeof lambdas / sizeof lambdas[0]; i++) {
        double l = lambdas[i] / 1000.0, want;
        want = sqrt(a[0] + a[1] * pow(l, 2) + a[2] * pow(l, -2) +
                    a[3] * pow(l, -4) + a[4] * pow(l, -6) + a[5] * pow(l, -8));
        CHECK_REL(lp_glass_index(&schott, lambdas[i]), want, 1e-14,
                  "Schott at %g nm", lambdas[i]);
        want = cy[0] + cy[1] / pow(l, 2) + cy[2] / pow(l, 4);
        CHECK_REL(lp_glass_index(&cauchy, lambdas[i]), want, 1e-14,
                  "Cauchy at %g nm", lambdas[i]);
        want = cr[0] + cr[1] / l + cr[2] / pow(l, 3.5);
        CHECK_REL(lp_glass_index(&conrady, lambdas[i]), want, 1e-14,
                  "Conrady at %g nm", lambdas[i]);
        CHECK(lp_glass_index(&constant, lambdas[i]) == 1.5, "constant at %g nm",
              lambdas[i]);
        CHECK_REL(lp_glass_index(&sell, lambdas[i]), sellmeier_by_hand(b, c, l),
                  1e-14, "Sellmeier at %g nm", lambdas[i]);
    }
    CHECK(strcmp(constant.name, "n=1.5") == 0, "constant name %s", constant.name);
    CHECK(lp_glass_check(&constant, NULL) == LP_OK, "constant check");
    CHECK(strcmp(sell.name, "mine") == 0, "Sellmeier name");
    CHECK(sell.lambda_min_nm == 380.0 && sell.lambda_max_nm == 780.0,
          "Sellmeier default range");
    CHECK(lp_glass_check(&sell, NULL) == LP_OK, "Sellmeier check");
    CHECK(lp_glass_check(&schott, NULL) == LP_OK, "Schott check");

    CHECK(isnan(lp_glass_index(&sell, 0.0)), "index at 0 nm is NaN");
    CHECK(isnan(lp_glass_index(&sell, -500.0)), "index at -500 nm is NaN");
    CHECK(isnan(lp_glass_index(&sell, NAN)), "index at NaN is NaN");
    CHECK(isnan(lp_glass_index(NULL, 500.0)), "index of NULL is NaN");
    sell.formula = LP_FORMULA_UNSUPPORTED;
    CHECK(isnan(lp_glass_index(&sell, 500.0)), "unsupported formula is NaN");
}

static void test_covers(void)
{
    lp_glass g;
    lp_glass_builtin("N-BK7", &g, NULL); /* LD 0.3 - 2.5 um */
    CHECK(lp_glass_covers(&g, 300.0) && lp_glass_covers(&g, 2500.0) &&
          lp_glass_covers(&g, 587.5618), "N-BK7 covers its range");
    CHECK(!lp_glass_covers(&g, 299.0) && !lp_glass_covers(&g, 2501.0),
          "N-BK7 range ends");
    CHECK(!lp_glass_covers(&g, NAN), "covers(NaN)");
    lp_glass_init_constant(&g, 1.33);
    CHECK(lp_glass_covers(&g, 10.0) && lp_glass_covers(&g, 1e5),
          "unbounded range covers all");
}

/* ---- lp_glass_check ----------------------------------------------------- */

static void expect_refused(const lp_glass *g, lp_status want, const char *what)
{
    lp_error err;
    lp_status s = lp_glass_check(g, &err);
    CHECK(s == want && err.status == want && err.message[0] != '\0',
          "check refuses %s: got %d (%s)", what, (int)s, err.message);
}

static void test_check(void)
{
    lp_glass base, g;
    lp_error err;

    lp_glass_builtin("N-BK7", &base, NULL);
    CHECK(lp_glass_check(&base, &err) == LP_OK && err.status == LP_OK &&
          err.message[0] == '\0', "N-BK7 passes: %s", err.message);

    g = base;
    g.coef[1] = NAN;
    expect_refused(&g, LP_ERROR_INVALID_GLASS, "a NaN coefficient");
    lp_glass_check(&g, &err);
    CHECK(strstr(err.message, "N-BK7") != NULL, "message names the glass: %s",
          err.message);
    g = base;
    g.coef[7] = INFINITY;
    expect_refused(&g, LP_ERROR_INVALID_GLASS, "an infinite unused coefficient");

    g = base;
    g.tau[3] = 1.01;
    expect_refused(&g, LP_ERROR_INVALID_GLASS, "tau > 1");
    g = base;
    g.tau[3] = 0.0;
    expect_refused(&g, LP_ERROR_INVALID_GLASS, "tau = 0");
    g = base;
    g.tau[3] = NAN;
    expect_refused(&g, LP_ERROR_INVALID_GLASS, "tau NaN");
    g = base;
    g.tau_lambda_nm[5] = g.tau_lambda_nm[4];
    expect_refused(&g, LP_ERROR_INVALID_GLASS, "a repeated wavelength");
    g = base;
    g.tau_lambda_nm[5] = g.tau_lambda_nm[4] - 1.0;
    expect_refused(&g, LP_ERROR_INVALID_GLASS, "a decreasing wavelength");
    g = base;
    g.tau_thickness_mm = 0.0;
    expect_refused(&g, LP_ERROR_INVALID_GLASS, "thickness 0");
    g = base;
    g.n_tau = LP_GLASS_TABLE_MAX + 1;
    expect_refused(&g, LP_ERROR_INVALID_GLASS, "a table too long");
    g = base;
    g.lambda_min_nm = 800.0;
    g.lambda_max_nm = 700.0;
    expect_refused(&g, LP_ERROR_INVALID_GLASS, "an empty range");

    lp_glass_init_constant(&g, 0.0);
    expect_refused(&g, LP_ERROR_INVALID_GLASS, "n = 0");
    lp_glass_init_constant(&g, NAN);
    expect_refused(&g, LP_ERROR_INVALID_GLASS, "n = NaN");
    {
        /* a resonance at 500 nm inside 380-780 nm */
        static const double b[3] = {1.0, 0.0, 0.0}, c[3] = {0.25, 0.0, 0.0};
        lp_glass_init_sellmeier(&g, "pole", b, c);
        expect_refused(&g, LP_ERROR_INVALID_GLASS, "a pole in range");
        lp_glass_init_sellmeier(&g, "nothing", NULL, c);
        expect_refused(&g, LP_ERROR_INVALID_GLASS, "missing B coefficients");
    }
    g = base;
    g.formula = LP_FORMULA_UNSUPPORTED;
    g.agf_formula = 7;
    expect_refused(&g, LP_ERROR_UNSUPPORTED, "an unsupported formula");
    g = base;
    g.formula = (lp_formula)42;
    expect_refused(&g, LP_ERROR_INVALID_GLASS, "an unknown formula code");
    g = base;
    memset(g.name, 'x', sizeof g.name);
    expect_refused(&g, LP_ERROR_INVALID_GLASS, "an unterminated name");
    CHECK(lp_glass_check(NULL, &err) == LP_ERROR_INVALID_ARGUMENT, "check NULL");
}

/* ---- catalog ------------------------------------------------------------ */

#define N_BUILTIN 7

static void test_catalog_basics(void)
{
    lp_catalog *cat = NULL;
    lp_glass g, b;
    lp_error err;
    size_t i;

    CHECK(lp_catalog_create(&cat, &err) == LP_OK && cat, "create: %s",
          err.message);
    if (!cat)
        return;
    CHECK(lp_catalog_count(cat) == N_BUILTIN, "built-in count %lu",
          (unsigned long)lp_catalog_count(cat));
    for (i = 0; i < lp_catalog_count(cat); i++) {
        const char *name = lp_catalog_name(cat, i);
        CHECK(name && lp_catalog_find(cat, name, &g, &err) == LP_OK &&
              lp_glass_builtin(name, &b, NULL) == LP_OK && same_glass(&g, &b),
              "catalog glass %lu (%s) is the built-in one", (unsigned long)i,
              name ? name : "NULL");
    }
    CHECK(lp_catalog_name(cat, N_BUILTIN) == NULL, "name past the end");
    CHECK(lp_catalog_find(cat, "sio2", &g, &err) == LP_OK &&
          strcmp(g.name, "FUSED-SILICA") == 0, "find alias sio2: %s", err.message);
    CHECK(lp_catalog_find(cat, "n-sf6", &g, &err) == LP_OK &&
          strcmp(g.name, "N-SF6") == 0, "find lower-case n-sf6");
    CHECK(lp_catalog_find(cat, "UNOBTAINIUM", &g, &err) == LP_ERROR_UNKNOWN_GLASS &&
          strstr(err.message, "UNOBTAINIUM"), "unknown glass: %s", err.message);
    CHECK(lp_catalog_find(NULL, "N-BK7", &g, &err) == LP_ERROR_INVALID_ARGUMENT,
          "find in NULL");
    CHECK(lp_catalog_count(NULL) == 0 && lp_catalog_name(NULL, 0) == NULL,
          "NULL catalog count/name");
    CHECK(lp_catalog_create(NULL, &err) == LP_ERROR_INVALID_ARGUMENT,
          "create NULL");
    lp_catalog_destroy(cat);
    lp_catalog_destroy(NULL); /* harmless */
}

/* A small catalog: Sellmeier (2), Schott (1), Conrady (5), Herzberger (3,
 * unsupported); CRLF line ends, a tab-separated NM line, IT lines out of
 * order, one wavelength at two thicknesses and an opaque reading. */
static const char agf_text[] =
    "CC lensprim test catalog\r\n"
    "NM TEST-SELL 2 517642.251 1.5168 64.17 0 1\r\n"
    "GC a Sellmeier glass with N-BK7's coefficients\r\n"
    "ED 7.100000 8.300000 2.510000 -0.000900 0\r\n"
    "CD 1.039612120E+00 6.000698670E-03 2.317923440E-01 2.001791440E-02 "
    "1.010469450E+00 1.035606530E+02 0.000000000E+00 0.000000000E+00\r\n"
    "TD 1.860000E-06 1.310000E-08 -1.370000E-11 4.340000E-07 6.270000E-10 "
    "1.700000E-01 2.000000E+01\r\n"
    "OD 1.0000 1.0000 0.0000 1.0000 2.3000 2.3000\r\n"
    "LD 3.00000E-01 2.50000E+00\r\n"
    "IT 5.00000E-01 9.98000E-01 1.00000E+01\r\n"
    "IT 4.00000E-01 9.97000E-01 1.00000E+01\r\n"
    "IT 4.00000E-01 9.92000E-01 2.50000E+01\r\n"
    "IT 3.10000E-01 0.00000E+00 2.50000E+01\r\n"
    "IT 7.00000E-01 9.98000E-01 1.00000E+01\r\n"
    "\r\n"
    "NM TEST-SCHOTT\t1\t0\t1.5\t60\t0\t0\t0\r\n"
    "CD 2.2718929 -1.0108077E-02 1.0592509E-02 2.0816965E-04 -7.6472538E-06 "
    "4.9240991E-07 0 0 0 0\r\n"
    "LD 0.365 1.014\r\n"
    "NM TEST-CONRADY 5 0 1.603233 42.504788 0 0 0\r\n"
    "CD 1.574103270E+000 1.397861490E-002 8.300451100E-004 0 0 0 0 0 0 0\r\n"
    "LD 0.334 2.325\r\n"
    "BD something\r\n"
    "NM TEST-HERZ 3 0 1.6 40 0 0 0\r\n"
    "CD 1 2 3 4 5 6\r\n"
    "XX an unknown record\r\n";

static void check_test_catalog(const lp_catalog *cat, const char *how)
{
    static const double b[3] = {1.03961212, 0.231792344, 1.01046945};
    static const double c[3] = {0.00600069867, 0.0200179144, 103.560653};
    static const double a[6] = {2.2718929, -1.0108077e-2, 1.0592509e-2,
                                2.0816965e-4, -7.6472538e-6, 4.9240991e-7};
    lp_glass g;
    lp_error err;
    double l;

    CHECK(lp_catalog_count(cat) == N_BUILTIN + 4, "%s: count %lu", how,
          (unsigned long)lp_catalog_count(cat));

    CHECK(lp_catalog_find(cat, "test-sell", &g, &err) == LP_OK, "%s: TEST-SELL: %s",
          how, err.message);
    CHECK(strcmp(g.name, "TEST-SELL") == 0 && g.formula == LP_FORMULA_SELLMEIER &&
          g.agf_formula == 2, "%s: TEST-SELL formula", how);
    l = LAMBDA_D / 1000.0;
    CHECK_REL(lp_glass_index(&g, LAMBDA_D), sellmeier_by_hand(b, c, l), 1e-14,
              "%s: TEST-SELL index (K/L order)", how);
    CHECK_ABS(lp_glass_index(&g, LAMBDA_D), 1.5168, TOL_INDEX, "%s: TEST-SELL nd",
              how);
    CHECK(g.lambda_min_nm == 300.0 && g.lambda_max_nm == 2500.0,
          "%s: TEST-SELL LD %g..%g", how, g.lambda_min_nm, g.lambda_max_nm);
    CHECK(g.n_tau == 4 && g.tau_thickness_mm == 10.0, "%s: TEST-SELL table %d @ %g",
          how, g.n_tau, g.tau_thickness_mm);
    if (g.n_tau == 4)
        CHECK(g.tau_lambda_nm[0] == 310.0 && g.tau_lambda_nm[1] == 400.0 &&
              g.tau_lambda_nm[2] == 500.0 && g.tau_lambda_nm[3] == 700.0,
              "%s: TEST-SELL table sorted", how);
    CHECK(lp_glass_check(&g, &err) == LP_OK, "%s: TEST-SELL check: %s", how,
          err.message);
    /* 400 nm read at 10 mm (0.997) and 25 mm (0.992): the 25 mm reading
     * (larger tau*d) is kept; alpha does not depend on the thickness used */
    CHECK_REL(lp_glass_absorption(&g, 400), -log(0.992) / 25.0, 1e-12,
              "%s: TEST-SELL alpha(400)", how);
    CHECK_REL(lp_glass_absorption(&g, 500), -log(0.998) / 10.0, 1e-12,
              "%s: TEST-SELL alpha(500)", how);
    /* an opaque reading is tau = 5e-4 at its own thickness */
    CHECK_REL(lp_glass_absorption(&g, 310), -log(5e-4) / 25.0, 1e-12,
              "%s: TEST-SELL alpha(310)", how);

    CHECK(lp_catalog_find(cat, "TEST-SCHOTT", &g, &err) == LP_OK &&
          g.formula == LP_FORMULA_SCHOTT && g.agf_formula == 1,
          "%s: TEST-SCHOTT: %s", how, err.message);
    l = 0.45;
    CHECK_REL(lp_glass_index(&g, 450.0),
              sqrt(a[0] + a[1] * l * l + a[2] / (l * l) + a[3] / pow(l, 4) +
                   a[4] / pow(l, 6) + a[5] / pow(l, 8)),
              1e-14, "%s: TEST-SCHOTT index", how);
    CHECK(g.lambda_min_nm == 365.0 && g.lambda_max_nm == 1014.0 && g.n_tau == 0 &&
          lp_glass_absorption(&g, 500) == 0.0, "%s: TEST-SCHOTT range/table", how);

    CHECK(lp_catalog_find(cat, "TEST-CONRADY", &g, &err) == LP_OK &&
          g.formula == LP_FORMULA_CONRADY && g.agf_formula == 5,
          "%s: TEST-CONRADY: %s", how, err.message);
    l = LAMBDA_D / 1000.0;
    CHECK_REL(lp_glass_index(&g, LAMBDA_D),
              1.574103270 + 1.397861490e-2 / l + 8.300451100e-4 / pow(l, 3.5),
              1e-14, "%s: TEST-CONRADY index", how);
    /* its NM line (Zemax MISC.AGF, BASF5) gives nd 1.603233 */
    CHECK_ABS(lp_glass_index(&g, LAMBDA_D), 1.603233, TOL_INDEX,
              "%s: TEST-CONRADY nd", how);

    CHECK(lp_catalog_find(cat, "TEST-HERZ", &g, &err) == LP_ERROR_UNSUPPORTED &&
          err.status == LP_ERROR_UNSUPPORTED && strstr(err.message, "TEST-HERZ") &&
          strstr(err.message, "3"), "%s: unsupported formula: %s", how,
          err.message);
}

static void test_agf_file(void)
{
    const char *path = LP_TEST_TMP "/lp_test_glass.agf";
    const char *path16 = LP_TEST_TMP "/lp_test_glass_utf16le.agf";
    size_t n = sizeof agf_text - 1, i;
    unsigned char *u16;
    lp_catalog *cat = NULL, *cat16 = NULL;
    lp_error err;

    lp_catalog_create(&cat, NULL);
    lp_catalog_create(&cat16, NULL);
    if (!cat || !cat16) {
        CHECK(0, "catalogs for the AGF test");
        lp_catalog_destroy(cat);
        lp_catalog_destroy(cat16);
        return;
    }

    CHECK(tf_write(path, agf_text, n) == 0, "write %s", path);
    CHECK(lp_catalog_load_agf(cat, path, &err) == LP_OK && err.status == LP_OK,
          "load %s: %s", path, err.message);
    check_test_catalog(cat, "CRLF file");

    /* the same text as UTF-16LE with a byte order mark */
    u16 = malloc(2 * n + 2);
    if (u16) {
        u16[0] = 0xFF;
        u16[1] = 0xFE;
        for (i = 0; i < n; i++) {
            u16[2 + 2 * i] = (unsigned char)agf_text[i];
            u16[3 + 2 * i] = 0;
        }
        CHECK(tf_write(path16, u16, 2 * n + 2) == 0, "write %s", path16);
        CHECK(lp_catalog_load_agf(cat16, path16, &err) == LP_OK,
              "load UTF-16LE: %s", err.message);
        check_test_catalog(cat16, "UTF-16LE file");
        for (i = 0; i < lp_catalog_count(cat); i++) {
            lp_glass a, b;
            const char *name = lp_catalog_name(cat, i);
            if (lp_catalog_find(cat, name, &a, NULL) == LP_OK)
                CHECK(lp_catalog_find(cat16, name, &b, NULL) == LP_OK &&
                      same_glass(&a, &b), "UTF-16LE %s same as UTF-8", name);
        }
        free(u16);
    }
    remove(path);
    remove(path16);
    lp_catalog_destroy(cat);
    lp_catalog_destroy(cat16);
}

static void test_agf_encodings(void)
{
    size_t n = sizeof agf_text - 1, i;
    unsigned char *buf = malloc(2 * n + 3);
    lp_catalog *cat = NULL;
    lp_error err;

    if (!buf)
        return;
    /* UTF-16BE with a byte order mark */
    lp_catalog_create(&cat, NULL);
    buf[0] = 0xFE;
    buf[1] = 0xFF;
    for (i = 0; i < n; i++) {
        buf[2 + 2 * i] = 0;
        buf[3 + 2 * i] = (unsigned char)agf_text[i];
    }
    CHECK(lp_catalog_load_agf_text(cat, (const char *)buf, 2 * n + 2, &err) ==
          LP_OK, "UTF-16BE: %s", err.message);
    check_test_catalog(cat, "UTF-16BE text");
    lp_catalog_destroy(cat);

    /* UTF-8 with a byte order mark, LF line ends */
    lp_catalog_create(&cat, NULL);
    buf[0] = 0xEF;
    buf[1] = 0xBB;
    buf[2] = 0xBF;
    for (i = 0, n = 3; agf_text[i]; i++)
        if (agf_text[i] != '\r')
            buf[n++] = (unsigned char)agf_text[i];
    CHECK(lp_catalog_load_agf_text(cat, (const char *)buf, n, &err) == LP_OK,
          "UTF-8 BOM: %s", err.message);
    check_test_catalog(cat, "UTF-8 BOM LF text");
    lp_catalog_destroy(cat);

    /* old Mac CR line ends */
    lp_catalog_create(&cat, NULL);
    for (i = 0, n = 0; agf_text[i]; i++)
        if (agf_text[i] != '\n')
            buf[n++] = (unsigned char)agf_text[i];
    CHECK(lp_catalog_load_agf_text(cat, (const char *)buf, n, &err) == LP_OK,
          "CR text: %s", err.message);
    check_test_catalog(cat, "CR text");
    lp_catalog_destroy(cat);
    free(buf);
}

/* Load `text`; expect LP_ERROR_PARSE naming `line` and nothing added. */
static void expect_parse_error(const char *text, size_t len, unsigned line,
                               const char *what)
{
    lp_catalog *cat = NULL;
    lp_error err;
    lp_glass g;
    char want[32];
    lp_status s;

    lp_catalog_create(&cat, NULL);
    if (!cat)
        return;
    s = lp_catalog_load_agf_text(cat, text, len, &err);
    CHECK(s == LP_ERROR_PARSE && err.status == LP_ERROR_PARSE,
          "%s: status %d (%s)", what, (int)s, err.message);
    if (line) {
        snprintf(want, sizeof want, "line %u:", line);
        CHECK(strstr(err.message, want) != NULL, "%s: message names %s: %s",
              what, want, err.message);
    }
    CHECK(lp_catalog_count(cat) == N_BUILTIN &&
          lp_catalog_find(cat, "GOOD", &g, NULL) == LP_ERROR_UNKNOWN_GLASS,
          "%s: nothing added", what);
    lp_catalog_destroy(cat);
}

#define PARSE_ERROR(text, line, what) \
    expect_parse_error(text, sizeof text - 1, line, what)

static void test_agf_errors(void)
{
    lp_catalog *cat = NULL;
    lp_error err;
    const char *missing = LP_TEST_TMP "/no-such-dir-lensprim/none.agf";

    PARSE_ERROR("CC bad\r\n"
                "NM GOOD 2 0 1.5 60\r\n"
                "CD 1 0.01 0.2 0.02 1 100\r\n"
                "NM BAD 2 0 1.5 60\r\n"
                "CD 1.0 0.0x1 0.2 0.02 1 100\r\n",
                5, "malformed CD number");
    PARSE_ERROR("NM GOOD 2 0 1.5 60\n"
                "CD 1 0.01 0.2 0.02 1 100\n"
                "IT 0.5 1.5 10\n", 3, "IT tau > 1");
    PARSE_ERROR("NM GOOD 2 0 1.5 60\n"
                "CD 1 0.01 0.2 0.02 1 100\n"
                "IT 0.5 0.9 0\n", 3, "IT thickness 0");
    PARSE_ERROR("NM GOOD 2 0 1.5 60\n"
                "CD 1 0.01 0.2 0.02 1 100\n"
                "IT 0.5 0.9\n", 3, "IT without thickness");
    PARSE_ERROR("NM GOOD 2 0 1.5 60\n"
                "CD 1 0.01 0.2 0.02 1 100\n"
                "LD 2.5 0.3\n", 3, "LD reversed");
    PARSE_ERROR("NM GOOD 2 0 1.5 60\n"
                "CD 1 0.01 0.2 0.02 1 100\n"
                "LD 0.3 2,5\n", 3, "LD decimal comma");
    PARSE_ERROR("NM GOOD\n", 1, "NM without formula");
    PARSE_ERROR("NM GOOD two 0 1.5 60\n", 1, "NM formula not a number");
    PARSE_ERROR("NM GOOD 2.5 0 1.5 60\n", 1, "NM formula not an integer");
    PARSE_ERROR("NM A-NAME-LONGER-THAN-THIRTY-ONE-CHARS 2 0 1.5 60\n", 1,
                "name too long");
    PARSE_ERROR("CD 1 0.01 0.2 0.02 1 100\n", 1, "CD before NM");
    PARSE_ERROR("NM GOOD 2 0 1.5 60\n"
                "CD 1 0.01 0.2 0.02 1 100\n"
                "\n"
                "NM NOCD 2 0 1.5 60\n"
                "LD 0.3 2.5\n", 4, "glass without CD");
    PARSE_ERROR("NM GOOD 2 0 1.5 60\nCD 1 0.01 0.2 0.02 1 nan\n", 2, "nan");
    PARSE_ERROR("NM GOOD 2 0 1.5 60\nCD 1 0.01 0.2\nLD 0.3 2.5\n", 2,
                "too few Sellmeier coefficients");
    PARSE_ERROR("NM GOOD 2 0 1.5 60\nCD 1 0.01 0.2 0.02 1 1e999\n", 2,
                "overflowing number");
    PARSE_ERROR("NM GOOD 2 0 1.5 60\nCD 1 0.01 0.2 0.02 1 1e\n", 2,
                "exponent without digits");
    PARSE_ERROR("NM GOOD 2 0 1.5 60\nCD 1 0.01 0.2 0.02 1 .\n", 2, "lone dot");
    PARSE_ERROR("N\0M GOOD 2 0 1.5 60\n", 0, "NUL bytes without a BOM");
    PARSE_ERROR("\xFF\xFE" "N\0M\0 ", 0, "UTF-16 with an odd byte count");

    /* a file that is not there */
    lp_catalog_create(&cat, NULL);
    CHECK(lp_catalog_load_agf(cat, missing, &err) == LP_ERROR_IO &&
          err.status == LP_ERROR_IO && strstr(err.message, missing),
          "missing file: %s", err.message);
    CHECK(lp_catalog_count(cat) == N_BUILTIN, "missing file adds nothing");
    CHECK(lp_catalog_load_agf(NULL, missing, &err) == LP_ERROR_INVALID_ARGUMENT,
          "load into NULL");
    CHECK(lp_catalog_load_agf(cat, NULL, &err) == LP_ERROR_INVALID_ARGUMENT,
          "load NULL path");
    CHECK(lp_catalog_load_agf_text(cat, NULL, 5, &err) ==
          LP_ERROR_INVALID_ARGUMENT, "load NULL text");
    CHECK(lp_catalog_load_agf_text(cat, NULL, 0, &err) == LP_OK,
          "load empty text");
    CHECK(lp_catalog_load_agf_text(cat, "CC nothing\n\n  \t\n", 16, &err) ==
          LP_OK && lp_catalog_count(cat) == N_BUILTIN, "comments only");
    lp_catalog_destroy(cat);
}

static void test_agf_replace(void)
{
    static const char text[] =
        "NM n-bk7 5 0 1.5 60\n"
        "CD 1.5 0 0\n"
        "NM TWICE 5 0 1.4 60\n"
        "CD 1.4 0 0\n"
        "NM TWICE 5 0 1.6 60\n"
        "CD 1.6 0 0\n";
    lp_catalog *cat = NULL;
    lp_glass g;
    lp_error err;

    lp_catalog_create(&cat, NULL);
    if (!cat)
        return;
    CHECK(lp_catalog_load_agf_text(cat, text, sizeof text - 1, &err) == LP_OK,
          "replace: %s", err.message);
    CHECK(lp_catalog_count(cat) == N_BUILTIN + 1, "replace: count %lu",
          (unsigned long)lp_catalog_count(cat));
    CHECK(lp_catalog_find(cat, "N-BK7", &g, NULL) == LP_OK &&
          g.formula == LP_FORMULA_CONRADY && lp_glass_index(&g, 500) == 1.5,
          "a loaded N-BK7 replaces the built-in one");
    CHECK(lp_catalog_find(cat, "TWICE", &g, NULL) == LP_OK &&
          lp_glass_index(&g, 500) == 1.6, "the later of two glasses wins");
    lp_catalog_destroy(cat);
}

/* More IT lines than a glass holds. */
static void test_agf_long_table(void)
{
    char *text = malloc(8192);
    lp_catalog *cat = NULL;
    lp_glass g;
    lp_error err;
    size_t len;
    int i, ok;

    if (!text)
        return;
    lp_catalog_create(&cat, NULL);

    /* 60 readings 250..840 nm (130 nm below the window, 60 above): the
     * farther end goes first, then the ends alternate: 340..810 nm */
    len = (size_t)sprintf(text, "NM LONG 2 0 1.5 60\nCD 1 0.01 0.2 0.02 1 100\n");
    for (i = 0; i < 60; i++)
        len += (size_t)sprintf(text + len, "IT %.3f %.4f 10\n",
                               (250 + 10 * i) / 1000.0, 0.9 + 0.001 * i);
    CHECK(lp_catalog_load_agf_text(cat, text, len, &err) == LP_OK, "long: %s",
          err.message);
    ok = lp_catalog_find(cat, "LONG", &g, &err) == LP_OK;
    CHECK(ok && g.n_tau == LP_GLASS_TABLE_MAX, "long table size %d", g.n_tau);
    if (ok && g.n_tau == LP_GLASS_TABLE_MAX) {
        CHECK(g.tau_lambda_nm[0] == 340.0 &&
              g.tau_lambda_nm[LP_GLASS_TABLE_MAX - 1] == 810.0,
              "long table kept 340..810 nm: %g..%g", g.tau_lambda_nm[0],
              g.tau_lambda_nm[LP_GLASS_TABLE_MAX - 1]);
        CHECK(lp_glass_check(&g, &err) == LP_OK, "long table check: %s",
              err.message);
        /* 500 nm is reading 25: tau = 0.925 */
        CHECK_REL(lp_glass_absorption(&g, 500), -log(0.925) / 10.0, 1e-12,
                  "long table alpha(500)");
    }

    /* 50 readings 400..645 nm, all inside the window, ln(tau) linear but
     * for two bumps: the bumps survive the thinning */
    len = (size_t)sprintf(text, "NM DENSE 2 0 1.5 60\nCD 1 0.01 0.2 0.02 1 100\n");
    for (i = 0; i < 50; i++) {
        int nm = 400 + 5 * i;
        double tau = nm == 500 || nm == 600 ? 0.5 : exp(-0.001 * i);
        len += (size_t)sprintf(text + len, "IT %.3f %.6f 10\n", nm / 1000.0, tau);
    }
    CHECK(lp_catalog_load_agf_text(cat, text, len, &err) == LP_OK, "dense: %s",
          err.message);
    ok = lp_catalog_find(cat, "DENSE", &g, &err) == LP_OK;
    CHECK(ok && g.n_tau == LP_GLASS_TABLE_MAX, "dense table size %d", g.n_tau);
    if (ok && g.n_tau == LP_GLASS_TABLE_MAX) {
        int has500 = 0, has600 = 0;
        for (i = 0; i < g.n_tau; i++) {
            has500 |= g.tau_lambda_nm[i] == 500.0;
            has600 |= g.tau_lambda_nm[i] == 600.0;
        }
        CHECK(g.tau_lambda_nm[0] == 400.0 &&
              g.tau_lambda_nm[LP_GLASS_TABLE_MAX - 1] == 645.0 && has500 &&
              has600, "dense table keeps its ends and bumps");
        CHECK(lp_glass_check(&g, &err) == LP_OK, "dense table check: %s",
              err.message);
    }
    lp_catalog_destroy(cat);
    free(text);
}

int main(void)
{
    test_builtin_indices();
    test_builtin_names();
    test_absorption();
    test_formulas();
    test_covers();
    test_check();
    test_catalog_basics();
    test_agf_file();
    test_agf_encodings();
    test_agf_errors();
    test_agf_replace();
    test_agf_long_table();
    return check_finish("test_glass");
}
