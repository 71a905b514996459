/* test_uniaxial.c -- plane waves at interfaces with a uniaxial crystal
 * (the pure functions of uniaxial.h) against closed forms written here.
 *
 *   index ellipsoid  a wave normal at angle psi from the optic axis has
 *                    o-index n_o and e-index n(psi),
 *                    1/n^2 = cos^2 psi/n_o^2 + sin^2 psi/n_e^2;
 *                    the e-ray lies in the plane (k, c) at psi_r from c,
 *                    tan psi_r = (n_o^2/n_e^2) tan psi; the o-field is
 *                    perpendicular to k and c, D = eps E of the e-wave is
 *                    perpendicular to k, E to the ray.
 *   phase matching   every wave has the incident tangential K.
 *   energy           the powers of the four outgoing waves sum to the
 *                    incident power (power-normalized amplitudes).
 *   isotropic limit  n_o = n_e = n: the fields are the Fresnel ones,
 *                    rs = (n1 ci - n2 ct)/(n1 ci + n2 ct),
 *                    rp = (n2 ci - n1 ct)/(n2 ci + n1 ct), p = k x s,
 *                    ts = 2 n1 ci/(n1 ci + n2 ct) sqrt(n2 ct/(n1 ci)),
 *                    tp = 2 n1 ci/(n2 ci + n1 ct) sqrt(n2 ct/(n1 ci)).
 *   c-cut plate      axis along the normal, from air at sin(theta) = s:
 *                    s light stays o, p light becomes e, with
 *                    r_o = (cos th - sqrt(n_o^2 - s^2))/(cos th + sqrt(n_o^2 - s^2)),
 *                    r_e = (n_o n_e cos th - sqrt(n_e^2 - s^2))/(n_o n_e cos th + sqrt(n_e^2 - s^2)),
 *                    normal wave vectors sqrt(n_o^2 - s^2) and
 *                    (n_o/n_e) sqrt(n_e^2 - s^2).
 *   a-cut plate      axis in the surface, normal incidence: the field
 *                    splits by projection, E_o = (E . o) o t(n_o),
 *                    E_e = (E . c) c t(n_e), t(n) = 2 sqrt(n)/(1 + n).
 *   TIR              beyond a wave's critical angle it carries nothing,
 *                    and the rest still conserves power.
 */
#include <complex.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "check.h"
#include "uniaxial.h"

#define PI 3.14159265358979323846

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static double urand(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}
static lp_vec3 rand_unit(void)
{
    for (;;) {
        lp_vec3 v = v3(2 * urand() - 1, 2 * urand() - 1, 2 * urand() - 1);
        double l = v3_len(v);
        if (l > 0.1 && l < 1.0)
            return v3_scale(v, 1.0 / l);
    }
}

static lp__medium iso(double n)
{
    lp__medium m = {0, n, n, {0, 0, 1}};
    return m;
}
static lp__medium crystal(double no, double ne, lp_vec3 c)
{
    lp__medium m = {1, no, ne, v3_normalize(c)};
    return m;
}

static double cdist(lp__cvec3 a, lp__cvec3 b)
{
    lp__cvec3 d = {a.x - b.x, a.y - b.y, a.z - b.z};
    return sqrt(cv3_norm2(d));
}

/* The incident wave of direction d in medium a (its mode `which`). */
static void incident(const lp__medium *a, lp_vec3 d, lp_vec3 N, int which, lp_vec3 t1hint,
                     lp__wave *inc)
{
    /* Build the modes of medium a for the wave going INTO the boundary:
     * tangential part of n d, energy along +N. */
    lp__wave w[2];
    lp_vec3 kt = v3_sub(d, v3_scale(N, v3_dot(d, N)));
    /* scale kt so that the chosen mode's normal part is along d: for an
     * isotropic medium and the o-wave, K = n d. */
    double n = which == 1 && a->uniaxial ? lp__e_index(a, d) : a->no;
    kt = v3_scale(kt, n);
    lp_vec3 t1 = v3_cross(N, kt);
    t1 = v3_len(t1) > 1e-12 ? v3_normalize(t1) : t1hint;
    lp__medium_waves(a, kt, N, t1, w);
    *inc = w[which];
}

