/* colorimetry.h -- CIE colorimetry, D65, Smits' spectra, black bodies and
 * linear sRGB (support floor: used by every program, depends on nothing of
 * the renderer).
 *
 * Everything here is a pure function of its arguments over constant
 * tables: no state, safe from any thread.  Wavelengths are in nanometres
 * in standard air, as the CIE tables give them.
 *
 * Tables (sources cited in colorimetry.c):
 *   - CIE 1931 2-degree colour-matching functions x̄ ȳ z̄, 360-830 nm at
 *     1 nm, linearly interpolated in between, 0 outside.
 *   - CIE standard illuminant D65, relative SPD (100 at 560 nm),
 *     300-830 nm at 5 nm, linearly interpolated, 0 outside.
 *   - Smits' seven basis reflectances (10 bins over 380-720 nm).
 *
 * ---- RGB colours as spectra ----------------------------------------------
 *
 * Reflectances (pigments): rs_reflectance(), Smits' method (B. Smits, "An
 * RGB-to-spectrum conversion for reflectances", Journal of Graphics Tools
 * 4(4):11-22, 1999).  A colour is split into white + one secondary (cyan,
 * magenta or yellow) + one primary (red, green or blue):
 *     min component m:  m * white
 *     the two other components a <= b (channels A, B):
 *         (a - m) * secondary(A+B) + (b - a) * primary(B)
 * each basis being a piecewise-constant spectrum over 10 equal bins of
 * 380-720 nm (bin k covers [380 + 34k, 380 + 34(k+1)); below 380 nm the
 * first bin's value, above 720 nm the last one's).  The sum is clamped to
 * [0, 1].  The white basis is taken as exactly 1 (Smits' table has
 * 0.9992-1.0000, a fitting residue), so that white reflects everything and
 * black nothing.  Smits' method is approximate: the spectrum of a linear
 * sRGB colour, lit by D65 and converted back, gives the colour to within
 * about 0.05 per channel for the primaries and secondaries (worst: cyan's
 * red channel, -0.049; pure red gives (1.041, 0.001, 0.003)).
 *
 * ---- Linear sRGB ---------------------------------------------------------
 *
 * The IEC 61966-2-1 (sRGB) primaries (0.64,0.33) (0.30,0.60) (0.15,0.06)
 * and D65 white (0.3127,0.3290): the RGB->XYZ matrix computed from these
 * at full double precision, and its exact inverse.  Rounded to four
 * decimals the forward matrix is the one printed in the standard
 * (0.4124 0.3576 0.1805 / 0.2126 0.7152 0.0722 / 0.0193 0.1192 0.9505);
 * the inverse agrees with the printed XYZ->RGB matrix (3.2406 -1.5372
 * -0.4986 / ...) to 4e-4, the printed one being the inverse of the
 * rounded forward matrix. */
#ifndef SUPPORT_COLORIMETRY_H
#define SUPPORT_COLORIMETRY_H

/* A linear RGB colour. */
typedef struct rs_color {
    double r, g, b;
} rs_color;

/* The band the spectral modes sample, nm. */
#define RS_LAMBDA_MIN 380.0
#define RS_LAMBDA_MAX 780.0

/* Smits' bins: bin k covers [RS_SMITS_FIRST_NM + k RS_SMITS_BIN_NM,
 * RS_SMITS_FIRST_NM + (k + 1) RS_SMITS_BIN_NM), k = 0 .. RS_SMITS_BINS - 1,
 * nm; below the first bin its value holds, above the last bin (720 nm)
 * the last one's.  Every RGB colour's spectrum (rs_reflectance,
 * rs_emission_shape) is therefore constant on each of [380, 414), [414,
 * 448) ... [652, 686) and [686, 780] and steps only at the 9 inner edges
 * 414, 448 ... 686 nm (none at 720). */
#define RS_SMITS_FIRST_NM 380.0
#define RS_SMITS_BIN_NM 34.0
#define RS_SMITS_BINS 10

/* Where the colour-matching table is defined (0 outside), nm. */
#define RS_CMF_MIN_NM 360.0
#define RS_CMF_MAX_NM 830.0

