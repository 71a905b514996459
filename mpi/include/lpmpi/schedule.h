/* schedule.h -- independent work items shared among the processes of a
 * group with dynamic scheduling, their results gathered on rank 0.
 *
 * Items are numbered 0 .. n_items - 1 and handed out in that order, one
 * at a time, to whichever process asks next: a process that finishes
 * early takes more (each other process holds at most two items: the one
 * it runs and the next).  Rank 0 hands them out AND does items itself (on
 * a thread of its own, while its calling thread answers the others,
 * polling for their messages every millisecond), so no core idles as a
 * mere scheduler.  Each item is run exactly once, on one process; its result
 * (at most result_size bytes) travels to rank 0, which passes it to
 * done().  Which process runs which item varies from run to run: a result
 * must depend on the item alone for the gathered whole to be the same for
 * any number of processes.  Results travel as bytes: the processes must
 * share one data representation (a homogeneous cluster).
 *
 * Failure: an item whose run() returns non-zero stops the hand-out; every
 * process finishes the item it is running, and mw_run returns that status
 * on every process (the first failure's, when several fail), its message
 * in msg on rank 0.  A process that dies is the launcher's business: Open
 * MPI's mpirun (and srun) then ends every process of the run. */
#ifndef LPMPI_SCHEDULE_H
#define LPMPI_SCHEDULE_H

#include <stddef.h>

#include "lpmpi/group.h"

typedef struct mw_job {
    long n_items;       /* >= 0, the same on every process */
    size_t result_size; /* the largest result of an item, bytes, the same
                           on every process */
    /* Do item k: write its result into result (result_size bytes) and its
     * length into *used (<= result_size).  Returns 0, or a non-zero status
     * with a one-line message in msg (msg_size bytes).  Called on every
     * process, for one item at a time (on rank 0 from a thread of the
     * scheduler's, which makes no MPI call: run() must make none either). */
    int (*run)(void *user, long item, void *result, size_t *used, char *msg,
               size_t msg_size);
    /* Rank 0 only: item k's result, from whichever process ran it.  Called
     * once per item, one call at a time, in no particular order of k (from
     * either of rank 0's threads); never after mw_run has returned.  May be
     * NULL. */
    void (*done)(void *user, long item, const void *result, size_t size);
    void *user;
} mw_job;

/* Collective: every process of g calls it with the same n_items and
 * result_size (user, run and done are its own).  Returns 0 when every
 * item was run and, on rank 0, passed to done(); else the status of the
 * failure (see above), with its message in msg on rank 0, or -1 with a
 * message when memory, a thread or the MPI library failed. */
int mw_run(mw_group *g, const mw_job *job, char *msg, size_t msg_size);

#endif
