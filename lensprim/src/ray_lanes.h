/* ray_lanes.h -- a polarized gather's bundle rays in lanes: their state
 * and their steps through a way's nodes (internal).
 *
 * Both gathers in lanes take these steps: gather_lanes.c (the rays of one
 * request, along one way) and gather_many.c (a lane per request, each
 * along its own way, two rays a lane).  Each function is one step of one
 * lane i, the one-ray code's operations in their order (trace_backward.c:
 * gather_one; interface.c: reflect_on, transmit_on; cvec3.h;
 * polarization.c: lp__field_split_real, lp__field_split_elliptic), so that
 * a lane's numbers are that code's bit for bit; the loops over the lanes
 * that call them are the callers' (lanes.h: LP__LANE_LOOP, LP__WIDE).  A
 * field is real until a node under total internal reflection makes it
 * complex: then its real and imaginary parts are carried side by side and
 * the amplitudes (s, p) multiplied by the complex factors part by part, as
 * the compiler's complex product does.  (A complex field whose imaginary
 * part vanishes is taken as real again by the one-ray code: such a lane is
 * marked odd, for its caller to leave to that code.) */
#ifndef LP_RAY_LANES_H
#define LP_RAY_LANES_H

#include <complex.h>
#include <math.h>

#include "backward.h"
#include "lanes.h"
#include "polarization.h"

/* Lanes of a group, at most. */
#define LP__RAY_LANES 8

typedef struct lp__ray_lanes {
    double vx[LP__RAY_LANES], vy[LP__RAY_LANES], vz[LP__RAY_LANES]; /* in: world field
                                                                       directions */
    double in[LP__RAY_LANES];  /* in: intensities */
    double ok[LP__RAY_LANES];  /* 1: the field direction checks out */
    double ex[LP__RAY_LANES], ey[LP__RAY_LANES], ez[LP__RAY_LANES]; /* the field, local
                                                                       (its real part) */
    double fx[LP__RAY_LANES], fy[LP__RAY_LANES], fz[LP__RAY_LANES]; /* its imaginary part,
                                                                       once complex */
    double odd[LP__RAY_LANES]; /* 1: it turned real again (one by one) */
    double ab[LP__RAY_LANES];  /* power absorbed in the glass */
    double fl[LP__RAY_LANES];  /* phase jumps counted */
    double pw[LP__RAY_LANES];  /* out: the power leaving */
    double wx[LP__RAY_LANES], wy[LP__RAY_LANES], wz[LP__RAY_LANES]; /* out: its world field
                                                                       direction */
    /* a complex field's split (lp__field_split_elliptic): the square
     * E.E, the ellipse's phase psi and exp(-i psi); out: the parts (0, 1
     * or 2), the second one's power and world field direction */
    double qr[LP__RAY_LANES], qi[LP__RAY_LANES], psi[LP__RAY_LANES];
    double hr[LP__RAY_LANES], hi[LP__RAY_LANES];
    double np[LP__RAY_LANES];
    double pw1[LP__RAY_LANES];
    double wx1[LP__RAY_LANES], wy1[LP__RAY_LANES], wz1[LP__RAY_LANES];
} lp__ray_lanes;

/* Whether a bundle ray passes the checks of lp__bundle_ray_check that
 * come before its field direction's (a ray that does not is left to the
 * one-ray code, which reports it). */
static inline int lp__ray_fine(const lp_ray *b)
{
    return isfinite(b->intensity) && !(b->intensity < 0.0) && isfinite(b->op) &&
           isfinite(b->phase) && v3_finite(b->vp);
}

/* lp__bundle_ray_check of lane i's ray (its local field direction,
 * perpendicular to the light; lens frame u, v, w), then its amplitude;
 * the counts start at 0. */
LP__INLINE void lp__rl_start(lp__ray_lanes *restrict R, int i, lp_vec3 u, lp_vec3 v, lp_vec3 w,
                             lp_vec3 light)
{
    lp_vec3 b = v3(R->vx[i], R->vy[i], R->vz[i]);
    lp_vec3 l = v3(v3_dot(b, u), v3_dot(b, v), v3_dot(b, w));
    double ok;
    lp_vec3 e = v3_scale(lp__perp_unit_core(l, light, &ok), sqrt(R->in[i]));
    R->ok[i] = ok;
    R->ex[i] = e.x, R->ey[i] = e.y, R->ez[i] = e.z;
    R->fx[i] = R->fy[i] = R->fz[i] = 0.0;
    R->odd[i] = 0.0;
    R->ab[i] = 0.0;
    R->fl[i] = 0.0;
}

