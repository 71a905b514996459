/* args.c -- parsing of lensrender's options.  No printing, no allocation,
 * no global mutable state: every message goes into the caller's
 * rs_args.error. */
#include "args.h"

#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/cli.h"

/* The parse's error: the message in args->error, returned. */
#define fail(args, ...) sp_format((args)->error, sizeof (args)->error, __VA_ARGS__)

void rs_args_init(rs_args *args)
{
    memset(args, 0, sizeof *args);
    args->width = 320;
    args->height = 240;
    args->mode = RS_MODE_POLARIZED;
    args->mode_auto = 0;
    args->depth = 0;
    args->wavelengths = 16;
    args->threads = 0;
    args->cutoff = -1.0;
    args->aa = 1;
    args->aa_threshold = -1.0;
}

const char *rs_mode_name(rs_mode mode)
{
    switch (mode) {
    case RS_MODE_POLARIZED: return "polarized";
    case RS_MODE_FRESNEL: return "fresnel";
    case RS_MODE_SCHLICK: return "schlick";
    case RS_MODE_RGB: return "rgb";
    }
    return "unknown";
}

/* A whole string as a finite double.  1: ok; 0: not a finite number. */
static int parse_double(const char *s, double *out)
{
    double v;
    if (sp_parse_double(s, &v) != 1 || !isfinite(v))
        return 0;
    *out = v;
    return 1;
}

static const char *int_option(rs_args *args, const char *name, const char *val,
                              long lo, long hi, int *out)
{
    long v;
    int r = sp_parse_long(val, lo, hi, &v);
    if (r == 0)
        return fail(args, "%s: '%s' is not a whole number", name, val);
    if (r < 0)
        return fail(args, "%s: %s is out of range (%ld..%ld)", name, val, lo, hi);
    *out = (int)v;
    return NULL;
}

/* The options that take a value. */
enum {
    OPT_OUT, OPT_WIDTH, OPT_HEIGHT, OPT_MODE, OPT_DEPTH, OPT_WAVELENGTHS,
    OPT_THREADS, OPT_PFM, OPT_CUTOFF, OPT_AA, OPT_LIBRARY, OPT_TOLERANCE, OPT_COUNT
};

static const struct {
    const char *name;
    int id;
} value_options[] = {
    { "-o", OPT_OUT },
    { "--output", OPT_OUT },
    { "--width", OPT_WIDTH },
    { "--height", OPT_HEIGHT },
    { "--mode", OPT_MODE },
    { "--depth", OPT_DEPTH },
    { "--wavelengths", OPT_WAVELENGTHS },
    { "--threads", OPT_THREADS },
    { "--pfm", OPT_PFM },
    { "--cutoff", OPT_CUTOFF },
    { "--aa", OPT_AA },
    { "--library", OPT_LIBRARY },
    { "-L", OPT_LIBRARY },
    { "--tolerance", OPT_TOLERANCE },
};

