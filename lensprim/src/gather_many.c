/* gather_many.c -- lp_backward_gather_many: the gathers of many builders
 * at once, a lane per request, each lane along its own way.
 *
 * A spectral renderer splits its packet at a dispersive lens into one
 * wavelength per builder (lp_backward_build_many), and each wavelength's
 * query is answered by a bundle of a ray or two (the two halves of
 * natural light): gathered builder by builder, the lanes of
 * lp__gather_lanes are half empty and the checks and set-up of a call are
 * paid for every two rays.  Here the rays of many requests are taken
 * together instead.  Along a way the lanes take (complex_at >= 0: no node
 * at normal incidence, total internal reflection only where the light
 * reflects) every ray takes the same kind of step at each node -- the
 * light reflects at a query's entry when its depth is 1 and refracts in
 * otherwise, reflects inside at nodes k-1..2 and refracts out at node 1;
 * its field is real down to the first node under total internal
 * reflection and complex from there (gather_lanes.c) -- so the requests
 * whose ways have the same depth, the same first such node and
 * absorption or none walk them side by side, a lane per request reading
 * its own way's axes and factors, copied once into arrays per lane, in
 * loops over lanes that the compiler vectorizes (lanes.h).  A lane
 * carries two rays of its request (natural light's two halves: a
 * renderer's bundles are mostly those), so that the way is read once for
 * both; a request of more rays takes more lanes, and an odd one's last
 * lane repeats its ray.  Each ray takes the one-ray code's operations in
 * their order (trace_backward.c: gather_one; the steps of ray_lanes.h,
 * which gather_lanes.c takes along one way), so its numbers are that
 * code's bit for bit, and the outgoing rays are stored request by
 * request, ray by ray, as the gathers one by one store them.  A request
 * the lanes do not take -- a crystal lens, a way of normal incidence, a
 * build for power alone (LP_BACKWARD_POWER: no ways), a bundle too long,
 * a ray that fails its checks, a complex field that turns real again --
 * is gathered by lp_backward_gather itself in its turn, so its results
 * (and its error) are that call's. */
#include <math.h>

#include "backward.h"
#include "error.h"
#include "lanes.h"
#include "ray_lanes.h"

/* Lanes per group. */
#define GM 8
_Static_assert(GM <= LP__RAY_LANES, "a group's rays fit lp__ray_lanes");

/* A loop over the lanes of a group (lanes.h). */
#define GM_LANES(i) LP__LANE_LOOP(i, GM)

/* The deepest way taken in lanes (the renderer's are a few nodes deep). */
#define GM_DEPTH 12

/* Bundle rays taken per window of requests: the window's rays are
 * gathered in lanes, then its requests stored in order. */
#define GM_WINDOW 256

/* The groups' keys: 2 ((GM_DEPTH + 1) depth + complex_at) + absorbs. */
#define GM_KEYS (2 * (GM_DEPTH + 1) * (GM_DEPTH + 1))

/* The lanes of a group: each lane's way, its two rays (h = 0, 1), and
 * what leaves. */
typedef struct gm_lanes {
    double lx[GM], ly[GM], lz[GM]; /* the light's direction at the entry */
    double dx[GM], dy[GM], dz[GM]; /* the exit's (local) direction */
    double ux[GM], uy[GM], uz[GM]; /* the lens frame */
    double wvx[GM], wvy[GM], wvz[GM];
    double wwx[GM], wwy[GM], wwz[GM];
    /* per node j of the way (j = depth: the entry): its s and p axes,
     * the branch's p axis, the branch's factors (rs, rp or ts, tp),
     * the segment from node j + 1 (seg_abs, seg_att) */
    double sx[GM_DEPTH + 1][GM], sy[GM_DEPTH + 1][GM], sz[GM_DEPTH + 1][GM];
    double px[GM_DEPTH + 1][GM], py[GM_DEPTH + 1][GM], pz[GM_DEPTH + 1][GM];
    double ax[GM_DEPTH + 1][GM], ay[GM_DEPTH + 1][GM], az[GM_DEPTH + 1][GM];
    double fa[GM_DEPTH + 1][GM], fb[GM_DEPTH + 1][GM];
    double fc[GM_DEPTH + 1][GM], fd[GM_DEPTH + 1][GM]; /* imaginary parts of rs, rp */
    double sa[GM_DEPTH + 1][GM], st[GM_DEPTH + 1][GM];
} gm_lanes;

/* The light's step at node j of a way of depth k: 1 a reflection (off
 * the outside at the entry of depth 1, inside at nodes k-1..2), 0 a
 * refraction (in at the entry, out at node 1); lp__backward_entry_way and
 * lp__backward_light_way (and lp__backward_ways, bit for bit) set them so. */
