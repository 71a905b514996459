/* test_batch.c -- lp_trace_forward_soa, the batch entry point of many rays
 * of one wavelength given as arrays.
 *
 * identity   For placed and tilted lenses of every kind (biconvex
 *            catalog glass with absorption, meniscus, flat plate,
 *            conical rim, knife edge, a lens in a denser medium, one
 *            index-matched to its medium, a uniaxial crystal), every mode, depths 1, 5 and 20, flags, a
 *            filter and min_weight: random rays -- hits, rays grazing the
 *            lens's bounding sphere, rays from the far side, rays starting
 *            on the lens (its own outgoing rays fed back), rays that meet
 *            the rim, rays through a cap's exact edge circle (where the
 *            cap's hit and the rim's tie), steep rays whose fields turn
 *            elliptical by total internal reflection and go on, rays
 *            along the axis (normal incidence), zero intensities, phases
 *            far outside [-pi, pi], all shuffled so that every group of
 *            the lane engine mixes them -- are traced by the batch and by lp_trace_forward_many
 *            on the same rays as lp_ray records, and by lp_trace_forward
 *            one ray at a time; so are groups of 1 to 200 rays from
 *            anywhere in them.  Every outgoing ray, every offset and every
 *            bookkeeping sum must be identical bit for bit (compared as
 *            bytes).  The contract is exactness, so the tolerance is 0.
 * closed     A flat plate of index n = 1.5 in air at normal incidence,
 *            traced by the batch: the depth-1 reflection carries
 *            R = ((n-1)/(n+1))^2 = 0.04 and the depth-2 transmission
 *            (1-R)^2, for 1000 rays across the aperture at once.
 *            Tolerance 4e-15 relative (measured 1.57e-15: r = 0.2 and
 *            the field's s/p components are rounded, squared and summed,
 *            about seven roundings of 1.1e-16 each).
 * errors     NULL arguments and arrays, a bad wavelength (also with no
 *            rays), an invalid ray k (its index in the message, the rays
 *            before it kept, as lp_trace_forward_many), NULL optional
 *            arrays standing for 0, and n = 0.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "splitmix.h"
#include "same_bits.h"
#include "lensprim.h"

#define PI 3.14159265358979323846
#define MAX_RAYS 4096

static uint64_t rng = 0x7e57ba7c4ull;
static double uniform(void)
{
    return splitmix_uniform(&rng);
}

static lp_vec3 vec(double x, double y, double z)
{
    lp_vec3 v = {x, y, z};
    return v;
}

/* Arrays of rays, both as a structure of arrays and as records. */
typedef struct rays {
    size_t n;
    double ox[MAX_RAYS], oy[MAX_RAYS], oz[MAX_RAYS];
    double dx[MAX_RAYS], dy[MAX_RAYS], dz[MAX_RAYS];
    double vx[MAX_RAYS], vy[MAX_RAYS], vz[MAX_RAYS];
    double in[MAX_RAYS], op[MAX_RAYS], phase[MAX_RAYS];
    int kphi[MAX_RAYS];
    uint64_t ch[MAX_RAYS];
} rays;

static void add_ray(rays *r, lp_vec3 o, lp_vec3 d, lp_vec3 vp, double intensity)
{
    size_t i = r->n++;
    r->ox[i] = o.x, r->oy[i] = o.y, r->oz[i] = o.z;
    r->dx[i] = d.x, r->dy[i] = d.y, r->dz[i] = d.z;
    r->vx[i] = vp.x, r->vy[i] = vp.y, r->vz[i] = vp.z;
    r->in[i] = intensity;
    r->op[i] = 10.0 * uniform();
    r->phase[i] = 6.0 * uniform() - 3.0;
    r->kphi[i] = (int)(3.0 * uniform());
    r->ch[i] = i * 7u + 1u;
}

/* Rays first.. of r as arrays. */
static lp_ray_soa soa_of(const rays *r, size_t first)
{
    size_t i = first;
    lp_ray_soa s = {r->ox + i, r->oy + i, r->oz + i, r->dx + i, r->dy + i, r->dz + i,
                    r->vx + i, r->vy + i, r->vz + i, r->in + i, r->op + i, r->phase + i,
                    r->kphi + i, r->ch + i};
    return s;
}

static lp_ray record_of(const rays *r, size_t i, double lambda_nm)
{
    lp_ray x;
    x.origin = vec(r->ox[i], r->oy[i], r->oz[i]);
    x.dir = vec(r->dx[i], r->dy[i], r->dz[i]);
    x.lambda_nm = lambda_nm;
    x.intensity = r->in[i];
    x.vp = vec(r->vx[i], r->vy[i], r->vz[i]);
    x.kphi = r->kphi[i];
    x.op = r->op[i];
    x.phase = r->phase[i];
    x.ch = r->ch[i];
    return x;
}

