/*
 * lensprim.h -- a lens as ONE scene primitive for polarized ray tracing.
 *
 * A lens is a homogeneous isotropic glass volume bounded by two caps
 * (spherical or flat) and an opaque rim (cylinder, or cone when the cap
 * diameters differ).  lensprim turns one incoming linearly polarized ray
 * into all its outgoing rays by Fresnel's equations at every node
 * (forward, from the light), or builds the query rays of a view ray and
 * gathers the bundles the application answers with (backward, from the
 * eye).  The model is Debelov & Kushner, "Lens model to process linear
 * polarized light"; where the paper and physics disagree, physics wins.
 *
 * CONVENTIONS (stated once, valid for the whole API)
 *
 *   Units        lengths in millimetres, wavelengths in nanometres,
 *                angles and phases in radians, absorption in 1/mm.
 *   Wavelengths  are in standard air, and every index (glass, medium) is
 *                relative to standard air, as glass makers' catalogs and
 *                the CIE tables give them; the default medium n = 1 is
 *                air.  In that frame Phi below is exact.  A vacuum
 *                wavelength l0 is l0 / lp_air_index(l0) in air, and the
 *                absolute optical path is lp_air_index(l0) * op.
 *   Lens frame   local axis +z, front vertex at the origin, back vertex at
 *                z = thickness.  The lens is placed in the world by the
 *                world position of its front vertex and the world
 *                direction of its local +z axis (a lens is rotationally
 *                symmetric, so nothing else is needed).
 *   Radii        optics sign convention: R > 0 means the centre of
 *                curvature lies at +z of the vertex.  A biconvex lens has
 *                radius1 > 0 and radius2 < 0.  0 or +-INFINITY is flat.
 *   Polarization a ray is fully linearly polarized: its electric field is
 *                E = sqrt(I) * vp * exp(i*Phi) with the total phase
 *                      Phi = 2*pi*op/lambda - pi*kphi + phase
 *                (time dependence exp(-i*omega*t), so propagation adds
 *                +2*pi*n*s/lambda).  Rays with the same `ch` are mutually
 *                coherent and may be added as such complex amplitudes.
 *   Phase jumps  a reflection adds 1 to kphi when the reflected field
 *                points against the mirror image of the incident field
 *                (Born & Wolf amplitudes).  For s light that is every
 *                external reflection (n1 < n2) and no internal one; for p
 *                light it is the paper's rule: n1 < n2 below Brewster's
 *                angle, n1 > n2 above it.  Refraction keeps the phase.
 *   TIR          beyond the critical angle s and p get different phase
 *                shifts; the light becomes elliptical.  lensprim then
 *                emits it as two coherent linear rays (part 0 and 1)
 *                along the axes of the polarization ellipse, each with
 *                its own `phase`.  Their amplitudes add to the exact field.
 *   Crystals     in a lens of a uniaxial crystal every node splits the
 *                light inside into an ordinary and an extraordinary ray
 *                (up to four rays per node: two reflected, two
 *                transmitted, the two on the isotropic side leaving as
 *                one field), so the rays inside form a tree; op adds
 *                K . s for each segment s (K the wave vector in units of
 *                2 pi / lambda: n_o s for the o-ray, n(psi) cos(walk-off)
 *                s for the e-ray).  The amplitudes at a crystal's surfaces
 *                are complex and carried in vp and phase; kphi counts no
 *                jumps there.  The o and e rays split from one ray keep
 *                its ch: they are mutually coherent.  The modes fresnel
 *                and schlick are laws of isotropic glass: a crystal is
 *                always traced with the polarized law.
 *   Depth        counts interface interactions along a path: the external
 *                reflection has depth 1, a ray straight through depth 2.
 *
 * ERRORS
 *
 *   Functions that can fail return an lp_status (LP_OK == 0) and, when the
 *   caller passes a non-NULL lp_error, fill it with the status and a
 *   one-line message naming the problem.  The library never prints, never
 *   exits and has no global mutable state.  A created lens is immutable:
 *   any number of threads may trace through one const lp_lens at once,
 *   each with its own lp_result / lp_backward.
 */
#ifndef LENSPRIM_H
#define LENSPRIM_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(_WIN32) && defined(LENSPRIM_SHARED)
#  ifdef LENSPRIM_BUILDING
#    define LP_API __declspec(dllexport)
#  else
#    define LP_API __declspec(dllimport)
#  endif
#elif defined(__GNUC__)
#  define LP_API __attribute__((visibility("default")))
#else
#  define LP_API
#endif

/* The version of this header (the build reads it from here).  A program
 * can compare it with the library it runs with, lp_version_number(). */
#define LP_VERSION_MAJOR 0
#define LP_VERSION_MINOR 1
#define LP_VERSION_PATCH 0
#define LP_VERSION_NUMBER \
    (LP_VERSION_MAJOR * 10000 + LP_VERSION_MINOR * 100 + LP_VERSION_PATCH)

/* The library's version as MAJOR * 10000 + MINOR * 100 + PATCH (so 0.1.0
 * is 100), and as the string "MAJOR.MINOR.PATCH" (static, never NULL). */
LP_API int lp_version_number(void);
LP_API const char *lp_version_string(void);

/* ------------------------------------------------------------------ */
/* Status                                                              */
/* ------------------------------------------------------------------ */

