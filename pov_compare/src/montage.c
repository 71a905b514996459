/* montage.c -- side_by_side.png with a built-in bitmap font (montage.h). */
#include <stdio.h>
#include <string.h>

#include "compare.h"
#include "montage.h"

#define GLYPH_W 5
#define GLYPH_H 7
#define GAP 4

/* The 5 x 7 font: seven rows per glyph, bit 4 the leftmost column. */
typedef struct glyph {
    char c;
    unsigned char rows[GLYPH_H];
} glyph;

static const glyph font[] = {
    {'A', {0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}},
    {'B', {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E}},
    {'C', {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}},
    {'D', {0x1E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1E}},
    {'E', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}},
    {'F', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10}},
    {'G', {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}},
    {'H', {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}},
    {'I', {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'J', {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C}},
    {'K', {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}},
    {'L', {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F}},
    {'M', {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}},
    {'N', {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}},
    {'O', {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}},
    {'P', {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}},
    {'Q', {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D}},
    {'R', {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11}},
    {'S', {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}},
    {'T', {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'U', {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}},
    {'V', {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04}},
    {'W', {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}},
    {'X', {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11}},
    {'Y', {0x11, 0x11, 0x0A, 0x04, 0x04, 0x04, 0x04}},
    {'Z', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F}},
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}},
    {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}},
    {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}},
    {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}},
    {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}},
    {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {' ', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}},
    {',', {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08}},
    {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
    {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}},
    {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {':', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}},
    {'=', {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}},
    {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
    {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}},
    {'_', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F}},
    {'|', {0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'?', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04}},
};

static const unsigned char *glyph_rows(char c)
{
    const unsigned char *unknown = NULL;
    if (c >= 'a' && c <= 'z')
        c = (char)(c - 'a' + 'A');
    for (size_t k = 0; k < sizeof font / sizeof font[0]; k++) {
        if (font[k].c == c)
            return font[k].rows;
        if (font[k].c == '?')
            unknown = font[k].rows;
    }
    return unknown;
}

int pc_text_width(const char *text, int scale)
{
    size_t n = strlen(text);
    return n ? (int)n * (GLYPH_W + 1) * scale - scale : 0;
}

static void put(rs_image *img, int x, int y, const float rgb[3])
{
    if (x < 0 || y < 0 || x >= img->width || y >= img->height)
        return;
    float *p = img->rgb + 3 * ((size_t)y * (size_t)img->width + (size_t)x);
    p[0] = rgb[0];
    p[1] = rgb[1];
    p[2] = rgb[2];
}

int pc_draw_text(rs_image *img, int x, int y, int scale, const char *text, const float rgb[3])
{
    int x0 = x;
    for (const char *s = text; *s; s++) {
        const unsigned char *rows = glyph_rows(*s);
        for (int r = 0; r < GLYPH_H; r++)
            for (int c = 0; c < GLYPH_W; c++) {
                if (!(rows[r] & (1u << (GLYPH_W - 1 - c))))
                    continue;
                for (int dy = 0; dy < scale; dy++)
                    for (int dx = 0; dx < scale; dx++)
                        put(img, x + c * scale + dx, y + r * scale + dy, rgb);
            }
        x += (GLYPH_W + 1) * scale;
    }
    return x > x0 ? x - x0 - scale : 0;
}

/* Copy src (clipped to [0, 1]) into img with its top-left at (x0, y0). */
static void blit(rs_image *img, const rs_image *src, int x0, int y0)
{
    for (int y = 0; y < src->height; y++)
        for (int x = 0; x < src->width; x++) {
            const float *s = src->rgb + 3 * ((size_t)y * (size_t)src->width + (size_t)x);
            float c[3];
            for (int k = 0; k < 3; k++)
                c[k] = s[k] > 0.0f ? (s[k] < 1.0f ? s[k] : 1.0f) : 0.0f;
            put(img, x0 + x, y0 + y, c);
        }
}

/* Text centred in [x0, x0 + w), shrunk to scale 1 if it does not fit. */
static void centred(rs_image *img, int x0, int w, int y, int scale, const char *text,
                    const float rgb[3])
{
    if (!text)
        return;
    if (pc_text_width(text, scale) > w && scale > 1) {
        y += (GLYPH_H * scale - GLYPH_H) / 2;
        scale = 1;
    }
    int tw = pc_text_width(text, scale);
    pc_draw_text(img, x0 + (w - tw) / 2, y, scale, text, rgb);
}

int pc_montage_build(const pc_montage_args *a, rs_image *out)
{
    const rs_image *panels[3] = {a->ours, a->povray, a->diff};
    const char *labels[3] = {a->ours_label, a->povray_label, a->diff_label};
    const float white[3] = {1.0f, 1.0f, 1.0f}, grey[3] = {0.6f, 0.6f, 0.6f};

    for (int k = 0; k < 3; k++)
        if (!panels[k] || !panels[k]->rgb || panels[k]->width != a->ours->width ||
            panels[k]->height != a->ours->height)
            return -1;
    int w = a->ours->width, h = a->ours->height;
    int scale = w >= 240 ? 2 : 1;
    int strip = GLYPH_H * scale + 2 * 3 * scale;
    if (rs_image_create(out, 3 * w + 2 * GAP, h + 2 * strip) != 0)
        return -1;
    for (int k = 0; k < 3; k++) {
        int x0 = k * (w + GAP);
        blit(out, panels[k], x0, strip);
        centred(out, x0, w, 3 * scale, scale, labels[k], white);
    }
    int yb = strip + h + 3 * scale;
    centred(out, 0, w, yb, scale, a->ours_caption, grey);
    centred(out, w + GAP, w, yb, scale, a->povray_caption, grey);

    /* The ramp under the difference map: "0 [bar] scale". */
    {
        char hi[32];
        int x0 = 2 * (w + GAP), s1 = 1;
        snprintf(hi, sizeof hi, "%g", a->diff_scale);
        int lw = pc_text_width("0", s1), hw = pc_text_width(hi, s1);
        int bx0 = x0 + 4 + lw + 4, bx1 = x0 + w - 4 - hw - 4;
        int ty = strip + h + (strip - GLYPH_H * s1) / 2;
        pc_draw_text(out, x0 + 4, ty, s1, "0", grey);
        pc_draw_text(out, bx1 + 4, ty, s1, hi, grey);
        for (int x = bx0; x < bx1; x++) {
            float c[3];
            pc_ramp((double)(x - bx0) / (double)(bx1 - bx0 > 1 ? bx1 - bx0 - 1 : 1), c);
            for (int y = strip + h + 3 * scale; y < strip + h + strip - 3 * scale; y++)
                put(out, x, y, c);
        }
    }
    return 0;
}

int pc_montage_write(const char *path, const pc_montage_args *args, char *msg, size_t msg_size)
{
    rs_image img;
    if (pc_montage_build(args, &img) != 0) {
        snprintf(msg, msg_size, "%s: cannot build the montage (images missing, of different "
                 "sizes, or out of memory)", path);
        return -1;
    }
    int rc = rs_png_write(path, &img, msg, msg_size);
    rs_image_free(&img);
    return rc;
}
