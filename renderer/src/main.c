/* main.c -- lensrender: render a .scene file to a PNG (and a PFM).
 *
 * Exit status: 0 success; 1 the render or writing the output failed;
 * 2 bad input (command line, scene file, camera).  Every message is one
 * line on stderr starting "lensrender: ". */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "args.h"
#include "auto_settings.h"
#include "camera.h"
#include "support/cli.h"
#include "support/image.h"
#include "integrator.h"
#include "library_path.h"
#include "parser.h"
#include "scene.h"
#include "support/tiles.h"

#define EXIT_RENDER 1
#define EXIT_BAD 2
#define TILE_SIZE 16
#define MSG_MAX 1024

static const char *const usage_text[] = {
"usage: lensrender SCENE [-o OUT.png] [--width W] [--height H]\n"
"                  [--mode rgb|schlick|fresnel|polarized|auto] [--depth N]\n"
"                  [--wavelengths N] [--threads N] [--pfm OUT.pfm] [--quiet]\n"
"                  [--cutoff F] [--tolerance E] [--aa N] [-L DIR]...\n"
"       lensrender SCENE +W640 +H480 +Oout.png [+A[THRESHOLD] | -A] [+LDIR]\n"
"       lensrender --help | --version\n"
"\n",
"Renders SCENE, a POV-Ray-style .scene file with lenses, to an 8-bit sRGB\n"
"PNG.  The image is the same whatever --threads is.  Lengths are in\n"
"millimetres; wavelengths (a light's spectrum { line NM }, the glass\n"
"data, the CIE tables) are in nanometres in standard air, as glass\n"
"catalogs and line tables give them.\n"
"\n"
"  -o, --output FILE   the PNG to write (default: the scene's name with\n"
"                      .png, in the current directory)\n"
"  --width W           image width in pixels, 1..16384 (default 320)\n"
"  --height H          image height in pixels, 1..16384 (default 240);\n"
"                      W x H at most 64 Mi pixels\n",
"  --mode MODE         light model (default polarized):\n"
"                        polarized  spectral, polarization tracked through\n"
"                                   every interface, coherent sources add\n"
"                                   as amplitudes\n"
"                        fresnel    spectral, unpolarized Fresnel per\n"
"                                   interface (POV-Ray's model)\n"
"                        schlick    spectral, Schlick's approximation\n"
"                        rgb        three colour channels, unpolarized\n"
"                        auto       the model, wavelengths, depth and\n"
"                                   cut-off that keep the error within\n"
"                                   --tolerance at the least cost (it says\n"
"                                   what it chose and why)\n"
"  --tolerance E       with --mode auto: the RMSE of linear RGB allowed\n"
"                      against a converged polarized render, 1e-6..1\n"
"                      (default 1e-3)\n",
"  --depth N           max trace level 1..256 (default: the scene's\n"
"                      global_settings max_trace_level, 5 if none)\n"
"  --wavelengths N     spectral samples per pixel, 1..1024 (default 16)\n"
"  --cutoff F          drop branches whose weight is below F, 0..1\n"
"                      (default: the scene's adc_bailout, 1/255 if none)\n"
"  --threads N         worker threads, 1..1024 (default 0: every core)\n"
"  --pfm FILE          also write linear float RGB (Portable FloatMap)\n"
"  --aa N              antialiasing: N x N regular samples per pixel,\n"
"                      1..16 (default 1; +A: 3, -A: 1; a +A threshold is\n"
"                      read, every pixel is supersampled)\n"
"  -L, --library DIR   look for #include files in DIR (after the\n"
"                      including file's directory; repeatable), then in\n"
"                      " RS_POVRAY_INCLUDE_DIR " and the\n"
"                      project's share directory when they exist\n"
"  -q, --quiet         print nothing but errors\n"
"  --no-dispersion     every glass becomes a constant lossless index, its\n"
"                      index at 587.56 nm in air, the d line (to compare\n"
"                      with POV-Ray)\n"
"  -h, --help          this text\n"
"  -V, --version       the version\n"
"\n"
"Exit status: 0 success, 1 render or output failure, 2 bad input.\n",
};

