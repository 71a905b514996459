/* sa_run.c -- run a program and measure its CPU time (see sa_run.h). */
#define _GNU_SOURCE

#include "sa_run.h"

#include "support/cli.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

int sa_run(char *const argv[], const char *dir, double cpu_limit, sa_run_result *out,
           char *msg, size_t msg_size)
{
    FILE *err = tmpfile();
    struct rusage ru;
    int wstatus;
    pid_t pid;
    double t0;

    memset(out, 0, sizeof *out);
    out->status = -1;
    if (!err) {
        snprintf(msg, msg_size, "cannot create a temporary file: %s", strerror(errno));
        return -1;
    }
    t0 = sp_now_seconds();
    pid = fork();
    if (pid < 0) {
        snprintf(msg, msg_size, "fork: %s", strerror(errno));
        fclose(err);
        return -1;
    }
    if (pid == 0) {
        int null_fd = open("/dev/null", O_RDWR);
        if (cpu_limit > 0.0) {
            struct rlimit rl;
            rl.rlim_cur = (rlim_t)cpu_limit + 1;
            rl.rlim_max = rl.rlim_cur + 1;
            if (setrlimit(RLIMIT_CPU, &rl) != 0)
                _exit(126);
        }
        if (null_fd < 0 || dup2(null_fd, 0) < 0 || dup2(null_fd, 1) < 0 ||
            dup2(fileno(err), 2) < 0 || (dir && chdir(dir) != 0))
            _exit(126);
        execvp(argv[0], argv);
        _exit(127);
    }
    while (wait4(pid, &wstatus, 0, &ru) < 0) {
        if (errno != EINTR) {
            snprintf(msg, msg_size, "wait4: %s", strerror(errno));
            fclose(err);
            return -1;
        }
    }
    out->wall_seconds = sp_now_seconds() - t0;
    out->cpu_seconds = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
                       (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
    out->status = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus)
                  : WIFSIGNALED(wstatus) ? 128 + WTERMSIG(wstatus) : -1;
    rewind(err);
    size_t n = fread(out->err, 1, sizeof out->err - 1, err);
    out->err[n] = '\0';
    fclose(err);
    return 0;
}
