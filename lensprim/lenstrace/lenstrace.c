/* lenstrace.c -- rays through one lens, as JSON Lines.
 *
 * Parses the command line (lenstrace_args.c), builds the lens, traces the
 * ray (--ray) or each ray of a file (--rays) forward (from the light) or
 * backward (from the eye), and prints one JSON line per outgoing ray and a
 * summary line per input ray.  All output is built in
 * memory first: on any error stdout stays empty and stderr gets exactly
 * one line "lenstrace: <message>", exit status 2. */
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lensprim.h"
#include "lenstrace_args.h"
#include "support/cli.h"

#define EXIT_BAD 2

/* Split in parts: C11 compilers need only support 4095-char literals. */
static const char *const usage_text[] = {
"usage: lenstrace --lens SPEC (--ray SPEC | --rays FILE) [--depth N]\n"
"                 [--mode polarized|fresnel|schlick] [--medium N]\n"
"                 [--backward] [--catalog FILE.agf]...\n"
"       lenstrace --lens SPEC --cone \"x,y,z\" [--depth N] [--azimuths K]\n"
"                 [--lambda NM] [--medium N] [--catalog FILE.agf]...\n"
"       lenstrace --help | --version\n"
"\n"
"Trace rays through one lens and print every outgoing ray as JSON Lines.\n"
"Options take their value as \"--opt VALUE\" or \"--opt=VALUE\".\n"
"Lengths are in millimetres, wavelengths in nanometres, phases in radians.\n"
"\n"
"  --lens SPEC      comma-separated KEY=VALUE, e.g.\n"
"                     \"R1=25.8,R2=inf,t=5.3,D=25.4,glass=N-BK7\"\n"
"                   R1, R2  surface radii (R > 0: centre of curvature at +z;\n"
"                           inf, -inf or 0: flat)                 required\n"
"                   t       centre thickness                       required\n"
"                   D       rim diameter at the front cap          required\n"
"                   D2      rim diameter at the back cap (conical rim)\n"
"                   glass   a catalog name (N-BK7, N-SF11, F2, ...) or\n"
"                           n=1.5 for a constant index; the key n=1.5\n"
"                           is accepted too                        required\n"
"                   crystal instead of the glass, a uniaxial crystal: a\n"
"                           built-in one (calcite, quartz, sapphire,\n"
"                           MgF2), or no=N,ne=N for constant indices\n"
"                   axis    the crystal's optic axis x:y:z in the lens\n"
"                           frame (default 0:0:1); the output lines then\n"
"                           carry \"waves\": bit k-1 set when the ray left\n"
"                           node k inside as an extraordinary wave\n"
"                   The lens sits in its local frame: axis +z, front vertex\n"
"                   at the origin, back vertex at z = t.\n"
"  --ray SPEC       space-separated KEY=VALUE, e.g.\n"
"                     \"o=0,3,-10 d=0,0,1 lambda=587.56 vp=1,0,0 I=1 ch=7\"\n"
"                   o=x,y,z   origin                               required\n"
"                   d=x,y,z   direction (normalized)               required\n"
"                   lambda=NM wavelength in standard air, as glass catalogs\n"
"                             and line tables give it (default 587.56, the\n"
"                             d line: n is the catalog's n_d exactly)\n"
"                   lambda_vac=NM  a vacuum wavelength instead, traced at\n"
"                             lambda_vac/n_air (standard air, Edlen 1966)\n"
"                   vp=x,y,z  field direction, made perpendicular to d,\n"
"                             or vp=unpolarized (the default)\n"
"                   I=..      intensity (default 1)\n"
"                   ch=..     source id, an unsigned integer (default 0)\n"
"                   The origin must lie outside the glass (in the\n"
"                   surrounding medium); a ray born inside is refused.\n"
"  --rays FILE      one --ray SPEC per line instead of --ray (- reads\n"
"                   standard input; blank lines and lines starting with #\n"
"                   are skipped).  Each ray's lines and its summary end\n"
"                   with \"ray\":K, K = 0, 1, ... in the order of the file;\n"
"                   an error names FILE:LINE and nothing is printed.\n"
"  --depth N        tree depth dT, 1..64 (default 5)\n"
"  --mode M         polarized (Fresnel on s and p with vectors and phases,\n"
"                   the default), fresnel ((Rs+Rp)/2 per interface) or\n"
"                   schlick (Schlick's approximation)\n"
"  --medium N       index of the surrounding medium relative to air\n"
"                   (default 1: air)\n"
"  --catalog FILE   load more glasses from a Zemax AGF file (repeatable;\n"
"                   a later glass of the same name replaces an earlier one)\n"
"  --backward       trace from the eye (see BACKWARD below)\n"
"  --cone x,y,z     print the cone K of rim-free directions from that point\n"
"                   (lens frame) at depth --depth instead of tracing a ray\n"
"                   (see CONE below)\n"
"  --azimuths K     with --cone: K azimuths evenly from 0 deg (default 36)\n"
"  --lambda NM      with --cone: wavelength in standard air (default 587.56)\n"
"  -h, --help       this text\n"
"  -V, --version    the version\n"
"\n",
"OUTPUT: one line per outgoing ray, keys in this order:\n"
"  {\"depth\":2,\"kind\":\"transmit\",\"o\":[x,y,z],\"d\":[x,y,z],"
"\"lambda\":587.56,\n"
"   \"I\":0.92,\"vp\":[x,y,z],\"kphi\":0,\"op\":8.04,\"phase\":0,\"ch\":7,\n"
"   \"surface\":\"back\",\"part\":0,\"path\":0}\n"
"  depth    interface interactions along the path (1 = external reflection)\n"
"  kind     reflect (leaves on the side the light came from) or transmit\n"
"  vp       unit field direction; the field is sqrt(I)*vp*exp(i*Phi) with\n"
"           Phi = 2*pi*op/lambda - pi*kphi + phase\n"
"  lambda   the wavelength in standard air (also with lambda_vac=)\n"
"  op       optical path inside the lens relative to air, mm: sum of n*s\n"
"           with the air-relative glass index n (times the index of air it\n"
"           is the absolute optical path)\n"
"  phase    extra phase beyond 2*pi*op/lambda - pi*kphi (non-zero only\n"
"           after total internal reflection)\n"
"  surface  cap the ray leaves from (front or back); part 0, or 1 for the\n"
"           second linear part of elliptical light after total internal\n"
"           reflection; path has bit k-1 set when node k was a reflection\n"
"  With vp=unpolarized the ray is traced as two orthogonal linear halves of\n"
"  I/2 each (vp1 = unit(d x y), or unit(d x x) when d is near the y axis;\n"
"  vp2 = d x vp1); the rays of half 0 come first, then those of half 1,\n"
"  each with a last key \"half\":0 or \"half\":1.\n"
"  Then one summary line (summed over both halves):\n"
"  {\"summary\":{\"in\":1,\"out\":..,\"absorbed_glass\":..,"
"\"absorbed_rim\":..,\"truncated\":..,\n"
"   \"skipped\":0,\"warnings\":[]}}\n"
"  with in = out + absorbed_glass + absorbed_rim + truncated + skipped.\n"
"  A ray that misses the lens gives no ray lines and a summary of zeros.\n"
"  Numbers are printed round-trip exact: the shortest of %.15g, %.16g\n"
"  and %.17g that reads back as the same double.\n"
"\n",
"BACKWARD (--backward): --ray is a view ray from the eye.  Its o, d and\n"
"  lambda define the view ray; its vp, I and ch describe the light that\n"
"  comes back.  The lens builds the query rays of the view ray; each query\n"
"  is answered with one ray of intensity I (two of I/2 with\n"
"  vp=unpolarized) arriving back along it, its vp the part of the given vp\n"
"  perpendicular to the query direction.  Every gathered ray leaves the\n"
"  lens at the view ray's entry point along -d and is printed like a\n"
"  forward ray, with \"query_o\":[..],\"query_d\":[..] (the query ray it\n"
"  came from) right after ch.  \"in\" in the summary is the total intensity\n"
"  of the answers (I per query).\n"
"\n"
"CONE (--cone): a direction is rim-free when the initial ray from the point\n"
"  meets a cap and its internal chain (the rays reflected from cap to cap)\n"
"  meets no rim up to the node of depth --depth.  The cone's axis runs from\n"
"  the point to the front vertex; azimuth 0 is along the part of +x\n"
"  perpendicular to it (+y when the axis is along x).  One line per azimuth\n"
"  phi = 360 k / K deg:\n"
"  {\"azimuth\":phi,\"theta\":theta_K}  (degrees: every direction of that\n"
"  azimuth closer to the axis than theta_K is rim-free; scan of 2048 steps\n"
"  and bisection to 1e-9 rad), then\n"
"  {\"cone\":{\"depth\":N,\"solid_angle\":sr,\"theta_min\":deg,\"theta_max\":deg,\n"
"   \"lambda\":NM,\"axis\":[x,y,z],\"ref\":[x,y,z]}}\n"
"  with solid_angle the sum of (1 - cos theta_K) 2 pi / K.\n"
"\n"
"EXIT STATUS: 0 on success; 2 on bad input or any error, with one line\n"
"  \"lenstrace: <message>\" on stderr and nothing on stdout.  Warnings (a\n"
"  wavelength outside the glass data range, ...) go to stderr and to the\n"
"  summary's \"warnings\" list; they do not change the exit status.\n"};

