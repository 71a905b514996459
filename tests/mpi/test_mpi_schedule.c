/* test_mpi_schedule.c -- the work items of mpi/ (schedule.h) under the
 * MPI launcher: on 1, 2 and 3 processes (3 on a 2-core machine: more
 * processes than cores) every item's result reaches rank 0 exactly once
 * and whole (mpi_items checks each byte); with items that take time,
 * rank 0 does items too, not only hands them out; an item failing on one
 * rank, and a rank killed, end the run with one message (the failure's)
 * and a non-zero status, within 60 s. */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "mpi_launch.h"

#define ITEMS LP_BIN_DIR "/mpi_items"

/* A run whose failure must end everything: its time bound.  The launcher
 * is stopped there: a hang shows as status 124.  Measured: 1.5-2.6 s in
 * release on this 2-core machine at load average 10. */
#define FAIL_BOUND_S 60.0

static void parse_counts(const char *out, int ranks, int *counts)
{
    const char *p = strstr(out ? out : "", "ranks:");
    for (int r = 0; r < ranks; r++)
        counts[r] = -1;
    if (!p)
        return;
    p += strlen("ranks:");
    for (int r = 0; r < ranks; r++) {
        char *end;
        long v = strtol(p, &end, 10);
        if (end == p)
            return;
        counts[r] = (int)v;
        p = end;
    }
}

static void all_once(int ranks, const char *n_items, const char *sleep_ms)
{
    tp_result r;
    const char *args[] = {n_items, "--sleep-ms", sleep_ms, NULL};
    int counts[8], total = 0;
    if (ml_run(ranks, ML_TIMEOUT_S, ITEMS, args, &r) != 0) {
        CHECK(0, "could not run the launcher: %s", r.error);
        return;
    }
    CHECK(r.status == 0, "%d ranks, %s items: status %d, stderr: %s", ranks, n_items, r.status,
          r.err);
    CHECK(strstr(r.out, "each once") != NULL, "%d ranks: %s", ranks, r.out);
    parse_counts(r.out, ranks, counts);
    for (int k = 0; k < ranks; k++)
        total += counts[k];
    CHECK(total == atoi(n_items), "%d ranks: the ranks' items add up to %d, not %s: %s", ranks,
          total, n_items, r.out);
    /* Items of 20 ms, 30 of them, and every rank asks as soon as it is
     * free: each rank does some, rank 0 included. */
    if (atoi(sleep_ms) > 0)
        for (int k = 0; k < ranks; k++)
            CHECK(counts[k] >= 1, "%d ranks: rank %d did no item: %s", ranks, k, r.out);
    printf("%d ranks, %s items: %.2f s, %s", ranks, n_items, r.seconds, r.out);
    tp_result_free(&r);
}

static void failure(int ranks, const char *how, const char *rank, int want_status)
{
    tp_result r;
    const char *args[] = {"40", "--sleep-ms", "20", how, rank, NULL};
    if (ml_run(ranks, (int)FAIL_BOUND_S, ITEMS, args, &r) != 0) {
        CHECK(0, "could not run the launcher: %s", r.error);
        return;
    }
    /* 124: timeout(1) ended a run that hung (a killed rank's own status,
     * 137 = 128 + SIGKILL, is what mpirun returns for it). */
    CHECK(r.status != 0 && r.status != 124, "%s on rank %s of %d: status %d (124: it hung)",
          how, rank, ranks, r.status);
    if (want_status)
        CHECK(r.status == want_status, "%s on rank %s of %d: status %d, not %d", how, rank,
              ranks, r.status, want_status);
    CHECK(r.seconds < FAIL_BOUND_S, "%s on rank %s of %d: %.1f s to end", how, rank, ranks,
          r.seconds);
    if (strcmp(how, "--fail") == 0) {
        CHECK(ml_count_lines(r.err, "mpi_items:") == 1 && strstr(r.err, "failed on rank") != NULL,
              "%s on rank %s of %d: not one message: %s", how, rank, ranks, r.err);
        CHECK(ml_count_lines(r.out, "mpi_items:") == 0, "a failed run reported success: %s",
              r.out);
    }
    printf("%s on rank %s of %d: status %d in %.2f s\n", how, rank, ranks, r.status, r.seconds);
    tp_result_free(&r);
}

int main(void)
{
    all_once(1, "7", "0");
    all_once(3, "200", "0");
    all_once(2, "30", "20");
    all_once(3, "30", "20");
    all_once(3, "0", "0");
    all_once(3, "1", "0");
    failure(2, "--fail", "1", 3);
    failure(3, "--fail", "0", 3);
    failure(2, "--die", "1", 137);
    failure(3, "--die", "0", 137);
    return check_finish("test_mpi_schedule");
}
