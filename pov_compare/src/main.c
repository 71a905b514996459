/* main.c -- pov_compare: render a .scene in POV-Ray 3.7 and in our
 * renderer (every light model), and compare them.
 *
 *   pov_compare SCENE [--out DIR] [--width W] [--height H] [--depth N]
 *   pov_compare --all [SCENES_DIR] [--out DIR] [...]
 *
 * Exit status: 0 success; 1 a render or an output file failed (POV-Ray
 * missing included); 2 bad input (command line, scene file, camera).
 * Every message is one line on stderr starting "pov_compare: ". */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "compare.h"
#include "lensrender/lensrender.h"
#include "montage.h"
#include "povray.h"
#include "report.h"
#include "support/cli.h"
#include "support/image.h"
#include "support/tiles.h"
#include "translate.h"

#define EXIT_RENDER 1
#define EXIT_BAD 2
#define MSG_MAX (2 * PATH_MAX + 1024)
#define SIZE_MAX_SIDE 16384
#define PIXELS_MAX (64LL * 1024 * 1024)
#define DEPTH_MAX 256
#define WAVELENGTHS 16
#define LIBRARY_PATHS_MAX 32

static const char usage_text[] =
    "usage: pov_compare SCENE [--out DIR] [--width W] [--height H] [--depth N]\n"
    "       pov_compare --all [SCENES_DIR] [--out DIR] [--width W] [--height H]\n"
    "       common options: [--povray PATH] [--lens-inc FILE] [-L DIR]... [--threads N]\n"
    "                       [--quiet]\n"
    "       pov_compare --help\n"
    "\n"
    "Renders SCENE (a .scene file) in POV-Ray 3.7 and in this renderer, in\n"
    "each light model (fresnel, schlick, polarized, rgb), and compares them.\n"
    "Both renderers trace one ray per pixel centre with adc_bailout 0, the\n"
    "same max trace level, and glass as a constant lossless index at the d\n"
    "line (587.56 nm); what POV-Ray cannot express is listed in the notes.\n"
    "\n"
    "  --out DIR        output directory (default compare-out/<scene name>;\n"
    "                   with --all, compare-out, one sub-directory per scene)\n"
    "  --width W        image width, 1..16384 (default 320)\n"
    "  --height H       image height, 1..16384 (default 240)\n"
    "  --depth N        max trace level 1..256 (default: the scene's)\n"
    "  --all [DIR]      compare every DIR/*.scene (default DIR: ./scenes, else the\n"
    "                   installed share/lensprim/scenes) and\n"
    "                   write index.md and index.html into the output directory\n"
    "  --povray PATH    the POV-Ray executable (default: povray on PATH)\n"
    "  --lens-inc FILE  the lens macro file the .pov includes; by default lens.inc\n"
    "                   is looked for next to the scene, in each -L directory,\n"
    "                   in the installed share/lensprim, in the source tree of\n"
    "                   the build\n"
    "  -L DIR, +LDIR, --library-path DIR\n"
    "                   a POV-Ray library path (repeatable, in order)\n"
    "  --threads N      threads for both renderers, 1..1024 (default: every core)\n"
    "  -q, --quiet      print nothing but errors\n"
    "  -h, --help       this text\n"
    "\n"
    "Writes into the output directory: scene.pov, mask.pov, lens.inc,\n"
    "povray.png (POV-Ray's 16-bit linear render), povray.log,\n"
    "ours_<mode>.png (8-bit sRGB) and ours_<mode>.pfm (linear float) for each\n"
    "mode, mask_ours.png, mask_povray.png, diff.png, side_by_side.png\n"
    "(ours in fresnel mode | POV-Ray | difference), report.json, report.md.\n"
    "\n"
    "Exit status: 0 success, 1 a render or output failed (POV-Ray missing\n"
    "included), 2 bad input: the scene, lens.inc or the output directory.\n";

typedef struct options {
    int help, all, quiet;
    const char *positional; /* SCENE, or SCENES_DIR with --all */
    const char *out;
    const char *povray;
    const char *lens_inc;
    const char *library_paths[LIBRARY_PATHS_MAX]; /* -L, in order */
    int n_library_paths;
    int width, height, depth, threads;
} options;

/* What --all keeps of each scene for the index. */
typedef struct summary {
    char name[256];
    int status;
    char error[MSG_MAX + PATH_MAX + 64];
    pc_report rep;          /* notes pointer not kept */
    int polarizer_note;
    int povray_missing;     /* POV-Ray could not be run */
    size_t n_notes;
} summary;

#define say(...) sp_say("pov_compare", __VA_ARGS__)

/* A progress line on a terminal (not with --quiet, not into files). */
static void progress(const options *o, const char *scene, const char *stage)
{
    if (o->quiet || !isatty(STDERR_FILENO))
        return;
    fprintf(stderr, "pov_compare: %s: %s\n", scene, stage);
}

