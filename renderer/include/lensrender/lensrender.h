/*
 * lensrender.h -- the renderer's public face: read a .scene file, choose
 * how to render it, render the image or any rectangle of it.
 *
 * A program that renders scenes (the lensrender command, an MPI driver,
 * the POV-Ray comparison) uses this header, lensrender/scene.h (the
 * scene as read, to look at) and the support floor; nothing else of the
 * renderer.
 *
 * CONVENTIONS
 *
 *   Pixels       column i = 0..width-1 from the left, row j = 0..height-1
 *                from the top.  A buffer of pixels is float linear sRGB
 *                (D65), three floats per pixel, rows top to bottom, no
 *                padding: pixel (i, j) of a w-wide buffer starts at
 *                rgb[3 * (j * w + i)].  An rs_image (support/image.h) is
 *                such a buffer.
 *   Units        lengths in millimetres, wavelengths in nanometres in
 *                standard air (as glass catalogs and the CIE tables give
 *                them).
 *   Determinism  the value of pixel (i, j) depends only on the scene, the
 *                render options and (i, j): never on the region it is
 *                rendered in, the number of threads, which thread renders
 *                it or in what order.  There are no random numbers.  So an
 *                image cut into regions in any way, rendered region by
 *                region (in one process or in many, with any thread
 *                counts) and put together, is byte for byte the image
 *                lr_render_image gives.
 *   Threads      a prepared lr_renderer is immutable: any number of
 *                threads may render from one at once.  An lr_scene must
 *                not change while a renderer made from it exists.
 *
 * ERRORS
 *
 *   Functions that can fail return an lr_status (LR_OK == 0) and, when
 *   the caller passes a non-NULL lr_error, fill it: the status, a one-line
 *   message (no newline), and where the problem was written when it comes
 *   from a file (file, line, column, 1-based; column counts bytes).  The
 *   message of a scene error is "FILE:LINE:COL: what", e.g.
 *   "box.scene:3:14: expected '{' after 'sphere', found number 1".  The
 *   library never prints and never exits: warnings, #debug text and the
 *   automatic mode's explanation are handed back as strings for the
 *   driver to print.
 */
#ifndef LENSRENDER_H
#define LENSRENDER_H

#include <stddef.h>

#include "lensprim.h"
#include "lensrender/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------ */
/* Status and errors                                                   */
/* ------------------------------------------------------------------ */

/* The values are fixed: a program may store or print them. */
typedef enum lr_status {
    LR_OK = 0,
    LR_ERROR_INVALID_ARGUMENT = 1, /* NULL, a size out of range, a bad option */
    LR_ERROR_IO = 2,               /* a file could not be read */
    LR_ERROR_SCENE = 3,            /* the scene file is wrong (with its location) */
    LR_ERROR_CAMERA = 4,           /* the camera cannot make rays for this image */
    LR_ERROR_NO_MEMORY = 5,
    LR_ERROR_RENDER = 6,           /* a render could not run (a worker thread) */
    LR_CANCELLED = 7               /* the progress callback asked to stop */
} lr_status;

#define LR_MESSAGE_MAX 1024
#define LR_FILE_MAX 1024

/* A status, a message and, when known, where in which file.  message
 * and file are always NUL-terminated; file is "" and line = column = 0
 * when the problem has no place in a file (a camera, a thread).  A file
 * that cannot be read gives its path in file and line 0. */
typedef struct lr_error {
    lr_status status;
    char message[LR_MESSAGE_MAX];
    char file[LR_FILE_MAX];
    int line, column;
} lr_error;

/* A static English string for a status; never NULL. */
const char *lr_status_string(lr_status status);

/* ------------------------------------------------------------------ */
/* Scenes                                                              */
/* ------------------------------------------------------------------ */

typedef struct lr_scene lr_scene;

/* How a scene is read. */
typedef struct lr_load_opts {
    /* The values of image_width and image_height in the scene (POV-Ray's
     * keywords); <= 0: 640 and 480.  Give the size you will render. */
    int image_width, image_height;
    /* Where #include looks after the including file's own directory, in
     * order (POV-Ray's Library_Path), before the defaults: POV-Ray 3.7's
     * installed include directory and the installed share/lensprim (with
     * lens.inc), each when it exists.  The caller owns the strings; they
     * are only read during the load. */
    const char *const *library_dirs;
    size_t n_library_dirs;
    /* Nonzero: #include is refused ("include files are off") and no file
     * is opened (for text from an untrusted source). */
    int no_include;
    /* Objects and lights allowed; 0: 100,000. */
    size_t max_objects;
    /* Tokens the whole read may take, loop bodies and macro calls counted
     * each time (an endless #while ends with an error); 0: 20,000,000. */
    unsigned long long max_tokens;
} lr_load_opts;

