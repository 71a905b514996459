/* extinction.h -- the extinction of an empty polarizing microscope against
 * its numerical aperture (tools-internal).
 *
 * Between an ideal polarizer (axis p) and a crossed ideal analyzer
 * (axis a, perpendicular to p) stand the lenses of the condenser and the
 * objective.  A ray parallel to the axis at height h and azimuth phi from
 * p is meridional: at every surface its field splits into p (in the
 * meridional plane) and s (across it) with the Fresnel amplitude
 * transmissions t_p, t_s, power-normalized (|t|^2 n2 cos t / n1 cos i).
 * With P = prod t_p, S = prod t_s over the surfaces and beta the angle
 * the ray leaves at, the field behind the lenses is
 *     E = P cos(phi) p_out - S sin(phi) s_hat,
 * so the analyzer (the field's component along a fixed axis) passes
 *     crossed  = [1/2 sin(2 phi) (P cos(beta) - S)]^2
 *     parallel = [P cos^2(phi) cos(beta) + S sin^2(phi)]^2
 * of a unit input.  The leak of the instrument at numerical aperture NA
 * is the ratio of the crossed to the parallel light summed over a uniform
 * collimated beam (weight h dh dphi) whose rays reach sin(theta) <= NA in
 * their steepest segment (the specimen space between the condenser and
 * the objective).
 *
 * Each point is computed twice: "traced" through the library's polarized
 * forward trace of each lens (the straight-through ray, depth 2: ghosts
 * left out), and "predicted" by the formulas above with the incidence
 * angles of a geometric Snell trace (the library's intersections and
 * normals only).  One function per NA point: the points are independent.
 * No global state; functions return 0, or -1 with a message. */
#ifndef EX_EXTINCTION_H
#define EX_EXTINCTION_H

#include <stddef.h>

#include "lensprim.h"

#define EXT_LENS_MAX 16

typedef struct ext_system {
    lp_lens *lens[EXT_LENS_MAX]; /* owned; in the order the light meets them */
    int n;
    lp_vec3 pol_axis, ana_axis;  /* unit, perpendicular, across the axis */
    double z_start;              /* the polarizer's plane: rays start there */
    double dir_z;                /* -1 or +1: the direction of the light */
    double lambda_nm;            /* in standard air */
} ext_system;

/* The lenses between the two polarizers of a scene whose optical axis is
 * the z axis: the polarizer is the one farther from the camera (the light
 * comes from behind the instrument), the analyzer the nearer.  The rays
 * start in the polarizer's plane travelling towards the analyzer.
 * Refused: not exactly two polarizers, polarizers not normal to z or not
 * crossed, no lens between them, a crystal between them (not an empty
 * instrument), more than EXT_LENS_MAX lenses. */
int ext_system_from_scene(const char *path, double lambda_nm, ext_system *sys, char *msg,
                          size_t msg_size);
void ext_system_free(ext_system *sys);

/* One ray at height h, azimuth phi (radians from the polarizer axis). */
typedef struct ext_ray {
    double s;                  /* the steepest sine along its path */
    double cross_t, par_t;     /* traced: analyzer crossed, parallel */
    double cross_p, par_p;     /* predicted */
} ext_ray;

/* 0, or -1 when the ray is stopped (a rim, total internal reflection) or
 * the library refuses it (msg). */
int ext_ray_compute(const ext_system *sys, double h, double phi, ext_ray *out, char *msg,
                    size_t msg_size);

/* The height of the ray that reaches s = na, by bisection between 0 and
 * h_max (s grows with h); -1 when h_max does not reach na. */
int ext_height_of_na(const ext_system *sys, double na, double h_max, double *h);

/* One point of the chart. */
typedef struct ext_point {
    double na;
    double h;                  /* the height of the rim ray */
    double leak_t, leak_p;     /* aperture leak, traced and predicted */
    double rim_t, rim_p;       /* the rim ray at phi = 45 degrees: crossed/parallel */
} ext_point;

/* The point at na with rings x azimuths rays (midpoint rule in h^2 and in
 * phi: exact in phi for azimuths >= 5, the integrands being trigonometric
 * polynomials of degree 4). */
int ext_point_compute(const ext_system *sys, double na, double h_max, int rings, int azimuths,
                      ext_point *out, char *msg, size_t msg_size);

#endif
