/* test_lensrender_cli.c -- runs the built lensrender binary and checks its
 * contract (docs/interfaces.md, "lensrender"):
 *   - the image does not depend on --threads: --threads 1 and --threads 2
 *     give byte-identical PFM (and PNG) files for scenes/default.scene;
 *   - the PNG is a well-formed 8-bit RGB PNG (signature, chunk CRCs, IHDR
 *     first, IEND last) of the requested size carrying sRGB and gAMA
 *     (45455) chunks before the image data; the PFM has the PF header,
 *     the size and little-endian scale -1;
 *   - bad input (missing scene, parse error, --width 0, --mode foo): exit
 *     status 2, exactly one line on stderr, nothing on stdout, and no
 *     output file (nor a temporary one) created;
 *   - a failed run does not clobber existing outputs: a good PNG/PFM
 *     written first stays byte-for-byte the same after a run with a
 *     broken scene aimed at the same paths, and after a run that cannot
 *     write its PFM (exit 1);
 *   - --threads 1, 2, 3, 7 and 64 give the same bytes;
 *   - --wavelengths over 1..16384: a directly seen emitter renders as its
 *     RGB (0 and 16385 refused);
 *   - --depth and --cutoff change a plate's transmission as the series of
 *     its internal reflections says;
 *   - the progress line on a terminal (a pseudo-terminal), none with
 *     --quiet or on a pipe. */
#define _POSIX_C_SOURCE 200809L
#define _XOPEN_SOURCE 700 /* posix_openpt, grantpt, unlockpt, ptsname */

#include <dirent.h>
#include <fcntl.h>
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "check.h"
#include "subprocess.h"

#ifndef LP_BIN_DIR
#error "LP_BIN_DIR must name the directory of the built programs"
#endif
#ifndef LP_TEST_TMP
#define LP_TEST_TMP "."
#endif
#ifndef LP_SOURCE_DIR
#error "LP_SOURCE_DIR must name the source tree"
#endif

static const char *const LENSRENDER = LP_BIN_DIR "/lensrender";
static const char *const DEFAULT_SCENE = LP_SOURCE_DIR "/scenes/default.scene";

/* ---- running the program ------------------------------------------------ */

typedef struct proc {
    int status; /* exit status, or 128 + signal, or -1 */
    char *out;
    char *err;
    char what[1024];
} proc;

static char *slurp_file(FILE *f, size_t *len)
{
    long n;
    char *s;
    fflush(f);
    if (fseek(f, 0, SEEK_END) != 0 || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0)
        return NULL;
    s = malloc((size_t)n + 1);
    if (!s)
        return NULL;
    if (fread(s, 1, (size_t)n, f) != (size_t)n) {
        free(s);
        return NULL;
    }
    s[n] = '\0';
    if (len)
        *len = (size_t)n;
    return s;
}

static proc run_argv(const char *const *args)
{
    proc p;
    tp_result r;

    memset(&p, 0, sizeof p);
    tp_describe(LENSRENDER, args, p.what, sizeof p.what);
    if (tp_run(LENSRENDER, args, NULL, &r) != 0) {
        fprintf(stderr, "%s: %s\n", p.what, r.error);
        exit(1);
    }
    p.status = r.status;
    p.out = r.out;
    p.err = r.err;
    return p;
}

static void proc_free(proc *p)
{
    free(p->out);
    free(p->err);
}

static unsigned char *read_all(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    unsigned char *s;
    if (!f)
        return NULL;
    s = (unsigned char *)slurp_file(f, len);
    fclose(f);
    return s;
}

static int write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    int ok = fputs(text, f) >= 0;
    return (fclose(f) == 0 && ok) ? 0 : -1;
}

/* A fresh empty directory under LP_TEST_TMP. */
static void fresh_dir(char *out, size_t n, const char *name)
{
    char cmd[4200];
    snprintf(out, n, "%s/lensrender_cli.%ld/%s", LP_TEST_TMP, (long)getpid(), name);
    snprintf(cmd, sizeof cmd, "%s/lensrender_cli.%ld", LP_TEST_TMP, (long)getpid());
    mkdir(cmd, 0777);
    if (mkdir(out, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "mkdir %s: %s\n", out, strerror(errno));
        exit(1);
    }
}

