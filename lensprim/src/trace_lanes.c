/* trace_lanes.c -- the lane engine (trace_lanes.h): a group of forward
 * rays of one wavelength through a glass lens, node by node in lockstep.
 *
 * The state of every lane is held as arrays (a structure of arrays), and
 * each step is a few loops over the lanes, free of branches and calls: a
 * lane's choices (which cap it meets, whether it has left, whether its
 * field is real) are selects, and a lane that has left keeps computing
 * numbers nobody reads (this file is built with -fno-trapping-math for
 * that).  Between those loops, plain loops do lane by lane what the one-
 * ray code does with calls: the rim test of the lanes near the rim,
 * expm1 (absorption), and the nodes of total internal reflection or
 * normal incidence (by the one-ray code's own node functions).  Each
 * formula below is the one-ray code's (lanes.h, interface.c,
 * polarization.h, trace_common.c, trace_forward.c) with its operations in
 * the same order, so every lane's numbers are that code's, bit for bit;
 * where a ray's branches could differ from the one-ray code's (the cases
 * trace_lanes.h lists) the ray is handed back.
 *
 * The outgoing rays are kept per node and lane, and lp__lanes_emit adds
 * them to the result ray by ray in the one-ray code's order: sums of
 * floating-point numbers depend on the order of their terms. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "interface.h"
#include "polarization.h"
#include "result.h"
#include "lanes.h"
#include "trace_lanes.h"

#define NL LP__LANES

/* What became of a ray of the group. */
enum { RAY_OFF, RAY_MISS, RAY_BACK, RAY_RIM, RAY_CHAIN };
/* How a chain ended before a node. */
enum { END_TRUNCATED = 1, END_RIM = 2 };
/* What a node sent out: nothing (total internal reflection), a real
 * field staged in full, or any field for lp__emit_power. */
enum { EMIT_NONE = 0, EMIT_REAL = 1, EMIT_FIELD = 2 };

/* The numbers kept per node and lane: the outgoing ray (world origin,
 * direction, field direction, power), the payload, the surface, how it
 * was sent out, the power absorbed on the way to the node, whether the
 * chain ended before the node (END_*) and the power it ended with; for
 * EMIT_FIELD the field (real and imaginary parts) and its local
 * direction.  (The loops never store a lane's old value back under a
 * condition: the compiler would make that a conditional store, which
 * cannot be vectorized.) */
enum { F_OX, F_OY, F_OZ, F_DX, F_DY, F_DZ, F_VX, F_VY, F_VZ, F_POW, F_KPHI, F_OP, F_SURF,
       F_EMIT, F_ABS, F_END, F_ENDVAL, F_ERX, F_ERY, F_ERZ, F_EIX, F_EIY, F_EIZ, F_LX, F_LY,
       F_LZ, NF };

struct lp__lanes {
    int max_depth;
    size_t m;                     /* rays in the group */
    size_t n_chain;               /* lanes walking a chain */
    size_t n_vec;                 /* lanes the vector loops step: n_chain
                                     rounded up to whole vectors of 4 (the
                                     rest copies lane 0, not live), so that
                                     no lane is left to a scalar tail */
    unsigned warnings;            /* of the optics */
    int absorbs;                  /* the glass absorbs */
    unsigned char ray[NL];        /* RAY_* of ray j */
    unsigned char lane[NL];       /* the chain lane of ray j */
    double take[NL];              /* 1: ray j is the engine's to trace */
    /* node 1's reflection, by ray */
    double r1[NF][NL];
    /* the chains, by lane */
    double px[NL], py[NL], pz[NL]; /* the node the lane is at */
    double dx[NL], dy[NL], dz[NL]; /* the direction it goes on in */
    double ex[NL], ey[NL], ez[NL]; /* its field: real part */
    double fx[NL], fy[NL], fz[NL]; /* imaginary part (0 before a TIR) */
    double pw[NL];                 /* the field's power */
    double surf[NL], entry[NL];    /* surface of the node, of node 1 */
    double kphi[NL], op[NL];       /* phase jumps inside, optical path */
    double cut[NL];                /* min_weight times the ray's intensity */
    double live[NL];               /* 1: still walking */
    double back[NL];               /* > 0: handed back */
    double final[NL];              /* the power left at the last node */
    int staged;                    /* the deepest node kept */
    /* one step's hit, and the lanes the one-ray code does a part for */
    double t[NL], hs[NL], hx[NL], hy[NL], hz[NL], rim[NL], em[NL], odd[NL], cut_now[NL];
    double odx[NL], ody[NL], odz[NL], oex[NL], oey[NL], oez[NL], ofx[NL], ofy[NL], ofz[NL];
    /* one node's geometry between the loops of a step (geom) */
    double gnx[NL], gny[NL], gnz[NL]; /* the cap's outward normal */
    double gtx[NL], gty[NL], gtz[NL]; /* transmitted direction */
    double grx[NL], gry[NL], grz[NL]; /* reflected direction */
    double gsx[NL], gsy[NL], gsz[NL]; /* the s axis */
    double ga[NL], gb[NL], gis[NL], gip[NL], grs[NL], grp[NL], gci[NL], gct[NL];
    double gts[NL], gtp[NL];
    double gtir[NL], godd[NL];
    double *node;                  /* [depth][NF][NL] for depths 2.. */
};

