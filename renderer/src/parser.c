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
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lexer.h"
#include "parser.h"

#define MAX_DEPTH 64
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

/* ------------------------------------------------------------------ */
/* Values and the identifier table                                     */
/* ------------------------------------------------------------------ */

typedef struct val {
    int vec;        /* 0: a float in v[0]; 1: a vector */
    double v[3];
} val;

typedef struct sym {
    char *name;     /* NULL: empty slot */
    size_t len;
    val v;
} sym;

typedef struct parser {
    rs_lexer lx;
    rs_token la[2];     /* lookahead */
    int n_la;
    rs_scene *scene;
    const char *file;   /* owned by the scene */
    double image_width, image_height;
    size_t max_objects;
    sym *syms;
    size_t sym_cap, sym_count;
    int depth;
    char *msg;
    size_t msg_size;
    int failed;
} parser;

/* ------------------------------------------------------------------ */
/* Errors                                                              */
/* ------------------------------------------------------------------ */

static int error_at(parser *p, int line, int column, const char *fmt, ...)
{
    if (!p->failed && p->msg != NULL && p->msg_size > 0) {
        va_list ap;
        int n = snprintf(p->msg, p->msg_size, "%s:%d:%d: ", p->file, line, column);
        if (n >= 0 && (size_t)n < p->msg_size) {
            va_start(ap, fmt);
            vsnprintf(p->msg + n, p->msg_size - (size_t)n, fmt, ap);
            va_end(ap);
        }
    }
    p->failed = 1;
    return -1;
}

/* "expected WHAT, found <token>" at the token (or the lexical error the
 * token stands for). */
static int expected(parser *p, const rs_token *t, const char *what)
{
    char desc[96];
    if (t->kind == RS_TOK_ERROR)
        return error_at(p, t->line, t->column, "%s", p->lx.error);
    rs_token_describe(t, desc, sizeof desc);
    return error_at(p, t->line, t->column, "expected %s, found %s", what, desc);
}

/* ------------------------------------------------------------------ */
/* Tokens                                                              */
/* ------------------------------------------------------------------ */

static const rs_token *peek_k(parser *p, int k)
{
    while (p->n_la <= k) {
        rs_lexer_next(&p->lx, &p->la[p->n_la]);
        p->n_la++;
    }
    return &p->la[k];
}

static const rs_token *peek(parser *p)
{
    return peek_k(p, 0);
}

/* Consume the current token and return a copy of it. */
static rs_token take(parser *p)
{
    rs_token t = *peek(p);
    if (t.kind != RS_TOK_EOF && t.kind != RS_TOK_ERROR) {
        p->la[0] = p->la[1];
        p->n_la--;
    }
    return t;
}

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
    if (++p->depth > MAX_DEPTH)
        return error_at(p, t->line, t->column, "nesting deeper than %d levels", MAX_DEPTH);
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
    "intersection", "difference", "merge", "interior", "normal", "inf",
    /* built-in values */
    "x", "y", "z", "pi", "true", "false", "on", "off", "yes", "no", "image_width",
    "image_height",
    /* functions */
    "sqrt", "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "pow", "abs", "min",
    "max", "radians", "degrees", "exp", "ln", "log", "floor", "ceil", "int", "mod",
    "vlength", "vnormalize", "vdot", "vcross",
};

static int name_is(const char *text, size_t len, const char *w)
{
    return strlen(w) == len && memcmp(text, w, len) == 0;
}

static int is_reserved(const char *text, size_t len)
{
    for (size_t i = 0; i < sizeof reserved_words / sizeof reserved_words[0]; i++)
        if (name_is(text, len, reserved_words[i]))
            return 1;
    return 0;
}

/* ------------------------------------------------------------------ */
/* Identifier table (open addressing, FNV-1a)                          */
/* ------------------------------------------------------------------ */

static size_t hash_name(const char *s, size_t n)
{
    size_t h = (size_t)1469598103934665603ull;
    for (size_t i = 0; i < n; i++) {
        h ^= (unsigned char)s[i];
        h *= (size_t)1099511628211ull;
    }
    return h;
}

