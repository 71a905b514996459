/* test_tiles.c -- the tile thread pool: every pixel rendered exactly once,
 * for several thread counts and image sizes that tiles do not divide;
 * one worker per thread, made on that thread and used only there; tiles
 * handed out in row-major order; errors reported. */
#define _POSIX_C_SOURCE 200809L

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "support/tiles.h"

typedef struct run_state {
    int width, height, tile;
    atomic_int *visits;        /* per pixel */
    atomic_int created, destroyed;
    atomic_int tiles_seen;
    atomic_int bad_worker;     /* a tile ran on a worker of another thread */
    atomic_int bad_rect;       /* a tile outside the image, or empty */
    int fail_create;           /* worker_create returns NULL */
    /* single-thread order check */
    int order_ok;
    int next_x0, next_y0;
    int check_order;
} run_state;

typedef struct worker {
    run_state *st;
    pthread_t owner;
    int tiles;
    int magic;
} worker;

#define WORKER_MAGIC 0x51ee7

static void *make_worker(void *user)
{
    run_state *st = user;
    worker *w;
    if (st->fail_create)
        return NULL;
    w = malloc(sizeof *w);
    if (!w)
        return NULL;
    w->st = st;
    w->owner = pthread_self();
    w->tiles = 0;
    w->magic = WORKER_MAGIC;
    atomic_fetch_add(&st->created, 1);
    return w;
}

static void free_worker(void *p)
{
    worker *w = p;
    if (w->magic != WORKER_MAGIC || !pthread_equal(w->owner, pthread_self()))
        atomic_fetch_add(&w->st->bad_worker, 1);
    atomic_fetch_add(&w->st->destroyed, 1);
    w->magic = 0;
    free(w);
}

static void tile_fn(void *user, void *wp, int x0, int y0, int x1, int y1)
{
    run_state *st = user;
    worker *w = wp;
    if (!w || w->magic != WORKER_MAGIC || !pthread_equal(w->owner, pthread_self()))
        atomic_fetch_add(&st->bad_worker, 1);
    else
        w->tiles++;
    if (x0 < 0 || y0 < 0 || x1 > st->width || y1 > st->height || x0 >= x1 ||
        y0 >= y1 || x1 - x0 > st->tile || y1 - y0 > st->tile) {
        atomic_fetch_add(&st->bad_rect, 1);
        return;
    }
    if (st->check_order) {
        if (x0 != st->next_x0 || y0 != st->next_y0)
            st->order_ok = 0;
        st->next_x0 = x1 < st->width ? x1 : 0;
        st->next_y0 = x1 < st->width ? y0 : y1;
    }
    atomic_fetch_add(&st->tiles_seen, 1);
    for (int j = y0; j < y1; j++)
        for (int i = x0; i < x1; i++)
            atomic_fetch_add(&st->visits[(size_t)j * st->width + i], 1);
}

static void plain_tile_fn(void *user, void *wp, int x0, int y0, int x1, int y1)
{
    run_state *st = user;
    (void)wp;
    for (int j = y0; j < y1; j++)
        for (int i = x0; i < x1; i++)
            atomic_fetch_add(&st->visits[(size_t)j * st->width + i], 1);
}

static void init_state(run_state *st, int w, int h, int tile)
{
    memset(st, 0, sizeof *st);
    st->width = w;
    st->height = h;
    st->tile = tile;
    st->visits = calloc((size_t)w * h, sizeof *st->visits);
    for (size_t k = 0; k < (size_t)w * h; k++)
        atomic_init(&st->visits[k], 0);
    atomic_init(&st->created, 0);
    atomic_init(&st->destroyed, 0);
    atomic_init(&st->tiles_seen, 0);
    atomic_init(&st->bad_worker, 0);
    atomic_init(&st->bad_rect, 0);
    st->order_ok = 1;
}

