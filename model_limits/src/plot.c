/* plot.c -- the line-plot renderer of plot.h.
 *
 * Coordinates: pixel (i, j) covers [i, i+1) x [j, j+1), its centre is
 * (i + 0.5, j + 0.5); j grows downwards.  A line is drawn by giving every
 * pixel the coverage clamp(w/2 + 0.5 - d, 0, 1), d the distance from the
 * pixel centre to the nearest segment of the line; the coverage of one
 * series is the maximum over its segments (so joints are round and never
 * doubled) and is composited once, in linear light, rounded to quarters. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "plot.h"
#include "support/colorimetry.h"

/* ---- The font ------------------------------------------------------------
 * 5x7 glyphs, one byte per row, top row first, bit 4 the leftmost column.
 * ASCII 32..126, then three extras: degree sign, theta, lambda.  The
 * letters with descenders (g p q y; j by one row) are drawn lower than the
 * others, into the two rows of line spacing below the cell. */

enum { GLYPH_W = 5, GLYPH_H = 7, ADVANCE = 6, LINE_H = 9 };
enum { G_DEGREE = 95, G_THETA = 96, G_LAMBDA = 97, G_COUNT = 98 };

static const unsigned char FONT[G_COUNT][GLYPH_H] = {
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, /* space */
    {0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x04}, /* ! */
    {0x0A, 0x0A, 0x00, 0x00, 0x00, 0x00, 0x00}, /* " */
    {0x0A, 0x0A, 0x1F, 0x0A, 0x1F, 0x0A, 0x0A}, /* # */
    {0x04, 0x0F, 0x14, 0x0E, 0x05, 0x1E, 0x04}, /* $ */
    {0x19, 0x19, 0x02, 0x04, 0x08, 0x13, 0x13}, /* % */
    {0x08, 0x14, 0x14, 0x08, 0x15, 0x12, 0x0D}, /* & */
    {0x04, 0x04, 0x08, 0x00, 0x00, 0x00, 0x00}, /* ' */
    {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}, /* ( */
    {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}, /* ) */
    {0x00, 0x04, 0x15, 0x0E, 0x15, 0x04, 0x00}, /* * */
    {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}, /* + */
    {0x00, 0x00, 0x00, 0x00, 0x06, 0x02, 0x04}, /* , */
    {0x00, 0x00, 0x00, 0x0E, 0x00, 0x00, 0x00}, /* - */
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x06, 0x06}, /* . */
    {0x01, 0x01, 0x02, 0x04, 0x08, 0x10, 0x10}, /* / */
    {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}, /* 0 */
    {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}, /* 1 */
    {0x0E, 0x11, 0x01, 0x06, 0x08, 0x10, 0x1F}, /* 2 */
    {0x0E, 0x11, 0x01, 0x06, 0x01, 0x11, 0x0E}, /* 3 */
    {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}, /* 4 */
    {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}, /* 5 */
    {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}, /* 6 */
    {0x1F, 0x01, 0x02, 0x04, 0x04, 0x08, 0x08}, /* 7 */
    {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}, /* 8 */
    {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}, /* 9 */
    {0x00, 0x06, 0x06, 0x00, 0x06, 0x06, 0x00}, /* : */
    {0x00, 0x06, 0x06, 0x00, 0x06, 0x02, 0x04}, /* ; */
    {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02}, /* < */
    {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}, /* = */
    {0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08}, /* > */
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04}, /* ? */
    {0x0E, 0x11, 0x17, 0x15, 0x17, 0x10, 0x0E}, /* @ */
    {0x04, 0x0A, 0x11, 0x11, 0x1F, 0x11, 0x11}, /* A */
    {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E}, /* B */
    {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}, /* C */
    {0x1E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1E}, /* D */
    {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}, /* E */
    {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10}, /* F */
    {0x0E, 0x11, 0x10, 0x13, 0x11, 0x11, 0x0F}, /* G */
    {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}, /* H */
    {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}, /* I */
    {0x01, 0x01, 0x01, 0x01, 0x01, 0x11, 0x0E}, /* J */
    {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}, /* K */
    {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F}, /* L */
    {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}, /* M */
    {0x11, 0x19, 0x19, 0x15, 0x13, 0x13, 0x11}, /* N */
    {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}, /* O */
    {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}, /* P */
    {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D}, /* Q */
    {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11}, /* R */
    {0x0E, 0x11, 0x10, 0x0E, 0x01, 0x11, 0x0E}, /* S */
    {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}, /* T */
    {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}, /* U */
    {0x11, 0x11, 0x11, 0x11, 0x0A, 0x0A, 0x04}, /* V */
    {0x11, 0x11, 0x11, 0x15, 0x15, 0x1B, 0x11}, /* W */
    {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11}, /* X */
    {0x11, 0x11, 0x0A, 0x04, 0x04, 0x04, 0x04}, /* Y */
    {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F}, /* Z */
    {0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E}, /* [ */
    {0x10, 0x10, 0x08, 0x04, 0x02, 0x01, 0x01}, /* backslash */
    {0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E}, /* ] */
    {0x04, 0x0A, 0x11, 0x00, 0x00, 0x00, 0x00}, /* ^ */
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F}, /* _ */
    {0x08, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00}, /* ` */
    {0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F}, /* a */
    {0x10, 0x10, 0x1E, 0x11, 0x11, 0x11, 0x1E}, /* b */
    {0x00, 0x00, 0x0F, 0x10, 0x10, 0x10, 0x0F}, /* c */
    {0x01, 0x01, 0x0F, 0x11, 0x11, 0x11, 0x0F}, /* d */
    {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0F}, /* e */
    {0x06, 0x08, 0x1C, 0x08, 0x08, 0x08, 0x08}, /* f */
    {0x0F, 0x11, 0x11, 0x11, 0x0F, 0x01, 0x0E}, /* g (descends) */
    {0x10, 0x10, 0x1E, 0x11, 0x11, 0x11, 0x11}, /* h */
    {0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E}, /* i */
    {0x02, 0x00, 0x06, 0x02, 0x02, 0x12, 0x0C}, /* j (descends 1) */
    {0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12}, /* k */
    {0x0C, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}, /* l */
    {0x00, 0x00, 0x1A, 0x15, 0x15, 0x15, 0x15}, /* m */
    {0x00, 0x00, 0x1E, 0x11, 0x11, 0x11, 0x11}, /* n */
    {0x00, 0x00, 0x0E, 0x11, 0x11, 0x11, 0x0E}, /* o */
    {0x1E, 0x11, 0x11, 0x11, 0x1E, 0x10, 0x10}, /* p (descends) */
    {0x0F, 0x11, 0x11, 0x11, 0x0F, 0x01, 0x01}, /* q (descends) */
    {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10}, /* r */
    {0x00, 0x00, 0x0F, 0x10, 0x0E, 0x01, 0x1E}, /* s */
    {0x08, 0x08, 0x1C, 0x08, 0x08, 0x08, 0x06}, /* t */
    {0x00, 0x00, 0x11, 0x11, 0x11, 0x11, 0x0F}, /* u */
    {0x00, 0x00, 0x11, 0x11, 0x0A, 0x0A, 0x04}, /* v */
    {0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0A}, /* w */
    {0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11}, /* x */
    {0x11, 0x11, 0x11, 0x11, 0x0F, 0x01, 0x0E}, /* y (descends) */
    {0x00, 0x00, 0x1F, 0x02, 0x04, 0x08, 0x1F}, /* z */
    {0x03, 0x04, 0x04, 0x18, 0x04, 0x04, 0x03}, /* { */
    {0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}, /* | */
    {0x18, 0x04, 0x04, 0x03, 0x04, 0x04, 0x18}, /* } */
    {0x00, 0x00, 0x08, 0x15, 0x02, 0x00, 0x00}, /* ~ */
    {0x0C, 0x12, 0x12, 0x0C, 0x00, 0x00, 0x00}, /* degree sign */
    {0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x0E}, /* theta */
    {0x08, 0x04, 0x04, 0x0A, 0x0A, 0x11, 0x11}, /* lambda */
};

