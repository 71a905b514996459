/* test_hostile_scenes.c -- malformed and hostile input to the scene parser
 * and to lensrender: a clear error naming a place, never a crash, a hang
 * or unbounded memory.
 *
 *   - every input kept in tests/regressions/scene/ (found by fuzz/fuzz_scene
 *     or by review) is parsed again, from a string and from its file: it
 *     parses into a scene that keeps the invariants of parser.h (finite
 *     values, unit normals, positive sizes), or it is refused with
 *     "NAME:LINE:COL: ...";
 *   - numbers: overflowing literals and arithmetic (1e308*1e308), 0/0,
 *     functions outside their domain, values that under- or overflow in
 *     normalizations and transforms;
 *   - nesting 10^5 deep (parentheses, vectors, calls, blocks, comments,
 *     unary signs): a clean error or a clean parse, no stack overflow;
 *   - 10^6 objects: refused at the object limit (100,000 by default), in a
 *     separate program (tests/renderer/parse_many) whose own peak memory is
 *     measured (tests/common/measure_child), checked and printed;
 *   - every prefix of every .scene file in scenes/ (truncation at each byte),
 *     and prefixes followed by junk;
 *   - binary junk (random bytes with NULs, from files) and a file larger
 *     than the 64 MiB limit (/dev/zero);
 *   - lenses with radius 1e308, thickness 1e-300, diameter nan or 0/0;
 *   - lensrender: absurd resolutions (--width 100000 --height 100000, ...)
 *     are refused before any allocation (the child's peak memory stays
 *     small), and a render whose PNG write fails half-way (RLIMIT_FSIZE)
 *     leaves the previous good PNG byte-for-byte intact and no temporary
 *     file behind. */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "subprocess.h"
#include "test_files.h"

#include "args.h"
#include "library_path.h"
#include "parser.h"
#include "scene.h"

#ifndef LP_BIN_DIR
#error "LP_BIN_DIR must name the directory of the built programs"
#endif
#ifndef LP_TEST_TMP
#define LP_TEST_TMP "."
#endif
#ifndef LP_SOURCE_DIR
#error "LP_SOURCE_DIR must name the source tree"
#endif

#if defined(__SANITIZE_ADDRESS__)
#define UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define UNDER_ASAN 1
#endif
#endif
#ifndef UNDER_ASAN
#define UNDER_ASAN 0
#endif

static const char *const LENSRENDER = LP_BIN_DIR "/lensrender";
static const char *const PARSE_MANY = LP_BIN_DIR "/parse_many";
static const char *const REGRESSIONS = LP_SOURCE_DIR "/tests/regressions/scene";
static const char *const SCENES = LP_SOURCE_DIR "/scenes";

/* Peak memory allowed to the child that parses 10^6 objects, MiB.  The
 * 100,000 objects kept before the limit take 100,000 * sizeof(rs_object)
 * (about 250 MB); ASan adds its quarantine and shadow. */
#define MAX_OBJECTS_PEAK_MB (UNDER_ASAN ? 1536 : 512)
/* Peak memory of a lensrender run refused for its resolution, MiB. */
#define REFUSED_RUN_PEAK_MB (UNDER_ASAN ? 256 : 64)

/* ---- helpers ------------------------------------------------------------ */

/* 1 when msg is "NAME:LINE:COL: text" with 1 <= LINE <= max_line and
 * COL >= 1 (max_line 0: any). */
static int has_location(const char *msg, const char *name, long max_line)
{
    size_t n = strlen(name);
    char *end;
    long line, col;
    if (strncmp(msg, name, n) != 0 || msg[n] != ':')
        return 0;
    line = strtol(msg + n + 1, &end, 10);
    if (end == msg + n + 1 || *end != ':')
        return 0;
    col = strtol(end + 1, &end, 10);
    if (*end != ':' || end[1] != ' ' || end[2] == '\0')
        return 0;
    return line >= 1 && (max_line == 0 || line <= max_line) && col >= 1;
}

static int fin(lp_vec3 v)
{
    return isfinite(v.x) && isfinite(v.y) && isfinite(v.z);
}

static int unit(lp_vec3 v)
{
    return fin(v) && fabs(v.x * v.x + v.y * v.y + v.z * v.z - 1.0) < 1e-9;
}

