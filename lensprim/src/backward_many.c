/* backward_many.c -- lp_backward_build_many: the backward chains of one
 * view ray at many wavelengths, in lockstep.
 *
 * The view ray meets the lens at the same point whatever its wavelength:
 * that hit is found once, by the one-ray code.  From there each
 * wavelength refracts its own way, so each is a lane, and the lanes walk
 * their chains node by node together, in loops over the lanes that the
 * compiler vectorizes (lanes.h): the node's geometry and Fresnel factors,
 * the path's bound and weight, the next hit.  Every formula is
 * lp_backward_build's with its operations in the same order, so each
 * lane's numbers are that build's at its wavelength, bit for bit; the
 * rim tests of the lanes near the rim and the absorption's expm1 are the
 * one-ray code's, lane by lane.  Each step writes its nodes straight into
 * the lanes' lp_backward; the queries are made at the end, wavelength by
 * wavelength in depth order (lp__backward_add_query_at: the flags and the
 * filter are called in the order of lp_backward_build).  Each query's
 * certificate that its ray leaves the lens (lp_backward_query_leaves) is
 * made in the lanes too, with the one-ray code's arithmetic (lens.c's
 * lp__lens_leaves; see leaves_step). */
#include <math.h>
#include <string.h>

#include "backward.h"
#include "error.h"
#include "jones.h"
#include "lanes.h"

/* Wavelengths per group (16 is what a spectral renderer traces). */
#define NW 16

/* The lanes of a group: their optics, their chains, one step's numbers. */
typedef struct wl_lanes {
    double ng[NW], nm[NW], ha[NW]; /* indices, -alpha/2 */
    double eta_in[NW], eta_out[NW];
    double r0_in[NW], r0_out[NW];  /* Schlick's R0 */
    double px[NW], py[NW], pz[NW]; /* the node the lane is at */
    double dx[NW], dy[NW], dz[NW]; /* the eye's direction from it */
    double surf[NW];
    double bound[NW], weight[NW], op[NW];
    double live[NW];
    /* a step: the hit, the rim test's lanes, the absorption */
    double t[NW], hs[NW], hx[NW], hy[NW], hz[NW], rim[NW], m[NW];
    /* the node there: normal, the query's direction, bound and weight */
    double nx[NW], ny[NW], nz[NW];
    double qx[NW], qy[NW], qz[NW], qb[NW], qw[NW], tir[NW];
    /* the query in the world: its origin (the node) and direction */
    double wox[NW], woy[NW], woz[NW], wdx[NW], wdy[NW], wdz[NW];
    double lv[NW]; /* whether the query leaves the lens (leaves_step) */
    /* a power build's (jones.h): the light's way to the exit so far (R,
     * its axes at the node before, whether defined), and the query's
     * form, entry axes (world) and whether defined */
    double Rr00[NW], Rr01[NW], Rr10[NW], Rr11[NW], Ri00[NW], Ri01[NW], Ri10[NW], Ri11[NW];
    double sx[NW], sy[NW], sz[NW], tx[NW], ty[NW], tz[NW], jok[NW];
    double P0[NW], P1[NW], P2[NW], esx[NW], esy[NW], esz[NW], epx[NW], epy[NW], epz[NW];
    double qok[NW];
} wl_lanes;

/* Lane k's Jones state (R, the axes before: s in s*, p in t*, ok) in and
 * out of its arrays, and its query's form out. */
LP__INLINE void jones_load(const wl_lanes *restrict W, size_t k, lp__cm2 *R, lp_vec3 *s,
                           lp_vec3 *p, double *ok)
{
    *R = (lp__cm2){W->Rr00[k], W->Rr01[k], W->Rr10[k], W->Rr11[k],
                   W->Ri00[k], W->Ri01[k], W->Ri10[k], W->Ri11[k]};
    *s = v3(W->sx[k], W->sy[k], W->sz[k]);
    *p = v3(W->tx[k], W->ty[k], W->tz[k]);
    *ok = W->jok[k];
}