/* The values are fixed: a program may store or print them. */
typedef enum lp_status {
    LP_OK = 0,
    LP_ERROR_INVALID_ARGUMENT = 1, /* NULL where not allowed, NaN, zero vector, ... */
    LP_ERROR_INVALID_LENS = 2,     /* a lens shape that cannot exist */
    LP_ERROR_INVALID_GLASS = 3,    /* a glass description that cannot be used */
    LP_ERROR_UNKNOWN_GLASS = 4,    /* no glass of that name in the catalog */
    LP_ERROR_UNSUPPORTED = 5,      /* e.g. an AGF dispersion formula lensprim cannot evaluate */
    LP_ERROR_PARSE = 6,            /* malformed catalog text */
    LP_ERROR_IO = 7,               /* a file could not be read */
    LP_ERROR_NO_MEMORY = 8,
    LP_ERROR_RANGE = 9             /* an index out of range */
} lp_status;

/* A status and a message.  message is always NUL-terminated. */
typedef struct lp_error {
    lp_status status;
    char message[256];
} lp_error;

/* A static English string for a status; never NULL (unknown codes give
 * "unknown status"). */
LP_API const char *lp_status_string(lp_status status);

/* ------------------------------------------------------------------ */
/* Small values                                                        */
/* ------------------------------------------------------------------ */

typedef struct lp_vec3 {
    double x, y, z;
} lp_vec3;

/* Refractive index of standard dry air (Edlen 1966: 15 degC, 101325 Pa)
 * at a vacuum wavelength, 160 nm and up; NaN outside. */
LP_API double lp_air_index(double lambda_vacuum_nm);

/* ------------------------------------------------------------------ */
/* Glass                                                               */
/* ------------------------------------------------------------------ */

/* Dispersion formulas.  lambda below is in MICROMETRES, as glass makers
 * publish the coefficients; the API takes nanometres and converts.
 *   CONSTANT   n = coef[0]
 *   SELLMEIER  n^2 = 1 + sum_{k=0..2} coef[k]*l^2 / (l^2 - coef[3+k])
 *              (Schott form: B1 B2 B3 C1 C2 C3, C in um^2)
 *   SCHOTT     n^2 = a0 + a1 l^2 + a2 l^-2 + a3 l^-4 + a4 l^-6 + a5 l^-8
 *   CAUCHY     n = A + B/l^2 + C/l^4                      (coef A B C)
 *   CONRADY    n = n0 + A/l + B/l^3.5                     (coef n0 A B) */
typedef enum lp_formula {
    LP_FORMULA_CONSTANT = 0,
    LP_FORMULA_SELLMEIER,
    LP_FORMULA_SCHOTT,
    LP_FORMULA_CAUCHY,
    LP_FORMULA_CONRADY,
    LP_FORMULA_UNSUPPORTED /* read from a catalog, cannot be evaluated */
} lp_formula;

#define LP_GLASS_NAME_MAX 32
#define LP_GLASS_TABLE_MAX 48

/* A glass is plain data: n(lambda) by a formula and the internal
 * transmittance tau(lambda) of a sample of thickness tau_thickness_mm,
 * which gives the absorption coefficient alpha = -ln(tau)/thickness.
 * n_tau == 0 means no absorption.  lambda_min_nm/lambda_max_nm is the
 * range where the maker's data hold (0, 0: unbounded); outside it the
 * formula is extrapolated and traces report LP_WARN_EXTRAPOLATED. */
typedef struct lp_glass {
    char name[LP_GLASS_NAME_MAX];
    lp_formula formula;
    int agf_formula;          /* the AGF formula number it came from, or 0 */
    double coef[10];
    double lambda_min_nm, lambda_max_nm;
    int n_tau;
    double tau_lambda_nm[LP_GLASS_TABLE_MAX]; /* strictly increasing */
    double tau[LP_GLASS_TABLE_MAX];           /* in (0, 1] */
    double tau_thickness_mm;
} lp_glass;

/* Fill *glass with a constant, lossless index n (named "n=<n>"). */
LP_API void lp_glass_init_constant(lp_glass *glass, double n);

/* Fill *glass with a lossless 3-term Sellmeier glass (Schott form, C in
 * um^2), valid over 380-780 nm unless the caller widens the range. */
LP_API void lp_glass_init_sellmeier(lp_glass *glass, const char *name,
                                    const double b[3], const double c[3]);

/* Check that a glass can be used: a supported formula, finite
 * coefficients, n >= 1e-3 and finite over its range (380-780 nm when the
 * range is unbounded), a valid transmittance table. */
LP_API lp_status lp_glass_check(const lp_glass *glass, lp_error *err);

/* Refractive index relative to air at a wavelength in air (see the
 * conventions above); NaN for an unsupported formula
 * or a wavelength <= 0.  No range check: see lp_glass_covers. */
LP_API double lp_glass_index(const lp_glass *glass, double lambda_nm);

/* Absorption coefficient alpha(lambda) in 1/mm (0 for no table).  The
 * table is interpolated linearly in ln(tau) and held constant past its
 * ends. */
LP_API double lp_glass_absorption(const lp_glass *glass, double lambda_nm);

/* 1 when lambda_nm lies inside the glass's data range (or the range is
 * unbounded), else 0. */
LP_API int lp_glass_covers(const lp_glass *glass, double lambda_nm);

/* Copy the built-in catalog glass `name` (case-insensitive; e.g. "N-BK7",
 * "N-SF11", "F2", "N-BAK4", "N-SF6", "FUSED-SILICA", "CAF2") into *out. */
