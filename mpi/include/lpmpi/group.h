/* group.h -- the processes of one run: started together under mpirun (or
 * srun), each knowing its rank, agreeing on whether a step succeeded.
 *
 * Built over MPI when the build found it (LENSPRIM_MPI), otherwise over a
 * one-process stand-in with the same functions: rank 0 of 1.  Nothing
 * here prints or exits; every message is returned to the caller.
 *
 * MPI is initialised with MPI_THREAD_FUNNELED: a process may run threads,
 * but only the thread that called mw_group_start makes MPI calls (every
 * function here and in schedule.h must be called from that thread). */
#ifndef LPMPI_GROUP_H
#define LPMPI_GROUP_H

#include <stddef.h>

typedef struct mw_group mw_group;

/* Start this process's part of the run (MPI_Init_thread; a program started
 * without mpirun is a group of one).  argc and argv are the program's own
 * (MPI may read its options from them).  Returns 0, or -1 with a one-line
 * message (the MPI library could not start, or gives less than
 * MPI_THREAD_FUNNELED) and *out NULL; then nothing else may be called. */
int mw_group_start(int *argc, char ***argv, mw_group **out, char *msg, size_t msg_size);

/* This process's rank, 0 .. size - 1; rank 0 leads (gathers, writes,
 * prints). */
int mw_group_rank(const mw_group *g);
/* The number of processes of the run, >= 1. */
int mw_group_size(const mw_group *g);
/* The number of processes of the run on this machine (sharing its memory
 * and cores), >= 1: a process's fair share of the machine's cores is the
 * machine's count divided by it. */
int mw_group_local_size(const mw_group *g);

/* Collective: every process calls it with its own status (0: success)
 * and, when status != 0, a message in msg.  Returns, on every process, the
 * status of the lowest-ranked process that failed (0 when none did); on
 * rank 0, msg then holds that process's message and *who its rank (who
 * may be NULL).  On the other ranks msg is left as it was.  msg_size must
 * be the same on every process.  A status the MPI library itself could
 * not agree on is returned as -1 with a message. */
int mw_agree(mw_group *g, int status, int *who, char *msg, size_t msg_size);

/* Collective: rank 0's size bytes at data replace every other process's
 * (size must be the same on every process).  Returns 0, or -1 with a
 * message (the MPI library could not send them). */
int mw_share(mw_group *g, void *data, size_t size, char *msg, size_t msg_size);

/* End this process's part (MPI_Finalize) and free g (NULL is harmless).
 * Every process must call it once, after its last collective call. */
void mw_group_end(mw_group *g);

#endif