/* Number of entries in a directory other than . and .., listing them. */
static int dir_entries(const char *dir, char *names, size_t n)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int count = 0;
    if (names && n)
        names[0] = '\0';
    if (!d)
        return -1;
    while ((e = readdir(d)) != NULL) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        count++;
        if (names) {
            size_t l = strlen(names);
            snprintf(names + l, n - l, "%s ", e->d_name);
        }
    }
    closedir(d);
    return count;
}

/* Remove the regular files of a directory, then the directory. */
static void remove_dir(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    char path[4600];
    if (!d)
        return;
    while ((e = readdir(d)) != NULL) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        unlink(path);
    }
    closedir(d);
    rmdir(dir);
}

/* ---- PNG structure --------------------------------------------------------- */

static uint32_t crc_table[256];

static void crc_init(void)
{
    for (uint32_t n = 0; n < 256; n++) {
        uint32_t c = n;
        for (int k = 0; k < 8; k++)
            c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        crc_table[n] = c;
    }
}

static uint32_t crc32_of(const unsigned char *p, size_t n)
{
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++)
        c = crc_table[(c ^ p[i]) & 0xFF] ^ (c >> 8);
    return c ^ 0xFFFFFFFFu;
}

static uint32_t be32(const unsigned char *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static void check_png(const char *path, int w, int h)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    size_t len = 0;
    unsigned char *b = read_all(path, &len);
    CHECK(b != NULL, "PNG %s exists", path);
    if (!b)
        return;
    CHECK(len > 8 && memcmp(b, sig, 8) == 0, "PNG %s starts with the PNG signature", path);
    int n_chunks = 0, crc_ok = 1, ihdr_first = 0, iend_last = 0;
    int has_srgb = 0, has_gama = 0, srgb_before_idat = 0, gama_before_idat = 0, seen_idat = 0;
    uint32_t gama = 0, iw = 0, ih = 0;
    int depth = -1, ctype = -1;
    size_t pos = 8;
    while (len >= 8 && pos + 12 <= len) {
        uint32_t n = be32(b + pos);
        if (n > len - pos - 12)
            break;
        const unsigned char *type = b + pos + 4, *data = b + pos + 8;
        if (crc32_of(type, (size_t)n + 4) != be32(data + n))
            crc_ok = 0;
        if (n_chunks == 0 && !memcmp(type, "IHDR", 4) && n == 13) {
            ihdr_first = 1;
            iw = be32(data);
            ih = be32(data + 4);
            depth = data[8];
            ctype = data[9];
        }
        if (!memcmp(type, "IDAT", 4))
            seen_idat = 1;
        if (!memcmp(type, "sRGB", 4)) {
            has_srgb = 1;
            srgb_before_idat = !seen_idat;
        }
        if (!memcmp(type, "gAMA", 4) && n == 4) {
            has_gama = 1;
            gama_before_idat = !seen_idat;
            gama = be32(data);
        }
        n_chunks++;
        pos += 12 + (size_t)n;
        if (!memcmp(type, "IEND", 4)) {
            iend_last = pos == len;
            break;
        }
    }
    CHECK(crc_ok, "PNG %s: every chunk's CRC is right", path);
    CHECK(ihdr_first, "PNG %s: IHDR comes first", path);
    CHECK(iend_last, "PNG %s: IEND ends the file", path);
    CHECK(iw == (uint32_t)w && ih == (uint32_t)h, "PNG %s is %ux%u, want %dx%d", path, iw, ih, w,
          h);
    CHECK(depth == 8 && ctype == 2, "PNG %s: 8-bit RGB (depth %d, colour type %d)", path, depth,
          ctype);
    CHECK(has_srgb && srgb_before_idat, "PNG %s has an sRGB chunk before the image data", path);
    CHECK(has_gama && gama_before_idat, "PNG %s has a gAMA chunk before the image data", path);
    CHECK(gama == 45455, "PNG %s: gAMA %u, want 45455 (1/2.2)", path, gama);
    free(b);
}

