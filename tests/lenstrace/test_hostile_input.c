/* test_hostile_input.c -- hostile input to lenstrace's argument parser,
 * to the AGF catalog reader and to lp_lens_create: a clear error, never
 * a crash, a hang or unbounded memory.
 *
 *   - every input kept in tests/regressions/lenstrace_args/ (one argv word
 *     per line, as fuzz/fuzz_lenstrace_args reads them) is parsed again by
 *     lt_args_parse, the lens built and the ray traced as lenstrace does,
 *     and the lenstrace binary is run on it: exit 0, or 2 with one stderr
 *     line; the same for tests/regressions/agf/ through
 *     lp_catalog_load_agf_text and lp_catalog_load_agf;
 *   - lenstrace arguments: numbers that overflow, underflow or are NaN,
 *     huge items and argument lists, control characters, a --catalog that
 *     never ends (/dev/zero); the message names the option or the key;
 *   - lenses with radius 1e308, thickness 1e-300, diameter NaN (and rays
 *     with non-finite payloads) straight through the library;
 *   - AGF text: every prefix of a small catalog, random bytes (with and
 *     without a UTF-16 byte order mark), out-of-range numbers, 10^5 IT
 *     lines, 10^5 glasses, text beyond the 64 MiB limit.  Parse errors name
 *     the line ("AGF text, line N: ...").
 *
 * The parser is lenstrace's own small library (lenstrace_args), linked
 * into this test as into the program and its fuzz target. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <unistd.h>

#include "check.h"
#include "subprocess.h"
#include "test_files.h"

#include "lenstrace_args.h"

#ifndef LP_BIN_DIR
#error "LP_BIN_DIR must name the directory of the built programs"
#endif

static const char *const LENSTRACE = LP_BIN_DIR "/lenstrace";

/* tests/regressions/<target>, beside this file's folder. */
static void regression_dir(char *out, size_t n, const char *target)
{
    const char *slash = strrchr(__FILE__, '/');
    if (slash)
        snprintf(out, n, "%.*s/../regressions/%s", (int)(slash - __FILE__), __FILE__, target);
    else
        snprintf(out, n, "../regressions/%s", target);
}

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;

static uint64_t rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}

/* ---- running lenstrace -------------------------------------------------- */

typedef struct run_result {
    int status;      /* exit status, 128 + signal, or -1 */
    char err[1024];  /* stderr (start) */
    double seconds;
} run_result;

static run_result run_lenstrace(char **args, int n)
{
    run_result r;
    const char **argv = calloc((size_t)n + 1, sizeof *argv);
    tp_result t;

    memset(&r, 0, sizeof r);
    r.status = -1;
    if (!argv)
        return r;
    for (int i = 0; i < n; i++)
        argv[i] = args[i];
    if (tp_run(LENSTRACE, argv, NULL, &t) == 0) {
        r.status = t.status;
        snprintf(r.err, sizeof r.err, "%s", t.err);
        r.seconds = t.seconds;
        tp_result_free(&t);
    }
    free(argv);
    return r;
}

/* exit 0, or exit 2 with exactly one line "lenstrace: ..." on stderr */
static void check_run(const run_result *r, const char *what)
{
    CHECK(r->status == 0 || r->status == 2, "%s: lenstrace exit status %d (%s)", what,
          r->status, r->err);
    if (r->status == 2) {
        const char *nl = strchr(r->err, '\n');
        CHECK(strncmp(r->err, "lenstrace: ", 11) == 0 && nl && nl[1] == '\0',
              "%s: stderr is not one 'lenstrace: ' line: '%s'", what, r->err);
    }
    CHECK(r->seconds < 30.0, "%s: lenstrace took %.1f s", what, r->seconds);
}

/* ---- lenstrace arguments in process ------------------------------------ */

static int is_unit(lp_vec3 v)
{
    double l = v.x * v.x + v.y * v.y + v.z * v.z;
    return isfinite(l) && fabs(l - 1.0) < 1e-12;
}

/* What lenstrace does after a successful parse (constant or built-in
 * glasses; --catalog files are not read here).  Returns 0 or a library
 * status; every failure must come with a message. */