/* Rows a glyph is drawn below the top of its cell. */
static int glyph_drop(int g)
{
    switch (g + 32) {
    case 'g': case 'p': case 'q': case 'y':
        return 2;
    case 'j':
        return 1;
    default:
        return 0;
    }
}

/* The glyph of the character starting at *s; advances *s past it (a whole
 * UTF-8 sequence).  Returns -1 for '\n'. */
static int next_glyph(const char **s)
{
    const unsigned char *p = (const unsigned char *)*s;
    unsigned c = p[0];

    if (c == '\n') {
        *s += 1;
        return -1;
    }
    if (c >= 32 && c <= 126) {
        *s += 1;
        return (int)c - 32;
    }
    if (c == 0xC2 && p[1] == 0xB0) {
        *s += 2;
        return G_DEGREE;
    }
    if (c == 0xCE && (p[1] == 0xB8 || p[1] == 0xBB)) {
        *s += 2;
        return p[1] == 0xB8 ? G_THETA : G_LAMBDA;
    }
    /* anything else: skip the sequence, draw '?' */
    *s += 1;
    if (c >= 0xC0)
        while ((**(const unsigned char **)s & 0xC0) == 0x80)
            *s += 1;
    return '?' - 32;
}

/* ---- Pixels --------------------------------------------------------------- */

