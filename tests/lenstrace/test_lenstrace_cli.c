/* test_lenstrace_cli.c -- runs the built lenstrace binary and checks its
 * contract (docs/interfaces.md, "lenstrace"): JSON Lines
 * with the contract's keys in order, the physics of an axial ray through
 * a plano-convex N-BK7 lens (closed-form normal-incidence Fresnel), the
 * energy bookkeeping, vp=unpolarized halves, --backward, and the error
 * behaviour (exit 2, one stderr line, empty stdout). */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "subprocess.h"

#ifndef LP_BIN_DIR
#error "LP_BIN_DIR must name the directory of the built programs"
#endif
#ifndef LP_TEST_TMP
#define LP_TEST_TMP "."
#endif

static const char *const LENSTRACE = LP_BIN_DIR "/lenstrace";

/* The lens of the contract's example: plano-convex, N-BK7. */
static const char *const LENS = "R1=25.8,R2=inf,t=5.3,D=25.4,glass=N-BK7";
static const double T_MM = 5.3;
/* The helium d line is 587.5618 nm in standard air, the contract's
 * wavelength: lambda=587.5618 is the d line itself, and lambda_vac= takes
 * the vacuum wavelength, 587.5618 * n_air = 587.7247 nm (Edlen 1966
 * standard air, below).  N-BK7's index there comes from its Sellmeier
 * coefficients (nbk7_d(), 1.5168000; the catalog prints n_d 1.51680). */

/* Edlen (1966) standard air at a vacuum wavelength (nm). */
static double air_index(double vac_nm)
{
    double s2 = (1000.0 / vac_nm) * (1000.0 / vac_nm);
    return 1.0 + 1e-8 * (8342.13 + 2406030.0 / (130.0 - s2) + 15997.0 / (38.9 - s2));
}

/* ------------------------------------------------------------------ */
/* Running the program                                                 */
/* ------------------------------------------------------------------ */

typedef struct proc {
    int status;   /* exit status, or 128 + signal, or -1 */
    char *out;    /* stdout, NUL-terminated */
    char *err;    /* stderr */
    char what[512];
} proc;

/* Run lenstrace with the given arguments (NULL-terminated array). */
static proc run_argv(const char *const *args)
{
    proc p;
    tp_result r;

    memset(&p, 0, sizeof p);
    tp_describe(LENSTRACE, args, p.what, sizeof p.what);
    if (tp_run(LENSTRACE, args, NULL, &r) != 0) {
        fprintf(stderr, "%s: %s\n", p.what, r.error);
        exit(1);
    }
    p.status = r.status;
    p.out = r.out;
    p.err = r.err;
    if (p.status == 127)
        fprintf(stderr, "note: could not execute %s\n", LENSTRACE);
    return p;
}

static proc run(const char *first, ...)
{
    const char *args[64];
    size_t n = 0;
    va_list ap;
    va_start(ap, first);
    for (const char *a = first; a && n < 63; a = va_arg(ap, const char *))
        args[n++] = a;
    va_end(ap);
    args[n] = NULL;
    return run_argv(args);
}

static void proc_free(proc *p)
{
    free(p->out);
    free(p->err);
    p->out = p->err = NULL;
}

/* Split text into lines (in place); returns the count. */
static size_t split_lines(char *text, char **lines, size_t max)
{
    size_t n = 0;
    char *p = text;
    while (*p && n < max) {
        char *e = strchr(p, '\n');
        lines[n++] = p;
        if (!e)
            break;
        *e = '\0';
        p = e + 1;
    }
    return n;
}

/* ------------------------------------------------------------------ */
/* A tiny strict JSON validator that also lists the keys of the top     */
/* object (level 0) and of the objects directly inside it (level 1).   */
/* ------------------------------------------------------------------ */

#define MAX_KEYS 24
typedef struct jkeys {
    char k[2][MAX_KEYS][24];
    int n[2];
} jkeys;

static void j_ws(const char **p)
{
    while (**p == ' ' || **p == '\t' || **p == '\n' || **p == '\r')
        (*p)++;
}

static int j_string(const char **p, char *out, size_t outsz)
{
    size_t n = 0;
    if (**p != '"')
        return 0;
    (*p)++;
    while (**p != '"') {
        unsigned char c = (unsigned char)**p;
        if (c == '\0' || c < 0x20)
            return 0;
        if (c == '\\') {
            (*p)++;
            if (!strchr("\"\\/bfnrtu", **p) || **p == '\0')
                return 0;
        }
        if (out && n + 1 < outsz)
            out[n++] = (char)**p;
        (*p)++;
    }
    (*p)++;
    if (out)
        out[n] = '\0';
    return 1;
}

static int is_digit(char c) { return c >= '0' && c <= '9'; }

static int j_number(const char **p)
{
    const char *s = *p;
    if (*s == '-')
        s++;
    if (*s == '0')
        s++;
    else if (*s >= '1' && *s <= '9')
        while (is_digit(*s))
            s++;
    else
        return 0;
    if (*s == '.') {
        s++;
        if (!is_digit(*s))
            return 0;
        while (is_digit(*s))
            s++;
    }
    if (*s == 'e' || *s == 'E') {
        s++;
        if (*s == '+' || *s == '-')
            s++;
        if (!is_digit(*s))
            return 0;
        while (is_digit(*s))
            s++;
    }
    *p = s;
    return 1;
}

static int j_value(const char **p, int level, jkeys *keys)
{
    j_ws(p);
    if (**p == '{') {
        (*p)++;
        j_ws(p);
        if (**p == '}') {
            (*p)++;
            return 1;
        }
        for (;;) {
            char key[24];
            j_ws(p);
            if (!j_string(p, key, sizeof key))
                return 0;
            if (level < 2 && keys->n[level] < MAX_KEYS)
                strcpy(keys->k[level][keys->n[level]++], key);
            j_ws(p);
            if (**p != ':')
                return 0;
            (*p)++;
            if (!j_value(p, level + 1, keys))
                return 0;
            j_ws(p);
            if (**p == ',') {
                (*p)++;
                continue;
            }
            if (**p == '}') {
                (*p)++;
                return 1;
            }
            return 0;
        }
    }
    if (**p == '[') {
        (*p)++;
        j_ws(p);
        if (**p == ']') {
            (*p)++;
            return 1;
        }
        for (;;) {
            /* arrays do not open a key level */
            if (!j_value(p, level + 1, keys))
                return 0;
            j_ws(p);
            if (**p == ',') {
                (*p)++;
                continue;
            }
            if (**p == ']') {
                (*p)++;
                return 1;
            }
            return 0;
        }
    }
    if (**p == '"')
        return j_string(p, NULL, 0);
    if (strncmp(*p, "true", 4) == 0) {
        *p += 4;
        return 1;
    }
    if (strncmp(*p, "false", 5) == 0) {
        *p += 5;
        return 1;
    }
    if (strncmp(*p, "null", 4) == 0) {
        *p += 4;
        return 1;
    }
    return j_number(p);
}

