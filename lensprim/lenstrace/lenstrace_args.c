/* lenstrace_args.c -- parsing of lenstrace's options and its --lens and
 * --ray specs.  No printing, no allocation, no global mutable state: every
 * message goes into the caller's lt_args.error. */
#include "lenstrace_args.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/cli.h"

#define LT_TOKEN_MAX 256 /* longest key=value item */

/* The parse's error: the message in args->error, returned. */
#define fail(args, ...) sp_format((args)->error, sizeof (args)->error, __VA_ARGS__)

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' ||
           c == '\f';
}

static int lower(int c)
{
    return (c >= 'A' && c <= 'Z') ? c - 'A' + 'a' : c;
}

static int equal_nocase(const char *a, const char *b)
{
    while (*a && *b) {
        if (lower((unsigned char)*a) != lower((unsigned char)*b))
            return 0;
        a++, b++;
    }
    return *a == *b;
}

/* Copy [b, e) with surrounding white space trimmed into buf (size n).
 * Returns 0 if it does not fit. */
static int copy_trimmed(const char *b, const char *e, char *buf, size_t n)
{
    while (b < e && is_space(*b))
        b++;
    while (e > b && is_space(e[-1]))
        e--;
    if ((size_t)(e - b) >= n)
        return 0;
    memcpy(buf, b, (size_t)(e - b));
    buf[e - b] = '\0';
    return 1;
}

/* A whole string as a finite double; messages name `what`. */
static const char *parse_finite(lt_args *args, const char *ctx,
                                const char *what, const char *s, double *out)
{
    int r = sp_parse_double(s, out);
    if (r == 0)
        return fail(args, "%s: %s: '%s' is not a number", ctx, what, s);
    if (r < 0)
        return fail(args, "%s: %s: '%s' is out of range", ctx, what, s);
    if (!isfinite(*out))
        return fail(args, "%s: %s must be a finite number, got '%s'", ctx,
                    what, s);
    return NULL;
}

static const char *parse_positive(lt_args *args, const char *ctx,
                                  const char *what, const char *s, double *out)
{
    if (parse_finite(args, ctx, what, s, out))
        return args->error;
    if (!(*out > 0.0))
        return fail(args, "%s: %s must be > 0, got '%s'", ctx, what, s);
    return NULL;
}

/* A radius: finite, or +-inf (flat); NaN refused. */
static const char *parse_radius(lt_args *args, const char *what,
                                const char *s, double *out)
{
    int r = sp_parse_double(s, out);
    if (r == 0)
        return fail(args, "--lens: %s: '%s' is not a number (use a radius "
                          "in mm, or inf or 0 for flat)", what, s);
    if (r < 0)
        return fail(args, "--lens: %s: '%s' is out of range", what, s);
    if (isnan(*out))
        return fail(args, "--lens: %s must be a number, inf or 0, got '%s'",
                    what, s);
    return NULL;
}

/* "x,y,z": three finite numbers. */
static const char *parse_vec3(lt_args *args, const char *what, const char *s,
                              lp_vec3 *out)
{
    double v[3];
    const char *p = s;
    for (int k = 0; k < 3; k++) {
        const char *q = strchr(p, ',');
        char buf[LT_TOKEN_MAX];
        int r;
        if (k < 2 && !q)
            return fail(args, "%s: expected x,y,z (no spaces inside "
                              "a value), got '%s'", what, s);
        if (k == 2 && q)
            return fail(args, "%s: expected three components x,y,z, "
                              "got '%s'", what, s);
        if (!q)
            q = p + strlen(p);
        if (!copy_trimmed(p, q, buf, sizeof buf))
            return fail(args, "%s: component %d is too long", what,
                        k + 1);
        r = sp_parse_double(buf, &v[k]);
        if (r == 0)
            return fail(args, "%s: component %d '%s' is not a number",
                        what, k + 1, buf);
        if (r < 0 || !isfinite(v[k]))
            return fail(args, "%s: component %d must be a finite "
                              "number, got '%s'", what, k + 1, buf);
        p = q + 1;
    }
    out->x = v[0];
    out->y = v[1];
    out->z = v[2];
    return NULL;
}

