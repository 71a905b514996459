/* directive.c -- the token stream of the scene reader: a stack of frames
 * (the scene file, include files, macro calls), each read by its own
 * lexer, and POV-Ray's language directives acted on as they come:
 *
 *   #include "FILE"         push FILE: first beside the including file, then
 *                           in each library directory in order
 *   #declare / #local N = V [;]   #undef N   #version F ;
 *   #if (F) ... [#elseif (F) ...] [#else ...] #end
 *   #ifdef (N) / #ifndef (N) ... [#else ...] #end
 *   #while (F) ... #end     re-reads the loop from its #while
 *   #switch (F) #case (F) ... #range (LO, HI) ... #break ... #else ... #end
 *                           (a case without #break falls through)
 *   #macro N (P1, ...) BODY #end   and calls N (ARG, ...): the body's
 *                           tokens take the place of the call, with each
 *                           parameter a local identifier
 *   #debug / #warning / #error "TEXT"
 *
 * Skipped text is still split into tokens (a lexical error there is an
 * error), and the directives in it are counted so that each #end closes its
 * own opening.  A scene may read at most RS_TOKEN_BUDGET tokens (an endless
 * #while ends with an error), nest include files and macro calls
 * RS_MAX_FRAMES deep and keep RS_MAX_CONDS conditions open. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "parse_internal.h"

#define RS_PATH_MAX 4096
#define RS_INCLUDE_MAX_BYTES ((size_t)64 << 20)

static int name_is(const rs_token *t, const char *w)
{
    size_t n = strlen(w);
    return t->len == n && memcmp(t->text, w, n) == 0;
}

static frame *top(parser *p)
{
    return &p->frames[p->n_frames - 1];
}

/* The next raw token of the current frame (no directives acted on). */
static int raw(parser *p, rs_token *t)
{
    frame *f = top(p);
    rs_lexer_next(&f->lx, t);
    if (t->kind == RS_TOK_ERROR)
        return rs__error_at(p, t->line, t->column, "%s", f->lx.error);
    if (p->budget == 0)
        return rs__error_at(p, t->line, t->column,
                            "the scene reads too many tokens (an endless #while?)");
    p->budget--;
    return 0;
}

static void set_file(parser *p)
{
    p->file = top(p)->file;
}

static int push_frame(parser *p, int kind, const rs_lexer *lx, const char *file, int line,
                      int column)
{
    frame *f;
    if (p->n_frames >= RS_MAX_FRAMES)
        return rs__error_at(p, line, column,
                            "include files and macro calls nested deeper than %d",
                            RS_MAX_FRAMES);
    if (rs__scope_push(p) != 0)
        return rs__error_at(p, line, column, "out of memory");
    f = &p->frames[p->n_frames++];
    memset(f, 0, sizeof *f);
    f->kind = kind;
    f->lx = *lx;
    f->file = file;
    f->cond_base = p->n_conds;
    f->has_scope = 1;
    f->line = line;
    f->column = column;
    set_file(p);
    return 0;
}

static void pop_frame(parser *p)
{
    if (top(p)->has_scope)
        rs__scope_pop(p);
    p->n_frames--;
    set_file(p);
}

int rs__push_file(parser *p, const char *text, size_t len, const char *name, int line,
                  int column)
{
    rs_lexer lx;
    rs_lexer_init(&lx, text, len);
    return push_frame(p, FRAME_FILE, &lx, name, line, column);
}

void rs__stream_free(parser *p)
{
    while (p->n_frames > 0) {
        if (p->frames[p->n_frames - 1].has_scope)
            rs__scope_pop(p);
        p->n_frames--;
    }
    for (size_t i = 0; i < p->n_buffers; i++)
        free(p->buffers[i]);
    free(p->buffers);
    p->buffers = NULL;
    p->n_buffers = 0;
}

/* ---- conditions ---- */

static int push_cond(parser *p, int kind, const rs_token *d)
{
    cond *c;
    if (p->n_conds >= RS_MAX_CONDS)
        return rs__error_at(p, d->line, d->column, "more than %d #if/#while/#switch open",
                            RS_MAX_CONDS);
    c = &p->conds[p->n_conds++];
    memset(c, 0, sizeof *c);
    c->kind = kind;
    c->line = d->line;
    c->column = d->column;
    c->file = p->file;
    return 0;
}

