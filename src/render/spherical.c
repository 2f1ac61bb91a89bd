/* spherical.c - sampling rectangles and triangles uniformly by the solid
 * angle they subtend from a point.
 *
 * Rectangles: Urena, Fajardo and King 2013, "An Area-Preserving
 * Parametrization for Spherical Rectangles" (EGSR). In a frame with x, y
 * along the edges and z pointing from the point o towards the rectangle's
 * plane (z0 < 0 is the plane's offset), the rectangle is [x0,x1] x [y0,y1]
 * at z = z0. The planes through o and each edge have unit normals n0..n3;
 * the spherical rectangle's interior angles are g_i = acos(-n_i . n_i+1)
 * and its solid angle S = g0 + g1 + g2 + g3 - 2 pi. A first uniform number
 * picks the sub-area S u1 swept from the x0 edge, which fixes the x
 * coordinate xu of a vertical line of the rectangle (eq. 4-7 of the
 * paper); the second is uniform in the sine-like coordinate h = y / sqrt(x^2
 * + y^2 + z^2) along that line (uniform in solid angle there), which gives
 * yv. Area-preserving in both numbers.
 *
 * Triangles: Arvo 1995, "Stratified Sampling of Spherical Triangles"
 * (SIGGRAPH). With unit directions A, B, C, angles alpha, beta, gamma and
 * area (solid angle) alpha + beta + gamma - pi, the first number picks the
 * sub-triangle A B C' of area u1 x area (C' on the arc AC, solved in closed
 * form from the spherical law of cosines); the second picks the point on
 * the arc B C' with its cosine to B linear in u2:
 *   s = sin(A' - alpha), t = cos(A' - alpha), A' = u1 x area
 *   u = t - cos alpha, v = s + sin alpha cos c   (c: the arc AB)
 *   q = ((v t - u s) cos alpha - v) / ((v s + u t) sin alpha) = cos of the arc AC'
 *   C' = q A + sqrt(1 - q^2) unit(C - (C.A) A)
 *   z = 1 - u2 (1 - C'.B),  P = z B + sqrt(1 - z^2) unit(C' - (C'.B) B)
 * The interior angles come from the normals of the planes through p and
 * each edge, as in pbrt-v4 (Pharr, Jakob, Humphreys, 4th ed.). All in
 * double precision; the renderer falls back to area sampling outside
 * pbrt-v4's range of solid angles (rt_sph_in_range).
 */
#include "rt/render/spherical.h"

#include <math.h>

#define PI_D 3.14159265358979323846

typedef struct dvec {
    double x, y, z;
} dvec;

