/* args.h -- the command line of lensrender, parsed into plain data
 * (renderer-internal).
 *
 *   lensrender SCENE [-o OUT.png] [--width W] [--height H]
 *              [--mode rgb|schlick|fresnel|polarized|auto] [--depth N]
 *              [--wavelengths N] [--threads N] [--pfm OUT.pfm] [--quiet]
 *              [--cutoff F] [--tolerance E] [--aa N] [-L DIR]...
 *   and POV-Ray's habits: +WW +HH +OOUT.png +A[THRESHOLD] -A +LDIR
 *   lensrender --help | --version
 *
 * Parsing only: nothing here prints, exits, allocates or touches global
 * state.  rs_args_parse returns NULL on success or a one-line message
 * naming the problem, held in the caller's rs_args (rs_args.error), with
 * no "lensrender: " prefix and no newline.  Strings point into argv,
 * except out_png when it is derived from the scene's name (then it points
 * into rs_args.out_default).
 */
#ifndef RS_ARGS_H
#define RS_ARGS_H

#include <stddef.h>

#include "integrator.h"
#include "lensrender/lensrender.h"

#define RS_ARGS_ERROR_MAX 512
#define RS_ARGS_PATH_MAX 4096

/* Limits of the options. */
#define RS_ARGS_SIZE_MAX 16384                     /* --width, --height */
#define RS_ARGS_PIXELS_MAX (64LL * 1024 * 1024)    /* W * H */
#define RS_ARGS_DEPTH_MAX 256                      /* POV-Ray's max_trace_level */
#define RS_ARGS_WAVELENGTHS_MAX 16384
#define RS_ARGS_THREADS_MAX 1024
#define RS_ARGS_AA_MAX 16                          /* --aa: N x N per pixel */
#define RS_ARGS_LIBRARY_MAX 32                     /* -L directories */

typedef struct rs_args {
    int help;             /* --help / -h: print usage; nothing else parsed */
    int version;          /* --version / -V */
    const char *scene;    /* the scene file (required) */
    const char *out_png;  /* -o / --output; default: the scene's base name
                             with its extension replaced by .png, in the
                             current directory */
    const char *pfm;      /* --pfm, or NULL */
    int width, height;    /* 1..16384 each, W*H <= 64 Mi; default 320x240 */
    int mode_auto;        /* --mode auto: the caller picks mode from the
                             scene */
    rs_mode mode;         /* default RS_MODE_POLARIZED */
    int depth;            /* 1..256; 0 = the scene's max_trace_level */
    int wavelengths;      /* 1..16384; default 16 */
    int wavelengths_given;/* --wavelengths was on the command line */
    int threads;          /* 1..1024; 0 = every online processor (default) */
    double cutoff;        /* 0..1; < 0 = the scene's adc_bailout (default) */
    double tolerance;     /* --tolerance E (with --mode auto), > 0; 0 = not
                             given */
    int quiet;            /* --quiet / -q */
    int no_dispersion;    /* --no-dispersion: every glass becomes a constant,
                             lossless index, its index at 587.56 nm (for
                             comparisons with POV-Ray) */
    int aa;               /* --aa N: N x N regular samples per pixel, 1..16
                             (default 1); +A alone: 3; -A: 1 */
    double aa_threshold;  /* +A0.3: read; < 0 when not given (supersampling
                             is regular, the threshold is not used) */
    const char *library[RS_ARGS_LIBRARY_MAX]; /* -L DIR / +LDIR, in order */
    int n_library;
    char out_default[RS_ARGS_PATH_MAX];
    char error[RS_ARGS_ERROR_MAX];
} rs_args;

/* The defaults above (no scene). */
void rs_args_init(rs_args *args);

/* Parse argv[1..argc).  Accepts "--opt VALUE" and "--opt=VALUE" (and
 * "-o VALUE", "-L DIR"), and POV-Ray's "+W640", "+H480", "+Oout.png",
 * "+A", "+A0.3", "-A", "+LDIR" (one argument each); "--" ends the options.  When --help/-h or --version/-V
 * appears, only that flag is set (the first wins) and nothing else is
 * checked or required.  Repeating an option keeps the last value.
 * Returns NULL on success, else args->error. */
const char *rs_args_parse(rs_args *args, int argc, char **argv);

/* The option name of a mode: "polarized", "fresnel", "schlick", "rgb". */
const char *rs_mode_name(rs_mode mode);

/* What the command line asks of the renderer's face, for every program
 * that takes lensrender's command line (lensrender, lensrender-mpi): the
 * load options (the image size, the -L directories, which point into
 * args) and the render options (the mode, auto's tolerance, the size,
 * depth, wavelengths (0 under --mode auto unless --wavelengths was given:
 * auto's choice), cut-off, antialiasing, --no-dispersion, threads). */
void rs_args_face_opts(const rs_args *args, lr_load_opts *lo, lr_render_opts *ro);

/* lensrender's exit status for a face status: 0 for LR_OK; 2 (bad input)
 * for an invalid argument, a file that cannot be read, a scene or camera
 * error; 1 (a render or output failure) for the rest. */
int rs_args_exit_status(lr_status st);

#endif
