/* test_lenstrace_cone.c -- lenstrace --cone, the contract's output.
 *
 * A flat plate seen from a point on its axis is the closed form: a ray at
 * polar angle theta enters at r0 = L tan(theta), and each of the dT - 1
 * internal segments moves it out by t tan(beta), sin(theta) = n sin(beta);
 * theta_K solves L tan(theta) + (dT - 1) t tan(beta) = h (solved here by
 * bisection of that equation alone).  Checked: one line per azimuth with
 * the azimuths 360 k / K, theta equal to the closed form, the cone line's
 * depth, solid angle 2 pi (1 - cos theta_K), theta_min/theta_max; an
 * off-axis point gives a non-circular cone; every bad input exits 2 with
 * exactly one line on stderr naming the problem and nothing on stdout. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "subprocess.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define LENSTRACE LP_BIN_DIR "/lenstrace"

static int run(const char *const *args, tp_result *r)
{
    char what[512];
    tp_describe(LENSTRACE, args, what, sizeof what);
    if (tp_run(LENSTRACE, args, NULL, r) != 0) {
        fprintf(stderr, "%s: %s\n", what, r->error);
        return 0;
    }
    return 1;
}

/* The number after "key": in line s, or NAN. */
static double num_after(const char *s, const char *key)
{
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\":", key);
    const char *p = strstr(s, pat);
    return p ? strtod(p + strlen(pat), NULL) : NAN;
}