static lp_vec3 place(lp_vec3 pos, lp_vec3 u, lp_vec3 v, lp_vec3 w, double x, double y,
                     double z)
{
    return vec(pos.x + x * u.x + y * v.x + z * w.x, pos.y + x * u.y + y * v.y + z * w.y,
               pos.z + x * u.z + y * v.z + z * w.z);
}

static int keep_odd_depths(const lp_branch_info *info, void *user)
{
    (void)user;
    return info->depth % 2 == 1 || info->kind == LP_KIND_TRANSMIT;
}

/* The lens's outgoing rays (the first per_ray of every step-th ray of r
 * traced at 550 nm) added to r: they start on its surface; back towards
 * the lens half the time, onward the other half.  Returns how many. */
static size_t feed_back(rays *r, const lp_lens *lens, size_t step, size_t per_ray)
{
    lp_result res;
    lp_result_init(&res);
    size_t base = r->n, added = 0;
    for (size_t i = 0; i < base && r->n < MAX_RAYS; i += step) {
        lp_ray x = record_of(r, i, 550.0);
        if (lp_trace_forward(lens, &x, NULL, &res, NULL) != LP_OK)
            continue;
        for (size_t k = 0; k < res.count && k < per_ray && r->n < MAX_RAYS; k++) {
            lp_vec3 d = res.rays[k].ray.dir;
            if (k % 2 == 0)
                d = vec(-d.x, -d.y, -d.z);
            add_ray(r, res.rays[k].ray.origin, d, res.rays[k].ray.vp, res.rays[k].ray.intensity);
            added++;
        }
    }
    lp_result_release(&res);
    return added;
}

/* Random rays at a lens with axis w at pos (u, v complete the frame). */
static void make_rays(rays *r, const lp_lens *lens, lp_vec3 pos, lp_vec3 u, lp_vec3 v,
                      lp_vec3 w, double h, double t)
{
    r->n = 0;
    for (int i = 0; i < 150; i++) {
        /* from in front, aimed at the aperture and a little beyond it */
        double rho = 1.3 * h * sqrt(uniform()), phi = 2.0 * PI * uniform();
        double tilt = (i % 7 == 0 ? 1.5 : 0.6) * uniform(), az = 2.0 * PI * uniform();
        double side = i % 5 == 0 ? t + 3.0 * h : -3.0 * h;
        double sz = side < 0.0 ? 1.0 : -1.0;
        lp_vec3 o = place(pos, u, v, w, rho * cos(phi), rho * sin(phi), side);
        lp_vec3 d = place(vec(0, 0, 0), u, v, w, sin(tilt) * cos(az), sin(tilt) * sin(az),
                          sz * cos(tilt));
        d = vec(d.x * 3.0, d.y * 3.0, d.z * 3.0); /* not unit: normalized by the call */
        lp_vec3 vp = place(vec(0, 0, 0), u, v, w, cos(az + 1.0), sin(az + 1.0), uniform());
        add_ray(r, o, d, vp, i % 11 == 0 ? 0.0 : 0.5 + uniform());
    }
    for (int i = 0; i < 40; i++) {
        /* tangent to a sphere around the lens: near its bounding sphere */
        double R = sqrt(h * h + 0.25 * t * t) * (1.0 + 0.02 * (uniform() - 0.5));
        double phi = 2.0 * PI * uniform();
        lp_vec3 o = place(pos, u, v, w, R * cos(phi), R * sin(phi), 0.5 * t - 4.0 * h);
        lp_vec3 d = place(vec(0, 0, 0), u, v, w, 0.0, 0.0, 1.0);
        add_ray(r, o, d, u, 1.0);
    }
    /* the lens's own outgoing rays, fed back: they start on its surface */
    feed_back(r, lens, 3, MAX_RAYS);
}

static int n_identity_cases;
static size_t n_identity_rays, n_two_parts, n_normal, n_on_lens, n_edge;

/* Rays first .. first+n of r, traced by the batch at lambda_nm, by
 * lp_trace_forward_many (the same rays as records) and one by one by
 * lp_trace_forward: every outgoing ray, offset and sum must be the same
 * bits. */