LP__INLINE void jones_store(wl_lanes *restrict W, size_t k, const lp__cm2 *R, lp_vec3 s,
                            lp_vec3 p, double ok, const double P[3], lp_vec3 es, lp_vec3 ep,
                            double qok)
{
    W->Rr00[k] = R->r00, W->Rr01[k] = R->r01, W->Rr10[k] = R->r10, W->Rr11[k] = R->r11;
    W->Ri00[k] = R->i00, W->Ri01[k] = R->i01, W->Ri10[k] = R->i10, W->Ri11[k] = R->i11;
    W->sx[k] = s.x, W->sy[k] = s.y, W->sz[k] = s.z;
    W->tx[k] = p.x, W->ty[k] = p.y, W->tz[k] = p.z;
    W->jok[k] = ok;
    W->P0[k] = P[0], W->P1[k] = P[1], W->P2[k] = P[2];
    W->esx[k] = es.x, W->esy[k] = es.y, W->esz[k] = es.z;
    W->epx[k] = ep.x, W->epy[k] = ep.y, W->epz[k] = ep.z;
    W->qok[k] = qok;
}

/* The bound and weight factors of a node (trace_backward.c's node_bound
 * and node_weight) for the reflected and the transmitted branch. */
LP__INLINE void factors(lp_mode mode, double r0, double n1, double n2, const lp__lane_node *g,
                        double *bR, double *bT, double *wR, double *wT)
{
    double Rf = lp__lane_reflectance(0, 0.0, 0, g); /* Fresnel's */
    if (mode == LP_MODE_POLARIZED) {
        double Rs = g->rs * g->rs, Rp = g->rp * g->rp;
        double ts = g->ts, tp = g->tp;
        double ts2 = ts * ts, tp2 = tp * tp;
        *bR = g->tir ? 1.0 : lp__max(Rs, Rp);
        *bT = g->tir ? 0.0 : lp__max(ts2, tp2);
        *wR = Rf;
        *wT = 1.0 - Rf;
    } else {
        double R = mode == LP_MODE_SCHLICK ? lp__lane_reflectance(1, r0, n1 > n2, g) : Rf;
        *bR = *wR = R;
        *bT = *wT = 1.0 - R;
    }
}

/* Node 1 of every lane: the view ray enters at the point of the unit
 * normal hn, along d; the reflected query and the refracted chain. */
LP__INLINE void entry_step(wl_lanes *restrict W, size_t n, const lp__lane_lens *Kp, lp_mode mode,
                           int power, lp_vec3 d, lp_vec3 hn)
{
    const lp__lane_lens K = *Kp; /* local: the loads are safe to select */
    for (size_t k = 0; k < n; k++) {
        lp__lane_node g;
        double bR, bT, wR, wT;
        lp__lane_node_at(W->nm[k], W->ng[k], W->eta_in[k], d, hn, &g);
        factors(mode, W->r0_in[k], W->nm[k], W->ng[k], &g, &bR, &bT, &wR, &wT);
        lp_vec3 wd = lp__lane_world_dir(&K, g.r);
        W->qx[k] = g.r.x;
        W->qy[k] = g.r.y;
        W->qz[k] = g.r.z;
        W->wdx[k] = wd.x;
        W->wdy[k] = wd.y;
        W->wdz[k] = wd.z;
        W->qb[k] = bR;
        W->qw[k] = wR;
        W->tir[k] = g.tir ? 1.0 : 0.0;
        W->dx[k] = g.t.x;
        W->dy[k] = g.t.y;
        W->dz[k] = g.t.z;
        W->bound[k] = bT;
        W->weight[k] = wT;
        W->op[k] = 0.0;
        W->live[k] = g.tir ? 0.0 : 1.0;
        if (power) { /* jones.h, with trace_backward.c's numbers */
            lp__cm2 R;
            lp_vec3 s, p, es, ep;
            double ok, qok, P[3];
            lp__jones_first(d, hn, g.r, g.t, g.rs, g.rp, g.tir, g.ci, W->nm[k], W->ng[k], g.ts,
                            g.tp, &R, &s, &p, &ok, P, &es, &ep, &qok);
            jones_store(W, k, &R, s, p, ok, P, lp__lane_world_dir(&K, es),
                        lp__lane_world_dir(&K, ep), qok);
        }
    }
}

