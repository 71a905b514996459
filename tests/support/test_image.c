/* test_image.c -- image files and metrics (image.h).
 *
 *  - PNG 8-bit sRGB: every code 0..255 survives write -> read (the value
 *    written is the sRGB decoding of k/255, read back raw as k/255); known
 *    points of the transfer function land on the codes written out here
 *    by hand (0.5 -> 0.735357 * 255 -> 188, 0.18 -> 118, 0.0031308 ->
 *    10.31 -> 10); the file carries sRGB (perceptual, intent 0) and gAMA
 *    45455 chunks (found by scanning its bytes).
 *  - PNG 16-bit linear: back to within half a step (1/131070), gAMA
 *    100000; 16-bit gray, RGBA, 2-bit gray and palette+tRNS files made here
 *    with libpng read back as raw sample / maxval.
 *  - Atomic writes: a path in a missing directory fails with a message
 *    and leaves nothing; a temporary path made impossible (a directory of
 *    that name) fails and leaves the existing file byte for byte; a
 *    stale temporary file is replaced; no "*.tmp.*" is ever left over.
 *  - PFM: bit-exact round trip (NaN, infinities, denormals, -0 included),
 *    the header and bottom-to-top row order, big-endian and gray files,
 *    truncated and malformed files rejected.
 *  - The 8-bit sRGB table: the code of each entry, of the float below it,
 *    of the transfer function's kink and of 200000 spread floats in
 *    (0, 1.25) is the transfer function's code written here (the table was
 *    also checked once against it on every float of [0, 1]: none differ);
 *    NaN, 0, negatives and infinities as the formula clamps them.
 *  - Metrics: a uniform error e gives RMSE e and PSNR -20 log10(e) (1e-12
 *    relative); identical images give RMSE 0, PSNR INFINITY, SSIM 1;
 *    uniform images give SSIM's closed form (2 x y + C1)/(x^2 + y^2 + C1);
 *    the SSIM of random images equals a brute-force evaluation of Wang et
 *    al.'s formula written here (1e-12); size mismatch gives NAN. */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include <png.h>

#include "check.h"
#include "support/image.h"
#include "support/colorimetry.h"
#include "test_files.h"

static char tmpdir[1024];

static void path_in(char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "%s/%s", tmpdir, name);
}

static void spit(const char *path, const void *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL, "cannot create %s", path);
    if (!f)
        return;
    CHECK(fwrite(data, 1, len, f) == len, "cannot write %s", path);
    fclose(f);
}

/* Offset of the first occurrence of a 4-byte chunk type, or -1. */
static long find_chunk(const unsigned char *buf, size_t len, const char *type)
{
    for (size_t i = 0; i + 4 <= len; i++)
        if (memcmp(buf + i, type, 4) == 0)
            return (long)i;
    return -1;
}

/* Number of entries of tmpdir whose name contains ".tmp.". */
static int count_temp_files(void)
{
    DIR *d = opendir(tmpdir);
    struct dirent *e;
    int n = 0;

    if (!d)
        return -1;
    while ((e = readdir(d)) != NULL)
        if (strstr(e->d_name, ".tmp."))
            n++;
    closedir(d);
    return n;
}

