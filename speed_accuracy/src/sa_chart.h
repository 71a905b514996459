/* sa_chart.h -- the speed-accuracy chart and the page that explains it
 * (speed_accuracy).
 *
 * From the measured points, writes DIR/speed-accuracy.png (one panel per
 * scene: error against time, both logarithmic; every swept setting a grey
 * cross, their Pareto front a line, POV-Ray's point, auto's three points,
 * the tolerances as dotted lines) and DIR/speed-accuracy.md (how to read
 * it, and per scene and tolerance auto's choice, error and time against
 * the cheapest swept setting that met the tolerance).  Returns 0, or -1
 * with a message. */
#ifndef SA_CHART_H
#define SA_CHART_H

#include <stddef.h>

#include "sa_point.h"

int sa_chart_write(const sa_points *ps, const char *dir, char *msg, size_t msg_size);

#endif