/* The innermost open condition of the current frame, or NULL. */
static cond *open_cond(parser *p)
{
    return p->n_conds > top(p)->cond_base ? &p->conds[p->n_conds - 1] : NULL;
}

static int opens_block(const rs_token *t)
{
    return name_is(t, "if") || name_is(t, "ifdef") || name_is(t, "ifndef") ||
           name_is(t, "while") || name_is(t, "switch") || name_is(t, "macro") ||
           name_is(t, "for");
}

enum { STOP_ELSE = 1, STOP_ELSEIF = 2, STOP_CASE = 4, STOP_END = 8 };

/* Skip raw tokens to the directive that ends the skipped part at this
 * level: #end always, and those in `stops`.  what/at name the opening for
 * the message when the file ends first. */
static int skip(parser *p, unsigned stops, rs_token *found, const char *what, int line,
                int column)
{
    int depth = 0;
    for (;;) {
        rs_token t;
        if (raw(p, &t) != 0)
            return -1;
        if (t.kind == RS_TOK_EOF)
            return rs__error_at(p, line, column, "#%s has no #end", what);
        if (t.kind != RS_TOK_DIRECTIVE)
            continue;
        if (opens_block(&t)) {
            depth++;
        } else if (name_is(&t, "end")) {
            if (depth == 0) {
                *found = t;
                return 0;
            }
            depth--;
        } else if (depth == 0 &&
                   (((stops & STOP_ELSE) && name_is(&t, "else")) ||
                    ((stops & STOP_ELSEIF) && name_is(&t, "elseif")) ||
                    ((stops & STOP_CASE) &&
                     (name_is(&t, "case") || name_is(&t, "range") || name_is(&t, "else"))))) {
            *found = t;
            return 0;
        }
    }
}

/* '(' expression ')' without reading past the ')'. */
static int paren_float(parser *p, const char *what, double *out)
{
    val v;
    rs_token start;
    char w[64];
    snprintf(w, sizeof w, "'(' after '#%s'", what);
    if (rs__peek(p)->kind != RS_TOK_PUNCT || rs__peek(p)->punct != '(')
        return rs__expected(p, rs__peek(p), w);
    rs__take(p);
    start = *rs__peek(p);
    if (rs__parse_expr(p, &v) != 0)
        return -1;
    if (v.kind != VAL_FLOAT) {
        rs__val_free(&v);
        return rs__error_at(p, start.line, start.column, "#%s needs a float", what);
    }
    *out = v.v[0];
    snprintf(w, sizeof w, "')' to close the condition of '#%s'", what);
    if (rs__peek(p)->kind != RS_TOK_PUNCT || rs__peek(p)->punct != ')')
        return rs__expected(p, rs__peek(p), w);
    p->n_la = 0; /* take the ')' and look no further */
    return 0;
}

/* '(' LO ',' HI ')' of #range. */
static int paren_range(parser *p, double *lo, double *hi)
{
    val a, b;
    if (rs__peek(p)->kind != RS_TOK_PUNCT || rs__peek(p)->punct != '(')
        return rs__expected(p, rs__peek(p), "'(' after '#range'");
    rs__take(p);
    if (rs__parse_expr(p, &a) != 0)
        return -1;
    if (rs__peek(p)->kind != RS_TOK_PUNCT || rs__peek(p)->punct != ',') {
        rs__val_free(&a);
        return rs__expected(p, rs__peek(p), "',' between the bounds of '#range'");
    }
    rs__take(p);
    if (rs__parse_expr(p, &b) != 0) {
        rs__val_free(&a);
        return -1;
    }
    if (a.kind != VAL_FLOAT || b.kind != VAL_FLOAT) {
        rs__val_free(&a);
        rs__val_free(&b);
        return rs__error_at(p, rs__peek(p)->line, rs__peek(p)->column,
                            "#range needs two floats");
    }
    *lo = a.v[0];
    *hi = b.v[0];
    if (rs__peek(p)->kind != RS_TOK_PUNCT || rs__peek(p)->punct != ')')
        return rs__expected(p, rs__peek(p), "')' to close '#range'");
    p->n_la = 0;
    return 0;
}

