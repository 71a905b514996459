/* spectrum.h -- colorimetry for the renderer's spectral modes
 * (renderer-internal).
 *
 * Everything here is a pure function of its arguments over constant
 * tables: no state, safe from any thread.  Wavelengths are vacuum
 * wavelengths in nanometres.
 *
 * Tables (sources cited in spectrum.c):
 *   - CIE 1931 2-degree colour-matching functions x̄ ȳ z̄, 360-830 nm at
 *     1 nm, linearly interpolated in between, 0 outside.
 *   - CIE standard illuminant D65, relative SPD (100 at 560 nm),
 *     300-830 nm at 5 nm, linearly interpolated, 0 outside.
 *   - Smits' seven basis reflectances (10 bins over 380-720 nm).
 *
 * ---- The spectral estimator ----------------------------------------------
 *
 * The integrator samples N stratified wavelengths over the band
 * [RS_LAMBDA_MIN, RS_LAMBDA_MAX] = [380, 780] nm (width 400 nm):
 *
 *     lambda_i = 380 + 400 (i + xi_i) / N,   i = 0..N-1, xi_i in [0,1)
 *
 * traces one ray per wavelength and gets a spectral radiance L(lambda_i)
 * at the camera that already includes the 1/K factor of the emitters
 * (rs_spectrum_emission does).  Then
 *
 *     XYZ = (400 / N) * sum_i L(lambda_i) * cmf(lambda_i)
 *
 * i.e. rs_xyz_accumulate(xyz, L(lambda_i), lambda_i, 400.0 / N) for each i,
 * and the pixel is rs_xyz_to_linear_srgb(xyz).  This is an unbiased (for
 * jittered xi) estimate of the integral of L * cmf over 380-780 nm.  The
 * emitters are normalised over the same band, so an RGB emitter of colour
 * (1,1,1) seen directly gives XYZ = D65 white (0.9504, 1, 1.0886) and
 * linear sRGB (1,1,1) to within 1e-3.
 *
 * Monochromatic (LINE) emitters are deltas: they are not sampled by the
 * stratified wavelengths (rs_spectrum_emission returns 0 for them); the
 * integrator traces one extra ray at line_nm with unit weight and adds
 *
 *     XYZ += T(line_nm) * rs_spectrum_line_xyz(light)
 *
 * where T is the path throughput (reflectances, Fresnel factors, ...) at
 * that wavelength; equivalently rs_xyz_accumulate(xyz, T *
 * rs_spectrum_line_power(light), line_nm, 1.0).
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
 * Emitters (rs_spectrum of type RGB): e(lambda) = D65(lambda) *
 * reflectance(c)(lambda) / K, K = integral over 380-780 nm of D65 * ȳ
 * (rs_spectral_normalization() = 1/K).  Colours brighter than 1 are
 * allowed: when max(r,g,b) = M > 1 the spectrum is M * reflectance(c/M),
 * so it scales linearly with the colour.
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
#ifndef RS_SPECTRUM_H
#define RS_SPECTRUM_H

#include "scene.h"

/* The band the spectral modes sample, nm. */
#define RS_LAMBDA_MIN 380.0
#define RS_LAMBDA_MAX 780.0

/* Where the colour-matching table is defined (0 outside), nm. */
#define RS_CMF_MIN_NM 360.0
#define RS_CMF_MAX_NM 830.0

/* Lines whose ȳ(lambda) is below this carry the power of a line with
 * ȳ = RS_LINE_YBAR_MIN (see rs_spectrum_line_power). */
#define RS_LINE_YBAR_MIN 1e-3

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

/* The scale factor of an emitter's spectrum, a function of the spectrum
 * alone: compute it once per light and pass it to
 * rs_spectrum_emission_norm.
 *   RGB:       1/K.
 *   BLACKBODY: luminance(tint) / integral over 380-780 nm of
 *              planck(T) ȳ  (0 when T <= 0 or the black body is too cold
 *              to give any visible power in double precision, T < ~50 K).
 *   LINE:      rs_spectrum_line_power(s). */
double rs_spectrum_norm(const rs_spectrum *s);

/* The emitted spectral radiance at lambda_nm given norm =
 * rs_spectrum_norm(s):
 *   RGB:       norm * D65(lambda) * rs_emission_shape(rgb, lambda).
 *              (1,1,1) -> Y = 1 over 380-780 nm.
 *   BLACKBODY: norm * planck(T, lambda): integrates over 380-780 nm to
 *              Y = luminance(tint), chromaticity that of the black body.
 *   LINE:      0 (a delta; see rs_spectrum_line_xyz). */
double rs_spectrum_emission_norm(const rs_spectrum *s, double norm,
                                 double lambda_nm);

/* rs_spectrum_emission_norm(s, rs_spectrum_norm(s), lambda_nm).  For a
 * BLACKBODY this integrates Planck's law (about 800 evaluations) on every
 * call: in loops, use the _norm form. */
double rs_spectrum_emission(const rs_spectrum *s, double lambda_nm);

/* The power P of a LINE emitter, in units where its XYZ is P * cmf(line):
 *     P = luminance(tint) / max(ȳ(line_nm), RS_LINE_YBAR_MIN)
 * so Y = luminance(tint) wherever ȳ >= 1e-3 (about 409-720 nm).  Farther
 * out the power is capped at that of a ȳ = 1e-3 line: deep violet and deep
 * red lines fade to black smoothly instead of carrying unbounded power
 * (their XYZ would otherwise grow as 1/ȳ).  0 outside 360-830 nm or for
 * other spectrum types. */
double rs_spectrum_line_power(const rs_spectrum *s);

/* XYZ of a LINE emitter: rs_spectrum_line_power(s) * cmf(line_nm), i.e.
 * Y = luminance(tint), XYZ = Y cmf / ȳ within 409-720 nm.  Zero for other
 * types. */
void rs_spectrum_line_xyz(const rs_spectrum *s, double xyz[3]);

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

#endif