/* One line "lensrender: [PREFIX: ]MESSAGE" on stderr. */
static void say(const char *prefix, const char *msg)
{
    if (prefix)
        sp_say("lensrender", "%s: %s", prefix, msg);
    else
        sp_say("lensrender", "%s", msg);
}

/* ---- the render: tiles of pixels into an rs_image ---------------------- */

typedef struct render_ctx {
    const rs_integrator *it;
    rs_image *img;
} render_ctx;

static void *worker_make(void *user)
{
    const render_ctx *c = user;
    return rs_worker_create(c->it);
}

static void worker_free(void *worker)
{
    rs_worker_destroy(worker);
}

static void render_tile(void *user, void *worker, int x0, int y0, int x1,
                        int y1)
{
    const render_ctx *c = user;
    for (int j = y0; j < y1; j++)
        for (int i = x0; i < x1; i++) {
            rs_color col;
            float *px = c->img->rgb + 3 * ((size_t)j * (size_t)c->img->width +
                                           (size_t)i);
            rs_integrator_pixel(c->it, worker, i, j, &col);
            px[0] = (float)col.r;
            px[1] = (float)col.g;
            px[2] = (float)col.b;
        }
}

/* The reader's warnings and #debug text, on stderr. */
static void print_messages(const rs_scene *s, int quiet)
{
    if (quiet)
        return;
    for (size_t i = 0; i < s->n_messages; i++) {
        if (s->messages[i].kind == RS_MSG_DEBUG)
            fputs(s->messages[i].text, stderr);
        else
            fprintf(stderr, "lensrender: %s\n", s->messages[i].text);
    }
}