/* Normalize without overflow or underflow; 0 for a zero vector. */
static int normalize(lp_vec3 v, lp_vec3 *out)
{
    double m = fmax(fabs(v.x), fmax(fabs(v.y), fabs(v.z)));
    double len;
    if (!(m > 0.0) || !isfinite(m))
        return 0;
    v.x /= m, v.y /= m, v.z /= m;
    len = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    out->x = v.x / len;
    out->y = v.y / len;
    out->z = v.z / len;
    return 1;
}

lp_vec3 lt_cross(lp_vec3 a, lp_vec3 b)
{
    lp_vec3 c;
    c.x = a.y * b.z - a.z * b.y;
    c.y = a.z * b.x - a.x * b.z;
    c.z = a.x * b.y - a.y * b.x;
    return c;
}

lp_vec3 lt_perpendicular(lp_vec3 d)
{
    lp_vec3 ax = {0.0, 1.0, 0.0}, out;
    if (fabs(d.y) > 0.9) {
        ax.x = 1.0;
        ax.y = 0.0;
    }
    if (!normalize(lt_cross(d, ax), &out)) {
        out.x = 1.0; /* unreachable for a unit d */
        out.y = out.z = 0.0;
    }
    return out;
}

int lt_perpendicular_part(lp_vec3 v, lp_vec3 d, lp_vec3 *out)
{
    lp_vec3 u, p;
    double dot;
    if (!normalize(v, &u))
        return 0;
    dot = u.x * d.x + u.y * d.y + u.z * d.z;
    p.x = u.x - dot * d.x;
    p.y = u.y - dot * d.y;
    p.z = u.z - dot * d.z;
    if (!(sqrt(p.x * p.x + p.y * p.y + p.z * p.z) > 1e-9))
        return 0;
    return normalize(p, out);
}

/* ------------------------------------------------------------------ */
/* --lens                                                              */
/* ------------------------------------------------------------------ */

enum { LK_R1, LK_R2, LK_T, LK_D, LK_D2, LK_GLASS, LK_N, LK_CRYSTAL, LK_NO, LK_NE,
       LK_AXIS, LK_COUNT };
static const char *const lens_keys[LK_COUNT] = {"R1", "R2", "t", "D", "D2", "glass",
                                                "n", "crystal", "no", "ne", "axis"};

/* axis=x:y:z (the --lens items are comma-separated) */
static const char *parse_axis(lt_args *args, const char *val, lp_vec3 *out)
{
    char buf[LT_TOKEN_MAX];
    size_t n = strlen(val);
    if (n >= sizeof buf)
        return fail(args, "--lens: axis: value is too long");
    for (size_t i = 0; i <= n; i++)
        buf[i] = val[i] == ':' ? ',' : val[i];
    if (!strchr(val, ':'))
        return fail(args, "--lens: axis: expected x:y:z, got '%s'", val);
    if (parse_vec3(args, "axis", buf, out))
        return args->error;
    if (out->x == 0.0 && out->y == 0.0 && out->z == 0.0)
        return fail(args, "--lens: axis: the optic axis must not be the zero vector");
    return NULL;
}

static const char *lens_value(lt_args *args, int key, const char *val,
                              lt_lens_spec *out)
{
    switch (key) {
    case LK_R1: return parse_radius(args, "R1", val, &out->r1);
    case LK_R2: return parse_radius(args, "R2", val, &out->r2);
    case LK_T: return parse_positive(args, "--lens", "t", val, &out->t);
    case LK_D: return parse_positive(args, "--lens", "D", val, &out->d);
    case LK_D2: return parse_positive(args, "--lens", "D2", val, &out->d2);
    case LK_N:
        out->glass_constant = 1;
        return parse_positive(args, "--lens", "n", val, &out->glass_n);
    case LK_CRYSTAL:
        if (*val == '\0' || strlen(val) >= sizeof out->crystal_name)
            return fail(args, "--lens: crystal: give a built-in name (calcite, quartz, "
                              "sapphire, MgF2)");
        out->crystal = 1;
        strcpy(out->crystal_name, val);
        return NULL;
    case LK_NO:
        out->crystal = 2;
        return parse_positive(args, "--lens", "no", val, &out->n_o);
    case LK_NE:
        out->crystal = 2;
        return parse_positive(args, "--lens", "ne", val, &out->n_e);
    case LK_AXIS:
        return parse_axis(args, val, &out->axis);
    case LK_GLASS:
        if (strncmp(val, "n=", 2) == 0) {
            out->glass_constant = 1;
            return parse_positive(args, "--lens", "glass=n", val + 2,
                                  &out->glass_n);
        }
        if (*val == '\0')
            return fail(args, "--lens: glass: empty name (use a catalog "
                              "name such as N-BK7, or n=1.5)");
        if (strlen(val) >= sizeof out->glass_name)
            return fail(args, "--lens: glass: name '%.40s...' is too long",
                        val);
        out->glass_constant = 0;
        strcpy(out->glass_name, val);
        return NULL;
    }
    return fail(args, "--lens: internal error");
}

