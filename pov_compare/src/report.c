/* report.c -- report.json and report.md (report.h). */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "report.h"

static const lr_mode order[PC_N_MODES] = {LR_MODE_FRESNEL, LR_MODE_SCHLICK, LR_MODE_POLARIZED,
                                          LR_MODE_RGB};

lr_mode pc_report_mode(int k)
{
    return order[k >= 0 && k < PC_N_MODES ? k : 0];
}

const char *pc_mode_label(lr_mode mode)
{
    return lr_mode_name(mode);
}

const pc_mode_result *pc_report_find(const pc_report *r, lr_mode mode)
{
    for (int k = 0; k < PC_N_MODES; k++)
        if (r->modes[k].mode == mode)
            return &r->modes[k];
    return NULL;
}

void pc_json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        switch (*p) {
        case '"': fputs("\\\"", f); break;
        case '\\': fputs("\\\\", f); break;
        case '\n': fputs("\\n", f); break;
        case '\r': fputs("\\r", f); break;
        case '\t': fputs("\\t", f); break;
        default:
            if (*p < 0x20)
                fprintf(f, "\\u%04x", *p);
            else
                fputc(*p, f);
        }
    }
    fputc('"', f);
}

void pc_json_number(FILE *f, double v)
{
    if (isfinite(v))
        fprintf(f, "%.6g", v);
    else
        fputs("null", f);
}

static void json_metrics(FILE *f, const pc_metrics *m)
{
    fputs("{\"rmse\":", f);
    pc_json_number(f, m->rmse);
    fputs(",\"psnr\":", f);
    pc_json_number(f, m->psnr);
    fputs(",\"ssim\":", f);
    pc_json_number(f, m->ssim);
    fputc('}', f);
}

/* Open path.tmp for writing. */
static FILE *open_tmp(const char *path, char *tmp, size_t tmp_size, char *msg, size_t msg_size)
{
    FILE *f;
    if (snprintf(tmp, tmp_size, "%s.tmp", path) >= (int)tmp_size) {
        snprintf(msg, msg_size, "%s: path too long", path);
        return NULL;
    }
    f = fopen(tmp, "w");
    if (!f)
        snprintf(msg, msg_size, "%s: cannot write: %s", tmp, strerror(errno));
    return f;
}

static int close_tmp(FILE *f, const char *tmp, const char *path, char *msg, size_t msg_size)
{
    int bad = ferror(f);
    if (fclose(f) != 0)
        bad = 1;
    if (bad) {
        snprintf(msg, msg_size, "%s: write error", tmp);
        remove(tmp);
        return -1;
    }
    if (rename(tmp, path) != 0) {
        snprintf(msg, msg_size, "%s: cannot rename to %s: %s", tmp, path, strerror(errno));
        remove(tmp);
        return -1;
    }
    return 0;
}