LP_API lp_status lp_glass_builtin(const char *name, lp_glass *out,
                                  lp_error *err);

/* A catalog: the built-in glasses plus any loaded from Zemax AGF files. */
typedef struct lp_catalog lp_catalog;

LP_API lp_status lp_catalog_create(lp_catalog **out, lp_error *err);
LP_API void lp_catalog_destroy(lp_catalog *catalog); /* NULL: no-op */

/* Load glasses from an AGF file (NM, CD, LD, IT lines are read; ED, TD,
 * OD, GC, CC, BD lines are skipped).  UTF-8/ASCII and UTF-16 (with BOM)
 * files are accepted.  A later glass of the same name replaces an earlier
 * one.  On error nothing is added. */
LP_API lp_status lp_catalog_load_agf(lp_catalog *catalog, const char *path,
                                     lp_error *err);
/* The same from text in memory (len bytes). */
LP_API lp_status lp_catalog_load_agf_text(lp_catalog *catalog,
                                          const char *text, size_t len,
                                          lp_error *err);

/* Find a glass by name (case-insensitive).  LP_ERROR_UNKNOWN_GLASS if
 * absent; LP_ERROR_UNSUPPORTED if its dispersion formula cannot be
 * evaluated. */
LP_API lp_status lp_catalog_find(const lp_catalog *catalog, const char *name,
                                 lp_glass *out, lp_error *err);

LP_API size_t lp_catalog_count(const lp_catalog *catalog);
/* The name of glass i (0 <= i < count), or NULL. */
LP_API const char *lp_catalog_name(const lp_catalog *catalog, size_t i);

/* ------------------------------------------------------------------ */
/* Uniaxial crystals                                                   */
/* ------------------------------------------------------------------ */

/* A uniaxial crystal: an ordinary index n_o(lambda) and an extraordinary
 * index n_e(lambda), each a glass (dispersion formula, and the
 * absorption of the wave with its field across / along the optic axis),
 * and the optic axis as a WORLD direction (any finite non-zero vector;
 * the lens normalizes it; a lens at the origin along +z, as lenstrace
 * has it, has its local frame equal to the world's).  A wave whose normal makes the angle
 * psi with the axis has two modes: the ordinary wave of index n_o, field
 * perpendicular to the plane (wave normal, axis), ray along the normal;
 * and the extraordinary wave of index n(psi), 1/n^2 = cos^2(psi)/n_o^2 +
 * sin^2(psi)/n_e^2, field in that plane, ray off the normal by the
 * walk-off angle.  The e-wave's absorption is, to first order in the
 * absorption, n(psi)^3 (cos^2 psi alpha_o/n_o^3 + sin^2 psi alpha_e/n_e^3)
 * per mm along its ray.  Optical activity (quartz's rotation of the
 * plane of polarization along its axis) is not modelled; biaxial crystals
 * are not modelled. */
typedef struct lp_crystal {
    char name[LP_GLASS_NAME_MAX];
    lp_glass ordinary;
    lp_glass extraordinary;
    lp_vec3 axis;
} lp_crystal;

/* Fill *crystal with constant, lossless indices n_o and n_e and the
 * given axis (named "uniaxial"). */
LP_API void lp_crystal_init_constant(lp_crystal *crystal, double n_o, double n_e,
                                     lp_vec3 axis);

/* Copy the built-in crystal `name` (case-insensitive) into *out, its axis
 * set to +z (a c-cut plate of a lens along +z).  Built in, lossless, room
 * temperature, o and e Sellmeier formulas (micrometres) as published and
 * taken as relative to air:
 *   "calcite"   CaCO3, Ghosh, Opt. Commun. 163, 95 (1999), 204-2172 nm
 *   "quartz"    crystalline SiO2, Ghosh 1999, 198-2053 nm (no optical
 *               activity: along its axis quartz rotates the plane of
 *               polarization by ~22 deg/mm at 589 nm, which lensprim
 *               leaves out)
 *   "sapphire"  Al2O3, Malitson & Dodge, JOSA 62, 1405 (1972), 200-5000 nm
 *   "MgF2"      Dodge, Appl. Opt. 23, 1980 (1984), 200-7000 nm
 * LP_ERROR_UNKNOWN_GLASS for another name. */
LP_API lp_status lp_crystal_builtin(const char *name, lp_crystal *out, lp_error *err);

/* Check that a crystal can be used: both glasses pass lp_glass_check and
 * the axis is a finite non-zero vector. */
LP_API lp_status lp_crystal_check(const lp_crystal *crystal, lp_error *err);

/* ------------------------------------------------------------------ */
/* Lens                                                                */
/* ------------------------------------------------------------------ */

typedef struct lp_lens lp_lens;

typedef struct lp_lens_desc {
    double radius1;    /* front surface radius, mm; 0 or +-inf = flat */
    double radius2;    /* back surface radius, mm */
    double thickness;  /* centre thickness, mm, > 0 */
    double diameter;   /* rim diameter at the front cap, mm, > 0 */
    double diameter2;  /* rim diameter at the back cap; 0 = diameter */
    lp_glass glass;
    lp_glass medium;   /* surrounding medium; default constant 1 (air) */
    int uniaxial;      /* 1: the lens is of `crystal` (glass is ignored);
                          0 (default): of the isotropic `glass` */
    lp_crystal crystal;
    lp_vec3 position;  /* world position of the front vertex */
    lp_vec3 axis;      /* world direction of the local +z axis */
} lp_lens_desc;

