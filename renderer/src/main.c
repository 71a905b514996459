/* main.c -- lensrender: render a .scene file to a PNG (and a PFM).
 *
 * Exit status: 0 success; 1 the render or writing the output failed;
 * 2 bad input (command line, scene file, camera).  Every message is one
 * line on stderr starting "lensrender: ".  A thin driver over the
 * renderer's face (lensrender/lensrender.h). */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "args.h"
#include "library_path.h"
#include "scene_messages.h"
#include "lensrender/lensrender.h"
#include "support/cli.h"
#include "support/image.h"
#include "support/tiles.h"

#define EXIT_RENDER 1
#define EXIT_BAD 2
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
"                                   --tolerance at the least cost, and\n"
"                                   more wavelengths for the pixels whose\n"
"                                   spectrum a dispersive lens makes step\n"
"                                   (it says what it chose and why)\n"
"  --tolerance E       with --mode auto: the RMSE of linear RGB allowed\n"
"                      against a converged polarized render, 1e-6..1\n"
"                      (default 1e-3)\n",
"  --depth N           max trace level 1..256 (default: the scene's\n"
"                      global_settings max_trace_level, 5 if none)\n"
"  --wavelengths N     spectral samples per pixel, 1..16384 (default 16)\n"
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

/* One line "lensrender: MESSAGE" on stderr. */
static void say(const char *msg)
{
    sp_say("lensrender", "%s", msg);
}

/* The terminal progress line (nothing when stderr is not a terminal). */
static int show_progress(void *user, long long done, long long total)
{
    rs_progress_line_show(user, done, total, done >= total);
    return 0;
}

/* Everything after the command line; returns the exit status. */
static int run(const rs_args *a)
{
    char msg[MSG_MAX] = "";
    lr_error err;
    lr_load_opts lo;
    lr_render_opts ro;
    lr_scene *scene = NULL;
    lr_renderer *r = NULL;
    rs_image img;
    rs_progress_line line;
    int status = 0;
    lr_status st;
    double t0 = sp_now_seconds();

    memset(&img, 0, sizeof img);
    rs_args_face_opts(a, &lo, &ro);
    st = lr_scene_load(a->scene, &lo, &scene, &err);
    if (!a->quiet)
        rs_print_scene_messages("lensrender", scene);
    if (st != LR_OK) {
        say(err.message);
        status = rs_args_exit_status(st);
        goto done;
    }
    if (a->aa_threshold >= 0.0 && !a->quiet)
        fprintf(stderr, "lensrender: +A%g: every pixel gets %d x %d regular samples (the "
                "threshold is not used)\n", a->aa_threshold, a->aa, a->aa);
    if ((st = lr_renderer_create(scene, &ro, &r, &err)) != LR_OK) {
        say(err.message);
        status = rs_args_exit_status(st);
        goto done;
    }
    if (a->mode_auto && !a->quiet)
        fprintf(stderr, "lensrender: auto: %s\n", lr_renderer_explanation(r));

    if (rs_image_create(&img, a->width, a->height) != 0) {
        say("out of memory for the image");
        status = EXIT_RENDER;
        goto done;
    }
    rs_progress_line_start(&line, a->quiet ? -1 : STDERR_FILENO);
    if ((st = lr_render_image(r, img.rgb, line.fd >= 0 ? show_progress : NULL, &line,
                              &err)) != LR_OK) {
        say(err.message);
        status = EXIT_RENDER;
        goto done;
    }

    /* The PFM first: if it cannot be written, the PNG (the main output)
     * is left as it was.  Each file is written atomically. */
    if (a->pfm) {
        if (rs_pfm_write(a->pfm, &img, msg, sizeof msg) != 0) {
            say(msg);
            status = EXIT_RENDER;
            goto done;
        }
        if (!a->quiet)
            fprintf(stderr, "lensrender: wrote %s\n", a->pfm);
    }
    if (rs_png_write(a->out_png, &img, msg, sizeof msg) != 0) {
        say(msg);
        status = EXIT_RENDER;
        goto done;
    }
    if (!a->quiet)
        fprintf(stderr,
                "lensrender: wrote %s (%d x %d, %s) in %.2f s\n", a->out_png, a->width,
                a->height, lr_renderer_description(r), sp_now_seconds() - t0);

done:
    rs_image_free(&img);
    lr_renderer_free(r);
    lr_scene_free(scene);
    return status;
}

int main(int argc, char **argv)
{
    rs_args *a = malloc(sizeof *a);
    int status;
    if (!a) {
        say("out of memory");
        return EXIT_RENDER;
    }
    rs_args_init(a);
    if (rs_args_parse(a, argc, argv)) {
        say(a->error);
        free(a);
        return EXIT_BAD;
    }
    if (a->help || a->version) {
        int rc = a->help ? sp_print_text(usage_text, sizeof usage_text / sizeof *usage_text)
                         : sp_print_version("lensrender", lp_version_string());
        free(a);
        return rc == 0 ? 0 : EXIT_RENDER;
    }
    status = run(a);
    free(a);
    return status;
}