lp__lanes *lp__lanes_create(int max_depth)
{
    lp__lanes *L = malloc(sizeof *L);
    if (!L)
        return NULL;
    L->max_depth = max_depth;
    L->node = malloc((size_t)(max_depth + 1) * NF * NL * sizeof *L->node);
    if (!L->node) {
        free(L);
        return NULL;
    }
    L->m = 0;
    return L;
}

void lp__lanes_destroy(lp__lanes *L)
{
    if (L)
        free(L->node);
    free(L);
}

/* The lens and the optics as the loops read them (copies, so that no
 * store to the lanes can be taken to change them). */
typedef struct consts {
    lp__lane_lens lens;
    double ng, nm, ha;      /* indices, -alpha/2 */
    double eta_in, eta_out; /* n_medium/n_glass, n_glass/n_medium */
    double r0_in, r0_out;   /* Schlick's R0 */
    double cut_w;           /* min_weight */
} consts;

static void consts_of(consts *K, const lp_lens *lens, const lp__optics *o, const lp_trace_args *a)
{
    lp__lane_lens_of(&K->lens, lens);
    K->ng = o->n_glass;
    K->nm = o->n_medium;
    K->ha = -0.5 * o->alpha;
    K->eta_in = o->n_medium / o->n_glass;
    K->eta_out = o->n_glass / o->n_medium;
    K->r0_in = lp__lane_schlick_r0(o->n_medium, o->n_glass);
    K->r0_out = lp__lane_schlick_r0(o->n_glass, o->n_medium);
    K->cut_w = a->min_weight;
}

/* A node of the field e + i f (lp__lane_node_at, then the field's part of
 * lp__node_setup, lp__node_project, lp__node_transmit_amp and
 * lp__node_reflect_amp) from index n1 into n2, eta = n1/n2, in three
 * passes over the lanes, so that each loop is short and its lanes
 * overlap (the square roots and divisions of one lane's chain wait on
 * each other): geom (the geometry and the s axis), units (the directions
 * normalized), fields (the field on the s and p axes, its amplitudes).
 * A field with an imaginary part (after a total internal reflection:
 * only in polarized mode) takes the complex arithmetic of the one-ray
 * code, a real one its real arithmetic.  godd is set where the one-ray
 * code branches otherwise: total internal reflection, normal
 * incidence. */
typedef struct node_out {
    lp_vec3 t, Et, Eti; /* transmitted direction and field */
    lp_vec3 r, Er, Eri; /* reflected direction and field */
    double flip;        /* 1: a phase jump on reflection */
} node_out;

/* The geometry of lane c's node along d, at the normal gn[c]. */
LP__INLINE void geom(lp__lanes *restrict L, size_t c, double n1, double n2, double eta, lp_vec3 d)
{
    lp__lane_node g;
    lp__lane_node_raw(n1, n2, eta, d, v3(L->gnx[c], L->gny[c], L->gnz[c]), &g);
    /* the s axis */
    lp_vec3 s = v3_cross(d, g.nn);
    double sl2 = v3_dot(s, s);
    int odd = g.tir | !(sl2 > 1e-18);
    s = v3_scale(s, 1.0 / sqrt(sl2));
    L->gtx[c] = g.t.x, L->gty[c] = g.t.y, L->gtz[c] = g.t.z;
    L->grx[c] = g.r.x, L->gry[c] = g.r.y, L->grz[c] = g.r.z;
    L->gsx[c] = s.x, L->gsy[c] = s.y, L->gsz[c] = s.z;
    L->ga[c] = g.a, L->gb[c] = g.b;
    L->gis[c] = g.is, L->gip[c] = g.ip;
    L->gts[c] = g.ts, L->gtp[c] = g.tp;
    L->grs[c] = g.rs, L->grp[c] = g.rp;
    L->gci[c] = g.ci, L->gct[c] = g.ct;
    L->gtir[c] = g.tir ? 1.0 : 0.0;
    L->godd[c] = odd ? 1.0 : 0.0;
}

/* The transmitted and reflected directions of lanes 0..n-1, normalized. */
LP__INLINE void units(lp__lanes *restrict L, size_t n)
{
    for (size_t c = 0; c < n; c++) {
        lp_vec3 t = v3_normalize(v3(L->gtx[c], L->gty[c], L->gtz[c]));
        lp_vec3 r = v3_normalize(v3(L->grx[c], L->gry[c], L->grz[c]));
        L->gtx[c] = t.x, L->gty[c] = t.y, L->gtz[c] = t.z;
        L->grx[c] = r.x, L->gry[c] = r.y, L->grz[c] = r.z;
    }
}

/* The outgoing fields of lane c's node for the field e + i f along d
 * (cplx: f is not 0). */
