/* parser.c -- recursive descent over the tokens of lexer.c; see parser.h.
 *
 * Every function that can fail returns 0 or -1; the first error is written
 * to the caller's buffer and parsing stops.  Recursion is bounded: braces,
 * parentheses, vector brackets and function calls together may nest 64
 * deep; chains of unary signs are read in a loop.  All memory the parser
 * allocates for itself (the identifier table, the file text) is released
 * before it returns; what it adds to the scene belongs to the scene.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "csg.h"
#include "parse_internal.h"
#include "support/vec.h"

/* An rs_object is about 2.5 kB (a lens description holds two glasses), so
 * 100,000 objects take about 250 MB; a scene asking for more is refused
 * rather than left to exhaust memory.  (The renderer tests every object
 * on every ray, so such scenes are far beyond what it can render anyway.) */
#define DEFAULT_MAX_OBJECTS ((size_t)100000)
/* Longest scene text read (a file stops being read past this). */
#define MAX_SOURCE_BYTES ((size_t)64 << 20)
#define DEFAULT_WIDTH 640
#define DEFAULT_HEIGHT 480
#define PI_VALUE 3.14159265358979323846
#define MAX_STRING 4096

/* ------------------------------------------------------------------ */
/* Errors and warnings                                                 */
/* ------------------------------------------------------------------ */

static void vmessage(parser *p, char *buf, size_t size, int line, int column, const char *kind,
                     const char *fmt, va_list ap)
{
    int n = snprintf(buf, size, "%s:%d:%d: %s", p->file, line, column, kind);
    if (n >= 0 && (size_t)n < size)
        vsnprintf(buf + n, size - (size_t)n, fmt, ap);
}

int rs__error_at(parser *p, int line, int column, const char *fmt, ...)
{
    if (!p->failed && p->msg != NULL && p->msg_size > 0) {
        va_list ap;
        va_start(ap, fmt);
        vmessage(p, p->msg, p->msg_size, line, column, "", fmt, ap);
        va_end(ap);
    }
    p->failed = 1;
    return -1;
}

void rs__warn(parser *p, int line, int column, const char *fmt, ...)
{
    char buf[512];
    va_list ap;
    if (p->failed)
        return;
    va_start(ap, fmt);
    vmessage(p, buf, sizeof buf, line, column, "warning: ", fmt, ap);
    va_end(ap);
    if (rs_scene_add_message(p->scene, RS_MSG_WARNING, buf) != 0)
        rs__error_at(p, line, column, "out of memory");
}

#define error_at rs__error_at

/* "expected WHAT, found <token>" at the token (a lexical error was
 * reported where it was read). */
int rs__expected(parser *p, const rs_token *t, const char *what)
{
    char desc[96];
    if (t->kind == RS_TOK_ERROR || p->failed) {
        p->failed = 1;
        return -1;
    }
    rs_token_describe(t, desc, sizeof desc);
    return error_at(p, t->line, t->column, "expected %s, found %s", what, desc);
}

#define expected rs__expected

/* ------------------------------------------------------------------ */
/* Tokens                                                              */
/* ------------------------------------------------------------------ */

const rs_token *rs__peek(parser *p)
{
    if (p->n_la == 0)
        rs__fetch(p);
    return &p->la;
}

/* Consume the current token and return a copy of it. */
rs_token rs__take(parser *p)
{
    rs_token t = *rs__peek(p);
    if (t.kind != RS_TOK_EOF && t.kind != RS_TOK_ERROR)
        p->n_la = 0;
    return t;
}

#define peek rs__peek
#define take rs__take

static int is_id(const rs_token *t, const char *kw)
{
    size_t n = strlen(kw);
    return t->kind == RS_TOK_IDENT && t->len == n && memcmp(t->text, kw, n) == 0;
}

static int is_punct(const rs_token *t, char c)
{
    return t->kind == RS_TOK_PUNCT && t->punct == c;
}

static int expect_punct(parser *p, char c, const char *what)
{
    if (!is_punct(peek(p), c))
        return expected(p, peek(p), what);
    take(p);
    return 0;
}

static void skip_comma(parser *p)
{
    if (is_punct(peek(p), ','))
        take(p);
}

static int enter(parser *p, const rs_token *t)
{
    if (++p->depth > RS_MAX_DEPTH)
        return error_at(p, t->line, t->column, "nesting deeper than %d levels", RS_MAX_DEPTH);
    return 0;
}

static void leave(parser *p)
{
    p->depth--;
}

/* '{' after the keyword kw. */
static int open_block(parser *p, const char *kw)
{
    char what[64];
    const rs_token *t = peek(p);
    if (!is_punct(t, '{')) {
        snprintf(what, sizeof what, "'{' after '%s'", kw);
        return expected(p, t, what);
    }
    if (enter(p, t) != 0)
        return -1;
    take(p);
    return 0;
}

static int close_block(parser *p, const char *kw)
{
    char what[64];
    snprintf(what, sizeof what, "'}' to close '%s'", kw);
    if (expect_punct(p, '}', what) != 0)
        return -1;
    leave(p);
    return 0;
}

/* ------------------------------------------------------------------ */
/* Reserved words                                                      */
/* ------------------------------------------------------------------ */

static const char *const reserved_words[] = {
    /* scene items and their keywords */
    "camera", "perspective", "orthographic", "fisheye", "ultra_wide_angle", "omnimax",
    "panoramic", "cylinder", "spherical", "location", "look_at", "angle", "right", "up",
    "direction", "sky", "focal_point", "aperture", "blur_samples", "light_source", "polarization", "spectrum", "blackbody", "line",
    "coherent", "background", "global_settings", "max_trace_level", "adc_bailout",
    "ambient_light", "assumed_gamma", "plane", "sphere", "box", "disc", "lens", "radius1",
    "radius2", "thickness", "diameter", "diameter2", "glass", "ior", "sellmeier", "medium",
    "uniaxial", "crystal", "ordinary", "extraordinary", "polarizer", "center", "normal", "radius", "axis", "pigment", "finish", "texture",
    "checker", "color", "colour", "rgb", "rgbf", "rgbt", "rgbft", "red", "green", "blue",
    "filter", "transmit", "ambient", "diffuse", "emission", "specular", "phong",
    "phong_size", "brilliance", "roughness", "reflection", "conserve_energy", "metallic",
    "translate", "rotate", "scale", "matrix", "transform", "object", "union",
    "intersection", "difference", "merge", "interior", "normal", "inf", "cone", "torus",
    "open", "inverse", "fresnel", "falloff", "exponent", "crand", "irid",
    /* built-in values */
    "x", "y", "z", "pi", "true", "false", "on", "off", "yes", "no", "image_width",
    "image_height", "version", "clock",
    /* functions */
    "sqrt", "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "pow", "abs", "min",
    "max", "radians", "degrees", "exp", "ln", "log", "floor", "ceil", "int", "mod",
    "vlength", "vnormalize", "vdot", "vcross", "select", "div", "concat", "str", "chr",
    "strlen",
};

static int name_is(const char *text, size_t len, const char *w)
{
    return strlen(w) == len && memcmp(text, w, len) == 0;
}

int rs__is_reserved(const char *text, size_t len)
{
    for (size_t i = 0; i < sizeof reserved_words / sizeof reserved_words[0]; i++)
        if (name_is(text, len, reserved_words[i]))
            return 1;
    return 0;
}

#define is_reserved rs__is_reserved

/* |v| without overflow or underflow in the squares (0 for a zero vector,
 * not finite when a component is not). */
static double vec_length(lp_vec3 v)
{
    double m = fmax(fabs(v.x), fmax(fabs(v.y), fabs(v.z)));
    double x, y, z;
    if (!(m > 0.0) || !isfinite(m))
        return m;
    x = v.x / m, y = v.y / m, z = v.z / m;
    return m * sqrt(x * x + y * y + z * z);
}

/* v / |v| into *out; 0 (and *out untouched) when v is zero or not finite. */
static int normalize(lp_vec3 v, lp_vec3 *out)
{
    double m = fmax(fabs(v.x), fmax(fabs(v.y), fabs(v.z))), l;
    if (!(m > 0.0) || !isfinite(m))
        return 0;
    v = (lp_vec3){ v.x / m, v.y / m, v.z / m };
    l = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    *out = (lp_vec3){ v.x / l, v.y / l, v.z / l };
    return 1;
}

/* ------------------------------------------------------------------ */
/* Values                                                              */
/* ------------------------------------------------------------------ */

static void set_float(val *v, double f)
{
    memset(v, 0, sizeof *v);
    v->kind = VAL_FLOAT;
    v->v[0] = f;
}

static void set_vector(val *v, int dim)
{
    v->kind = VAL_VECTOR;
    v->vec = 1;
    v->dim = dim;
}

static const char *kind_name(val_kind k)
{
    static const char *const names[] = { "a float", "a vector", "a string", "a pigment",
                                         "a finish", "a texture", "an interior", "an object" };
    return names[k];
}

/* A float becomes <f,f,f,f,f> (POV-Ray's promotion); a vector keeps its
 * components and gets at least dim of them (the new ones 0). */
static void promote_to(val *v, int dim)
{
    if (v->kind == VAL_FLOAT) {
        for (int i = 1; i < 5; i++)
            v->v[i] = v->v[0];
        set_vector(v, dim);
    } else if (v->dim < dim) {
        v->dim = dim;
    }
}

static void promote(val *v)
{
    promote_to(v, 3);
}

static int val_finite(const val *v)
{
    for (int i = 0; i < 5; i++)
        if (!isfinite(v->v[i]))
            return 0;
    return 1;
}

static int want_number(parser *p, val *v, const rs_token *start, const char *what)
{
    if (v->kind == VAL_FLOAT || v->kind == VAL_VECTOR)
        return 0;
    rs__val_free(v);
    return error_at(p, start->line, start->column, "expected %s, found %s", what,
                    kind_name(v->kind));
}

/* ------------------------------------------------------------------ */
/* Expressions                                                         */
/* ------------------------------------------------------------------ */

enum fn_id {
    FN_SQRT, FN_SIN, FN_COS, FN_TAN, FN_ASIN, FN_ACOS, FN_ATAN, FN_ATAN2, FN_POW, FN_ABS,
    FN_MIN, FN_MAX, FN_RADIANS, FN_DEGREES, FN_EXP, FN_LN, FN_LOG, FN_FLOOR, FN_CEIL,
    FN_INT, FN_MOD, FN_VLENGTH, FN_VNORMALIZE, FN_VDOT, FN_VCROSS, FN_SELECT, FN_DIV,
    FN_STRLEN
};

typedef struct fn_def {
    const char *name;
    enum fn_id id;
    int nargs;      /* -1: two or more; -3: three or four */
    int vec_args;   /* arguments are vectors (floats promote) */
    int vec_result;
} fn_def;

static const fn_def functions[] = {
    { "sqrt", FN_SQRT, 1, 0, 0 },       { "sin", FN_SIN, 1, 0, 0 },
    { "cos", FN_COS, 1, 0, 0 },         { "tan", FN_TAN, 1, 0, 0 },
    { "asin", FN_ASIN, 1, 0, 0 },       { "acos", FN_ACOS, 1, 0, 0 },
    { "atan", FN_ATAN, 1, 0, 0 },       { "atan2", FN_ATAN2, 2, 0, 0 },
    { "pow", FN_POW, 2, 0, 0 },         { "abs", FN_ABS, 1, 0, 0 },
    { "min", FN_MIN, -1, 0, 0 },        { "max", FN_MAX, -1, 0, 0 },
    { "radians", FN_RADIANS, 1, 0, 0 }, { "degrees", FN_DEGREES, 1, 0, 0 },
    { "exp", FN_EXP, 1, 0, 0 },         { "ln", FN_LN, 1, 0, 0 },
    { "log", FN_LOG, 1, 0, 0 },         { "floor", FN_FLOOR, 1, 0, 0 },
    { "ceil", FN_CEIL, 1, 0, 0 },       { "int", FN_INT, 1, 0, 0 },
    { "mod", FN_MOD, 2, 0, 0 },         { "vlength", FN_VLENGTH, 1, 1, 0 },
    { "vnormalize", FN_VNORMALIZE, 1, 1, 1 },
    { "vdot", FN_VDOT, 2, 1, 0 },       { "vcross", FN_VCROSS, 2, 1, 1 },
    { "select", FN_SELECT, -3, 0, 0 },  { "div", FN_DIV, 2, 0, 0 },
    { "strlen", FN_STRLEN, 1, 0, 0 },
};

static const fn_def *find_function(const rs_token *t)
{
    if (t->kind != RS_TOK_IDENT)
        return NULL;
    for (size_t i = 0; i < sizeof functions / sizeof functions[0]; i++)
        if (name_is(t->text, t->len, functions[i].name))
            return &functions[i];
    return NULL;
}

/* Built-in constants; 1 and *out filled when t names one. */
static int builtin_value(const parser *p, const rs_token *t, val *out)
{
    static const char *const ones[] = { "true", "on", "yes" };
    static const char *const zeros[] = { "false", "off", "no", "clock" };
    set_float(out, 0.0);
    if (t->kind != RS_TOK_IDENT)
        return 0;
    if (t->len == 1 && (t->text[0] == 'x' || t->text[0] == 'y' || t->text[0] == 'z')) {
        set_vector(out, 3);
        out->v[t->text[0] - 'x'] = 1.0;
        return 1;
    }
    if (is_id(t, "pi")) {
        out->v[0] = PI_VALUE;
        return 1;
    }
    if (is_id(t, "image_width")) {
        out->v[0] = p->image_width;
        return 1;
    }
    if (is_id(t, "image_height")) {
        out->v[0] = p->image_height;
        return 1;
    }
    if (is_id(t, "version")) {
        out->v[0] = p->version;
        return 1;
    }
    if (p->allow_inf && is_id(t, "inf")) {
        out->v[0] = INFINITY;
        return 1;
    }
    for (int i = 0; i < 3; i++)
        if (is_id(t, ones[i])) {
            out->v[0] = 1.0;
            return 1;
        }
    for (int i = 0; i < 4; i++)
        if (is_id(t, zeros[i]))
            return 1;
    return 0;
}

/* Can an expression start here?  Undeclared non-reserved identifiers
 * count, so that they are reported as undeclared. */
static int is_expr_start(parser *p, const rs_token *t)
{
    val dummy;
    if (t->kind == RS_TOK_NUMBER)
        return 1;
    if (t->kind == RS_TOK_PUNCT)
        return t->punct == '(' || t->punct == '<' || t->punct == '-' || t->punct == '+' ||
               t->punct == '!';
    if (t->kind != RS_TOK_IDENT)
        return 0;
    return builtin_value(p, t, &dummy) || find_function(t) != NULL ||
           !is_reserved(t->text, t->len);
}

static int is_color_keyword(const rs_token *t)
{
    static const char *const kws[] = { "color", "colour", "rgb", "rgbf", "rgbt", "rgbft",
                                       "red", "green", "blue", "filter", "transmit" };
    for (size_t i = 0; i < sizeof kws / sizeof kws[0]; i++)
        if (is_id(t, kws[i]))
            return 1;
    return 0;
}