/* ---------------------------------------------------------------- */

static void test_index_ellipsoid(void)
{
    const double no = 1.6584, ne = 1.4864;
    for (int trial = 0; trial < 2000; trial++) {
        double a = trial < 1000 ? no : 1.5443, b = trial < 1000 ? ne : 1.5534;
        lp__medium X = crystal(a, b, rand_unit());
        lp_vec3 N = rand_unit();
        lp_vec3 d = rand_unit();
        if (v3_dot(d, N) < 0.05)
            d = v3_normalize(v3_add(d, v3_scale(N, 1.05 - v3_dot(d, N))));
        double kmag = 1.2 * urand() * fmin(a, b);
        lp_vec3 kt = v3_scale(v3_sub(d, v3_scale(N, v3_dot(d, N))), 1.0);
        double l = v3_len(kt);
        kt = l > 0 ? v3_scale(kt, kmag / l) : kt;
        lp_vec3 t1 = l > 0 ? v3_normalize(v3_cross(N, kt)) : v3_any_perp(N);
        lp__wave w[2];
        lp__medium_waves(&X, kt, N, t1, w);
        for (int j = 0; j < 2; j++) {
            if (w[j].evanescent)
                continue;
            lp_vec3 K = cv3_re(w[j].K);
            lp_vec3 Kt = v3_sub(K, v3_scale(N, v3_dot(K, N)));
            CHECK_ABS(v3_len(v3_sub(Kt, kt)), 0.0, 1e-14, "phase matching %d", trial);
            double k = v3_len(K);
            lp_vec3 kh = v3_scale(K, 1.0 / k);
            double cpsi = v3_dot(kh, X.c), spsi2 = 1.0 - cpsi * cpsi;
            lp_vec3 E = cv3_re(w[j].E);
            CHECK_ABS(v3_len(cv3_im(w[j].E)), 0.0, 1e-15, "real field %d", trial);
            CHECK_REL(v3_len(E), 1.0, 1e-15, "unit field %d", trial);
            CHECK(v3_dot(w[j].ray, N) >= 0.0, "energy leaves the interface %d", trial);
            if (j == 0) {
                CHECK_REL(k, a, 1e-14, "o index %d", trial);
                CHECK_ABS(v3_dot(E, X.c), 0.0, 1e-12, "o field perp c %d", trial);
                CHECK_ABS(v3_dot(E, kh), 0.0, 1e-14, "o field perp k %d", trial);
                CHECK_ABS(v3_len(v3_cross(w[j].ray, kh)), 0.0, 1e-14, "o ray along k %d",
                          trial);
            } else {
                double want = 1.0 / sqrt(cpsi * cpsi / (a * a) + spsi2 / (b * b));
                CHECK_REL(k, want, 1e-14, "e index %d", trial);
                /* D = eps E perpendicular to k */
                lp_vec3 D = v3_add(v3_scale(E, a * a),
                                   v3_scale(X.c, (b * b - a * a) * v3_dot(E, X.c)));
                CHECK_ABS(v3_dot(D, kh) / v3_len(D), 0.0, 1e-14, "e D perp k %d", trial);
                CHECK_ABS(v3_dot(E, w[j].ray), 0.0, 1e-14, "e E perp ray %d", trial);
                /* ray in the plane (k, c) at psi_r from c */
                lp_vec3 pl = v3_cross(kh, X.c);
                if (v3_len(pl) > 1e-6) {
                    CHECK_ABS(v3_dot(w[j].ray, v3_normalize(pl)), 0.0, 1e-13,
                              "e ray in plane (k,c) %d", trial);
                    double psi = acos(fabs(cpsi));
                    double psir = acos(fabs(v3_dot(w[j].ray, X.c)));
                    if (psi > 1e-3 && psi < PI / 2 - 1e-3)
                        CHECK_REL(tan(psir), (a * a) / (b * b) * tan(psi), 1e-11,
                                  "walk-off %d", trial);
                }
            }
        }
    }
}

