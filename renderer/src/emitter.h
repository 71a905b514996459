/* emitter.h -- the spectra of the scene's emitters and the spectral
 * estimator of the renderer's spectral modes (renderer-internal; the
 * colour tables are in support/colorimetry.h).
 *
 * ---- The spectral estimator ----------------------------------------------
 *
 * The integrator samples N wavelengths lambda_i over the band
 * [RS_LAMBDA_MIN, RS_LAMBDA_MAX] = [380, 780] nm (width 400 nm), the
 * midpoints of N cells of widths w_i (quadrature.h: cells that keep out
 * of the steps of Smits' spectra), traces one ray per wavelength and gets
 * a spectral radiance L(lambda_i) at the camera that already includes the
 * 1/K factor of the emitters (rs_spectrum_emission does).  Then
 *
 *     XYZ = sum_i w_i L(lambda_i) cmf(lambda_i)
 *
 * i.e. rs_xyz_accumulate(xyz, L(lambda_i), lambda_i, w_i) for each i, and
 * the pixel is rs_xyz_to_linear_srgb(xyz): the midpoint rule for the
 * integral of L * cmf over 380-780 nm.  The emitters are normalised over
 * the same band, so an RGB emitter of colour (1,1,1) seen directly gives
 * XYZ = D65 white (0.9504, 1, 1.0886) and linear sRGB (1,1,1) to within
 * 1e-3 (exactly, after the integrator's colour correction).
 *
 * Monochromatic (LINE) emitters are deltas: they are not sampled by the
 * N wavelengths (rs_spectrum_emission returns 0 for them); the
 * integrator traces one extra ray at line_nm with unit weight and adds
 *
 *     XYZ += T(line_nm) * rs_spectrum_line_xyz(light)
 *
 * where T is the path throughput (reflectances, Fresnel factors, ...) at
 * that wavelength; equivalently rs_xyz_accumulate(xyz, T *
 * rs_spectrum_line_power(light), line_nm, 1.0).
 *
 * Emitters (rs_spectrum of type RGB): e(lambda) = D65(lambda) *
 * reflectance(c)(lambda) / K, K = integral over 380-780 nm of D65 * ȳ
 * (rs_spectral_normalization() = 1/K).  Colours brighter than 1 are
 * allowed: when max(r,g,b) = M > 1 the spectrum is M * reflectance(c/M),
 * so it scales linearly with the colour. */
#ifndef RS_EMITTER_H
#define RS_EMITTER_H

#include "scene.h"
#include "support/colorimetry.h"

/* Lines whose ȳ(lambda) is below this carry the power of a line with
 * ȳ = RS_LINE_YBAR_MIN (see rs_spectrum_line_power). */
#define RS_LINE_YBAR_MIN 1e-3

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

#endif
