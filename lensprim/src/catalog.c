/* catalog.c -- the built-in glasses and the catalog that holds them and
 * whatever is loaded from AGF files (agf.c).
 *
 * Every built-in glass below cites where its numbers come from.  Sellmeier
 * coefficients are stored B1 B2 B3 C1 C2 C3 (C in um^2); wavelengths in
 * nanometres; transmittances are internal (no surface losses) at the
 * stated sample thickness, copied as published. */
#include <stdlib.h>
#include <string.h>

#include "catalog_internal.h"
#include "error.h"

#define COUNT(a) (sizeof (a) / sizeof (a)[0])

/* One internal transmittance reading: wavelength (nm), tau. */
typedef struct tau_point {
    double lambda_nm;
    double tau;
} tau_point;

typedef struct builtin_glass {
    const char *name;
    const char *aliases[4];      /* NULL-terminated */
    double b[3], c[3];           /* Sellmeier, C in um^2 */
    double lambda_min_nm, lambda_max_nm;
    const tau_point *tau;
    size_t n_tau;
    double tau_thickness_mm;
} builtin_glass;

/* ---- Schott glasses ------------------------------------------------------
 * Sellmeier coefficients and data range (LD): SCHOTT Zemax catalog
 * "SCHOTT.AGF", status 14 July 2016 (public copy: github.com/hoogeroo/
 * raytracing, SCHOTT.agf); the same coefficients appear in the SCHOTT
 * data sheets and on refractiveindex.info (SCHOTT Zemax catalog
 * 2017-01-20b).
 *
 * Transmittance: N-BK7 at 10 mm from the SCHOTT N-BK7 data sheet, column
 * tau_i(10 mm), as reproduced in the "Schott N-BK7 Glass" entry of the
 * COMSOL material library (public copy in a COMSOL model file); the
 * tau_i(25 mm) column given there equals the IT lines of SCHOTT.AGF,
 * which vouches for the copy.  For N-SF11, F2, N-BAK4 and N-SF6 no public
 * copy of the 10 mm column was found, so the maker's 25 mm readings are
 * used as published in SCHOTT.AGF (IT lines); the glass records its
 * thickness, so alpha = -ln(tau)/25 mm is the same physics. */

/* SCHOTT N-BK7 data sheet, tau_i at 10 mm. */
static const tau_point nbk7_tau[] = {
    {290, 0.063}, {300, 0.292}, {310, 0.574}, {320, 0.770}, {334, 0.905},
    {350, 0.967}, {365, 0.988}, {370, 0.991}, {380, 0.993}, {390, 0.996},
    {400, 0.997}, {405, 0.997}, {420, 0.997}, {436, 0.997}, {460, 0.997},
    {500, 0.998}, {546, 0.998}, {580, 0.998}, {620, 0.998}, {660, 0.998},
    {700, 0.998}, {1060, 0.999}, {1530, 0.992}, {1970, 0.933},
    {2325, 0.793}, {2500, 0.665},
};

/* SCHOTT.AGF, N-SF11 IT lines, tau_i at 25 mm. */
static const tau_point nsf11_tau[] = {
    {370, 0.002}, {380, 0.120}, {390, 0.390}, {400, 0.600}, {405, 0.670},
    {420, 0.810}, {436, 0.870}, {460, 0.920}, {500, 0.953}, {546, 0.978},
    {580, 0.984}, {620, 0.981}, {660, 0.981}, {700, 0.985}, {1060, 0.998},
    {1530, 0.985}, {1970, 0.915}, {2325, 0.700}, {2500, 0.620},
};

/* SCHOTT.AGF, F2 IT lines, tau_i at 25 mm.  The 320 nm reading is 0.000,
 * stored as LP__TAU_OPAQUE (see catalog_internal.h). */
