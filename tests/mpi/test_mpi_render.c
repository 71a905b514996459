/* test_mpi_render.c -- lensrender-mpi under the MPI launcher.
 *
 * Byte for byte: the PNG and the PFM of 2 and 3 processes (3 on a 2-core
 * machine: more processes than cores), with 1 and 2 threads each, are
 * the files of the one-process lensrender, for two scenes (a lens over a
 * checkerboard; crossed polarizers with a crystal, polarized light); the
 * image, 56 x 40, has partial tiles at its right and bottom edges.
 *
 * Failures, each ending every process within FAIL_BOUND_S with a
 * non-zero status, one "lensrender-mpi:" line and no output file: a
 * region failing on one rank (LENSRENDER_MPI_FAULT), a rank killed at
 * its first region, a scene that only rank 1 cannot read (rank 0 and
 * rank 1 given different files: MPMD), a scene error every rank sees
 * (one message, not one per rank), a bad option, an output that cannot
 * be written. */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "mpi_launch.h"
#include "test_files.h"

#define MPI_PROGRAM LP_BIN_DIR "/lensrender-mpi"
#define W "56"
#define H "40"

/* A failed run must end everything: its time bound.  The launcher is
 * stopped there: a hang shows as status 124; measured: 1-3 s on a loaded
 * 2-core machine. */
#define FAIL_BOUND_S 60.0

static const char *const SCENES[] = {"default", "crossed_polarizers"};

static void path_of(char *buf, size_t n, const char *name, const char *what)
{
    snprintf(buf, n, "%s/mpi_render_%s.%s", LP_TEST_TMP, name, what);
}

static void reference(const char *scene, const char *png, const char *pfm)
{
    char path[4096];
    tp_result r;
    snprintf(path, sizeof path, "%s/scenes/%s.scene", LP_SOURCE_DIR, scene);
    const char *args[] = {path, "--width", W, "--height", H, "--threads", "1", "-o", png,
                          "--pfm", pfm, "--quiet", NULL};
    CHECK(tp_run(LP_BIN_DIR "/lensrender", args, NULL, &r) == 0 && r.status == 0,
          "lensrender %s: status %d: %s", scene, r.status, r.err ? r.err : r.error);
    tp_result_free(&r);
}

static void same_bytes(const char *scene, int ranks, const char *threads)
{
    char path[4096], png[4096], pfm[4096], ref_png[4096], ref_pfm[4096];
    tp_result r;
    snprintf(path, sizeof path, "%s/scenes/%s.scene", LP_SOURCE_DIR, scene);
    path_of(ref_png, sizeof ref_png, scene, "ref.png");
    path_of(ref_pfm, sizeof ref_pfm, scene, "ref.pfm");
    path_of(png, sizeof png, scene, "mpi.png");
    path_of(pfm, sizeof pfm, scene, "mpi.pfm");
    unlink(png);
    unlink(pfm);
    const char *args[] = {path, "--width", W, "--height", H, "--threads", threads, "-o", png,
                          "--pfm", pfm, "--quiet", NULL};
    if (ml_run(ranks, ML_TIMEOUT_S, MPI_PROGRAM, args, &r) != 0) {
        CHECK(0, "could not run the launcher: %s", r.error);
        return;
    }
    CHECK(r.status == 0, "%s, %d ranks x %s threads: status %d: %s", scene, ranks, threads,
          r.status, r.err);
    CHECK(ml_same_file(png, ref_png), "%s, %d ranks x %s threads: the PNG differs from lensrender's",
          scene, ranks, threads);
    CHECK(ml_same_file(pfm, ref_pfm), "%s, %d ranks x %s threads: the PFM differs from lensrender's",
          scene, ranks, threads);
    printf("%s, %d ranks x %s threads: %.2f s, PNG and PFM the same bytes\n", scene, ranks,
           threads, r.seconds);
    tp_result_free(&r);
}

/* A run that must fail: status (0: any non-zero), one message containing
 * want, no PNG, within the bound. */
