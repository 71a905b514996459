/* main.c -- lensrender-mpi: lensrender across the processes of an MPI run.
 *
 *   mpirun -n N lensrender-mpi SCENE [lensrender's options]
 *
 * Every process reads the scene and prepares the renderer (each its own
 * copy: nothing of the scene travels); the image's square regions
 * (regions.h) are shared out with dynamic scheduling (lpmpi/schedule.h),
 * each rendered with the process's threads (the face's
 * lr_render_region); rank 0 gathers them, shows the progress and writes
 * the PFM and the PNG atomically (support/image.h).  The face makes each
 * pixel a function of the scene, the options and the pixel alone, so the
 * files are byte for byte lensrender's for any number of processes and
 * threads.
 *
 * --threads 0 (the default) gives each process the cores of its machine
 * divided by the processes on that machine.
 *
 * Exit status as lensrender's (0; 1 a render or output failure; 2 bad
 * input), the same on every process.  A failure on any process gives one
 * line on stderr, printed by rank 0: "lensrender-mpi: MESSAGE", with
 * "rank K: " before a message that only rank K saw.
 *
 * For the tests, LENSRENDER_MPI_FAULT="K:fail" makes rank K's first region
 * fail (status 1, "rank K: injected failure"), "K:die" kills rank K
 * (SIGKILL) at its first region. */
#define _POSIX_C_SOURCE 200809L

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "args.h"
#include "lensrender/lensrender.h"
#include "lpmpi/group.h"
#include "lpmpi/schedule.h"
#include "regions.h"
#include "scene_messages.h"
#include "support/cli.h"
#include "support/image.h"
#include "support/tiles.h"

#define PROGRAM "lensrender-mpi"
#define EXIT_RENDER 1
#define EXIT_BAD 2
#define MSG_MAX 1024

static const char usage_text[] =
"usage: mpirun -n N lensrender-mpi SCENE [lensrender's options]\n"
"       lensrender-mpi --help | --version\n"
"\n"
"Renders SCENE as lensrender does (the same options: lensrender --help),\n"
"its image shared among the N processes of an MPI run in square regions,\n"
"dynamically: a process that finishes early takes more.  Rank 0 gathers\n"
"the regions, shows the progress and writes the PNG (and --pfm) atomically;\n"
"the files are byte for byte lensrender's, for any N and any --threads.\n"
"--threads 0 (the default): the cores of each machine divided among the\n"
"processes on it.  Started without mpirun, it is a run of one process.\n"
"\n"
"Exit status: 0 success, 1 render or output failure, 2 bad input; one\n"
"message, from rank 0, for a failure on any process.\n";

typedef enum fault { FAULT_NONE, FAULT_FAIL, FAULT_DIE } fault;

typedef struct ctx {
    const lr_renderer *renderer;
    lm_regions regions;
    int rank, size, regions_run;
    fault fault;
    rs_image img;             /* rank 0: the image */
    rs_progress_line line;    /* rank 0 */
    long long pixels_done;    /* rank 0 */
} ctx;

/* LENSRENDER_MPI_FAULT for this rank. */
static fault fault_of(int rank)
{
    const char *f = getenv("LENSRENDER_MPI_FAULT");
    char *end;
    long k;
    if (!f)
        return FAULT_NONE;
    k = strtol(f, &end, 10);
    if (end == f || *end != ':' || k != rank)
        return FAULT_NONE;
    return strcmp(end + 1, "die") == 0 ? FAULT_DIE
           : strcmp(end + 1, "fail") == 0 ? FAULT_FAIL
                                          : FAULT_NONE;
}

/* A message this rank alone may have seen. */
static void own_message(const ctx *c, char *msg, size_t msg_size, const char *text)
{
    if (c->size > 1)
        snprintf(msg, msg_size, "rank %d: %s", c->rank, text);
    else
        snprintf(msg, msg_size, "%s", text);
}

static int run_region(void *user, long k, void *result, size_t *used, char *msg,
                      size_t msg_size)
{
    ctx *c = user;
    int x0, y0, x1, y1;
    lr_error err;
    if (c->regions_run++ == 0 && c->fault != FAULT_NONE) {
        if (c->fault == FAULT_DIE)
            raise(SIGKILL);
        own_message(c, msg, msg_size, "injected failure");
        return EXIT_RENDER;
    }
    lm_region_rect(&c->regions, k, &x0, &y0, &x1, &y1);
    if (lr_render_region(c->renderer, x0, y0, x1, y1, result, NULL, NULL, &err) != LR_OK) {
        own_message(c, msg, msg_size, err.message);
        return EXIT_RENDER;
    }
    *used = (size_t)(x1 - x0) * (size_t)(y1 - y0) * 3 * sizeof(float);
    return 0;
}

/* Rank 0: region k into the image (called one at a time). */
static void region_done(void *user, long k, const void *result, size_t size)
{
    ctx *c = user;
    int x0, y0, x1, y1;
    const float *src = result;
    size_t row;
    lm_region_rect(&c->regions, k, &x0, &y0, &x1, &y1);
    row = (size_t)(x1 - x0) * 3;
    if (size < row * (size_t)(y1 - y0) * sizeof(float))
        return; /* cannot happen: the scheduler passes what run_region made */
    for (int j = y0; j < y1; j++)
        memcpy(c->img.rgb + 3 * ((size_t)j * (size_t)c->img.width + (size_t)x0),
               src + row * (size_t)(j - y0), row * sizeof(float));
    c->pixels_done += (long long)(x1 - x0) * (y1 - y0);
    rs_progress_line_show(&c->line, c->pixels_done,
                          (long long)c->img.width * c->img.height,
                          c->pixels_done >= (long long)c->img.width * c->img.height);
}

