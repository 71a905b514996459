/* render_check.c -- see render_check.h. */
#include "render_check.h"

#include <stdio.h>
#include <stdlib.h>

#include "parser.h"
#include "support/tiles.h"

typedef struct job {
    const rs_integrator *it;
    picture *pic;
    const unsigned char *mask; /* NULL: every pixel */
} job;

static void *job_worker_make(void *user)
{
    const job *j = user;
    return rs_worker_create(j->it);
}

static void job_worker_free(void *w)
{
    rs_worker_destroy(w);
}

static void job_tile(void *user, void *worker, int x0, int y0, int x1, int y1)
{
    const job *jb = user;
    for (int j = y0; j < y1; j++)
        for (int i = x0; i < x1; i++) {
            size_t k = (size_t)j * (size_t)jb->pic->w + (size_t)i;
            rs_color c = {0, 0, 0};
            if (!jb->mask || jb->mask[k])
                rs_integrator_pixel(jb->it, worker, i, j, &c);
            jb->pic->rgb[3 * k + 0] = c.r;
            jb->pic->rgb[3 * k + 1] = c.g;
            jb->pic->rgb[3 * k + 2] = c.b;
        }
}

int rc_load_scene(rs_scene *sc, const char *text, const char *path, int w, int h)
{
    char msg[1024] = "";
    rs_parse_opts po;
    rs_parse_opts_init(&po);
    po.image_width = w;
    po.image_height = h;
    int rc = text ? rs_parse_string(text, "<test>", &po, sc, msg, sizeof msg)
                  : rs_parse_file(path, &po, sc, msg, sizeof msg);
    if (rc != 0 || rs_scene_prepare(sc, msg, sizeof msg) != 0) {
        fprintf(stderr, "scene: %s\n", msg);
        return -1;
    }
    return 0;
}

int rc_render(const rs_scene *sc, rs_mode mode, int w, int h, int depth, double cutoff,
              int wavelengths, const unsigned char *mask, picture *pic)
{
    char msg[1024] = "";
    rs_render_opts o;
    rs_integrator *it = NULL;
    rs_render_opts_init(&o);
    o.mode = mode;
    o.width = w;
    o.height = h;
    o.depth = depth;
    o.cutoff = cutoff;
    if (wavelengths > 0)
        o.wavelengths = wavelengths;
    pic->w = w;
    pic->h = h;
    pic->rgb = calloc((size_t)3 * (size_t)w * (size_t)h, sizeof *pic->rgb);
    if (!pic->rgb)
        return -1;
    if (rs_integrator_create(sc, &o, &it, msg, sizeof msg) != 0) {
        fprintf(stderr, "integrator: %s\n", msg);
        return -1;
    }
    job jb = {it, pic, mask};
    int rc = rs_render_tiles(w, h, 16, 2, job_worker_make, job_worker_free, job_tile, &jb, -1);
    rs_integrator_destroy(it);
    return rc;
}

double rc_px(const picture *p, int i, int j, int c)
{
    return p->rgb[3 * ((size_t)j * (size_t)p->w + (size_t)i) + (size_t)c];
}

double rc_luminance(const picture *p, int i, int j)
{
    return 0.2126 * rc_px(p, i, j, 0) + 0.7152 * rc_px(p, i, j, 1) + 0.0722 * rc_px(p, i, j, 2);
}

int rc_parabola_min(const double *x, const double *y, int n, double *xv, double *yv)
{
    /* y = a + b t + c t^2, t = x - x0 (x0 the middle abscissa), by the
     * normal equations, solved by Cramer's rule */
    double x0 = x[n / 2], s[5] = {0}, sy[3] = {0};
    if (n < 3)
        return -1;
    for (int q = 0; q < n; q++) {
        double t = x[q] - x0, tp = 1.0;
        for (int e = 0; e < 5; e++) {
            s[e] += tp;
            if (e < 3)
                sy[e] += tp * y[q];
            tp *= t;
        }
    }
    double m[3][3] = {{s[0], s[1], s[2]}, {s[1], s[2], s[3]}, {s[2], s[3], s[4]}};
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                 m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    double db = m[0][0] * (sy[1] * m[2][2] - m[1][2] * sy[2]) -
                sy[0] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                m[0][2] * (m[1][0] * sy[2] - sy[1] * m[2][0]);
    double dc = m[0][0] * (m[1][1] * sy[2] - sy[1] * m[2][1]) -
                m[0][1] * (m[1][0] * sy[2] - sy[1] * m[2][0]) +
                sy[0] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (!(det != 0.0) || !(dc / det > 0.0))
        return -1;
    double a = (sy[0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                m[0][1] * (sy[1] * m[2][2] - m[1][2] * sy[2]) +
                m[0][2] * (sy[1] * m[2][1] - m[1][1] * sy[2])) / det;
    double b = db / det, c = dc / det, t = -b / (2.0 * c);
    *xv = x0 + t;
    if (yv)
        *yv = a + b * t + c * t * t;
    return 0;
}