static void check_pfm(const char *path, int w, int h)
{
    size_t len = 0;
    unsigned char *b = read_all(path, &len);
    char want[64];
    CHECK(b != NULL, "PFM %s exists", path);
    if (!b)
        return;
    int hl = snprintf(want, sizeof want, "PF\n%d %d\n-1.0\n", w, h);
    CHECK(len >= (size_t)hl && memcmp(b, want, (size_t)hl) == 0,
          "PFM %s has the header PF / %d %d / -1.0", path, w, h);
    CHECK(len == (size_t)hl + (size_t)w * h * 12, "PFM %s has %zu bytes, want %zu", path, len,
          (size_t)hl + (size_t)w * h * 12);
    free(b);
}

/* ---- the checks -------------------------------------------------------------- */

static void test_threads_identical(void)
{
    char dir[4096], png1[4200], png2[4200], pfm1[4200], pfm2[4200];
    fresh_dir(dir, sizeof dir, "threads");
    snprintf(png1, sizeof png1, "%s/t1.png", dir);
    snprintf(png2, sizeof png2, "%s/t2.png", dir);
    snprintf(pfm1, sizeof pfm1, "%s/t1.pfm", dir);
    snprintf(pfm2, sizeof pfm2, "%s/t2.pfm", dir);
    const char *a1[] = {DEFAULT_SCENE, "-o", png1, "--pfm", pfm1, "--width", "96", "--height",
                        "72", "--threads", "1", "--quiet", NULL};
    const char *a2[] = {DEFAULT_SCENE, "-o", png2, "--pfm", pfm2, "--width", "96", "--height",
                        "72", "--threads", "2", "--quiet", NULL};
    proc p1 = run_argv(a1), p2 = run_argv(a2);
    CHECK(p1.status == 0, "%s: exit %d, stderr: %s", p1.what, p1.status, p1.err);
    CHECK(p2.status == 0, "%s: exit %d, stderr: %s", p2.what, p2.status, p2.err);
    CHECK(p1.err[0] == '\0' && p1.out[0] == '\0', "--quiet prints nothing: [%s] [%s]", p1.out,
          p1.err);
    size_t l1 = 0, l2 = 0, m1 = 0, m2 = 0;
    unsigned char *f1 = read_all(pfm1, &l1), *f2 = read_all(pfm2, &l2);
    unsigned char *g1 = read_all(png1, &m1), *g2 = read_all(png2, &m2);
    CHECK(f1 && f2 && l1 == l2 && memcmp(f1, f2, l1) == 0,
          "--threads 1 and --threads 2 give byte-identical PFM files (%zu, %zu bytes)", l1, l2);
    CHECK(g1 && g2 && m1 == m2 && memcmp(g1, g2, m1) == 0,
          "--threads 1 and --threads 2 give byte-identical PNG files");
    /* More threads than cores, an odd count, more threads than the 96x72
     * image has tiles: the same bytes. */
    static const char *const more[] = {"3", "7", "64"};
    for (size_t k = 0; k < sizeof more / sizeof *more; k++) {
        const char *an[] = {DEFAULT_SCENE, "-o", png2, "--pfm", pfm2, "--width", "96",
                            "--height", "72", "--threads", more[k], "--quiet", NULL};
        proc pn = run_argv(an);
        CHECK(pn.status == 0, "%s: exit %d, stderr: %s", pn.what, pn.status, pn.err);
        size_t ln = 0;
        unsigned char *fn = read_all(pfm2, &ln);
        CHECK(f1 && fn && l1 == ln && memcmp(f1, fn, l1) == 0,
              "--threads 1 and --threads %s give byte-identical PFM files", more[k]);
        free(fn);
        proc_free(&pn);
    }
    /* not an all-black (or all-equal) render: the scene is there */
    if (f1 && l1 > 64) {
        size_t hl = strlen("PF\n96 72\n-1.0\n");
        int differ = 0;
        for (size_t i = hl + 12; i + 12 <= l1; i += 12)
            if (memcmp(f1 + hl, f1 + i, 12) != 0)
                differ = 1;
        CHECK(differ, "the default scene's render is not uniform");
    }
    free(f1);
    free(f2);
    free(g1);
    free(g2);
    check_png(png1, 96, 72);
    check_pfm(pfm1, 96, 72);
    printf("threads: --threads 1 and 2 PFM %s (%zu bytes)\n",
           (l1 == l2) ? "identical" : "DIFFER", l1);
    proc_free(&p1);
    proc_free(&p2);
    remove_dir(dir);
}