static void one_case(int w, int h, int tile, int threads)
{
    run_state st;
    int rc, once = 0, tiles_x = (w + tile - 1) / tile, tiles_y = (h + tile - 1) / tile;
    int n_tiles = tiles_x * tiles_y;
    init_state(&st, w, h, tile);
    st.check_order = threads == 1;
    rc = rs_render_tiles(w, h, tile, threads, make_worker, free_worker, tile_fn,
                         &st, -1);
    CHECK(rc == 0, "%dx%d tile %d threads %d: returned %d", w, h, tile, threads, rc);
    for (size_t k = 0; k < (size_t)w * h; k++)
        once += atomic_load(&st.visits[k]) == 1;
    CHECK(once == w * h, "%dx%d tile %d threads %d: %d of %d pixels visited exactly once",
          w, h, tile, threads, once, w * h);
    CHECK(atomic_load(&st.tiles_seen) == n_tiles,
          "%dx%d tile %d threads %d: %d tiles rendered, want %d", w, h, tile, threads,
          atomic_load(&st.tiles_seen), n_tiles);
    CHECK(atomic_load(&st.bad_rect) == 0, "%dx%d tile %d threads %d: %d bad tiles",
          w, h, tile, threads, atomic_load(&st.bad_rect));
    CHECK(atomic_load(&st.bad_worker) == 0,
          "%dx%d tile %d threads %d: %d tiles ran on another thread's worker",
          w, h, tile, threads, atomic_load(&st.bad_worker));
    {
        int c = atomic_load(&st.created), d = atomic_load(&st.destroyed);
        int max_threads = threads > 0 ? threads : 1024;
        if (max_threads > n_tiles)
            max_threads = n_tiles;
        CHECK(c >= 1 && c <= max_threads,
              "%dx%d tile %d threads %d: %d workers created (1..%d expected)",
              w, h, tile, threads, c, max_threads);
        if (threads > 0 && threads <= n_tiles)
            CHECK(c == threads, "%dx%d tile %d threads %d: %d workers created, one per thread",
                  w, h, tile, threads, c);
        CHECK(c == d, "%dx%d tile %d threads %d: %d workers created, %d destroyed",
              w, h, tile, threads, c, d);
    }
    if (threads == 1)
        CHECK(st.order_ok, "%dx%d tile %d: one thread renders tiles row by row", w, h, tile);
    free(st.visits);
}

int main(void)
{
    static const int sizes[][3] = {
        { 37, 23, 16 }, { 16, 16, 16 }, { 1, 1, 16 }, { 1, 100, 16 },
        { 100, 1, 16 }, { 33, 17, 1 }, { 64, 48, 16 }, { 5, 7, 64 },
        { 129, 65, 8 }, { 17, 33, 16 },
    };
    static const int thread_counts[] = { 1, 2, 3, 4, 7, 0 };

    for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++)
        for (size_t t = 0; t < sizeof thread_counts / sizeof *thread_counts; t++)
            one_case(sizes[s][0], sizes[s][1], sizes[s][2], thread_counts[t]);

    /* Repeat the small odd case many times to shake out races. */
    for (int r = 0; r < 50; r++)
        one_case(37, 23, 16, 3);

    /* No worker callbacks at all. */
    {
        run_state st;
        int once = 0;
        init_state(&st, 37, 23, 16);
        CHECK(rs_render_tiles(37, 23, 16, 3, NULL, NULL, plain_tile_fn, &st, -1) == 0,
              "no worker callbacks: render succeeds");
        for (size_t k = 0; k < 37 * 23; k++)
            once += atomic_load(&st.visits[k]) == 1;
        CHECK(once == 37 * 23, "no worker callbacks: every pixel once (%d)", once);
        free(st.visits);
    }

    /* A worker that cannot be made fails the render. */
    for (int threads = 1; threads <= 3; threads++) {
        run_state st;
        init_state(&st, 37, 23, 16);
        st.fail_create = 1;
        CHECK(rs_render_tiles(37, 23, 16, threads, make_worker, free_worker, tile_fn,
                              &st, -1) == -1,
              "threads %d: failing worker_create -> -1", threads);
        CHECK(atomic_load(&st.tiles_seen) == 0, "threads %d: no tile without a worker",
              threads);
        free(st.visits);
    }

    /* Bad arguments. */
    {
        run_state st;
        init_state(&st, 4, 4, 2);
        CHECK(rs_render_tiles(0, 4, 2, 1, NULL, NULL, plain_tile_fn, &st, -1) == -1,
              "width 0 -> -1");
        CHECK(rs_render_tiles(4, -1, 2, 1, NULL, NULL, plain_tile_fn, &st, -1) == -1,
              "height -1 -> -1");
        CHECK(rs_render_tiles(4, 4, 0, 1, NULL, NULL, plain_tile_fn, &st, -1) == -1,
              "tile 0 -> -1");
        CHECK(rs_render_tiles(4, 4, 2, 1, NULL, NULL, NULL, &st, -1) == -1,
              "no tile function -> -1");
        free(st.visits);
    }

    /* A progress fd that is not a terminal writes nothing (and works). */
    {
        run_state st;
        int fds[2];
        init_state(&st, 20, 20, 4);
        if (pipe(fds) == 0) {
            char buf[16];
            ssize_t n;
            CHECK(rs_render_tiles(20, 20, 4, 2, NULL, NULL, plain_tile_fn, &st, fds[1]) == 0,
                  "progress to a pipe: render succeeds");
            close(fds[1]);
            n = read(fds[0], buf, sizeof buf);
            CHECK(n == 0, "progress to a pipe (not a terminal): nothing written (%d bytes)",
                  (int)n);
            close(fds[0]);
        }
        free(st.visits);
    }

    CHECK(rs_online_processors() >= 1, "online processors >= 1");
    return check_finish("test_tiles");
}