/* Defaults: flat surfaces, thickness 0 (must be set), diameter 0 (must be
 * set), glass constant 1.5, medium constant 1, at the origin, axis +z,
 * not a crystal. */
LP_API void lp_lens_desc_init(lp_lens_desc *desc);

/* Create an immutable lens.  Refused with LP_ERROR_INVALID_LENS and a
 * message naming the problem: a non-finite number, thickness <= 0,
 * diameter <= 0, a cap wider than its sphere (D/2 > |R|), caps that cross
 * before the rim (negative edge thickness), a conical rim between caps
 * that meet (knife edge with D != D2), a zero axis.  A knife-edge lens
 * (edge thickness 0, D2 == D) has no rim. *out is NULL on error. */
LP_API lp_status lp_lens_create(const lp_lens_desc *desc, lp_lens **out,
                                lp_error *err);
LP_API void lp_lens_destroy(lp_lens *lens); /* NULL: no-op */

/* The description the lens was created from (axis normalized). */
LP_API void lp_lens_get_desc(const lp_lens *lens, lp_lens_desc *out);

/* Edge (rim) thickness along the rim, mm; 0 for a knife edge. */
LP_API double lp_lens_edge_thickness(const lp_lens *lens);

/* World-space axis-aligned bounding box. */
LP_API void lp_lens_bounds(const lp_lens *lens, lp_vec3 *lo, lp_vec3 *hi);

enum {
    LP_SURFACE_NONE = -1,
    LP_SURFACE_FRONT = 0,
    LP_SURFACE_BACK = 1,
    LP_SURFACE_RIM = 2
};

typedef struct lp_hit {
    double t;        /* distance along the unit direction */
    lp_vec3 point;   /* world */
    lp_vec3 normal;  /* world, unit, pointing out of the glass */
    int surface;     /* LP_SURFACE_* */
} lp_hit;

/* Nearest intersection of the world ray origin + t*dir with the lens
 * surface, t in (t_min, t_max).  dir is normalized first, so t is a
 * distance in mm.  Returns 1 and fills *hit, or 0 when there is none or
 * the input is not finite.  A cap's edge circle belongs to the opaque
 * rim: a ray through it (to within the lens's rounding, about 1e-12 of its
 * size) meets the rim there, never a cap it would leave. */
LP_API int lp_lens_intersect(const lp_lens *lens, lp_vec3 origin, lp_vec3 dir,
                             double t_min, double t_max, lp_hit *hit);

/* 1 if the world point lies inside the glass (boundary excluded). */
LP_API int lp_lens_contains(const lp_lens *lens, lp_vec3 point);

/* ------------------------------------------------------------------ */
/* Rays and tracing                                                    */
/* ------------------------------------------------------------------ */

/* A ray with its payload <lambda, I, vp, kphi, op, ch> (+ phase). */
typedef struct lp_ray {
    lp_vec3 origin;
    lp_vec3 dir;        /* unit */
    double lambda_nm;   /* wavelength in standard air */
    double intensity;   /* power carried, >= 0 */
    lp_vec3 vp;         /* unit field direction, perpendicular to dir */
    int kphi;           /* phase jumps by pi */
    double op;          /* optical path, mm (sum of n*s) */
    double phase;       /* extra phase, rad (non-zero after TIR) */
    uint64_t ch;        /* source id, copied, never interpreted */
} lp_ray;

typedef enum lp_kind {
    LP_KIND_REFLECT = 0,  /* left on the side the light came from */
    LP_KIND_TRANSMIT = 1  /* left on the other side */
} lp_kind;

/* One outgoing ray. */
typedef struct lp_out_ray {
    lp_ray ray;       /* origin on the lens surface, dir pointing away */
    int depth;        /* interface interactions along the path, >= 1 */
    lp_kind kind;
    int surface;      /* LP_SURFACE_FRONT or LP_SURFACE_BACK */
    int part;         /* 0, or 1 for the second linear part after TIR */
    uint64_t path;    /* bit k-1 set when node k was a reflection */
    uint64_t waves;   /* crystal lenses: bit k-1 set when the ray left
                         node k inside the crystal as an extraordinary
                         wave; 0 for a glass lens */
} lp_out_ray;

/* Warnings a trace can raise (bits of lp_result.warnings). */
enum {
    LP_WARN_EXTRAPOLATED = 1u << 0, /* lambda outside a glass's data range */
    LP_WARN_LEAK = 1u << 1          /* an internal ray found no surface
                                       (numerical); its energy was counted
                                       as absorbed at the rim */
};

/* The outgoing rays of a trace and its energy bookkeeping:
 *   in = out + skipped + absorbed_glass + absorbed_rim + truncated
 * to rounding.  `truncated` is the energy left inside at depth max_depth
 * or in branches cut below min_weight; `skipped` is the energy of
 * outgoing rays the filter or flags declined.  The rays array is owned by
 * the result and reused by later calls. */
typedef struct lp_result {
    lp_out_ray *rays;
    size_t count;
    size_t capacity;
    double in, out, skipped, absorbed_glass, absorbed_rim, truncated;
    unsigned warnings;
    size_t nodes;     /* interface interactions computed (a cost measure) */
} lp_result;

