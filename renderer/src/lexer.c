/* lexer.c -- tokens of a .scene file; see lexer.h. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lexer.h"

#define LEX_NUMBER_MAX 128 /* longest number literal accepted */

void rs_lexer_init(rs_lexer *lx, const char *src, size_t len)
{
    memset(lx, 0, sizeof *lx);
    lx->src = src;
    lx->len = len;
    lx->line = 1;
    lx->column = 1;
    if (len >= 3 && (unsigned char)src[0] == 0xEF && (unsigned char)src[1] == 0xBB &&
        (unsigned char)src[2] == 0xBF)
        lx->pos = 3; /* UTF-8 byte order mark */
}

static int cur(const rs_lexer *lx)
{
    return lx->pos < lx->len ? (unsigned char)lx->src[lx->pos] : -1;
}

static int ahead(const rs_lexer *lx, size_t k)
{
    return lx->pos + k < lx->len ? (unsigned char)lx->src[lx->pos + k] : -1;
}

static void advance(rs_lexer *lx)
{
    if (lx->pos >= lx->len)
        return;
    if (lx->src[lx->pos] == '\n') {
        lx->line++;
        lx->column = 1;
    } else {
        lx->column++;
    }
    lx->pos++;
}

static int is_digit(int c) { return c >= '0' && c <= '9'; }
static int is_alpha(int c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }

static void fail(rs_lexer *lx, rs_token *tok, int line, int column, const char *fmt,
                 const char *arg)
{
    snprintf(lx->error, sizeof lx->error, fmt, arg);
    memset(tok, 0, sizeof *tok);
    tok->kind = RS_TOK_ERROR;
    tok->line = line;
    tok->column = column;
    lx->failed = 1;
    lx->error_tok = *tok;
}

/* Skip whitespace and comments.  Returns 0, or -1 after an unterminated
 * block comment (error filled). */
static int skip_space(rs_lexer *lx, rs_token *tok)
{
    for (;;) {
        int c = cur(lx);
        if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v') {
            advance(lx);
        } else if (c == '/' && ahead(lx, 1) == '/') {
            while (cur(lx) != -1 && cur(lx) != '\n')
                advance(lx);
        } else if (c == '/' && ahead(lx, 1) == '*') {
            int line = lx->line, column = lx->column;
            long depth = 0;
            do {
                if (cur(lx) == -1) {
                    fail(lx, tok, line, column, "unterminated comment%s",
                         "");
                    return -1;
                }
                if (cur(lx) == '/' && ahead(lx, 1) == '*') {
                    depth++;
                    advance(lx);
                    advance(lx);
                } else if (cur(lx) == '*' && ahead(lx, 1) == '/') {
                    depth--;
                    advance(lx);
                    advance(lx);
                } else {
                    advance(lx);
                }
            } while (depth > 0);
        } else {
            return 0;
        }
    }
}

static void lex_number(rs_lexer *lx, rs_token *tok)
{
    size_t start = lx->pos, n;
    char buf[LEX_NUMBER_MAX + 1];
    int bad = 0;

    while (is_digit(cur(lx)))
        advance(lx);
    if (cur(lx) == '.') {
        advance(lx);
        while (is_digit(cur(lx)))
            advance(lx);
    }
    if (cur(lx) == 'e' || cur(lx) == 'E') {
        advance(lx);
        if (cur(lx) == '+' || cur(lx) == '-')
            advance(lx);
        if (!is_digit(cur(lx)))
            bad = 1;
        while (is_digit(cur(lx)))
            advance(lx);
    }
    /* A number glued to letters ("3x", "1e3e") is a typo, not two tokens. */
    while (is_alpha(cur(lx)) || is_digit(cur(lx))) {
        bad = 1;
        advance(lx);
    }
    n = lx->pos - start;
    if (n > LEX_NUMBER_MAX) {
        fail(lx, tok, tok->line, tok->column, "number literal too long%s", "");
        return;
    }
    memcpy(buf, lx->src + start, n);
    buf[n] = '\0';
    if (bad) {
        fail(lx, tok, tok->line, tok->column, "bad number '%s'", buf);
        return;
    }
    errno = 0;
    tok->number = strtod(buf, NULL);
    if (!isfinite(tok->number) || (errno == ERANGE && fabs(tok->number) > 1.0)) {
        fail(lx, tok, tok->line, tok->column, "number '%s' is out of range", buf);
        return;
    }
    tok->kind = RS_TOK_NUMBER;
}

