/* lenstrace_args.h -- the command line of lenstrace, parsed into plain data.
 *
 * Parsing only: nothing here prints, exits, allocates or touches global
 * state.  Every function that can fail returns NULL on success or a
 * pointer to a one-line message naming the problem, written into the
 * caller's lt_args (lt_args.error); the message has no "lenstrace: "
 * prefix and no newline.
 *
 * Catalog glass names are only stored: resolving them needs the catalog,
 * which the caller builds after the --catalog files are known.
 */
#ifndef LENSTRACE_ARGS_H
#define LENSTRACE_ARGS_H

#include <stddef.h>
#include <stdint.h>

#include "lensprim.h"

#define LT_GLASS_NAME_MAX 128 /* longest accepted glass name + 1 */
#define LT_CATALOG_MAX 16     /* --catalog may be given this many times */
#define LT_ERROR_MAX 384
#define LT_AZIMUTHS_MAX 100000 /* --azimuths at most */
/* The shortest wavelength accepted (air or vacuum), nm: where Edlen's
 * standard air, lp_air_index, begins. */
#define LT_LAMBDA_MIN_NM 160.0

/* --lens "R1=..,R2=..,t=..,D=..,D2=..,glass=NAME|n=N" (or n=N as a key),
 * or instead of the glass a uniaxial crystal: crystal=NAME (built-in) or
 * no=N,ne=N, with axis=x:y:z */
typedef struct lt_lens_spec {
    double r1, r2;        /* mm; 0 or +-inf = flat */
    double t;             /* centre thickness, mm, finite > 0 */
    double d;             /* rim diameter at the front cap, finite > 0 */
    double d2;            /* rim diameter at the back cap; 0 = not given */
    int glass_constant;   /* 1: glass_n is a constant index */
    double glass_n;       /* finite > 0 when glass_constant */
    char glass_name[LT_GLASS_NAME_MAX]; /* catalog name when !glass_constant */
    int crystal;          /* 0: glass; 1: built-in crystal_name; 2: no/ne */
    char crystal_name[LT_GLASS_NAME_MAX];
    double n_o, n_e;      /* crystal == 2: constant indices */
    lp_vec3 axis;         /* optic axis, lens frame (default 0,0,1) */
} lt_lens_spec;

/* --ray "o=x,y,z d=x,y,z lambda=NM vp=x,y,z|unpolarized I=.. ch=.."
 * (or lambda_vac=NM instead of lambda=NM) */
typedef struct lt_ray_spec {
    lp_vec3 o;
    lp_vec3 d;            /* unit */
    double lambda_nm;     /* in standard air, finite > 0; default 587.56
                             (the d line: glass catalogs' n_d exactly) */
    double lambda_vac_nm; /* lambda_vac=, a vacuum wavelength (0: not
                             given); lambda_nm is then lambda_vac_nm /
                             lp_air_index(lambda_vac_nm) (Edlen 1966) */
    double intensity;     /* finite >= 0; default 1 */
    int unpolarized;      /* 1 when vp=unpolarized or vp omitted */
    lp_vec3 vp;           /* unit, perpendicular to d, when !unpolarized */
    uint64_t ch;          /* default 0 */
} lt_ray_spec;

typedef struct lt_args {
    int help;             /* --help / -h: print usage, nothing else parsed */
    int version;          /* --version / -V */
    lt_lens_spec lens;
    lt_ray_spec ray;      /* --ray, when rays_file is NULL */
    const char *rays_file; /* --rays FILE ("-": standard input), points
                              into argv; its lines are parsed by the
                              program with lt_parse_ray_spec */
    int depth;            /* 1..LP_MAX_DEPTH, default 5 */
    lp_mode mode;         /* default LP_MODE_POLARIZED */
    double medium;        /* constant index, finite > 0, default 1 */
    int backward;
    int cone;             /* --cone "x,y,z" given: print the cone K */
    lp_vec3 cone_point;   /* its apex, in the lens's frame */
    int azimuths;         /* --azimuths, 1..LT_AZIMUTHS_MAX, default 36 */
    double lambda_nm;     /* --lambda (with --cone), in air, default 587.56 */
    const char *catalogs[LT_CATALOG_MAX]; /* point into argv */
    size_t n_catalogs;
    char error[LT_ERROR_MAX];
} lt_args;

/* Defaults for everything (no lens, no ray). */
void lt_args_init(lt_args *args);

/* Parse argv[1..argc).  Accepts "--opt VALUE" and "--opt=VALUE".  When
 * --help/-h or --version/-V appears anywhere, only that flag is set
 * (the first of them wins) and nothing else is parsed or required.
 * Returns NULL on success, else args->error. */
const char *lt_args_parse(lt_args *args, int argc, char **argv);

/* Parse one spec into *out (the other fields of args untouched except
 * error).  Return NULL or args->error. */
const char *lt_parse_lens_spec(lt_args *args, const char *spec,
                               lt_lens_spec *out);
const char *lt_parse_ray_spec(lt_args *args, const char *spec,
                              lt_ray_spec *out);

/* A unit vector perpendicular to the unit vector d, chosen
 * deterministically: normalize(d x (0,1,0)), or normalize(d x (1,0,0))
 * when d is within ~25 degrees of the y axis. */
lp_vec3 lt_perpendicular(lp_vec3 d);

/* a x b */
lp_vec3 lt_cross(lp_vec3 a, lp_vec3 b);

/* The part of v perpendicular to the unit vector d, normalized, in *out.
 * Returns 0 (and leaves *out alone) when v is zero, not finite, or
 * parallel to d within 1e-9 relative. */
int lt_perpendicular_part(lp_vec3 v, lp_vec3 d, lp_vec3 *out);

#endif