static int build_and_trace(const lt_args *a, const char *what)
{
    lp_catalog *cat = NULL;
    lp_lens_desc desc;
    lp_lens *lens = NULL;
    lp_error err;
    lp_result res;
    lp_trace_args targs;
    lp_status st;
    double n_air = lp_air_index(a->ray.lambda_nm);

    memset(&err, 0, sizeof err);
    if (!isfinite(n_air))
        return -1; /* lenstrace: "lambda must be ... at least 160 nm" */
    lp_lens_desc_init(&desc);
    desc.radius1 = a->lens.r1;
    desc.radius2 = a->lens.r2;
    desc.thickness = a->lens.t;
    desc.diameter = a->lens.d;
    desc.diameter2 = a->lens.d2;
    if (a->lens.glass_constant) {
        lp_glass_init_constant(&desc.glass, a->lens.glass_n);
    } else if (lp_catalog_create(&cat, &err) != LP_OK ||
               lp_catalog_find(cat, a->lens.glass_name, &desc.glass, &err) != LP_OK) {
        CHECK(err.message[0] != '\0', "%s: catalog error without a message", what);
        lp_catalog_destroy(cat);
        return -1;
    }
    lp_catalog_destroy(cat);
    lp_glass_init_constant(&desc.medium, a->medium);
    if ((st = lp_glass_check(&desc.glass, &err)) != LP_OK ||
        (st = lp_glass_check(&desc.medium, &err)) != LP_OK ||
        (st = lp_lens_create(&desc, &lens, &err)) != LP_OK) {
        CHECK(err.message[0] != '\0', "%s: status %d without a message", what, (int)st);
        return (int)st;
    }
    lp_trace_args_init(&targs);
    targs.mode = a->mode;
    targs.max_depth = a->depth;
    lp_result_init(&res);
    {
        lp_ray in;
        memset(&in, 0, sizeof in);
        in.origin = a->ray.o;
        in.dir = a->ray.d;
        in.lambda_nm = a->ray.lambda_nm / n_air;
        in.intensity = a->ray.intensity;
        in.vp = a->ray.unpolarized ? lt_perpendicular(a->ray.d) : a->ray.vp;
        in.ch = a->ray.ch;
        st = lp_trace_forward(lens, &in, &targs, &res, &err);
        if (st != LP_OK)
            CHECK(err.message[0] != '\0', "%s: trace status %d without a message", what,
                  (int)st);
    }
    lp_result_release(&res);
    lp_lens_destroy(lens);
    return (int)st;
}

/* Parse argv[0..n) (without argv[0]); on success check the documented
 * postconditions and trace.  Returns the message or NULL. */
static const char *parse_args(char **words, int n, lt_args *a, const char *what)
{
    char **argv = calloc((size_t)n + 2, sizeof *argv);
    const char *e;
    if (!argv)
        abort();
    argv[0] = "lenstrace";
    for (int i = 0; i < n; i++)
        argv[i + 1] = words[i];
    lt_args_init(a);
    e = lt_args_parse(a, n + 1, argv);
    free(argv);
    if (e != NULL) {
        CHECK(e[0] != '\0' && strchr(e, '\n') == NULL, "%s: bad message '%s'", what, e);
        return e;
    }
    if (a->help || a->version)
        return NULL;
    CHECK(!isnan(a->lens.r1) && !isnan(a->lens.r2) && isfinite(a->lens.t) && a->lens.t > 0 &&
              isfinite(a->lens.d) && a->lens.d > 0 && isfinite(a->lens.d2) && a->lens.d2 >= 0,
          "%s: the parsed lens breaks its contract", what);
    CHECK(is_unit(a->ray.d) && isfinite(a->ray.lambda_nm) && a->ray.lambda_nm > 0 &&
              isfinite(a->ray.intensity) && a->ray.intensity >= 0 &&
              (a->ray.unpolarized || is_unit(a->ray.vp)),
          "%s: the parsed ray breaks its contract", what);
    build_and_trace(a, what);
    return NULL;
}

/* Split a text into words at newlines (fuzz_lenstrace_args's format). */
static int split_words(char *text, size_t len, char **words, int max)
{
    int n = 0;
    for (char *p = text; n < max && p < text + len;) {
        char *nl = memchr(p, '\n', (size_t)(text + len - p));
        if (nl)
            *nl = '\0';
        words[n++] = p;
        if (!nl)
            break;
        p = nl + 1;
    }
    return n;
}

static int is_regular_entry(const struct dirent *e)
{
    return e->d_name[0] != '.' && strcmp(e->d_name, "README.md") != 0;
}

static void test_args_regressions(void)
{
    char dir[4096];
    DIR *d;
    struct dirent *e;
    int files = 0;
    lt_args *a = malloc(sizeof *a);

    regression_dir(dir, sizeof dir, "lenstrace_args");
    d = opendir(dir);
    CHECK(d != NULL && a != NULL, "cannot open %s", dir);
    while (d && a && (e = readdir(d)) != NULL) {
        char path[4400], *words[64];
        unsigned char *data;
        size_t len;
        int n;
        run_result r;
        if (!is_regular_entry(e))
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        data = (unsigned char *)tf_read(path, &len);
        CHECK(data != NULL, "cannot read %s", path);
        if (!data)
            continue;
        files++;
        {
            char *text = realloc(data, len + 1);
            if (!text)
                abort();
            text[len] = '\0';
            data = (unsigned char *)text;
            /* the fuzzer ends a word at a NUL too: strlen does that */
            n = split_words(text, len, words, 63);
            parse_args(words, n, a, path);
            /* the specs on the whole input, as the fuzzer does */
            {
                lt_lens_spec ls;
                lt_ray_spec rs;
                lt_args_init(a);
                (void)lt_parse_lens_spec(a, words[0] ? words[0] : "", &ls);
                lt_args_init(a);
                (void)lt_parse_ray_spec(a, words[0] ? words[0] : "", &rs);
            }
            r = run_lenstrace(words, n);
            check_run(&r, path);
        }
        free(data);
    }
    if (d)
        closedir(d);
    free(a);
    CHECK(files > 0, "no regression inputs in %s", dir);
    printf("lenstrace_args regressions: %d files replayed\n", files);
}

