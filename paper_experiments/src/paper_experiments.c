/* paper_experiments.c -- the four experiments of the paper's section 5.
 *
 * Reads the lenses of the shipped scenes, runs the cone K, the shares by
 * depth and the render comparisons (experiments.h), and writes
 * docs/paper-experiments.md with its figures and tables.  The renders
 * themselves are made by lensrender (scripts/paper_experiments.sh runs
 * both: one command for the whole page). */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "experiments.h"
#include "plot.h"
#include "lensrender/lensrender.h"

#define EXIT_USAGE 2

static const char usage_text[] =
"usage: paper_experiments --renders DIR [--scene-name NAME] [--wavelengths N]\n"
"                         [--scenes DIR] [--out DIR] [--md FILE]\n"
"       paper_experiments --help\n"
"\n"
"The experiments of section 5 of Debelov & Kushner's lens paper:\n"
"  1. the cone K of rim-free initial directions of every lens of the\n"
"     scenes in --scenes (default scenes), against the tree depth dT;\n"
"  2. backward tracing with initial rays inside K: the share of the\n"
"     outgoing intensity per depth (biconvex, meniscus, flat plate in\n"
"     N-BK7 and N-SF11);\n"
"  3./4. RGB against spectral and Schlick against Fresnel through G, from\n"
"     the renders rgb.pfm, fresnel.pfm, polarized.pfm and schlick.pfm in\n"
"     --renders (made by lensrender --pfm; scripts/paper_experiments.sh),\n"
"     a render of --scene-name with --wavelengths spectral samples.\n"
"Writes the figures and tables into --out (default docs/paper-experiments)\n"
"and the page --md (default docs/paper-experiments.md).\n";

const unsigned ex_palette[12] = {0x1f77b4u, 0xd62728u, 0x2ca02cu, 0xff7f0eu,
                                 0x9467bdu, 0x8c564bu, 0xe377c2u, 0x7f7f7fu,
                                 0xbcbd22u, 0x17becfu, 0x393b79u, 0xad494au};

lp_lens *ex_make_lens(ex_ctx *ctx, double r1, double r2, double t, double d, double d2,
                      const char *glass)
{
    lp_lens_desc desc;
    lp_lens *lens = NULL;
    lp_error err;
    lp_lens_desc_init(&desc);
    desc.radius1 = r1;
    desc.radius2 = r2;
    desc.thickness = t;
    desc.diameter = d;
    desc.diameter2 = d2;
    if (lp_glass_builtin(glass, &desc.glass, &err) != LP_OK ||
        lp_lens_create(&desc, &lens, &err) != LP_OK) {
        snprintf(ctx->msg, sizeof ctx->msg, "lens R1=%g R2=%g t=%g D=%g %s: %s", r1, r2, t, d,
                 glass, err.message);
        return NULL;
    }
    return lens;
}

static int out_path(ex_ctx *ctx, const char *name, char *path, size_t size)
{
    if (snprintf(path, size, "%s/%s", ctx->out_dir, name) >= (int)size) {
        snprintf(ctx->msg, sizeof ctx->msg, "output path too long: %s/%s", ctx->out_dir, name);
        return -1;
    }
    return 0;
}

int ex_canvas(ex_ctx *ctx, rs_image *img, int w, int h)
{
    if (rs_image_create(img, w, h) != 0) {
        snprintf(ctx->msg, sizeof ctx->msg, "out of memory for a %d x %d picture", w, h);
        return -1;
    }
    pl_fill(img, 0xFFFFFFu);
    return 0;
}

int ex_save_png(ex_ctx *ctx, const char *name, const rs_image *img)
{
    char path[4096], msg[256];
    if (out_path(ctx, name, path, sizeof path))
        return -1;
    if (rs_png_write(path, img, msg, sizeof msg) != 0) {
        snprintf(ctx->msg, sizeof ctx->msg, "%s", msg);
        return -1;
    }
    return 0;
}