/* Representative wavelengths of the rgb mode's three channels (R, G, B),
 * nm: {642.4, 543.0, 440.8}.  Each is the first moment of its channel's
 * response to D65 light, i.e. of w_c(lambda) = D65(lambda) * (M^-1
 * cmf(lambda))_c with M^-1 the XYZ->linear sRGB matrix, over 380-780 nm:
 *     lambda_c = integral(lambda w_c) / integral(w_c).
 * A glass index that varies linearly with wavelength across the band then
 * bends each channel of a white beam, on average, exactly as the spectral
 * modes do, so rgb-mode colour fringes match the spectral ones to first
 * order.  (The CIE 1931 RGB primaries 700 / 546.1 / 435.8 nm would put
 * red far out in the tail of its channel's response.) */
extern const double RS_RGB_LAMBDA[3];

/* CIE 1931 2-degree colour-matching functions at lambda_nm, linearly
 * interpolated in the 1 nm table; 0 outside 360-830 nm. */
void rs_cmf(double lambda_nm, double xyz[3]);

/* CIE standard illuminant D65, relative spectral power (100 at 560 nm),
 * linearly interpolated in the 5 nm table; 0 outside 300-830 nm. */
double rs_d65(double lambda_nm);

/* Luminance of a linear sRGB colour: 0.2126 r + 0.7152 g + 0.0722 b. */
double rs_luminance(rs_color c);

/* Smits' reflectance spectrum of the colour c at lambda_nm, in [0, 1].
 * Negative components count as 0. */
double rs_reflectance(rs_color c, double lambda_nm);

/* The relative spectrum of an RGB EMITTER (before the D65 factor): linear
 * in c, c.r s_R + c.g s_G + c.b s_B with Smits' red, green and blue
 * spectra normalized to add up to exactly 1 at every wavelength (negative
 * components count as 0).  Linear, so a renderer can undo the colour error
 * of its own wavelength quadrature with one 3x3 matrix and reproduce every
 * emitter's RGB exactly (integrator.c does). */
double rs_emission_shape(rs_color c, double lambda_nm);

/* 1/K, K = integral over 380-780 nm of D65(lambda) ȳ(lambda) dlambda
 * (exact for the interpolated tables: K = 10567.0315473943...). */
double rs_spectral_normalization(void);

/* Spectral radiance of a black body (Planck's law) at temperature_k,
 * W sr^-1 m^-2 nm^-1; 0 for temperature_k <= 0 or lambda_nm <= 0. */
double rs_planck(double temperature_k, double lambda_nm);

/* xyz += weight * radiance * cmf(lambda_nm). */
void rs_xyz_accumulate(double xyz[3], double radiance, double lambda_nm,
                       double weight);

/* CIE XYZ (Y = 1 for white) <-> linear sRGB (D65), no clamping. */
void rs_xyz_to_linear_srgb(const double xyz[3], rs_color *rgb);
void rs_linear_srgb_to_xyz(const rs_color *rgb, double xyz[3]);

/* The sRGB transfer function (IEC 61966-2-1): 12.92 v for v <= 0.0031308,
 * else 1.055 v^(1/2.4) - 0.055; input clamped to [0, 1] first, NaN -> 0. */
double rs_srgb_encode(double linear);
/* Its inverse: v / 12.92 for v <= 0.04045, else ((v + 0.055) / 1.055)^2.4;
 * input clamped to [0, 1], NaN -> 0. */
double rs_srgb_decode(double encoded);

/* The 8-bit sRGB code of a linear value, (int)(rs_srgb_encode(v) * 255 +
 * 0.5), without a power per value: the table holds, for each code k in
 * 1..255, the least float that takes code k or more; a value's code is the
 * number of entries at or below it (found in 8 comparisons).  It gives the
 * formula's byte for every float (the formula is non-decreasing in v; the
 * test checks each entry and its neighbours). */
typedef struct rs_srgb8_table {
    float at_least[256]; /* [k]: least float of code >= k; [0] unused */
} rs_srgb8_table;

/* Fills t (once per image: 255 bisections of 30 steps, ~7700 power
 * evaluations, about 0.26 ms). */
void rs_srgb8_table_init(rs_srgb8_table *t);

/* The code of v by the formula (NaN and v <= 0: 0; v >= 1: 255). */
unsigned char rs_srgb8_by_formula(float v);

/* The same code from the table. */
static inline unsigned char rs_srgb8(const rs_srgb8_table *t, float v)
{
    unsigned k = 0;
    if (!(v > 0.0f))
        return 0;
    for (unsigned step = 128; step > 0; step >>= 1)
        if (k + step <= 255 && t->at_least[k + step] <= v)
            k += step;
    return (unsigned char)k;
}

#endif