static int is_color_start(parser *p, const rs_token *t)
{
    return is_color_keyword(t) || is_expr_start(p, t);
}

static int parse_expr(parser *p, val *out);
int rs__parse_expr(parser *p, val *out)
{
    return parse_expr(p, out);
}

/* An expression that must be a float or vector (what names it). */
static int parse_number(parser *p, val *out, const char *what)
{
    rs_token start = *peek(p);
    if (parse_expr(p, out) != 0)
        return -1;
    return want_number(p, out, &start, what);
}

static int want_float_val(parser *p, const val *v, const rs_token *start, const char *what)
{
    if (v->kind != VAL_FLOAT)
        return error_at(p, start->line, start->column, "expected a float%s%s, found %s",
                        what ? " for " : "", what ? what : "", kind_name(v->kind));
    return 0;
}

/* name ( args ) */
static int parse_function(parser *p, const fn_def *fn, val *out)
{
    rs_token name = take(p);
    val a[4];
    double r = 0.0;
    int nargs = 0;
    char what[48];

    snprintf(what, sizeof what, "'(' after '%s'", fn->name);
    if (!is_punct(peek(p), '('))
        return expected(p, peek(p), what);
    if (enter(p, peek(p)) != 0)
        return -1;
    take(p);
    memset(a, 0, sizeof a);
    set_float(out, 0.0);
    for (;;) {
        rs_token start = *peek(p);
        val v;
        if (fn->id == FN_STRLEN) {
            char *str = NULL;
            if (rs__parse_string(p, &str) != 0)
                return -1;
            set_float(&v, (double)strlen(str));
            free(str);
        } else if (parse_expr(p, &v) != 0) {
            return -1;
        }
        if (fn->vec_args) {
            if (want_number(p, &v, &start, "a vector argument") != 0)
                return -1;
            promote(&v);
        } else {
            snprintf(what, sizeof what, "the argument of %s()", fn->name);
            if (want_float_val(p, &v, &start, what) != 0) {
                rs__val_free(&v);
                return -1;
            }
        }
        if (fn->id == FN_MIN || fn->id == FN_MAX) {
            if (nargs == 0)
                r = v.v[0];
            else
                r = fn->id == FN_MIN ? fmin(r, v.v[0]) : fmax(r, v.v[0]);
        } else {
            a[nargs] = v;
        }
        nargs++;
        if ((fn->nargs > 0 && nargs == fn->nargs) || (fn->nargs == -3 && nargs == 4)) {
            snprintf(what, sizeof what, "')' after the %s of %s()",
                     nargs == 1 ? "argument" : "arguments", fn->name);
            if (expect_punct(p, ')', what) != 0)
                return -1;
            break;
        }
        if (((fn->nargs == -1 && nargs >= 2) || (fn->nargs == -3 && nargs == 3)) &&
            is_punct(peek(p), ')')) {
            take(p);
            break;
        }
        snprintf(what, sizeof what, "',' between the arguments of %s()", fn->name);
        if (expect_punct(p, ',', what) != 0)
            return -1;
    }
    leave(p);

    switch (fn->id) {
    case FN_SQRT: r = sqrt(a[0].v[0]); break;
    case FN_SIN: r = sin(a[0].v[0]); break;
    case FN_COS: r = cos(a[0].v[0]); break;
    case FN_TAN: r = tan(a[0].v[0]); break;
    case FN_ASIN: r = asin(a[0].v[0]); break;
    case FN_ACOS: r = acos(a[0].v[0]); break;
    case FN_ATAN: r = atan(a[0].v[0]); break;
    case FN_ATAN2: r = atan2(a[0].v[0], a[1].v[0]); break;
    case FN_POW: r = pow(a[0].v[0], a[1].v[0]); break;
    case FN_ABS: r = fabs(a[0].v[0]); break;
    case FN_MIN: case FN_MAX: break;
    case FN_RADIANS: r = a[0].v[0] * (PI_VALUE / 180.0); break;
    case FN_DEGREES: r = a[0].v[0] * (180.0 / PI_VALUE); break;
    case FN_EXP: r = exp(a[0].v[0]); break;
    case FN_LN: r = log(a[0].v[0]); break;
    case FN_LOG: r = log10(a[0].v[0]); break;
    case FN_FLOOR: r = floor(a[0].v[0]); break;
    case FN_CEIL: r = ceil(a[0].v[0]); break;
    case FN_INT: r = trunc(a[0].v[0]); break;
    case FN_STRLEN: r = a[0].v[0]; break;
    case FN_MOD:
    case FN_DIV:
        if (a[1].v[0] == 0.0)
            return error_at(p, name.line, name.column, "%s(): division by zero", fn->name);
        r = fn->id == FN_MOD ? fmod(a[0].v[0], a[1].v[0]) : trunc(a[0].v[0] / a[1].v[0]);
        break;
    case FN_SELECT:
        /* select(A, B, C [, D]): B if A < 0, C if A = 0 (or >= 0 with three
         * arguments), D if A > 0 */
        if (a[0].v[0] < 0.0)
            r = a[1].v[0];
        else if (nargs == 3 || a[0].v[0] == 0.0)
            r = a[2].v[0];
        else
            r = a[3].v[0];
        break;
    case FN_VLENGTH:
        r = vec_length((lp_vec3){ a[0].v[0], a[0].v[1], a[0].v[2] });
        break;
    case FN_VNORMALIZE: {
        lp_vec3 u;
        if (!normalize((lp_vec3){ a[0].v[0], a[0].v[1], a[0].v[2] }, &u))
            return error_at(p, name.line, name.column, "vnormalize() of a zero vector");
        set_vector(out, 3);
        out->v[0] = u.x;
        out->v[1] = u.y;
        out->v[2] = u.z;
        break;
    }
    case FN_VDOT:
        r = a[0].v[0] * a[1].v[0] + a[0].v[1] * a[1].v[1] + a[0].v[2] * a[1].v[2];
        break;
    case FN_VCROSS:
        set_vector(out, 3);
        out->v[0] = a[0].v[1] * a[1].v[2] - a[0].v[2] * a[1].v[1];
        out->v[1] = a[0].v[2] * a[1].v[0] - a[0].v[0] * a[1].v[2];
        out->v[2] = a[0].v[0] * a[1].v[1] - a[0].v[1] * a[1].v[0];
        break;
    }
    if (!fn->vec_result)
        out->v[0] = r;
    if (!val_finite(out))
        return error_at(p, name.line, name.column, "the result of %s() is not a finite number",
                        fn->name);
    return 0;
}

/* < a, b, c [, d [, e]] >: the components are read without the
 * comparisons < and > (the closing '>'), unless in parentheses. */
static int parse_vector_literal(parser *p, val *out)
{
    rs_token open = take(p);
    int saved = p->in_vector, n = 0;
    if (enter(p, &open) != 0)
        return -1;
    set_float(out, 0.0);
    p->in_vector = 1;
    for (;;) {
        rs_token start = *peek(p);
        val c;
        if (parse_expr(p, &c) != 0)
            return -1;
        if (c.kind != VAL_FLOAT) {
            rs__val_free(&c);
            return error_at(p, start.line, start.column,
                            "expected a float for a vector component, found %s",
                            kind_name(c.kind));
        }
        out->v[n++] = c.v[0];
        if (n >= 3 && is_punct(peek(p), '>'))
            break;
        if (n == 5)
            return expected(p, peek(p), "'>' to close the vector");
        if (n < 3 && !is_punct(peek(p), ','))
            return expected(p, peek(p), n == 1 ? "',' after the first vector component"
                                               : "',' after the second vector component");
        if (!is_punct(peek(p), ','))
            return expected(p, peek(p), "',' or '>' in the vector");
        take(p);
    }
    take(p);
    p->in_vector = saved;
    set_vector(out, n);
    leave(p);
    return 0;
}

static int parse_primary(parser *p, val *out)
{
    const rs_token *t = peek(p);
    const fn_def *fn;
    sym *s;

    set_float(out, 0.0);
    if (t->kind == RS_TOK_NUMBER) {
        out->v[0] = take(p).number;
        return 0;
    }
    if (is_punct(t, '(')) {
        int saved = p->in_vector;
        if (enter(p, t) != 0)
            return -1;
        take(p);
        p->in_vector = 0;
        if (parse_expr(p, out) != 0)
            return -1;
        p->in_vector = saved;
        if (expect_punct(p, ')', "')'") != 0) {
            rs__val_free(out);
            return -1;
        }
        leave(p);
        return 0;
    }
    if (is_punct(t, '<'))
        return parse_vector_literal(p, out);
    if (t->kind == RS_TOK_STRING || is_id(t, "concat") || is_id(t, "str") || is_id(t, "chr")) {
        set_float(out, 0.0);
        out->kind = VAL_STRING;
        return rs__parse_string(p, &out->str);
    }
    if (t->kind == RS_TOK_IDENT) {
        if (builtin_value(p, t, out)) {
            take(p);
            return 0;
        }
        if ((fn = find_function(t)) != NULL)
            return parse_function(p, fn, out);
        if ((s = rs__sym_find(p, t->text, t->len)) != NULL) {
            if (rs__val_copy(&s->v, out) != 0)
                return error_at(p, t->line, t->column, "out of memory");
            take(p);
            return 0;
        }
        if (!is_reserved(t->text, t->len)) {
            int n = t->len > 48 ? 48 : (int)t->len;
            return error_at(p, t->line, t->column, "undeclared identifier '%.*s'", n, t->text);
        }
    }
    return expected(p, t, "an expression");
}

/* primary { . x|y|z|u|v|red|green|blue|filter|transmit|t } */
static int parse_postfix(parser *p, val *out)
{
    if (parse_primary(p, out) != 0)
        return -1;
    while (is_punct(peek(p), '.')) {
        static const struct { const char *name; int k; } comps[] = {
            { "x", 0 }, { "u", 0 }, { "red", 0 }, { "y", 1 }, { "v", 1 }, { "green", 1 },
            { "z", 2 }, { "blue", 2 }, { "filter", 3 }, { "transmit", 4 }, { "t", 4 },
        };
        rs_token dot = take(p);
        const rs_token *c = peek(p);
        int k = -1;
        for (size_t i = 0; i < sizeof comps / sizeof comps[0]; i++)
            if (is_id(c, comps[i].name))
                k = comps[i].k;
        if (k < 0) {
            rs__val_free(out);
            return expected(p, c, "x, y, z, red, green, blue, filter or transmit after '.'");
        }
        if (out->kind != VAL_VECTOR) {
            rs__val_free(out);
            return error_at(p, dot.line, dot.column, "'.' needs a vector, found %s",
                            kind_name(out->kind));
        }
        take(p);
        set_float(out, out->v[k]);
    }
    return 0;
}

/* A run of unary signs and '!', read in a loop (no recursion). */
static int parse_unary(parser *p, val *out)
{
    int neg = 0, nots = 0;
    rs_token start = *peek(p);
    while (is_punct(peek(p), '-') || is_punct(peek(p), '+') || is_punct(peek(p), '!')) {
        rs_token op = take(p);
        if (op.punct == '-')
            neg = !neg;
        else if (op.punct == '!')
            nots++;
    }
    if (parse_postfix(p, out) != 0)
        return -1;
    if ((neg || nots) && want_number(p, out, &start, "a number after a sign") != 0)
        return -1;
    if (neg)
        for (int i = 0; i < 5; i++)
            out->v[i] = -out->v[i];
    if (nots) {
        if (out->kind != VAL_FLOAT)
            return error_at(p, start.line, start.column, "'!' needs a float, found a vector");
        if (nots & 1)
            out->v[0] = out->v[0] == 0.0 ? 1.0 : 0.0;
        else
            out->v[0] = out->v[0] != 0.0;
    }
    return 0;
}

static int binary(parser *p, const rs_token *op, val *a, val b)
{
    int dim;
    if (a->kind != VAL_FLOAT && a->kind != VAL_VECTOR) {
        rs__val_free(&b);
        rs__val_free(a);
        return error_at(p, op->line, op->column, "'%c' needs numbers on its left", op->punct);
    }
    if (b.kind != VAL_FLOAT && b.kind != VAL_VECTOR) {
        rs__val_free(&b);
        return error_at(p, op->line, op->column, "'%c' needs numbers on its right", op->punct);
    }
    if (a->kind == VAL_VECTOR || b.kind == VAL_VECTOR) {
        dim = a->kind == VAL_VECTOR ? a->dim : 3;
        if (b.kind == VAL_VECTOR && b.dim > dim)
            dim = b.dim;
        promote_to(a, dim);
        promote_to(&b, dim);
    }
    for (int i = 0; i < 5; i++) {
        switch (op->punct) {
        case '+': a->v[i] += b.v[i]; break;
        case '-': a->v[i] -= b.v[i]; break;
        case '*': a->v[i] *= b.v[i]; break;
        default:
            if (b.v[i] == 0.0) {
                if (i >= (a->kind == VAL_VECTOR ? a->dim : 1))
                    continue; /* padding of a shorter vector */
                return error_at(p, op->line, op->column, "division by zero");
            }
            a->v[i] /= b.v[i];
            break;
        }
    }
    if (!val_finite(a))
        return error_at(p, op->line, op->column, "the result of '%c' is not a finite number",
                        op->punct);
    return 0;
}

static int parse_term(parser *p, val *out)
{
    if (parse_unary(p, out) != 0)
        return -1;
    while (is_punct(peek(p), '*') || is_punct(peek(p), '/')) {
        rs_token op = take(p);
        val b = { 0 };   /* nothing to free until parsed */
        if (parse_unary(p, &b) != 0) {
            rs__val_free(&b);
            return -1;
        }
        if (binary(p, &op, out, b) != 0)
            return -1;
    }
    return 0;
}

static int parse_sum(parser *p, val *out)
{
    if (parse_term(p, out) != 0)
        return -1;
    while (is_punct(peek(p), '+') || is_punct(peek(p), '-')) {
        rs_token op = take(p);
        val b = { 0 };   /* nothing to free until parsed */
        if (parse_term(p, &b) != 0) {
            rs__val_free(&b);
            return -1;
        }
        if (binary(p, &op, out, b) != 0)
            return -1;
    }
    return 0;
}

/* a OP b for the comparisons and & |: both floats, result 0 or 1. */
static int compare(parser *p, const rs_token *op, const char *name, val *a, val *b, double r)
{
    if (a->kind != VAL_FLOAT || b->kind != VAL_FLOAT) {
        rs__val_free(a);
        rs__val_free(b);
        return error_at(p, op->line, op->column, "'%s' needs floats on both sides", name);
    }
    set_float(a, r);
    return 0;
}

/* sum [ < <= = != >= > sum ]: '<' only after a float (after a vector it
 * starts the next vector), '>' not inside a vector literal. */
