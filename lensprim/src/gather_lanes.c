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
 * (lp__ellipse_psi, lp__phasor_minus), taken lane by lane.  The rays of a group take these steps side
 * by side, in loops over lanes that the compiler vectorizes (lanes.h),
 * each lane with the operations of the one-ray code (trace_backward.c:
 * gather_one, interface.c: reflect_on, transmit_on; cvec3.h) in their
 * order, so that its numbers are that code's bit for bit; the outgoing
 * rays are then stored in the rays' order, as gathering them one by one
 * stores them.  (A complex field whose imaginary part vanishes on the way
 * is taken as real again by the one-ray code; a lane where that happens
 * is left to it.) */
#include <math.h>

#include "backward.h"
#include "lanes.h"

/* Rays per group. */
#define GL 4

/* A loop over the lanes of a group (lanes.h). */
#define GL_LANES(i) LP__LANE_LOOP(i, GL)

/* The lanes of a group. */
typedef struct gl_lanes {
    double vx[GL], vy[GL], vz[GL]; /* in: world field directions */
    double in[GL];                 /* in: intensities */
    double ok[GL];                 /* 1: the field direction checks out */
    double ex[GL], ey[GL], ez[GL]; /* the field, local (its real part) */
    double fx[GL], fy[GL], fz[GL]; /* its imaginary part, once complex */
    double odd[GL];                /* 1: it turned real again (one by one) */
    double ab[GL];                 /* power absorbed in the glass */
    double fl[GL];                 /* phase jumps counted */
    double pw[GL];                 /* out: the power leaving */
    double wx[GL], wy[GL], wz[GL]; /* out: its world field direction */
    /* a complex field's split (lp__field_split_elliptic): the square
     * E.E, the ellipse's phase psi and exp(-i psi); out: the parts (0, 1
     * or 2), the second one's power and world field direction */
    double qr[GL], qi[GL], psi[GL], hr[GL], hi[GL];
    double np[GL];
    double pw1[GL];
    double wx1[GL], wy1[GL], wz1[GL];
} gl_lanes;

/* lp__node_project of lane i's field on the axes s, p: the real and
 * imaginary parts of its amplitudes.  A real field (cplx 0, a constant
 * of each loop) has real ones, their imaginary parts 0 (not its zeros
 * projected); a complex one whose imaginary part is zero is marked odd
 * (lp__node_project would take it as real). */
LP__INLINE void gl_project(gl_lanes *restrict L, int i, lp_vec3 s, lp_vec3 p, int cplx,
                           double *esr, double *esi, double *epr, double *epi)
{
    lp_vec3 e = v3(L->ex[i], L->ey[i], L->ez[i]);
    lp_vec3 f = v3(L->fx[i], L->fy[i], L->fz[i]);
    *esr = v3_dot(e, s), *epr = v3_dot(e, p);
    if (cplx) {
        *esi = v3_dot(f, s), *epi = v3_dot(f, p);
        L->odd[i] += (f.x == 0.0) & (f.y == 0.0) & (f.z == 0.0) ? 1.0 : 0.0;
    } else {
        *esi = 0.0, *epi = 0.0;
    }
}

/* Lane i's field after a node, a s + b pr for the complex a = (ar, ai),
 * b = (br, bi): cv3_combine. */
LP__INLINE void gl_combine(gl_lanes *restrict L, int i, double ar, double ai, lp_vec3 s,
                           double br, double bi, lp_vec3 pr)
{
    L->ex[i] = ar * s.x + br * pr.x, L->fx[i] = ai * s.x + bi * pr.x;
    L->ey[i] = ar * s.y + br * pr.y, L->fy[i] = ai * s.y + bi * pr.y;
    L->ez[i] = ar * s.z + br * pr.z, L->fz[i] = ai * s.z + bi * pr.z;
}

/* The world direction of the unit part of the local e perpendicular to
 * the unit d (lp__unit_perp, lp__to_world_dir). */
LP__INLINE lp_vec3 gl_world_perp(lp_vec3 e, lp_vec3 d, lp_vec3 u, lp_vec3 v, lp_vec3 w)
{
    lp_vec3 c = lp__unit_perp(e, d);
    return v3_add(v3_add(v3_scale(u, c.x), v3_scale(v, c.y)), v3_scale(w, c.z));
}