/* The invariants parser.h promises for a parsed scene; 1 when kept. */
static int scene_ok(const rs_scene *s, char *why, size_t n)
{
    for (size_t i = 0; i < s->n_objects; i++) {
        const rs_object *o = &s->objects[i];
        int ok = 1;
        switch (o->type) {
        case RS_OBJ_PLANE:
            ok = unit(o->u.plane.normal) && isfinite(o->u.plane.distance);
            break;
        case RS_OBJ_SPHERE:
            ok = fin(o->u.sphere.center) && isfinite(o->u.sphere.radius) &&
                 o->u.sphere.radius > 0.0;
            break;
        case RS_OBJ_BOX:
            ok = fin(o->u.box.corner1) && fin(o->u.box.corner2);
            break;
        case RS_OBJ_DISC:
            ok = fin(o->u.disc.center) && unit(o->u.disc.normal) &&
                 isfinite(o->u.disc.radius) && o->u.disc.radius > 0.0;
            break;
        case RS_OBJ_LENS:
            ok = !isnan(o->u.lens.desc.radius1) && !isnan(o->u.lens.desc.radius2) &&
                 isfinite(o->u.lens.desc.thickness) && isfinite(o->u.lens.desc.diameter) &&
                 fin(o->u.lens.desc.position) && unit(o->u.lens.desc.axis);
            break;
        case RS_OBJ_POLARIZER:
            ok = fin(o->u.polarizer.center) && unit(o->u.polarizer.normal) &&
                 unit(o->u.polarizer.axis) && isfinite(o->u.polarizer.radius) &&
                 o->u.polarizer.radius > 0.0;
            break;
        case RS_OBJ_CYLINDER:
            ok = fin(o->u.cylinder.base) && fin(o->u.cylinder.cap) &&
                 o->u.cylinder.radius > 0.0 && isfinite(o->u.cylinder.radius);
            break;
        case RS_OBJ_CONE:
            ok = fin(o->u.cone.base) && fin(o->u.cone.cap) && o->u.cone.base_radius >= 0.0 &&
                 o->u.cone.cap_radius >= 0.0 && isfinite(o->u.cone.base_radius) &&
                 isfinite(o->u.cone.cap_radius);
            break;
        case RS_OBJ_TORUS:
            ok = o->u.torus.major > 0.0 && o->u.torus.minor > 0.0 &&
                 isfinite(o->u.torus.major) && isfinite(o->u.torus.minor);
            break;
        case RS_OBJ_CSG: /* members: solids only, never lenses, polarizers or discs */
            ok = o->u.csg.n_members > 0 && o->u.csg.members != NULL;
            for (size_t k = 0; ok && k < o->u.csg.n_members; k++) {
                rs_object_type t = o->u.csg.members[k].type;
                ok = t != RS_OBJ_LENS && t != RS_OBJ_POLARIZER && t != RS_OBJ_DISC;
            }
            break;
        }
        if (!ok) {
            snprintf(why, n, "object %zu (line %d) has a non-finite, zero or non-unit value", i,
                     o->loc.line);
            return 0;
        }
    }
    for (size_t i = 0; i < s->n_lights; i++) {
        const rs_light *l = &s->lights[i];
        if (!fin(l->position) || (l->polarized && !unit(l->polarization))) {
            snprintf(why, n, "light %zu (line %d) has a non-finite or non-unit value", i,
                     l->loc.line);
            return 0;
        }
    }
    return 1;
}

static long count_lines(const char *text, size_t len)
{
    long n = 1;
    for (size_t i = 0; i < len; i++)
        if (text[i] == '\n')
            n++;
    return n;
}

/* Parse text[0..len) (NUL-terminated at len by the caller) as `name`:
 * success with the invariants kept (and rs_scene_prepare succeeding or
 * failing with a location), or failure with a location.  Returns the
 * parse result (0 / -1); checks are recorded. */
static int parse_checked(const char *text, size_t len, const char *name, const char *what)
{
    rs_scene scene;
    char msg[512], why[160];
    int rc;

    rs_parse_opts opts;
    const char *dirs[4];

    /* the library path lensrender uses (POV-Ray's colors.inc ...) */
    rs_parse_opts_init(&opts);
    opts.include_dirs = dirs;
    opts.n_include_dirs = rs_library_path(NULL, 0, dirs, sizeof dirs / sizeof dirs[0]);
    rs_scene_init(&scene);
    rc = rs_parse_string(text, name, &opts, &scene, msg, sizeof msg);
    if (rc != 0) {
        CHECK(has_location(msg, name, count_lines(text, len ? len : strlen(text))),
              "%s: the error '%s' does not name %s:LINE:COL", what, msg, name);
    } else {
        CHECK(scene_ok(&scene, why, sizeof why), "%s: parsed, but %s", what, why);
        if (rs_scene_prepare(&scene, msg, sizeof msg) != 0)
            CHECK(has_location(msg, name, 0), "%s: rs_scene_prepare's error '%s' names no place",
                  what, msg);
    }
    rs_scene_free(&scene);
    return rc;
}

/* Parse a string that must be refused with a message containing `want`. */
static void refused(const char *text, const char *want)
{
    rs_scene scene;
    char msg[512];
    int rc;

    rs_scene_init(&scene);
    rc = rs_parse_string(text, "hostile.scene", NULL, &scene, msg, sizeof msg);
    if (rc == 0) {
        /* some problems are only found when the lenses are made */
        rc = rs_scene_prepare(&scene, msg, sizeof msg);
    }
    CHECK(rc != 0, "'%.80s' was accepted", text);
    if (rc != 0) {
        CHECK(has_location(msg, "hostile.scene", 0), "'%.80s': the error '%s' names no place",
              text, msg);
        CHECK(strstr(msg, want) != NULL, "'%.80s': the error '%s' does not say '%s'", text, msg,
              want);
    }
    rs_scene_free(&scene);
}