/* 1 if line is exactly one valid JSON object; fills keys. */
static int json_object_line(const char *line, jkeys *keys)
{
    const char *p = line;
    memset(keys, 0, sizeof *keys);
    j_ws(&p);
    if (*p != '{')
        return 0;
    if (!j_value(&p, 0, keys))
        return 0;
    j_ws(&p);
    return *p == '\0';
}

/* ------------------------------------------------------------------ */
/* Field extraction                                                    */
/* ------------------------------------------------------------------ */

static const char *j_find(const char *line, const char *key)
{
    char pat[48];
    const char *at;
    snprintf(pat, sizeof pat, "\"%s\":", key);
    at = strstr(line, pat);
    return at ? at + strlen(pat) : NULL;
}

static int jnum(const char *line, const char *key, double *v)
{
    const char *p = j_find(line, key);
    char *end;
    if (!p)
        return 0;
    *v = strtod(p, &end);
    return end != p;
}

static double jnum_or_nan(const char *line, const char *key)
{
    double v;
    return jnum(line, key, &v) ? v : NAN;
}

static int jvec(const char *line, const char *key, double v[3])
{
    const char *p = j_find(line, key);
    char *end;
    if (!p || *p != '[')
        return 0;
    p++;
    for (int k = 0; k < 3; k++) {
        v[k] = strtod(p, &end);
        if (end == p)
            return 0;
        p = end;
        if (*p != (k < 2 ? ',' : ']'))
            return 0;
        p++;
    }
    return 1;
}

static int jstr(const char *line, const char *key, char *out, size_t n)
{
    const char *p = j_find(line, key);
    size_t i = 0;
    if (!p || *p != '"')
        return 0;
    p++;
    while (*p && *p != '"' && i + 1 < n)
        out[i++] = *p++;
    out[i] = '\0';
    return *p == '"';
}

/* ------------------------------------------------------------------ */
/* Parsed output                                                       */
/* ------------------------------------------------------------------ */

#define MAX_LINES 512

typedef struct rayline {
    const char *text;
    int depth;
    char kind[16];
    double o[3], d[3], vp[3];
    double lambda, I, op, phase;
    int kphi;
    double ch;
    int half;      /* -1 when absent */
    jkeys keys;
} rayline;

typedef struct output {
    rayline rays[MAX_LINES];
    size_t n;
    int have_summary;
    double in, out, absorbed_glass, absorbed_rim, truncated, skipped;
    jkeys summary_keys;
    char *buf;
} output;

static const char *const contract_keys[11] = {
    "depth", "kind", "o", "d", "lambda", "I", "vp", "kphi", "op", "phase",
    "ch"};

/* Parse and check the shape of a successful run's stdout (all lines valid
 * JSON, contract keys first and in order, summary last). */
static void parse_output(const proc *p, output *o, const char *what)
{
    char *lines[MAX_LINES];
    size_t n;

    memset(o, 0, sizeof *o);
    o->buf = malloc(strlen(p->out) + 1);
    if (!o->buf)
        exit(1);
    strcpy(o->buf, p->out);
    CHECK(p->out[0] == '\0' || p->out[strlen(p->out) - 1] == '\n',
          "%s: stdout ends with a newline", what);
    n = split_lines(o->buf, lines, MAX_LINES);
    if (n > 0 && lines[n - 1][0] == '\0')
        n--; /* after the final newline */
    CHECK(n >= 1, "%s: at least the summary line", what);
    for (size_t i = 0; i < n; i++) {
        jkeys keys;
        int valid = json_object_line(lines[i], &keys);
        CHECK(valid, "%s: line %zu is one valid JSON object: %s", what, i + 1,
              lines[i]);
        CHECK(strstr(lines[i], "nan") == NULL &&
                  strstr(lines[i], "inf") == NULL,
              "%s: line %zu has no nan/inf: %s", what, i + 1, lines[i]);
        if (i + 1 == n) {
            /* the summary */
            static const char *const sk[5] = {"in", "out", "absorbed_glass",
                                              "absorbed_rim", "truncated"};
            CHECK(keys.n[0] == 1 && strcmp(keys.k[0][0], "summary") == 0,
                  "%s: the last line is the summary: %s", what, lines[i]);
            CHECK(keys.n[1] >= 5, "%s: summary has >= 5 keys", what);
            for (int k = 0; k < 5 && k < keys.n[1]; k++)
                CHECK(strcmp(keys.k[1][k], sk[k]) == 0,
                      "%s: summary key %d is '%s', want '%s'", what, k + 1,
                      keys.k[1][k], sk[k]);
            o->have_summary = keys.n[0] == 1 &&
                              strcmp(keys.k[0][0], "summary") == 0;
            o->in = jnum_or_nan(lines[i], "in");
            o->out = jnum_or_nan(lines[i], "out");
            o->absorbed_glass = jnum_or_nan(lines[i], "absorbed_glass");
            o->absorbed_rim = jnum_or_nan(lines[i], "absorbed_rim");
            o->truncated = jnum_or_nan(lines[i], "truncated");
            if (!jnum(lines[i], "skipped", &o->skipped))
                o->skipped = 0.0;
            o->summary_keys = keys;
            continue;
        }
        {
            rayline *r = &o->rays[o->n++];
            double v;
            r->text = lines[i];
            r->keys = keys;
            CHECK(keys.n[0] >= 11, "%s: ray line %zu has the 11 contract keys",
                  what, i + 1);
            for (int k = 0; k < 11 && k < keys.n[0]; k++)
                CHECK(strcmp(keys.k[0][k], contract_keys[k]) == 0,
                      "%s: ray line %zu key %d is '%s', want '%s'", what,
                      i + 1, k + 1, keys.k[0][k], contract_keys[k]);
            r->depth = jnum(lines[i], "depth", &v) ? (int)v : -1;
            CHECK(jstr(lines[i], "kind", r->kind, sizeof r->kind) &&
                      (strcmp(r->kind, "reflect") == 0 ||
                       strcmp(r->kind, "transmit") == 0),
                  "%s: line %zu kind is reflect or transmit", what, i + 1);
            CHECK(jvec(lines[i], "o", r->o) && jvec(lines[i], "d", r->d) &&
                      jvec(lines[i], "vp", r->vp),
                  "%s: line %zu o, d, vp are [x,y,z]", what, i + 1);
            r->lambda = jnum_or_nan(lines[i], "lambda");
            r->I = jnum_or_nan(lines[i], "I");
            r->op = jnum_or_nan(lines[i], "op");
            r->phase = jnum_or_nan(lines[i], "phase");
            r->kphi = jnum(lines[i], "kphi", &v) ? (int)v : -999;
            r->ch = jnum_or_nan(lines[i], "ch");
            r->half = jnum(lines[i], "half", &v) ? (int)v : -1;
            CHECK(r->depth >= 1, "%s: line %zu depth >= 1", what, i + 1);
            CHECK(r->I >= 0.0, "%s: line %zu I >= 0", what, i + 1);
            CHECK_ABS(r->d[0] * r->d[0] + r->d[1] * r->d[1] + r->d[2] * r->d[2],
                      1.0, 1e-12, "%s: line %zu |d|^2", what, i + 1);
            CHECK_ABS(r->vp[0] * r->vp[0] + r->vp[1] * r->vp[1] +
                          r->vp[2] * r->vp[2],
                      1.0, 1e-12, "%s: line %zu |vp|^2", what, i + 1);
            CHECK_ABS(r->vp[0] * r->d[0] + r->vp[1] * r->d[1] +
                          r->vp[2] * r->d[2],
                      0.0, 1e-12, "%s: line %zu vp.d", what, i + 1);
        }
    }
    CHECK(o->have_summary, "%s: a summary line", what);
}