/* All zero: the defaults above. */
void lr_load_opts_init(lr_load_opts *opts);

/* Read the scene file at path (opts NULL: the defaults), check every rule
 * of the scene where it is read, and create its lenses.  *out is set in
 * every case but out of memory (then NULL): on failure it holds what was
 * read before the error, so that its messages can be printed, and cannot
 * be rendered; release it with lr_scene_free whatever the status.
 * Returns LR_OK, LR_ERROR_IO (the file or an included one cannot be
 * read), LR_ERROR_SCENE (with file, line and column), LR_ERROR_NO_MEMORY
 * or LR_ERROR_INVALID_ARGUMENT (path or out NULL). */
lr_status lr_scene_load(const char *path, const lr_load_opts *opts, lr_scene **out,
                        lr_error *err);

/* The same from NUL-terminated text; name (NULL: "<string>") is the file
 * name in locations and the directory #include starts from is the
 * current one. */
lr_status lr_scene_load_string(const char *text, const char *name, const lr_load_opts *opts,
                               lr_scene **out, lr_error *err);

/* Release a scene (NULL is allowed).  No renderer made from it may be
 * used afterwards. */
void lr_scene_free(lr_scene *scene);

/* What the reader says besides errors, in the order written. */
typedef enum lr_message_kind {
    LR_MESSAGE_WARNING = 0, /* one line, "FILE:LINE:COL: warning: ...", no newline:
                               what is read but not rendered, #warning, no objects */
    LR_MESSAGE_DEBUG = 1    /* #debug's text as written (newlines included) */
} lr_message_kind;

/* The number of messages, and message k (0 <= k < count; NULL past the
 * end); *kind (may be NULL) gets its kind.  The text belongs to the scene. */
size_t lr_scene_message_count(const lr_scene *scene);
const char *lr_scene_message(const lr_scene *scene, size_t k, lr_message_kind *kind);

/* The scene as read, to look at (lensrender/scene.h): the camera, lights
 * and objects with the parameters as written, after the checks, with the
 * lenses created.  Read only; it lives as long as the scene.  NULL for a
 * scene that failed to load. */
const rs_scene *lr_scene_description(const lr_scene *scene);

/* The rules every scene description obeys (rs_scene_check in
 * lensrender/scene.h: finite numbers, unit normals, positive sizes, lenses
 * that can exist).  Every description lr_scene_load gives obeys them; a
 * program that builds or changes a description calls this before using
 * it.  Returns LR_OK, or LR_ERROR_SCENE with the first broken rule and,
 * for an object or light, its file, line and column. */
lr_status lr_scene_check(const rs_scene *description, lr_error *err);

/* The primary ray through image point (px, py) (pixel centres at i + 0.5,
 * j + 0.5) of a width x height image, with POV-Ray's camera rules
 * (lensrender/scene.h): *origin, and *dir a unit vector.  Returns LR_OK,
 * or LR_ERROR_CAMERA with a message when this camera cannot make rays for
 * that image (*origin and *dir untouched). */
lr_status lr_camera_ray(const rs_camera *camera, int width, int height, double px, double py,
                        lp_vec3 *origin, lp_vec3 *dir, lr_error *err);

/* Nonzero when the world point p is inside the object as the renderer
 * sees it: the primitives with an inside (plane, sphere, box, cylinder,
 * cone, torus) and CSG objects, `inverse` swapping inside and outside;
 * discs, lenses and polarizers have no inside (0). */
int lr_object_inside(const rs_object *object, lp_vec3 p);

/* The RGB colour of a light for a renderer without spectra: its colour
 * for an RGB spectrum; for a line, the linear sRGB of the line exactly as
 * the spectral modes add it; for a black body, the linear sRGB of its
 * spectrum integrated at 1 nm over 380-780 nm (each with Y = the
 * luminance of the light's colour); negative components (colours outside
 * the sRGB gamut) clipped to 0. */
rs_color lr_light_rgb(const rs_light *light);