static void identity_case(const char *name, const lp_lens *lens, const rays *r, size_t first,
                          size_t n, double lambda_nm, const lp_trace_args *a)
{
    static lp_ray recs[MAX_RAYS];
    static size_t off_a[MAX_RAYS + 1], off_b[MAX_RAYS + 1];
    lp_result ra, rb, one;
    lp_error err;
    char what[256];
    lp_ray_soa s = soa_of(r, first);

    lp_result_init(&ra);
    lp_result_init(&rb);
    lp_result_init(&one);
    for (size_t i = 0; i < n; i++)
        recs[i] = record_of(r, first + i, lambda_nm);
    snprintf(what, sizeof what, "%s mode %d depth %d flags %u%s rays %zu..%zu", name,
             (int)a->mode, a->max_depth, a->flags, a->filter ? " filter" : "", first,
             first + n);
    lp_status sa = lp_trace_forward_soa(lens, lambda_nm, &s, n, a, &ra, off_a, &err);
    CHECK(sa == LP_OK, "%s: batch: %s", what, err.message);
    lp_status sb = lp_trace_forward_many(lens, recs, n, a, &rb, off_b, &err);
    CHECK(sb == LP_OK, "%s: many: %s", what, err.message);
    if (sa == LP_OK && sb == LP_OK) {
        size_t differ = 0;
        CHECK(same_books(&ra, &rb), "%s: bookkeeping bit for bit (in %.17g / %.17g)", what,
              ra.in, rb.in);
        CHECK(memcmp(off_a, off_b, (n + 1) * sizeof *off_a) == 0, "%s: offsets", what);
        for (size_t k = 0; k < ra.count && k < rb.count; k++)
            differ += !same_out_ray(&ra.rays[k], &rb.rays[k]);
        CHECK(differ == 0, "%s: %zu of %zu outgoing rays differ from lp_trace_forward_many",
              what, differ, ra.count);
        /* and the one-ray entry point, ray by ray */
        differ = 0;
        for (size_t i = 0; i < n; i++) {
            if (lp_trace_forward(lens, &recs[i], a, &one, NULL) != LP_OK) {
                differ++;
                continue;
            }
            size_t m = off_a[i + 1] - off_a[i];
            if (m != one.count) {
                differ++;
                continue;
            }
            for (size_t k = 0; k < m; k++)
                if (!same_out_ray(&ra.rays[off_a[i] + k], &one.rays[k])) {
                    differ++;
                    break;
                }
        }
        CHECK(differ == 0, "%s: %zu of %zu rays differ from lp_trace_forward", what, differ, n);
        for (size_t k = 0; k < ra.count; k++)
            n_two_parts += ra.rays[k].part == 1;
        n_identity_cases++;
        n_identity_rays += n;
    }
    lp_result_release(&ra);
    lp_result_release(&rb);
    lp_result_release(&one);
}

/* Rays for the lane engine's every way (trace_lanes.h): a wide beam from
 * both sides with steep rays (total internal reflections inside, fields
 * that turn elliptical and go on), rays along the axis and parallel to it
 * (normal incidence), rays that start on the lens, zero intensities and
 * phases far outside [-pi, pi]; in shuffled order, so that each group of
 * rays mixes them. */
