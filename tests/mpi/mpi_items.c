/* mpi_items.c -- a run of independent items through mpi/ (schedule.h),
 * checked on rank 0: every item's result arrives exactly once, whole and
 * right.  For test_mpi_schedule.
 *
 *   mpi_items N [--sleep-ms MS] [--fail RANK] [--die RANK]
 *
 * Item k's result is 8 + 8 (k % 50) bytes, byte b = (k * 131 + b) & 255,
 * so a short, long, misplaced or repeated result is seen.  --sleep-ms:
 * each item takes that long.  --fail RANK: that rank's first item fails
 * (status 3, "item K failed on rank RANK").  --die RANK: that rank
 * kills itself (SIGKILL) at its first item.
 *
 * Prints on rank 0 "mpi_items: N items, each once, ranks: c0 c1 ..."
 * (the items each rank did) and exits 0; a wrong result: one line and
 * exit 1; a failure: its message (one line, rank 0) and its status, on
 * every rank. */
#define _POSIX_C_SOURCE 200809L

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "lpmpi/group.h"
#include "lpmpi/schedule.h"

#define RESULT_MAX (8 + 8 * 49 + 4)

typedef struct ctx {
    int rank, sleep_ms, fail_rank, die_rank, ran;
    long n;
    int *seen;      /* rank 0: deliveries per item */
    int *by_rank;   /* rank 0: items per rank */
    int ranks;
    int bad;        /* rank 0: a wrong result */
} ctx;

static size_t item_size(long k)
{
    return (size_t)(8 + 8 * (k % 50));
}

static int run(void *user, long k, void *result, size_t *used, char *msg, size_t msg_size)
{
    ctx *c = user;
    unsigned char *b = result;
    if (c->ran++ == 0 && c->rank == c->die_rank)
        raise(SIGKILL);
    if (c->ran == 1 && c->rank == c->fail_rank) {
        snprintf(msg, msg_size, "item %ld failed on rank %d", k, c->rank);
        return 3;
    }
    if (c->sleep_ms > 0) {
        struct timespec t = {c->sleep_ms / 1000, (long)(c->sleep_ms % 1000) * 1000000L};
        nanosleep(&t, NULL);
    }
    *used = item_size(k) + 4;
    for (size_t i = 0; i < item_size(k); i++)
        b[i] = (unsigned char)((k * 131 + (long)i) & 255);
    memcpy(b + item_size(k), &c->rank, 4);
    return 0;
}

static void done(void *user, long k, const void *result, size_t size)
{
    ctx *c = user;
    const unsigned char *b = result;
    int who;
    if (k < 0 || k >= c->n || size != item_size(k) + 4) {
        c->bad = 1;
        return;
    }
    for (size_t i = 0; i < item_size(k); i++)
        if (b[i] != (unsigned char)((k * 131 + (long)i) & 255))
            c->bad = 1;
    memcpy(&who, b + item_size(k), 4);
    if (who >= 0 && who < c->ranks)
        c->by_rank[who]++;
    else
        c->bad = 1;
    c->seen[k]++;
}

int main(int argc, char **argv)
{
    mw_group *g;
    char msg[1024] = "";
    ctx c;
    mw_job job;
    int rc;

    if (mw_group_start(&argc, &argv, &g, msg, sizeof msg) != 0) {
        fprintf(stderr, "mpi_items: %s\n", msg);
        return 1;
    }
    memset(&c, 0, sizeof c);
    c.rank = mw_group_rank(g);
    c.ranks = mw_group_size(g);
    c.fail_rank = c.die_rank = -1;
    c.n = argc > 1 ? atol(argv[1]) : 0;
    for (int i = 2; i + 1 < argc; i += 2) {
        int v = atoi(argv[i + 1]);
        if (strcmp(argv[i], "--sleep-ms") == 0)
            c.sleep_ms = v;
        else if (strcmp(argv[i], "--fail") == 0)
            c.fail_rank = v;
        else if (strcmp(argv[i], "--die") == 0)
            c.die_rank = v;
    }
    c.seen = calloc((size_t)c.n + 1, sizeof *c.seen);
    c.by_rank = calloc((size_t)c.ranks, sizeof *c.by_rank);
    memset(&job, 0, sizeof job);
    job.n_items = c.n;
    job.result_size = RESULT_MAX;
    job.run = run;
    job.done = done;
    job.user = &c;
    rc = mw_run(g, &job, msg, sizeof msg);
    if (c.rank == 0) {
        if (rc != 0) {
            fprintf(stderr, "mpi_items: %s\n", msg);
        } else {
            for (long k = 0; k < c.n; k++)
                if (c.seen[k] != 1) {
                    fprintf(stderr, "mpi_items: item %ld arrived %d times\n", k, c.seen[k]);
                    rc = 1;
                    break;
                }
            if (rc == 0 && c.bad) {
                fprintf(stderr, "mpi_items: a result arrived wrong\n");
                rc = 1;
            }
            if (rc == 0) {
                printf("mpi_items: %ld items, each once, ranks:", c.n);
                for (int r = 0; r < c.ranks; r++)
                    printf(" %d", c.by_rank[r]);
                printf("\n");
            }
        }
    }
    free(c.seen);
    free(c.by_rank);
    mw_group_end(g);
    return rc;
}
