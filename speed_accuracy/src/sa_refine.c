/* sa_refine.c -- a reference converged pixel by pixel (see sa_refine.h). */
#include "sa_refine.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "lensrender/lensrender.h"

static double cpu_now(void)
{
    return (double)clock() / CLOCKS_PER_SEC;
}

/* The largest channel change of pixel k. */
static double change_of(const rs_image *last, long k)
{
    const float *c = &last->rgb[3 * k];
    return fmax(fabs((double)c[0]), fmax(fabs((double)c[1]), fabs((double)c[2])));
}

/* The pixels not yet calm in SA_CALM doublings in a row. */
static long count_open(const unsigned char *calm, long total)
{
    long n = 0;
    for (long k = 0; k < total; k++)
        n += calm[k] < SA_CALM;
    return n;
}

/* One doubling: every open pixel of img rendered with r (one list, the
 * workers made once), its change into last, its calm doublings counted
 * (a NaN change is not calm). */
static int level(const lr_renderer *r, double tol, rs_image *img, rs_image *last,
                 unsigned char *calm, long *renders, char *msg, size_t msg_size)
{
    long total = (long)img->width * img->height, n = 0;
    int *xy = malloc(sizeof *xy * 2 * (size_t)total);
    float *got = malloc(sizeof *got * 3 * (size_t)total);
    lr_error err;
    if (!xy || !got) {
        free(xy);
        free(got);
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    for (long k = 0; k < total; k++)
        if (calm[k] < SA_CALM) {
            xy[2 * n] = (int)(k % img->width);
            xy[2 * n + 1] = (int)(k / img->width);
            n++;
        }
    if (lr_render_pixels(r, xy, (size_t)n, got, NULL, NULL, &err) != LR_OK) {
        snprintf(msg, msg_size, "%s", err.message);
        free(xy);
        free(got);
        return -1;
    }
    for (long m = 0; m < n; m++) {
        size_t k = (size_t)xy[2 * m + 1] * (size_t)img->width + (size_t)xy[2 * m];
        for (int ch = 0; ch < 3; ch++) {
            float v = got[3 * m + ch];
            last->rgb[3 * k + ch] = v - img->rgb[3 * k + ch];
            img->rgb[3 * k + ch] = v;
        }
        calm[k] = change_of(last, (long)k) <= tol ? (unsigned char)(calm[k] + 1) : 0;
    }
    *renders += n;
    free(xy);
    free(got);
    return 0;
}

int sa_refine(const sa_refine_opts *o, rs_image *img, rs_image *last, sa_refine_stats *st,
              char *msg, size_t msg_size)
{
    long total = (long)img->width * img->height;
    double per = o->s_per_pixel_wl > 0.0 ? o->s_per_pixel_wl : 1e-6;
    int n = o->wavelengths;
    lr_scene *scene = NULL;
    lr_error err;
    lr_load_opts lo;
    unsigned char *calm; /* each pixel's calm doublings in a row */

    memset(st, 0, sizeof *st);
    st->wavelengths = n;
    if (!img->rgb || !last->rgb || last->width != img->width || last->height != img->height ||
        (o->before && (!o->before->rgb || o->before->width != img->width ||
                       o->before->height != img->height))) {
        snprintf(msg, msg_size, "sa_refine: images of different sizes");
        return -1;
    }
    /* a pixel calm in the given doubling has one calm doubling, two
     * where it was calm in the one before too */
    calm = malloc((size_t)total + 1);
    if (!calm) {
        snprintf(msg, msg_size, "out of memory");
        return -1;
    }
    for (long k = 0; k < total; k++)
        calm[k] = (unsigned char)(change_of(last, k) <= o->tol
                                      ? 1 + (o->before && change_of(o->before, k) <= o->tol)
                                      : 0); /* NaN: 0 */
    lr_load_opts_init(&lo);
    lo.image_width = img->width;
    lo.image_height = img->height;
    if (lr_scene_load(o->scene, &lo, &scene, &err) != LR_OK) {
        snprintf(msg, msg_size, "%s:%d:%d: %s", err.file, err.line, err.column, err.message);
        free(calm);
        return -1;
    }
    for (;;) {
        long open = count_open(calm, total);
        if (open == 0 || 2 * n > o->wavelengths_max ||
            (double)open * 2.0 * n * per > o->budget)
            break;
        lr_render_opts ro;
        lr_renderer *r;
        lr_render_opts_init(&ro);
        ro.mode = LR_MODE_POLARIZED;
        ro.width = img->width;
        ro.height = img->height;
        ro.depth = o->depth;
        ro.cutoff = o->cutoff;
        ro.wavelengths = 2 * n;
        ro.threads = 1;
        if (lr_renderer_create(scene, &ro, &r, &err) != LR_OK) {
            snprintf(msg, msg_size, "%s", err.message);
            lr_scene_free(scene);
            free(calm);
            return -1;
        }
        double t0 = cpu_now();
        long before = st->renders;
        int rc = level(r, o->tol, img, last, calm, &st->renders, msg, msg_size);
        double dt = cpu_now() - t0;
        lr_renderer_free(r);
        if (rc != 0) {
            lr_scene_free(scene);
            free(calm);
            return -1;
        }
        st->seconds += dt;
        st->levels++;
        n *= 2;
        st->wavelengths = n;
        if (st->renders > before && dt > 0.0)
            per = dt / ((double)(st->renders - before) * n);
    }
    lr_scene_free(scene);
    {
        double s = 0.0;
        for (long k = 0; k < 3 * total; k++)
            s += (double)last->rgb[k] * last->rgb[k];
        st->rmse = sqrt(s / (3.0 * (double)total));
        st->max = 0.0;
        for (long k = 0; k < total; k++)
            st->max = fmax(st->max, change_of(last, k));
        st->left = count_open(calm, total);
    }
    free(calm);
    return 0;
}