typedef struct arg_case {
    const char *words[6];
    const char *want; /* NULL: parses */
} arg_case;

static void test_hostile_args(void)
{
    static const arg_case cases[] = {
        { { "--lens", "R1=1e308,R2=-1e308,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1" }, NULL },
        { { "--lens", "R1=50,R2=-50,t=1e-300,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1" }, NULL },
        { { "--lens", "R1=50,R2=-50,t=5,D=nan,n=1.5", "--ray", "o=0 d=0,0,1" },
          "--lens: D must be a finite number" },
        { { "--lens", "R1=nan,R2=-50,t=5,D=25,n=1.5" }, "--lens: R1 must be a number" },
        { { "--lens", "R1=50,R2=-50,t=1e999,D=25,n=1.5" }, "--lens: t: '1e999' is out of range" },
        { { "--lens", "R1=50,R2=-50,t=inf,D=25,n=1.5" }, "--lens: t must be a finite number" },
        { { "--lens", "R1=50,R2=-50,t=-0,D=25,n=1.5" }, "--lens: t must be > 0" },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=0x1p-1074", "--ray", "o=0,1,-10 d=0,0,1" },
          NULL },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,glass=n=nan" }, "--lens: glass=n must be a finite" },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=1e308,1e308,-1e308 d=0,0,1" },
          NULL },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=1e-320,0,1e-320" },
          NULL },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=1e308,1e308,1e308" },
          NULL },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,0" },
          "--ray: d is the zero vector" },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,nan" },
          "--ray: d: component 3 must be a finite number" },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1 vp=0,0,1e300" },
          "--ray: vp is parallel to d" },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1 lambda=1e-300" },
          "--ray: lambda must be at least 160 nm" },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1 lambda_vac=1e-300" },
          "--ray: lambda_vac must be at least 160 nm" },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1 lambda_vac=1e308" },
          NULL },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1 lambda=1e308" },
          NULL },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1 I=1e308" },
          NULL },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1 I=nan" },
          "--ray: I must be a finite number" },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray",
            "o=0,1,-10 d=0,0,1 ch=18446744073709551616" }, "--ray: ch '18446744073709551616' "
                                                          "is out of range" },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1", "--depth",
            "99999999999999999999" }, "--depth must be an integer from 1 to 64" },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1", "--depth",
            "65" }, "--depth must be an integer from 1 to 64" },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1", "--depth",
            "64" }, NULL },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1", "--medium",
            "nan" }, "--medium must be a finite index > 0" },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1", "--medium",
            "1e-300" }, NULL },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1", "--medium",
            "1e308" }, NULL },
        { { "--lens", "R1=\x01,R2=-50,t=5,D=25,n=1.5" }, "--lens: R1: '\x01' is not a number" },
        { { "--lens", "R1=50,R2=-50,t=5,D=25,glass=\xff\xfe" , "--ray", "o=0,1,-10 d=0,0,1" },
          NULL },
        { { "--lens", "" }, "--lens: empty spec" },
        { { "--lens=R1=50,R2=-50,t=5,D=25,n=1.5,", "--ray=o=0,0,0 d=0,0,1" },
          "--lens: empty item" },
        { { "--ray" }, "option --ray needs a value" },
        { { "--\x7f" }, "unknown option" },
        { { "-" }, "unknown option '-'" },
        { { "" }, "unexpected argument ''" },
    };
    lt_args *a = malloc(sizeof *a);
    if (!a)
        abort();
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char *words[6];
        int n = 0;
        char what[512];
        const char *e;
        run_result r;
        size_t l = 0;
        while (n < 6 && cases[i].words[n]) {
            words[n] = (char *)cases[i].words[n];
            l += (size_t)snprintf(what + l, l < sizeof what ? sizeof what - l : 0, "%s ",
                                  words[n]);
            n++;
        }
        e = parse_args(words, n, a, what);
        if (cases[i].want == NULL)
            CHECK(e == NULL, "%s: refused: %s", what, e);
        else
            CHECK(e != NULL && strstr(e, cases[i].want) == e,
                  "%s: expected '%s...', got '%s'", what, cases[i].want, e ? e : "(accepted)");
        r = run_lenstrace(words, n);
        check_run(&r, what);
        if (cases[i].want != NULL)
            CHECK(r.status == 2, "%s: lenstrace exit %d", what, r.status);
    }

    /* the library refusals, through the binary: one line naming --lens */
    {
        char *w[] = { "--lens", "R1=50,R2=-50,t=1e-300,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1" };
        run_result r = run_lenstrace(w, 4);
        check_run(&r, "t=1e-300");
        CHECK(r.status == 2 && strstr(r.err, "--lens: ") != NULL, "t=1e-300: '%s'", r.err);
    }
    {
        char *w[] = { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray",
                      "o=0,1,-10 d=0,0,1 lambda=1e-300" };
        run_result r = run_lenstrace(w, 4);
        CHECK(r.status == 2 && strstr(r.err, "lambda") != NULL, "lambda=1e-300: '%s'", r.err);
    }
    /* a --catalog that never ends: refused after 64 MiB, quickly */
    {
        char *w[] = { "--lens", "R1=50,R2=-50,t=5,D=25,n=1.5", "--ray", "o=0,1,-10 d=0,0,1",
                      "--catalog", "/dev/zero" };
        run_result r = run_lenstrace(w, 6);
        check_run(&r, "--catalog /dev/zero");
        CHECK(r.status == 2 && strstr(r.err, "/dev/zero") != NULL &&
                  strstr(r.err, "64 MiB") != NULL,
              "--catalog /dev/zero: '%s'", r.err);
    }

    /* huge items and argument lists */
    {
        size_t big = 1000000;
        char *s = malloc(big + 16), *words[4];
        const char *e;
        if (!s)
            abort();
        memcpy(s, "R1=", 3);
        memset(s + 3, '9', big);
        s[big + 3] = '\0';
        words[0] = "--lens";
        words[1] = s;
        e = parse_args(words, 2, a, "R1=10^6 digits");
        CHECK(e && strstr(e, "--lens: item 'R1=999") == e && strstr(e, "too long"),
              "R1=10^6 digits: '%.100s'", e ? e : "(accepted)");
        memset(s, ',', big);
        s[big] = '\0';
        e = parse_args(words, 2, a, "10^6 commas");
        CHECK(e && strstr(e, "--lens: empty item") == e, "10^6 commas: '%.100s'",
              e ? e : "(accepted)");
        memset(s, ' ', big);
        memcpy(s + big / 2, "o=1,2,3", 7);
        words[0] = "--ray";
        e = parse_args(words, 2, a, "10^6 spaces");
        CHECK(e && strstr(e, "--ray: missing key 'd'") == e, "10^6 spaces: '%.100s'",
              e ? e : "(accepted)");
        free(s);
    }
    {
        int n = 100000;
        char **words = malloc((size_t)n * sizeof *words);
        const char *e;
        if (!words)
            abort();
        for (int i = 0; i < n; i++)
            words[i] = "--backward";
        e = parse_args(words, n, a, "10^5 x --backward");
        CHECK(e && strstr(e, "option --backward given more than once") == e,
              "10^5 x --backward: '%s'", e ? e : "(accepted)");
        for (int i = 0; i < n; i++)
            words[i] = (i % 2) ? "x.agf" : "--catalog";
        e = parse_args(words, n, a, "--catalog x 5*10^4");
        CHECK(e && strstr(e, "--catalog given more than 16 times") == e,
              "--catalog x 5*10^4: '%s'", e ? e : "(accepted)");
        free(words);
    }
    free(a);
}

