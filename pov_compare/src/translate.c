/* translate.c -- a parsed .scene as a POV-Ray 3.7 scene (see translate.h).
 *
 * The rules follow POV-Ray 3.7's measured behaviour:
 *   - `#version 3.7;` first, assumed_gamma 1, adc_bailout 0 (depth alone
 *     decides); every finish written out in full as the scene holds it
 *     (ambient, diffuse, brilliance, emission, phong, phong_size, specular,
 *     roughness, reflection with its fresnel flag, and the object's ior
 *     when fresnel needs it), so that no default of either program
 *     decides anything; what the scene reader warned about (read but not
 *     rendered) becomes a note;
 *   - lenses as CSG from lens.inc, the interior on the CSG parent, clear
 *     glass `rgbf 1` with exact Fresnel reflection and conserve_energy;
 *   - no object may contain the camera: a plane, sphere or box whose
 *     inside holds the camera is turned inside out (plane normal and
 *     distance negated, `inverse` for spheres and boxes).  Our objects are
 *     all opaque, so this changes nothing that can be seen, while POV-Ray
 *     would otherwise compute Fresnel at every lens exit face with the
 *     wrong outside index.  A lens on the far side of an opaque object
 *     cannot be seen at all, so the camera alone decides; a lens that
 *     crosses such a surface gets a note.  (Discs do not count: measured,
 *     POV-Ray 3.7 gives the same lens transmission with the camera on
 *     either side of a disc.)
 *   - the whole scene magnified by a power of ten (pc_pov_scale), so that
 *     POV-Ray's fixed near cut-off of 1e-4 units does not swallow thin air
 *     gaps between lenses.
 *
 * No state: everything lives on the stack or in the caller's objects. */
#include "translate.h"

#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "lensrender/lensrender.h"
#include "support/vec.h"

#define PC_PI 3.14159265358979323846
/* pc_pov_scale's largest factor.  Rays bent by a lens can travel far
 * beyond the scene's bounding box (grazing reflections reached boards
 * 1e4-6e4 mm away in our scenes), and POV-Ray drops hits beyond 1e7 units:
 * a factor of 100 keeps 1e5 mm in reach while lifting the 1e-4 near
 * cut-off to 1e-6 mm (measured: Newton's rings 59.7 dB against POV-Ray at
 * 100, 39.0 dB at 1; at 1000, grazing reflections were lost). */
#define PC_POV_MAX_SCALE 1e2
#define PC_POV_SCALED_EXTENT 1e6  /* ... and the extent it aims below */

/* ---- notes ------------------------------------------------------------ */

void pc_notes_free(pc_notes *notes)
{
    if (notes == NULL)
        return;
    for (size_t i = 0; i < notes->n; i++)
        free(notes->text[i]);
    free(notes->text);
    notes->text = NULL;
    notes->n = notes->cap = 0;
}

int pc_notes_add(pc_notes *notes, const char *text)
{
    if (notes == NULL || text == NULL)
        return -1;
    for (size_t i = 0; i < notes->n; i++)
        if (strcmp(notes->text[i], text) == 0)
            return 0;
    if (notes->n == notes->cap) {
        size_t cap = notes->cap ? 2 * notes->cap : 8;
        char **t = realloc(notes->text, cap * sizeof *t);
        if (t == NULL)
            return -1;
        notes->text = t;
        notes->cap = cap;
    }
    size_t len = strlen(text);
    char *copy = malloc(len + 1);
    if (copy == NULL)
        return -1;
    memcpy(copy, text, len + 1);
    notes->text[notes->n++] = copy;
    return 0;
}

/* ---- small helpers ------------------------------------------------------ */

static int fail(char *msg, size_t msg_size, const char *fmt, ...)
{
    if (msg != NULL && msg_size > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, msg_size, fmt, ap);
        va_end(ap);
    }
    return -1;
}

static int fail_at(char *msg, size_t msg_size, const rs_loc *loc, const char *what)
{
    if (loc != NULL && loc->file != NULL)
        return fail(msg, msg_size, "%s:%d:%d: %s", loc->file, loc->line, loc->column, what);
    return fail(msg, msg_size, "%s", what);
}

static int xf_is_identity(const rs_transform *xf)
{
    for (int i = 0; i < 3; i++) {
        if (xf->t[i] != 0.0)
            return 0;
        for (int j = 0; j < 3; j++)
            if (xf->m[i][j] != (i == j ? 1.0 : 0.0))
                return 0;
    }
    return 1;
}

/* The inverse map as a transform of its own. */
static rs_transform xf_inverse(const rs_transform *xf)
{
    rs_transform r;
    memcpy(r.m, xf->inv_m, sizeof r.m);
    memcpy(r.inv_m, xf->m, sizeof r.m);
    memcpy(r.t, xf->inv_t, sizeof r.t);
    memcpy(r.inv_t, xf->t, sizeof r.t);
    return r;
}