/* Parse a string that must be accepted, keeping the invariants. */
static void accepted(const char *text)
{
    rs_scene scene;
    char msg[512], why[160];
    int rc;

    rs_scene_init(&scene);
    rc = rs_parse_string(text, "hostile.scene", NULL, &scene, msg, sizeof msg);
    CHECK(rc == 0, "'%.80s' was refused: %s", text, msg);
    if (rc == 0)
        CHECK(scene_ok(&scene, why, sizeof why), "'%.80s': %s", text, why);
    rs_scene_free(&scene);
}

/* ---- the regression files ----------------------------------------------- */

static void test_regressions(void)
{
    DIR *d = opendir(REGRESSIONS);
    struct dirent *e;
    int files = 0;

    CHECK(d != NULL, "cannot open %s", REGRESSIONS);
    if (!d)
        return;
    while ((e = readdir(d)) != NULL) {
        char path[4096], msg[512];
        unsigned char *data;
        size_t len;
        rs_scene scene;
        int rc;

        if (e->d_name[0] == '.' || strcmp(e->d_name, "README.md") == 0)
            continue;
        snprintf(path, sizeof path, "%s/%s", REGRESSIONS, e->d_name);
        data = (unsigned char *)tf_read(path, &len);
        CHECK(data != NULL, "cannot read %s", path);
        if (!data)
            continue;
        files++;
        /* as the fuzzer saw it: a NUL-terminated copy */
        {
            char *text = malloc(len + 1);
            if (!text)
                abort();
            memcpy(text, data, len);
            text[len] = '\0';
            parse_checked(text, strlen(text), e->d_name, path);
            free(text);
        }
        /* and from the file (embedded NULs are errors there) */
        rs_scene_init(&scene);
        rc = rs_parse_file(path, NULL, &scene, msg, sizeof msg);
        if (rc != 0)
            CHECK(has_location(msg, path, 0), "%s: rs_parse_file's error '%s' names no place",
                  path, msg);
        rs_scene_free(&scene);
        free(data);
    }
    closedir(d);
    CHECK(files > 0, "no regression inputs in %s", REGRESSIONS);
    printf("regressions: %d files replayed\n", files);
}

/* ---- numbers ------------------------------------------------------------ */

static void test_numbers(void)
{
    static const struct { const char *text, *want; } bad[] = {
        { "sphere { 0, 1e308*1e308 }", "not a finite number" },
        { "sphere { 0, 1e308+1e308 }", "not a finite number" },
        { "sphere { 0, -1e308-1e308 }", "not a finite number" },
        { "sphere { 0, 1e999 }", "out of range" },
        { "sphere { 0, 1e-99999 }", "must be positive" }, /* underflows to 0 */
        { "sphere { 0, 0/0 }", "division by zero" },
        { "sphere { 0, 1/0 }", "division by zero" },
        { "sphere { <1,2,3>/<1,0,1>, 1 }", "division by zero" },
        { "sphere { 0, mod(1, 0) }", "division by zero" },
        { "sphere { 0, sqrt(-1) }", "not a finite number" },
        { "sphere { 0, ln(0) }", "not a finite number" },
        { "sphere { 0, log(-1) }", "not a finite number" },
        { "sphere { 0, exp(1000) }", "not a finite number" },
        { "sphere { 0, pow(10, 400) }", "not a finite number" },
        { "sphere { 0, pow(0, -1) }", "not a finite number" },
        { "sphere { 0, asin(2) }", "not a finite number" },
        { "sphere { 0, tan(pi/2)*1e300*1e300 }", "not a finite number" },
        { "sphere { 0, vlength(<1.5e308,1.5e308,1.5e308>) }", "not a finite number" },
        { "sphere { vnormalize(<0,0,0>), 1 }", "zero vector" },
        { "sphere { 0, nan }", "undeclared identifier 'nan'" },
        { "sphere { 0, inf }", "expected an expression" },
        { "sphere { 0, 0 }", "must be positive" },
        { "sphere { 0, -1e-320 }", "must be positive" },
        { "#declare A = 1e200; sphere { 0, A*A }", "not a finite number" },
        { "sphere { 0, 1 scale 1e200 scale 1e200 }", "too large" },
        { "sphere { 0, 1 translate 1e308 translate 1e308 }", "too large" },
        { "sphere { 0, 1 scale 1e-200 scale 1e-200 }", "too large" },
        { "sphere { 0, 1 scale 0 }", "zero component" },
        { "sphere { 0, 1 scale 1e-320 }", "zero component" },
        { "light_source { 0, 1 polarization <1e300,0,0> scale 1e10 }", "polarization" },
        { "light_source { <1e300,0,0>, 1 scale 1e10 }", "not finite" },
        { "polarizer { normal z radius 1e-200 axis x scale 1e-200 }", "underflows" },
        { "polarizer { normal z radius 1 axis z }", "parallel" },
        { "lens { radius1 1e-200 radius2 -inf thickness 1 diameter 1e-200 ior 1.5 "
          "scale 1e-200 }", "underflows" },
        { "lens { radius1 1e300 radius2 -inf thickness 1 diameter 1 ior 1.5 scale 1e10 }",
          "not finite" },
        { "camera { angle 0/0 }", "division by zero" },
        { "camera { angle 1e308*10 }", "not a finite number" },
        { "global_settings { max_trace_level 1e300 }", "between 1 and 256" },
        { "global_settings { max_trace_level -1e300 }", "between 1 and 256" },
        { "background { rgb 1e308*1e308 }", "not a finite number" },
        { "#version 1e999;", "out of range" },
        { "sphere { 0, 11111111111111111111111111111111111111111111111111111111111111111111"
          "111111111111111111111111111111111111111111111111111111111111111111111111 }",
          "too long" },
    };
    static const char *const good[] = {
        "sphere { 0, 1e308 }",
        "sphere { 0, 1e-300 }",
        "sphere { 0, 1 scale 1e150 scale 1e150 }",
        "plane { <1e-200, 0, 0>, 1 }",
        "plane { <1e200, 1e200, 0>, 1 }",
        "plane { <1e-320, 0, 1e-320>, -1e308 }",
        "disc { 0, <1e-170, 0, 0>, 1 }",
        "disc { 0, <1e300, 1e300, 1e300>, 1e308, 1e307 }",
        "polarizer { normal <1e-200, 0, 0> radius 1 axis y }",
        "polarizer { normal z radius 1 axis <1e-300, 1e-300, 0> }",
        "polarizer { normal z radius 1 axis x scale 1e-200 }",
        "light_source { 0, 1 polarization <1e-200, 0, 0> }",
        "light_source { 0, 1 polarization <1e300, 1e300, 1e300> rotate 45*y }",
        "sphere { vnormalize(<1e200, 1e200, 0>), vlength(<1e200, 0, 0>) / 1e199 }",
        "sphere { vnormalize(<1e-300, 0, 0>), vlength(<3e-300, 4e-300, 0>) * 1e300 }",
        "box { <-1e308, -1e308, -1e308>, <1e308, 1e308, 1e308> }",
        "sphere { 0, 1 rotate <1e308, -1e308, 1e300> }",
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        refused(bad[i].text, bad[i].want);
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++)
        accepted(good[i]);
}

