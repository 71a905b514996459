/* scene.h -- the scene a .scene file describes: what lr_scene_description
 * (lensrender/lensrender.h) shows of a loaded scene, and what the
 * renderer itself renders from.
 *
 * The reader fills an rs_scene and checks it (every rule once, with the
 * place it was written); the renderer reads it.  A program using the face
 * only reads a description: the functions at the end that build, prepare
 * or change one are the renderer's own.  POV-Ray meaning throughout:
 * left-handed coordinates (x right, y up, z into the screen), lengths in
 * millimetres for lenses, colours linear RGB.  Transforms are affine maps
 * from object space to world space, composed in the order the keywords
 * appear (POV-Ray: each new transform applies after the ones before it). */
#ifndef RS_SCENE_H
#define RS_SCENE_H

#include <stddef.h>

#include "lensprim.h"
#include "support/colorimetry.h" /* rs_color */

/* x_world = m * x_object + t  (m row-major 3x3), with its inverse. */
typedef struct rs_transform {
    double m[3][3];
    double t[3];
    double inv_m[3][3]; /* inverse of m */
    double inv_t[3];    /* x_object = inv_m * x_world + inv_t */
} rs_transform;

/* Where a construct was written, for messages. */
typedef struct rs_loc {
    const char *file;  /* owned by the scene (rs_scene.files) */
    int line, column;  /* 1-based */
} rs_loc;

typedef enum rs_pigment_type {
    RS_PIGMENT_SOLID = 0,
    RS_PIGMENT_CHECKER
} rs_pigment_type;

typedef struct rs_pigment {
    rs_pigment_type type;
    rs_color color[2];      /* solid: color[0]; checker: the two colours */
    rs_transform to_pattern;/* world -> pattern space: the inverse of the
                               object's and the pigment's own transforms */
} rs_pigment;

/* POV-Ray 3.7's finish, with its formulas (the integrator's shade()):
 * per light of colour C seen in direction L from a point with normal N,
 * viewed along the ray direction D (R = D - 2 (D.N) N, H = unit(L - D)):
 *   diffuse   pigment * C * diffuse * (N.L)^brilliance        (N.L > 0)
 *   phong     C * phong * (R.L)^phong_size                    (R.L > 0)
 *   specular  C * specular * (N.H)^(1/roughness)              (N.H > 0)
 * and a mirror ray along R weighted by the reflectivity: `reflection`
 * as a colour (min = max), or { min, max [fresnel on] }: with fresnel,
 * min + (max - min) * F(theta) where F is the unpolarized Fresnel
 * reflectance from air into an index `ior` (the object's interior). */
typedef struct rs_finish {
    rs_color ambient;       /* POV-Ray default 0.1 */
    double diffuse;         /* POV-Ray default 0.6 */
    double brilliance;      /* default 1 */
    rs_color emission;      /* default 0 */
    double phong;           /* default 0 */
    double phong_size;      /* default 40 */
    double specular;        /* default 0 */
    double roughness;       /* default 0.05 */
    rs_color reflection_min;/* default 0 */
    rs_color reflection_max;/* default 0 */
    int fresnel;            /* reflection { ... fresnel on } */
    int conserve_energy;    /* read: used by lenses only (they conserve) */
} rs_finish;

/* A spectrum of an emitter.  RGB colours become spectra by the method in
 * emitter.h; a LINE is monochromatic (a delta of the given power). */
typedef enum rs_spectrum_type {
    RS_SPECTRUM_RGB = 0,
    RS_SPECTRUM_BLACKBODY,
    RS_SPECTRUM_LINE
} rs_spectrum_type;

typedef struct rs_spectrum {
    rs_spectrum_type type;
    rs_color rgb;           /* RGB: the colour; BLACKBODY/LINE: a tint
                               multiplying the luminance scale (default 1) */
    double temperature_k;   /* BLACKBODY */
    double line_nm;         /* LINE */
} rs_spectrum;

typedef enum rs_object_type {
    RS_OBJ_PLANE = 0,
    RS_OBJ_SPHERE,
    RS_OBJ_BOX,
    RS_OBJ_DISC,
    RS_OBJ_LENS,
    RS_OBJ_POLARIZER,
    RS_OBJ_CYLINDER,
    RS_OBJ_CONE,
    RS_OBJ_TORUS,
    RS_OBJ_CSG
} rs_object_type;

