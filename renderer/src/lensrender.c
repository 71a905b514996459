/* lensrender.c -- the renderer's public face (lensrender/lensrender.h):
 * the reader, the automatic choice, the integrator and the thread pool
 * behind opaque handles. */
#include "lensrender/lensrender.h"

#include <ctype.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "auto_settings.h"
#include "camera.h"
#include "csg.h"
#include "emitter.h"
#include "integrator.h"
#include "library_path.h"
#include "parser.h"
#include "support/tiles.h"

#define TILE_SIZE 16
#define MSG_MAX 1024
#define WHY_MAX 1024
#define DESCRIPTION_MAX 160

struct lr_scene {
    rs_scene s;
    int ok;             /* loaded without error: may be rendered */
    int frozen;         /* no_dispersion applied (once) */
    char *name;         /* the path or name it was read from */
};

struct lr_renderer {
    const lr_scene *scene;
    rs_integrator *it;
    lr_render_opts settings;   /* as rendered (lr_renderer_settings) */
    char why[WHY_MAX];         /* auto's explanation, or "" */
    char what[DESCRIPTION_MAX]; /* lr_renderer_description */
};

/* ---- errors ------------------------------------------------------------ */

const char *lr_status_string(lr_status status)
{
    switch (status) {
    case LR_OK: return "ok";
    case LR_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case LR_ERROR_IO: return "a file could not be read";
    case LR_ERROR_SCENE: return "error in the scene";
    case LR_ERROR_CAMERA: return "the camera cannot make rays";
    case LR_ERROR_NO_MEMORY: return "out of memory";
    case LR_ERROR_RENDER: return "the render could not run";
    case LR_CANCELLED: return "cancelled";
    }
    return "unknown status";
}

static lr_status fail(lr_error *err, lr_status status, const char *fmt, const char *a,
                      const char *b)
{
    if (err) {
        memset(err, 0, sizeof *err);
        err->status = status;
        snprintf(err->message, sizeof err->message, fmt, a, b ? b : "");
    }
    return status;
}

/* The reader's messages are "FILE:LINE:COL: what" or "PATH: cannot read:
 * why": the first ":DIGITS:DIGITS: " is the location. */
static lr_status fail_located(lr_error *err, lr_status status, const char *msg)
{
    fail(err, status, "%s%s", msg, NULL);
    if (!err)
        return status;
    for (const char *p = msg; *p; p++) {
        const char *q = p + 1;
        long line, col;
        if (*p != ':' || !isdigit((unsigned char)*q))
            continue;
        line = strtol(q, (char **)&q, 10);
        if (*q != ':' || !isdigit((unsigned char)q[1]))
            continue;
        col = strtol(q + 1, (char **)&q, 10);
        if (*q != ':' || line < 1 || col < 1 || line > 0x7fffffff || col > 0x7fffffff)
            continue;
        size_t n = (size_t)(p - msg) < sizeof err->file - 1 ? (size_t)(p - msg)
                                                              : sizeof err->file - 1;
        memcpy(err->file, msg, n);
        err->file[n] = '\0';
        err->line = (int)line;
        err->column = (int)col;
        return status;
    }
    const char *cr = strstr(msg, ": cannot read");
    if (cr) {
        size_t n = (size_t)(cr - msg) < sizeof err->file - 1 ? (size_t)(cr - msg)
                                                             : sizeof err->file - 1;
        memcpy(err->file, msg, n);
        err->file[n] = '\0';
        err->status = LR_ERROR_IO;
        return LR_ERROR_IO;
    }
    return status;
}

/* ---- scenes ------------------------------------------------------------ */

void lr_load_opts_init(lr_load_opts *opts)
{
    memset(opts, 0, sizeof *opts);
}

