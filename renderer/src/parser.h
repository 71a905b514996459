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
 *   directives   (directive.c) #include "F" (beside the including file,
 *                then in include_dirs), #declare / #local NAME = VALUE [;]
 *                of every kind below, #undef, #version F;, #if / #elseif /
 *                #else / #end, #ifdef / #ifndef (NAME), #while (F),
 *                #switch (F) #case (F) #range (LO, HI) #break #else,
 *                #macro NAME (P, ...) ... #end and calls NAME (ARG, ...),
 *                #debug / #warning / #error "TEXT"
 *   values       float, vector (3 to 5 components), colour (5: r g b filter
 *                transmit), string, pigment { }, finish { }, texture { },
 *                interior { }, and objects (any object statement below,
 *                light_source too); a float, vector or string declaration
 *                ends with ';'
 *   expressions  + - * / unary - + !, ( ), < > <= >= = != & | ?:, <a,b,c[,d[,e]]>,
 *                V.x V.y V.z V.u V.v V.red V.green V.blue V.filter V.transmit
 *                V.t, x y z pi true false on off yes no clock (0) version
 *                image_width image_height, sqrt sin cos tan asin acos atan
 *                atan2 pow abs min max radians degrees exp ln log floor ceil
 *                int mod div select vlength vnormalize vdot vcross strlen;
 *                strings "..." concat str chr; a float promotes to all
 *                components where a vector is wanted.  '<' compares only
 *                after a float and '>' only outside a vector literal (or in
 *                parentheses), so "box { <0,0,0> <1,1,1> }" still reads.
 *   colours      [color|colour] rgb V | rgbf V | rgbt V | rgbft V | V, then
 *                red green blue filter transmit F.  A pigment must be opaque
 *                (filter = transmit = 0): transparency is refused (a lone
 *                float V sets filter and transmit too, as in POV-Ray).
 *   camera { [perspective|orthographic] location look_at angle right up
 *            direction sky translate rotate scale }  (stored as written;
 *            angle with orthographic is refused)
 *   light_source { V [,] COLOUR [polarization V] [spectrum { blackbody T |
 *            line NM | rgb }] [coherent [on|off | L]] [translate rotate scale] }
 *            (coherent L: coherence length L mm, 0 or none = infinite)
 *   background { COLOUR }
 *   global_settings { max_trace_level N adc_bailout F ambient_light C
 *            assumed_gamma F (a value other than 1 warns) coherent BOOL }
 *   plane { N [,] D ... }  sphere { C [,] R ... }  box { A [,] B ... }
 *   disc { C [,] N [,] R [, HOLE] ... }  cylinder { A, B, R [open] ... }
 *   cone { A, RA, B, RB [open] ... }  torus { MAJOR, MINOR ... }
 *   object { NAME | OBJECT  modifiers }  union / merge { objects modifiers }
 *     (kept as separate objects; a union's texture goes to the members
 *     without one; lenses and polarizers are refused inside)
 *   intersection / difference { objects modifiers }: one RS_OBJ_CSG (csg.h)
 *     of planes, spheres, boxes, cylinders, cones, tori and CSG (a union
 *     inside is one member); the objects first, then the modifiers
 *     (pigment, finish, texture, interior, inverse, transforms); a member
 *     without a texture or interior takes its CSG's; lenses, polarizers
 *     and discs are refused inside
 *     with pigment { NAME | COLOUR | checker [C1 [,] [C2]] + transforms },
 *     finish { NAME ambient C diffuse F brilliance F emission C phong F
 *              phong_size F specular F roughness F reflection F | C |
 *              { [C_MIN,] C_MAX [fresnel [BOOL]] } conserve_energy;
 *              metallic, crand and reflection's falloff, exponent and
 *              metallic are read and warned about }, texture { NAME
 *              pigment finish transforms }, interior { NAME ior F },
 *     inverse, translate rotate scale
 *   lens { radius1 R radius2 R thickness T diameter D [diameter2 D2]
 *          glass "NAME" | ior N | sellmeier { B1, B2, B3, C1, C2, C3 }
 *          [medium ior N] translate rotate scale }   (R: 0 or inf = flat)
 *   polarizer { [center V] normal V radius F axis V translate rotate scale }
 *
 * Warnings (rs_scene.messages, "FILE:LINE:COL: warning: ..."): whatever is
 * read but not rendered, #warning, and a scene with no objects.
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
    /* Tokens the whole parse may read, loops and macro bodies counted each
     * time (an endless #while ends with an error); 0: 20,000,000. */
    unsigned long long max_tokens;
    /* Nonzero: #include is refused ("include files are off"): the scene is
     * read from the text alone, no file is opened. */
    int no_include;
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