static void put_num(FILE *out, double v)
{
    if (v == 0.0)
        v = 0.0; /* no "-0" */
    fprintf(out, "%.17g", v);
}

static void put_vec(FILE *out, lp_vec3 v)
{
    fputc('<', out);
    put_num(out, v.x);
    fputs(", ", out);
    put_num(out, v.y);
    fputs(", ", out);
    put_num(out, v.z);
    fputc('>', out);
}

static void put_rgb(FILE *out, rs_color c)
{
    fputs("rgb ", out);
    put_vec(out, (lp_vec3){ c.r, c.g, c.b });
}

/* POV-Ray's `matrix <a,b,c, d,e,f, g,h,i, j,k,l>` maps a point as a row
 * vector: x' = x a + y d + z g + j, y' = x b + y e + z h + k, ...  Ours is
 * x'_i = sum_j m[i][j] x_j + t_i, so POV's row j is our column j. */
static void put_matrix(FILE *out, const rs_transform *xf, double k)
{
    fputs("matrix <", out);
    for (int j = 0; j < 3; j++) {
        for (int i = 0; i < 3; i++) {
            put_num(out, k * xf->m[i][j]);
            fputs(", ", out);
        }
    }
    for (int i = 0; i < 3; i++) {
        put_num(out, k * xf->t[i]);
        if (i < 2)
            fputs(", ", out);
    }
    fputc('>', out);
}

/* ---- lenses ------------------------------------------------------------- */

/* A lens radius as lens.inc wants it: 0 for flat (0 or infinite). */
static double lens_radius(double r)
{
    return isfinite(r) ? r : 0.0;
}

/* The lens's local frame: u, v perpendicular to the unit axis w (any pair
 * will do, the lens is rotationally symmetric), as the transform local ->
 * world with the front vertex at the origin. */
static rs_transform lens_frame(const lp_lens_desc *d)
{
    lp_vec3 w = v3_unit(d->axis);
    lp_vec3 a = fabs(w.x) <= fabs(w.y) && fabs(w.x) <= fabs(w.z) ? (lp_vec3){ 1, 0, 0 }
              : fabs(w.y) <= fabs(w.z)                           ? (lp_vec3){ 0, 1, 0 }
                                                                 : (lp_vec3){ 0, 0, 1 };
    lp_vec3 u = v3_unit(v3_cross(a, w));
    lp_vec3 v = v3_cross(w, u);
    rs_transform xf;
    lp_vec3 cols[3] = { u, v, w };
    for (int j = 0; j < 3; j++) {
        xf.m[0][j] = cols[j].x;
        xf.m[1][j] = cols[j].y;
        xf.m[2][j] = cols[j].z;
        /* orthonormal: the inverse is the transpose */
        xf.inv_m[j][0] = cols[j].x;
        xf.inv_m[j][1] = cols[j].y;
        xf.inv_m[j][2] = cols[j].z;
    }
    xf.t[0] = d->position.x;
    xf.t[1] = d->position.y;
    xf.t[2] = d->position.z;
    for (int i = 0; i < 3; i++)
        xf.inv_t[i] = -(xf.inv_m[i][0] * xf.t[0] + xf.inv_m[i][1] * xf.t[1] +
                        xf.inv_m[i][2] * xf.t[2]);
    return xf;
}

static double cap_sag(double radius, double h)
{
    if (!isfinite(radius) || radius == 0.0)
        return 0.0;
    double c = 1.0 / radius;
    double q = 1.0 - c * c * h * h;
    return c * h * h / (1.0 + sqrt(q > 0.0 ? q : 0.0));
}

/* Points on the surface of a lens (both caps, the rim's edge circles), in
 * world coordinates, for inside/outside tests. */
enum { LENS_RINGS = 6, LENS_SPOKES = 12,
       LENS_SAMPLES = 2 * (1 + LENS_RINGS * LENS_SPOKES) };

static size_t lens_samples(const lp_lens_desc *d, lp_vec3 *pts)
{
    rs_transform fr = lens_frame(d);
    double h[2] = { 0.5 * d->diameter, 0.5 * (d->diameter2 > 0.0 ? d->diameter2 : d->diameter) };
    double z0[2] = { 0.0, d->thickness };
    double r[2] = { d->radius1, d->radius2 };
    size_t n = 0;
    for (int c = 0; c < 2; c++) {
        pts[n++] = rs_xf_point(&fr, (lp_vec3){ 0.0, 0.0, z0[c] });
        for (int i = 1; i <= LENS_RINGS; i++) {
            double rho = h[c] * i / LENS_RINGS;
            double z = z0[c] + cap_sag(r[c], rho);
            for (int k = 0; k < LENS_SPOKES; k++) {
                double a = 2.0 * PC_PI * k / LENS_SPOKES;
                pts[n++] = rs_xf_point(&fr, (lp_vec3){ rho * cos(a), rho * sin(a), z });
            }
        }
    }
    return n;
}

/* ---- inside tests (POV-Ray's insides, in object space) ------------------- */

