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

/* The number of online processors (at least 1). */
int rs_online_processors(void);

#endif