static void test_png8(void)
{
    char path[1200], msg[256] = "";
    rs_image img, back;
    int depth = 0;
    unsigned char *buf;
    size_t len;
    long at;

    /* A 16x16 image: pixel k = (x + 16 y) has the linear value that
     * encodes to code k in R, 255 - k in G, and k again in B. */
    CHECK(rs_image_create(&img, 16, 16) == 0, "create 16x16");
    for (int k = 0; k < 256; k++) {
        img.rgb[3 * k] = (float)rs_srgb_decode(k / 255.0);
        img.rgb[3 * k + 1] = (float)rs_srgb_decode((255 - k) / 255.0);
        img.rgb[3 * k + 2] = (float)rs_srgb_decode(k / 255.0);
    }
    path_in(path, sizeof path, "ramp.png");
    CHECK(rs_png_write(path, &img, msg, sizeof msg) == 0, "write ramp.png: %s", msg);
    CHECK(rs_png_read(path, &back, &depth, msg, sizeof msg) == 0, "read ramp.png: %s", msg);
    CHECK(depth == 8, "ramp.png bit depth %d", depth);
    CHECK(back.width == 16 && back.height == 16, "ramp.png size %dx%d", back.width, back.height);
    if (back.rgb) {
        for (int k = 0; k < 256; k++) {
            CHECK(back.rgb[3 * k] == (float)(k / 255.0), "code %d r: %.9g", k, back.rgb[3 * k]);
            CHECK(back.rgb[3 * k + 1] == (float)((255 - k) / 255.0), "code %d g", k);
            CHECK(back.rgb[3 * k + 2] == (float)(k / 255.0), "code %d b", k);
        }
    }
    rs_image_free(&back);

    /* The chunks. */
    buf = (unsigned char *)tf_read(path, &len);
    CHECK(buf && len > 8 && memcmp(buf, "\x89PNG\r\n\x1a\n", 8) == 0, "PNG signature");
    if (buf) {
        at = find_chunk(buf, len, "sRGB");
        CHECK(at >= 0, "no sRGB chunk");
        if (at >= 0 && (size_t)at + 5 <= len)
            CHECK(buf[at + 4] == 0, "sRGB intent %d, want 0 (perceptual)", buf[at + 4]);
        at = find_chunk(buf, len, "gAMA");
        CHECK(at >= 0, "no gAMA chunk");
        if (at >= 0 && (size_t)at + 8 <= len) {
            unsigned long g = (unsigned long)buf[at + 4] << 24 | (unsigned long)buf[at + 5] << 16
                              | (unsigned long)buf[at + 6] << 8 | buf[at + 7];
            CHECK(g == 45455, "gAMA %lu, want 45455", g);
        }
        CHECK(find_chunk(buf, len, "IDAT") > find_chunk(buf, len, "sRGB"),
              "sRGB before IDAT");
    }
    free(buf);

    /* Known points, out-of-range values and NaN. */
    {
        const float in[6] = {0.5f, 0.18f, 0.0031308f, 1.0f, 3.0f, -1.0f};
        const int want[6] = {188, 118, 10, 255, 255, 0};
        rs_image p;
        CHECK(rs_image_create(&p, 7, 1) == 0, "create 7x1");
        for (int i = 0; i < 6; i++)
            p.rgb[3 * i] = p.rgb[3 * i + 1] = p.rgb[3 * i + 2] = in[i];
        p.rgb[18] = p.rgb[19] = p.rgb[20] = NAN;
        path_in(path, sizeof path, "points.png");
        CHECK(rs_png_write(path, &p, msg, sizeof msg) == 0, "write points.png: %s", msg);
        CHECK(rs_png_read(path, &back, NULL, msg, sizeof msg) == 0, "read points.png: %s", msg);
        if (back.rgb) {
            for (int i = 0; i < 6; i++)
                CHECK(back.rgb[3 * i] == (float)(want[i] / 255.0), "linear %g -> %g, want code %d",
                      in[i], back.rgb[3 * i] * 255.0, want[i]);
            CHECK(back.rgb[18] == 0.0f, "NaN -> code 0");
        }
        rs_image_free(&back);
        rs_image_free(&p);
    }
    rs_image_free(&img);
}

static void test_png16(void)
{
    char path[1200], msg[256] = "";
    rs_image img, back;
    int depth = 0;
    unsigned char *buf;
    size_t len;
    unsigned seed = 7u;

    CHECK(rs_image_create(&img, 13, 9) == 0, "create 13x9");
    for (size_t i = 0; i < 13 * 9 * 3; i++) {
        seed = seed * 1664525u + 1013904223u;
        img.rgb[i] = (float)((seed >> 8) / 16777216.0);
    }
    img.rgb[0] = 0.0f;
    img.rgb[1] = 1.0f;
    path_in(path, sizeof path, "linear16.png");
    CHECK(rs_png_write16_linear(path, &img, msg, sizeof msg) == 0, "write linear16.png: %s", msg);
    CHECK(rs_png_read(path, &back, &depth, msg, sizeof msg) == 0, "read linear16.png: %s", msg);
    CHECK(depth == 16, "linear16.png bit depth %d", depth);
    if (back.rgb)
        for (size_t i = 0; i < 13 * 9 * 3; i++)
            CHECK_ABS(back.rgb[i], img.rgb[i], 0.5 / 65535.0 + 1e-7, "16-bit value %zu", i);
    rs_image_free(&back);
    buf = (unsigned char *)tf_read(path, &len);
    CHECK(buf != NULL, "cannot read back %s", path);
    if (buf) {
        long at = find_chunk(buf, len, "gAMA");
        CHECK(at >= 0 && (size_t)at + 8 <= len, "no gAMA in the 16-bit file");
        if (at >= 0 && (size_t)at + 8 <= len) {
            unsigned long g = (unsigned long)buf[at + 4] << 24 | (unsigned long)buf[at + 5] << 16
                              | (unsigned long)buf[at + 6] << 8 | buf[at + 7];
            CHECK(g == 100000, "16-bit gAMA %lu, want 100000", g);
        }
        CHECK(find_chunk(buf, len, "sRGB") < 0, "a linear file claims sRGB");
    }
    free(buf);
    rs_image_free(&img);
}

