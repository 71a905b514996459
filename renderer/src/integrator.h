/* integrator.h -- Whitted-style backward tracing of a scene with lenses
 * as single primitives, in four light models (renderer-internal).
 *
 * A pixel's value is linear sRGB (D65).  Wavelengths are in standard air
 * (as the CIE tables and glass catalogs give them).  Spectral modes sample
 * `wavelengths` wavelengths over 380-780 nm (the midpoints of cells that
 * keep out of the steps of Smits' spectra, each weighted by its cell's
 * width: quadrature.h; noise-free, the same for every pixel) plus the line
 * wavelengths of monochromatic lights, weight them with the CIE 1931
 * 2-degree observer to XYZ (normalized so that a white emitter renders
 * exactly white) and convert to linear sRGB. */
#ifndef RS_INTEGRATOR_H
#define RS_INTEGRATOR_H

#include <math.h>
#include <stddef.h>

#include "scene.h"

typedef enum rs_mode {
    RS_MODE_POLARIZED = 0,
    RS_MODE_FRESNEL,
    RS_MODE_SCHLICK,
    RS_MODE_RGB
} rs_mode;

typedef struct rs_render_opts {
    rs_mode mode;
    int depth;         /* max trace level; <= 0: the scene's max_trace_level */
    int wavelengths;   /* spectral samples per pixel, default 16 */
    double cutoff;     /* drop branches whose weight bound is below this;
                          < 0: the scene's adc_bailout */
    int width, height;
    int aa;            /* N x N regular samples per pixel at the centres
                          of an N x N grid, averaged (default 1) */
    /* Refinement of the wavelengths per pixel (spectral modes; auto sets
     * it): a pixel whose spectral packet split at a dispersive lens (its
     * lanes went different ways: its spectrum may have steps, whose error
     * falls only as 1/N) is rendered again at twice the wavelengths, and
     * again, until two doublings in a row change no channel by more than
     * refine_tol, or at refine_max wavelengths; it takes the last
     * render's value, bit for bit what a render at that count gives it.
     * refine_tol <= 0 (default): off.  Past refine_max a pixel whose
     * last doubling still changed some channel by more than
     * refine_outlier (> 0) goes on doubling, up to refine_limit: a pixel
     * that alone would take a noticeable share of the image's error (a
     * bright light seen through a dispersive lens: a step of its size in
     * the spectrum). */
    double refine_tol;
    int refine_max;
    double refine_outlier;
    int refine_limit;
} rs_render_opts;

void rs_render_opts_init(rs_render_opts *o);

typedef struct rs_integrator rs_integrator;
typedef struct rs_worker rs_worker; /* per-thread scratch */

/* The scene must outlive the integrator and stay unchanged.  Returns 0, or
 * -1 with a message. */
int rs_integrator_create(const rs_scene *scene, const rs_render_opts *opts,
                         rs_integrator **out, char *msg, size_t msg_size);
void rs_integrator_destroy(rs_integrator *it);

rs_worker *rs_worker_create(const rs_integrator *it);
void rs_worker_destroy(rs_worker *w);

/* Linear sRGB of pixel (i, j), i = column from the left, j = row from the
 * top: the mean of its aa x aa points (antialiasing), each what its camera
 * ray brings, or with a camera aperture the mean of its aperture rays
 * (camera.h).  Deterministic for a given scene, options and pixel (no
 * random numbers, whatever thread renders it). */
void rs_integrator_pixel(const rs_integrator *it, rs_worker *w, int i, int j,
                         rs_color *out);

/* What a worker has traced since it was created: a measure of cost that
 * does not depend on the machine or its load (the automatic mode prices
 * its candidates with it).  rays: rays traced (each a scene intersection
 * and the shading or lens hit there); lane_rays: the lanes they carried,
 * summed; builds: lens hits' backward builds (one per sub-packet of equal
 * optics); gathered: rays gathered back through lenses (polarized). */
typedef struct rs_work {
    double rays, lane_rays, builds, gathered;
} rs_work;

void rs_worker_work(const rs_worker *w, rs_work *out);

/* The refinement's rule (rs_render_opts.refine_tol), one definition for
 * the integrator and for auto's replay of it: a doubling's change is the
 * pixel's largest channel difference; calm counts the doublings in a row
 * that changed it by at most the tolerance (a NaN change breaks the row),
 * and the pixel stops at RS_REFINE_CALM of them. */
#define RS_REFINE_CALM 2

static inline double rs_refine_change(rs_color a, rs_color b)
{
    double dr = a.r - b.r, dg = a.g - b.g, db = a.b - b.b;
    return fmax(fabs(dr), fmax(fabs(dg), fabs(db)));
}

static inline int rs_refine_calm(int calm, double change, double tol)
{
    return change > tol || change != change ? 0 : calm + 1;
}

/* How many lens hits of the worker's so far split a spectral packet
 * (lanes of different optics there: a dispersive lens).  A pixel whose
 * render leaves it unchanged has a spectrum without the steps that lanes
 * going different ways make.  The refinement's own renders not counted. */
unsigned long long rs_worker_splits(const rs_worker *w);

/* The cost of work w done on `pixels` pixels in a mode, in instructions
 * of this renderer: per mode a linear fit (non-negative least squares of
 * the relative error) of callgrind's counts of the pixels of 560 renders
 * (14 shipped scenes, every mode, 4-64 wavelengths, depth 4 and 16,
 * cut-off 1e-3 and 1e-6, 24 x 18 pixels, 12 x 9 for the 3 slowest, one
 * thread), 0.06-1.48 times the count, 34 % RMS.  What the counters miss
 * is mostly a scene's own: its intersections' and its lens builds' cost
 * (the geometric mean of predicted / count is 0.14 on michel_levy's
 * crystal, 0.46 on machined_parts' CSG, 0.58-1.29 on the others); divided
 * by that factor, which auto's comparisons of one scene's settings do not
 * see, 0.42-1.60 times the count, 15.5 % RMS.  bench/work_cost_fit.sh
 * reproduces the fit and prints this function's body.
 * Deterministic: it prices what a render will cost on any machine. */
double rs_work_cost(const rs_work *w, rs_mode mode, double pixels);

#endif