LP_API void lp_result_init(lp_result *result);
/* Forget the rays and zero the bookkeeping; keep the memory. */
LP_API void lp_result_clear(lp_result *result);
/* Free the memory; the result may be initialized again. NULL: no-op. */
LP_API void lp_result_release(lp_result *result);

typedef enum lp_mode {
    LP_MODE_POLARIZED = 0, /* transformation G: s/p amplitudes, vp, phase */
    LP_MODE_FRESNEL,       /* unpolarized: R = (Rs + Rp)/2 per node */
    LP_MODE_SCHLICK        /* unpolarized: R0 + (1-R0)(1-cos)^5, with
                              cos of the transmitted angle when n1 > n2 */
} lp_mode;

/* What the filter callback is told about a candidate outgoing ray
 * (forward: an outgoing ray; backward: a query ray). */
typedef struct lp_branch_info {
    int depth;
    lp_kind kind;
    int surface;
    lp_vec3 origin;   /* world */
    lp_vec3 dir;      /* world, unit, pointing away from the lens */
    double bound;     /* forward: the ray's intensity; backward: an upper
                         bound of the path's power transmittance */
} lp_branch_info;

/* Return nonzero to keep the ray, 0 to skip it. */
typedef int (*lp_filter_fn)(const lp_branch_info *info, void *user);

enum {
    LP_SKIP_EXTERNAL_REFLECTION = 1u << 0, /* drop the depth-1 reflection */
    LP_SKIP_REFLECTED = 1u << 1,           /* drop every ray leaving on the
                                              incoming side */
    /* (Revision 2) A polarized backward build whose queries' light will be
     * added up for its power only (lp_backward_gather_power_many): the
     * build makes each query's power form -- its way's Jones matrix,
     * grown node by node as the view ray's chain is walked -- instead of
     * setting up the ways that lp_backward_gather carries rays along
     * (that call still gives the same rays, setting its way up itself).
     * Ignored by forward traces and the unpolarized modes. */
    LP_BACKWARD_POWER = 1u << 2
};

#define LP_MAX_DEPTH 64

typedef struct lp_trace_args {
    lp_mode mode;
    int max_depth;        /* dT, 1..LP_MAX_DEPTH; default 5 */
    double min_weight;    /* cut an internal branch when its power relative
                             to the input (forward) or its bound (backward)
                             falls below this; default 0 = never */
    unsigned flags;       /* LP_SKIP_*, LP_BACKWARD_POWER */
    lp_filter_fn filter;  /* optional */
    void *user;           /* passed to filter */
} lp_trace_args;

LP_API void lp_trace_args_init(lp_trace_args *args);

/* Forward trace (from the light).  `in` is a world ray with a full
 * payload; vp is made perpendicular to dir and normalized (a vp parallel
 * to dir is an error), dir is normalized.  The result is cleared first,
 * then filled with every outgoing ray up to depth max_depth and the
 * bookkeeping.  A ray that misses the lens gives no rays and all the
 * bookkeeping zero (the lens received nothing).  args NULL: defaults. */
LP_API lp_status lp_trace_forward(const lp_lens *lens, const lp_ray *in,
                                  const lp_trace_args *args, lp_result *out,
                                  lp_error *err);

/* Many rays at once: the results of ray i are out->rays[offsets[i] ..
 * offsets[i+1]) and the bookkeeping is summed over all rays.  offsets has
 * n + 1 entries.  Stops at the first invalid ray (its index is in the
 * message).  The rays are traced in order, each as lp_trace_forward
 * traces it; consecutive rays of one wavelength are traced together as
 * lp_trace_forward_soa traces them, with the same results, bit for bit. */
LP_API lp_status lp_trace_forward_many(const lp_lens *lens, const lp_ray *in,
                                       size_t n, const lp_trace_args *args,
                                       lp_result *out, size_t *offsets,
                                       lp_error *err);

/* Revision 2.  Many rays of ONE wavelength as a structure of arrays:
 * element i of every array belongs to ray i.  The origin, direction and
 * field-direction arrays and the intensities are required; op, phase,
 * kphi and ch may each be NULL, which stands for 0 for every ray. */
typedef struct lp_ray_soa {
    const double *ox, *oy, *oz; /* origins, world, mm */
    const double *dx, *dy, *dz; /* directions, world (normalized here) */
    const double *vx, *vy, *vz; /* field directions vp, world (made
                                   perpendicular to dir and normalized) */
    const double *intensity;    /* finite, >= 0 */
    const double *op;           /* optical paths so far, mm; NULL: 0 */
    const double *phase;        /* extra phases, rad; NULL: 0 */
    const int *kphi;            /* phase-jump counts; NULL: 0 */
    const uint64_t *ch;         /* source ids; NULL: 0 */
} lp_ray_soa;

/* Revision 2.  Forward trace of the n rays of `in`, all at lambda_nm (in
 * standard air).  The result is exactly lp_trace_forward_many's on the
 * same rays given as lp_ray records with that wavelength: the same
 * outgoing rays in the same order, the same offsets (n + 1 entries) and
 * the same bookkeeping, bit for bit.  What depends on the wavelength
 * alone (the indices, the absorption, the data-range check) is computed
 * once per call.  Through a glass lens the rays of a group walk their
 * internal chains node by node together, in loops over the rays that the
 * compiler vectorizes, compiled for the widest vectors of the machine
 * (AVX-512, AVX2 or the baseline, chosen at load time, the same bits on
 * each); what those loops leave (total internal reflection, normal
 * incidence, a ray starting on the lens, a crystal) is done by the
 * one-ray code.  A wavelength that is not a
 * finite number > 0 fails the call before any ray (also when n is 0).
 * NULL lens, out or offsets, a NULL in when n > 0, or a required array
 * that is NULL when n > 0 gives LP_ERROR_INVALID_ARGUMENT.  The first
 * invalid ray stops the call with its index in the message, as
 * lp_trace_forward_many; out then holds the rays traced before it. */
