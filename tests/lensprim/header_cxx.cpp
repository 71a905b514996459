// The public header compiles as C++ too (built only when a C++ compiler exists).
#include "lensprim.h"

int main()
{
    lp_lens_desc d;
    lp_lens_desc_init(&d);
    return d.axis.z == 1.0 ? 0 : 1;
}