void rs_lexer_next(rs_lexer *lx, rs_token *tok)
{
    int c;

    if (lx->failed) {
        *tok = lx->error_tok;
        return;
    }
    if (skip_space(lx, tok) != 0)
        return;
    memset(tok, 0, sizeof *tok);
    tok->line = lx->line;
    tok->column = lx->column;
    c = cur(lx);
    if (c == -1) {
        tok->kind = RS_TOK_EOF;
        return;
    }
    if (is_digit(c) || (c == '.' && is_digit(ahead(lx, 1)))) {
        lex_number(lx, tok);
        return;
    }
    if (is_alpha(c)) {
        size_t start = lx->pos;
        while (is_alpha(cur(lx)) || is_digit(cur(lx)))
            advance(lx);
        tok->kind = RS_TOK_IDENT;
        tok->text = lx->src + start;
        tok->len = lx->pos - start;
        return;
    }
    if (c == '"') {
        size_t start;
        advance(lx);
        start = lx->pos;
        for (;;) {
            int d = cur(lx);
            if (d == -1 || d == '\n' || d == '\r') {
                fail(lx, tok, tok->line, tok->column, "unterminated string%s", "");
                return;
            }
            if (d == '"')
                break;
            if (d == '\\' && ahead(lx, 1) != -1 && ahead(lx, 1) != '\n')
                advance(lx);
            advance(lx);
        }
        tok->kind = RS_TOK_STRING;
        tok->text = lx->src + start;
        tok->len = lx->pos - start;
        advance(lx); /* closing quote */
        return;
    }
    if (c == '#') {
        size_t start;
        advance(lx);
        while (cur(lx) == ' ' || cur(lx) == '\t') /* POV-Ray: "#   debug" */
            advance(lx);
        if (!is_alpha(cur(lx))) {
            fail(lx, tok, tok->line, tok->column,
                 "expected a directive name after '#'%s", "");
            return;
        }
        start = lx->pos;
        while (is_alpha(cur(lx)) || is_digit(cur(lx)))
            advance(lx);
        tok->kind = RS_TOK_DIRECTIVE;
        tok->text = lx->src + start;
        tok->len = lx->pos - start;
        return;
    }
    if (c < 128 && c > 0 && strchr("<>{}()[],;=+-*/.?:!&|", c) != NULL) {
        tok->kind = RS_TOK_PUNCT;
        tok->punct = (char)c;
        advance(lx);
        return;
    }
    {
        char what[16];
        if (c >= 32 && c < 127)
            snprintf(what, sizeof what, "'%c'", c);
        else
            snprintf(what, sizeof what, "0x%02X", (unsigned)c);
        fail(lx, tok, tok->line, tok->column, "unexpected character %s", what);
    }
}

void rs_token_describe(const rs_token *tok, char *buf, size_t size)
{
    int n;
    if (size == 0)
        return;
    n = tok->len > 48 ? 48 : (int)tok->len;
    switch (tok->kind) {
    case RS_TOK_EOF:
        snprintf(buf, size, "end of file");
        break;
    case RS_TOK_NUMBER:
        snprintf(buf, size, "number %.10g", tok->number);
        break;
    case RS_TOK_IDENT:
        snprintf(buf, size, "identifier '%.*s'%s", n, tok->text, tok->len > 48 ? "..." : "");
        break;
    case RS_TOK_STRING:
        snprintf(buf, size, "string \"%.*s\"%s", n, tok->text, tok->len > 48 ? "..." : "");
        break;
    case RS_TOK_DIRECTIVE:
        snprintf(buf, size, "directive '#%.*s'", n, tok->text);
        break;
    case RS_TOK_PUNCT:
        snprintf(buf, size, "'%c'", tok->punct);
        break;
    default:
        snprintf(buf, size, "an invalid token");
        break;
    }
}

int rs_string_decode(const rs_token *tok, char *out, size_t size)
{
    size_t o = 0;
    if (size == 0)
        return -1;
    for (size_t i = 0; i < tok->len; i++) {
        char c = tok->text[i];
        if (c == '\\' && i + 1 < tok->len) {
            char e = tok->text[++i];
            c = e == 'n' ? '\n' : e == 't' ? '\t' : e;
        }
        if (o + 1 >= size) {
            out[0] = '\0';
            return -1;
        }
        out[o++] = c;
    }
    out[o] = '\0';
    return (int)o;
}
