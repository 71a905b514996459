/* test_mpi_sweep.c -- the sweeps across processes give one process's
 * outputs.  The speed-accuracy sweep: two scenes' references made once
 * (4 x 3 pixels), then speed_accuracy alone and under the MPI launcher on
 * 4 processes reusing them (three that ask for work: at least one of
 * them did not make a reference), one run per point, with --point-seconds set
 * from the references' own time per wavelength so that the dearest
 * settings are left out of the sweep: their CSVs must be the same line
 * for line and column for column but for the times (column 8, seconds: a
 * measurement, different in every run), and each table must hold both
 * scenes' three auto points with auto's choice in their notes.  Which
 * settings are left out depends on a reference's numbers, and every
 * process must list the same points: a process that did not make a
 * scene's reference must still know them.  The NA sweep of the empty
 * microscope: extinction_na alone and on 3 processes, its CSV and chart
 * the same bytes. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
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

#define SCENE_A "default"
#define SCENE_B "plan_view"
#define RANKS 4

/* One sweep of SCENE_A and SCENE_B: ranks 0 without the launcher;
 * point_seconds NULL: make the references only. */
static void sweep(int ranks, const char *docs, const char *work, const char *point_seconds)
{
    char scenes[4096];
    tp_result r;
    snprintf(scenes, sizeof scenes, "%s/scenes", LP_SOURCE_DIR);
    mkdir(docs, 0777);
    mkdir(work, 0777);
    const char *args[] = {"--bin", LP_BIN_DIR, "--scenes", scenes, "--docs", docs, "--work",
                          work, "--width", "4", "--height", "3", "--runs", "1", "--scene",
                          SCENE_A, "--scene", SCENE_B, "--max-wavelengths", "128",
                          point_seconds ? "--reuse-references" : "--references-only",
                          point_seconds ? "--point-seconds" : NULL, point_seconds, NULL};
    int rc = ranks == 0 ? tp_run(LP_BIN_DIR "/speed_accuracy", args, NULL, &r)
                        : ml_run(ranks, ML_TIMEOUT_S, LP_BIN_DIR "/speed_accuracy", args, &r);
    CHECK(rc == 0 && r.status == 0, "speed_accuracy on %d processes: status %d: %s", ranks,
          r.status, r.err ? r.err : r.error);
    printf("speed_accuracy on %d processes (0: without the launcher)%s: %.2f s\n", ranks,
           point_seconds ? "" : ", references", r.seconds);
    tp_result_free(&r);
}

/* The reference's CPU seconds per wavelength (the 13th field of its
 * reference.txt), or -1. */
static double seconds_per_wavelength(const char *work, const char *scene)
{
    char path[4096];
    double v[13];
    int i[4];
    snprintf(path, sizeof path, "%s/%s/reference.txt", work, scene);
    FILE *f = fopen(path, "r");
    if (!f)
        return -1.0;
    int n = fscanf(f, "%d %d %d %d %lg %lg %lg %lg %lg %lg %lg %lg %lg", &i[0], &i[1], &i[2],
                   &i[3], &v[4], &v[5], &v[6], &v[7], &v[8], &v[9], &v[10], &v[11], &v[12]);
    fclose(f);
    return n == 13 ? v[12] : -1.0;
}

/* Per scene of the table: its auto points with a note naming the model
 * chosen, and whether it has a point at `wl` wavelengths. */
static void table_counts(const char *csv, const char *scene, int *autos, int *at_wl, int wl)
{
    size_t n;
    char *t = tf_read(csv, &n);
    char want_auto[128], want_wl[128];
    *autos = *at_wl = 0;
    snprintf(want_auto, sizeof want_auto, "%s,auto,auto,", scene);
    snprintf(want_wl, sizeof want_wl, "%s,sweep,polarized,%d,", scene, wl);
    for (char *line = t; line && *line;) {
        char *end = strchr(line, '\n');
        if (end)
            *end = '\0';
        if (strncmp(line, want_auto, strlen(want_auto)) == 0) {
            const char *note = strrchr(line, ',');
            if (note && (strncmp(note + 1, "polarized", 9) == 0 ||
                         strncmp(note + 1, "fresnel", 7) == 0 ||
                         strncmp(note + 1, "schlick", 7) == 0 || strncmp(note + 1, "rgb", 3) == 0))
                (*autos)++;
        }
        if (strncmp(line, want_wl, strlen(want_wl)) == 0)
            (*at_wl)++;
        line = end ? end + 1 : NULL;
    }
    free(t);
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
    char d1[2048], w1[2048], d3[2048], c1[4096], c3[4096];
    snprintf(d1, sizeof d1, "%s/mpi_sweep_docs1", LP_TEST_TMP);
    snprintf(w1, sizeof w1, "%s/mpi_sweep_work1", LP_TEST_TMP);
    snprintf(d3, sizeof d3, "%s/mpi_sweep_docs3", LP_TEST_TMP);
    snprintf(c1, sizeof c1, "%s/speed-accuracy.csv", d1);
    snprintf(c3, sizeof c3, "%s/speed-accuracy.csv", d3);
    remove(c1);
    remove(c3);
    ml_environment();
    sweep(0, d1, w1, NULL);
    /* The cut: 12 x the larger time per wavelength leaves that scene's
     * 4- and 8-wavelength settings in and the rest out: early in the list
     * of points, so that a process listing them otherwise runs the wrong
     * ones from the first polarized setting at 16 wavelengths on. */
    double spw = fmax(seconds_per_wavelength(w1, SCENE_A), seconds_per_wavelength(w1, SCENE_B));
    char ps[64];
    CHECK(spw > 0.0, "the references' times per wavelength were not written");
    snprintf(ps, sizeof ps, "%.9g", 12.0 * spw);
    sweep(0, d1, w1, ps);
    sweep(RANKS, d3, w1, ps);
    for (int k = 0; k < 2; k++) {
        const char *scene = k ? SCENE_B : SCENE_A;
        int dearest = seconds_per_wavelength(w1, scene) == spw;
        for (int t = 0; t < 2; t++) {
            const char *who = t ? "4 processes" : "one process";
            int autos, at8, at16;
            table_counts(t ? c3 : c1, scene, &autos, &at8, 8);
            table_counts(t ? c3 : c1, scene, &autos, &at16, 16);
            CHECK(autos == 3, "%s, %s: %d auto points with their choice, not 3", who, scene,
                  autos);
            /* The cut takes effect where it must, and leaves 8 in. */
            CHECK(at8 > 0, "%s, %s: no point at 8 wavelengths", who, scene);
            CHECK(!dearest || at16 == 0,
                  "%s, %s: %d points at 16 wavelengths, over --point-seconds %s", who, scene,
                  at16, ps);
        }
    }

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
            CHECK(strcmp(x, y) == 0, "line %d differs:\n  one process: %s\n  4 processes: %s",
                  lines + 1, x, y);
            lines++;
            p += pn + (pe ? 1 : 0);
            q += qn + (qe ? 1 : 0);
        }
        CHECK(*p == '\0' && *q == '\0', "the tables differ in length");
        /* The header, and per scene at least its reference, POV-Ray, three
         * auto, 9 rgb, the default and the 38 settings at 4 and 8
         * wavelengths: 107 lines. */
        CHECK(lines >= 107, "only %d lines", lines);
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