LP__INLINE void fields(const lp__lanes *restrict L, size_t c, int law, double r0, lp_vec3 d,
                       lp_vec3 e, lp_vec3 f, int cplx, node_out *o)
{
    lp__lane_node g;
    g.a = L->ga[c], g.b = L->gb[c];
    g.is = L->gis[c], g.ip = L->gip[c];
    g.ts = L->gts[c], g.tp = L->gtp[c];
    g.rs = L->grs[c], g.rp = L->grp[c];
    g.ci = L->gci[c], g.ct = L->gct[c];
    g.tir = L->gtir[c] != 0.0;
    lp_vec3 s = v3(L->gsx[c], L->gsy[c], L->gsz[c]);
    lp_vec3 p = v3_cross(d, s);
    /* the field on them: real parts, and imaginary ones (0 when real) */
    double es = v3_dot(e, s), ep = v3_dot(e, p);
    double esi = cplx ? v3_dot(f, s) : 0.0, epi = cplx ? v3_dot(f, p) : 0.0;
    o->t = v3(L->gtx[c], L->gty[c], L->gtz[c]);
    o->r = v3(L->grx[c], L->gry[c], L->grz[c]);
    lp_vec3 pt = v3_cross(o->t, s), pr = v3_cross(o->r, s);
    /* the amplitudes on s and p: transmitted (t), reflected (r) */
    double ts_, tp_, tsi, tpi, rs_, rp_, rsi, rpi;
    if (law == LP__LAW_POLARIZED) {
        double mirror = g.rs * (es * es + esi * esi) - g.rp * (ep * ep + epi * epi);
        int flip = mirror < 0.0;
        double gs = g.ts, gp = g.tp;
        double ks = flip ? -g.rs : g.rs, kp = flip ? -g.rp : g.rp;
        double ki = flip ? -0.0 : 0.0; /* the imaginary part of +-rs, +-rp */
        o->flip = flip ? 1.0 : 0.0;
        ts_ = gs * es;
        tp_ = gp * ep;
        tsi = gs * esi;
        tpi = gp * epi;
        /* complex products (a full product, as the one-ray code's) */
        rs_ = cplx ? ks * es - ki * esi : ks * es;
        rp_ = cplx ? kp * ep - ki * epi : kp * ep;
        rsi = ks * esi + ki * es;
        rpi = kp * epi + ki * ep;
    } else {
        double R =
            lp__lane_reflectance(law != LP__LAW_FRESNEL, r0, law == LP__LAW_SCHLICK_CT, &g);
        double T = 1.0 - R;
        double kt = sqrt(T > 0.0 ? T : 0.0), kr = sqrt(R);
        o->flip = 0.0;
        ts_ = kt * es;
        tp_ = kt * ep;
        rs_ = kr * es;
        rp_ = -kr * ep;
        tsi = tpi = rsi = rpi = 0.0; /* the fields stay real */
    }
    o->Et = v3_add(v3_scale(s, ts_), v3_scale(pt, tp_));
    o->Er = v3_add(v3_scale(s, rs_), v3_scale(pr, rp_));
    lp_vec3 zero = v3(0.0, 0.0, 0.0);
    lp_vec3 Eti = v3_add(v3_scale(s, tsi), v3_scale(pt, tpi));
    lp_vec3 Eri = v3_add(v3_scale(s, rsi), v3_scale(pr, rpi));
    o->Eti = cplx ? Eti : zero;
    o->Eri = cplx ? Eri : zero;
}

/* cv3_norm2 of the field e + i f. */
LP__INLINE double power_of(lp_vec3 e, lp_vec3 f)
{
    return e.x * e.x + f.x * f.x + e.y * e.y + f.y * f.y + e.z * e.z + f.z * f.z;
}

/* cv3_norm2 of a real field (its zero imaginary parts add nothing). */
LP__INLINE double power_real(lp_vec3 e)
{
    return e.x * e.x + e.y * e.y + e.z * e.z;
}

/* An outgoing field from x (lp__leave, lp__exit_at, lp__field_split):
 * slot j of the fields f[NF][...] of one node holds its local direction
 * (F_L*) and its field's real part (F_ER*); this adds its world origin,
 * direction, and field direction. */
LP__INLINE void stage(const consts *K, double (*f)[NL], size_t j, lp_vec3 x)
{
    lp_vec3 dir = v3(f[F_LX][j], f[F_LY][j], f[F_LZ][j]);
    lp_vec3 e = v3(f[F_ERX][j], f[F_ERY][j], f[F_ERZ][j]);
    lp_vec3 o = lp__lane_world_point(&K->lens, x), dw = lp__lane_world_dir(&K->lens, dir);
    lp_vec3 vp = lp__lane_world_dir(&K->lens, lp__unit_perp(e, dir));
    f[F_OX][j] = o.x;
    f[F_OY][j] = o.y;
    f[F_OZ][j] = o.z;
    f[F_DX][j] = dw.x;
    f[F_DY][j] = dw.y;
    f[F_DZ][j] = dw.z;
    f[F_VX][j] = vp.x;
    f[F_VY][j] = vp.y;
    f[F_VZ][j] = vp.z;
}

/* ---- the steps ---------------------------------------------------- */

/* Node 1 of every ray taken: the entry hit (lp__lens_hit from outside
 * the lens), the external reflection, the refracted field; in passes
 * over the rays (see geom). */
