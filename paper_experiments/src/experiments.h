/* experiments.h -- the paper's experiments (tools-internal).
 *
 * Each experiment writes its figures (PNG) and tables (CSV) into the
 * output directory and its section of docs/paper-experiments.md into the
 * Markdown stream, with the numbers it measured.  Functions return 0, or
 * -1 with a one-line message in ctx->msg.  No global state. */
#ifndef EX_EXPERIMENTS_H
#define EX_EXPERIMENTS_H

#include <stdio.h>

#include "support/image.h"
#include "lensprim.h"

#define EX_LENS_MAX 24
#define EX_DEPTH_MAX 8

/* A lens of a shipped scene, in its own frame. */
typedef struct ex_lens {
    char name[64];      /* "default", "polariscope #2", ... */
    lp_lens_desc desc;  /* position 0, axis +z */
    char glass[LP_GLASS_NAME_MAX];
} ex_lens;

typedef struct ex_ctx {
    const char *out_dir;    /* figures and tables */
    const char *fig_rel;    /* out_dir as the Markdown file links it */
    const char *renders;    /* directory of the renders (exp_images) */
    const char *scene_name; /* the scene those renders are of */
    int wavelengths;        /* spectral samples of those renders */
    FILE *md;
    ex_lens lens[EX_LENS_MAX];
    int n_lens;
    char msg[512];
} ex_ctx;

/* Colours of series, 0xRRGGBB sRGB. */
extern const unsigned ex_palette[12];

/* A lens from its shape and a catalog glass, in its own frame; NULL and
 * ctx->msg on error. */
lp_lens *ex_make_lens(ex_ctx *ctx, double r1, double r2, double t, double d, double d2,
                      const char *glass);

/* A white w x h picture to draw charts on; -1 and ctx->msg on error. */
int ex_canvas(ex_ctx *ctx, rs_image *img, int w, int h);

/* Write img as out_dir/name; -1 and ctx->msg on error. */
int ex_save_png(ex_ctx *ctx, const char *name, const rs_image *img);

/* Open out_dir/name for writing (a table); NULL and ctx->msg on error. */
FILE *ex_open(ex_ctx *ctx, const char *name);
/* Close a table; -1 and ctx->msg when writing failed. */
int ex_close(ex_ctx *ctx, FILE *f, const char *name);

/* The experiments. */
int ex_cone(ex_ctx *ctx);    /* the cone K: shipped lenses, figures */
int ex_shares(ex_ctx *ctx);  /* bundle shares by depth */
int ex_images(ex_ctx *ctx);  /* RGB vs spectral, Schlick vs G */

#endif