static int parse_relation(parser *p, val *out)
{
    if (parse_sum(p, out) != 0)
        return -1;
    for (;;) {
        const rs_token *t = peek(p);
        rs_token op;
        char name[3] = { 0, 0, 0 };
        val b = { 0 };   /* nothing to free until parsed */
        double x, y, r;
        if (!(is_punct(t, '=') || is_punct(t, '!') ||
              (!p->in_vector && out->kind == VAL_FLOAT &&
               (is_punct(t, '<') || is_punct(t, '>')))))
            return 0;
        op = take(p);
        name[0] = op.punct;
        if (op.punct != '=' && is_punct(peek(p), '=')) {
            take(p);
            name[1] = '=';
        } else if (op.punct == '!') {
            return expected(p, peek(p), "'=' after '!'");
        }
        if (parse_sum(p, &b) != 0) {
            rs__val_free(&b);
            return -1;
        }
        x = out->v[0];
        y = b.v[0];
        if (name[0] == '=')
            r = x == y;
        else if (name[0] == '!')
            r = x != y;
        else if (name[0] == '<')
            r = name[1] ? x <= y : x < y;
        else
            r = name[1] ? x >= y : x > y;
        if (compare(p, &op, name, out, &b, r) != 0)
            return -1;
    }
}

static int parse_and(parser *p, val *out)
{
    if (parse_relation(p, out) != 0)
        return -1;
    while (is_punct(peek(p), '&')) {
        rs_token op = take(p);
        val b = { 0 };   /* nothing to free until parsed */
        if (parse_relation(p, &b) != 0) {
            rs__val_free(&b);
            return -1;
        }
        if (compare(p, &op, "&", out, &b, out->v[0] != 0.0 && b.v[0] != 0.0) != 0)
            return -1;
    }
    return 0;
}

static int parse_or(parser *p, val *out)
{
    if (parse_and(p, out) != 0)
        return -1;
    while (is_punct(peek(p), '|')) {
        rs_token op = take(p);
        val b = { 0 };   /* nothing to free until parsed */
        if (parse_and(p, &b) != 0) {
            rs__val_free(&b);
            return -1;
        }
        if (compare(p, &op, "|", out, &b, out->v[0] != 0.0 || b.v[0] != 0.0) != 0)
            return -1;
    }
    return 0;
}

/* or [ ? expr : expr ] (both branches are read; one is kept). */
static int parse_ternary(parser *p, val *out)
{
    rs_token q;
    val a, b;
    if (parse_or(p, out) != 0)
        return -1;
    if (!is_punct(peek(p), '?'))
        return 0;
    q = take(p);
    if (out->kind != VAL_FLOAT) {
        rs__val_free(out);
        return error_at(p, q.line, q.column, "'?' needs a float condition");
    }
    if (enter(p, &q) != 0)
        return -1;
    if (parse_expr(p, &a) != 0)
        return -1;
    if (expect_punct(p, ':', "':' in 'c ? a : b'") != 0) {
        rs__val_free(&a);
        return -1;
    }
    if (parse_expr(p, &b) != 0) {
        rs__val_free(&a);
        return -1;
    }
    leave(p);
    if (out->v[0] != 0.0) {
        *out = a;
        rs__val_free(&b);
    } else {
        *out = b;
        rs__val_free(&a);
    }
    return 0;
}

/* An expression; on failure *out holds nothing to free. */
static int parse_expr(parser *p, val *out)
{
    if (parse_ternary(p, out) != 0) {
        rs__val_free(out);
        return -1;
    }
    return 0;
}

static int parse_float(parser *p, const char *what, double *out)
{
    rs_token start = *peek(p);
    val v;
    if (parse_expr(p, &v) != 0)
        return -1;
    if (want_float_val(p, &v, &start, what) != 0) {
        rs__val_free(&v);
        return -1;
    }
    *out = v.v[0];
    return 0;
}

static int parse_vector(parser *p, lp_vec3 *out)
{
    val v;
    if (parse_number(p, &v, "a vector") != 0)
        return -1;
    promote(&v);
    out->x = v.v[0];
    out->y = v.v[1];
    out->z = v.v[2];
    return 0;
}

/* A vector that must not be zero. */
static int parse_nonzero_vector(parser *p, const char *what, lp_vec3 *out)
{
    rs_token start = *peek(p);
    if (parse_vector(p, out) != 0)
        return -1;
    if (out->x == 0.0 && out->y == 0.0 && out->z == 0.0)
        return error_at(p, start.line, start.column, "%s must not be a zero vector", what);
    return 0;
}

/* ------------------------------------------------------------------ */
/* Strings                                                             */
/* ------------------------------------------------------------------ */

static int append(parser *p, const rs_token *at, char *buf, size_t *len, const char *s, size_t n)
{
    if (*len + n >= MAX_STRING)
        return error_at(p, at->line, at->column, "a string longer than %d bytes",
                        MAX_STRING - 1);
    memcpy(buf + *len, s, n);
    *len += n;
    buf[*len] = '\0';
    return 0;
}

/* "literal" | concat(S, ...) | str(F, W, P) | chr(F) | a string identifier. */
int rs__parse_string(parser *p, char **out)
{
    const rs_token *t = peek(p);
    rs_token at = *t;
    char buf[MAX_STRING];
    size_t len = 0;
    sym *s;

    *out = NULL;
    buf[0] = '\0';
    if (t->kind == RS_TOK_STRING) {
        int n = rs_string_decode(t, buf, sizeof buf);
        if (n < 0)
            return error_at(p, t->line, t->column, "a string longer than %d bytes",
                            MAX_STRING - 1);
        take(p);
    } else if (is_id(t, "concat")) {
        take(p);
        if (enter(p, &at) != 0 || expect_punct(p, '(', "'(' after 'concat'") != 0)
            return -1;
        for (;;) {
            char *part;
            if (rs__parse_string(p, &part) != 0)
                return -1;
            if (append(p, &at, buf, &len, part, strlen(part)) != 0) {
                free(part);
                return -1;
            }
            free(part);
            if (!is_punct(peek(p), ','))
                break;
            take(p);
        }
        if (expect_punct(p, ')', "',' or ')' in concat()") != 0)
            return -1;
        leave(p);
    } else if (is_id(t, "str")) {
        double f, w, prec;
        char num[400];
        take(p);
        if (enter(p, &at) != 0 || expect_punct(p, '(', "'(' after 'str'") != 0 ||
            parse_float(p, "str()", &f) != 0 || expect_punct(p, ',', "',' in str()") != 0 ||
            parse_float(p, "str()", &w) != 0 || expect_punct(p, ',', "',' in str()") != 0 ||
            parse_float(p, "str()", &prec) != 0 || expect_punct(p, ')', "')' after str()") != 0)
            return -1;
        leave(p);
        if (!(fabs(w) <= 64.0) || !(prec <= 64.0))
            return error_at(p, at.line, at.column, "str(): width and precision must be at "
                                                   "most 64");
        /* POV-Ray: a negative width pads with zeros, a negative precision
         * means as many digits as needed */
        if (prec < 0.0)
            snprintf(num, sizeof num, w < 0 ? "%0*g" : "%*g", (int)fabs(w), f);
        else
            snprintf(num, sizeof num, w < 0 ? "%0*.*f" : "%*.*f", (int)fabs(w), (int)prec, f);
        if (append(p, &at, buf, &len, num, strlen(num)) != 0)
            return -1;
    } else if (is_id(t, "chr")) {
        double f;
        char c;
        take(p);
        if (enter(p, &at) != 0 || expect_punct(p, '(', "'(' after 'chr'") != 0 ||
            parse_float(p, "chr()", &f) != 0 || expect_punct(p, ')', "')' after chr()") != 0)
            return -1;
        leave(p);
        if (!(f >= 1.0 && f < 256.0))
            return error_at(p, at.line, at.column, "chr(): a code from 1 to 255");
        c = (char)(unsigned char)f;
        if (append(p, &at, buf, &len, &c, 1) != 0)
            return -1;
    } else if (t->kind == RS_TOK_IDENT && (s = rs__sym_find(p, t->text, t->len)) != NULL &&
               s->v.kind == VAL_STRING) {
        snprintf(buf, sizeof buf, "%s", s->v.str);
        take(p);
    } else {
        return expected(p, t, "a string");
    }
    len = strlen(buf);
    if ((*out = malloc(len + 1)) == NULL)
        return error_at(p, at.line, at.column, "out of memory");
    memcpy(*out, buf, len + 1);
    return 0;
}

/* ------------------------------------------------------------------ */
/* Colours                                                             */
/* ------------------------------------------------------------------ */

static const char transparent_msg[] =
    "transparent pigments are not supported: use a lens object";

/* [color|colour] (rgb V | rgbf V | rgbt V | rgbft V | V) and then
 * red/green/blue/filter/transmit F, into c[0..5) (r g b filter transmit).
 * A float V gives every component (POV-Ray), so `color 0.5` is also half
 * transparent. */
static int parse_color5(parser *p, double c[5])
{
    const rs_token *t = peek(p);
    val v;
    int any = 0;

    set_float(&v, 0.0);
    set_vector(&v, 5);
    if (is_id(t, "color") || is_id(t, "colour")) {
        take(p);
        t = peek(p);
    }
    if (is_id(t, "rgb") || is_id(t, "rgbf") || is_id(t, "rgbt") || is_id(t, "rgbft")) {
        rs_token kw = take(p);
        int n = (int)kw.len - 3 + 3; /* rgb 3, rgbf/rgbt 4, rgbft 5 */
        rs_token start = *peek(p);
        val w;
        if (parse_number(p, &w, "a colour") != 0)
            return -1;
        if (w.kind == VAL_FLOAT) {
            for (int i = 0; i < n; i++)
                v.v[i] = w.v[0];
        } else {
            if (w.dim < n && !(w.dim == 3 && n > 3))
                return error_at(p, start.line, start.column, "%.*s needs %d components",
                                (int)kw.len, kw.text, n);
            for (int i = 0; i < 3; i++)
                v.v[i] = w.v[i];
            if (n == 4)
                v.v[is_id(&kw, "rgbt") ? 4 : 3] = w.dim > 3 ? w.v[3] : 0.0;
            if (n == 5) {
                v.v[3] = w.dim > 3 ? w.v[3] : 0.0;
                v.v[4] = w.dim > 4 ? w.v[4] : 0.0;
            }
        }
        if (n == 4 && w.kind == VAL_FLOAT && is_id(&kw, "rgbt")) {
            v.v[4] = v.v[3];
            v.v[3] = 0.0;
        }
        any = 1;
    } else if (!(is_id(t, "red") || is_id(t, "green") || is_id(t, "blue") ||
                 is_id(t, "filter") || is_id(t, "transmit"))) {
        val w;
        if (!is_expr_start(p, t))
            return expected(p, t, "a colour");
        if (parse_number(p, &w, "a colour") != 0)
            return -1;
        promote_to(&w, 5);
        for (int i = 0; i < 5; i++)
            v.v[i] = w.v[i];
        any = 1;
    }
    for (;;) {
        static const char *const names[] = { "red", "green", "blue", "filter", "transmit" };
        int k = -1;
        t = peek(p);
        for (int i = 0; i < 5; i++)
            if (is_id(t, names[i]))
                k = i;
        if (k < 0)
            break;
        take(p);
        if (parse_float(p, names[k], &v.v[k]) != 0)
            return -1;
        any = 1;
    }
    if (!any)
        return expected(p, peek(p), "a colour");
    for (int i = 0; i < 5; i++)
        c[i] = v.v[i];
    return 0;
}

/* A colour where only an opaque one makes sense (opaque_only: a pigment;
 * else filter and transmit are dropped: light colours, finishes). */
static int parse_color(parser *p, int opaque_only, rs_color *out)
{
    rs_token start = *peek(p);
    double c[5];
    if (parse_color5(p, c) != 0)
        return -1;
    if (opaque_only && (c[3] != 0.0 || c[4] != 0.0))
        return error_at(p, start.line, start.column,
                        "%s (filter %g, transmit %g)%s", transparent_msg, c[3], c[4],
                        (c[0] == c[3] && c[1] == c[3] && c[2] == c[3] && c[4] == c[3])
                            ? " -- a lone float colour also sets filter and transmit in "
                              "POV-Ray; write rgb V"
                            : "");
    out->r = c[0];
    out->g = c[1];
    out->b = c[2];
    return 0;
}

/* ------------------------------------------------------------------ */
/* Transforms                                                          */
/* ------------------------------------------------------------------ */

enum { XF_NONE = 0, XF_TRANSLATE, XF_ROTATE, XF_SCALE };

static int transform_kind(const rs_token *t)
{
    if (is_id(t, "translate"))
        return XF_TRANSLATE;
    if (is_id(t, "rotate"))
        return XF_ROTATE;
    if (is_id(t, "scale"))
        return XF_SCALE;
    return XF_NONE;
}

/* *xf = step after *xf, refused when the result is not finite. */
static int apply_step(parser *p, const rs_token *kw, rs_transform *xf, const rs_transform *step)
{
    rs_transform_compose(xf, step, xf);
    if (!rs_transform_finite(xf))
        return error_at(p, kw->line, kw->column,
                        "the transforms are too large: a value is not finite");
    return 0;
}

/* translate|rotate|scale V as one step; *v gets the vector, *kw_out the
 * keyword. */
static int parse_transform_step(parser *p, rs_transform *step, lp_vec3 *v, rs_token *kw_out)
{
    rs_token kw = take(p);
    int kind = transform_kind(&kw);
    rs_token start = *peek(p);
    int ok;

    if (parse_vector(p, v) != 0)
        return -1;
    rs_transform_identity(step);
    if (kind == XF_TRANSLATE)
        ok = rs_transform_translate(step, *v);
    else if (kind == XF_ROTATE)
        ok = rs_transform_rotate(step, *v);
    else
        ok = rs_transform_scale(step, *v);
    if (!ok)
        return error_at(p, start.line, start.column,
                        "scale <%g,%g,%g> has a zero component", v->x, v->y, v->z);
    *kw_out = kw;
    return 0;
}

/* ------------------------------------------------------------------ */
/* Pigment, finish, texture                                            */
/* ------------------------------------------------------------------ */

static void default_pigment(rs_pigment *pig)
{
    memset(pig, 0, sizeof *pig);
    pig->type = RS_PIGMENT_SOLID; /* POV-Ray's default pigment: black */
    rs_transform_identity(&pig->to_pattern);
}

static void default_finish(rs_finish *f)
{
    memset(f, 0, sizeof *f);
    f->ambient = (rs_color){ 0.1, 0.1, 0.1 };
    f->diffuse = 0.6;
    f->brilliance = 1.0;
    f->emission = (rs_color){ 0.0, 0.0, 0.0 };
    f->phong_size = 40.0;
    f->roughness = 0.05;
}

/* A declared value of the given kind named by the current token, or NULL. */
static sym *declared(parser *p, val_kind kind)
{
    const rs_token *t = peek(p);
    sym *s;
    if (t->kind != RS_TOK_IDENT)
        return NULL;
    s = rs__sym_find(p, t->text, t->len);
    return s != NULL && s->v.kind == kind ? s : NULL;
}

