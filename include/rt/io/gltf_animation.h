/* rt/io/gltf_animation.h - sampling glTF animation curves (keyframes) at a
 * time, as the glTF 2.0 specification defines them (section 3.11
 * "Animations" and Appendix C "Animation Sampler Interpolation Modes").
 *
 * A curve is n strictly increasing key times and the values at them:
 * LINEAR and STEP hold one value (ncomp floats) per key; CUBICSPLINE holds
 * three per key: in-tangent, value, out-tangent. Before the first key the
 * first value holds, after the last the last. Rotations (quat = true) are
 * unit quaternions x, y, z, w: LINEAR interpolates them by spherical linear
 * interpolation along the shorter arc, and every result is normalised.
 *
 *   float v[4];
 *   rt_anim_sample(RT_INTERP_LINEAR, times, n, values, 4, true, 0.5f, v);
 */
#ifndef RT_GLTF_ANIMATION_H
#define RT_GLTF_ANIMATION_H

#include <stdbool.h>
#include <stddef.h>

typedef enum rt_interp { RT_INTERP_LINEAR = 0, RT_INTERP_STEP, RT_INTERP_CUBICSPLINE } rt_interp;

/* out: ncomp floats (ncomp <= 64). n >= 1; times strictly increasing. */
void rt_anim_sample(rt_interp interp, const float *times, size_t n, const float *values, int ncomp, bool quat,
                    float t, float *out);

/* Spherical linear interpolation of unit quaternions a -> b (x, y, z, w),
 * the shorter way round; nearly equal ones are blended linearly. */
void rt_quat_slerp(const float a[4], const float b[4], float u, float out[4]);

#endif
