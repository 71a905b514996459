/* uniaxial.h -- plane waves at an interface between isotropic media and
 * uniaxial crystals, as pure functions (internal; tests include it).
 *
 * Units: a wave vector K is written in units of the vacuum (here: air)
 * wave number k0, so |K| = n for a real wave of index n.  Fields are
 * complex 3-vectors in the lens's local frame; H means k0 x (the magnetic
 * field in units where H = K x E), so the time-averaged Poynting vector
 * is proportional to Re(E x conj(H)) in every medium.
 *
 * A uniaxial crystal of optic axis c (unit), ordinary index n_o and
 * extraordinary index n_e has the dielectric tensor
 *     eps = n_o^2 I + (n_e^2 - n_o^2) c c^T
 * and, for a wave normal k, two modes:
 *   o: |K| = n_o, D = eps E along K x c;
 *   e: 1/|K|^2 = cos^2(psi)/n_o^2 + sin^2(psi)/n_e^2 (psi the angle of K
 *      from c), i.e. K . M K = 1 with M = I/n_e^2 + (1/n_o^2 - 1/n_e^2) c c^T,
 *      D along K x (K x c), E = eps^-1 D, energy along M K.
 * At an interface the tangential part kt of K is common to all waves
 * (phase matching); each wave's normal part q follows from its
 * dispersion relation (a quadratic for the e-wave).  The amplitudes follow
 * from the continuity of the tangential E and H: a 4x4 linear system
 * (Yeh, "Optical Waves in Layered Media"; Weidlich & Wilkie, ACM TOG
 * 27(1), 2008).  A wave whose q is complex is evanescent (total internal
 * reflection of that wave) and carries no power across the interface.
 */
#ifndef LP_UNIAXIAL_H
#define LP_UNIAXIAL_H

#include "cvec3.h"

/* A medium at one wavelength: isotropic (uniaxial == 0, index no) or a
 * uniaxial crystal. */
typedef struct lp__medium {
    int uniaxial;
    double no, ne;   /* indices; ne unused when isotropic */
    lp_vec3 c;       /* unit optic axis */
} lp__medium;

enum { LP__WAVE_S = 0, LP__WAVE_P = 1, LP__WAVE_O = 2, LP__WAVE_E = 3 };

/* One plane wave at the interface. */
typedef struct lp__wave {
    int kind;        /* LP__WAVE_*: s/p in an isotropic medium, o/e in a crystal */
    int evanescent;  /* 1 when the normal part of K is not real */
    lp__cvec3 K;     /* wave vector / k0 */
    lp__cvec3 E;     /* field of unit amplitude (a real unit vector when
                        propagating) */
    lp__cvec3 H;     /* K x E */
    lp_vec3 ray;     /* unit energy (ray) direction; 0 when evanescent */
    double flux;     /* Re(E x conj H) . m: power per unit area across the
                        interface, along the side's normal m; >= 0 */
} lp__wave;

/* Index of the e-wave along the unit wave normal k. */
double lp__e_index(const lp__medium *m, lp_vec3 k);

/* The two waves medium `med` holds at an interface whose tangential wave
 * vector is kt (real), whose energy leaves the interface into the medium
 * along the unit normal m.  t1 is the unit tangent "s" axis (m x kt
 * direction, or any tangent at normal incidence); the s/p pair of an
 * isotropic medium is E_s = t1, E_p = K x t1 / n, and a crystal's o-wave
 * falls back to t1 when K is along the optic axis (o and e degenerate).
 * w[0] is s or o, w[1] is p or e. */
void lp__medium_waves(const lp__medium *med, lp_vec3 kt, lp_vec3 m, lp_vec3 t1,
                      lp__wave w[2]);

/* A propagating wave of real wave vector K and real field e (a mode of
 * its medium, not checked) as the incident wave of an interface whose
 * normal m points away from the incident side. */
void lp__wave_incident(lp_vec3 K, lp_vec3 e, lp_vec3 m, int kind, lp__wave *w);

/* One interface crossing.  The incident wave is in medium a and meets the
 * boundary whose unit normal N points into medium b.  out[0..1] are the
 * reflected waves (in a), out[2..3] the transmitted ones (in b). */
typedef struct lp__xnode {
    lp_vec3 N;       /* unit, from a into b */
    lp_vec3 t1;      /* unit tangent s axis */
    lp_vec3 kt;      /* tangential wave vector */
    lp__wave out[4];
    lp__wave inc[2];  /* the incident medium's two waves of the incident K,
                         built in this node's frame (s/p or o/e) */
    int inc_kind;     /* LP__WAVE_S for an isotropic incident medium */
    int degenerate;   /* incident K along the optic axis: o = e */
} lp__xnode;

/* Set up the node for an incident real wave vector K_inc of kind
 * inc_kind (LP__WAVE_*; in an isotropic medium s and p alike).  hint (a
 * field direction, may be zero) fixes the s axis at normal incidence; it
 * keeps the incident frame there. */
void lp__xnode_setup(lp__xnode *x, const lp__medium *a, const lp__medium *b, int inc_kind,
                     lp_vec3 K_inc, lp_vec3 N, lp_vec3 hint);

/* Power-normalized amplitudes c[0..3] of the four outgoing waves for an
 * incident wave `inc` of unit power: a beam of complex amplitude A in the
 * incident wave leaves as beams of amplitude c[j] A along out[j].E (zero
 * for an evanescent wave), and sum |c[j]|^2 = 1 (power conservation).
 * Returns 0, or -1 when the incident wave carries no power across the
 * boundary (exactly grazing) or the system is singular. */
int lp__xnode_solve(const lp__xnode *x, const lp__wave *inc, double complex c[4]);

/* Carry a beam of complex field E (power |E|^2) across the node: out[j]
 * is the field of the beam leaving along out[j] (zero when evanescent).
 * The incident field is taken on the node's own incident waves: its s
 * and p parts, or (crystal) its projection on the wave of its kind, on
 * both when o and e are degenerate.  Returns 0, or -1 as
 * lp__xnode_solve. */
int lp__xnode_apply(const lp__xnode *x, const lp__cvec3 *E, lp__cvec3 out[4]);

#endif
