/* lexer.h -- tokens of a .scene file (POV-Ray's lexical rules, subset).
 *
 * Whitespace and comments separate tokens: // to the end of the line, and
 * block comments, which nest as in POV-Ray ("/" "* a /" "* b *" "/ c *" "/"
 * is one comment).  A UTF-8 byte order mark at the start is skipped.
 * Lines and columns are 1-based; a column counts bytes (a tab is one).
 *
 *   NUMBER     digits [. digits] [e|E [+|-] digits], or . digits
 *              (1, 1., .5, 1e-3); always a double, never negative (the
 *              sign is an operator); out-of-range literals are errors
 *   IDENT      [A-Za-z_][A-Za-z0-9_]*  (case-sensitive)
 *   STRING     "..." on one line; \" \\ \n \t escapes; text/len are the
 *              raw bytes between the quotes (decode with rs_string_decode)
 *   DIRECTIVE  # followed by a name, spaces and tabs between allowed
 *              (#declare, #   debug, ...); text/len are the name alone
 *   PUNCT      one of  < > { } ( ) [ ] , ; = + - * / . ? : ! & |
 *
 * The lexer works on a caller-owned buffer of known length (embedded NUL
 * bytes are errors), keeps no global state and allocates nothing; token
 * text points into that buffer.
 */
#ifndef RS_LEXER_H
#define RS_LEXER_H

#include <stddef.h>

typedef enum rs_tok_kind {
    RS_TOK_EOF = 0,
    RS_TOK_NUMBER,
    RS_TOK_IDENT,
    RS_TOK_STRING,
    RS_TOK_DIRECTIVE,
    RS_TOK_PUNCT,
    RS_TOK_ERROR   /* a lexical error; the message is in the lexer */
} rs_tok_kind;

typedef struct rs_token {
    rs_tok_kind kind;
    int line, column;   /* of the first byte (ERROR: of the problem) */
    double number;      /* NUMBER */
    char punct;         /* PUNCT */
    const char *text;   /* IDENT, STRING, DIRECTIVE: into the source */
    size_t len;
} rs_token;

typedef struct rs_lexer {
    const char *src;
    size_t len;
    size_t pos;
    int line, column;
    int failed;         /* after an ERROR every call returns it again */
    rs_token error_tok;
    char error[160];    /* the ERROR message, without location */
} rs_lexer;

/* Start reading src[0..len). */
void rs_lexer_init(rs_lexer *lx, const char *src, size_t len);

/* The next token into *tok.  At the end, EOF again and again; after an
 * error, the same ERROR again and again (lx->error holds the message:
 * "unterminated comment" at the opening "/" "*", "unterminated string" at
 * the opening quote, "bad number '1e+'", "number '1e999' is out of range",
 * "unexpected character '$'"). */
void rs_lexer_next(rs_lexer *lx, rs_token *tok);

/* What a token is, for "expected X, found Y" messages: "identifier 'foo'",
 * "number 2.5", "'{'", "string \"N-BK7\"", "directive '#include'",
 * "end of file".  Always NUL-terminates buf (size > 0). */
void rs_token_describe(const rs_token *tok, char *buf, size_t size);

/* Decode a STRING token's escapes into out (NUL-terminated).  Returns the
 * decoded length, or -1 when it does not fit in size bytes with the NUL. */
int rs_string_decode(const rs_token *tok, char *out, size_t size);

#endif
