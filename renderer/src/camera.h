/* camera.h -- POV-Ray 3.7's perspective camera: the keywords of a
 * `camera { ... }` block turned into the four vectors that make the
 * primary rays, with POV-Ray's exact rules (renderer-internal).
 *
 * Conventions (POV-Ray's): left-handed world coordinates, x right, y up,
 * z into the screen; angles in degrees.  Cross products are the ordinary
 * component formula a x b = (ay bz - az by, az bx - ax bz, ax by - ay bx);
 * handedness only shows in which way round they are taken, which is fixed
 * below so that the default camera (direction z, up y, right x) and any
 * look_at camera with sky y see +x on the right of the image and +y at
 * its top.
 *
 * rs_camera_setup applies, whatever the order the keywords were written
 * in (POV-Ray 3.7's Parse_Camera):
 *   1. direction, up, right as given (defaults <0,0,1>, <0,1,0>,
 *      <1.33,0,0>, not adapted to the image's aspect);
 *   2. angle A (full horizontal field of view across right), when given
 *      and A > 0:  D = normalize(D) * |R| / (2 tan(A/2));
 *   3. look_at P, when given, with h = (U x D) . R taken before the
 *      change (the sign of the supplied frame, negative for a mirrored
 *      right):
 *        D = |D| * normalize(P - location)
 *        R' = sky x normalize(D); when that is (near) zero, i.e. D is
 *             parallel to sky, the supplied right is kept instead
 *        U = |U| * (normalize(D) x normalize(R'))
 *        R = (h > 0 ? +1 : -1) * |R| * normalize(R')
 *      (U is taken from R' before the sign, so a mirrored right mirrors
 *      the image left-right only, as in POV-Ray);
 *   4. the camera's transforms (rs_camera.xf when has_xf): location as a
 *      point, D, R and U as directions (sky and look_at are not
 *      transformed again: look_at was applied in step 3).
 *
 * Primary rays (POV-Ray's perspective camera, antialiasing off): pixel
 * column i = 0..W-1 from the left, row j = 0..H-1 from the top, pixel
 * centre px = i + 0.5, py = j + 0.5,
 *   dir = normalize(D + (px/W - 0.5) R + (0.5 - py/H) U), origin = location.
 * Orthographic (`orthographic`): dir = normalize(D) for every pixel,
 *   origin = location + (px/W - 0.5) R + (0.5 - py/H) U.
 *
 * Focal blur (POV-Ray's focal_point and aperture): with aperture A > 0 the
 * camera is a thin lens, a disk of radius A/2 about the location,
 * perpendicular to D, in focus at the distance F = |focal_point -
 * location| (focal_point is transformed with the camera; the surface in
 * focus is the sphere of radius F about the location, as in POV-Ray).  A
 * pixel is the mean of blur_samples rays (default RS_CAMERA_BLUR_SAMPLES),
 * each from a point of the disk through the pixel's point in focus,
 * location + F dir.  The disk points are a deterministic sunflower
 * quadrature of equal areas: sample k of N at radius (A/2) sqrt((k+1/2)/N)
 * and azimuth k times the golden angle (POV-Ray jitters its samples; here
 * a picture is the same on every run).  Aperture 0 (the default) is a
 * pinhole: one ray per pixel, everything in focus.
 */
#ifndef RS_CAMERA_H
#define RS_CAMERA_H

#include <stddef.h>

#include "lensprim.h"
#include "scene.h"

/* The camera ready to make rays: world location and the three world
 * vectors, with their lengths (|D| sets the field of view). */
typedef struct rs_view {
    lp_vec3 location;
    lp_vec3 D;   /* direction: from location to the image centre */
    lp_vec3 R;   /* right: spans the image width, left edge to right edge */
    lp_vec3 U;   /* up: spans the image height, bottom edge to top edge */
    int orthographic; /* rays along D from location + x0 R + y0 U (the
                         image is |R| by |U| scene units), POV-Ray's
                         orthographic camera */
    double lens_radius;    /* aperture / 2; 0: a pinhole */
    double focal_distance; /* |focal_point - location| */
    lp_vec3 lens_x, lens_y; /* unit, spanning the lens disk (perpendicular to D) */
    int samples;           /* rays per pixel: 1 for a pinhole */
} rs_view;

/* Aperture rays per pixel when the scene gives no blur_samples. */
#define RS_CAMERA_BLUR_SAMPLES 16

/* Build *out from the camera keywords *cam by the rules above.  width and
 * height are the image size in pixels (both >= 1); POV-Ray does not adapt
 * the camera to them (write `right x*image_width/image_height`), they are
 * only checked.
 *
 * Returns 0, or -1 with a one-line message in msg (no newline; msg may be
 * NULL when msg_size is 0) and *out untouched, when:
 *   a vector or the angle is not finite; the angle is negative or
 *   >= 180 degrees; direction, right or up is zero (or, after look_at, up
 *   vanishes because the kept right is parallel to the view direction);
 *   location and look_at coincide (|P - location|^2 < 1e-10, POV-Ray's
 *   test); D, R and U are coplanar (every ray would lie in one plane);
 *   width or height < 1; the transform makes the camera degenerate; the
 *   aperture is negative or not finite, or positive with the focal point
 *   at the location; blur_samples is negative. */
int rs_camera_setup(const rs_camera *cam, int width, int height,
                    rs_view *out, char *msg, size_t msg_size);

/* The primary ray through image point (px, py), in pixels from the
 * image's top-left corner (pixel centres at i + 0.5, j + 0.5):
 *   *origin = v->location,
 *   *dir = normalize(D + (px/width - 0.5) R + (0.5 - py/height) U).
 * width and height must be >= 1; *dir is a unit vector for any setup that
 * rs_camera_setup accepted.  Pure: safe from any number of threads. */
void rs_camera_ray(const rs_view *v, double px, double py, int width,
                   int height, lp_vec3 *origin, lp_vec3 *dir);

/* Aperture ray k (0 <= k < v->samples) through image point (px, py): for
 * a pinhole the primary ray above; else from the k-th point of the lens
 * disk towards location + F dir (the rules above).  Pure, as above. */
void rs_camera_aperture_ray(const rs_view *v, double px, double py, int width,
                            int height, int k, lp_vec3 *origin, lp_vec3 *dir);

/* The pixels whose primary ray (rs_camera_ray) may meet the box lo..hi:
 * the rectangle rect[0] <= i < rect[1], rect[2] <= j < rect[3] (perhaps
 * empty) that holds the box's eight corners projected onto the image --
 * through v->location, or along D for an orthographic camera: a ray
 * meets a convex body only through its projection, the hull of the
 * corners' -- widened by a pixel on every side for rounding.  Returns 1,
 * or 0 when it cannot tell (a corner not in front of the camera, or the
 * box or the projection not finite): then any pixel's ray may meet it
 * and rect is the whole image.  Pure. */
int rs_camera_box_pixels(const rs_view *v, int width, int height, lp_vec3 lo, lp_vec3 hi,
                         int rect[4]);

#endif
