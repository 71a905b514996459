/* serial.c -- the one-process stand-in for group.h and schedule.h, built
 * when MPI is not: a group of one, whose items run in order on the
 * calling thread. */
#include <stdio.h>
#include <stdlib.h>

#include "lpmpi/group.h"
#include "lpmpi/schedule.h"

struct mw_group {
    int unused;
};

int mw_group_start(int *argc, char ***argv, mw_group **out, char *msg, size_t msg_size)
{
    (void)argc;
    (void)argv;
    *out = calloc(1, sizeof **out);
    if (!*out) {
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    return 0;
}

int mw_group_rank(const mw_group *g)
{
    (void)g;
    return 0;
}

int mw_group_size(const mw_group *g)
{
    (void)g;
    return 1;
}

int mw_group_local_size(const mw_group *g)
{
    (void)g;
    return 1;
}

int mw_agree(mw_group *g, int status, int *who, char *msg, size_t msg_size)
{
    (void)g;
    (void)msg;
    (void)msg_size;
    if (who)
        *who = 0;
    return status;
}

int mw_share(mw_group *g, void *data, size_t size, char *msg, size_t msg_size)
{
    (void)g;
    (void)data;
    (void)size;
    (void)msg;
    (void)msg_size;
    return 0;
}

void mw_group_end(mw_group *g)
{
    free(g);
}

int mw_run(mw_group *g, const mw_job *job, char *msg, size_t msg_size)
{
    void *buf = malloc(job->result_size > 0 ? job->result_size : 1);
    int rc = 0;
    (void)g;
    if (!buf) {
        snprintf(msg, msg_size, "out of memory for a result");
        return -1;
    }
    for (long k = 0; k < job->n_items && rc == 0; k++) {
        size_t used = 0;
        rc = job->run(job->user, k, buf, &used, msg, msg_size);
        if (rc == 0 && job->done)
            job->done(job->user, k, buf, used > job->result_size ? job->result_size : used);
    }
    free(buf);
    return rc;
}
