/* kdtree_trace.c - the kd-tree's traversal: the closest hit
 * (rt_kdtree_intersect) and any hit (rt_kdtree_occluded) along a ray,
 * exactly the hit brute force would find, over the arrays kdtree_pack.c
 * made (wide nodes, leaf blocks: a leaf's id list, then the triangles it
 * was the first to use; a triangle's id is its record's offset).
 *
 * Traversal: the recursive ray segment algorithm (Havran's thesis, "TA_B^rec",
 * and pbrt's KdTreeAccel) with a fixed stack, three levels per step. In a
 * wide node, each plane gives t = (split - o) / d, each cell the ray's t
 * interval through it (the parent interval cut by the near or far side of
 * its three planes), all 8 at once in AVX2 lanes; the cells' front-to-back
 * order depends only on the direction signs along the 7 planes' axes, so two
 * 128-entry tables give it. A step with one valid cell (most of them:
 * 48-73% on the benchmark sets, the descent to a surface ray's origin)
 * enters it before any of that ordering. Otherwise the nearest valid cell
 * is entered, the others
 * pushed farthest first (compacted by a permute from a 256-entry table);
 * a cell is popped only if it starts before the closest hit so far. The
 * nearest cell is taken through a switch on the cell number, not by indexing
 * the node with it: when the branch is predicted (coherent rays), the next
 * node's address is known as soon as this node is loaded (indexing made
 * primary rays 35% slower). The cells and intervals are exactly the binary
 * traversal's. Every primitive test uses the ray's own (tmin, closest-so-
 * far) interval, so t is what brute force would compute.
 * Exactness against rounding: cells are widened by a tiny distance mp
 * (2^-18 of the scene's and the origin's largest coordinate, 64 times the
 * float rounding of those coordinates) on every plane, so a hit whose
 * computed t lies a few ulps outside the cell of its primitive (edges shared
 * on a split plane, grazing hits) is still found before the traversal stops.
 * Without it the lattice and chaos tests fail; with 2^-24 they pass; the
 * widening costs under 1% of the steps on the benchmark scenes. An axis
 * along which the ray moves less than mp for any finite t (direction
 * component 0, or mp / |d| overflows) is "parallel": the side of a plane is
 * then decided by the origin (both sides within mp), without the 0 * inf =
 * NaN of the slab formula; such rays (rare) run a copy of the loop with
 * that case, the others a copy without it. Empty leaves are not stored
 * (their cells' references are "empty"), so no step is spent on them.
 * This file is compiled twice (kdtree_internal.h, "Runtime AVX2
 * dispatch"): as itself, the AVX2 kernels (built for AVX2 and FMA whatever
 * the build's flags, names ending _avx2), and by kdtree.c
 * with KD_PORTABLE, where the same step runs as plain loops (_portable);
 * the tree says which one its rays take.
 *
 * A leaf's triangles are tested 8 at a time with AVX2 (when compiled for
 * it): the same IEEE operations per lane as the scalar
 * watertight test of intersect.h (Woop, Benthin and Wald 2013; its shear
 * is made once per ray, in kd_ray), so the same bits (tests check it). Its
 * three edge functions need no divide, so a group whose lanes all have
 * edge functions of both signs ends before the divide (most groups; the
 * early reject of session 3 did the same for Moeller-Trumbore with
 * bounds); a lane whose edge function rounds to zero sends the group to
 * the scalar reference (which recomputes it in double), so the rare case
 * costs no code in the vector path. The vertex columns are taken in the
 * ray's axis order by one branch on a per-ray constant (three inlined
 * copies of the test). The eight triangles are loaded with one unaligned
 * 8-float load each and an 8x8 transpose, plus one gather for the ninth
 * float: nine gathers were the hottest instructions in the profile
 * (+10-30% rays/s without them). The list itself is read 8 ids at a time,
 * its end and its last triangle found from the loaded ids (no length loop;
 * groups of 1-2 triangles too: the scalar test costs more).
 *
 * Everything the two entry points use is in this file and inlined into
 * them (always_inline, flatten), intersect.h's tests included: keep new
 * traversal helpers here, not in another file, or they lose that.
 *
 * Measured and not kept (docs/performance.md has the numbers): a start
 * shortcut that walks down from the root plane by plane in scalar code
 * while only one cell can be entered (exact, but as costly per node as the
 * 8-lane step, +8% instructions); prefetching the cell on top of
 * the stack (-12% on DamagedHelmet diffuse); the leaf test out of line;
 * leaves that hold their triangles in SoA groups (no ids, no transpose:
 * -3% on the Cornell box but 146 bytes a triangle on DamagedHelmet, and
 * +1.4% on the list trees for carrying both layouts).
 */
#include "kdtree_internal.h"

#include <math.h>
#include <string.h>

#include "rt/accel/intersect.h"

#if defined(KD_PORTABLE) || defined(KD_HAVE_AVX2) /* else: only the portable pass, nothing here */
#ifdef KD_PORTABLE
#define KD_NAME(f) f##_portable
#else
#include <immintrin.h>
#define KD_SIMD 1
#define KD_NAME(f) f##_avx2
KD_AVX2_BEGIN
#endif

/* -------------------------------------------------------------- the ray */


/* What both set-ups below share: rays that can hit nothing (an empty tree,
 * an empty interval, a non-finite or zero vector) are turned away, and the
 * cell widening mp is set. */
static inline bool ray_accept(const rt_kdtree *tree, const rt_ray *ray, kd_ray *r)
{
    if (tree->root == RT_KD_EMPTY || !(ray->tmin < ray->tmax) || rt_box_is_empty(tree->bounds))
        return false;
    if (!rt_finite3(ray->org) || !rt_finite3(ray->dir))
        return false;
    if (ray->dir.x == 0.0f && ray->dir.y == 0.0f && ray->dir.z == 0.0f)
        return false;
    float omax = fmaxf(fabsf(ray->org.x), fmaxf(fabsf(ray->org.y), fabsf(ray->org.z)));
    r->mp = (tree->scale + omax) * 0x1p-18f;
    rt_tri_ray_init(&r->tr, ray->org, ray->dir);
    return true;
}

/* Clips the ray to the (widened) root box; false when it misses. An axis
 * is treated as parallel when 1/d is infinite or mp/|d| overflows: then the
 * ray moves less than mp along it for any finite t, so the side of a plane
 * is decided by the origin alone (within mp: both sides). */