/* Random node set-ups of every kind: powers sum to 1. */
static void test_energy(void)
{
    const double no = 1.6584, ne = 1.4864;
    int tir_seen = 0, one_wave_tir = 0;
    double worst = 0.0;
    for (int trial = 0; trial < 20000; trial++) {
        int kind = trial % 4; /* 0 iso->X, 1 X->iso, 2 X->iso (e incident), 3 iso(2.0)->X */
        lp__medium X = crystal(trial & 8 ? 1.5443 : no, trial & 8 ? 1.5534 : ne, rand_unit());
        lp__medium A = iso(kind == 3 ? 2.0 : 1.0 + 0.5 * urand());
        const lp__medium *a = kind == 1 || kind == 2 ? &X : &A;
        const lp__medium *b = kind == 1 || kind == 2 ? &A : &X;
        lp_vec3 N = rand_unit(), d = rand_unit();
        if (v3_dot(d, N) < 0.0)
            d = v3_neg(d);
        if (v3_dot(d, N) < 1e-6)
            continue;
        for (int which = 0; which < 2; which++) {
            if (kind == 2 && which == 0)
                continue;
            if (kind == 1 && which == 1)
                continue;
            lp__wave inc;
            incident(a, d, N, which, v3_any_perp(N), &inc);
            if (inc.evanescent || !(inc.flux > 0))
                continue;
            lp__xnode x;
            lp__xnode_setup(&x, a, b, inc.kind, cv3_re(inc.K), N, cv3_re(inc.E));
            /* a beam of unit power: any field across d in an isotropic
             * medium, the mode's own field in the crystal */
            lp__cvec3 E = inc.E;
            if (!a->uniaxial) {
                double th = 2 * PI * urand(), ph = 2 * PI * urand();
                lp_vec3 s = v3_normalize(v3_cross(N, d)), p = v3_cross(d, s);
                E = cv3_combine(cos(th), s, sin(th) * cexp(I * ph), p);
            }
            lp__cvec3 out[4];
            int rc = lp__xnode_apply(&x, &E, out);
            CHECK(rc == 0, "solve %d", trial);
            double P = 0;
            for (int j = 0; j < 4; j++)
                P += cv3_norm2(out[j]);
            /* Near grazing incidence the field's tangential parts, which
             * the boundary conditions see, are ~cos i of its size, so
             * its rounding weighs 1/cos i more: 1e-12 down to cos i =
             * 0.02, 1e-11 below.  Measured worst: 2.3e-12 at cos i =
             * 5.3e-3, 5.7e-12 at cos i = 9.5e-6; above cos i = 0.02 it
             * is printed below (9.7e-13, an e-wave near its critical angle). */
            double ci = v3_dot(d, N);
            CHECK_ABS(P, 1.0, ci >= 0.02 ? 1e-12 : 1e-11, "energy trial %d kind %d cos %g",
                      trial, kind, ci);
            if (ci >= 0.02 && fabs(P - 1.0) > worst)
                worst = fabs(P - 1.0);
            if (x.out[2].evanescent && x.out[3].evanescent)
                tir_seen++;
            if (x.out[2].evanescent != x.out[3].evanescent ||
                x.out[0].evanescent != x.out[1].evanescent)
                one_wave_tir++;
            for (int j = 0; j < 4; j++)
                if (x.out[j].evanescent)
                    CHECK(cv3_norm2(out[j]) == 0.0, "evanescent wave carries nothing");
        }
    }
    printf("energy: worst |P - 1| at cos i >= 0.02: %.3g\n", worst);
    CHECK(tir_seen > 100, "total internal reflection sampled (%d)", tir_seen);
    CHECK(one_wave_tir > 100, "TIR of one wave only sampled (%d)", one_wave_tir);
}