/* Write a PNG of the given type with libpng directly (rows: raw bytes). */
static int write_raw_png(const char *path, int w, int h, int depth, int color_type,
                         const unsigned char *data, size_t row_bytes, int with_trns)
{
    FILE *f = fopen(path, "wb");
    png_structp png;
    png_infop info;

    if (!f)
        return -1;
    png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    info = png_create_info_struct(png);
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        fclose(f);
        return -1;
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, w, h, depth, color_type, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (color_type == PNG_COLOR_TYPE_PALETTE) {
        png_color pal[3] = {{255, 0, 0}, {0, 128, 255}, {10, 20, 30}};
        png_byte trans[3] = {0, 128, 255};
        png_set_PLTE(png, info, pal, 3);
        if (with_trns)
            png_set_tRNS(png, info, trans, 3, NULL);
    }
    /* A gamma that must NOT be applied on reading. */
    png_set_gAMA(png, info, 1.0 / 2.2);
    png_write_info(png, info);
    for (int y = 0; y < h; y++)
        png_write_row(png, data + (size_t)y * row_bytes);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    fclose(f);
    return 0;
}

static void test_png_read_types(void)
{
    char path[1200], msg[256] = "";
    rs_image im;
    int depth;

    /* 16-bit gray, 3x1: 0, 1000, 65535 (POV-Ray's linear renders are
     * 16-bit). */
    {
        const unsigned char d[6] = {0, 0, 0x03, 0xe8, 0xff, 0xff};
        path_in(path, sizeof path, "gray16.png");
        CHECK(write_raw_png(path, 3, 1, 16, PNG_COLOR_TYPE_GRAY, d, 6, 0) == 0, "gray16.png");
        depth = 0;
        CHECK(rs_png_read(path, &im, &depth, msg, sizeof msg) == 0, "read gray16: %s", msg);
        CHECK(depth == 16, "gray16 depth %d", depth);
        if (im.rgb) {
            CHECK(im.rgb[0] == 0.0f && im.rgb[1] == 0.0f, "gray16 px0");
            CHECK(im.rgb[3] == (float)(1000 / 65535.0) && im.rgb[4] == im.rgb[3]
                      && im.rgb[5] == im.rgb[3],
                  "gray16 px1 = 1000/65535 in R, G, B (no gamma)");
            CHECK(im.rgb[8] == 1.0f, "gray16 px2");
        }
        rs_image_free(&im);
    }
    /* 8-bit RGBA 2x1: alpha dropped, no premultiplication. */
    {
        const unsigned char d[8] = {10, 20, 30, 0, 200, 100, 50, 128};
        path_in(path, sizeof path, "rgba8.png");
        CHECK(write_raw_png(path, 2, 1, 8, PNG_COLOR_TYPE_RGB_ALPHA, d, 8, 0) == 0, "rgba8.png");
        CHECK(rs_png_read(path, &im, &depth, msg, sizeof msg) == 0, "read rgba8: %s", msg);
        CHECK(depth == 8, "rgba8 depth %d", depth);
        if (im.rgb) {
            CHECK(im.rgb[0] == (float)(10 / 255.0) && im.rgb[1] == (float)(20 / 255.0)
                      && im.rgb[2] == (float)(30 / 255.0),
                  "rgba8 px0");
            CHECK(im.rgb[3] == (float)(200 / 255.0) && im.rgb[5] == (float)(50 / 255.0),
                  "rgba8 px1");
        }
        rs_image_free(&im);
    }
    /* 16-bit RGB 1x2. */
    {
        const unsigned char d[12] = {0x12, 0x34, 0, 0, 0xff, 0xff, 0, 1, 0x80, 0, 0xab, 0xcd};
        path_in(path, sizeof path, "rgb16.png");
        CHECK(write_raw_png(path, 1, 2, 16, PNG_COLOR_TYPE_RGB, d, 6, 0) == 0, "rgb16.png");
        CHECK(rs_png_read(path, &im, &depth, msg, sizeof msg) == 0, "read rgb16: %s", msg);
        CHECK(depth == 16 && im.width == 1 && im.height == 2, "rgb16 header");
        if (im.rgb) {
            CHECK(im.rgb[0] == (float)(0x1234 / 65535.0), "rgb16 r0");
            CHECK(im.rgb[3] == (float)(1 / 65535.0), "rgb16 r1 (row 1)");
            CHECK(im.rgb[5] == (float)(0xabcd / 65535.0), "rgb16 b1");
        }
        rs_image_free(&im);
    }
    /* 2-bit gray 4x1: 0, 1, 2, 3 -> 0, 1/3, 2/3, 1. */
    {
        const unsigned char d[1] = {0x1b}; /* 00 01 10 11 */
        path_in(path, sizeof path, "gray2.png");
        CHECK(write_raw_png(path, 4, 1, 2, PNG_COLOR_TYPE_GRAY, d, 1, 0) == 0, "gray2.png");
        CHECK(rs_png_read(path, &im, &depth, msg, sizeof msg) == 0, "read gray2: %s", msg);
        CHECK(depth == 2, "gray2 depth %d", depth);
        if (im.rgb)
            for (int i = 0; i < 4; i++)
                CHECK_ABS(im.rgb[3 * i + 1], i / 3.0, 1e-7, "gray2 px%d", i);
        rs_image_free(&im);
    }
    /* Palette with tRNS, 3x1: the palette colours, alpha dropped. */
    {
        const unsigned char d[3] = {0, 1, 2};
        path_in(path, sizeof path, "palette.png");
        CHECK(write_raw_png(path, 3, 1, 8, PNG_COLOR_TYPE_PALETTE, d, 3, 1) == 0, "palette.png");
        CHECK(rs_png_read(path, &im, &depth, msg, sizeof msg) == 0, "read palette: %s", msg);
        CHECK(depth == 8, "palette depth %d", depth);
        if (im.rgb) {
            CHECK(im.rgb[0] == 1.0f && im.rgb[1] == 0.0f, "palette px0");
            CHECK(im.rgb[4] == (float)(128 / 255.0) && im.rgb[5] == 1.0f, "palette px1");
            CHECK(im.rgb[6] == (float)(10 / 255.0), "palette px2");
        }
        rs_image_free(&im);
    }
    /* Not a PNG, missing, truncated. */
    {
        size_t len;
        unsigned char *buf;
        path_in(path, sizeof path, "not_a_png.png");
        spit(path, "hello, world", 12);
        im.rgb = (float *)&im; /* must be reset on failure */
        CHECK(rs_png_read(path, &im, NULL, msg, sizeof msg) != 0, "text read as PNG");
        CHECK(im.rgb == NULL && im.width == 0, "out not emptied on failure");
        CHECK(strstr(msg, "not a PNG") != NULL, "message: %s", msg);
        path_in(path, sizeof path, "missing.png");
        CHECK(rs_png_read(path, &im, NULL, msg, sizeof msg) != 0, "missing file read");
        path_in(path, sizeof path, "ramp.png");
        buf = (unsigned char *)tf_read(path, &len);
        CHECK(buf != NULL, "cannot read %s", path);
        if (buf) {
            path_in(path, sizeof path, "truncated.png");
            spit(path, buf, len / 2);
            CHECK(rs_png_read(path, &im, NULL, msg, sizeof msg) != 0, "truncated PNG read");
            printf("truncated PNG: %s\n", msg);
        }
        free(buf);
    }
}