/* theta_K of the plate: h = L tan(th) + m t tan(asin(sin(th) / n)). */
static double plate_theta(double L, double t, double h, double n, int m)
{
    double lo = 0, hi = M_PI / 2 - 1e-12;
    for (int i = 0; i < 200; i++) {
        double mid = 0.5 * (lo + hi);
        double sb = sin(mid) / n;
        double r = L * tan(mid) + m * t * sb / sqrt(1 - sb * sb);
        if (r <= h)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

static void test_plate(void)
{
    const char *lens = "R1=inf,R2=inf,t=5,D=20,n=1.5";
    for (int depth = 1; depth <= 6; depth++) {
        char ds[8];
        snprintf(ds, sizeof ds, "%d", depth);
        const char *args[] = {"--lens", lens, "--cone", "0,0,-30", "--depth", ds,
                              "--azimuths", "8", NULL};
        tp_result r;
        if (!run(args, &r))
            continue;
        CHECK(r.status == 0 && r.err_len == 0, "plate dT=%d: status %d, stderr '%s'", depth,
              r.status, r.err);
        double want = plate_theta(30, 5, 10, 1.5, depth - 1) * 180 / M_PI;
        int lines = 0;
        const char *p = r.out;
        while (p && *p) {
            const char *e = strchr(p, '\n');
            if (!e)
                break;
            char line[512];
            size_t len = (size_t)(e - p) < sizeof line - 1 ? (size_t)(e - p) : sizeof line - 1;
            memcpy(line, p, len);
            line[len] = '\0';
            if (lines < 8) {
                CHECK(strncmp(line, "{\"azimuth\":", 11) == 0 && strstr(line, ",\"theta\":") &&
                          line[len - 1] == '}',
                      "plate dT=%d line %d: '%s'", depth, lines, line);
                CHECK_ABS(num_after(line, "azimuth"), 45.0 * lines, 1e-12,
                          "plate dT=%d azimuth of line %d", depth, lines);
                /* measured: 3e-8 deg (the library bisects to 1e-9 rad) */
                CHECK_ABS(num_after(line, "theta"), want, 1e-6, "plate dT=%d theta line %d",
                          depth, lines);
            } else if (lines == 8) {
                CHECK(strncmp(line, "{\"cone\":{\"depth\":", 17) == 0, "cone line: '%s'", line);
                CHECK(num_after(line, "depth") == depth, "cone line depth");
                double th = want * M_PI / 180;
                /* measured: 3.3e-9 relative */
                CHECK_REL(num_after(line, "solid_angle"), 2 * M_PI * (1 - cos(th)), 1e-7,
                          "plate dT=%d solid angle", depth);
                CHECK_ABS(num_after(line, "theta_min"), want, 1e-6, "theta_min");
                CHECK_ABS(num_after(line, "theta_max"), want, 1e-6, "theta_max");
            }
            lines++;
            p = e + 1;
        }
        CHECK(lines == 9, "plate dT=%d: %d lines, want 8 azimuths + 1 cone line", depth, lines);
        tp_result_free(&r);
    }
}

static void test_defaults_and_off_axis(void)
{
    const char *args[] = {"--lens", "R1=50,R2=-50,t=8,D=25,glass=N-BK7", "--cone", "4,0,-30",
                          NULL};
    tp_result r;
    if (!run(args, &r))
        return;
    CHECK(r.status == 0, "off-axis: status %d '%s'", r.status, r.err);
    int lines = 0;
    double tmin = 1e9, tmax = -1e9;
    for (const char *p = r.out; p && *p;) {
        const char *e = strchr(p, '\n');
        if (!e)
            break;
        if (strncmp(p, "{\"azimuth\":", 11) == 0) {
            double th = num_after(p, "theta");
            tmin = fmin(tmin, th);
            tmax = fmax(tmax, th);
            lines++;
        } else {
            CHECK(num_after(p, "depth") == 5, "default depth 5");
            CHECK(fabs(num_after(p, "theta_min") - tmin) < 1e-12 &&
                      fabs(num_after(p, "theta_max") - tmax) < 1e-12,
                  "theta_min/max are the extremes of the lines");
        }
        p = e + 1;
    }
    CHECK(lines == 36, "default 36 azimuths, got %d", lines);
    CHECK(tmax - tmin > 0.1, "off the axis the cone is not circular (%.6f..%.6f deg)", tmin, tmax);
    tp_result_free(&r);
}

static void test_bad_input(void)
{
    const char *lens = "R1=50,R2=-50,t=8,D=25,n=1.5";
    struct {
        const char *args[12];
        const char *word;
    } cases[] = {
        {{"--lens", lens, "--cone", "0,0,4", NULL}, "inside"},
        {{"--lens", lens, "--cone", "0,0,0", NULL}, "vertex"},
        {{"--lens", lens, "--cone", "0,0", NULL}, "x,y,z"},
        {{"--lens", lens, "--cone", "a,0,-5", NULL}, "number"},
        {{"--lens", lens, "--cone", "nan,0,-5", NULL}, "finite"},
        {{"--lens", lens, "--cone", "0,0,-5", "--azimuths", "0", NULL}, "azimuths"},
        {{"--lens", lens, "--cone", "0,0,-5", "--azimuths", "3x", NULL}, "azimuths"},
        {{"--lens", lens, "--cone", "0,0,-5", "--depth", "0", NULL}, "depth"},
        {{"--lens", lens, "--cone", "0,0,-5", "--lambda", "-1", NULL}, "lambda"},
        {{"--lens", lens, "--cone", "0,0,-5", "--ray", "o=0,0,-5 d=0,0,1", NULL}, "ray"},
        {{"--lens", lens, "--azimuths", "4", "--ray", "o=0,0,-5 d=0,0,1", NULL}, "cone"},
        {{"--lens", "R1=50,R2=-50,t=8,D=200,n=1.5", "--cone", "0,0,-5", NULL}, "wider"},
        {{"--cone", "0,0,-5", NULL}, "lens"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        tp_result r;
        if (!run(cases[i].args, &r))
            continue;
        const char *nl = r.err ? strchr(r.err, '\n') : NULL;
        CHECK(r.status == 2 && r.out_len == 0 && nl && nl[1] == '\0' &&
                  strstr(r.err, cases[i].word) && strncmp(r.err, "lenstrace: ", 11) == 0,
              "bad input %zu: status %d, stdout %zu bytes, stderr '%s' (want one line naming "
              "'%s')",
              i, r.status, r.out_len, r.err ? r.err : "", cases[i].word);
        tp_result_free(&r);
    }
}

int main(void)
{
    test_plate();
    test_defaults_and_off_axis();
    test_bad_input();
    return check_finish("test_lenstrace_cone");
}
