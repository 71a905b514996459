/* parse_internal.h -- what the scene reader's parts share (parser.c: the
 * grammar and expressions; directive.c: the token stream with POV-Ray's
 * directives, macros and include files; symbols.c: values and scopes).
 * Renderer-internal; see parser.h for the language. */
#ifndef RS_PARSE_INTERNAL_H
#define RS_PARSE_INTERNAL_H

#include <stddef.h>

#include "lexer.h"
#include "parser.h"
#include "scene.h"

#define RS_MAX_DEPTH 64       /* braces, parentheses, brackets, calls */
#define RS_MAX_FRAMES 64      /* include files and macro calls in progress */
#define RS_MAX_CONDS 256      /* open #if/#while/#switch per parse */
#define RS_MAX_PARAMS 16      /* parameters of one macro */
#define RS_TOKEN_BUDGET 20000000ull /* tokens one parse may read */

/* ---- values ---- */

typedef enum val_kind {
    VAL_FLOAT = 0,
    VAL_VECTOR,     /* 3 to 5 components; colours are 5: r g b filter transmit */
    VAL_STRING,
    VAL_PIGMENT,
    VAL_FINISH,
    VAL_TEXTURE,
    VAL_INTERIOR,
    VAL_OBJECT
} val_kind;

/* A declared pigment: the pigment and its pattern -> world transform so far. */
typedef struct rs_pigment_val {
    rs_pigment pig;
    rs_transform pat;
} rs_pigment_val;

/* A declared texture. */
typedef struct rs_texture_val {
    rs_pigment pig;
    rs_transform pat;
    rs_finish fin;
} rs_texture_val;

/* A declared object: objects and lights (a union is several). */
typedef struct rs_group {
    rs_object *objects;
    size_t n_objects, cap_objects;
    rs_light *lights;
    size_t n_lights, cap_lights;
} rs_group;

typedef struct val {
    val_kind kind;
    int vec;        /* kind == VAL_VECTOR (kept for the arithmetic) */
    int dim;        /* VAL_VECTOR: 3, 4 or 5 components */
    double v[5];    /* FLOAT: v[0]; VECTOR: v[0..dim) (the rest 0) */
    char *str;      /* VAL_STRING (owned) */
    void *ptr;      /* PIGMENT: rs_pigment_val, FINISH: rs_finish,
                       TEXTURE: rs_texture_val, INTERIOR: double (ior),
                       OBJECT: rs_group (owned) */
} val;

/* ---- symbols: a stack of scopes ---- */

typedef struct sym {
    char *name;     /* NULL: empty slot */
    size_t len;
    val v;
} sym;

typedef struct scope {
    sym *syms;
    size_t cap, count;
} scope;

/* ---- macros ---- */

typedef struct macro {
    char *name;
    size_t len;
    const char *file;       /* owned by the scene */
    rs_lexer body;          /* lexer state at the start of the body */
    int line, column;       /* of the #macro directive */
    int n_params;
    char *params[RS_MAX_PARAMS];
} macro;

/* ---- the token stream ---- */

enum { FRAME_FILE = 0, FRAME_MACRO };

typedef struct frame {
    int kind;
    rs_lexer lx;
    const char *file;       /* owned by the scene */
    size_t cond_base;       /* p->n_conds when the frame started */
    int has_scope;          /* the frame pushed a scope (#local goes there) */
    const macro *m;         /* FRAME_MACRO */
    int line, column;       /* where it was entered (for messages) */
} frame;

enum { COND_IF = 0, COND_WHILE, COND_SWITCH };

typedef struct cond {
    int kind;
    int line, column;       /* the opening directive */
    const char *file;
    rs_lexer restart;       /* COND_WHILE: lexer state just after '#while' */
    double value;           /* COND_SWITCH: the switch value */
} cond;

typedef struct parser {
    frame frames[RS_MAX_FRAMES];
    int n_frames;
    cond conds[RS_MAX_CONDS];
    size_t n_conds;
    rs_token la;            /* one token of lookahead */
    int n_la;
    rs_scene *scene;
    const char *file;       /* the current frame's file (for locations) */
    double image_width, image_height;
    size_t max_objects;
    size_t csg_nodes;       /* objects made inside intersections and
                               differences so far (bounded by max_objects) */
    const char *const *include_dirs;
    size_t n_include_dirs;
    int no_include;         /* #include refused */
    double version;         /* #version (default 3.7) */
    unsigned long long budget; /* tokens left (loops and macros end) */
    scope *scopes;
    size_t n_scopes, cap_scopes;
    macro *macros;
    size_t n_macros, cap_macros;
    char **buffers;         /* file texts read (macros point into them) */
    size_t n_buffers;
    int allow_inf;          /* `inf` is a value (lens radii) */
    int fetch_depth;        /* rs__fetch calls in progress (a directive's
                               arguments may hold directives) */
    int in_vector;          /* reading a vector literal's components */
    int depth;
    char *msg;
    size_t msg_size;
    int failed;
} parser;

/* ---- parser.c ---- */
int rs__error_at(parser *p, int line, int column, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
int rs__expected(parser *p, const rs_token *t, const char *what);
void rs__warn(parser *p, int line, int column, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
const rs_token *rs__peek(parser *p);
rs_token rs__take(parser *p);
int rs__is_reserved(const char *text, size_t len);
/* Any value: float, vector, colour, string, pigment, finish, texture,
 * interior or object. */
int rs__parse_value(parser *p, val *out, const char *what);
int rs__parse_expr(parser *p, val *out);
int rs__parse_string(parser *p, char **out);

/* ---- directive.c ---- */
/* The next token for the parser after directives and macro calls, into
 * p->la (p->n_la = 1), or p->failed. */
void rs__fetch(parser *p);
int rs__push_file(parser *p, const char *text, size_t len, const char *name, int line,
                  int column);
void rs__stream_free(parser *p);
/* Read the whole file at path into *out (malloc'd, NUL-terminated; at most
 * 64 MiB).  0, or -1 with errno set and a reason in why. */
int rs__read_text(const char *path, char **out, size_t *out_len, char *why, size_t why_size);
/* Keep a copy of a file name in the scene (for rs_loc); NULL: no memory. */
const char *rs__scene_add_file(rs_scene *scene, const char *name);

/* ---- symbols.c ---- */
void rs__val_free(val *v);
int rs__val_copy(const val *src, val *dst);       /* -1: out of memory */
int rs__group_push_object(rs_group *g, const rs_object *o); /* a deep copy; -1: no memory */
int rs__group_push_light(rs_group *g, const rs_light *l);
int rs__group_append(rs_group *dst, const rs_group *src);
void rs__group_free(rs_group *g);
int rs__scope_push(parser *p);
void rs__scope_pop(parser *p);
sym *rs__sym_find(parser *p, const char *name, size_t len);
/* #declare (local = 0) or #local (1); the value moves into the table. */
int rs__sym_set(parser *p, const char *name, size_t len, val *v, int local);
int rs__sym_undef(parser *p, const char *name, size_t len);
void rs__symbols_free(parser *p);
const macro *rs__macro_find(const parser *p, const char *name, size_t len);

#endif