FILE *ex_open(ex_ctx *ctx, const char *name)
{
    char path[4096];
    if (out_path(ctx, name, path, sizeof path))
        return NULL;
    FILE *f = fopen(path, "w");
    if (!f)
        snprintf(ctx->msg, sizeof ctx->msg, "cannot write %.300s: %s", path, strerror(errno));
    return f;
}

int ex_close(ex_ctx *ctx, FILE *f, const char *name)
{
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) {
        snprintf(ctx->msg, sizeof ctx->msg, "writing %s/%s failed", ctx->out_dir, name);
        return -1;
    }
    return 0;
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Every lens of every *.scene in dir, in the order of the file names. */
static int load_lenses(ex_ctx *ctx, const char *dir)
{
    DIR *d = opendir(dir);
    char *names[256];
    size_t n = 0;
    struct dirent *e;
    int rc = 0;

    if (!d) {
        snprintf(ctx->msg, sizeof ctx->msg, "cannot read the scenes directory %s: %s", dir,
                 strerror(errno));
        return -1;
    }
    while ((e = readdir(d)) != NULL && n < 256) {
        size_t len = strlen(e->d_name);
        if (len > 6 && strcmp(e->d_name + len - 6, ".scene") == 0) {
            names[n] = strdup(e->d_name);
            if (names[n])
                n++;
        }
    }
    closedir(d);
    qsort(names, n, sizeof names[0], cmp_str);
    for (size_t i = 0; i < n && rc == 0; i++) {
        char path[4096];
        lr_scene *sc = NULL;
        lr_error err;
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        /* loaded as lensrender loads it (POV-Ray's colors.inc ... found):
         * the lenses have their catalog glass (the reader keeps only the
         * name) */
        if (lr_scene_load(path, NULL, &sc, &err) != LR_OK) {
            snprintf(ctx->msg, sizeof ctx->msg, "%.*s", (int)sizeof ctx->msg - 1, err.message);
            rc = -1;
        }
        const rs_scene *scene = lr_scene_description(sc);
        int k = 0, count = 0;
        /* the paper's lens is of glass: crystal specimens are left out */
        for (size_t j = 0; rc == 0 && j < scene->n_objects; j++)
            count += scene->objects[j].type == RS_OBJ_LENS && !scene->objects[j].u.lens.desc.uniaxial;
        for (size_t j = 0; rc == 0 && j < scene->n_objects; j++) {
            const rs_object *o = &scene->objects[j];
            if (o->type != RS_OBJ_LENS || o->u.lens.desc.uniaxial || ctx->n_lens >= EX_LENS_MAX)
                continue;
            ex_lens *l = &ctx->lens[ctx->n_lens++];
            int base = (int)(strlen(names[i]) - 6);
            k++;
            if (count > 1)
                snprintf(l->name, sizeof l->name, "%.*s #%d", base, names[i], k);
            else
                snprintf(l->name, sizeof l->name, "%.*s", base, names[i]);
            lp_lens_get_desc(o->lens, &l->desc);
            l->desc.position = (lp_vec3){0, 0, 0};
            l->desc.axis = (lp_vec3){0, 0, 1};
            snprintf(l->glass, sizeof l->glass, "%s",
                     o->u.lens.glass_name[0] ? o->u.lens.glass_name : l->desc.glass.name);
        }
        lr_scene_free(sc);
    }
    for (size_t i = 0; i < n; i++)
        free(names[i]);
    return rc;
}

/* The directory of the Markdown file, and out_dir relative to it. */
static const char *relative_to(const char *md, const char *out_dir)
{
    const char *slash = strrchr(md, '/');
    size_t len = slash ? (size_t)(slash - md) : 0;
    if (len == 0)
        return out_dir;
    if (strncmp(out_dir, md, len) == 0 && out_dir[len] == '/')
        return out_dir + len + 1;
    return out_dir;
}