/* 1 if the world point lies inside the object as POV-Ray sees it (before
 * the object's own `inverse`, which an opaque object shows nowhere), 0 if
 * not, -1 for objects without an inside that matters (discs, lenses,
 * polarizers). */
static int pov_inside(const rs_object *o, lp_vec3 world)
{
    if (o->type == RS_OBJ_DISC || o->type == RS_OBJ_LENS || o->type == RS_OBJ_POLARIZER)
        return -1;
    return lr_object_inside(o, world) != o->inverse;
}

static lp_vec3 camera_location(const rs_camera *cam)
{
    return cam->has_xf ? rs_xf_point(&cam->xf, cam->location) : cam->location;
}

static const char *type_name(rs_object_type t)
{
    switch (t) {
    case RS_OBJ_PLANE: return "plane";
    case RS_OBJ_SPHERE: return "sphere";
    case RS_OBJ_BOX: return "box";
    case RS_OBJ_DISC: return "disc";
    case RS_OBJ_LENS: return "lens";
    case RS_OBJ_POLARIZER: return "polarizer";
    case RS_OBJ_CYLINDER: return "cylinder";
    case RS_OBJ_CONE: return "cone";
    case RS_OBJ_TORUS: return "torus";
    case RS_OBJ_CSG: return "CSG object";
    }
    return "object";
}

static void loc_text(const rs_loc *loc, char *buf, size_t size)
{
    if (loc->file != NULL)
        snprintf(buf, size, "%s:%d:%d", loc->file, loc->line, loc->column);
    else
        snprintf(buf, size, "line %d", loc->line);
}

/* Notes for lenses that cross the surface of a plane, sphere or box. */
static int note_straddling(const rs_scene *sc, const rs_object *o, pc_notes *notes)
{
    lp_vec3 pts[LENS_SAMPLES];
    for (size_t k = 0; k < sc->n_objects; k++) {
        const rs_object *l = &sc->objects[k];
        if (l->type != RS_OBJ_LENS)
            continue;
        size_t n = lens_samples(&l->u.lens.desc, pts);
        int in = 0, outside = 0;
        for (size_t i = 0; i < n; i++) {
            if (pov_inside(o, pts[i]) == 1)
                in = 1;
            else
                outside = 1;
        }
        if (in && outside) {
            char a[160], b[160], text[512];
            loc_text(&l->loc, a, sizeof a);
            loc_text(&o->loc, b, sizeof b);
            snprintf(text, sizeof text,
                     "the lens at %s crosses the surface of the %s at %s: POV-Ray computes "
                     "Fresnel at its exit faces with the wrong outside index there",
                     a, type_name(o->type), b);
            if (pc_notes_add(notes, text) != 0)
                return -1;
        }
    }
    return 0;
}

/* ---- lights --------------------------------------------------------------- */

/* ---- objects ---------------------------------------------------------- */

static void put_pigment(FILE *out, const rs_object *o)
{
    const rs_pigment *pg = &o->pigment;
    if (pg->type != RS_PIGMENT_CHECKER) {
        fputs("  pigment { ", out);
        put_rgb(out, pg->color[0]);
        fputs(" }\n", out);
        return;
    }
    /* POV-Ray maps pattern space to world by the pigment's own transform
     * P followed by the object's matrix M (written after the pigment).
     * We want pattern = to_pattern(world), i.e. M P = to_pattern^-1, so
     * P = M^-1 to_pattern^-1: pattern -> world -> object. */
    rs_transform pat = xf_inverse(&pg->to_pattern);
    rs_transform minv = xf_inverse(&o->xf);
    rs_transform p;
    rs_transform_compose(&pat, &minv, &p);
    fputs("  pigment { checker ", out);
    put_rgb(out, pg->color[0]);
    fputs(", ", out);
    put_rgb(out, pg->color[1]);
    if (!xf_is_identity(&p)) {
        fputs("\n    ", out);
        put_matrix(out, &p, 1.0);
    }
    fputs(" }\n", out);
}

static void put_finish(FILE *out, const rs_finish *f)
{
    fputs("  finish { ambient ", out);
    put_rgb(out, f->ambient);
    fputs(" diffuse ", out);
    put_num(out, f->diffuse);
    fputs(" brilliance ", out);
    put_num(out, f->brilliance);
    fputs(" emission ", out);
    put_rgb(out, f->emission);
    fputs("\n    phong ", out);
    put_num(out, f->phong);
    fputs(" phong_size ", out);
    put_num(out, f->phong_size);
    fputs(" specular ", out);
    put_num(out, f->specular);
    fputs(" roughness ", out);
    put_num(out, f->roughness);
    fputs("\n    reflection { ", out);
    put_rgb(out, f->fresnel ? f->reflection_min : f->reflection_max);
    fputs(", ", out);
    put_rgb(out, f->reflection_max);
    fputs(f->fresnel ? " fresnel on } }\n" : " } }\n", out);
}