/* The set operations of a CSG object (csg.h): a union or merge inside an
 * intersection or difference is one member of it, so it is kept as a
 * node. */
typedef enum rs_csg_op {
    RS_CSG_UNION = 0,
    RS_CSG_INTERSECTION,
    RS_CSG_DIFFERENCE
} rs_csg_op;

typedef struct rs_object {
    rs_object_type type;
    rs_loc loc;
    /* Geometry in object space (POV-Ray parameters as written). */
    union {
        struct { lp_vec3 normal; double distance; } plane;   /* n.x = d */
        struct { lp_vec3 center; double radius; } sphere;
        struct { lp_vec3 corner1, corner2; } box;
        struct { lp_vec3 center, normal; double radius, hole; } disc;
        struct {
            lp_lens_desc desc;          /* radii, thickness, diameters, glass,
                                           and the placement after transforms */
            char glass_name[LP_GLASS_NAME_MAX]; /* "" when ior/sellmeier given */
        } lens;
        struct { lp_vec3 center, normal, axis; double radius; } polarizer;
        /* cylinder: base, cap, radius; open: no end discs */
        struct { lp_vec3 base, cap; double radius; int open; } cylinder;
        struct { lp_vec3 base, cap; double base_radius, cap_radius; int open; } cone;
        /* torus about the y axis, centred at the origin */
        struct { double major, minor; } torus;
        /* intersection / difference (and a union inside them): the
           members, owned, each with its transforms folded in (csg.h) */
        struct { rs_csg_op op; struct rs_object *members; size_t n_members; } csg;
    } u;
    rs_transform xf;        /* object -> world (identity when none);
                               lenses and polarizers have it folded into
                               their parameters already and keep identity */
    rs_pigment pigment;
    rs_finish finish;
    double ior;             /* interior { ior } (default 1): for fresnel
                               reflection of opaque objects */
    int has_interior;       /* an interior was given (a CSG member without
                               one takes its CSG's) */
    int has_texture;        /* a pigment, finish or texture was given (a
                               union passes its own to children without) */
    int inverse;            /* inside and outside swapped */
    lp_lens *lens;          /* RS_OBJ_LENS: created by rs_scene_prepare */
} rs_object;

typedef struct rs_light {
    rs_loc loc;
    lp_vec3 position;
    rs_color color;         /* POV-Ray's colour (RGB spectrum by default) */
    rs_spectrum spectrum;
    int polarized;          /* 0: natural light */
    lp_vec3 polarization;   /* when polarized: the field direction */
    int coherent;           /* rays from this light add as amplitudes */
    double coherence_length;/* mm; 0 = infinite.  Written `coherent L`.
                               Two rays of the light whose optical paths
                               differ by D interfere with visibility
                               exp(-(D/L)^2). */
} rs_light;

/* The camera keywords as written; camera.c turns them into rays with
 * POV-Ray's exact rules (up, right, angle, then look_at). */
typedef struct rs_camera {
    lp_vec3 location;       /* default <0,0,0> */
    lp_vec3 direction;      /* default <0,0,1> */
    lp_vec3 right;          /* default <1.33,0,0> */
    lp_vec3 up;             /* default <0,1,0> */
    lp_vec3 sky;            /* default <0,1,0> */
    lp_vec3 look_at;
    int has_look_at;
    double angle;           /* degrees */
    int has_angle;
    rs_transform xf;        /* transforms applied to the camera */
    int has_xf;
    int orthographic;       /* rays parallel to direction, from the plane
                               spanned by right and up through location */
    lp_vec3 focal_point;    /* default <0,0,0>: the point in focus */
    double aperture;        /* default 0: a pinhole; else the diameter of
                               the lens disk (camera.h) */
    int blur_samples;       /* aperture rays per pixel; 0: the default */
} rs_camera;

typedef struct rs_settings {
    int max_trace_level;    /* default 5 */
    double adc_bailout;     /* default 1/255 */
    rs_color ambient_light; /* default 1 */
    double assumed_gamma;   /* default 1.0 (read, not used) */
    int coherent;           /* global: same-ch rays add as amplitudes */
} rs_settings;

/* What the reader says besides errors: "FILE:LINE:COL: warning: ..." for
 * what is read but not rendered (and #warning), or #debug's text as is. */
