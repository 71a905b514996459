/* sa_point.h -- one measured render setting, and the table of them
 * (speed_accuracy).
 *
 * The CSV has one header line and one line per point, columns:
 *   scene,kind,model,wavelengths,depth,cutoff,tolerance,seconds,runs,
 *   rmse,max_abs,share_visible,note
 * kind: reference | povray | auto | sweep | default.  wavelengths, depth:
 * 0 = the renderer's default (the scene's depth; 16 wavelengths) or not
 * applicable; cutoff: -1 = the scene's adc_bailout; tolerance: auto's E,
 * else 0; seconds: the median CPU time of `runs` runs, on one thread;
 * note: free text without commas or quotes (auto's choice, the
 * reference's convergence).  Numbers are written with %.6g or exactly. */
#ifndef SA_POINT_H
#define SA_POINT_H

#include <stddef.h>
#include <stdio.h>

#include "sa_error.h"

typedef struct sa_point {
    char scene[64];
    char kind[16];
    char model[16];
    int wavelengths, depth;
    double cutoff, tolerance;
    double seconds;
    int runs;
    sa_error err;
    char note[512];
} sa_point;

/* A point of the given kind and setting, nothing measured yet. */
void sa_point_init(sa_point *p, const char *kind, const char *model, int wavelengths,
                   int depth, double cutoff);

typedef struct sa_points {
    sa_point *p;
    size_t n, cap;
} sa_points;

void sa_points_init(sa_points *ps);
void sa_points_free(sa_points *ps);
/* Append a copy; 0, or -1 out of memory. */
int sa_points_add(sa_points *ps, const sa_point *p);

int sa_point_write_csv_header(FILE *f);
int sa_point_write_csv(FILE *f, const sa_point *p);
/* Read a whole CSV written by the functions above (appending to ps).
 * Returns 0, or -1 with a message naming the line. */
int sa_points_read_csv(const char *path, sa_points *ps, char *msg, size_t msg_size);

#endif
