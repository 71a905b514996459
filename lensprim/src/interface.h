/* interface.h -- the transformation G at one interface crossing (internal).
 *
 * A beam is a power-normalized complex field E (|E|^2 = power, E
 * perpendicular to the direction).  In polarized mode G splits E into s
 * and p, applies Fresnel's amplitudes (fresnel.h) and rebuilds the
 * reflected and transmitted fields on their own s/p axes.  A reflection
 * whose field points against the mirror image of the incident field is
 * reported as a phase jump (flip = 1) and the field is negated, so that
 * E * (-1)^kphi stays the physical field.  In the unpolarized modes the
 * field only carries a direction for v_p: its power is scaled by R or
 * 1 - R of the mode's law and its direction is mirrored or carried over
 * on the s/p axes.
 *
 * Cost: a node is set up once (geometry, Fresnel factors, s/p axes) and
 * serves both branches; a field whose components are all real (every
 * field before a total internal reflection) is projected and rebuilt in
 * real arithmetic. */
#ifndef LP_INTERFACE_H
#define LP_INTERFACE_H

#include "cvec3.h"
#include "fresnel.h"
#include "lensprim.h"

typedef struct lp__branch {
    lp_vec3 dir;   /* unit */
    lp__cvec3 E;
    int flip;      /* a phase jump by pi was counted */
} lp__branch;

/* Geometry and Fresnel factors of one node, shared by both branches. */
typedef struct lp__node {
    lp_vec3 d;        /* incident direction */
    lp_vec3 n;        /* unit normal facing the incident side */
    double cos_i;
    lp__fresnel f;
    lp_vec3 s;        /* unit s axis */
    lp_vec3 p;        /* unit p axis of the incident wave, d x s */
    double n1, n2;    /* indices before and after the boundary */
    int normal;       /* normal incidence: s was taken from the hint */
} lp__node;

/* The geometry and Fresnel factors of lp__node_setup alone (no s and p
 * axes: for the directions and powers of the branches, not their
 * fields).  Returns 1 under total internal reflection.  Inline, as the
 * two below: every node of a build and every way of a gather sets up. */
static inline int lp__node_setup_fresnel(lp__node *node, lp_vec3 d, lp_vec3 normal, double n1,
                                         double n2)
{
    double dn = v3_dot(d, normal);
    double adn = fabs(dn);
    node->d = d;
    node->n1 = n1;
    node->n2 = n2;
    node->n = dn > 0.0 ? v3_neg(normal) : normal;
    node->cos_i = adn < 1.0 ? adn : 1.0;
    lp__fresnel_eval(node->cos_i, n1, n2, &node->f);
    return node->f.tir;
}

/* The unit directions of the reflected and (not under TIR) transmitted
 * branches: those of lp__node_reflect and lp__node_transmit. */
static inline lp_vec3 lp__node_reflect_dir(const lp__node *node)
{
    return v3_normalize(v3_madd(node->d, node->n, 2.0 * node->cos_i));
}

static inline lp_vec3 lp__node_transmit_dir(const lp__node *node)
{
    double eta = node->f.eta, ci = node->cos_i, ct = node->f.cos_t;
    return v3_normalize(v3_madd(v3_scale(node->d, eta), node->n, eta * ci - ct));
}

/* The s axis at normal incidence: that of the field hint (NULL: any
 * axis perpendicular to d). */
lp_vec3 lp__hint_axis(lp_vec3 d, const lp__cvec3 *hint);

/* Set up a node: light along unit d meets a surface with unit normal
 * `normal` (either orientation) going from index n1 into n2.  hint is a
 * field to take the s axis from at normal incidence (the s/p split is
 * undefined there; any axis gives the same result, the incoming field's
 * own keeps the frame).  Returns 1 under total internal reflection.
 * Inline: every node of a trace and every way of a polarized build sets
 * up one. */
static inline int lp__node_setup(lp__node *node, lp_vec3 d, lp_vec3 normal, double n1,
                                 double n2, const lp__cvec3 *hint)
{
    lp__node_setup_fresnel(node, d, normal, n1, n2);
    lp_vec3 s = v3_cross(d, node->n);
    double sl2 = v3_dot(s, s);
    node->normal = !(sl2 > 1e-18);
    node->s = node->normal ? lp__hint_axis(d, hint) : v3_scale(s, 1.0 / sqrt(sl2));
    node->p = v3_cross(d, node->s);
    return node->f.tir;
}