/* ------------------------------------------------------------------ */
/* An in-memory output buffer                                          */
/* ------------------------------------------------------------------ */

typedef struct outbuf {
    char *p;
    size_t len, cap;
    int oom;
    const char *bad_key; /* first non-finite value's key, or NULL */
} outbuf;

static void ob_printf(outbuf *b, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static void ob_printf(outbuf *b, const char *fmt, ...)
{
    va_list ap;
    int n;
    if (b->oom)
        return;
    for (;;) {
        size_t room = b->cap - b->len;
        va_start(ap, fmt);
        n = vsnprintf(b->p ? b->p + b->len : NULL, room, fmt, ap);
        va_end(ap);
        if (n < 0) {
            b->oom = 1;
            return;
        }
        if ((size_t)n < room) {
            b->len += (size_t)n;
            return;
        }
        {
            size_t cap = b->cap ? b->cap : 4096;
            char *q;
            while (cap - b->len <= (size_t)n)
                cap *= 2;
            q = realloc(b->p, cap);
            if (!q) {
                b->oom = 1;
                return;
            }
            b->p = q;
            b->cap = cap;
        }
    }
}

/* The shortest of %.15g, %.16g, %.17g that reads back as exactly v (so
 * 587.56 prints as 587.56, not 587.55999999999995); -0 prints as 0. */
static void fmt_num(char *s, size_t n, double v)
{
    if (v == 0.0)
        v = 0.0;
    for (int prec = 15; prec <= 17; prec++) {
        snprintf(s, n, "%.*g", prec, v);
        if (strtod(s, NULL) == v)
            return;
    }
}

static void ob_num(outbuf *b, const char *key, double v)
{
    char s[40];
    if (!isfinite(v)) {
        if (!b->bad_key)
            b->bad_key = key;
        v = 0.0; /* never written: the run fails */
    }
    fmt_num(s, sizeof s, v);
    ob_printf(b, ",\"%s\":%s", key, s);
}

static void ob_vec(outbuf *b, const char *key, lp_vec3 v)
{
    char x[40], y[40], z[40];
    if (!isfinite(v.x) || !isfinite(v.y) || !isfinite(v.z)) {
        if (!b->bad_key)
            b->bad_key = key;
        v.x = v.y = v.z = 0.0;
    }
    fmt_num(x, sizeof x, v.x);
    fmt_num(y, sizeof y, v.y);
    fmt_num(z, sizeof z, v.z);
    ob_printf(b, ",\"%s\":[%s,%s,%s]", key, x, y, z);
}

static const char *surface_name(int s)
{
    switch (s) {
    case LP_SURFACE_FRONT: return "front";
    case LP_SURFACE_BACK: return "back";
    case LP_SURFACE_RIM: return "rim";
    default: return "none";
    }
}

/* One ray line.  query: NULL for a forward trace.  half: -1 when the ray
 * is polarized (no "half" key). */
static void put_ray(outbuf *b, const lp_out_ray *r, const lp_query *query,
                    int half, double lambda_nm, long index)
{
    ob_printf(b, "{\"depth\":%d,\"kind\":\"%s\"", r->depth,
              r->kind == LP_KIND_REFLECT ? "reflect" : "transmit");
    ob_vec(b, "o", r->ray.origin);
    ob_vec(b, "d", r->ray.dir);
    ob_num(b, "lambda", lambda_nm);
    ob_num(b, "I", r->ray.intensity);
    ob_vec(b, "vp", r->ray.vp);
    ob_printf(b, ",\"kphi\":%d", r->ray.kphi);
    ob_num(b, "op", r->ray.op);
    ob_num(b, "phase", r->ray.phase);
    ob_printf(b, ",\"ch\":%" PRIu64, r->ray.ch);
    if (query) {
        ob_vec(b, "query_o", query->origin);
        ob_vec(b, "query_d", query->dir);
    }
    ob_printf(b, ",\"surface\":\"%s\",\"part\":%d,\"path\":%" PRIu64,
              surface_name(r->surface), r->part, r->path);
    if (r->waves)
        ob_printf(b, ",\"waves\":%" PRIu64, r->waves);
    if (half >= 0)
        ob_printf(b, ",\"half\":%d", half);
    if (index >= 0)
        ob_printf(b, ",\"ray\":%ld", index);
    ob_printf(b, "}\n");
}

typedef struct totals {
    double in, out, absorbed_glass, absorbed_rim, truncated, skipped;
    unsigned warnings;
} totals;

static void add_totals(totals *t, const lp_result *r)
{
    t->in += r->in;
    t->out += r->out;
    t->absorbed_glass += r->absorbed_glass;
    t->absorbed_rim += r->absorbed_rim;
    t->truncated += r->truncated;
    t->skipped += r->skipped;
    t->warnings |= r->warnings;
}

static void put_summary(outbuf *b, const totals *t, long index)
{
    char in[40];
    if (!isfinite(t->in) && !b->bad_key)
        b->bad_key = "in";
    fmt_num(in, sizeof in, isfinite(t->in) ? t->in : 0.0);
    ob_printf(b, "{\"summary\":{\"in\":%s", in);
    ob_num(b, "out", t->out);
    ob_num(b, "absorbed_glass", t->absorbed_glass);
    ob_num(b, "absorbed_rim", t->absorbed_rim);
    ob_num(b, "truncated", t->truncated);
    ob_num(b, "skipped", t->skipped);
    ob_printf(b, ",\"warnings\":[");
    {
        const char *sep = "";
        if (t->warnings & LP_WARN_EXTRAPOLATED) {
            ob_printf(b, "%s\"extrapolated\"", sep);
            sep = ",";
        }
        if (t->warnings & LP_WARN_LEAK)
            ob_printf(b, "%s\"leak\"", sep);
    }
    if (index >= 0)
        ob_printf(b, "]},\"ray\":%ld}\n", index);
    else
        ob_printf(b, "]}}\n");
}

/* ------------------------------------------------------------------ */
/* Errors                                                              */
/* ------------------------------------------------------------------ */

/* Print "lenstrace: <prefix><message>" as ONE line (control characters in
 * user text or library messages become '?'). */
static void say(const char *prefix, const char *msg)
{
    sp_say("lenstrace", "%s%s", prefix ? prefix : "", msg);
}

static const char *lib_message(const lp_error *err, lp_status st)
{
    return err->message[0] ? err->message : lp_status_string(st);
}

/* ------------------------------------------------------------------ */
/* The runs                                                            */
/* ------------------------------------------------------------------ */

typedef struct run {
    const lt_args *a;
    const lt_ray_spec *ray; /* the ray being traced */
    long index;             /* its index in --rays, -1 for --ray */
    char where[256];        /* "--ray" or "--rays: FILE:LINE" */
    unsigned warnings;      /* of every ray traced */
    const lp_lens *lens;
    lp_trace_args targs;
    outbuf out;
    totals sum;
    char msg[768];
} run;

/* The field of half h (0 or 1) of unpolarized light along the unit d. */
static lp_vec3 half_vp(lp_vec3 d, int h)
{
    lp_vec3 v1 = lt_perpendicular(d);
    return h == 0 ? v1 : lt_cross(d, v1);
}

static int run_forward(run *r)
{
    const lt_ray_spec *ray = r->ray;
    int halves = ray->unpolarized ? 2 : 1;
    lp_result res;
    lp_error err;
    int ok = 1;

    lp_result_init(&res);
    for (int h = 0; h < halves && ok; h++) {
        lp_ray in;
        lp_status st;
        memset(&in, 0, sizeof in);
        in.origin = ray->o;
        in.dir = ray->d;
        in.lambda_nm = ray->lambda_nm;
        in.intensity = ray->intensity / halves;
        in.vp = ray->unpolarized ? half_vp(ray->d, h) : ray->vp;
        in.ch = ray->ch;
        memset(&err, 0, sizeof err);
        st = lp_trace_forward(r->lens, &in, &r->targs, &res, &err);
        if (st != LP_OK) {
            snprintf(r->msg, sizeof r->msg, "%s", lib_message(&err, st));
            ok = 0;
            break;
        }
        for (size_t i = 0; i < res.count; i++)
            put_ray(&r->out, &res.rays[i], NULL, ray->unpolarized ? h : -1,
                    ray->lambda_nm, r->index);
        add_totals(&r->sum, &res);
    }
    lp_result_release(&res);
    return ok;
}

static int run_backward(run *r)
{
    const lt_ray_spec *ray = r->ray;
    int halves = ray->unpolarized ? 2 : 1;
    lp_backward *bw = NULL;
    lp_result res;
    lp_error err;
    lp_status st;
    const lp_query *qs;
    size_t nq;
    size_t *qidx = NULL; /* query of each gathered ray */
    int *half = NULL;    /* half of each gathered ray */
    size_t idx_cap = 0;
    int ok = 1;

    lp_result_init(&res);
    memset(&err, 0, sizeof err);
    st = lp_backward_create(&bw, &err);
    if (st == LP_OK)
        st = lp_backward_build(bw, r->lens, ray->o, ray->d, ray->lambda_nm,
                               &r->targs, &err);
    if (st != LP_OK) {
        snprintf(r->msg, sizeof r->msg, "%s", lib_message(&err, st));
        lp_backward_destroy(bw);
        return 0;
    }
    nq = lp_backward_query_count(bw);
    qs = lp_backward_queries(bw);

    for (int h = 0; h < halves && ok; h++) {
        for (size_t q = 0; q < nq && ok; q++) {
            lp_ray b;
            lp_vec3 back = {-qs[q].dir.x, -qs[q].dir.y, -qs[q].dir.z};
            size_t before = res.count;
            memset(&b, 0, sizeof b);
            b.origin = qs[q].origin;
            b.dir = back;
            b.lambda_nm = ray->lambda_nm;
            b.intensity = ray->intensity / halves;
            b.ch = ray->ch;
            if (ray->unpolarized)
                b.vp = half_vp(back, h);
            else if (!lt_perpendicular_part(ray->vp, back, &b.vp))
                b.vp = lt_perpendicular(back); /* vp along the query */
            memset(&err, 0, sizeof err);
            st = lp_backward_gather(bw, q, &b, 1, &res, &err);
            if (st != LP_OK) {
                snprintf(r->msg, sizeof r->msg, "%s", lib_message(&err, st));
                ok = 0;
                break;
            }
            if (res.count > idx_cap) {
                size_t cap = idx_cap ? idx_cap : 16;
                size_t *nqi;
                int *nh;
                while (cap < res.count)
                    cap *= 2;
                nqi = realloc(qidx, cap * sizeof *qidx);
                if (nqi)
                    qidx = nqi;
                nh = nqi ? realloc(half, cap * sizeof *half) : NULL;
                if (nh)
                    half = nh;
                if (!nqi || !nh) {
                    snprintf(r->msg, sizeof r->msg, "out of memory");
                    ok = 0;
                    break;
                }
                idx_cap = cap;
            }
            for (size_t i = before; i < res.count; i++) {
                qidx[i] = q;
                half[i] = h;
            }
        }
    }
    if (ok) {
        for (size_t i = 0; i < res.count; i++)
            put_ray(&r->out, &res.rays[i], &qs[qidx[i]],
                    ray->unpolarized ? half[i] : -1, ray->lambda_nm,
                    r->index);
        add_totals(&r->sum, &res);
    }
    free(qidx);
    free(half);
    lp_result_release(&res);
    lp_backward_destroy(bw);
    return ok;
}

static double deg(double rad)
{
    return rad * (180.0 / 3.14159265358979323846);
}

static int run_cone(run *r)
{
    const lt_args *a = r->a;
    size_t n = (size_t)a->azimuths;
    double *theta = malloc(n * sizeof *theta);
    lp_cone_args ca;
    lp_cone cone;
    lp_error err;
    lp_status st;

    if (!theta) {
        snprintf(r->msg, sizeof r->msg, "out of memory");
        return 0;
    }
    lp_cone_args_init(&ca);
    ca.max_depth = a->depth;
    ca.lambda_nm = a->lambda_nm;
    memset(&err, 0, sizeof err);
    st = lp_cone_compute(r->lens, a->cone_point, &ca, n, theta, &cone, &err);
    if (st != LP_OK) {
        snprintf(r->msg, sizeof r->msg, "--cone: %s", lib_message(&err, st));
        free(theta);
        return 0;
    }
    for (size_t k = 0; k < n; k++) {
        char az[40];
        fmt_num(az, sizeof az, 360.0 * (double)k / (double)n);
        ob_printf(&r->out, "{\"azimuth\":%s", az);
        ob_num(&r->out, "theta", deg(theta[k]));
        ob_printf(&r->out, "}\n");
    }
    ob_printf(&r->out, "{\"cone\":{\"depth\":%d", cone.depth);
    ob_num(&r->out, "solid_angle", cone.solid_angle);
    ob_num(&r->out, "theta_min", deg(cone.theta_min));
    ob_num(&r->out, "theta_max", deg(cone.theta_max));
    ob_num(&r->out, "lambda", a->lambda_nm);
    ob_vec(&r->out, "axis", cone.frame.axis);
    ob_vec(&r->out, "ref", cone.frame.ref);
    ob_printf(&r->out, "}}\n");
    free(theta);
    return 1;
}

/* Trace r->ray: its ray lines and its summary line into r->out.  0 and
 * r->msg on error. */
static int trace_one(run *r)
{
    static const totals zero;
    const lp_vec3 o = r->ray->o;
    int ok;

    if (lp_lens_contains(r->lens, o)) {
        /* The library's chain starts with the light arriving from the
           surrounding medium; a ray born in the glass would have no first
           interface. */
        snprintf(r->msg, sizeof r->msg,
                 "%s: the origin %.17g,%.17g,%.17g lies inside the glass "
                 "(rays must start in the surrounding medium)",
                 r->where, o.x, o.y, o.z);
        return 0;
    }
    r->sum = zero;
    ok = r->a->backward ? run_backward(r) : run_forward(r);
    if (ok) {
        put_summary(&r->out, &r->sum, r->index);
        r->warnings |= r->sum.warnings;
    }
    return ok;
}

/* The longest line of a --rays file, newline included. */
#define RAYS_LINE_MAX 4096

/* --rays FILE: one ray spec per line (blank lines and lines starting with
 * '#' are skipped), traced in order with index 0, 1, ...  0 and r->msg on
 * error (nothing is kept of the rays before it). */
static int trace_file(run *r)
{
    const char *name = r->a->rays_file;
    int is_stdin = strcmp(name, "-") == 0;
    FILE *f = is_stdin ? stdin : fopen(name, "r");
    const char *shown = is_stdin ? "<stdin>" : name;
    char line[RAYS_LINE_MAX + 1];
    lt_args *scratch = NULL;
    lt_ray_spec ray;
    long lineno = 0;
    int ok = 1;

    r->index = 0;
    if (!f) {
        snprintf(r->msg, sizeof r->msg, "--rays: cannot open %s: %s", name,
                 strerror(errno));
        return 0;
    }
    scratch = malloc(sizeof *scratch);
    if (!scratch) {
        snprintf(r->msg, sizeof r->msg, "out of memory");
        ok = 0;
    }
    while (ok && fgets(line, sizeof line, f)) {
        size_t len = strlen(line);
        const char *p = line;
        lineno++;
        if (len > 0 && line[len - 1] == '\n')
            line[--len] = '\0';
        else if (!feof(f)) {
            snprintf(r->msg, sizeof r->msg, "--rays: %.200s:%ld: line longer "
                     "than %d characters", shown, lineno, RAYS_LINE_MAX - 1);
            ok = 0;
            break;
        }
        if (len > 0 && line[len - 1] == '\r')
            line[--len] = '\0';
        while (*p == ' ' || *p == '\t')
            p++;
        if (*p == '\0' || *p == '#')
            continue;
        lt_args_init(scratch);
        if (lt_parse_ray_spec(scratch, p, &ray)) {
            snprintf(r->msg, sizeof r->msg, "--rays: %.200s:%ld: %s", shown,
                     lineno, scratch->error);
            ok = 0;
            break;
        }
        snprintf(r->where, sizeof r->where, "--rays: %.200s:%ld", shown,
                 lineno);
        r->ray = &ray;
        ok = trace_one(r);
        r->index++;
    }
    if (ok && ferror(f)) {
        snprintf(r->msg, sizeof r->msg, "--rays: cannot read %s: %s", name,
                 strerror(errno));
        ok = 0;
    }
    if (ok && r->index == 0) {
        snprintf(r->msg, sizeof r->msg, "--rays: %s holds no ray spec",
                 shown);
        ok = 0;
    }
    if (!is_stdin)
        fclose(f);
    free(scratch);
    return ok;
}

/* Build the glass of the lens; 0 and r->msg on error. */
static int make_glass(run *r, const lp_catalog *catalog, lp_glass *glass)
{
    const lt_args *a = r->a;
    lp_error err;
    lp_status st;

    memset(&err, 0, sizeof err);
    if (a->lens.glass_constant) {
        lp_glass_init_constant(glass, a->lens.glass_n);
    } else {
        st = lp_catalog_find(catalog, a->lens.glass_name, glass, &err);
        if (st != LP_OK) {
            const char *m = lib_message(&err, st);
            if (strstr(m, a->lens.glass_name))
                snprintf(r->msg, sizeof r->msg, "--lens: %s", m);
            else
                snprintf(r->msg, sizeof r->msg, "--lens: glass '%s': %s",
                         a->lens.glass_name, m);
            return 0;
        }
    }
    st = lp_glass_check(glass, &err);
    if (st != LP_OK) {
        snprintf(r->msg, sizeof r->msg, "--lens: glass: %s",
                 lib_message(&err, st));
        return 0;
    }
    return 1;
}

/* Make the lens a uniaxial crystal; 0 and r->msg on error. */
static int make_crystal(run *r, lp_lens_desc *desc)
{
    const lt_args *a = r->a;
    lp_error err;
    lp_status st = LP_OK;

    memset(&err, 0, sizeof err);
    desc->uniaxial = 1;
    if (a->lens.crystal == 1)
        st = lp_crystal_builtin(a->lens.crystal_name, &desc->crystal, &err);
    else
        lp_crystal_init_constant(&desc->crystal, a->lens.n_o, a->lens.n_e, a->lens.axis);
    if (st == LP_OK) {
        desc->crystal.axis = a->lens.axis;
        st = lp_crystal_check(&desc->crystal, &err);
    }
    if (st != LP_OK) {
        snprintf(r->msg, sizeof r->msg, "--lens: %s", lib_message(&err, st));
        return 0;
    }
    return 1;
}

static int build_and_trace(run *r)
{
    const lt_args *a = r->a;
    lp_catalog *catalog = NULL;
    lp_lens_desc desc;
    lp_lens *lens = NULL;
    lp_error err;
    lp_status st;
    int ok = 0;

    memset(&err, 0, sizeof err);
    if (!a->lens.glass_constant) {
        st = lp_catalog_create(&catalog, &err);
        if (st != LP_OK) {
            snprintf(r->msg, sizeof r->msg, "%s", lib_message(&err, st));
            return 0;
        }
    }
    for (size_t i = 0; i < a->n_catalogs; i++) {
        if (!catalog) {
            /* a constant glass needs no catalog, but a bad --catalog file
               is still an error */
            st = lp_catalog_create(&catalog, &err);
            if (st != LP_OK) {
                snprintf(r->msg, sizeof r->msg, "%s", lib_message(&err, st));
                return 0;
            }
        }
        st = lp_catalog_load_agf(catalog, a->catalogs[i], &err);
        if (st != LP_OK) {
            const char *m = lib_message(&err, st);
            if (strstr(m, a->catalogs[i]))
                snprintf(r->msg, sizeof r->msg, "--catalog: %s", m);
            else
                snprintf(r->msg, sizeof r->msg, "--catalog %s: %s",
                         a->catalogs[i], m);
            goto done;
        }
    }

    lp_lens_desc_init(&desc);
    desc.radius1 = a->lens.r1;
    desc.radius2 = a->lens.r2;
    desc.thickness = a->lens.t;
    desc.diameter = a->lens.d;
    desc.diameter2 = a->lens.d2; /* 0 = not given = D */
    if (a->lens.crystal) {
        if (!make_crystal(r, &desc))
            goto done;
    } else if (!make_glass(r, catalog, &desc.glass))
        goto done;
    lp_glass_init_constant(&desc.medium, a->medium);
    st = lp_glass_check(&desc.medium, &err);
    if (st != LP_OK) {
        snprintf(r->msg, sizeof r->msg, "--medium: %s", lib_message(&err, st));
        goto done;
    }
    st = lp_lens_create(&desc, &lens, &err);
    if (st != LP_OK) {
        snprintf(r->msg, sizeof r->msg, "--lens: %s", lib_message(&err, st));
        goto done;
    }

    r->lens = lens;
    lp_trace_args_init(&r->targs);
    r->targs.mode = a->mode;
    r->targs.max_depth = a->depth;
    if (a->cone) {
        ok = run_cone(r);
    } else if (a->rays_file) {
        ok = trace_file(r);
    } else {
        r->ray = &a->ray;
        r->index = -1;
        snprintf(r->where, sizeof r->where, "--ray");
        ok = trace_one(r);
    }
    if (ok) {
        if (r->out.oom) {
            snprintf(r->msg, sizeof r->msg, "out of memory");
            ok = 0;
        } else if (r->out.bad_key) {
            snprintf(r->msg, sizeof r->msg,
                     "internal error: non-finite value (\"%s\") in the "
                     "library's result", r->out.bad_key);
            ok = 0;
        }
    }
done:
    lp_lens_destroy(lens);
    lp_catalog_destroy(catalog);
    return ok;
}

int main(int argc, char **argv)
{
    lt_args *a = malloc(sizeof *a);
    run r;
    int status = 0;

    if (!a) {
        say(NULL, "out of memory");
        return EXIT_BAD;
    }
    lt_args_init(a);
    if (lt_args_parse(a, argc, argv)) {
        say(NULL, a->error);
        free(a);
        return EXIT_BAD;
    }
    if (a->help || a->version) {
        int rc = a->help ? sp_print_text(usage_text, sizeof usage_text / sizeof *usage_text)
                         : sp_print_version("lenstrace", lp_version_string());
        free(a);
        return rc == 0 ? 0 : EXIT_BAD;
    }

    memset(&r, 0, sizeof r);
    r.a = a;
    if (!build_and_trace(&r)) {
        say(NULL, r.msg);
        status = EXIT_BAD;
    } else {
        if (r.warnings & LP_WARN_EXTRAPOLATED) {
            char m[160];
            if (a->rays_file)
                snprintf(m, sizeof m, "a wavelength lies outside the glass's "
                         "data range; its index was extrapolated (see the "
                         "summaries' warnings)");
            else
                snprintf(m, sizeof m, "lambda %.17g nm lies outside the "
                         "glass's data range; its index was extrapolated",
                         a->ray.lambda_nm);
            say("warning: ", m);
        }
        if (r.warnings & LP_WARN_LEAK)
            say("warning: ", "an internal ray found no surface (numerical); "
                "its energy was counted as absorbed at the rim");
        if (fwrite(r.out.p, 1, r.out.len, stdout) != r.out.len ||
            fflush(stdout) != 0) {
            char m[160];
            snprintf(m, sizeof m, "cannot write the output: %s",
                     strerror(errno));
            say(NULL, m);
            status = EXIT_BAD;
        }
    }
    free(r.out.p);
    free(a);
    return status;
}