int main(int argc, char **argv)
{
    const char *scenes = "scenes", *out = "docs/paper-experiments";
    const char *md_path = "docs/paper-experiments.md";
    ex_ctx *ctx = calloc(1, sizeof *ctx);
    if (!ctx) {
        fprintf(stderr, "paper_experiments: out of memory\n");
        return 1;
    }
    ctx->scene_name = "dispersion.scene";
    ctx->wavelengths = 16;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage_text, stdout);
            free(ctx);
            return 0;
        }
        if (i + 1 >= argc) {
            fprintf(stderr, "paper_experiments: %s needs a value (try --help)\n", a);
            free(ctx);
            return EXIT_USAGE;
        }
        const char *v = argv[++i];
        if (strcmp(a, "--scenes") == 0)
            scenes = v;
        else if (strcmp(a, "--renders") == 0)
            ctx->renders = v;
        else if (strcmp(a, "--scene-name") == 0)
            ctx->scene_name = v;
        else if (strcmp(a, "--wavelengths") == 0)
            ctx->wavelengths = atoi(v);
        else if (strcmp(a, "--out") == 0)
            out = v;
        else if (strcmp(a, "--md") == 0)
            md_path = v;
        else {
            fprintf(stderr, "paper_experiments: unknown option '%s' (try --help)\n", a);
            free(ctx);
            return EXIT_USAGE;
        }
    }
    if (!ctx->renders) {
        fprintf(stderr, "paper_experiments: missing --renders DIR (try --help)\n");
        free(ctx);
        return EXIT_USAGE;
    }
    static const char *const modes[4] = {"rgb", "fresnel", "polarized", "schlick"};
    for (int m = 0; m < 4; m++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s.pfm", ctx->renders, modes[m]);
        FILE *f = fopen(path, "rb");
        if (!f) {
            fprintf(stderr, "paper_experiments: cannot read the render %s: %s (make it with "
                            "lensrender --mode %s --pfm)\n", path, strerror(errno), modes[m]);
            free(ctx);
            return 1;
        }
        fclose(f);
    }
    ctx->out_dir = out;
    ctx->fig_rel = relative_to(md_path, out);
    if (mkdir(out, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "paper_experiments: cannot create %s: %s\n", out, strerror(errno));
        free(ctx);
        return 1;
    }
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", md_path, (long)getpid());
    ctx->md = fopen(tmp, "w");
    if (!ctx->md) {
        fprintf(stderr, "paper_experiments: cannot write %s: %s\n", tmp, strerror(errno));
        free(ctx);
        return 1;
    }
    int rc = load_lenses(ctx, scenes);
    if (rc == 0) {
        fprintf(ctx->md,
                "# The paper's experiments\n\n"
                "Section 5 of the paper (Debelov & Kushner, \"Lens model to process linear "
                "polarized light\") reports four experiments: two renders of one lens scene "
                "(RGB against spectral, Schlick against Fresnel through G) and two about "
                "the lens module itself (the cone K of rim-free directions and the share "
                "of the outgoing intensity by depth in the tree).  This page is made by one "
                "command, which renders the scene, runs the experiments and writes the "
                "page, its figures and its tables (`%s/*.csv`):\n\n"
                "```sh\nsh scripts/paper_experiments.sh        # builds if needed\n```\n\n"
                "Lengths in millimetres, wavelengths in nanometres in standard air; "
                "glasses from the built-in catalog (Schott data).\n\n",
                ctx->fig_rel);
        rc = ex_cone(ctx);
    }
    if (rc == 0)
        rc = ex_shares(ctx);
    if (rc == 0)
        rc = ex_images(ctx);
    int bad = ferror(ctx->md);
    if (fclose(ctx->md) != 0 || bad) {
        if (rc == 0)
            snprintf(ctx->msg, sizeof ctx->msg, "writing %.400s failed", tmp);
        rc = -1;
    }
    if (rc == 0 && rename(tmp, md_path) != 0) {
        snprintf(ctx->msg, sizeof ctx->msg, "cannot rename %.200s to %.200s: %s", tmp, md_path,
                 strerror(errno));
        rc = -1;
    }
    if (rc != 0) {
        remove(tmp);
        fprintf(stderr, "paper_experiments: %s\n", ctx->msg);
    } else {
        printf("paper_experiments: wrote %s and %s/\n", md_path, out);
    }
    free(ctx);
    return rc == 0 ? 0 : 1;
}