static int reflects(int j, int k)
{
    return j == k ? k == 1 : j > 1;
}

/* Node j's axes of lane i: its s and p, the branch's p. */
LP__INLINE void gm_axes(const gm_lanes *restrict L, int j, int i, lp_vec3 *s, lp_vec3 *p,
                        lp_vec3 *ap)
{
    *s = v3(L->sx[j][i], L->sy[j][i], L->sz[j][i]);
    *p = v3(L->px[j][i], L->py[j][i], L->pz[j][i]);
    *ap = v3(L->ax[j][i], L->ay[j][i], L->az[j][i]);
}

/* Lane i's lens frame u, v, w and exit direction d. */
LP__INLINE void gm_frame(const gm_lanes *restrict L, int i, lp_vec3 *u, lp_vec3 *v, lp_vec3 *w,
                         lp_vec3 *d)
{
    *u = v3(L->ux[i], L->uy[i], L->uz[i]);
    *v = v3(L->wvx[i], L->wvy[i], L->wvz[i]);
    *w = v3(L->wwx[i], L->wwy[i], L->wwz[i]);
    *d = v3(L->dx[i], L->dy[i], L->dz[i]);
}

/* Every lane's two rays through its way of depth k (all lanes alike),
 * its field complex below node jc (0: real all the way), absorbing on
 * the segments where absorbs: gather_lanes.c's steps (ray_lanes.h), each
 * lane reading its own way; the lanes from g on (repeating lane 0) are
 * not split (psi 0). */
LP__WIDE static void gm_kernel(const gm_lanes *restrict L, lp__ray_lanes *restrict R0,
                               lp__ray_lanes *restrict R1, int k, int jc, int absorbs, int g)
{
    GM_LANES(i) {
        lp_vec3 u, v, w, d;
        gm_frame(L, i, &u, &v, &w, &d);
        lp_vec3 light = v3(L->lx[i], L->ly[i], L->lz[i]);
        lp__rl_start(R0, i, u, v, w, light);
        lp__rl_start(R1, i, u, v, w, light);
    }
    /* the way, in the light's direction: way_step_real while the field is
     * real (j > jc), way_step on a complex one */
    for (int j = k; j >= 1; j--) {
        const int cplx = j < jc; /* the field arriving is complex */
        if (j < k && absorbs) { /* over the segment from node j + 1 */
            if (cplx)
                GM_LANES(i) {
                    lp__rl_absorb_complex(R0, i, L->sa[j][i], L->st[j][i]);
                    lp__rl_absorb_complex(R1, i, L->sa[j][i], L->st[j][i]);
                }
            else
                GM_LANES(i) {
                    lp__rl_absorb(R0, i, L->sa[j][i], L->st[j][i]);
                    lp__rl_absorb(R1, i, L->sa[j][i], L->st[j][i]);
                }
        }
        if (j <= jc && reflects(j, k)) { /* lp__node_project, reflect_on, complex */
            if (cplx)
                GM_LANES(i) {
                    lp_vec3 s, p, ap;
                    gm_axes(L, j, i, &s, &p, &ap);
                    double rs = L->fa[j][i], rp = L->fb[j][i];
                    double rsi = L->fc[j][i], rpi = L->fd[j][i];
                    lp__rl_reflect_complex(R0, i, s, p, ap, rs, rsi, rp, rpi, 1);
                    lp__rl_reflect_complex(R1, i, s, p, ap, rs, rsi, rp, rpi, 1);
                }
            else
                GM_LANES(i) {
                    lp_vec3 s, p, ap;
                    gm_axes(L, j, i, &s, &p, &ap);
                    double rs = L->fa[j][i], rp = L->fb[j][i];
                    double rsi = L->fc[j][i], rpi = L->fd[j][i];
                    lp__rl_reflect_complex(R0, i, s, p, ap, rs, rsi, rp, rpi, 0);
                    lp__rl_reflect_complex(R1, i, s, p, ap, rs, rsi, rp, rpi, 0);
                }
        } else if (j <= jc) { /* lp__node_project, transmit_on, complex */
            GM_LANES(i) {
                lp_vec3 s, p, ap;
                gm_axes(L, j, i, &s, &p, &ap);
                lp__rl_transmit_complex(R0, i, s, p, ap, L->fa[j][i], L->fb[j][i]);
                lp__rl_transmit_complex(R1, i, s, p, ap, L->fa[j][i], L->fb[j][i]);
            }
        } else if (reflects(j, k)) { /* lp__node_reflect_real */
            GM_LANES(i) {
                lp_vec3 s, p, ap;
                gm_axes(L, j, i, &s, &p, &ap);
                lp__rl_reflect(R0, i, s, p, ap, L->fa[j][i], L->fb[j][i]);
                lp__rl_reflect(R1, i, s, p, ap, L->fa[j][i], L->fb[j][i]);
            }
        } else { /* lp__node_transmit_real */
            GM_LANES(i) {
                lp_vec3 s, p, ap;
                gm_axes(L, j, i, &s, &p, &ap);
                lp__rl_transmit(R0, i, s, p, ap, L->fa[j][i], L->fb[j][i]);
                lp__rl_transmit(R1, i, s, p, ap, L->fa[j][i], L->fb[j][i]);
            }
        }
    }
    if (jc > 0) { /* lp__field_split of a complex field */
        GM_LANES(i) {
            lp__rl_square(R0, i);
            lp__rl_square(R1, i);
        }
        for (int i = 0; i < GM; i++)
            for (int h = 0; h < 2; h++)
                lp__rl_phase(h ? R1 : R0, i, i < g);
        GM_LANES(i) {
            lp_vec3 u, v, w, d;
            gm_frame(L, i, &u, &v, &w, &d);
            lp__rl_parts(R0, i, d, u, v, w);
            lp__rl_parts(R1, i, d, u, v, w);
        }
        return;
    }
    GM_LANES(i) {
        lp_vec3 u, v, w, d;
        gm_frame(L, i, &u, &v, &w, &d);
        lp__rl_leave(R0, i, d, u, v, w);
        lp__rl_leave(R1, i, d, u, v, w);
    }
}

