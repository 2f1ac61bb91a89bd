/* kdtree_stream_walk4.c - the ray stream's walk (kdtree_stream_walk.c)
 * compiled for 4 lanes and the build's target (SSE on x86-64; plain code
 * elsewhere), as rt_kd_stream_walk4: the width every machine runs.
 */
#define KD_STREAM_LANES 4
#define KD_STREAM_WALK rt_kd_stream_walk4
#define KD_STREAM_SETUP rt_kd_stream_setup4
#define KD_STREAM_BEGIN
#define KD_STREAM_END
#include "kdtree_stream_walk.c"
