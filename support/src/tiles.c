/* tiles.c -- the tile thread pool (see tiles.h). */
#define _POSIX_C_SOURCE 200809L

#include "support/tiles.h"

#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define RS_TILES_MAX_THREADS 1024
#define RS_PROGRESS_BAR 30            /* characters in the bar */
#define RS_PROGRESS_PERIOD_NS 100000000L /* 0.1 s between updates */

typedef struct rs_pool {
    int width, height, tile;
    int tiles_x, n_tiles;
    void *(*worker_create)(void *user);
    void (*worker_destroy)(void *worker);
    rs_tile_fn fn;
    void *user;

    atomic_int next_tile;      /* the next tile number to hand out */
    atomic_llong pixels_done;  /* for progress */
    atomic_int failed;         /* a worker could not be created */
    atomic_int cancelled;      /* the progress callback said stop */
    rs_progress_fn progress;   /* called by the calling thread only */
    void *progress_user;
    int inline_progress;       /* no thread: run_tiles reports per tile */

    pthread_mutex_t lock;      /* guards running */
    pthread_cond_t ended;      /* signalled when a thread ends */
    int running;               /* threads not yet ended */
} rs_pool;

int rs_online_processors(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    if (n < 1)
        return 1;
    if (n > RS_TILES_MAX_THREADS)
        return RS_TILES_MAX_THREADS;
    return (int)n;
}

/* Take tiles until there are none left (or the render failed). */
static void run_tiles(rs_pool *p)
{
    void *worker = NULL;
    if (p->worker_create) {
        worker = p->worker_create(p->user);
        if (!worker) {
            atomic_store(&p->failed, 1);
            return;
        }
    }
    for (;;) {
        int t, tx, ty, x0, y0, x1, y1;
        if (atomic_load_explicit(&p->failed, memory_order_relaxed) ||
            atomic_load_explicit(&p->cancelled, memory_order_relaxed))
            break;
        t = atomic_fetch_add(&p->next_tile, 1);
        if (t >= p->n_tiles)
            break;
        tx = t % p->tiles_x;
        ty = t / p->tiles_x;
        x0 = tx * p->tile;
        y0 = ty * p->tile;
        x1 = p->width - x0 > p->tile ? x0 + p->tile : p->width;
        y1 = p->height - y0 > p->tile ? y0 + p->tile : p->height;
        p->fn(p->user, worker, x0, y0, x1, y1);
        atomic_fetch_add_explicit(&p->pixels_done,
                                  (long long)(x1 - x0) * (y1 - y0),
                                  memory_order_relaxed);
        if (p->inline_progress && p->progress &&
            p->progress(p->progress_user, atomic_load(&p->pixels_done),
                        (long long)p->width * p->height) != 0)
            atomic_store(&p->cancelled, 1);
    }
    if (worker && p->worker_destroy)
        p->worker_destroy(worker);
}