/* ---- lenses ------------------------------------------------------------- */

static void test_lenses(void)
{
    static const struct { const char *text, *want; } bad[] = {
        { "lens { radius1 50 radius2 -50 thickness 1e-300 diameter 25 ior 1.5 }", "cross" },
        { "lens { radius1 50 radius2 -50 thickness 5 diameter nan ior 1.5 }",
          "undeclared identifier 'nan'" },
        { "lens { radius1 50 radius2 -50 thickness 5 diameter 0/0 ior 1.5 }",
          "division by zero" },
        { "lens { radius1 50 radius2 -50 thickness 5 diameter 1e308 ior 1.5 }", "wider" },
        { "lens { radius1 1e-300 radius2 -50 thickness 5 diameter 25 ior 1.5 }", "wider" },
        { "lens { radius1 50 radius2 -50 thickness 1e308*10 diameter 25 ior 1.5 }",
          "not a finite number" },
        { "lens { radius1 50 radius2 -50 thickness 5 diameter 25 ior 1e-300 }", "index" },
        { "lens { radius1 50 radius2 -50 thickness 5 diameter 25 ior 0 }", "positive" },
        { "lens { radius1 50 radius2 -50 thickness 5 diameter 25 sellmeier { 1e308, 1e308, "
          "1e308, 0, 0, 0 } }", "lens:" },
        { "lens { radius1 50 radius2 -50 thickness 5 diameter 25 sellmeier { -5, 0, 0, 0, 0, "
          "0 } }", "lens:" },
        { "lens { radius1 50 radius2 -50 thickness 5 diameter 25 glass \"NO-SUCH-GLASS\" }",
          "NO-SUCH-GLASS" },
        { "lens { radius1 50 radius2 -50 thickness 5 diameter 25 glass \""
          "AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA"
          "AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA"
          "\" }", "longer than" },
    };
    /* R = 1e308 is a valid, all-but-flat surface: accepted, and the lens is
     * created. */
    rs_scene scene;
    char msg[512];
    rs_scene_init(&scene);
    CHECK(rs_parse_string("lens { radius1 1e308 radius2 -1e308 thickness 5 diameter 25 "
                          "ior 1.5 }", "flat.scene", NULL, &scene, msg, sizeof msg) == 0 &&
              rs_scene_prepare(&scene, msg, sizeof msg) == 0,
          "a lens with radius 1e308 was refused: %s", msg);
    rs_scene_free(&scene);
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        refused(bad[i].text, bad[i].want);
    /* extreme but meaningful: a needle-sharp conical rim, a medium of
     * index 1e308 (parsed; made or refused with a place) */
    parse_checked("lens { radius1 50 radius2 -50 thickness 5 diameter 25 diameter2 1e-300 "
                  "ior 1.5 }", 0, "hostile.scene", "diameter2 1e-300");
    parse_checked("lens { radius1 50 radius2 -50 thickness 5 diameter 25 ior 1.5 "
                  "medium ior 1e308 }", 0, "hostile.scene", "medium ior 1e308");
}