/* A run that must fail with bad input: exit 2, one stderr line
 * containing `must_say` (if any), no stdout, nothing written in dir. */
static void expect_bad(const char *name, const char *const *args, const char *dir,
                       const char *must_say)
{
    char names[2048];
    proc p = run_argv(args);
    CHECK(p.status == 2, "%s: %s: exit %d, want 2", name, p.what, p.status);
    size_t el = strlen(p.err), lines = 0;
    for (size_t i = 0; i < el; i++)
        lines += p.err[i] == '\n';
    CHECK(lines == 1 && el > 1 && p.err[el - 1] == '\n',
          "%s: exactly one line on stderr, got %zu: [%s]", name, lines, p.err);
    CHECK(p.out[0] == '\0', "%s: nothing on stdout: [%s]", name, p.out);
    if (must_say)
        CHECK(strstr(p.err, must_say) != NULL, "%s: the message names '%s': %s", name, must_say,
              p.err);
    int n = dir_entries(dir, names, sizeof names);
    CHECK(n == 0, "%s: no output (nor temporary) file created, found: %s", name, names);
    printf("bad input %-13s exit %d: %s", name, p.status, p.err);
    proc_free(&p);
}

static void test_bad_input(void)
{
    char dir[4096], src[4096], bad_scene[4300], png[4300], pfm[4300], missing[4300];
    fresh_dir(dir, sizeof dir, "bad_out");
    fresh_dir(src, sizeof src, "bad_src");
    snprintf(png, sizeof png, "%s/out.png", dir);
    snprintf(pfm, sizeof pfm, "%s/out.pfm", dir);
    snprintf(missing, sizeof missing, "%s/no_such.scene", src);
    snprintf(bad_scene, sizeof bad_scene, "%s/broken.scene", src);
    /* line 3, column 10: a number where '{' must follow 'sphere' */
    CHECK(write_text(bad_scene, "// broken\ncamera { location <0, 0, -5> look_at 0 }\n"
                                "sphere 1 { 0, 1 pigment { rgb 1 } }\n") == 0,
          "write the broken scene");

    const char *a_missing[] = {missing, "-o", png, "--pfm", pfm, "--width", "8", "--height",
                               "6", NULL};
    expect_bad("missing scene", a_missing, dir, "no_such.scene");
    const char *a_parse[] = {bad_scene, "-o", png, "--pfm", pfm, "--width", "8", "--height", "6",
                             NULL};
    expect_bad("parse error", a_parse, dir, "broken.scene:3:8");
    const char *a_width[] = {DEFAULT_SCENE, "-o", png, "--pfm", pfm, "--width", "0", "--height",
                             "6", NULL};
    expect_bad("--width 0", a_width, dir, "width");
    const char *a_mode[] = {DEFAULT_SCENE, "-o", png, "--pfm", pfm, "--width", "8", "--height",
                            "6", "--mode", "foo", NULL};
    expect_bad("--mode foo", a_mode, dir, "foo");

    /* A failed run leaves existing outputs alone. */
    const char *a_good[] = {DEFAULT_SCENE, "-o", png, "--pfm", pfm, "--width", "16", "--height",
                            "12", "--quiet", NULL};
    proc g = run_argv(a_good);
    CHECK(g.status == 0, "%s: exit %d: %s", g.what, g.status, g.err);
    proc_free(&g);
    size_t lp0 = 0, lf0 = 0;
    unsigned char *png0 = read_all(png, &lp0), *pfm0 = read_all(pfm, &lf0);
    CHECK(png0 && pfm0, "the good run wrote its PNG and PFM");
    const char *a_clobber[] = {bad_scene, "-o", png, "--pfm", pfm, "--width", "16", "--height",
                               "12", NULL};
    proc b = run_argv(a_clobber);
    CHECK(b.status == 2, "%s: exit %d, want 2", b.what, b.status);
    proc_free(&b);
    size_t lp1 = 0, lf1 = 0;
    unsigned char *png1 = read_all(png, &lp1), *pfm1 = read_all(pfm, &lf1);
    CHECK(png0 && png1 && lp0 == lp1 && memcmp(png0, png1, lp0) == 0,
          "a failed run leaves the existing PNG unchanged");
    CHECK(pfm0 && pfm1 && lf0 == lf1 && memcmp(pfm0, pfm1, lf0) == 0,
          "a failed run leaves the existing PFM unchanged");
    /* A run that renders but cannot write its PFM fails (exit 1, one
     * line); it must not have replaced the PNG either (the outputs of a
     * failed run are all-or-nothing). */
    char bad_pfm[4400];
    snprintf(bad_pfm, sizeof bad_pfm, "%s/no_such_dir/out.pfm", dir);
    const char *a_pfm[] = {DEFAULT_SCENE, "-o", png, "--pfm", bad_pfm, "--width", "20",
                           "--height", "10", "--quiet", NULL};
    proc q = run_argv(a_pfm);
    size_t el = strlen(q.err), lines = 0;
    for (size_t i = 0; i < el; i++)
        lines += q.err[i] == '\n';
    CHECK(q.status == 1, "%s: exit %d, want 1", q.what, q.status);
    CHECK(lines == 1, "unwritable --pfm: one line on stderr: [%s]", q.err);
    proc_free(&q);
    free(png1);
    png1 = read_all(png, &lp1);
    CHECK(png0 && png1 && lp0 == lp1 && memcmp(png0, png1, lp0) == 0,
          "a run that fails writing its PFM leaves the existing PNG unchanged");
    char names[1024];
    CHECK(dir_entries(dir, names, sizeof names) == 2, "only out.png and out.pfm remain: %s",
          names);
    free(png0);
    free(pfm0);
    free(png1);
    free(pfm1);
    remove_dir(dir);
    remove_dir(src);
}

