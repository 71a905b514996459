/* camera.c -- POV-Ray 3.7's perspective camera (see camera.h for the
 * rules and their order). */
#include "camera.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

#include "support/vec.h"

/* POV-Ray's small number for its camera tests (EPSILON in its sources). */
#define RS_CAMERA_EPSILON 1.0e-10
/* Relative size under which D, R, U count as coplanar. */
#define RS_CAMERA_COPLANAR 1.0e-12

static const double rs_camera_pi = 3.14159265358979323846;

static int fail(char *msg, size_t msg_size, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static int fail(char *msg, size_t msg_size, const char *fmt, ...)
{
    if (msg && msg_size > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, msg_size, fmt, ap);
        va_end(ap);
    }
    return -1;
}

/* The checks every finished frame must pass (before and after the
 * camera's transform). */
static int check_frame(const rs_view *v, const char *when, char *msg,
                       size_t msg_size)
{
    double ld, lr, lu, vol;
    if (!v3_finite(v->location) || !v3_finite(v->D) || !v3_finite(v->R) ||
        !v3_finite(v->U))
        return fail(msg, msg_size, "camera: the camera vectors are not finite%s",
                    when);
    ld = v3_len(v->D);
    lr = v3_len(v->R);
    lu = v3_len(v->U);
    if (!(ld > 0.0))
        return fail(msg, msg_size, "camera: the direction vector is zero%s", when);
    if (!(lr > 0.0))
        return fail(msg, msg_size, "camera: the right vector is zero%s", when);
    if (!(lu > 0.0))
        return fail(msg, msg_size,
                    "camera: the up vector is zero%s (with look_at: the right "
                    "vector is parallel to the view direction; set sky)",
                    when);
    vol = v3_dot(v->D, v3_cross(v->R, v->U));
    if (!(fabs(vol) > RS_CAMERA_COPLANAR * ld * lr * lu))
        return fail(msg, msg_size,
                    "camera: direction, right and up are coplanar%s, so the "
                    "image has no area", when);
    return 0;
}

int rs_camera_setup(const rs_camera *cam, int width, int height,
                    rs_view *out, char *msg, size_t msg_size)
{
    rs_view v;

    if (!cam || !out)
        return fail(msg, msg_size, "camera: no camera");
    if (width < 1 || height < 1)
        return fail(msg, msg_size, "camera: image size %d x %d is not positive",
                    width, height);
    if (!v3_finite(cam->location) || !v3_finite(cam->direction) ||
        !v3_finite(cam->right) || !v3_finite(cam->up) || !v3_finite(cam->sky) ||
        (cam->has_look_at && !v3_finite(cam->look_at)))
        return fail(msg, msg_size, "camera: a camera vector is not finite");

    v.location = cam->location;
    v.D = cam->direction;
    v.R = cam->right;
    v.U = cam->up;

    /* 1. up and right as given. */
    if (!(v3_len(v.R) > 0.0))
        return fail(msg, msg_size, "camera: the right vector is zero");
    if (!(v3_len(v.U) > 0.0))
        return fail(msg, msg_size, "camera: the up vector is zero");
    if (!(v3_len(v.D) > 0.0))
        return fail(msg, msg_size, "camera: the direction vector is zero");

    /* 2. angle: the full horizontal field of view across right. */
    if (cam->has_angle) {
        if (!isfinite(cam->angle))
            return fail(msg, msg_size, "camera: the angle is not finite");
        if (cam->angle < 0.0)
            return fail(msg, msg_size, "camera: negative viewing angle %g",
                        cam->angle);
        if (cam->angle >= 180.0)
            return fail(msg, msg_size,
                        "camera: viewing angle %g must be smaller than 180 "
                        "degrees", cam->angle);
        if (cam->angle > 0.0) {
            double half = cam->angle * (rs_camera_pi / 360.0);
            /* evaluated in POV-Ray's order, for bit-equal vectors */
            double dir_len = v3_len(v.R) / tan(half) / 2.0;
            v.D = v3_scale(v3_unit(v.D), dir_len);
        }
    }

    /* 3. look_at. */
    if (cam->has_look_at) {
        double len_d = v3_len(v.D), len_u = v3_len(v.U), len_r = v3_len(v.R);
        /* The sign of the supplied frame: (U x D) . R > 0 for the default
         * camera, < 0 for a mirrored right. */
        double handed = v3_dot(v3_cross(v.U, v.D), v.R);
        lp_vec3 to = v3_sub(cam->look_at, cam->location);
        lp_vec3 d_hat, r_new, r_hat;
        if (v3_dot(to, to) < RS_CAMERA_EPSILON)
            return fail(msg, msg_size,
                        "camera: location and look_at must be different");
        d_hat = v3_unit(to);
        r_new = v3_cross(cam->sky, d_hat);
        if (fabs(r_new.x) < RS_CAMERA_EPSILON &&
            fabs(r_new.y) < RS_CAMERA_EPSILON &&
            fabs(r_new.z) < RS_CAMERA_EPSILON)
            r_new = v.R; /* D parallel to sky: POV-Ray keeps the right */
        r_hat = v3_unit(r_new);
        v.U = v3_scale(v3_cross(d_hat, r_hat), len_u);
        v.D = v3_scale(d_hat, len_d);
        v.R = v3_scale(r_hat, handed > 0.0 ? len_r : -len_r);
    }

    if (check_frame(&v, "", msg, msg_size) != 0)
        return -1;

    /* 4. the camera's own transforms. */
    if (cam->has_xf) {
        v.location = rs_xf_point(&cam->xf, v.location);
        v.D = rs_xf_dir(&cam->xf, v.D);
        v.R = rs_xf_dir(&cam->xf, v.R);
        v.U = rs_xf_dir(&cam->xf, v.U);
        if (check_frame(&v, " after the camera's transforms", msg, msg_size) != 0)
            return -1;
    }

    v.orthographic = cam->orthographic;
    /* 5. focal blur. */
    v.lens_radius = 0.0;
    v.focal_distance = 0.0;
    v.lens_x = v3_unit(v.R);
    v.lens_y = v3_unit(v.U);
    v.samples = 1;
    if (!isfinite(cam->aperture) || cam->aperture < 0.0)
        return fail(msg, msg_size, "camera: the aperture %g is not a finite size >= 0",
                    cam->aperture);
    if (cam->blur_samples < 0)
        return fail(msg, msg_size, "camera: blur_samples %d is negative", cam->blur_samples);
    if (cam->aperture > 0.0 && cam->orthographic)
        return fail(msg, msg_size, "camera: focal blur (aperture) with an orthographic camera "
                                   "is not supported");
    if (cam->aperture > 0.0) {
        lp_vec3 fp = cam->has_xf ? rs_xf_point(&cam->xf, cam->focal_point) : cam->focal_point;
        lp_vec3 dh = v3_unit(v.D), x;
        if (!v3_finite(fp))
            return fail(msg, msg_size, "camera: the focal point is not finite");
        v.focal_distance = v3_len(v3_sub(fp, v.location));
        if (!(v.focal_distance > RS_CAMERA_EPSILON * (1.0 + v3_len(v.location))))
            return fail(msg, msg_size,
                        "camera: with an aperture the focal point must differ from the "
                        "location");
        x = v3_sub(v.R, v3_scale(dh, v3_dot(v.R, dh)));
        if (!(v3_len(x) > 0.0))
            x = v3_sub(v.U, v3_scale(dh, v3_dot(v.U, dh)));
        v.lens_x = v3_unit(x);
        v.lens_y = v3_cross(dh, v.lens_x);
        v.lens_radius = 0.5 * cam->aperture;
        v.samples = cam->blur_samples > 0 ? cam->blur_samples : RS_CAMERA_BLUR_SAMPLES;
    }

    *out = v;
    return 0;
}