typedef struct lin {
    float r, g, b;
} lin;

static lin to_linear(unsigned color)
{
    lin c;
    c.r = (float)rs_srgb_decode(((color >> 16) & 0xFF) / 255.0);
    c.g = (float)rs_srgb_decode(((color >> 8) & 0xFF) / 255.0);
    c.b = (float)rs_srgb_decode((color & 0xFF) / 255.0);
    return c;
}

static void blend(rs_image *img, int x, int y, lin c, float a)
{
    if (x < 0 || y < 0 || x >= img->width || y >= img->height || !(a > 0.0f))
        return;
    if (a > 1.0f)
        a = 1.0f;
    float *p = img->rgb + 3 * ((size_t)y * (size_t)img->width + (size_t)x);
    p[0] = p[0] * (1.0f - a) + c.r * a;
    p[1] = p[1] * (1.0f - a) + c.g * a;
    p[2] = p[2] * (1.0f - a) + c.b * a;
}

static void fill_rect(rs_image *img, int x, int y, int w, int h, lin c)
{
    for (int j = y; j < y + h; j++)
        for (int i = x; i < x + w; i++)
            blend(img, i, j, c, 1.0f);
}

void pl_fill(rs_image *img, unsigned color)
{
    if (img && img->rgb)
        fill_rect(img, 0, 0, img->width, img->height, to_linear(color));
}

/* ---- Text ----------------------------------------------------------------- */

int pl_text_width(const char *text, int scale)
{
    int best = 0, cur = 0;

    if (!text)
        return 0;
    if (scale < 1)
        scale = 1;
    while (*text) {
        if (next_glyph(&text) < 0)
            cur = 0;
        else
            cur++;
        if (cur > best)
            best = cur;
    }
    return best > 0 ? (best * ADVANCE - 1) * scale : 0;
}

/* rotate == 0: normal, (x, y) the top-left corner.  rotate == 1: turned a
 * quarter counter-clockwise (reads bottom to top), (x, y) the bottom-left
 * corner of the turned text. */
static void draw_text(rs_image *img, int x, int y, int scale, lin c, const char *text,
                      int rotate)
{
    int col = 0, row = 0;

    if (!text)
        return;
    if (scale < 1)
        scale = 1;
    while (*text) {
        int g = next_glyph(&text);
        if (g < 0) {
            col = 0;
            row++;
            continue;
        }
        int drop = glyph_drop(g);
        for (int gy = 0; gy < GLYPH_H; gy++)
            for (int gx = 0; gx < GLYPH_W; gx++) {
                if (!(FONT[g][gy] & (0x10 >> gx)))
                    continue;
                int u = (col * ADVANCE + gx) * scale, v = (row * LINE_H + gy + drop) * scale;
                for (int sy = 0; sy < scale; sy++)
                    for (int sx = 0; sx < scale; sx++) {
                        if (rotate)
                            blend(img, x + v + sy, y - 1 - (u + sx), c, 1.0f);
                        else
                            blend(img, x + u + sx, y + v + sy, c, 1.0f);
                    }
            }
        col++;
    }
}

void pl_text(rs_image *img, int x, int y, int scale, unsigned color, const char *text)
{
    if (img && img->rgb)
        draw_text(img, x, y, scale, to_linear(color), text, 0);
}