LP__INLINE void entry_step(lp__lanes *restrict L, const consts *Kp, const lp__lane_in *in,
                           size_t m, int law)
{
    const consts Kl = *Kp, *K = &Kl; /* local: the loads are safe to select */
    double (*restrict f)[NL] = L->r1;
    for (size_t j = 0; j < m; j++) {
        lp_vec3 p = v3(in->px[j], in->py[j], in->pz[j]);
        lp_vec3 d = v3(in->dx[j], in->dy[j], in->dz[j]);
        int on = lp__lane_on_lens(&K->lens, p);
        double best;
        lp_vec3 x;
        int rim;
        double hs = lp__lane_hit_outside(&K->lens, p, d, &best, &x, &rim);
        int cap = hs >= 0.0;
        double surf = hs == 1.0 ? 1.0 : 0.0;
        /* the rim, for the lanes that could meet it: see entry_rim */
        L->rim[j] = rim ? 1.0 : 0.0;
        L->t[j] = best;
        /* the chain's start, at lane j until the lanes are packed */
        L->px[j] = x.x;
        L->py[j] = x.y;
        L->pz[j] = x.z;
        L->surf[j] = surf;
        /* what became of the ray (a start on the lens changes the hit;
         * odd nodes at the entry are the one-ray code's: below) */
        double what = cap ? RAY_CHAIN : RAY_MISS;
        what = on ? RAY_BACK : what;
        L->hs[j] = L->take[j] != 0.0 ? what : RAY_OFF;
    }
    for (size_t j = 0; j < m; j++) {
        lp_vec3 n = lp__lane_cap_normal(&K->lens, L->surf[j], v3(L->px[j], L->py[j], L->pz[j]));
        L->gnx[j] = n.x, L->gny[j] = n.y, L->gnz[j] = n.z;
    }
    for (size_t j = 0; j < m; j++)
        geom(L, j, K->nm, K->ng, K->eta_in, v3(in->dx[j], in->dy[j], in->dz[j]));
    units(L, m);
    for (size_t j = 0; j < m; j++) {
        lp_vec3 d = v3(in->dx[j], in->dy[j], in->dz[j]);
        lp_vec3 vp = v3(in->vx[j], in->vy[j], in->vz[j]);
        double I0 = in->intensity[j];
        lp_vec3 E = v3_scale(vp, sqrt(I0));
        node_out o;
        fields(L, j, law, K->r0_in, d, E, v3(0.0, 0.0, 0.0), 0, &o);
        f[F_LX][j] = o.r.x;
        f[F_LY][j] = o.r.y;
        f[F_LZ][j] = o.r.z;
        f[F_ERX][j] = o.Er.x;
        f[F_ERY][j] = o.Er.y;
        f[F_ERZ][j] = o.Er.z;
        f[F_POW][j] = power_real(o.Er);
        f[F_EMIT][j] = EMIT_REAL;
        f[F_KPHI][j] = o.flip;
        f[F_SURF][j] = L->surf[j];
        L->dx[j] = o.t.x;
        L->dy[j] = o.t.y;
        L->dz[j] = o.t.z;
        L->ex[j] = o.Et.x;
        L->ey[j] = o.Et.y;
        L->ez[j] = o.Et.z;
        L->pw[j] = power_real(o.Et);
        L->cut[j] = K->cut_w * I0;
        int odd = (L->hs[j] == RAY_CHAIN) & (L->godd[j] != 0.0);
        L->hs[j] = odd ? RAY_BACK : L->hs[j];
    }
    for (size_t j = 0; j < m; j++)
        stage(K, f, j, v3(L->px[j], L->py[j], L->pz[j]));
}

/* The first half of a step from a node: the weight cut, the next
 * hit (lp__lens_hit from the cap the lane is on) but for the rim of the
 * lanes that could meet it (rim[c] = 1: see between). */
LP__INLINE void hit_step(lp__lanes *restrict L, const consts *Kp)
{
    const consts Kl = *Kp, *K = &Kl; /* local: the loads are safe to select */
    size_t n = L->n_vec;
    for (size_t c = 0; c < n; c++) {
        lp_vec3 p = v3(L->px[c], L->py[c], L->pz[c]);
        lp_vec3 d = v3(L->dx[c], L->dy[c], L->dz[c]);
        int was = L->live[c] != 0.0;
        int cut = was & (L->pw[c] < L->cut[c]);
        int live = was & !cut;
        L->live[c] = live ? 1.0 : 0.0;
        L->cut_now[c] = cut ? 1.0 : 0.0;
        double best;
        lp_vec3 x;
        int rim;
        double hs = lp__lane_hit_inside(&K->lens, p, d, L->surf[c], &best, &x, &rim);
        L->t[c] = best;
        L->hs[c] = hs;
        L->hx[c] = x.x;
        L->hy[c] = x.y;
        L->hz[c] = x.z;
        L->rim[c] = rim & live ? 1.0 : 0.0;
        L->em[c] = K->ha * best;
    }
}

/* The vector loops, each in one copy per law and vector width. */
LP__WIDE static void entry_kernel(lp__lanes *restrict L, const consts *K, const lp__lane_in *in,
                                  size_t m, int law)
{
    switch (law) {
    case LP__LAW_POLARIZED: entry_step(L, K, in, m, LP__LAW_POLARIZED); break;
    case LP__LAW_FRESNEL: entry_step(L, K, in, m, LP__LAW_FRESNEL); break;
    case LP__LAW_SCHLICK_CI: entry_step(L, K, in, m, LP__LAW_SCHLICK_CI); break;
    default: entry_step(L, K, in, m, LP__LAW_SCHLICK_CT); break;
    }
}

LP__WIDE static void hit_kernel(lp__lanes *restrict L, const consts *K)
{
    hit_step(L, K);
}

/* Between a step's vector loops, lane by lane: the rim test of the lanes
 * near it (few) and the absorption's expm1, both the one-ray code's.
 * Returns the number of lanes still walking. */