#ifdef KD_SIMD
static inline bool ray_setup(const rt_kdtree *tree, const rt_ray *ray, kd_ray *r)
{
    /* the same operations as the scalar set-up below, three axes at once
     * (lane 3 repeats x); ray_accept's tests on SSE lanes (its scalar
     * isfinite and fmaxf calls were 6% of a primary ray's instructions) */
    if (tree->root == RT_KD_EMPTY || !(ray->tmin < ray->tmax))
        return false;
    const rt_box *bb = &tree->bounds;
    __m128 o = _mm_setr_ps(ray->org.x, ray->org.y, ray->org.z, ray->org.x);
    __m128 d = _mm_setr_ps(ray->dir.x, ray->dir.y, ray->dir.z, ray->dir.x);
    __m128 inf = _mm_set1_ps(INFINITY), sign = _mm_set1_ps(-0.0f);
    __m128 ao = _mm_andnot_ps(sign, o);
    if (_mm_movemask_ps(_mm_and_ps(_mm_cmp_ps(ao, inf, _CMP_LT_OQ), _mm_cmp_ps(_mm_andnot_ps(sign, d), inf, _CMP_LT_OQ))) != 0xf ||
        _mm_movemask_ps(_mm_cmp_ps(d, _mm_setzero_ps(), _CMP_EQ_OQ)) == 0xf)
        return false; /* non-finite, or a zero direction */
    __m128 lo = _mm_setr_ps(bb->lo.x, bb->lo.y, bb->lo.z, bb->lo.x), hi = _mm_setr_ps(bb->hi.x, bb->hi.y, bb->hi.z, bb->hi.x);
    if (_mm_movemask_ps(_mm_cmp_ps(lo, hi, _CMP_LE_OQ)) != 0xf)
        return false; /* an empty tree box */
    __m128 om = _mm_max_ps(ao, _mm_shuffle_ps(ao, ao, _MM_SHUFFLE(1, 0, 3, 2)));
    om = _mm_max_ps(om, _mm_shuffle_ps(om, om, _MM_SHUFFLE(2, 3, 0, 1)));
    r->mp = (tree->scale + _mm_cvtss_f32(om)) * 0x1p-18f;
    rt_tri_ray_init(&r->tr, ray->org, ray->dir);
    __m128 mp = _mm_set1_ps(r->mp);
    __m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), d);
    __m128 ma = _mm_mul_ps(mp, _mm_andnot_ps(_mm_set1_ps(-0.0f), inv));
    __m128 par = _mm_cmp_ps(ma, inf, _CMP_NLT_UQ);
    __m128 out = _mm_or_ps(_mm_cmp_ps(o, _mm_sub_ps(lo, mp), _CMP_LT_OQ), _mm_cmp_ps(o, _mm_add_ps(hi, mp), _CMP_GT_OQ));
    if (_mm_movemask_ps(_mm_and_ps(par, out)))
        return false;
    __m128 t0 = _mm_mul_ps(_mm_sub_ps(lo, o), inv), t1 = _mm_mul_ps(_mm_sub_ps(hi, o), inv);
    __m128 a = _mm_sub_ps(_mm_min_ps(t1, t0), ma), b = _mm_add_ps(_mm_max_ps(t0, t1), ma);
    a = _mm_blendv_ps(a, _mm_set1_ps(-INFINITY), par);
    b = _mm_blendv_ps(b, inf, par);
    a = _mm_max_ps(a, _mm_shuffle_ps(a, a, _MM_SHUFFLE(1, 0, 3, 2)));
    a = _mm_max_ps(a, _mm_shuffle_ps(a, a, _MM_SHUFFLE(2, 3, 0, 1)));
    b = _mm_min_ps(b, _mm_shuffle_ps(b, b, _MM_SHUFFLE(1, 0, 3, 2)));
    b = _mm_min_ps(b, _mm_shuffle_ps(b, b, _MM_SHUFFLE(2, 3, 0, 1)));
    /* fmaxf and fminf, but inline (libm calls here): tmin and tmax are
     * not NaN (tmin < tmax), nor are a and b for a finite ray */
    float tn = _mm_cvtss_f32(_mm_max_ss(_mm_set_ss(ray->tmin), a)), tf = _mm_cvtss_f32(_mm_min_ss(_mm_set_ss(ray->tmax), b));
    if (!(tn <= tf))
        return false;
    r->tn = tn;
    r->tf = tf;
    __m128 neg = _mm_andnot_ps(par, _mm_cmp_ps(inv, _mm_setzero_ps(), _CMP_NGT_UQ));
    inv = _mm_andnot_ps(par, inv);
    ma = _mm_andnot_ps(par, ma);
    _mm256_store_ps(r->o, _mm256_set_m128(o, o));
    _mm256_store_ps(r->inv, _mm256_set_m128(inv, inv));
    _mm256_store_ps(r->ma, _mm256_set_m128(ma, ma));
    _mm256_store_ps((float *)(void *)r->neg, _mm256_set_m128(neg, neg));
    _mm256_store_ps((float *)(void *)r->par, _mm256_set_m128(par, par));
    r->any_par = _mm_movemask_ps(par) != 0;
    return true;
}
#else
static inline bool ray_setup(const rt_kdtree *tree, const rt_ray *ray, kd_ray *r)
{
    if (!ray_accept(tree, ray, r))
        return false;
    const float o[3] = {ray->org.x, ray->org.y, ray->org.z}, d[3] = {ray->dir.x, ray->dir.y, ray->dir.z};
    r->any_par = false;
    float tn = ray->tmin, tf = ray->tmax;
    const float *lo = &tree->bounds.lo.x, *hi = &tree->bounds.hi.x;
    for (int k = 0; k < 3; k++) {
        float inv = 1.0f / d[k], ma = r->mp * fabsf(inv);
        r->o[k] = o[k];
        if (!(ma < INFINITY)) {
            if (o[k] < lo[k] - r->mp || o[k] > hi[k] + r->mp)
                return false;
            r->inv[k] = 0.0f, r->ma[k] = 0.0f, r->neg[k] = 0, r->par[k] = -1;
            r->any_par = true;
            continue;
        }
        r->inv[k] = inv, r->ma[k] = ma, r->neg[k] = inv > 0.0f ? 0 : -1, r->par[k] = 0;
        float t0 = (lo[k] - o[k]) * inv, t1 = (hi[k] - o[k]) * inv;
        if (t0 > t1) {
            float t = t0; t0 = t1; t1 = t;
        }
        t0 -= ma;
        t1 += ma;
        if (t0 > tn)
            tn = t0;
        if (t1 < tf)
            tf = t1;
    }
    if (!(tn <= tf))
        return false;
    r->tn = tn;
    r->tf = tf;
    return true;
}
#endif

/* --------------------------------------------------------------- leaves */

#if defined(__GNUC__)
#define KD_INLINE static inline __attribute__((always_inline))
#define KD_FLATTEN __attribute__((flatten)) /* inline the intersect.h tests into the loops */
#else
#define KD_INLINE static inline
#define KD_FLATTEN
#endif

/* A quad, out of line: rare in meshes, and the traversal's flattened code
 * stays as it is without it. */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static bool quad_hit(const rt_quad_prep *q, const rt_ray *ray, float best, float *t, float *u, float *v)
{
    return rt_intersect_quad_prepared(ray->org, ray->dir, q, ray->tmin, best, t, u, v);
}

/* Tests one primitive with the reference functions on (tmin, *best).
 * any: an instance may answer "something is hit" without finding the
 * closest (occlusion); every other primitive is tested the same way. */
KD_INLINE bool test_prim(const rt_kdtree *tree, uint32_t id, const rt_ray *ray, const rt_tri_ray *tr, float *best,
                         rt_hit *hit, bool any)
{
    float t, u, v;
    if (id < tree->other_base) {
        const float *p = tree->tri + id;
        if (!rt_intersect_triangle_ray(tr, rt_v3(p[0], p[1], p[2]), rt_v3(p[3], p[4], p[5]),
                                       rt_v3(p[6], p[7], p[8]), ray->tmin, *best, &t, &u, &v))
            return false;
    } else if (id - tree->other_base < tree->sphere_count) {
        const rt_spheres *s = &tree->scene->spheres;
        size_t i = id - tree->other_base;
        if (!rt_intersect_sphere(ray->org, ray->dir, rt_v3(s->cx[i], s->cy[i], s->cz[i]), s->radius[i], ray->tmin,
                                 *best, &t))
            return false;
        u = v = 0.0f;
    } else {
        size_t q = id - tree->other_base - tree->sphere_count;
        if (q >= tree->quad_count) /* past the quads: an instance (kdtree_instances.c) */
            return rt_kd_instance_hit(tree, (uint32_t)(q - tree->quad_count), id, ray, best, hit, any);
        if (!quad_hit(&tree->quads[q], ray, *best, &t, &u, &v))
            return false;
    }
    *best = t;
    hit->t = t;
    hit->u = u;
    hit->v = v;
    hit->prim = id;
    return true;
}

#ifdef KD_SIMD

