/* mpi_launch.h -- running a program under the MPI launcher from a test.
 *
 *   tp_result r;
 *   const char *args[] = {"8", NULL};
 *   ml_run(2, ML_TIMEOUT_S, LP_BIN_DIR "/mpi_items", args, &r);   (mpirun -n 2 ... 8)
 *
 * The launcher is the one the build found (LP_MPIEXEC, its -n flag
 * LP_MPIEXEC_NUMPROC_FLAG).  Open MPI's settings for this machine go in
 * through the environment, which other launchers ignore: more processes
 * than cores are allowed (OMPI_MCA_rmaps_base_oversubscribe), mpirun
 * prints no banners of its own (OMPI_MCA_orte_execute_quiet), and a test
 * run as root (containers, CI) may start them
 * (OMPI_ALLOW_RUN_AS_ROOT{,_CONFIRM}).  The whole run is bounded by
 * timeout(1): `seconds`, then SIGTERM (mpirun then ends every process),
 * then SIGKILL 10 s later: a run that hangs comes back with status 124
 * (137 after the SIGKILL) instead of hanging the test. */
#ifndef LP_TEST_MPI_LAUNCH_H
#define LP_TEST_MPI_LAUNCH_H

#include "subprocess.h"

/* The bound of a run that should succeed: far beyond any (the slowest,
 * the sweep under the sanitizers on a loaded machine, takes about 60 s). */
#define ML_TIMEOUT_S 600

/* Runs `program` with args (NULL-terminated) on n processes, at most
 * `seconds`; as tp_run. */
int ml_run(int n, int seconds, const char *program, const char *const args[], tp_result *r);

/* The environment ml_run gives the launcher (above); also for a program
 * of the MPI build run without the launcher (a run of one process). */
void ml_environment(void);

/* Whether the files at a and b hold the same bytes (both readable). */
int ml_same_file(const char *a, const char *b);

/* The number of lines of text that start with prefix. */
int ml_count_lines(const char *text, const char *prefix);

#endif
