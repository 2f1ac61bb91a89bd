/* kdtree_stream_walk8.c - the ray stream's walk (kdtree_stream_walk.c)
 * compiled for 8 lanes with AVX2, by a target pragma whatever the build's
 * flags (x86 with GCC or clang, as kdtree_trace.c's AVX2 kernels), as
 * rt_kd_stream_walk8.
 */
#include "kdtree_internal.h"

#ifdef KD_HAVE_AVX2
#define KD_STREAM_LANES 8
#define KD_STREAM_WALK rt_kd_stream_walk8
#define KD_STREAM_SETUP rt_kd_stream_setup8
#if defined(__clang__)
#define KD_STREAM_BEGIN _Pragma("clang attribute push (__attribute__((target(\"avx2\"))), apply_to = function)")
#define KD_STREAM_END _Pragma("clang attribute pop")
#else
#define KD_STREAM_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx2\")")
#define KD_STREAM_END _Pragma("GCC pop_options")
#endif
#include "kdtree_stream_walk.c"
#else
typedef int kd_stream_walk_no_avx2; /* (ISO C wants something in a file) */
#endif