/* ---- the command line ---- */

static int parse_int(const char *s, int lo, int hi, int *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi)
        return -1;
    *out = (int)v;
    return 0;
}

/* Returns 0, or -1 after printing the problem. */
static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->width = 320;
    o->height = 240;
    o->povray = "povray";
    int no_more_options = 0;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i], *val = NULL;
        char name[64];
        if (!no_more_options &&
            (strncmp(arg, "+L", 2) == 0 || strncmp(arg, "-L", 2) == 0 ||
             strcmp(arg, "--library-path") == 0 ||
             strncmp(arg, "--library-path=", 15) == 0)) {
            /* POV-Ray's +LDIR, and -L DIR / -LDIR / --library-path DIR */
            const char *dir = arg[0] == '+' || (arg[1] == 'L' && arg[2]) ? arg + 2
                              : arg[14] == '=' ? arg + 15
                              : i + 1 < argc ? argv[++i] : NULL;
            if (!dir || !*dir) {
                say("%s needs a directory", arg);
                return -1;
            }
            if (o->n_library_paths >= LIBRARY_PATHS_MAX) {
                say("more than %d library paths", LIBRARY_PATHS_MAX);
                return -1;
            }
            o->library_paths[o->n_library_paths++] = dir;
            continue;
        }
        if (no_more_options || arg[0] != '-' || arg[1] == '\0') {
            if (o->positional) {
                say("unexpected argument '%s' (one %s only)", arg,
                    o->all ? "scenes directory" : "scene");
                return -1;
            }
            o->positional = arg;
            continue;
        }
        if (strcmp(arg, "--") == 0) {
            no_more_options = 1;
            continue;
        }
        if (strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0) {
            o->help = 1;
            return 0;
        }
        if (strcmp(arg, "-q") == 0 || strcmp(arg, "--quiet") == 0) {
            o->quiet = 1;
            continue;
        }
        if (strcmp(arg, "--all") == 0) {
            o->all = 1;
            continue;
        }
        const char *eq = strchr(arg, '=');
        size_t len = eq ? (size_t)(eq - arg) : strlen(arg);
        if (len >= sizeof name) {
            say("unknown option '%s' (try --help)", arg);
            return -1;
        }
        memcpy(name, arg, len);
        name[len] = '\0';
        static const char *const with_value[] = {"--out", "--width", "--height", "--depth",
                                                 "--povray", "--lens-inc", "--threads", "-o"};
        int known = 0;
        for (size_t k = 0; k < sizeof with_value / sizeof *with_value; k++)
            known |= strcmp(name, with_value[k]) == 0;
        if (!known) {
            say("unknown option '%s' (try --help)", arg);
            return -1;
        }
        if (eq)
            val = eq + 1;
        else if (i + 1 < argc)
            val = argv[++i];
        else {
            say("option %s needs a value", name);
            return -1;
        }
        if (strcmp(name, "--out") == 0 || strcmp(name, "-o") == 0) {
            if (!*val) {
                say("--out needs a directory");
                return -1;
            }
            o->out = val;
        } else if (strcmp(name, "--povray") == 0) {
            if (!*val) {
                say("--povray needs a program");
                return -1;
            }
            o->povray = val;
        } else if (strcmp(name, "--lens-inc") == 0) {
            o->lens_inc = val;
        } else if (strcmp(name, "--width") == 0) {
            if (parse_int(val, 1, SIZE_MAX_SIDE, &o->width)) {
                say("--width must be an integer 1..%d, not '%s'", SIZE_MAX_SIDE, val);
                return -1;
            }
        } else if (strcmp(name, "--height") == 0) {
            if (parse_int(val, 1, SIZE_MAX_SIDE, &o->height)) {
                say("--height must be an integer 1..%d, not '%s'", SIZE_MAX_SIDE, val);
                return -1;
            }
        } else if (strcmp(name, "--depth") == 0) {
            if (parse_int(val, 1, DEPTH_MAX, &o->depth)) {
                say("--depth must be an integer 1..%d, not '%s'", DEPTH_MAX, val);
                return -1;
            }
        } else if (strcmp(name, "--threads") == 0) {
            if (parse_int(val, 1, 1024, &o->threads)) {
                say("--threads must be an integer 1..1024, not '%s'", val);
                return -1;
            }
        }
    }
    if ((long long)o->width * o->height > PIXELS_MAX) {
        say("--width x --height is %lld pixels, more than %lld", (long long)o->width * o->height,
            PIXELS_MAX);
        return -1;
    }
    if (!o->all && !o->positional) {
        say("no scene given (usage: pov_compare SCENE [--out DIR] ..., or --help)");
        return -1;
    }
    return 0;
}