static void make_lane_rays(rays *r, const lp_lens *lens, lp_vec3 pos, lp_vec3 u, lp_vec3 v,
                           lp_vec3 w, double h, double t)
{
    make_rays(r, lens, pos, u, v, w, h, t);
    for (int i = 0; i < 1500 && r->n < MAX_RAYS - 600; i++) {
        double rho = 1.1 * h * sqrt(uniform()), phi = 2.0 * PI * uniform();
        double tilt = (i % 3 == 0 ? 1.3 : 0.5) * uniform(), az = 2.0 * PI * uniform();
        double side = i % 4 == 0 ? t + 2.0 * h : -2.0 * h;
        double sz = side < 0.0 ? 1.0 : -1.0;
        lp_vec3 o = place(pos, u, v, w, rho * cos(phi), rho * sin(phi), side);
        lp_vec3 d = place(vec(0, 0, 0), u, v, w, sin(tilt) * cos(az), sin(tilt) * sin(az),
                          sz * cos(tilt));
        lp_vec3 vp = place(vec(0, 0, 0), u, v, w, cos(az + 2.0), sin(az + 2.0), 0.3);
        add_ray(r, o, d, vp, i % 97 == 0 ? 0.0 : 0.1 + 2.0 * uniform());
        if (i % 13 == 0)
            r->phase[r->n - 1] = 40.0 * (uniform() - 0.5);
    }
    for (int i = 0; i < 40; i++) {
        /* along the axis, and parallel to it: normal incidence on the
         * axis (every node), oblique off it */
        double off = i % 2 == 0 ? 0.0 : 0.6 * h * uniform();
        lp_vec3 o = place(pos, u, v, w, off, 0.0, i % 4 < 2 ? -h : t + h);
        lp_vec3 d = i % 4 < 2 ? w : vec(-w.x, -w.y, -w.z);
        n_normal += off == 0.0;
        add_ray(r, o, d, v, 1.0);
    }
    /* at the caps' edge circles, where a cap's hit and the rim's tie */
    lp_lens_desc ds;
    lp_lens_get_desc(lens, &ds);
    for (int i = 0; i < 64; i++) {
        int back = i & 1;
        double R = back ? ds.radius2 : ds.radius1;
        double a = 0.5 * (back && ds.diameter2 > 0.0 ? ds.diameter2 : ds.diameter);
        double sag = R == 0.0 || isinf(R) ? 0.0 : R - copysign(sqrt(R * R - a * a), R);
        double phi = 2.0 * PI * uniform();
        double z = (back ? ds.thickness : 0.0) + sag;
        lp_vec3 e = place(pos, u, v, w, a * cos(phi), a * sin(phi), z);
        double cz = 2.0 * uniform() - 1.0, az = 2.0 * PI * uniform(), sz = sqrt(1.0 - cz * cz);
        lp_vec3 d = vec(sz * cos(az), sz * sin(az), cz);
        double far = 3.0 * (h + t);
        lp_vec3 o = vec(e.x - far * d.x, e.y - far * d.y, e.z - far * d.z);
        lp_vec3 vp = fabs(d.x) < 0.9 ? vec(0.0, -d.z, d.y) : vec(-d.z, 0.0, d.x); /* d x axis */
        add_ray(r, o, d, vp, 1.0);
        n_edge++;
    }
    /* the lens's own outgoing rays of depth 1 and 2, fed back */
    n_on_lens += feed_back(r, lens, 7, 2);
    /* shuffled (Fisher-Yates, on every array) */
    for (size_t i = r->n - 1; i > 0; i--) {
        size_t k = (size_t)(uniform() * (double)(i + 1));
        k = k > i ? i : k;
#define SWAP(arr, T)                                                                           \
    do {                                                                                       \
        T tmp_ = r->arr[i];                                                                    \
        r->arr[i] = r->arr[k];                                                                 \
        r->arr[k] = tmp_;                                                                      \
    } while (0)
        SWAP(ox, double);
        SWAP(oy, double);
        SWAP(oz, double);
        SWAP(dx, double);
        SWAP(dy, double);
        SWAP(dz, double);
        SWAP(vx, double);
        SWAP(vy, double);
        SWAP(vz, double);
        SWAP(in, double);
        SWAP(op, double);
        SWAP(phase, double);
        SWAP(kphi, int);
        SWAP(ch, uint64_t);
#undef SWAP
    }
}