/* The watertight test of intersect.h on 8 triangles whose vertex
 * coordinates come permuted to the ray's (kx, ky, kz) (see tri8): the very
 * IEEE operations of rt_intersect_triangle_ray, lane by lane (add, sub, mul
 * and div round the same in a vector lane as in a scalar register, and
 * -std=c11 contracts nothing into FMAs). Returns 1 when some lane may hit
 * (ok, t, u, v, det set), 0 when none does, -1 when a live lane's edge
 * function is zero (the reference then recomputes it in double: the
 * caller tests those 8 triangles with the reference, one by one). The
 * edge functions need no divide, so most groups end before it. */
KD_INLINE int tri8_core(__m256 ax, __m256 ay, __m256 az, __m256 bx, __m256 by, __m256 bz, __m256 cx, __m256 cy,
                        __m256 cz, const rt_ray *ray, const rt_tri_ray *tr, float best, __m256 *ok, __m256 *t_out,
                        __m256 *u_out, __m256 *v_out, __m256 *det_out)
{
    RT_NO_FP_CONTRACT
    __m256 ox = _mm256_set1_ps(tr->okx), oy = _mm256_set1_ps(tr->oky), oz = _mm256_set1_ps(tr->okz);
    __m256 sx = _mm256_set1_ps(tr->sx), sy = _mm256_set1_ps(tr->sy), sz = _mm256_set1_ps(tr->sz);
    __m256 akz = _mm256_sub_ps(az, oz), bkz = _mm256_sub_ps(bz, oz), ckz = _mm256_sub_ps(cz, oz);
    __m256 Ax = _mm256_sub_ps(_mm256_sub_ps(ax, ox), _mm256_mul_ps(sx, akz));
    __m256 Ay = _mm256_sub_ps(_mm256_sub_ps(ay, oy), _mm256_mul_ps(sy, akz));
    __m256 Bx = _mm256_sub_ps(_mm256_sub_ps(bx, ox), _mm256_mul_ps(sx, bkz));
    __m256 By = _mm256_sub_ps(_mm256_sub_ps(by, oy), _mm256_mul_ps(sy, bkz));
    __m256 Cx = _mm256_sub_ps(_mm256_sub_ps(cx, ox), _mm256_mul_ps(sx, ckz));
    __m256 Cy = _mm256_sub_ps(_mm256_sub_ps(cy, oy), _mm256_mul_ps(sy, ckz));
    __m256 U = _mm256_sub_ps(_mm256_mul_ps(Cx, By), _mm256_mul_ps(Cy, Bx));
    __m256 V = _mm256_sub_ps(_mm256_mul_ps(Ax, Cy), _mm256_mul_ps(Ay, Cx));
    __m256 W = _mm256_sub_ps(_mm256_mul_ps(Bx, Ay), _mm256_mul_ps(By, Ax));
    __m256 zero = _mm256_setzero_ps();
    __m256 neg = _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(U, zero, _CMP_LT_OQ), _mm256_cmp_ps(V, zero, _CMP_LT_OQ)),
                              _mm256_cmp_ps(W, zero, _CMP_LT_OQ));
    __m256 pos = _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(U, zero, _CMP_GT_OQ), _mm256_cmp_ps(V, zero, _CMP_GT_OQ)),
                              _mm256_cmp_ps(W, zero, _CMP_GT_OQ));
    __m256 m = _mm256_andnot_ps(_mm256_and_ps(neg, pos), *ok);
    if (_mm256_testz_ps(m, m)) /* the edge functions' signs differ in every lane */
        return 0;
    __m256 z = _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(U, zero, _CMP_EQ_OQ), _mm256_cmp_ps(V, zero, _CMP_EQ_OQ)),
                            _mm256_cmp_ps(W, zero, _CMP_EQ_OQ));
    if (!_mm256_testz_ps(z, *ok))
        return -1;
    __m256 det = _mm256_add_ps(_mm256_add_ps(U, V), W);
    __m256 adet = _mm256_andnot_ps(_mm256_set1_ps(-0.0f), det);
    m = _mm256_and_ps(m, _mm256_cmp_ps(det, zero, _CMP_NEQ_OQ));
    m = _mm256_and_ps(m, _mm256_cmp_ps(adet, _mm256_set1_ps(INFINITY), _CMP_LT_OQ));
    __m256 T = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(U, _mm256_mul_ps(sz, akz)), _mm256_mul_ps(V, _mm256_mul_ps(sz, bkz))),
                             _mm256_mul_ps(W, _mm256_mul_ps(sz, ckz)));
    __m256 inv = _mm256_div_ps(_mm256_set1_ps(1.0f), det);
    __m256 t = _mm256_mul_ps(T, inv);
    m = _mm256_and_ps(m, _mm256_cmp_ps(t, _mm256_set1_ps(ray->tmin), _CMP_GT_OQ));
    m = _mm256_and_ps(m, _mm256_cmp_ps(t, _mm256_set1_ps(best), _CMP_LT_OQ));
    *ok = m;
    *t_out = t;
    *u_out = _mm256_mul_ps(V, inv);
    *v_out = _mm256_mul_ps(W, inv);
    *det_out = adet;
    return !_mm256_testz_ps(m, m);
}

/* The first n (1-8) triangles of a group of 8 ids at once with the
 * watertight test (tri8_core), bit for bit the reference's; the closest
 * valid lane wins, on a tie the first, like the scalar loop. id: the 8 ids
 * without their flags (test_leaf loaded them). */