const char *lt_parse_lens_spec(lt_args *args, const char *spec,
                               lt_lens_spec *out)
{
    lt_lens_spec s;
    int seen[LK_COUNT] = {0};
    const char *p = spec;

    memset(&s, 0, sizeof s);
    s.axis.z = 1.0;
    for (;;) {
        const char *e = strchr(p, ',');
        const char *eq;
        char item[LT_TOKEN_MAX], *val;
        int key = -1;
        if (!e)
            e = p + strlen(p);
        if (!copy_trimmed(p, e, item, sizeof item))
            return fail(args, "--lens: item '%.40s...' is too long", p);
        if (item[0] == '\0') {
            if (*e == '\0' && p == spec)
                return fail(args, "--lens: empty spec (expected e.g. "
                                  "R1=25.8,R2=inf,t=5.3,D=25.4,glass=N-BK7)");
            return fail(args, "--lens: empty item in '%s'", spec);
        }
        eq = strchr(item, '=');
        if (!eq)
            return fail(args, "--lens: '%s' is not KEY=VALUE", item);
        item[eq - item] = '\0';
        val = item + (eq - item) + 1;
        {
            /* trim around '=' */
            size_t n = strlen(item);
            while (n > 0 && is_space(item[n - 1]))
                item[--n] = '\0';
            while (is_space(*val))
                val++;
        }
        for (int k = 0; k < LK_COUNT; k++)
            if (strcmp(item, lens_keys[k]) == 0)
                key = k;
        if (key < 0)
            return fail(args, "--lens: unknown key '%s' (keys: R1, R2, t, D, "
                              "D2, glass, n, crystal, no, ne, axis)", item);
        if (seen[key])
            return fail(args, "--lens: duplicate key '%s'", item);
        if ((key == LK_GLASS && seen[LK_N]) || (key == LK_N && seen[LK_GLASS]))
            return fail(args, "--lens: give either glass=... or n=..., "
                              "not both");
        seen[key] = 1;
        if (lens_value(args, key, val, &s))
            return args->error;
        if (*e == '\0')
            break;
        p = e + 1;
    }
    int glassy = seen[LK_GLASS] || seen[LK_N];
    int crystal = seen[LK_CRYSTAL] || seen[LK_NO] || seen[LK_NE];
    if (glassy && crystal)
        return fail(args, "--lens: give either a glass (glass=, n=) or a crystal "
                          "(crystal=, or no= and ne=), not both");
    if (seen[LK_CRYSTAL] && (seen[LK_NO] || seen[LK_NE]))
        return fail(args, "--lens: give either crystal=NAME or no= and ne=, not both");
    if ((seen[LK_NO] || seen[LK_NE]) && !(seen[LK_NO] && seen[LK_NE]))
        return fail(args, "--lens: a constant crystal needs both no= and ne=");
    if (seen[LK_AXIS] && !crystal)
        return fail(args, "--lens: axis= is the optic axis of a crystal (crystal= or "
                          "no=,ne=)");
    if (crystal)
        seen[LK_GLASS] = 1; /* the crystal stands for the glass */
    for (int k = 0; k < LK_COUNT; k++) {
        if (k == LK_D2 || k == LK_GLASS || k == LK_N || k >= LK_CRYSTAL)
            continue;
        if (!seen[k])
            return fail(args, "--lens: missing key '%s' (required: R1, R2, "
                              "t, D, glass)", lens_keys[k]);
    }
    if (!seen[LK_GLASS] && !seen[LK_N])
        return fail(args, "--lens: missing key 'glass' (a catalog name such "
                          "as N-BK7, or n=1.5)");
    *out = s;
    return NULL;
}

/* ------------------------------------------------------------------ */
/* --ray                                                               */
/* ------------------------------------------------------------------ */