/* lp__field_split of each lane's complex field, leaving along the local
 * d, the lanes' outgoing parts in world directions (axes u, v, w), the
 * first one's in pw and wx..wz: lp__field_split_elliptic's steps, the
 * complex products part by part; the phase psi and exp(-i psi) by its
 * own helpers, lane by lane (only the m lanes in use).  A field whose
 * imaginary part is zero is marked odd (split as real by the one-ray
 * code). */
LP__INLINE void gl_split(gl_lanes *restrict L, int m, lp_vec3 d, lp_vec3 u, lp_vec3 v,
                         lp_vec3 w)
{
    GL_LANES(i) { /* cv3_norm2, cv3_is_real, E.E */
        double ex = L->ex[i], ey = L->ey[i], ez = L->ez[i];
        double fx = L->fx[i], fy = L->fy[i], fz = L->fz[i];
        L->pw[i] = ex * ex + fx * fx + ey * ey + fy * fy + ez * ez + fz * fz;
        L->odd[i] += (fx == 0.0) & (fy == 0.0) & (fz == 0.0) ? 1.0 : 0.0;
        L->qr[i] = (ex * ex - fx * fx) + (ey * ey - fy * fy) + (ez * ez - fz * fz);
        L->qi[i] = (ex * fx + fx * ex) + (ey * fy + fy * ey) + (ez * fz + fz * ez);
    }
    for (int i = m; i < GL; i++) /* lanes not in use: psi 0 */
        L->psi[i] = 0.0, L->hr[i] = 1.0, L->hi[i] = 0.0;
    for (int i = 0; i < m; i++) {
        double psi = lp__ellipse_psi(CMPLX(L->qr[i], L->qi[i]));
        double complex h = psi == 0.0 ? 1.0 : lp__phasor_minus(psi);
        L->psi[i] = psi, L->hr[i] = creal(h), L->hi[i] = cimag(h);
    }
    GL_LANES(i) { /* F = E exp(-i psi) (E itself for psi 0), A and B its parts */
        double ex = L->ex[i], ey = L->ey[i], ez = L->ez[i];
        double fx = L->fx[i], fy = L->fy[i], fz = L->fz[i];
        double hr = L->hr[i], hi = L->hi[i], total = L->pw[i];
        int same = L->psi[i] == 0.0;
        lp_vec3 a = v3(same ? ex : ex * hr - fx * hi, same ? ey : ey * hr - fy * hi,
                       same ? ez : ez * hr - fz * hi);
        lp_vec3 b = v3(same ? fx : ex * hi + fx * hr, same ? fy : ey * hi + fy * hr,
                       same ? fz : ez * hi + fz * hr);
        double ia = v3_dot(a, a), ib = v3_dot(b, b);
        int one = ib <= 1e-20 * total;
        lp_vec3 o = gl_world_perp(a, d, u, v, w), o1 = gl_world_perp(b, d, u, v, w);
        L->np[i] = !(total > 0.0) ? 0.0 : (one ? 1.0 : 2.0);
        L->pw[i] = one ? total : ia;
        L->wx[i] = o.x, L->wy[i] = o.y, L->wz[i] = o.z;
        L->pw1[i] = ib;
        L->wx1[i] = o1.x, L->wy1[i] = o1.y, L->wz1[i] = o1.z;
    }
}

/* reflect_on for lane i's field (cplx: complex, else real at a node
 * under total internal reflection) and the complex rs, rp (real and
 * imaginary parts): the field turns the mirror way round where its
 * mirror image would point against it, a phase jump counted. */
LP__INLINE void gl_reflect(gl_lanes *restrict L, int i, lp_vec3 s, lp_vec3 p, lp_vec3 ap,
                           const double rs[2], const double rp[2], int cplx)
{
    double esr, esi, epr, epi;
    gl_project(L, i, s, p, cplx, &esr, &esi, &epr, &epi);
    double mirror = rs[0] * (esr * esr + esi * esi) - rp[0] * (epr * epr + epi * epi);
    int flip = mirror < 0.0;
    double a = flip ? -rs[0] : rs[0], b = flip ? -rs[1] : rs[1];
    double c = flip ? -rp[0] : rp[0], d = flip ? -rp[1] : rp[1];
    gl_combine(L, i, a * esr - b * esi, a * esi + b * esr, s, c * epr - d * epi,
               c * epi + d * epr, ap);
    L->fl[i] += flip ? 1.0 : 0.0;
}