KD_INLINE bool tri8(const rt_kdtree *tree, const uint32_t *ids, __m256i id, uint32_t n, const rt_ray *ray,
                    const rt_tri_ray *tr, float *best, rt_hit *hit)
{
    RT_NO_FP_CONTRACT
    const float *tri = tree->tri;
    __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    __m256i live = _mm256_cmpgt_epi32(_mm256_set1_epi32((int)n), lane);
    /* idle lanes repeat the first triangle (a record that exists) */
    __m256i base = _mm256_blendv_epi8(_mm256_permutevar8x32_epi32(id, _mm256_setzero_si256()), id, live);
    /* floats 0-7 of each triangle: one unaligned load per lane and an 8x8
     * transpose (cheaper than eight gathers); float 8 by one gather */
    uint32_t off[8];
    _mm256_storeu_si256((__m256i *)off, base);
    __m256 r0 = _mm256_loadu_ps(tri + off[0]), r1 = _mm256_loadu_ps(tri + off[1]), r2 = _mm256_loadu_ps(tri + off[2]),
           r3 = _mm256_loadu_ps(tri + off[3]), r4 = _mm256_loadu_ps(tri + off[4]), r5 = _mm256_loadu_ps(tri + off[5]),
           r6 = _mm256_loadu_ps(tri + off[6]), r7 = _mm256_loadu_ps(tri + off[7]);
    __m256 v2z = _mm256_i32gather_ps(tri + 8, base, 4);
    __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpackhi_ps(r0, r1), t2 = _mm256_unpacklo_ps(r2, r3),
           t3 = _mm256_unpackhi_ps(r2, r3), t4 = _mm256_unpacklo_ps(r4, r5), t5 = _mm256_unpackhi_ps(r4, r5),
           t6 = _mm256_unpacklo_ps(r6, r7), t7 = _mm256_unpackhi_ps(r6, r7);
    __m256 s0 = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0)), s1 = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2)),
           s2 = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0)), s3 = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2)),
           s4 = _mm256_shuffle_ps(t4, t6, _MM_SHUFFLE(1, 0, 1, 0)), s5 = _mm256_shuffle_ps(t4, t6, _MM_SHUFFLE(3, 2, 3, 2)),
           s6 = _mm256_shuffle_ps(t5, t7, _MM_SHUFFLE(1, 0, 1, 0)), s7 = _mm256_shuffle_ps(t5, t7, _MM_SHUFFLE(3, 2, 3, 2));
    __m256 v0x = _mm256_permute2f128_ps(s0, s4, 0x20), v0y = _mm256_permute2f128_ps(s1, s5, 0x20),
           v0z = _mm256_permute2f128_ps(s2, s6, 0x20), v1x = _mm256_permute2f128_ps(s3, s7, 0x20),
           v1y = _mm256_permute2f128_ps(s0, s4, 0x31), v1z = _mm256_permute2f128_ps(s1, s5, 0x31),
           v2x = _mm256_permute2f128_ps(s2, s6, 0x31), v2y = _mm256_permute2f128_ps(s3, s7, 0x31);
    __m256 ok = _mm256_castsi256_ps(live), t, u, v, adet;
    int res;
    /* the columns in the ray's axis order: three inlined copies, one
     * branch on a per-ray constant */
    if (tr->kz == 2)
        res = tri8_core(v0x, v0y, v0z, v1x, v1y, v1z, v2x, v2y, v2z, ray, tr, *best, &ok, &t, &u, &v, &adet);
    else if (tr->kz == 1)
        res = tri8_core(v0z, v0x, v0y, v1z, v1x, v1y, v2z, v2x, v2y, ray, tr, *best, &ok, &t, &u, &v, &adet);
    else
        res = tri8_core(v0y, v0z, v0x, v1y, v1z, v1x, v2y, v2z, v2x, ray, tr, *best, &ok, &t, &u, &v, &adet);
    if (res <= 0) {
        if (res == 0)
            return false;
        bool found = false; /* an edge function rounded to zero: the reference decides, in order */
        for (uint32_t i = 0; i < n; i++)
            found |= test_prim(tree, ids[i] & RT_KD_PAYLOAD, ray, tr, best, hit, false);
        return found;
    }
    /* intersect.h's guard against determinants that are rounding noise */
    __m256 absmask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
    __m256 e1x = _mm256_sub_ps(v1x, v0x), e1y = _mm256_sub_ps(v1y, v0y), e1z = _mm256_sub_ps(v1z, v0z);
    __m256 e2x = _mm256_sub_ps(v2x, v0x), e2y = _mm256_sub_ps(v2y, v0y), e2z = _mm256_sub_ps(v2z, v0z);
    __m256 a1 = _mm256_add_ps(_mm256_add_ps(_mm256_and_ps(e1x, absmask), _mm256_and_ps(e1y, absmask)),
                              _mm256_and_ps(e1z, absmask));
    __m256 a2 = _mm256_add_ps(_mm256_add_ps(_mm256_and_ps(e2x, absmask), _mm256_and_ps(e2y, absmask)),
                              _mm256_and_ps(e2z, absmask));
    __m256 lhs = _mm256_div_ps(_mm256_div_ps(_mm256_mul_ps(adet, _mm256_set1_ps(tr->adz)), a1), a2);
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(lhs, _mm256_set1_ps(0x1p-16f * tr->ad), _CMP_GT_OQ));
    int mask = _mm256_movemask_ps(ok);
    if (!mask)
        return false;
    float tl[8], ul[8], vl[8];
    _mm256_storeu_ps(tl, t);
    _mm256_storeu_ps(ul, u);
    _mm256_storeu_ps(vl, v);
    int k = __builtin_ctz((unsigned)mask);
    for (int i = k + 1; i < 8; i++)
        if ((mask >> i) & 1 && tl[i] < tl[k])
            k = i;
    *best = tl[k];
    hit->t = tl[k];
    hit->u = ul[k];
    hit->v = vl[k];
    hit->prim = ids[k] & RT_KD_PAYLOAD;
    return true;
}
#endif

#ifndef KD_SIMD
/* The length of a leaf list: up to its id with RT_KD_LAST. */
KD_INLINE uint32_t leaf_length(const uint32_t *p)
{
    uint32_t n = 0;
    while (!(p[n] & RT_KD_LAST))
        n++;
    return n + 1;
}
#endif

/* All primitives of a multi-primitive leaf list p (ids ascending:
 * triangles first, then spheres and quads; the last id flagged
 * RT_KD_LAST). The AVX2 pass reads the list 8 ids at a time (the blocks
 * are followed by KD_IDS_PAD flagged ids, so 8 can always be loaded): the
 * flag's lane ends the list and the ids below other_base are the group's
 * triangles, tested together by tri8, so finding the list's length and
 * its last triangle costs no loop; the spheres and quads after them go one
 * by one. The same primitives in the same order as one by one. */
KD_INLINE bool test_leaf(const rt_kdtree *tree, const uint32_t *p, const rt_ray *ray, const rt_tri_ray *tr,
                         float *best, rt_hit *hit, bool any)
{
    bool found = false;
#ifdef KD_SIMD
    const __m256i payload = _mm256_set1_epi32((int)RT_KD_PAYLOAD);
    const __m256i other = _mm256_set1_epi32((int)tree->other_base - 1); /* ids < 2^30: signed compares */
    for (;; p += 8) {
        __m256i raw = _mm256_loadu_si256((const __m256i *)(const void *)p);
        unsigned end = (unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(raw));
        unsigned n = end ? (unsigned)__builtin_ctz(end) + 1u : 8u; /* ids of this group */
        __m256i id = _mm256_and_si256(raw, payload);
        unsigned rest = (unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(id, other))) &
                        ((2u << (n - 1u)) - 1u); /* spheres and quads: the last lanes */
        unsigned nt = rest ? (unsigned)__builtin_ctz(rest) : n;
        if (nt > 0 && tri8(tree, p, id, nt, ray, tr, best, hit)) {
            found = true;
            if (any)
                return true;
        }
        for (unsigned i = nt; i < n; i++)
            if (test_prim(tree, p[i] & RT_KD_PAYLOAD, ray, tr, best, hit, any)) {
                found = true;
                if (any)
                    return true;
            }
        if (end)
            return found;
    }
#else
    uint32_t n = leaf_length(p);
    for (uint32_t i = 0; i < n; i++)
        if (test_prim(tree, p[i] & RT_KD_PAYLOAD, ray, tr, best, hit, any)) {
            found = true;
            if (any)
                return true;
        }
    return found;
#endif
}

/* ------------------------------------------------------ the wide step */

/* One step through a wide node w for the ray's interval [tn, tf]: which of
 * the 8 cells the ray crosses (non-empty t interval, non-empty child), in
 * front-to-back order. The nearest is returned in *near_cell with its
 * interval, the others are pushed farthest first (so the next nearest ends
 * on top of the stack); returns how many were pushed, or -1 when the ray
 * crosses no non-empty cell.
 *
 * Order: a cell's key k = k0 k1 k2 (bit 2 = level 0) says on which side of
 * its plane at each level it lies, 0 = the side the ray enters first (the
 * below side unless the ray runs towards -axis: neg). Cell c = 4 b0 + 2 b1
 * + b2 with b = k ^ neg at each level, its planes 0, 1 + b0, 3 + 2 b0 + b1;
 * ascending keys are front to back. The cell's t interval is [tn, tf] cut
 * by [lo, inf) for each plane it lies beyond and (-inf, hi] for each it lies
 * before, lo/hi = t(plane) -/+ ma: the binary traversal's intervals, so the
 * same leaves in the same order. */
#define KD_WSTACK 192 /* 7 net pushes per wide level, KD_MAX_DEPTH / 3 levels, + 8 for the full-width store */
_Static_assert(7 * ((KD_MAX_DEPTH + 2) / 3) + 8 <= KD_WSTACK, "wide traversal stack");