static void test_atomic(void)
{
    char path[1200], tmp[1300], msg[256] = "";
    rs_image img;
    unsigned char *before, *after;
    size_t nb, na;
    struct stat st;

    CHECK(rs_image_create(&img, 4, 3) == 0, "create 4x3");
    for (size_t i = 0; i < 36; i++)
        img.rgb[i] = (float)(i / 40.0);

    /* A missing directory: clean failure, nothing created. */
    path_in(path, sizeof path, "no_such_dir/out.png");
    CHECK(rs_png_write(path, &img, msg, sizeof msg) != 0, "write into a missing directory");
    CHECK(msg[0] != '\0', "no message");
    printf("missing directory: %s\n", msg);
    path_in(path, sizeof path, "no_such_dir");
    CHECK(stat(path, &st) != 0, "the missing directory appeared");
    path_in(path, sizeof path, "no_such_dir/out.pfm");
    CHECK(rs_pfm_write(path, &img, msg, sizeof msg) != 0, "PFM into a missing directory");

    /* An existing file, and the temporary path made impossible. */
    path_in(path, sizeof path, "keep.png");
    spit(path, "precious old contents", 21);
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    CHECK(mkdir(tmp, 0755) == 0, "mkdir %s: %s", tmp, strerror(errno));
    msg[0] = '\0';
    CHECK(rs_png_write(path, &img, msg, sizeof msg) != 0, "write with the temp path blocked");
    printf("blocked temporary: %s\n", msg);
    CHECK(msg[0] != '\0', "no message");
    CHECK(rs_pfm_write(path, &img, msg, sizeof msg) != 0, "PFM with the temp path blocked");
    CHECK(rs_png_write16_linear(path, &img, msg, sizeof msg) != 0, "16-bit with the temp path blocked");
    before = (unsigned char *)tf_read(path, &nb);
    CHECK(before && nb == 21 && memcmp(before, "precious old contents", 21) == 0,
          "the existing file was clobbered");
    free(before);
    CHECK(stat(tmp, &st) == 0 && S_ISDIR(st.st_mode), "the blocking directory was removed");
    rmdir(tmp);

    /* Now it works and replaces the file. */
    CHECK(rs_png_write(path, &img, msg, sizeof msg) == 0, "overwrite keep.png: %s", msg);
    after = (unsigned char *)tf_read(path, &na);
    CHECK(after && na > 8 && memcmp(after, "\x89PNG", 4) == 0, "keep.png replaced by a PNG");
    free(after);
    CHECK(stat(tmp, &st) != 0, "temporary file left behind");

    /* A stale regular temporary file is replaced. */
    spit(tmp, "stale", 5);
    CHECK(rs_pfm_write(path, &img, msg, sizeof msg) == 0, "write over a stale temp: %s", msg);
    CHECK(stat(tmp, &st) != 0, "stale temporary file left behind");

    /* A write that fails half way (the file size limit, as a full disk
     * would): the temporary file is removed, the old file stays. */
    {
        struct rlimit old, small;
        rs_image big;
        unsigned seed = 5u;
        CHECK(rs_image_create(&big, 300, 200) == 0, "create 300x200");
        for (size_t i = 0; i < 300 * 200 * 3; i++) {
            seed = seed * 1664525u + 1013904223u;
            big.rgb[i] = (float)((seed >> 8) / 16777216.0);
        }
        before = (unsigned char *)tf_read(path, &nb);
        signal(SIGXFSZ, SIG_IGN);
        CHECK(getrlimit(RLIMIT_FSIZE, &old) == 0, "getrlimit");
        small = old;
        small.rlim_cur = 4096;
        CHECK(setrlimit(RLIMIT_FSIZE, &small) == 0, "setrlimit");
        msg[0] = '\0';
        CHECK(rs_png_write(path, &big, msg, sizeof msg) != 0, "PNG larger than the limit written");
        printf("file size limit, PNG: %s\n", msg);
        CHECK(rs_pfm_write(path, &big, msg, sizeof msg) != 0, "PFM larger than the limit written");
        printf("file size limit, PFM: %s\n", msg);
        CHECK(setrlimit(RLIMIT_FSIZE, &old) == 0, "restore the file size limit");
        signal(SIGXFSZ, SIG_DFL);
        after = (unsigned char *)tf_read(path, &na);
        CHECK(before && after && na == nb && memcmp(after, before, na) == 0,
              "a failed write changed the file");
        CHECK(stat(tmp, &st) != 0, "temporary file left after a failed write");
        free(before);
        free(after);
        rs_image_free(&big);
    }

    /* An empty image is refused without touching anything. */
    {
        rs_image empty = {0, 0, NULL};
        after = (unsigned char *)tf_read(path, &na);
        CHECK(rs_png_write(path, &empty, msg, sizeof msg) != 0, "empty image written");
        CHECK(rs_pfm_write(path, &empty, msg, sizeof msg) != 0, "empty image written as PFM");
        before = (unsigned char *)tf_read(path, &nb);
        CHECK(after && before && na == nb && memcmp(after, before, na) == 0,
              "a refused write changed the file");
        free(after);
        free(before);
    }
    CHECK(count_temp_files() == 0, "%d temporary files left in %s", count_temp_files(), tmpdir);
    rs_image_free(&img);
}