enum { RK_O, RK_D, RK_LAMBDA, RK_LAMBDA_VAC, RK_VP, RK_I, RK_CH, RK_COUNT };
static const char *const ray_keys[RK_COUNT] = {"o", "d", "lambda", "lambda_vac",
                                               "vp", "I", "ch"};

static const char *parse_ch(lt_args *args, const char *s, uint64_t *out)
{
    char *end;
    unsigned long long v;
    if (*s == '\0')
        return fail(args, "--ray: ch: empty value");
    for (const char *c = s; *c; c++)
        if (*c < '0' || *c > '9')
            return fail(args, "--ray: ch must be an unsigned integer, got "
                              "'%s'", s);
    errno = 0;
    v = strtoull(s, &end, 10);
    if (errno == ERANGE || *end != '\0'
#if ULLONG_MAX > UINT64_MAX
        || v > UINT64_MAX
#endif
    )
        return fail(args, "--ray: ch '%s' is out of range (max %llu)", s,
                    (unsigned long long)UINT64_MAX);
    *out = (uint64_t)v;
    return NULL;
}

const char *lt_parse_ray_spec(lt_args *args, const char *spec,
                              lt_ray_spec *out)
{
    lt_ray_spec r;
    int seen[RK_COUNT] = {0};
    lp_vec3 vp = {0.0, 0.0, 0.0};
    const char *p = spec;
    int any = 0;

    memset(&r, 0, sizeof r);
    r.lambda_nm = 587.56;
    r.intensity = 1.0;
    r.unpolarized = 1;
    r.ch = 0;

    for (;;) {
        const char *b, *e, *eq;
        char item[LT_TOKEN_MAX], *val;
        int key = -1;
        while (is_space(*p))
            p++;
        if (*p == '\0')
            break;
        b = p;
        while (*p && !is_space(*p))
            p++;
        e = p;
        any = 1;
        if (!copy_trimmed(b, e, item, sizeof item))
            return fail(args, "--ray: item '%.40s...' is too long", b);
        eq = strchr(item, '=');
        if (!eq)
            return fail(args, "--ray: '%s' is not KEY=VALUE (items are "
                              "separated by spaces)", item);
        item[eq - item] = '\0';
        val = item + (eq - item) + 1;
        for (int k = 0; k < RK_COUNT; k++)
            if (strcmp(item, ray_keys[k]) == 0)
                key = k;
        if (key < 0)
            return fail(args, "--ray: unknown key '%s' (keys: o, d, lambda, "
                              "lambda_vac, vp, I, ch)", item);
        if (seen[key])
            return fail(args, "--ray: duplicate key '%s'", item);
        seen[key] = 1;
        switch (key) {
        case RK_O:
            if (parse_vec3(args, "--ray: o", val, &r.o))
                return args->error;
            break;
        case RK_D:
            if (parse_vec3(args, "--ray: d", val, &r.d))
                return args->error;
            break;
        case RK_LAMBDA:
            if (parse_positive(args, "--ray", "lambda", val, &r.lambda_nm))
                return args->error;
            break;
        case RK_LAMBDA_VAC:
            if (parse_positive(args, "--ray", "lambda_vac", val, &r.lambda_vac_nm))
                return args->error;
            break;
        case RK_VP:
            if (equal_nocase(val, "unpolarized") ||
                equal_nocase(val, "unpolarised")) {
                r.unpolarized = 1;
            } else {
                r.unpolarized = 0;
                if (parse_vec3(args, "--ray: vp", val, &vp))
                    return args->error;
            }
            break;
        case RK_I:
            if (parse_finite(args, "--ray", "I", val, &r.intensity))
                return args->error;
            if (!(r.intensity >= 0.0))
                return fail(args, "--ray: I must be >= 0, got '%s'", val);
            break;
        case RK_CH:
            if (parse_ch(args, val, &r.ch))
                return args->error;
            break;
        }
    }
    if (!any)
        return fail(args, "--ray: empty spec (expected e.g. \"o=0,3,-10 "
                          "d=0,0,1 lambda=587.56 vp=1,0,0 I=1 ch=7\")");
    if (!seen[RK_O])
        return fail(args, "--ray: missing key 'o' (the origin x,y,z)");
    if (!seen[RK_D])
        return fail(args, "--ray: missing key 'd' (the direction x,y,z)");
    if (seen[RK_LAMBDA] && seen[RK_LAMBDA_VAC])
        return fail(args, "--ray: give lambda (in air) or lambda_vac (in "
                          "vacuum), not both");
    if (seen[RK_LAMBDA_VAC]) {
        double n_air = lp_air_index(r.lambda_vac_nm);
        if (!isfinite(n_air))
            return fail(args, "--ray: lambda_vac must be at least %g nm "
                              "(Edlen's standard air), got '%.17g'",
                        LT_LAMBDA_MIN_NM, r.lambda_vac_nm);
        r.lambda_nm = r.lambda_vac_nm / n_air;
    } else if (!(r.lambda_nm >= LT_LAMBDA_MIN_NM)) {
        return fail(args, "--ray: lambda must be at least %g nm (where "
                          "standard air is defined), got '%.17g'",
                    LT_LAMBDA_MIN_NM, r.lambda_nm);
    }
    if (!normalize(r.d, &r.d))
        return fail(args, "--ray: d is the zero vector (a direction is "
                          "needed)");
    if (!r.unpolarized) {
        lp_vec3 u;
        if (!normalize(vp, &u))
            return fail(args, "--ray: vp is the zero vector (use a field "
                              "direction perpendicular to d, or "
                              "vp=unpolarized)");
        if (!lt_perpendicular_part(u, r.d, &r.vp))
            return fail(args, "--ray: vp is parallel to d (the field must "
                              "have a part perpendicular to the direction)");
    }
    *out = r;
    return NULL;
}