/* A real field over a segment: the power absorbed (seg_abs sa) and the
 * amplitude's factor (seg_att st). */
LP__INLINE void lp__rl_absorb(lp__ray_lanes *restrict R, int i, double sa, double st)
{
    lp_vec3 e = v3(R->ex[i], R->ey[i], R->ez[i]);
    R->ab[i] += v3_dot(e, e) * sa;
    e = v3_scale(e, st);
    R->ex[i] = e.x, R->ey[i] = e.y, R->ez[i] = e.z;
}

/* lp__node_reflect_real on the node's axes s, p, the branch's p axis ap
 * and the real factors rs, rp: the field turns the mirror way round where
 * its mirror image would point against it, a phase jump counted. */
LP__INLINE void lp__rl_reflect(lp__ray_lanes *restrict R, int i, lp_vec3 s, lp_vec3 p,
                               lp_vec3 ap, double rs, double rp)
{
    lp_vec3 e = v3(R->ex[i], R->ey[i], R->ez[i]);
    double es = v3_dot(e, s), ep = v3_dot(e, p);
    int flip = rs * (es * es) - rp * (ep * ep) < 0.0;
    double a = flip ? -rs : rs, c = flip ? -rp : rp;
    e = v3_add(v3_scale(s, a * es), v3_scale(ap, c * ep));
    R->ex[i] = e.x, R->ey[i] = e.y, R->ez[i] = e.z;
    R->fl[i] += flip ? 1.0 : 0.0;
}

/* lp__node_transmit_real. */
LP__INLINE void lp__rl_transmit(lp__ray_lanes *restrict R, int i, lp_vec3 s, lp_vec3 p,
                                lp_vec3 ap, double ts, double tp)
{
    lp_vec3 e = v3(R->ex[i], R->ey[i], R->ez[i]);
    double es = v3_dot(e, s), ep = v3_dot(e, p);
    e = v3_add(v3_scale(s, ts * es), v3_scale(ap, tp * ep));
    R->ex[i] = e.x, R->ey[i] = e.y, R->ez[i] = e.z;
}

/* The world direction of the unit part of the local e perpendicular to
 * the unit d (lp__unit_perp, lp__to_world_dir). */
LP__INLINE lp_vec3 lp__rl_world_perp(lp_vec3 e, lp_vec3 d, lp_vec3 u, lp_vec3 v, lp_vec3 w)
{
    lp_vec3 c = lp__unit_perp(e, d);
    return v3_add(v3_add(v3_scale(u, c.x), v3_scale(v, c.y)), v3_scale(w, c.z));
}

/* lp__field_split_real and lp__emit_linear of a real field: the power
 * and the world field direction of the ray leaving along the local d. */
LP__INLINE void lp__rl_leave(lp__ray_lanes *restrict R, int i, lp_vec3 d, lp_vec3 u, lp_vec3 v,
                             lp_vec3 w)
{
    lp_vec3 e = v3(R->ex[i], R->ey[i], R->ez[i]);
    lp_vec3 o = lp__rl_world_perp(e, d, u, v, w);
    R->pw[i] = v3_dot(e, e);
    R->wx[i] = o.x, R->wy[i] = o.y, R->wz[i] = o.z;
}

/* A complex field over a segment (cv3_norm2, cv3_scale_real). */
LP__INLINE void lp__rl_absorb_complex(lp__ray_lanes *restrict R, int i, double sa, double st)
{
    double n2 = R->ex[i] * R->ex[i] + R->fx[i] * R->fx[i] + R->ey[i] * R->ey[i] +
                R->fy[i] * R->fy[i] + R->ez[i] * R->ez[i] + R->fz[i] * R->fz[i];
    R->ab[i] += n2 * sa;
    R->ex[i] *= st, R->ey[i] *= st, R->ez[i] *= st;
    R->fx[i] *= st, R->fy[i] *= st, R->fz[i] *= st;
}