static lr_status load(const char *path, const char *text, const char *name,
                      const lr_load_opts *opts, lr_scene **out, lr_error *err)
{
    lr_load_opts def;
    rs_parse_opts popts;
    const char **dirs;
    char msg[MSG_MAX] = "";
    lr_scene *sc;
    int rc;

    if (!out)
        return fail(err, LR_ERROR_INVALID_ARGUMENT, "%s%s", "no place for the scene", NULL);
    *out = NULL;
    if (!opts) {
        lr_load_opts_init(&def);
        opts = &def;
    }
    if (opts->n_library_dirs > 0 && !opts->library_dirs)
        return fail(err, LR_ERROR_INVALID_ARGUMENT, "%s%s", "library_dirs is NULL", NULL);
    sc = calloc(1, sizeof *sc);
    dirs = malloc((opts->n_library_dirs + 4) * sizeof *dirs);
    if (sc)
        sc->name = malloc(strlen(path ? path : name) + 1);
    if (!sc || !dirs || !sc->name) {
        if (sc)
            free(sc->name);
        free(sc);
        free(dirs);
        return fail(err, LR_ERROR_NO_MEMORY, "%s%s", "out of memory", NULL);
    }
    strcpy(sc->name, path ? path : name);
    rs_scene_init(&sc->s);
    rs_parse_opts_init(&popts);
    popts.image_width = opts->image_width;
    popts.image_height = opts->image_height;
    popts.max_objects = opts->max_objects;
    popts.max_tokens = opts->max_tokens;
    popts.no_include = opts->no_include;
    popts.include_dirs = dirs;
    popts.n_include_dirs = rs_library_path(opts->library_dirs, opts->n_library_dirs, dirs,
                                           opts->n_library_dirs + 4);
    *out = sc;
    if (path)
        rc = rs_parse_file(path, &popts, &sc->s, msg, sizeof msg);
    else
        rc = rs_parse_string(text, name, &popts, &sc->s, msg, sizeof msg);
    free(dirs);
    if (rc != 0)
        return fail_located(err, LR_ERROR_SCENE, msg);
    if (rs_scene_prepare(&sc->s, msg, sizeof msg) != 0)
        return fail_located(err, LR_ERROR_SCENE, msg);
    sc->ok = 1;
    if (err)
        memset(err, 0, sizeof *err);
    return LR_OK;
}

lr_status lr_scene_load(const char *path, const lr_load_opts *opts, lr_scene **out,
                        lr_error *err)
{
    if (!path) {
        if (out)
            *out = NULL;
        return fail(err, LR_ERROR_INVALID_ARGUMENT, "%s%s", "no scene path", NULL);
    }
    return load(path, NULL, NULL, opts, out, err);
}

lr_status lr_scene_load_string(const char *text, const char *name, const lr_load_opts *opts,
                               lr_scene **out, lr_error *err)
{
    if (!text) {
        if (out)
            *out = NULL;
        return fail(err, LR_ERROR_INVALID_ARGUMENT, "%s%s", "no scene text", NULL);
    }
    return load(NULL, text, name ? name : "<string>", opts, out, err);
}

void lr_scene_free(lr_scene *scene)
{
    if (!scene)
        return;
    rs_scene_free(&scene->s);
    free(scene->name);
    free(scene);
}

size_t lr_scene_message_count(const lr_scene *scene)
{
    return scene ? scene->s.n_messages : 0;
}

const char *lr_scene_message(const lr_scene *scene, size_t k, lr_message_kind *kind)
{
    if (!scene || k >= scene->s.n_messages)
        return NULL;
    if (kind)
        *kind = scene->s.messages[k].kind == RS_MSG_DEBUG ? LR_MESSAGE_DEBUG
                                                          : LR_MESSAGE_WARNING;
    return scene->s.messages[k].text;
}

const rs_scene *lr_scene_description(const lr_scene *scene)
{
    return scene && scene->ok ? &scene->s : NULL;
}

lr_status lr_scene_check(const rs_scene *description, lr_error *err)
{
    char msg[MSG_MAX];
    if (rs_scene_check(description, msg, sizeof msg) != 0)
        return fail_located(err, LR_ERROR_SCENE, msg);
    if (err)
        memset(err, 0, sizeof *err);
    return LR_OK;
}

lr_status lr_camera_ray(const rs_camera *camera, int width, int height, double px, double py,
                        lp_vec3 *origin, lp_vec3 *dir, lr_error *err)
{
    rs_view v;
    char msg[MSG_MAX];
    if (!camera || !origin || !dir)
        return fail(err, LR_ERROR_INVALID_ARGUMENT, "%s%s", "NULL camera or ray", NULL);
    if (rs_camera_setup(camera, width, height, &v, msg, sizeof msg) != 0)
        return fail(err, LR_ERROR_CAMERA, "%s%s", msg, NULL);
    rs_camera_ray(&v, px, py, width, height, origin, dir);
    return LR_OK;
}