/* ------------------------------------------------------------------ */
/* Options                                                             */
/* ------------------------------------------------------------------ */

void lt_args_init(lt_args *args)
{
    memset(args, 0, sizeof *args);
    args->depth = 5;
    args->mode = LP_MODE_POLARIZED;
    args->medium = 1.0;
    args->azimuths = 36;
    args->lambda_nm = 587.56;
}

enum {
    OPT_LENS, OPT_RAY, OPT_RAYS, OPT_DEPTH, OPT_MODE, OPT_MEDIUM, OPT_BACKWARD,
    OPT_CATALOG, OPT_HELP, OPT_VERSION, OPT_CONE, OPT_AZIMUTHS, OPT_LAMBDA,
    OPT_COUNT
};

static const struct {
    const char *name;
    int takes_value;
} options[OPT_COUNT] = {
    {"lens", 1},     {"ray", 1},      {"rays", 1},     {"depth", 1},
    {"mode", 1},     {"medium", 1},   {"backward", 0},
    {"catalog", 1},  {"help", 0},     {"version", 0},
    {"cone", 1},     {"azimuths", 1}, {"lambda", 1},
};

static const char *parse_depth(lt_args *args, const char *s)
{
    long v;
    if (sp_parse_long(s, 1, LP_MAX_DEPTH, &v) != 1)
        return fail(args, "--depth must be an integer from 1 to %d, got '%s'",
                    LP_MAX_DEPTH, s);
    args->depth = (int)v;
    return NULL;
}

static const char *parse_mode(lt_args *args, const char *s)
{
    if (strcmp(s, "polarized") == 0)
        args->mode = LP_MODE_POLARIZED;
    else if (strcmp(s, "fresnel") == 0)
        args->mode = LP_MODE_FRESNEL;
    else if (strcmp(s, "schlick") == 0)
        args->mode = LP_MODE_SCHLICK;
    else
        return fail(args, "--mode must be polarized, fresnel or schlick, "
                          "got '%s'", s);
    return NULL;
}