typedef enum rs_message_kind {
    RS_MSG_WARNING = 0,
    RS_MSG_DEBUG
} rs_message_kind;

typedef struct rs_message {
    rs_message_kind kind;
    char *text;             /* owned */
} rs_message;

typedef struct rs_scene {
    rs_camera camera;
    rs_color background;    /* default black */
    rs_settings settings;
    rs_object *objects;
    size_t n_objects, cap_objects;
    rs_light *lights;
    size_t n_lights, cap_lights;
    char **files;           /* names of the files read (for rs_loc) */
    size_t n_files;
    rs_message *messages;   /* warnings and #debug text, in order */
    size_t n_messages;
    lp_catalog *catalog;    /* glasses for lenses */
    struct rs_bvh *bvh;     /* acceleration structure over the objects,
                               built by rs_scene_prepare (bvh.h); NULL
                               before: intersections loop over objects */
} rs_scene;

/* Append a copy of text to the scene's messages.  0, or -1 (no memory). */
int rs_scene_add_message(rs_scene *scene, rs_message_kind kind, const char *text);

/* Identity transform. */
void rs_transform_identity(rs_transform *xf);
/* Apply to a point / direction / normal (object -> world). */
lp_vec3 rs_xf_point(const rs_transform *xf, lp_vec3 p);
lp_vec3 rs_xf_dir(const rs_transform *xf, lp_vec3 d);
lp_vec3 rs_xf_normal(const rs_transform *xf, lp_vec3 n); /* inverse transpose */
/* world -> object */
lp_vec3 rs_xf_inv_point(const rs_transform *xf, lp_vec3 p);
lp_vec3 rs_xf_inv_dir(const rs_transform *xf, lp_vec3 d);
/* out = b after a (first a, then b). */
void rs_transform_compose(const rs_transform *a, const rs_transform *b, rs_transform *out);
/* POV-Ray transforms: translate v; rotate v (degrees about x, then y,
 * then z, left-handed); scale v.  Return 0 when the matrix is singular. */
int rs_transform_translate(rs_transform *xf, lp_vec3 v);
int rs_transform_rotate(rs_transform *xf, lp_vec3 degrees);
int rs_transform_scale(rs_transform *xf, lp_vec3 s);
/* Nonzero when every number of the transform and of its inverse is finite. */
int rs_transform_finite(const rs_transform *xf);

void rs_scene_init(rs_scene *scene);
/* Free everything the scene owns (lenses, catalog, arrays). */
void rs_scene_free(rs_scene *scene);
/* Create the lensprim lenses of all lens objects (after parsing) and the
 * bounding volume hierarchy over all objects; the objects must not change
 * afterwards (call it again if they do).
 * Returns 0, or -1 with a message "file:line:col: ..." in msg. */
int rs_scene_prepare(rs_scene *scene, char *msg, size_t msg_size);

/* The rules every scene obeys, stated once: every number finite; plane,
 * disc, polarizer normals, a polarizer's axis, a lens's axis and a
 * polarized light's field unit vectors (to 1e-9); sphere, disc, cylinder,
 * torus, polarizer radii > 0, cone radii >= 0, 0 <= a disc's hole <
 * its radius; phong_size, roughness and ior > 0; a light's coherence
 * length >= 0; every object placed in a file (line, column >= 1); a lens
 * not yet created one that lp_lens_create accepts; a CSG object has
 * members, each keeping the same rules.  The reader builds only
 * scenes that obey them (it refuses each broken rule where it is written);
 * who builds or changes a scene otherwise calls this.  Returns 0, or -1
 * with "FILE:LINE:COL: what" (or "camera: ..." and the like) in msg. */
int rs_scene_check(const rs_scene *scene, char *msg, size_t msg_size);

/* The helium d line (air wavelength), where catalogs quote n_d. */
#define RS_LAMBDA_D_LINE 587.5618

/* After rs_scene_prepare: replace every lens's glass and medium by
 * constant, lossless indices, their indices at lambda_nm, and recreate the
 * lenses.  For comparisons with renderers that have no dispersion or
 * Beer-Lambert absorption (POV-Ray).  Returns 0, or -1 with a message. */
int rs_scene_freeze_glass(rs_scene *scene, double lambda_nm, char *msg, size_t msg_size);

#endif