static void check_balance(const output *o, const char *what)
{
    double sum_out = 0.0;
    double rhs = o->out + o->absorbed_glass + o->absorbed_rim + o->truncated +
                 o->skipped;
    CHECK_ABS(rhs, o->in, 1e-12 * (o->in > 1.0 ? o->in : 1.0),
              "%s: in = out + absorbed_glass + absorbed_rim + truncated + "
              "skipped", what);
    for (size_t i = 0; i < o->n; i++)
        sum_out += o->rays[i].I;
    CHECK_ABS(sum_out, o->out, 1e-12 * (o->in > 1.0 ? o->in : 1.0),
              "%s: sum of printed I = summary out", what);
}

static const rayline *find_ray(const output *o, int depth, const char *kind,
                               int half)
{
    for (size_t i = 0; i < o->n; i++)
        if (o->rays[i].depth == depth && strcmp(o->rays[i].kind, kind) == 0 &&
            (half < 0 || o->rays[i].half == half))
            return &o->rays[i];
    return NULL;
}

static int key_index(const jkeys *k, const char *key)
{
    for (int i = 0; i < k->n[0]; i++)
        if (strcmp(k->k[0][i], key) == 0)
            return i;
    return -1;
}

static void expect_success(const proc *p, const char *what)
{
    CHECK(p->status == 0, "%s: exit status %d, want 0 (stderr: %s) [%s]",
          what, p->status, p->err, p->what);
    CHECK(p->err[0] == '\0', "%s: stderr empty, got: %s", what, p->err);
}

/* ------------------------------------------------------------------ */
/* The tests                                                           */
/* ------------------------------------------------------------------ */

static double fresnel_normal(double n1, double n2)
{
    double r = (n2 - n1) / (n2 + n1);
    return r * r;
}


/* N-BK7 from the catalog's data, written here: Sellmeier (SCHOTT, C in
 * um^2) and the internal transmittance tau_i at 10 mm (SCHOTT data sheet)
 * around the wavelengths used, interpolated linearly in ln(tau) as the
 * catalog's documentation says. */
static double nbk7_index(double air_nm)
{
    static const double B[3] = {1.03961212, 0.231792344, 1.01046945};
    static const double C[3] = {0.00600069867, 0.0200179144, 103.560653};
    double l2 = (air_nm / 1000.0) * (air_nm / 1000.0), n2 = 1.0;
    for (int k = 0; k < 3; k++)
        n2 += B[k] * l2 / (l2 - C[k]);
    return sqrt(n2);
}

static double nbk7_tau10(double air_nm)
{
    static const double tab[][2] = {{334, 0.905}, {350, 0.967}, {365, 0.988}, {370, 0.991},
                                    {380, 0.993}, {390, 0.996}, {400, 0.997}, {580, 0.998},
                                    {620, 0.998}};
    for (size_t i = 0; i + 1 < sizeof tab / sizeof tab[0]; i++)
        if (air_nm >= tab[i][0] && air_nm <= tab[i + 1][0]) {
            double t = (air_nm - tab[i][0]) / (tab[i + 1][0] - tab[i][0]);
            return exp((1 - t) * log(tab[i][1]) + t * log(tab[i + 1][1]));
        }
    return NAN;
}

/* The axial depth-2 transmit of LENS (two normal-incidence refractions,
 * T_MM of glass) for a ray of the given lambda= (in standard air, as
 * lenstrace traces it).  Rounding only: relative tolerance 1e-14,
 * measured <= 2.2e-16. */
static double nbk7_depth2(double air)
{
    double n = nbk7_index(air);
    double r = (n - 1) / (n + 1), T = 1 - r * r;
    return T * T * pow(nbk7_tau10(air), T_MM / 10.0);
}

/* N-BK7 at the d line (lambda=587.5618) */
static double nbk7_d(void) { return nbk7_index(587.5618); }

static const char *const AXIAL =
    "o=0,0,-10 d=0,0,1 lambda=587.5618 vp=1,0,0 I=1 ch=7";

/* Forward, axial, polarized: physics and shape.  Keeps the depth-2
 * transmit intensity for the backward (reciprocity) check. */