/* ---- Anti-aliased strokes ------------------------------------------------- */

/* A coverage buffer over the pixel rectangle [x0, x0+w) x [y0, y0+h). */
typedef struct covbuf {
    float *c;
    int x0, y0, w, h;
} covbuf;

static void cov_segment(covbuf *cb, double ax, double ay, double bx, double by, double width)
{
    double r = 0.5 * width + 0.5;
    int i0 = (int)floor(fmin(ax, bx) - r), i1 = (int)ceil(fmax(ax, bx) + r);
    int j0 = (int)floor(fmin(ay, by) - r), j1 = (int)ceil(fmax(ay, by) + r);
    double dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;

    if (i0 < cb->x0)
        i0 = cb->x0;
    if (j0 < cb->y0)
        j0 = cb->y0;
    if (i1 > cb->x0 + cb->w - 1)
        i1 = cb->x0 + cb->w - 1;
    if (j1 > cb->y0 + cb->h - 1)
        j1 = cb->y0 + cb->h - 1;
    for (int j = j0; j <= j1; j++)
        for (int i = i0; i <= i1; i++) {
            double px = i + 0.5 - ax, py = j + 0.5 - ay;
            double t = len2 > 0.0 ? (px * dx + py * dy) / len2 : 0.0;
            if (t < 0.0)
                t = 0.0;
            else if (t > 1.0)
                t = 1.0;
            double ex = px - t * dx, ey = py - t * dy;
            double cov = r - sqrt(ex * ex + ey * ey);
            if (cov <= 0.0)
                continue;
            if (cov > 1.0)
                cov = 1.0;
            float *q = &cb->c[(size_t)(j - cb->y0) * (size_t)cb->w + (size_t)(i - cb->x0)];
            if ((float)cov > *q)
                *q = (float)cov;
        }
}

static void cov_composite(rs_image *img, covbuf *cb, lin c)
{
    for (int j = 0; j < cb->h; j++)
        for (int i = 0; i < cb->w; i++) {
            float *q = &cb->c[(size_t)j * (size_t)cb->w + (size_t)i];
            /* coverage in quarters: a few distinct colours per line keep
             * the PNG files small, and still look smooth */
            float a = floorf(*q * 4.0f + 0.5f) * 0.25f;
            if (a > 0.0f)
                blend(img, cb->x0 + i, cb->y0 + j, c, a);
            *q = 0.0f;
        }
}

/* The on/off lengths of a dash pattern for a line of the given width. */
static void dash_pattern(pl_dash dash, double width, double *on, double *off)
{
    switch (dash) {
    case PL_DASHED:
        *on = 4.0 * width + 3.0;
        *off = 2.5 * width + 2.0;
        break;
    case PL_DOTTED:
        *on = 0.01;
        *off = 1.5 * width + 2.5;
        break;
    default:
        *on = INFINITY;
        *off = 0.0;
        break;
    }
}

/* Stroke the part [t0, t1] of the segment a-b with the dash pattern, the
 * pattern being at position *phase at t = 0; *phase is advanced by the
 * whole segment's length. */
static void dash_segment(covbuf *cb, double ax, double ay, double bx, double by, double t0,
                         double t1, pl_dash dash, double width, double *phase)
{
    double on, off, len = hypot(bx - ax, by - ay);

    dash_pattern(dash, width, &on, &off);
    if (dash == PL_SOLID || len == 0.0) {
        cov_segment(cb, ax + t0 * (bx - ax), ay + t0 * (by - ay), ax + t1 * (bx - ax),
                    ay + t1 * (by - ay), width);
        return;
    }
    double period = on + off;
    double s = -fmod(*phase, period); /* start of the current period, along the segment */
    for (; s < len; s += period) {
        double a = fmax(s, t0 * len), b = fmin(s + on, t1 * len);
        if (b >= a)
            cov_segment(cb, ax + (bx - ax) * a / len, ay + (by - ay) * a / len,
                        ax + (bx - ax) * b / len, ay + (by - ay) * b / len, width);
    }
    *phase = fmod(*phase + len, period);
}

/* Liang-Barsky: the parameter range of a-b inside [x0,x1]x[y0,y1]; 0 when
 * none. */