#ifndef KD_SIMD /* the portable step (the AVX2 one below does the same, 8 cells at once) */
KD_INLINE int wide_step_scalar(const rt_kdtree_wide *w, const kd_ray *r, bool par, float tn, float tf, uint32_t *sref,
                               float *slo, float *shi, unsigned *near_cell, float *near_tn, float *near_tf)
{
    float lo[7], hi[7];
    int neg[7];
    for (int p = 0; p < 7; p++) {
        unsigned k = (w->axes >> (2 * p)) & 3u;
        if (par && r->par[k]) {
            float dist = r->o[k] - w->split[p];
            lo[p] = dist >= -r->mp ? -INFINITY : INFINITY;
            hi[p] = dist <= r->mp ? INFINITY : -INFINITY;
            neg[p] = 0;
        } else {
            float t = (w->split[p] - r->o[k]) * r->inv[k];
            lo[p] = t - r->ma[k];
            hi[p] = t + r->ma[k];
            neg[p] = r->neg[k];
        }
    }
    /* back to front: the entries come out farthest first, and the last one
     * (the nearest) is returned instead of pushed */
    int n = 0;
    for (unsigned key = 8; key-- > 0;) {
        unsigned f0 = key >> 2 & 1u, f1 = key >> 1 & 1u, f2 = key & 1u;
        unsigned b0 = f0 ^ (unsigned)(neg[0] & 1), p1 = 1 + b0, b1 = f1 ^ (unsigned)(neg[p1] & 1),
                 p2 = 3 + 2 * b0 + b1, b2 = f2 ^ (unsigned)(neg[p2] & 1);
        float l = tn, h = tf;
        if (f0) l = lo[0] > l ? lo[0] : l; else h = hi[0] < h ? hi[0] : h;
        if (f1) l = lo[p1] > l ? lo[p1] : l; else h = hi[p1] < h ? hi[p1] : h;
        if (f2) l = lo[p2] > l ? lo[p2] : l; else h = hi[p2] < h ? hi[p2] : h;
        unsigned cell = 4 * b0 + 2 * b1 + b2;
        uint32_t ref = w->child[cell];
        if (ref == RT_KD_EMPTY || !(l <= h))
            continue;
        sref[n] = ref, slo[n] = l, shi[n] = h;
        n++;
        *near_cell = cell, *near_tn = l, *near_tf = h;
    }
    return n - 1; /* -1: none */
}
#endif

#ifdef KD_SIMD
/* Byte i of entry m: the lane of the i-th set bit of m (compaction by a
 * permute, as AVX2 has no compress instruction). This table and the two
 * below are printed by tools/kd_tables.py. */
const uint64_t rt_kd_compress[256] = {
    0x0000000000000000ull, 0x0000000000000000ull, 0x0000000000000001ull, 0x0000000000000100ull,
    0x0000000000000002ull, 0x0000000000000200ull, 0x0000000000000201ull, 0x0000000000020100ull,
    0x0000000000000003ull, 0x0000000000000300ull, 0x0000000000000301ull, 0x0000000000030100ull,
    0x0000000000000302ull, 0x0000000000030200ull, 0x0000000000030201ull, 0x0000000003020100ull,
    0x0000000000000004ull, 0x0000000000000400ull, 0x0000000000000401ull, 0x0000000000040100ull,
    0x0000000000000402ull, 0x0000000000040200ull, 0x0000000000040201ull, 0x0000000004020100ull,
    0x0000000000000403ull, 0x0000000000040300ull, 0x0000000000040301ull, 0x0000000004030100ull,
    0x0000000000040302ull, 0x0000000004030200ull, 0x0000000004030201ull, 0x0000000403020100ull,
    0x0000000000000005ull, 0x0000000000000500ull, 0x0000000000000501ull, 0x0000000000050100ull,
    0x0000000000000502ull, 0x0000000000050200ull, 0x0000000000050201ull, 0x0000000005020100ull,
    0x0000000000000503ull, 0x0000000000050300ull, 0x0000000000050301ull, 0x0000000005030100ull,
    0x0000000000050302ull, 0x0000000005030200ull, 0x0000000005030201ull, 0x0000000503020100ull,
    0x0000000000000504ull, 0x0000000000050400ull, 0x0000000000050401ull, 0x0000000005040100ull,
    0x0000000000050402ull, 0x0000000005040200ull, 0x0000000005040201ull, 0x0000000504020100ull,
    0x0000000000050403ull, 0x0000000005040300ull, 0x0000000005040301ull, 0x0000000504030100ull,
    0x0000000005040302ull, 0x0000000504030200ull, 0x0000000504030201ull, 0x0000050403020100ull,
    0x0000000000000006ull, 0x0000000000000600ull, 0x0000000000000601ull, 0x0000000000060100ull,
    0x0000000000000602ull, 0x0000000000060200ull, 0x0000000000060201ull, 0x0000000006020100ull,
    0x0000000000000603ull, 0x0000000000060300ull, 0x0000000000060301ull, 0x0000000006030100ull,
    0x0000000000060302ull, 0x0000000006030200ull, 0x0000000006030201ull, 0x0000000603020100ull,
    0x0000000000000604ull, 0x0000000000060400ull, 0x0000000000060401ull, 0x0000000006040100ull,
    0x0000000000060402ull, 0x0000000006040200ull, 0x0000000006040201ull, 0x0000000604020100ull,
    0x0000000000060403ull, 0x0000000006040300ull, 0x0000000006040301ull, 0x0000000604030100ull,
    0x0000000006040302ull, 0x0000000604030200ull, 0x0000000604030201ull, 0x0000060403020100ull,
    0x0000000000000605ull, 0x0000000000060500ull, 0x0000000000060501ull, 0x0000000006050100ull,
    0x0000000000060502ull, 0x0000000006050200ull, 0x0000000006050201ull, 0x0000000605020100ull,
    0x0000000000060503ull, 0x0000000006050300ull, 0x0000000006050301ull, 0x0000000605030100ull,
    0x0000000006050302ull, 0x0000000605030200ull, 0x0000000605030201ull, 0x0000060503020100ull,
    0x0000000000060504ull, 0x0000000006050400ull, 0x0000000006050401ull, 0x0000000605040100ull,
    0x0000000006050402ull, 0x0000000605040200ull, 0x0000000605040201ull, 0x0000060504020100ull,
    0x0000000006050403ull, 0x0000000605040300ull, 0x0000000605040301ull, 0x0000060504030100ull,
    0x0000000605040302ull, 0x0000060504030200ull, 0x0000060504030201ull, 0x0006050403020100ull,
    0x0000000000000007ull, 0x0000000000000700ull, 0x0000000000000701ull, 0x0000000000070100ull,
    0x0000000000000702ull, 0x0000000000070200ull, 0x0000000000070201ull, 0x0000000007020100ull,
    0x0000000000000703ull, 0x0000000000070300ull, 0x0000000000070301ull, 0x0000000007030100ull,
    0x0000000000070302ull, 0x0000000007030200ull, 0x0000000007030201ull, 0x0000000703020100ull,
    0x0000000000000704ull, 0x0000000000070400ull, 0x0000000000070401ull, 0x0000000007040100ull,
    0x0000000000070402ull, 0x0000000007040200ull, 0x0000000007040201ull, 0x0000000704020100ull,
    0x0000000000070403ull, 0x0000000007040300ull, 0x0000000007040301ull, 0x0000000704030100ull,
    0x0000000007040302ull, 0x0000000704030200ull, 0x0000000704030201ull, 0x0000070403020100ull,
    0x0000000000000705ull, 0x0000000000070500ull, 0x0000000000070501ull, 0x0000000007050100ull,
    0x0000000000070502ull, 0x0000000007050200ull, 0x0000000007050201ull, 0x0000000705020100ull,
    0x0000000000070503ull, 0x0000000007050300ull, 0x0000000007050301ull, 0x0000000705030100ull,
    0x0000000007050302ull, 0x0000000705030200ull, 0x0000000705030201ull, 0x0000070503020100ull,
    0x0000000000070504ull, 0x0000000007050400ull, 0x0000000007050401ull, 0x0000000705040100ull,
    0x0000000007050402ull, 0x0000000705040200ull, 0x0000000705040201ull, 0x0000070504020100ull,
    0x0000000007050403ull, 0x0000000705040300ull, 0x0000000705040301ull, 0x0000070504030100ull,
    0x0000000705040302ull, 0x0000070504030200ull, 0x0000070504030201ull, 0x0007050403020100ull,
    0x0000000000000706ull, 0x0000000000070600ull, 0x0000000000070601ull, 0x0000000007060100ull,
    0x0000000000070602ull, 0x0000000007060200ull, 0x0000000007060201ull, 0x0000000706020100ull,
    0x0000000000070603ull, 0x0000000007060300ull, 0x0000000007060301ull, 0x0000000706030100ull,
    0x0000000007060302ull, 0x0000000706030200ull, 0x0000000706030201ull, 0x0000070603020100ull,
    0x0000000000070604ull, 0x0000000007060400ull, 0x0000000007060401ull, 0x0000000706040100ull,
    0x0000000007060402ull, 0x0000000706040200ull, 0x0000000706040201ull, 0x0000070604020100ull,
    0x0000000007060403ull, 0x0000000706040300ull, 0x0000000706040301ull, 0x0000070604030100ull,
    0x0000000706040302ull, 0x0000070604030200ull, 0x0000070604030201ull, 0x0007060403020100ull,
    0x0000000000070605ull, 0x0000000007060500ull, 0x0000000007060501ull, 0x0000000706050100ull,
    0x0000000007060502ull, 0x0000000706050200ull, 0x0000000706050201ull, 0x0000070605020100ull,
    0x0000000007060503ull, 0x0000000706050300ull, 0x0000000706050301ull, 0x0000070605030100ull,
    0x0000000706050302ull, 0x0000070605030200ull, 0x0000070605030201ull, 0x0007060503020100ull,
    0x0000000007060504ull, 0x0000000706050400ull, 0x0000000706050401ull, 0x0000070605040100ull,
    0x0000000706050402ull, 0x0000070605040200ull, 0x0000070605040201ull, 0x0007060504020100ull,
    0x0000000706050403ull, 0x0000070605040300ull, 0x0000070605040301ull, 0x0007060504030100ull,
    0x0000070605040302ull, 0x0007060504030200ull, 0x0007060504030201ull, 0x0706050403020100ull,
};

