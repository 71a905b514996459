/* test_header.c -- the public header stands alone as C11 (this file
 * includes nothing before it) and its plain-data defaults hold. */
#include "lensprim.h"

#include <stdio.h>
#include <string.h>

#include "check.h"

int main(void)
{
    lp_lens_desc d;
    lp_trace_args a;
    lp_result r;

    lp_lens_desc_init(&d);
    CHECK(d.axis.z == 1.0 && d.axis.x == 0.0 && d.axis.y == 0.0, "default axis is +z");
    CHECK(lp_glass_index(&d.medium, 550.0) == 1.0, "default medium is n = 1");
    lp_trace_args_init(&a);
    CHECK(a.mode == LP_MODE_POLARIZED && a.max_depth == 5 && a.min_weight == 0.0 &&
              a.filter == NULL && a.flags == 0,
          "trace defaults: polarized, depth 5, no cut, no filter");
    lp_result_init(&r);
    CHECK(r.count == 0 && r.rays == NULL, "an initialized result is empty");
    lp_result_release(&r);
    lp_result_release(NULL);
    lp_lens_destroy(NULL);
    lp_backward_destroy(NULL);
    lp_catalog_destroy(NULL);
    for (int s = LP_OK; s <= LP_ERROR_RANGE; s++)
        CHECK(lp_status_string((lp_status)s) != NULL && lp_status_string((lp_status)s)[0],
              "status %d has a string", s);
    CHECK(lp_status_string((lp_status)999) != NULL, "unknown status has a string");
    /* The status values are part of the contract. */
    CHECK(LP_OK == 0 && LP_ERROR_INVALID_ARGUMENT == 1 && LP_ERROR_INVALID_LENS == 2 &&
              LP_ERROR_INVALID_GLASS == 3 && LP_ERROR_UNKNOWN_GLASS == 4 &&
              LP_ERROR_UNSUPPORTED == 5 && LP_ERROR_PARSE == 6 && LP_ERROR_IO == 7 &&
              LP_ERROR_NO_MEMORY == 8 && LP_ERROR_RANGE == 9,
          "lp_status values 0..9 as documented");
    /* The library built is the header's version. */
    {
        char want[64];
        snprintf(want, sizeof want, "%d.%d.%d", LP_VERSION_MAJOR, LP_VERSION_MINOR,
                 LP_VERSION_PATCH);
        CHECK(lp_version_number() == LP_VERSION_NUMBER &&
                  lp_version_number() ==
                      LP_VERSION_MAJOR * 10000 + LP_VERSION_MINOR * 100 + LP_VERSION_PATCH,
              "lp_version_number %d", lp_version_number());
        CHECK(strcmp(lp_version_string(), want) == 0, "lp_version_string '%s', want '%s'",
              lp_version_string(), want);
    }
    return check_finish("header");
}