/* '(' IDENT ')' read raw (a macro name is not called). */
static int paren_name(parser *p, const char *what, rs_token *name)
{
    rs_token t;
    char w[64];
    snprintf(w, sizeof w, "'(' after '#%s'", what);
    if (raw(p, &t) != 0)
        return -1;
    if (t.kind != RS_TOK_PUNCT || t.punct != '(')
        return rs__expected(p, &t, w);
    if (raw(p, name) != 0)
        return -1;
    if (name->kind != RS_TOK_IDENT)
        return rs__expected(p, name, "an identifier");
    if (raw(p, &t) != 0)
        return -1;
    if (t.kind != RS_TOK_PUNCT || t.punct != ')')
        return rs__expected(p, &t, "')' after the identifier");
    return 0;
}

static int is_defined(parser *p, const rs_token *n)
{
    return rs__sym_find(p, n->text, n->len) != NULL || rs__macro_find(p, n->text, n->len) != NULL;
}

/* #if/#elseif chain from a false condition: skip to the branch to run. */
static int if_false(parser *p, const rs_token *d, const char *what)
{
    for (;;) {
        rs_token f = {RS_TOK_EOF, 0, 0, 0, 0, NULL, 0};
        double c;
        if (skip(p, STOP_ELSE | STOP_ELSEIF, &f, what, d->line, d->column) != 0)
            return -1;
        if (name_is(&f, "end"))
            return 0;
        if (name_is(&f, "else"))
            return push_cond(p, COND_IF, d);
        if (paren_float(p, "elseif", &c) != 0)
            return -1;
        if (c != 0.0)
            return push_cond(p, COND_IF, d);
    }
}

static int do_while(parser *p, const rs_token *d, const rs_lexer *restart)
{
    double c;
    if (paren_float(p, "while", &c) != 0)
        return -1;
    if (c == 0.0) {
        rs_token f = {RS_TOK_EOF, 0, 0, 0, 0, NULL, 0};
        return skip(p, 0, &f, "while", d->line, d->column);
    }
    if (push_cond(p, COND_WHILE, d) != 0)
        return -1;
    p->conds[p->n_conds - 1].restart = *restart;
    return 0;
}

/* From #switch: find the first case that holds (or #else, or #end). */
static int switch_find(parser *p, const rs_token *d, double value)
{
    for (;;) {
        rs_token f = {RS_TOK_EOF, 0, 0, 0, 0, NULL, 0};
        if (skip(p, STOP_CASE, &f, "switch", d->line, d->column) != 0)
            return -1;
        if (name_is(&f, "end"))
            return 0;
        if (name_is(&f, "case")) {
            double c;
            if (paren_float(p, "case", &c) != 0)
                return -1;
            if (c == value)
                break;
        } else if (name_is(&f, "range")) {
            double lo, hi;
            if (paren_range(p, &lo, &hi) != 0)
                return -1;
            if (value >= lo && value <= hi)
                break;
        } else {
            break; /* #else */
        }
    }
    if (push_cond(p, COND_SWITCH, d) != 0)
        return -1;
    p->conds[p->n_conds - 1].value = value;
    return 0;
}

/* ---- include files ---- */

/* The directory part of path ("" for none), with its trailing '/'. */
static void dir_of(const char *path, char *out, size_t size)
{
    const char *slash = strrchr(path, '/');
    size_t n = slash ? (size_t)(slash - path) + 1 : 0;
    if (n >= size)
        n = 0;
    memcpy(out, path, n);
    out[n] = '\0';
}