static void put_shape(FILE *out, const rs_object *o, int turn, const char *why, double k);

/* An intersection, difference or union of a CSG object: its members, each
 * with the texture it has after POV-Ray's rule (csg.h), so the CSG
 * itself needs none; `inverse` when turned. */
static void put_csg(FILE *out, const rs_object *o, int turn, double k)
{
    static const char *const ops[] = { "union", "intersection", "difference" };
    fprintf(out, "%s {\n", ops[o->u.csg.op]);
    for (size_t i = 0; i < o->u.csg.n_members; i++) {
        const rs_object *m = &o->u.csg.members[i];
        put_shape(out, m, m->inverse, m->inverse ? " (inverse)" : "", k);
    }
    fputs(turn ? "inverse\n}\n" : "}\n", out);
}

/* A plane, sphere, box, disc, cylinder, cone, torus or CSG object with its
 * pigment, finish and transform, magnified k times; turned inside out
 * when turn (why says why, in the comment line). */
static void put_shape(FILE *out, const rs_object *o, int turn, const char *why, double k)
{
    char where[200];
    rs_object flat;
    /* A plane goes out with its transforms and the magnification folded
     * into its normal, distance and pattern, without a matrix: POV-Ray 3.7
     * misplaces the inside of a plane that has one (measured: a plane
     * cutting a torus in an intersection, with matrix <k 0 0 0 k 0 0 0 k
     * 0 0 0>, shaded and shadowed 0.1-1 mm of the torus wrongly, 46.4 dB
     * against ours; with the distance multiplied instead, 107 dB). */
    int folded = o->type == RS_OBJ_PLANE;
    if (folded) {
        lp_vec3 m = rs_xf_normal(&o->xf, o->u.plane.normal);
        double len = sqrt(v3_dot(m, m));
        lp_vec3 t = { o->xf.t[0], o->xf.t[1], o->xf.t[2] };
        rs_transform shrink;
        rs_transform_identity(&shrink);
        rs_transform_scale(&shrink, (lp_vec3){ 1.0 / k, 1.0 / k, 1.0 / k });
        flat = *o;
        flat.u.plane.normal = v3_scale(m, 1.0 / len);
        flat.u.plane.distance = k * (o->u.plane.distance + v3_dot(m, t)) / len;
        rs_transform_identity(&flat.xf);
        /* world' = k world: pattern = to_pattern(world' / k) */
        rs_transform_compose(&shrink, &o->pigment.to_pattern, &flat.pigment.to_pattern);
        o = &flat;
    }
    loc_text(&o->loc, where, sizeof where);
    fprintf(out, "// %s at %s%s\n", type_name(o->type), where, why);
    switch (o->type) {
    case RS_OBJ_CSG:
        put_csg(out, o, turn, k);
        return;
    case RS_OBJ_PLANE: {
        lp_vec3 n = o->u.plane.normal;
        double d = o->u.plane.distance;
        if (turn) {
            n = (lp_vec3){ -n.x, -n.y, -n.z };
            d = -d;
        }
        fputs("plane { ", out);
        put_vec(out, n);
        fputs(", ", out);
        put_num(out, d);
        fputs("\n", out);
        break;
    }
    case RS_OBJ_SPHERE:
        fputs("sphere { ", out);
        put_vec(out, o->u.sphere.center);
        fputs(", ", out);
        put_num(out, o->u.sphere.radius);
        fputs(turn ? " inverse\n" : "\n", out);
        break;
    case RS_OBJ_BOX:
        fputs("box { ", out);
        put_vec(out, o->u.box.corner1);
        fputs(", ", out);
        put_vec(out, o->u.box.corner2);
        fputs(turn ? " inverse\n" : "\n", out);
        break;
    case RS_OBJ_DISC:
        fputs("disc { ", out);
        put_vec(out, o->u.disc.center);
        fputs(", ", out);
        put_vec(out, o->u.disc.normal);
        fputs(", ", out);
        put_num(out, o->u.disc.radius);
        if (o->u.disc.hole != 0.0) {
            fputs(", ", out);
            put_num(out, o->u.disc.hole);
        }
        fputs("\n", out);
        break;
    case RS_OBJ_CYLINDER:
    case RS_OBJ_CONE: {
        int cone = o->type == RS_OBJ_CONE;
        fputs(cone ? "cone { " : "cylinder { ", out);
        put_vec(out, cone ? o->u.cone.base : o->u.cylinder.base);
        if (cone) {
            fputs(", ", out);
            put_num(out, o->u.cone.base_radius);
        }
        fputs(", ", out);
        put_vec(out, cone ? o->u.cone.cap : o->u.cylinder.cap);
        fputs(", ", out);
        put_num(out, cone ? o->u.cone.cap_radius : o->u.cylinder.radius);
        fputs((cone ? o->u.cone.open : o->u.cylinder.open) ? " open" : "", out);
        fputs(turn ? " inverse\n" : "\n", out);
        break;
    }
    case RS_OBJ_TORUS:
        fputs("torus { ", out);
        put_num(out, o->u.torus.major);
        fputs(", ", out);
        put_num(out, o->u.torus.minor);
        fputs(turn ? " inverse\n" : "\n", out);
        break;
    default:
        return;
    }
    put_pigment(out, o);
    put_finish(out, &o->finish);
    if (o->finish.fresnel) {
        fputs("  interior { ior ", out);
        put_num(out, o->ior);
        fputs(" }\n", out);
    }
    if (!folded && (k != 1.0 || !xf_is_identity(&o->xf))) {
        fputs("  ", out);
        put_matrix(out, &o->xf, k);
        fputs("\n", out);
    }
    fputs("}\n", out);
}

