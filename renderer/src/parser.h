/* parser.h -- read a .scene file (POV-Ray's language, subset, plus lens
 * and polarizer objects) into an rs_scene.
 *
 * The scene must have been set up with rs_scene_init; parsing ADDS to it
 * (objects and lights are appended; camera, background and settings are
 * overwritten where the file says so).  On error the scene keeps what was
 * complete before the error and must still be released with
 * rs_scene_free.  Lenses are described, not created: call
 * rs_scene_prepare after parsing.
 *
 * Messages are one line, "FILE:LINE:COL: what", e.g.
 *   "box.scene:3:14: expected '{' after 'sphere', found number 1".
 * LINE and COL are 1-based; COL counts bytes.  A file that cannot be read
 * gives "PATH: cannot read: <reason>".
 *
 * What is accepted (POV-Ray 3.7 meaning unless noted):
 *   #declare / #local NAME = float | vector | colour ;   #version F ;
 *   expressions  + - * / unary -, ( ), <a,b,c>, V.x V.y V.z V.red ...,
 *                x y z pi true false on off yes no image_width image_height,
 *                sqrt sin cos tan asin acos atan atan2 pow abs min max
 *                radians degrees exp ln log floor ceil int mod
 *                vlength vnormalize vdot vcross; a float promotes to
 *                <f,f,f> where a vector is wanted
 *   colours      [color|colour] rgb V | V | red F green F blue F (and an
 *                identifier followed by red/green/blue overrides).  rgbf,
 *                rgbt, rgbft, filter, transmit are refused; so is a lone
 *                non-zero float as a pigment colour (POV-Ray would make it
 *                transparent).
 *   camera { [perspective] location look_at angle right up direction sky
 *            translate rotate scale }            (stored as written)
 *   light_source { V [,] COLOUR [polarization V] [spectrum { blackbody T |
 *            line NM | rgb }] [coherent [on|off | L]] [translate rotate scale] }
 *            (coherent L: coherence length L mm, 0 or none = infinite)
 *   background { COLOUR }
 *   global_settings { max_trace_level N adc_bailout F ambient_light C
 *            assumed_gamma F coherent BOOL }
 *   plane { N [,] D ... }  sphere { C [,] R ... }  box { A [,] B ... }
 *   disc { C [,] N [,] R [, HOLE] ... }
 *     with pigment { COLOUR | checker [C1 [,] [C2]] + transforms },
 *     finish { ambient C diffuse F emission C; specular phong phong_size
 *              brilliance roughness reflection conserve_energy are read
 *              and ignored }, texture { pigment finish transforms },
 *     translate rotate scale
 *   lens { radius1 R radius2 R thickness T diameter D [diameter2 D2]
 *          glass "NAME" | ior N | sellmeier { B1, B2, B3, C1, C2, C3 }
 *          [medium ior N] translate rotate scale }   (R: 0 or inf = flat)
 *   polarizer { [center V] normal V radius F axis V translate rotate scale }
 *
 * A later pigment or finish block modifies the object's current one (a new
 * colour or checker replaces the pattern and its transforms); defaults are
 * POV-Ray's: black pigment, finish ambient 0.1 diffuse 0.6 emission 0;
 * checker without colours is blue then green.  Every number must stay
 * finite: overflowing literals, arithmetic, functions and transform chains
 * are errors.
 *
 * Stored values: plane and disc normals are normalized (the plane is
 * n.x = D with the normalized n, as POV-Ray); box corners are sorted so
 * corner1 <= corner2.  A pigment's to_pattern maps world points to pattern
 * space: the inverse of the pigment's own transforms followed by the
 * object transforms written AFTER the pigment (POV-Ray: transforms before
 * a texture do not move it).  Lens and polarizer transforms are folded
 * into their parameters (only uniform scales); their xf stays identity.
 */
#ifndef RS_PARSER_H
#define RS_PARSER_H

#include <stddef.h>

#include "scene.h"

typedef struct rs_parse_opts {
    int image_width;     /* the value of image_width; <= 0: 640 */
    int image_height;    /* the value of image_height; <= 0: 480 */
    size_t max_objects;  /* objects (and lights) allowed; 0: 100,000 */
    /* Where #include looks after the including file's own directory, in
     * order (POV-Ray's Library_Path); the caller owns the strings. */
    const char *const *include_dirs;
    size_t n_include_dirs;
} rs_parse_opts;

/* All zero: the defaults above. */
void rs_parse_opts_init(rs_parse_opts *opts);

/* Parse the file at path.  opts may be NULL (defaults).  Returns 0, or -1
 * with a message in msg (msg may be NULL). */
int rs_parse_file(const char *path, const rs_parse_opts *opts, rs_scene *scene,
                  char *msg, size_t msg_size);

/* Parse NUL-terminated text; name is used in locations (NULL: "<string>"). */
int rs_parse_string(const char *text, const char *name, const rs_parse_opts *opts,
                    rs_scene *scene, char *msg, size_t msg_size);

#endif
