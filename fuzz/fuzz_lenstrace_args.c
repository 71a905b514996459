/* fuzz_lenstrace_args.c -- libFuzzer target: lenstrace's command line.
 *
 * The input is split at newlines into argv words (argv[0] = "lenstrace";
 * an embedded NUL ends its word, so "--ray=o=0,0,0 d=0,0,1" is one word
 * with its spaces).  lt_args_parse runs on them; when they parse, the lens
 * is built and the ray traced (forward or backward) exactly as lenstrace
 * does, except that --catalog files are not read (fuzz_agf covers AGF
 * text).  The whole input is also given to lt_parse_lens_spec and
 * lt_parse_ray_spec directly.  Whatever parses must satisfy the
 * documented postconditions of lenstrace_args.h, else abort(). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "lensprim.h"
#include "lenstrace_args.h"

#define MAX_WORDS 64

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void require(int cond)
{
    if (!cond)
        abort();
}

static int is_unit(lp_vec3 v)
{
    double l = v.x * v.x + v.y * v.y + v.z * v.z;
    return isfinite(l) && fabs(l - 1.0) < 1e-12;
}

static void check_lens(const lt_lens_spec *s)
{
    require(!isnan(s->r1) && !isnan(s->r2));
    require(isfinite(s->t) && s->t > 0.0);
    require(isfinite(s->d) && s->d > 0.0);
    require(isfinite(s->d2) && s->d2 >= 0.0);
    if (s->glass_constant)
        require(isfinite(s->glass_n) && s->glass_n > 0.0);
    else
        require(s->glass_name[0] != '\0' &&
                memchr(s->glass_name, '\0', sizeof s->glass_name) != NULL);
}

static void check_ray(const lt_ray_spec *r)
{
    require(isfinite(r->o.x) && isfinite(r->o.y) && isfinite(r->o.z));
    require(is_unit(r->d));
    require(isfinite(r->lambda_nm) && r->lambda_nm > 0.0);
    require(isfinite(r->intensity) && r->intensity >= 0.0);
    if (!r->unpolarized) {
        require(is_unit(r->vp));
        require(fabs(r->vp.x * r->d.x + r->vp.y * r->d.y + r->vp.z * r->d.z) < 1e-9);
    }
}

/* What lenstrace's build_and_trace does, without --catalog files. */
static void build_and_trace(const lt_args *a)
{
    lp_catalog *catalog = NULL;
    lp_lens_desc desc;
    lp_lens *lens = NULL;
    lp_trace_args targs;
    lp_result res;
    lp_error err;
    double n_air = lp_air_index(a->ray.lambda_nm), lambda_air;
    int halves = a->ray.unpolarized ? 2 : 1;

    if (!isfinite(n_air))
        return;
    lambda_air = a->ray.lambda_nm / n_air;
    lp_lens_desc_init(&desc);
    desc.radius1 = a->lens.r1;
    desc.radius2 = a->lens.r2;
    desc.thickness = a->lens.t;
    desc.diameter = a->lens.d;
    desc.diameter2 = a->lens.d2;
    if (a->lens.glass_constant) {
        lp_glass_init_constant(&desc.glass, a->lens.glass_n);
    } else {
        if (lp_catalog_create(&catalog, &err) != LP_OK)
            return;
        if (lp_catalog_find(catalog, a->lens.glass_name, &desc.glass, &err) != LP_OK)
            goto done;
    }
    if (lp_glass_check(&desc.glass, &err) != LP_OK)
        goto done;
    lp_glass_init_constant(&desc.medium, a->medium);
    if (lp_glass_check(&desc.medium, &err) != LP_OK)
        goto done;
    if (lp_lens_create(&desc, &lens, &err) != LP_OK)
        goto done;

    lp_trace_args_init(&targs);
    targs.mode = a->mode;
    targs.max_depth = a->depth;
    lp_result_init(&res);
    if (!a->backward) {
        for (int h = 0; h < halves; h++) {
            lp_ray in;
            memset(&in, 0, sizeof in);
            in.origin = a->ray.o;
            in.dir = a->ray.d;
            in.lambda_nm = lambda_air;
            in.intensity = a->ray.intensity / halves;
            in.vp = a->ray.unpolarized
                        ? (h == 0 ? lt_perpendicular(a->ray.d)
                                  : lt_cross(a->ray.d, lt_perpendicular(a->ray.d)))
                        : a->ray.vp;
            in.ch = a->ray.ch;
            if (lp_trace_forward(lens, &in, &targs, &res, &err) != LP_OK)
                break;
        }
    } else {
        lp_backward *bw = NULL;
        if (lp_backward_create(&bw, &err) == LP_OK &&
            lp_backward_build(bw, lens, a->ray.o, a->ray.d, lambda_air, &targs, &err) ==
                LP_OK) {
            size_t nq = lp_backward_query_count(bw);
            const lp_query *qs = lp_backward_queries(bw);
            for (size_t q = 0; q < nq; q++) {
                lp_ray b;
                lp_vec3 back = {-qs[q].dir.x, -qs[q].dir.y, -qs[q].dir.z};
                memset(&b, 0, sizeof b);
                b.origin = qs[q].origin;
                b.dir = back;
                b.lambda_nm = lambda_air;
                b.intensity = a->ray.intensity;
                b.ch = a->ray.ch;
                if (a->ray.unpolarized || !lt_perpendicular_part(a->ray.vp, back, &b.vp))
                    b.vp = lt_perpendicular(back);
                if (lp_backward_gather(bw, q, &b, 1, &res, &err) != LP_OK)
                    break;
            }
        }
        lp_backward_destroy(bw);
    }
    lp_result_release(&res);
done:
    lp_lens_destroy(lens);
    lp_catalog_destroy(catalog);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    char *argv[MAX_WORDS + 1];
    int argc = 0;
    lt_args *a = malloc(sizeof *a);
    lt_lens_spec ls;
    lt_ray_spec rs;

    if (text == NULL || a == NULL) {
        free(text);
        free(a);
        return 0;
    }
    memcpy(text, data, size);
    text[size] = '\0';

    /* The specs on the whole input. */
    lt_args_init(a);
    if (lt_parse_lens_spec(a, text, &ls) == NULL)
        check_lens(&ls);
    else
        require(a->error[0] != '\0');
    lt_args_init(a);
    if (lt_parse_ray_spec(a, text, &rs) == NULL)
        check_ray(&rs);
    else
        require(a->error[0] != '\0');

    /* The command line: one word per line. */
    argv[argc++] = "lenstrace";
    for (char *p = text; argc < MAX_WORDS && p < text + size;) {
        char *nl = memchr(p, '\n', (size_t)(text + size - p));
        if (nl != NULL)
            *nl = '\0';
        argv[argc++] = p;
        if (nl == NULL)
            break;
        p = nl + 1;
    }
    argv[argc] = NULL;
    lt_args_init(a);
    if (lt_args_parse(a, argc, argv) != NULL) {
        require(a->error[0] != '\0' && memchr(a->error, '\n', strlen(a->error)) == NULL);
    } else if (!a->help && !a->version) {
        check_lens(&a->lens);
        check_ray(&a->ray);
        require(a->depth >= 1 && a->depth <= LP_MAX_DEPTH);
        require(isfinite(a->medium) && a->medium > 0.0);
        build_and_trace(a);
    }
    free(a);
    free(text);
    return 0;
}