int lr_object_inside(const rs_object *object, lp_vec3 p)
{
    return rs_object_inside(object, p);
}

static rs_color clamp_nonneg(rs_color c)
{
    return (rs_color){ c.r > 0.0 ? c.r : 0.0, c.g > 0.0 ? c.g : 0.0, c.b > 0.0 ? c.b : 0.0 };
}

rs_color lr_light_rgb(const rs_light *l)
{
    rs_spectrum s = l->spectrum;
    double xyz[3] = { 0.0, 0.0, 0.0 };
    rs_color c;

    s.rgb = l->color;
    switch (s.type) {
    case RS_SPECTRUM_LINE:
        rs_spectrum_line_xyz(&s, xyz);
        break;
    case RS_SPECTRUM_BLACKBODY: {
        double norm = rs_spectrum_norm(&s);
        int n = (int)(RS_LAMBDA_MAX - RS_LAMBDA_MIN);
        for (int i = 0; i < n; i++) {
            double lambda = RS_LAMBDA_MIN + i + 0.5;
            rs_xyz_accumulate(xyz, rs_spectrum_emission_norm(&s, norm, lambda), lambda, 1.0);
        }
        break;
    }
    default:
        return l->color;
    }
    rs_xyz_to_linear_srgb(xyz, &c);
    return clamp_nonneg(c);
}

/* ---- options ----------------------------------------------------------- */

const char *lr_mode_name(lr_mode mode)
{
    switch (mode) {
    case LR_MODE_POLARIZED: return "polarized";
    case LR_MODE_FRESNEL: return "fresnel";
    case LR_MODE_SCHLICK: return "schlick";
    case LR_MODE_RGB: return "rgb";
    case LR_MODE_AUTO: return "auto";
    }
    return "unknown";
}

void lr_render_opts_init(lr_render_opts *o)
{
    memset(o, 0, sizeof *o);
    o->mode = LR_MODE_POLARIZED;
    o->width = 320;
    o->height = 240;
    o->cutoff = -1.0;
    o->aa = 1;
}

static rs_mode to_rs_mode(lr_mode m)
{
    switch (m) {
    case LR_MODE_FRESNEL: return RS_MODE_FRESNEL;
    case LR_MODE_SCHLICK: return RS_MODE_SCHLICK;
    case LR_MODE_RGB: return RS_MODE_RGB;
    default: return RS_MODE_POLARIZED;
    }
}

static lr_mode to_lr_mode(rs_mode m)
{
    switch (m) {
    case RS_MODE_FRESNEL: return LR_MODE_FRESNEL;
    case RS_MODE_SCHLICK: return LR_MODE_SCHLICK;
    case RS_MODE_RGB: return LR_MODE_RGB;
    default: return LR_MODE_POLARIZED;
    }
}

/* NULL when o is usable, else what is wrong. */
static const char *opts_problem(const lr_render_opts *o)
{
    if ((int)o->mode < LR_MODE_POLARIZED || (int)o->mode > LR_MODE_AUTO)
        return "mode is not one of the lr_mode values";
    if (o->width < 1 || o->width > LR_SIZE_MAX || o->height < 1 || o->height > LR_SIZE_MAX)
        return "width and height must be 1..16384";
    if ((long long)o->width * o->height > LR_PIXELS_MAX)
        return "width x height must be at most 64 Mi pixels";
    if (o->depth < 0 || o->depth > LR_DEPTH_MAX)
        return "depth must be 0 (the scene's) or 1..256";
    if (o->wavelengths < 0 || o->wavelengths > LR_WAVELENGTHS_MAX)
        return "wavelengths must be 0 (the default) or 1..16384";
    if (isnan(o->cutoff) || o->cutoff > 1.0)
        return "cutoff must be at most 1 (< 0: the scene's adc_bailout)";
    if (o->aa < 1 || o->aa > LR_AA_MAX)
        return "aa must be 1..16";
    if (o->threads < 0 || o->threads > LR_THREADS_MAX)
        return "threads must be 0 (every processor) or 1..1024";
    if (o->mode == LR_MODE_AUTO && o->tolerance > 0.0 &&
        !(o->tolerance >= 1e-6 && o->tolerance <= 1.0))
        return "tolerance must be 1e-6..1";
    if (isnan(o->tolerance))
        return "tolerance must be a number";
    return NULL;
}