/* pigment { ... }: modifies *pig; *pat is the pigment's pattern -> world
 * transform so far (a new colour or checker starts a new one). */
static int parse_pigment(parser *p, rs_pigment *pig, rs_transform *pat)
{
    int has_pattern = 0;
    take(p);
    if (open_block(p, "pigment") != 0)
        return -1;
    for (;;) {
        const rs_token *t = peek(p);
        if (is_punct(t, '}'))
            break;
        if (transform_kind(t) != XF_NONE) {
            rs_transform step;
            rs_token kw;
            lp_vec3 v;
            if (parse_transform_step(p, &step, &v, &kw) != 0 ||
                apply_step(p, &kw, pat, &step) != 0)
                return -1;
        } else if (!has_pattern && declared(p, VAL_PIGMENT) != NULL) {
            const rs_pigment_val *pv = declared(p, VAL_PIGMENT)->v.ptr;
            take(p);
            *pig = pv->pig;
            *pat = pv->pat;
            has_pattern = 1;
        } else if (!has_pattern && is_id(t, "checker")) {
            take(p);
            pig->type = RS_PIGMENT_CHECKER;
            pig->color[0] = (rs_color){ 0.0, 0.0, 1.0 }; /* POV-Ray: blue, */
            pig->color[1] = (rs_color){ 0.0, 1.0, 0.0 }; /* then green */
            if (is_color_start(p, peek(p))) {
                if (parse_color(p, 1, &pig->color[0]) != 0)
                    return -1;
                skip_comma(p);
                if (is_color_start(p, peek(p)) && parse_color(p, 1, &pig->color[1]) != 0)
                    return -1;
            }
            rs_transform_identity(pat);
            has_pattern = 1;
        } else if (!has_pattern && is_color_start(p, t)) {
            if (parse_color(p, 1, &pig->color[0]) != 0)
                return -1;
            pig->type = RS_PIGMENT_SOLID;
            pig->color[1] = pig->color[0];
            rs_transform_identity(pat);
            has_pattern = 1;
        } else {
            return expected(p, t, has_pattern
                                      ? "translate, rotate, scale or '}' in pigment"
                                      : "a colour, checker, translate, rotate, scale or '}' "
                                        "in pigment");
        }
    }
    return close_block(p, "pigment");
}

/* reflection F | C | { [C_MIN ,] C_MAX [fresnel [BOOL]] [falloff F] [exponent F]
 * [metallic [F]] } (the last three are read and warned about). */
static int parse_reflection(parser *p, rs_finish *f)
{
    rs_color a, b;
    if (!is_punct(peek(p), '{')) {
        if (parse_color(p, 0, &a) != 0)
            return -1;
        f->reflection_min = f->reflection_max = a;
        f->fresnel = 0;
        return 0;
    }
    if (open_block(p, "reflection") != 0 || parse_color(p, 0, &a) != 0)
        return -1;
    b = a;
    if (is_punct(peek(p), ',')) {
        take(p);
        if (parse_color(p, 0, &b) != 0)
            return -1;
    }
    f->reflection_min = a;
    f->reflection_max = b;
    f->fresnel = 0;
    for (;;) {
        const rs_token *t = peek(p);
        if (is_punct(t, '}'))
            break;
        if (is_id(t, "fresnel")) {
            double v = 1.0;
            take(p);
            if (is_expr_start(p, peek(p)) && parse_float(p, "fresnel", &v) != 0)
                return -1;
            f->fresnel = v != 0.0;
        } else if (is_id(t, "falloff") || is_id(t, "exponent") || is_id(t, "metallic")) {
            rs_token kw = take(p);
            double v = 1.0;
            if ((!is_id(&kw, "metallic") || is_expr_start(p, peek(p))) &&
                parse_float(p, "the reflection parameter", &v) != 0)
                return -1;
            rs__warn(p, kw.line, kw.column, "reflection %.*s is read but not rendered",
                     (int)kw.len, kw.text);
        } else {
            return expected(p, t, "fresnel, falloff, exponent, metallic or '}' in reflection");
        }
    }
    return close_block(p, "reflection");
}

static int parse_finish(parser *p, rs_finish *f)
{
    take(p);
    if (open_block(p, "finish") != 0)
        return -1;
    if (declared(p, VAL_FINISH) != NULL) {
        *f = *(const rs_finish *)declared(p, VAL_FINISH)->v.ptr;
        take(p);
    }
    for (;;) {
        static const struct { const char *kw; size_t off; int positive; } floats[] = {
            { "diffuse", offsetof(rs_finish, diffuse), 0 },
            { "brilliance", offsetof(rs_finish, brilliance), 0 },
            { "phong", offsetof(rs_finish, phong), 0 },
            { "phong_size", offsetof(rs_finish, phong_size), 1 },
            { "specular", offsetof(rs_finish, specular), 0 },
            { "roughness", offsetof(rs_finish, roughness), 1 },
        };
        const rs_token *t = peek(p);
        int done = 0;
        if (is_punct(t, '}'))
            break;
        if (is_id(t, "ambient")) {
            take(p);
            if (parse_color(p, 0, &f->ambient) != 0)
                return -1;
            continue;
        }
        if (is_id(t, "emission")) {
            take(p);
            if (parse_color(p, 0, &f->emission) != 0)
                return -1;
            continue;
        }
        if (is_id(t, "reflection")) {
            take(p);
            if (parse_reflection(p, f) != 0)
                return -1;
            continue;
        }
        if (is_id(t, "conserve_energy")) {
            take(p);
            f->conserve_energy = 1;
            continue;
        }
        if (is_id(t, "metallic") || is_id(t, "crand") || is_id(t, "irid")) {
            rs_token kw = take(p);
            double v;
            if (is_id(&kw, "irid"))
                return error_at(p, kw.line, kw.column, "irid is not supported");
            if (is_expr_start(p, peek(p)) && parse_float(p, "the finish parameter", &v) != 0)
                return -1;
            rs__warn(p, kw.line, kw.column, "finish %.*s is read but not rendered",
                     (int)kw.len, kw.text);
            continue;
        }
        for (size_t i = 0; i < sizeof floats / sizeof floats[0]; i++) {
            if (is_id(t, floats[i].kw)) {
                rs_token kw = take(p);
                rs_token start = *peek(p);
                double *dst = (double *)((char *)f + floats[i].off);
                if (parse_float(p, floats[i].kw, dst) != 0)
                    return -1;
                if (floats[i].positive ? !(*dst > 0.0) : !(*dst >= 0.0))
                    return error_at(p, start.line, start.column, "%s must be %s",
                                    floats[i].kw, floats[i].positive ? "positive"
                                                                      : "at least 0");
                (void)kw;
                done = 1;
                break;
            }
        }
        if (!done)
            return expected(p, t, "ambient, diffuse, brilliance, emission, specular, roughness, "
                                  "phong, phong_size, reflection, conserve_energy, metallic or "
                                  "'}' in finish");
    }
    return close_block(p, "finish");
}

static int parse_texture(parser *p, rs_pigment *pig, rs_transform *pat, rs_finish *fin)
{
    take(p);
    if (open_block(p, "texture") != 0)
        return -1;
    if (declared(p, VAL_TEXTURE) != NULL) {
        const rs_texture_val *tv = declared(p, VAL_TEXTURE)->v.ptr;
        take(p);
        *pig = tv->pig;
        *pat = tv->pat;
        *fin = tv->fin;
    }
    for (;;) {
        const rs_token *t = peek(p);
        if (is_punct(t, '}'))
            break;
        if (is_id(t, "pigment")) {
            if (parse_pigment(p, pig, pat) != 0)
                return -1;
        } else if (is_id(t, "finish")) {
            if (parse_finish(p, fin) != 0)
                return -1;
        } else if (transform_kind(t) != XF_NONE) {
            rs_transform step;
            rs_token kw;
            lp_vec3 v;
            if (parse_transform_step(p, &step, &v, &kw) != 0 ||
                apply_step(p, &kw, pat, &step) != 0)
                return -1;
        } else {
            return expected(p, t, "pigment, finish, translate, rotate, scale or '}' in texture");
        }
    }
    return close_block(p, "texture");
}

/* ------------------------------------------------------------------ */
/* Objects                                                             */
/* ------------------------------------------------------------------ */

static const char *const type_names[] = { "plane", "sphere", "box", "disc", "lens",
                                          "polarizer", "cylinder", "cone", "torus", "csg" };
static const char *const csg_names[] = { "union", "intersection", "difference" };
static const char *const csg_phrases[] = { "a union", "an intersection", "a difference" };

static const char *object_name(const rs_object *o)
{
    return o->type == RS_OBJ_CSG ? csg_names[o->u.csg.op] : type_names[o->type];
}

static void object_init(rs_object *o, rs_object_type type, const parser *p, const rs_token *kw)
{
    memset(o, 0, sizeof *o);
    o->type = type;
    o->loc.file = p->file;
    o->loc.line = kw->line;
    o->loc.column = kw->column;
    rs_transform_identity(&o->xf);
    default_pigment(&o->pigment);
    default_finish(&o->finish);
    o->ior = 1.0;
    o->lens = NULL;
}

static int check_room(parser *p, size_t n, const rs_token *kw, const char *what)
{
    if (n >= p->max_objects)
        return error_at(p, kw->line, kw->column, "too many %s (the limit is %zu)", what,
                        p->max_objects);
    return 0;
}

/* Move o into the scene (o owns nothing afterwards); a CSG's members take
 * their textures now that it is final. */
static int push_object(parser *p, rs_object *o, const rs_token *kw)
{
    rs_scene *s = p->scene;
    if (check_room(p, s->n_objects, kw, "objects") != 0)
        return -1;
    if (s->n_objects == s->cap_objects) {
        size_t cap = s->cap_objects ? s->cap_objects * 2 : 16;
        rs_object *a;
        if (cap > p->max_objects)
            cap = p->max_objects;
        a = realloc(s->objects, cap * sizeof *a);
        if (a == NULL)
            return error_at(p, kw->line, kw->column, "out of memory");
        s->objects = a;
        s->cap_objects = cap;
    }
    s->objects[s->n_objects] = *o;
    rs_csg_inherit(&s->objects[s->n_objects++]);
    if (o->type == RS_OBJ_CSG) {
        o->u.csg.members = NULL;
        o->u.csg.n_members = 0;
    }
    return 0;
}

/* interior { ior F }: the index an opaque object's fresnel reflection uses. */
static int parse_interior(parser *p, double *ior)
{
    take(p);
    if (open_block(p, "interior") != 0)
        return -1;
    if (declared(p, VAL_INTERIOR) != NULL) {
        *ior = *(const double *)declared(p, VAL_INTERIOR)->v.ptr;
        take(p);
    }
    for (;;) {
        const rs_token *t = peek(p);
        if (is_punct(t, '}'))
            break;
        if (is_id(t, "ior")) {
            rs_token start;
            take(p);
            start = *peek(p);
            if (parse_float(p, "ior", ior) != 0)
                return -1;
            if (!(*ior > 0.0))
                return error_at(p, start.line, start.column, "ior must be positive");
        } else {
            return expected(p, t, "ior or '}' in interior");
        }
    }
    return close_block(p, "interior");
}

/* pigment / finish / texture / transforms until '}'.  The pigment's
 * to_pattern is the inverse of its pattern -> world transform: its own
 * transforms, then the object's written after it. */
static int parse_object_modifiers(parser *p, rs_object *o)
{
    const char *name = object_name(o);
    rs_transform pat;
    char what[112];

    rs_transform_identity(&pat);
    for (;;) {
        const rs_token *t = peek(p);
        if (is_punct(t, '}'))
            break;
        if (is_id(t, "pigment")) {
            if (parse_pigment(p, &o->pigment, &pat) != 0)
                return -1;
            o->has_texture = 1;
        } else if (is_id(t, "finish")) {
            if (parse_finish(p, &o->finish) != 0)
                return -1;
            o->has_texture = 1;
        } else if (is_id(t, "texture")) {
            if (parse_texture(p, &o->pigment, &pat, &o->finish) != 0)
                return -1;
            o->has_texture = 1;
        } else if (is_id(t, "interior")) {
            if (parse_interior(p, &o->ior) != 0)
                return -1;
            o->has_interior = 1;
        } else if (is_id(t, "inverse")) {
            take(p);
            o->inverse = !o->inverse;
        } else if (transform_kind(t) != XF_NONE) {
            rs_transform step;
            rs_token kw;
            lp_vec3 v;
            if (parse_transform_step(p, &step, &v, &kw) != 0 ||
                apply_step(p, &kw, &o->xf, &step) != 0 || apply_step(p, &kw, &pat, &step) != 0)
                return -1;
        } else {
            snprintf(what, sizeof what,
                     "pigment, finish, texture, interior, inverse, translate, rotate, scale or "
                     "'}' in %s", name);
            return expected(p, t, what);
        }
    }
    /* world -> pattern: swap the two directions */
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            o->pigment.to_pattern.m[i][j] = pat.inv_m[i][j];
            o->pigment.to_pattern.inv_m[i][j] = pat.m[i][j];
        }
        o->pigment.to_pattern.t[i] = pat.inv_t[i];
        o->pigment.to_pattern.inv_t[i] = pat.t[i];
    }
    return close_block(p, name);
}

static int parse_plane(parser *p, rs_object *o)
{
    if (open_block(p, "plane") != 0)
        return -1;
    if (parse_nonzero_vector(p, "the plane normal", &o->u.plane.normal) != 0)
        return -1;
    normalize(o->u.plane.normal, &o->u.plane.normal); /* non-zero, finite */
    skip_comma(p);
    if (parse_float(p, "the plane distance", &o->u.plane.distance) != 0)
        return -1;
    return parse_object_modifiers(p, o);
}

static int parse_sphere(parser *p, rs_object *o)
{
    rs_token start;
    if (open_block(p, "sphere") != 0 || parse_vector(p, &o->u.sphere.center) != 0)
        return -1;
    skip_comma(p);
    start = *peek(p);
    if (parse_float(p, "the sphere radius", &o->u.sphere.radius) != 0)
        return -1;
    if (!(o->u.sphere.radius > 0.0))
        return error_at(p, start.line, start.column, "the sphere radius must be positive");
    return parse_object_modifiers(p, o);
}

static int parse_box(parser *p, rs_object *o)
{
    lp_vec3 a, b;
    if (open_block(p, "box") != 0 || parse_vector(p, &a) != 0)
        return -1;
    skip_comma(p);
    if (parse_vector(p, &b) != 0)
        return -1;
    o->u.box.corner1 = (lp_vec3){ fmin(a.x, b.x), fmin(a.y, b.y), fmin(a.z, b.z) };
    o->u.box.corner2 = (lp_vec3){ fmax(a.x, b.x), fmax(a.y, b.y), fmax(a.z, b.z) };
    return parse_object_modifiers(p, o);
}

