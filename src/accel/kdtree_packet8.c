/* kdtree_packet8.c - the packet walk (kdtree_packet.c) compiled for 8
 * lanes with AVX2 and FMA, by a target pragma whatever the build's flags
 * (x86 with GCC or clang, as kdtree_trace.c's AVX2 kernels), as
 * rt_kd_packet_walk8: 8-ray packets, and 16-ray packets as two vectors
 * where the CPU has no AVX-512.
 */
#include "kdtree_internal.h"

#ifdef KD_HAVE_AVX2
#define KD_PW 8
#define KD_PACKET_WALK rt_kd_packet_walk8
#define KD_PBEGIN KD_AVX2_BEGIN
#define KD_PEND KD_AVX2_END
#define KD_PACKET_WALK_ONLY 1
#include "kdtree_packet.c"
#else
typedef int kd_packet_walk_no_avx2; /* (ISO C wants something in a file) */
#endif