/* ---- nesting ------------------------------------------------------------ */

#define DEEP 100000

/* prefix + open x DEEP + middle + close x DEEP + suffix */
static char *nest(const char *prefix, const char *open, const char *middle, const char *close,
                  const char *suffix)
{
    size_t lo = strlen(open), lc = strlen(close);
    size_t n = strlen(prefix) + DEEP * (lo + lc) + strlen(middle) + strlen(suffix) + 1;
    char *s = malloc(n), *p;
    if (!s)
        abort();
    p = s;
    p += sprintf(p, "%s", prefix);
    for (int i = 0; i < DEEP; i++, p += lo)
        memcpy(p, open, lo);
    p += sprintf(p, "%s", middle);
    for (int i = 0; i < DEEP; i++, p += lc)
        memcpy(p, close, lc);
    sprintf(p, "%s", suffix);
    return s;
}

static void test_nesting(void)
{
    static const struct { const char *pre, *open, *mid, *close, *post, *want; } deep[] = {
        { "sphere { 0, ", "(", "1", ")", " }", "nesting deeper than" },
        { "sphere { ", "<", "1", ",0,0>", ", 1 }", "nesting deeper than" },
        { "sphere { 0, ", "sin(", "1", ")", " }", "nesting deeper than" },
        { "sphere { 0, ", "max(1,", "1", ")", " }", "nesting deeper than" },
        { "sphere { 0, ", "vlength(", "1", ")", " }", "nesting deeper than" },
        { "", "{", "", "}", "", "expected camera" },
        { "sphere { 0, 1 ", "{", "", "}", " }", "expected pigment" },
        { "#declare A = ", "(", "1", ")", ";", "nesting deeper than" },
        { "", "/*", "", "", "", "unterminated comment" },
        { "sphere { 0, 1 ", "pigment { ", "", "}", " }", "expected" },
        { "sphere { 0, 1 ", "texture { ", "", "}", " }", "expected" },
    };
    for (size_t i = 0; i < sizeof deep / sizeof deep[0]; i++) {
        char *s = nest(deep[i].pre, deep[i].open, deep[i].mid, deep[i].close, deep[i].post);
        double t0 = tf_now();
        refused(s, deep[i].want);
        CHECK(tf_now() - t0 < 10.0, "nesting '%s' x %d took %.1f s", deep[i].open, DEEP,
              tf_now() - t0);
        free(s);
    }
    refused("sphere { 0, 1 } \"abc", "unterminated string");
    refused("sphere { 0, 1 } \"abc\ndef\"", "unterminated string");
    /* what nests legally, 10^5 deep: comments and unary signs */
    {
        char *s = nest("", "/*", " x ", "*/", "sphere { 0, 1 }");
        accepted(s);
        free(s);
        s = nest("sphere { 0, ", "-", "1", "", " }");
        accepted(s); /* an even number of minus signs: +1 */
        free(s);
        s = nest("sphere { 0, ", "+-", "1", "", " }");
        accepted(s);
        free(s);
        s = nest("sphere { 0, 1", "", "", "+1", " }");
        accepted(s); /* a long flat sum: a loop, not recursion */
        free(s);
    }
}

/* ---- running a program with its peak memory measured ------------------ */

typedef struct run_result {
    int status;       /* exit status, 128 + signal, or -1 */
    long peak_kb;     /* the program's own peak RSS, KiB (-1: unknown) */
    double seconds;
    char out[2048];   /* stdout (start) */
    char err[2048];   /* stderr (start) */
} run_result;

/* Run program with args through measure_child, which reports the
 * program's own peak RSS (see tests/common/measure_child.c: a child forked
 * from this process would count this process's memory, and under valgrind
 * or ASan that is the tool's).  fsize_limit > 0 sets RLIMIT_FSIZE, with
 * SIGXFSZ ignored, so writes fail with EFBIG.  stdout and stderr are
 * captured. */
static run_result run_measured(const char *program, const char *const *args, long fsize_limit)
{
    run_result r;
    tp_opts opts = { .fsize_limit = fsize_limit, .measure_memory = 1 };
    tp_result t;

    memset(&r, 0, sizeof r);
    r.status = -1;
    r.peak_kb = -1;
    if (tp_run(program, args, &opts, &t) != 0)
        return r;
    r.status = t.status;
    r.peak_kb = t.peak_kb;
    r.seconds = t.seconds;
    snprintf(r.out, sizeof r.out, "%s", t.out);
    snprintf(r.err, sizeof r.err, "%s", t.err);
    tp_result_free(&t);
    return r;
}

