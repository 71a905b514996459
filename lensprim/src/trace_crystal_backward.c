/* trace_crystal_backward.c -- from the eye through a lens of a uniaxial
 * crystal, in two phases.
 *
 * build: the view ray's tree through the crystal (an o and an e ray at
 * every node, as in trace_crystal.c) is traced in the eye's direction;
 * every node where light can come in from outside gives a query ray.
 * Each node keeps its parent, so a query's path back to the eye is the
 * chain of parents.
 *
 * gather: light answering a query arrives along -query.dir and follows
 * the path in the direction of light: it refracts in at the query's node
 * into the wave (o or e) of the segment the eye came along, reflects at
 * each parent into the wave of the segment before, and refracts out at
 * the entry node towards the eye.  Uniaxial media are reciprocal and
 * their wave surfaces centrosymmetric, so the light's wave vectors are
 * exactly the eye's reversed; at each node the one outgoing wave of the
 * path's kind is taken. */
#include <math.h>
#include <stdlib.h>

#include "error.h"
#include "trace_crystal.h"

#define NODE_BUDGET 65536

typedef struct xnode_rec {
    lp_vec3 p;       /* local point */
    lp_vec3 n;       /* outward normal */
    int parent;      /* index of the node the segment came from, -1 at entry */
    int kind;        /* wave of the segment parent -> this node (O/E) */
    lp_vec3 K;       /* its wave vector, eye direction */
    double seg;      /* its length */
    int depth;
    int surface;     /* LP_SURFACE_FRONT or LP_SURFACE_BACK */
} xnode_rec;

struct lp__xback {
    int active;
    const lp_lens *lens;
    lp_trace_args args;
    lp__optics optics;
    lp__crystal_optics xo;
    lp_vec3 view_dir;
    xnode_rec *node;
    size_t n_nodes, cap_nodes;
    lp_query *query;
    int *query_node;     /* the node each query leaves from */
    lp_vec3 *query_dir;  /* local */
    size_t n_queries, cap_queries;
    int rim_depth;
    unsigned warnings;
};

void lp__xback_free(lp__xback *x)
{
    if (!x)
        return;
    free(x->node);
    free(x->query);
    free(x->query_node);
    free(x->query_dir);
    free(x);
}

int lp__xback_active(const lp__xback *x) { return x && x->active; }
size_t lp__xback_query_count(const lp__xback *x) { return x->n_queries; }
const lp_query *lp__xback_queries(const lp__xback *x) { return x->query; }
int lp__xback_rim_depth(const lp__xback *x) { return x->rim_depth; }
void lp__xback_deactivate(lp__xback *x)
{
    if (x)
        x->active = 0;
}

static int add_node(lp__xback *x, const xnode_rec *r)
{
    if (x->n_nodes == x->cap_nodes) {
        size_t cap = x->cap_nodes ? 2 * x->cap_nodes : 16;
        xnode_rec *p = realloc(x->node, cap * sizeof *p);
        if (!p)
            return -1;
        x->node = p;
        x->cap_nodes = cap;
    }
    x->node[x->n_nodes] = *r;
    return (int)x->n_nodes++;
}

static int add_query(lp__xback *x, int node, lp_kind kind, int surface, lp_vec3 dir,
                     uint64_t path, uint64_t waves, double op, double bound, double weight)
{
    lp_branch_info info;
    if (bound < x->args.min_weight ||
        !lp__branch_keep(x->lens, &x->args, x->node[node].depth, kind, surface, x->node[node].p,
                         dir, bound, &info))
        return 0;
    if (x->n_queries == x->cap_queries) {
        size_t cap = x->cap_queries ? 2 * x->cap_queries : 16;
        lp_query *q = realloc(x->query, cap * sizeof *q);
        if (q)
            x->query = q;
        int *qn = realloc(x->query_node, cap * sizeof *qn);
        if (qn)
            x->query_node = qn;
        lp_vec3 *qd = realloc(x->query_dir, cap * sizeof *qd);
        if (qd)
            x->query_dir = qd;
        if (!q || !qn || !qd)
            return -1;
        x->cap_queries = cap;
    }
    lp_query *q = &x->query[x->n_queries];
    q->origin = info.origin;
    q->dir = info.dir;
    q->depth = info.depth;
    q->kind = kind;
    q->surface = surface;
    q->path = path;
    q->waves = waves;
    q->op = op;
    q->bound = bound;
    q->weight = weight;
    x->query_node[x->n_queries] = node;
    x->query_dir[x->n_queries] = dir;
    x->n_queries++;
    return 0;
}

/* Power factors of the outgoing waves j0, j0+1 of a node for an incident
 * isotropic beam (bound: max over s and p; weight: their mean) or crystal
 * beam of the node's incident kind. */