void rs_camera_ray(const rs_view *v, double px, double py, int width,
                   int height, lp_vec3 *origin, lp_vec3 *dir)
{
    double x0 = px / (double)width - 0.5;
    double y0 = 0.5 - py / (double)height;
    if (v->orthographic) {
        *origin = v3_add(v3_add(v->location, v3_scale(v->R, x0)), v3_scale(v->U, y0));
        *dir = v3_unit(v->D);
        return;
    }
    lp_vec3 d = v3_add(v3_add(v->D, v3_scale(v->R, x0)), v3_scale(v->U, y0));
    *origin = v->location;
    *dir = v3_unit(d);
}

static double det3(lp_vec3 a, lp_vec3 b, lp_vec3 c)
{
    return v3_dot(a, v3_cross(b, c));
}

int rs_camera_box_pixels(const rs_view *v, int width, int height, lp_vec3 lo, lp_vec3 hi,
                         int rect[4])
{
    double det = det3(v->R, v->U, v->D), xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY,
           ymax = -INFINITY;
    rect[0] = 0, rect[1] = width, rect[2] = 0, rect[3] = height;
    if (!(fabs(det) > 0.0) || !isfinite(det))
        return 0;
    for (int c = 0; c < 8; c++) {
        lp_vec3 p = v3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
        lp_vec3 w = v3_sub(p, v->location);
        /* w = a R + b U + s D (Cramer) */
        double a = det3(w, v->U, v->D) / det, b = det3(v->R, w, v->D) / det;
        if (!v->orthographic) {
            double s = det3(v->R, v->U, w) / det;
            if (!(s > 0.0))
                return 0; /* on or behind the camera's plane */
            a /= s;
            b /= s;
        }
        /* x0 = a = px / width - 0.5, y0 = b = 0.5 - py / height */
        double px = (a + 0.5) * width, py = (0.5 - b) * height;
        if (!isfinite(px) || !isfinite(py))
            return 0;
        xmin = fmin(xmin, px), xmax = fmax(xmax, px);
        ymin = fmin(ymin, py), ymax = fmax(ymax, py);
    }
    /* pixel i's ray is at px = i + 0.5 */
    double i0 = floor(xmin - 0.5) - 1.0, i1 = ceil(xmax - 0.5) + 2.0;
    double j0 = floor(ymin - 0.5) - 1.0, j1 = ceil(ymax - 0.5) + 2.0;
    rect[0] = (int)fmax(0.0, fmin((double)width, i0));
    rect[1] = (int)fmax(0.0, fmin((double)width, i1));
    rect[2] = (int)fmax(0.0, fmin((double)height, j0));
    rect[3] = (int)fmax(0.0, fmin((double)height, j1));
    return 1;
}

void rs_camera_aperture_ray(const rs_view *v, double px, double py, int width,
                            int height, int k, lp_vec3 *origin, lp_vec3 *dir)
{
    /* the golden angle, pi (3 - sqrt 5) */
    const double golden = rs_camera_pi * (3.0 - 2.2360679774997896964);
    lp_vec3 o, d, focus, a;
    double r, phi;
    rs_camera_ray(v, px, py, width, height, &o, &d);
    if (v->samples <= 1 || !(v->lens_radius > 0.0)) {
        *origin = o;
        *dir = d;
        return;
    }
    focus = v3_add(o, v3_scale(d, v->focal_distance));
    r = v->lens_radius * sqrt((k + 0.5) / v->samples);
    phi = golden * k;
    a = v3_add(v3_scale(v->lens_x, r * cos(phi)), v3_scale(v->lens_y, r * sin(phi)));
    *origin = v3_add(o, a);
    *dir = v3_unit(v3_sub(focus, *origin));
}
