/* cli.h -- what every command-line program of the project needs: its
 * one-line messages, a clock, output directories (support floor).
 *
 * For programs only: sp_say writes to stderr, which no library does. */
#ifndef SUPPORT_CLI_H
#define SUPPORT_CLI_H

#include <stddef.h>

/* One line "PROGRAM: MESSAGE\n" on stderr, MESSAGE formatted as printf
 * does.  Control characters in it (from user text or file names) become
 * '?', so the message stays one line. */
void sp_say(const char *program, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Format a one-line message into buf (printf's rules, cut to size - 1
 * characters) and return buf: what an argument parser hands back as its
 * error.  size must be >= 1. */
const char *sp_format(char *buf, size_t size, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* A whole string as a number: no white space before it, nothing after.
 * sp_parse_double: 1 and *out (which may be +-inf or NaN: the caller
 * decides), 0 when it is not a number, -1 when a finite literal is too
 * large (overflow).  sp_parse_long (base 10): 1 and *out, 0 when it is not
 * an integer, -1 when it is outside [lo, hi].  *out is untouched unless 1. */
int sp_parse_double(const char *s, double *out);
int sp_parse_long(const char *s, long lo, long hi, long *out);

/* --help: the n parts of the text on stdout, in order, flushed.  0, or -1
 * when stdout could not be written. */
int sp_print_text(const char *const *parts, size_t n);

/* --version: "PROGRAM (lensprim) VERSION" and a newline on stdout,
 * flushed.  0, or -1 when stdout could not be written. */
int sp_print_version(const char *program, const char *version);

/* Seconds on the monotonic clock (for elapsed times only). */
double sp_now_seconds(void);

/* Create the directory path and its missing parents (mode 0777 before the
 * umask).  0 when path is a directory afterwards; else -1 and a one-line
 * message naming the directory in msg. */
int sp_mkdir_p(const char *path, char *msg, size_t msg_size);

#endif
