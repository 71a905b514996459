/* trace_backward.c -- from the eye, in two phases.
 *
 * build: the view ray's chain through the lens is traced in the eye's
 * direction; every node where light could come in from outside gives a
 * query ray.  The geometry of each node is kept.
 *
 * gather: light answering query k arrives along -query.dir at node k and
 * runs back along the chain to node 1, where it leaves towards the eye.
 * Refraction is reversible, so the light path is the eye path reversed;
 * at each node G is applied in the direction of light: at node k the
 * light refracts in (or, k = 1, reflects off the outside), at nodes
 * k-1..2 it reflects inside, at node 1 it refracts out.  The nodes of the
 * light's way, with the axes of the branch it takes at each, serve any
 * field: every bundle ray runs through the same ones (only at normal
 * incidence does a node's s axis follow the field: lp__node_refit).  A
 * polarized build, whose light comes only by gathering, sets them up
 * once for every gather of its queries; in the other modes, whose query
 * weights are exact and seldom gathered, a gather sets up its own. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "backward.h"
#include "jones.h"
#include "error.h"
#include "interface.h"

lp_status lp_backward_create(lp_backward **out, lp_error *err)
{
    if (!out)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_backward_create: NULL argument");
    /* Only the scalars, which come first (backward.h), are cleared.  The
     * per-node and per-query arrays after them, all but a few hundred
     * bytes of the builder's 55 kB, are written by every build before
     * anything reads them (a node as the chain reaches it, a query's
     * entries as it is added, the ways when a build sets them up):
     * zeroing them paid for pages a shallow build never touches, each
     * time a builder was made (--mode auto's probe makes a worker per
     * render: 30 % of its time on desk_lamp.scene at 320 x 240). */
    lp_backward *bw = malloc(sizeof *bw);
    if (!bw)
        return lp__fail(err, LP_ERROR_NO_MEMORY, "out of memory creating a backward tracer");
    memset(bw, 0, offsetof(lp_backward, node));
    *out = bw;
    lp__ok(err);
    return LP_OK;
}

void lp_backward_destroy(lp_backward *bw)
{
    if (bw)
        lp__xback_free(bw->xb);
    free(bw);
}

size_t lp_backward_query_count(const lp_backward *bw)
{
    if (bw && lp__xback_active(bw->xb))
        return lp__xback_query_count(bw->xb);
    return bw ? bw->n_queries : 0;
}

const lp_query *lp_backward_queries(const lp_backward *bw)
{
    if (bw && lp__xback_active(bw->xb))
        return lp__xback_queries(bw->xb);
    return bw ? bw->query : NULL;
}

int lp_backward_rim_depth(const lp_backward *bw)
{
    if (bw && lp__xback_active(bw->xb))
        return lp__xback_rim_depth(bw->xb);
    return bw ? bw->rim_depth : 0;
}

int lp_backward_query_leaves(const lp_backward *bw, size_t q)
{
    if (!bw || lp__xback_active(bw->xb) || q >= bw->n_queries)
        return 0;
    if (bw->leaves[q] >= 0)
        return bw->leaves[q];
    return lp__lens_leaves(bw->lens, bw->query[q].origin, bw->query[q].dir);
}

/* Power factors of a node for the bound (max over s/p) and the
 * unpolarized weight of the mode. */
static double node_bound(const lp__node *nd, lp_mode mode, int reflect)
{
    if (mode != LP_MODE_POLARIZED) {
        double R = lp__node_reflectance(nd, mode);
        return reflect ? R : 1.0 - R;
    }
    if (reflect)
        return lp__max(nd->f.Rs, nd->f.Rp);
    return lp__max(nd->f.ts * nd->f.ts, nd->f.tp * nd->f.tp);
}

static double node_weight(const lp__node *nd, lp_mode mode, int reflect)
{
    double R = lp__node_reflectance(nd, mode == LP_MODE_POLARIZED ? LP_MODE_FRESNEL : mode);
    return reflect ? R : 1.0 - R;
}

/* The node where light answering query qi enters the lens (any field):
 * it reflects off the outside (depth 1) or refracts in. */