LP__WIDE static void gather_kernel(gl_lanes *restrict L, const lp_backward *bw, size_t q, int m)
{
    const lp_lens *lens = bw->lens;
    const lp_vec3 u = lens->u, v = lens->v, w = lens->w;
    const lp_vec3 light = bw->entry[q].node.d, exit_d = bw->exit.d;
    const int k = bw->query[q].depth, absorbs = bw->optics.alpha > 0.0;
    const int jc = bw->complex_at[q]; /* the field is complex below node jc */

    /* lp__bundle_ray_check: the local field direction, perpendicular to
     * the light; then the amplitude */
    GL_LANES(i) {
        lp_vec3 b = v3(L->vx[i], L->vy[i], L->vz[i]);
        lp_vec3 l = v3(v3_dot(b, u), v3_dot(b, v), v3_dot(b, w));
        double ok;
        lp_vec3 e = v3_scale(lp__perp_unit_core(l, light, &ok), sqrt(L->in[i]));
        L->ok[i] = ok;
        L->ex[i] = e.x, L->ey[i] = e.y, L->ez[i] = e.z;
        L->fx[i] = L->fy[i] = L->fz[i] = 0.0;
        L->odd[i] = 0.0;
        L->ab[i] = 0.0;
        L->fl[i] = 0.0;
    }
    /* the way, in the light's direction: way_step_real while the field is
     * real (j > jc), way_step on a complex one */
    for (int j = k; j >= 1; j--) {
        const lp__bw_way *wj = j == k ? &bw->entry[q] : &bw->light[j];
        const lp_vec3 s = wj->node.s, p = wj->node.p, ap = wj->ax.p;
        const int cplx = j < jc; /* the field arriving is complex */
        if (j < k && absorbs) { /* over the segment from node j + 1 */
            const double seg_abs = bw->node[j].seg_abs, seg_att = bw->node[j].seg_att;
            if (cplx) { /* cv3_norm2, cv3_scale_real */
                GL_LANES(i) {
                    double n2 = L->ex[i] * L->ex[i] + L->fx[i] * L->fx[i] + L->ey[i] * L->ey[i] +
                                L->fy[i] * L->fy[i] + L->ez[i] * L->ez[i] + L->fz[i] * L->fz[i];
                    L->ab[i] += n2 * seg_abs;
                    L->ex[i] *= seg_att, L->ey[i] *= seg_att, L->ez[i] *= seg_att;
                    L->fx[i] *= seg_att, L->fy[i] *= seg_att, L->fz[i] *= seg_att;
                }
            } else {
                GL_LANES(i) {
                    lp_vec3 e = v3(L->ex[i], L->ey[i], L->ez[i]);
                    L->ab[i] += v3_dot(e, e) * seg_abs;
                    e = v3_scale(e, seg_att);
                    L->ex[i] = e.x, L->ey[i] = e.y, L->ez[i] = e.z;
                }
            }
        }
        if (j <= jc && wj->reflect) { /* lp__node_project, reflect_on, complex */
            const double rs[2] = {creal(wj->node.f.rs), cimag(wj->node.f.rs)};
            const double rp[2] = {creal(wj->node.f.rp), cimag(wj->node.f.rp)};
            if (cplx)
                GL_LANES(i) gl_reflect(L, i, s, p, ap, rs, rp, 1);
            else
                GL_LANES(i) gl_reflect(L, i, s, p, ap, rs, rp, 0);
        } else if (j <= jc) { /* lp__node_project, transmit_on, complex */
            const double ts = wj->node.f.ts, tp = wj->node.f.tp;
            GL_LANES(i) {
                double esr, esi, epr, epi;
                gl_project(L, i, s, p, 1, &esr, &esi, &epr, &epi);
                gl_combine(L, i, ts * esr, ts * esi, s, tp * epr, tp * epi, ap);
            }
        } else if (wj->reflect) { /* lp__node_reflect_real */
            const double rs = creal(wj->node.f.rs), rp = creal(wj->node.f.rp);
            GL_LANES(i) {
                lp_vec3 e = v3(L->ex[i], L->ey[i], L->ez[i]);
                double es = v3_dot(e, s), ep = v3_dot(e, p);
                int flip = rs * (es * es) - rp * (ep * ep) < 0.0;
                double a = flip ? -rs : rs, c = flip ? -rp : rp;
                e = v3_add(v3_scale(s, a * es), v3_scale(ap, c * ep));
                L->ex[i] = e.x, L->ey[i] = e.y, L->ez[i] = e.z;
                L->fl[i] += flip ? 1.0 : 0.0;
            }
        } else { /* lp__node_transmit_real */
            const double ts = wj->node.f.ts, tp = wj->node.f.tp;
            GL_LANES(i) {
                lp_vec3 e = v3(L->ex[i], L->ey[i], L->ez[i]);
                double es = v3_dot(e, s), ep = v3_dot(e, p);
                e = v3_add(v3_scale(s, ts * es), v3_scale(ap, tp * ep));
                L->ex[i] = e.x, L->ey[i] = e.y, L->ez[i] = e.z;
            }
        }
    }
    if (jc > 0) {
        gl_split(L, m, exit_d, u, v, w);
        return;
    }
    /* lp__field_split_real and lp__emit_linear: the power and the world
     * field direction of the ray leaving */
    GL_LANES(i) {
        lp_vec3 e = v3(L->ex[i], L->ey[i], L->ez[i]);
        lp_vec3 d = lp__unit_perp(e, exit_d);
        lp_vec3 o = v3_add(v3_add(v3_scale(u, d.x), v3_scale(v, d.y)), v3_scale(w, d.z));
        L->pw[i] = v3_dot(e, e);
        L->wx[i] = o.x, L->wy[i] = o.y, L->wz[i] = o.z;
    }
}