static const tau_point f2_tau[] = {
    {320, LP__TAU_OPAQUE}, {334, 0.211}, {350, 0.780}, {365, 0.921},
    {370, 0.940}, {380, 0.963}, {390, 0.977}, {400, 0.985}, {405, 0.987},
    {420, 0.991}, {436, 0.993}, {460, 0.994}, {500, 0.997}, {546, 0.998},
    {580, 0.998}, {620, 0.998}, {660, 0.997}, {700, 0.998}, {1060, 0.998},
    {1530, 0.989}, {1970, 0.876}, {2325, 0.685}, {2500, 0.589},
};

/* SCHOTT.AGF, N-BAK4 IT lines, tau_i at 25 mm. */
static const tau_point nbak4_tau[] = {
    {334, 0.070}, {350, 0.550}, {365, 0.840}, {370, 0.890}, {380, 0.940},
    {390, 0.967}, {400, 0.980}, {405, 0.983}, {420, 0.987}, {436, 0.988},
    {460, 0.989}, {500, 0.994}, {546, 0.996}, {580, 0.996}, {620, 0.995},
    {660, 0.995}, {700, 0.997}, {1060, 0.995}, {1530, 0.982},
    {1970, 0.900}, {2325, 0.710}, {2500, 0.540},
};

/* SCHOTT.AGF, N-SF6 IT lines, tau_i at 25 mm. */
static const tau_point nsf6_tau[] = {
    {370, 0.010}, {380, 0.160}, {390, 0.410}, {400, 0.610}, {405, 0.680},
    {420, 0.810}, {436, 0.870}, {460, 0.905}, {500, 0.943}, {546, 0.972},
    {580, 0.980}, {620, 0.978}, {660, 0.976}, {700, 0.983}, {1060, 0.996},
    {1530, 0.978}, {1970, 0.860}, {2325, 0.590}, {2500, 0.530},
};

/* ---- Crystals and silica -------------------------------------------------
 * Fused silica: I. H. Malitson, "Interspecimen comparison of the refractive
 * index of fused silica", J. Opt. Soc. Am. 55, 1205 (1965), 20 C, valid
 * 0.21-3.71 um; the paper gives the poles as wavelengths 0.0684043,
 * 0.1162414, 9.896161 um, squared here.
 * CaF2: I. H. Malitson, "A redetermination of some optical properties of
 * calcium fluoride", Appl. Opt. 2, 1103 (1963), 24 C, valid 0.23-9.7 um;
 * poles 0.050263605, 0.1003909, 34.649040 um, squared here.
 * Transmittance of both: no maker table was found; the Zemax catalog
 * MISC.AGF (public copy: github.com/nzhagen/zemaxglass, misc.agf) lists
 * tau = 1.000 at 25 mm for F_SILICA and CAF2 from 334 to 2325 nm (sources
 * there: Handbook of Optics Vol. II; The Infrared & Electro-Optical Systems
 * Handbook Vol. III), i.e. no absorption to three decimals. */
static const tau_point clear_tau[] = {
    {334, 1.0}, {350, 1.0}, {365, 1.0}, {370, 1.0}, {380, 1.0},
    {390, 1.0}, {400, 1.0}, {420, 1.0}, {460, 1.0}, {500, 1.0},
    {660, 1.0}, {1060, 1.0}, {1529, 1.0}, {2325, 1.0},
};

#define SQ(x) ((x) * (x))