static int clip(double ax, double ay, double bx, double by, double x0, double y0, double x1,
                double y1, double *t0, double *t1)
{
    double p[4] = {-(bx - ax), bx - ax, -(by - ay), by - ay};
    double q[4] = {ax - x0, x1 - ax, ay - y0, y1 - ay};

    *t0 = 0.0;
    *t1 = 1.0;
    for (int k = 0; k < 4; k++) {
        if (p[k] == 0.0) {
            if (q[k] < 0.0)
                return 0;
            continue;
        }
        double t = q[k] / p[k];
        if (p[k] < 0.0) {
            if (t > *t1)
                return 0;
            if (t > *t0)
                *t0 = t;
        } else {
            if (t < *t0)
                return 0;
            if (t < *t1)
                *t1 = t;
        }
    }
    return 1;
}

/* ---- Axes ----------------------------------------------------------------- */

typedef struct frame {
    int x0, y0, w, h; /* the data rectangle in pixels */
    const pl_chart *ch;
    double ly0, ly1;  /* the y range as drawn: log10 of it for a log axis */
} frame;

static double map_x(const frame *f, double x)
{
    return f->x0 + (x - f->ch->xmin) / (f->ch->xmax - f->ch->xmin) * f->w;
}

/* NaN for a value that cannot be drawn (y <= 0 on a log axis). */
static double map_y(const frame *f, double y)
{
    double v = y;
    if (f->ch->ylog) {
        if (!(y > 0.0))
            return NAN;
        v = log10(y);
    }
    return f->y0 + (f->ly1 - v) / (f->ly1 - f->ly0) * f->h;
}

static double nice_step(double range)
{
    double raw = range / 6.0, mag = pow(10.0, floor(log10(raw))), m = raw / mag;
    return (m < 1.5 ? 1.0 : m < 3.0 ? 2.0 : m < 7.0 ? 5.0 : 10.0) * mag;
}

static void linear_label(char *buf, size_t size, double v, double step, int percent)
{
    int dec = step >= 1.0 ? 0 : (int)ceil(-log10(step) - 1e-9);
    if (fabs(v) < 0.5 * step * 1e-6)
        v = 0.0; /* no "-0" */
    snprintf(buf, size, "%.*f%s", dec, v, percent ? "%" : "");
}

static void decade_label(char *buf, size_t size, int k, int percent)
{
    const char *pc = percent ? "%" : "";
    if (k >= -4 && k <= 4)
        snprintf(buf, size, "%.*f%s", k < 0 ? -k : 0, pow(10.0, k), pc);
    else
        snprintf(buf, size, "1e%d%s", k, pc);
}

/* Tick positions of an axis: linear from lo to hi by step, or the decades
 * (log).  Returns the count (at most max). */
static int linear_ticks(double lo, double hi, double step, double *t, int max)
{
    int n = 0;
    double k0 = ceil(lo / step - 1e-9), k1 = floor(hi / step + 1e-9);
    for (double k = k0; k <= k1 && n < max; k += 1.0)
        t[n++] = k * step;
    return n;
}

typedef struct tick_set {
    double v[64];    /* positions in data units (log: the exponent) */
    char label[64][32];
    int n;
    int label_every; /* label every n-th tick */
} tick_set;

static void x_ticks(const pl_chart *ch, tick_set *ts)
{
    double step = ch->xstep > 0.0 ? ch->xstep : nice_step(ch->xmax - ch->xmin);
    ts->n = linear_ticks(ch->xmin, ch->xmax, step, ts->v, 64);
    ts->label_every = 1;
    for (int i = 0; i < ts->n; i++)
        linear_label(ts->label[i], sizeof ts->label[i], ts->v[i], step, 0);
}

static void y_ticks(const pl_chart *ch, tick_set *ts)
{
    if (ch->ylog) {
        int k0 = (int)ceil(log10(ch->ymin) - 1e-9), k1 = (int)floor(log10(ch->ymax) + 1e-9);
        ts->n = 0;
        for (int k = k0; k <= k1 && ts->n < 64; k++) {
            ts->v[ts->n] = k;
            decade_label(ts->label[ts->n], sizeof ts->label[ts->n], k, ch->yticks_percent);
            ts->n++;
        }
        ts->label_every = ts->n > 10 ? (ts->n + 9) / 10 : 1;
    } else {
        double step = ch->ystep > 0.0 ? ch->ystep : nice_step(ch->ymax - ch->ymin);
        ts->n = linear_ticks(ch->ymin, ch->ymax, step, ts->v, 64);
        ts->label_every = 1;
        for (int i = 0; i < ts->n; i++)
            linear_label(ts->label[i], sizeof ts->label[i], ts->v[i], step,
                         ch->yticks_percent);
    }
}

