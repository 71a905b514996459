/* coherence.c -- the common-source-point model of coherence.h. */
#include "coherence.h"

#include <math.h>
#include <stdlib.h>

#include "support/vec.h"

#define RS_COH_PI 3.14159265358979323846
#define RS_COH_LOW 0xffffffffu

long rs_wavelets_push(rs_wavelets *t, const rs_wavelet *w)
{
    if (t->n >= (size_t)RS_COH_LOW)
        return -1;
    if (t->n == t->cap) {
        size_t cap = t->cap ? 2 * t->cap : 32;
        rs_wavelet *p = realloc(t->w, cap * sizeof *p);
        if (!p)
            return -1;
        t->w = p;
        t->cap = cap;
    }
    t->w[t->n] = *w;
    return (long)t->n++;
}

void rs_wavelets_free(rs_wavelets *t)
{
    free(t->w);
    t->w = NULL;
    t->n = t->cap = 0;
}

#define RS_COH_SPLIT 0x80000000u
#define RS_COH_SOURCE 0xffffu

uint64_t rs_coherence_split(uint64_t ch, uint64_t hit, int depth, int transmit)
{
    uint64_t group = ((hit & 0xff) << 7 | (uint64_t)(depth & 0x3f) << 1 | (transmit != 0)) & 0x7fff;
    return (ch & ~(uint64_t)0xffff0000u) | RS_COH_SPLIT | group << 16;
}

/* The difference of the wavelets' optical paths from the pair's common
 * source point (coherence.h); 0 with *ok = 0 when the pair has none. */
static double wavelet_difference(const rs_wavelet *a, const rs_wavelet *b, int *ok)
{
    *ok = 1;
    if (a == b)
        return 0.0;
    if (a->emitter != b->emitter || a->finite != b->finite) {
        *ok = 0;
        return 0.0;
    }
    lp_vec3 dab = v3_sub(a->o, b->o);
    if (a->finite) {
        /* |S - o_a| - |S - o_b| = (o_a - o_b).(o_a + o_b - 2S) / (|S - o_a| + |S - o_b|),
         * S = (s_a + s_b)/2: no cancellation of the two long distances. */
        lp_vec3 s = {0.5 * (a->s.x + b->s.x), 0.5 * (a->s.y + b->s.y), 0.5 * (a->s.z + b->s.z)};
        lp_vec3 sa = v3_sub(s, a->o), sb = v3_sub(s, b->o);
        double la = sqrt(v3_dot(sa, sa)), lb = sqrt(v3_dot(sb, sb));
        if (!(la + lb > 0.0))
            return 0.0;
        lp_vec3 m = {-(sa.x + sb.x), -(sa.y + sb.y), -(sa.z + sb.z)}; /* o_a + o_b - 2S */
        return v3_dot(dab, m) / (la + lb);
    }
    lp_vec3 u = {a->d.x + b->d.x, a->d.y + b->d.y, a->d.z + b->d.z};
    double lu = sqrt(v3_dot(u, u));
    if (!(lu > 1e-9)) { /* opposite directions: no common point at infinity */
        *ok = 0;
        return 0.0;
    }
    return -v3_dot(u, dab) / lu;
}

double rs_coherent_power(const lp_ray *const *r, const double *I, size_t n, const rs_wavelets *t,
                         const unsigned char *coherent, const double *coherence,
                         int n_sources, double lambda_nm)
{
    double total = 0.0;
    double k0 = 2.0 * RS_COH_PI / (lambda_nm * 1e-6);

    for (size_t i = 0; i < n; i++) {
        const lp_ray *a = r[i];
        total += I[i];
        uint64_t ca = a->ch & RS_COH_LOW, src = (ca & RS_COH_SOURCE) / 2, ia = a->ch >> 32;
        int split = (ca & RS_COH_SPLIT) != 0;
        if (src >= (uint64_t)n_sources || !(coherent[src] || split) || I[i] == 0.0 ||
            ia >= t->n)
            continue;
        double lc = coherent[src] ? coherence[src] : 0.0;
        for (size_t j = i + 1; j < n; j++) {
            const lp_ray *b = r[j];
            uint64_t ib = b->ch >> 32;
            if ((b->ch & RS_COH_LOW) != ca || I[j] == 0.0 || ib >= t->n)
                continue;
            int ok;
            double dop = a->op - b->op + wavelet_difference(&t->w[ia], &t->w[ib], &ok);
            if (!ok)
                continue;
            double gamma = lc > 0.0 ? exp(-(dop / lc) * (dop / lc)) : 1.0;
            if (gamma < 1e-12)
                continue;
            double dphi = k0 * dop - RS_COH_PI * (a->kphi - b->kphi) + (a->phase - b->phase);
            double vv = v3_dot(a->vp, b->vp);
            total += 2.0 * gamma * sqrt(I[i] * I[j]) * vv * cos(dphi);
        }
    }
    return total > 0.0 ? total : 0.0;
}