/* ---- renderers --------------------------------------------------------- */

/* lr_renderer_description's phrase, from the settings as rendered and
 * the integrator's options (where auto refines pixels). */
static void describe(const lr_render_opts *used, const rs_render_opts *ro, char *out,
                     size_t size)
{
    char wl[96] = "";
    if (used->mode != LR_MODE_RGB && ro->refine_tol > 0.0 && ro->refine_max > used->wavelengths) {
        if (ro->refine_outlier > 0.0 && ro->refine_limit > ro->refine_max)
            snprintf(wl, sizeof wl, "%d wavelengths, refined per pixel up to %d (outliers %d), ",
                     used->wavelengths, ro->refine_max, ro->refine_limit);
        else
            snprintf(wl, sizeof wl, "%d wavelengths, refined per pixel up to %d, ",
                     used->wavelengths, ro->refine_max);
    } else if (used->mode != LR_MODE_RGB) {
        snprintf(wl, sizeof wl, "%d wavelength%s, ", used->wavelengths,
                 used->wavelengths == 1 ? "" : "s");
    }
    snprintf(out, size, "%s, %sdepth %d", lr_mode_name(used->mode), wl, used->depth);
}

lr_status lr_renderer_create(lr_scene *scene, const lr_render_opts *opts, lr_renderer **out,
                             lr_error *err)
{
    lr_render_opts def;
    rs_render_opts ro;
    rs_view view;
    char msg[MSG_MAX] = "";
    const char *bad;
    lr_renderer *r;

    if (!out)
        return fail(err, LR_ERROR_INVALID_ARGUMENT, "%s%s", "no place for the renderer", NULL);
    *out = NULL;
    if (!scene || !scene->ok)
        return fail(err, LR_ERROR_INVALID_ARGUMENT, "%s%s",
                    "the scene is NULL or did not load", NULL);
    if (!opts) {
        lr_render_opts_init(&def);
        opts = &def;
    }
    if ((bad = opts_problem(opts)) != NULL)
        return fail(err, LR_ERROR_INVALID_ARGUMENT, "%s%s", bad, NULL);
    if (opts->no_dispersion && !scene->frozen) {
        if (rs_scene_freeze_glass(&scene->s, RS_LAMBDA_D_LINE, msg, sizeof msg) != 0)
            return fail_located(err, LR_ERROR_SCENE, msg);
        scene->frozen = 1;
    }
    if (rs_camera_setup(&scene->s.camera, opts->width, opts->height, &view, msg,
                        sizeof msg) != 0)
        return fail(err, LR_ERROR_CAMERA, "%s: %s", scene->name, msg);
    r = calloc(1, sizeof *r);
    if (!r)
        return fail(err, LR_ERROR_NO_MEMORY, "%s%s", "out of memory", NULL);
    r->scene = scene;
    rs_render_opts_init(&ro);
    ro.mode = to_rs_mode(opts->mode);
    ro.depth = opts->depth;
    if (opts->wavelengths > 0)
        ro.wavelengths = opts->wavelengths;
    ro.cutoff = opts->cutoff;
    ro.width = opts->width;
    ro.height = opts->height;
    ro.aa = opts->aa;
    if (opts->mode == LR_MODE_AUTO) {
        rs_auto_request req = {opts->tolerance > 0.0 ? opts->tolerance : LR_TOLERANCE_DEFAULT,
                               opts->width, opts->height, opts->depth, opts->wavelengths,
                               opts->cutoff};
        if (rs_auto_choose(&scene->s, &req, &ro, NULL, r->why, sizeof r->why, msg,
                           sizeof msg) != 0) {
            free(r);
            return fail(err, LR_ERROR_RENDER, "%s: %s", scene->name, msg);
        }
    }
    ro.aa = opts->aa; /* antialiasing is the caller's, whatever auto chose */
    if (rs_integrator_create(&scene->s, &ro, &r->it, msg, sizeof msg) != 0) {
        free(r);
        return fail(err, LR_ERROR_RENDER, "%s: %s", scene->name, msg);
    }
    r->settings = *opts;
    r->settings.mode = to_lr_mode(ro.mode);
    r->settings.wavelengths = ro.wavelengths;
    r->settings.depth = ro.depth > 0 ? ro.depth : scene->s.settings.max_trace_level;
    r->settings.cutoff = ro.cutoff >= 0.0 ? ro.cutoff : scene->s.settings.adc_bailout;
    if (opts->tolerance <= 0.0 && opts->mode == LR_MODE_AUTO)
        r->settings.tolerance = LR_TOLERANCE_DEFAULT;
    describe(&r->settings, &ro, r->what, sizeof r->what);
    *out = r;
    if (err)
        memset(err, 0, sizeof *err);
    return LR_OK;
}