/* A node set up once for any field (hint NULL) serves every field, except
 * at normal incidence, where the s axis follows the field: this redoes
 * the set-up for E then (node->normal), and is a no-op otherwise. */
void lp__node_refit(lp__node *node, const lp__cvec3 *E);

/* The reflected branch of G for field E in the given mode. */
void lp__node_reflect(const lp__node *node, lp_mode mode, const lp__cvec3 *E, lp__branch *out);
/* The transmitted branch (not under TIR). */
void lp__node_transmit(const lp__node *node, lp_mode mode, const lp__cvec3 *E,
                       lp__branch *out);

/* A field on the node's s and p axes of the incident wave.  Both
 * branches of a node start from it, so a field is projected once (inline:
 * every node projects one). */
typedef struct lp__amp {
    double complex es, ep;
    int real;         /* 1: both are real (the field had no imaginary part) */
} lp__amp;

static inline void lp__node_project(const lp__node *node, const lp__cvec3 *E, lp__amp *out)
{
    if (cv3_is_real(*E)) {
        lp_vec3 e = cv3_re(*E);
        out->es = v3_dot(e, node->s);
        out->ep = v3_dot(e, node->p);
        out->real = 1;
        return;
    }
    out->es = cv3_dot_real(*E, node->s);
    out->ep = cv3_dot_real(*E, node->p);
    out->real = 0;
}

/* The branches of G for a field already projected (lp__node_project);
 * the same as lp__node_reflect / lp__node_transmit on that field. */
void lp__node_reflect_amp(const lp__node *node, lp_mode mode, const lp__amp *amp,
                          lp__branch *out);
void lp__node_transmit_amp(const lp__node *node, lp_mode mode, const lp__amp *amp,
                           lp__branch *out);

/* A branch's direction and the p axis of its wave (dir x s): what a
 * branch of a node costs beyond its field.  They are the same for every
 * field of a node not at normal incidence (there s, hence p, follows the
 * field: lp__node_refit), so a node that serves many fields computes
 * them once. */
typedef struct lp__axes {
    lp_vec3 dir;  /* unit */
    lp_vec3 p;    /* dir x s */
} lp__axes;

static inline void lp__node_reflect_axes(const lp__node *node, lp__axes *ax)
{
    ax->dir = lp__node_reflect_dir(node);
    ax->p = v3_cross(ax->dir, node->s);
}

static inline void lp__node_transmit_axes(const lp__node *node, lp__axes *ax)
{
    ax->dir = lp__node_transmit_dir(node);
    ax->p = v3_cross(ax->dir, node->s);
}

/* The branches of G on axes computed for the node as it is: the same as
 * lp__node_reflect_amp / lp__node_transmit_amp. */
void lp__node_reflect_on(const lp__node *node, const lp__axes *ax, lp_mode mode,
                         const lp__amp *amp, lp__branch *out);
void lp__node_transmit_on(const lp__node *node, const lp__axes *ax, lp_mode mode,
                          const lp__amp *amp, lp__branch *out);

/* The polarized branches of a real field (every field before a total
 * internal reflection) projected on the node's axes as es, ep, at a node
 * not under TIR, in real arithmetic: the real parts of what
 * lp__node_reflect_on / lp__node_transmit_on give (their imaginary parts
 * are 0), which use these.  *flip as lp__branch.flip. */
static inline lp_vec3 lp__node_reflect_real(const lp__node *node, const lp__axes *ax, double es,
                                            double ep, int *flip)
{
    double rs = creal(node->f.rs), rp = creal(node->f.rp);
    *flip = rs * (es * es) - rp * (ep * ep) < 0.0;
    if (*flip) {
        rs = -rs;
        rp = -rp;
    }
    return v3_add(v3_scale(node->s, rs * es), v3_scale(ax->p, rp * ep));
}

static inline lp_vec3 lp__node_transmit_real(const lp__node *node, const lp__axes *ax, double es,
                                             double ep)
{
    return v3_add(v3_scale(node->s, node->f.ts * es), v3_scale(ax->p, node->f.tp * ep));
}

/* Power reflectance of the node in an unpolarized mode (fresnel or
 * schlick); 1 under TIR. */
double lp__node_reflectance(const lp__node *node, lp_mode mode);

#endif