const char *lt_args_parse(lt_args *args, int argc, char **argv)
{
    int seen[OPT_COUNT] = {0};

    /* --help and --version win wherever they are, whatever else is wrong
       (no option takes a value that starts with "--" or is "-h"/"-V" as a
       separate argument, so these are never values). */
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            args->help = 1;
            return NULL;
        }
        if (strcmp(argv[i], "--version") == 0 || strcmp(argv[i], "-V") == 0) {
            args->version = 1;
            return NULL;
        }
    }

    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        const char *eq, *value = NULL;
        size_t name_len;
        int opt = -1;

        if (arg[0] != '-')
            return fail(args, "unexpected argument '%s' (try --help)", arg);
        if (arg[1] != '-' || arg[2] == '\0')
            return fail(args, "unknown option '%s' (try --help)", arg);

        eq = strchr(arg + 2, '=');
        name_len = eq ? (size_t)(eq - (arg + 2)) : strlen(arg + 2);
        for (int k = 0; k < OPT_COUNT; k++)
            if (strlen(options[k].name) == name_len &&
                strncmp(options[k].name, arg + 2, name_len) == 0)
                opt = k;
        if (opt < 0)
            return fail(args, "unknown option '%.*s' (try --help)",
                        (int)(name_len + 2), arg);

        if (options[opt].takes_value) {
            if (eq) {
                value = eq + 1;
            } else {
                if (i + 1 >= argc ||
                    (argv[i + 1][0] == '-' && argv[i + 1][1] == '-') ||
                    strcmp(argv[i + 1], "-h") == 0 ||
                    strcmp(argv[i + 1], "-V") == 0)
                    return fail(args, "option --%s needs a value",
                                options[opt].name);
                value = argv[++i];
            }
        } else if (eq) {
            return fail(args, "option --%s takes no value", options[opt].name);
        }

        if (opt == OPT_HELP) {
            args->help = 1;
            return NULL;
        }
        if (opt == OPT_VERSION) {
            args->version = 1;
            return NULL;
        }
        if (opt == OPT_CATALOG) {
            if (*value == '\0')
                return fail(args, "--catalog: empty file name");
            if (args->n_catalogs >= LT_CATALOG_MAX)
                return fail(args, "--catalog given more than %d times",
                            LT_CATALOG_MAX);
            args->catalogs[args->n_catalogs++] = value;
            continue;
        }
        if (seen[opt])
            return fail(args, "option --%s given more than once",
                        options[opt].name);
        seen[opt] = 1;

        switch (opt) {
        case OPT_LENS:
            if (lt_parse_lens_spec(args, value, &args->lens))
                return args->error;
            break;
        case OPT_RAY:
            if (lt_parse_ray_spec(args, value, &args->ray))
                return args->error;
            break;
        case OPT_RAYS:
            if (*value == '\0')
                return fail(args, "--rays: empty file name (use - for "
                                  "standard input)");
            args->rays_file = value;
            break;
        case OPT_DEPTH:
            if (parse_depth(args, value))
                return args->error;
            break;
        case OPT_MODE:
            if (parse_mode(args, value))
                return args->error;
            break;
        case OPT_MEDIUM:
            if (sp_parse_double(value, &args->medium) != 1 ||
                !isfinite(args->medium) || !(args->medium > 0.0))
                return fail(args, "--medium must be a finite index > 0, got "
                                  "'%s'", value);
            break;
        case OPT_BACKWARD:
            args->backward = 1;
            break;
        case OPT_CONE:
            if (parse_vec3(args, "--cone", value, &args->cone_point))
                return args->error;
            args->cone = 1;
            break;
        case OPT_AZIMUTHS: {
            long v;
            if (sp_parse_long(value, 1, LT_AZIMUTHS_MAX, &v) != 1)
                return fail(args, "--azimuths must be an integer from 1 to %d, "
                                  "got '%s'", LT_AZIMUTHS_MAX, value);
            args->azimuths = (int)v;
            break;
        }
        case OPT_LAMBDA:
            if (parse_positive(args, "--lambda", "the wavelength", value,
                               &args->lambda_nm))
                return args->error;
            break;
        }
    }
    if (seen[OPT_CONE] && (seen[OPT_RAY] || seen[OPT_RAYS] || seen[OPT_BACKWARD] ||
                           seen[OPT_MODE]))
        return fail(args, "--cone traces no ray: it takes no --ray, --backward "
                          "or --mode");
    if (!seen[OPT_CONE] && (seen[OPT_AZIMUTHS] || seen[OPT_LAMBDA]))
        return fail(args, "--%s needs --cone",
                    seen[OPT_AZIMUTHS] ? "azimuths" : "lambda");
    if (!seen[OPT_LENS])
        return fail(args, "missing --lens (e.g. --lens "
                          "\"R1=25.8,R2=inf,t=5.3,D=25.4,glass=N-BK7\"; "
                          "try --help)");
    if (seen[OPT_RAY] && seen[OPT_RAYS])
        return fail(args, "give --ray or --rays, not both");
    if (!seen[OPT_RAY] && !seen[OPT_RAYS] && !seen[OPT_CONE])
        return fail(args, "missing --ray (e.g. --ray \"o=0,3,-10 d=0,0,1 "
                          "vp=1,0,0\") or --rays FILE; try --help)");
    args->error[0] = '\0';
    return NULL;
}