static int do_include(parser *p, const rs_token *d)
{
    char *name = NULL, *text = NULL, path[RS_PATH_MAX], dir[RS_PATH_MAX], why[256] = "";
    size_t len = 0;
    const char *file;
    int found = 0;
    rs_token at = *rs__peek(p);

    if (rs__parse_string(p, &name) != 0)
        return -1;
    if (name[0] == '\0') {
        free(name);
        return rs__error_at(p, at.line, at.column, "#include of an empty file name");
    }
    if (p->no_include) {
        free(name);
        return rs__error_at(p, d->line, d->column, "#include: include files are off here");
    }
    for (size_t k = 0; !found && k <= p->n_include_dirs; k++) {
        int n;
        if (name[0] == '/') {
            if (k > 0)
                break;
            n = snprintf(path, sizeof path, "%s", name);
        } else if (k == 0) {
            dir_of(p->file, dir, sizeof dir);
            n = snprintf(path, sizeof path, "%s%s", dir, name);
        } else {
            const char *ld = p->include_dirs[k - 1];
            size_t l = strlen(ld);
            n = snprintf(path, sizeof path, "%s%s%s", ld, l > 0 && ld[l - 1] != '/' ? "/" : "",
                         name);
        }
        if (n < 0 || (size_t)n >= sizeof path)
            continue;
        if (rs__read_text(path, &text, &len, why, sizeof why) == 0)
            found = 1;
        else if (errno != ENOENT && errno != ENOTDIR) {
            rs__error_at(p, at.line, at.column, "#include \"%s\": %s", name, why);
            free(name);
            return -1;
        }
    }
    if (!found) {
        rs__error_at(p, at.line, at.column,
                     "#include: cannot find \"%.200s\" beside %.200s or in the %zu library "
                     "director%s (add one with -L DIR)", name, p->file, p->n_include_dirs,
                     p->n_include_dirs == 1 ? "y" : "ies");
        free(name);
        return -1;
    }
    free(name);
    {
        char **b = realloc(p->buffers, (p->n_buffers + 1) * sizeof *b);
        if (b == NULL) {
            free(text);
            return rs__error_at(p, d->line, d->column, "out of memory");
        }
        p->buffers = b;
        p->buffers[p->n_buffers++] = text;
    }
    file = rs__scene_add_file(p->scene, path);
    if (file == NULL)
        return rs__error_at(p, d->line, d->column, "out of memory");
    return rs__push_file(p, text, len, file, d->line, d->column);
}

/* ---- macros ---- */

static char *dup_token(const rs_token *t)
{
    char *s = malloc(t->len + 1);
    if (s != NULL) {
        memcpy(s, t->text, t->len);
        s[t->len] = '\0';
    }
    return s;
}

static int do_macro(parser *p, const rs_token *d)
{
    rs_token name, t, f = {RS_TOK_EOF, 0, 0, 0, 0, NULL, 0};
    macro m;

    memset(&m, 0, sizeof m);
    if (raw(p, &name) != 0)
        return -1;
    if (name.kind != RS_TOK_IDENT)
        return rs__expected(p, &name, "a macro name after '#macro'");
    if (rs__is_reserved(name.text, name.len))
        return rs__error_at(p, name.line, name.column, "'%.*s' is a reserved word",
                            (int)(name.len > 48 ? 48 : name.len), name.text);
    if (raw(p, &t) != 0)
        return -1;
    if (t.kind != RS_TOK_PUNCT || t.punct != '(')
        return rs__expected(p, &t, "'(' after the macro name");
    m.line = d->line;
    m.column = d->column;
    m.file = p->file;
    for (;;) {
        if (raw(p, &t) != 0)
            goto fail;
        if (t.kind == RS_TOK_PUNCT && t.punct == ')' && m.n_params == 0)
            break;
        if (t.kind != RS_TOK_IDENT) {
            rs__expected(p, &t, "a parameter name");
            goto fail;
        }
        if (m.n_params == RS_MAX_PARAMS) {
            rs__error_at(p, t.line, t.column, "a macro takes at most %d parameters",
                         RS_MAX_PARAMS);
            goto fail;
        }
        if ((m.params[m.n_params++] = dup_token(&t)) == NULL) {
            rs__error_at(p, t.line, t.column, "out of memory");
            goto fail;
        }
        if (raw(p, &t) != 0)
            goto fail;
        if (t.kind == RS_TOK_PUNCT && t.punct == ')')
            break;
        if (t.kind != RS_TOK_PUNCT || t.punct != ',') {
            rs__expected(p, &t, "',' or ')' in the macro's parameters");
            goto fail;
        }
    }
    m.body = top(p)->lx;
    if (skip(p, 0, &f, "macro", d->line, d->column) != 0)
        goto fail;
    if ((m.name = dup_token(&name)) == NULL) {
        rs__error_at(p, name.line, name.column, "out of memory");
        goto fail;
    }
    m.len = name.len;
    for (size_t i = 0; i < p->n_macros; i++) {
        if (p->macros[i].len == m.len && memcmp(p->macros[i].name, m.name, m.len) == 0) {
            free(p->macros[i].name);
            for (int k = 0; k < p->macros[i].n_params; k++)
                free(p->macros[i].params[k]);
            p->macros[i] = m;
            return 0;
        }
    }
    if (p->n_macros == p->cap_macros) {
        size_t cap = p->cap_macros ? 2 * p->cap_macros : 8;
        macro *a = realloc(p->macros, cap * sizeof *a);
        if (a == NULL) {
            rs__error_at(p, d->line, d->column, "out of memory");
            goto fail;
        }
        p->macros = a;
        p->cap_macros = cap;
    }
    p->macros[p->n_macros++] = m;
    return 0;
fail:
    free(m.name);
    for (int k = 0; k < m.n_params; k++)
        free(m.params[k]);
    return -1;
}

