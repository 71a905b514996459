/* test_lensrender_cli.c -- runs the built lensrender binary and checks its
 * contract (docs: shared/design/interfaces.md, "lensrender"):
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
 *   - every --wavelengths count the option accepts (1..1024) renders. */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
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

/* --wavelengths takes 1..1024 (args.h, --help): every count renders. */
static void test_wavelength_counts(void)
{
    char dir[4096], png[4200];
    static const char *const counts[] = {"1", "2", "3", "16"};
    fresh_dir(dir, sizeof dir, "wavelengths");
    snprintf(png, sizeof png, "%s/w.png", dir);
    for (size_t k = 0; k < sizeof counts / sizeof *counts; k++) {
        const char *a[] = {DEFAULT_SCENE, "-o", png, "--width", "8", "--height", "6",
                           "--wavelengths", counts[k], "--quiet", NULL};
        proc p = run_argv(a);
        CHECK(p.status == 0, "%s: exit %d: %s", p.what, p.status, p.err);
        proc_free(&p);
    }
    remove_dir(dir);
}

int main(void)
{
    char top[4096];
    crc_init();
    test_threads_identical();
    test_bad_input();
    test_wavelength_counts();
    snprintf(top, sizeof top, "%s/lensrender_cli.%ld", LP_TEST_TMP, (long)getpid());
    rmdir(top);
    return check_finish("test_lensrender_cli");
}