/* ---- The chart ------------------------------------------------------------ */

#define C_TEXT 0x202020u
#define C_FRAME 0x404040u
#define C_GRID 0xDCDCDCu
#define C_MARKER 0x707070u

static void stroke_series(rs_image *img, covbuf *cb, const frame *f, const pl_series *s)
{
    double width = s->width > 0.0 ? s->width : 2.0, phase = 0.0;
    size_t run = 0; /* points in the current unbroken run */
    double px = 0.0, py = 0.0;
    /* clip to the data rectangle, a little outside so edges look whole */
    double cx0 = f->x0 - 0.5 * width, cy0 = f->y0 - 0.5 * width;
    double cx1 = f->x0 + f->w + 0.5 * width, cy1 = f->y0 + f->h + 0.5 * width;

    for (size_t i = 0; i <= s->n; i++) {
        double x = NAN, y = NAN;
        if (i < s->n && isfinite(s->x[i]) && isfinite(s->y[i])) {
            x = map_x(f, s->x[i]);
            y = map_y(f, s->y[i]);
        }
        if (!isfinite(x) || !isfinite(y)) {
            /* a break: a run of one point is drawn as a dot */
            if (run == 1 && px >= cx0 && px <= cx1 && py >= cy0 && py <= cy1)
                cov_segment(cb, px, py, px, py, width);
            run = 0;
            continue;
        }
        /* keep huge values from overflowing the clipper */
        if (y < f->y0 - 1e6)
            y = f->y0 - 1e6;
        if (y > f->y0 + f->h + 1e6)
            y = f->y0 + f->h + 1e6;
        if (run > 0) {
            double t0, t1;
            if (clip(px, py, x, y, cx0, cy0, cx1, cy1, &t0, &t1))
                dash_segment(cb, px, py, x, y, t0, t1, s->dash, width, &phase);
            else
                phase = fmod(phase + hypot(x - px, y - py), 1e6);
        }
        px = x;
        py = y;
        run++;
    }
    cov_composite(img, cb, to_linear(s->color));
}

static void draw_legend(rs_image *img, const frame *f, const pl_series *series, size_t n,
                        int scale)
{
    const pl_chart *ch = f->ch;
    int cols = ch->legend_columns > 0 ? ch->legend_columns : 1;
    int count = 0, label_w = 0;
    int sample = 14 * scale + 4, pad = 3 * scale + 2, row_h = LINE_H * scale + 2;

    for (size_t i = 0; i < n; i++)
        if (series[i].label) {
            int w = pl_text_width(series[i].label, scale);
            if (w > label_w)
                label_w = w;
            count++;
        }
    if (count == 0 || ch->legend == PL_LEGEND_NONE)
        return;
    if (cols > count)
        cols = count;
    int rows = (count + cols - 1) / cols;
    int entry_w = sample + 2 * scale + label_w + 4 * scale;
    int box_w = cols * entry_w - 4 * scale + 2 * pad, box_h = rows * row_h + 2 * pad - 2;
    int inset = 6;
    int bx_left = ch->legend == PL_LEGEND_TOP_LEFT || ch->legend == PL_LEGEND_BOTTOM_LEFT ||
                  ch->legend == PL_LEGEND_LEFT;
    int by = (ch->legend == PL_LEGEND_TOP_LEFT || ch->legend == PL_LEGEND_TOP_RIGHT)
                 ? f->y0 + inset
             : (ch->legend == PL_LEGEND_LEFT || ch->legend == PL_LEGEND_RIGHT)
                 ? f->y0 + (f->h - box_h) / 2
                 : f->y0 + f->h - inset - box_h;

    int bx = bx_left ? f->x0 + inset : f->x0 + f->w - inset - box_w;

    fill_rect(img, bx, by, box_w, box_h, to_linear(0xFFFFFFu));
    lin border = to_linear(0xA0A0A0u);
    fill_rect(img, bx, by, box_w, 1, border);
    fill_rect(img, bx, by + box_h - 1, box_w, 1, border);
    fill_rect(img, bx, by, 1, box_h, border);
    fill_rect(img, bx + box_w - 1, by, 1, box_h, border);

    float buf[(14 * 8 + 4 + 8) * (LINE_H * 8 + 8)];
    int k = 0;
    for (size_t i = 0; i < n; i++) {
        if (!series[i].label)
            continue;
        int r = k / cols, c = k % cols;
        int ex = bx + pad + c * entry_w, ey = by + pad + r * row_h;
        int cy = ey + (GLYPH_H * scale) / 2;
        double width = series[i].width > 0.0 ? series[i].width : 2.0;
        covbuf cb = {buf, ex, ey - 2, sample, GLYPH_H * scale + 4};
        if (sample * (GLYPH_H * scale + 4) <= (int)(sizeof buf / sizeof buf[0])) {
            double phase = 0.0;
            memset(buf, 0, sizeof buf);
            dash_segment(&cb, ex + 0.5 * width + 1.0, cy + 0.5, ex + sample - 0.5 * width - 1.0,
                         cy + 0.5, 0.0, 1.0, series[i].dash, width, &phase);
            cov_composite(img, &cb, to_linear(series[i].color));
        }
        draw_text(img, ex + sample + 2 * scale, ey, scale, to_linear(C_TEXT), series[i].label,
                  0);
        k++;
    }
}