/* ------------------------------------------------------------------ */
/* Render options                                                      */
/* ------------------------------------------------------------------ */

typedef enum lr_mode {
    LR_MODE_POLARIZED = 0, /* spectral, polarization through every interface,
                              coherent sources add as amplitudes */
    LR_MODE_FRESNEL = 1,   /* spectral, unpolarized Fresnel (POV-Ray's model) */
    LR_MODE_SCHLICK = 2,   /* spectral, Schlick's approximation */
    LR_MODE_RGB = 3,       /* three colour channels, unpolarized */
    LR_MODE_AUTO = 4       /* the model, wavelengths, depth and cut-off that
                              keep the error within the tolerance at the
                              least cost, chosen by lr_renderer_create;
                              and, where it costs less, more wavelengths
                              for the pixels whose spectrum a dispersive
                              lens makes step (each pixel still what a
                              render at its own count gives it) */
} lr_mode;

/* The option name of a mode: "polarized", "fresnel", "schlick", "rgb",
 * "auto"; "unknown" otherwise. */
const char *lr_mode_name(lr_mode mode);

#define LR_TOLERANCE_DEFAULT 1e-3
#define LR_SIZE_MAX 16384            /* width, height */
#define LR_PIXELS_MAX (64LL * 1024 * 1024) /* width * height */
#define LR_DEPTH_MAX 256
#define LR_WAVELENGTHS_MAX 16384
#define LR_AA_MAX 16
#define LR_THREADS_MAX 1024

typedef struct lr_render_opts {
    lr_mode mode;      /* default LR_MODE_POLARIZED */
    double tolerance;  /* LR_MODE_AUTO: the RMSE of linear RGB allowed against
                          a converged polarized render, 1e-6..1; <= 0:
                          LR_TOLERANCE_DEFAULT */
    int width, height; /* the image, 1..LR_SIZE_MAX each, at most
                          LR_PIXELS_MAX pixels; default 320 x 240 */
    int depth;         /* max trace level 1..LR_DEPTH_MAX; 0 (default): the
                          scene's max_trace_level, or auto's choice */
    int wavelengths;   /* spectral samples per pixel 1..LR_WAVELENGTHS_MAX;
                          0 (default): 16, or auto's choice */
    double cutoff;     /* drop branches whose weight is below this, 0..1;
                          < 0 (default): the scene's adc_bailout, or auto's
                          choice */
    int aa;            /* N x N regular samples per pixel, 1..LR_AA_MAX
                          (default 1); auto never changes it */
    int no_dispersion; /* nonzero: every glass becomes a constant lossless
                          index, its index at 587.5618 nm (to compare with
                          renderers without dispersion).  The first renderer
                          that asks for it changes the scene's lenses for
                          good (the description and every later renderer see
                          the constant indices): ask for it before any other
                          renderer of the scene is made. */
    int threads;       /* worker threads 1..LR_THREADS_MAX; 0 (default):
                          every online processor */
} lr_render_opts;

/* The defaults above. */
void lr_render_opts_init(lr_render_opts *opts);

/* ------------------------------------------------------------------ */
/* Renderers                                                           */
/* ------------------------------------------------------------------ */

typedef struct lr_renderer lr_renderer;

/* Prepare to render a loaded scene with opts (NULL: the defaults): check
 * the options (LR_ERROR_INVALID_ARGUMENT names the one out of range),
 * apply no_dispersion, set up the camera for the image
 * (LR_ERROR_CAMERA), and for LR_MODE_AUTO probe the scene and choose
 * (this takes a fraction of a render).  The scene must stay alive and
 * unchanged while the renderer exists. */
lr_status lr_renderer_create(lr_scene *scene, const lr_render_opts *opts, lr_renderer **out,
                             lr_error *err);

/* Release a renderer (NULL is allowed). */
void lr_renderer_free(lr_renderer *renderer);

/* The options the renderer renders with: those given, with auto's
 * choice of mode (never LR_MODE_AUTO), wavelengths, depth and cut-off,
 * and the scene's depth and cut-off where 0 and < 0 asked for them.
 * Where auto refines pixels (its explanation says so), wavelengths is
 * the count every pixel starts with. */
void lr_renderer_settings(const lr_renderer *renderer, lr_render_opts *out);

/* For LR_MODE_AUTO, one line (no newline) saying what was chosen and
 * why; "" for the other modes.  Belongs to the renderer. */