/* The next hit of every lane still walking (the loop's condition of
 * lp_backward_build), but for the rim of the lanes near it. */
LP__INLINE void hit_step(wl_lanes *restrict W, size_t n, const lp__lane_lens *Kp,
                         double min_weight)
{
    const lp__lane_lens K = *Kp; /* local: the loads are safe to select */
    for (size_t k = 0; k < n; k++) {
        lp_vec3 p = v3(W->px[k], W->py[k], W->pz[k]);
        lp_vec3 d = v3(W->dx[k], W->dy[k], W->dz[k]);
        int live = (W->live[k] != 0.0) & !(W->bound[k] < min_weight);
        double t;
        lp_vec3 x;
        int rim;
        double hs = lp__lane_hit_inside(&K, p, d, W->surf[k], &t, &x, &rim);
        W->live[k] = live ? 1.0 : 0.0;
        W->t[k] = t;
        W->hs[k] = hs;
        W->hx[k] = x.x;
        W->hy[k] = x.y;
        W->hz[k] = x.z;
        W->rim[k] = rim & live ? 1.0 : 0.0;
        W->m[k] = W->ha[k] * t;
    }
}

/* The segment to the hit and the node there, for every lane that met a
 * cap: the query's direction, bound and weight, the reflected chain. */
LP__INLINE void node_step(wl_lanes *restrict W, size_t n, const lp__lane_lens *Kp, lp_mode mode,
                          int power)
{
    const lp__lane_lens K = *Kp;
    for (size_t k = 0; k < n; k++) {
        double m = W->m[k], t = W->t[k], hs = W->hs[k];
        double att = (1.0 + m) * (1.0 + m);
        double bound = W->bound[k] * att, weight = W->weight[k] * att;
        W->op[k] = W->op[k] + W->ng[k] * t;
        lp_vec3 x = v3(W->hx[k], W->hy[k], W->hz[k]);
        lp_vec3 d = v3(W->dx[k], W->dy[k], W->dz[k]);
        lp_vec3 nrm = lp__lane_cap_normal(&K, hs, x);
        lp__lane_node g;
        double bR, bT, wR, wT;
        lp__lane_node_at(W->ng[k], W->nm[k], W->eta_out[k], d, nrm, &g);
        factors(mode, W->r0_out[k], W->ng[k], W->nm[k], &g, &bR, &bT, &wR, &wT);
        W->nx[k] = nrm.x;
        W->ny[k] = nrm.y;
        W->nz[k] = nrm.z;
        lp_vec3 wo = lp__lane_world_point(&K, x), wd = lp__lane_world_dir(&K, g.t);
        W->qx[k] = g.t.x;
        W->qy[k] = g.t.y;
        W->qz[k] = g.t.z;
        W->wox[k] = wo.x;
        W->woy[k] = wo.y;
        W->woz[k] = wo.z;
        W->wdx[k] = wd.x;
        W->wdy[k] = wd.y;
        W->wdz[k] = wd.z;
        W->qb[k] = bound * bT;
        W->qw[k] = weight * wT;
        W->tir[k] = g.tir ? 1.0 : 0.0;
        W->bound[k] = bound * bR;
        W->weight[k] = weight * wR;
        W->px[k] = x.x;
        W->py[k] = x.y;
        W->pz[k] = x.z;
        W->dx[k] = g.r.x;
        W->dy[k] = g.r.y;
        W->dz[k] = g.r.z;
        W->surf[k] = hs;
        if (power) { /* jones.h, with trace_backward.c's numbers */
            lp__cm2 R;
            lp_vec3 s, p, es, ep;
            double ok, qok, P[3];
            jones_load(W, k, &R, &s, &p, &ok);
            lp__jones_node(d, nrm, g.r, g.t, 1.0 + m, g.ts, g.tp, g.rs, g.rp, g.tir, g.ci,
                           W->ng[k], W->nm[k], &R, &s, &p, &ok, P, &es, &ep, &qok);
            jones_store(W, k, &R, s, p, ok, P, lp__lane_world_dir(&K, es),
                        lp__lane_world_dir(&K, ep), qok);
        }
    }
}

