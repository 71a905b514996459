/* group_mpi.c -- the processes of a run over MPI (group.h). */
#define _POSIX_C_SOURCE 200809L
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "group_mpi.h"

static void mpi_message(int code, const char *what, char *msg, size_t msg_size)
{
    char text[MPI_MAX_ERROR_STRING];
    int len = 0;
    if (MPI_Error_string(code, text, &len) != MPI_SUCCESS)
        snprintf(text, sizeof text, "error %d", code);
    if (msg_size > 0)
        snprintf(msg, msg_size, "MPI: %s: %s", what, text);
}

int mw_group_start(int *argc, char ***argv, mw_group **out, char *msg, size_t msg_size)
{
    int provided = MPI_THREAD_SINGLE, rc;
    MPI_Comm local;
    mw_group *g;

    *out = NULL;
    rc = MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
    if (rc != MPI_SUCCESS) {
        mpi_message(rc, "MPI_Init_thread", msg, msg_size);
        return -1;
    }
    if (provided < MPI_THREAD_FUNNELED) {
        snprintf(msg, msg_size, "MPI: the library gives no MPI_THREAD_FUNNELED (threads "
                                "alongside MPI), which the render's threads need");
        MPI_Finalize();
        return -1;
    }
    g = calloc(1, sizeof *g);
    if (!g) {
        snprintf(msg, msg_size, "out of memory");
        MPI_Finalize();
        return -1;
    }
    /* Errors are returned, not fatal, so that they reach the user as one
     * message; a communicator of our own keeps our tags out of anyone
     * else's way. */
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    if ((rc = MPI_Comm_dup(MPI_COMM_WORLD, &g->comm)) != MPI_SUCCESS ||
        (rc = MPI_Comm_rank(g->comm, &g->rank)) != MPI_SUCCESS ||
        (rc = MPI_Comm_size(g->comm, &g->size)) != MPI_SUCCESS ||
        (rc = MPI_Comm_split_type(g->comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL,
                                  &local)) != MPI_SUCCESS) {
        mpi_message(rc, "setting up the communicator", msg, msg_size);
        free(g);
        MPI_Finalize();
        return -1;
    }
    MPI_Comm_set_errhandler(g->comm, MPI_ERRORS_RETURN);
    if (MPI_Comm_size(local, &g->local_size) != MPI_SUCCESS || g->local_size < 1)
        g->local_size = 1;
    MPI_Comm_free(&local);
    *out = g;
    return 0;
}

int mw_group_rank(const mw_group *g)
{
    return g->rank;
}

int mw_group_size(const mw_group *g)
{
    return g->size;
}

int mw_group_local_size(const mw_group *g)
{
    return g->local_size;
}

int mw_agree(mw_group *g, int status, int *who, char *msg, size_t msg_size)
{
    /* The lowest failing rank, then its status and message to rank 0. */
    int mine = status != 0 ? g->rank : g->size, first = g->size, rc;
    int pair[2] = {0, 0};

    if (who)
        *who = 0;
    rc = MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, g->comm);
    if (rc != MPI_SUCCESS) {
        mpi_message(rc, "MPI_Allreduce", msg, msg_size);
        return -1;
    }
    if (first == g->size)
        return 0;
    if (g->rank == first) {
        pair[0] = status;
        pair[1] = (int)(msg_size > 0 ? strnlen(msg, msg_size - 1) : 0);
    }
    rc = MPI_Bcast(pair, 2, MPI_INT, first, g->comm);
    if (rc == MPI_SUCCESS && first != 0) {
        if (g->rank == first)
            rc = MPI_Send(msg, pair[1], MPI_CHAR, 0, 0, g->comm);
        else if (g->rank == 0) {
            rc = MPI_Recv(msg, pair[1], MPI_CHAR, first, 0, g->comm, MPI_STATUS_IGNORE);
            if (rc == MPI_SUCCESS && msg_size > 0)
                msg[pair[1]] = '\0';
        }
    }
    if (rc != MPI_SUCCESS) {
        mpi_message(rc, "sharing a failure", msg, msg_size);
        return -1;
    }
    if (who)
        *who = first;
    return pair[0];
}

int mw_share(mw_group *g, void *data, size_t size, char *msg, size_t msg_size)
{
    /* In pieces of at most INT_MAX bytes (MPI counts are ints). */
    for (size_t done = 0; done < size;) {
        size_t n = size - done < (size_t)INT_MAX ? size - done : (size_t)INT_MAX;
        int rc = MPI_Bcast((char *)data + done, (int)n, MPI_BYTE, 0, g->comm);
        if (rc != MPI_SUCCESS) {
            mpi_message(rc, "MPI_Bcast", msg, msg_size);
            return -1;
        }
        done += n;
    }
    return 0;
}

void mw_group_end(mw_group *g)
{
    if (!g)
        return;
    MPI_Comm_free(&g->comm);
    free(g);
    MPI_Finalize();
}

/* ---- the MPI library under the sanitizers ------------------------------
 *
 * Open MPI keeps allocations until the process ends (and unloads the
 * components that made some): LeakSanitizer would report them as leaks of
 * every program that starts MPI.  In a sanitizer build these defaults of
 * the sanitizers' runtime suppress a leak whose allocation has a frame in
 * the MPI library or what it loads, and take allocation stacks with the
 * slow unwinder, which sees through those libraries' frames; the program's
 * own leaks are still reported (and the table of what was suppressed is
 * not printed).  ASAN_OPTIONS and LSAN_OPTIONS still override them. */
#if defined(__SANITIZE_ADDRESS__)
#define LPMPI_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define LPMPI_ASAN 1
#endif
#endif
#if defined(LPMPI_ASAN)
const char *__asan_default_options(void);
const char *__lsan_default_suppressions(void);
const char *__lsan_default_options(void);

const char *__asan_default_options(void)
{
    return "fast_unwind_on_malloc=0";
}

const char *__lsan_default_suppressions(void)
{
    return "leak:libmpi.so\n"
           "leak:libopen-pal.so\n"
           "leak:libopen-rte.so\n"
           "leak:libevent\n"
           "leak:libpmix\n"
           "leak:libhwloc\n"
           "leak:mca_\n";
}

const char *__lsan_default_options(void)
{
    return "print_suppressions=0"; /* no table of what was suppressed */
}
#endif
