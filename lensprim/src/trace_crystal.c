/* trace_crystal.c -- one ray from the light through a lens of a uniaxial
 * crystal.
 *
 * Every node on a cap sends one field out (the isotropic side's two
 * waves leave together, along one direction) and reflects up to two rays
 * back in, an ordinary and an extraordinary one (uniaxial.h); the entry
 * node reflects one field and refracts an o and an e ray in.  The rays
 * inside therefore form a tree, walked depth first; a branch ends at
 * depth max_depth, below min_weight, at the rim, or when the node budget
 * is spent (its power is then `truncated`).  Along a segment of length s
 * a ray of wave vector K gains the optical path K . dir s and loses
 * exp(-alpha s) of its power. */
#include <math.h>

#include "error.h"
#include "interface.h"
#include "trace_crystal.h"

/* Nodes one forward trace may compute: a full tree of depth 16 (2^15
 * internal rays); past it branches are truncated. */
#define NODE_BUDGET 65536

typedef struct xbeam {
    lp_vec3 p;        /* local start point, on `surface` */
    int surface;
    lp_vec3 dir;      /* unit ray direction */
    lp_vec3 K;        /* wave vector / k0 */
    int kind;         /* LP__WAVE_O or LP__WAVE_E */
    lp__cvec3 E;      /* field, |E|^2 = power */
    double op;
    int depth;
    uint64_t path, waves;
} xbeam;

lp_status lp__crystal_optics_at(const lp_lens *lens, lp__optics *o, lp__crystal_optics *x,
                                lp_error *err)
{
    const lp_crystal *c = &lens->desc.crystal;
    double ne = lp_glass_index(&c->extraordinary, o->lambda_nm);
    if (!isfinite(ne) || !(ne > 0.0))
        return lp__fail(err, LP_ERROR_INVALID_GLASS, "crystal %s has no valid n_e at %g nm",
                        c->name, o->lambda_nm);
    x->crystal = (lp__medium){1, o->n_glass, ne, lens->crystal_axis};
    x->medium = (lp__medium){0, o->n_medium, o->n_medium, v3(0, 0, 1)};
    x->alpha_o = o->alpha;
    x->alpha_e = lp_glass_absorption(&c->extraordinary, o->lambda_nm);
    if (!isfinite(x->alpha_e) || x->alpha_e < 0.0)
        x->alpha_e = 0.0;
    if (!lp_glass_covers(&c->extraordinary, o->lambda_nm))
        o->warnings |= LP_WARN_EXTRAPOLATED;
    return LP_OK;
}

double lp__crystal_alpha(const lp__crystal_optics *x, int kind, lp_vec3 K)
{
    if (kind == LP__WAVE_O || (x->alpha_o == 0.0 && x->alpha_e == 0.0))
        return x->alpha_o;
    /* first order in the absorption: the imaginary part of n(psi) from
     * 1/n^2 = cos^2/n_o^2 + sin^2/n_e^2 with complex n_o, n_e */
    const lp__medium *m = &x->crystal;
    double n = v3_len(K), c = v3_dot(K, m->c) / n, c2 = c * c, s2 = 1.0 - c2;
    return n * n * n *
           (c2 * x->alpha_o / (m->no * m->no * m->no) + s2 * x->alpha_e / (m->ne * m->ne * m->ne));
}

static lp__cvec3 cv_sum(lp__cvec3 a, lp__cvec3 b)
{
    lp__cvec3 r = {a.x + b.x, a.y + b.y, a.z + b.z};
    return r;
}

/* The field's real part, or its imaginary part when that is zero: a
 * direction for the s axis at normal incidence. */
static lp_vec3 field_hint(const lp__cvec3 *E)
{
    lp_vec3 e = cv3_re(*E);
    return v3_dot(e, e) > 0.0 ? e : cv3_im(*E);
}

/* Emit the isotropic side's field (out[j0] + out[j0+1]) of node x. */
static lp_status emit_side(const lp_lens *lens, const lp_trace_args *a, lp_result *res,
                           const lp__xnode *x, const lp__cvec3 out[4], int j0, lp_vec3 p,
                           const lp__payload *pl, int depth, lp_kind kind, int surface,
                           uint64_t path, uint64_t waves, lp_error *err)
{
    const lp__wave *w = &x->out[j0];
    if (w->evanescent)
        return LP_OK; /* total reflection: nothing leaves */
    lp__branch b;
    b.dir = w->ray;
    b.E = cv_sum(out[j0], out[j0 + 1]);
    b.flip = 0;
    size_t first = res->count;
    lp_status st = lp__leave(lens, a, res, &b, p, pl, depth, kind, surface, path, err);
    for (size_t i = first; i < res->count; i++)
        res->rays[i].waves = waves;
    return st;
}