void lp__backward_entry_way(const lp_backward *bw, size_t qi, lp__bw_way *w)
{
    const lp_query *q = &bw->query[qi];
    lp__node_setup(&w->node, v3_neg(bw->query_dir[qi]), bw->node[q->depth].n,
                   bw->optics.n_medium, bw->optics.n_glass, NULL);
    w->reflect = q->depth == 1;
    if (w->reflect)
        lp__node_reflect_axes(&w->node, &w->ax);
    else
        lp__node_transmit_axes(&w->node, &w->ax);
}

/* The node j of the way back, light arriving from inside (any field): it
 * reflects there (j > 1) or refracts out (j = 1). */
void lp__backward_light_way(const lp_backward *bw, int j, lp__bw_way *w)
{
    lp__node_setup(&w->node, v3_neg(bw->node[j].e_out), bw->node[j].n, bw->optics.n_glass,
                   bw->optics.n_medium, NULL);
    w->reflect = j > 1;
    if (w->reflect)
        lp__node_reflect_axes(&w->node, &w->ax);
    else
        lp__node_transmit_axes(&w->node, &w->ax);
}

int lp__backward_deepest(const lp_backward *bw)
{
    int deepest = 0;
    for (size_t qi = 0; qi < bw->n_queries; qi++)
        if (bw->query[qi].depth > deepest)
            deepest = bw->query[qi].depth;
    return deepest;
}

/* Once bw's ways are set up (lp__backward_ways_many): where each way's fields
 * turn complex, if the lanes take it: at[j] for the light's way from
 * node j - 1 down (-1: not in lanes; 0: the field stays real; else the
 * first node under total internal reflection), then each query's from
 * its entry on. */
static void mark_ways(lp_backward *bw, int deepest)
{
    signed char at[LP_MAX_DEPTH + 1];
    at[1] = 0;
    for (int j = 1; j < deepest; j++) {
        const lp__bw_way *w = &bw->light[j];
        int tir = w->node.f.tir;
        at[j + 1] = (signed char)(w->node.normal || (tir && !w->reflect) || at[j] < 0 ? -1
                                  : tir ? j : at[j]);
    }
    for (size_t qi = 0; qi < bw->n_queries; qi++) {
        const lp__bw_way *w = &bw->entry[qi];
        int k = bw->query[qi].depth, tir = w->node.f.tir;
        bw->complex_at[qi] = (signed char)(w->node.normal || (tir && !w->reflect) || at[k] < 0
                                               ? -1
                                               : tir ? k : at[k]);
    }
    bw->ways = 1;
}

int lp__backward_sets_ways(const lp_backward *bw)
{
    return bw->args.mode == LP_MODE_POLARIZED && !lp__backward_power(&bw->args) &&
           !lp__xback_active(bw->xb);
}

void lp__backward_keep_form(lp_backward *bw, size_t before, const double P[3], lp_vec3 s,
                            lp_vec3 p, double ok)
{
    if (bw->n_queries == before)
        return;
    size_t k = bw->n_queries - 1;
    bw->pform[k][0] = P[0], bw->pform[k][1] = P[1], bw->pform[k][2] = P[2];
    bw->pform_s[k] = s;
    bw->pform_p[k] = p;
    bw->pform_ok[k] = ok != 0.0;
}

/* The ways of every query of a polarized build (backward.h). */
void lp__backward_built(lp_backward *bw)
{
    lp__backward_built_many(&bw, 1);
}

/* Those of many builds, set up in lanes across them (backward.h). */
void lp__backward_built_many(lp_backward *const *bw, size_t n)
{
    lp__backward_ways_many(bw, n);
    for (size_t k = 0; k < n; k++)
        if (lp__backward_sets_ways(bw[k]))
            mark_ways(bw[k], lp__backward_deepest(bw[k]));
}

/* Field E through way node w in the direction of light, into *br. */
static void way_step(const lp__bw_way *w, lp_mode mode, const lp__cvec3 *E, lp__branch *br)
{
    if (w->node.normal) { /* the s axis follows the field: set up for it */
        lp__node nd = w->node;
        lp__node_refit(&nd, E);
        if (w->reflect)
            lp__node_reflect(&nd, mode, E, br);
        else
            lp__node_transmit(&nd, mode, E, br);
        return;
    }
    lp__amp amp;
    lp__node_project(&w->node, E, &amp);
    if (w->reflect)
        lp__node_reflect_on(&w->node, &w->ax, mode, &amp, br);
    else
        lp__node_transmit_on(&w->node, &w->ax, mode, &amp, br);
}