/* The linear RGB of pixel k of a PFM written by lensrender (bottom-up rows,
 * little-endian floats: the header says -1.0); 0 on success. */
static int pfm_pixel(const char *path, int w, int h, int i, int j, double rgb[3])
{
    size_t len = 0;
    unsigned char *b = read_all(path, &len);
    char head[64];
    int hl = snprintf(head, sizeof head, "PF\n%d %d\n-1.0\n", w, h);
    int rc = -1;
    if (b && len == (size_t)hl + (size_t)w * h * 12 && memcmp(b, head, (size_t)hl) == 0) {
        const unsigned char *p = b + hl + 12 * ((size_t)(h - 1 - j) * w + i);
        for (int c = 0; c < 3; c++) {
            uint32_t u = (uint32_t)p[4 * c] | (uint32_t)p[4 * c + 1] << 8 |
                         (uint32_t)p[4 * c + 2] << 16 | (uint32_t)p[4 * c + 3] << 24;
            float f;
            memcpy(&f, &u, sizeof f);
            rgb[c] = f;
        }
        rc = 0;
    }
    free(b);
    return rc;
}

/* Render scene text at w x h with extra arguments; fills rgb with pixel
 * (i, j) of the PFM.  0 on success. */
static int render_text(const char *dir, const char *text, int w, int h, const char *const *extra,
                       int i, int j, double rgb[3])
{
    char scene[4300], png[4300], pfm[4300], ws[16], hs[16];
    const char *a[32];
    size_t n = 0;
    snprintf(scene, sizeof scene, "%s/s.scene", dir);
    snprintf(png, sizeof png, "%s/s.png", dir);
    snprintf(pfm, sizeof pfm, "%s/s.pfm", dir);
    snprintf(ws, sizeof ws, "%d", w);
    snprintf(hs, sizeof hs, "%d", h);
    if (write_text(scene, text) != 0)
        return -1;
    a[n++] = scene;
    const char *fixed[] = {"-o", png, "--pfm", pfm, "--width", ws, "--height", hs, "--quiet"};
    for (size_t k = 0; k < sizeof fixed / sizeof *fixed; k++)
        a[n++] = fixed[k];
    for (size_t k = 0; extra && extra[k] && n + 1 < sizeof a / sizeof *a; k++)
        a[n++] = extra[k];
    a[n] = NULL;
    proc p = run_argv(a);
    int rc = p.status == 0 ? pfm_pixel(pfm, w, h, i, j, rgb) : -1;
    if (p.status != 0)
        fprintf(stderr, "%s: exit %d: %s", p.what, p.status, p.err);
    proc_free(&p);
    return rc;
}