static uint32_t float_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

/* A FIFO (as /dev/null or /dev/stdout: not a regular file) is written in
 * place and stays a FIFO; no temporary file beside it. */
static void test_special_file(void)
{
    char path[1200], msg[256] = "";
    unsigned char buf[4096];
    rs_image img;
    struct stat st;
    CHECK(rs_image_create(&img, 4, 3) == 0, "create 4x3");
    for (size_t i = 0; i < 36; i++)
        img.rgb[i] = (float)(i / 40.0);
    path_in(path, sizeof path, "pipe.png");
    unlink(path);
    CHECK(mkfifo(path, 0600) == 0, "mkfifo %s: %s", path, strerror(errno));
    /* a reader first, so that the writer's open does not wait; the image
     * is far smaller than a pipe's buffer */
    int rd = open(path, O_RDONLY | O_NONBLOCK);
    CHECK(rd >= 0, "open the FIFO for reading: %s", strerror(errno));
    CHECK(rs_png_write(path, &img, msg, sizeof msg) == 0, "PNG into a FIFO: %s", msg);
    CHECK(stat(path, &st) == 0 && S_ISFIFO(st.st_mode), "the FIFO was replaced by a file");
    ssize_t n = rd >= 0 ? read(rd, buf, sizeof buf) : -1;
    CHECK(n > 8 && memcmp(buf, "\x89PNG", 4) == 0, "the FIFO got no PNG (%ld bytes)", (long)n);
    CHECK(rs_pfm_write(path, &img, msg, sizeof msg) == 0, "PFM into a FIFO: %s", msg);
    n = rd >= 0 ? read(rd, buf, sizeof buf) : -1;
    CHECK(n > 2 && buf[0] == 'P' && buf[1] == 'F', "the FIFO got no PFM (%ld bytes)", (long)n);
    CHECK(stat(path, &st) == 0 && S_ISFIFO(st.st_mode), "the FIFO was replaced by a PFM");
    CHECK(count_temp_files() == 0, "%d temporary files left in %s", count_temp_files(), tmpdir);
    if (rd >= 0)
        close(rd);
    unlink(path);
    rs_image_free(&img);
}

