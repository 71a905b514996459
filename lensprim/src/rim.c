/* rim.c -- the opaque side of the lens: a cylinder or a cone segment.
 *
 * x^2 + y^2 = rho(z)^2 with rho(z) = rho_a + k (z - z_a), z in [z_a, z_b].
 * For p + t d this is  A t^2 + 2 B t + C = 0  with
 *     A = dx^2 + dy^2 - k^2 dz^2,
 *     B = px dx + py dy - k rho(pz) dz,
 *     C = px^2 + py^2 - rho(pz)^2. */
#include <math.h>

#include "lens_internal.h"
#include "vec3.h"

static double rho_at(const lp__rim *rim, double z)
{
    return rim->rho_a + rim->k * (z - rim->z_a);
}

int lp__rim_intersect(const lp__rim *rim, lp_vec3 p, lp_vec3 d, double t_min,
                      double t_max, double *t)
{
    if (!rim->present)
        return 0;
    double rp = rho_at(rim, p.z);
    double A = d.x * d.x + d.y * d.y - rim->k * rim->k * d.z * d.z;
    double B = p.x * d.x + p.y * d.y - rim->k * rp * d.z;
    double C = p.x * p.x + p.y * p.y - rp * rp;
    double roots[2];
    int n = 0;

    if (fabs(A) <= 1e-300) {
        if (B == 0.0)
            return 0;
        roots[n++] = -C / (2.0 * B);
    } else {
        double disc = B * B - A * C;
        if (disc < 0.0)
            return 0;
        double q = -(B + copysign(sqrt(disc), B));
        if (q != 0.0)
            roots[n++] = C / q;
        roots[n++] = q / A;
        if (n == 2 && roots[1] < roots[0]) {
            double tmp = roots[0];
            roots[0] = roots[1];
            roots[1] = tmp;
        }
    }
    double slack = rim->slack;
    for (int i = 0; i < n; i++) {
        double s = roots[i];
        if (!(s > t_min && s < t_max))
            continue;
        double z = p.z + s * d.z;
        if (z < rim->z_a - slack || z > rim->z_b + slack)
            continue;
        if (rho_at(rim, z) < 0.0) /* the other nappe of the cone */
            continue;
        *t = s;
        return 1;
    }
    return 0;
}

lp_vec3 lp__rim_normal(const lp__rim *rim, lp_vec3 p)
{
    /* gradient of x^2 + y^2 - rho(z)^2 */
    double r = rho_at(rim, p.z);
    return v3_normalize(v3(p.x, p.y, -rim->k * r));
}