/* PFM values are floats: half an ulp, 6e-8 relative, is all a correct
 * value may be off by after the doubles are rounded. */
#define FLOAT_TOL 1.2e-7

/* --wavelengths takes 1..16384 (args.h, --help).  A directly seen RGB
 * emitter renders as exactly its RGB whatever the count >= 3 (the colour
 * correction; test_spectrum checks its rounding), and with 1 or 2
 * wavelengths as grey (luminance only; white as 1): checked over the
 * range, to the PFM's float precision (measured 4e-8). */
static void test_wavelength_counts(void)
{
    char dir[4096], text[256];
    static const char *const counts[] = {"1", "2", "3", "5", "16", "100", "1024", "16384"};
    static const double cols[2][3] = {{1, 1, 1}, {0.8, 0.3, 0.1}};
    fresh_dir(dir, sizeof dir, "wavelengths");
    for (size_t k = 0; k < sizeof counts / sizeof *counts; k++)
        for (int c = 0; c < 2; c++) {
            snprintf(text, sizeof text,
                     "camera { location <0, 0, 0> look_at <0, 0, 1> angle 10 }\n"
                     "background { rgb <%g, %g, %g> }\n", cols[c][0], cols[c][1], cols[c][2]);
            const char *extra[] = {"--wavelengths", counts[k], NULL};
            double rgb[3];
            if (render_text(dir, text, 2, 2, extra, 1, 1, rgb) != 0) {
                CHECK(0, "--wavelengths %s renders", counts[k]);
                continue;
            }
            if (c == 1 && atoi(counts[k]) < 3) {
                /* no colour from one or two wavelengths: grey */
                CHECK(rgb[0] == rgb[1] && rgb[1] == rgb[2] && rgb[0] > 0,
                      "--wavelengths %s: a coloured emitter renders grey (%g %g %g)", counts[k],
                      rgb[0], rgb[1], rgb[2]);
                continue;
            }
            for (int ch = 0; ch < 3; ch++)
                CHECK_REL(rgb[ch], cols[c][ch], FLOAT_TOL,
                          "--wavelengths %s: emitter (%g %g %g) channel %d", counts[k],
                          cols[c][0], cols[c][1], cols[c][2], ch);
        }
    static const char *const bad[] = {"0", "16385"};
    for (size_t k = 0; k < 2; k++) {
        const char *a[] = {DEFAULT_SCENE, "--wavelengths", bad[k], "--quiet", NULL};
        proc p = run_argv(a);
        CHECK(p.status == 2, "--wavelengths %s refused: exit %d", bad[k], p.status);
        proc_free(&p);
    }
    remove_dir(dir);
}

/* --depth and --cutoff on the command line, on a lossless plate (n 1.5168,
 * R = ((n-1)/(n+1))^2 = 0.0422) in front of a self-lit plane, seen at
 * normal incidence in the rgb mode.  A path with 2k internal reflections
 * reaches the plane at trace level 3 + 2k and carries (1-R)^2 R^2k; inside
 * the glass, before leaving, its weight is (1-R) R^2k.  So --depth N keeps
 * the paths with 3 + 2k <= N (N = 2: the plane is out of reach, black;
 * 3, 4: (1-R)^2; 5, 6: (1-R)^2 (1 + R^2)) and --cutoff F those with
 * (1-R) R^2k >= F (thresholds 1.70e-3 and 3.03e-6: checked 10 % either
 * side).  The scene's own max_trace_level 60 and adc_bailout 1e-12 give
 * the whole series, (1-R)/(1+R), 3.1e-6 above one round trip. */