/* n_o = n_e: the isotropic Fresnel fields. */
static void test_isotropic_limit(void)
{
    for (int trial = 0; trial < 3000; trial++) {
        double n1 = 1.0 + urand(), n2 = 1.0 + urand();
        lp__medium A = iso(n1);
        lp__medium X = crystal(n2, n2, rand_unit());
        int inside = trial & 1; /* light from the crystal side */
        const lp__medium *a = inside ? &X : &A, *b = inside ? &A : &X;
        double na = inside ? n2 : n1, nb = inside ? n1 : n2;
        lp_vec3 N = rand_unit(), d = rand_unit();
        if (v3_dot(d, N) < 0.0)
            d = v3_neg(d);
        double ci = v3_dot(d, N);
        if (ci < 1e-3)
            continue;
        double si2 = 1 - ci * ci, ct2 = 1 - (na / nb) * (na / nb) * si2;
        lp_vec3 s = v3_normalize(v3_cross(N, d));
        lp_vec3 r = v3_sub(d, v3_scale(N, 2 * ci));
        lp_vec3 pin = v3_cross(d, s), pr = v3_cross(r, s);
        /* an incident field E = Es s + Ep p_in of unit power */
        double th = 2 * PI * urand();
        double Es = cos(th), Ep = sin(th);
        lp_vec3 E = v3_add(v3_scale(s, Es), v3_scale(pin, Ep));
        lp__xnode x;
        lp__xnode_setup(&x, a, b, LP__WAVE_O, v3_scale(d, na), N, E);
        lp__cvec3 Ein = cv3_real(E, 1.0), out[4];
        CHECK(lp__xnode_apply(&x, &Ein, out) == 0, "solve");
        lp__cvec3 R = {out[0].x + out[1].x, out[0].y + out[1].y, out[0].z + out[1].z};
        lp__cvec3 T = {out[2].x + out[3].x, out[2].y + out[3].y, out[2].z + out[3].z};
        double complex rs, rp, ts = 0, tp = 0;
        if (ct2 >= 0) {
            double ct = sqrt(ct2);
            rs = (na * ci - nb * ct) / (na * ci + nb * ct);
            rp = (nb * ci - na * ct) / (nb * ci + na * ct);
            double g = sqrt(nb * ct / (na * ci));
            ts = 2 * na * ci / (na * ci + nb * ct) * g;
            tp = 2 * na * ci / (nb * ci + na * ct) * g;
        } else {
            double complex q = I * sqrt(na * na * si2 - nb * nb);
            rs = (na * ci - q) / (na * ci + q);
            rp = (nb * nb * ci - na * q) / (nb * nb * ci + na * q);
        }
        lp__cvec3 Rw = cv3_combine(rs * Es, s, rp * Ep, pr);
        lp_vec3 t = ct2 >= 0 ? v3_normalize(v3_add(v3_scale(d, na / nb),
                                                   v3_scale(N, sqrt(ct2) - na / nb * ci)))
                             : N;
        lp__cvec3 Tw = cv3_combine(ts * Es, s, tp * Ep, v3_cross(t, s));
        /* measured worst: 4e-15 */
        CHECK_ABS(cdist(R, Rw), 0.0, 1e-12, "isotropic limit reflected %d ci %g ct2 %g in %d", trial, ci, ct2, inside);
        CHECK_ABS(cdist(T, Tw), 0.0, 1e-12, "isotropic limit transmitted %d", trial);
    }
}