/* The front-to-back order of a node's cells depends only on which of its 7
 * planes the ray crosses towards -axis (7 bits nb): byte L of
 * rt_kd_cell_of_key[nb] is the cell with key 7 - L, byte c of
 * rt_kd_key_of_cell[nb] the key of cell c (keys as in wide_step_scalar). */
const uint64_t rt_kd_cell_of_key[128] = {
    0x0001020304050607ull, 0x0405060700010203ull, 0x0203000104050607ull, 0x0405060702030001ull,
    0x0001020306070405ull, 0x0607040500010203ull, 0x0203000106070405ull, 0x0607040502030001ull,
    0x0100020304050607ull, 0x0405060701000203ull, 0x0203010004050607ull, 0x0405060702030100ull,
    0x0100020306070405ull, 0x0607040501000203ull, 0x0203010006070405ull, 0x0607040502030100ull,
    0x0001030204050607ull, 0x0405060700010302ull, 0x0302000104050607ull, 0x0405060703020001ull,
    0x0001030206070405ull, 0x0607040500010302ull, 0x0302000106070405ull, 0x0607040503020001ull,
    0x0100030204050607ull, 0x0405060701000302ull, 0x0302010004050607ull, 0x0405060703020100ull,
    0x0100030206070405ull, 0x0607040501000302ull, 0x0302010006070405ull, 0x0607040503020100ull,
    0x0001020305040607ull, 0x0504060700010203ull, 0x0203000105040607ull, 0x0504060702030001ull,
    0x0001020306070504ull, 0x0607050400010203ull, 0x0203000106070504ull, 0x0607050402030001ull,
    0x0100020305040607ull, 0x0504060701000203ull, 0x0203010005040607ull, 0x0504060702030100ull,
    0x0100020306070504ull, 0x0607050401000203ull, 0x0203010006070504ull, 0x0607050402030100ull,
    0x0001030205040607ull, 0x0504060700010302ull, 0x0302000105040607ull, 0x0504060703020001ull,
    0x0001030206070504ull, 0x0607050400010302ull, 0x0302000106070504ull, 0x0607050403020001ull,
    0x0100030205040607ull, 0x0504060701000302ull, 0x0302010005040607ull, 0x0504060703020100ull,
    0x0100030206070504ull, 0x0607050401000302ull, 0x0302010006070504ull, 0x0607050403020100ull,
    0x0001020304050706ull, 0x0405070600010203ull, 0x0203000104050706ull, 0x0405070602030001ull,
    0x0001020307060405ull, 0x0706040500010203ull, 0x0203000107060405ull, 0x0706040502030001ull,
    0x0100020304050706ull, 0x0405070601000203ull, 0x0203010004050706ull, 0x0405070602030100ull,
    0x0100020307060405ull, 0x0706040501000203ull, 0x0203010007060405ull, 0x0706040502030100ull,
    0x0001030204050706ull, 0x0405070600010302ull, 0x0302000104050706ull, 0x0405070603020001ull,
    0x0001030207060405ull, 0x0706040500010302ull, 0x0302000107060405ull, 0x0706040503020001ull,
    0x0100030204050706ull, 0x0405070601000302ull, 0x0302010004050706ull, 0x0405070603020100ull,
    0x0100030207060405ull, 0x0706040501000302ull, 0x0302010007060405ull, 0x0706040503020100ull,
    0x0001020305040706ull, 0x0504070600010203ull, 0x0203000105040706ull, 0x0504070602030001ull,
    0x0001020307060504ull, 0x0706050400010203ull, 0x0203000107060504ull, 0x0706050402030001ull,
    0x0100020305040706ull, 0x0504070601000203ull, 0x0203010005040706ull, 0x0504070602030100ull,
    0x0100020307060504ull, 0x0706050401000203ull, 0x0203010007060504ull, 0x0706050402030100ull,
    0x0001030205040706ull, 0x0504070600010302ull, 0x0302000105040706ull, 0x0504070603020001ull,
    0x0001030207060504ull, 0x0706050400010302ull, 0x0302000107060504ull, 0x0706050403020001ull,
    0x0100030205040706ull, 0x0504070601000302ull, 0x0302010005040706ull, 0x0504070603020100ull,
    0x0100030207060504ull, 0x0706050401000302ull, 0x0302010007060504ull, 0x0706050403020100ull,
};
const uint64_t rt_kd_key_of_cell[128] = {
    0x0706050403020100ull, 0x0302010007060504ull, 0x0706050401000302ull, 0x0302010005040706ull,
    0x0504070603020100ull, 0x0100030207060504ull, 0x0504070601000302ull, 0x0100030205040706ull,
    0x0706050403020001ull, 0x0302010007060405ull, 0x0706050401000203ull, 0x0302010005040607ull,
    0x0504070603020001ull, 0x0100030207060405ull, 0x0504070601000203ull, 0x0100030205040607ull,
    0x0706050402030100ull, 0x0302010006070504ull, 0x0706050400010302ull, 0x0302010004050706ull,
    0x0504070602030100ull, 0x0100030206070504ull, 0x0504070600010302ull, 0x0100030204050706ull,
    0x0706050402030001ull, 0x0302010006070405ull, 0x0706050400010203ull, 0x0302010004050607ull,
    0x0504070602030001ull, 0x0100030206070405ull, 0x0504070600010203ull, 0x0100030204050607ull,
    0x0706040503020100ull, 0x0302000107060504ull, 0x0706040501000302ull, 0x0302000105040706ull,
    0x0504060703020100ull, 0x0100020307060504ull, 0x0504060701000302ull, 0x0100020305040706ull,
    0x0706040503020001ull, 0x0302000107060405ull, 0x0706040501000203ull, 0x0302000105040607ull,
    0x0504060703020001ull, 0x0100020307060405ull, 0x0504060701000203ull, 0x0100020305040607ull,
    0x0706040502030100ull, 0x0302000106070504ull, 0x0706040500010302ull, 0x0302000104050706ull,
    0x0504060702030100ull, 0x0100020306070504ull, 0x0504060700010302ull, 0x0100020304050706ull,
    0x0706040502030001ull, 0x0302000106070405ull, 0x0706040500010203ull, 0x0302000104050607ull,
    0x0504060702030001ull, 0x0100020306070405ull, 0x0504060700010203ull, 0x0100020304050607ull,
    0x0607050403020100ull, 0x0203010007060504ull, 0x0607050401000302ull, 0x0203010005040706ull,
    0x0405070603020100ull, 0x0001030207060504ull, 0x0405070601000302ull, 0x0001030205040706ull,
    0x0607050403020001ull, 0x0203010007060405ull, 0x0607050401000203ull, 0x0203010005040607ull,
    0x0405070603020001ull, 0x0001030207060405ull, 0x0405070601000203ull, 0x0001030205040607ull,
    0x0607050402030100ull, 0x0203010006070504ull, 0x0607050400010302ull, 0x0203010004050706ull,
    0x0405070602030100ull, 0x0001030206070504ull, 0x0405070600010302ull, 0x0001030204050706ull,
    0x0607050402030001ull, 0x0203010006070405ull, 0x0607050400010203ull, 0x0203010004050607ull,
    0x0405070602030001ull, 0x0001030206070405ull, 0x0405070600010203ull, 0x0001030204050607ull,
    0x0607040503020100ull, 0x0203000107060504ull, 0x0607040501000302ull, 0x0203000105040706ull,
    0x0405060703020100ull, 0x0001020307060504ull, 0x0405060701000302ull, 0x0001020305040706ull,
    0x0607040503020001ull, 0x0203000107060405ull, 0x0607040501000203ull, 0x0203000105040607ull,
    0x0405060703020001ull, 0x0001020307060405ull, 0x0405060701000203ull, 0x0001020305040607ull,
    0x0607040502030100ull, 0x0203000106070504ull, 0x0607040500010302ull, 0x0203000104050706ull,
    0x0405060702030100ull, 0x0001020306070504ull, 0x0405060700010302ull, 0x0001020304050706ull,
    0x0607040502030001ull, 0x0203000106070405ull, 0x0607040500010203ull, 0x0203000104050607ull,
    0x0405060702030001ull, 0x0001020306070405ull, 0x0405060700010203ull, 0x0001020304050607ull,
};