static double test_forward_axial(void)
{
    static output o;
    const double R = fresnel_normal(1.0, nbk7_d());
    const rayline *r1, *r2;
    double i2 = NAN;
    proc p = run("--lens", LENS, "--ray", AXIAL, (const char *)NULL);

    expect_success(&p, "forward axial");
    parse_output(&p, &o, "forward axial");
    CHECK(o.n >= 2, "forward axial: at least 2 ray lines, got %zu", o.n);
    if (o.n >= 1) {
        r1 = &o.rays[0];
        CHECK(r1->depth == 1 && strcmp(r1->kind, "reflect") == 0,
              "forward axial: the first line is the depth-1 reflection: %s",
              r1->text);
        CHECK_REL(r1->I, fresnel_normal(1.0, nbk7_d()),
                  1e-14, "depth-1 reflect I = ((n-1)/(n+1))^2, n from Sellmeier");
        CHECK_ABS(r1->d[2], -1.0, 1e-12, "depth-1 reflect d.z");
        CHECK_ABS(r1->o[0], 0.0, 1e-9, "depth-1 reflect o.x");
        CHECK_ABS(r1->o[1], 0.0, 1e-9, "depth-1 reflect o.y");
        CHECK_ABS(r1->o[2], 0.0, 1e-9, "depth-1 reflect o.z (front vertex)");
        CHECK_ABS(fabs(r1->vp[0]), 1.0, 1e-12, "depth-1 reflect |vp.x|");
        CHECK_ABS(r1->op, 0.0, 1e-12, "depth-1 reflect op (never inside)");
        CHECK_ABS(r1->phase, 0.0, 1e-12, "depth-1 reflect phase");
        /* External reflection at normal incidence (n1 < n2) reverses the
           field: one phase jump by pi. */
        CHECK(r1->kphi == 1, "depth-1 external reflection kphi = 1, got %d",
              r1->kphi);
    }
    for (size_t i = 0; i < o.n; i++) {
        CHECK(o.rays[i].depth <= 5, "default depth 5: line %zu depth %d", i,
              o.rays[i].depth);
        CHECK(o.rays[i].lambda == 587.5618, "lambda copied exactly: %.17g",
              o.rays[i].lambda);
        CHECK(o.rays[i].ch == 7.0, "ch copied: %g", o.rays[i].ch);
        CHECK(o.rays[i].half == -1, "no half key for a polarized ray");
        CHECK(o.rays[i].kphi >= 0, "kphi is a count");
    }
    r2 = find_ray(&o, 2, "transmit", -1);
    CHECK(r2 != NULL, "forward axial: a depth-2 transmit ray");
    if (r2) {
        CHECK_ABS(r2->d[0], 0.0, 1e-12, "depth-2 transmit d.x");
        CHECK_ABS(r2->d[1], 0.0, 1e-12, "depth-2 transmit d.y");
        CHECK_ABS(r2->d[2], 1.0, 1e-12, "depth-2 transmit d.z");
        CHECK_ABS(r2->o[0], 0.0, 1e-9, "depth-2 transmit o.x");
        CHECK_ABS(r2->o[1], 0.0, 1e-9, "depth-2 transmit o.y");
        CHECK_ABS(r2->o[2], T_MM, 1e-9, "depth-2 transmit o.z = t");
        CHECK_REL(r2->op, nbk7_d() * T_MM, 1e-14,
                  "depth-2 transmit op = n*t (air-relative optical path)");
        /* Two refractions keep the phase and the field direction. */
        CHECK(r2->kphi == 0, "depth-2 transmit kphi 0, got %d", r2->kphi);
        CHECK_ABS(r2->phase, 0.0, 1e-12, "depth-2 transmit phase");
        CHECK_ABS(r2->vp[0], 1.0, 1e-9, "depth-2 transmit vp.x");
        /* (1-R)^2 times the internal transmittance of 5.3 mm of N-BK7:
           tau_i(10 mm) = 0.998 at 580 and 620 nm (catalog data), so
           0.998^0.53 = 1 - 1.06e-3; checked with R and tau computed here
           in nbk7_depth2() (measured 2e-16; see there). */
        CHECK_REL(r2->I, nbk7_depth2(587.5618), 1e-14,
                  "depth-2 transmit I = (1-R)^2 tau^(t/10 mm)");
        CHECK(fabs(r2->I - (1.0 - R) * (1.0 - R)) > 1e-3 * (1.0 - R) * (1.0 - R),
              "depth-2 transmit I: absorption is there");
        i2 = r2->I;
    }
    CHECK_REL(o.in, 1.0, 1e-12, "forward axial: summary in == 1");
    check_balance(&o, "forward axial");
    CHECK(o.summary_keys.n[1] < 6 ||
              strcmp(o.summary_keys.k[1][5], "skipped") == 0 ||
              strcmp(o.summary_keys.k[1][5], "warnings") == 0,
          "summary extra keys after the contract's");
    {
        /* The same run with --opt=VALUE gives the same bytes. */
        proc q = run("--lens=R1=25.8,R2=inf,t=5.3,D=25.4,glass=N-BK7",
                     "--ray=o=0,0,-10 d=0,0,1 lambda=587.5618 vp=1,0,0 I=1 ch=7",
                     "--depth=5", "--mode=polarized", "--medium=1",
                     (const char *)NULL);
        expect_success(&q, "--opt=VALUE form");
        CHECK(strcmp(q.out, p.out) == 0,
              "--opt=VALUE and --opt VALUE give the same output");
        proc_free(&q);
    }
    free(o.buf);
    proc_free(&p);
    return i2;
}

/* Absorption where the catalog's tau varies: the axial depth-2 transmit
 * at three wavelengths (588 nm: tau 0.998 flat; 342 and 375 nm: between
 * table points 0.905/0.967 and 0.991/0.993, where a wrong interpolation
 * or a wrong thickness shows).  Measured worst 4.4e-16 relative. */
static void test_absorption(void)
{
    static output o;
    const double lambdas[] = {587.5618, 342.2, 375.1};
    double worst = 0;
    for (size_t k = 0; k < sizeof lambdas / sizeof lambdas[0]; k++) {
        char ray[96], what[48];
        snprintf(ray, sizeof ray, "o=0,0,-10 d=0,0,1 lambda=%.17g vp=1,0,0", lambdas[k]);
        snprintf(what, sizeof what, "absorption at lambda=%g", lambdas[k]);
        proc p = run("--lens", LENS, "--ray", ray, "--depth", "2", (const char *)NULL);
        expect_success(&p, what);
        parse_output(&p, &o, what);
        const rayline *r2 = find_ray(&o, 2, "transmit", -1);
        CHECK(r2 != NULL, "%s: a depth-2 transmit ray", what);
        if (r2) {
            double want = nbk7_depth2(lambdas[k]);
            CHECK_REL(r2->I, want, 1e-14, "%s: I = (1-R)^2 tau^(t/10 mm)", what);
            worst = fmax(worst, fabs(r2->I / want - 1));
        }
        free(o.buf);
        proc_free(&p);
    }
    printf("absorption: worst depth-2 transmit vs catalog data %.3g (relative)\n", worst);
}

static void test_depth_one(void)
{
    static output o;
    proc p = run("--lens", LENS, "--ray", AXIAL, "--depth", "1",
                 (const char *)NULL);
    const rayline *r1;
    expect_success(&p, "depth 1");
    parse_output(&p, &o, "depth 1");
    for (size_t i = 0; i < o.n; i++)
        CHECK(o.rays[i].depth == 1, "--depth 1: only depth-1 rays, got %d",
              o.rays[i].depth);
    r1 = find_ray(&o, 1, "reflect", -1);
    CHECK(r1 != NULL, "--depth 1: the external reflection");
    if (r1)
        CHECK_REL(o.truncated, 1.0 - r1->I, 1e-12,
                  "--depth 1: truncated = 1 - R (the refracted ray)");
    check_balance(&o, "depth 1");
    free(o.buf);
    proc_free(&p);
}

