/* backward.h -- what an lp_backward holds (internal): trace_backward.c
 * builds one and gathers through it, backward_many.c builds many at once. */
#ifndef LP_BACKWARD_H
#define LP_BACKWARD_H

#include "interface.h"
#include "trace.h"
#include "trace_crystal.h"

/* A node of the view ray's chain. */
typedef struct lp__bw_node {
    lp_vec3 p;       /* local point */
    lp_vec3 n;       /* outward normal */
    lp_vec3 e_out;   /* eye direction inside the glass leaving this node */
    double seg;      /* length from this node to the next one */
    double seg_att;  /* amplitude factor over seg: exp(-alpha seg / 2) */
    double seg_abs;  /* power fraction absorbed over seg: 1 - seg_att^2 */
    int surface;
} lp__bw_node;

/* A node of the light's way back in a gather, for any field: the node
 * and the axes of the branch the light takes there. */
typedef struct lp__bw_way {
    lp__node node;
    lp__axes ax;
    int reflect;     /* 1: it reflects there, 0: it refracts */
} lp__bw_way;

struct lp_backward {
    /* The scalars first: lp_backward_create clears the builder up to
     * node[] and no further (the arrays below are written by every build
     * before they are read), so a new scalar belongs here. */
    const lp_lens *lens;
    lp_trace_args args;
    lp__optics optics;
    lp_vec3 view_dir;              /* local e_0 */
    int n_nodes;
    size_t n_queries;
    lp__exit exit;                   /* where gathered light leaves */
    int rim_depth;
    unsigned warnings;
    lp__xback *xb;                 /* the last build's, through a crystal */
    /* The gathers' ways (trace_backward.c), set up once by a polarized
     * build: ways is 0 until then (cleared as a build starts) */
    int ways;
    /* lp_backward_build_many's mark: whether this builder was met
     * already in its list (found in two passes, not by comparing pairs) */
    unsigned char listed;
    lp__bw_node node[LP_MAX_DEPTH + 1]; /* node[1..n_nodes] */
    lp_query query[LP_MAX_DEPTH];
    lp_vec3 query_dir[LP_MAX_DEPTH]; /* local */
    /* per query: 1 its ray leaves the lens for sure, 0 not for sure, -1
     * not known yet (lp_backward_query_leaves works it out) */
    signed char leaves[LP_MAX_DEPTH];
    lp__bw_way light[LP_MAX_DEPTH]; /* light[j]: node j, light arriving from inside */
    lp__bw_way entry[LP_MAX_DEPTH]; /* entry[q]: where query q's light enters */
    /* per query, how a gather may take its rays in lanes
     * (lp__gather_lanes): 0 when its fields stay real (no node of its way
     * under total internal reflection or at normal incidence); j >= 1
     * when they turn complex at node j, the first under total internal
     * reflection the light meets, and the way has no node at normal
     * incidence nor a total internal reflection where the light
     * refracts; -1 otherwise (one ray at a time) */
    signed char complex_at[LP_MAX_DEPTH];
    /* per query, its power form (a build with LP_BACKWARD_POWER: jones.h):
     * P (entries 00, 01, 11) and the axes s, p (world) of the light
     * entering; pform_ok 0: none (another build, or a node at normal
     * incidence on its way) */
    double pform[LP_MAX_DEPTH][3];
    lp_vec3 pform_s[LP_MAX_DEPTH], pform_p[LP_MAX_DEPTH];
    signed char pform_ok[LP_MAX_DEPTH];
};

/* Add the query of the given depth, kind and surface leaving node
 * bw->node[depth] along the local direction dir, with the path's bound,
 * weight, optical path and path bits, unless bw->args (min_weight against
 * the bound, the flags, the filter) decline it. */
void lp__backward_add_query(lp_backward *bw, int depth, lp_kind kind, int surface, lp_vec3 dir,
                            uint64_t path, double op, double bound, double weight);

/* The same with the query's world origin (of bw->node[depth].p) and world
 * direction (of dir) given, and whether its ray leaves the lens (as
 * bw->leaves). */
void lp__backward_add_query_at(lp_backward *bw, int depth, lp_kind kind, int surface,
                               lp_vec3 dir, lp_vec3 world_origin, lp_vec3 world_dir,
                               uint64_t path, double op, double bound, double weight,
                               int leaves);

/* Whether a build with args makes its queries' power forms: polarized,
 * with LP_BACKWARD_POWER (a crystal's build makes none). */
static inline int lp__backward_power(const lp_trace_args *args)
{
    return args->mode == LP_MODE_POLARIZED && (args->flags & LP_BACKWARD_POWER) != 0;
}

/* Keep the power form (P, the entry's world axes s, p, ok) for the query
 * just added to bw if lp__backward_add_query(_at) added one (n_queries
 * was `before`). */
void lp__backward_keep_form(lp_backward *bw, size_t before, const double P[3], lp_vec3 s,
                            lp_vec3 p, double ok);

/* Once a build of bw is done: in the polarized mode, whose light comes
 * only by gathering, set up the ways of every gather of its queries
 * (lp__backward_sets_ways: not through a crystal, not for power alone). */
void lp__backward_built(lp_backward *bw);

/* lp__backward_built of bw[0..n) (distinct builders), bit for bit, their
 * ways set up in lanes across the builds (lp__backward_ways_many). */
void lp__backward_built_many(lp_backward *const *bw, size_t n);

/* Whether a build of bw sets up its gathers' ways (a polarized one, not
 * through a crystal, not with LP_BACKWARD_POWER), and the depth of its
 * deepest query (0: none). */
int lp__backward_sets_ways(const lp_backward *bw);
int lp__backward_deepest(const lp_backward *bw);

/* The way where the light of query qi enters the lens, and the way of
 * node j of the light's way back (trace_backward.c), into *w. */
void lp__backward_entry_way(const lp_backward *bw, size_t qi, lp__bw_way *w);
void lp__backward_light_way(const lp_backward *bw, int j, lp__bw_way *w);

/* Gather bundle[0..n) along query q, whose way the lanes take
 * (bw->complex_at[q] >= 0), into res as gathering them one by one does,
 * the same bits, a few rays at a time in lanes (gather_lanes.c).  Returns
 * how many rays it gathered, in order: n, or fewer where a ray fails its
 * checks (the caller gathers it and the rest one by one, which reports
 * it) or whose complex field turns real again on the way (left to the
 * one-ray code too), or where an outgoing ray cannot be stored (*st
 * LP_ERROR_NO_MEMORY, with err; else *st is LP_OK). */
size_t lp__gather_lanes(const lp_backward *bw, size_t q, const lp_ray *bundle, size_t n,
                        lp_result *res, lp_status *st, lp_error *err);

/* The ways of every bw[k] that sets up its ways (lp__backward_sets_ways):
 * each query's entry way and the light's ways at nodes 1 .. deepest-1
 * (deepest: its deepest query), into bw[k]->entry and bw[k]->light --
 * those of lp__backward_entry_way and lp__backward_light_way, bit for bit
 * -- set up in lanes (backward_ways.c), the groups filled across the
 * builds. */
void lp__backward_ways_many(lp_backward *const *bw, size_t n);

#endif