/* NAME ( ARG, ... ): evaluate the arguments, then read the body. */
static int call_macro(parser *p, const rs_token *at, const macro *mp)
{
    val args[RS_MAX_PARAMS];
    int n = 0, rc = -1;
    char mname[64];
    macro m = *mp; /* p->macros may move while the arguments are read */

    snprintf(mname, sizeof mname, "%.48s", m.name);
    if (rs__peek(p)->kind != RS_TOK_PUNCT || rs__peek(p)->punct != '(') {
        char w[96];
        snprintf(w, sizeof w, "'(' after the macro name '%s'", mname);
        return rs__expected(p, rs__peek(p), w);
    }
    rs__take(p);
    if (rs__peek(p)->kind == RS_TOK_PUNCT && rs__peek(p)->punct == ')') {
        /* no arguments */
    } else {
        for (;;) {
            if (n == m.n_params) {
                rs__error_at(p, rs__peek(p)->line, rs__peek(p)->column,
                             "macro '%s' takes %d argument%s", mname, m.n_params,
                             m.n_params == 1 ? "" : "s");
                goto out;
            }
            if (rs__parse_value(p, &args[n], "a macro argument") != 0)
                goto out;
            n++;
            if (rs__peek(p)->kind == RS_TOK_PUNCT && rs__peek(p)->punct == ',') {
                rs__take(p);
                continue;
            }
            break;
        }
    }
    if (rs__peek(p)->kind != RS_TOK_PUNCT || rs__peek(p)->punct != ')') {
        rs__expected(p, rs__peek(p), "',' or ')' after a macro argument");
        goto out;
    }
    if (n != m.n_params) {
        rs__error_at(p, rs__peek(p)->line, rs__peek(p)->column,
                     "macro '%s' takes %d argument%s, found %d", mname, m.n_params,
                     m.n_params == 1 ? "" : "s", n);
        goto out;
    }
    p->n_la = 0; /* the ')' */
    if (push_frame(p, FRAME_MACRO, &m.body, m.file, at->line, at->column) != 0)
        goto out;
    for (int k = 0; k < n; k++)
        if (rs__sym_set(p, m.params[k], strlen(m.params[k]), &args[k], 1) != 0) {
            rs__error_at(p, at->line, at->column, "out of memory");
            goto out;
        }
    rc = 0;
out:
    for (int k = 0; k < n; k++)
        rs__val_free(&args[k]);
    return rc;
}

/* ---- the directives ---- */