/* ---- 10^6 objects ------------------------------------------------------- */

/* Parse `count` copies of `item` in tests/renderer/parse_many; returns its peak
 * RSS in KiB (-1 on failure) and the message / object count it printed. */
static long parse_many_measured(const char *item, long count, size_t max_objects, char *msg,
                                size_t msg_size, long *objects, double *seconds)
{
    char cnt[32], lim[32];
    const char *args[] = { item, cnt, lim, NULL };
    run_result r;
    char *nl;

    snprintf(cnt, sizeof cnt, "%ld", count);
    snprintf(lim, sizeof lim, "%zu", max_objects);
    r = run_measured(PARSE_MANY, args, 0);
    *seconds = r.seconds;
    *objects = -1;
    msg[0] = '\0';
    if (r.status != 0) {
        snprintf(msg, msg_size, "parse_many exit %d: %.400s", r.status, r.err);
        return -1;
    }
    nl = strchr(r.out, '\n');
    if (!nl || sscanf(r.out, "%ld", objects) != 1)
        return -1;
    snprintf(msg, msg_size, "%s", nl + 1);
    nl = strchr(msg, '\n');
    if (nl)
        *nl = '\0';
    return r.peak_kb;
}

static void test_many_objects(void)
{
    char msg[512];
    long objects, kb;
    double secs;

    kb = parse_many_measured("sphere{0,1}\n", 1000000, 0, msg, sizeof msg, &objects, &secs);
    CHECK(kb > 0, "the child parsing 10^6 objects failed (crashed or ran out of memory)");
    CHECK(has_location(msg, "many.scene", 0) && strstr(msg, "many.scene:100001:1: ") == msg &&
              strstr(msg, "too many objects (the limit is 100000)") != NULL,
          "10^6 objects: expected 'many.scene:100001:1: too many objects (the limit is 100000)',"
          " got '%s'", msg);
    CHECK(objects == 100000, "10^6 objects: %ld kept before the limit", objects);
    CHECK(kb > 0 && kb / 1024 <= MAX_OBJECTS_PEAK_MB,
          "10^6 objects: peak memory %ld MiB > %d MiB", kb / 1024, MAX_OBJECTS_PEAK_MB);
    CHECK(secs < 60.0, "10^6 objects: %.1f s", secs);
    printf("10^6 objects (default limit): refused at object 100,001 after %.2f s, child peak "
           "RSS %.1f MiB (limit %d MiB%s)\n", secs, kb / 1024.0, MAX_OBJECTS_PEAK_MB,
           UNDER_ASAN ? ", ASan build" : "");

    kb = parse_many_measured("light_source{0,1}\n", 1000000, 0, msg, sizeof msg, &objects,
                             &secs);
    CHECK(kb > 0 && strstr(msg, "too many light sources (the limit is 100000)") != NULL &&
              has_location(msg, "many.scene", 0),
          "10^6 lights: got '%s'", msg);
    printf("10^6 light sources: refused, child peak RSS %.1f MiB\n", kb / 1024.0);

    /* under the limit: parsed, and the memory is what the objects need */
    kb = parse_many_measured("sphere{0,1}\n", 50000, 0, msg, sizeof msg, &objects, &secs);
    CHECK(kb > 0 && strcmp(msg, "ok") == 0 && objects == 50000,
          "50,000 objects: '%s', %ld objects", msg, objects);
    printf("50,000 objects: parsed in %.2f s, child peak RSS %.1f MiB (%zu bytes per object)\n",
           secs, kb / 1024.0, sizeof(rs_object));
}

/* ---- truncated scene files ---------------------------------------------- */

static void test_truncations(void)
{
    DIR *d = opendir(SCENES);
    struct dirent *e;
    int files = 0;
    long prefixes = 0, parsed = 0;
    uint64_t rng = 0x9E3779B97F4A7C15ull;

    CHECK(d != NULL, "cannot open %s", SCENES);
    if (!d)
        return;
    while ((e = readdir(d)) != NULL) {
        size_t nl = strlen(e->d_name), len;
        char path[4096], what[4200];
        unsigned char *data;
        char *buf;
        if (nl < 7 || strcmp(e->d_name + nl - 6, ".scene") != 0)
            continue;
        snprintf(path, sizeof path, "%s/%s", SCENES, e->d_name);
        data = (unsigned char *)tf_read(path, &len);
        CHECK(data != NULL, "cannot read %s", path);
        if (!data)
            continue;
        files++;
        buf = malloc(len + 64);
        if (!buf)
            abort();
        memcpy(buf, data, len);
        buf[len] = '\0';
        CHECK(parse_checked(buf, len, e->d_name, path) == 0, "%s does not parse whole", path);
        for (size_t cut = 0; cut < len; cut++) {
            memcpy(buf, data, cut);
            buf[cut] = '\0';
            snprintf(what, sizeof what, "%s cut at byte %zu", e->d_name, cut);
            if (parse_checked(buf, cut, e->d_name, what) == 0)
                parsed++;
            prefixes++;
            /* the same prefix followed by junk bytes */
            {
                size_t k = 1 + (size_t)(rng % 16);
                for (size_t j = 0; j < k; j++) {
                    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
                    buf[cut + j] = (char)(1 + rng % 255);
                }
                buf[cut + k] = '\0';
                snprintf(what, sizeof what, "%s cut at byte %zu + junk", e->d_name, cut);
                parse_checked(buf, cut + k, e->d_name, what);
            }
        }
        free(buf);
        free(data);
    }
    closedir(d);
    CHECK(files >= 5, "only %d scene files in %s", files, SCENES);
    printf("truncations: %ld prefixes of %d scene files (%ld parse as complete scenes), each "
           "also followed by junk\n", prefixes, files, parsed);
}