/* ---- files and directories ---- */

static int is_file(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static int is_dir(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

/* The directory part of path ("." when none) into out. */
static void dir_of(const char *path, char *out, size_t size)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(out, size, ".");
    else if (slash == path)
        snprintf(out, size, "/");
    else
        snprintf(out, size, "%.*s", (int)(slash - path), path);
}

static const char *base_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

/* The scene's name: its base name without the .scene extension. */
static void scene_name(const char *path, char *out, size_t size)
{
    const char *b = base_of(path);
    size_t n = strlen(b);
    if (n > 6 && strcmp(b + n - 6, ".scene") == 0)
        n -= 6;
    snprintf(out, size, "%.*s", (int)n, b);
}

/* The installed share directory seen from the executable:
 * <exe dir>/LP_BIN_TO_SHARE (bin/../share/lensprim when installed), so an
 * install can be moved. */
static int exe_share_dir(char *out, size_t size)
{
#ifdef LP_BIN_TO_SHARE
    char exe[PATH_MAX], d1[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0)
        return -1;
    exe[n] = '\0';
    dir_of(exe, d1, sizeof d1);
    if (snprintf(out, size, "%s/%s", d1, LP_BIN_TO_SHARE) >= (int)size)
        return -1;
    return is_dir(out) ? 0 : -1;
#else
    (void)out;
    (void)size;
    return -1;
#endif
}

/* dir/lens.inc into out when it is a file. */
static int lens_inc_in(const char *dir, char *out, size_t size)
{
    return snprintf(out, size, "%s/lens.inc", dir) < (int)size && is_file(out) ? 0 : -1;
}

/* Where lens.inc is: --lens-inc, next to the scene, the library paths,
 * the installed share directory, the source tree of the build. */
static int find_lens_inc(const options *o, const char *scene_path, char *out, size_t size)
{
    char dir[PATH_MAX];
    if (o->lens_inc) {
        snprintf(out, size, "%s", o->lens_inc);
        return is_file(out) ? 0 : -1;
    }
    dir_of(scene_path, dir, sizeof dir);
    if (lens_inc_in(dir, out, size) == 0)
        return 0;
    for (int k = 0; k < o->n_library_paths; k++)
        if (lens_inc_in(o->library_paths[k], out, size) == 0)
            return 0;
    if (exe_share_dir(dir, sizeof dir) == 0 && lens_inc_in(dir, out, size) == 0)
        return 0;
#ifdef LP_BUILD_SCENES_DIR
    if (lens_inc_in(LP_BUILD_SCENES_DIR, out, size) == 0)
        return 0;
#endif
    return -1;
}

/* ---- our renders ---- */

/* Render the scene in mode into *img (created here), with the
 * approximations of the translation (no dispersion: the scene's glass is
 * frozen at the d line by the first render); *seconds = wall clock. */
static int render_ours(lr_scene *scene, lr_mode mode, int width, int height, int depth,
                       int threads, rs_image *img, double *seconds, char *msg, size_t msg_size)
{
    lr_render_opts ro;
    lr_renderer *r = NULL;
    lr_error err;
    double t0 = sp_now_seconds();

    lr_render_opts_init(&ro);
    ro.mode = mode;
    ro.depth = depth;
    ro.cutoff = 0.0;            /* POV-Ray runs with adc_bailout 0 */
    ro.wavelengths = WAVELENGTHS;
    ro.width = width;
    ro.height = height;
    ro.no_dispersion = 1;
    ro.threads = threads;
    if (lr_renderer_create(scene, &ro, &r, &err) != LR_OK) {
        snprintf(msg, msg_size, "%s", err.message);
        return -1;
    }
    if (rs_image_create(img, width, height) != 0) {
        lr_renderer_free(r);
        snprintf(msg, msg_size, "out of memory for a %d x %d image", width, height);
        return -1;
    }
    lr_status st = lr_render_image(r, img->rgb, NULL, NULL, &err);
    lr_renderer_free(r);
    *seconds = sp_now_seconds() - t0;
    if (st != LR_OK) {
        rs_image_free(img);
        snprintf(msg, msg_size, "the %s render failed: %s", pc_mode_label(mode), err.message);
        return -1;
    }
    return 0;
}

/* Our silhouette: 1 where the pixel-centre ray hits any lens. */
static unsigned char *our_mask(const rs_scene *scene, int w, int h)
{
    unsigned char *m = calloc((size_t)w * (size_t)h, 1);
    if (!m)
        return NULL;
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            lp_vec3 o, d;
            if (lr_camera_ray(&scene->camera, w, h, i + 0.5, j + 0.5, &o, &d, NULL) != LR_OK) {
                free(m);
                return NULL;
            }
            for (size_t k = 0; k < scene->n_objects; k++) {
                const rs_object *ob = &scene->objects[k];
                lp_hit hit;
                if (ob->type != RS_OBJ_LENS || !ob->lens)
                    continue;
                if (lp_lens_intersect(ob->lens, o, d, 0.0, INFINITY, &hit)) {
                    m[(size_t)j * (size_t)w + (size_t)i] = 1;
                    break;
                }
            }
        }
    return m;
}