static const builtin_glass builtins[] = {
    {"N-BK7", {NULL},
     {1.03961212, 0.231792344, 1.01046945},
     {0.00600069867, 0.0200179144, 103.560653},
     300, 2500, nbk7_tau, COUNT(nbk7_tau), 10.0},
    {"N-SF11", {NULL},
     {1.73759695, 0.313747346, 1.89878101},
     {0.013188707, 0.0623068142, 155.23629},
     370, 2500, nsf11_tau, COUNT(nsf11_tau), 25.0},
    {"F2", {NULL},
     {1.34533359, 0.209073176, 0.937357162},
     {0.00997743871, 0.0470450767, 111.886764},
     320, 2500, f2_tau, COUNT(f2_tau), 25.0},
    {"N-BAK4", {NULL},
     {1.28834642, 0.132817724, 0.945395373},
     {0.00779980626, 0.0315631177, 105.965875},
     334, 2500, nbak4_tau, COUNT(nbak4_tau), 25.0},
    {"N-SF6", {NULL},
     {1.77931763, 0.338149866, 2.08734474},
     {0.0133714182, 0.0617533621, 174.01759},
     370, 2500, nsf6_tau, COUNT(nsf6_tau), 25.0},
    {"FUSED-SILICA", {"SILICA", "F_SILICA", "SIO2", NULL},
     {0.6961663, 0.4079426, 0.8974794},
     {SQ(0.0684043), SQ(0.1162414), SQ(9.896161)},
     210, 3710, clear_tau, COUNT(clear_tau), 25.0},
    {"CAF2", {NULL},
     {0.5675888, 0.4710914, 3.8484723},
     {SQ(0.050263605), SQ(0.1003909), SQ(34.649040)},
     230, 9700, clear_tau, COUNT(clear_tau), 25.0},
};

_Static_assert(COUNT(nbk7_tau) <= LP_GLASS_TABLE_MAX &&
               COUNT(nsf11_tau) <= LP_GLASS_TABLE_MAX &&
               COUNT(f2_tau) <= LP_GLASS_TABLE_MAX &&
               COUNT(nbak4_tau) <= LP_GLASS_TABLE_MAX &&
               COUNT(nsf6_tau) <= LP_GLASS_TABLE_MAX &&
               COUNT(clear_tau) <= LP_GLASS_TABLE_MAX,
               "a built-in transmittance table is larger than lp_glass holds");

int lp__name_equal(const char *a, const char *b)
{
    for (;; a++, b++) {
        unsigned char x = (unsigned char)*a, y = (unsigned char)*b;
        if (x >= 'a' && x <= 'z')
            x = (unsigned char)(x - 'a' + 'A');
        if (y >= 'a' && y <= 'z')
            y = (unsigned char)(y - 'a' + 'A');
        if (x != y)
            return 0;
        if (x == '\0')
            return 1;
    }
}

static void builtin_to_glass(const builtin_glass *b, lp_glass *g)
{
    size_t i;
    memset(g, 0, sizeof *g);
    strcpy(g->name, b->name); /* all built-in names fit */
    g->formula = LP_FORMULA_SELLMEIER;
    for (i = 0; i < 3; i++) {
        g->coef[i] = b->b[i];
        g->coef[3 + i] = b->c[i];
    }
    g->lambda_min_nm = b->lambda_min_nm;
    g->lambda_max_nm = b->lambda_max_nm;
    g->n_tau = (int)b->n_tau;
    for (i = 0; i < b->n_tau; i++) {
        g->tau_lambda_nm[i] = b->tau[i].lambda_nm;
        g->tau[i] = b->tau[i].tau;
    }
    g->tau_thickness_mm = b->tau_thickness_mm;
}

/* The built-in glass called `name` or one of its aliases, or NULL. */
static const builtin_glass *find_builtin(const char *name)
{
    size_t i, k;
    for (i = 0; i < COUNT(builtins); i++) {
        if (lp__name_equal(builtins[i].name, name))
            return &builtins[i];
        for (k = 0; builtins[i].aliases[k]; k++)
            if (lp__name_equal(builtins[i].aliases[k], name))
                return &builtins[i];
    }
    return NULL;
}

lp_status lp_glass_builtin(const char *name, lp_glass *out, lp_error *err)
{
    const builtin_glass *b;
    if (!name || !out)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "lp_glass_builtin: %s is NULL", name ? "out" : "name");
    b = find_builtin(name);
    if (!b)
        return lp__fail(err, LP_ERROR_UNKNOWN_GLASS,
                        "no built-in glass named \"%s\"", name);
    builtin_to_glass(b, out);
    lp__ok(err);
    return LP_OK;
}