static void fails(const char *what, int ranks, const char *const args[], int status,
                  const char *want, const char *png)
{
    tp_result r;
    unlink(png);
    if (ml_run(ranks, (int)FAIL_BOUND_S, MPI_PROGRAM, args, &r) != 0) {
        CHECK(0, "could not run the launcher: %s", r.error);
        return;
    }
    /* 124: timeout(1) ended a run that hung. */
    CHECK(r.status != 0 && r.status != 124, "%s: status %d (124: it hung)", what, r.status);
    if (status)
        CHECK(r.status == status, "%s: status %d, not %d: %s", what, r.status, status, r.err);
    CHECK(r.seconds < FAIL_BOUND_S, "%s: %.1f s to end", what, r.seconds);
    if (want)
        CHECK(ml_count_lines(r.err, "lensrender-mpi:") == 1 && strstr(r.err, want) != NULL,
              "%s: not one message with '%s': %s", what, want, r.err);
    CHECK(access(png, F_OK) != 0, "%s: the PNG was written", what);
    printf("%s: status %d in %.2f s: %s", what, r.status, r.seconds, r.err);
    tp_result_free(&r);
}

int main(void)
{
    char scene[4096], png[4096], bad[4096], missing[4096];
    for (size_t s = 0; s < sizeof SCENES / sizeof *SCENES; s++) {
        char ref_png[4096], ref_pfm[4096];
        path_of(ref_png, sizeof ref_png, SCENES[s], "ref.png");
        path_of(ref_pfm, sizeof ref_pfm, SCENES[s], "ref.pfm");
        reference(SCENES[s], ref_png, ref_pfm);
        same_bytes(SCENES[s], 2, "1");
        same_bytes(SCENES[s], 3, "1");
        same_bytes(SCENES[s], 2, "2");
        same_bytes(SCENES[s], 3, "2");
    }
    same_bytes("default", 1, "2");

    snprintf(scene, sizeof scene, "%s/scenes/default.scene", LP_SOURCE_DIR);
    path_of(png, sizeof png, "fail", "png");
    {
        const char *args[] = {scene, "--width", W, "--height", H, "--threads", "1", "-o", png,
                              "--quiet", NULL};
        setenv("LENSRENDER_MPI_FAULT", "1:fail", 1);
        fails("a region failing on rank 1 of 2", 2, args, 1, "rank 1: injected failure", png);
        setenv("LENSRENDER_MPI_FAULT", "0:fail", 1);
        fails("a region failing on rank 0 of 3", 3, args, 1, "rank 0: injected failure", png);
        setenv("LENSRENDER_MPI_FAULT", "2:die", 1);
        fails("rank 2 of 3 killed", 3, args, 0, NULL, png);
        unsetenv("LENSRENDER_MPI_FAULT");
    }
    {
        /* MPMD: rank 0 reads the scene, rank 1 a file that is not there. */
        snprintf(missing, sizeof missing, "%s/mpi_render_missing.scene", LP_TEST_TMP);
        unlink(missing);
        const char *args[] = {scene, "--width", W, "--height", H, "-o", png, "--quiet", ":",
                              LP_MPIEXEC_NUMPROC_FLAG, "1", MPI_PROGRAM, missing, "--width", W,
                              "--height", H, "-o", png, "--quiet", NULL};
        fails("a scene only rank 1 cannot read", 1, args, 2, "rank 1: ", png);
    }
    {
        snprintf(bad, sizeof bad, "%s/mpi_render_bad.scene", LP_TEST_TMP);
        static const char text[] = "camera { location <0, 0, -5> look_at <0, 0, 0> }\n"
                                   "sphere { <0, 0, 0> 1 pigment { colour rgb <1, 1, 1> }\n";
        CHECK(tf_write(bad, text, sizeof text - 1) == 0, "cannot write %s", bad);
        const char *args[] = {bad, "--width", W, "--height", H, "-o", png, NULL};
        fails("a scene error every rank sees", 3, args, 2, "mpi_render_bad.scene:", png);
    }
    {
        const char *args[] = {scene, "--width", "0", "-o", png, NULL};
        fails("a bad option", 3, args, 2, "--width", png);
    }
    {
        char out[4096];
        snprintf(out, sizeof out, "%s/no/such/dir/x.png", LP_TEST_TMP);
        const char *args[] = {scene, "--width", W, "--height", H, "-o", out, "--quiet", NULL};
        fails("an output that cannot be written", 2, args, 1, "x.png", out);
    }
    return check_finish("test_mpi_render");
}
