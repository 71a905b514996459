/* crystal.c -- uniaxial crystals as plain data: an ordinary and an
 * extraordinary glass and an optic axis, and the built-in crystals.
 *
 * The built-in dispersion formulas are Sellmeier fits in micrometres.
 * Ghosh's form n^2 = A + B1 l^2/(l^2 - C1) + B2 l^2/(l^2 - C2) is the
 * three-term Sellmeier of lp_glass with B3 = A - 1 and C3 = 0 (a term
 * B3 l^2/l^2 = B3).  Poles given as wavelengths are squared here. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "catalog_internal.h"
#include "error.h"
#include "vec3.h"

typedef struct builtin_crystal {
    const char *name;
    double b_o[3], c_o[3];  /* Sellmeier B (1), C (um^2) of n_o */
    double b_e[3], c_e[3];  /* the same of n_e */
    double lambda_min_nm, lambda_max_nm;
} builtin_crystal;

#define SQ(x) ((x) * (x))

static const builtin_crystal crystals[] = {
    /* Ghosh, Opt. Commun. 163, 95-102 (1999) */
    {"calcite",
     {0.96464345, 1.82831454, 0.73358749}, {1.94325203e-2, 120.0, 0.0},
     {0.82427830, 0.14429128, 0.35859695}, {1.06689543e-2, 120.0, 0.0},
     204, 2172},
    /* Ghosh 1999 (alpha quartz; optical activity not modelled) */
    {"quartz",
     {1.07044083, 1.10202242, 0.28604141}, {1.00585997e-2, 100.0, 0.0},
     {1.09509924, 1.15662475, 0.28851804}, {1.02101864e-2, 100.0, 0.0},
     198, 2053},
    /* Malitson & Dodge, JOSA 62, 1405 (1972); Dodge, Handbook of Laser
     * Science and Technology IV (1986) */
    {"sapphire",
     {1.4313493, 0.65054713, 5.3414021}, {SQ(0.0726631), SQ(0.1193242), SQ(18.028251)},
     {1.5039759, 0.55069141, 6.5927379}, {SQ(0.0740288), SQ(0.1216529), SQ(20.072248)},
     200, 5000},
    /* Dodge, Appl. Opt. 23, 1980-1985 (1984) */
    {"MgF2",
     {0.48755108, 0.39875031, 2.3120353}, {SQ(0.04338408), SQ(0.09461442), SQ(23.793604)},
     {0.41344023, 0.50497499, 2.4904862}, {SQ(0.03684262), SQ(0.09076162), SQ(23.771995)},
     200, 7000},
};

#define COUNT(a) (sizeof(a) / sizeof((a)[0]))

void lp_crystal_init_constant(lp_crystal *crystal, double n_o, double n_e, lp_vec3 axis)
{
    if (!crystal)
        return;
    memset(crystal, 0, sizeof *crystal);
    strcpy(crystal->name, "uniaxial");
    lp_glass_init_constant(&crystal->ordinary, n_o);
    lp_glass_init_constant(&crystal->extraordinary, n_e);
    crystal->axis = axis;
}

lp_status lp_crystal_builtin(const char *name, lp_crystal *out, lp_error *err)
{
    if (!name || !out)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_crystal_builtin: %s is NULL",
                        name ? "out" : "name");
    for (size_t i = 0; i < COUNT(crystals); i++) {
        const builtin_crystal *b = &crystals[i];
        if (!lp__name_equal(b->name, name))
            continue;
        memset(out, 0, sizeof *out);
        strcpy(out->name, b->name);
        lp_glass_init_sellmeier(&out->ordinary, b->name, b->b_o, b->c_o);
        lp_glass_init_sellmeier(&out->extraordinary, b->name, b->b_e, b->c_e);
        snprintf(out->ordinary.name, sizeof out->ordinary.name, "%s-o", b->name);
        snprintf(out->extraordinary.name, sizeof out->extraordinary.name, "%s-e", b->name);
        out->ordinary.lambda_min_nm = out->extraordinary.lambda_min_nm = b->lambda_min_nm;
        out->ordinary.lambda_max_nm = out->extraordinary.lambda_max_nm = b->lambda_max_nm;
        out->axis = v3(0.0, 0.0, 1.0);
        lp__ok(err);
        return LP_OK;
    }
    return lp__fail(err, LP_ERROR_UNKNOWN_GLASS,
                    "unknown crystal \"%s\" (built in: calcite, quartz, sapphire, MgF2)", name);
}

lp_status lp_crystal_check(const lp_crystal *crystal, lp_error *err)
{
    lp_status st;
    if (!crystal)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_crystal_check: NULL crystal");
    if ((st = lp_glass_check(&crystal->ordinary, err)) != LP_OK)
        return st;
    if ((st = lp_glass_check(&crystal->extraordinary, err)) != LP_OK)
        return st;
    if (!v3_finite(crystal->axis) || !(v3_len(crystal->axis) > 0.0))
        return lp__fail(err, LP_ERROR_INVALID_GLASS,
                        "crystal %s: the optic axis must be a finite non-zero vector",
                        crystal->name);
    lp__ok(err);
    return LP_OK;
}
