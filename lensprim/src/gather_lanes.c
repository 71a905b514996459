/* gather_lanes.c -- a polarized gather, a few rays at a time in lanes.
 *
 * In the polarized mode a bundle ray's field is real until a node under
 * total internal reflection (or at normal incidence, where the node's s
 * axis follows the field) makes it complex; both are properties of the
 * query's way, not of the ray (lp__backward_built marks where each way's
 * fields turn complex, and the ways the lanes take).  Along such a way
 * every ray of a gather takes the same steps: its field direction is
 * checked and taken into the lens frame and scaled to its amplitude; at
 * each node the field is projected on the node's s and p axes and
 * rebuilt on the branch's axes (a reflection counting its phase jump),
 * having lost power to the glass on the segment before.  From the first
 * node under total internal reflection on, the field is complex: its
 * real and imaginary parts are carried in lanes of their own, and the
 * amplitudes (s, p) are multiplied by the complex factors part by part,
 * as the compiler's complex product does.  A field that stays real
 * leaves as one linear ray; a complex one is split into the axes of its
 * ellipse, in lanes but for the ellipse's phase and its exponential
 * (lp__ellipse_psi, lp__phasor_minus), taken lane by lane.  The rays of a
 * group take these steps side by side, in loops over lanes that the
 * compiler vectorizes (lanes.h), each lane with the operations of the
 * one-ray code in their order (ray_lanes.h, whose steps gather_many.c
 * takes too), so that its numbers are that code's bit for bit; the
 * outgoing rays are then stored in the rays' order, as gathering them one
 * by one stores them.  (A complex field whose imaginary part vanishes on the way
 * is taken as real again by the one-ray code; a lane where that happens
 * is left to it.) */
#include <math.h>

#include "backward.h"
#include "lanes.h"
#include "ray_lanes.h"

/* Rays per group. */
#define GL 4
_Static_assert(GL <= LP__RAY_LANES, "a group's rays fit lp__ray_lanes");

/* A loop over the lanes of a group (lanes.h). */
#define GL_LANES(i) LP__LANE_LOOP(i, GL)

LP__WIDE static void gather_kernel(lp__ray_lanes *restrict L, const lp_backward *bw, size_t q,
                                   int m)
{
    const lp_lens *lens = bw->lens;
    const lp_vec3 u = lens->u, v = lens->v, w = lens->w;
    const lp_vec3 light = bw->entry[q].node.d, exit_d = bw->exit.d;
    const int k = bw->query[q].depth, absorbs = bw->optics.alpha > 0.0;
    const int jc = bw->complex_at[q]; /* the field is complex below node jc */

    GL_LANES(i) lp__rl_start(L, i, u, v, w, light);
    /* the way, in the light's direction: way_step_real while the field is
     * real (j > jc), way_step on a complex one */
    for (int j = k; j >= 1; j--) {
        const lp__bw_way *wj = j == k ? &bw->entry[q] : &bw->light[j];
        const lp_vec3 s = wj->node.s, p = wj->node.p, ap = wj->ax.p;
        const int cplx = j < jc; /* the field arriving is complex */
        if (j < k && absorbs) { /* over the segment from node j + 1 */
            const double seg_abs = bw->node[j].seg_abs, seg_att = bw->node[j].seg_att;
            if (cplx)
                GL_LANES(i) lp__rl_absorb_complex(L, i, seg_abs, seg_att);
            else
                GL_LANES(i) lp__rl_absorb(L, i, seg_abs, seg_att);
        }
        if (j <= jc && wj->reflect) { /* lp__node_project, reflect_on, complex */
            const double rs = creal(wj->node.f.rs), rsi = cimag(wj->node.f.rs);
            const double rp = creal(wj->node.f.rp), rpi = cimag(wj->node.f.rp);
            if (cplx)
                GL_LANES(i) lp__rl_reflect_complex(L, i, s, p, ap, rs, rsi, rp, rpi, 1);
            else
                GL_LANES(i) lp__rl_reflect_complex(L, i, s, p, ap, rs, rsi, rp, rpi, 0);
        } else if (j <= jc) { /* lp__node_project, transmit_on, complex */
            const double ts = wj->node.f.ts, tp = wj->node.f.tp;
            GL_LANES(i) lp__rl_transmit_complex(L, i, s, p, ap, ts, tp);
        } else if (wj->reflect) { /* lp__node_reflect_real */
            const double rs = creal(wj->node.f.rs), rp = creal(wj->node.f.rp);
            GL_LANES(i) lp__rl_reflect(L, i, s, p, ap, rs, rp);
        } else { /* lp__node_transmit_real */
            const double ts = wj->node.f.ts, tp = wj->node.f.tp;
            GL_LANES(i) lp__rl_transmit(L, i, s, p, ap, ts, tp);
        }
    }
    if (jc > 0) { /* lp__field_split of a complex field: the m lanes in use */
        GL_LANES(i) lp__rl_square(L, i);
        for (int i = 0; i < GL; i++)
            lp__rl_phase(L, i, i < m);
        GL_LANES(i) lp__rl_parts(L, i, exit_d, u, v, w);
        return;
    }
    /* lp__field_split_real and lp__emit_linear */
    GL_LANES(i) lp__rl_leave(L, i, exit_d, u, v, w);
}

size_t lp__gather_lanes(const lp_backward *bw, size_t q, const lp_ray *bundle, size_t n,
                        lp_result *res, lp_status *st, lp_error *err)
{
    lp__ray_lanes L;
    size_t done = 0;

    *st = LP_OK;
    while (done < n) {
        size_t m = n - done < GL ? n - done : GL;
        const lp_ray *b = bundle + done;
        for (size_t i = 0; i < m; i++)
            if (!lp__ray_fine(&b[i])) {
                m = i; /* ray i and the rest one by one: that reports ray i */
                break;
            }
        if (m == 0)
            return done;
        for (size_t i = 0; i < GL; i++) { /* lanes past m repeat the first */
            const lp_ray *r = &b[i < m ? i : 0];
            L.vx[i] = r->vp.x, L.vy[i] = r->vp.y, L.vz[i] = r->vp.z;
            L.in[i] = r->intensity;
        }
        gather_kernel(&L, bw, q, (int)m);
        for (size_t i = 0; i < m; i++) {
            if (L.ok[i] == 0.0 || L.odd[i] != 0.0)
                return done; /* the field direction fails, or turns real: one by one */
            if (bw->complex_at[q] > 0) /* split (lp__field_split_elliptic) */
                *st = lp__rl_store(res, bw, q, &b[i], L.fl[i], L.ab[i], (int)L.np[i], L.pw[i],
                                   v3(L.wx[i], L.wy[i], L.wz[i]), L.pw1[i],
                                   v3(L.wx1[i], L.wy1[i], L.wz1[i]), L.psi[i], err);
            else /* real: one part (lp__field_split_real) */
                *st = lp__rl_store(res, bw, q, &b[i], L.fl[i], L.ab[i], L.pw[i] > 0.0, L.pw[i],
                                   v3(L.wx[i], L.wy[i], L.wz[i]), 0.0, v3(0, 0, 0), 0.0, err);
            if (*st != LP_OK)
                return done;
            done++;
        }
    }
    return done;
}
