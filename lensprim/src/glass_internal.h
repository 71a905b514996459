/* glass_internal.h -- a glass's absorption from logarithms computed once
 * (internal). */
#ifndef LP_GLASS_INTERNAL_H
#define LP_GLASS_INTERNAL_H

#include "lensprim.h"

/* ln_tau[i] = log(glass->tau[i]) for the glass's table (0 past it). */
void lp__glass_ln_tau(const lp_glass *glass, double ln_tau[LP_GLASS_TABLE_MAX]);

/* lp_glass_absorption(glass, lambda_nm), bit for bit, from the table
 * lp__glass_ln_tau filled (NULL: the logarithms are taken here). */
double lp__glass_absorption_ln(const lp_glass *glass, const double *ln_tau,
                               double lambda_nm);

#endif