static size_t between(lp__lanes *restrict L, const consts *K, int absorbs)
{
    size_t n = L->n_chain, live = 0;
    /* rim[c] is set on live lanes only */
    for (size_t c = 0; c < n; c++) {
        double t;
        if (L->rim[c] == 0.0)
            continue;
        lp_vec3 p = v3(L->px[c], L->py[c], L->pz[c]);
        lp_vec3 d = v3(L->dx[c], L->dy[c], L->dz[c]);
        double t_max = lp__rim_t_max(L->t[c], K->lens.eps);
        if (lp__rim_intersect(&K->lens.r, p, d, K->lens.eps, t_max, &t)) {
            lp_vec3 x = v3_madd(p, d, t);
            L->t[c] = t;
            L->hs[c] = 2.0;
            L->hx[c] = x.x;
            L->hy[c] = x.y;
            L->hz[c] = x.z;
            L->em[c] = K->ha * t;
        }
    }
    for (size_t c = 0; c < n; c++) {
        if (L->live[c] == 0.0) {
            L->em[c] = 0.0;
            continue;
        }
        live++;
        L->em[c] = absorbs ? expm1(L->em[c]) : 0.0;
    }
    for (size_t c = n; c < L->n_vec; c++)
        L->em[c] = 0.0;
    return live;
}

/* The entry's rim test (lp__lens_hit from outside the lens) of the rays
 * that could meet it: a hit before the cap's absorbs the ray. */
static void entry_rim(lp__lanes *restrict L, const consts *K, const lp__lane_in *in, size_t m)
{
    for (size_t j = 0; j < m; j++) {
        if (L->rim[j] == 0.0 || L->take[j] == 0.0 || L->hs[j] == RAY_BACK)
            continue;
        lp_vec3 p = v3(in->px[j], in->py[j], in->pz[j]);
        lp_vec3 d = v3(in->dx[j], in->dy[j], in->dz[j]);
        double t;
        if (lp__rim_intersect(&K->lens.r, p, d, 0.0, lp__rim_t_max(L->t[j], K->lens.eps), &t))
            L->hs[j] = RAY_RIM;
    }
}

/* The second half of a step: the end of the lanes cut, the segment to
 * the hit (absorption, optical path), the rim, the node there: its
 * outgoing ray into f, the reflected field on; in passes over the lanes
 * (see geom).  odd[c] = 1 marks the lanes whose node odd_step does
 * instead. */
LP__INLINE void node_step(lp__lanes *restrict L, const consts *Kp, int law,
                          double (*restrict f)[NL])
{
    const consts Kl = *Kp, *K = &Kl; /* local: the loads are safe to select */
    size_t n = L->n_vec;
    for (size_t c = 0; c < n; c++) {
        int was = L->live[c] != 0.0;
        lp_vec3 x = v3(L->hx[c], L->hy[c], L->hz[c]);
        lp_vec3 d = v3(L->dx[c], L->dy[c], L->dz[c]);
        lp_vec3 E = v3(L->ex[c], L->ey[c], L->ez[c]);
        lp_vec3 F = v3(L->fx[c], L->fy[c], L->fz[c]);
        double hs = L->hs[c];
        /* absorption (m = 0 when the glass has none: a factor 1) */
        double m = L->em[c];
        f[F_ABS][c] = L->pw[c] * (-m * (2.0 + m));
        E = v3_scale(E, 1.0 + m);
        F = v3_scale(F, 1.0 + m);
        double op = L->op[c] + K->ng * L->t[c];
        int cut = L->cut_now[c] != 0.0;
        int rim = was & (hs == 2.0);
        f[F_END][c] = cut ? END_TRUNCATED : (rim ? END_RIM : 0.0);
        f[F_ENDVAL][c] = cut ? L->pw[c] : power_of(E, F);
        int leak = was & (hs < 0.0);
        int live = was & !rim & !leak;
        f[F_OP][c] = op;
        f[F_SURF][c] = hs;
        L->op[c] = op;
        L->px[c] = x.x;
        L->py[c] = x.y;
        L->pz[c] = x.z;
        /* what the passes below and odd_step start from */
        L->odx[c] = d.x;
        L->ody[c] = d.y;
        L->odz[c] = d.z;
        L->oex[c] = E.x;
        L->oey[c] = E.y;
        L->oez[c] = E.z;
        L->ofx[c] = F.x;
        L->ofy[c] = F.y;
        L->ofz[c] = F.z;
        L->surf[c] = hs;
        L->back[c] = L->back[c] + (leak ? 1.0 : 0.0);
        L->live[c] = live ? 1.0 : 0.0;
    }
    for (size_t c = 0; c < n; c++) {
        lp_vec3 nrm = lp__lane_cap_normal(&K->lens, L->surf[c], v3(L->px[c], L->py[c], L->pz[c]));
        L->gnx[c] = nrm.x, L->gny[c] = nrm.y, L->gnz[c] = nrm.z;
    }
    for (size_t c = 0; c < n; c++)
        geom(L, c, K->ng, K->nm, K->eta_out, v3(L->odx[c], L->ody[c], L->odz[c]));
    units(L, n);
    for (size_t c = 0; c < n; c++) {
        lp_vec3 d = v3(L->odx[c], L->ody[c], L->odz[c]);
        lp_vec3 E = v3(L->oex[c], L->oey[c], L->oez[c]);
        lp_vec3 F = v3(L->ofx[c], L->ofy[c], L->ofz[c]);
        int cplx = (F.x != 0.0) | (F.y != 0.0) | (F.z != 0.0);
        node_out o;
        fields(L, c, law, K->r0_out, d, E, F, cplx, &o);
        /* Total internal reflection in an unpolarized mode is no odd
         * node: the one-ray code reflects the real field with R = 1 on
         * the same axes, as fields does, and sends nothing out. */
        int tir_here = (law != LP__LAW_POLARIZED) & (L->gtir[c] != 0.0);
        int odd = (L->live[c] != 0.0) & (L->godd[c] != 0.0) & !tir_here;
        /* a field with an imaginary part leaves by lp__emit_power */
        f[F_EMIT][c] = tir_here ? EMIT_NONE : (cplx ? EMIT_FIELD : EMIT_REAL);
        f[F_POW][c] = power_of(o.Et, o.Eti);
        f[F_ERX][c] = o.Et.x;
        f[F_ERY][c] = o.Et.y;
        f[F_ERZ][c] = o.Et.z;
        f[F_EIX][c] = o.Eti.x;
        f[F_EIY][c] = o.Eti.y;
        f[F_EIZ][c] = o.Eti.z;
        f[F_LX][c] = o.t.x;
        f[F_LY][c] = o.t.y;
        f[F_LZ][c] = o.t.z;
        f[F_KPHI][c] = L->kphi[c];
        L->kphi[c] = L->kphi[c] + (odd ? 0.0 : o.flip);
        /* the reflected field goes on (odd_step's, for an odd lane) */
        L->dx[c] = o.r.x;
        L->dy[c] = o.r.y;
        L->dz[c] = o.r.z;
        L->ex[c] = o.Er.x;
        L->ey[c] = o.Er.y;
        L->ez[c] = o.Er.z;
        L->fx[c] = o.Eri.x;
        L->fy[c] = o.Eri.y;
        L->fz[c] = o.Eri.z;
        L->pw[c] = power_of(o.Er, o.Eri);
        L->odd[c] = odd ? 1.0 : 0.0;
    }
    for (size_t c = 0; c < n; c++)
        stage(K, f, c, v3(L->px[c], L->py[c], L->pz[c]));
}