static void test_unpolarized(void)
{
    static output o;
    const double R = fresnel_normal(1.0, nbk7_d());
    proc p = run("--lens", LENS, "--ray",
                 "o=0,0,-10 d=0,0,1 lambda=587.5618 vp=unpolarized ch=2",
                 (const char *)NULL);
    size_t n0 = 0, n1 = 0;
    int order_ok = 1, seen1 = 0;

    expect_success(&p, "unpolarized");
    parse_output(&p, &o, "unpolarized");
    for (size_t i = 0; i < o.n; i++) {
        const rayline *r = &o.rays[i];
        int hk = key_index(&r->keys, "half");
        CHECK(r->half == 0 || r->half == 1, "unpolarized: half key 0 or 1: %s",
              r->text);
        CHECK(hk == r->keys.n[0] - 1 && hk >= 11,
              "unpolarized: half is the last key, after the contract's: %s",
              r->text);
        if (r->half == 1)
            seen1 = 1, n1++;
        if (r->half == 0) {
            n0++;
            if (seen1)
                order_ok = 0;
        }
    }
    CHECK(order_ok, "unpolarized: all half-0 rays before the half-1 rays");
    CHECK(n0 >= 2 && n0 == n1,
          "unpolarized axial: both halves give the same tree (%zu, %zu)", n0,
          n1);
    for (int h = 0; h < 2; h++) {
        const rayline *r1 = find_ray(&o, 1, "reflect", h);
        CHECK(r1 != NULL, "unpolarized: half %d depth-1 reflection", h);
        if (r1)
            CHECK_REL(r1->I, R / 2, 1e-14, "unpolarized half %d reflect = R/2",
                      h);
    }
    {
        const rayline *a = find_ray(&o, 2, "transmit", 0);
        const rayline *b = find_ray(&o, 2, "transmit", 1);
        if (a && b)
            CHECK_ABS(a->vp[0] * b->vp[0] + a->vp[1] * b->vp[1] +
                          a->vp[2] * b->vp[2],
                      0.0, 1e-9, "unpolarized: the halves are orthogonal");
    }
    CHECK_REL(o.in, 1.0, 1e-12, "unpolarized: summary in == 1 (both halves)");
    check_balance(&o, "unpolarized");
    {
        /* vp omitted: unpolarized by default. */
        proc q = run("--lens", LENS, "--ray",
                     "o=0,0,-10 d=0,0,1 lambda=587.5618 ch=2",
                     (const char *)NULL);
        expect_success(&q, "vp omitted");
        CHECK(strcmp(q.out, p.out) == 0, "vp omitted = vp=unpolarized");
        proc_free(&q);
    }
    free(o.buf);
    proc_free(&p);
}

static void test_backward(double forward_i2)
{
    static output o;
    const double R = fresnel_normal(1.0, nbk7_d());
    proc p = run("--lens", LENS, "--ray",
                 "o=0,0,-10 d=0,0,1 lambda=587.5618 vp=1,0,0 I=1 ch=3",
                 "--backward", (const char *)NULL);
    const rayline *r1, *r2;

    expect_success(&p, "backward");
    parse_output(&p, &o, "backward");
    CHECK(o.n >= 2, "backward: gathered rays printed, got %zu", o.n);
    for (size_t i = 0; i < o.n; i++) {
        const rayline *r = &o.rays[i];
        double qo[3], qd[3];
        CHECK(key_index(&r->keys, "query_o") == 11 &&
                  key_index(&r->keys, "query_d") == 12,
              "backward: query_o, query_d right after the contract keys: %s",
              r->text);
        CHECK(jvec(r->text, "query_o", qo) && jvec(r->text, "query_d", qd),
              "backward: query_o/query_d are vectors");
        CHECK_ABS(r->d[2], -1.0, 1e-12, "backward: gathered d = -view dir");
        CHECK_ABS(r->o[2], 0.0, 1e-9, "backward: gathered o = entry point");
        CHECK(r->ch == 3.0, "backward: ch of the answer copied");
        CHECK(r->half == -1, "backward polarized: no half key");
    }
    r1 = find_ray(&o, 1, "reflect", -1);
    CHECK(r1 != NULL, "backward: a depth-1 reflect");
    if (r1)
        CHECK_REL(r1->I, R, 1e-14, "backward depth-1 reflect I = R");
    r2 = find_ray(&o, 2, "transmit", -1);
    CHECK(r2 != NULL, "backward: a depth-2 transmit");
    if (r2) {
        double qd[3];
        CHECK(jvec(r2->text, "query_d", qd) && fabs(qd[2] - 1.0) < 1e-12,
              "backward: the depth-2 query leaves along +z");
        CHECK_REL(r2->op, nbk7_d() * T_MM, 1e-14,
                  "backward depth-2 op = n*t");
        if (isfinite(forward_i2))
            CHECK_REL(r2->I, forward_i2, 1e-9,
                      "reciprocity: backward depth-2 I = forward depth-2 I");
    }
    check_balance(&o, "backward");
    free(o.buf);
    proc_free(&p);

    p = run("--lens", LENS, "--ray", "o=0,0,-10 d=0,0,1 vp=unpolarized",
            "--backward", (const char *)NULL);
    expect_success(&p, "backward unpolarized");
    parse_output(&p, &o, "backward unpolarized");
    CHECK(o.n >= 4, "backward unpolarized: rays of two halves");
    for (size_t i = 0; i < o.n; i++) {
        const rayline *r = &o.rays[i];
        CHECK(r->half == 0 || r->half == 1, "backward unpolarized: half key");
        CHECK(key_index(&r->keys, "half") == r->keys.n[0] - 1,
              "backward unpolarized: half is the last key");
        CHECK(key_index(&r->keys, "query_o") == 11,
              "backward unpolarized: query_o after the contract keys");
    }
    check_balance(&o, "backward unpolarized");
    free(o.buf);
    proc_free(&p);
}