static void test_depth_cutoff(void)
{
    char dir[4096];
    const char *scene =
        "global_settings { max_trace_level 60 adc_bailout 1e-12 }\n"
        "camera { location <0, 0, -100> look_at <0, 0, 0> right x angle 2 }\n"
        "background { rgb 0 }\n"
        "lens { radius1 0 radius2 0 thickness 2 diameter 200 ior 1.5168 translate <0, 0, -1> }\n"
        "plane { z, 50 pigment { rgb 1 } finish { ambient 0 diffuse 0 emission 1 } }\n";
    const double n = 1.5168, r = (n - 1) / (n + 1), R = r * r;
    const double t0 = (1 - R) * (1 - R), t1 = t0 * (1 + R * R), tall = (1 - R) / (1 + R);
    const double c1 = (1 - R) * R * R, c2 = c1 * R * R;
    char c1a[32], c1b[32], c2a[32], c2b[32];
    snprintf(c1a, sizeof c1a, "%.6g", 1.1 * c1);
    snprintf(c1b, sizeof c1b, "%.6g", 0.9 * c1);
    snprintf(c2a, sizeof c2a, "%.6g", 1.1 * c2);
    snprintf(c2b, sizeof c2b, "%.6g", 0.9 * c2);
    const struct { const char *opt, *val; double want; } cases[] = {
        {NULL, NULL, tall},        {"--depth", "2", 0.0},  {"--depth", "3", t0},
        {"--depth", "4", t0},      {"--depth", "5", t1},   {"--depth", "6", t1},
        {"--cutoff", c1a, t0},     {"--cutoff", c1b, t1},  {"--cutoff", c2a, t1},
        {"--cutoff", c2b, tall},   {"--cutoff", "0", tall},
    };
    fresh_dir(dir, sizeof dir, "depth_cutoff");
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        const char *extra[] = {"--mode", "rgb", cases[k].opt, cases[k].val, NULL};
        double rgb[3];
        if (render_text(dir, scene, 1, 1, extra, 0, 0, rgb) != 0) {
            CHECK(0, "%s %s renders", cases[k].opt ? cases[k].opt : "(scene's)",
                  cases[k].val ? cases[k].val : "");
            continue;
        }
        for (int ch = 0; ch < 3; ch++)
            CHECK_ABS(rgb[ch], cases[k].want, FLOAT_TOL * cases[k].want + 1e-30,
                      "plate with %s %s: channel %d", cases[k].opt ? cases[k].opt : "(scene's)",
                      cases[k].val ? cases[k].val : "settings", ch);
    }
    remove_dir(dir);
}

/* Run lensrender with its stderr (and stdout) on a pseudo-terminal;
 * returns what the terminal received (malloc'd, NUL-terminated) and the
 * exit status, or NULL when no pseudo-terminal can be had. */
