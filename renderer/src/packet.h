/* packet.h -- spectral packets: which wavelengths can share one path
 * (renderer-internal).
 *
 * A pixel's wavelengths ("lanes") are traced together, as one packet,
 * while they meet the same surfaces in the same order: one scene
 * intersection, one lens-hit search and one node set-up serve every lane
 * whose lens optics are equal there.  That is every lane at a lens of
 * constant index (no dispersion, or --no-dispersion) and at every object
 * that is not a lens; at a dispersive lens the packet splits into
 * sub-packets of lanes with equal optics (usually one lane each), and each
 * goes on its own way.  Since a shared computation is the very one each
 * lane would have done alone, a packet's result equals the per-wavelength
 * trace's bit for bit.
 *
 * This file holds only the bookkeeping: the classes of lanes with equal
 * optics at each lens, computed once per render, and the split. */
#ifndef RS_PACKET_H
#define RS_PACKET_H

#include "scene.h"

typedef struct rs_lane_classes rs_lane_classes;

/* For every lens of the scene and every lane (wavelength lambda[k] in
 * air), the first lane whose optics at that lens (glass index, medium
 * index, absorption, and whether the glasses' data cover the wavelength)
 * are equal to its own.  Returns 0, or -1 when memory runs out. */
int rs_lane_classes_create(const rs_scene *scene, const double *lambda, int n_lanes,
                           rs_lane_classes **out);
void rs_lane_classes_destroy(rs_lane_classes *c); /* NULL: no-op */

/* The class of lane k at object i (k itself for an object that is not a
 * lens: every lane is alike there). */
int rs_lane_class(const rs_lane_classes *c, int object, int lane);

/* The sub-packets of lane[0..n) at object i: the first lane and every
 * later one of its class, then the first lane left and its class, and so
 * on.  Sub-packet s holds the positions in lane[] pos[at[s] .. at[s+1]),
 * in order; returns how many sub-packets (at[] has one more entry).  sub
 * is scratch for n entries; slot for n_lanes entries, every one -1 on
 * entry, and so again on return.  O(n). */
int rs_packet_split(const rs_lane_classes *c, int object, const int *lane, int n, int *at,
                    int *pos, int *sub, int *slot);

#endif