/* The same as wide_step_scalar, eight cells at once. Lanes are cells here
 * (lane c = cell c, whose planes 0, 1 + c/4 and 3 + c/2 are the same for
 * every node), so the caller can read the nearest cell's interval from a
 * fixed lane once it has branched on the cell: only that branch waits for
 * the choice of the nearest cell, the data does not. The pushes go in key
 * order (see wide_step_scalar) through the key -> cell permutation. */
typedef struct kd_step {
    __m256 l, h;   /* per cell: its t interval */
    unsigned cell; /* the nearest valid cell */
} kd_step;

KD_INLINE int wide_step_avx2(const rt_kdtree_wide *w, const kd_ray *r, bool par, float tn, float tf, uint32_t *sref,
                             float *slo, float *shi, kd_step *out)
{
    const __m256i three = _mm256_set1_epi32(3), zero = _mm256_setzero_si256();
    const __m256 ninf = _mm256_set1_ps(-INFINITY), pinf = _mm256_set1_ps(INFINITY);
    __m256 split = _mm256_load_ps((const float *)(const void *)w); /* lane 7: the axes, unused */
    __m256i axis = _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32((int)w->axes),
                                                      _mm256_setr_epi32(0, 2, 4, 6, 8, 10, 12, 0)),
                                    three);
    __m256 o = _mm256_permutevar8x32_ps(_mm256_load_ps(r->o), axis);
    __m256 inv = _mm256_permutevar8x32_ps(_mm256_load_ps(r->inv), axis);
    __m256 ma = _mm256_permutevar8x32_ps(_mm256_load_ps(r->ma), axis);
    __m256i neg = _mm256_permutevar8x32_epi32(_mm256_load_si256((const __m256i *)(const void *)r->neg), axis);
    __m256 t = _mm256_mul_ps(_mm256_sub_ps(split, o), inv);
    __m256 lo = _mm256_sub_ps(t, ma), hi = _mm256_add_ps(t, ma);
    if (par) {
        __m256 pm = _mm256_castsi256_ps(
            _mm256_permutevar8x32_epi32(_mm256_load_si256((const __m256i *)(const void *)r->par), axis));
        __m256 dist = _mm256_sub_ps(o, split), mp = _mm256_set1_ps(r->mp);
        __m256 plo = _mm256_blendv_ps(pinf, ninf, _mm256_cmp_ps(dist, _mm256_sub_ps(_mm256_setzero_ps(), mp), _CMP_GE_OQ));
        __m256 phi = _mm256_blendv_ps(ninf, pinf, _mm256_cmp_ps(dist, mp, _CMP_LE_OQ));
        lo = _mm256_blendv_ps(lo, plo, pm);
        hi = _mm256_blendv_ps(hi, phi, pm);
        neg = _mm256_andnot_si256(_mm256_castps_si256(pm), neg);
    }
    /* cell order: the planes of cell c (0, 1 + c/4, 3 + c/2), and the key
     * bits that say on which side of each the cell is for this ray */
    const __m256i q1 = _mm256_setr_epi32(1, 1, 1, 1, 2, 2, 2, 2), q2 = _mm256_setr_epi32(3, 3, 4, 4, 5, 5, 6, 6);
    unsigned nb = (unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(neg)) & 0x7fu;
    uint64_t order = rt_kd_cell_of_key[nb];
    __m256i key = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128((long long)rt_kd_key_of_cell[nb]));
    /* blendv reads the sign bit: key bit 2, 1, 0 = far side at level 0, 1, 2 */
    __m256 m0 = _mm256_castsi256_ps(_mm256_slli_epi32(key, 29)), m1 = _mm256_castsi256_ps(_mm256_slli_epi32(key, 30)),
           m2 = _mm256_castsi256_ps(_mm256_slli_epi32(key, 31));
    __m256 x = _mm256_max_ps(_mm256_blendv_ps(ninf, _mm256_permutevar8x32_ps(lo, zero), m0),
                             _mm256_max_ps(_mm256_blendv_ps(ninf, _mm256_permutevar8x32_ps(lo, q1), m1),
                                           _mm256_blendv_ps(ninf, _mm256_permutevar8x32_ps(lo, q2), m2)));
    __m256 y = _mm256_min_ps(_mm256_blendv_ps(_mm256_permutevar8x32_ps(hi, zero), pinf, m0),
                             _mm256_min_ps(_mm256_blendv_ps(_mm256_permutevar8x32_ps(hi, q1), pinf, m1),
                                           _mm256_blendv_ps(_mm256_permutevar8x32_ps(hi, q2), pinf, m2)));
    __m256 l = _mm256_max_ps(x, _mm256_set1_ps(tn)), h = _mm256_min_ps(y, _mm256_set1_ps(tf));
    __m256i ref = _mm256_load_si256((const __m256i *)(const void *)w->child);
    __m256 ok = _mm256_andnot_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(ref, _mm256_set1_epi32(-1))),
                                 _mm256_cmp_ps(l, h, _CMP_LE_OQ));
    /* one valid cell (or none): nothing to order or push */
    unsigned okm = (unsigned)_mm256_movemask_ps(ok);
    if ((okm & (okm - 1u)) == 0) {
        if (!okm)
            return -1;
        out->l = l, out->h = h, out->cell = (unsigned)__builtin_ctz(okm);
        return 0;
    }
    /* key order, farthest first: the nearest valid cell is the top bit */
    __m256i cell = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128((long long)order));
    unsigned mask = (unsigned)_mm256_movemask_ps(_mm256_permutevar8x32_ps(ok, cell));
    unsigned lane = 31u - (unsigned)__builtin_clz(mask), rest = mask ^ (1u << lane);
    out->l = l, out->h = h, out->cell = (unsigned)(order >> (8 * lane)) & 7u;
    __m256i idx = _mm256_permutevar8x32_epi32(
        cell, _mm256_cvtepu8_epi32(_mm_loadl_epi64((const __m128i *)(const void *)&rt_kd_compress[rest])));
    _mm256_storeu_si256((__m256i *)(void *)sref, _mm256_permutevar8x32_epi32(ref, idx));
    _mm256_storeu_ps(slo, _mm256_permutevar8x32_ps(l, idx));
    _mm256_storeu_ps(shi, _mm256_permutevar8x32_ps(h, idx));
    return __builtin_popcount(rest);
}

