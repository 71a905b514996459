/* uniaxial.c -- plane waves in isotropic media and uniaxial crystals at
 * one interface, and their amplitudes (see uniaxial.h for the physics).
 *
 * Every wave is built from the common tangential wave vector kt and its
 * own normal component q along the side's normal m: K = kt + q m.
 *   isotropic, o-wave:  q^2 = n^2 - |kt|^2
 *   e-wave:             (kt + q m) . M (kt + q m) = 1, i.e.
 *                       A q^2 + B q + C = 0 with A = m.Mm, B = 2 kt.Mm,
 *                       C = kt.M kt - 1.
 * Of the two roots the one whose energy leaves the interface into the
 * medium is taken: (M K) . m = A q + B/2 = +sqrt(B^2 - 4AC)/2 >= 0.  When
 * the root is complex its imaginary part is taken positive, so that
 * exp(i K.r) decays away from the boundary (time dependence
 * exp(-i omega t), as in fresnel.c). */
#include <math.h>

#include "uniaxial.h"

/* Complex 3-vector algebra (bilinear: no conjugation unless named). */
static lp__cvec3 cv(double complex x, double complex y, double complex z)
{
    lp__cvec3 r = {x, y, z};
    return r;
}
static lp__cvec3 cv_from(lp_vec3 a) { return cv(a.x, a.y, a.z); }
static lp__cvec3 cv_cross(lp__cvec3 a, lp__cvec3 b)
{
    return cv(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static double complex cv_dot(lp__cvec3 a, lp__cvec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static lp__cvec3 cv_madd(lp__cvec3 a, lp__cvec3 b, double complex s)
{
    return cv(a.x + s * b.x, a.y + s * b.y, a.z + s * b.z);
}
static lp__cvec3 cv_conj(lp__cvec3 a) { return cv(conj(a.x), conj(a.y), conj(a.z)); }
static double cv_norm(lp__cvec3 a) { return sqrt(cv3_norm2(a)); }
static lp__cvec3 cv_unit(lp__cvec3 a)
{
    double l = cv_norm(a);
    return l > 0.0 ? cv3_scale(a, 1.0 / l) : a;
}
/* A unit field that is real up to one common phase, made real: a
 * propagating mode's field is linear, and the sign is fixed by its
 * largest component. */
static lp__cvec3 cv_real_unit(lp__cvec3 a)
{
    double complex big = a.x;
    if (cabs(a.y) > cabs(big))
        big = a.y;
    if (cabs(a.z) > cabs(big))
        big = a.z;
    if (big == 0.0)
        return a;
    a = cv3_scale(a, conj(big) / cabs(big));
    lp_vec3 r = v3_normalize(cv3_re(a));
    return cv_from(r);
}

/* eps^-1 v for the crystal */
static lp__cvec3 eps_inv(const lp__medium *m, lp__cvec3 v)
{
    double complex vc = cv_dot(v, cv_from(m->c));
    double b = 1.0 / (m->ne * m->ne) - 1.0 / (m->no * m->no);
    return cv_madd(cv3_scale(v, 1.0 / (m->no * m->no)), cv_from(m->c), b * vc);
}

double lp__e_index(const lp__medium *m, lp_vec3 k)
{
    double ck = v3_dot(k, m->c) / v3_len(k);
    double c2 = ck * ck, s2 = 1.0 - c2;
    return 1.0 / sqrt(c2 / (m->no * m->no) + s2 / (m->ne * m->ne));
}

/* q with q^2 = n^2 - kt2, positive real or positive imaginary. */
/* |kt|^2 = kt2_base - q_ref^2 (see waves()). */
static double complex normal_part(double n, double kt2_base, double q_ref, int *evanescent)
{
    double b = sqrt(kt2_base);
    double q2 = (n - b) * (n + b) + q_ref * q_ref;
    *evanescent = q2 < 0.0;
    return q2 >= 0.0 ? sqrt(q2) : I * sqrt(-q2);
}

/* K x v for K = kt + q m (kt tangential, m the unit normal), written so
 * that each of its tangential and normal parts is accurate to rounding
 * relative to its own size: near grazing incidence q is tiny and the
 * plain cross product would bury q (m x v) under the rounding of
 * kt x v. */
static lp__cvec3 k_cross(lp_vec3 kt, double complex q, lp_vec3 m, lp__cvec3 v)
{
    lp__cvec3 mv = cv_from(m), ktv = cv_from(kt);
    double complex vm = cv_dot(v, mv);
    lp__cvec3 vt = cv_madd(v, mv, -vm);
    double complex nrm = cv_dot(cv_cross(ktv, vt), mv);
    lp__cvec3 r = cv3_scale(mv, nrm);
    r = cv_madd(r, cv_cross(ktv, mv), vm);
    return cv_madd(r, cv_cross(mv, vt), q);
}

/* H, ray and flux of a wave whose K = kt + q m and E are set. */
static void finish_wave(lp__wave *w, lp_vec3 kt, double complex q, lp_vec3 m)
{
    w->H = k_cross(kt, q, m, w->E);
    lp__cvec3 S = cv_cross(w->E, cv_conj(w->H));
    lp_vec3 s = cv3_re(S);
    if (w->evanescent) {
        w->ray = v3(0, 0, 0);
        w->flux = 0.0;
        return;
    }
    w->ray = v3_normalize(s);
    w->flux = fmax(0.0, v3_dot(s, m));
}

void lp__wave_incident(lp_vec3 K, lp_vec3 e, lp_vec3 m, int kind, lp__wave *w)
{
    w->kind = kind;
    w->evanescent = 0;
    w->K = cv_from(K);
    w->E = cv_from(e);
    double q = v3_dot(K, m);
    finish_wave(w, v3_madd(K, m, -q), q, m);
}

static void isotropic_waves(double n, lp_vec3 kt, double kt2_base, double q_ref, lp_vec3 m,
                            lp_vec3 t1, lp__wave w[2])
{
    int ev;
    double complex q = normal_part(n, kt2_base, q_ref, &ev);
    lp__cvec3 K = cv_madd(cv_from(kt), cv_from(m), q);
    for (int j = 0; j < 2; j++) {
        w[j].kind = j == 0 ? LP__WAVE_S : LP__WAVE_P;
        w[j].evanescent = ev;
        w[j].K = K;
    }
    w[0].E = cv_from(t1);
    w[1].E = cv3_scale(k_cross(kt, q, m, cv_from(t1)), 1.0 / n);
    if (!ev)
        w[1].E = cv_real_unit(w[1].E);
    finish_wave(&w[0], kt, q, m);
    finish_wave(&w[1], kt, q, m);
}

static void crystal_waves(const lp__medium *med, lp_vec3 kt, double kt2_base, double q_ref,
                          lp_vec3 m, lp_vec3 t1, double q_known_e, int e_same,
                          lp__wave w[2])
{
    lp__cvec3 c = cv_from(med->c);

    /* o-wave */
    int ev;
    double complex q = normal_part(med->no, kt2_base, q_ref, &ev);
    lp__wave *o = &w[0];
    o->kind = LP__WAVE_O;
    o->evanescent = ev;
    o->K = cv_madd(cv_from(kt), cv_from(m), q);
    lp__cvec3 eo = k_cross(kt, q, m, c);
    /* K along c: o and e are degenerate and any pair of fields is a
     * pair of modes; t1 keeps the node's s/p frame. */
    o->E = cv_norm(eo) > 1e-9 * med->no ? cv_unit(eo) : cv_from(t1);
    if (!ev)
        o->E = cv_real_unit(o->E);
    finish_wave(o, kt, q, m);

    /* e-wave: the quadratic of the normal surface */
    double ine2 = 1.0 / (med->ne * med->ne);
    double beta = 1.0 / (med->no * med->no) - ine2;
    double mc = v3_dot(m, med->c), kc = v3_dot(kt, med->c);
    double A = ine2 + beta * mc * mc;
    double B = 2.0 * beta * kc * mc;
    double C = (kt2_base * ine2 - 1.0) + beta * kc * kc - q_ref * q_ref * ine2;
    double disc = B * B - 4.0 * A * C;
    lp__wave *e = &w[1];
    e->kind = LP__WAVE_E;
    if (q_known_e >= 0.0 && e_same) {
        /* the incident e-wave itself, of known normal part */
        q = q_known_e;
        e->evanescent = 0;
    } else if (q_known_e >= 0.0) {
        /* The e-wave reflected from an incident e-wave whose normal part
         * along -m is q_known_e: the other root, -B/A + q_known_e (the
         * sum of the roots), with no cancellation near grazing. */
        q = q_known_e - B / A;
        e->evanescent = 0;
    } else if (disc >= 0.0) {
        double sq = sqrt(disc);
        /* the root -B/2A + sq/2A, without cancellation */
        q = B > 0.0 ? 2.0 * C / (-B - sq) : (-B + sq) / (2.0 * A);
        e->evanescent = 0;
    } else {
        q = (-B + I * sqrt(-disc)) / (2.0 * A);
        e->evanescent = 1;
    }
    e->K = cv_madd(cv_from(kt), cv_from(m), q);
    /* D along K x (K x c): perpendicular to K and to the o-field of this
     * wave normal (t1 again when K is along c). */
    lp__cvec3 kc_e = k_cross(kt, q, m, c);
    lp__cvec3 D = k_cross(kt, q, m, cv_norm(kc_e) > 1e-9 * med->no ? kc_e : cv_from(t1));
    e->E = cv_unit(eps_inv(med, D));
    if (!e->evanescent)
        e->E = cv_real_unit(e->E);
    finish_wave(e, kt, q, m);
}

/* The tangential wave vector kt, and its square written as
 * kt2_base - q_ref^2: with kt2_base = n^2 of the incident wave and q_ref
 * its normal part, n'^2 - |kt|^2 = (n'^2 - n^2) + q_ref^2 has no
 * cancellation near grazing incidence (and is exact in the incident's
 * own medium).  q_known_e >= 0: the incident e-wave's normal part: the
 * e-wave is the incident one (e_same) or its reflection. */
static void waves(const lp__medium *med, lp_vec3 kt, double kt2_base, double q_ref, lp_vec3 m,
                  lp_vec3 t1, double q_known_e, int e_same, lp__wave w[2])
{
    if (med->uniaxial)
        crystal_waves(med, kt, kt2_base, q_ref, m, t1, q_known_e, e_same, w);
    else
        isotropic_waves(med->no, kt, kt2_base, q_ref, m, t1, w);
}

void lp__medium_waves(const lp__medium *med, lp_vec3 kt, lp_vec3 m, lp_vec3 t1,
                      lp__wave w[2])
{
    waves(med, kt, v3_dot(kt, kt), 0.0, m, t1, -1.0, 0, w);
}

void lp__xnode_setup(lp__xnode *x, const lp__medium *a, const lp__medium *b, int inc_kind,
                     lp_vec3 K_inc, lp_vec3 N, lp_vec3 hint)
{
    x->N = N;
    x->kt = v3_sub(K_inc, v3_scale(N, v3_dot(K_inc, N)));
    lp_vec3 s = v3_cross(N, x->kt);
    double sl = v3_len(s);
    if (sl > 1e-9 * v3_len(K_inc)) {
        x->t1 = v3_scale(s, 1.0 / sl);
    } else {
        /* Normal incidence: the s/p split is free; keep the hint's frame. */
        lp_vec3 h = v3_sub(hint, v3_scale(N, v3_dot(hint, N)));
        x->t1 = v3_dot(h, h) > 0.0 ? v3_normalize(h) : v3_any_perp(N);
        x->kt = v3(0, 0, 0);
    }
    /* The wave reflected in the incident's own mode (s/p, or o from o)
     * has exactly the mirrored normal part: no rounding of n^2 - |kt|^2,
     * which near grazing incidence would cost ~eps/cos^2. */
    double q_inc = fabs(v3_dot(K_inc, N));
    int e_inc = a->uniaxial && inc_kind == LP__WAVE_E;
    double base = e_inc ? v3_dot(K_inc, K_inc) : a->no * a->no;
    if (x->kt.x == 0.0 && x->kt.y == 0.0 && x->kt.z == 0.0)
        base = q_inc * q_inc; /* |kt|^2 = 0 exactly */
    waves(a, x->kt, base, q_inc, v3_neg(N), x->t1, e_inc ? q_inc : -1.0, 0, &x->out[0]);
    waves(b, x->kt, base, q_inc, N, x->t1, -1.0, 0, &x->out[2]);
    /* the incident waves of this frame: s/p, or o/e of the incident K */
    waves(a, x->kt, base, q_inc, N, x->t1, e_inc ? q_inc : -1.0, 1, x->inc);
    x->degenerate = a->uniaxial && (a->no == a->ne ||
                                    v3_len(v3_cross(K_inc, a->c)) <= 1e-9 * v3_len(K_inc));
    x->inc_kind = a->uniaxial ? inc_kind : LP__WAVE_S;
}

/* Tangential E and H of a wave on the basis t1, t2 = N x t1. */
static void tangential(const lp__wave *w, lp_vec3 t1, lp_vec3 t2, double complex v[4])
{
    v[0] = cv_dot(w->E, cv_from(t1));
    v[1] = cv_dot(w->E, cv_from(t2));
    v[2] = cv_dot(w->H, cv_from(t1));
    v[3] = cv_dot(w->H, cv_from(t2));
}

/* Solve the 4x4 complex system A x = b by Gaussian elimination with
 * partial pivoting; -1 when singular. */
static int solve4(double complex A[4][5], double complex x[4])
{
    for (int col = 0; col < 4; col++) {
        int piv = col;
        for (int r = col + 1; r < 4; r++)
            if (cabs(A[r][col]) > cabs(A[piv][col]))
                piv = r;
        if (!(cabs(A[piv][col]) > 0.0))
            return -1;
        if (piv != col)
            for (int k = 0; k < 5; k++) {
                double complex t = A[col][k];
                A[col][k] = A[piv][k];
                A[piv][k] = t;
            }
        for (int r = col + 1; r < 4; r++) {
            double complex f = A[r][col] / A[col][col];
            for (int k = col; k < 5; k++)
                A[r][k] -= f * A[col][k];
        }
    }
    for (int r = 3; r >= 0; r--) {
        double complex s = A[r][4];
        for (int k = r + 1; k < 4; k++)
            s -= A[r][k] * x[k];
        x[r] = s / A[r][r];
    }
    return 0;
}

int lp__xnode_solve(const lp__xnode *x, const lp__wave *inc, double complex c[4])
{
    lp_vec3 t1 = x->t1, t2 = v3_cross(x->N, x->t1);
    double complex A[4][5], v[4];
    double complex amp[4];

    if (!(inc->flux > 0.0))
        return -1;
    /* incident + reflected = transmitted, tangentially:
     * sum_trans a_j v_j - sum_refl a_j v_j = v_inc */
    for (int j = 0; j < 4; j++) {
        tangential(&x->out[j], t1, t2, v);
        for (int r = 0; r < 4; r++)
            A[r][j] = j < 2 ? -v[r] : v[r];
    }
    tangential(inc, t1, t2, v);
    for (int r = 0; r < 4; r++)
        A[r][4] = v[r];
    if (solve4(A, amp) != 0)
        return -1;
    for (int j = 0; j < 4; j++) {
        const lp__wave *w = &x->out[j];
        c[j] = w->evanescent ? 0.0 : amp[j] * sqrt(w->flux / inc->flux);
        if (!isfinite(creal(c[j])) || !isfinite(cimag(c[j])))
            return -1;
    }
    return 0;
}

int lp__xnode_apply(const lp__xnode *x, const lp__cvec3 *E, lp__cvec3 out[4])
{
    double complex c[4], A[2];
    int use[2];

    A[0] = cv_dot(*E, x->inc[0].E);
    A[1] = cv_dot(*E, x->inc[1].E);
    use[0] = x->inc_kind != LP__WAVE_E || x->degenerate;
    use[1] = x->inc_kind != LP__WAVE_O || x->degenerate;
    for (int j = 0; j < 4; j++)
        out[j] = cv3_real(v3(0, 0, 0), 0.0);
    for (int k = 0; k < 2; k++) {
        if (!use[k] || A[k] == 0.0)
            continue;
        if (lp__xnode_solve(x, &x->inc[k], c) != 0)
            return -1;
        for (int j = 0; j < 4; j++)
            if (!x->out[j].evanescent)
                out[j] = cv_madd(out[j], x->out[j].E, A[k] * c[j]);
    }
    return 0;
}
