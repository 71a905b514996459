/* subprocess.c -- running a built program from a test (subprocess.h). */
#define _POSIX_C_SOURCE 200809L

#include "subprocess.h"
#include "test_files.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#ifndef LP_BIN_DIR
#error "LP_BIN_DIR must name the directory of the built programs"
#endif

static const char *const MEASURE_CHILD = LP_BIN_DIR "/measure_child";

/* Records why tp_run failed (with errno's text); returns -1. */
static int fail(tp_result *r, const char *what)
{
    int e = errno;
    snprintf(r->error, sizeof r->error, "%s: %s", what, strerror(e));
    errno = e;
    return -1;
}

/* All of the temporary file f as a new NUL-terminated string (its length
 * in *len), read by position: the child moved the shared file offset.
 * NULL on failure, errno set. */
static char *read_back(FILE *f, size_t *len)
{
    int fd = fileno(f);
    struct stat st;
    size_t size, n = 0;
    char *s;

    if (fstat(fd, &st) != 0)
        return NULL;
    if (st.st_size < 0 || (uintmax_t)st.st_size >= SIZE_MAX) {
        errno = EFBIG;
        return NULL;
    }
    size = (size_t)st.st_size;
    s = malloc(size + 1);
    if (!s)
        return NULL;
    while (n < size) {
        ssize_t got = pread(fd, s + n, size - n, (off_t)n);
        if (got < 0 && errno == EINTR)
            continue;
        if (got <= 0) {
            if (got == 0)
                errno = EIO; /* the file shrank */
            free(s);
            return NULL;
        }
        n += (size_t)got;
    }
    s[n] = '\0';
    *len = n;
    return s;
}

/* The forked child: standard streams, limit, exec.  Never returns; only
 * async-signal-safe calls (the test may have threads). */
static void exec_child(char *const argv[], int out_fd, int err_fd, long fsize_limit)
{
    int in = open("/dev/null", O_RDONLY);
    if (in < 0 || dup2(in, 0) < 0 || dup2(out_fd, 1) < 0 || dup2(err_fd, 2) < 0)
        _exit(126);
    if (in > 2)
        close(in);
    if (out_fd > 2)
        close(out_fd);
    if (err_fd > 2)
        close(err_fd);
    if (fsize_limit > 0) {
        struct rlimit rl;
        rl.rlim_cur = rl.rlim_max = (rlim_t)fsize_limit;
        signal(SIGXFSZ, SIG_IGN);
        if (setrlimit(RLIMIT_FSIZE, &rl) != 0)
            _exit(126);
    }
    execv(argv[0], argv);
    _exit(127);
}

int tp_run(const char *program, const char *const args[], const tp_opts *opts, tp_result *r)
{
    static const tp_opts defaults;
    const char **argv;
    size_t nargs = 0, n = 0;
    FILE *fo, *fe, *fr = NULL;
    char fdarg[24];
    pid_t pid;
    int st, status, rc = -1;
    double t0;

    if (!opts)
        opts = &defaults;
    memset(r, 0, sizeof *r);
    r->status = -1;
    r->peak_kb = -1;
    while (args && args[nargs])
        nargs++;
    argv = malloc((nargs + 4) * sizeof *argv);
    fo = tmpfile();
    fe = tmpfile();
    if (opts->measure_memory)
        fr = tmpfile();
    if (!argv) {
        fail(r, "malloc");
        goto done;
    }
    if (!fo || !fe || (opts->measure_memory && !fr)) {
        fail(r, "tmpfile");
        goto done;
    }
    if (opts->measure_memory) {
        /* measure_child FD PROGRAM [ARG...]: its report goes to fr */
        snprintf(fdarg, sizeof fdarg, "%d", fileno(fr));
        argv[n++] = MEASURE_CHILD;
        argv[n++] = fdarg;
    }
    argv[n++] = program;
    for (size_t i = 0; i < nargs; i++)
        argv[n++] = args[i];
    argv[n] = NULL;

    fflush(stdout);
    fflush(stderr);
    t0 = tf_now();
    pid = fork();
    if (pid < 0) {
        fail(r, "fork");
        goto done;
    }
    if (pid == 0)
        exec_child((char *const *)argv, fileno(fo), fileno(fe), opts->fsize_limit);
    while (waitpid(pid, &st, 0) < 0) {
        if (errno != EINTR) {
            fail(r, "waitpid");
            goto done;
        }
    }
    r->seconds = tf_now() - t0;
    status = WIFEXITED(st) ? WEXITSTATUS(st) : WIFSIGNALED(st) ? 128 + WTERMSIG(st) : -1;
    if (opts->measure_memory) {
        /* "status S peak_kb K" when measure_child ran and reported (exit 0) */
        size_t len;
        char *line = read_back(fr, &len);
        int s;
        long kb;
        if (status == 0 && line && sscanf(line, "status %d peak_kb %ld", &s, &kb) == 2) {
            r->status = s;
            r->peak_kb = kb;
        }
        free(line);
    } else {
        r->status = status;
    }
    r->out = read_back(fo, &r->out_len);
    if (!r->out) {
        fail(r, "reading the program's stdout back");
        goto done;
    }
    r->err = read_back(fe, &r->err_len);
    if (!r->err) {
        fail(r, "reading the program's stderr back");
        goto done;
    }
    rc = 0;
done:
    if (fo)
        fclose(fo);
    if (fe)
        fclose(fe);
    if (fr)
        fclose(fr);
    free(argv);
    if (rc != 0) {
        tp_result_free(r);
        r->status = -1;
        r->peak_kb = -1;
    }
    return rc;
}

void tp_result_free(tp_result *r)
{
    if (!r)
        return;
    free(r->out);
    free(r->err);
    r->out = r->err = NULL;
    r->out_len = r->err_len = 0;
}

void tp_describe(const char *program, const char *const args[], char *buf, size_t size)
{
    const char *base = strrchr(program, '/');
    if (size == 0)
        return;
    snprintf(buf, size, "%s", base ? base + 1 : program);
    for (size_t i = 0; args && args[i]; i++) {
        size_t len = strlen(buf);
        snprintf(buf + len, size - len, " '%s'", args[i]);
    }
}