static inline dvec dv(rt_vec3 a) { dvec r = {a.x, a.y, a.z}; return r; }
static inline dvec dsub(dvec a, dvec b) { dvec r = {a.x - b.x, a.y - b.y, a.z - b.z}; return r; }
static inline dvec dscale(dvec a, double s) { dvec r = {a.x * s, a.y * s, a.z * s}; return r; }
static inline dvec dadd(dvec a, dvec b) { dvec r = {a.x + b.x, a.y + b.y, a.z + b.z}; return r; }
static inline double ddot(dvec a, dvec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline dvec dcross(dvec a, dvec b)
{
    dvec r = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    return r;
}
static inline double dlen(dvec a) { return sqrt(ddot(a, a)); }
static inline double dclamp(double x, double lo, double hi) { return x < lo ? lo : (x > hi ? hi : x); }
static inline rt_vec3 fv(dvec a) { return rt_v3((float)a.x, (float)a.y, (float)a.z); }

/* Unit vector along a, or false when it has no length. */
static inline bool dunit(dvec a, dvec *out)
{
    double l = dlen(a);
    if (!(l > 0.0) || !isfinite(l))
        return false;
    *out = dscale(a, 1.0 / l);
    return true;
}

/* ------------------------------------------------------------ rectangles */

/* The interior angle of the spherical rectangle at a vertex (x, y, z0)
 * is the argument of (c, h |v|) with c = +-x y (the paper's -n_i . n_i+1
 * times the lengths of both normals, h = -z0): its four angles are
 * multiplied as complex numbers, so that S = arg(z0 z1 z2 z3) (g sums to
 * S + 2 pi) costs one atan2, and k = 2 pi - arg(z2 z3) enters the sampler
 * only through its cosine and sine. */
typedef struct cplx {
    double re, im;
} cplx;

static inline cplx cmul(cplx a, cplx b)
{
    cplx r = {a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re};
    return r;
}

bool rt_sph_rect_init(rt_sph_rect *r, rt_vec3 corner, rt_vec3 ex, rt_vec3 ey, rt_vec3 o)
{
    r->S = 0.0f;
    dvec ux = dv(ex), uy = dv(ey);
    double exl = dlen(ux), eyl = dlen(uy);
    if (!(exl > 0.0 && eyl > 0.0))
        return false;
    dvec x = dscale(ux, 1.0 / exl), y = dscale(uy, 1.0 / eyl);
    dvec z = dcross(x, y);
    dvec d = dsub(dv(corner), dv(o));
    double z0 = ddot(d, z);
    if (z0 > 0.0) { /* z points from the rectangle's plane towards o: flip it */
        z = dscale(z, -1.0);
        z0 = -z0;
    }
    if (!(z0 < 0.0) || !isfinite(z0))
        return false; /* o in the plane */
    double x0 = ddot(d, x), y0 = ddot(d, y), x1 = x0 + exl, y1 = y0 + eyl;
    double h = -z0, h2 = z0 * z0;
    /* the angles at v10, v11, v01, v00 (the paper's g0 .. g3) */
    cplx g0 = {x1 * y0, h * sqrt(x1 * x1 + y0 * y0 + h2)};
    cplx g1 = {-x1 * y1, h * sqrt(x1 * x1 + y1 * y1 + h2)};
    cplx g2 = {x0 * y1, h * sqrt(x0 * x0 + y1 * y1 + h2)};
    cplx g3 = {-x0 * y0, h * sqrt(x0 * x0 + y0 * y0 + h2)};
    cplx g23 = cmul(g2, g3), all = cmul(cmul(g0, g1), g23);
    double S = atan2(all.im, all.re); /* g0 + g1 + g2 + g3 - 2 pi, in (0, 2 pi) */
    if (S <= 0.0)
        S += 2.0 * PI_D;
    double l23 = sqrt(g23.re * g23.re + g23.im * g23.im);
    if (!(S > 0.0) || !isfinite(S) || !(l23 > 0.0) || !isfinite(l23))
        return false;
    r->x = fv(x);
    r->y = fv(y);
    r->z = fv(z);
    r->x0 = x0;
    r->y0 = y0;
    r->z0 = z0;
    r->x1 = x1;
    r->y1 = y1;
    r->b0 = -y0 / sqrt(h2 + y0 * y0); /* n0.z */
    r->b1 = y1 / sqrt(h2 + y1 * y1);  /* n2.z */
    r->cos_k = g23.re / l23;          /* k = 2 pi - arg(g2 g3) */
    r->sin_k = -g23.im / l23;
    r->S = (float)S;
    return true;
}

rt_vec3 rt_sph_rect_sample(const rt_sph_rect *r, rt_vec2 u, float *dist)
{
    double z0 = r->z0, b0 = r->b0;
    /* the x coordinate of the vertical line that sweeps solid angle u.x S:
     * au = u.x S + k, through the sum formulas */
    double us = (double)u.x * (double)r->S, cs = cos(us), sn = sin(us);
    double cos_au = r->cos_k * cs - r->sin_k * sn, sin_au = r->sin_k * cs + r->cos_k * sn;
    double fu = (cos_au * b0 - r->b1) / sin_au;
    double cu = 1.0 / sqrt(fu * fu + b0 * b0);
    cu = dclamp(fu > 0.0 ? cu : -cu, -1.0, 1.0);
    double xu = -(cu * z0) / sqrt(fmax(1e-300, 1.0 - cu * cu));
    xu = isfinite(xu) ? dclamp(xu, r->x0, r->x1) : (cu > 0.0 ? r->x1 : r->x0);
    /* along it, uniform in h = y / |(xu, y, z0)| */
    double dd2 = xu * xu + z0 * z0, dd = sqrt(dd2);
    double h0 = r->y0 / sqrt(dd2 + r->y0 * r->y0), h1 = r->y1 / sqrt(dd2 + r->y1 * r->y1);
    double hv = h0 + (double)u.y * (h1 - h0), hv2 = hv * hv;
    double yv = hv2 < 1.0 - 1e-12 ? hv * dd / sqrt(1.0 - hv2) : r->y1;
    yv = dclamp(yv, r->y0, r->y1);
    dvec w = dadd(dadd(dscale(dv(r->x), xu), dscale(dv(r->y), yv)), dscale(dv(r->z), z0));
    double l = sqrt(dd2 + yv * yv);
    *dist = (float)l;
    return fv(dscale(w, 1.0 / l));
}

/* ------------------------------------------------------------ triangles */

/* The angle between vectors a and b as the complex number (cos, sin)
 * times |a| |b|. */
static inline cplx angle_between(dvec a, dvec b)
{
    cplx r = {ddot(a, b), dlen(dcross(a, b))};
    return r;
}

bool rt_sph_tri_init(rt_sph_tri *t, rt_vec3 a, rt_vec3 b, rt_vec3 c, rt_vec3 p)
{
    t->S = 0.0f;
    dvec dp = dv(p), A, B, C;
    if (!dunit(dsub(dv(a), dp), &A) || !dunit(dsub(dv(b), dp), &B) || !dunit(dsub(dv(c), dp), &C))
        return false;
    dvec nab = dcross(A, B), nbc = dcross(B, C), nca = dcross(C, A);
    /* interior angles: between the planes through each vertex's two edges;
     * their sum minus pi is the argument of minus their product */
    cplx za = angle_between(nab, dscale(nca, -1.0));
    cplx zb = angle_between(nbc, dscale(nab, -1.0));
    cplx zc = angle_between(nca, dscale(nbc, -1.0));
    cplx prod = cmul(cmul(za, zb), zc);
    double la = sqrt(za.re * za.re + za.im * za.im);
    double area = atan2(-prod.im, -prod.re);
    if (area <= 0.0)
        area += 2.0 * PI_D;
    if (!(la > 0.0) || !isfinite(la) || !(area > 0.0) || !isfinite(area) || !(prod.re != 0.0 || prod.im != 0.0))
        return false;
    t->a[0] = A.x, t->a[1] = A.y, t->a[2] = A.z;
    t->b[0] = B.x, t->b[1] = B.y, t->b[2] = B.z;
    t->c[0] = C.x, t->c[1] = C.y, t->c[2] = C.z;
    t->cos_alpha = za.re / la;
    t->sin_alpha = za.im / la;
    t->cos_c = dclamp(ddot(A, B), -1.0, 1.0);
    t->S = (float)area;
    return true;
}

rt_vec3 rt_sph_tri_sample(const rt_sph_tri *t, rt_vec2 u)
{
    dvec A = {t->a[0], t->a[1], t->a[2]}, B = {t->b[0], t->b[1], t->b[2]}, C = {t->c[0], t->c[1], t->c[2]};
    /* C' on the arc AC such that A B C' has area u.x x area; s, c: the
     * sine and cosine of (u.x area - alpha) by the difference formulas */
    double ap = (double)u.x * (double)t->S, sa = sin(ap), ca = cos(ap);
    double s = sa * t->cos_alpha - ca * t->sin_alpha, c = ca * t->cos_alpha + sa * t->sin_alpha;
    double uu = c - t->cos_alpha, vv = s + t->sin_alpha * t->cos_c;
    double q = ((vv * c - uu * s) * t->cos_alpha - vv) / ((vv * s + uu * c) * t->sin_alpha);
    q = isfinite(q) ? dclamp(q, -1.0, 1.0) : 1.0;
    dvec cperp, cp = A;
    if (dunit(dsub(C, dscale(A, ddot(C, A))), &cperp))
        cp = dadd(dscale(A, q), dscale(cperp, sqrt(fmax(0.0, 1.0 - q * q))));
    /* the point on the arc B C' whose cosine to B is linear in u.y */
    double z = dclamp(1.0 - (double)u.y * (1.0 - ddot(cp, B)), -1.0, 1.0);
    dvec bperp, w = B;
    if (dunit(dsub(cp, dscale(B, ddot(cp, B))), &bperp))
        w = dadd(dscale(B, z), dscale(bperp, sqrt(fmax(0.0, 1.0 - z * z))));
    dunit(w, &w);
    return fv(w);
}