/* Whether the lanes take request (bw, q, bundle[0..n)): a polarized
 * build's query (its ways set up) whose way lanes take (complex_at >= 0),
 * not too deep, its rays fine and few enough. */
static int in_lanes(const lp_backward *bw, size_t q, const lp_ray *bundle, size_t n)
{
    /* (a build through a crystal sets no ways) */
    if (!bw || !bundle || n == 0 || n > GM_WINDOW || !bw->ways || q >= bw->n_queries ||
        bw->complex_at[q] < 0 || bw->query[q].depth > GM_DEPTH)
        return 0;
    for (size_t i = 0; i < n; i++)
        if (!lp__ray_fine(&bundle[i]))
            return 0;
    return 1;
}

/* Node j of lane i's way: w's axes and factors (the imaginary parts of a
 * reflection's where im: a node the complex steps take). */
LP__INLINE void way_in(gm_lanes *L, int i, int j, const lp__bw_way *w, int im)
{
    const lp__node *nd = &w->node;
    L->sx[j][i] = nd->s.x, L->sy[j][i] = nd->s.y, L->sz[j][i] = nd->s.z;
    L->px[j][i] = nd->p.x, L->py[j][i] = nd->p.y, L->pz[j][i] = nd->p.z;
    L->ax[j][i] = w->ax.p.x, L->ay[j][i] = w->ax.p.y, L->az[j][i] = w->ax.p.z;
    if (w->reflect) {
        L->fa[j][i] = creal(nd->f.rs), L->fb[j][i] = creal(nd->f.rp);
        if (im)
            L->fc[j][i] = cimag(nd->f.rs), L->fd[j][i] = cimag(nd->f.rp);
    } else {
        L->fa[j][i] = nd->f.ts, L->fb[j][i] = nd->f.tp;
    }
}

/* Lane i of L takes query q of bw (in_lanes; its field complex below
 * node jc, absorbing where absorbs) and its rays b[0] and b[1] (b[0]
 * twice where two is 0): what gm_kernel reads of them. */
LP__INLINE void lane_in(gm_lanes *L, lp__ray_lanes *R, int i, const lp_backward *bw, size_t q,
                        const lp_ray *b, int two, int jc, int absorbs)
{
    const lp_lens *lens = bw->lens;
    const int k = bw->query[q].depth;
    const lp__bw_way *entry = &bw->entry[q];
    const lp_vec3 light = entry->node.d, d = bw->exit.d;
    const lp_ray *b1 = two ? b + 1 : b;
    R[0].vx[i] = b->vp.x, R[0].vy[i] = b->vp.y, R[0].vz[i] = b->vp.z;
    R[0].in[i] = b->intensity;
    R[1].vx[i] = b1->vp.x, R[1].vy[i] = b1->vp.y, R[1].vz[i] = b1->vp.z;
    R[1].in[i] = b1->intensity;
    L->lx[i] = light.x, L->ly[i] = light.y, L->lz[i] = light.z;
    L->dx[i] = d.x, L->dy[i] = d.y, L->dz[i] = d.z;
    L->ux[i] = lens->u.x, L->uy[i] = lens->u.y, L->uz[i] = lens->u.z;
    L->wvx[i] = lens->v.x, L->wvy[i] = lens->v.y, L->wvz[i] = lens->v.z;
    L->wwx[i] = lens->w.x, L->wwy[i] = lens->w.y, L->wwz[i] = lens->w.z;
    way_in(L, i, k, entry, jc >= k);
    for (int j = k - 1; j >= 1; j--) {
        way_in(L, i, j, &bw->light[j], j <= jc);
        if (absorbs)
            L->sa[j][i] = bw->node[j].seg_abs, L->st[j][i] = bw->node[j].seg_att;
    }
}

