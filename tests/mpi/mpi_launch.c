/* mpi_launch.c -- the MPI launcher from a test (mpi_launch.h). */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mpi_launch.h"
#include "test_files.h"

void ml_environment(void)
{
    setenv("OMPI_MCA_rmaps_base_oversubscribe", "1", 1);
    setenv("OMPI_MCA_orte_execute_quiet", "1", 1); /* mpirun -q: no banners of its own */
    if (geteuid() == 0) {
        setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
        setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    }
}

int ml_run(int n, int seconds, const char *program, const char *const args[], tp_result *r)
{
    const char *argv[64];
    char count[16], limit[16];
    size_t k = 0;

    ml_environment();
    snprintf(count, sizeof count, "%d", n);
    snprintf(limit, sizeof limit, "%d", seconds);
    argv[k++] = "-k";
    argv[k++] = "10";
    argv[k++] = limit;
    argv[k++] = LP_MPIEXEC;
    argv[k++] = LP_MPIEXEC_NUMPROC_FLAG;
    argv[k++] = count;
    argv[k++] = program;
    for (size_t i = 0; args && args[i] && k + 1 < sizeof argv / sizeof *argv; i++)
        argv[k++] = args[i];
    argv[k] = NULL;
    return tp_run(LP_TIMEOUT_PROGRAM, argv, NULL, r);
}

int ml_count_lines(const char *text, const char *prefix)
{
    int count = 0;
    size_t n = strlen(prefix);
    for (const char *line = text; line && *line;) {
        const char *end = strchr(line, '\n');
        if (strncmp(line, prefix, n) == 0)
            count++;
        line = end ? end + 1 : NULL;
    }
    return count;
}

int ml_same_file(const char *a, const char *b)
{
    size_t na, nb;
    char *x = tf_read(a, &na), *y = tf_read(b, &nb);
    int same = x && y && na == nb && memcmp(x, y, na) == 0;
    free(x);
    free(y);
    return same;
}
