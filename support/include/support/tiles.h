/* tiles.h -- render an image in square tiles on a small thread pool
 * (support floor: the thread pool of every program).
 *
 * The image is cut into tiles of tile_size x tile_size pixels (smaller at
 * the right and bottom edges), numbered row by row from the top-left.
 * Threads take the next tile number from one atomic counter, so tiles are
 * started in that fixed order; which thread renders which tile varies from
 * run to run, so fn must make each pixel's value depend on the pixel
 * alone (never on the worker's history) for the image to be the same for
 * any number of threads.  Every pixel lies in exactly one tile and each
 * tile is passed to fn exactly once (unless a worker could not be made).
 *
 * Progress: when progress_fd >= 0 and refers to a terminal, the calling
 * thread writes one updating line
 *     [##########..........]  42%  12.3 s elapsed, 17.0 s left
 * with a leading carriage return, at most about 10 times a second, and
 * ends it with a newline when the render ends.  Otherwise nothing is
 * written.  Nothing else here prints.
 */
#ifndef RS_TILES_H
#define RS_TILES_H

#include <stddef.h>
#include <time.h>

/* Render the pixels x0 <= i < x1, y0 <= j < y1 (column i from the left,
 * row j from the top) with the calling thread's worker. */
typedef void (*rs_tile_fn)(void *user, void *worker, int x0, int y0, int x1,
                           int y1);

/* Render a width x height image (both >= 1) in tiles of tile_size
 * (>= 1; tiles larger than the image are clipped) on `threads` threads
 * (<= 0: the number of online processors; never more threads than
 * tiles).  Each thread calls worker_create(user) once before its first
 * tile and worker_destroy(worker) once after its last; worker_create may
 * be NULL (the worker passed to fn is then NULL) and so may
 * worker_destroy.  A worker_create that returns NULL stops the render.
 *
 * When no thread can be started at all, the calling thread renders every
 * tile itself (without progress updates).
 *
 * Returns 0 when every tile was rendered; -1 on a bad argument (a size or
 * tile_size < 1, fn NULL) or when a worker could not be created (the
 * other threads then stop after their current tile). */
int rs_render_tiles(int width, int height, int tile_size, int threads,
                    void *(*worker_create)(void *user),
                    void (*worker_destroy)(void *worker), rs_tile_fn fn,
                    void *user, int progress_fd);

/* What rs_render_tiles_cb calls on the calling thread, about 10 times a
 * second and once at the end: done pixels of total so far.  A nonzero
 * return cancels the render: no tile is started after it (tiles being
 * rendered are finished). */
typedef int (*rs_progress_fn)(void *user, long long done, long long total);

/* rs_render_tiles with a progress callback instead of a terminal line
 * (progress may be NULL).  The callback is only ever called from the
 * calling thread (also when no thread could be started: then after each
 * tile), never concurrently.  Returns 0 when every tile was rendered, -2
 * when the callback cancelled, -1 as rs_render_tiles. */
int rs_render_tiles_cb(int width, int height, int tile_size, int threads,
                       void *(*worker_create)(void *user),
                       void (*worker_destroy)(void *worker), rs_tile_fn fn,
                       void *user, rs_progress_fn progress, void *progress_user);

/* The updating progress line described above, for a driver that gets its
 * progress from a callback.  rs_progress_line_start: fd >= 0 and a
 * terminal, else nothing is ever written; the clock starts.
 * rs_progress_line_show: the line for done of total; final ends it with a
 * newline. */
typedef struct rs_progress_line {
    int fd;                 /* -1: no output */
    struct timespec start;
    size_t last_len;        /* length of the previous line, to blank it */
} rs_progress_line;

void rs_progress_line_start(rs_progress_line *pr, int fd);
void rs_progress_line_show(rs_progress_line *pr, long long done, long long total, int final);

/* The number of online processors (at least 1). */
int rs_online_processors(void);

#endif