/* c-cut: axis along the normal. */
static void test_c_cut(void)
{
    const double no = 1.6584, ne = 1.4864;
    lp__medium A = iso(1.0), X = crystal(no, ne, v3(0, 0, 1));
    lp_vec3 N = v3(0, 0, 1);
    for (int i = 0; i <= 89; i++) {
        double th = i * PI / 180, s = sin(th), ct = cos(th);
        lp_vec3 d = v3(s, 0, ct);
        lp_vec3 sax = v3(0, 1, 0), pax = v3_cross(d, sax);
        lp__xnode x;
        lp__xnode_setup(&x, &A, &X, LP__WAVE_S, d, N, sax);
        double kzo = sqrt(no * no - s * s), kze = no / ne * sqrt(ne * ne - s * s);
        CHECK_REL(creal(x.out[2].K.z), kzo, 1e-14, "o normal K at %d deg", i);
        CHECK_REL(creal(x.out[3].K.z), kze, 1e-14, "e normal K at %d deg", i);
        double ro = (ct - kzo) / (ct + kzo);
        double re = (no * ne * ct - sqrt(ne * ne - s * s)) / (no * ne * ct + sqrt(ne * ne - s * s));
        for (int pol = 0; pol < 2; pol++) {
            lp__wave inc;
            lp__wave_incident(d, pol ? pax : sax, N, pol, &inc);
            double complex c[4];
            CHECK(lp__xnode_solve(&x, &inc, c) == 0, "solve");
            if (pol == 0) {
                CHECK_ABS(cabs(c[3]), 0.0, 1e-14, "s light gives no e wave (%d deg)", i);
                CHECK_ABS(cabs(c[1]), 0.0, 1e-14, "s light reflects no p (%d deg)", i);
                CHECK_ABS(creal(c[0] * cv3_dot_real(x.out[0].E, sax)), ro, 1e-14,
                          "r_o at %d deg", i);
                CHECK_ABS(creal(c[0] * c[0]) + creal(c[2] * conj(c[2])), 1.0, 1e-14,
                          "o energy at %d deg", i);
            } else {
                lp_vec3 r = v3(s, 0, -ct);
                CHECK_ABS(cabs(c[2]), 0.0, 1e-14, "p light gives no o wave (%d deg)", i);
                CHECK_ABS(creal(c[1] * cv3_dot_real(x.out[1].E, v3_cross(r, sax))), re, 1e-14,
                          "r_e at %d deg", i);
            }
        }
    }
}

/* a-cut: axis in the surface at azimuth phi, normal incidence. */
static void test_a_cut(void)
{
    const double no = 1.6584, ne = 1.4864;
    lp__medium A = iso(1.0);
    lp_vec3 N = v3(0, 0, 1);
    for (int i = 0; i < 36; i++) {
        double phi = i * 5 * PI / 180;
        lp_vec3 c = v3(cos(phi), sin(phi), 0);
        lp__medium X = crystal(no, ne, c);
        lp_vec3 E = v3(1, 0, 0);
        lp__wave inc;
        lp__wave_incident(v3(0, 0, 1), E, N, LP__WAVE_S, &inc);
        lp__xnode x;
        lp__xnode_setup(&x, &A, &X, LP__WAVE_S, v3(0, 0, 1), N, E);
        double complex cc[4];
        CHECK(lp__xnode_solve(&x, &inc, cc) == 0, "solve");
        lp_vec3 o = v3(-sin(phi), cos(phi), 0);
        double to = 2 * sqrt(no) / (1 + no), te = 2 * sqrt(ne) / (1 + ne);
        lp__cvec3 Eo = cv3_scale(x.out[2].E, cc[2]), Ee = cv3_scale(x.out[3].E, cc[3]);
        lp__cvec3 Wo = cv3_real(o, v3_dot(E, o) * to), We = cv3_real(c, v3_dot(E, c) * te);
        CHECK_ABS(cdist(Eo, Wo), 0.0, 1e-14, "a-cut o by projection at %d deg", i * 5);
        CHECK_ABS(cdist(Ee, We), 0.0, 1e-14, "a-cut e by projection at %d deg", i * 5);
        /* and out again at normal incidence: each wave transmits t(n)^2
         * of its power and reflects the rest into itself */
        for (int w = 0; w < 2; w++) {
            double n = w ? ne : no;
            lp_vec3 e = w ? c : o;
            lp__xnode y;
            lp__xnode_setup(&y, &X, &A, w ? LP__WAVE_E : LP__WAVE_O, v3(0, 0, n), N, e);
            lp__cvec3 in = cv3_real(e, 1.0), out[4];
            CHECK(lp__xnode_apply(&y, &in, out) == 0, "solve");
            double T = cv3_norm2(out[2]) + cv3_norm2(out[3]);
            double R = ((n - 1) / (n + 1)) * ((n - 1) / (n + 1));
            CHECK_ABS(T, 1 - R, 1e-14, "a-cut exit T of the %c wave", w ? 'e' : 'o');
            CHECK_ABS(cv3_norm2(out[w]), R, 1e-14, "a-cut exit R of the %c wave",
                      w ? 'e' : 'o');
        }
    }
}