void lr_renderer_free(lr_renderer *r)
{
    if (!r)
        return;
    rs_integrator_destroy(r->it);
    free(r);
}

const char *lr_renderer_description(const lr_renderer *r)
{
    return r->what;
}

void lr_renderer_settings(const lr_renderer *r, lr_render_opts *out)
{
    *out = r->settings;
}

const char *lr_renderer_explanation(const lr_renderer *r)
{
    return r->why;
}

/* ---- rendering --------------------------------------------------------- */

/* The tiles' contexts (region_ctx, list_ctx) start with the integrator,
 * which is all worker_make reads. */
typedef struct region_ctx {
    const rs_integrator *it; /* first: worker_make */
    float *rgb;
    int x0, y0, w; /* the region's corner in the image and its width */
    atomic_llong pixels, rays, lane_rays, builds, gathered; /* the tiles' work, summed */
} region_ctx;

static void *worker_make(void *user)
{
    return rs_worker_create(*(const rs_integrator *const *)user);
}

static void worker_free(void *worker)
{
    rs_worker_destroy(worker);
}

/* Tile (x0..x1, y0..y1) of the region, in region coordinates; its work
 * (whole numbers) added to the region's. */
static void render_tile(void *user, void *worker, int x0, int y0, int x1, int y1)
{
    region_ctx *c = user;
    rs_work before, after;
    rs_worker_work(worker, &before);
    for (int j = y0; j < y1; j++)
        for (int i = x0; i < x1; i++) {
            rs_color col;
            float *px = c->rgb + 3 * ((size_t)j * (size_t)c->w + (size_t)i);
            rs_integrator_pixel(c->it, worker, c->x0 + i, c->y0 + j, &col);
            px[0] = (float)col.r;
            px[1] = (float)col.g;
            px[2] = (float)col.b;
        }
    rs_worker_work(worker, &after);
    atomic_fetch_add(&c->pixels, (long long)(x1 - x0) * (y1 - y0));
    atomic_fetch_add(&c->rays, (long long)(after.rays - before.rays));
    atomic_fetch_add(&c->lane_rays, (long long)(after.lane_rays - before.lane_rays));
    atomic_fetch_add(&c->builds, (long long)(after.builds - before.builds));
    atomic_fetch_add(&c->gathered, (long long)(after.gathered - before.gathered));
}

/* lr_status of rs_render_tiles_cb's return (err cleared on success). */
static lr_status tiles_status(int rc, lr_error *err)
{
    if (rc == -2)
        return fail(err, LR_CANCELLED, "%s%s", "the render was cancelled", NULL);
    if (rc != 0)
        return fail(err, LR_ERROR_RENDER, "%s%s",
                    "the render failed (out of memory for a worker thread)", NULL);
    if (err)
        memset(err, 0, sizeof *err);
    return LR_OK;
}

