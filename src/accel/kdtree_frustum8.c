/* kdtree_frustum8.c - the frustum walk (kdtree_frustum.c) compiled for 8
 * lanes with AVX2 and FMA, by a target pragma whatever the build's flags
 * (x86 with GCC or clang, as kdtree_trace.c's AVX2 kernels), as
 * rt_kd_frustum_walk8, for CPUs without AVX-512.
 */
#include "kdtree_internal.h"

#ifdef KD_HAVE_AVX2
#define KD_PW 8
#define KD_FRUSTUM_WALK rt_kd_frustum_walk8
#define KD_PBEGIN KD_AVX2_BEGIN
#define KD_PEND KD_AVX2_END
#define KD_FRUSTUM_WALK_ONLY 1
#include "kdtree_frustum.c"
#else
typedef int kd_frustum_walk_no_avx2; /* (ISO C wants something in a file) */
#endif