static void test_pfm(void)
{
    char path[1200], msg[256] = "";
    rs_image img, back;
    unsigned char *buf;
    size_t len;
    unsigned seed = 99u;

    CHECK(rs_image_create(&img, 5, 3) == 0, "create 5x3");
    for (size_t i = 0; i < 45; i++) {
        seed = seed * 1664525u + 1013904223u;
        img.rgb[i] = (float)((seed >> 8) / 16777216.0 * 4.0 - 1.0);
    }
    img.rgb[0] = NAN;
    img.rgb[1] = INFINITY;
    img.rgb[2] = -INFINITY;
    img.rgb[3] = 1e-42f;   /* denormal */
    img.rgb[4] = -0.0f;
    img.rgb[5] = 3.4e38f;
    img.rgb[3 * (2 * 5) + 0] = 0.125f; /* pixel (0, 2): the bottom-left */
    path_in(path, sizeof path, "round.pfm");
    CHECK(rs_pfm_write(path, &img, msg, sizeof msg) == 0, "write round.pfm: %s", msg);
    CHECK(rs_pfm_read(path, &back, msg, sizeof msg) == 0, "read round.pfm: %s", msg);
    CHECK(back.width == 5 && back.height == 3, "PFM size %dx%d", back.width, back.height);
    if (back.rgb)
        for (size_t i = 0; i < 45; i++)
            CHECK(float_bits(back.rgb[i]) == float_bits(img.rgb[i]),
                  "PFM value %zu: %08x vs %08x", i, (unsigned)float_bits(back.rgb[i]),
                  (unsigned)float_bits(img.rgb[i]));
    rs_image_free(&back);

    buf = (unsigned char *)tf_read(path, &len);
    CHECK(buf && len == 12 + 45 * 4, "PFM file length %zu", len);
    if (buf && len == 12 + 45 * 4) {
        /* 0.125f = 0x3e000000, little-endian, first value of the file. */
        static const unsigned char first[4] = {0x00, 0x00, 0x00, 0x3e};
        CHECK(memcmp(buf, "PF\n5 3\n-1.0\n", 12) == 0, "PFM header");
        CHECK(memcmp(buf + 12, first, 4) == 0, "PFM first row is the bottom row");
    }
    free(buf);

    /* Big-endian RGB and gray files made by hand. */
    {
        const unsigned char be[] = "PF\n1 1\n1.0\n\x3f\x80\x00\x00\x40\x00\x00\x00\xbf\x00\x00\x00";
        const unsigned char gray[] = "Pf 2 1 -1 \x00\x00\x80\x3e\x00\x00\x00\x40";
        path_in(path, sizeof path, "be.pfm");
        spit(path, be, sizeof be - 1);
        CHECK(rs_pfm_read(path, &back, msg, sizeof msg) == 0, "read be.pfm: %s", msg);
        if (back.rgb)
            CHECK(back.rgb[0] == 1.0f && back.rgb[1] == 2.0f && back.rgb[2] == -0.5f,
                  "big-endian PFM values %g %g %g", back.rgb[0], back.rgb[1], back.rgb[2]);
        rs_image_free(&back);
        path_in(path, sizeof path, "gray.pfm");
        spit(path, gray, sizeof gray - 1);
        CHECK(rs_pfm_read(path, &back, msg, sizeof msg) == 0, "read gray.pfm: %s", msg);
        if (back.rgb)
            CHECK(back.width == 2 && back.rgb[0] == 0.25f && back.rgb[2] == 0.25f
                      && back.rgb[3] == 2.0f && back.rgb[5] == 2.0f,
                  "gray PFM");
        rs_image_free(&back);
    }
    /* Malformed. */
    {
        static const char *bad[] = {"P6\n1 1\n255\nabc", "PF\n0 1\n-1.0\n", "PF\n1 1\n0\n",
                                    "PF\n2 2\n-1.0\n\x00\x00\x00\x00", "PF\n1 x\n-1\n"};
        for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
            path_in(path, sizeof path, "bad.pfm");
            spit(path, bad[i], strlen(bad[i]) + (i == 3 ? 4 : 0));
            msg[0] = '\0';
            CHECK(rs_pfm_read(path, &back, msg, sizeof msg) != 0, "bad PFM %zu accepted", i);
            CHECK(back.rgb == NULL && msg[0] != '\0', "bad PFM %zu: no message or image left", i);
        }
    }
    rs_image_free(&img);
}