/* ---- lenses and rays straight through the library ----------------------- */

static void test_hostile_lenses(void)
{
    typedef struct { const char *what; double r1, r2, t, d, d2, n; int ok; } lcase;
    static const lcase cases[] = {
        { "radius 1e308", 1e308, -1e308, 5, 25, 0, 1.5, 1 },
        { "radius -1e308", -1e308, 50, 5, 25, 0, 1.5, 1 },
        { "radius 1e-300", 1e-300, -50, 5, 25, 0, 1.5, 0 },
        { "thickness 1e-300", 50, -50, 1e-300, 25, 0, 1.5, 0 },
        { "thickness 1e-300, flat", INFINITY, INFINITY, 1e-300, 25, 0, 1.5, 1 },
        { "thickness 1e308", 50, -50, 1e308, 25, 0, 1.5, 1 },
        { "thickness NaN", 50, -50, NAN, 25, 0, 1.5, 0 },
        { "thickness inf", 50, -50, INFINITY, 25, 0, 1.5, 0 },
        { "diameter NaN", 50, -50, 5, NAN, 0, 1.5, 0 },
        { "diameter inf", 50, -50, 5, INFINITY, 0, 1.5, 0 },
        { "diameter 1e308", 50, -50, 5, 1e308, 0, 1.5, 0 },
        { "diameter 1e308, flat", INFINITY, 0, 5, 1e308, 0, 1.5, 1 },
        { "diameter 1e-300", 50, -50, 5, 1e-300, 0, 1.5, 1 },
        { "diameter -1", 50, -50, 5, -1, 0, 1.5, 0 },
        { "diameter2 NaN", 50, -50, 5, 25, NAN, 1.5, 0 },
        { "radius NaN", NAN, -50, 5, 25, 0, 1.5, 0 },
        { "index NaN", 50, -50, 5, 25, 0, NAN, 0 },
        { "index 1e308", 50, -50, 5, 25, 0, 1e308, 1 },
        { "index 1e-300", 50, -50, 5, 25, 0, 1e-300, 0 },
    };
    static const struct { const char *what; lp_vec3 o, d; double lambda, i; } rays[] = {
        { "plain", { 0, 1, -10 }, { 0, 0, 1 }, 550, 1 },
        { "origin 1e308", { 0, 1, -1e308 }, { 0, 0, 1 }, 550, 1 },
        { "origin inf", { 0, 1, -INFINITY }, { 0, 0, 1 }, 550, 1 },
        { "origin NaN", { NAN, 1, -10 }, { 0, 0, 1 }, 550, 1 },
        { "dir NaN", { 0, 1, -10 }, { 0, NAN, 1 }, 550, 1 },
        { "dir 0", { 0, 1, -10 }, { 0, 0, 0 }, 550, 1 },
        { "dir 1e-320", { 0, 1, -10 }, { 0, 0, 1e-320 }, 550, 1 },
        { "dir 1e308", { 0, 1, -10 }, { 1e308, 1e308, 1e308 }, 550, 1 },
        { "lambda 0", { 0, 1, -10 }, { 0, 0, 1 }, 0, 1 },
        { "lambda NaN", { 0, 1, -10 }, { 0, 0, 1 }, NAN, 1 },
        { "lambda inf", { 0, 1, -10 }, { 0, 0, 1 }, INFINITY, 1 },
        { "lambda 1e-300", { 0, 1, -10 }, { 0, 0, 1 }, 1e-300, 1 },
        { "intensity NaN", { 0, 1, -10 }, { 0, 0, 1 }, 550, NAN },
        { "intensity -1", { 0, 1, -10 }, { 0, 0, 1 }, 550, -1 },
        { "intensity 1e308", { 0, 1, -10 }, { 0, 0, 1 }, 550, 1e308 },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        lp_lens_desc desc;
        lp_lens *lens = NULL;
        lp_error err;
        lp_status st;
        memset(&err, 0, sizeof err);
        lp_lens_desc_init(&desc);
        desc.radius1 = cases[i].r1;
        desc.radius2 = cases[i].r2;
        desc.thickness = cases[i].t;
        desc.diameter = cases[i].d;
        desc.diameter2 = cases[i].d2;
        lp_glass_init_constant(&desc.glass, cases[i].n);
        st = lp_lens_create(&desc, &lens, &err);
        if (cases[i].ok)
            CHECK(st == LP_OK, "%s: refused: %s", cases[i].what, err.message);
        else
            CHECK(st != LP_OK && lens == NULL && err.message[0] != '\0',
                  "%s: status %d, message '%s'", cases[i].what, (int)st, err.message);
        if (st != LP_OK)
            continue;
        for (size_t k = 0; k < sizeof rays / sizeof rays[0]; k++) {
            lp_ray in;
            lp_result res;
            lp_trace_args ta;
            memset(&in, 0, sizeof in);
            in.origin = rays[k].o;
            in.dir = rays[k].d;
            in.lambda_nm = rays[k].lambda;
            in.intensity = rays[k].i;
            in.vp = (lp_vec3){ 1, 0, 0 };
            lp_trace_args_init(&ta);
            ta.max_depth = LP_MAX_DEPTH;
            lp_result_init(&res);
            memset(&err, 0, sizeof err);
            st = lp_trace_forward(lens, &in, &ta, &res, &err);
            if (st != LP_OK)
                CHECK(err.message[0] != '\0', "%s, ray %s: status %d without a message",
                      cases[i].what, rays[k].what, (int)st);
            else
                for (size_t j = 0; j < res.count; j++)
                    CHECK(isfinite(res.rays[j].ray.intensity) && res.rays[j].ray.intensity >= 0,
                          "%s, ray %s: output %zu has intensity %g", cases[i].what,
                          rays[k].what, j, res.rays[j].ray.intensity);
            lp_result_release(&res);
        }
        lp_lens_destroy(lens);
    }
}