/* Whether each lane's query ray (world origin wo, direction wd) leaves
 * the lens for sure: lp__lens_leaves (lens.c), the one-ray code's
 * arithmetic (lp_lens_intersect's normalization and local ray,
 * lp__lens_surface_at, lp__lens_hit's caps from the surface found, its
 * rim test skipped by lp__rim_beyond) in lanes: 1 it leaves, 0 not for
 * sure (from no cap, or a cap hit), -1 where only the rim's own test can
 * tell (lp__lens_leaves decides when asked).  The caps' tests and the
 * rim's z range are the shared lanes.h and lens_internal.h ones; what is
 * spelled out here is not shareable as it stands: the one-ray code's
 * lp__lens_surface_at and local frame are scalar with branches, and
 * lanes.h's lp__lane_on_lens does not say which cap, while
 * lp__lane_hit_inside, which makes the same choice of caps, also finds
 * the hit point and rim flags this test does not need, and its rim flag
 * is set for every ray that meets no cap: built on it, this loop took
 * 104.5 M instructions instead of 26.3 M in a fresnel 160x120
 * default.scene render with dispersion (444.8 M -> 622.0 M in all, the
 * undecided rays decided one by one).  A lanes.h helper for the caps met
 * from a cap could serve both. */
LP__INLINE void leaves_step(wl_lanes *restrict W, size_t n, const lp__lane_lens *Kp)
{
    const lp__lane_lens K = *Kp;
    double t_other = lp__max(0.0, K.eps), tol = K.tol;
    for (size_t k = 0; k < n; k++) {
        lp_vec3 d = v3_normalize(v3(W->wdx[k], W->wdy[k], W->wdz[k]));
        lp_vec3 o = v3_sub(v3(W->wox[k], W->woy[k], W->woz[k]), K.pos);
        lp_vec3 p = v3(v3_dot(o, K.u), v3_dot(o, K.v), v3_dot(o, K.w));
        lp_vec3 dl = v3(v3_dot(d, K.u), v3_dot(d, K.v), v3_dot(d, K.w));
        /* lp__lens_surface_at: the front cap, else the back one */
        double r2 = p.x * p.x + p.y * p.y;
        double z0 = p.z - K.z0[0], z1 = p.z - K.z0[1];
        double f0 = K.c[0] * (r2 + z0 * z0) - 2.0 * z0;
        double f1 = K.c[1] * (r2 + z1 * z1) - 2.0 * z1;
        int on0 = (fabs(f0) <= 2.0 * tol) & (r2 <= K.hh[0] + tol) & (K.c[0] * z0 <= 1.0);
        int on1 = !on0 & (fabs(f1) <= 2.0 * tol) & (r2 <= K.hh[1] + tol) & (K.c[1] * z1 <= 1.0);
        double ts, to;
        int hself = lp__lane_cap_self(on1 ? K.c[1] : K.c[0], on1 ? K.z0[1] : K.z0[0],
                                      on1 ? K.hh[1] : K.hh[0], p, dl, 0.0, &ts);
        int hother = lp__lane_cap_far(on1 ? K.c[0] : K.c[1], on1 ? K.z0[0] : K.z0[1],
                                      on1 ? K.hh[0] : K.hh[1], p, dl, t_other, &to);
        int clear = (on0 | on1) & !hself & !hother;
        int sure = (K.has_rim == 0.0) | lp__rim_beyond(&K.r, p, dl);
        W->lv[k] = clear ? (sure ? 1.0 : -1.0) : 0.0;
    }
}

/* The vector loops, each in one copy per mode and vector width. */
LP__WIDE static void entry_kernel(wl_lanes *restrict W, size_t n, const lp__lane_lens *K,
                                  lp_mode mode, int power, lp_vec3 d, lp_vec3 hn)
{
    switch (mode) {
    case LP_MODE_POLARIZED:
        if (power)
            entry_step(W, n, K, LP_MODE_POLARIZED, 1, d, hn);
        else
            entry_step(W, n, K, LP_MODE_POLARIZED, 0, d, hn);
        break;
    case LP_MODE_FRESNEL: entry_step(W, n, K, LP_MODE_FRESNEL, 0, d, hn); break;
    default: entry_step(W, n, K, LP_MODE_SCHLICK, 0, d, hn); break;
    }
}