/* Wang et al.'s mean SSIM, brute force: every 11x11 window, Gaussian
 * sigma 1.5 weights, on the luminance. */
static double ssim_reference(const rs_image *a, const rs_image *b)
{
    double g[11][11], gs = 0.0, total = 0.0;
    const double c1 = 1e-4, c2 = 9e-4;
    int count = 0;

    for (int i = 0; i < 11; i++)
        for (int j = 0; j < 11; j++) {
            g[i][j] = exp(-((i - 5) * (i - 5) + (j - 5) * (j - 5)) / (2.0 * 1.5 * 1.5));
            gs += g[i][j];
        }
    for (int y0 = 0; y0 + 11 <= a->height; y0++)
        for (int x0 = 0; x0 + 11 <= a->width; x0++) {
            double mx = 0, my = 0, sxx = 0, syy = 0, sxy = 0;
            for (int i = 0; i < 11; i++)
                for (int j = 0; j < 11; j++) {
                    size_t p = 3 * ((size_t)(y0 + i) * a->width + x0 + j);
                    double x = 0.2126 * a->rgb[p] + 0.7152 * a->rgb[p + 1] + 0.0722 * a->rgb[p + 2];
                    double y = 0.2126 * b->rgb[p] + 0.7152 * b->rgb[p + 1] + 0.0722 * b->rgb[p + 2];
                    double w = g[i][j] / gs;
                    mx += w * x;
                    my += w * y;
                }
            for (int i = 0; i < 11; i++)
                for (int j = 0; j < 11; j++) {
                    size_t p = 3 * ((size_t)(y0 + i) * a->width + x0 + j);
                    double x = 0.2126 * a->rgb[p] + 0.7152 * a->rgb[p + 1] + 0.0722 * a->rgb[p + 2];
                    double y = 0.2126 * b->rgb[p] + 0.7152 * b->rgb[p + 1] + 0.0722 * b->rgb[p + 2];
                    double w = g[i][j] / gs;
                    sxx += w * (x - mx) * (x - mx);
                    syy += w * (y - my) * (y - my);
                    sxy += w * (x - mx) * (y - my);
                }
            total += (2 * mx * my + c1) * (2 * sxy + c2)
                     / ((mx * mx + my * my + c1) * (sxx + syy + c2));
            count++;
        }
    return total / count;
}

static void fill(rs_image *img, float v)
{
    for (size_t i = 0; i < (size_t)img->width * img->height * 3; i++)
        img->rgb[i] = v;
}