/* A window of requests: per request whether the lanes take it (its group,
 * else -1) and the place of its first ray; per ray (request by request,
 * each one's rays in order) what leaves. */
typedef struct gm_window {
    int key[GM_WINDOW];
    size_t ray[GM_WINDOW];
    int order[GM_WINDOW]; /* the requests, by group */
    unsigned char bad[GM_WINDOW]; /* per request: a ray's field direction
                                     fails, or a complex field turns real */
    double pw[GM_WINDOW], ab[GM_WINDOW], fl[GM_WINDOW];
    double wx[GM_WINDOW], wy[GM_WINDOW], wz[GM_WINDOW];
    /* a complex field's: the parts, the second's power and direction, the
     * phase */
    double np[GM_WINDOW], pw1[GM_WINDOW], psi[GM_WINDOW];
    double wx1[GM_WINDOW], wy1[GM_WINDOW], wz1[GM_WINDOW];
    /* the group being filled: its lanes' first rays' places in the
     * window and how many rays each has (1 or 2) */
    size_t at[GM];
    size_t req[GM];
    int two[GM];
    /* and its first lane's request and first ray there */
    size_t k0, i0;
} gm_window;

/* Run the g lanes of group `key` filled, the lanes past g repeating the
 * first, and keep what leaves at the rays' places. */
static void run_group(gm_window *W, gm_lanes *L, lp__ray_lanes *R, int g, int key,
                      const lp_backward *const *bw, const size_t *q, const lp_ray *const *bundle)
{
    int jc = (key >> 1) % (GM_DEPTH + 1);
    for (int i = g; i < GM; i++)
        lane_in(L, R, i, bw[W->k0], q[W->k0], &bundle[W->k0][W->i0], W->two[0], jc, key & 1);
    gm_kernel(L, &R[0], &R[1], (key >> 1) / (GM_DEPTH + 1), jc, key & 1, g);
    for (int i = 0; i < g; i++)
        for (int h = 0; h <= W->two[i]; h++) {
            size_t t = W->at[i] + (size_t)h;
            W->bad[W->req[i]] |= (R[h].ok[i] == 0.0) | (R[h].odd[i] != 0.0);
            W->pw[t] = R[h].pw[i];
            W->ab[t] = R[h].ab[i];
            W->fl[t] = R[h].fl[i];
            W->wx[t] = R[h].wx[i], W->wy[t] = R[h].wy[i], W->wz[t] = R[h].wz[i];
            if (jc > 0) {
                W->np[t] = R[h].np[i];
                W->pw1[t] = R[h].pw1[i];
                W->psi[t] = R[h].psi[i];
                W->wx1[t] = R[h].wx1[i], W->wy1[t] = R[h].wy1[i], W->wz1[t] = R[h].wz1[i];
            }
        }
}

/* Gather the rays of requests k0 .. k0+m the lanes take, group by group,
 * GM lanes at a time, two rays a lane. */