static void test_identity(void)
{
    static rays r;
    struct {
        const char *name;
        double r1, r2, t, d, d2, n; /* n = 0: N-BK7 from the catalog */
        int crystal;
        double medium;              /* 0: air */
    } shapes[] = {
        {"biconvex N-BK7", 50, -50, 8, 25, 0, 0, 0, 0},
        {"meniscus n=1.7", 20, 40, 4, 20, 0, 1.7, 0, 0},
        {"flat plate n=1.5", 0, 0, 3, 20, 0, 1.5, 0, 0},
        {"conical rim", 60, -30, 6, 24, 18, 1.6, 0, 0},
        {"knife edge", 20, -20, 2 * (20 - sqrt(400 - 100)), 20, 0, 1.5, 0, 0},
        {"ball-like n=1.9", 10, -10, 19, 19.9, 0, 1.9, 0, 0},
        {"n=1.5 in a medium n=1.8", 30, -40, 5, 20, 0, 1.5, 0, 1.8},
        /* index-matched: no interface at the caps (fresnel.h's n1 == n2) */
        {"n=1.5 in a medium n=1.5", 30, -40, 5, 20, 0, 1.5, 0, 1.5},
        {"calcite-like crystal plate", 0, 0, 3, 20, 0, 0, 1, 0},
    };
    lp_mode modes[] = {LP_MODE_POLARIZED, LP_MODE_FRESNEL, LP_MODE_SCHLICK};
    int depths[] = {1, 5, 20};
    /* group sizes around the engine's groups (64 rays) */
    size_t sizes[] = {1, 2, 7, 63, 64, 65, 130, 200};
    lp_error err;

    for (size_t si = 0; si < sizeof shapes / sizeof shapes[0]; si++) {
        lp_lens_desc desc;
        lp_lens *lens;
        lp_lens_desc_init(&desc);
        desc.radius1 = shapes[si].r1;
        desc.radius2 = shapes[si].r2;
        desc.thickness = shapes[si].t;
        desc.diameter = shapes[si].d;
        desc.diameter2 = shapes[si].d2;
        if (shapes[si].crystal) {
            desc.uniaxial = 1;
            lp_crystal_init_constant(&desc.crystal, 1.658, 1.486, vec(0.3, 0.5, 0.8));
        } else if (shapes[si].n > 0.0) {
            lp_glass_init_constant(&desc.glass, shapes[si].n);
        } else {
            CHECK(lp_glass_builtin("N-BK7", &desc.glass, &err) == LP_OK, "N-BK7: %s",
                  err.message);
        }
        if (shapes[si].medium > 0.0)
            lp_glass_init_constant(&desc.medium, shapes[si].medium);
        /* placed off the origin, tilted */
        double th = 0.4 + 0.1 * (double)si, ph = 0.7 * (double)si;
        lp_vec3 w = vec(sin(th) * cos(ph), sin(th) * sin(ph), cos(th));
        desc.axis = w;
        desc.position = vec(3.0 * (double)si, -2.0, 5.0);
        if (lp_lens_create(&desc, &lens, &err) != LP_OK) {
            CHECK(0, "%s: %s", shapes[si].name, err.message);
            continue;
        }
        lp_lens_get_desc(lens, &desc);
        lp_vec3 u = fabs(w.x) < 0.6 ? vec(1, 0, 0) : vec(0, 1, 0);
        double uw = u.x * w.x + u.y * w.y + u.z * w.z;
        u = vec(u.x - uw * w.x, u.y - uw * w.y, u.z - uw * w.z);
        double ul = sqrt(u.x * u.x + u.y * u.y + u.z * u.z);
        u = vec(u.x / ul, u.y / ul, u.z / ul);
        lp_vec3 v = vec(w.y * u.z - w.z * u.y, w.z * u.x - w.x * u.z, w.x * u.y - w.y * u.x);
        make_lane_rays(&r, lens, desc.position, u, v, w, 0.5 * desc.diameter, desc.thickness);
        for (size_t mi = 0; mi < 3; mi++)
            for (size_t di = 0; di < sizeof depths / sizeof depths[0]; di++) {
                lp_trace_args a;
                lp_trace_args_init(&a);
                a.mode = modes[mi];
                /* a crystal's tree doubles at every node: depth 6 at most */
                a.max_depth = shapes[si].crystal && depths[di] > 6 ? 6 : depths[di];
                identity_case(shapes[si].name, lens, &r, 0, r.n,
                              380.0 + 57.0 * (double)(si + di), &a);
            }
        /* flags, a filter and a weight cut */
        lp_trace_args a;
        lp_trace_args_init(&a);
        a.max_depth = shapes[si].crystal ? 6 : 12;
        a.flags = LP_SKIP_EXTERNAL_REFLECTION;
        a.filter = keep_odd_depths;
        a.min_weight = 1e-3;
        identity_case(shapes[si].name, lens, &r, 0, r.n, 633.0, &a);
        a.flags = LP_SKIP_REFLECTED;
        a.filter = NULL;
        identity_case(shapes[si].name, lens, &r, 0, r.n, 486.1, &a);
        /* groups of every size, from anywhere in the rays */
        a.flags = 0;
        a.min_weight = 0.0;
        a.max_depth = shapes[si].crystal ? 4 : 7;
        for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
            size_t first = (size_t)(uniform() * (double)(r.n - sizes[k]));
            a.mode = modes[k % 3];
            identity_case(shapes[si].name, lens, &r, first, sizes[k], 550.0, &a);
        }
        lp_lens_destroy(lens);
    }
    printf("identity: %d cases (lens x mode x depth x args; whole sets, groups of 1 to 200), "
           "%zu rays, every ray, offset and sum identical; among them %zu along a lens's axis, "
           "%zu starting on a lens, %zu through a cap's edge circle; %zu second parts of "
           "elliptical fields out\n",
           n_identity_cases, n_identity_rays, n_normal, n_on_lens, n_edge, n_two_parts);
}

