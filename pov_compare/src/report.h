/* report.h -- the results of one comparison as report.json (for
 * machines) and report.md (for people) (pov_compare).
 *
 * report.json follows the contract of docs interfaces.md ("pov_compare"):
 *
 *   {"scene":"default.scene","width":320,"height":240,"depth":8,
 *    "geometry":{"iou":0.9995,"max_boundary_px":1.0, ...},
 *    "modes":{"fresnel":  {"vs_povray":{"rmse":..,"psnr":..,"ssim":..},
 *                          "vs_polarized":{...}},
 *             "schlick":  {"vs_povray":{...},"vs_polarized":{...}},
 *             "polarized":{"vs_povray":{...}},
 *             "rgb":      {"vs_povray":{...},"vs_polarized":{...}}},
 *    "seconds":{"povray":..,"fresnel":..,"schlick":..,"polarized":..,"rgb":..},
 *    "notes":["..."], ...}
 *
 * plus keys of its own (povray_version, diff_scale, worst pixels, file
 * names).  JSON has no infinity: a PSNR of identical images, and any
 * value that is not finite, is written as null (report.md says so).
 * Both files are written to "<path>.tmp" and renamed into place. */
#ifndef PC_REPORT_H
#define PC_REPORT_H

#include <stddef.h>
#include <stdio.h>

#include "compare.h"
#include "lensrender/lensrender.h"
#include "translate.h"

#define PC_N_MODES 4

/* One of our light models against POV-Ray (and against polarized). */
typedef struct pc_mode_result {
    lr_mode mode;
    pc_metrics vs_povray;
    pc_metrics vs_polarized;   /* not for the polarized mode itself */
    int has_vs_polarized;
    double seconds;            /* wall clock of the render */
    pc_worst_pixel worst;      /* largest luminance difference to POV-Ray */
} pc_mode_result;

typedef struct pc_report {
    const char *scene;         /* the scene file's name, e.g. "default.scene" */
    int width, height, depth;
    int wavelengths;           /* of our spectral modes */
    pc_geometry geometry;      /* our silhouette (a) against POV-Ray's (b) */
    pc_mode_result modes[PC_N_MODES]; /* fresnel, schlick, polarized, rgb */
    double povray_seconds;     /* the scene render */
    double povray_mask_seconds;/* the silhouette render */
    char povray_version[64];
    double diff_scale;         /* top of the difference map's ramp */
    double diff_max;           /* largest |dY|, fresnel against POV-Ray */
    const pc_notes *notes;
} pc_report;

/* The order of modes in reports: fresnel, schlick, polarized, rgb. */
lr_mode pc_report_mode(int k);
const char *pc_mode_label(lr_mode mode); /* "fresnel", ... */

/* The result of mode in r, or NULL. */
const pc_mode_result *pc_report_find(const pc_report *r, lr_mode mode);

/* Write report.json / report.md.  Return 0, or -1 with a message. */
int pc_report_write_json(const pc_report *r, const char *path, char *msg, size_t msg_size);
int pc_report_write_md(const pc_report *r, const char *path, char *msg, size_t msg_size);

/* Write a JSON string literal (quotes and escapes included) to f. */
void pc_json_string(FILE *f, const char *s);

/* A number for JSON: %.6g, or null when not finite. */
void pc_json_number(FILE *f, double v);

#endif