static int do_declare(parser *p, const rs_token *d, int local)
{
    rs_token name;
    val v;
    char w[48];

    snprintf(w, sizeof w, "an identifier after '#%s'", local ? "local" : "declare");
    if (raw(p, &name) != 0)
        return -1;
    if (name.kind != RS_TOK_IDENT)
        return rs__expected(p, &name, w);
    if (rs__is_reserved(name.text, name.len))
        return rs__error_at(p, name.line, name.column, "'%.*s' is a reserved word",
                            (int)(name.len > 48 ? 48 : name.len), name.text);
    if (rs__peek(p)->kind != RS_TOK_PUNCT || rs__peek(p)->punct != '=')
        return rs__expected(p, rs__peek(p), "'=' after the identifier");
    rs__take(p);
    if (rs__parse_value(p, &v, "a value") != 0)
        return -1;
    if (v.kind == VAL_FLOAT || v.kind == VAL_VECTOR || v.kind == VAL_STRING) {
        const rs_token *t = rs__peek(p);
        if (t->kind != RS_TOK_PUNCT || t->punct != ';') {
            rs__val_free(&v);
            return rs__expected(p, t, "';' after the declared value");
        }
        p->n_la = 0;
        if (rs__sym_set(p, name.text, name.len, &v, local) != 0) {
            rs__val_free(&v);
            return rs__error_at(p, name.line, name.column, "out of memory");
        }
        return 0;
    }
    (void)d;
    if (rs__sym_set(p, name.text, name.len, &v, local) != 0) {
        rs__val_free(&v);
        return rs__error_at(p, name.line, name.column, "out of memory");
    }
    if (rs__peek(p)->kind == RS_TOK_PUNCT && rs__peek(p)->punct == ';')
        rs__take(p);
    return 0;
}

static int do_message(parser *p, const rs_token *d)
{
    char *text = NULL;
    int rc = 0;
    if (rs__parse_string(p, &text) != 0)
        return -1;
    if (name_is(d, "error")) {
        rc = rs__error_at(p, d->line, d->column, "#error: %s", text);
    } else if (name_is(d, "warning")) {
        rs__warn(p, d->line, d->column, "#warning: %s", text);
    } else {
        if (rs_scene_add_message(p->scene, RS_MSG_DEBUG, text) != 0)
            rc = rs__error_at(p, d->line, d->column, "out of memory");
    }
    free(text);
    return rc;
}

/* Act on the directive d (just read raw).  0, or -1 with p->failed. */
static int directive(parser *p, const rs_token *d)
{
    cond *c;
    rs_token f = {RS_TOK_EOF, 0, 0, 0, 0, NULL, 0};

    if (name_is(d, "include"))
        return do_include(p, d);
    if (name_is(d, "declare"))
        return do_declare(p, d, 0);
    if (name_is(d, "local"))
        return do_declare(p, d, 1);
    if (name_is(d, "undef")) {
        rs_token n;
        if (raw(p, &n) != 0)
            return -1;
        if (n.kind != RS_TOK_IDENT)
            return rs__expected(p, &n, "an identifier after '#undef'");
        if (rs__sym_undef(p, n.text, n.len) < 0)
            return rs__error_at(p, n.line, n.column, "out of memory");
        return 0;
    }
    if (name_is(d, "version")) {
        val v;
        rs_token start = *rs__peek(p);
        if (rs__parse_expr(p, &v) != 0)
            return -1;
        if (v.kind != VAL_FLOAT) {
            rs__val_free(&v);
            return rs__error_at(p, start.line, start.column, "#version needs a float");
        }
        p->version = v.v[0];
        if (rs__peek(p)->kind == RS_TOK_PUNCT && rs__peek(p)->punct == ';')
            p->n_la = 0;
        return 0;
    }
    if (name_is(d, "if")) {
        double v;
        if (paren_float(p, "if", &v) != 0)
            return -1;
        return v != 0.0 ? push_cond(p, COND_IF, d) : if_false(p, d, "if");
    }
    if (name_is(d, "ifdef") || name_is(d, "ifndef")) {
        rs_token n;
        int def;
        if (paren_name(p, name_is(d, "ifdef") ? "ifdef" : "ifndef", &n) != 0)
            return -1;
        def = is_defined(p, &n);
        if (name_is(d, "ifndef"))
            def = !def;
        if (def)
            return push_cond(p, COND_IF, d);
        if (skip(p, STOP_ELSE, &f, name_is(d, "ifdef") ? "ifdef" : "ifndef", d->line,
                 d->column) != 0)
            return -1;
        return name_is(&f, "else") ? push_cond(p, COND_IF, d) : 0;
    }
    if (name_is(d, "while")) {
        rs_lexer restart = top(p)->lx;
        return do_while(p, d, &restart);
    }
    if (name_is(d, "switch")) {
        double v;
        if (paren_float(p, "switch", &v) != 0)
            return -1;
        return switch_find(p, d, v);
    }
    if (name_is(d, "macro"))
        return do_macro(p, d);
    if (name_is(d, "debug") || name_is(d, "warning") || name_is(d, "error"))
        return do_message(p, d);

    c = open_cond(p);
    if (name_is(d, "else") || name_is(d, "elseif")) {
        if (c != NULL && c->kind == COND_IF) {
            if (skip(p, 0, &f, "if", c->line, c->column) != 0)
                return -1;
            p->n_conds--;
            return 0;
        }
        if (c != NULL && c->kind == COND_SWITCH && name_is(d, "else"))
            return 0; /* falls through */
        return rs__error_at(p, d->line, d->column, "#%.*s without #if", (int)d->len, d->text);
    }
    if (name_is(d, "case") || name_is(d, "range")) {
        double lo, hi;
        if (c == NULL || c->kind != COND_SWITCH)
            return rs__error_at(p, d->line, d->column, "#%.*s without #switch", (int)d->len,
                                d->text);
        /* a case without #break falls through: read and pass its label */
        if (name_is(d, "case"))
            return paren_float(p, "case", &lo);
        return paren_range(p, &lo, &hi);
    }
    if (name_is(d, "break")) {
        if (c == NULL || c->kind != COND_SWITCH)
            return rs__error_at(p, d->line, d->column, "#break without #switch");
        if (skip(p, 0, &f, "switch", c->line, c->column) != 0)
            return -1;
        p->n_conds--;
        return 0;
    }
    if (name_is(d, "end")) {
        if (c != NULL) {
            cond done = *c;
            p->n_conds--;
            if (done.kind == COND_WHILE) {
                rs_token w = {RS_TOK_DIRECTIVE, done.line, done.column, 0, 0, "while", 5};
                top(p)->lx = done.restart;
                return do_while(p, &w, &done.restart);
            }
            return 0;
        }
        if (top(p)->kind == FRAME_MACRO) {
            pop_frame(p);
            return 0;
        }
        return rs__error_at(p, d->line, d->column,
                            "#end without #if, #ifdef, #ifndef, #while, #switch or #macro");
    }
    return rs__error_at(p, d->line, d->column, "unsupported directive '#%.*s'",
                        (int)(d->len > 48 ? 48 : d->len), d->text);
}

