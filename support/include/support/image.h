/* image.h -- float RGB images, their files (PNG, PFM) and the metrics that
 * compare them (support floor).
 *
 * An rs_image holds linear RGB as floats, 3 per pixel, row 0 at the top:
 * pixel (x, y) is rgb[3 * ((size_t)y * width + x) + c], c = 0, 1, 2.
 *
 * Every function returning int returns 0, or -1 with a one-line message
 * in msg (msg may be NULL when msg_size is 0).  No state: safe from any
 * thread on distinct images and paths.
 *
 * Writing is atomic: the file is written to "<path>.tmp.<pid>" in the
 * same directory, flushed and fsync'ed, closed, then renamed over path.  On
 * any failure the temporary file is removed and whatever was at path is
 * left untouched; a reader never sees a half-written file.  (The
 * temporary file is created exclusively; a stale regular file or symlink
 * of that name is replaced, anything else there makes the write fail.
 * When path is a symlink, the link itself is replaced.)  A path that
 * exists and is neither a regular file nor a directory -- a device such
 * as /dev/null or /dev/stdout, a FIFO -- is written in place instead,
 * with no temporary file: renaming one over it would replace it. */
#ifndef RS_IMAGE_H
#define RS_IMAGE_H

#include <stddef.h>

typedef struct rs_image {
    int width, height;
    float *rgb; /* 3 * width * height linear RGB values, row 0 = top */
} rs_image;

/* Limits on image size (also applied to the files read, so a corrupt
 * header cannot ask for absurd memory). */
#define RS_IMAGE_MAX_SIDE 1000000
#define RS_IMAGE_MAX_PIXELS ((size_t)1 << 28) /* 3 GiB of floats */

/* Allocate a width x height image filled with zeros, 1 <= width, height
 * <= RS_IMAGE_MAX_SIDE, width * height <= RS_IMAGE_MAX_PIXELS.  On failure
 * img is left empty ({0, 0, NULL}). */
int rs_image_create(rs_image *img, int width, int height);
/* Free the pixels and empty the image (safe on an empty image). */
void rs_image_free(rs_image *img);

/* 8-bit sRGB PNG: each value is encoded with the sRGB transfer function
 * (clamped to [0,1], NaN -> 0) and stored as floor(v * 255 + 0.5), no
 * dithering.  The file carries an sRGB chunk (perceptual intent) and, for
 * readers without sRGB support, gAMA 45455 and the sRGB cHRM. */
int rs_png_write(const char *path, const rs_image *img, char *msg,
                 size_t msg_size);

/* 16-bit linear PNG: floor(clamp(v, 0, 1) * 65535 + 0.5), with gAMA
 * 100000 (linear) and the sRGB cHRM.  For references that must keep
 * linear values; rs_png_read gives them back to within 1/131070. */
int rs_png_write16_linear(const char *path, const rs_image *img, char *msg,
                          size_t msg_size);

/* Read a PNG (gray, gray+alpha, RGB, RGBA or palette; any bit depth;
 * interlaced or not) into out as RGB floats sample / (2^depth - 1), with
 * NO gamma decoding: the stored numbers as they are (POV-Ray's 16-bit
 * linear renders and our 16-bit references read back linear; an 8-bit
 * sRGB file reads back sRGB-encoded).  Gray is copied to R, G and B;
 * alpha and tRNS are dropped; palette entries are 8-bit.  *bit_depth
 * (may be NULL) gets the file's bit depth (1, 2, 4, 8 or 16; palette
 * files report 8).  out is overwritten (not freed first); on failure it
 * is left empty. */
int rs_png_read(const char *path, rs_image *out, int *bit_depth, char *msg,
                size_t msg_size);

/* Portable FloatMap: "PF\n<w> <h>\n-1.0\n" then float32 little-endian RGB,
 * rows bottom to top.  Values are stored bit-exactly (NaN and infinities
 * included).  Atomic like rs_png_write. */
int rs_pfm_write(const char *path, const rs_image *img, char *msg,
                 size_t msg_size);

/* Read a PFM: "PF" (RGB) or "Pf" (gray, copied to R, G, B), either byte
 * order (scale < 0: little-endian, > 0: big-endian; its magnitude is
 * ignored).  out as for rs_png_read. */
int rs_pfm_read(const char *path, rs_image *out, char *msg, size_t msg_size);

/* ---- Metrics ------------------------------------------------------------
 * For linear RGB in [0, 1] (values are used as they are, not clamped).
 * Images of different sizes, or empty ones, give NAN. */

/* Root mean square difference over all pixels and channels. */
double rs_image_rmse(const rs_image *a, const rs_image *b);

/* Peak signal-to-noise ratio, dB, peak 1, over all channels:
 * -10 log10(MSE) = -20 log10(RMSE); INFINITY for identical images. */
double rs_image_psnr(const rs_image *a, const rs_image *b);

/* Mean structural similarity (Wang, Bovik, Sheikh, Simoncelli, "Image
 * quality assessment: from error visibility to structural similarity",
 * IEEE Trans. Image Processing 13(4), 2004) on the luminance
 * Y = 0.2126 R + 0.7152 G + 0.0722 B, with the paper's 11x11 circular
 * Gaussian window (sigma 1.5, weights normalised to 1), K1 = 0.01,
 * K2 = 0.03, dynamic range L = 1, so C1 = (0.01)^2, C2 = (0.03)^2; the
 * mean is over every window position that lies wholly inside the image
 * (no padding).  An image narrower or lower than 11 pixels is one window
 * with uniform weights over the whole image.  Identical images give 1. */
double rs_image_ssim(const rs_image *a, const rs_image *b);

#endif
