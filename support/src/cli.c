/* cli.c -- messages, clock and directories of the programs (cli.h). */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "support/cli.h"

#ifndef PATH_MAX
#define PATH_MAX 4096
#endif

void sp_say(const char *program, const char *fmt, ...)
{
    char line[2048];
    va_list ap;
    int n = snprintf(line, sizeof line, "%s: ", program);

    va_start(ap, fmt);
    if (n >= 0 && (size_t)n < sizeof line)
        vsnprintf(line + n, sizeof line - (size_t)n, fmt, ap);
    va_end(ap);
    for (char *c = line; *c; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f)
            *c = '?';
    fprintf(stderr, "%s\n", line);
}

const char *sp_format(char *buf, size_t size, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, size, fmt, ap);
    va_end(ap);
    return buf;
}

static int starts_blank(const char *s)
{
    return *s == '\0' || *s == ' ' || *s == '\t' || *s == '\n' || *s == '\r' || *s == '\v' ||
           *s == '\f';
}

int sp_parse_double(const char *s, double *out)
{
    char *end;
    double v;
    if (starts_blank(s))
        return 0;
    errno = 0;
    v = strtod(s, &end);
    if (end == s || *end != '\0')
        return 0;
    if (errno == ERANGE && isinf(v))
        return -1;
    *out = v;
    return 1;
}

int sp_parse_long(const char *s, long lo, long hi, long *out)
{
    char *end;
    long v;
    if (starts_blank(s))
        return 0;
    errno = 0;
    v = strtol(s, &end, 10);
    if (end == s || *end != '\0')
        return 0;
    if (errno == ERANGE || v < lo || v > hi)
        return -1;
    *out = v;
    return 1;
}

int sp_print_text(const char *const *parts, size_t n)
{
    for (size_t i = 0; i < n; i++)
        fputs(parts[i], stdout);
    return fflush(stdout) == 0 && !ferror(stdout) ? 0 : -1;
}

int sp_print_version(const char *program, const char *version)
{
    printf("%s (lensprim) %s\n", program, version);
    return fflush(stdout) == 0 && !ferror(stdout) ? 0 : -1;
}

double sp_now_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int sp_mkdir_p(const char *path, char *msg, size_t msg_size)
{
    char buf[PATH_MAX];
    struct stat st;

    if (!*path || snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf) {
        snprintf(msg, msg_size, "%s: %s", path, *path ? "path too long" : "empty directory name");
        return -1;
    }
    for (char *p = buf + 1;; p++) {
        if (*p == '/' || *p == '\0') {
            char c = *p;
            *p = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST) {
                snprintf(msg, msg_size, "%s: cannot create directory: %s", buf, strerror(errno));
                return -1;
            }
            *p = c;
            if (c == '\0')
                break;
        }
    }
    if (stat(path, &st) != 0 || !S_ISDIR(st.st_mode)) {
        snprintf(msg, msg_size, "%s: not a directory", path);
        return -1;
    }
    return 0;
}
