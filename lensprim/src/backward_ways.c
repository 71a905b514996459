/* backward_ways.c -- the ways of a polarized build, in lanes.
 *
 * A polarized build sets up, once for all its gathers, the node of every
 * query where its light enters the lens and the nodes of the light's way
 * back (trace_backward.c: lp__backward_entry_way, lp__backward_light_way):
 * each is lp__node_setup of the light's direction and the surface normal
 * there with the axes of the branch the light takes.  Those of one build
 * -- or of the many builds of lp_backward_build_many, whose few ways each
 * (a query or two and the nodes between) would leave the groups half
 * empty -- are set up side by side, in loops over lanes that the compiler
 * vectorizes (lanes.h), each lane with the operations of the one-node
 * code (interface.h, fresnel.h) in their order, so that its numbers are
 * that code's bit for bit.  A node that code treats apart -- total
 * internal reflection (complex factors), normal incidence (its s axis is
 * the field's), no interface at all (equal indices) -- is set up by the
 * one-node code instead. */
#include <complex.h>
#include <math.h>

#include "backward.h"
#include "lanes.h"

/* Ways per group. */
#define WL 8

/* A loop over the lanes of a group (lanes.h). */
#define WL_LANES(i) LP__LANE_LOOP(i, WL)

/* The lanes of a group of ways. */
typedef struct wl_lanes {
    /* in: the light's direction, the surface normal, the indices before
     * and after, and whether the light reflects there (1) or refracts (0) */
    double dx[WL], dy[WL], dz[WL];
    double mx[WL], my[WL], mz[WL];
    double n1[WL], n2[WL], eta[WL], refl[WL];
    /* out: the node and the branch's axes */
    double nx[WL], ny[WL], nz[WL]; /* the normal facing the light */
    double ci[WL], ct[WL];
    double rs[WL], rp[WL], ts[WL], tp[WL], Rs[WL], Rp[WL];
    double sx[WL], sy[WL], sz[WL];
    double px[WL], py[WL], pz[WL];
    double ox[WL], oy[WL], oz[WL]; /* the branch's direction */
    double qx[WL], qy[WL], qz[WL]; /* the branch's p axis */
    double apart[WL];              /* 1: left to the one-node code */
} wl_lanes;

LP__WIDE static void ways_kernel(wl_lanes *restrict L)
{
    WL_LANES(i) {
        lp_vec3 d = v3(L->dx[i], L->dy[i], L->dz[i]);
        lp_vec3 normal = v3(L->mx[i], L->my[i], L->mz[i]);
        double n1 = L->n1[i], n2 = L->n2[i], eta = L->eta[i];
        /* lp__node_setup_fresnel */
        double dn = v3_dot(d, normal);
        double adn = fabs(dn);
        lp_vec3 nn = v3(dn > 0.0 ? -normal.x : normal.x, dn > 0.0 ? -normal.y : normal.y,
                        dn > 0.0 ? -normal.z : normal.z); /* v3_neg where dn > 0 */
        double cos_i = adn < 1.0 ? adn : 1.0;
        /* lp__fresnel_eval */
        double ci = cos_i < 0.0 ? 0.0 : (cos_i > 1.0 ? 1.0 : cos_i);
        double sin2_i = (1.0 - ci) * (1.0 + ci);
        double cos2_t = 1.0 - eta * eta * sin2_i;
        double ct = sqrt(cos2_t);
        double a = n1 * ci, b = n2 * ct;
        double c = n2 * ci, e = n1 * ct;
        double is = 1.0 / (a + b), ip = 1.0 / (c + e);
        double rs = (a - b) * is;
        double rp = (c - e) * ip;
        double g = 2.0 * sqrt(a * b);
        /* lp__node_setup's axes */
        lp_vec3 s = v3_cross(d, nn);
        double sl2 = v3_dot(s, s);
        s = v3_scale(s, 1.0 / sqrt(sl2));
        lp_vec3 p = v3_cross(d, s);
        /* lp__node_reflect_axes, lp__node_transmit_axes */
        lp_vec3 r = v3_madd(d, nn, 2.0 * cos_i);
        lp_vec3 t = v3_madd(v3_scale(d, eta), nn, eta * cos_i - ct);
        int refl = L->refl[i] != 0.0;
        lp_vec3 o = v3_normalize(v3(refl ? r.x : t.x, refl ? r.y : t.y, refl ? r.z : t.z));
        lp_vec3 q = v3_cross(o, s);
        L->nx[i] = nn.x, L->ny[i] = nn.y, L->nz[i] = nn.z;
        L->ci[i] = cos_i;
        L->ct[i] = ct;
        L->rs[i] = rs, L->rp[i] = rp;
        L->ts[i] = g * is, L->tp[i] = g * ip;
        L->Rs[i] = rs * rs, L->Rp[i] = rp * rp;
        L->sx[i] = s.x, L->sy[i] = s.y, L->sz[i] = s.z;
        L->px[i] = p.x, L->py[i] = p.y, L->pz[i] = p.z;
        L->ox[i] = o.x, L->oy[i] = o.y, L->oz[i] = o.z;
        L->qx[i] = q.x, L->qy[i] = q.y, L->qz[i] = q.z;
        L->apart[i] = (cos2_t < 0.0) | !(sl2 > 1e-18) | (n1 == n2) ? 1.0 : 0.0;
    }
}

