/* test_mpi_sweep.c -- the sweeps across processes give one process's
 * outputs.  The speed-accuracy sweep: speed_accuracy alone and under the
 * MPI launcher on 3 processes (one scene, 4 x 3 pixels, one run per
 * point), their CSVs the same line for line and column for column but
 * for the times (column 8, seconds: a measurement, different in every
 * run).  The NA sweep of the empty microscope: extinction_na alone and on
 * 3 processes, its CSV and chart the same bytes. */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "mpi_launch.h"
#include "test_files.h"

#define SECONDS_COLUMN 7 /* 0-based: scene,kind,model,wavelengths,depth,cutoff,tolerance,seconds */

/* Line text without its seconds column, into out. */
static void drop_seconds(const char *line, size_t n, char *out, size_t out_size)
{
    size_t o = 0;
    int col = 0;
    for (size_t i = 0; i < n && o + 1 < out_size; i++) {
        if (line[i] == ',')
            col++;
        if (col != SECONDS_COLUMN || (line[i] == ',' && col == SECONDS_COLUMN))
            out[o++] = line[i];
    }
    out[o] = '\0';
}

static void sweep(int ranks, const char *docs, const char *work)
{
    char scenes[4096];
    tp_result r;
    snprintf(scenes, sizeof scenes, "%s/scenes", LP_SOURCE_DIR);
    mkdir(docs, 0777);
    mkdir(work, 0777);
    const char *args[] = {"--bin", LP_BIN_DIR, "--scenes", scenes, "--docs", docs, "--work",
                          work, "--width", "4", "--height", "3", "--runs", "1", "--scene",
                          "default", "--max-wavelengths", "128", NULL};
    int rc = ranks == 0 ? tp_run(LP_BIN_DIR "/speed_accuracy", args, NULL, &r)
                        : ml_run(ranks, ML_TIMEOUT_S, LP_BIN_DIR "/speed_accuracy", args, &r);
    CHECK(rc == 0 && r.status == 0, "speed_accuracy on %d processes: status %d: %s", ranks,
          r.status, r.err ? r.err : r.error);
    printf("speed_accuracy on %d processes (0: without the launcher): %.2f s\n", ranks,
           r.seconds);
    tp_result_free(&r);
}

static void na_sweep(int ranks, const char *csv, const char *png)
{
    char scene[4096];
    tp_result r;
    snprintf(scene, sizeof scene, "%s/scenes/microscope/microscope_empty.scene", LP_SOURCE_DIR);
    remove(csv);
    const char *args[] = {"--scene", scene, "--csv", csv, "--png", png, NULL};
    int rc = ranks == 0 ? tp_run(LP_BIN_DIR "/extinction_na", args, NULL, &r)
                        : ml_run(ranks, ML_TIMEOUT_S, LP_BIN_DIR "/extinction_na", args, &r);
    CHECK(rc == 0 && r.status == 0, "extinction_na on %d processes: status %d: %s", ranks,
          r.status, r.err ? r.err : r.error);
    tp_result_free(&r);
}

int main(void)
{
    char d1[2048], w1[2048], d3[2048], w3[2048], c1[4096], c3[4096];
    snprintf(d1, sizeof d1, "%s/mpi_sweep_docs1", LP_TEST_TMP);
    snprintf(w1, sizeof w1, "%s/mpi_sweep_work1", LP_TEST_TMP);
    snprintf(d3, sizeof d3, "%s/mpi_sweep_docs3", LP_TEST_TMP);
    snprintf(w3, sizeof w3, "%s/mpi_sweep_work3", LP_TEST_TMP);
    snprintf(c1, sizeof c1, "%s/speed-accuracy.csv", d1);
    snprintf(c3, sizeof c3, "%s/speed-accuracy.csv", d3);
    remove(c1);
    remove(c3);
    ml_environment();
    sweep(0, d1, w1);
    sweep(3, d3, w3);

    size_t n1, n3;
    char *a = tf_read(c1, &n1), *b = tf_read(c3, &n3);
    CHECK(a && b, "the tables were not written");
    if (a && b) {
        const char *p = a, *q = b;
        int lines = 0;
        while (*p && *q) {
            const char *pe = strchr(p, '\n'), *qe = strchr(q, '\n');
            size_t pn = pe ? (size_t)(pe - p) : strlen(p), qn = qe ? (size_t)(qe - q) : strlen(q);
            char x[2048], y[2048];
            drop_seconds(p, pn, x, sizeof x);
            drop_seconds(q, qn, y, sizeof y);
            CHECK(strcmp(x, y) == 0, "line %d differs:\n  one process: %s\n  3 processes: %s",
                  lines + 1, x, y);
            lines++;
            p += pn + (pe ? 1 : 0);
            q += qn + (qe ? 1 : 0);
        }
        CHECK(*p == '\0' && *q == '\0', "the tables differ in length");
        /* The header, the reference and more than a hundred points. */
        CHECK(lines > 100, "only %d lines", lines);
        printf("%d lines the same but for the times\n", lines);
    }
    free(a);
    free(b);

    char na1[4096], na3[4096], pa1[4096], pa3[4096];
    snprintf(na1, sizeof na1, "%s/mpi_sweep_na1.csv", LP_TEST_TMP);
    snprintf(na3, sizeof na3, "%s/mpi_sweep_na3.csv", LP_TEST_TMP);
    snprintf(pa1, sizeof pa1, "%s/mpi_sweep_na1.png", LP_TEST_TMP);
    snprintf(pa3, sizeof pa3, "%s/mpi_sweep_na3.png", LP_TEST_TMP);
    na_sweep(0, na1, pa1);
    na_sweep(3, na3, pa3);
    CHECK(ml_same_file(na1, na3), "extinction_na: the CSV of 3 processes differs from one process's");
    CHECK(ml_same_file(pa1, pa3), "extinction_na: the chart of 3 processes differs from one process's");
    return check_finish("test_mpi_sweep");
}