LP__WIDE static void node_kernel(lp__lanes *restrict L, const consts *K, int law,
                                 double (*restrict f)[NL])
{
    switch (law) {
    case LP__LAW_POLARIZED: node_step(L, K, LP__LAW_POLARIZED, f); break;
    case LP__LAW_FRESNEL: node_step(L, K, LP__LAW_FRESNEL, f); break;
    case LP__LAW_SCHLICK_CI: node_step(L, K, LP__LAW_SCHLICK_CI, f); break;
    default: node_step(L, K, LP__LAW_SCHLICK_CT, f); break;
    }
}

/* The nodes node_step leaves to the one-ray code (odd[c] = 1): total
 * internal reflection in polarized mode (complex rs, rp), and normal
 * incidence, where the field gives the s axis; by its own node
 * functions, lane by lane. */
static void odd_step(lp__lanes *restrict L, const lp_lens *lens, const lp__optics *op,
                     lp_mode mode, double (*restrict f)[NL])
{
    size_t n = L->n_chain;
    for (size_t c = 0; c < n; c++) {
        if (L->odd[c] == 0.0)
            continue;
        lp_vec3 x = v3(L->px[c], L->py[c], L->pz[c]);
        lp_vec3 d = v3(L->odx[c], L->ody[c], L->odz[c]);
        lp__cvec3 E;
        double *e = (double *)&E; /* a complex is an array of two doubles */
        e[0] = L->oex[c], e[1] = L->ofx[c];
        e[2] = L->oey[c], e[3] = L->ofy[c];
        e[4] = L->oez[c], e[5] = L->ofz[c];
        lp__node nd;
        lp__amp amp;
        lp__branch br;
        int s = (int)L->surf[c];
        int tir = lp__node_setup(&nd, d, lp__cap_normal(&lens->cap[s], x), op->n_glass,
                                 op->n_medium, &E);
        lp__node_project(&nd, &E, &amp);
        f[F_EMIT][c] = EMIT_NONE;
        if (!tir) {
            lp__node_transmit_amp(&nd, mode, &amp, &br);
            lp__exit xo = lp__exit_at(lens, x, br.dir);
            const double *b = (const double *)&br.E;
            f[F_OX][c] = xo.world_origin.x;
            f[F_OY][c] = xo.world_origin.y;
            f[F_OZ][c] = xo.world_origin.z;
            f[F_DX][c] = xo.world_dir.x;
            f[F_DY][c] = xo.world_dir.y;
            f[F_DZ][c] = xo.world_dir.z;
            f[F_LX][c] = br.dir.x;
            f[F_LY][c] = br.dir.y;
            f[F_LZ][c] = br.dir.z;
            f[F_ERX][c] = b[0], f[F_EIX][c] = b[1];
            f[F_ERY][c] = b[2], f[F_EIY][c] = b[3];
            f[F_ERZ][c] = b[4], f[F_EIZ][c] = b[5];
            f[F_POW][c] = cv3_norm2(br.E);
            f[F_EMIT][c] = EMIT_FIELD;
        }
        lp__node_reflect_amp(&nd, mode, &amp, &br);
        const double *b = (const double *)&br.E;
        L->dx[c] = br.dir.x;
        L->dy[c] = br.dir.y;
        L->dz[c] = br.dir.z;
        L->ex[c] = b[0], L->fx[c] = b[1];
        L->ey[c] = b[2], L->fy[c] = b[3];
        L->ez[c] = b[4], L->fz[c] = b[5];
        L->pw[c] = cv3_norm2(br.E);
        L->kphi[c] += br.flip;
    }
}