/* The way number k of a build: query k's entry for k < n_queries, else
 * the light's way at node k - n_queries + 1. */
static lp__bw_way *way_at(lp_backward *bw, size_t k)
{
    return k < bw->n_queries ? &bw->entry[k] : &bw->light[k - bw->n_queries + 1];
}

/* Lane i of L takes way k of bw. */
LP__INLINE void lane_in(const lp_backward *bw, size_t k, wl_lanes *L, int i)
{
    const lp__optics *o = &bw->optics;
    lp_vec3 d, m;
    double n1, n2;
    int refl;
    if (k < bw->n_queries) { /* lp__backward_entry_way */
        const lp_query *q = &bw->query[k];
        d = v3_neg(bw->query_dir[k]);
        m = bw->node[q->depth].n;
        n1 = o->n_medium, n2 = o->n_glass;
        refl = q->depth == 1;
    } else { /* lp__backward_light_way */
        int j = (int)(k - bw->n_queries) + 1;
        d = v3_neg(bw->node[j].e_out);
        m = bw->node[j].n;
        n1 = o->n_glass, n2 = o->n_medium;
        refl = j > 1;
    }
    L->dx[i] = d.x, L->dy[i] = d.y, L->dz[i] = d.z;
    L->mx[i] = m.x, L->my[i] = m.y, L->mz[i] = m.z;
    L->n1[i] = n1, L->n2[i] = n2;
    L->eta[i] = n1 / n2;
    L->refl[i] = refl;
}

/* Way k of bw from lane i of L. */
LP__INLINE void lane_out(lp_backward *bw, size_t k, const wl_lanes *L, int i)
{
    lp__bw_way *w = way_at(bw, k);
    if (L->apart[i] != 0.0) {
        if (k < bw->n_queries)
            lp__backward_entry_way(bw, k, w);
        else
            lp__backward_light_way(bw, (int)(k - bw->n_queries) + 1, w);
        return;
    }
    lp__node *nd = &w->node;
    nd->d = v3(L->dx[i], L->dy[i], L->dz[i]);
    nd->n = v3(L->nx[i], L->ny[i], L->nz[i]);
    nd->cos_i = L->ci[i];
    nd->f.tir = 0;
    nd->f.eta = L->eta[i];
    nd->f.cos_t = L->ct[i];
    nd->f.rs = L->rs[i];
    nd->f.rp = L->rp[i];
    nd->f.ts = L->ts[i];
    nd->f.tp = L->tp[i];
    nd->f.Rs = L->Rs[i];
    nd->f.Rp = L->Rp[i];
    nd->s = v3(L->sx[i], L->sy[i], L->sz[i]);
    nd->p = v3(L->px[i], L->py[i], L->pz[i]);
    nd->n1 = L->n1[i];
    nd->n2 = L->n2[i];
    nd->normal = 0;
    w->ax.dir = v3(L->ox[i], L->oy[i], L->oz[i]);
    w->ax.p = v3(L->qx[i], L->qy[i], L->qz[i]);
    w->reflect = L->refl[i] != 0.0;
}

void lp__backward_ways_many(lp_backward *const *bw, size_t n)
{
    wl_lanes L;
    lp_backward *who[WL]; /* each lane's build and way */
    size_t way[WL];
    int m = 0, first = 1;
    for (size_t b = 0; b < n; b++) {
        if (!lp__backward_sets_ways(bw[b]))
            continue;
        int deepest = lp__backward_deepest(bw[b]);
        size_t nw = bw[b]->n_queries + (size_t)(deepest > 1 ? deepest - 1 : 0);
        for (size_t k = 0; k < nw; k++) {
            lane_in(bw[b], k, &L, m);
            who[m] = bw[b], way[m] = k;
            if (++m == WL) {
                ways_kernel(&L);
                for (int i = 0; i < WL; i++)
                    lane_out(who[i], way[i], &L, i);
                m = 0, first = 0;
            }
        }
    }
    if (m == 0)
        return;
    /* the last group: lanes past m repeat the first in a first group, and
     * keep the group before's ways (set up for nothing) after it */
    for (int i = m; first && i < WL; i++)
        lane_in(who[0], way[0], &L, i);
    ways_kernel(&L);
    for (int i = 0; i < m; i++)
        lane_out(who[i], way[i], &L, i);
}
