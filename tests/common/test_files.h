/* test_files.h -- files and the clock as the tests use them.
 *
 *   double t0 = tf_now();
 *   size_t len;
 *   char *text = tf_read(path, &len);      (NULL: could not read)
 *   ... text[0..len), text[len] == '\0' ...
 *   free(text);
 *   if (tf_write(path, data, n) != 0) ... could not write ...
 *   printf("%.2f s\n", tf_now() - t0);
 *
 * Plain C11 + POSIX (clock_gettime), no other dependency; nothing here
 * prints or exits. */
#ifndef LP_TEST_FILES_H
#define LP_TEST_FILES_H

#include <stddef.h>

/* Seconds on the monotonic clock (CLOCK_MONOTONIC) from an unspecified
 * origin: only differences mean something. */
double tf_now(void);

/* All of the file at `path` (opened in binary mode, read to its end; any
 * kind of file that can be read, seekable or not) in a new malloc'd buffer
 * that the caller frees.  One byte past the data is '\0', so a text file
 * is a C string; that byte is not counted in *len.  A NUL inside the file
 * ends the C string early: *len counts every byte.  An empty file gives a
 * non-NULL "" with *len == 0.  Returns NULL when the file cannot be
 * opened or read, or memory runs out (errno says why); then *len is 0.
 * len may be NULL: the length is not reported. */
char *tf_read(const char *path, size_t *len);

/* Creates or truncates the file at `path` and writes the len bytes at
 * data into it (binary mode; data may be NULL when len is 0).  Returns 0
 * when every byte was written and the file closed without error, -1
 * otherwise (the file may then exist with part of the data). */
int tf_write(const char *path, const void *data, size_t len);

/* 1 when the file at `path` can be read and begins with the PNG
 * signature, else 0. */
int tf_is_png(const char *path);

#endif