static int write_mask_png(const char *path, const unsigned char *m, int w, int h, char *msg,
                          size_t msg_size)
{
    rs_image img;
    if (rs_image_create(&img, w, h) != 0) {
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    for (size_t p = 0; p < (size_t)w * (size_t)h; p++)
        img.rgb[3 * p] = img.rgb[3 * p + 1] = img.rgb[3 * p + 2] = m[p] ? 1.0f : 0.0f;
    int rc = rs_png_write(path, &img, msg, msg_size);
    rs_image_free(&img);
    return rc;
}

/* ---- one comparison ---- */

static int path_in(char *buf, size_t size, const char *dir, const char *name)
{
    return snprintf(buf, size, "%s/%s", dir, name) < (int)size ? 0 : -1;
}

typedef struct run_state {
    lr_scene *scene;
    pc_notes notes;
    rs_image pov, pov_mask, ours[PC_N_MODES], diff;
    unsigned char *mask_a, *mask_b;
} run_state;

static void run_state_free(run_state *s)
{
    lr_scene_free(s->scene);
    pc_notes_free(&s->notes);
    rs_image_free(&s->pov);
    rs_image_free(&s->pov_mask);
    for (int k = 0; k < PC_N_MODES; k++)
        rs_image_free(&s->ours[k]);
    rs_image_free(&s->diff);
    free(s->mask_a);
    free(s->mask_b);
}

static int has_polarizer_note(const pc_notes *n)
{
    for (size_t k = 0; k < n->n; k++)
        if (strcmp(n->text[k], PC_NOTE_POLARIZERS) == 0)
            return 1;
    return 0;
}

/* Compare one scene into out_dir; fills *sum.  Returns the exit status. */
static int compare_scene(const options *o, const char *scene_path, const char *out_dir,
                         summary *sum)
{
    char msg[MSG_MAX] = "", path[PATH_MAX], lens_inc[PATH_MAX], log_path[PATH_MAX];
    run_state st;
    lr_load_opts lo;
    lr_error err;
    lp_vec3 ray_o, ray_d;
    const rs_scene *desc = NULL;
    pc_report *rep = &sum->rep;
    int status = 0, w = o->width, h = o->height;
    int threads = o->threads > 0 ? o->threads : rs_online_processors();

    memset(&st, 0, sizeof st);
    memset(sum, 0, sizeof *sum);
    scene_name(scene_path, sum->name, sizeof sum->name);
    lr_load_opts_init(&lo);
    lo.image_width = w;
    lo.image_height = h;

#define FAIL(code, ...)                                                                        \
    do {                                                                                       \
        snprintf(sum->error, sizeof sum->error, __VA_ARGS__);                                  \
        say("%s", sum->error);                                                                 \
        status = (code);                                                                       \
        goto done;                                                                             \
    } while (0)

    if (lr_scene_load(scene_path, &lo, &st.scene, &err) != LR_OK)
        FAIL(EXIT_BAD, "%s", err.message);
    desc = lr_scene_description(st.scene);
    if (lr_camera_ray(&desc->camera, w, h, 0.5, 0.5, &ray_o, &ray_d, &err) != LR_OK)
        FAIL(EXIT_BAD, "%s: camera: %s", scene_path, err.message);
    if (sp_mkdir_p(out_dir, msg, sizeof msg) != 0)
        FAIL(EXIT_BAD, "%s", msg);

    rep->scene = base_of(scene_path);
    rep->width = w;
    rep->height = h;
    rep->depth = o->depth > 0 ? o->depth : desc->settings.max_trace_level;
    rep->wavelengths = WAVELENGTHS;
    rep->notes = &st.notes;
    for (int k = 0; k < PC_N_MODES; k++)
        rep->modes[k].mode = pc_report_mode(k);

    /* The POV-Ray side: lens.inc, scene.pov, mask.pov, two renders. */
    if (find_lens_inc(o, scene_path, lens_inc, sizeof lens_inc) != 0) {
        if (o->lens_inc)
            FAIL(EXIT_BAD, "--lens-inc %s: no such file", o->lens_inc);
        FAIL(EXIT_BAD,
             "lens.inc not found (looked next to %s, in the -L directories, in the "
             "installed share/lensprim and in the build's source tree): pass "
             "--lens-inc FILE",
             scene_path);
    }
    if (path_in(path, sizeof path, out_dir, "lens.inc") ||
        pc_copy_file(lens_inc, path, msg, sizeof msg) != 0)
        FAIL(EXIT_RENDER, "%s", msg[0] ? msg : "output path too long");
    for (int mask = 0; mask <= 1; mask++) {
        pc_translate_opts to = {w, h, rep->depth, "lens.inc", mask};
        if (path_in(path, sizeof path, out_dir, mask ? "mask.pov" : "scene.pov") ||
            pc_povray_write_scene(desc, &to, path, &st.notes, msg, sizeof msg) != 0)
            FAIL(EXIT_RENDER, "%s", msg[0] ? msg : "output path too long");
    }
    if (path_in(log_path, sizeof log_path, out_dir, "povray.log"))
        FAIL(EXIT_RENDER, "output path too long");
    {
        FILE *lf = fopen(log_path, "w"); /* a fresh log for this comparison */
        if (!lf)
            FAIL(EXIT_RENDER, "%s: cannot write: %s", log_path, strerror(errno));
        fclose(lf);
    }
    for (int mask = 0; mask <= 1; mask++) {
        progress(o, rep->scene, mask ? "POV-Ray: the silhouettes (mask.pov)"
                                     : "POV-Ray: the scene (scene.pov)");
        pc_povray_job job = {o->povray, out_dir, mask ? "mask.pov" : "scene.pov",
                             mask ? "mask_povray.png" : "povray.png", log_path, w, h, threads};
        double secs = 0.0;
        pc_povray_status ps =
            pc_povray_render(&job, mask ? &st.pov_mask : &st.pov, &secs, msg, sizeof msg);
        if (ps == PC_POVRAY_NOT_FOUND)
            sum->povray_missing = 1;
        if (ps != PC_POVRAY_OK)
            FAIL(EXIT_RENDER, "%s", msg);
        if (mask)
            rep->povray_mask_seconds = secs;
        else
            rep->povray_seconds = secs;
    }
    pc_povray_version_from_log(log_path, rep->povray_version, sizeof rep->povray_version);

    /* Our side: the same approximations (no dispersion), then every mode. */
    for (int k = 0; k < PC_N_MODES; k++) {
        lr_mode mode = rep->modes[k].mode;
        char name[64], stage[64];
        snprintf(stage, sizeof stage, "ours: %s", pc_mode_label(mode));
        progress(o, rep->scene, stage);
        if (render_ours(st.scene, mode, w, h, rep->depth, threads, &st.ours[k],
                        &rep->modes[k].seconds, msg, sizeof msg) != 0)
            FAIL(EXIT_RENDER, "%s: %s", scene_path, msg);
        snprintf(name, sizeof name, "ours_%s.png", pc_mode_label(mode));
        if (path_in(path, sizeof path, out_dir, name) ||
            rs_png_write(path, &st.ours[k], msg, sizeof msg) != 0)
            FAIL(EXIT_RENDER, "%s", msg);
        snprintf(name, sizeof name, "ours_%s.pfm", pc_mode_label(mode));
        if (path_in(path, sizeof path, out_dir, name) ||
            rs_pfm_write(path, &st.ours[k], msg, sizeof msg) != 0)
            FAIL(EXIT_RENDER, "%s", msg);
    }

    /* Silhouettes. */
    st.mask_a = our_mask(desc, w, h);
    st.mask_b = pc_mask_from_image(&st.pov_mask);
    if (!st.mask_a || !st.mask_b ||
        pc_compare_masks(st.mask_a, st.mask_b, w, h, &rep->geometry) != 0)
        FAIL(EXIT_RENDER, "out of memory comparing silhouettes");
    if (path_in(path, sizeof path, out_dir, "mask_ours.png") ||
        write_mask_png(path, st.mask_a, w, h, msg, sizeof msg) != 0)
        FAIL(EXIT_RENDER, "%s", msg);

    /* Metrics. */
    const rs_image *pol = NULL;
    for (int k = 0; k < PC_N_MODES; k++)
        if (rep->modes[k].mode == LR_MODE_POLARIZED)
            pol = &st.ours[k];
    for (int k = 0; k < PC_N_MODES; k++) {
        pc_mode_result *m = &rep->modes[k];
        pc_compare_images(&st.ours[k], &st.pov, &m->vs_povray);
        pc_worst_pixel_find(&st.ours[k], &st.pov, &m->worst);
        m->has_vs_polarized = m->mode != LR_MODE_POLARIZED;
        if (m->has_vs_polarized)
            pc_compare_images(&st.ours[k], pol, &m->vs_polarized);
    }

    /* Pictures: the difference map and the montage (fresnel | POV-Ray). */
    const pc_mode_result *fr = &rep->modes[0];
    if (pc_diff_map(&st.ours[0], &st.pov, &st.diff, &rep->diff_scale, &rep->diff_max) != 0)
        FAIL(EXIT_RENDER, "out of memory for the difference map");
    if (path_in(path, sizeof path, out_dir, "diff.png") ||
        rs_png_write(path, &st.diff, msg, sizeof msg) != 0)
        FAIL(EXIT_RENDER, "%s", msg);
    {
        char cap[128], dl[64];
        if (isinf(fr->vs_povray.psnr))
            snprintf(cap, sizeof cap, "IDENTICAL, %.2f S", fr->seconds);
        else
            snprintf(cap, sizeof cap, "PSNR %.1f DB  SSIM %.4f", fr->vs_povray.psnr,
                     fr->vs_povray.ssim);
        char pcap[64];
        snprintf(pcap, sizeof pcap, "%.2f S (OURS %.2f S)", rep->povray_seconds, fr->seconds);
        snprintf(dl, sizeof dl, "|DIFFERENCE| 0..%g", rep->diff_scale);
        pc_montage_args ma = {&st.ours[0], &st.pov, &st.diff, "OURS (FRESNEL)", "POV-RAY 3.7", dl,
                              cap, pcap, rep->diff_scale};
        if (path_in(path, sizeof path, out_dir, "side_by_side.png") ||
            pc_montage_write(path, &ma, msg, sizeof msg) != 0)
            FAIL(EXIT_RENDER, "%s", msg);
    }

    if (path_in(path, sizeof path, out_dir, "report.json") ||
        pc_report_write_json(rep, path, msg, sizeof msg) != 0)
        FAIL(EXIT_RENDER, "%s", msg);
    if (path_in(path, sizeof path, out_dir, "report.md") ||
        pc_report_write_md(rep, path, msg, sizeof msg) != 0)
        FAIL(EXIT_RENDER, "%s", msg);

    if (!o->quiet) {
        const pc_mode_result *p = pc_report_find(rep, LR_MODE_POLARIZED);
        printf("%s: IoU %.5f, boundary %.3g px; vs POV-Ray PSNR fresnel %.2f, schlick %.2f, "
               "polarized %.2f, rgb %.2f dB; POV-Ray %.2f s, ours %.2f/%.2f/%.2f/%.2f s -> %s/\n",
               rep->scene, rep->geometry.iou, rep->geometry.max_boundary_px, fr->vs_povray.psnr,
               rep->modes[1].vs_povray.psnr, p->vs_povray.psnr, rep->modes[3].vs_povray.psnr,
               rep->povray_seconds, rep->modes[0].seconds, rep->modes[1].seconds,
               rep->modes[2].seconds, rep->modes[3].seconds, out_dir);
        fflush(stdout);
    }

done:
#undef FAIL
    sum->status = status;
    sum->polarizer_note = has_polarizer_note(&st.notes);
    sum->n_notes = st.notes.n;
    rep->notes = NULL;
    rep->scene = NULL;
    run_state_free(&st);
    return status;
}

/* ---- --all ---- */

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The sorted names of the .scene files in dir; *n set.  NULL on failure. */
static char **list_scenes(const char *dir, size_t *n, char *msg, size_t msg_size)
{
    DIR *d = opendir(dir);
    char **names = NULL;
    size_t cap = 0;
    struct dirent *e;
    *n = 0;
    if (!d) {
        snprintf(msg, msg_size, "%s: cannot open directory: %s", dir, strerror(errno));
        return NULL;
    }
    while ((e = readdir(d)) != NULL) {
        size_t len = strlen(e->d_name);
        if (len <= 6 || strcmp(e->d_name + len - 6, ".scene") != 0 || e->d_name[0] == '.')
            continue;
        if (*n == cap) {
            size_t nc = cap ? 2 * cap : 16;
            char **nn = realloc(names, nc * sizeof *nn);
            if (!nn)
                goto oom;
            names = nn;
            cap = nc;
        }
        names[*n] = malloc(len + 1);
        if (!names[*n])
            goto oom;
        memcpy(names[*n], e->d_name, len + 1);
        (*n)++;
    }
    closedir(d);
    if (*n == 0) {
        snprintf(msg, msg_size, "%s: no .scene files", dir);
        free(names);
        return NULL;
    }
    qsort(names, *n, sizeof *names, cmp_str);
    return names;
oom:
    closedir(d);
    for (size_t k = 0; k < *n; k++)
        free(names[k]);
    free(names);
    snprintf(msg, msg_size, "out of memory");
    return NULL;
}

/* text with & < > " escaped for HTML. */
static void html_text(FILE *f, const char *text)
{
    for (const char *p = text; *p; p++) {
        switch (*p) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*p, f);
        }
    }
}