/* ---- AGF ---------------------------------------------------------------- */

/* The small catalog of fuzz/corpus/agf/test.agf. */
static const char agf_text[] =
    "CC lensprim test catalog\r\n"
    "NM TEST-SELL 2 517642.251 1.5168 64.17 0 1\r\n"
    "CD 1.039612120E+00 6.000698670E-03 2.317923440E-01 2.001791440E-02 "
    "1.010469450E+00 1.035606530E+02 0.000000000E+00 0.000000000E+00\r\n"
    "LD 3.00000E-01 2.50000E+00\r\n"
    "IT 5.00000E-01 9.98000E-01 1.00000E+01\r\n"
    "IT 4.00000E-01 9.97000E-01 1.00000E+01\r\n"
    "IT 3.10000E-01 0.00000E+00 2.50000E+01\r\n"
    "\r\n"
    "NM TEST-SCHOTT\t1\t0\t1.5\t60\t0\t0\t0\r\n"
    "CD 2.2718929 -1.0108077E-02 1.0592509E-02 2.0816965E-04 -7.6472538E-06 "
    "4.9240991E-07 0 0 0 0\r\n"
    "LD 0.365 1.014\r\n"
    "NM TEST-CONRADY 5 0 1.603233 42.504788 0 0 0\r\n"
    "CD 1.574103270E+000 1.397861490E-002 8.300451100E-004 0 0 0 0 0 0 0\r\n"
    "NM TEST-HERZ 3 0 1.6 40 0 0 0\r\n"
    "CD 1 2 3 4 5 6\r\n";

