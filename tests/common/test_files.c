/* test_files.c -- files and the clock as the tests use them (test_files.h). */
#define _POSIX_C_SOURCE 200809L

#include "test_files.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

double tf_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

char *tf_read(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    size_t n = 0, cap = 0;
    int e;

    if (len)
        *len = 0;
    if (!f)
        return NULL;
    errno = 0;
    /* grow by doubling, always keeping one byte for the terminating NUL */
    for (;;) {
        size_t got;
        if (cap - n < 2) {
            size_t ncap = cap ? 2 * cap : 4096;
            char *nb = ncap > cap ? realloc(buf, ncap) : NULL;
            if (!nb) {
                e = ncap > cap ? errno : EFBIG;
                goto fail;
            }
            buf = nb;
            cap = ncap;
        }
        got = fread(buf + n, 1, cap - 1 - n, f);
        n += got;
        if (got == 0)
            break;
    }
    if (ferror(f)) {
        e = errno ? errno : EIO;
        goto fail;
    }
    fclose(f);
    buf[n] = '\0';
    /* to the exact size, so that a sanitizer sees a read past the NUL */
    {
        char *fit = realloc(buf, n + 1);
        if (fit)
            buf = fit;
    }
    if (len)
        *len = n;
    return buf;

fail:
    free(buf);
    fclose(f);
    errno = e;
    return NULL;
}

int tf_write(const char *path, const void *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    int ok;
    if (!f)
        return -1;
    ok = len == 0 || fwrite(data, 1, len, f) == len;
    return (fclose(f) == 0 && ok) ? 0 : -1;
}

int tf_is_png(const char *path)
{
    size_t n = 0;
    char *d = tf_read(path, &n);
    int ok = d && n > 8 && memcmp(d, "\x89PNG\r\n\x1a\n", 8) == 0;
    free(d);
    return ok;
}