/* lp__node_project of the field on the axes s, p: the real and imaginary
 * parts of its amplitudes.  A real field (cplx 0, a constant of each
 * loop) has real ones, their imaginary parts 0 (not its zeros projected);
 * a complex one whose imaginary part is zero is marked odd
 * (lp__node_project would take it as real). */
LP__INLINE void lp__rl_project(lp__ray_lanes *restrict R, int i, lp_vec3 s, lp_vec3 p, int cplx,
                               double *esr, double *esi, double *epr, double *epi)
{
    lp_vec3 e = v3(R->ex[i], R->ey[i], R->ez[i]);
    lp_vec3 f = v3(R->fx[i], R->fy[i], R->fz[i]);
    *esr = v3_dot(e, s), *epr = v3_dot(e, p);
    if (cplx) {
        *esi = v3_dot(f, s), *epi = v3_dot(f, p);
        R->odd[i] += (f.x == 0.0) & (f.y == 0.0) & (f.z == 0.0) ? 1.0 : 0.0;
    } else {
        *esi = 0.0, *epi = 0.0;
    }
}

/* The field after a node, a s + b pr for the complex a = (ar, ai),
 * b = (br, bi): cv3_combine. */
LP__INLINE void lp__rl_combine(lp__ray_lanes *restrict R, int i, double ar, double ai, lp_vec3 s,
                               double br, double bi, lp_vec3 pr)
{
    R->ex[i] = ar * s.x + br * pr.x, R->fx[i] = ai * s.x + bi * pr.x;
    R->ey[i] = ar * s.y + br * pr.y, R->fy[i] = ai * s.y + bi * pr.y;
    R->ez[i] = ar * s.z + br * pr.z, R->fz[i] = ai * s.z + bi * pr.z;
}

/* reflect_on for a complex field (cplx 1), or a real one at a node under
 * total internal reflection (cplx 0), with the complex rs = (rs, rsi),
 * rp = (rp, rpi): the field turns the mirror way round where its mirror
 * image would point against it, a phase jump counted. */
LP__INLINE void lp__rl_reflect_complex(lp__ray_lanes *restrict R, int i, lp_vec3 s, lp_vec3 p,
                                       lp_vec3 ap, double rs, double rsi, double rp, double rpi,
                                       int cplx)
{
    double esr, esi, epr, epi;
    lp__rl_project(R, i, s, p, cplx, &esr, &esi, &epr, &epi);
    double mirror = rs * (esr * esr + esi * esi) - rp * (epr * epr + epi * epi);
    int flip = mirror < 0.0;
    double a = flip ? -rs : rs, b = flip ? -rsi : rsi;
    double c = flip ? -rp : rp, d = flip ? -rpi : rpi;
    lp__rl_combine(R, i, a * esr - b * esi, a * esi + b * esr, s, c * epr - d * epi,
                   c * epi + d * epr, ap);
    R->fl[i] += flip ? 1.0 : 0.0;
}

/* transmit_on of a complex field. */
LP__INLINE void lp__rl_transmit_complex(lp__ray_lanes *restrict R, int i, lp_vec3 s, lp_vec3 p,
                                        lp_vec3 ap, double ts, double tp)
{
    double esr, esi, epr, epi;
    lp__rl_project(R, i, s, p, 1, &esr, &esi, &epr, &epi);
    lp__rl_combine(R, i, ts * esr, ts * esi, s, tp * epr, tp * epi, ap);
}

/* lp__field_split_elliptic of a complex field leaving along the local d,
 * in three steps: its square (cv3_norm2, cv3_is_real, E.E; a field whose
 * imaginary part is zero is marked odd: split as real by the one-ray
 * code) ... */
LP__INLINE void lp__rl_square(lp__ray_lanes *restrict R, int i)
{
    double ex = R->ex[i], ey = R->ey[i], ez = R->ez[i];
    double fx = R->fx[i], fy = R->fy[i], fz = R->fz[i];
    R->pw[i] = ex * ex + fx * fx + ey * ey + fy * fy + ez * ez + fz * fz;
    R->odd[i] += (fx == 0.0) & (fy == 0.0) & (fz == 0.0) ? 1.0 : 0.0;
    R->qr[i] = (ex * ex - fx * fx) + (ey * ey - fy * fy) + (ez * ez - fz * fz);
    R->qi[i] = (ex * fx + fx * ex) + (ey * fy + fy * ey) + (ez * fz + fz * ez);
}