int pl_draw(rs_image *img, int x, int y, int w, int h, const pl_chart *ch,
            const pl_series *series, size_t n_series, char *msg, size_t msg_size)
{
    int s = ch && ch->text_scale > 0 ? ch->text_scale : 2;
    tick_set xt, yt;
    frame f;

    if (!img || !img->rgb || !ch) {
        if (msg && msg_size)
            snprintf(msg, msg_size, "plot: no image or chart");
        return -1;
    }
    if (s > 8)
        s = 8;
    if (!(ch->xmin < ch->xmax) || !(ch->ymin < ch->ymax) || !isfinite(ch->xmin) ||
        !isfinite(ch->xmax) || !isfinite(ch->ymin) || !isfinite(ch->ymax) ||
        (ch->ylog && !(ch->ymin > 0.0))) {
        if (msg && msg_size)
            snprintf(msg, msg_size, "plot '%s': invalid axis range", ch->title ? ch->title : "");
        return -1;
    }
    x_ticks(ch, &xt);
    y_ticks(ch, &yt);

    int th = GLYPH_H * s, tick = 5;
    int ytw = 0;
    for (int i = 0; i < yt.n; i++) {
        int tw = pl_text_width(yt.label[i], s);
        if (tw > ytw)
            ytw = tw;
    }
    int top = ch->title ? th + 3 * s + 8 : 10;
    int left = 6 + (ch->ylabel ? th + 4 * s : 0) + ytw + 4 + tick;
    int bottom = tick + 4 + th + (ch->xlabel ? 4 * s + th : 0) + 8;
    int right = 8 + (xt.n > 0 ? pl_text_width(xt.label[xt.n - 1], s) / 2 : 0);
    f.x0 = x + left;
    f.y0 = y + top;
    f.w = w - left - right;
    f.h = h - top - bottom;
    f.ch = ch;
    f.ly0 = ch->ylog ? log10(ch->ymin) : ch->ymin;
    f.ly1 = ch->ylog ? log10(ch->ymax) : ch->ymax;
    if (f.w < 20 || f.h < 20) {
        if (msg && msg_size)
            snprintf(msg, msg_size, "plot '%s': %dx%d pixels is too small",
                     ch->title ? ch->title : "", w, h);
        return -1;
    }

    lin text = to_linear(C_TEXT), frame_c = to_linear(C_FRAME);
    lin grid = to_linear(C_GRID);

    /* grid */
    for (int i = 0; i < xt.n; i++)
        fill_rect(img, (int)map_x(&f, xt.v[i]), f.y0, 1, f.h, grid);
    for (int i = 0; i < yt.n; i++) {
        double py = ch->ylog ? map_y(&f, pow(10.0, yt.v[i])) : map_y(&f, yt.v[i]);
        fill_rect(img, f.x0, (int)py, f.w, 1, grid);
    }

    /* series, then markers over them */
    covbuf cb;
    cb.x0 = f.x0 - 4;
    cb.y0 = f.y0 - 4;
    cb.w = f.w + 8;
    cb.h = f.h + 8;
    cb.c = calloc((size_t)cb.w * (size_t)cb.h, sizeof *cb.c);
    if (!cb.c) {
        if (msg && msg_size)
            snprintf(msg, msg_size, "plot: out of memory");
        return -1;
    }
    for (size_t i = 0; i < n_series; i++)
        if (series[i].n > 0 && series[i].x && series[i].y)
            stroke_series(img, &cb, &f, &series[i]);
    for (size_t i = 0; i < ch->n_markers; i++) {
        double mx = map_x(&f, ch->markers[i].x), phase = 0.0;
        if (!(mx >= f.x0 && mx <= f.x0 + f.w))
            continue;
        dash_segment(&cb, mx, f.y0, mx, f.y0 + f.h, 0.0, 1.0, PL_DASHED, 1.5, &phase);
        cov_composite(img, &cb, to_linear(C_MARKER));
        if (ch->markers[i].label) {
            int lw = pl_text_width(ch->markers[i].label, s);
            int lx = (int)mx + 2 * s;
            if (lx + lw > f.x0 + f.w - 2)
                lx = (int)mx - 2 * s - lw;
            int ly = f.y0 + 3 * s + (int)(i % 2) * (LINE_H * s + 2);
            fill_rect(img, lx - 2, ly - 2, lw + 4, th + 4, to_linear(0xFFFFFFu));
            draw_text(img, lx, ly, s, to_linear(C_MARKER), ch->markers[i].label, 0);
        }
    }
    free(cb.c);

    /* frame and ticks */
    fill_rect(img, f.x0 - 1, f.y0 - 1, f.w + 2, 1, frame_c);
    fill_rect(img, f.x0 - 1, f.y0 + f.h, f.w + 2, 1, frame_c);
    fill_rect(img, f.x0 - 1, f.y0 - 1, 1, f.h + 2, frame_c);
    fill_rect(img, f.x0 + f.w, f.y0 - 1, 1, f.h + 2, frame_c);
    for (int i = 0; i < xt.n; i++) {
        int px = (int)map_x(&f, xt.v[i]);
        fill_rect(img, px, f.y0 + f.h, 1, tick, frame_c);
        int lw = pl_text_width(xt.label[i], s);
        draw_text(img, px - lw / 2, f.y0 + f.h + tick + 4, s, text, xt.label[i], 0);
    }
    for (int i = 0; i < yt.n; i++) {
        double v = ch->ylog ? pow(10.0, yt.v[i]) : yt.v[i];
        int py = (int)map_y(&f, v);
        fill_rect(img, f.x0 - tick - 1, py, tick, 1, frame_c);
        if (i % yt.label_every)
            continue;
        int lw = pl_text_width(yt.label[i], s);
        draw_text(img, f.x0 - tick - 5 - lw, py - th / 2, s, text, yt.label[i], 0);
    }

    /* labels */
    if (ch->title) {
        /* a title too wide for the chart gets a smaller font */
        int ts = s, tw = pl_text_width(ch->title, ts);
        while (tw > w - 8 && ts > 1)
            tw = pl_text_width(ch->title, --ts);
        int tx = f.x0 + (f.w - tw) / 2;
        if (tx + tw > x + w - 4)
            tx = x + w - 4 - tw;
        if (tx < x + 4)
            tx = x + 4;
        draw_text(img, tx, y + 6 + (s - ts) * GLYPH_H / 2, ts, text, ch->title, 0);
    }
    if (ch->xlabel) {
        int tw = pl_text_width(ch->xlabel, s);
        draw_text(img, f.x0 + (f.w - tw) / 2, f.y0 + f.h + tick + 4 + th + 4 * s, s, text,
                  ch->xlabel, 0);
    }
    if (ch->ylabel) {
        int tw = pl_text_width(ch->ylabel, s);
        draw_text(img, x + 6, f.y0 + (f.h + tw) / 2, s, text, ch->ylabel, 1);
    }
    draw_legend(img, &f, series, n_series, s);
    return 0;
}