static sym *sym_find(parser *p, const char *name, size_t len)
{
    size_t i;
    if (p->sym_cap == 0)
        return NULL;
    i = hash_name(name, len) & (p->sym_cap - 1);
    while (p->syms[i].name != NULL) {
        if (p->syms[i].len == len && memcmp(p->syms[i].name, name, len) == 0)
            return &p->syms[i];
        i = (i + 1) & (p->sym_cap - 1);
    }
    return NULL;
}

static int sym_grow(parser *p)
{
    size_t cap = p->sym_cap ? p->sym_cap * 2 : 64;
    sym *s = calloc(cap, sizeof *s);
    if (s == NULL)
        return -1;
    for (size_t k = 0; k < p->sym_cap; k++) {
        if (p->syms[k].name != NULL) {
            size_t i = hash_name(p->syms[k].name, p->syms[k].len) & (cap - 1);
            while (s[i].name != NULL)
                i = (i + 1) & (cap - 1);
            s[i] = p->syms[k];
        }
    }
    free(p->syms);
    p->syms = s;
    p->sym_cap = cap;
    return 0;
}

/* Set name to v (declaring it if new).  -1: out of memory. */
static int sym_set(parser *p, const char *name, size_t len, const val *v)
{
    sym *s = sym_find(p, name, len);
    size_t i;
    if (s != NULL) {
        s->v = *v;
        return 0;
    }
    if ((p->sym_count + 1) * 10 > p->sym_cap * 7 && sym_grow(p) != 0)
        return -1;
    i = hash_name(name, len) & (p->sym_cap - 1);
    while (p->syms[i].name != NULL)
        i = (i + 1) & (p->sym_cap - 1);
    p->syms[i].name = malloc(len + 1);
    if (p->syms[i].name == NULL)
        return -1;
    memcpy(p->syms[i].name, name, len);
    p->syms[i].name[len] = '\0';
    p->syms[i].len = len;
    p->syms[i].v = *v;
    p->sym_count++;
    return 0;
}

static void sym_free(parser *p)
{
    for (size_t i = 0; i < p->sym_cap; i++)
        free(p->syms[i].name);
    free(p->syms);
    p->syms = NULL;
    p->sym_cap = p->sym_count = 0;
}

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
/* Expressions                                                         */
/* ------------------------------------------------------------------ */

enum fn_id {
    FN_SQRT, FN_SIN, FN_COS, FN_TAN, FN_ASIN, FN_ACOS, FN_ATAN, FN_ATAN2, FN_POW, FN_ABS,
    FN_MIN, FN_MAX, FN_RADIANS, FN_DEGREES, FN_EXP, FN_LN, FN_LOG, FN_FLOOR, FN_CEIL,
    FN_INT, FN_MOD, FN_VLENGTH, FN_VNORMALIZE, FN_VDOT, FN_VCROSS
};

