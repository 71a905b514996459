/* packet.c -- the lane classes of spectral packets (see packet.h). */
#include <math.h>
#include <stdlib.h>

#include "packet.h"

struct rs_lane_classes {
    int n_lanes;
    size_t n_objects;
    int *cls;   /* [object * n_lanes + lane]; NULL rows for non-lenses */
    unsigned char *is_lens;
};

typedef struct optics_key {
    double n_glass, n_medium, alpha;
    int covers;
} optics_key;

static optics_key key_at(const lp_lens_desc *d, double lambda)
{
    optics_key k;
    k.n_glass = lp_glass_index(&d->glass, lambda);
    k.n_medium = lp_glass_index(&d->medium, lambda);
    k.alpha = lp_glass_absorption(&d->glass, lambda);
    k.covers = lp_glass_covers(&d->glass, lambda) + 2 * lp_glass_covers(&d->medium, lambda);
    return k;
}

/* Equal optics; a NaN equals nothing (such a lane stays alone). */
static int same(const optics_key *a, const optics_key *b)
{
    return a->n_glass == b->n_glass && a->n_medium == b->n_medium && a->alpha == b->alpha &&
           a->covers == b->covers;
}

static int has_nan(const optics_key *k)
{
    return k->n_glass != k->n_glass || k->n_medium != k->n_medium || k->alpha != k->alpha;
}

typedef struct keyed {
    optics_key k;
    int lane;
} keyed;

static int cmp_d(double a, double b)
{
    return (a > b) - (a < b);
}

/* An order in which equal optics are neighbours, each run by lane. */
static int cmp_keyed(const void *pa, const void *pb)
{
    const keyed *a = pa, *b = pb;
    int c = cmp_d(a->k.n_glass, b->k.n_glass);
    if (!c)
        c = cmp_d(a->k.n_medium, b->k.n_medium);
    if (!c)
        c = cmp_d(a->k.alpha, b->k.alpha);
    if (!c)
        c = (a->k.covers > b->k.covers) - (a->k.covers < b->k.covers);
    return c ? c : (a->lane > b->lane) - (a->lane < b->lane);
}

int rs_lane_classes_create(const rs_scene *scene, const double *lambda, int n_lanes,
                           rs_lane_classes **out)
{
    rs_lane_classes *c = calloc(1, sizeof *c);
    keyed *keys = calloc((size_t)(n_lanes > 0 ? n_lanes : 1), sizeof *keys);
    size_t n = scene->n_objects;
    *out = NULL;
    if (!c || !keys)
        goto fail;
    c->n_lanes = n_lanes;
    c->n_objects = n;
    c->cls = calloc((n ? n : 1) * (size_t)(n_lanes > 0 ? n_lanes : 1), sizeof *c->cls);
    c->is_lens = calloc(n ? n : 1, 1);
    if (!c->cls || !c->is_lens)
        goto fail;
    for (size_t i = 0; i < n; i++) {
        const rs_object *o = &scene->objects[i];
        int *row = &c->cls[i * (size_t)n_lanes];
        c->is_lens[i] = o->type == RS_OBJ_LENS && o->lens != NULL;
        for (int k = 0; k < n_lanes; k++)
            row[k] = k;
        if (!c->is_lens[i])
            continue;
        lp_lens_desc d;
        lp_lens_get_desc(o->lens, &d);
        if (d.uniaxial)
            continue; /* a crystal's o and e indices: no sharing */
        /* Each lane's class is the first lane of equal optics: sorted by
         * optics, then by lane, each run's first (n log n: a dispersive
         * glass has a class per lane, and comparing each lane with every
         * class before it took 1.2e9 instructions at 16384 lanes). */
        int m = 0;
        for (int k = 0; k < n_lanes; k++) {
            keys[m].k = key_at(&d, lambda[k]);
            keys[m].lane = k;
            m += !has_nan(&keys[m].k); /* a NaN lane stays alone */
        }
        qsort(keys, (size_t)m, sizeof *keys, cmp_keyed);
        for (int r = 0; r < m;) {
            int e = r + 1;
            while (e < m && same(&keys[e].k, &keys[r].k))
                e++;
            for (int q = r + 1; q < e; q++)
                row[keys[q].lane] = keys[r].lane;
            r = e;
        }
    }
    free(keys);
    *out = c;
    return 0;
fail:
    free(keys);
    rs_lane_classes_destroy(c);
    return -1;
}

void rs_lane_classes_destroy(rs_lane_classes *c)
{
    if (!c)
        return;
    free(c->cls);
    free(c->is_lens);
    free(c);
}

int rs_lane_class(const rs_lane_classes *c, int object, int lane)
{
    if (object < 0 || (size_t)object >= c->n_objects || lane < 0 || lane >= c->n_lanes)
        return lane;
    return c->cls[(size_t)object * (size_t)c->n_lanes + (size_t)lane];
}

int rs_packet_split(const rs_lane_classes *c, int object, const int *lane, int n, int *at,
                    int *pos, int *sub, int *slot)
{
    /* rs_lane_class's look-ups, with the object's row found once */
    const int *row = object >= 0 && (size_t)object < c->n_objects
                         ? &c->cls[(size_t)object * (size_t)c->n_lanes]
                         : NULL;
    int nl = c->n_lanes, ns = 0;
    for (int k = 0; k < n; k++) {
        int l = lane[k];
        int cls = row && l >= 0 && l < nl ? row[l] : l;
        if (cls < 0 || cls >= nl) { /* not a lane: alone (no slot) */
            at[ns] = 0;
            sub[k] = ns++;
            continue;
        }
        if (slot[cls] < 0) {
            at[ns] = 0;
            slot[cls] = ns++;
        }
        sub[k] = slot[cls];
    }
    /* at[s]: sub-packet s's size, then where it starts */
    for (int k = 0; k < n; k++)
        at[sub[k]]++;
    for (int s = 0, start = 0; s <= ns; s++) {
        int size = s < ns ? at[s] : 0;
        at[s] = start;
        start += size;
    }
    for (int k = 0; k < n; k++) {
        int l = lane[k];
        int cls = row && l >= 0 && l < nl ? row[l] : l;
        if (cls >= 0 && cls < nl)
            slot[cls] = -1;
    }
    /* the members in order, each sub-packet filled from its start */
    for (int k = 0; k < n; k++)
        pos[at[sub[k]]++] = k;
    for (int s = ns; s > 0; s--) /* at[s] was moved to the end of s: back */
        at[s] = at[s - 1];
    at[0] = 0;
    return ns;
}