int pc_report_write_json(const pc_report *r, const char *path, char *msg, size_t msg_size)
{
    char tmp[4200];
    FILE *f = open_tmp(path, tmp, sizeof tmp, msg, msg_size);
    if (!f)
        return -1;

    fputs("{\"scene\":", f);
    pc_json_string(f, r->scene);
    fprintf(f, ",\"width\":%d,\"height\":%d,\"depth\":%d,\n", r->width, r->height, r->depth);

    const pc_geometry *g = &r->geometry;
    fputs(" \"geometry\":{\"iou\":", f);
    pc_json_number(f, g->iou);
    fputs(",\"max_boundary_px\":", f);
    pc_json_number(f, g->max_boundary_px);
    fprintf(f, ",\"area_ours_px\":%zu,\"area_povray_px\":%zu,\"differing_px\":%zu",
            g->area_a, g->area_b, g->flipped);
    if (g->worst_mask >= 0)
        fprintf(f, ",\"worst_boundary_pixel\":{\"x\":%d,\"y\":%d,\"of\":\"%s\"}", g->worst_x,
                g->worst_y, g->worst_mask ? "povray" : "ours");
    fputs("},\n \"modes\":{", f);
    for (int k = 0; k < PC_N_MODES; k++) {
        const pc_mode_result *m = &r->modes[k];
        fprintf(f, "%s\n   ", k ? "," : "");
        pc_json_string(f, pc_mode_label(m->mode));
        fputs(":{\"vs_povray\":", f);
        json_metrics(f, &m->vs_povray);
        if (m->has_vs_polarized) {
            fputs(",\"vs_polarized\":", f);
            json_metrics(f, &m->vs_polarized);
        }
        fprintf(f, ",\"worst_pixel_vs_povray\":{\"x\":%d,\"y\":%d,\"ours\":", m->worst.x,
                m->worst.y);
        pc_json_number(f, m->worst.a);
        fputs(",\"povray\":", f);
        pc_json_number(f, m->worst.b);
        fputs("}}", f);
    }
    fputs("},\n \"seconds\":{\"povray\":", f);
    pc_json_number(f, r->povray_seconds);
    for (int k = 0; k < PC_N_MODES; k++) {
        fprintf(f, ",\"%s\":", pc_mode_label(r->modes[k].mode));
        pc_json_number(f, r->modes[k].seconds);
    }
    fputs(",\"povray_mask\":", f);
    pc_json_number(f, r->povray_mask_seconds);
    fputs("},\n \"notes\":[", f);
    for (size_t k = 0; r->notes && k < r->notes->n; k++) {
        fputs(k ? ",\n   " : "\n   ", f);
        pc_json_string(f, r->notes->text[k]);
    }
    fputs("],\n \"povray_version\":", f);
    pc_json_string(f, r->povray_version);
    fprintf(f, ",\n \"wavelengths\":%d,\"adc_bailout\":0,\"glass_lambda_nm\":587.5618",
            r->wavelengths);
    fputs(",\n \"diff_scale\":", f);
    pc_json_number(f, r->diff_scale);
    fputs(",\"diff_max\":", f);
    pc_json_number(f, r->diff_max);
    fputs(",\n \"files\":{\"scene_pov\":\"scene.pov\",\"mask_pov\":\"mask.pov\","
          "\"povray\":\"povray.png\",\"povray_mask\":\"mask_povray.png\","
          "\"ours_mask\":\"mask_ours.png\",\"side_by_side\":\"side_by_side.png\","
          "\"diff\":\"diff.png\",\"log\":\"povray.log\"",
          f);
    for (int k = 0; k < PC_N_MODES; k++) {
        const char *l = pc_mode_label(r->modes[k].mode);
        fprintf(f, ",\"ours_%s\":\"ours_%s.png\",\"ours_%s_pfm\":\"ours_%s.pfm\"", l, l, l, l);
    }
    fputs("}}\n", f);
    return close_tmp(f, tmp, path, msg, msg_size);
}

/* A metric cell for the Markdown table. */
static void md_num(FILE *f, double v, const char *fmt)
{
    if (isnan(v))
        fputs(" – |", f);
    else if (isinf(v))
        fputs(" ∞ |", f);
    else {
        fputc(' ', f);
        fprintf(f, fmt, v);
        fputs(" |", f);
    }
}

static void md_metrics(FILE *f, const pc_metrics *m, int present)
{
    if (!present) {
        fputs(" | | |", f);
        return;
    }
    md_num(f, m->rmse, "%.3g");
    md_num(f, m->psnr, "%.2f");
    md_num(f, m->ssim, "%.5f");
}

