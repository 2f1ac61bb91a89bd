/* rt/render/medium.h - nested dielectrics: which medium a path is in, as a
 * small stack of the dielectric objects it has entered, resolved by
 * priority (Schmidt and Budge 2002, "Simple Nested Dielectrics in Ray
 * Traced Images", JGT 7(1)).
 *
 * A path carries one rt_medium_stack (a plain struct: in a register-sized
 * local for the scalar path tracer, or one column of a wavefront's
 * structure-of-arrays state); every function takes it by pointer and reads
 * the materials from the scene's table. Per hit on a surface of material
 * `mat` seen from its front (entering) or back (leaving):
 *
 *   rt_medium_stack media;
 *   rt_medium_stack_init(&media);                        // camera ray: outside everything
 *   ... hit sf:
 *   uint32_t seg = rt_medium_of_segment(&media, mats, sf.material, sf.front);
 *   beta = rt_mul(beta, rt_medium_transmittance(mats, seg, distance));  // Beer-Lambert
 *   if (rt_medium_false_hit(&media, mats, sf.material, sf.front)) {
 *       rt_medium_cross(&media, mats, sf.material, sf.front);  // record it, go straight on
 *       continue;
 *   }
 *   float n_out = rt_medium_outside_ior(&media, mats, sf.material, sf.front);
 *   // the interface's eta: front n_out / ior, back 1 / (n_out / ior) (rt_bsdf_set_eta)
 *   ... sample the BSDF; if it transmitted:
 *   rt_medium_cross(&media, mats, sf.material, sf.front);
 *
 * Rules (docs/shading.md, "Nested media"):
 * - Only `bsdf dielectric` materials are media here (`whitted` counts every
 *   transmissive material, through rt_medium_stack_*); every other surface
 *   is a plain boundary (a glTF KHR_materials_volume object keeps its own
 *   rule: a segment ending on its back ran inside it).
 * - The current medium is the entry of highest `priority` (ties: the one
 *   entered last); an empty stack is the outside, whose index is each
 *   object's own `exterior_ior` (default 1), so a scene without nesting
 *   renders as before.
 * - A hit is false (an interface that does not exist, because a
 *   higher-priority medium fills the overlap) when entering a medium of
 *   lower priority than the current one, or leaving one that is not the
 *   current one (a medium of higher priority, or of equal priority entered
 *   later, is still on the stack). The path goes straight on and the
 *   medium is pushed or removed.
 * - A true hit refracts between the current medium and the next one:
 *   entering, the current medium (or the outside) to `mat`; leaving,
 *   `mat` to the medium on top once `mat` is removed (or the outside).
 * - Overflow (entering with RT_MEDIUM_STACK_MAX entries): the oldest
 *   (outermost) entry is dropped. Underflow (leaving a medium that is not
 *   on the stack: a camera inside glass, an open mesh, a dropped entry):
 *   the hit is true, the segment is taken to have run inside `mat` (its
 *   absorption counts, as for a lone object) and the stack is unchanged.
 */
#ifndef RT_MEDIUM_H
#define RT_MEDIUM_H

#include <stdbool.h>
#include <stdint.h>

#include "rt/scene/scene.h"

#define RT_MEDIUM_STACK_MAX 8 /* nesting depth: a liquid in a glass with ice in it is 3 */

/* The media a path is inside, oldest first. The `whitted` integrator
 * carries the same struct under the same rules, with its own idea of a
 * medium (every transmissive surface: rt/render/whitted.h), through the
 * rt_medium_stack_* functions below. */
typedef struct rt_medium_stack {
    int depth;                              /* entries in use, 0..RT_MEDIUM_STACK_MAX */
    uint32_t material[RT_MEDIUM_STACK_MAX]; /* entered media (material ids), oldest first */
} rt_medium_stack;

void rt_medium_stack_init(rt_medium_stack *st);
/* Whether a material is a medium of the stack (bsdf dielectric). */
bool rt_medium_is_medium(const rt_material *m);
/* The medium the path is in: the highest priority entry (ties: the last
 * entered), RT_NONE outside everything. */
uint32_t rt_medium_current(const rt_medium_stack *st, const rt_material *mats);
/* The medium the segment that ends on this hit ran through (the current
 * one, or `mat` itself on the back of a medium the stack does not hold, or
 * of a glTF volume); RT_NONE for none. */
uint32_t rt_medium_of_segment(const rt_medium_stack *st, const rt_material *mats, uint32_t mat, bool front);
/* Beer-Lambert transmittance exp(-sigma d) of medium `medium` (RT_NONE:
 * 1) over distance d (rt_material_absorption's sigma). */
rt_vec3 rt_medium_transmittance(const rt_material *mats, uint32_t medium, float d);
/* True when the hit on `mat` is a false intersection: the path goes
 * straight through (only for media; false for any other material). */
bool rt_medium_false_hit(const rt_medium_stack *st, const rt_material *mats, uint32_t mat, bool front);
/* Index of refraction on the far side of `mat`'s surface from its
 * interior: entering, the current medium's; leaving, the one left on top
 * once `mat` is gone; `mat`'s exterior_ior when that is the outside. */
float rt_medium_outside_ior(const rt_medium_stack *st, const rt_material *mats, uint32_t mat, bool front);
/* The path crossed `mat`'s surface: push it (front) or remove its last
 * entry (back). Overflow drops the oldest entry; removing an absent
 * medium changes nothing. Non-media are ignored. */
void rt_medium_cross(rt_medium_stack *st, const rt_material *mats, uint32_t mat, bool front);

/* True when the hit on `mat` is a smooth dielectric with the same index
 * on both sides (rt_medium_outside_ior equals its own): light passes it
 * unbent and unreflected (Fresnel 0), so the media tracer passes it, paths
 * and shadow rays alike, as it passes a null boundary (an index-matched
 * subsurface material: docs/media.md). */
bool rt_medium_index_matched(const rt_medium_stack *st, const rt_material *mats, uint32_t mat, bool front);

/* rt_medium_false_hit and rt_medium_cross for a caller that decides
 * itself which materials are media: `mat` is taken to be one (the
 * functions above are these, for bsdf dielectric materials only). */
bool rt_medium_stack_false_hit(const rt_medium_stack *st, const rt_material *mats, uint32_t mat, bool front);
void rt_medium_stack_cross(rt_medium_stack *st, uint32_t mat, bool front);

#endif
