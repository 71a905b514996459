/* schedule_mpi.c -- dynamic scheduling of work items over MPI
 * (schedule.h).
 *
 * The protocol, on the group's own communicator: every message of a
 * worker (rank > 0) to rank 0 gets exactly one answer.
 *   worker -> 0   TAG_ASK     (empty)            a request, sent AHEAD times
 *                 TAG_RESULT  header + result    an item done; asks again
 *                 TAG_FAILED  header + message   an item failed; asks again
 *   0 -> worker   TAG_ITEM    long item          do this one
 *                 TAG_STOP    long status        no more for this request
 * A worker keeps AHEAD requests open, so the answer for its next item is
 * there when it finishes one (no worker waits for rank 0), and ends when
 * each has been answered with TAG_STOP.  Then rank 0 broadcasts the run's
 * status, so every process returns the same one.  Rank 0's calling thread
 * only talks (MPI_Iprobe, then a receive, every POLL_NS when nothing
 * came); a thread of its own runs rank 0's items, taking them from the
 * same counter under a mutex. */
#define _POSIX_C_SOURCE 200809L

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "group_mpi.h"
#include "lpmpi/schedule.h"

enum { TAG_ASK = 101, TAG_RESULT, TAG_FAILED, TAG_ITEM, TAG_STOP };

#define POLL_NS 1000000L /* 1 ms between polls when nothing came */
#define AHEAD 2           /* requests a worker keeps open */

/* What precedes a result or a failure message. */
typedef struct header {
    long item;
    long status; /* TAG_FAILED */
    size_t size; /* bytes after the header */
} header;

typedef struct leader {
    const mw_job *job;
    pthread_mutex_t lock;   /* guards everything below and done() */
    long next;              /* the next item to hand out */
    long status;            /* the first failure's, 0 while none */
    char *msg;
    size_t msg_size;
    atomic_int local_busy;  /* rank 0's own thread still runs items */
} leader;

/* The next item for someone, or -1 when there is none (or a failure
 * stopped the hand-out). */
static long take(leader *L)
{
    long k = -1;
    pthread_mutex_lock(&L->lock);
    if (L->status == 0 && L->next < L->job->n_items)
        k = L->next++;
    pthread_mutex_unlock(&L->lock);
    return k;
}

/* Record a failure (the first one wins). */
static void fail(leader *L, long status, const char *text)
{
    pthread_mutex_lock(&L->lock);
    if (L->status == 0) {
        L->status = status;
        if (L->msg_size > 0)
            snprintf(L->msg, L->msg_size, "%s", text);
    }
    pthread_mutex_unlock(&L->lock);
}

static void deliver(leader *L, long item, const void *data, size_t size)
{
    pthread_mutex_lock(&L->lock);
    if (L->job->done)
        L->job->done(L->job->user, item, data, size);
    pthread_mutex_unlock(&L->lock);
}

/* Rank 0's own items (no MPI call here). */
static void *local_main(void *arg)
{
    leader *L = arg;
    const mw_job *job = L->job;
    void *buf = malloc(job->result_size > 0 ? job->result_size : 1);
    char text[1024];
    long k;

    if (!buf) {
        fail(L, -1, "out of memory for a result");
    } else {
        while ((k = take(L)) >= 0) {
            size_t used = 0;
            int rc;
            text[0] = '\0';
            rc = job->run(job->user, k, buf, &used, text, sizeof text);
            if (rc != 0) {
                fail(L, rc, text);
                break;
            }
            deliver(L, k, buf, used > job->result_size ? job->result_size : used);
        }
    }
    free(buf);
    atomic_store(&L->local_busy, 0);
    return NULL;
}

static int mpi_fail(int rc, const char *what, char *msg, size_t msg_size)
{
    char text[MPI_MAX_ERROR_STRING];
    int len = 0;
    if (MPI_Error_string(rc, text, &len) != MPI_SUCCESS)
        snprintf(text, sizeof text, "error %d", rc);
    if (msg_size > 0)
        snprintf(msg, msg_size, "MPI: %s: %s", what, text);
    return -1;
}

/* Answer one worker: its next item, or stop with the run's status. */
static int answer(mw_group *g, leader *L, int rank, int *active)
{
    long k = take(L), status;
    if (k >= 0)
        return MPI_Send(&k, 1, MPI_LONG, rank, TAG_ITEM, g->comm);
    pthread_mutex_lock(&L->lock);
    status = L->status;
    pthread_mutex_unlock(&L->lock);
    (*active)--;
    return MPI_Send(&status, 1, MPI_LONG, rank, TAG_STOP, g->comm);
}