/* The Lens(...) call for a lens, placed (and magnified k times) by a
 * matrix. */
static void put_lens(FILE *out, const rs_object *o, size_t index, int mask, double ior, double k)
{
    const lp_lens_desc *d = &o->u.lens.desc;
    char where[200];
    rs_transform fr = lens_frame(d);

    loc_text(&o->loc, where, sizeof where);
    fprintf(out, "// lens at %s", where);
    if (o->u.lens.glass_name[0] != '\0')
        fprintf(out, ", glass %s", o->u.lens.glass_name);
    fputs("\n", out);
    if (!mask) {
        fprintf(out, "#declare PC_Interior_%zu = interior { ior ", index);
        put_num(out, ior);
        fputs(" }\n", out);
    }
    fputs("object {\n  Lens(", out);
    put_num(out, lens_radius(d->radius1));
    fputs(", ", out);
    put_num(out, lens_radius(d->radius2));
    fputs(", ", out);
    put_num(out, d->thickness);
    fputs(", ", out);
    put_num(out, d->diameter);
    fputs(", ", out);
    put_num(out, d->diameter2);
    if (mask)
        fputs(", PC_Mask, PC_Mask, interior { })\n  ", out);
    else
        fprintf(out, ", PC_Glass, PC_Rim, PC_Interior_%zu)\n  ", index);
    put_matrix(out, &fr, k);
    fputs("\n}\n", out);
}

static int glass_absorbs(const lp_glass *g)
{
    for (int i = 0; i < g->n_tau && i < LP_GLASS_TABLE_MAX; i++)
        if (g->tau[i] < 1.0)
            return 1;
    return 0;
}

/* ---- camera ------------------------------------------------------------- */

static void put_camera(FILE *out, const rs_camera *c, double k)
{
    /* POV-Ray applies these in its own fixed order (up, right, angle,
     * look_at, then the transforms), as our camera does; the order written
     * here is that order too. */
    fputs(c->orthographic ? "camera {\n  orthographic\n  location "
                          : "camera {\n  perspective\n  location ", out);
    put_vec(out, v3_scale(c->location, k));
    fputs("\n  direction ", out);
    put_vec(out, c->direction);
    /* an orthographic camera's right and up are lengths of the scene */
    fputs("\n  right ", out);
    put_vec(out, c->orthographic ? v3_scale(c->right, k) : c->right);
    fputs("\n  up ", out);
    put_vec(out, c->orthographic ? v3_scale(c->up, k) : c->up);
    fputs("\n  sky ", out);
    put_vec(out, c->sky);
    fputs("\n", out);
    if (c->has_angle) {
        fputs("  angle ", out);
        put_num(out, c->angle);
        fputs("\n", out);
    }
    if (c->has_look_at) {
        fputs("  look_at ", out);
        put_vec(out, v3_scale(c->look_at, k));
        fputs("\n", out);
    }
    if (c->has_xf && !xf_is_identity(&c->xf)) {
        rs_transform m = c->xf;
        for (int i = 0; i < 3; i++)
            m.t[i] *= k;
        fputs("  ", out);
        put_matrix(out, &m, 1.0);
        fputs("\n", out);
    }
    fputs("}\n\n", out);
}

/* ---- the scene -------------------------------------------------------- */

/* 1 if the path can be written in a POV-Ray string literal. */
static int path_writable(const char *path)
{
    for (const char *p = path; *p; p++)
        if (*p == '"' || (unsigned char)*p < 0x20 || *p == 0x7f)
            return 0;
    return 1;
}

/* POV-Ray 3.7 reads backslash escapes in strings: double them. */
static void put_include(FILE *out, const char *path)
{
    fputs("#include \"", out);
    for (const char *p = path; *p; p++) {
        if (*p == '\\')
            fputc('\\', out);
        fputc(*p, out);
    }
    fputs("\"\n", out);
}

