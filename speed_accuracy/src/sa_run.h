/* sa_run.h -- run a program once and measure it (speed_accuracy).
 *
 * The program runs as a child (fork/execvp, no shell) with standard input
 * from /dev/null, standard output discarded and standard error captured
 * whole.  Its time is the CPU time the child itself used (user + system,
 * from wait4's rusage): on a machine shared with other work that is what
 * the render costs, while wall time also counts the time other processes
 * held the cores.  No state: every call works on its arguments only. */
#ifndef SA_RUN_H
#define SA_RUN_H

#include <stddef.h>

typedef struct sa_run_result {
    int status;        /* exit status; 128 + N after signal N; -1: not run */
    double cpu_seconds;
    double wall_seconds;
    char err[4096];    /* the start of its standard error, NUL-terminated */
} sa_run_result;

/* Run argv[0] with argv (NULL-terminated) in directory dir (NULL: the
 * current one), with at most cpu_limit CPU seconds (RLIMIT_CPU, rounded
 * up: past it the kernel ends the program with SIGXCPU; <= 0: no limit).  Returns 0 when the program ran (whatever its status), -1
 * with a message when it could not be started. */
int sa_run(char *const argv[], const char *dir, double cpu_limit, sa_run_result *out,
           char *msg, size_t msg_size);

#endif