/* ... the ellipse's phase psi and exp(-i psi) (lp__ellipse_psi,
 * lp__phasor_minus: not in lanes, a lane at a time; a lane not in use
 * (used 0) gets psi 0) ... */
static inline void lp__rl_phase(lp__ray_lanes *R, int i, int used)
{
    double psi = 0.0;
    double complex h = 1.0;
    if (used) {
        psi = lp__ellipse_psi(CMPLX(R->qr[i], R->qi[i]));
        h = psi == 0.0 ? 1.0 : lp__phasor_minus(psi);
    }
    R->psi[i] = psi, R->hr[i] = creal(h), R->hi[i] = cimag(h);
}

/* ... and the parts: F = E exp(-i psi) (E itself for psi 0), A and B its
 * real and imaginary parts, each leaving as a linear ray in world
 * directions (lens frame u, v, w); the first one's in pw and wx..wz. */
LP__INLINE void lp__rl_parts(lp__ray_lanes *restrict R, int i, lp_vec3 d, lp_vec3 u, lp_vec3 v,
                             lp_vec3 w)
{
    double ex = R->ex[i], ey = R->ey[i], ez = R->ez[i];
    double fx = R->fx[i], fy = R->fy[i], fz = R->fz[i];
    double hr = R->hr[i], hi = R->hi[i], total = R->pw[i];
    int same = R->psi[i] == 0.0;
    lp_vec3 a = v3(same ? ex : ex * hr - fx * hi, same ? ey : ey * hr - fy * hi,
                   same ? ez : ez * hr - fz * hi);
    lp_vec3 b = v3(same ? fx : ex * hi + fx * hr, same ? fy : ey * hi + fy * hr,
                   same ? fz : ez * hi + fz * hr);
    double ia = v3_dot(a, a), ib = v3_dot(b, b);
    int one = ib <= 1e-20 * total;
    lp_vec3 o = lp__rl_world_perp(a, d, u, v, w), o1 = lp__rl_world_perp(b, d, u, v, w);
    R->np[i] = !(total > 0.0) ? 0.0 : (one ? 1.0 : 2.0);
    R->pw[i] = one ? total : ia;
    R->wx[i] = o.x, R->wy[i] = o.y, R->wz[i] = o.z;
    R->pw1[i] = ib;
    R->wx1[i] = o1.x, R->wy1[i] = o1.y, R->wz1[i] = o1.z;
}

/* A gathered bundle ray b of query q of bw stored in res as the one-ray
 * code stores it (lp__emit_gathered_parts): its np parts leaving (the
 * first of power pw along the world field direction w and phase psi, the
 * second of power pw1 along w1 and phase psi + pi/2; a real field is one
 * part of phase 0, or none where its power is not > 0), its phase jumps
 * fl and the power ab its glass absorbed, the rest truncated.  What both
 * gathers in lanes do with a lane's outcome. */
LP__INLINE lp_status lp__rl_store(lp_result *res, const lp_backward *bw, size_t q,
                                  const lp_ray *b, double fl, double ab, int np, double pw,
                                  lp_vec3 w, double pw1, lp_vec3 w1, double psi, lp_error *err)
{
    const lp_query *qr = &bw->query[q];
    lp__payload pl = {bw->optics.lambda_nm, b->kphi + (int)fl, b->op + qr->op, b->phase, b->ch};
    double before = res->out;
    lp_status st = LP_OK;
    res->in += b->intensity;
    res->nodes += (size_t)qr->depth;
    if (np > 0)
        st = lp__emit_ray(res, &bw->exit, &pl, qr->depth, qr->kind, qr->surface, qr->path,
                          qr->waves, 0, pw, w, psi, err);
    if (np > 1 && st == LP_OK)
        st = lp__emit_ray(res, &bw->exit, &pl, qr->depth, qr->kind, qr->surface, qr->path,
                          qr->waves, 1, pw1, w1, psi + 0.5 * LP_PI, err);
    if (st != LP_OK)
        return st;
    lp__gathered_rest(res, before, b->intensity, ab);
    return LP_OK;
}

#endif