/* Notes for what the scene has that POV-Ray cannot show. */
static int add_feature_notes(const rs_scene *sc, pc_notes *notes)
{
    int coherent = sc->settings.coherent, line = 0, blackbody = 0, lpol = 0;
    int polarizer = 0, dispersion = 0, absorption = 0, medium = 0;
    for (size_t i = 0; i < sc->n_lights; i++) {
        const rs_light *l = &sc->lights[i];
        coherent |= l->coherent != 0;
        line |= l->spectrum.type == RS_SPECTRUM_LINE;
        blackbody |= l->spectrum.type == RS_SPECTRUM_BLACKBODY;
        lpol |= l->polarized != 0;
    }
    for (size_t i = 0; i < sc->n_objects; i++) {
        const rs_object *o = &sc->objects[i];
        if (o->type == RS_OBJ_POLARIZER)
            polarizer = 1;
        if (o->type != RS_OBJ_LENS)
            continue;
        const lp_lens_desc *d = &o->u.lens.desc;
        dispersion |= d->glass.formula != LP_FORMULA_CONSTANT ||
                      d->medium.formula != LP_FORMULA_CONSTANT;
        absorption |= glass_absorbs(&d->glass) || glass_absorbs(&d->medium);
        medium |= lp_glass_index(&d->medium, RS_LAMBDA_D_LINE) != 1.0;
    }
    if ((polarizer && pc_notes_add(notes, PC_NOTE_POLARIZERS) != 0) ||
        (coherent && pc_notes_add(notes, PC_NOTE_COHERENCE) != 0) ||
        (dispersion && pc_notes_add(notes, PC_NOTE_DISPERSION) != 0) ||
        (absorption && pc_notes_add(notes, PC_NOTE_ABSORPTION) != 0) ||
        (medium && pc_notes_add(notes, PC_NOTE_MEDIUM) != 0) ||
        (line && pc_notes_add(notes, PC_NOTE_LINE_LIGHTS) != 0) ||
        (blackbody && pc_notes_add(notes, PC_NOTE_BLACKBODY_LIGHTS) != 0) ||
        (lpol && pc_notes_add(notes, PC_NOTE_LIGHT_POLARIZATION) != 0))
        return -1;
    for (size_t i = 0; i < sc->n_messages; i++) {
        char text[600];
        if (sc->messages[i].kind != RS_MSG_WARNING)
            continue;
        snprintf(text, sizeof text, "the scene reader warned (not rendered by lensrender, "
                 "left out of the POV-Ray scene): %s", sc->messages[i].text);
        if (pc_notes_add(notes, text) != 0)
            return -1;
    }
    return 0;
}

/* Grow the box lo..hi by a point (non-finite points are ignored). */
static void box_add(lp_vec3 *lo, lp_vec3 *hi, lp_vec3 p)
{
    if (!v3_finite(p))
        return;
    lo->x = fmin(lo->x, p.x);
    lo->y = fmin(lo->y, p.y);
    lo->z = fmin(lo->z, p.z);
    hi->x = fmax(hi->x, p.x);
    hi->y = fmax(hi->y, p.y);
    hi->z = fmax(hi->z, p.z);
}

/* The 8 corners of an object-space box, to world. */
static void box_add_xf(lp_vec3 *lo, lp_vec3 *hi, const rs_transform *xf, lp_vec3 a, lp_vec3 b)
{
    for (int c = 0; c < 8; c++) {
        lp_vec3 p = { (c & 1) ? b.x : a.x, (c & 2) ? b.y : a.y, (c & 4) ? b.z : a.z };
        box_add(lo, hi, rs_xf_point(xf, p));
    }
}

/* The farthest point where a primary ray meets a plane (0: none). */
static double farthest_plane_hit(const rs_scene *scene, int width, int height)
{
    double far = 0.0;
    size_t n_planes = 0;
    for (size_t i = 0; i < scene->n_objects; i++)
        n_planes += scene->objects[i].type == RS_OBJ_PLANE;
    if (n_planes == 0)
        return 0.0;
    for (int j = 0; j < height; j++)
        for (int i = 0; i < width; i++) {
            lp_vec3 o, d;
            if (lr_camera_ray(&scene->camera, width, height, i + 0.5, j + 0.5, &o, &d, NULL) !=
                LR_OK)
                return INFINITY;
            for (size_t k = 0; k < scene->n_objects; k++) {
                const rs_object *ob = &scene->objects[k];
                if (ob->type != RS_OBJ_PLANE)
                    continue;
                /* in object space; t stays the world distance (affine map,
                   unit world direction) */
                lp_vec3 lo = rs_xf_inv_point(&ob->xf, o), ld = rs_xf_inv_dir(&ob->xf, d);
                double dn = v3_dot(ob->u.plane.normal, ld);
                double t = (ob->u.plane.distance - v3_dot(ob->u.plane.normal, lo)) / dn;
                if (t > 0.0 && t > far)
                    far = t; /* +inf for a ray parallel to the plane, in it */
            }
        }
    return far;
}