static void fmt_num(char *buf, size_t size, double v, const char *fmt)
{
    if (isnan(v))
        snprintf(buf, size, "–");
    else if (isinf(v))
        snprintf(buf, size, "∞");
    else
        snprintf(buf, size, fmt, v);
}

static int write_index(const char *out_dir, const summary *s, size_t n, const options *o,
                       char *msg, size_t msg_size)
{
    char md[PATH_MAX], html[PATH_MAX];
    if (path_in(md, sizeof md, out_dir, "index.md") ||
        path_in(html, sizeof html, out_dir, "index.html")) {
        snprintf(msg, msg_size, "output path too long");
        return -1;
    }
    FILE *fm = fopen(md, "w"), *fh = fopen(html, "w");
    if (!fm || !fh) {
        snprintf(msg, msg_size, "%s: cannot write: %s", fm ? html : md, strerror(errno));
        if (fm)
            fclose(fm);
        if (fh)
            fclose(fh);
        return -1;
    }
    static const char *const heads[] = {"scene", "IoU", "boundary px", "fresnel PSNR",
                                        "fresnel SSIM", "schlick PSNR", "polarized PSNR",
                                        "rgb PSNR", "POV-Ray s", "ours s (f/s/p/rgb)", "notes"};
    const size_t nh = sizeof heads / sizeof *heads;
    fprintf(fm, "# pov_compare: every scene\n\n%d × %d pixels; PSNR (dB) and SSIM of our "
                "renders against POV-Ray 3.7; geometry from the lens silhouettes.\n\n|",
            o->width, o->height);
    fputs("<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>pov_compare</title>\n"
          "<style>body{font-family:sans-serif;background:#111;color:#ddd}"
          "table{border-collapse:collapse}td,th{border:1px solid #444;padding:3px 6px;"
          "text-align:right}a{color:#8cf}img{max-width:100%}</style></head><body>\n",
          fh);
    fprintf(fh, "<h1>pov_compare: every scene</h1>\n<p>%d &times; %d pixels; PSNR (dB) and "
                "SSIM of our renders against POV-Ray 3.7.</p>\n<table><tr>",
            o->width, o->height);
    for (size_t k = 0; k < nh; k++) {
        fprintf(fm, " %s |", heads[k]);
        fprintf(fh, "<th>%s</th>", heads[k]);
    }
    fputs("\n|", fm);
    for (size_t k = 0; k < nh; k++)
        fputs(k ? "---:|" : "---|", fm);
    fputs("\n", fm);
    fputs("</tr>\n", fh);
    for (size_t i = 0; i < n; i++) {
        const pc_report *r = &s[i].rep;
        if (s[i].status != 0) {
            fprintf(fm, "| %s | failed: %s |\n", s[i].name, s[i].error);
            fputs("<tr><td>", fh);
            html_text(fh, s[i].name);
            fprintf(fh, "</td><td colspan=\"%zu\" style=\"text-align:left\">failed: ", nh - 1);
            html_text(fh, s[i].error);
            fputs("</td></tr>\n", fh);
            continue;
        }
        char c[10][48];
        fmt_num(c[0], sizeof c[0], r->geometry.iou, "%.5f");
        fmt_num(c[1], sizeof c[1], r->geometry.max_boundary_px, "%.3g");
        fmt_num(c[2], sizeof c[2], r->modes[0].vs_povray.psnr, "%.2f");
        fmt_num(c[3], sizeof c[3], r->modes[0].vs_povray.ssim, "%.4f");
        fmt_num(c[4], sizeof c[4], r->modes[1].vs_povray.psnr, "%.2f");
        fmt_num(c[5], sizeof c[5], r->modes[2].vs_povray.psnr, "%.2f");
        fmt_num(c[6], sizeof c[6], r->modes[3].vs_povray.psnr, "%.2f");
        fmt_num(c[7], sizeof c[7], r->povray_seconds, "%.2f");
        snprintf(c[8], sizeof c[8], "%.2f/%.2f/%.2f/%.2f", r->modes[0].seconds,
                 r->modes[1].seconds, r->modes[2].seconds, r->modes[3].seconds);
        snprintf(c[9], sizeof c[9], "%zu%s", s[i].n_notes,
                 s[i].polarizer_note ? " (polarizers)" : "");
        fprintf(fm, "| [%s](%s/report.md) |", s[i].name, s[i].name);
        fputs("<tr><td style=\"text-align:left\"><a href=\"", fh);
        html_text(fh, s[i].name);
        fputs("/report.md\">", fh);
        html_text(fh, s[i].name);
        fputs("</a></td>", fh);
        for (int k = 0; k < 10; k++) {
            fprintf(fm, " %s |", c[k]);
            fprintf(fh, "<td>%s</td>", c[k]);
        }
        fputs("\n", fm);
        fputs("</tr>\n", fh);
    }
    fputs("\n", fm);
    fputs("</table>\n", fh);
    for (size_t i = 0; i < n; i++) {
        if (s[i].status != 0)
            continue;
        fprintf(fm, "## %s\n\n![%s](%s/side_by_side.png)\n\n", s[i].name, s[i].name,
                s[i].name);
        fputs("<h2><a href=\"", fh);
        html_text(fh, s[i].name);
        fputs("/report.md\">", fh);
        html_text(fh, s[i].name);
        fputs("</a></h2>\n<p><img src=\"", fh);
        html_text(fh, s[i].name);
        fputs("/side_by_side.png\" alt=\"", fh);
        html_text(fh, s[i].name);
        fputs("\"></p>\n", fh);
    }
    fputs("</body></html>\n", fh);
    int bad = ferror(fm) || ferror(fh);
    bad |= fclose(fm) != 0;
    bad |= fclose(fh) != 0;
    if (bad) {
        snprintf(msg, msg_size, "%s: write error", out_dir);
        return -1;
    }
    return 0;
}