static void test_closed_form(void)
{
    static rays r;
    static size_t off[MAX_RAYS + 1];
    lp_lens_desc desc;
    lp_lens *lens;
    lp_error err;
    lp_result res;
    double n = 1.5, R = ((n - 1.0) / (n + 1.0)) * ((n - 1.0) / (n + 1.0));

    /* the rays this check has always had, whatever the tests before it
     * drew */
    rng = 0x9d50edbb71a5ce8aull;
    lp_lens_desc_init(&desc);
    desc.radius1 = desc.radius2 = 0.0;
    desc.thickness = 2.0;
    desc.diameter = 20.0;
    lp_glass_init_constant(&desc.glass, n);
    CHECK(lp_lens_create(&desc, &lens, &err) == LP_OK, "plate: %s", err.message);
    r.n = 0;
    for (int i = 0; i < 250; i++) {
        double rho = 9.0 * sqrt(uniform()), phi = 2.0 * PI * uniform();
        add_ray(&r, vec(rho * cos(phi), rho * sin(phi), -5.0), vec(0, 0, 1),
                vec(cos(phi), sin(phi), 0), 1.0);
    }
    lp_result_init(&res);
    lp_trace_args a;
    lp_trace_args_init(&a);
    a.max_depth = 2;
    lp_ray_soa s = soa_of(&r, 0);
    CHECK(lp_trace_forward_soa(lens, 550.0, &s, r.n, &a, &res, off, &err) == LP_OK, "plate: %s",
          err.message);
    for (size_t i = 0; i < r.n; i++) {
        CHECK(off[i + 1] - off[i] == 2, "plate ray %zu: two outgoing rays", i);
        if (off[i + 1] - off[i] != 2)
            continue;
        const lp_out_ray *x = &res.rays[off[i]], *y = &res.rays[off[i] + 1];
        char what[64];
        snprintf(what, sizeof what, "plate ray %zu: R", i);
        CHECK_REL(x->ray.intensity, R, 4e-15, "%s", what);
        snprintf(what, sizeof what, "plate ray %zu: (1-R)^2", i);
        CHECK_REL(y->ray.intensity, (1.0 - R) * (1.0 - R), 4e-15, "%s", what);
        CHECK(x->depth == 1 && x->kind == LP_KIND_REFLECT && y->depth == 2 &&
                  y->kind == LP_KIND_TRANSMIT,
              "plate ray %zu: depths and kinds", i);
        CHECK(x->ray.dir.z == -1.0 && y->ray.dir.z == 1.0, "plate ray %zu: directions", i);
    }
    lp_result_release(&res);
    lp_lens_destroy(lens);
}