/* The lanes of every ray that walks a chain, packed to the front. */
static void pack(lp__lanes *L, const lp__lane_in *in, size_t m)
{
    size_t n = 0;
    for (size_t j = 0; j < m; j++) {
        L->ray[j] = (unsigned char)L->hs[j];
        if (L->ray[j] != RAY_CHAIN)
            continue;
        L->lane[j] = (unsigned char)n;
        L->px[n] = L->px[j];
        L->py[n] = L->py[j];
        L->pz[n] = L->pz[j];
        L->dx[n] = L->dx[j];
        L->dy[n] = L->dy[j];
        L->dz[n] = L->dz[j];
        L->ex[n] = L->ex[j];
        L->ey[n] = L->ey[j];
        L->ez[n] = L->ez[j];
        L->fx[n] = L->fy[n] = L->fz[n] = 0.0;
        L->pw[n] = L->pw[j];
        L->surf[n] = L->surf[j];
        L->entry[n] = L->surf[j];
        L->kphi[n] = 0.0;
        L->cut[n] = L->cut[j];
        L->op[n] = in->op[j];
        L->live[n] = 1.0;
        L->back[n] = 0.0;
        n++;
    }
    L->n_chain = n;
    L->n_vec = (n + 3) & ~(size_t)3;
    for (size_t c = n; c < L->n_vec; c++) {
        L->px[c] = L->px[0], L->py[c] = L->py[0], L->pz[c] = L->pz[0];
        L->dx[c] = L->dx[0], L->dy[c] = L->dy[0], L->dz[c] = L->dz[0];
        L->ex[c] = L->ex[0], L->ey[c] = L->ey[0], L->ez[c] = L->ez[0];
        L->fx[c] = L->fy[c] = L->fz[c] = 0.0;
        L->pw[c] = L->pw[0];
        L->surf[c] = L->surf[0];
        L->kphi[c] = 0.0;
        L->cut[c] = L->cut[0];
        L->op[c] = L->op[0];
        L->live[c] = 0.0;
        L->back[c] = 0.0;
    }
}

static void run(lp__lanes *restrict L, const consts *K, const lp_lens *lens,
                const lp__optics *op, const lp__lane_in *in, size_t m, int max_depth,
                lp_mode mode, int law_in, int law_out)
{
    entry_kernel(L, K, in, m, law_in);
    entry_rim(L, K, in, m);
    pack(L, in, m);
    int absorbs = L->absorbs;
    L->staged = 1;
    for (int depth = 1; depth < max_depth; depth++) {
        double (*f)[NL] = (double (*)[NL])(L->node + (size_t)(depth + 1) * NF * NL);
        hit_kernel(L, K);
        size_t live = between(L, K, absorbs);
        node_kernel(L, K, law_out, f);
        L->staged = depth + 1;
        if (live == 0)
            break;
        odd_step(L, lens, op, mode, f);
    }
    /* the lanes still walking stop at the depth */
    for (size_t c = 0; c < L->n_chain; c++)
        L->final[c] = L->pw[c];
}

void lp__lanes_run(lp__lanes *L, const lp_lens *lens, const lp__optics *o,
                   const lp_trace_args *a, const lp__lane_in *in, size_t m)
{
    consts K;
    consts_of(&K, lens, o, a);
    L->m = m;
    L->n_chain = L->n_vec = 0;
    L->warnings = o->warnings;
    L->absorbs = K.ha < 0.0;
    /* a crystal, or no interface at all: the one-ray code */
    int engine = !lens->desc.uniaxial && o->n_glass != o->n_medium;
    for (size_t j = 0; j < m; j++)
        L->take[j] = engine && in->take[j] != 0.0 ? 1.0 : 0.0;
    lp_mode mode = a->mode;
    int depth = a->max_depth;
    if (mode == LP_MODE_POLARIZED)
        run(L, &K, lens, o, in, m, depth, mode, LP__LAW_POLARIZED, LP__LAW_POLARIZED);
    else if (mode == LP_MODE_FRESNEL)
        run(L, &K, lens, o, in, m, depth, mode, LP__LAW_FRESNEL, LP__LAW_FRESNEL);
    else if (o->n_medium > o->n_glass)
        run(L, &K, lens, o, in, m, depth, mode, LP__LAW_SCHLICK_CT, LP__LAW_SCHLICK_CI);
    else
        run(L, &K, lens, o, in, m, depth, mode, LP__LAW_SCHLICK_CI, LP__LAW_SCHLICK_CT);
    for (size_t j = 0; j < m; j++)
        if (L->ray[j] == RAY_CHAIN && L->back[L->lane[j]] != 0.0)
            L->ray[j] = RAY_BACK;
}

int lp__lanes_traced(const lp__lanes *L, size_t j)
{
    return j < L->m && (L->ray[j] == RAY_MISS || L->ray[j] == RAY_RIM || L->ray[j] == RAY_CHAIN);
}

/* Field i of the slot a column f (&fields[0][lane]) points at. */
#define AT(f, i) ((f)[(size_t)(i) * NL])

/* Where lp__lanes_emit appends: the result, its running sum of the power
 * out (kept here, and written back before any call that reads it), and
 * whether room for every ray of the chain was made beforehand. */
typedef struct sink {
    lp_result *res;
    double out;
    int room;
} sink;

/* One outgoing ray of a node (lp__leave) from the column f: kept (and
 * appended when it carries power) or counted as skipped.  check: the
 * flags or the filter may decline it. */