/* Add an object's world box (a CSG object's: its members') to lo, hi. */
static void object_box_add(lp_vec3 *lo, lp_vec3 *hi, const rs_object *o)
{
    lp_vec3 pts[LENS_SAMPLES];
    switch (o->type) {
    case RS_OBJ_SPHERE:
    case RS_OBJ_DISC: { /* both inside the cube of half-side r about c */
        int sph = o->type == RS_OBJ_SPHERE;
        lp_vec3 c = sph ? o->u.sphere.center : o->u.disc.center;
        double r = fabs(sph ? o->u.sphere.radius : o->u.disc.radius);
        box_add_xf(lo, hi, &o->xf, (lp_vec3){ c.x - r, c.y - r, c.z - r },
                   (lp_vec3){ c.x + r, c.y + r, c.z + r });
        break;
    }
    case RS_OBJ_BOX:
        box_add_xf(lo, hi, &o->xf, o->u.box.corner1, o->u.box.corner2);
        break;
    case RS_OBJ_POLARIZER: {
        lp_vec3 c = o->u.polarizer.center;
        double r = fabs(o->u.polarizer.radius);
        box_add(lo, hi, (lp_vec3){ c.x - r, c.y - r, c.z - r });
        box_add(lo, hi, (lp_vec3){ c.x + r, c.y + r, c.z + r });
        break;
    }
    case RS_OBJ_LENS: {
        size_t n = lens_samples(&o->u.lens.desc, pts);
        for (size_t k = 0; k < n; k++)
            box_add(lo, hi, pts[k]);
        break;
    }
    case RS_OBJ_CSG:
        for (size_t i = 0; i < o->u.csg.n_members; i++)
            object_box_add(lo, hi, &o->u.csg.members[i]);
        break;
    default:
        break;
    }
}

double pc_pov_scale(const rs_scene *scene, int width, int height)
{
    lp_vec3 lo = { INFINITY, INFINITY, INFINITY }, hi = { -INFINITY, -INFINITY, -INFINITY };

    if (scene == NULL)
        return 1.0;
    box_add(&lo, &hi, camera_location(&scene->camera));
    for (size_t i = 0; i < scene->n_lights; i++)
        box_add(&lo, &hi, scene->lights[i].position);
    for (size_t i = 0; i < scene->n_objects; i++)
        object_box_add(&lo, &hi, &scene->objects[i]);
    lp_vec3 d = v3_sub(hi, lo);
    double e = sqrt(v3_dot(d, d));
    if (width <= 0 || height <= 0) {
        width = 640;
        height = 480;
    }
    e = fmax(e, farthest_plane_hit(scene, width, height));
    if (!isfinite(e) || !(e > 0.0))
        return 1.0;
    double k = 1.0;
    while (k < PC_POV_MAX_SCALE && 10.0 * k * e <= PC_POV_SCALED_EXTENT)
        k *= 10.0;
    return k;
}

int pc_translate(const rs_scene *scene, const pc_translate_opts *opts, FILE *out,
                 pc_notes *notes, char *msg, size_t msg_size)
{
    return pc_translate_scaled(scene, opts, 0.0, out, notes, msg, msg_size);
}