/* Index of the glass called `name` in the catalog, or -1. */
static long find_index(const lp_catalog *cat, const char *name)
{
    size_t i;
    for (i = 0; i < cat->count; i++)
        if (lp__name_equal(cat->glasses[i].name, name))
            return (long)i;
    return -1;
}

lp_status lp__catalog_add(lp_catalog *cat, const lp_glass *glasses, size_t n,
                          lp_error *err)
{
    size_t i;
    if (n > cat->capacity - cat->count) {
        size_t cap = cat->capacity ? cat->capacity : 16;
        lp_glass *p;
        while (cap - cat->count < n) {
            if (cap > (size_t)-1 / 2 / sizeof *p)
                return lp__fail(err, LP_ERROR_NO_MEMORY,
                                "catalog: too many glasses");
            cap *= 2;
        }
        p = realloc(cat->glasses, cap * sizeof *p);
        if (!p)
            return lp__fail(err, LP_ERROR_NO_MEMORY,
                            "catalog: out of memory for %lu glasses",
                            (unsigned long)(cat->count + n));
        cat->glasses = p;
        cat->capacity = cap;
    }
    /* From here nothing can fail. */
    for (i = 0; i < n; i++) {
        long at = find_index(cat, glasses[i].name);
        if (at >= 0)
            cat->glasses[at] = glasses[i];
        else
            cat->glasses[cat->count++] = glasses[i];
    }
    return LP_OK;
}

lp_status lp_catalog_create(lp_catalog **out, lp_error *err)
{
    lp_glass list[COUNT(builtins)];
    lp_catalog *cat;
    lp_status s;
    size_t i;

    if (!out)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "lp_catalog_create: out is NULL");
    *out = NULL;
    cat = calloc(1, sizeof *cat);
    if (!cat)
        return lp__fail(err, LP_ERROR_NO_MEMORY, "catalog: out of memory");
    for (i = 0; i < COUNT(builtins); i++)
        builtin_to_glass(&builtins[i], &list[i]);
    s = lp__catalog_add(cat, list, COUNT(builtins), err);
    if (s != LP_OK) {
        lp_catalog_destroy(cat);
        return s;
    }
    *out = cat;
    lp__ok(err);
    return LP_OK;
}

void lp_catalog_destroy(lp_catalog *catalog)
{
    if (!catalog)
        return;
    free(catalog->glasses);
    free(catalog);
}

lp_status lp_catalog_find(const lp_catalog *catalog, const char *name,
                          lp_glass *out, lp_error *err)
{
    const builtin_glass *b;
    const lp_glass *g;
    long at;

    if (!catalog || !name || !out)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "lp_catalog_find: %s is NULL",
                        !catalog ? "catalog" : !name ? "name" : "out");
    at = find_index(catalog, name);
    if (at < 0) {
        /* An alias of a built-in glass ("SILICA") finds the glass under
         * its catalog name, unless a glass of that very name was loaded. */
        b = find_builtin(name);
        if (b)
            at = find_index(catalog, b->name);
    }
    if (at < 0)
        return lp__fail(err, LP_ERROR_UNKNOWN_GLASS,
                        "no glass named \"%s\" in the catalog", name);
    g = &catalog->glasses[at];
    if (g->formula == LP_FORMULA_UNSUPPORTED)
        return lp__fail(err, LP_ERROR_UNSUPPORTED,
                        "glass \"%s\" uses AGF dispersion formula %d, which "
                        "lensprim cannot evaluate", g->name, g->agf_formula);
    *out = *g;
    lp__ok(err);
    return LP_OK;
}

size_t lp_catalog_count(const lp_catalog *catalog)
{
    return catalog ? catalog->count : 0;
}

const char *lp_catalog_name(const lp_catalog *catalog, size_t i)
{
    if (!catalog || i >= catalog->count)
        return NULL;
    return catalog->glasses[i].name;
}