LP__WIDE static void hit_kernel(wl_lanes *restrict W, size_t n, const lp__lane_lens *K,
                                double min_weight)
{
    hit_step(W, n, K, min_weight);
}

LP__WIDE static void leaves_kernel(wl_lanes *restrict W, size_t n, const lp__lane_lens *K)
{
    leaves_step(W, n, K);
}

LP__WIDE static void node_kernel(wl_lanes *restrict W, size_t n, const lp__lane_lens *K,
                                 lp_mode mode, int power)
{
    switch (mode) {
    case LP_MODE_POLARIZED:
        if (power)
            node_step(W, n, K, LP_MODE_POLARIZED, 1);
        else
            node_step(W, n, K, LP_MODE_POLARIZED, 0);
        break;
    case LP_MODE_FRESNEL: node_step(W, n, K, LP_MODE_FRESNEL, 0); break;
    default: node_step(W, n, K, LP_MODE_SCHLICK, 0); break;
    }
}

/* A query candidate of node `depth` (the transmitted branch; node 1's
 * reflected one) of lane k, kept in the builder's own query slot
 * depth - 1 until lp__backward_add_query_at makes the queries: so no
 * scratch is needed. */
static void keep_candidate(lp_backward *bw, int depth, const wl_lanes *W, size_t k, lp_vec3 wo,
                           int power)
{
    lp_query *q = &bw->query[depth - 1];
    if (power) { /* its form and world entry axes, in the slot's too */
        double *P = bw->pform[depth - 1];
        P[0] = W->P0[k], P[1] = W->P1[k], P[2] = W->P2[k];
        bw->pform_s[depth - 1] = v3(W->esx[k], W->esy[k], W->esz[k]);
        bw->pform_p[depth - 1] = v3(W->epx[k], W->epy[k], W->epz[k]);
        bw->pform_ok[depth - 1] = W->qok[k] != 0.0;
    }
    bw->query_dir[depth - 1] = v3(W->qx[k], W->qy[k], W->qz[k]);
    q->origin = wo;
    q->dir = v3(W->wdx[k], W->wdy[k], W->wdz[k]);
    q->op = W->op[k];
    q->bound = W->qb[k];
    q->weight = W->qw[k];
    bw->leaves[depth - 1] = (signed char)W->lv[k];
}

/* Wavelengths k0 .. k0+n of a cap hit h of the view ray (local
 * direction d): their chains, into bw[k0..]. */