static int parse_disc(parser *p, rs_object *o)
{
    rs_token start;
    if (open_block(p, "disc") != 0 || parse_vector(p, &o->u.disc.center) != 0)
        return -1;
    skip_comma(p);
    if (parse_nonzero_vector(p, "the disc normal", &o->u.disc.normal) != 0)
        return -1;
    normalize(o->u.disc.normal, &o->u.disc.normal); /* non-zero, finite */
    skip_comma(p);
    start = *peek(p);
    if (parse_float(p, "the disc radius", &o->u.disc.radius) != 0)
        return -1;
    if (!(o->u.disc.radius > 0.0))
        return error_at(p, start.line, start.column, "the disc radius must be positive");
    o->u.disc.hole = 0.0;
    if (is_punct(peek(p), ',')) {
        take(p);
        start = *peek(p);
        if (parse_float(p, "the disc hole radius", &o->u.disc.hole) != 0)
            return -1;
        if (!(o->u.disc.hole >= 0.0 && o->u.disc.hole < o->u.disc.radius))
            return error_at(p, start.line, start.column,
                            "the disc hole radius must be at least 0 and less than the radius");
    }
    return parse_object_modifiers(p, o);
}

/* The uniform-scale rule of lenses and polarizers: |sx| = |sy| = |sz|. */
static int check_uniform(parser *p, const rs_token *kw, lp_vec3 s, const char *object)
{
    double ax = fabs(s.x), ay = fabs(s.y), az = fabs(s.z);
    double hi = fmax(ax, fmax(ay, az)), lo = fmin(ax, fmin(ay, az));
    if (hi - lo > 1e-12 * hi)
        return error_at(p, kw->line, kw->column,
                        "non-uniform scale <%g,%g,%g> of a %s: a %s can only be scaled by the "
                        "same factor on every axis", s.x, s.y, s.z, object, object);
    return 0;
}

/* A similarity transform's scale factor. */
static double xf_scale_factor(const rs_transform *xf)
{
    return vec_length(rs_xf_dir(xf, (lp_vec3){ 0.0, 0.0, 1.0 }));
}

/* A lens radius: a float, or inf / -inf / +inf (flat). */
static int parse_lens_radius(parser *p, const char *what, double *out)
{
    int rc;
    p->allow_inf = 1;
    rc = parse_float(p, what, out);
    p->allow_inf = 0;
    return rc;
}

static int parse_positive(parser *p, const char *what, double *out)
{
    rs_token start = *peek(p);
    if (parse_float(p, what, out) != 0)
        return -1;
    if (!(*out > 0.0))
        return error_at(p, start.line, start.column, "%s must be positive", what);
    return 0;
}

static int check_glass(parser *p, const rs_token *at, const lp_glass *g)
{
    lp_error err;
    if (lp_glass_check(g, &err) != LP_OK)
        return error_at(p, at->line, at->column, "lens: %s", err.message);
    return 0;
}

/* The lens is of a uniaxial crystal (the token g, 'uniaxial' or 'crystal'
 * is taken):
 *   uniaxial { ordinary N extraordinary N axis <x, y, z> }   constant indices
 *   crystal "NAME" [axis <x, y, z>]                          built in
 * The axis (default <0, 0, 1>) is in the lens's frame; *axis receives it
 * for the lens's transforms. */
static int parse_crystal(parser *p, lp_lens_desc *d, const rs_token *g, lp_vec3 *axis)
{
    lp_error err;
    *axis = (lp_vec3){ 0.0, 0.0, 1.0 };
    d->uniaxial = 1;
    if (is_id(g, "crystal")) {
        char name[LP_GLASS_NAME_MAX];
        const rs_token *s = peek(p);
        if (s->kind != RS_TOK_STRING)
            return expected(p, s, "a crystal name in quotes after 'crystal'");
        if (rs_string_decode(s, name, sizeof name) < 0 ||
            lp_crystal_builtin(name, &d->crystal, &err) != LP_OK)
            return error_at(p, s->line, s->column, "lens: %s",
                            s->len >= LP_GLASS_NAME_MAX ? "crystal name too long" : err.message);
        take(p);
        if (is_id(peek(p), "axis")) {
            take(p);
            if (parse_nonzero_vector(p, "the crystal axis", axis) != 0)
                return -1;
        }
        return 0;
    }
    double no = 0.0, ne = 0.0;
    if (open_block(p, "uniaxial") != 0)
        return -1;
    for (;;) {
        const rs_token *t = peek(p);
        if (is_punct(t, '}'))
            break;
        if (is_id(t, "ordinary")) {
            take(p);
            if (parse_positive(p, "ordinary", &no) != 0)
                return -1;
        } else if (is_id(t, "extraordinary")) {
            take(p);
            if (parse_positive(p, "extraordinary", &ne) != 0)
                return -1;
        } else if (is_id(t, "axis")) {
            take(p);
            if (parse_nonzero_vector(p, "the crystal axis", axis) != 0)
                return -1;
        } else {
            return expected(p, t, "ordinary, extraordinary, axis or '}' in uniaxial");
        }
    }
    if (!(no > 0.0) || !(ne > 0.0))
        return error_at(p, g->line, g->column, "uniaxial: missing %s index",
                        no > 0.0 ? "the extraordinary" : "the ordinary");
    if (close_block(p, "uniaxial") != 0)
        return -1;
    lp_crystal_init_constant(&d->crystal, no, ne, *axis);
    if (lp_crystal_check(&d->crystal, &err) != LP_OK)
        return error_at(p, g->line, g->column, "lens: %s", err.message);
    return 0;
}

static int parse_lens(parser *p, rs_object *o, const rs_token *kw)
{
    lp_lens_desc *d = &o->u.lens.desc;
    rs_transform xf;
    int have_r1 = 0, have_r2 = 0, have_t = 0, have_d = 0, have_glass = 0;
    double k, r1, r2;
    lp_vec3 axis, crystal_axis = { 0.0, 0.0, 1.0 };

    lp_lens_desc_init(d);
    o->u.lens.glass_name[0] = '\0';
    rs_transform_identity(&xf);
    if (open_block(p, "lens") != 0)
        return -1;
    for (;;) {
        const rs_token *t = peek(p);
        if (is_punct(t, '}'))
            break;
        if (is_id(t, "radius1")) {
            take(p);
            if (parse_lens_radius(p, "radius1", &d->radius1) != 0)
                return -1;
            have_r1 = 1;
        } else if (is_id(t, "radius2")) {
            take(p);
            if (parse_lens_radius(p, "radius2", &d->radius2) != 0)
                return -1;
            have_r2 = 1;
        } else if (is_id(t, "thickness")) {
            take(p);
            if (parse_positive(p, "thickness", &d->thickness) != 0)
                return -1;
            have_t = 1;
        } else if (is_id(t, "diameter")) {
            take(p);
            if (parse_positive(p, "diameter", &d->diameter) != 0)
                return -1;
            have_d = 1;
        } else if (is_id(t, "diameter2")) {
            take(p);
            if (parse_positive(p, "diameter2", &d->diameter2) != 0)
                return -1;
        } else if (is_id(t, "glass") || is_id(t, "ior") || is_id(t, "sellmeier")) {
            rs_token g = take(p);
            if (have_glass)
                return error_at(p, g.line, g.column,
                                "lens: the glass is already given (use one of glass, ior, "
                                "sellmeier)");
            have_glass = 1;
            if (is_id(&g, "glass")) {
                const rs_token *s = peek(p);
                if (s->kind != RS_TOK_STRING)
                    return expected(p, s, "a glass name in quotes after 'glass'");
                if (s->len == 0)
                    return error_at(p, s->line, s->column, "lens: empty glass name");
                if (rs_string_decode(s, o->u.lens.glass_name, sizeof o->u.lens.glass_name) < 0)
                    return error_at(p, s->line, s->column,
                                    "lens: glass name longer than %d characters",
                                    LP_GLASS_NAME_MAX - 1);
                take(p);
            } else if (is_id(&g, "ior")) {
                double n;
                if (parse_positive(p, "ior", &n) != 0)
                    return -1;
                lp_glass_init_constant(&d->glass, n);
                if (check_glass(p, &g, &d->glass) != 0)
                    return -1;
            } else {
                double c[6];
                if (open_block(p, "sellmeier") != 0)
                    return -1;
                for (int i = 0; i < 6; i++) {
                    static const char *const names[] = { "B1", "B2", "B3", "C1", "C2", "C3" };
                    if (i > 0 && expect_punct(p, ',', "',' between sellmeier coefficients") != 0)
                        return -1;
                    if (parse_float(p, names[i], &c[i]) != 0)
                        return -1;
                }
                if (close_block(p, "sellmeier") != 0)
                    return -1;
                lp_glass_init_sellmeier(&d->glass, "sellmeier", c, c + 3);
                if (check_glass(p, &g, &d->glass) != 0)
                    return -1;
            }
        } else if (is_id(t, "uniaxial") || is_id(t, "crystal")) {
            rs_token g = take(p);
            if (have_glass)
                return error_at(p, g.line, g.column,
                                "lens: the glass is already given (use one of glass, ior, "
                                "sellmeier, uniaxial, crystal)");
            have_glass = 1;
            if (parse_crystal(p, d, &g, &crystal_axis) != 0)
                return -1;
        } else if (is_id(t, "medium")) {
            rs_token m = take(p);
            double n;
            if (!is_id(peek(p), "ior"))
                return expected(p, peek(p), "'ior' after 'medium'");
            take(p);
            if (parse_positive(p, "the medium ior", &n) != 0)
                return -1;
            lp_glass_init_constant(&d->medium, n);
            if (check_glass(p, &m, &d->medium) != 0)
                return -1;
        } else if (transform_kind(t) != XF_NONE) {
            rs_transform step;
            rs_token tk;
            lp_vec3 v;
            if (parse_transform_step(p, &step, &v, &tk) != 0)
                return -1;
            if (transform_kind(&tk) == XF_SCALE && check_uniform(p, &tk, v, "lens") != 0)
                return -1;
            if (apply_step(p, &tk, &xf, &step) != 0)
                return -1;
        } else {
            return expected(p, t, "radius1, radius2, thickness, diameter, diameter2, glass, "
                                  "ior, sellmeier, uniaxial, crystal, medium, translate, "
                                  "rotate, scale or '}' in lens");
        }
    }
    if (!have_r1 || !have_r2 || !have_t || !have_d || !have_glass) {
        const char *missing = !have_r1 ? "radius1" : !have_r2 ? "radius2"
                            : !have_t ? "thickness" : !have_d ? "diameter"
                            : "a glass (glass \"NAME\", ior, sellmeier, uniaxial or crystal)";
        return error_at(p, kw->line, kw->column, "lens: missing %s", missing);
    }
    if (close_block(p, "lens") != 0)
        return -1;
    /* Fold the transforms: front vertex at the local origin, axis +z. */
    k = xf_scale_factor(&xf);
    r1 = d->radius1;
    r2 = d->radius2;
    d->radius1 *= k;
    d->radius2 *= k;
    d->thickness *= k;
    d->diameter *= k;
    d->diameter2 *= k;
    d->position = rs_xf_point(&xf, (lp_vec3){ 0.0, 0.0, 0.0 });
    axis = rs_xf_dir(&xf, (lp_vec3){ 0.0, 0.0, 1.0 });
    d->axis = (lp_vec3){ axis.x / k, axis.y / k, axis.z / k };
    if (d->uniaxial)
        d->crystal.axis = rs_xf_dir(&xf, crystal_axis); /* lensprim wants it in the world */
    if ((isfinite(r1) && !isfinite(d->radius1)) || (isfinite(r2) && !isfinite(d->radius2)) ||
        !isfinite(d->thickness) || !isfinite(d->diameter) || !isfinite(d->diameter2) ||
        !v3_finite(d->position) || !v3_finite(d->axis) ||
        (d->uniaxial && !v3_finite(d->crystal.axis)))
        return error_at(p, kw->line, kw->column,
                        "lens: a value is not finite after the transforms");
    if ((r1 != 0.0 && d->radius1 == 0.0) || (r2 != 0.0 && d->radius2 == 0.0))
        return error_at(p, kw->line, kw->column,
                        "lens: a radius underflows to 0 (flat) after the transforms");
    return 0;
}

static int parse_polarizer(parser *p, rs_object *o, const rs_token *kw)
{
    rs_transform xf;
    lp_vec3 c = { 0.0, 0.0, 0.0 }, n = { 0.0, 0.0, 0.0 }, a = { 0.0, 0.0, 0.0 };
    double r = 0.0, k, dot;
    int have_n = 0, have_r = 0, have_a = 0;
    rs_token axis_tok = *kw;

    rs_transform_identity(&xf);
    if (open_block(p, "polarizer") != 0)
        return -1;
    for (;;) {
        const rs_token *t = peek(p);
        if (is_punct(t, '}'))
            break;
        if (is_id(t, "center")) {
            take(p);
            if (parse_vector(p, &c) != 0)
                return -1;
        } else if (is_id(t, "normal")) {
            take(p);
            if (parse_nonzero_vector(p, "the polarizer normal", &n) != 0)
                return -1;
            have_n = 1;
        } else if (is_id(t, "radius")) {
            take(p);
            if (parse_positive(p, "the polarizer radius", &r) != 0)
                return -1;
            have_r = 1;
        } else if (is_id(t, "axis")) {
            axis_tok = take(p);
            if (parse_nonzero_vector(p, "the polarizer axis", &a) != 0)
                return -1;
            have_a = 1;
        } else if (transform_kind(t) != XF_NONE) {
            rs_transform step;
            rs_token tk;
            lp_vec3 v;
            if (parse_transform_step(p, &step, &v, &tk) != 0)
                return -1;
            if (transform_kind(&tk) == XF_SCALE && check_uniform(p, &tk, v, "polarizer") != 0)
                return -1;
            if (apply_step(p, &tk, &xf, &step) != 0)
                return -1;
        } else {
            return expected(p, t, "center, normal, radius, axis, translate, rotate, scale or "
                                  "'}' in polarizer");
        }
    }
    if (!have_n || !have_r || !have_a)
        return error_at(p, kw->line, kw->column, "polarizer: missing %s",
                        !have_n ? "normal" : !have_r ? "radius" : "axis");
    /* Fold the transforms; keep the axis in the disc's plane. */
    k = xf_scale_factor(&xf);
    if (!normalize(rs_xf_dir(&xf, n), &n) || !normalize(rs_xf_dir(&xf, a), &a))
        return error_at(p, kw->line, kw->column,
                        "polarizer: the normal or the axis is not finite (or vanishes) after "
                        "the transforms");
    dot = a.x * n.x + a.y * n.y + a.z * n.z;
    a = (lp_vec3){ a.x - dot * n.x, a.y - dot * n.y, a.z - dot * n.z };
    if (!(vec_length(a) > 1e-9) || !normalize(a, &a))
        return error_at(p, axis_tok.line, axis_tok.column,
                        "the polarizer axis must not be parallel to its normal");
    o->u.polarizer.center = rs_xf_point(&xf, c);
    o->u.polarizer.normal = n;
    o->u.polarizer.axis = a;
    o->u.polarizer.radius = r * k;
    if (!v3_finite(o->u.polarizer.center) || !isfinite(o->u.polarizer.radius))
        return error_at(p, kw->line, kw->column,
                        "polarizer: a value is not finite after the transforms");
    if (!(o->u.polarizer.radius > 0.0))
        return error_at(p, kw->line, kw->column,
                        "polarizer: the radius underflows to 0 after the transforms");
    return close_block(p, "polarizer");
}