/* ---- binary junk -------------------------------------------------------- */

static void test_junk(void)
{
    char path[4096], msg[512];
    uint64_t rng = 0x243F6A8885A308D3ull;
    unsigned char buf[4097];
    rs_scene scene;

    snprintf(path, sizeof path, "%s/hostile_junk.%ld.scene", LP_TEST_TMP, (long)getpid());
    for (int round = 0; round < 2000; round++) {
        size_t len = (size_t)(rng % 4096);
        int printable = round % 2; /* half: bytes of the scene alphabet */
        static const char alpha[] = "{}<>(),;=+-*/.#\"0123456789eE xyz\nsphere lens pigment";
        for (size_t i = 0; i < len; i++) {
            rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
            buf[i] = printable ? (unsigned char)alpha[rng % (sizeof alpha - 1)]
                               : (unsigned char)(rng & 0xFF);
        }
        rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
        buf[len] = '\0';
        parse_checked((const char *)buf, strlen((const char *)buf), "junk.scene", "junk");
        /* from a file, with its NULs */
        if (tf_write(path, buf, len) != 0) {
            CHECK(0, "cannot write %s", path);
            break;
        }
        rs_scene_init(&scene);
        if (rs_parse_file(path, NULL, &scene, msg, sizeof msg) != 0)
            CHECK(has_location(msg, path, 0), "junk file: error '%s' names no place", msg);
        rs_scene_free(&scene);
    }
    /* a NUL in the middle of a valid scene read from a file */
    {
        static const char nul[] = "sphere { 0, 1 }\n\0sphere { 0, 1 }\n";
        tf_write(path, nul, sizeof nul - 1);
        rs_scene_init(&scene);
        CHECK(rs_parse_file(path, NULL, &scene, msg, sizeof msg) != 0 &&
                  has_location(msg, path, 2) && strstr(msg, "0x00") != NULL,
              "a NUL byte in a scene file: '%s'", msg);
        rs_scene_free(&scene);
    }
    remove(path);
    /* an endless file: refused after 64 MiB, not read into memory forever */
    {
        double t0 = tf_now();
        rs_scene_init(&scene);
        CHECK(rs_parse_file("/dev/zero", NULL, &scene, msg, sizeof msg) != 0 &&
                  strstr(msg, "larger than 64 MiB") != NULL && has_location(msg, "/dev/zero", 1),
              "/dev/zero: '%s'", msg);
        rs_scene_free(&scene);
        CHECK(tf_now() - t0 < 30.0, "/dev/zero took %.1f s", tf_now() - t0);
    }
    /* a directory */
    rs_scene_init(&scene);
    CHECK(rs_parse_file(SCENES, NULL, &scene, msg, sizeof msg) != 0 &&
              strstr(msg, "cannot read") != NULL,
          "a directory as the scene: '%s'", msg);
    rs_scene_free(&scene);
}

/* ---- lensrender --------------------------------------------------------- */

static run_result run_lensrender(const char *const *args, long fsize_limit)
{
    return run_measured(LENSRENDER, args, fsize_limit);
}

static int one_line(const char *s)
{
    const char *nl = strchr(s, '\n');
    return nl != NULL && nl[1] == '\0';
}