static void *thread_main(void *arg)
{
    rs_pool *p = arg;
    run_tiles(p);
    pthread_mutex_lock(&p->lock);
    p->running--;
    pthread_cond_signal(&p->ended);
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

/* ---- progress line ---------------------------------------------------- */


static double seconds_since(const struct timespec *t0)
{
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (double)(now.tv_sec - t0->tv_sec) +
           1e-9 * (double)(now.tv_nsec - t0->tv_nsec);
}

static void write_all(int fd, const char *s, size_t n)
{
    while (n > 0) {
        ssize_t w = write(fd, s, n);
        if (w < 0) {
            if (errno == EINTR)
                continue;
            return; /* progress is best effort */
        }
        s += w;
        n -= (size_t)w;
    }
}

void rs_progress_line_show(rs_progress_line *pr, long long done, long long total,
                          int final)
{
    char line[160];
    char bar[RS_PROGRESS_BAR + 1];
    double frac = total > 0 ? (double)done / (double)total : 1.0;
    double elapsed = seconds_since(&pr->start);
    int filled, pct, n;
    size_t len;

    if (pr->fd < 0)
        return;
    if (frac > 1.0)
        frac = 1.0;
    filled = (int)(frac * RS_PROGRESS_BAR);
    for (int k = 0; k < RS_PROGRESS_BAR; k++)
        bar[k] = k < filled ? '#' : '.';
    bar[RS_PROGRESS_BAR] = '\0';
    pct = (int)(frac * 100.0);
    if (done > 0) {
        double left = elapsed * (double)(total - done) / (double)done;
        n = snprintf(line, sizeof line, "\r[%s] %3d%%  %.1f s elapsed, %.1f s left",
                     bar, pct, elapsed, left);
    } else {
        n = snprintf(line, sizeof line, "\r[%s] %3d%%  %.1f s elapsed",
                     bar, pct, elapsed);
    }
    if (n < 0)
        return;
    len = (size_t)n < sizeof line ? (size_t)n : sizeof line - 1;
    /* blank what is left of a longer previous line */
    while (len < pr->last_len && len + 1 < sizeof line)
        line[len++] = ' ';
    line[len] = '\0';
    pr->last_len = len;
    if (final && len + 1 < sizeof line)
        line[len++] = '\n';
    write_all(pr->fd, line, len);
}

/* ---- the pool --------------------------------------------------------- */

void rs_progress_line_start(rs_progress_line *pr, int fd)
{
    pr->fd = (fd >= 0 && isatty(fd)) ? fd : -1;
    pr->last_len = 0;
    clock_gettime(CLOCK_MONOTONIC, &pr->start);
}

/* The callback rs_render_tiles gives rs_render_tiles_cb: the line. */
static int line_progress(void *user, long long done, long long total)
{
    rs_progress_line *pr = user;
    rs_progress_line_show(pr, done, total, done >= total);
    return 0;
}

int rs_render_tiles(int width, int height, int tile_size, int threads,
                    void *(*worker_create)(void *user),
                    void (*worker_destroy)(void *worker), rs_tile_fn fn,
                    void *user, int progress_fd)
{
    rs_progress_line pr;
    int rc;
    rs_progress_line_start(&pr, progress_fd);
    rc = rs_render_tiles_cb(width, height, tile_size, threads, worker_create,
                            worker_destroy, fn, user,
                            pr.fd >= 0 ? line_progress : NULL, &pr);
    if (rc != 0 && pr.last_len > 0)
        write_all(pr.fd, "\n", 1); /* end the line the render left open */
    return rc == -2 ? -1 : rc;
}

int rs_render_tiles_cb(int width, int height, int tile_size, int threads,
                       void *(*worker_create)(void *user),
                       void (*worker_destroy)(void *worker), rs_tile_fn fn,
                       void *user, rs_progress_fn progress, void *progress_user)
{
    rs_pool p;
    pthread_t *ids;
    pthread_condattr_t cattr;
    int tiles_y, started = 0;
    long long total;

    if (width < 1 || height < 1 || tile_size < 1 || !fn)
        return -1;

    memset(&p, 0, sizeof p);
    p.width = width;
    p.height = height;
    p.tile = tile_size;
    p.tiles_x = (width - 1) / tile_size + 1;
    tiles_y = (height - 1) / tile_size + 1;
    if ((long long)p.tiles_x * tiles_y > 0x7fffffffLL - RS_TILES_MAX_THREADS)
        return -1;
    p.n_tiles = p.tiles_x * tiles_y;
    p.worker_create = worker_create;
    p.worker_destroy = worker_destroy;
    p.fn = fn;
    p.user = user;
    atomic_init(&p.next_tile, 0);
    atomic_init(&p.pixels_done, 0);
    atomic_init(&p.failed, 0);
    atomic_init(&p.cancelled, 0);
    p.progress = progress;
    p.progress_user = progress_user;
    total = (long long)width * height;

    if (threads <= 0)
        threads = rs_online_processors();
    if (threads > RS_TILES_MAX_THREADS)
        threads = RS_TILES_MAX_THREADS;
    if (threads > p.n_tiles)
        threads = p.n_tiles;


    if (pthread_mutex_init(&p.lock, NULL) != 0)
        return -1;
    if (pthread_condattr_init(&cattr) != 0) {
        pthread_mutex_destroy(&p.lock);
        return -1;
    }
    pthread_condattr_setclock(&cattr, CLOCK_MONOTONIC);
    if (pthread_cond_init(&p.ended, &cattr) != 0) {
        pthread_condattr_destroy(&cattr);
        pthread_mutex_destroy(&p.lock);
        return -1;
    }
    pthread_condattr_destroy(&cattr);

    ids = malloc((size_t)threads * sizeof *ids);
    if (ids) {
        pthread_mutex_lock(&p.lock);
        for (int k = 0; k < threads; k++) {
            p.running++;
            if (pthread_create(&ids[started], NULL, thread_main, &p) != 0) {
                p.running--;
                break;
            }
            started++;
        }
        pthread_mutex_unlock(&p.lock);
    }

    if (started == 0) {
        /* No thread at all: do the work here. */
        p.inline_progress = 1;
        run_tiles(&p);
    } else {
        if (progress && progress(progress_user, 0, total) != 0)
            atomic_store(&p.cancelled, 1);
        pthread_mutex_lock(&p.lock);
        while (p.running > 0) {
            struct timespec until;
            clock_gettime(CLOCK_MONOTONIC, &until);
            until.tv_nsec += RS_PROGRESS_PERIOD_NS;
            if (until.tv_nsec >= 1000000000L) {
                until.tv_nsec -= 1000000000L;
                until.tv_sec++;
            }
            while (p.running > 0 &&
                   pthread_cond_timedwait(&p.ended, &p.lock, &until) == 0)
                ;
            if (p.running > 0) {
                pthread_mutex_unlock(&p.lock);
                if (progress && !atomic_load(&p.cancelled) &&
                    progress(progress_user, atomic_load(&p.pixels_done), total) != 0)
                    atomic_store(&p.cancelled, 1);
                pthread_mutex_lock(&p.lock);
            }
        }
        pthread_mutex_unlock(&p.lock);
        for (int k = 0; k < started; k++)
            pthread_join(ids[k], NULL);
    }
    free(ids);
    if (progress && !p.inline_progress && !atomic_load(&p.cancelled) &&
        !atomic_load(&p.failed))
        (void)progress(progress_user, atomic_load(&p.pixels_done), total);

    pthread_cond_destroy(&p.ended);
    pthread_mutex_destroy(&p.lock);
    if (atomic_load(&p.failed))
        return -1;
    return atomic_load(&p.cancelled) ? -2 : 0;
}