/* Push the crystal side's o and e rays of node x. */
static void push_inside(xbeam *stack, int *n, const lp__xnode *x, const lp__cvec3 out[4],
                        int j0, lp_vec3 p, int surface, double op, int depth, uint64_t path,
                        uint64_t waves)
{
    for (int j = j0; j < j0 + 2; j++) {
        const lp__wave *w = &x->out[j];
        if (w->evanescent || !(cv3_norm2(out[j]) > 0.0))
            continue;
        xbeam *b = &stack[(*n)++];
        b->p = p;
        b->surface = surface;
        b->dir = w->ray;
        b->K = cv3_re(w->K);
        b->kind = w->kind;
        b->E = out[j];
        b->op = op;
        b->depth = depth;
        b->path = path;
        b->waves = waves | (w->kind == LP__WAVE_E ? (uint64_t)1 << (depth - 1) : 0);
    }
}

lp_status lp__crystal_forward(const lp_lens *lens, lp__optics *o, const lp_trace_args *a,
                              const lp__local_hit *h, lp_vec3 d, const lp__cvec3 *E,
                              const lp__payload *pl, lp_result *res, lp_error *err)
{
    lp__crystal_optics xo;
    lp__xnode x;
    lp__cvec3 out[4];
    lp_status st;
    /* depth first: each node pops one ray and pushes at most two, so the
     * stack never holds more than max_depth + 1 */
    xbeam stack[LP_MAX_DEPTH + 2];
    int n = 0;
    double I0 = cv3_norm2(*E);
    size_t budget = NODE_BUDGET;

    if ((st = lp__crystal_optics_at(lens, o, &xo, err)) != LP_OK)
        return st;
    res->warnings |= o->warnings;
    int entry = h->surface;

    /* Node 1: from the medium into the crystal. */
    lp__xnode_setup(&x, &xo.medium, &xo.crystal, LP__WAVE_S, v3_scale(d, xo.medium.no),
                    v3_neg(h->n), field_hint(E));
    res->nodes++;
    if (lp__xnode_apply(&x, E, out) != 0) {
        res->absorbed_rim += I0; /* exactly grazing: cannot be followed */
        res->warnings |= LP_WARN_LEAK;
        return LP_OK;
    }
    if ((st = emit_side(lens, a, res, &x, out, 0, h->p, pl, 1, LP_KIND_REFLECT, h->surface,
                        1u, 0, err)) != LP_OK)
        return st;
    push_inside(stack, &n, &x, out, 2, h->p, h->surface, pl->op, 1, 0, 0);

    while (n > 0) {
        xbeam b = stack[--n];
        double power = cv3_norm2(b.E);
        if (b.depth >= a->max_depth || power < a->min_weight * I0 || budget == 0) {
            res->truncated += power;
            continue;
        }
        lp__local_hit hh;
        if (!lp__lens_hit(lens, b.p, b.dir, b.surface, 0.0, INFINITY, &hh)) {
            res->absorbed_rim += power; /* cannot happen on a closed surface */
            res->warnings |= LP_WARN_LEAK;
            continue;
        }
        double alpha = lp__crystal_alpha(&xo, b.kind, b.K);
        if (alpha > 0.0) {
            res->absorbed_glass += power * -expm1(-alpha * hh.t);
            b.E = cv3_scale(b.E, exp(-0.5 * alpha * hh.t));
        }
        b.op += v3_dot(b.K, b.dir) * hh.t;
        if (hh.surface == LP_SURFACE_RIM) {
            res->absorbed_rim += cv3_norm2(b.E);
            continue;
        }
        int depth = b.depth + 1;
        budget--;
        res->nodes++;
        lp__xnode_setup(&x, &xo.crystal, &xo.medium, b.kind, b.K, hh.n, field_hint(&b.E));
        if (lp__xnode_apply(&x, &b.E, out) != 0) {
            res->absorbed_rim += cv3_norm2(b.E);
            res->warnings |= LP_WARN_LEAK;
            continue;
        }
        lp__payload pb = *pl;
        pb.op = b.op;
        lp_kind kind = hh.surface == entry ? LP_KIND_REFLECT : LP_KIND_TRANSMIT;
        if ((st = emit_side(lens, a, res, &x, out, 2, hh.p, &pb, depth, kind, hh.surface,
                            b.path, b.waves, err)) != LP_OK)
            return st;
        push_inside(stack, &n, &x, out, 0, hh.p, hh.surface, b.op, depth,
                    b.path | (uint64_t)1 << (depth - 1), b.waves);
    }
    return LP_OK;
}