/* The nearest cell's child and interval: a branch per cell (see above). */
#define KD_NEAR(c)                                                                 \
    case c:                                                                        \
        ref = w->child[c];                                                         \
        tn = _mm_cvtss_f32(_mm_permute_ps(_mm256_extractf128_ps(st.l, (c) / 4), (c) % 4)); \
        tf = _mm_cvtss_f32(_mm_permute_ps(_mm256_extractf128_ps(st.h, (c) / 4), (c) % 4)); \
        break;
#endif

/* The shared traversal; any = stop at the first hit (occlusion). A stack
 * entry is a child reference with its t interval; the nearest is on top. */
KD_INLINE bool traverse_ray(const rt_kdtree *tree, const rt_ray *ray, rt_hit *hit, bool any, bool par, const kd_ray *r,
                            uint32_t start)
{
    const rt_kdtree_wide *wide = tree->wide;
    const uint32_t *ids = tree->prim_ids;
    uint32_t sref[KD_WSTACK];
    float slo[KD_WSTACK], shi[KD_WSTACK];
    int sp = 0;
    uint32_t ref = start;
    float tn = r->tn, tf = r->tf, best = ray->tmax;
    bool found = false;
    for (;;) {
        while (ref < RT_KD_LEAF) {
            const rt_kdtree_wide *w = &wide[ref];
#ifdef KD_SIMD
            kd_step st;
            int n = wide_step_avx2(w, r, par, tn, tf < best ? tf : best, sref + sp, slo + sp, shi + sp, &st);
            if (n < 0)
                goto pop;
            sp += n;
            /* a branch per cell rather than w->child[cell]: when the branch
             * is predicted (coherent rays), the next node's address is
             * known as soon as this node is loaded */
            switch (st.cell) {
                KD_NEAR(0) KD_NEAR(1) KD_NEAR(2) KD_NEAR(3) KD_NEAR(4) KD_NEAR(5) KD_NEAR(6)
            default:
                KD_NEAR(7)
            }
#else
            unsigned cell = 0; /* set whenever the step returns >= 0 */
            int n = wide_step_scalar(w, r, par, tn, tf < best ? tf : best, sref + sp, slo + sp, shi + sp, &cell, &tn,
                                     &tf);
            if (n < 0)
                goto pop;
            sp += n;
            ref = w->child[cell];
#endif
        }
        if (ref >= RT_KD_ONE) {
            if (test_prim(tree, ref & RT_KD_PAYLOAD, ray, &r->tr, &best, hit, any)) {
                found = true;
                if (any)
                    return true;
            }
        } else {
            const uint32_t *p = ids + (ref & RT_KD_PAYLOAD);
            if (test_leaf(tree, p, ray, &r->tr, &best, hit, any)) {
                found = true;
                if (any)
                    return true;
            }
        }
    pop:
        for (;;) { /* next cell that starts before the closest hit */
            if (sp == 0)
                return found;
            sp--;
            if (slo[sp] <= best)
                break;
        }
        ref = sref[sp];
        tn = slo[sp];
        tf = shi[sp];
    }
}

/* Two copies of the loop: rays parallel to some axis (rare: a zero direction
 * component) need a case in every step that the others skip. */
KD_INLINE bool traverse(const rt_kdtree *tree, const rt_ray *ray, rt_hit *hit, bool any)
{
    kd_ray r;
    if (!ray_setup(tree, ray, &r))
        return false;
    if (!r.any_par)
        return traverse_ray(tree, ray, hit, any, false, &r, tree->root);
    return traverse_ray(tree, ray, hit, any, true, &r, tree->root);
}

KD_FLATTEN bool KD_NAME(rt_kd_intersect)(const rt_kdtree *tree, const rt_ray *ray, rt_hit *hit)
{
    hit->prim = RT_NONE;
    if (traverse(tree, ray, hit, false)) {
        rt_kd_finish_hit(tree, hit);
        return true;
    }
    hit->prim = RT_NONE;
    hit->inst = 0;
    return false;
}

KD_FLATTEN bool KD_NAME(rt_kd_occluded)(const rt_kdtree *tree, const rt_ray *ray)
{
    rt_hit h;
    return traverse(tree, ray, &h, true);
}

/* For the ray streams (kdtree_stream.c): the single-ray walk from child
 * reference ref (a wide node or a leaf) over the ray's [tn, tf], the t
 * interval the stream walk gave it in that cell, with ray->tmax the closest
 * hit so far; hit->prim the tree's primitive id. The ray passed the same
 * set-up in the stream (ray_setup would accept it). */
KD_FLATTEN bool KD_NAME(rt_kd_walk_from)(const rt_kdtree *tree, uint32_t ref, float tn, float tf, const rt_ray *ray,
                                         rt_hit *hit, bool any)
{
    kd_ray r;
    if (!ray_setup(tree, ray, &r))
        return false;
    r.tn = tn;
    r.tf = tf;
    if (!r.any_par)
        return traverse_ray(tree, ray, hit, any, false, &r, ref);
    return traverse_ray(tree, ray, hit, any, true, &r, ref);
}

#ifndef KD_SIMD
/* The portable pass's leaf test, for the ray streams (the AVX2 pass's is
 * rt_kd_leaf_hit_avx2 below). */
KD_FLATTEN bool rt_kd_leaf_hit_portable(const rt_kdtree *tree, uint32_t ref, const rt_ray *ray, const rt_tri_ray *tr,
                                        float *best, rt_hit *hit, bool any)
{
    if (ref >= RT_KD_ONE)
        return test_prim(tree, ref & RT_KD_PAYLOAD, ray, tr, best, hit, any);
    return test_leaf(tree, tree->prim_ids + (ref & RT_KD_PAYLOAD), ray, tr, best, hit, any);
}
#endif

#ifdef KD_SIMD
/* For the packet traversal (kdtree_packet.c): one leaf, or one primitive,
 * for one ray, out of line. */
KD_FLATTEN bool rt_kd_leaf_hit_avx2(const rt_kdtree *tree, uint32_t ref, const rt_ray *ray, const rt_tri_ray *tr,
                                    float *best, rt_hit *hit, bool any)
{
    if (ref >= RT_KD_ONE)
        return test_prim(tree, ref & RT_KD_PAYLOAD, ray, tr, best, hit, any);
    const uint32_t *p = tree->prim_ids + (ref & RT_KD_PAYLOAD);
    return test_leaf(tree, p, ray, tr, best, hit, any);
}

KD_FLATTEN bool rt_kd_prim_hit_avx2(const rt_kdtree *tree, uint32_t id, const rt_ray *ray, const rt_tri_ray *tr,
                                    float *best, rt_hit *hit)
{
    return test_prim(tree, id, ray, tr, best, hit, false);
}
KD_AVX2_END
#endif
#else
typedef int kd_trace_no_avx2; /* (ISO C wants something in a file) */
#endif