/* Agree on a step's status; rank 0 prints the failure's message, with
 * the rank that saw it when that is not rank 0 (a message every rank
 * saw comes from rank 0). */
static int agree(mw_group *g, int status, char *msg)
{
    int who = 0;
    status = mw_agree(g, status, &who, msg, MSG_MAX);
    if (status != 0 && mw_group_rank(g) == 0) {
        if (who != 0)
            sp_say(PROGRAM, "rank %d: %s", who, msg);
        else
            sp_say(PROGRAM, "%s", msg);
    }
    return status;
}

/* Read, prepare, render, write; returns the exit status (the same on
 * every process). */
static int render(mw_group *g, const rs_args *a, ctx *c)
{
    char msg[MSG_MAX] = "";
    lr_error err;
    lr_load_opts lo;
    lr_render_opts ro;
    lr_scene *scene = NULL;
    lr_renderer *r = NULL;
    mw_job job;
    int status = 0, lead = c->rank == 0;
    double t0 = sp_now_seconds();

    rs_args_face_opts(a, &lo, &ro);
    if (ro.threads == 0) {
        ro.threads = rs_online_processors() / mw_group_local_size(g);
        if (ro.threads < 1)
            ro.threads = 1;
    }
    lr_status st = lr_scene_load(a->scene, &lo, &scene, &err);
    if (st == LR_OK)
        st = lr_renderer_create(scene, &ro, &r, &err);
    if (st != LR_OK) {
        snprintf(msg, sizeof msg, "%s", err.message);
        status = rs_args_exit_status(st);
    } else if (lead && rs_image_create(&c->img, a->width, a->height) != 0) {
        snprintf(msg, sizeof msg, "out of memory for the image");
        status = EXIT_RENDER;
    }
    if (lead && scene && !a->quiet)
        rs_print_scene_messages(PROGRAM, scene);
    if ((status = agree(g, status, msg)) != 0)
        goto done;
    if (lead && a->mode_auto && !a->quiet)
        sp_say(PROGRAM, "auto: %s", lr_renderer_explanation(r));

    c->renderer = r;
    lm_regions_init(&c->regions, a->width, a->height, c->size, ro.threads);
    rs_progress_line_start(&c->line, lead && !a->quiet ? STDERR_FILENO : -1);
    memset(&job, 0, sizeof job);
    job.n_items = lm_regions_count(&c->regions);
    job.result_size = (size_t)c->regions.side * (size_t)c->regions.side * 3 * sizeof(float);
    job.run = run_region;
    job.done = region_done;
    job.user = c;
    status = mw_run(g, &job, msg, sizeof msg);
    if (status != 0) {
        if (lead)
            sp_say(PROGRAM, "%s", msg);
        if (status < 0)
            status = EXIT_RENDER;
        goto done;
    }

    /* Rank 0 writes, the PFM first: if it cannot be written, the PNG (the
     * main output) is left as it was. */
    if (lead && a->pfm && rs_pfm_write(a->pfm, &c->img, msg, sizeof msg) != 0)
        status = EXIT_RENDER;
    if (lead && status == 0 && rs_png_write(a->out_png, &c->img, msg, sizeof msg) != 0)
        status = EXIT_RENDER;
    if ((status = agree(g, status, msg)) != 0)
        goto done;
    if (lead && !a->quiet)
        sp_say(PROGRAM, "wrote %s%s%s (%d x %d, %s) in %.2f s on %d process%s x %d thread%s",
               a->out_png, a->pfm ? " and " : "", a->pfm ? a->pfm : "", a->width, a->height,
               lr_renderer_description(r), sp_now_seconds() - t0, c->size,
               c->size == 1 ? "" : "es", ro.threads, ro.threads == 1 ? "" : "s");
done:
    lr_renderer_free(r);
    lr_scene_free(scene);
    return status;
}

int main(int argc, char **argv)
{
    char msg[MSG_MAX] = "";
    mw_group *g;
    rs_args *a;
    ctx c;
    int status = 0;

    if (mw_group_start(&argc, &argv, &g, msg, sizeof msg) != 0) {
        sp_say(PROGRAM, "%s", msg);
        return EXIT_RENDER;
    }
    memset(&c, 0, sizeof c);
    c.rank = mw_group_rank(g);
    c.size = mw_group_size(g);
    c.fault = fault_of(c.rank);
    a = malloc(sizeof *a);
    if (!a) {
        snprintf(msg, sizeof msg, "out of memory");
        status = EXIT_RENDER;
    } else {
        rs_args_init(a);
        if (rs_args_parse(a, argc, argv)) {
            snprintf(msg, sizeof msg, "%s", a->error);
            status = EXIT_BAD;
        }
    }
    status = agree(g, status, msg);
    if (status == 0 && (a->help || a->version)) {
        if (c.rank == 0) {
            if (a->help)
                fputs(usage_text, stdout);
            else
                printf("lensrender-mpi (lensprim) %d.%d.%d\n", LP_VERSION_MAJOR,
                       LP_VERSION_MINOR, LP_VERSION_PATCH);
            status = fflush(stdout) == 0 ? 0 : EXIT_RENDER;
            snprintf(msg, sizeof msg, "cannot write to standard output");
        }
        status = agree(g, status, msg);
    } else if (status == 0) {
        status = render(g, a, &c);
    }
    rs_image_free(&c.img);
    free(a);
    mw_group_end(g);
    return status;
}