static void build_group(lp_backward *const *bw, size_t n, const lp_lens *lens,
                        const lp__lane_lens *K, lp_vec3 d, const lp__local_hit *h)
{
    wl_lanes W;
    const lp_trace_args *a = &bw[0]->args;
    lp_mode mode = a->mode;
    int entry = h->surface, max_depth = a->max_depth, power = lp__backward_power(a);
    int cand[NW][LP_MAX_DEPTH + 1]; /* 1: node j of lane k has a candidate */

    for (size_t k = 0; k < n; k++) {
        const lp__optics *o = &bw[k]->optics;
        W.ng[k] = o->n_glass;
        W.nm[k] = o->n_medium;
        W.ha[k] = -0.5 * o->alpha;
        W.eta_in[k] = o->n_medium / o->n_glass;
        W.eta_out[k] = o->n_glass / o->n_medium;
        W.r0_in[k] = lp__lane_schlick_r0(o->n_medium, o->n_glass);
        W.r0_out[k] = lp__lane_schlick_r0(o->n_glass, o->n_medium);
        W.px[k] = h->p.x, W.py[k] = h->p.y, W.pz[k] = h->p.z;
        W.surf[k] = h->surface;
    }
    entry_kernel(&W, n, K, mode, power, d, h->n);
    lp__exit exit = lp__exit_at(lens, h->p, v3_neg(d));
    lp_vec3 wo1 = lp__to_world_point(lens, h->p);
    for (size_t k = 0; k < n; k++)
        W.wox[k] = wo1.x, W.woy[k] = wo1.y, W.woz[k] = wo1.z;
    leaves_kernel(&W, n, K);
    for (size_t k = 0; k < n; k++) {
        lp_backward *b = bw[k];
        b->exit = exit;
        b->n_nodes = 1;
        b->node[1].p = h->p;
        b->node[1].n = h->n;
        b->node[1].surface = h->surface;
        b->node[1].e_out = v3(W.dx[k], W.dy[k], W.dz[k]);
        keep_candidate(b, 1, &W, k, wo1, power);
        cand[k][1] = 1;
    }
    /* the chains, a node per step */
    for (int depth = 1; depth < max_depth; depth++) {
        size_t live = 0;
        hit_kernel(&W, n, K, a->min_weight);
        for (size_t k = 0; k < n; k++) {
            if (W.live[k] == 0.0)
                continue;
            live++;
            double t;
            lp_vec3 p = v3(W.px[k], W.py[k], W.pz[k]), dk = v3(W.dx[k], W.dy[k], W.dz[k]);
            if (W.rim[k] != 0.0 &&
                lp__rim_intersect(&K->r, p, dk, K->eps, lp__rim_t_max(W.t[k], K->eps), &t)) {
                W.t[k] = t;
                W.hs[k] = LP_SURFACE_RIM;
                lp_vec3 x = v3_madd(p, dk, t);
                W.hx[k] = x.x, W.hy[k] = x.y, W.hz[k] = x.z;
                W.m[k] = W.ha[k] * t;
            }
            W.m[k] = W.ha[k] < 0.0 ? expm1(W.m[k]) : 0.0;
        }
        if (live == 0)
            break;
        node_kernel(&W, n, K, mode, power);
        leaves_kernel(&W, n, K);
        for (size_t k = 0; k < n; k++) {
            if (W.live[k] == 0.0)
                continue;
            lp_backward *b = bw[k];
            if (W.hs[k] < 0.0) { /* the chain lost its way */
                b->warnings |= LP_WARN_LEAK;
                W.live[k] = 0.0;
                continue;
            }
            double m = W.m[k];
            b->node[depth].seg = W.t[k];
            b->node[depth].seg_att = 1.0 + m;
            b->node[depth].seg_abs = -m * (2.0 + m);
            if (W.hs[k] == LP_SURFACE_RIM) {
                b->rim_depth = depth + 1;
                W.live[k] = 0.0;
                continue;
            }
            lp__bw_node *nd = &b->node[depth + 1];
            nd->p = v3(W.px[k], W.py[k], W.pz[k]);
            nd->n = v3(W.nx[k], W.ny[k], W.nz[k]);
            nd->surface = (int)W.hs[k];
            nd->e_out = v3(W.dx[k], W.dy[k], W.dz[k]);
            b->n_nodes = depth + 1;
            cand[k][depth + 1] = W.tir[k] == 0.0;
            if (cand[k][depth + 1])
                keep_candidate(b, depth + 1, &W, k, v3(W.wox[k], W.woy[k], W.woz[k]), power);
        }
    }
    /* the queries, wavelength by wavelength, in depth order */
    for (size_t k = 0; k < n; k++) {
        lp_backward *b = bw[k];
        uint64_t path = 0;
        for (int j = 1; j <= b->n_nodes; j++) {
            if (cand[k][j]) {
                /* the candidate's slot: the query made from it goes to
                 * this slot or an earlier one, after the arguments are read */
                const lp_query *q = &b->query[j - 1];
                int surface = b->node[j].surface;
                lp_kind kind = j == 1 || surface == entry ? LP_KIND_REFLECT : LP_KIND_TRANSMIT;
                size_t before = b->n_queries;
                /* two calls, not one after a conditional copy of the form:
                 * that shape cost fresnel default.scene 160x120 --cutoff 0
                 * 0.9 M more instructions (443.0 M) */
                if (!power) {
                    lp__backward_add_query_at(b, j, kind, surface, b->query_dir[j - 1],
                                              q->origin, q->dir, j == 1 ? 1u : path, q->op,
                                              q->bound, q->weight, b->leaves[j - 1]);
                } else { /* its form read before the query may take its slot */
                    double P[3] = {b->pform[j - 1][0], b->pform[j - 1][1], b->pform[j - 1][2]};
                    lp_vec3 es = b->pform_s[j - 1], ep = b->pform_p[j - 1];
                    double ok = b->pform_ok[j - 1];
                    lp__backward_add_query_at(b, j, kind, surface, b->query_dir[j - 1],
                                              q->origin, q->dir, j == 1 ? 1u : path, q->op,
                                              q->bound, q->weight, b->leaves[j - 1]);
                    lp__backward_keep_form(b, before, P, es, ep, ok);
                }
            }
            if (j > 1)
                path |= (uint64_t)1 << (j - 1);
        }
    }
}