void lp__backward_add_query(lp_backward *bw, int depth, lp_kind kind, int surface, lp_vec3 dir,
                            uint64_t path, double op, double bound, double weight)
{
    lp__backward_add_query_at(bw, depth, kind, surface, dir,
                              lp__to_world_point(bw->lens, bw->node[depth].p),
                              lp__to_world_dir(bw->lens, dir), path, op, bound, weight, -1);
}

void lp__backward_add_query_at(lp_backward *bw, int depth, lp_kind kind, int surface,
                               lp_vec3 dir, lp_vec3 world_origin, lp_vec3 world_dir,
                               uint64_t path, double op, double bound, double weight,
                               int leaves)
{
    lp_query *q = &bw->query[bw->n_queries];

    if (bound < bw->args.min_weight)
        return;
    if ((bw->args.flags & ~(unsigned)LP_BACKWARD_POWER) != 0 ||
        bw->args.filter) { /* else lp__args_keep keeps it */
        lp_branch_info info = {depth, kind, surface, world_origin, world_dir, bound};
        if (!lp__args_keep(&bw->args, &info))
            return;
    }
    /* every byte, padding too: a query is public, and two builds of one
     * ray give byte-identical queries (the builder is not zeroed when
     * made) */
    memset(q, 0, sizeof *q);
    q->origin = world_origin;
    q->dir = world_dir;
    q->depth = depth;
    q->kind = kind;
    q->surface = surface;
    q->path = path;
    q->op = op;
    q->bound = bound;
    q->weight = weight;
    q->waves = 0;
    bw->pform_ok[bw->n_queries] = 0;
    bw->query_dir[bw->n_queries] = dir;
    bw->leaves[bw->n_queries] = (signed char)leaves;
    bw->n_queries++;
}