int pc_translate_scaled(const rs_scene *scene, const pc_translate_opts *opts, double scale,
                        FILE *out, pc_notes *notes, char *msg, size_t msg_size)
{
    if (msg != NULL && msg_size > 0)
        msg[0] = '\0';
    if (scene == NULL || opts == NULL || out == NULL || notes == NULL)
        return fail(msg, msg_size, "pc_translate: NULL argument");

    const int mask = opts->mask != 0;
    const char *inc = opts->lens_inc != NULL && opts->lens_inc[0] != '\0' ? opts->lens_inc
                                                                          : "lens.inc";
    int mtl = opts->max_trace_level > 0 ? opts->max_trace_level
                                        : scene->settings.max_trace_level;
    if (mask)
        mtl = 1;
    if (mtl < 1)
        mtl = 1;
    if (mtl > PC_POV_MAX_TRACE_LEVEL) {
        char text[160];
        snprintf(text, sizeof text,
                 "max_trace_level %d is above POV-Ray's limit and was written as %d", mtl,
                 PC_POV_MAX_TRACE_LEVEL);
        if (pc_notes_add(notes, text) != 0)
            return fail(msg, msg_size, "out of memory");
        mtl = PC_POV_MAX_TRACE_LEVEL;
    }

    double k = scale;
    if (k == 0.0)
        k = pc_pov_scale(scene, opts->width, opts->height);
    if (!isfinite(k) || !(k > 0.0))
        return fail(msg, msg_size, "the scale must be a finite number > 0 (or 0: automatic)");

    /* Check and prepare everything before writing a byte. */
    if (!path_writable(inc))
        return fail(msg, msg_size, "the lens.inc path cannot be written in a POV-Ray string: %s",
                    inc);
    lr_error check;
    if (lr_scene_check(scene, &check) != LR_OK)
        return fail(msg, msg_size, "%s", check.message);
    size_t n_lenses = 0;
    for (size_t i = 0; i < scene->n_objects; i++) {
        const rs_object *o = &scene->objects[i];
        if (o->type != RS_OBJ_LENS)
            continue;
        const lp_lens_desc *d = &o->u.lens.desc;
        double ng = lp_glass_index(&d->glass, RS_LAMBDA_D_LINE);
        double nm = lp_glass_index(&d->medium, RS_LAMBDA_D_LINE);
        if (!isfinite(ng) || !isfinite(nm) || !(ng > 0.0) || !(nm > 0.0))
            return fail_at(msg, msg_size, &o->loc, "lens: no index at the d line");
        n_lenses++;
    }

    lp_vec3 eye = camera_location(&scene->camera);
    if (!mask) {
        if (add_feature_notes(scene, notes) != 0)
            return fail(msg, msg_size, "out of memory");
        for (size_t i = 0; i < scene->n_objects; i++) {
            const rs_object *o = &scene->objects[i];
            if ((o->type == RS_OBJ_PLANE || o->type == RS_OBJ_SPHERE || o->type == RS_OBJ_BOX) &&
                note_straddling(scene, o, notes) != 0)
                return fail(msg, msg_size, "out of memory");
        }
    }

    /* ---- header ---- */
    fputs("#version 3.7;\n", out);
    fprintf(out, "// Written by pov_compare from %s%s.\n",
            scene->n_files > 0 && scene->files[0] != NULL ? scene->files[0] : "a scene",
            mask ? " (mask: the lenses' silhouettes, white on black)" : "");
    if (opts->width > 0 && opts->height > 0)
        fprintf(out, "// Image size %dx%d (the camera's right vector is already %d/%d).\n",
                opts->width, opts->height, opts->width, opts->height);
    if (k != 1.0) {
        fputs("// Lengths are magnified ", out);
        put_num(out, k);
        fputs(" times (POV-Ray ignores hits closer than 1e-4 of its units).\n", out);
    }
    fputs("// Render: povray -D +I<this> +O<out.png> +W<w> +H<h> -A +FN16 File_Gamma=1.0 "
          "Dither=off\n", out);
    if (!mask)
        for (size_t i = 0; i < notes->n; i++)
            fprintf(out, "// note: %s\n", notes->text[i]);
    fputs("\nglobal_settings {\n  assumed_gamma 1.0\n", out);
    fprintf(out, "  max_trace_level %d\n  adc_bailout 0\n  ambient_light ", mtl);
    put_rgb(out, mask ? (rs_color){ 0, 0, 0 } : scene->settings.ambient_light);
    fputs("\n}\n\n", out);

    put_camera(out, &scene->camera, k);
    fputs("background { ", out);
    put_rgb(out, mask ? (rs_color){ 0, 0, 0 } : scene->background);
    fputs(" }\n\n", out);

    /* ---- lenses ---- */
    if (n_lenses > 0) {
        put_include(out, inc);
        if (mask) {
            fputs("#declare PC_Mask = texture { pigment { rgb 1 }\n"
                  "  finish { ambient 0 diffuse 0 emission 1 specular 0 phong 0 } }\n", out);
        } else {
            fputs("#declare PC_Glass = texture { pigment { rgbf 1 }\n"
                  "  finish { ambient 0 diffuse 0 specular 0 phong 0\n"
                  "           reflection { 0, 1 fresnel on } conserve_energy } }\n"
                  "#declare PC_Rim = texture { pigment { rgb 0 }\n"
                  "  finish { ambient 0 diffuse 0 emission 0 specular 0 phong 0 } }\n", out);
        }
        fputs("\n", out);
        size_t n = 0;
        for (size_t i = 0; i < scene->n_objects; i++) {
            const rs_object *o = &scene->objects[i];
            if (o->type != RS_OBJ_LENS)
                continue;
            const lp_lens_desc *d = &o->u.lens.desc;
            double ior = lp_glass_index(&d->glass, RS_LAMBDA_D_LINE) /
                         lp_glass_index(&d->medium, RS_LAMBDA_D_LINE);
            put_lens(out, o, n++, mask, ior, k);
        }
        fputs("\n", out);
    }
    if (!mask) {
        /* ---- lights ---- */
        for (size_t i = 0; i < scene->n_lights; i++) {
            const rs_light *l = &scene->lights[i];
            fputs("light_source { ", out);
            put_vec(out, v3_scale(l->position, k));
            fputs(" color ", out);
            put_rgb(out, lr_light_rgb(l));
            fputs(" }\n", out);
        }
        if (scene->n_lights > 0)
            fputs("\n", out);

        /* ---- other objects (polarizers are left out) ---- */
        for (size_t i = 0; i < scene->n_objects; i++) {
            const rs_object *o = &scene->objects[i];
            if (o->type == RS_OBJ_LENS || o->type == RS_OBJ_POLARIZER)
                continue;
            int turn = pov_inside(o, eye) == 1;
            put_shape(out, o, turn, turn ? " (turned inside out: the camera was inside it)" : "",
                      k);
        }
    }
    fflush(out);
    if (ferror(out))
        return fail(msg, msg_size, "writing the POV-Ray scene failed");
    return 0;
}