lp_status lp_backward_build_many(lp_backward *const *bw, size_t n, const lp_lens *lens,
                                 lp_vec3 origin, lp_vec3 dir, const double *lambda_nm,
                                 const lp_trace_args *args, lp_error *err)
{
    lp_status st;
    lp_trace_args a;
    lp__local_hit h;

    if (!lens || (n > 0 && (!bw || !lambda_nm)))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_backward_build_many: NULL argument");
    /* What fails alike at every wavelength, or is done otherwise: the
     * builds one by one (the first fails, or each is the one-ray code's). */
    int one_by_one = n == 0 || lens->desc.uniaxial || lp__args_resolve(args, &a, NULL) != LP_OK ||
                     !v3_finite(origin) || !v3_finite(dir);
    lp_vec3 dw = v3_normalize(dir);
    one_by_one |= dw.x == 0.0 && dw.y == 0.0 && dw.z == 0.0;
    /* a NULL builder, or one twice: clear every mark, then set each,
     * finding one set already (linear: a spectral renderer's packet has
     * hundreds of wavelengths, and a test of every pair cost it more than
     * the builds at 256 and more) */
    for (size_t k = 0; k < n && !one_by_one; k++) {
        one_by_one = !bw[k];
        if (!one_by_one)
            bw[k]->listed = 0;
    }
    for (size_t k = 0; k < n && !one_by_one; k++) {
        one_by_one = bw[k]->listed;
        bw[k]->listed = 1;
    }
    size_t ok = 0; /* the wavelengths before the first that fails */
    if (!one_by_one) {
        /* every builder as lp_backward_build sets it before its chain */
        for (; ok < n; ok++) {
            lp_backward *b = bw[ok];
            b->lens = lens;
            b->n_nodes = 0;
            b->n_queries = 0;
            b->rim_depth = 0;
            b->warnings = 0;
            b->args = a;
            b->ways = 0;
            lp__xback_deactivate(b->xb);
            if (lp__optics_at(lens, lambda_nm[ok], &b->optics, NULL) != LP_OK)
                break;
            b->warnings = b->optics.warnings;
            b->view_dir = lp__to_local_dir(lens, dw);
        }
        lp_vec3 p = lp__to_local_point(lens, origin), d = lp__to_local_dir(lens, dw);
        if (ok > 0 && lp__lens_hit(lens, p, d, lp__lens_surface_at(lens, p), 0.0, INFINITY, &h)) {
            if (h.surface == LP_SURFACE_RIM) {
                for (size_t k = 0; k < ok; k++)
                    bw[k]->rim_depth = 1;
            } else {
                lp__lane_lens K;
                lp__lane_lens_of(&K, lens);
                for (size_t k0 = 0; k0 < ok; k0 += NW)
                    build_group(bw + k0, ok - k0 < NW ? ok - k0 : NW, lens, &K, d, &h);
            }
        }
        if (a.mode == LP_MODE_POLARIZED) /* else no build sets up ways */
            lp__backward_built_many(bw, ok);
        if (ok == n) {
            lp__ok(err);
            return LP_OK;
        }
    }
    /* the rest one by one, from the first that fails or from the start */
    for (size_t k = ok; k < n; k++) {
        if (!bw[k])
            st = lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "NULL lp_backward");
        else
            st = lp_backward_build(bw[k], lens, origin, dir, lambda_nm[k], args, err);
        if (st != LP_OK) {
            if (err) {
                lp_error e = *err;
                lp__fail(err, st, "wavelength %zu: %s", k, e.message);
            }
            return st;
        }
    }
    lp__ok(err);
    return LP_OK;
}