static lp_status build_chain(lp_backward *bw, const lp_lens *lens, lp_vec3 origin, lp_vec3 dir,
                             double lambda_nm, const lp_trace_args *args, lp_error *err)
{
    lp__local_hit h;
    lp__node nd;
    lp_status st;

    if (!bw || !lens)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_backward_build: NULL argument");
    bw->lens = lens;
    bw->n_nodes = 0;
    bw->n_queries = 0;
    bw->rim_depth = 0;
    bw->warnings = 0;
    if ((st = lp__args_resolve(args, &bw->args, err)) != LP_OK)
        return st;
    lp__xback_deactivate(bw->xb);
    if (!v3_finite(origin) || !v3_finite(dir))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "view ray is not finite");
    lp_vec3 dw = v3_normalize(dir);
    if (dw.x == 0.0 && dw.y == 0.0 && dw.z == 0.0)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "view ray direction is the zero vector");
    if ((st = lp__optics_at(lens, lambda_nm, &bw->optics, err)) != LP_OK)
        return st;
    bw->warnings = bw->optics.warnings;

    const lp__optics *o = &bw->optics;
    lp_mode mode = bw->args.mode;
    lp_vec3 p = lp__to_local_point(lens, origin), d = lp__to_local_dir(lens, dw);
    bw->view_dir = d;
    if (!lp__lens_hit(lens, p, d, lp__lens_surface_at(lens, p), 0.0, INFINITY, &h)) {
        lp__ok(err);
        return LP_OK;
    }
    if (h.surface == LP_SURFACE_RIM) {
        bw->rim_depth = 1;
        lp__ok(err);
        return LP_OK;
    }
    if (lens->desc.uniaxial)
        return lp__crystal_build(&bw->xb, lens, &bw->optics, &bw->args, d, &h, err);

    int entry = h.surface;
    bw->exit = lp__exit_at(lens, h.p, v3_neg(d));
    bw->n_nodes = 1;
    bw->node[1].p = h.p;
    bw->node[1].n = h.n;
    bw->node[1].surface = h.surface;
    /* the branches' directions and powers (no fields) */
    int tir = lp__node_setup_fresnel(&nd, d, h.n, o->n_medium, o->n_glass);
    /* the light's way as a Jones matrix (jones.h), in a power build */
    const int power = lp__backward_power(&bw->args);
    lp__cm2 R = lp__jones_diag(0.0, 0.0, 0.0, 0.0);
    lp_vec3 s_prev = v3(0, 0, 0), p_prev = s_prev, es = s_prev, ep = s_prev;
    double jok = 0.0, qok = 0.0, P[3] = {0.0, 0.0, 0.0};
    lp_vec3 r = lp__node_reflect_dir(&nd), t = lp__node_transmit_dir(&nd);
    if (power)
        lp__jones_first(d, h.n, r, t, creal(nd.f.rs), creal(nd.f.rp), nd.f.tir, nd.cos_i,
                        o->n_medium, o->n_glass, nd.f.ts, nd.f.tp, &R, &s_prev, &p_prev, &jok, P,
                        &es, &ep, &qok);
    size_t before = bw->n_queries;
    lp__backward_add_query(bw, 1, LP_KIND_REFLECT, h.surface, r, 1u, 0.0,
                           node_bound(&nd, mode, 1), node_weight(&nd, mode, 1));
    if (power && bw->n_queries > before)
        lp__backward_keep_form(bw, before, P, lp__to_world_dir(lens, es),
                               lp__to_world_dir(lens, ep), qok);
    if (tir) {
        lp__ok(err);
        return LP_OK;
    }

    double bound = node_bound(&nd, mode, 0), weight = node_weight(&nd, mode, 0), op = 0.0;
    uint64_t path = 0;
    int depth = 1;
    d = t;
    p = h.p;
    int surface = h.surface;
    bw->node[1].e_out = d;

    while (depth < bw->args.max_depth && !(bound < bw->args.min_weight)) {
        if (!lp__lens_hit(lens, p, d, surface, 0.0, INFINITY, &h)) {
            bw->warnings |= LP_WARN_LEAK;
            break;
        }
        double m = o->alpha > 0.0 ? expm1(-0.5 * o->alpha * h.t) : 0.0;
        double att = (1.0 + m) * (1.0 + m);
        bound *= att;
        weight *= att;
        op += o->n_glass * h.t;
        bw->node[depth].seg = h.t;
        bw->node[depth].seg_att = 1.0 + m;
        bw->node[depth].seg_abs = -m * (2.0 + m);
        if (h.surface == LP_SURFACE_RIM) {
            bw->rim_depth = depth + 1;
            break;
        }
        depth++;
        bw->n_nodes = depth;
        bw->node[depth].p = h.p;
        bw->node[depth].n = h.n;
        bw->node[depth].surface = h.surface;
        tir = lp__node_setup_fresnel(&nd, d, h.n, o->n_glass, o->n_medium);
        r = lp__node_reflect_dir(&nd), t = lp__node_transmit_dir(&nd);
        if (power)
            lp__jones_node(d, h.n, r, t, 1.0 + m, nd.f.ts, nd.f.tp, creal(nd.f.rs),
                           creal(nd.f.rp), nd.f.tir, nd.cos_i, o->n_glass, o->n_medium, &R,
                           &s_prev, &p_prev, &jok, P, &es, &ep, &qok);
        before = bw->n_queries;
        if (!tir)
            lp__backward_add_query(bw, depth,
                                   h.surface == entry ? LP_KIND_REFLECT : LP_KIND_TRANSMIT,
                                   h.surface, t, path, op,
                                   bound * node_bound(&nd, mode, 0),
                                   weight * node_weight(&nd, mode, 0));
        if (power && bw->n_queries > before)
            lp__backward_keep_form(bw, before, P, lp__to_world_dir(lens, es),
                                   lp__to_world_dir(lens, ep), qok);
        bound *= node_bound(&nd, mode, 1);
        weight *= node_weight(&nd, mode, 1);
        path |= (uint64_t)1 << (depth - 1);
        d = r;
        p = h.p;
        surface = h.surface;
        bw->node[depth].e_out = d;
    }
    lp__ok(err);
    return LP_OK;
}

lp_status lp_backward_build(lp_backward *bw, const lp_lens *lens, lp_vec3 origin, lp_vec3 dir,
                            double lambda_nm, const lp_trace_args *args, lp_error *err)
{
    if (bw)
        bw->ways = 0;
    lp_status st = build_chain(bw, lens, origin, dir, lambda_nm, args, err);
    if (st == LP_OK)
        lp__backward_built(bw);
    return st;
}

/* A real field e through way node w in the direction of light, in real
 * arithmetic (polarized mode): what way_step gives it.  0, e unchanged,
 * where a field may turn complex or steer the node (TIR, normal
 * incidence). */