typedef struct fn_def {
    const char *name;
    enum fn_id id;
    int nargs;      /* -1: two or more */
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
    static const char *const zeros[] = { "false", "off", "no" };
    memset(out, 0, sizeof *out);
    if (t->kind != RS_TOK_IDENT)
        return 0;
    if (t->len == 1 && (t->text[0] == 'x' || t->text[0] == 'y' || t->text[0] == 'z')) {
        out->vec = 1;
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
    for (int i = 0; i < 3; i++) {
        if (is_id(t, ones[i])) {
            out->v[0] = 1.0;
            return 1;
        }
        if (is_id(t, zeros[i]))
            return 1;
    }
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
        return t->punct == '(' || t->punct == '<' || t->punct == '-' || t->punct == '+';
    if (t->kind != RS_TOK_IDENT)
        return 0;
    return builtin_value(p, t, &dummy) || find_function(t) != NULL ||
           !is_reserved(t->text, t->len);
}

static int is_color_start(parser *p, const rs_token *t)
{
    static const char *const kws[] = { "color", "colour", "rgb", "rgbf", "rgbt", "rgbft",
                                       "red", "green", "blue", "filter", "transmit" };
    for (size_t i = 0; i < sizeof kws / sizeof kws[0]; i++)
        if (is_id(t, kws[i]))
            return 1;
    return is_expr_start(p, t);
}

static void promote(val *v)
{
    if (!v->vec) {
        v->vec = 1;
        v->v[1] = v->v[2] = v->v[0];
    }
}

static int val_finite(const val *v)
{
    int n = v->vec ? 3 : 1;
    for (int i = 0; i < n; i++)
        if (!isfinite(v->v[i]))
            return 0;
    return 1;
}

static int parse_expr(parser *p, val *out);

static int want_float_val(parser *p, const val *v, const rs_token *start, const char *what)
{
    if (v->vec)
        return error_at(p, start->line, start->column, "expected a float%s%s, found a vector",
                        what ? " for " : "", what ? what : "");
    return 0;
}

/* name ( args ) */
static int parse_function(parser *p, const fn_def *fn, val *out)
{
    rs_token name = take(p);
    val a[2];
    double r = 0.0;
    int nargs = 0;
    char what[48];

    snprintf(what, sizeof what, "'(' after '%s'", fn->name);
    if (!is_punct(peek(p), '('))
        return expected(p, peek(p), what);
    if (enter(p, peek(p)) != 0)
        return -1;
    take(p);
    memset(out, 0, sizeof *out);
    for (;;) {
        rs_token start = *peek(p);
        val v;
        if (parse_expr(p, &v) != 0)
            return -1;
        if (fn->vec_args) {
            promote(&v);
        } else {
            snprintf(what, sizeof what, "the argument of %s()", fn->name);
            if (want_float_val(p, &v, &start, what) != 0)
                return -1;
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
        if (fn->nargs > 0 && nargs == fn->nargs) {
            snprintf(what, sizeof what, "')' after the %s of %s()",
                     nargs == 1 ? "argument" : "arguments", fn->name);
            if (expect_punct(p, ')', what) != 0)
                return -1;
            break;
        }
        if (fn->nargs < 0 && nargs >= 2 && is_punct(peek(p), ')')) {
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
    case FN_MOD:
        if (a[1].v[0] == 0.0)
            return error_at(p, name.line, name.column, "mod(): division by zero");
        r = fmod(a[0].v[0], a[1].v[0]);
        break;
    case FN_VLENGTH:
        r = vec_length((lp_vec3){ a[0].v[0], a[0].v[1], a[0].v[2] });
        break;
    case FN_VNORMALIZE: {
        lp_vec3 u;
        if (!normalize((lp_vec3){ a[0].v[0], a[0].v[1], a[0].v[2] }, &u))
            return error_at(p, name.line, name.column, "vnormalize() of a zero vector");
        out->vec = 1;
        out->v[0] = u.x;
        out->v[1] = u.y;
        out->v[2] = u.z;
        break;
    }
    case FN_VDOT:
        r = a[0].v[0] * a[1].v[0] + a[0].v[1] * a[1].v[1] + a[0].v[2] * a[1].v[2];
        break;
    case FN_VCROSS:
        out->vec = 1;
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

static int parse_vector_literal(parser *p, val *out)
{
    static const char *const seps[] = { "',' after the first vector component",
                                        "',' after the second vector component",
                                        "'>' to close the vector" };
    rs_token open = take(p);
    if (enter(p, &open) != 0)
        return -1;
    out->vec = 1;
    for (int i = 0; i < 3; i++) {
        rs_token start = *peek(p);
        val c;
        if (parse_expr(p, &c) != 0)
            return -1;
        if (want_float_val(p, &c, &start, "a vector component") != 0)
            return -1;
        out->v[i] = c.v[0];
        if (expect_punct(p, i < 2 ? ',' : '>', seps[i]) != 0)
            return -1;
    }
    leave(p);
    return 0;
}

static int parse_primary(parser *p, val *out)
{
    const rs_token *t = peek(p);
    const fn_def *fn;
    sym *s;

    memset(out, 0, sizeof *out);
    if (t->kind == RS_TOK_NUMBER) {
        out->v[0] = take(p).number;
        return 0;
    }
    if (is_punct(t, '(')) {
        if (enter(p, t) != 0)
            return -1;
        take(p);
        if (parse_expr(p, out) != 0)
            return -1;
        if (expect_punct(p, ')', "')'") != 0)
            return -1;
        leave(p);
        return 0;
    }
    if (is_punct(t, '<'))
        return parse_vector_literal(p, out);
    if (t->kind == RS_TOK_IDENT) {
        if (builtin_value(p, t, out)) {
            take(p);
            return 0;
        }
        if ((fn = find_function(t)) != NULL)
            return parse_function(p, fn, out);
        if ((s = sym_find(p, t->text, t->len)) != NULL) {
            *out = s->v;
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

/* primary { . x|y|z|red|green|blue } */
static int parse_postfix(parser *p, val *out)
{
    if (parse_primary(p, out) != 0)
        return -1;
    while (is_punct(peek(p), '.')) {
        rs_token dot = take(p);
        const rs_token *c = peek(p);
        int k = -1;
        if (is_id(c, "x") || is_id(c, "red"))
            k = 0;
        else if (is_id(c, "y") || is_id(c, "green"))
            k = 1;
        else if (is_id(c, "z") || is_id(c, "blue"))
            k = 2;
        if (k < 0)
            return expected(p, c, "x, y, z, red, green or blue after '.'");
        if (!out->vec)
            return error_at(p, dot.line, dot.column, "'.' needs a vector, found a float");
        take(p);
        out->vec = 0;
        out->v[0] = out->v[k];
        out->v[1] = out->v[2] = 0.0;
    }
    return 0;
}

/* A run of unary signs, read in a loop (no recursion). */
static int parse_unary(parser *p, val *out)
{
    int neg = 0;
    while (is_punct(peek(p), '-') || is_punct(peek(p), '+')) {
        if (take(p).punct == '-')
            neg = !neg;
    }
    if (parse_postfix(p, out) != 0)
        return -1;
    if (neg)
        for (int i = 0; i < 3; i++)
            out->v[i] = -out->v[i];
    return 0;
}

static int binary(parser *p, const rs_token *op, val *a, val b)
{
    int n;
    if (a->vec || b.vec) {
        promote(a);
        promote(&b);
    }
    n = a->vec ? 3 : 1;
    for (int i = 0; i < n; i++) {
        switch (op->punct) {
        case '+': a->v[i] += b.v[i]; break;
        case '-': a->v[i] -= b.v[i]; break;
        case '*': a->v[i] *= b.v[i]; break;
        default:
            if (b.v[i] == 0.0)
                return error_at(p, op->line, op->column, "division by zero");
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
        val b;
        if (parse_unary(p, &b) != 0 || binary(p, &op, out, b) != 0)
            return -1;
    }
    return 0;
}

static int parse_expr(parser *p, val *out)
{
    if (parse_term(p, out) != 0)
        return -1;
    while (is_punct(peek(p), '+') || is_punct(peek(p), '-')) {
        rs_token op = take(p);
        val b;
        if (parse_term(p, &b) != 0 || binary(p, &op, out, b) != 0)
            return -1;
    }
    return 0;
}

static int parse_float(parser *p, const char *what, double *out)
{
    rs_token start = *peek(p);
    val v;
    if (parse_expr(p, &v) != 0 || want_float_val(p, &v, &start, what) != 0)
        return -1;
    *out = v.v[0];
    return 0;
}

static int parse_vector(parser *p, lp_vec3 *out)
{
    val v;
    if (parse_expr(p, &v) != 0)
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
/* Colours                                                             */
/* ------------------------------------------------------------------ */

static const char transparent_msg[] =
    "transparent pigments are not supported: use a lens object";

/* [color|colour] rgb V | V | red/green/blue F ...  In a pigment (and a
 * declared colour) a lone non-zero float is refused: POV-Ray would set
 * filter and transmit to it as well. */
static int parse_color(parser *p, int opaque_only, rs_color *out)
{
    const rs_token *t = peek(p);
    val v;
    int any = 0;

    memset(&v, 0, sizeof v);
    v.vec = 1;
    if (is_id(t, "color") || is_id(t, "colour")) {
        take(p);
        t = peek(p);
    }
    if (is_id(t, "rgbf") || is_id(t, "rgbt") || is_id(t, "rgbft") || is_id(t, "filter") ||
        is_id(t, "transmit")) {
        return error_at(p, t->line, t->column, "%s", transparent_msg);
    } else if (is_id(t, "rgb")) {
        take(p);
        if (parse_expr(p, &v) != 0)
            return -1;
        promote(&v);
        any = 1;
    } else if (!(is_id(t, "red") || is_id(t, "green") || is_id(t, "blue"))) {
        rs_token start = *t;
        if (!is_expr_start(p, t))
            return expected(p, t, "a colour");
        if (parse_expr(p, &v) != 0)
            return -1;
        if (!v.vec && v.v[0] != 0.0 && opaque_only)
            return error_at(p, start.line, start.column,
                            "%s (a lone float colour also sets filter and transmit in "
                            "POV-Ray; write rgb %g)", transparent_msg, v.v[0]);
        promote(&v);
        any = 1;
    }
    for (;;) {
        int k;
        t = peek(p);
        if (is_id(t, "filter") || is_id(t, "transmit"))
            return error_at(p, t->line, t->column, "%s", transparent_msg);
        k = is_id(t, "red") ? 0 : is_id(t, "green") ? 1 : is_id(t, "blue") ? 2 : -1;
        if (k < 0)
            break;
        take(p);
        if (parse_float(p, k == 0 ? "red" : k == 1 ? "green" : "blue", &v.v[k]) != 0)
            return -1;
        any = 1;
    }
    if (!any)
        return expected(p, peek(p), "a colour");
    out->r = v.v[0];
    out->g = v.v[1];
    out->b = v.v[2];
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

static int xf_finite(const rs_transform *xf)
{
    for (int i = 0; i < 3; i++) {
        if (!isfinite(xf->t[i]) || !isfinite(xf->inv_t[i]))
            return 0;
        for (int j = 0; j < 3; j++)
            if (!isfinite(xf->m[i][j]) || !isfinite(xf->inv_m[i][j]))
                return 0;
    }
    return 1;
}

/* *xf = step after *xf, refused when the result is not finite. */
static int apply_step(parser *p, const rs_token *kw, rs_transform *xf, const rs_transform *step)
{
    rs_transform_compose(xf, step, xf);
    if (!xf_finite(xf))
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
    f->ambient = (rs_color){ 0.1, 0.1, 0.1 };
    f->diffuse = 0.6;
    f->emission = (rs_color){ 0.0, 0.0, 0.0 };
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

static int parse_finish(parser *p, rs_finish *f)
{
    static const char *const ignored[] = { "specular", "phong", "phong_size", "brilliance",
                                           "roughness" };
    take(p);
    if (open_block(p, "finish") != 0)
        return -1;
    for (;;) {
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
        if (is_id(t, "diffuse")) {
            take(p);
            if (parse_float(p, "diffuse", &f->diffuse) != 0)
                return -1;
            continue;
        }
        if (is_id(t, "reflection")) { /* read, not rendered */
            rs_color ignore;
            take(p);
            if (parse_color(p, 0, &ignore) != 0)
                return -1;
            continue;
        }
        if (is_id(t, "conserve_energy")) {
            take(p);
            continue;
        }
        for (size_t i = 0; i < sizeof ignored / sizeof ignored[0]; i++) {
            if (is_id(t, ignored[i])) {
                double ignore;
                rs_token kw = take(p);
                char what[32];
                snprintf(what, sizeof what, "%.*s", (int)kw.len, kw.text);
                if (parse_float(p, what, &ignore) != 0)
                    return -1;
                done = 1;
                break;
            }
        }
        if (!done)
            return expected(p, t, "ambient, diffuse, emission, specular, phong, phong_size, "
                                   "brilliance, roughness, reflection, conserve_energy or "
                                   "'}' in finish");
    }
    return close_block(p, "finish");
}

static int parse_texture(parser *p, rs_pigment *pig, rs_transform *pat, rs_finish *fin)
{
    take(p);
    if (open_block(p, "texture") != 0)
        return -1;
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
                                          "polarizer" };

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
    o->lens = NULL;
}

static int check_room(parser *p, size_t n, const rs_token *kw, const char *what)
{
    if (n >= p->max_objects)
        return error_at(p, kw->line, kw->column, "too many %s (the limit is %zu)", what,
                        p->max_objects);
    return 0;
}

static int push_object(parser *p, const rs_object *o, const rs_token *kw)
{
    rs_scene *s = p->scene;
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
    s->objects[s->n_objects++] = *o;
    return 0;
}

/* pigment / finish / texture / transforms until '}'.  The pigment's
 * to_pattern is the inverse of its pattern -> world transform: its own
 * transforms, then the object's written after it. */
static int parse_object_modifiers(parser *p, rs_object *o)
{
    const char *name = type_names[o->type];
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
        } else if (is_id(t, "finish")) {
            if (parse_finish(p, &o->finish) != 0)
                return -1;
        } else if (is_id(t, "texture")) {
            if (parse_texture(p, &o->pigment, &pat, &o->finish) != 0)
                return -1;
        } else if (transform_kind(t) != XF_NONE) {
            rs_transform step;
            rs_token kw;
            lp_vec3 v;
            if (parse_transform_step(p, &step, &v, &kw) != 0 ||
                apply_step(p, &kw, &o->xf, &step) != 0 || apply_step(p, &kw, &pat, &step) != 0)
                return -1;
        } else {
            snprintf(what, sizeof what,
                     "pigment, finish, texture, translate, rotate, scale or '}' in %s", name);
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

static int vec_finite(lp_vec3 v)
{
    return isfinite(v.x) && isfinite(v.y) && isfinite(v.z);
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
    const rs_token *t = peek(p);
    if (is_id(t, "inf")) {
        take(p);
        *out = INFINITY;
        return 0;
    }
    if ((is_punct(t, '-') || is_punct(t, '+')) && is_id(peek_k(p, 1), "inf")) {
        int neg = take(p).punct == '-';
        take(p);
        *out = neg ? -INFINITY : INFINITY;
        return 0;
    }
    return parse_float(p, what, out);
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
        !vec_finite(d->position) || !vec_finite(d->axis) ||
        (d->uniaxial && !vec_finite(d->crystal.axis)))
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
    if (!vec_finite(o->u.polarizer.center) || !isfinite(o->u.polarizer.radius))
        return error_at(p, kw->line, kw->column,
                        "polarizer: a value is not finite after the transforms");
    if (!(o->u.polarizer.radius > 0.0))
        return error_at(p, kw->line, kw->column,
                        "polarizer: the radius underflows to 0 after the transforms");
    return close_block(p, "polarizer");
}

static int parse_object(parser *p, rs_object_type type)
{
    rs_token kw = take(p);
    rs_object o;
    int rc;

    if (check_room(p, p->scene->n_objects, &kw, "objects") != 0)
        return -1;
    object_init(&o, type, p, &kw);
    switch (type) {
    case RS_OBJ_PLANE: rc = parse_plane(p, &o); break;
    case RS_OBJ_SPHERE: rc = parse_sphere(p, &o); break;
    case RS_OBJ_BOX: rc = parse_box(p, &o); break;
    case RS_OBJ_DISC: rc = parse_disc(p, &o); break;
    case RS_OBJ_LENS: rc = parse_lens(p, &o, &kw); break;
    default: rc = parse_polarizer(p, &o, &kw); break;
    }
    if (rc != 0)
        return -1;
    return push_object(p, &o, &kw);
}

/* ------------------------------------------------------------------ */
/* Camera, lights, background, global settings                         */
/* ------------------------------------------------------------------ */

static int parse_camera(parser *p)
{
    static const char *const other_types[] = { "orthographic", "fisheye", "ultra_wide_angle",
                                               "omnimax", "panoramic", "cylinder",
                                               "spherical" };
    rs_camera *c = &p->scene->camera;
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
                                "only the perspective camera is supported, found '%s'",
                                other_types[i]);
        if (is_id(t, "perspective")) {
            take(p);
            continue;
        }
        if (is_id(t, "angle")) {
            rs_token start;
            take(p);
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
            return expected(p, t, "perspective, location, look_at, angle, right, up, "
                                  "direction, sky, focal_point, aperture, blur_samples, "
                                  "translate, rotate, scale or '}' in camera");
        if (target == &c->look_at)
            c->has_look_at = 1;
        take(p);
        if (parse_vector(p, target) != 0)
            return -1;
    }
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
static int parse_light(parser *p)
{
    rs_token kw = take(p);
    rs_light l;
    rs_transform xf;

    if (check_room(p, p->scene->n_lights, &kw, "light sources") != 0)
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
    if (!vec_finite(l.position))
        return error_at(p, kw.line, kw.column,
                        "light_source: the position is not finite after the transforms");
    if (l.polarized && !normalize(rs_xf_dir(&xf, l.polarization), &l.polarization))
        return error_at(p, kw.line, kw.column,
                        "light_source: the polarization is not finite (or vanishes) after "
                        "the transforms");
    l.spectrum.rgb = l.color;
    return push_light(p, &l, &kw);
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
            take(p);
            if (parse_positive(p, "assumed_gamma", &s->assumed_gamma) != 0)
                return -1;
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
/* Directives                                                          */
/* ------------------------------------------------------------------ */

static int parse_directive(parser *p)
{
    rs_token d = take(p);
    if (name_is(d.text, d.len, "version")) {
        double v;
        if (parse_float(p, "#version", &v) != 0)
            return -1;
        if (is_punct(peek(p), ';'))
            take(p);
        return 0;
    }
    if (name_is(d.text, d.len, "declare") || name_is(d.text, d.len, "local")) {
        const rs_token *t = peek(p);
        rs_token name, start;
        val v;
        char what[48];
        snprintf(what, sizeof what, "an identifier after '#%.*s'", (int)d.len, d.text);
        if (t->kind != RS_TOK_IDENT)
            return expected(p, t, what);
        if (is_reserved(t->text, t->len))
            return error_at(p, t->line, t->column, "'%.*s' is a reserved word", (int)t->len,
                            t->text);
        name = take(p);
        if (expect_punct(p, '=', "'=' after the identifier") != 0)
            return -1;
        t = peek(p);
        start = *t;
        if (is_color_start(p, t) && !is_expr_start(p, t)) {
            rs_color c;
            if (parse_color(p, 1, &c) != 0)
                return -1;
            v.vec = 1;
            v.v[0] = c.r;
            v.v[1] = c.g;
            v.v[2] = c.b;
        } else if (is_expr_start(p, t)) {
            if (parse_expr(p, &v) != 0)
                return -1;
        } else {
            return expected(p, &start, "a float, vector or colour value");
        }
        if (expect_punct(p, ';', "';' after the declared value") != 0)
            return -1;
        if (sym_set(p, name.text, name.len, &v) != 0)
            return error_at(p, name.line, name.column, "out of memory");
        return 0;
    }
    return error_at(p, d.line, d.column, "unsupported directive '#%.*s'",
                    (int)(d.len > 48 ? 48 : d.len), d.text);
}

/* ------------------------------------------------------------------ */
/* The file                                                            */
/* ------------------------------------------------------------------ */

static int parse_scene(parser *p)
{
    static const struct { const char *kw; rs_object_type type; } objects[] = {
        { "plane", RS_OBJ_PLANE }, { "sphere", RS_OBJ_SPHERE }, { "box", RS_OBJ_BOX },
        { "disc", RS_OBJ_DISC },   { "lens", RS_OBJ_LENS },     { "polarizer", RS_OBJ_POLARIZER },
    };
    for (;;) {
        const rs_token *t = peek(p);
        int rc = 1;
        if (t->kind == RS_TOK_EOF)
            return 0;
        if (t->kind == RS_TOK_DIRECTIVE) {
            rc = parse_directive(p);
        } else if (is_id(t, "camera")) {
            rc = parse_camera(p);
        } else if (is_id(t, "light_source")) {
            rc = parse_light(p);
        } else if (is_id(t, "background")) {
            rc = parse_background(p);
        } else if (is_id(t, "global_settings")) {
            rc = parse_global_settings(p);
        } else {
            for (size_t i = 0; i < sizeof objects / sizeof objects[0]; i++) {
                if (is_id(t, objects[i].kw)) {
                    rc = parse_object(p, objects[i].type);
                    break;
                }
            }
        }
        if (rc > 0)
            return expected(p, t, "camera, light_source, background, global_settings, plane, "
                                  "sphere, box, disc, lens, polarizer or a directive");
        if (rc < 0)
            return -1;
    }
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

/* Keep a copy of the file name in the scene for rs_loc. */
static const char *scene_add_file(rs_scene *scene, const char *name)
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

static int parse_buffer(const char *text, size_t len, const char *name,
                        const rs_parse_opts *opts, rs_scene *scene, char *msg, size_t msg_size)
{
    parser p;
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
    p.file = scene_add_file(scene, name);
    if (p.file == NULL) {
        set_msg(msg, msg_size, "%s: out of memory", name);
        return -1;
    }
    p.image_width = (opts != NULL && opts->image_width > 0) ? opts->image_width : DEFAULT_WIDTH;
    p.image_height =
        (opts != NULL && opts->image_height > 0) ? opts->image_height : DEFAULT_HEIGHT;
    p.max_objects = (opts != NULL && opts->max_objects > 0) ? opts->max_objects
                                                            : DEFAULT_MAX_OBJECTS;
    rs_lexer_init(&p.lx, text, len);
    rc = parse_scene(&p);
    sym_free(&p);
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
    FILE *f;
    char *buf = NULL;
    size_t len = 0, cap = 0;
    int rc;

    set_msg(msg, msg_size, "%s", "");
    if (path == NULL || scene == NULL) {
        set_msg(msg, msg_size, "no file or no scene to parse into");
        return -1;
    }
    f = fopen(path, "rb");
    if (f == NULL) {
        set_msg(msg, msg_size, "%s: cannot read: %s", path, strerror(errno));
        return -1;
    }
    for (;;) {
        size_t got;
        if (len == cap) {
            size_t ncap = cap ? cap * 2 : 65536;
            char *nb;
            if (ncap > MAX_SOURCE_BYTES + 1)
                ncap = MAX_SOURCE_BYTES + 1; /* one byte more tells "too long" */
            nb = realloc(buf, ncap);
            if (nb == NULL) {
                free(buf);
                fclose(f);
                set_msg(msg, msg_size, "%s: out of memory", path);
                return -1;
            }
            buf = nb;
            cap = ncap;
        }
        got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (got == 0 || len > MAX_SOURCE_BYTES)
            break; /* len > MAX: too long (/dev/zero, ...), refused below */
    }
    if (ferror(f)) {
        set_msg(msg, msg_size, "%s: cannot read: %s", path, strerror(errno));
        free(buf);
        fclose(f);
        return -1;
    }
    fclose(f);
    rc = parse_buffer(buf, len, path, opts, scene, msg, msg_size);
    free(buf);
    return rc;
}