/* Load text; on success look up, check and evaluate every glass.  On
 * failure the message must start with the source ("AGF text") and, for
 * a parse error, name the line.  Returns the status. */
static lp_status agf_checked(const char *text, size_t len, const char *what)
{
    lp_catalog *cat = NULL;
    lp_error err;
    lp_status st;

    memset(&err, 0, sizeof err);
    if (lp_catalog_create(&cat, &err) != LP_OK) {
        CHECK(0, "lp_catalog_create failed");
        return LP_ERROR_NO_MEMORY;
    }
    st = lp_catalog_load_agf_text(cat, text, len, &err);
    if (st != LP_OK) {
        CHECK(strncmp(err.message, "AGF text", 8) == 0, "%s: message '%s'", what, err.message);
        if (st == LP_ERROR_PARSE && strstr(err.message, "UTF-16") == NULL &&
            strstr(err.message, "NUL") == NULL && strstr(err.message, "MiB") == NULL)
            CHECK(strncmp(err.message, "AGF text, line ", 15) == 0,
                  "%s: the parse error '%s' names no line", what, err.message);
    } else {
        for (size_t i = 0; i < lp_catalog_count(cat); i++) {
            const char *name = lp_catalog_name(cat, i);
            lp_glass g;
            CHECK(name != NULL, "%s: glass %zu has no name", what, i);
            if (!name || lp_catalog_find(cat, name, &g, &err) != LP_OK ||
                lp_glass_check(&g, &err) != LP_OK) {
                CHECK(err.message[0] != '\0', "%s: glass %zu refused without a message",
                      what, i);
                continue;
            }
            CHECK(isfinite(lp_glass_index(&g, 587.5618)), "%s: glass %s has no index", what,
                  name);
            (void)lp_glass_absorption(&g, 587.5618);
        }
    }
    lp_catalog_destroy(cat);
    return st;
}

static void test_agf_regressions(void)
{
    char dir[4096];
    DIR *d;
    struct dirent *e;
    int files = 0;

    regression_dir(dir, sizeof dir, "agf");
    d = opendir(dir);
    CHECK(d != NULL, "cannot open %s", dir);
    while (d && (e = readdir(d)) != NULL) {
        char path[4400];
        unsigned char *data;
        size_t len;
        lp_catalog *cat = NULL;
        lp_error err;
        if (!is_regular_entry(e))
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        data = (unsigned char *)tf_read(path, &len);
        CHECK(data != NULL, "cannot read %s", path);
        if (!data)
            continue;
        files++;
        agf_checked((const char *)data, len, path);
        if (lp_catalog_create(&cat, &err) == LP_OK) {
            if (lp_catalog_load_agf(cat, path, &err) != LP_OK)
                CHECK(strstr(err.message, path) != NULL, "%s: message '%s'", path,
                      err.message);
            lp_catalog_destroy(cat);
        }
        free(data);
    }
    if (d)
        closedir(d);
    CHECK(files > 0, "no regression inputs in %s", dir);
    printf("agf regressions: %d files replayed\n", files);
}