static int way_step_real(const lp__bw_way *w, lp_vec3 *e, int *flip)
{
    const lp__node *nd = &w->node;
    if (nd->normal || nd->f.tir)
        return 0;
    double es = v3_dot(*e, nd->s), ep = v3_dot(*e, nd->p);
    *flip = 0;
    if (w->reflect)
        *e = lp__node_reflect_real(nd, &w->ax, es, ep, flip);
    else
        *e = lp__node_transmit_real(nd, &w->ax, es, ep);
    return 1;
}

/* One bundle ray through the path of a query, in the direction of light:
 * it enters at `entry` (node k) and runs back through light[k-1..1],
 * where it reflects inside (j > 1) and refracts out (j = 1).  The field
 * is kept real (e) as long as it stays real, then complex (E). */
static lp_status gather_one(const lp_backward *bw, size_t qi, const lp__bw_way *entry,
                            const lp__bw_way *light, const lp_ray *b, lp_result *res,
                            lp_error *err)
{
    const lp__optics *o = &bw->optics;
    const lp_query *q = &bw->query[qi];
    lp_mode mode = bw->args.mode;
    lp__branch br;
    lp_vec3 vp;
    int k = q->depth;

    lp_status st0 = lp__bundle_ray_check(bw->lens, b, entry->node.d, &vp, err);
    if (st0 != LP_OK)
        return st0;

    double I0 = b->intensity;
    lp_vec3 e = v3_scale(vp, sqrt(I0));
    lp__cvec3 E = {0, 0, 0};
    int real = mode == LP_MODE_POLARIZED;
    if (!real)
        E = cv3_real(e, 1.0);
    lp__payload pl = {o->lambda_nm, b->kphi, b->op + q->op, b->phase, b->ch};
    double absorbed = 0.0;
    res->in += I0;

    for (int j = k; j >= 1; j--) {
        const lp__bw_way *w = j == k ? entry : &light[j];
        int flip;
        if (j < k && o->alpha > 0.0) { /* over the segment from node j + 1 */
            const lp__bw_node *nj = &bw->node[j];
            if (real) {
                absorbed += v3_dot(e, e) * nj->seg_abs;
                e = v3_scale(e, nj->seg_att);
            } else {
                absorbed += cv3_norm2(E) * nj->seg_abs;
                E = cv3_scale_real(E, nj->seg_att);
            }
        }
        if (real && !way_step_real(w, &e, &flip)) {
            real = 0;
            E = cv3_real(e, 1.0);
        }
        if (!real) {
            way_step(w, mode, &E, &br);
            flip = br.flip;
            E = br.E;
        }
        pl.kphi += flip;
    }
    res->nodes += (size_t)k;
    if (real)
        return lp__emit_gathered_real(bw->lens, res, e, &bw->exit, &pl, q, I0, absorbed, err);
    return lp__emit_gathered(bw->lens, res, &E, &bw->exit, &pl, q, I0, absorbed, err);
}

lp_status lp_backward_gather(const lp_backward *bw, size_t q, const lp_ray *bundle, size_t n,
                             lp_result *out, lp_error *err)
{
    lp_status st;
    if (!bw || !out || (!bundle && n > 0))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_backward_gather: NULL argument");
    if (lp__xback_active(bw->xb))
        return lp__crystal_gather(bw->xb, q, bundle, n, out, err);
    if (q >= bw->n_queries)
        return lp__fail(err, LP_ERROR_RANGE, "query %zu does not exist (%zu queries)", q,
                        bw->n_queries);
    out->warnings |= bw->warnings;
    if (n > 0) {
        const lp__bw_way *entry = &bw->entry[q], *light = bw->light;
        lp__bw_way way[LP_MAX_DEPTH + 1]; /* this gather's own: way[k] the entry */
        if (!bw->ways) {
            int k = bw->query[q].depth;
            lp__backward_entry_way(bw, q, &way[k]);
            for (int j = 1; j < k; j++)
                lp__backward_light_way(bw, j, &way[j]);
            entry = &way[k];
            light = way;
        }
        size_t i = 0;
        if (bw->ways && bw->complex_at[q] >= 0) {
            i = lp__gather_lanes(bw, q, bundle, n, out, &st, err);
            if (st != LP_OK)
                return st;
        }
        for (; i < n; i++)
            if ((st = gather_one(bw, q, entry, light, &bundle[i], out, err)) != LP_OK)
                return st;
    }
    lp__ok(err);
    return LP_OK;
}
