/* quadrature.h -- the spectral quadrature of the spectral modes: where a
 * pixel's N wavelengths lie in 380-780 nm and what each weighs
 * (renderer-internal).
 *
 * Every RGB colour becomes a spectrum by Smits' method (pigments, mirror
 * colours, RGB lights and the background; support/colorimetry.h), and
 * Smits' spectra are constant on each of 10 pieces of the band, [380,
 * 414), [414, 448) ... [652, 686), [686, 780], stepping at the 9 inner
 * edges only (RS_SMITS_*).  The quadrature is the midpoint rule on N
 * cells that never straddle such an edge: a lit coloured surface's
 * spectrum is then smooth inside every cell (D65, the colour-matching
 * functions and the glasses' absorption are interpolated tables, with
 * kinks but no steps; Fresnel factors, black bodies and interference are
 * smooth), and where a path does not change with the wavelength the
 * error falls as 1/N^2.  On equal bands a cell holds a step wherever an
 * edge falls inside it: the error falls only as 1/N, and not
 * monotonically (a count whose band edges happen to meet Smits' edges is
 * "lucky").
 *
 *   N >= 10: each piece is cut into equal cells, at least one; each
 *            further cell goes to the piece where it lowers the most
 *            the midpoint rule's error bound for D65 light, sum over
 *            pieces of (width / count)^2 / 8 times the total variation
 *            of the derivative of D65 x the sRGB channels' colour-
 *            matching functions there: the blue and green pieces get
 *            more cells than the red end, where the eye sees little
 *            (16 cells: 17 nm from 414 to 618 nm, 34 nm at 380-414 and
 *            618-686, one of 94 nm above 686).
 *   N < 10:  no N cells can keep all 9 steps out; the cells are N equal
 *            bands (the rule before this one).  Whole pieces joined into
 *            N cells were measured no better overall (fresnel, 11 scenes
 *            at 32 x 24: better at 5, 7 and 9 cells, alike at 4, worse
 *            at 3 and 6; joined by their error bound, worse at 4 by 2-14x:
 *            with so few nodes what counts is where they fall on the
 *            colour-matching functions' peaks, not the steps).
 *
 * Lines of monochromatic lights are deltas, outside this quadrature. */
#ifndef RS_QUADRATURE_H
#define RS_QUADRATURE_H

#include "support/colorimetry.h"

/* The most pieces there can be. */
#define RS_QUADRATURE_MAX_PIECES (RS_SMITS_BINS + 1)

/* The pieces of the band between Smits' steps: edge[0] = 380 nm ...
 * edge[count] = 780 nm, ascending.  Returns the count (10). */
int rs_quadrature_pieces(double edge[RS_QUADRATURE_MAX_PIECES + 1]);

/* The n cells (n >= 1): lambda[k] the midpoint of cell k, ascending, in
 * nm in standard air, and weight[k] its width in nm; the widths add up to
 * RS_LAMBDA_MAX - RS_LAMBDA_MIN = 400 nm.  A pure function of n. */
void rs_quadrature(int n, double *lambda, double *weight);

#endif
