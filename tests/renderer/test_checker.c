/* test_checker.c -- POV-Ray's checker pattern at any distance: the square
 * of (x, y, z) has the colour of the parity of floor(x) + floor(y) +
 * floor(z), also where the coordinates are far beyond a long's range (a
 * plane met near grazing, 1e20 mm away: the fuzzer's render found the cast
 * to long overflowing there). */
#include <stdio.h>

#include "check.h"
#include "one_pixel.h"

int main(void)
{
    /* an orthographic camera straight above the point (x, 0, z) of a checker
     * floor of red and blue, lit by emission alone */
    static const struct { double x, z; int odd; } pts[] = {
        {0.5, 0.5, 0},   {1.5, 0.5, 1},    {-0.5, 0.5, 1},  {-1.5, -0.5, 1},
        {1e20, 0.5, 0},  {1e20, 1.5, 1},   {-1e20, -0.5, 1}, {3e300, 2.5, 0},
        {9007199254740993.0, 0.5, 0}, /* 2^53 + 1 rounds to 2^53: even */
    };
    char text[1024];
    for (size_t i = 0; i < sizeof pts / sizeof pts[0]; i++) {
        rs_color c;
        snprintf(text, sizeof text,
                 "camera { orthographic location <%.17g, 1, %.17g> look_at <%.17g, 0, %.17g> "
                 "sky z right x*0.001 up z*0.001 }\n"
                 "plane { y, 0 pigment { checker rgb <1, 0, 0>, rgb <0, 0, 1> } "
                 "finish { ambient 0 diffuse 0 emission 1 } }\n",
                 pts[i].x, pts[i].z, pts[i].x, pts[i].z);
        if (one_pixel(text, RS_MODE_RGB, 0, &c) != 0) {
            CHECK(0, "render at x = %g", pts[i].x);
            continue;
        }
        /* emission 1 of a pure colour in rgb mode: exact */
        CHECK(c.r == (pts[i].odd ? 0.0 : 1.0) && c.b == (pts[i].odd ? 1.0 : 0.0),
              "the square at (%g, %g) is %s (got %g %g %g)", pts[i].x, pts[i].z,
              pts[i].odd ? "the second colour" : "the first", c.r, c.g, c.b);
    }
    return check_finish("test_checker");
}