static void test_metrics(void)
{
    rs_image a, b, c;
    unsigned seed = 2024u;
    const double e = 0.0625;

    CHECK(rs_image_create(&a, 40, 30) == 0 && rs_image_create(&b, 40, 30) == 0,
          "create 40x30");
    /* Values on a 2^-10 grid in [0, 0.5]: a + e is exact in float. */
    for (size_t i = 0; i < 40 * 30 * 3; i++) {
        seed = seed * 1664525u + 1013904223u;
        a.rgb[i] = (float)((seed >> 22) / 2048.0);
        b.rgb[i] = a.rgb[i] + (float)e;
    }
    CHECK_REL(rs_image_rmse(&a, &b), e, 1e-12, "RMSE of a uniform error");
    CHECK_REL(rs_image_psnr(&a, &b), -20.0 * log10(e), 1e-12, "PSNR of a uniform error");
    CHECK(rs_image_rmse(&a, &a) == 0.0, "RMSE of identical images");
    CHECK(isinf(rs_image_psnr(&a, &a)) && rs_image_psnr(&a, &a) > 0, "PSNR of identical images");
    CHECK_ABS(rs_image_ssim(&a, &a), 1.0, 1e-15, "SSIM of identical images");
    CHECK_ABS(rs_image_ssim(&a, &b), ssim_reference(&a, &b), 1e-12, "SSIM vs brute force");
    CHECK_ABS(rs_image_ssim(&b, &a), rs_image_ssim(&a, &b), 1e-14, "SSIM symmetric");

    /* Noise lowers SSIM; the brute-force reference agrees. */
    for (size_t i = 0; i < 40 * 30 * 3; i++) {
        seed = seed * 1664525u + 1013904223u;
        b.rgb[i] = a.rgb[i] + (float)(((seed >> 8) / 16777216.0 - 0.5) * 0.2);
    }
    {
        double s = rs_image_ssim(&a, &b);
        printf("SSIM of a noisy copy: %.6f\n", s);
        CHECK(s < 0.99 && s > 0.0, "noisy SSIM %g", s);
        CHECK_ABS(s, ssim_reference(&a, &b), 1e-12, "noisy SSIM vs brute force");
    }

    /* Uniform images: SSIM = (2xy + C1) / (x^2 + y^2 + C1), both for the
     * windowed case and for a small image (one window). */
    fill(&a, 0.25f);
    fill(&b, 0.3125f);
    {
        double x = 0.25, y = 0.3125, want = (2 * x * y + 1e-4) / (x * x + y * y + 1e-4);
        rs_image sa, sb;
        CHECK_ABS(rs_image_ssim(&a, &b), want, 1e-12, "SSIM of uniform images");
        CHECK(rs_image_create(&sa, 8, 5) == 0 && rs_image_create(&sb, 8, 5) == 0, "8x5");
        fill(&sa, 0.25f);
        fill(&sb, 0.3125f);
        CHECK_ABS(rs_image_ssim(&sa, &sb), want, 1e-12, "SSIM of small uniform images");
        CHECK_ABS(rs_image_ssim(&sa, &sa), 1.0, 1e-15, "SSIM of identical small images");
        rs_image_free(&sa);
        rs_image_free(&sb);
    }

    /* Size mismatch and empty images. */
    CHECK(rs_image_create(&c, 41, 30) == 0, "create 41x30");
    CHECK(isnan(rs_image_rmse(&a, &c)) && isnan(rs_image_psnr(&a, &c))
              && isnan(rs_image_ssim(&a, &c)),
          "mismatched sizes not NAN");
    {
        rs_image empty = {0, 0, NULL};
        CHECK(isnan(rs_image_rmse(&empty, &empty)) && isnan(rs_image_ssim(&empty, &empty)),
              "empty images not NAN");
    }
    rs_image_free(&c);
    CHECK(rs_image_create(&c, 0, 5) != 0 && c.rgb == NULL, "0-width image created");
    CHECK(rs_image_create(&c, 1 << 30, 1 << 30) != 0 && c.rgb == NULL, "huge image created");
    rs_image_free(&c);
    rs_image_free(&a);
    rs_image_free(&b);
}

/* The 8-bit code by IEC 61966-2-1, written here. */
static unsigned srgb8_formula(float f)
{
    double v = f;
    if (!(v > 0.0))
        return 0;
    if (v >= 1.0)
        return 255;
    v = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
    return (unsigned)(v * 255.0 + 0.5);
}

static void test_srgb8_table(void)
{
    rs_srgb8_table t;
    unsigned long bad = 0;
    float special[] = {0.0f, -0.0f, -1.0f, (float)NAN, (float)INFINITY, -(float)INFINITY,
                       1.0f, 0.0031308f, 1e-40f};
    rs_srgb8_table_init(&t);
    for (unsigned k = 1; k < 256; k++) {
        float at = t.at_least[k], below = nextafterf(at, 0.0f);
        CHECK(srgb8_formula(at) >= k && srgb8_formula(below) < k,
              "sRGB table: entry %u (%.9g) is the least float of code >= %u "
              "(codes %u there, %u below)", k, at, k, srgb8_formula(at), srgb8_formula(below));
        if (rs_srgb8(&t, at) != srgb8_formula(at) || rs_srgb8(&t, below) != srgb8_formula(below))
            bad++;
    }
    for (size_t i = 0; i < sizeof special / sizeof special[0]; i++)
        if (rs_srgb8(&t, special[i]) != srgb8_formula(special[i]))
            bad++;
    for (unsigned i = 1; i <= 200000; i++) {
        float f = (float)(1.25 * i / 200000.0);
        float g = (float)pow(10.0, -6.0 * i / 200000.0); /* 1 .. 1e-6, log-spaced */
        if (rs_srgb8(&t, f) != srgb8_formula(f) || rs_srgb8(&t, g) != srgb8_formula(g))
            bad++;
    }
    CHECK(bad == 0, "sRGB table: %lu values take another code than the formula's", bad);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "%s/test_image.d", LP_TEST_TMP);
    mkdir(tmpdir, 0755);
    test_srgb8_table();
    test_png8();
    test_png16();
    test_png_read_types();
    test_atomic();
    test_special_file();
    test_pfm();
    test_metrics();
    return check_finish("test_image");
}