static void test_errors(void)
{
    static rays r;
    static lp_ray recs[MAX_RAYS];
    static size_t off[MAX_RAYS + 1], off_b[MAX_RAYS + 1];
    lp_lens_desc desc;
    lp_lens *lens;
    lp_error err, err_b;
    lp_result res, rb;

    lp_lens_desc_init(&desc);
    desc.radius1 = 40;
    desc.radius2 = -40;
    desc.thickness = 5;
    desc.diameter = 20;
    CHECK(lp_lens_create(&desc, &lens, &err) == LP_OK, "lens: %s", err.message);
    lp_result_init(&res);
    lp_result_init(&rb);
    r.n = 0;
    for (int i = 0; i < 10; i++)
        add_ray(&r, vec(0.5 * i, 0, -10), vec(0, 0, 1), vec(1, 0, 0), 1.0);
    lp_ray_soa s = soa_of(&r, 0);

    CHECK(lp_trace_forward_soa(NULL, 550, &s, r.n, NULL, &res, off, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "NULL lens");
    CHECK(lp_trace_forward_soa(lens, 550, NULL, 1, NULL, &res, off, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "NULL rays");
    CHECK(lp_trace_forward_soa(lens, 550, &s, r.n, NULL, NULL, off, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "NULL result");
    CHECK(lp_trace_forward_soa(lens, 550, &s, r.n, NULL, &res, NULL, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "NULL offsets");
    lp_ray_soa t = s;
    t.vz = NULL;
    CHECK(lp_trace_forward_soa(lens, 550, &t, r.n, NULL, &res, off, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "NULL field array");
    t = s;
    t.intensity = NULL;
    CHECK(lp_trace_forward_soa(lens, 550, &t, r.n, NULL, &res, off, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "NULL intensity array");
    CHECK(lp_trace_forward_soa(lens, 550, &t, 0, NULL, &res, off, &err) == LP_OK && off[0] == 0,
          "no rays: arrays unused, offsets[0] = 0");
    CHECK(lp_trace_forward_soa(lens, -1.0, &s, 0, NULL, &res, off, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "negative wavelength, no rays");
    CHECK(lp_trace_forward_soa(lens, NAN, &s, r.n, NULL, &res, off, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "NaN wavelength");
    lp_trace_args a;
    lp_trace_args_init(&a);
    a.max_depth = 0;
    CHECK(lp_trace_forward_soa(lens, 550, &s, r.n, &a, &res, off, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "depth 0");

    /* invalid rays, one kind at a time, at index 6 */
    for (int kind = 0; kind < 7; kind++) {
        static rays bad;
        bad = r;
        size_t k = 6;
        switch (kind) {
        case 0: bad.dx[k] = bad.dy[k] = bad.dz[k] = 0.0; break;
        case 1: bad.ox[k] = INFINITY; break;
        case 2: bad.dy[k] = NAN; break;
        case 3: bad.in[k] = -1.0; break;
        case 4: bad.vx[k] = 0.0, bad.vz[k] = 1.0; break; /* parallel to dir */
        case 5: bad.op[k] = NAN; break;
        case 6: bad.phase[k] = INFINITY; break;
        }
        lp_ray_soa bs = soa_of(&bad, 0);
        for (size_t i = 0; i < bad.n; i++)
            recs[i] = record_of(&bad, i, 550.0);
        lp_status st = lp_trace_forward_soa(lens, 550, &bs, bad.n, NULL, &res, off, &err);
        lp_status sb = lp_trace_forward_many(lens, recs, bad.n, NULL, &rb, off_b, &err_b);
        CHECK(st == LP_ERROR_INVALID_ARGUMENT && st == sb, "bad ray kind %d: refused", kind);
        CHECK(strncmp(err.message, "ray 6: ", 7) == 0, "bad ray kind %d: index in '%s'", kind,
              err.message);
        CHECK(strcmp(err.message, err_b.message) == 0, "bad ray kind %d: '%s' vs '%s'", kind,
              err.message, err_b.message);
        CHECK(same_books(&res, &rb) && memcmp(off, off_b, 6 * sizeof *off) == 0,
              "bad ray kind %d: the rays before it kept", kind);
    }

    /* NULL optional arrays stand for 0 */
    t = s;
    t.op = t.phase = NULL;
    t.kphi = NULL;
    t.ch = NULL;
    for (size_t i = 0; i < r.n; i++) {
        recs[i] = record_of(&r, i, 550.0);
        recs[i].op = recs[i].phase = 0.0;
        recs[i].kphi = 0;
        recs[i].ch = 0;
    }
    CHECK(lp_trace_forward_soa(lens, 550, &t, r.n, NULL, &res, off, &err) == LP_OK, "%s",
          err.message);
    CHECK(lp_trace_forward_many(lens, recs, r.n, NULL, &rb, off_b, &err) == LP_OK, "%s",
          err.message);
    size_t differ = res.count != rb.count;
    for (size_t k = 0; k < res.count && k < rb.count; k++)
        differ += !same_out_ray(&res.rays[k], &rb.rays[k]);
    CHECK(differ == 0 && same_books(&res, &rb), "NULL optional arrays: %zu rays differ", differ);
    lp_result_release(&res);
    lp_result_release(&rb);
    lp_lens_destroy(lens);
}

/* lp_trace_forward_many on records whose wavelengths come in runs of 1 to
 * 130 (the runs of 8 and more go through the lane engine, the others ray
 * by ray): every outgoing ray and offset is lp_trace_forward's for that
 * ray, bit for bit; `in` and `out` are the sums, in order, of the
 * intensities of the rays that meet the lens and of the outgoing rays'
 * intensities, bit for bit; the
 * other sums differ from the sums of lp_trace_forward's per-ray sums only
 * by the order of their terms (each of n terms >= 0: at most n roundings
 * of DBL_EPSILON/2 of the total).  An invalid ray or wavelength inside a
 * long run stops the call at that ray with the one-ray code's message. */
static void test_runs(void)
{
    static rays r;
    static lp_ray recs[MAX_RAYS];
    static size_t off[MAX_RAYS + 1];
    const size_t lengths[] = {1, 2, 8, 9, 70, 3, 64, 65, 7, 130, 1, 8};
    const double lambdas[] = {450.0, 550.0, 650.0, 500.0};
    const char *glass[] = {"N-BK7", "N-SF11"};
    lp_error err, err1;
    lp_result res, one;

    lp_result_init(&res);
    lp_result_init(&one);
    for (int gi = 0; gi < 2; gi++) {
        lp_lens_desc desc;
        lp_lens *lens;
        lp_lens_desc_init(&desc);
        desc.radius1 = gi ? 10 : 50;
        desc.radius2 = gi ? -10 : -50;
        desc.thickness = gi ? 19 : 8;
        desc.diameter = gi ? 19.9 : 25;
        CHECK(lp_glass_builtin(glass[gi], &desc.glass, &err) == LP_OK, "%s", err.message);
        CHECK(lp_lens_create(&desc, &lens, &err) == LP_OK, "%s", err.message);
        make_lane_rays(&r, lens, vec(0, 0, 0), vec(1, 0, 0), vec(0, 1, 0), vec(0, 0, 1),
                       0.5 * desc.diameter, desc.thickness);
        size_t n = 0;
        for (size_t k = 0; n < r.n; k++) {
            size_t len = lengths[k % (sizeof lengths / sizeof lengths[0])];
            for (size_t i = 0; i < len && n < r.n; i++, n++)
                recs[n] = record_of(&r, n, lambdas[k % 4]);
        }
        for (int mode = 0; mode < 3; mode++) {
            lp_trace_args a;
            lp_trace_args_init(&a);
            a.mode = (lp_mode)mode;
            a.max_depth = 6;
            CHECK(lp_trace_forward_many(lens, recs, n, &a, &res, off, &err) == LP_OK, "%s",
                  err.message);
            size_t differ = 0, nodes = 0;
            double in = 0.0, out = 0.0, rest[4] = {0, 0, 0, 0}, want[4];
            unsigned warnings = 0;
            for (size_t i = 0; i < n; i++) {
                if (lp_trace_forward(lens, &recs[i], &a, &one, NULL) != LP_OK ||
                    off[i + 1] - off[i] != one.count) {
                    differ++;
                    continue;
                }
                in += one.in; /* the ray's intensity, or 0 when it misses */
                for (size_t k = 0; k < one.count; k++) {
                    differ += !same_out_ray(&res.rays[off[i] + k], &one.rays[k]);
                    out += one.rays[k].ray.intensity;
                }
                rest[0] += one.skipped, rest[1] += one.absorbed_glass;
                rest[2] += one.absorbed_rim, rest[3] += one.truncated;
                nodes += one.nodes;
                warnings |= one.warnings;
            }
            CHECK(differ == 0, "%s mode %d: %zu of %zu rays differ from lp_trace_forward",
                  glass[gi], mode, differ, n);
            CHECK(memcmp(&in, &res.in, sizeof in) == 0 && memcmp(&out, &res.out, sizeof out) == 0,
                  "%s mode %d: in %.17g / %.17g, out %.17g / %.17g", glass[gi], mode, res.in,
                  in, res.out, out);
            CHECK(nodes == res.nodes && warnings == res.warnings, "%s mode %d: nodes, warnings",
                  glass[gi], mode);
            want[0] = res.skipped, want[1] = res.absorbed_glass;
            want[2] = res.absorbed_rim, want[3] = res.truncated;
            for (int k = 0; k < 4; k++)
                CHECK(fabs(want[k] - rest[k]) <= (double)n * DBL_EPSILON * rest[k],
                      "%s mode %d: sum %d %.17g / %.17g", glass[gi], mode, k, want[k], rest[k]);
        }
        /* an invalid ray, then a bad wavelength, inside a run of 70 */
        for (int bad = 0; bad < 2; bad++) {
            size_t k = 40 + (size_t)bad;
            lp_ray keep = recs[k];
            if (bad == 0)
                recs[k].vp = recs[k].dir; /* parallel to the direction */
            else
                for (size_t i = k; i < k + 5; i++)
                    recs[i].lambda_nm = NAN;
            lp_status st = lp_trace_forward_many(lens, recs, n, NULL, &res, off, &err);
            lp_status s1 = lp_trace_forward(lens, &recs[k], NULL, &one, &err1);
            char want_msg[300];
            snprintf(want_msg, sizeof want_msg, "ray %zu: %s", k, err1.message);
            CHECK(st == s1 && st != LP_OK && strcmp(err.message, want_msg) == 0,
                  "%s bad %d: '%s', want '%s'", glass[gi], bad, err.message, want_msg);
            size_t count = 0;
            for (size_t i = 0; i < k; i++)
                if (lp_trace_forward(lens, &recs[i], NULL, &one, NULL) == LP_OK)
                    count += one.count;
            CHECK(res.count == count && off[k] == count, "%s bad %d: the rays before it kept",
                  glass[gi], bad);
            for (size_t i = k; i < k + 5; i++)
                recs[i].lambda_nm = keep.lambda_nm;
            recs[k] = keep;
        }
        lp_lens_destroy(lens);
    }
    lp_result_release(&res);
    lp_result_release(&one);
    printf("runs: lp_trace_forward_many on runs of 1 to 130 rays of one wavelength, every "
           "ray as lp_trace_forward's\n");
}

int main(void)
{
    test_identity();
    test_closed_form();
    test_errors();
    test_runs();
    return check_finish("test_batch");
}