lr_status lr_render_region_work(const lr_renderer *r, int x0, int y0, int x1, int y1,
                                float *rgb, lr_progress_fn progress, void *user, lr_work *work,
                                lr_error *err)
{
    region_ctx ctx;
    int rc;
    if (work)
        memset(work, 0, sizeof *work);
    if (!r || !rgb)
        return fail(err, LR_ERROR_INVALID_ARGUMENT, "%s%s", "NULL renderer or buffer", NULL);
    if (x0 < 0 || y0 < 0 || x0 >= x1 || y0 >= y1 || x1 > r->settings.width ||
        y1 > r->settings.height)
        return fail(err, LR_ERROR_INVALID_ARGUMENT, "%s%s",
                    "the region must be a non-empty rectangle inside the image", NULL);
    ctx.it = r->it;
    ctx.rgb = rgb;
    ctx.x0 = x0;
    ctx.y0 = y0;
    ctx.w = x1 - x0;
    atomic_init(&ctx.pixels, 0);
    atomic_init(&ctx.rays, 0);
    atomic_init(&ctx.lane_rays, 0);
    atomic_init(&ctx.builds, 0);
    atomic_init(&ctx.gathered, 0);
    rc = rs_render_tiles_cb(x1 - x0, y1 - y0, TILE_SIZE, r->settings.threads, worker_make,
                            worker_free, render_tile, &ctx, progress, user);
    if (work) {
        rs_work d = {(double)atomic_load(&ctx.rays), (double)atomic_load(&ctx.lane_rays),
                     (double)atomic_load(&ctx.builds), (double)atomic_load(&ctx.gathered)};
        work->pixels = (double)atomic_load(&ctx.pixels);
        work->rays = d.rays;
        work->lane_rays = d.lane_rays;
        work->builds = d.builds;
        work->gathered = d.gathered;
        work->cost = rs_work_cost(&d, to_rs_mode(r->settings.mode), work->pixels);
    }
    return tiles_status(rc, err);
}

/* A list of pixels, laid out as a 1-pixel-high image of n columns that
 * the tiles cut into runs. */
typedef struct list_ctx {
    const rs_integrator *it; /* first, as in region_ctx (worker_make) */
    const int *xy;
    float *rgb;
} list_ctx;

static void render_list_tile(void *user, void *worker, int x0, int y0, int x1, int y1)
{
    list_ctx *c = user;
    (void)y0;
    (void)y1;
    for (int k = x0; k < x1; k++) {
        rs_color col;
        float *px = c->rgb + 3 * (size_t)k;
        rs_integrator_pixel(c->it, worker, c->xy[2 * (size_t)k], c->xy[2 * (size_t)k + 1], &col);
        px[0] = (float)col.r;
        px[1] = (float)col.g;
        px[2] = (float)col.b;
    }
}

lr_status lr_render_pixels(const lr_renderer *r, const int *xy, size_t n, float *rgb,
                           lr_progress_fn progress, void *user, lr_error *err)
{
    list_ctx ctx;
    int rc;
    if (!r || (n > 0 && (!xy || !rgb)))
        return fail(err, LR_ERROR_INVALID_ARGUMENT, "%s%s", "NULL renderer, list or buffer",
                    NULL);
    if (n > (size_t)LR_PIXELS_MAX)
        return fail(err, LR_ERROR_INVALID_ARGUMENT, "%s%s",
                    "more pixels in the list than an image has at most", NULL);
    for (size_t k = 0; k < n; k++)
        if (xy[2 * k] < 0 || xy[2 * k] >= r->settings.width || xy[2 * k + 1] < 0 ||
            xy[2 * k + 1] >= r->settings.height)
            return fail(err, LR_ERROR_INVALID_ARGUMENT, "%s%s",
                        "a pixel of the list is outside the image", NULL);
    if (n == 0) {
        if (err)
            memset(err, 0, sizeof *err);
        return LR_OK;
    }
    ctx.it = r->it;
    ctx.xy = xy;
    ctx.rgb = rgb;
    /* the list as one row of n <= LR_PIXELS_MAX columns */
    rc = rs_render_tiles_cb((int)n, 1, TILE_SIZE, r->settings.threads, worker_make,
                            worker_free, render_list_tile, &ctx, progress, user);
    return tiles_status(rc, err);
}

lr_status lr_render_region(const lr_renderer *r, int x0, int y0, int x1, int y1, float *rgb,
                           lr_progress_fn progress, void *user, lr_error *err)
{
    return lr_render_region_work(r, x0, y0, x1, y1, rgb, progress, user, NULL, err);
}

lr_status lr_render_image(const lr_renderer *r, float *rgb, lr_progress_fn progress, void *user,
                          lr_error *err)
{
    if (!r)
        return fail(err, LR_ERROR_INVALID_ARGUMENT, "%s%s", "NULL renderer", NULL);
    return lr_render_region(r, 0, 0, r->settings.width, r->settings.height, rgb, progress, user,
                            err);
}