static int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static void test_resolutions(void)
{
    static const struct { const char *w, *h, *want; } bad[] = {
        { "100000", "100000", "--width" },
        { "16384", "16384", "pixels" },
        { "1000000000", "1", "--width" },
        { "99999999999999999999", "1", "--width" },
        { "1", "-5", "--height" },
        { "0", "1", "--width" },
        { "1e9", "1", "--width" },
        { "nan", "1", "--width" },
        { "1", "0x7fffffff", "--height" },
    };
    char out[4096], scene[4096];

    snprintf(out, sizeof out, "%s/hostile_res.%ld.png", LP_TEST_TMP, (long)getpid());
    snprintf(scene, sizeof scene, "%s/scenes/default.scene", LP_SOURCE_DIR);
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        rs_args a;
        char *argv[] = { "lensrender", scene, "--width", (char *)bad[i].w, "--height",
                         (char *)bad[i].h, NULL };
        const char *args[] = { scene, "-o", out, "--width", bad[i].w, "--height", bad[i].h,
                               NULL };
        const char *err;
        run_result r;

        rs_args_init(&a);
        err = rs_args_parse(&a, 6, argv);
        CHECK(err != NULL && strstr(err, bad[i].want) != NULL,
              "--width %s --height %s: rs_args_parse said '%s'", bad[i].w, bad[i].h,
              err ? err : "(accepted)");

        r = run_lensrender(args, 0);
        CHECK(r.status == 2, "lensrender --width %s --height %s: exit %d", bad[i].w, bad[i].h,
              r.status);
        CHECK(one_line(r.err) && strstr(r.err, bad[i].want) != NULL,
              "lensrender --width %s --height %s: stderr '%s'", bad[i].w, bad[i].h, r.err);
        CHECK(r.peak_kb / 1024 <= REFUSED_RUN_PEAK_MB && r.seconds < 10.0,
              "lensrender --width %s --height %s: %.1f MiB peak, %.1f s (no allocation "
              "expected)", bad[i].w, bad[i].h, r.peak_kb / 1024.0, r.seconds);
        CHECK(!file_exists(out), "lensrender --width %s: created %s", bad[i].w, out);
        if (i == 0)
            printf("lensrender --width 100000 --height 100000: exit %d in %.3f s, peak RSS "
                   "%.1f MiB: %s", r.status, r.seconds, r.peak_kb / 1024.0, r.err);
    }
    remove(out);
}

/* A render whose PNG write fails half-way (the file size limit) must keep
 * the good PNG from before, and leave no temporary file. */
static void test_atomic_output(void)
{
    char dir[4096], out[4200], scene[4096], bad_scene[4200];
    unsigned char *good = NULL, *after = NULL;
    size_t good_len = 0, after_len = 0;
    const char *render[] = { scene, "-o", out, "--width", "48", "--height", "36",
                             "--wavelengths", "1", "--depth", "2", "--threads", "1", "--quiet",
                             NULL };
    const char *broken[] = { bad_scene, "-o", out, "--width", "48", "--height", "36",
                             "--quiet", NULL };
    run_result r;

    snprintf(dir, sizeof dir, "%s/hostile_atomic.%ld", LP_TEST_TMP, (long)getpid());
    mkdir(dir, 0777);
    snprintf(out, sizeof out, "%s/out.png", dir);
    snprintf(bad_scene, sizeof bad_scene, "%s/bad.scene", dir);
    snprintf(scene, sizeof scene, "%s/scenes/default.scene", LP_SOURCE_DIR);

    r = run_lensrender(render, 0);
    CHECK(r.status == 0, "the good render failed (%d): %s", r.status, r.err);
    good = (unsigned char *)tf_read(out, &good_len);
    CHECK(good != NULL && good_len > 200, "no good PNG at %s", out);
    if (!good || good_len <= 200) {
        free(good);
        return;
    }

    /* a file size limit below the PNG's size: the write fails half-way */
    r = run_lensrender(render, (long)good_len / 2);
    CHECK(r.status != 0 && r.status < 128, "a render that cannot write its PNG: exit %d (%s)",
          r.status, r.err);
    CHECK(strstr(r.err, "out.png") != NULL, "the write failure names no file: %s", r.err);
    after = (unsigned char *)tf_read(out, &after_len);
    CHECK(after != NULL && after_len == good_len && memcmp(after, good, good_len) == 0,
          "a failed PNG write changed %s (%zu bytes, was %zu)", out, after_len, good_len);
    free(after);

    /* a hostile scene aimed at the same output */
    {
        char *deep = nest("sphere { 0, ", "(", "1", ")", " }");
        tf_write(bad_scene, deep, strlen(deep));
        free(deep);
    }
    r = run_lensrender(broken, 0);
    CHECK(r.status == 2 && one_line(r.err) && strstr(r.err, "nesting deeper than") != NULL,
          "a deeply nested scene: exit %d, stderr '%s'", r.status, r.err);
    after = (unsigned char *)tf_read(out, &after_len);
    CHECK(after != NULL && after_len == good_len && memcmp(after, good, good_len) == 0,
          "a refused scene changed %s", out);
    free(after);

    /* nothing but the good PNG and the scene is left in the directory */
    {
        DIR *d = opendir(dir);
        struct dirent *e;
        int others = 0;
        while (d && (e = readdir(d)) != NULL) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..") ||
                !strcmp(e->d_name, "out.png") || !strcmp(e->d_name, "bad.scene"))
                continue;
            CHECK(0, "a failed render left %s/%s behind", dir, e->d_name);
            others++;
        }
        if (d)
            closedir(d);
        (void)others;
    }
    remove(out);
    remove(bad_scene);
    rmdir(dir);
    free(good);
}

int main(void)
{
    /* first, while this process is small: the memory measurements (a
     * child's peak RSS counts what it inherited from this process) */
    test_many_objects();
    test_resolutions();
    test_regressions();
    test_numbers();
    test_lenses();
    test_nesting();
    test_truncations();
    test_junk();
    test_atomic_output();
    return check_finish("test_hostile_scenes");
}