static void test_modes_and_medium(void)
{
    static output o;
    /* Off axis, where the three models differ: a ray parallel to the axis
     * at y = 10 mm meets the front sphere (R1 = 25.8) at cos i =
     * sqrt(R1^2 - 100) / R1, 22.8 degrees.  A constant index keeps the
     * wavelength out of it.  vp = x is s-polarized (the plane of
     * incidence is y-z), vp = y p-polarized; fresnel gives (Rs + Rp)/2,
     * schlick R0 + (1 - R0)(1 - cos i)^5: 0.0519 / 0.0333 / 0.0426 /
     * 0.0422, each computed here.  Rounding only (the hit point's
     * cos i, a few ulps): tolerance 1e-13 relative, measured 4e-16. */
    const double n = 1.5168, Rc = 25.8, y = 10.0;
    const double ci = sqrt(Rc * Rc - y * y) / Rc, st = sqrt(1 - ci * ci) / n,
                 ct = sqrt(1 - st * st);
    const double rs = (ci - n * ct) / (ci + n * ct), rp = (n * ci - ct) / (n * ci + ct);
    const double r0 = fresnel_normal(1.0, n);
    const struct { const char *mode, *vp; double R; } cases[] = {
        {"polarized", "vp=1,0,0", rs * rs},
        {"polarized", "vp=0,1,0", rp * rp},
        {"fresnel", "vp=1,0,0", 0.5 * (rs * rs + rp * rp)},
        {"fresnel", "vp=unpolarized", 0.5 * (rs * rs + rp * rp)},
        {"schlick", "vp=1,0,0", r0 + (1 - r0) * pow(1 - ci, 5)},
    };
    for (size_t m = 0; m < sizeof cases / sizeof cases[0]; m++) {
        char ray[128], what[64];
        snprintf(ray, sizeof ray, "o=0,%g,-10 d=0,0,1 lambda=587.56 %s", y, cases[m].vp);
        snprintf(what, sizeof what, "--mode %s %s", cases[m].mode, cases[m].vp);
        proc p = run("--lens", "R1=25.8,R2=inf,t=5.3,D=25.4,glass=n=1.5168", "--ray", ray,
                     "--mode", cases[m].mode, "--depth", "1", (const char *)NULL);
        expect_success(&p, what);
        parse_output(&p, &o, what);
        double sum = 0;
        int nr = 0;
        for (size_t i = 0; i < o.n; i++)
            if (o.rays[i].depth == 1 && strcmp(o.rays[i].kind, "reflect") == 0) {
                sum += o.rays[i].I;
                nr++;
            }
        CHECK(nr >= 1, "%s: a depth-1 reflection", what);
        CHECK_REL(sum, cases[m].R, 1e-13, "%s: off-axis R at 22.8 degrees", what);
        check_balance(&o, what);
        free(o.buf);
        proc_free(&p);
    }
    {
        /* A constant glass in water: R = ((1.5-1.333)/(1.5+1.333))^2. */
        proc p = run("--lens", "R1=25.8,R2=inf,t=5.3,D=25.4,glass=n=1.5",
                     "--ray", AXIAL, "--medium", "1.333", (const char *)NULL);
        proc q = run("--lens", "R1=25.8, R2=inf, t=5.3, D=25.4, n=1.5",
                     "--ray", AXIAL, "--medium", "1.333", (const char *)NULL);
        const rayline *r1, *r2;
        expect_success(&p, "medium");
        expect_success(&q, "n= key");
        CHECK(strcmp(p.out, q.out) == 0, "glass=n=1.5 and n=1.5 agree");
        parse_output(&p, &o, "medium");
        r1 = find_ray(&o, 1, "reflect", -1);
        CHECK(r1 != NULL, "medium: a depth-1 reflection");
        if (r1)
            CHECK_REL(r1->I, fresnel_normal(1.333, 1.5), 1e-12,
                      "medium 1.333, n 1.5: R");
        r2 = find_ray(&o, 2, "transmit", -1);
        if (r2)
            CHECK_REL(r2->op, 1.5 * T_MM, 1e-12,
                      "constant glass op = n*t");
        check_balance(&o, "medium");
        free(o.buf);
        proc_free(&p);
        proc_free(&q);
    }
}

static void test_miss(void)
{
    static output o;
    proc p = run("--lens", LENS, "--ray", "o=100,0,-10 d=0,0,1 vp=0,1,0",
                 (const char *)NULL);
    expect_success(&p, "miss");
    parse_output(&p, &o, "miss");
    CHECK(o.n == 0, "a missing ray prints no ray lines (%zu)", o.n);
    CHECK(o.in == 0.0 && o.out == 0.0 && o.absorbed_glass == 0.0 &&
              o.absorbed_rim == 0.0 && o.truncated == 0.0,
          "a missing ray: summary of zeros");
    free(o.buf);
    proc_free(&p);
}

static void test_catalog(void)
{
    static output o;
    const char *path = LP_TEST_TMP "/test_lenstrace_cli.agf";
    FILE *f = fopen(path, "w");
    CHECK(f != NULL, "write %s", path);
    if (!f)
        return;
    /* N-BK7 under another name, Zemax AGF Sellmeier 1 (K1 L1 K2 L2 K3 L3). */
    fputs("CC lenstrace test catalog\n"
          "NM MY-BK7 2 517642 1.5168 64.17 0 0 0\n"
          "CD 1.03961212 6.00069867E-03 0.231792344 2.00179144E-02 "
          "1.01046945 1.03560653E+02 0 0 0 0\n"
          "LD 0.3 2.5\n",
          f);
    fclose(f);
    {
        proc p = run("--catalog", path, "--lens",
                     "R1=25.8,R2=inf,t=5.3,D=25.4,glass=MY-BK7", "--ray",
                     AXIAL, (const char *)NULL);
        const rayline *r1;
        expect_success(&p, "catalog");
        parse_output(&p, &o, "catalog");
        r1 = find_ray(&o, 1, "reflect", -1);
        CHECK(r1 != NULL, "catalog: a depth-1 reflection");
        if (r1)
            CHECK_REL(r1->I, fresnel_normal(1.0, nbk7_d()), 1e-14,
                      "catalog glass MY-BK7: R");
        free(o.buf);
        proc_free(&p);
    }
    remove(path);
}

static void test_help_version(void)
{
    proc p = run("--help", (const char *)NULL);
    CHECK(p.status == 0, "--help exits 0 (%d)", p.status);
    CHECK(strstr(p.out, "--lens") && strstr(p.out, "--backward") &&
              strstr(p.out, "unpolarized"),
          "--help prints the usage on stdout");
    CHECK(p.err[0] == '\0', "--help: stderr empty");
    proc_free(&p);
    p = run("--version", (const char *)NULL);
    CHECK(p.status == 0 && strstr(p.out, "lenstrace") != NULL,
          "--version exits 0 and names the program");
    proc_free(&p);
}

/* Bad input: exit 2, nothing on stdout, ONE line on stderr starting with
 * "lenstrace: " that mentions `names` (when non-NULL). */
static void expect_error(const char *names, const char *what,
                         const char *const *args)
{
    proc p = run_argv(args);
    const char *nl = strchr(p.err, '\n');
    CHECK(p.status == 2, "%s: exit status %d, want 2 [%s]", what, p.status,
          p.what);
    CHECK(p.out[0] == '\0', "%s: stdout empty, got: %.200s", what, p.out);
    CHECK(strncmp(p.err, "lenstrace: ", 11) == 0 && nl && nl[1] == '\0' &&
              strlen(p.err) > 20,
          "%s: exactly one line 'lenstrace: <message>' on stderr, got: %s",
          what, p.err);
    if (names)
        CHECK(strstr(p.err, names) != NULL, "%s: the message names '%s': %s",
              what, names, p.err);
    proc_free(&p);
}

#define BAD(names, what, ...)                                                 \
    do {                                                                      \
        const char *const a_[] = {__VA_ARGS__, NULL};                         \
        expect_error(names, what, a_);                                        \
    } while (0)

/* Write text to path; exits on failure (the test cannot go on). */
static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f || fputs(text, f) == EOF || fclose(f) != 0) {
        fprintf(stderr, "cannot write %s\n", path);
        exit(1);
    }
}

/* The output of one --ray run with ,"ray":k before the last '}' of each
 * line, appended to buf. */