LP__INLINE lp_status leave(const lp_lens *lens, const lp_trace_args *a, sink *sk,
                           const double *f, const lp__payload *pl, double phase, int depth,
                           int kphi, double op, lp_kind kind, int surface, uint64_t path,
                           int check, lp_error *err)
{
    lp_result *res = sk->res;
    double power = AT(f, F_POW);
    lp_vec3 origin = v3(AT(f, F_OX), AT(f, F_OY), AT(f, F_OZ));
    lp_vec3 dir = v3(AT(f, F_DX), AT(f, F_DY), AT(f, F_DZ));
    if (check) {
        lp_branch_info info = {depth, kind, surface, origin, dir, power};
        res->out = sk->out;
        int keep = lp__args_keep(a, &info);
        sk->out = res->out;
        if (!keep) {
            res->skipped += power;
            return LP_OK;
        }
    }
    if (AT(f, F_EMIT) == EMIT_FIELD) {
        lp__cvec3 E;
        double *e = (double *)&E;
        e[0] = AT(f, F_ERX), e[1] = AT(f, F_EIX);
        e[2] = AT(f, F_ERY), e[3] = AT(f, F_EIY);
        e[4] = AT(f, F_ERZ), e[5] = AT(f, F_EIZ);
        lp__exit x = {v3(AT(f, F_LX), AT(f, F_LY), AT(f, F_LZ)), origin, dir};
        lp__payload p = {pl->lambda_nm, kphi, op, pl->phase, pl->ch};
        res->out = sk->out;
        lp_status st =
            lp__emit_power(lens, res, &E, power, &x, &p, depth, kind, surface, path, err);
        sk->out = res->out;
        return st;
    }
    if (!(power > 0.0))
        return LP_OK;
    lp_out_ray *o = sk->room ? &res->rays[res->count++] : lp__result_push(res);
    if (!o)
        return lp__fail(err, LP_ERROR_NO_MEMORY, "out of memory storing outgoing rays");
    o->ray.origin = origin;
    o->ray.dir = dir;
    o->ray.lambda_nm = pl->lambda_nm;
    o->ray.intensity = power;
    o->ray.vp = v3(AT(f, F_VX), AT(f, F_VY), AT(f, F_VZ));
    o->ray.kphi = kphi;
    o->ray.op = op;
    o->ray.phase = phase;
    o->ray.ch = pl->ch;
    o->depth = depth;
    o->kind = kind;
    o->surface = surface;
    o->part = 0;
    o->path = path;
    o->waves = 0;
    sk->out += power;
    return LP_OK;
}

/* lp__lanes_emit's work once the ray is known to have entered: its
 * chain's outgoing rays and sums, with res->out kept in sk.out. */
LP__INLINE lp_status emit_chain(const lp__lanes *L, size_t j, const lp_lens *lens,
                            const lp_trace_args *a, const lp__payload *pl, sink *sk,
                            lp_error *err)
{
    lp_result *res = sk->res;
    lp_status st;
    size_t c = L->lane[j];
    int entry = (int)L->entry[c];
    int check_r = a->filter || a->flags, check_t = a->filter != NULL;
    double phase = lp__wrap_phase(pl->phase + 0.0);
    st = leave(lens, a, sk, &L->r1[0][j], pl, phase, 1, pl->kphi + (int)L->r1[F_KPHI][j],
               pl->op, LP_KIND_REFLECT, entry, 1u, check_r, err);
    if (st != LP_OK)
        return st;
    uint64_t path = 0;
    int k, staged = L->staged, absorbs = L->absorbs;
    for (k = 2; k <= staged; k++) {
        const double *f = L->node + (size_t)k * NF * NL + c;
        double end = AT(f, F_END);
        if (end == END_TRUNCATED) {
            res->truncated += AT(f, F_ENDVAL);
            break;
        }
        if (absorbs)
            res->absorbed_glass += AT(f, F_ABS);
        if (end == END_RIM) {
            res->absorbed_rim += AT(f, F_ENDVAL);
            break;
        }
        if (AT(f, F_EMIT) != EMIT_NONE) {
            int surface = (int)AT(f, F_SURF);
            int reflect = surface == entry;
            st = leave(lens, a, sk, f, pl, phase, k, pl->kphi + (int)AT(f, F_KPHI), AT(f, F_OP),
                       reflect ? LP_KIND_REFLECT : LP_KIND_TRANSMIT, surface, path,
                       reflect ? check_r : check_t, err);
            if (st != LP_OK)
                return st;
        }
        path |= (uint64_t)1 << (k - 1);
    }
    if (k > staged)
        res->truncated += L->final[c]; /* at the depth */
    res->nodes += (size_t)(k - 1);
    return LP_OK;
}

lp_status lp__lanes_emit(const lp__lanes *L, size_t j, const lp_lens *lens,
                         const lp_trace_args *a, double intensity, const lp__payload *pl,
                         lp_result *res, lp_error *err)
{
    if (L->ray[j] == RAY_MISS)
        return LP_OK;
    res->in += intensity;
    res->warnings |= L->warnings;
    if (L->ray[j] == RAY_RIM) {
        res->absorbed_rim += intensity;
        return LP_OK;
    }
    /* at most two rays a node (the parts of an elliptical field) */
    sink sk = {res, res->out, lp__result_reserve(res, 2 * (size_t)L->staged)};
    lp_status st = emit_chain(L, j, lens, a, pl, &sk, err);
    res->out = sk.out;
    return st;
}