static const char *set_value(rs_args *args, int id, const char *name,
                             const char *val)
{
    switch (id) {
    case OPT_OUT:
    case OPT_PFM:
        if (*val == '\0')
            return fail(args, "%s: empty file name", name);
        if (id == OPT_OUT)
            args->out_png = val;
        else
            args->pfm = val;
        return NULL;
    case OPT_WIDTH:
        return int_option(args, name, val, 1, RS_ARGS_SIZE_MAX, &args->width);
    case OPT_HEIGHT:
        return int_option(args, name, val, 1, RS_ARGS_SIZE_MAX, &args->height);
    case OPT_DEPTH:
        return int_option(args, name, val, 1, RS_ARGS_DEPTH_MAX, &args->depth);
    case OPT_WAVELENGTHS:
        args->wavelengths_given = 1;
        return int_option(args, name, val, 1, RS_ARGS_WAVELENGTHS_MAX,
                          &args->wavelengths);
    case OPT_THREADS:
        return int_option(args, name, val, 0, RS_ARGS_THREADS_MAX,
                          &args->threads);
    case OPT_MODE:
        args->mode_auto = 0;
        if (strcmp(val, "polarized") == 0)
            args->mode = RS_MODE_POLARIZED;
        else if (strcmp(val, "fresnel") == 0)
            args->mode = RS_MODE_FRESNEL;
        else if (strcmp(val, "schlick") == 0)
            args->mode = RS_MODE_SCHLICK;
        else if (strcmp(val, "rgb") == 0)
            args->mode = RS_MODE_RGB;
        else if (strcmp(val, "auto") == 0)
            args->mode_auto = 1;
        else
            return fail(args, "%s: unknown mode '%s' (rgb, schlick, fresnel, "
                        "polarized or auto)", name, val);
        return NULL;
    case OPT_AA:
        return int_option(args, name, val, 1, RS_ARGS_AA_MAX, &args->aa);
    case OPT_LIBRARY:
        if (*val == '\0')
            return fail(args, "%s: empty directory name", name);
        if (args->n_library == RS_ARGS_LIBRARY_MAX)
            return fail(args, "%s: at most %d library directories", name,
                        RS_ARGS_LIBRARY_MAX);
        args->library[args->n_library++] = val;
        return NULL;
    case OPT_CUTOFF: {
        double v;
        if (!parse_double(val, &v))
            return fail(args, "%s: '%s' is not a finite number", name, val);
        if (v < 0.0 || v > 1.0)
            return fail(args, "%s: %s is out of range (0..1)", name, val);
        args->cutoff = v;
        return NULL;
    }
    case OPT_TOLERANCE: {
        double v;
        if (!parse_double(val, &v))
            return fail(args, "%s: '%s' is not a finite number", name, val);
        if (!(v >= 1e-6 && v <= 1.0))
            return fail(args, "%s: %s is out of range (1e-6..1)", name, val);
        args->tolerance = v;
        return NULL;
    }
    default:
        return fail(args, "%s: internal error", name);
    }
}

/* The default output: the scene's base name, its last extension (if any,
 * and not a leading dot) replaced by .png. */
static const char *derive_output(rs_args *args)
{
    const char *base = args->scene, *dot = NULL;
    size_t n;
    for (const char *p = args->scene; *p; p++)
        if (*p == '/')
            base = p + 1;
    if (*base == '\0')
        return fail(args, "%s: the scene is not a file name", args->scene);
    for (const char *p = base + 1; *p; p++)
        if (*p == '.')
            dot = p;
    n = dot ? (size_t)(dot - base) : strlen(base);
    if (n + sizeof ".png" > sizeof args->out_default)
        return fail(args, "%s: the scene's name is too long", args->scene);
    memcpy(args->out_default, base, n);
    memcpy(args->out_default + n, ".png", sizeof ".png");
    args->out_png = args->out_default;
    return NULL;
}

/* POV-Ray's +W640 +H480 +Oout.png +A[threshold] -A +LDIR.  1: it was one
 * (args->error set on a bad value), 0: not one of them. */
static int pov_option(rs_args *args, const char *a, const char **err)
{
    char name[4] = { a[0], a[1], '\0', '\0' };
    const char *val = a + 2;
    *err = NULL;
    if ((a[0] != '+' && a[0] != '-') || a[1] == '\0')
        return 0;
    if (a[0] == '-' && (a[1] == 'A' || a[1] == 'a') && a[2] == '\0') {
        args->aa = 1;
        args->aa_threshold = -1.0;
        return 1;
    }
    if (a[0] != '+')
        return 0;
    switch (a[1]) {
    case 'W': case 'w':
        *err = int_option(args, name, val, 1, RS_ARGS_SIZE_MAX, &args->width);
        return 1;
    case 'H': case 'h':
        *err = int_option(args, name, val, 1, RS_ARGS_SIZE_MAX, &args->height);
        return 1;
    case 'O': case 'o':
        *err = set_value(args, OPT_OUT, name, val);
        return 1;
    case 'L': case 'l':
        *err = set_value(args, OPT_LIBRARY, name, val);
        return 1;
    case 'A': case 'a':
        if (*val != '\0') {
            double t;
            if (!parse_double(val, &t) || t < 0.0 || t > 3.0) {
                *err = fail(args, "+A: '%s' is not a threshold (0..3)", val);
                return 1;
            }
            args->aa_threshold = t;
        }
        if (args->aa < 2)
            args->aa = 3;
        return 1;
    default:
        return 0;
    }
}