static char *run_on_terminal(const char *const *args, int *status)
{
    int m = posix_openpt(O_RDWR | O_NOCTTY);
    if (m < 0)
        return NULL;
    char *name = (grantpt(m) == 0 && unlockpt(m) == 0) ? ptsname(m) : NULL;
    if (name == NULL) {
        close(m);
        return NULL;
    }
    char slave[256];
    snprintf(slave, sizeof slave, "%s", name);
    pid_t pid = fork();
    if (pid < 0) {
        close(m);
        return NULL;
    }
    if (pid == 0) {
        setsid();
        int s = open(slave, O_RDWR);
        if (s < 0)
            _exit(126);
        dup2(s, 1);
        dup2(s, 2);
        if (s > 2)
            close(s);
        close(m);
        int i = 0;
        const char *argv[40];
        argv[i++] = LENSRENDER;
        for (; args[i - 1] && i < 39; i++)
            argv[i] = args[i - 1];
        argv[i] = NULL;
        execv(LENSRENDER, (char *const *)argv);
        _exit(127);
    }
    size_t cap = 4096, len = 0;
    char *buf = malloc(cap);
    for (;;) {
        if (buf && len + 1024 > cap) {
            char *nb = realloc(buf, cap * 2);
            if (!nb) {
                free(buf);
                buf = NULL;
            } else {
                buf = nb;
                cap *= 2;
            }
        }
        char tmp[1024];
        ssize_t r = read(m, tmp, sizeof tmp);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            break; /* EIO: the last slave descriptor closed */
        if (buf) {
            memcpy(buf + len, tmp, (size_t)r);
            len += (size_t)r;
        }
    }
    close(m);
    int st = 0;
    waitpid(pid, &st, 0);
    *status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + (WIFSIGNALED(st) ? WTERMSIG(st) : 0);
    if (buf)
        buf[len] = '\0';
    return buf;
}

/* The progress line (README, --quiet): on a terminal lensrender redraws
 * "\r[bar of 30] NNN%  ..." as tiles finish and ends with the full bar at
 * 100 % and a newline; --quiet prints nothing; on a pipe (every other
 * test here) there is no progress line. */
static void test_progress(void)
{
    char dir[4096], png[4200];
    fresh_dir(dir, sizeof dir, "progress");
    snprintf(png, sizeof png, "%s/p.png", dir);
    const char *a[] = {DEFAULT_SCENE, "-o", png, "--width", "64", "--height", "48", NULL};
    int st = -1;
    char *t = run_on_terminal(a, &st);
    if (t == NULL) {
        CHECK(0, "a pseudo-terminal for the progress test");
        remove_dir(dir);
        return;
    }
    CHECK(st == 0, "on a terminal: exit %d: %s", st, t);
    int updates = 0, monotone = 1, last = -1, full = 0;
    for (const char *p = t; (p = strstr(p, "\r[")) != NULL; p++) {
        int bar = 0, ok = 1, pct = -1;
        const char *q = p + 2;
        for (; *q == '#' || *q == '.'; q++)
            bar++;
        ok = bar == 30 && *q == ']' && sscanf(q + 1, "%d%%", &pct) == 1;
        CHECK(ok, "progress line: a bar of 30 and a percentage: [%.60s]", p + 1);
        if (!ok)
            continue;
        updates++;
        monotone &= pct >= last;
        last = pct;
        if (pct == 100 && strncmp(p + 2, "##############################]", 31) == 0)
            full = 1;
    }
    CHECK(updates >= 2, "progress: %d updates on a terminal, want the 0 %% and the final one",
          updates);
    CHECK(monotone && last == 100 && full, "progress: rises to a full bar at 100 %% (last %d)",
          last);
    const char *end = strstr(t, "100%");
    CHECK(end != NULL && strchr(end, '\n') != NULL, "progress: the final line ends with a newline");
    free(t);
    const char *aq[] = {DEFAULT_SCENE, "-o", png, "--width", "64", "--height", "48", "--quiet",
                        NULL};
    t = run_on_terminal(aq, &st);
    CHECK(t != NULL && st == 0 && t[0] == '\0', "--quiet on a terminal prints nothing: [%s]",
          t ? t : "");
    free(t);
    proc p = run_argv(a);
    CHECK(p.status == 0 && strstr(p.err, "\r[") == NULL && strstr(p.err, "%") == NULL,
          "on a pipe: no progress line: [%s]", p.err);
    proc_free(&p);
    remove_dir(dir);
}

int main(void)
{
    char top[4096];
    crc_init();
    test_threads_identical();
    test_bad_input();
    test_wavelength_counts();
    test_depth_cutoff();
    test_progress();
    snprintf(top, sizeof top, "%s/lensrender_cli.%ld", LP_TEST_TMP, (long)getpid());
    rmdir(top);
    return check_finish("test_lensrender_cli");
}