/* Everything after the command line; returns the exit status. */
static int run(const rs_args *a)
{
    char msg[MSG_MAX] = "";
    rs_scene scene;
    rs_parse_opts popts;
    const char *dirs[RS_ARGS_LIBRARY_MAX + 4];
    rs_view view;
    rs_render_opts ropts;
    rs_integrator *it = NULL;
    rs_image img;
    render_ctx ctx;
    rs_mode mode = a->mode;
    int depth, status = 0;
    double t0 = sp_now_seconds();

    memset(&img, 0, sizeof img);
    rs_scene_init(&scene);
    rs_parse_opts_init(&popts);
    popts.image_width = a->width;
    popts.image_height = a->height;
    popts.include_dirs = dirs;
    popts.n_include_dirs = rs_library_path(a->library, (size_t)a->n_library, dirs,
                                           sizeof dirs / sizeof dirs[0]);
    if (rs_parse_file(a->scene, &popts, &scene, msg, sizeof msg) != 0) {
        print_messages(&scene, a->quiet);
        say(NULL, msg);
        status = EXIT_BAD;
        goto done;
    }
    print_messages(&scene, a->quiet);
    if (a->aa_threshold >= 0.0 && !a->quiet)
        fprintf(stderr, "lensrender: +A%g: every pixel gets %d x %d regular samples (the "
                "threshold is not used)\n", a->aa_threshold, a->aa, a->aa);
    if (rs_scene_prepare(&scene, msg, sizeof msg) != 0) {
        say(NULL, msg);
        status = EXIT_BAD;
        goto done;
    }
    if (a->no_dispersion &&
        rs_scene_freeze_glass(&scene, RS_LAMBDA_D_LINE, msg, sizeof msg) != 0) {
        say(NULL, msg);
        status = EXIT_BAD;
        goto done;
    }
    if (rs_camera_setup(&scene.camera, a->width, a->height, &view, msg,
                        sizeof msg) != 0) {
        say(a->scene, msg);
        status = EXIT_BAD;
        goto done;
    }
    rs_render_opts_init(&ropts);
    ropts.mode = mode;
    ropts.depth = a->depth;
    ropts.wavelengths = a->wavelengths;
    ropts.cutoff = a->cutoff;
    ropts.width = a->width;
    ropts.height = a->height;
    ropts.aa = a->aa;
    if (a->mode_auto) {
        char why[512];
        rs_auto_request req = {a->tolerance > 0.0 ? a->tolerance : RS_AUTO_TOLERANCE_DEFAULT,
                               a->width, a->height, a->depth,
                               a->wavelengths_given ? a->wavelengths : 0, a->cutoff};
        if (rs_auto_choose(&scene, &req, &ropts, why, sizeof why, msg, sizeof msg) != 0) {
            say(a->scene, msg);
            status = EXIT_RENDER;
            goto done;
        }
        mode = ropts.mode;
        if (!a->quiet)
            fprintf(stderr, "lensrender: auto: %s\n", why);
    }
    ropts.aa = a->aa; /* antialiasing is the user's, whatever auto chose */
    depth = ropts.depth > 0 ? ropts.depth : scene.settings.max_trace_level;
    if (rs_integrator_create(&scene, &ropts, &it, msg, sizeof msg) != 0) {
        say(a->scene, msg);
        status = EXIT_RENDER;
        goto done;
    }

    if (rs_image_create(&img, a->width, a->height) != 0) {
        say(NULL, "out of memory for the image");
        status = EXIT_RENDER;
        goto done;
    }
    ctx.it = it;
    ctx.img = &img;
    if (rs_render_tiles(a->width, a->height, TILE_SIZE, a->threads,
                        worker_make, worker_free, render_tile, &ctx,
                        a->quiet ? -1 : STDERR_FILENO) != 0) {
        say(NULL, "the render failed (out of memory for a worker thread)");
        status = EXIT_RENDER;
        goto done;
    }

    /* The PFM first: if it cannot be written, the PNG (the main output)
     * is left as it was.  Each file is written atomically. */
    if (a->pfm) {
        if (rs_pfm_write(a->pfm, &img, msg, sizeof msg) != 0) {
            say(NULL, msg);
            status = EXIT_RENDER;
            goto done;
        }
        if (!a->quiet)
            fprintf(stderr, "lensrender: wrote %s\n", a->pfm);
    }
    if (rs_png_write(a->out_png, &img, msg, sizeof msg) != 0) {
        say(NULL, msg);
        status = EXIT_RENDER;
        goto done;
    }
    if (!a->quiet)
        fprintf(stderr,
                "lensrender: wrote %s (%d x %d, %s, %d wavelengths, depth %d) "
                "in %.2f s\n",
                a->out_png, a->width, a->height, rs_mode_name(mode),
                ropts.wavelengths, depth, sp_now_seconds() - t0);

done:
    rs_image_free(&img);
    rs_integrator_destroy(it);
    rs_scene_free(&scene);
    return status;
}

int main(int argc, char **argv)
{
    rs_args *a = malloc(sizeof *a);
    int status;
    if (!a) {
        say(NULL, "out of memory");
        return EXIT_RENDER;
    }
    rs_args_init(a);
    if (rs_args_parse(a, argc, argv)) {
        say(NULL, a->error);
        free(a);
        return EXIT_BAD;
    }
    if (a->help) {
        for (size_t i = 0; i < sizeof usage_text / sizeof *usage_text; i++)
            fputs(usage_text[i], stdout);
        free(a);
        return fflush(stdout) == 0 ? 0 : EXIT_RENDER;
    }
    if (a->version) {
        printf("lensrender (lensprim) %d.%d.%d\n", LP_VERSION_MAJOR,
               LP_VERSION_MINOR, LP_VERSION_PATCH);
        free(a);
        return fflush(stdout) == 0 ? 0 : EXIT_RENDER;
    }
    status = run(a);
    free(a);
    return status;
}