/* cylinder { BASE, CAP, R [open] ... } and cone { BASE, R1, CAP, R2 [open]
 * ... }: one reader, the cone reading a radius after each point. */
static int parse_round(parser *p, rs_object *o, int cone)
{
    const char *name = cone ? "cone" : "cylinder";
    rs_token start, rtok;
    lp_vec3 a, b;
    double r1 = 0.0, r2;
    int open = 0;
    if (open_block(p, name) != 0 || parse_vector(p, &a) != 0)
        return -1;
    skip_comma(p);
    rtok = *peek(p);
    if (cone) {
        if (parse_float(p, "the cone's base radius", &r1) != 0)
            return -1;
        skip_comma(p);
    }
    start = *peek(p);
    if (parse_vector(p, &b) != 0)
        return -1;
    if (a.x == b.x && a.y == b.y && a.z == b.z)
        return error_at(p, start.line, start.column, "the %s's base and cap points must differ",
                        name);
    skip_comma(p);
    if (!cone)
        rtok = *peek(p);
    if (parse_float(p, cone ? "the cone's cap radius" : "the cylinder radius", &r2) != 0)
        return -1;
    if (cone && (!(r1 >= 0.0) || !(r2 >= 0.0) || !(r1 > 0.0 || r2 > 0.0)))
        return error_at(p, rtok.line, rtok.column,
                        "the cone's radii must be at least 0, and one of them positive");
    if (!cone && !(r2 > 0.0))
        return error_at(p, rtok.line, rtok.column, "the cylinder radius must be positive");
    if (is_id(peek(p), "open")) {
        take(p);
        open = 1;
    }
    if (cone) {
        o->u.cone.base = a;
        o->u.cone.cap = b;
        o->u.cone.base_radius = r1;
        o->u.cone.cap_radius = r2;
        o->u.cone.open = open;
    } else {
        o->u.cylinder.base = a;
        o->u.cylinder.cap = b;
        o->u.cylinder.radius = r2;
        o->u.cylinder.open = open;
    }
    return parse_object_modifiers(p, o);
}

/* torus { MAJOR, MINOR ... }: about the y axis. */
static int parse_torus(parser *p, rs_object *o, const rs_token *kw)
{
    rs_token start;
    if (open_block(p, "torus") != 0)
        return -1;
    start = *peek(p);
    if (parse_float(p, "the torus major radius", &o->u.torus.major) != 0)
        return -1;
    skip_comma(p);
    if (parse_float(p, "the torus minor radius", &o->u.torus.minor) != 0)
        return -1;
    if (!(o->u.torus.major > 0.0 && o->u.torus.minor > 0.0))
        return error_at(p, start.line, start.column, "the torus radii must be positive");
    (void)kw;
    return parse_object_modifiers(p, o);
}

static int parse_primitive(parser *p, rs_object_type type, rs_group *g)
{
    rs_token kw = take(p);
    rs_object o;
    int rc;

    object_init(&o, type, p, &kw);
    switch (type) {
    case RS_OBJ_PLANE: rc = parse_plane(p, &o); break;
    case RS_OBJ_SPHERE: rc = parse_sphere(p, &o); break;
    case RS_OBJ_BOX: rc = parse_box(p, &o); break;
    case RS_OBJ_DISC: rc = parse_disc(p, &o); break;
    case RS_OBJ_LENS: rc = parse_lens(p, &o, &kw); break;
    case RS_OBJ_CYLINDER: rc = parse_round(p, &o, 0); break;
    case RS_OBJ_CONE: rc = parse_round(p, &o, 1); break;
    case RS_OBJ_TORUS: rc = parse_torus(p, &o, &kw); break;
    default: rc = parse_polarizer(p, &o, &kw); break;
    }
    if (rc != 0)
        return -1;
    if (check_room(p, g->n_objects, &kw, "objects") != 0)
        return -1;
    if (rs__group_push_object(g, &o) != 0)
        return error_at(p, kw.line, kw.column, "out of memory");
    return 0;
}

/* Is xf a similarity (the same scale k on every axis)?  *k gets it. */
static int similarity(const rs_transform *xf, double *k)
{
    double c[3][3], n[3], hi = 0.0, lo = INFINITY;
    for (int j = 0; j < 3; j++) {
        for (int i = 0; i < 3; i++)
            c[j][i] = xf->m[i][j];
        n[j] = vec_length((lp_vec3){ c[j][0], c[j][1], c[j][2] });
        hi = fmax(hi, n[j]);
        lo = fmin(lo, n[j]);
    }
    if (!(hi > 0.0) || hi - lo > 1e-9 * hi)
        return 0;
    for (int a = 0; a < 3; a++)
        for (int b = a + 1; b < 3; b++)
            if (fabs(c[a][0] * c[b][0] + c[a][1] * c[b][1] + c[a][2] * c[b][2]) > 1e-9 * hi * hi)
                return 0;
    *k = hi;
    return 1;
}

/* Move an already built object by T (object { NAME transforms }, a union's
 * transforms): its placement and its pattern. */
static int transform_object(parser *p, const rs_token *kw, rs_object *o, const rs_transform *T)
{
    rs_transform inv;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            inv.m[i][j] = T->inv_m[i][j];
            inv.inv_m[i][j] = T->m[i][j];
        }
        inv.t[i] = T->inv_t[i];
        inv.inv_t[i] = T->t[i];
    }
    rs_transform_compose(&inv, &o->pigment.to_pattern, &o->pigment.to_pattern);
    if (!rs_transform_finite(&o->pigment.to_pattern))
        return error_at(p, kw->line, kw->column,
                        "the transforms are too large: a value is not finite");
    if (o->type == RS_OBJ_LENS || o->type == RS_OBJ_POLARIZER) {
        double k, dot;
        const char *what = o->type == RS_OBJ_LENS ? "lens" : "polarizer";
        if (!similarity(T, &k))
            return error_at(p, kw->line, kw->column,
                            "a %s can only be moved, turned and scaled by the same factor on "
                            "every axis", what);
        if (o->type == RS_OBJ_LENS) {
            lp_lens_desc *d = &o->u.lens.desc;
            lp_vec3 ax = rs_xf_dir(T, d->axis);
            d->radius1 *= k;
            d->radius2 *= k;
            d->thickness *= k;
            d->diameter *= k;
            d->diameter2 *= k;
            d->position = rs_xf_point(T, d->position);
            d->axis = (lp_vec3){ ax.x / k, ax.y / k, ax.z / k };
            if (!v3_finite(d->position) || !isfinite(d->thickness) ||
                !isfinite(d->diameter) || !isfinite(d->diameter2) || !(d->thickness > 0.0))
                return error_at(p, kw->line, kw->column,
                                "lens: a value is not finite after the transforms");
        } else {
            lp_vec3 n, a;
            if (!normalize(rs_xf_dir(T, o->u.polarizer.normal), &n) ||
                !normalize(rs_xf_dir(T, o->u.polarizer.axis), &a))
                return error_at(p, kw->line, kw->column,
                                "polarizer: a value is not finite after the transforms");
            dot = a.x * n.x + a.y * n.y + a.z * n.z;
            a = (lp_vec3){ a.x - dot * n.x, a.y - dot * n.y, a.z - dot * n.z };
            if (!normalize(a, &a))
                return error_at(p, kw->line, kw->column, "polarizer: the axis vanishes");
            o->u.polarizer.center = rs_xf_point(T, o->u.polarizer.center);
            o->u.polarizer.normal = n;
            o->u.polarizer.axis = a;
            o->u.polarizer.radius *= k;
            if (!v3_finite(o->u.polarizer.center) || !(o->u.polarizer.radius > 0.0) ||
                !isfinite(o->u.polarizer.radius))
                return error_at(p, kw->line, kw->column,
                                "polarizer: a value is not finite after the transforms");
        }
        return 0;
    }
    if (o->type == RS_OBJ_CSG) {
        for (size_t i = 0; i < o->u.csg.n_members; i++)
            if (transform_object(p, kw, &o->u.csg.members[i], T) != 0)
                return -1;
        return 0;
    }
    return apply_step(p, kw, &o->xf, T);
}

static int transform_light(parser *p, const rs_token *kw, rs_light *l, const rs_transform *T)
{
    l->position = rs_xf_point(T, l->position);
    if (!v3_finite(l->position))
        return error_at(p, kw->line, kw->column,
                        "light_source: the position is not finite after the transforms");
    if (l->polarized && !normalize(rs_xf_dir(T, l->polarization), &l->polarization))
        return error_at(p, kw->line, kw->column,
                        "light_source: the polarization vanishes after the transforms");
    return 0;
}

static int parse_object_statement(parser *p, rs_group *g);
static int is_object_start(parser *p, const rs_token *t);

/* The modifiers of object { NAME ... } and of union/merge: transforms move
 * everything; a pigment, finish or texture goes to every member without one
 * of its own (to the member itself when there is just one). */
static int parse_group_modifiers(parser *p, rs_group *g, int children, const char *name)
{
    char what[160];
    for (;;) {
        const rs_token *t = peek(p);
        if (is_punct(t, '}'))
            return close_block(p, name);
        if (children && is_object_start(p, t)) {
            if (parse_object_statement(p, g) != 0)
                return -1;
        } else if (transform_kind(t) != XF_NONE) {
            rs_transform step;
            rs_token kw;
            lp_vec3 v;
            if (parse_transform_step(p, &step, &v, &kw) != 0)
                return -1;
            for (size_t i = 0; i < g->n_objects; i++)
                if (transform_object(p, &kw, &g->objects[i], &step) != 0)
                    return -1;
            for (size_t i = 0; i < g->n_lights; i++)
                if (transform_light(p, &kw, &g->lights[i], &step) != 0)
                    return -1;
        } else if (is_id(t, "pigment") || is_id(t, "finish") || is_id(t, "texture")) {
            int one = g->n_objects == 1;
            rs_pigment pig;
            rs_finish fin;
            rs_transform pat;
            int is_pig = is_id(t, "pigment"), is_fin = is_id(t, "finish");
            default_pigment(&pig);
            default_finish(&fin);
            rs_transform_identity(&pat);
            if (one) {
                const rs_transform *tp = &g->objects[0].pigment.to_pattern;
                pig = g->objects[0].pigment;
                fin = g->objects[0].finish;
                for (int i = 0; i < 3; i++) {
                    for (int j = 0; j < 3; j++) {
                        pat.m[i][j] = tp->inv_m[i][j];
                        pat.inv_m[i][j] = tp->m[i][j];
                    }
                    pat.t[i] = tp->inv_t[i];
                    pat.inv_t[i] = tp->t[i];
                }
            }
            if (is_pig ? parse_pigment(p, &pig, &pat)
                       : is_fin ? parse_finish(p, &fin) : parse_texture(p, &pig, &pat, &fin))
                return -1;
            for (int i = 0; i < 3; i++) {
                for (int j = 0; j < 3; j++) {
                    pig.to_pattern.m[i][j] = pat.inv_m[i][j];
                    pig.to_pattern.inv_m[i][j] = pat.m[i][j];
                }
                pig.to_pattern.t[i] = pat.inv_t[i];
                pig.to_pattern.inv_t[i] = pat.t[i];
            }
            for (size_t i = 0; i < g->n_objects; i++) {
                rs_object *o = &g->objects[i];
                if (!one && o->has_texture)
                    continue;
                if (!is_fin)
                    o->pigment = pig;
                if (!is_pig)
                    o->finish = fin;
                o->has_texture = 1;
            }
        } else if (is_id(t, "interior")) {
            double ior = 1.0;
            if (parse_interior(p, &ior) != 0)
                return -1;
            for (size_t i = 0; i < g->n_objects; i++) {
                g->objects[i].ior = ior;
                g->objects[i].has_interior = 1;
            }
        } else {
            snprintf(what, sizeof what, "%spigment, finish, texture, interior, translate, "
                                        "rotate, scale or '}' in %s",
                     children ? "an object, " : "", name);
            return expected(p, t, what);
        }
    }
}

/* Every object of a CSG tree needs an inside: a lens, polarizer or disc
 * anywhere in it is refused at its own place. */
static int check_solid(parser *p, const rs_object *o, const char *csg)
{
    if (o->type == RS_OBJ_CSG) {
        for (size_t i = 0; i < o->u.csg.n_members; i++)
            if (check_solid(p, &o->u.csg.members[i], csg) != 0)
                return -1;
        return 0;
    }
    if (o->type == RS_OBJ_LENS)
        return error_at(p, o->loc.line, o->loc.column,
                        "a lens cannot be part of %s: write it on its own (it is one "
                        "primitive with its own caps and rim)", csg);
    if (o->type == RS_OBJ_POLARIZER || o->type == RS_OBJ_DISC)
        return error_at(p, o->loc.line, o->loc.column,
                        "a %s has no inside and cannot be part of %s: use a thin "
                        "cylinder or box", type_names[o->type], csg);
    return 0;
}

/* Count the objects a CSG tree adds to the scene's memory (its members
 * are not in the scene's object count): at most max_objects in all. */
static int count_nodes(parser *p, const rs_object *o, const rs_token *kw)
{
    if (o->type != RS_OBJ_CSG)
        return 0;
    p->csg_nodes += rs_object_node_count(o);
    if (p->csg_nodes > p->max_objects)
        return error_at(p, kw->line, kw->column,
                        "too many objects in intersections and differences (the limit is "
                        "%zu)", p->max_objects);
    return 0;
}

/* object { NAME modifiers } */
static int parse_object_ref(parser *p, rs_group *g)
{
    rs_token kw = take(p);
    const rs_token *t;
    sym *s;
    rs_group mine;
    int rc;

    if (open_block(p, "object") != 0)
        return -1;
    t = peek(p);
    if (is_object_start(p, t) && !(t->kind == RS_TOK_IDENT && (s = declared(p, VAL_OBJECT)))) {
        memset(&mine, 0, sizeof mine);
        if (parse_object_statement(p, &mine) != 0) {
            rs__group_free(&mine);
            return -1;
        }
    } else {
        if (t->kind != RS_TOK_IDENT)
            return expected(p, t, "a declared object's name in 'object'");
        s = rs__sym_find(p, t->text, t->len);
        if (s == NULL) {
            int n = t->len > 48 ? 48 : (int)t->len;
            return error_at(p, t->line, t->column, "undeclared identifier '%.*s'", n, t->text);
        }
        if (s->v.kind != VAL_OBJECT)
            return error_at(p, t->line, t->column, "'%.*s' is %s, not an object",
                            (int)(t->len > 48 ? 48 : t->len), t->text, kind_name(s->v.kind));
        memset(&mine, 0, sizeof mine);
        if (rs__group_append(&mine, s->v.ptr) != 0) {
            rs__group_free(&mine);
            return error_at(p, t->line, t->column, "out of memory");
        }
        for (size_t i = 0; i < mine.n_objects; i++)
            if (count_nodes(p, &mine.objects[i], t) != 0) {
                rs__group_free(&mine);
                return -1;
            }
        take(p);
    }
    rc = parse_group_modifiers(p, &mine, 0, "object");
    if (rc == 0 && check_room(p, g->n_objects + mine.n_objects, &kw, "objects") != 0)
        rc = -1;
    if (rc == 0 && rs__group_append(g, &mine) != 0)
        rc = error_at(p, kw.line, kw.column, "out of memory");
    rs__group_free(&mine);
    return rc;
}