const char *rs_args_parse(rs_args *args, int argc, char **argv)
{
    int options_done = 0;

    /* --help and --version win over everything, errors included. */
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--") == 0)
            break;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            args->help = 1;
            return NULL;
        }
        if (strcmp(a, "--version") == 0 || strcmp(a, "-V") == 0) {
            args->version = 1;
            return NULL;
        }
    }

    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *val = NULL;
        int id = -1;
        size_t len;

        if (!options_done) {
            const char *err;
            if (pov_option(args, a, &err)) {
                if (err)
                    return err;
                continue;
            }
        }
        if (options_done || a[0] != '-' || a[1] == '\0') {
            if (args->scene)
                return fail(args, "more than one scene file ('%s' and '%s')",
                            args->scene, a);
            if (*a == '\0')
                return fail(args, "empty scene file name");
            args->scene = a;
            continue;
        }
        if (strcmp(a, "--") == 0) {
            options_done = 1;
            continue;
        }
        if (strcmp(a, "--no-dispersion") == 0) {
            args->no_dispersion = 1;
            continue;
        }
        if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
            args->quiet = 1;
            continue;
        }
        for (size_t k = 0; k < sizeof value_options / sizeof *value_options; k++) {
            const char *name = value_options[k].name;
            len = strlen(name);
            if (strncmp(a, name, len) != 0)
                continue;
            if (a[len] == '\0') {
                id = value_options[k].id;
                if (i + 1 >= argc)
                    return fail(args, "%s needs a value", name);
                val = argv[++i];
            } else if (a[len] == '=' && name[1] == '-') {
                id = value_options[k].id;
                val = a + len + 1;
            } else {
                continue;
            }
            if (set_value(args, id, name, val))
                return args->error;
            break;
        }
        if (id < 0) {
            const char *eq = strchr(a, '=');
            if (eq && a[1] == '-')
                return fail(args, "unknown option '%.*s' (see --help)",
                            (int)(eq - a), a);
            return fail(args, "unknown option '%s' (see --help)", a);
        }
    }

    if (args->tolerance > 0.0 && !args->mode_auto)
        return fail(args, "--tolerance applies to --mode auto only");
    if (!args->scene)
        return fail(args, "no scene file given (usage: lensrender SCENE "
                    "[options]; see --help)");
    if ((long long)args->width * args->height > RS_ARGS_PIXELS_MAX)
        return fail(args, "image %d x %d has more than %lld pixels",
                    args->width, args->height, RS_ARGS_PIXELS_MAX);
    if (!args->out_png && derive_output(args))
        return args->error;
    return NULL;
}

/* The face's mode for the command line's. */
static lr_mode face_mode(const rs_args *a)
{
    if (a->mode_auto)
        return LR_MODE_AUTO;
    switch (a->mode) {
    case RS_MODE_FRESNEL: return LR_MODE_FRESNEL;
    case RS_MODE_SCHLICK: return LR_MODE_SCHLICK;
    case RS_MODE_RGB: return LR_MODE_RGB;
    default: return LR_MODE_POLARIZED;
    }
}

void rs_args_face_opts(const rs_args *a, lr_load_opts *lo, lr_render_opts *ro)
{
    lr_load_opts_init(lo);
    lo->image_width = a->width;
    lo->image_height = a->height;
    lo->library_dirs = a->library;
    lo->n_library_dirs = (size_t)a->n_library;
    lr_render_opts_init(ro);
    ro->mode = face_mode(a);
    ro->tolerance = a->tolerance;
    ro->width = a->width;
    ro->height = a->height;
    ro->depth = a->depth;
    ro->wavelengths = a->mode_auto && !a->wavelengths_given ? 0 : a->wavelengths;
    ro->cutoff = a->cutoff;
    ro->aa = a->aa;
    ro->no_dispersion = a->no_dispersion;
    ro->threads = a->threads;
}

int rs_args_exit_status(lr_status st)
{
    if (st == LR_OK)
        return 0;
    return st == LR_ERROR_INVALID_ARGUMENT || st == LR_ERROR_IO || st == LR_ERROR_SCENE ||
                   st == LR_ERROR_CAMERA
               ? 2 /* bad input */
               : 1 /* a render or output failure */;
}
