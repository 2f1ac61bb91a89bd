/* kdtree.c - the kd-tree's public queries (rt/accel/kdtree.h): the
 * portable traversal, and the choice between it and the AVX2 one (runtime
 * dispatch).
 *
 * kdtree_trace.c compiled a second time with KD_PORTABLE: the same
 * traversal with the wide step, the ray set-up and the leaf test as plain
 * loops (no SIMD), as rt_kd_intersect_portable / rt_kd_occluded_portable.
 * Then kdtree.h's rt_kdtree_intersect and rt_kdtree_occluded, which branch
 * once a ray on the kernels the tree chose when it was built
 * (rt_kdtree.isa), and rt_kd_isa_best, the build's choice: the AVX2
 * kernels when they are compiled in (x86 with GCC or clang, whatever the
 * -march: a PORTABLE=1 build has them too) and the CPU has AVX2 and FMA
 * (__builtin_cpu_supports, GCC's and clang's view of CPUID). This file is
 * compiled for the build's target, so it runs on any CPU of it. The build
 * itself is kdtree_build.c's and kdtree_pack.c's.
 */
#define KD_PORTABLE 1
#include "kdtree_trace.c"

rt_kd_isa rt_kd_isa_best(void)
{
#ifdef KD_HAVE_AVX2
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
        return RT_KD_ISA_AVX2;
#endif
    return RT_KD_ISA_PORTABLE;
}

int rt_kd_lanes_best(rt_kd_isa isa, int want)
{
    if (isa != RT_KD_ISA_AVX2)
        return 0;
#ifdef KD_HAVE_AVX2
    if (want != 8 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
        __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl"))
        return 16;
#endif
    (void)want;
    return 8;
}

bool rt_kdtree_intersect(const rt_kdtree *tree, const rt_ray *ray, rt_hit *hit)
{
#ifdef KD_HAVE_AVX2
    if (tree->isa == RT_KD_ISA_AVX2)
        return rt_kd_intersect_avx2(tree, ray, hit);
#endif
    return rt_kd_intersect_portable(tree, ray, hit);
}

bool rt_kdtree_occluded(const rt_kdtree *tree, const rt_ray *ray)
{
#ifdef KD_HAVE_AVX2
    if (tree->isa == RT_KD_ISA_AVX2)
        return rt_kd_occluded_avx2(tree, ray);
#endif
    return rt_kd_occluded_portable(tree, ray);
}