static void run_window(gm_window *W, gm_lanes *L, lp__ray_lanes *R, size_t k0, size_t m,
                       const lp_backward *const *bw, const size_t *q,
                       const lp_ray *const *bundle, const size_t *n)
{
    /* the requests the lanes take by group, each group in the requests'
     * order: a counting sort over the keys from the least to the largest
     * in the window (a few queries' depths) */
    int lo = GM_KEYS, hi = -1;
    for (size_t r = 0; r < m; r++)
        if (W->key[r] >= 0) {
            lo = W->key[r] < lo ? W->key[r] : lo;
            hi = W->key[r] > hi ? W->key[r] : hi;
        }
    int count[GM_KEYS + 1];
    for (int c = 0; c <= hi - lo + 1; c++)
        count[c] = 0;
    for (size_t r = 0; r < m; r++)
        if (W->key[r] >= 0)
            count[W->key[r] - lo + 1]++;
    for (int c = 1; c <= hi - lo + 1; c++)
        count[c] += count[c - 1];
    int end = hi < 0 ? 0 : count[hi - lo + 1];
    for (size_t r = 0; r < m; r++)
        if (W->key[r] >= 0)
            W->order[count[W->key[r] - lo]++] = (int)r;
    int g = 0, key = -1, jc = 0, absorbs = 0;
    for (int o = 0; o < end; o++) {
        size_t r = (size_t)W->order[o], k = k0 + r;
        if (W->key[r] != key) {
            if (g > 0)
                run_group(W, L, R, g, key, bw, q, bundle);
            g = 0;
            key = W->key[r];
            jc = (key >> 1) % (GM_DEPTH + 1), absorbs = key & 1;
        }
        for (size_t i = 0; i < n[k]; i += 2) {
            int two = i + 1 < n[k];
            if (g == 0)
                W->k0 = k, W->i0 = i;
            lane_in(L, R, g, bw[k], q[k], &bundle[k][i], two, jc, absorbs);
            W->at[g] = W->ray[r] + i;
            W->req[g] = r;
            W->two[g] = two;
            if (++g == GM) {
                run_group(W, L, R, g, key, bw, q, bundle);
                g = 0;
            }
        }
    }
    if (g > 0)
        run_group(W, L, R, g, key, bw, q, bundle);
}

/* Store request r's rays, from place t of the window, into out as
 * lp_backward_gather does (lp__gather_lanes). */
static lp_status store(const gm_window *W, size_t t, const lp_backward *bw, size_t q,
                       const lp_ray *b, size_t n, lp_result *out, lp_error *err)
{
    const int cx = bw->complex_at[q] > 0; /* split (lp__field_split_elliptic) */
    out->warnings |= bw->warnings;
    for (size_t i = 0; i < n; i++, t++) {
        lp_status st =
            cx ? lp__rl_store(out, bw, q, &b[i], W->fl[t], W->ab[t], (int)W->np[t], W->pw[t],
                              v3(W->wx[t], W->wy[t], W->wz[t]), W->pw1[t],
                              v3(W->wx1[t], W->wy1[t], W->wz1[t]), W->psi[t], err)
               : lp__rl_store(out, bw, q, &b[i], W->fl[t], W->ab[t], W->pw[t] > 0.0, W->pw[t],
                              v3(W->wx[t], W->wy[t], W->wz[t]), 0.0, v3(0, 0, 0), 0.0, err);
        if (st != LP_OK)
            return st;
    }
    return LP_OK;
}

lp_status lp_backward_gather_many(const lp_backward *const *bw, const size_t *q,
                                  const lp_ray *const *bundle, const size_t *n, size_t count,
                                  lp_result *out, size_t *start, lp_error *err)
{
    gm_window W;
    gm_lanes L;
    lp__ray_lanes R[2]; /* the lanes' two rays */

    if (!out || (count > 0 && (!bw || !q || !bundle || !n)))
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_backward_gather_many: NULL argument");
    for (size_t k0 = 0; k0 < count;) {
        /* a window: the requests from k0 whose rays fit, each marked with
         * its group if the lanes take it */
        size_t m = 0, rays = 0;
        while (k0 + m < count && m < GM_WINDOW) {
            size_t k = k0 + m;
            const lp_backward *b = bw[k];
            W.key[m] = -1;
            W.bad[m] = 0;
            if (in_lanes(b, q[k], bundle[k], n[k])) {
                if (rays + n[k] > GM_WINDOW)
                    break;
                int depth = b->query[q[k]].depth, jc = b->complex_at[q[k]];
                W.key[m] = 2 * ((GM_DEPTH + 1) * depth + jc) + (b->optics.alpha > 0.0);
                W.ray[m] = rays;
                rays += n[k];
            }
            m++;
        }
        if (rays > 0)
            run_window(&W, &L, R, k0, m, bw, q, bundle, n);
        /* the window's requests in order: from the lanes where every ray's
         * field direction checked out (and no complex field turned real),
         * else by lp_backward_gather */
        for (size_t r = 0; r < m; r++) {
            size_t k = k0 + r;
            lp_status st;
            int in = W.key[r] >= 0 && !W.bad[r];
            if (start)
                start[k] = out->count;
            if (in)
                st = store(&W, W.ray[r], bw[k], q[k], bundle[k], n[k], out, err);
            else
                st = lp_backward_gather(bw[k], q[k], bundle[k], n[k], out, err);
            if (st != LP_OK) {
                if (err) {
                    lp_error e = *err;
                    lp__fail(err, st, "request %zu: %s", k, e.message);
                }
                return st;
            }
        }
        k0 += m;
    }
    lp__ok(err);
    return LP_OK;
}