static int lead(mw_group *g, const mw_job *job, char *msg, size_t msg_size)
{
    leader L;
    pthread_t thread;
    int active = AHEAD * (g->size - 1), rc = MPI_SUCCESS, started = 0; /* open requests */
    size_t cap = sizeof(header) + job->result_size;
    char *buf = malloc(cap);

    memset(&L, 0, sizeof L);
    L.job = job;
    L.msg = msg;
    L.msg_size = msg_size;
    if (!buf || pthread_mutex_init(&L.lock, NULL) != 0) {
        free(buf);
        snprintf(msg, msg_size, "out of memory for the scheduler");
        return -1;
    }
    atomic_init(&L.local_busy, 1);
    if (pthread_create(&thread, NULL, local_main, &L) == 0)
        started = 1;
    else
        atomic_store(&L.local_busy, 0); /* the others do every item */

    while (active > 0 || atomic_load(&L.local_busy)) {
        int flag = 0, count = 0;
        MPI_Status st;
        if (active > 0 && (rc = MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, g->comm, &flag,
                                           &st)) != MPI_SUCCESS)
            break;
        if (!flag) {
            struct timespec nap = {0, POLL_NS};
            nanosleep(&nap, NULL);
            continue;
        }
        MPI_Get_count(&st, MPI_BYTE, &count);
        if (count < 0 || (size_t)count > cap) {
            fail(&L, -1, "a worker sent a message larger than a result");
            count = (int)cap;
        }
        rc = MPI_Recv(buf, count, MPI_BYTE, st.MPI_SOURCE, st.MPI_TAG, g->comm,
                      MPI_STATUS_IGNORE);
        if (rc != MPI_SUCCESS)
            break;
        if ((st.MPI_TAG == TAG_RESULT || st.MPI_TAG == TAG_FAILED) &&
            (size_t)count >= sizeof(header)) {
            header h;
            memcpy(&h, buf, sizeof h);
            if (h.size > (size_t)count - sizeof h)
                h.size = (size_t)count - sizeof h;
            if (st.MPI_TAG == TAG_RESULT) {
                deliver(&L, h.item, buf + sizeof h, h.size);
            } else {
                char text[1024];
                size_t n = h.size < sizeof text - 1 ? h.size : sizeof text - 1;
                memcpy(text, buf + sizeof h, n);
                text[n] = '\0';
                fail(&L, h.status != 0 ? h.status : -1, text);
            }
        }
        if ((rc = answer(g, &L, st.MPI_SOURCE, &active)) != MPI_SUCCESS)
            break;
    }
    if (started)
        pthread_join(thread, NULL);
    free(buf);
    pthread_mutex_destroy(&L.lock);
    if (rc != MPI_SUCCESS)
        return mpi_fail(rc, "scheduling", msg, msg_size);
    if ((rc = MPI_Bcast(&L.status, 1, MPI_LONG, 0, g->comm)) != MPI_SUCCESS)
        return mpi_fail(rc, "sharing the status", msg, msg_size);
    return (int)L.status;
}

static int work(mw_group *g, const mw_job *job, char *msg, size_t msg_size)
{
    char *buf = malloc(sizeof(header) + job->result_size + 1024);
    int rc = MPI_SUCCESS, open = 0;
    long cmd = 0, status = 0;
    MPI_Status st;

    for (int k = 0; k < AHEAD && rc == MPI_SUCCESS; k++, open++)
        rc = MPI_Send(NULL, 0, MPI_BYTE, 0, TAG_ASK, g->comm);
    while (rc == MPI_SUCCESS && open > 0) {
        header h;
        int tag;
        size_t n;
        rc = MPI_Recv(&cmd, 1, MPI_LONG, 0, MPI_ANY_TAG, g->comm, &st);
        open--;
        if (rc != MPI_SUCCESS || st.MPI_TAG == TAG_STOP)
            continue;
        memset(&h, 0, sizeof h);
        h.item = cmd;
        if (buf) {
            char text[1024] = "";
            int failed = job->run(job->user, cmd, buf + sizeof h, &h.size, text, sizeof text);
            if (failed == 0) {
                tag = TAG_RESULT;
                if (h.size > job->result_size)
                    h.size = job->result_size;
            } else {
                tag = TAG_FAILED;
                h.status = failed;
                h.size = strlen(text);
                memcpy(buf + sizeof h, text, h.size);
            }
            memcpy(buf, &h, sizeof h);
            n = sizeof h + h.size;
            rc = MPI_Send(buf, (int)n, MPI_BYTE, 0, tag, g->comm);
        } else {
            static const char oom[] = "out of memory for a result";
            char small[sizeof h + sizeof oom];
            h.status = -1;
            h.size = sizeof oom - 1;
            memcpy(small, &h, sizeof h);
            memcpy(small + sizeof h, oom, h.size);
            rc = MPI_Send(small, (int)(sizeof h + h.size), MPI_BYTE, 0, TAG_FAILED, g->comm);
        }
        open++;
    }
    free(buf);
    if (rc == MPI_SUCCESS)
        rc = MPI_Bcast(&status, 1, MPI_LONG, 0, g->comm);
    if (rc != MPI_SUCCESS)
        return mpi_fail(rc, "waiting for work", msg, msg_size);
    return (int)status;
}

int mw_run(mw_group *g, const mw_job *job, char *msg, size_t msg_size)
{
    if (job->result_size > (size_t)0x7fffffff - sizeof(header) - 1024) {
        snprintf(msg, msg_size, "a result of %zu bytes is too large for one message",
                 job->result_size);
        return -1;
    }
    return g->rank == 0 ? lead(g, job, msg, msg_size) : work(g, job, msg, msg_size);
}