static void append_indexed(char *buf, size_t cap, const char *out, int k)
{
    const char *p = out;
    while (*p) {
        const char *nl = strchr(p, '\n');
        size_t len = nl ? (size_t)(nl - p) : strlen(p);
        size_t used = strlen(buf);
        if (len > 0 && p[len - 1] == '}')
            snprintf(buf + used, cap - used, "%.*s,\"ray\":%d}\n",
                     (int)(len - 1), p, k);
        p += len + (nl ? 1 : 0);
    }
}

/* --rays FILE: the rays of the file, in order, each exactly as --ray gives
 * it, with its index on every line; a bad line or a ray born inside the
 * glass fails the whole run naming FILE:LINE. */
static void test_rays_file(void)
{
    static char want[1 << 16];
    const char *path = LP_TEST_TMP "/test_lenstrace_cli.rays";
    const char *bad = LP_TEST_TMP "/test_lenstrace_cli_bad.rays";
    const char *r0 = "o=0,0,-10 d=0,0,1 lambda=587.5618 vp=1,0,0 I=1 ch=7";
    const char *r1 = "o=0,3,-10 d=0,0.1,1 lambda_vac=500 vp=unpolarized ch=2";
    char text[512];
    proc p, q0, q1;

    snprintf(text, sizeof text, "# a fan of two rays\n%s\n\n   %s\r\n", r0, r1);
    write_text(path, text);
    p = run("--lens", LENS, "--rays", path, (const char *)NULL);
    q0 = run("--lens", LENS, "--ray", r0, (const char *)NULL);
    q1 = run("--lens", LENS, "--ray", r1, (const char *)NULL);
    expect_success(&p, "--rays");
    expect_success(&q0, "--ray r0");
    expect_success(&q1, "--ray r1");
    want[0] = '\0';
    append_indexed(want, sizeof want, q0.out, 0);
    append_indexed(want, sizeof want, q1.out, 1);
    CHECK(strlen(q0.out) > 100 && strcmp(p.out, want) == 0,
          "--rays: each ray's lines as --ray gives them, with \"ray\":k:\n"
          "got:\n%.600s\nwant:\n%.600s", p.out, want);
    proc_free(&p);
    proc_free(&q0);
    proc_free(&q1);

    snprintf(text, sizeof text, "%s\n%s\nthis is no ray\n", r0, r1);
    write_text(bad, text);
    BAD("_bad.rays:3", "--rays: a bad line", "--lens", LENS, "--rays", bad);
    snprintf(text, sizeof text, "%s\no=0,0,1 d=0,0,1\n", r0);
    write_text(bad, text);
    BAD("_bad.rays:2: the origin 0,0,1 lies inside the glass",
        "--rays: an origin inside the glass", "--lens", LENS, "--rays", bad);
    BAD("inside the glass", "--ray: an origin inside the glass", "--lens",
        LENS, "--ray", "o=0,0,2.5 d=1,0,0");
    BAD("inside the glass", "--backward: an origin inside the glass",
        "--lens", LENS, "--ray", "o=0,1,2.5 d=0,0,1", "--backward");
    BAD("not both", "--ray and --rays", "--lens", LENS, "--ray", r0,
        "--rays", path);
    BAD("<stdin> holds no ray spec", "--rays - on an empty standard input",
        "--lens", LENS, "--rays", "-");
    BAD("no-such.rays", "--rays: a missing file", "--lens", LENS, "--rays",
        LP_TEST_TMP "/no-such.rays");
}

/* lambda= is in standard air, lambda_vac= in vacuum: the same light given
 * both ways traces the same, and lambda is always printed in air. */
static void test_wavelength_convention(void)
{
    static output o;
    const double vac = 587.7247;
    const double air = vac / air_index(vac);
    proc p = run("--lens", LENS, "--ray",
                 "o=0,0,-10 d=0,0,1 lambda_vac=587.7247 vp=1,0,0 I=1 ch=7",
                 (const char *)NULL);
    const rayline *r2;
    expect_success(&p, "lambda_vac");
    parse_output(&p, &o, "lambda_vac");
    for (size_t i = 0; i < o.n; i++)
        /* Edlen's formula written here against the library's: the two
           agree to rounding (measured 0 difference). */
        CHECK_REL(o.rays[i].lambda, air, 1e-15,
                  "lambda_vac=587.7247: printed lambda is in air (%.17g)",
                  o.rays[i].lambda);
    r2 = find_ray(&o, 2, "transmit", -1);
    CHECK(r2 != NULL, "lambda_vac: a depth-2 transmit ray");
    if (r2)
        /* Traced at 587.7247 / n_air: Sellmeier there, rounding only. */
        CHECK_REL(r2->op, nbk7_index(air) * T_MM, 1e-14,
                  "lambda_vac: op = n(lambda_vac / n_air) * t");
    free(o.buf);
    proc_free(&p);
    BAD("not both", "lambda and lambda_vac", "--lens", LENS, "--ray",
        "o=0,0,-10 d=0,0,1 lambda=587.56 lambda_vac=587.72");
    BAD("lambda_vac", "lambda_vac below Edlen's range", "--lens", LENS,
        "--ray", "o=0,0,-10 d=0,0,1 lambda_vac=100");
}