static int compare_all(const options *o)
{
    char dir[PATH_MAX], msg[MSG_MAX], scene[PATH_MAX], out[PATH_MAX];
    const char *out_root = o->out ? o->out : "compare-out";
    size_t n = 0;
    int status = 0;

    if (o->positional)
        snprintf(dir, sizeof dir, "%s", o->positional);
    else if (is_dir("scenes"))
        snprintf(dir, sizeof dir, "scenes");
    else if (exe_share_dir(dir, sizeof dir) == 0 &&
             strlen(dir) + sizeof "/scenes" <= sizeof dir && is_dir(strcat(dir, "/scenes")))
        ; /* the installed examples */
    else {
        say("--all: no scenes directory given and none found (./scenes, the installed "
            "share/lensprim/scenes)");
        return EXIT_BAD;
    }
    char **names = list_scenes(dir, &n, msg, sizeof msg);
    if (!names) {
        say("%s", msg);
        return EXIT_BAD;
    }
    summary *sums = calloc(n, sizeof *sums);
    if (!sums) {
        say("out of memory");
        for (size_t k = 0; k < n; k++)
            free(names[k]);
        free(names);
        return EXIT_RENDER;
    }
    size_t done = 0;
    for (size_t k = 0; k < n; k++) {
        char nm[256];
        scene_name(names[k], nm, sizeof nm);
        if (snprintf(scene, sizeof scene, "%s/%s", dir, names[k]) >= (int)sizeof scene ||
            snprintf(out, sizeof out, "%s/%s", out_root, nm) >= (int)sizeof out) {
            snprintf(sums[k].name, sizeof sums[k].name, "%s", nm);
            snprintf(sums[k].error, sizeof sums[k].error, "%s: path too long", names[k]);
            say("%s", sums[k].error);
            sums[k].status = EXIT_BAD;
            done = k + 1;
            if (status == 0)
                status = EXIT_BAD;
            continue;
        }
        int s = compare_scene(o, scene, out, &sums[k]);
        done = k + 1;
        if (s != 0 && (status == 0 || s == EXIT_RENDER))
            status = s;
        /* Without POV-Ray every other scene would fail the same way. */
        if (sums[k].povray_missing)
            break;
    }
    if (done > 0) {
        if (sp_mkdir_p(out_root, msg, sizeof msg) != 0 ||
            write_index(out_root, sums, done, o, msg, sizeof msg) != 0) {
            say("%s", msg);
            status = EXIT_RENDER;
        } else if (!o->quiet) {
            printf("wrote %s/index.md and %s/index.html\n", out_root, out_root);
        }
    }
    for (size_t k = 0; k < n; k++)
        free(names[k]);
    free(names);
    free(sums);
    return status;
}

int main(int argc, char **argv)
{
    options o;
    if (parse_args(argc, argv, &o) != 0)
        return EXIT_BAD;
    if (o.help) {
        const char *text = usage_text;
        return sp_print_text(&text, 1) == 0 ? 0 : EXIT_RENDER;
    }
    if (o.all)
        return compare_all(&o);

    if (!is_file(o.positional)) {
        say("%s: cannot read: %s", o.positional,
            access(o.positional, F_OK) == 0 ? "not a regular file" : strerror(errno));
        return EXIT_BAD;
    }
    char out[PATH_MAX], nm[256];
    if (o.out)
        snprintf(out, sizeof out, "%s", o.out);
    else {
        scene_name(o.positional, nm, sizeof nm);
        snprintf(out, sizeof out, "compare-out/%s", nm);
    }
    summary *sum = malloc(sizeof *sum);
    if (!sum) {
        say("out of memory");
        return EXIT_RENDER;
    }
    int status = compare_scene(&o, o.positional, out, sum);
    free(sum);
    return status;
}