static void node_powers(const lp__xnode *x, int iso, double bound[4], double weight[4])
{
    double complex c[4];
    for (int j = 0; j < 4; j++)
        bound[j] = weight[j] = 0.0;
    for (int k = 0; k < 2; k++) {
        if (!iso && (k == 0) != (x->inc_kind == LP__WAVE_O))
            continue;
        if (lp__xnode_solve(x, &x->inc[k], c) != 0)
            continue;
        for (int j = 0; j < 4; j++) {
            double P = creal(c[j] * conj(c[j]));
            bound[j] = fmax(bound[j], P);
            weight[j] += iso ? 0.5 * P : P;
        }
    }
}

typedef struct eye_beam {
    int from;        /* node index */
    lp_vec3 dir, K;
    int kind;
    double op, bound, weight;
    uint64_t path, waves;
    int depth;
} eye_beam;

static lp_vec3 zero3(void)
{
    lp_vec3 z = {0, 0, 0};
    return z;
}

lp_status lp__crystal_build(lp__xback **xp, const lp_lens *lens, const lp__optics *optics,
                            const lp_trace_args *args, lp_vec3 d, const lp__local_hit *h,
                            lp_error *err)
{
    lp__xback *x = *xp;
    lp__xnode nd;
    lp_status st;
    double bw_[4], wt_[4];

    if (!x) {
        x = calloc(1, sizeof *x);
        if (!x)
            return lp__fail(err, LP_ERROR_NO_MEMORY, "out of memory building a backward trace");
        *xp = x;
    }
    x->active = 1;
    x->lens = lens;
    x->args = *args;
    x->optics = *optics;
    x->view_dir = d;
    x->n_nodes = x->n_queries = 0;
    x->rim_depth = 0;
    if ((st = lp__crystal_optics_at(lens, &x->optics, &x->xo, err)) != LP_OK)
        return st;
    x->warnings = x->optics.warnings;
    const lp__crystal_optics *xo = &x->xo;
    double nm = xo->medium.no;

    xnode_rec entry = {h->p, h->n, -1, 0, zero3(), 0.0, 1, h->surface};
    if (add_node(x, &entry) < 0)
        return lp__fail(err, LP_ERROR_NO_MEMORY, "out of memory building a backward trace");
    int entry_surface = h->surface;
    lp__xnode_setup(&nd, &xo->medium, &xo->crystal, LP__WAVE_S, v3_scale(d, nm), v3_neg(h->n),
                    zero3());
    node_powers(&nd, 1, bw_, wt_);
    if (add_query(x, 0, LP_KIND_REFLECT, h->surface, nd.out[0].ray, 1u, 0, 0.0, bw_[0] + bw_[1],
                  wt_[0] + wt_[1]) < 0)
        return lp__fail(err, LP_ERROR_NO_MEMORY, "out of memory building a backward trace");

    eye_beam stack[LP_MAX_DEPTH + 2];
    int n = 0;
    for (int j = 2; j < 4; j++) {
        if (nd.out[j].evanescent || !(bw_[j] > 0.0))
            continue;
        eye_beam *b = &stack[n++];
        b->from = 0;
        b->dir = nd.out[j].ray;
        b->K = cv3_re(nd.out[j].K);
        b->kind = nd.out[j].kind;
        b->op = 0.0;
        b->bound = bw_[j];
        b->weight = wt_[j];
        b->path = 0;
        b->waves = nd.out[j].kind == LP__WAVE_E ? 1u : 0u;
        b->depth = 1;
    }
    size_t budget = NODE_BUDGET;
    while (n > 0) {
        eye_beam b = stack[--n];
        if (b.depth >= x->args.max_depth || b.bound < x->args.min_weight || budget == 0)
            continue;
        const xnode_rec *from = &x->node[b.from];
        lp__local_hit hh;
        if (!lp__lens_hit(lens, from->p, b.dir, from->surface, 0.0, INFINITY, &hh)) {
            x->warnings |= LP_WARN_LEAK;
            continue;
        }
        double att = exp(-lp__crystal_alpha(xo, b.kind, b.K) * hh.t);
        b.bound *= att;
        b.weight *= att;
        b.op += v3_dot(b.K, b.dir) * hh.t;
        if (hh.surface == LP_SURFACE_RIM) {
            if (x->rim_depth == 0 || b.depth + 1 < x->rim_depth)
                x->rim_depth = b.depth + 1;
            continue;
        }
        budget--;
        xnode_rec rec = {hh.p, hh.n, b.from, b.kind, b.K, hh.t, b.depth + 1, hh.surface};
        int me = add_node(x, &rec);
        if (me < 0)
            return lp__fail(err, LP_ERROR_NO_MEMORY, "out of memory building a backward trace");
        lp__xnode_setup(&nd, &xo->crystal, &xo->medium, b.kind, b.K, hh.n, zero3());
        node_powers(&nd, 0, bw_, wt_);
        if (!nd.out[2].evanescent) {
            lp_kind kind = hh.surface == entry_surface ? LP_KIND_REFLECT : LP_KIND_TRANSMIT;
            if (add_query(x, me, kind, hh.surface, nd.out[2].ray, b.path, b.waves, b.op,
                          b.bound * (bw_[2] + bw_[3]), b.weight * (wt_[2] + wt_[3])) < 0)
                return lp__fail(err, LP_ERROR_NO_MEMORY,
                                "out of memory building a backward trace");
        }
        int depth = b.depth + 1;
        for (int j = 0; j < 2; j++) {
            if (nd.out[j].evanescent || !(bw_[j] > 0.0))
                continue;
            eye_beam *c = &stack[n++];
            c->from = me;
            c->dir = nd.out[j].ray;
            c->K = cv3_re(nd.out[j].K);
            c->kind = nd.out[j].kind;
            c->op = b.op;
            c->bound = b.bound * bw_[j];
            c->weight = b.weight * wt_[j];
            c->path = b.path | (uint64_t)1 << (depth - 1);
            c->waves = b.waves | (nd.out[j].kind == LP__WAVE_E ? (uint64_t)1 << (depth - 1) : 0);
            c->depth = depth;
        }
    }
    lp__ok(err);
    return LP_OK;
}