static void test_errors(void)
{
    const char *L = LENS;
    const char *Y = AXIAL;
    BAD("nan", "NaN in o", "--lens", L, "--ray", "o=0,nan,-10 d=0,0,1");
    BAD("topaz", "unknown crystal", "--lens", "R1=0,R2=0,t=1,D=10,crystal=topaz", "--ray", Y);
    BAD("not both", "glass and crystal", "--lens", "R1=0,R2=0,t=1,D=10,glass=N-BK7,no=1.6,ne=1.5",
        "--ray", Y);
    BAD("ne", "no without ne", "--lens", "R1=0,R2=0,t=1,D=10,no=1.6", "--ray", Y);
    BAD("axis", "zero optic axis", "--lens", "R1=0,R2=0,t=1,D=10,crystal=quartz,axis=0:0:0",
        "--ray", Y);
    BAD("axis", "axis without a crystal", "--lens", "R1=0,R2=0,t=1,D=10,glass=N-BK7,axis=0:0:1",
        "--ray", Y);
    BAD("d", "zero direction", "--lens", L, "--ray", "o=0,0,-10 d=0,0,0");
    BAD(NULL, "impossible lens D=60 R1=25.8", "--lens",
        "R1=25.8,R2=inf,t=5.3,D=60,glass=N-BK7", "--ray", Y);
    BAD("NOSUCHGLASS", "unknown glass", "--lens",
        "R1=25.8,R2=inf,t=5.3,D=25.4,glass=NOSUCHGLASS", "--ray", Y);
    BAD("X", "unknown key in --lens", "--lens",
        "R1=25.8,R2=inf,t=5.3,D=25.4,glass=N-BK7,X=1", "--ray", Y);
    BAD("foo", "unknown key in --ray", "--lens", L, "--ray",
        "o=0,0,-10 d=0,0,1 foo=1");
    BAD("--frobnicate", "unknown option", "--lens", L, "--ray", Y,
        "--frobnicate");
    BAD("--lens", "missing --lens", "--ray", Y);
    BAD("--ray", "missing --ray", "--lens", L);
    BAD("depth", "depth 0", "--lens", L, "--ray", Y, "--depth", "0");
    BAD("depth", "depth 65", "--lens", L, "--ray", Y, "--depth=65");
    BAD("depth", "depth 2.5", "--lens", L, "--ray", Y, "--depth", "2.5");
    BAD("foo", "mode foo", "--lens", L, "--ray", Y, "--mode", "foo");
    BAD("R1", "duplicate key", "--lens",
        "R1=25.8,R1=20,R2=inf,t=5.3,D=25.4,glass=N-BK7", "--ray", Y);
    BAD("D", "missing key D", "--lens", "R1=25.8,R2=inf,t=5.3,glass=N-BK7",
        "--ray", Y);
    BAD("glass", "missing glass", "--lens", "R1=25.8,R2=inf,t=5.3,D=25.4",
        "--ray", Y);
    BAD("t", "non-numeric t", "--lens",
        "R1=25.8,R2=inf,t=abc,D=25.4,glass=N-BK7", "--ray", Y);
    BAD("R1", "NaN radius", "--lens",
        "R1=nan,R2=inf,t=5.3,D=25.4,glass=N-BK7", "--ray", Y);
    BAD("D", "infinite diameter", "--lens",
        "R1=25.8,R2=inf,t=5.3,D=inf,glass=N-BK7", "--ray", Y);
    BAD("vp", "vp parallel to d", "--lens", L, "--ray",
        "o=0,0,-10 d=0,0,1 vp=0,0,2");
    BAD("vp", "vp zero", "--lens", L, "--ray", "o=0,0,-10 d=0,0,1 vp=0,0,0");
    BAD("ch", "negative ch", "--lens", L, "--ray", "o=0,0,-10 d=0,0,1 ch=-1");
    BAD("lambda", "lambda 0", "--lens", L, "--ray",
        "o=0,0,-10 d=0,0,1 lambda=0");
    BAD("I", "negative I", "--lens", L, "--ray", "o=0,0,-10 d=0,0,1 I=-1");
    BAD("o", "o with two components", "--lens", L, "--ray",
        "o=0,0 d=0,0,1");
    BAD("medium", "medium 0", "--lens", L, "--ray", Y, "--medium", "0");
    BAD("--lens", "option without its value", "--ray", Y, "--lens");
    BAD("stray", "positional argument", "--lens", L, "--ray", Y, "stray");
    BAD("--backward", "flag with a value", "--lens", L, "--ray", Y,
        "--backward=1");
    BAD(NULL, "missing catalog file", "--lens", L, "--ray", Y, "--catalog",
        LP_TEST_TMP "/no-such-dir/none.agf");
    BAD(NULL, "a newline in a spec still gives one line", "--lens",
        "R1=25.8,R2=inf,\nbad=1,t=5.3,D=25.4,glass=N-BK7", "--ray", Y);
    BAD(NULL, "NaN in backward ray", "--lens", L, "--ray",
        "o=0,0,-10 d=nan,0,1", "--backward");
}

/* A uniaxial crystal: an a-cut plate (axis 1:1:0 in its faces) at normal
 * incidence splits x light into an o ray (op n_o t) and an e ray (op n_e
 * t, "waves":1), each carrying half of T = (1 - R)^2 at depth 2 (op is
 * relative to air, as the indices). */
static void test_crystal(void)
{
    static output o;
    const double no = 1.6584, ne = 1.4864, t = 0.03;
    proc p = run("--lens", "R1=0,R2=0,t=0.03,D=10,no=1.6584,ne=1.4864,axis=1:1:0", "--ray",
                 "o=0,0,-1 d=0,0,1 lambda=587.7247 vp=1,0,0", "--depth", "2",
                 (const char *)NULL);
    expect_success(&p, "crystal");
    parse_output(&p, &o, "crystal");
    check_balance(&o, "crystal");
    int seen_o = 0, seen_e = 0;
    for (size_t i = 0; i < o.n; i++) {
        const rayline *r = &o.rays[i];
        if (r->depth != 2)
            continue;
        double w = 0;
        int e = jnum(r->text, "waves", &w) && w == 1;
        double n = e ? ne : no, R = fresnel_normal(1.0, n);
        CHECK_REL(r->op, n * t, 1e-12, "crystal: %c ray op", e ? 'e' : 'o');
        CHECK_REL(r->I, 0.5 * (1 - R) * (1 - R), 1e-12, "crystal: %c ray I", e ? 'e' : 'o');
        seen_e += e;
        seen_o += !e;
    }
    CHECK(seen_o == 1 && seen_e == 1, "crystal: one o and one e ray (%d, %d)", seen_o, seen_e);
    free(o.buf);
    proc_free(&p);
    p = run("--lens", "R1=0,R2=0,t=0.03,D=10,crystal=calcite", "--ray",
            "o=0,0,-1 d=0,0,1 lambda=589", (const char *)NULL);
    expect_success(&p, "built-in crystal");
    proc_free(&p);
    /* backward: the same o and e rays reach the eye */
    p = run("--lens", "R1=0,R2=0,t=0.03,D=10,no=1.6584,ne=1.4864,axis=1:1:0", "--ray",
            "o=0,0,-1 d=0,0,1 lambda=587.7247 vp=1,0,0", "--depth", "2", "--backward",
            (const char *)NULL);
    expect_success(&p, "crystal backward");
    parse_output(&p, &o, "crystal backward");
    check_balance(&o, "crystal backward");
    double sum2 = 0;
    for (size_t i = 0; i < o.n; i++)
        if (o.rays[i].depth == 2)
            sum2 += o.rays[i].I;
    double Ro = fresnel_normal(1.0, no), Re = fresnel_normal(1.0, ne);
    CHECK_REL(sum2, 0.5 * ((1 - Ro) * (1 - Ro) + (1 - Re) * (1 - Re)), 1e-12,
              "crystal backward: depth-2 power");
    free(o.buf);
    proc_free(&p);
}

int main(void)
{
    double i2;
    if (access(LENSTRACE, X_OK) != 0) {
        fprintf(stderr, "%s is not built or not executable\n", LENSTRACE);
        return 1;
    }
    i2 = test_forward_axial();
    test_depth_one();
    test_absorption();
    test_unpolarized();
    test_backward(i2);
    test_modes_and_medium();
    test_miss();
    test_catalog();
    test_help_version();
    test_errors();
    test_wavelength_convention();
    test_rays_file();
    test_crystal();
    return check_finish("test_lenstrace_cli");
}