void rs__fetch(parser *p)
{
    for (;;) {
        rs_token t;
        if (p->failed) {
            memset(&p->la, 0, sizeof p->la);
            p->la.kind = RS_TOK_ERROR;
            p->n_la = 1;
            return;
        }
        if (raw(p, &t) != 0)
            continue;
        if (t.kind == RS_TOK_EOF) {
            frame *f = top(p);
            if (p->n_conds > f->cond_base) {
                cond *c = &p->conds[p->n_conds - 1];
                static const char *const names[] = {"if", "while", "switch"};
                p->file = c->file;
                rs__error_at(p, c->line, c->column, "#%s has no #end", names[c->kind]);
                continue;
            }
            if (f->kind == FRAME_MACRO) {
                rs__error_at(p, f->line, f->column, "the macro's body has no #end");
                continue;
            }
            if (p->n_frames > 1) {
                pop_frame(p);
                continue;
            }
            p->la = t;
            p->n_la = 1;
            return;
        }
        if (t.kind == RS_TOK_DIRECTIVE) {
            if (p->fetch_depth >= RS_MAX_DEPTH) {
                rs__error_at(p, t.line, t.column,
                             "directives inside directives nested deeper than %d", RS_MAX_DEPTH);
                continue;
            }
            p->fetch_depth++;
            directive(p, &t);
            p->fetch_depth--;
            if (p->n_la > 0 && !p->failed)
                return;
            continue;
        }
        if (t.kind == RS_TOK_IDENT) {
            const macro *m = rs__macro_find(p, t.text, t.len);
            if (m != NULL && rs__sym_find(p, t.text, t.len) == NULL) {
                if (p->fetch_depth >= RS_MAX_DEPTH) {
                    rs__error_at(p, t.line, t.column,
                                 "macro calls inside arguments nested deeper than %d",
                                 RS_MAX_DEPTH);
                    continue;
                }
                p->fetch_depth++;
                call_macro(p, &t, m);
                p->fetch_depth--;
                continue;
            }
        }
        p->la = t;
        p->n_la = 1;
        return;
    }
}