LP_API lp_status lp_trace_forward_soa(const lp_lens *lens, double lambda_nm,
                                      const lp_ray_soa *in, size_t n,
                                      const lp_trace_args *args, lp_result *out,
                                      size_t *offsets, lp_error *err);

/* ------------------------------------------------------------------ */
/* Backward tracing (from the eye), in two phases                      */
/* ------------------------------------------------------------------ */

/* A query ray: the application traces it into the scene and answers
 * with a bundle of linearly polarized rays arriving back along it. */
typedef struct lp_query {
    lp_vec3 origin;   /* world, on the lens surface */
    lp_vec3 dir;      /* world, unit, pointing away from the lens */
    int depth;        /* depth of the path, >= 1 */
    lp_kind kind;     /* REFLECT: leaves on the viewer's side */
    int surface;
    uint64_t path;
    double op;        /* optical path inside the lens along this path */
    double bound;     /* upper bound of the power transmittance of the path
                         for any polarization: prod max(Rs,Rp)|max(Ts,Tp)
                         times absorption.  For fresnel/schlick modes it is
                         the exact transmittance. */
    double weight;    /* unpolarized transmittance estimate: the fresnel
                         (or schlick) product along the path */
    uint64_t waves;   /* crystal lenses: as lp_out_ray.waves; 0 for glass */
} lp_query;

typedef struct lp_backward lp_backward;

LP_API lp_status lp_backward_create(lp_backward **out, lp_error *err);
LP_API void lp_backward_destroy(lp_backward *bw); /* NULL: no-op */

/* Phase 1, build.  The view ray carries only lambda.  Builds the internal
 * chain and the query rays (filtered by args->flags, args->filter and
 * args->min_weight against `bound`).  Replaces what bw held before.  A
 * ray that misses the lens yields no queries and LP_OK. */
LP_API lp_status lp_backward_build(lp_backward *bw, const lp_lens *lens,
                                   lp_vec3 origin, lp_vec3 dir,
                                   double lambda_nm, const lp_trace_args *args,
                                   lp_error *err);

/* Revision 2.  Phase 1 for one view ray at n wavelengths at once: the
 * same as lp_backward_build(bw[k], lens, origin, dir, lambda_nm[k], args,
 * err) for k = 0, 1, ..., n-1 in turn.  Each bw[k] ends holding exactly
 * what that build leaves in it -- the same queries, bit for bit, the same
 * rim depth, and the same results of every later lp_backward_gather -- and
 * args->filter is called as those builds call it, wavelength by
 * wavelength.  The view ray meets the lens at the same point at every
 * wavelength; that hit is found once, and the chains inside, which
 * differ with the wavelength, are traced side by side in loops over the
 * wavelengths that the compiler vectorizes, so the call costs less than
 * the n builds.  The first build that fails stops the call: its status is
 * returned with lp_backward_build's message prefixed by "wavelength k: ",
 * bw[k] is left as that build leaves it and bw[k+1 .. n) are not touched.
 * A builder that appears twice holds the build of its last wavelength.
 * n = 0 does nothing and returns LP_OK.  A NULL lens, or a NULL bw or
 * lambda_nm when n > 0, gives LP_ERROR_INVALID_ARGUMENT before any build;
 * a NULL bw[k] fails build k with LP_ERROR_INVALID_ARGUMENT. */
LP_API lp_status lp_backward_build_many(lp_backward *const *bw, size_t n, const lp_lens *lens,
                                        lp_vec3 origin, lp_vec3 dir, const double *lambda_nm,
                                        const lp_trace_args *args, lp_error *err);

LP_API size_t lp_backward_query_count(const lp_backward *bw);
/* The query rays, count of them; valid until the next build. */
LP_API const lp_query *lp_backward_queries(const lp_backward *bw);

/* Depth at which the view ray's chain met the rim (1 = the view ray hit
 * the rim itself), or 0 if it did not (within max_depth).  Through a
 * crystal, the smallest depth at which a branch of its tree did. */
LP_API int lp_backward_rim_depth(const lp_backward *bw);

/* (Revision 2) 1 when query q's ray certainly does not meet bw's lens
 * again: lp_lens_intersect(lens, query.origin, query.dir, 0, t_max) gives
 * no hit, whatever t_max, so a renderer may leave the lens out of the
 * query ray's scene test.  0 when that is not certain, and for a crystal
 * lens or a query that does not exist. */
LP_API int lp_backward_query_leaves(const lp_backward *bw, size_t q);

/* Phase 2, gather.  bundle[0..n) are linearly polarized rays arriving
 * back along query q (their origin and dir are ignored: they travel along
 * -query.dir).  Each is carried through the path's nodes in the direction
 * of light and APPENDED to out as a ray leaving the lens at the view
 * ray's entry point along -view dir, with depth/kind/path of the query,
 * op and kphi added to the bundle ray's own, ch copied.  Not merged:
 * one or two (after TIR) output rays per bundle ray.  out->in gains the
 * bundle's intensity, out->out the output, out->absorbed_glass the
 * absorption, out->truncated what the path's nodes sent elsewhere. */