static lp_vec3 hint_of(const lp__cvec3 *E)
{
    lp_vec3 e = cv3_re(*E);
    return v3_dot(e, e) > 0.0 ? e : cv3_im(*E);
}

/* One bundle ray through the path of query qi, in the direction of light. */
static lp_status gather_one(const lp__xback *x, size_t qi, const lp_ray *b, lp_result *res,
                            lp_error *err)
{
    const lp__crystal_optics *xo = &x->xo;
    const lp_query *q = &x->query[qi];
    lp_vec3 light = v3_neg(x->query_dir[qi]);
    lp_vec3 vp;
    lp__xnode nd;
    lp__cvec3 out[4];

    lp_status st = lp__bundle_ray_check(x->lens, b, light, &vp, err);
    if (st != LP_OK)
        return st;
    double I0 = b->intensity, absorbed = 0.0;
    lp__cvec3 E = cv3_real(vp, sqrt(I0));
    lp__payload pl = {x->optics.lambda_nm, b->kphi, b->op + q->op, b->phase, b->ch};
    double nm = xo->medium.no;
    int k = x->query_node[qi];
    res->in += I0;

    const xnode_rec *nk = &x->node[k];
    lp__xnode_setup(&nd, &xo->medium, &xo->crystal, LP__WAVE_S, v3_scale(light, nm),
                    v3_neg(nk->n), hint_of(&E));
    res->nodes++;
    int ok = lp__xnode_apply(&nd, &E, out) == 0;
    if (k == 0) {
        /* the external reflection */
        E = (lp__cvec3){out[0].x + out[1].x, out[0].y + out[1].y, out[0].z + out[1].z};
    } else {
        int kind = nk->kind;
        E = out[kind == LP__WAVE_O ? 2 : 3];
        lp_vec3 K = v3_neg(nk->K);
        for (int j = k; ok && j > 0; j = x->node[j].parent) {
            const xnode_rec *nj = &x->node[j];
            double s = nj->seg;
            double alpha = lp__crystal_alpha(xo, nj->kind, K);
            if (alpha > 0.0) {
                absorbed += cv3_norm2(E) * -expm1(-alpha * s);
                E = cv3_scale(E, exp(-0.5 * alpha * s));
            }
            const xnode_rec *np = &x->node[nj->parent];
            lp__xnode_setup(&nd, &xo->crystal, &xo->medium, nj->kind, K, np->n, hint_of(&E));
            res->nodes++;
            if (lp__xnode_apply(&nd, &E, out) != 0) {
                ok = 0;
                break;
            }
            if (nj->parent == 0) {
                E = (lp__cvec3){out[2].x + out[3].x, out[2].y + out[3].y, out[2].z + out[3].z};
            } else {
                int pk = np->kind;
                E = out[pk == LP__WAVE_O ? 0 : 1];
                K = v3_neg(np->K);
            }
        }
    }
    if (!ok) {
        res->warnings |= LP_WARN_LEAK;
        res->absorbed_rim += I0 - absorbed;
        res->absorbed_glass += absorbed;
        return LP_OK;
    }
    lp__exit ex = lp__exit_at(x->lens, x->node[0].p, v3_neg(x->view_dir));
    return lp__emit_gathered(x->lens, res, &E, &ex, &pl, q, I0, absorbed, err);
}

lp_status lp__crystal_gather(const lp__xback *x, size_t q, const lp_ray *bundle, size_t n,
                             lp_result *out, lp_error *err)
{
    lp_status st;
    if (q >= x->n_queries)
        return lp__fail(err, LP_ERROR_RANGE, "query %zu does not exist (%zu queries)", q,
                        x->n_queries);
    out->warnings |= x->warnings;
    for (size_t i = 0; i < n; i++)
        if ((st = gather_one(x, q, &bundle[i], out, err)) != LP_OK)
            return st;
    lp__ok(err);
    return LP_OK;
}