static void test_hostile_agf(void)
{
    static const struct { const char *text, *want; } bad[] = {
        { "NM A 2 0 1.5 60\nCD 1e999 0 0 0 0 0\n", "line 2: malformed CD coefficient" },
        { "NM A 2 0 1.5 60\nCD nan 0 0 0 0 0\n", "line 2: malformed CD coefficient" },
        { "NM A 2 0 1.5 60\nCD inf 0 0 0 0 0\n", "line 2: malformed CD coefficient" },
        { "NM A 2 0 1.5 60\nCD 1 0 0 0 0 0\nLD 0.3 1e306\n", "line 3: LD wavelength out of range" },
        { "NM A 2 0 1.5 60\nCD 1 0 0 0 0 0\nLD 0.3 1e999\n", "line 3: malformed LD wavelength" },
        { "NM A 2 0 1.5 60\nCD 1 0 0 0 0 0\nLD -1 2\n", "line 3: LD range" },
        { "NM A 2 0 1.5 60\nCD 1 0 0 0 0 0\nIT 1e306 0.5 10\n", "line 3: IT wavelength" },
        { "NM A 2 0 1.5 60\nCD 1 0 0 0 0 0\nIT 0.5 2 10\n", "line 3: IT transmittance" },
        { "NM A 2 0 1.5 60\nCD 1 0 0 0 0 0\nIT 0.5 0.5 0\n", "line 3: IT thickness" },
        { "NM A 1e300 0 1.5 60\n", "line 1: malformed formula number" },
        { "NM A 2.5 0 1.5 60\n", "line 1: malformed formula number" },
        { "NM A 2\n", "line 1: glass \"A\" has no CD line" },
        { "CD 1 2 3\n", "line 1: data line before any NM line" },
        { "NM AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA"
          "AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA 2\n",
          "line 1: glass name longer than" },
        { "NM A 2 0 1.5 60\nCD 1 0.01\n", "needs 6 CD" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        lp_catalog *cat = NULL;
        lp_error err;
        memset(&err, 0, sizeof err);
        agf_checked(bad[i].text, strlen(bad[i].text), bad[i].text);
        if (lp_catalog_create(&cat, &err) != LP_OK)
            continue;
        CHECK(lp_catalog_load_agf_text(cat, bad[i].text, strlen(bad[i].text), &err) != LP_OK &&
                  strstr(err.message, bad[i].want) != NULL,
              "'%.60s': expected '%s', got '%s'", bad[i].text, bad[i].want, err.message);
        lp_catalog_destroy(cat);
    }

    /* a 1e-320 mm sample: read, but the glass is refused by lp_glass_check
     * (its absorption coefficient would be infinite) */
    {
        static const char t[] = "NM THIN 2 0 1.5 60\nCD 1 0 0 0 0 0\nIT 0.5 0.5 1e-320\n";
        lp_catalog *cat = NULL;
        lp_error err;
        lp_glass g;
        if (lp_catalog_create(&cat, &err) == LP_OK) {
            CHECK(lp_catalog_load_agf_text(cat, t, sizeof t - 1, &err) == LP_OK &&
                      lp_catalog_find(cat, "THIN", &g, &err) == LP_OK &&
                      lp_glass_check(&g, &err) != LP_OK &&
                      strstr(err.message, "not finite") != NULL,
                  "an IT sample 1e-320 mm thick: '%s'", err.message);
            lp_catalog_destroy(cat);
        }
    }

    /* every prefix of a good catalog, and each followed by junk */
    {
        size_t len = sizeof agf_text - 1;
        char *buf = malloc(len + 32);
        long ok = 0;
        if (!buf)
            abort();
        CHECK(agf_checked(agf_text, len, "the whole catalog") == LP_OK, "the catalog is refused");
        for (size_t cut = 0; cut <= len; cut++) {
            char what[64];
            memcpy(buf, agf_text, cut);
            snprintf(what, sizeof what, "AGF cut at byte %zu", cut);
            if (agf_checked(buf, cut, what) == LP_OK)
                ok++;
            for (size_t j = 0; j < 16; j++)
                buf[cut + j] = (char)(rnd() & 0xFF);
            agf_checked(buf, cut + 16, what);
        }
        free(buf);
        printf("agf truncations: %zu prefixes (%ld load), each also followed by junk\n",
               len + 1, ok);
    }

    /* random bytes, as they are and behind a UTF-16 byte order mark */
    {
        unsigned char buf[2050];
        for (int round = 0; round < 3000; round++) {
            size_t len = (size_t)(rnd() % 2048), off = 0;
            if (round % 3 == 1) {
                buf[0] = 0xFF, buf[1] = 0xFE, off = 2;
            } else if (round % 3 == 2) {
                buf[0] = 0xFE, buf[1] = 0xFF, off = 2;
            }
            for (size_t i = off; i < len + off; i++) {
                uint64_t r = rnd();
                /* bias toward the format's own bytes */
                static const char alpha[] = "NMCDLDIT 0123456789.eE+-\n\r\t";
                buf[i] = (r & 1) ? (unsigned char)(r >> 8) : (unsigned char)alpha[(r >> 8) % 28];
            }
            agf_checked((const char *)buf, len + off, "random bytes");
        }
    }
    /* UTF-16 oddities: an odd byte count, lone and reversed surrogates */
    {
        static const unsigned char odd[] = { 0xFF, 0xFE, 'N', 0, 'M' };
        static const unsigned char lone[] = { 0xFF, 0xFE, 0x00, 0xD8, 'N', 0, 'M', 0, ' ', 0,
                                              'A', 0, ' ', 0, '2', 0, 0x00, 0xDC, 0x00, 0xD8 };
        CHECK(agf_checked((const char *)odd, sizeof odd, "odd UTF-16") != LP_OK,
              "odd UTF-16 accepted");
        agf_checked((const char *)lone, sizeof lone, "lone surrogates");
    }

    /* 10^5 IT lines in one glass: shortened to the table size, quickly */
    {
        size_t n = 100000, cap = 64 + n * 40, len = 0;
        char *t = malloc(cap);
        double t0 = tf_now();
        if (!t)
            abort();
        len += (size_t)snprintf(t + len, cap - len,
                                "NM BIG 2 0 1.5 60\nCD 1 0.006 0.23 0.02 1 103\nLD 0.3 2.5\n");
        for (size_t i = 0; i < n; i++)
            len += (size_t)snprintf(t + len, cap - len, "IT %.6f %.4f 10\n",
                                    0.3 + 2.2 * (double)rnd() / 18446744073709551616.0,
                                    0.5 + 0.5 * (double)(i % 97) / 97.0);
        CHECK(agf_checked(t, len, "10^5 IT lines") == LP_OK, "10^5 IT lines refused");
        CHECK(tf_now() - t0 < 20.0, "10^5 IT lines took %.1f s", tf_now() - t0);
        printf("agf: 10^5 IT lines loaded in %.2f s\n", tf_now() - t0);
        /* 10^4 glasses load; 10^5 are refused at the 20,000th (the
         * catalog searches names linearly: no quadratic hang) */
        for (size_t count = 10000; count <= 100000; count *= 10) {
            lp_catalog *cat = NULL;
            lp_error err;
            lp_status st = LP_ERROR_NO_MEMORY;
            len = 0;
            t0 = tf_now();
            for (size_t i = 0; i < count && len + 80 < cap; i++)
                len += (size_t)snprintf(t + len, cap - len,
                                        "NM G%zu 5 0 1.5 60\nCD 1.5 0.01 0\n", i);
            if (lp_catalog_create(&cat, &err) == LP_OK) {
                st = lp_catalog_load_agf_text(cat, t, len, &err);
                if (st == LP_OK) {
                    lp_glass g;
                    CHECK(lp_catalog_find(cat, "g9999", &g, &err) == LP_OK &&
                              lp_catalog_find(cat, "nope", &g, &err) != LP_OK,
                          "10^4 glasses: lookups");
                }
                lp_catalog_destroy(cat);
            }
            if (count == 10000)
                CHECK(st == LP_OK, "10^4 glasses refused: %s", err.message);
            else
                CHECK(st != LP_OK && strstr(err.message, "line 40001: more than 20000 glasses"),
                      "10^5 glasses: '%s'", err.message);
            CHECK(tf_now() - t0 < 20.0, "%zu glasses took %.1f s", count, tf_now() - t0);
            printf("agf: %zu glasses: %s in %.2f s\n", count, st == LP_OK ? "loaded" : "refused",
                   tf_now() - t0);
        }
        free(t);
    }
    /* beyond the size limit: refused before parsing */
    {
        size_t len = ((size_t)64 << 20) + 1;
        char *t = malloc(len);
        lp_catalog *cat = NULL;
        lp_error err;
        if (!t)
            abort();
        memset(t, ' ', len);
        if (lp_catalog_create(&cat, &err) == LP_OK) {
            CHECK(lp_catalog_load_agf_text(cat, t, len, &err) != LP_OK &&
                      strstr(err.message, "larger than 64 MiB") != NULL,
                  "64 MiB + 1 of AGF text: '%s'", err.message);
            CHECK(lp_catalog_load_agf(cat, "/dev/zero", &err) != LP_OK &&
                      strstr(err.message, "/dev/zero") != NULL &&
                      strstr(err.message, "64 MiB") != NULL,
                  "/dev/zero as AGF: '%s'", err.message);
            CHECK(lp_catalog_count(cat) == 7, "refused text added glasses (%zu)",
                  lp_catalog_count(cat));
            lp_catalog_destroy(cat);
        }
        free(t);
    }
}

int main(void)
{
    test_args_regressions();
    test_hostile_args();
    test_hostile_lenses();
    test_agf_regressions();
    test_hostile_agf();
    return check_finish("test_hostile_input");
}
