/* placed_lens.h -- the placed and tilted lenses of the batch tests
 * (test_backward_many, test_gather_many), which compare a call for many
 * wavelengths with the calls one by one on the same lenses: a table of
 * shapes, and each made with its own tilt and place, so that no lens
 * frame is the world's. */
#ifndef PLACED_LENS_H
#define PLACED_LENS_H

#include <math.h>
#include <stddef.h>

#include "check.h"
#include "lensprim.h"

typedef struct placed_shape {
    const char *name;
    double r1, r2, t, d, d2;
    const char *glass;  /* catalog, or NULL: constant n */
    double n;
    const char *medium; /* catalog medium, or NULL: air */
    int crystal;        /* 1: a uniaxial crystal (constant indices) */
    double tau10;       /* > 0: the glass absorbs, this internal
                           transmittance per 10 mm at every wavelength */
} placed_shape;

static inline lp_vec3 vec(double x, double y, double z)
{
    lp_vec3 v = {x, y, z};
    return v;
}

/* pos + x u + y v + z w */
static inline lp_vec3 place(lp_vec3 pos, lp_vec3 u, lp_vec3 v, lp_vec3 w, double x, double y,
                            double z)
{
    return vec(pos.x + x * u.x + y * v.x + z * w.x, pos.y + x * u.y + y * v.y + z * w.y,
               pos.z + x * u.z + y * v.z + z * w.z);
}

/* Lens number si of the table, shape s: its axis w tilted by 0.3 + 0.1 si
 * from +z and turned by 0.9 si, its front vertex at (-2 si, 1, 4).  Into
 * *lens, *desc (as the lens holds it) and the orthonormal frame u, v, w
 * (u, v across the axis).  Returns 0, or -1 after a failed CHECK. */
static inline int placed_lens(const placed_shape *s, size_t si, lp_lens **lens,
                              lp_lens_desc *desc, lp_vec3 *u, lp_vec3 *v, lp_vec3 *w)
{
    lp_error err;
    lp_lens_desc_init(desc);
    desc->radius1 = s->r1;
    desc->radius2 = s->r2;
    desc->thickness = s->t;
    desc->diameter = s->d;
    desc->diameter2 = s->d2;
    if (s->crystal) {
        desc->uniaxial = 1;
        lp_crystal_init_constant(&desc->crystal, 1.658, 1.486, vec(0.3, 0.5, 0.8));
    } else if (s->glass) {
        CHECK(lp_glass_builtin(s->glass, &desc->glass, &err) == LP_OK, "%s", err.message);
    } else {
        lp_glass_init_constant(&desc->glass, s->n);
    }
    if (s->tau10 > 0.0) {
        desc->glass.n_tau = 2;
        desc->glass.tau_lambda_nm[0] = 380.0, desc->glass.tau_lambda_nm[1] = 780.0;
        desc->glass.tau[0] = desc->glass.tau[1] = s->tau10;
        desc->glass.tau_thickness_mm = 10.0;
    }
    if (s->medium)
        CHECK(lp_glass_builtin(s->medium, &desc->medium, &err) == LP_OK, "%s", err.message);
    double th = 0.3 + 0.1 * (double)si, ph = 0.9 * (double)si;
    *w = vec(sin(th) * cos(ph), sin(th) * sin(ph), cos(th));
    desc->axis = *w;
    desc->position = vec(-2.0 * (double)si, 1.0, 4.0);
    if (lp_lens_create(desc, lens, &err) != LP_OK) {
        CHECK(0, "%s: %s", s->name, err.message);
        return -1;
    }
    lp_lens_get_desc(*lens, desc);
    lp_vec3 a = fabs(w->x) < 0.6 ? vec(1, 0, 0) : vec(0, 1, 0);
    double aw = a.x * w->x + a.y * w->y + a.z * w->z;
    a = vec(a.x - aw * w->x, a.y - aw * w->y, a.z - aw * w->z);
    double al = sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
    *u = vec(a.x / al, a.y / al, a.z / al);
    *v = vec(w->y * u->z - w->z * u->y, w->z * u->x - w->x * u->z, w->x * u->y - w->y * u->x);
    return 0;
}

#endif