LP_API lp_status lp_backward_gather(const lp_backward *bw, size_t q,
                                    const lp_ray *bundle, size_t n,
                                    lp_result *out, lp_error *err);

/* (Revision 2) Many gathers in one call, of one builder or of many: the
 * same as lp_backward_gather(bw[k], q[k], bundle[k], n[k], out, err) for
 * k = 0, 1, ..., count-1 in turn, every gather appending to the one out:
 * the same outgoing rays, bit for bit and in that order, and the same
 * sums.  start[k] is set to out->count as gather k begins, so request k's
 * rays are out->rays[start[k] .. start[k+1]) (the last one's up to
 * out->count); start may be NULL.  For a spectral renderer whose packet
 * splits into one wavelength per builder at a dispersive lens
 * (lp_backward_build_many), each gather a ray or two: the rays of many
 * requests are carried through their own ways side by side, in loops over
 * them that the compiler vectorizes, so the call costs less than the
 * gathers one by one.  The first gather that fails stops the call: its
 * status is returned with lp_backward_gather's message prefixed by
 * "request k: ", out holds what gathers 0 .. k-1 appended and what gather
 * k appended before it failed (from start[k] on), and requests k+1 ..
 * count-1 are not gathered (start[k+1 ..) not set): a caller that wants
 * them calls again from k + 1.  Every request's arguments must be valid
 * to read even after one that fails: they are read ahead, up to 256
 * requests at a time.  start must not overlap bw, q or n, and no bundle
 * may lie in out->rays.  count = 0 with a non-NULL out does nothing and
 * returns LP_OK.  A NULL out, or a NULL bw, q, bundle or n when
 * count > 0, gives LP_ERROR_INVALID_ARGUMENT before any gather; a NULL
 * bw[k], or a NULL bundle[k] with n[k] > 0, fails gather k as
 * lp_backward_gather does.  The call takes about 46 KB of stack. */
LP_API lp_status lp_backward_gather_many(const lp_backward *const *bw, const size_t *q,
                                         const lp_ray *const *bundle, const size_t *n,
                                         size_t count, lp_result *out, size_t *start,
                                         lp_error *err);

/* (Revision 2) The power that lp_backward_gather_many would carry out,
 * request by request, without the rays: power[k] is the sum of the
 * intensities of the rays that lp_backward_gather(bw[k], q[k], bundle[k],
 * n[k], ...) appends, to rounding (about 1e-15 of the bundle's
 * intensity; more for a field direction within 1e-10 of the light's,
 * whose part across the light is itself known only to rounding).  For an
 * application that only adds up the light that leaves -- an image of
 * intensities, where nothing after the lens sees polarization and no
 * rays interfere.  Of a build made with LP_BACKWARD_POWER (polarized, not
 * a crystal) each query has its power form P, the 2 x 2 matrix with
 * |T x|^2 = x' P x for T its way's Jones matrix: a ray of intensity I and
 * field direction v, x = sqrt(I) (v.s, v.p) / |(v.s, v.p)| on the axes
 * of the light entering, leaves with power x' P x -- no phase jump,
 * ellipse or stored ray.  Any other request (another build, a way with a
 * node at normal incidence) is gathered by lp_backward_gather and its
 * rays' intensities added up.  Errors as lp_backward_gather_many's: the
 * first request that fails stops the call with lp_backward_gather's
 * message prefixed by "request k: ", power[0 .. k) set and power[k] 0.
 * A NULL bw, q,
 * bundle, n or power when count > 0 gives LP_ERROR_INVALID_ARGUMENT;
 * count 0 does nothing. */
LP_API lp_status lp_backward_gather_power_many(const lp_backward *const *bw, const size_t *q,
                                               const lp_ray *const *bundle, const size_t *n,
                                               size_t count, double *power, lp_error *err);

/* ------------------------------------------------------------------ */
/* The cone K of rim-free directions (the paper's section 5)           */
/* ------------------------------------------------------------------ */

/* The rim holds the mount: polarization cannot be followed past it, so an
 * application that needs every ray of the tree asks which initial rays
 * keep their whole internal chain off the rim.  The chain is the one
 * lp_backward_build traces: the entry node (the initial ray meets a cap,
 * not the rim) and the internal rays reflected from cap to cap, up to the
 * node of depth max_depth.  Refraction is at args.lambda_nm; the chain
 * follows the reflected ray after total internal reflection too.  An
 * initial ray that misses the lens is not rim-free (it has no tree). */

/* The frame points and directions are given and returned in. */
typedef enum lp_frame {
    LP_FRAME_LOCAL = 0, /* the lens's frame: axis +z, front vertex at 0 */
    LP_FRAME_WORLD = 1
} lp_frame;

typedef struct lp_cone_args {
    int max_depth;     /* dT, 1..LP_MAX_DEPTH; default 5 */
    double lambda_nm;  /* wavelength in standard air; default 587.56 */
    double tolerance;  /* width the bisection stops at: radians for a
                          cone, millimetres for a beam; default 1e-9 */
    int scan_steps;    /* grid steps over the bracket before bisecting,
                          1..1000000; default 2048 */
    lp_frame frame;    /* the frame of the arguments and results;
                          default LP_FRAME_LOCAL */
} lp_cone_args;