/* A wave with its own total reflection: from n = 2 into calcite with
 * n_o > |kt| > n_e-ish (the e-wave with K in the surface plane of a c-cut
 * has index n_o; take the axis in the surface across the plane of
 * incidence: e index n_e for K in the plane), and full TIR to air. */
static void test_tir(void)
{
    const double no = 1.6584, ne = 1.4864;
    lp__medium G = iso(2.0), X = crystal(no, ne, v3(1, 0, 0));
    lp_vec3 N = v3(0, 0, 1);
    double s = 1.55 / 2.0, ct = sqrt(1 - s * s); /* |kt| = 1.55: between n_e and n_o */
    lp_vec3 d = v3(0, s, ct);
    lp__xnode x;
    lp__xnode_setup(&x, &G, &X, LP__WAVE_S, v3_scale(d, 2.0), N, v3(1, 0, 0));
    CHECK(!x.out[2].evanescent, "o wave propagates");
    CHECK(x.out[3].evanescent, "e wave is totally reflected");
    for (int pol = 0; pol < 2; pol++) {
        lp__wave inc;
        lp_vec3 e = pol ? v3_cross(d, v3(-1, 0, 0)) : v3(-1, 0, 0);
        lp__wave_incident(v3_scale(d, 2.0), e, N, pol, &inc);
        double complex c[4];
        CHECK(lp__xnode_solve(&x, &inc, c) == 0, "solve");
        double P = 0;
        for (int j = 0; j < 4; j++)
            P += creal(c[j] * conj(c[j]));
        CHECK_ABS(P, 1.0, 1e-14, "energy with one wave in TIR (pol %d)", pol);
        /* the axis is along s: s light is e light, p light is o light */
        if (pol == 0)
            CHECK_ABS(cabs(c[0]), 1.0, 1e-14, "s (e) light totally reflected");
    }
    /* calcite to air at 50 degrees: everything reflects, into o and e */
    lp__medium A = iso(1.0), Y = crystal(no, ne, v3_normalize(v3(1, 1, 1)));
    d = v3(0, sin(50 * PI / 180), cos(50 * PI / 180));
    lp__wave w[2];
    lp_vec3 kt = v3_scale(v3(0, d.y, 0), no);
    lp__medium_waves(&Y, kt, N, v3(-1, 0, 0), w);
    lp__xnode_setup(&x, &Y, &A, LP__WAVE_O, cv3_re(w[0].K), N, v3(1, 0, 0));
    CHECK(x.out[2].evanescent && x.out[3].evanescent, "TIR into air");
    double complex c[4];
    CHECK(lp__xnode_solve(&x, &w[0], c) == 0, "solve");
    double Pr = creal(c[0] * conj(c[0])) + creal(c[1] * conj(c[1]));
    CHECK_ABS(Pr, 1.0, 1e-14, "TIR: o and e reflections carry everything");
    CHECK(cabs(c[1]) > 0.05, "TIR inside the crystal converts o into e (%g)", cabs(c[1]));
}

int main(void)
{
    test_index_ellipsoid();
    test_energy();
    test_isotropic_limit();
    test_c_cut();
    test_a_cut();
    test_tir();
    return check_finish("test_uniaxial");
}