/* union / merge { objects modifiers }: opaque objects look the same merged
 * or not, so the members are kept as separate objects. */
static int parse_union(parser *p, rs_group *g)
{
    rs_token kw = take(p);
    char name[16];
    rs_group mine;
    int rc;

    snprintf(name, sizeof name, "%.*s", (int)kw.len, kw.text);
    if (open_block(p, name) != 0)
        return -1;
    memset(&mine, 0, sizeof mine);
    rc = parse_group_modifiers(p, &mine, 1, name);
    for (size_t i = 0; rc == 0 && i < mine.n_objects; i++)
        if (mine.objects[i].type == RS_OBJ_LENS || mine.objects[i].type == RS_OBJ_POLARIZER)
            rc = error_at(p, mine.objects[i].loc.line, mine.objects[i].loc.column,
                          "a %s cannot be part of a %s: write it on its own (it is one "
                          "primitive with its own caps and rim)",
                          type_names[mine.objects[i].type], name);
    if (rc == 0 && check_room(p, g->n_objects + mine.n_objects, &kw, "objects") != 0)
        rc = -1;
    if (rc == 0 && rs__group_append(g, &mine) != 0)
        rc = error_at(p, kw.line, kw.column, "out of memory");
    rs__group_free(&mine);
    return rc;
}

/* One member of a CSG from the objects one statement made: itself, or a
 * union node over them (a union or merge statement, or object { NAME }
 * of one).  The objects move into *out. */
static void csg_member(parser *p, rs_group *one, rs_object *out, const rs_token *kw)
{
    if (one->n_objects == 1) {
        *out = one->objects[0];
        one->n_objects = 0;
        return;
    }
    object_init(out, RS_OBJ_CSG, p, kw);
    out->u.csg.op = RS_CSG_UNION;
    out->u.csg.members = one->objects;
    out->u.csg.n_members = one->n_objects;
    one->objects = NULL;
    one->n_objects = one->cap_objects = 0;
}

/* intersection / difference { objects modifiers }: one solid object.  Its
 * transforms go down to the members; its pigment, finish, texture and
 * interior stay with it until it is final (push_object), when every member
 * without its own takes them (POV-Ray's rule). */
static int parse_csg(parser *p, rs_group *g)
{
    rs_token kw = take(p);
    rs_object o;
    rs_group lights;
    size_t cap = 0;
    int rc = 0;

    object_init(&o, RS_OBJ_CSG, p, &kw);
    o.u.csg.op = is_id(&kw, "intersection") ? RS_CSG_INTERSECTION : RS_CSG_DIFFERENCE;
    o.u.csg.members = NULL;
    o.u.csg.n_members = 0;
    if (open_block(p, csg_names[o.u.csg.op]) != 0)
        return -1;
    memset(&lights, 0, sizeof lights);
    while (rc == 0 && is_object_start(p, peek(p))) {
        rs_token mk = *peek(p);
        rs_group one;
        memset(&one, 0, sizeof one);
        rc = parse_object_statement(p, &one);
        for (size_t i = 0; rc == 0 && i < one.n_lights; i++)
            if (rs__group_push_light(&lights, &one.lights[i]) != 0)
                rc = error_at(p, mk.line, mk.column, "out of memory");
        if (rc == 0 && one.n_objects > 0 && o.u.csg.n_members == cap) {
            size_t ncap = cap ? 2 * cap : 4;
            rs_object *grown = NULL;
            if (ncap > p->max_objects)
                ncap = p->max_objects;
            if (cap >= ncap)
                rc = error_at(p, mk.line, mk.column, "too many members (the limit is %zu)",
                              p->max_objects);
            else if ((grown = realloc(o.u.csg.members, ncap * sizeof *grown)) == NULL)
                rc = error_at(p, mk.line, mk.column, "out of memory");
            else {
                o.u.csg.members = grown;
                cap = ncap;
            }
        }
        if (rc == 0 && one.n_objects > 0) {
            csg_member(p, &one, &o.u.csg.members[o.u.csg.n_members], &mk);
            rc = check_solid(p, &o.u.csg.members[o.u.csg.n_members++], csg_phrases[o.u.csg.op]);
        }
        rs__group_free(&one);
    }
    if (rc == 0 && o.u.csg.n_members == 0)
        rc = error_at(p, kw.line, kw.column, "%s needs at least one object",
                      csg_phrases[o.u.csg.op]);
    if (rc == 0)
        rc = parse_object_modifiers(p, &o);
    /* the transforms written on the CSG move its members and lights */
    for (size_t i = 0; rc == 0 && i < o.u.csg.n_members; i++)
        rc = transform_object(p, &kw, &o.u.csg.members[i], &o.xf);
    for (size_t i = 0; rc == 0 && i < lights.n_lights; i++)
        rc = transform_light(p, &kw, &lights.lights[i], &o.xf);
    rs_transform_identity(&o.xf);
    if (rc == 0)
        rc = count_nodes(p, &o, &kw);
    if (rc == 0 && check_room(p, g->n_objects, &kw, "objects") != 0)
        rc = -1;
    if (rc == 0 && (rs__group_push_object(g, &o) != 0 || rs__group_append(g, &lights) != 0))
        rc = error_at(p, kw.line, kw.column, "out of memory");
    rs_object_release(&o);
    rs__group_free(&lights);
    return rc;
}

/* ------------------------------------------------------------------ */
/* Camera, lights, background, global settings                         */
/* ------------------------------------------------------------------ */

static int parse_camera(parser *p)
{
    static const char *const other_types[] = { "fisheye", "ultra_wide_angle",
                                               "omnimax", "panoramic", "cylinder",
                                               "spherical" };
    rs_camera *c = &p->scene->camera;
    rs_token angle_tok = { RS_TOK_EOF, 0, 0, 0, 0, NULL, 0 };
    take(p);
    if (open_block(p, "camera") != 0)
        return -1;
    for (;;) {
        const rs_token *t = peek(p);
        lp_vec3 *target = NULL;
        if (is_punct(t, '}'))
            break;
        for (size_t i = 0; i < sizeof other_types / sizeof other_types[0]; i++)
            if (is_id(t, other_types[i]))
                return error_at(p, t->line, t->column,
                                "only the perspective and orthographic cameras are supported, "
                                "found '%s'", other_types[i]);
        if (is_id(t, "perspective") || is_id(t, "orthographic")) {
            c->orthographic = is_id(t, "orthographic");
            take(p);
            continue;
        }
        if (is_id(t, "angle")) {
            rs_token start;
            angle_tok = take(p);
            start = *peek(p);
            if (parse_float(p, "the camera angle", &c->angle) != 0)
                return -1;
            if (!(c->angle > 0.0 && c->angle < 180.0))
                return error_at(p, start.line, start.column,
                                "the camera angle must be between 0 and 180 degrees");
            c->has_angle = 1;
            continue;
        }
        if (is_id(t, "aperture") || is_id(t, "blur_samples")) {
            int aperture = is_id(t, "aperture");
            rs_token start;
            double f;
            take(p);
            start = *peek(p);
            if (parse_float(p, aperture ? "the aperture" : "blur_samples", &f) != 0)
                return -1;
            if (aperture && !(f >= 0.0 && f < INFINITY))
                return error_at(p, start.line, start.column,
                                "the aperture must be a finite size >= 0");
            if (!aperture && !(f >= 1.0 && f < 4097.0))
                return error_at(p, start.line, start.column,
                                "blur_samples must be between 1 and 4096");
            if (aperture)
                c->aperture = f;
            else
                c->blur_samples = (int)f;
            continue;
        }
        if (transform_kind(t) != XF_NONE) {
            rs_transform step;
            rs_token kw;
            lp_vec3 v;
            if (parse_transform_step(p, &step, &v, &kw) != 0 ||
                apply_step(p, &kw, &c->xf, &step) != 0)
                return -1;
            c->has_xf = 1;
            continue;
        }
        if (is_id(t, "focal_point"))
            target = &c->focal_point;
        else if (is_id(t, "location"))
            target = &c->location;
        else if (is_id(t, "look_at"))
            target = &c->look_at;
        else if (is_id(t, "right"))
            target = &c->right;
        else if (is_id(t, "up"))
            target = &c->up;
        else if (is_id(t, "direction"))
            target = &c->direction;
        else if (is_id(t, "sky"))
            target = &c->sky;
        if (target == NULL)
            return expected(p, t, "perspective, orthographic, location, look_at, angle, right, "
                                  "up, direction, sky, focal_point, aperture, blur_samples, "
                                  "translate, rotate, scale or '}' in camera");
        if (target == &c->look_at)
            c->has_look_at = 1;
        take(p);
        if (parse_vector(p, target) != 0)
            return -1;
    }
    if (c->orthographic && c->has_angle)
        return error_at(p, angle_tok.line, angle_tok.column,
                        "angle with an orthographic camera is not supported: give right and "
                        "up the size of the view");
    return close_block(p, "camera");
}

/* After a light's `coherent`: nothing (coherent, coherence length 0 =
 * infinite), on/off/true/false/yes/no, or a coherence length L >= 0 in mm
 * (a float expression). */
static int parse_light_coherence(parser *p, rs_light *l)
{
    const rs_token *t = peek(p);
    val v;
    l->coherent = 1;
    l->coherence_length = 0.0;
    if (is_id(t, "on") || is_id(t, "off") || is_id(t, "true") || is_id(t, "false") ||
        is_id(t, "yes") || is_id(t, "no")) {
        builtin_value(p, t, &v);
        take(p);
        l->coherent = v.v[0] != 0.0;
    } else if (is_expr_start(p, t)) {
        rs_token start = *t;
        if (parse_float(p, "the coherence length", &l->coherence_length) != 0)
            return -1;
        if (!(l->coherence_length >= 0.0))
            return error_at(p, start.line, start.column,
                            "the coherence length must not be negative (mm; 0 = infinite)");
    }
    return 0;
}

static int parse_spectrum(parser *p, rs_light *l)
{
    take(p);
    if (open_block(p, "spectrum") != 0)
        return -1;
    {
        const rs_token *t = peek(p);
        rs_token start;
        if (is_id(t, "blackbody")) {
            take(p);
            start = *peek(p);
            if (parse_float(p, "the blackbody temperature", &l->spectrum.temperature_k) != 0)
                return -1;
            if (!(l->spectrum.temperature_k > 0.0))
                return error_at(p, start.line, start.column,
                                "the blackbody temperature must be positive (kelvin)");
            l->spectrum.type = RS_SPECTRUM_BLACKBODY;
        } else if (is_id(t, "line")) {
            take(p);
            start = *peek(p);
            if (parse_float(p, "the line wavelength", &l->spectrum.line_nm) != 0)
                return -1;
            if (!(l->spectrum.line_nm > 0.0))
                return error_at(p, start.line, start.column,
                                "the line wavelength must be positive (nm)");
            l->spectrum.type = RS_SPECTRUM_LINE;
        } else if (is_id(t, "rgb")) {
            take(p);
            l->spectrum.type = RS_SPECTRUM_RGB;
        } else {
            return expected(p, t, "blackbody, line or rgb in spectrum");
        }
    }
    return close_block(p, "spectrum");
}

static int push_light(parser *p, const rs_light *l, const rs_token *kw)
{
    rs_scene *s = p->scene;
    if (check_room(p, s->n_lights, kw, "light sources") != 0)
        return -1;
    if (s->n_lights == s->cap_lights) {
        size_t cap = s->cap_lights ? s->cap_lights * 2 : 4;
        rs_light *a;
        if (cap > p->max_objects)
            cap = p->max_objects;
        a = realloc(s->lights, cap * sizeof *a);
        if (a == NULL)
            return error_at(p, kw->line, kw->column, "out of memory");
        s->lights = a;
        s->cap_lights = cap;
    }
    s->lights[s->n_lights++] = *l;
    return 0;
}

/* light_source { V [,] COLOUR modifiers }.  Transforms move the position
 * and turn the polarization direction. */
static int parse_light(parser *p, rs_group *g)
{
    rs_token kw = take(p);
    rs_light l;
    rs_transform xf;

    if (check_room(p, g->n_lights, &kw, "light sources") != 0)
        return -1;
    memset(&l, 0, sizeof l);
    l.loc.file = p->file;
    l.loc.line = kw.line;
    l.loc.column = kw.column;
    rs_transform_identity(&xf);
    if (open_block(p, "light_source") != 0 || parse_vector(p, &l.position) != 0)
        return -1;
    skip_comma(p);
    if (parse_color(p, 0, &l.color) != 0)
        return -1;
    l.spectrum.type = RS_SPECTRUM_RGB;
    for (;;) {
        const rs_token *t = peek(p);
        if (is_punct(t, '}'))
            break;
        if (is_id(t, "polarization")) {
            take(p);
            if (parse_nonzero_vector(p, "the polarization", &l.polarization) != 0)
                return -1;
            l.polarized = 1;
        } else if (is_id(t, "spectrum")) {
            if (parse_spectrum(p, &l) != 0)
                return -1;
        } else if (is_id(t, "coherent")) {
            take(p);
            if (parse_light_coherence(p, &l) != 0)
                return -1;
        } else if (transform_kind(t) != XF_NONE) {
            rs_transform step;
            rs_token tk;
            lp_vec3 v;
            if (parse_transform_step(p, &step, &v, &tk) != 0 ||
                apply_step(p, &tk, &xf, &step) != 0)
                return -1;
        } else {
            return expected(p, t, "polarization, spectrum, coherent, translate, rotate, scale "
                                  "or '}' in light_source");
        }
    }
    if (close_block(p, "light_source") != 0)
        return -1;
    l.position = rs_xf_point(&xf, l.position);
    if (!v3_finite(l.position))
        return error_at(p, kw.line, kw.column,
                        "light_source: the position is not finite after the transforms");
    if (l.polarized && !normalize(rs_xf_dir(&xf, l.polarization), &l.polarization))
        return error_at(p, kw.line, kw.column,
                        "light_source: the polarization is not finite (or vanishes) after "
                        "the transforms");
    l.spectrum.rgb = l.color;
    if (rs__group_push_light(g, &l) != 0)
        return error_at(p, kw.line, kw.column, "out of memory");
    return 0;
}