int pc_report_write_md(const pc_report *r, const char *path, char *msg, size_t msg_size)
{
    char tmp[4200];
    int any_inf = 0;
    FILE *f = open_tmp(path, tmp, sizeof tmp, msg, msg_size);
    if (!f)
        return -1;

    fprintf(f, "# pov_compare: %s\n\n", r->scene);
    fprintf(f, "%d × %d pixels, max_trace_level %d, POV-Ray %s. Both renderers trace one "
               "ray per pixel centre with adc_bailout 0 (depth alone ends a path) and glass "
               "as a constant lossless index at 587.5618 nm; our spectral modes use %d "
               "wavelengths. Metrics compare linear RGB clipped to [0, 1]; PSNR in dB with "
               "peak 1; SSIM on luminance.\n\n",
            r->width, r->height, r->depth, r->povray_version[0] ? r->povray_version : "3.7",
            r->wavelengths);
    fputs("![ours (fresnel) | POV-Ray | difference](side_by_side.png)\n\n", f);
    fputs("| mode | vs POV-Ray RMSE | PSNR dB | SSIM | vs polarized RMSE | PSNR dB | SSIM "
          "| seconds |\n",
          f);
    fputs("|---|---:|---:|---:|---:|---:|---:|---:|\n", f);
    fputs("| POV-Ray |  |  |  |  |  |  |", f);
    md_num(f, r->povray_seconds, "%.2f");
    fputc('\n', f);
    for (int k = 0; k < PC_N_MODES; k++) {
        const pc_mode_result *m = &r->modes[k];
        fprintf(f, "| [%s](ours_%s.png) |", pc_mode_label(m->mode), pc_mode_label(m->mode));
        md_metrics(f, &m->vs_povray, 1);
        md_metrics(f, &m->vs_polarized, m->has_vs_polarized);
        md_num(f, m->seconds, "%.2f");
        fputc('\n', f);
        if (isinf(m->vs_povray.psnr) || (m->has_vs_polarized && isinf(m->vs_polarized.psnr)))
            any_inf = 1;
    }
    fputc('\n', f);
    fprintf(f, "Seconds are wall clock: POV-Ray's include its start-up (its silhouette render "
               "of the same scene, [mask.pov](mask.pov), took %.2f s); ours are the render "
               "alone, on the same number of threads.\n\n",
            r->povray_mask_seconds);
    if (any_inf)
        fputs("∞: the two images are identical after clipping (report.json writes this "
              "PSNR as null: JSON has no infinity).\n\n",
              f);

    const pc_geometry *g = &r->geometry;
    fprintf(f, "**Geometry** (lens silhouettes, ours from lp_lens_intersect per pixel ray, "
               "POV-Ray's from [mask.pov](mask.pov)): IoU %.6f, largest boundary "
               "displacement %.3g px; %zu of %zu / %zu lens pixels differ "
               "([ours](mask_ours.png), [POV-Ray](mask_povray.png)).\n\n",
            g->iou, g->max_boundary_px, g->flipped, g->area_a, g->area_b);

    const pc_mode_result *fr = pc_report_find(r, LR_MODE_FRESNEL);
    if (fr)
        fprintf(f, "**Largest difference** (fresnel against POV-Ray, luminance): pixel "
                   "(%d, %d), ours %.5f, POV-Ray %.5f.\n\n",
                fr->worst.x, fr->worst.y, fr->worst.a, fr->worst.b);
    fprintf(f, "**Difference map** ([diff.png](diff.png)): |Y(ours fresnel) − Y(POV-Ray)| "
               "on a ramp from 0 (black) through blue, purple, red and orange to %g (pale "
               "yellow; larger differences saturate); the largest is %.4g.\n\n",
            r->diff_scale, r->diff_max);

    fputs("## Notes\n\n", f);
    if (!r->notes || r->notes->n == 0)
        fputs("- none: the translation is exact.\n", f);
    for (size_t k = 0; r->notes && k < r->notes->n; k++)
        fprintf(f, "- %s\n", r->notes->text[k]);

    fputs("\n## Files\n\n", f);
    fputs("- [scene.pov](scene.pov) with [lens.inc](lens.inc): the scene as POV-Ray renders "
          "it; [povray.log](povray.log): its output\n",
          f);
    fputs("- [povray.png](povray.png): POV-Ray's render, 16-bit linear PNG as written\n", f);
    for (int k = 0; k < PC_N_MODES; k++) {
        const char *l = pc_mode_label(r->modes[k].mode);
        fprintf(f, "- [ours_%s.png](ours_%s.png) (8-bit sRGB), [ours_%s.pfm](ours_%s.pfm) "
                   "(linear float)\n",
                l, l, l, l);
    }
    fputs("- [side_by_side.png](side_by_side.png), [diff.png](diff.png), "
          "[report.json](report.json)\n",
          f);
    return close_tmp(f, tmp, path, msg, msg_size);
}