const char *lr_renderer_explanation(const lr_renderer *renderer);

/* What the renderer renders with, in a few words (no newline), for a
 * driver's last line: "polarized, 16 wavelengths, depth 5"; "rgb,
 * depth 8" (rgb has no wavelengths); where auto refines pixels "polarized,
 * 4 wavelengths, refined per pixel up to 1024 (outliers 16384), depth 8".
 * Belongs to the renderer. */
const char *lr_renderer_description(const lr_renderer *renderer);

/* Progress, called from the calling thread only (never concurrently):
 * done pixels of total in this render so far, about 10 times a second
 * and once when every pixel is done.  Return 0 to go on; nonzero cancels:
 * no more tiles are started, and the render returns LR_CANCELLED with
 * the buffer partly written. */
typedef int (*lr_progress_fn)(void *user, long long done, long long total);

/* Render the whole image into rgb (3 * width * height floats, the
 * conventions above) on the renderer's threads.  progress may be NULL.
 * Returns LR_OK, LR_CANCELLED, LR_ERROR_RENDER (a worker could not be
 * made) or LR_ERROR_INVALID_ARGUMENT. */
lr_status lr_render_image(const lr_renderer *renderer, float *rgb, lr_progress_fn progress,
                          void *user, lr_error *err);

/* Render the pixels x0 <= i < x1, y0 <= j < y1 of the image (0 <= x0 <
 * x1 <= width, 0 <= y0 < y1 <= height) into rgb, a (x1 - x0) x (y1 - y0)
 * buffer: pixel (i, j) at rgb[3 * ((j - y0) * (x1 - x0) + (i - x0))].
 * Each value is bit for bit what lr_render_image gives for that pixel
 * (see Determinism).  Threads, progress (counting this region's pixels)
 * and returns as lr_render_image. */
lr_status lr_render_region(const lr_renderer *renderer, int x0, int y0, int x1, int y1,
                           float *rgb, lr_progress_fn progress, void *user, lr_error *err);

/* (Revision 2) Render a list of n pixels of the image, pixel k at
 * (xy[2k], xy[2k + 1]) (0 <= x < width, 0 <= y < height; in any order,
 * repeats allowed), into rgb[3k .. 3k + 2]: each value bit for bit what
 * lr_render_image gives for that pixel.  For adaptive sampling, which
 * goes back to a few scattered pixels at a time: the workers (whose
 * buffers grow with the wavelengths) are made once for the list, not
 * once per rectangle.  Threads, progress (counting the list's pixels)
 * and returns as lr_render_image; n == 0 is allowed and renders nothing;
 * a pixel outside the image is LR_ERROR_INVALID_ARGUMENT, before any is
 * rendered. */
lr_status lr_render_pixels(const lr_renderer *renderer, const int *xy, size_t n, float *rgb,
                           lr_progress_fn progress, void *user, lr_error *err);

/* What a render did: counts that depend only on the scene, the options
 * and the pixels rendered (never on the machine, its load, the threads or
 * the order), each a whole number, and the price the automatic mode puts
 * on them.  A measure of cost for benchmarks and for choosing settings. */
typedef struct lr_work {
    double pixels;    /* pixels rendered */
    double rays;      /* rays traced: each a scene intersection and the
                         shading or lens hit there */
    double lane_rays; /* the spectral lanes those rays carried, summed */
    double builds;    /* lens hits' backward builds (one per sub-packet of
                         equal optics) */
    double gathered;  /* rays gathered back through lenses (polarized),
                         but for those whose power alone is gathered
                         (at the camera ray's hit of a dispersive lens
                         where nothing interferes: about a
                         multiplication each) */
    double cost;      /* the automatic mode's price of these counts in the
                         mode rendered: a linear model of them in
                         instructions of this renderer, fitted to
                         callgrind's counts by bench/work_cost_fit.sh */
} lr_work;

/* lr_render_region that also sets *work (when not NULL) to what it did:
 * the sums over the region's pixels (those rendered, when cancelled).
 * The same for any number of threads. */
lr_status lr_render_region_work(const lr_renderer *renderer, int x0, int y0, int x1, int y1,
                                float *rgb, lr_progress_fn progress, void *user,
                                lr_work *work, lr_error *err);

#ifdef __cplusplus
}
#endif

#endif
