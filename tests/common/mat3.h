/* mat3.h -- the inverse of a 3x3 matrix, for the tests that undo the
 * renderer's colour correction (written here, not taken from the code
 * under test). */
#ifndef LP_TEST_MAT3_H
#define LP_TEST_MAT3_H

/* out = a^-1 by cofactors (a must be invertible). */
static inline void mat3_invert(const double a[3][3], double out[3][3])
{
    double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                 a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                 a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
            out[i][j] = (a[i1][j1] * a[i2][j2] - a[i1][j2] * a[i2][j1]) / det;
        }
}

#endif