static int is_object_start(parser *p, const rs_token *t)
{
    static const char *const kws[] = { "plane", "sphere", "box", "disc", "lens", "polarizer",
                                       "cylinder", "cone", "torus", "object", "union", "merge",
                                       "intersection", "difference", "light_source" };
    (void)p;
    for (size_t i = 0; i < sizeof kws / sizeof kws[0]; i++)
        if (is_id(t, kws[i]))
            return 1;
    return 0;
}

/* One object statement (or light_source) into g. */
static int parse_object_statement(parser *p, rs_group *g)
{
    static const struct { const char *kw; rs_object_type type; } prims[] = {
        { "plane", RS_OBJ_PLANE },   { "sphere", RS_OBJ_SPHERE }, { "box", RS_OBJ_BOX },
        { "disc", RS_OBJ_DISC },     { "lens", RS_OBJ_LENS },     { "polarizer", RS_OBJ_POLARIZER },
        { "cylinder", RS_OBJ_CYLINDER }, { "cone", RS_OBJ_CONE }, { "torus", RS_OBJ_TORUS },
    };
    const rs_token *t = peek(p);
    for (size_t i = 0; i < sizeof prims / sizeof prims[0]; i++)
        if (is_id(t, prims[i].kw))
            return parse_primitive(p, prims[i].type, g);
    if (is_id(t, "object"))
        return parse_object_ref(p, g);
    if (is_id(t, "union") || is_id(t, "merge"))
        return parse_union(p, g);
    if (is_id(t, "light_source"))
        return parse_light(p, g);
    if (is_id(t, "intersection") || is_id(t, "difference"))
        return parse_csg(p, g);
    return expected(p, t, "an object");
}

static int parse_background(parser *p)
{
    take(p);
    if (open_block(p, "background") != 0 || parse_color(p, 0, &p->scene->background) != 0)
        return -1;
    return close_block(p, "background");
}

static int parse_global_settings(parser *p)
{
    rs_settings *s = &p->scene->settings;
    take(p);
    if (open_block(p, "global_settings") != 0)
        return -1;
    for (;;) {
        const rs_token *t = peek(p);
        rs_token start;
        double f;
        if (is_punct(t, '}'))
            break;
        if (is_id(t, "max_trace_level")) {
            take(p);
            start = *peek(p);
            if (parse_float(p, "max_trace_level", &f) != 0)
                return -1;
            if (!(f >= 1.0 && f < 257.0))
                return error_at(p, start.line, start.column,
                                "max_trace_level must be between 1 and 256");
            s->max_trace_level = (int)f;
        } else if (is_id(t, "adc_bailout")) {
            take(p);
            start = *peek(p);
            if (parse_float(p, "adc_bailout", &f) != 0)
                return -1;
            if (!(f >= 0.0))
                return error_at(p, start.line, start.column, "adc_bailout must not be negative");
            s->adc_bailout = f;
        } else if (is_id(t, "ambient_light")) {
            take(p);
            if (parse_color(p, 0, &s->ambient_light) != 0)
                return -1;
        } else if (is_id(t, "assumed_gamma")) {
            rs_token kw = take(p);
            if (parse_positive(p, "assumed_gamma", &s->assumed_gamma) != 0)
                return -1;
            if (s->assumed_gamma != 1.0)
                rs__warn(p, kw.line, kw.column,
                         "assumed_gamma %g is read but not used: colours are linear, as with "
                         "assumed_gamma 1", s->assumed_gamma);
        } else if (is_id(t, "coherent")) {
            take(p);
            if (parse_float(p, "coherent", &f) != 0)
                return -1;
            s->coherent = f != 0.0;
        } else {
            return expected(p, t, "max_trace_level, adc_bailout, ambient_light, assumed_gamma, "
                                  "coherent or '}' in global_settings");
        }
    }
    return close_block(p, "global_settings");
}

/* ------------------------------------------------------------------ */
/* Declared values                                                     */
/* ------------------------------------------------------------------ */

static int alloc_payload(parser *p, const rs_token *at, val *out, val_kind kind, size_t size)
{
    set_float(out, 0.0);
    out->kind = kind;
    if ((out->ptr = calloc(1, size)) == NULL)
        return error_at(p, at->line, at->column, "out of memory");
    return 0;
}

static int parse_value(parser *p, val *out, const char *what);

/* Any value; on failure *out holds nothing to free. */
int rs__parse_value(parser *p, val *out, const char *what)
{
    if (parse_value(p, out, what) != 0) {
        rs__val_free(out);
        return -1;
    }
    return 0;
}

static int parse_value(parser *p, val *out, const char *what)
{
    const rs_token *t = peek(p);
    rs_token at = *t;
    sym *s;

    set_float(out, 0.0);
    if (is_id(t, "pigment")) {
        rs_pigment_val *pv;
        if (alloc_payload(p, &at, out, VAL_PIGMENT, sizeof *pv) != 0)
            return -1;
        pv = out->ptr;
        default_pigment(&pv->pig);
        rs_transform_identity(&pv->pat);
        return parse_pigment(p, &pv->pig, &pv->pat);
    }
    if (is_id(t, "finish")) {
        if (alloc_payload(p, &at, out, VAL_FINISH, sizeof(rs_finish)) != 0)
            return -1;
        default_finish(out->ptr);
        return parse_finish(p, out->ptr);
    }
    if (is_id(t, "texture")) {
        rs_texture_val *tv;
        if (alloc_payload(p, &at, out, VAL_TEXTURE, sizeof *tv) != 0)
            return -1;
        tv = out->ptr;
        default_pigment(&tv->pig);
        rs_transform_identity(&tv->pat);
        default_finish(&tv->fin);
        return parse_texture(p, &tv->pig, &tv->pat, &tv->fin);
    }
    if (is_id(t, "interior")) {
        if (alloc_payload(p, &at, out, VAL_INTERIOR, sizeof(double)) != 0)
            return -1;
        *(double *)out->ptr = 1.0;
        return parse_interior(p, out->ptr);
    }
    if (is_object_start(p, t)) {
        if (alloc_payload(p, &at, out, VAL_OBJECT, sizeof(rs_group)) != 0)
            return -1;
        return parse_object_statement(p, out->ptr);
    }
    if (is_id(t, "camera") || is_id(t, "background") || is_id(t, "global_settings"))
        return error_at(p, t->line, t->column,
                        "a %.*s cannot be declared: write it in the scene", (int)t->len,
                        t->text);
    if (is_color_keyword(t)) {
        double c[5];
        if (parse_color5(p, c) != 0)
            return -1;
        set_vector(out, 5);
        for (int i = 0; i < 5; i++)
            out->v[i] = c[i];
        return 0;
    }
    if (t->kind == RS_TOK_IDENT && (s = rs__sym_find(p, t->text, t->len)) != NULL &&
        s->v.kind != VAL_FLOAT && s->v.kind != VAL_VECTOR && s->v.kind != VAL_STRING) {
        if (rs__val_copy(&s->v, out) != 0)
            return error_at(p, t->line, t->column, "out of memory");
        take(p);
        return 0;
    }
    if (is_expr_start(p, t) || t->kind == RS_TOK_STRING || is_id(t, "concat") ||
        is_id(t, "str") || is_id(t, "chr"))
        return parse_expr(p, out);
    if (t->kind == RS_TOK_IDENT && is_reserved(t->text, t->len)) {
        char w[160];
        snprintf(w, sizeof w, "%s (a float, vector, colour, string, pigment, finish, texture, "
                              "interior or object)", what);
        return expected(p, t, w);
    }
    return expected(p, t, what);
}

/* ------------------------------------------------------------------ */
/* The file                                                            */
/* ------------------------------------------------------------------ */

static int parse_scene(parser *p)
{
    for (;;) {
        const rs_token *t = peek(p);
        int rc = 1;
        if (p->failed)
            return -1;
        if (t->kind == RS_TOK_EOF)
            break;
        if (is_id(t, "camera")) {
            rc = parse_camera(p);
        } else if (is_id(t, "background")) {
            rc = parse_background(p);
        } else if (is_id(t, "global_settings")) {
            rc = parse_global_settings(p);
        } else if (is_object_start(p, t)) {
            rs_group g;
            rs_token kw = *t;
            memset(&g, 0, sizeof g);
            rc = parse_object_statement(p, &g);
            for (size_t i = 0; rc == 0 && i < g.n_objects; i++)
                rc = push_object(p, &g.objects[i], &kw);
            for (size_t i = 0; rc == 0 && i < g.n_lights; i++)
                rc = push_light(p, &g.lights[i], &kw);
            rs__group_free(&g);
        }
        if (rc > 0) {
            if (t->kind == RS_TOK_IDENT && declared(p, VAL_OBJECT) != NULL)
                return error_at(p, t->line, t->column,
                                "'%.*s' is a declared object: write object { %.*s }",
                                (int)(t->len > 48 ? 48 : t->len), t->text,
                                (int)(t->len > 48 ? 48 : t->len), t->text);
            return expected(p, t, "camera, light_source, background, global_settings, an "
                                  "object (plane, sphere, box, disc, cylinder, cone, torus, "
                                  "lens, polarizer, object, union, merge, intersection, difference) or a "
                                  "directive");
        }
        if (rc < 0)
            return -1;
    }
    if (p->scene->n_objects == 0)
        rs__warn(p, peek(p)->line, peek(p)->column, "no objects in the scene");
    return p->failed ? -1 : 0;
}

static void set_msg(char *msg, size_t msg_size, const char *fmt, ...)
{
    if (msg != NULL && msg_size > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, msg_size, fmt, ap);
        va_end(ap);
    }
}

const char *rs__scene_add_file(rs_scene *scene, const char *name)
{
    size_t n = strlen(name);
    char *copy = malloc(n + 1);
    char **files;
    if (copy == NULL)
        return NULL;
    memcpy(copy, name, n + 1);
    files = realloc(scene->files, (scene->n_files + 1) * sizeof *files);
    if (files == NULL) {
        free(copy);
        return NULL;
    }
    scene->files = files;
    scene->files[scene->n_files++] = copy;
    return copy;
}

int rs__read_text(const char *path, char **out, size_t *out_len, char *why, size_t why_size)
{
    FILE *f;
    char *buf = NULL;
    size_t len = 0, cap = 0;

    *out = NULL;
    *out_len = 0;
    f = fopen(path, "rb");
    if (f == NULL) {
        int e = errno;
        set_msg(why, why_size, "cannot read: %s", strerror(e));
        errno = e;
        return -1;
    }
    for (;;) {
        size_t got;
        if (len + 1 >= cap) {
            size_t ncap = cap ? cap * 2 : 65536;
            char *nb;
            if (ncap > MAX_SOURCE_BYTES + 2)
                ncap = MAX_SOURCE_BYTES + 2; /* one byte more tells "too long" */
            nb = realloc(buf, ncap);
            if (nb == NULL) {
                free(buf);
                fclose(f);
                set_msg(why, why_size, "out of memory");
                errno = ENOMEM;
                return -1;
            }
            buf = nb;
            cap = ncap;
        }
        got = fread(buf + len, 1, cap - 1 - len, f);
        len += got;
        if (got == 0 || len > MAX_SOURCE_BYTES)
            break; /* len > MAX: too long (/dev/zero, ...), refused below */
    }
    if (ferror(f)) {
        int e = errno;
        set_msg(why, why_size, "cannot read: %s", strerror(e));
        free(buf);
        fclose(f);
        errno = e ? e : EIO;
        return -1;
    }
    fclose(f);
    if (len > MAX_SOURCE_BYTES) {
        set_msg(why, why_size, "larger than %zu MiB", MAX_SOURCE_BYTES >> 20);
        free(buf);
        errno = EFBIG;
        return -1;
    }
    buf[len] = '\0';
    *out = buf;
    *out_len = len;
    return 0;
}

static int parse_buffer(const char *text, size_t len, const char *name,
                        const rs_parse_opts *opts, rs_scene *scene, char *msg, size_t msg_size)
{
    parser p;
    const char *file;
    int rc;

    if (len > MAX_SOURCE_BYTES) {
        set_msg(msg, msg_size, "%s:1:1: the scene is larger than %zu MiB", name,
                MAX_SOURCE_BYTES >> 20);
        return -1;
    }
    memset(&p, 0, sizeof p);
    p.msg = msg;
    p.msg_size = msg_size;
    p.scene = scene;
    p.version = 3.7;
    p.budget = RS_TOKEN_BUDGET;
    file = rs__scene_add_file(scene, name);
    if (file == NULL) {
        set_msg(msg, msg_size, "%s: out of memory", name);
        return -1;
    }
    p.file = file;
    p.image_width = (opts != NULL && opts->image_width > 0) ? opts->image_width : DEFAULT_WIDTH;
    p.image_height =
        (opts != NULL && opts->image_height > 0) ? opts->image_height : DEFAULT_HEIGHT;
    p.max_objects = (opts != NULL && opts->max_objects > 0) ? opts->max_objects
                                                            : DEFAULT_MAX_OBJECTS;
    if (opts != NULL) {
        p.include_dirs = opts->include_dirs;
        p.n_include_dirs = opts->n_include_dirs;
        if (opts->max_tokens > 0)
            p.budget = opts->max_tokens;
        p.no_include = opts->no_include;
    }
    if (rs__scope_push(&p) != 0 || rs__push_file(&p, text, len, file, 1, 1) != 0) {
        set_msg(msg, msg_size, "%s: out of memory", name);
        rc = -1;
    } else {
        rc = parse_scene(&p);
    }
    rs__stream_free(&p);
    rs__symbols_free(&p);
    return rc;
}

void rs_parse_opts_init(rs_parse_opts *opts)
{
    memset(opts, 0, sizeof *opts);
}

int rs_parse_string(const char *text, const char *name, const rs_parse_opts *opts,
                    rs_scene *scene, char *msg, size_t msg_size)
{
    set_msg(msg, msg_size, "%s", "");
    if (name == NULL)
        name = "<string>";
    if (text == NULL || scene == NULL) {
        set_msg(msg, msg_size, "%s: no text or no scene to parse into", name);
        return -1;
    }
    return parse_buffer(text, strlen(text), name, opts, scene, msg, msg_size);
}

int rs_parse_file(const char *path, const rs_parse_opts *opts, rs_scene *scene, char *msg,
                  size_t msg_size)
{
    char *buf = NULL, why[256] = "";
    size_t len = 0;
    int rc;

    set_msg(msg, msg_size, "%s", "");
    if (path == NULL || scene == NULL) {
        set_msg(msg, msg_size, "no file or no scene to parse into");
        return -1;
    }
    if (rs__read_text(path, &buf, &len, why, sizeof why) != 0) {
        if (errno == EFBIG)
            set_msg(msg, msg_size, "%s:1:1: the scene is %s", path, why);
        else
            set_msg(msg, msg_size, "%s: %s", path, why);
        return -1;
    }
    rc = parse_buffer(buf, len, path, opts, scene, msg, msg_size);
    free(buf);
    return rc;
}
