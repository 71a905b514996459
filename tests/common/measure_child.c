/* measure_child -- run a program and report its own peak memory.
 *
 *   measure_child FD PROGRAM [ARG...]
 *
 * Runs PROGRAM with the given arguments (standard streams, resource limits
 * and ignored signals inherited), waits for it, and writes one line to the
 * already open file descriptor FD:
 *
 *   status S peak_kb K
 *
 * S is the exit status, or 128 + the signal number; K is the program's
 * peak resident set size in KiB (getrusage's ru_maxrss).  measure_child
 * then exits 0; it exits 125 when it cannot run or report at all.
 *
 * Why a separate program: Linux counts in a child's ru_maxrss the resident
 * size it had before exec, i.e. a copy of its parent.  A test process is
 * small natively, but under valgrind or a sanitizer it holds the tool's
 * memory (70 MiB or more), which then shows up as the child's peak.  The
 * tests run measured programs through this small process, whose fork is
 * small, and valgrind is told not to trace into it (scripts/valgrind.sh):
 * a resource bound is measured on the program alone. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

int main(int argc, char **argv)
{
    char *end;
    long fd;
    pid_t pid;
    int st;
    struct rusage ru;
    char line[96];
    int len;

    if (argc < 3) {
        fprintf(stderr, "usage: measure_child FD PROGRAM [ARG...]\n");
        return 125;
    }
    errno = 0;
    fd = strtol(argv[1], &end, 10);
    if (errno || *end || end == argv[1] || fd < 0 || fd > 1024) {
        fprintf(stderr, "measure_child: bad file descriptor '%s'\n", argv[1]);
        return 125;
    }
    pid = fork();
    if (pid < 0) {
        fprintf(stderr, "measure_child: fork: %s\n", strerror(errno));
        return 125;
    }
    if (pid == 0) {
        close((int)fd);
        execv(argv[2], argv + 2);
        fprintf(stderr, "measure_child: cannot run %s: %s\n", argv[2], strerror(errno));
        _exit(127);
    }
    while (waitpid(pid, &st, 0) < 0) {
        if (errno != EINTR) {
            fprintf(stderr, "measure_child: wait: %s\n", strerror(errno));
            return 125;
        }
    }
    /* the only child, so its usage is all of RUSAGE_CHILDREN */
    if (getrusage(RUSAGE_CHILDREN, &ru) != 0) {
        fprintf(stderr, "measure_child: getrusage: %s\n", strerror(errno));
        return 125;
    }
    len = snprintf(line, sizeof line, "status %d peak_kb %ld\n",
                   WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st), (long)ru.ru_maxrss);
    if (write((int)fd, line, (size_t)len) != (ssize_t)len) {
        fprintf(stderr, "measure_child: cannot report on fd %ld\n", fd);
        return 125;
    }
    return 0;
}
