/* subprocess.h -- running a built program from a test.
 *
 *   tp_result r;
 *   const char *args[] = {"--lens", spec, NULL};
 *   if (tp_run(LP_BIN_DIR "/lenstrace", args, NULL, &r) != 0)
 *       ... r.error says why nothing ran ...
 *   ... r.status, r.out, r.err, r.seconds ...
 *   tp_result_free(&r);
 *
 * The program runs with standard input from /dev/null and standard output
 * and error each captured whole in an anonymous temporary file (no pipe to
 * drain, no size limit), read back after it exits.  The caller waits:
 * tp_run returns when the program has ended.
 *
 * Exit status convention (the shell's): the program's exit status; 128 + N
 * when signal N ended it; 126 when the child could not be set up (standard
 * streams, resource limit); 127 when the program could not be executed.  A
 * program may itself exit 126 or 127.
 *
 * Needs LP_BIN_DIR (the directory of the built programs, where
 * measure_child is) when compiled; every test target defines it. */
#ifndef LP_TEST_SUBPROCESS_H
#define LP_TEST_SUBPROCESS_H

#include <stddef.h>

/* How to run the program.  All-zero (or a NULL pointer) is the default:
 * no limit, not measured. */
typedef struct tp_opts {
    /* > 0: RLIMIT_FSIZE of the program, in bytes, with SIGXFSZ ignored, so
     * that a write past it fails with EFBIG instead of killing the program.
     * The limit also applies to the captured stdout and stderr (they are
     * files): what the program writes there past fsize_limit bytes is
     * lost. */
    long fsize_limit;
    /* non-zero: run the program through LP_BIN_DIR/measure_child, which
     * reports the program's own peak resident size in peak_kb (see
     * tests/common/measure_child.c: a child forked from the test would
     * count the test's memory, which under valgrind or a sanitizer is the
     * tool's). */
    int measure_memory;
} tp_opts;

/* What a run gave. */
typedef struct tp_result {
    /* The exit status (see the convention above); -1 when tp_run failed,
     * and with measure_memory when measure_child reported nothing (it
     * could not run or could not report; its own message is in err). */
    int status;
    /* All of stdout / stderr, NUL-terminated, owned by the result (free
     * with tp_result_free).  Never NULL after success; NULL after failure.
     * A NUL the program wrote ends them as C strings early: the lengths
     * count every byte. */
    char *out, *err;
    size_t out_len, err_len;
    double seconds; /* wall time from start to exit */
    long peak_kb;   /* the program's peak RSS, KiB, with measure_memory; else -1 */
    char error[160]; /* why tp_run failed; empty after success */
} tp_result;

/* Runs `program` (a path; no PATH search) with argv[0] = program and
 * argv[1..] = args (NULL-terminated; NULL: no arguments), under `opts`
 * (NULL: the defaults), and waits for it.  Standard output and error of
 * the test are flushed first.  Returns 0 when the program was started and
 * waited for, whatever its status (r->status, out, err, seconds and
 * peak_kb filled); -1 when it could not be (no temporary file, fork or
 * wait failed, the output could not be read back): then r->status is -1,
 * r->out and r->err are NULL, and r->error says what failed, with
 * strerror(errno).  r must not be NULL; its previous contents are
 * overwritten, not freed. */
int tp_run(const char *program, const char *const args[], const tp_opts *opts, tp_result *r);

/* Frees r->out and r->err and sets them to NULL; r == NULL and a result
 * already freed (or of a failed run) are harmless. */
void tp_result_free(tp_result *r);

/* Writes a description of the command line into buf (size > 0; truncated
 * to fit, always NUL-terminated): the program's base name, then each
 * argument in single quotes, space-separated -- "lenstrace '--depth' '1'".
 * For messages. */
void tp_describe(const char *program, const char *const args[], char *buf, size_t size);

#endif