/* Whether a bundle ray passes the checks of lp__bundle_ray_check that
 * come before its field direction's. */
static int ray_fine(const lp_ray *b)
{
    return isfinite(b->intensity) && !(b->intensity < 0.0) && isfinite(b->op) &&
           isfinite(b->phase) && v3_finite(b->vp);
}

size_t lp__gather_lanes(const lp_backward *bw, size_t q, const lp_ray *bundle, size_t n,
                        lp_result *res, lp_status *st, lp_error *err)
{
    const lp_query *qr = &bw->query[q];
    gl_lanes L;
    size_t done = 0;

    *st = LP_OK;
    while (done < n) {
        size_t m = n - done < GL ? n - done : GL;
        const lp_ray *b = bundle + done;
        for (size_t i = 0; i < m; i++)
            if (!ray_fine(&b[i])) {
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
            lp__payload pl = {bw->optics.lambda_nm, b[i].kphi + (int)L.fl[i],
                              b[i].op + qr->op, b[i].phase, b[i].ch};
            double before = res->out;
            res->in += L.in[i];
            res->nodes += (size_t)qr->depth;
            if (bw->complex_at[q] > 0) { /* lp__emit_gathered_parts of the split */
                for (int t = 0; t < (int)L.np[i]; t++) {
                    *st = lp__emit_ray(res, &bw->exit, &pl, qr->depth, qr->kind, qr->surface,
                                       qr->path, qr->waves, t, t ? L.pw1[i] : L.pw[i],
                                       t ? v3(L.wx1[i], L.wy1[i], L.wz1[i])
                                         : v3(L.wx[i], L.wy[i], L.wz[i]),
                                       t ? L.psi[i] + 0.5 * LP_PI : L.psi[i], err);
                    if (*st != LP_OK)
                        return done;
                }
                lp__gathered_rest(res, before, L.in[i], L.ab[i]);
                done++;
                continue;
            }
            if (L.pw[i] > 0.0) { /* lp__field_split_real: one part */
                *st = lp__emit_ray(res, &bw->exit, &pl, qr->depth, qr->kind, qr->surface,
                                   qr->path, qr->waves, 0, L.pw[i],
                                   v3(L.wx[i], L.wy[i], L.wz[i]), 0.0, err);
                if (*st != LP_OK)
                    return done;
            }
            lp__gathered_rest(res, before, L.in[i], L.ab[i]);
            done++;
        }
    }
    return done;
}