/* Defaults as above. */
LP_API void lp_cone_args_init(lp_cone_args *args);

/* Is the initial ray origin + s*dir rim-free up to args->max_depth?  Sets
 * *rim_free to 1 or 0.  A chain that loses its way numerically (see
 * LP_WARN_LEAK) counts as not rim-free.  args NULL: defaults. */
LP_API lp_status lp_rim_free(const lp_lens *lens, lp_vec3 origin, lp_vec3 dir,
                             const lp_cone_args *args, int *rim_free,
                             lp_error *err);

/* Where a cone's angles are measured from.  The axis is the unit vector
 * from the apex to the front vertex; azimuth 0 is along `ref`, the part of
 * the lens's local +x axis perpendicular to the axis (local +y when the
 * axis lies along local x), and azimuth pi/2 along axis x ref.  The
 * direction at polar angle theta and azimuth phi is
 *     cos(theta) axis + sin(theta) (cos(phi) ref + sin(phi) axis x ref).
 * For a beam (lp_beam_region) the same holds with the beam's direction
 * as the axis and offsets instead of angles. */
typedef struct lp_cone_frame {
    lp_vec3 apex;  /* the point (a beam: the front vertex) */
    lp_vec3 axis;  /* unit */
    lp_vec3 ref;   /* unit, perpendicular to axis */
} lp_cone_frame;

/* The frame of the cone from `point` (in args->frame).  Refused: a point
 * that is not finite, lies inside the glass, or is the front vertex. */
LP_API lp_status lp_cone_frame_of(const lp_lens *lens, lp_vec3 point,
                                  const lp_cone_args *args, lp_cone_frame *out,
                                  lp_error *err);

/* theta_K at one azimuth (radians): the largest polar angle such that every
 * direction at a smaller angle on that azimuth is rim-free.  The bracket
 * [0, the angle beyond which every ray misses the lens's bounding sphere]
 * is scanned in args->scan_steps equal steps for the first direction that
 * is not rim-free, and the step where it happens is bisected to
 * args->tolerance; *theta is the rim-free end.  A rim-free interval
 * narrower than one scan step that follows a gap narrower than one step
 * can be missed (the grid is the resolution of "every direction").
 * *theta is 0 when the axis itself is not rim-free. */
LP_API lp_status lp_cone_theta(const lp_lens *lens, lp_vec3 point, double azimuth,
                               const lp_cone_args *args, double *theta,
                               lp_error *err);

/* The cone as a whole. */
typedef struct lp_cone {
    lp_cone_frame frame;
    int depth;           /* the dT it was computed for */
    double solid_angle;  /* sr: the sum over the n azimuths of
                            (1 - cos theta_K) * 2 pi / n (exact,
                            2 pi (1 - cos theta_K), for a circular cone) */
    double theta_min, theta_max; /* over the azimuths, radians */
} lp_cone;

/* theta_K at n >= 1 azimuths 2 pi k / n, k = 0..n-1, into theta[0..n), and
 * the cone's summary into *out. */
LP_API lp_status lp_cone_compute(const lp_lens *lens, lp_vec3 point,
                                 const lp_cone_args *args, size_t n,
                                 double *theta, lp_cone *out, lp_error *err);

/* The collimated case: parallel light along `dir` (in args->frame).  The
 * entry points are described in the plane perpendicular to dir by their
 * offset from the ray through the front vertex: at azimuth phi (frame as
 * above, the apex the front vertex) the largest offset rho_K such that
 * every ray at a smaller offset on that azimuth is rim-free, found as
 * theta_K is (mm).  Every rho_K is 0 when the ray through the front vertex
 * is not rim-free itself (a rim-free region away from it is not sought). */
typedef struct lp_beam_region {
    lp_cone_frame frame;
    int depth;
    double area;         /* mm^2: the sum of rho_K^2 pi / n */
    double radius_min, radius_max;
} lp_beam_region;

/* rho_K at n >= 1 azimuths 2 pi k / n into radius[0..n), the summary into
 * *out.  Refused: a dir that is zero or not finite. */
LP_API lp_status lp_beam_region_compute(const lp_lens *lens, lp_vec3 dir,
                                        const lp_cone_args *args, size_t n,
                                        double *radius, lp_beam_region *out,
                                        lp_error *err);

/* The paper's second experiment: the light a view ray gathers, by depth.
 * Builds the view ray's queries (lp_backward_build with args; NULL: the
 * defaults), answers every query with natural light of unit intensity --
 * two mutually incoherent orthogonal linear halves of 1/2 -- and ADDS the
 * intensity of the gathered bundle rays of depth k to by_depth[k], for
 * k = 1..max_depth (by_depth has max_depth + 1 entries; [0] is not
 * touched).  So the caller sums over many view rays, and by_depth[k] over
 * the sum is the share of the outgoing intensity carried by depth k.
 * args->flags select the queries: LP_SKIP_REFLECTED keeps the light from
 * behind the lens only.  A view ray that misses the lens adds nothing. */
LP_API lp_status lp_bundle_by_depth(const lp_lens *lens, lp_vec3 origin,
                                    lp_vec3 dir, double lambda_nm,
                                    const lp_trace_args *args,
                                    double *by_depth, lp_error *err);

#ifdef __cplusplus
}
#endif

#endif /* LENSPRIM_H */
