/* cap.c -- the sag of a spherical or flat cap (its intersection, which
 * every node needs, is inline in cap.h). */
#include <math.h>

#include "cap.h"

double lp__cap_sag(double c, double r)
{
    double cr = c * r;
    double root = 1.0 - cr * cr;
    return c * r * r / (1.0 + sqrt(root > 0.0 ? root : 0.0));
}
