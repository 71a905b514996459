/* group_mpi.h -- what a group is over MPI (private to mpi/src). */
#ifndef LPMPI_GROUP_MPI_H
#define LPMPI_GROUP_MPI_H

#include <mpi.h>

#include "lpmpi/group.h"

struct mw_group {
    MPI_Comm comm;  /* a duplicate of MPI_COMM_WORLD, ours alone */
    int rank, size, local_size;
};

#endif
