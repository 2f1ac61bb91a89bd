/* camera_control.c - orbit, pan, dolly and walk for the interactive viewer
 * (rt/render/camera_control.h), and the camera as a scene-file line.
 *
 * Orbit is a turntable, as in yocto-gl's and pbrt-v4's viewers: the offset
 * of position (and look_at) from the pivot turns by Rodrigues' rotation
 * formula, v' = v cos a + (k x v) sin a + k (k . v)(1 - cos a) for a unit
 * axis k, first about the image's right axis (pitch, kept 1 degree away
 * from `up` so the camera never becomes degenerate), then about `up`
 * (yaw). The rotation runs in double precision, so the distance to the
 * pivot changes by no more than the final rounding to float. Pan and walk
 * move position and look_at by one vector in the camera's frame (the frame
 * of rt_camera_frame_init: f = normalize(look_at - position), r =
 * normalize(f x up), u = r x f); dolly scales the distance to look_at.
 * A camera whose look_at is only a direction (a glTF camera's, 1 unit
 * ahead) gets its pivot from the scene: the first surface the ray through
 * the image's centre meets (that ray is the view direction f itself), else
 * the depth of the scene bounds' centre along f.
 *
 * The `camera` line prints floats with %.9g: nine significant digits
 * identify every binary32 value (IEEE 754-2008, 5.12.2), so the scene
 * parser's strtod-and-round reads back the very float.
 */
#include "rt/render/camera_control.h"

#include <math.h>
#include <stdio.h>

#include "rt/accel/kdtree.h"

#define MIN_POLAR_DEG 1.0
#define PI_D 3.14159265358979323846

typedef struct dvec {
    double x, y, z;
} dvec;

static dvec dv(rt_vec3 v) { return (dvec){v.x, v.y, v.z}; }
static rt_vec3 fv(dvec v) { return rt_v3((float)v.x, (float)v.y, (float)v.z); }
static dvec dsub(dvec a, dvec b) { return (dvec){a.x - b.x, a.y - b.y, a.z - b.z}; }
static dvec dadd(dvec a, dvec b) { return (dvec){a.x + b.x, a.y + b.y, a.z + b.z}; }
static dvec dscale(dvec a, double s) { return (dvec){a.x * s, a.y * s, a.z * s}; }
static double ddot(dvec a, dvec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static dvec dcross(dvec a, dvec b) { return (dvec){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
static double dlen(dvec a) { return sqrt(ddot(a, a)); }

static dvec dnormalize(dvec a)
{
    double l = dlen(a);
    return l > 0.0 ? dscale(a, 1.0 / l) : a;
}

/* v turned by `angle` radians about the unit axis k (Rodrigues). */
static dvec rotate(dvec v, dvec k, double angle)
{
    double c = cos(angle), s = sin(angle);
    return dadd(dadd(dscale(v, c), dscale(dcross(k, v), s)), dscale(k, ddot(k, v) * (1.0 - c)));
}

/* The camera's frame: forward, right, up (unit vectors), as camera.c makes it. */
static void frame(const rt_camera *c, dvec *f, dvec *r, dvec *u)
{
    *f = dnormalize(dsub(dv(c->look_at), dv(c->position)));
    *r = dnormalize(dcross(*f, dv(c->up)));
    *u = dcross(*r, *f);
}

rt_camera rt_camera_orbit(rt_camera c, rt_vec3 pivot, float yaw, float pitch)
{
    dvec p = dv(pivot), f, r, u;
    frame(&c, &f, &r, &u);
    dvec up = dnormalize(dv(c.up));
    dvec v = dsub(dv(c.position), p), w = dsub(dv(c.look_at), p);
    /* pitch: the angle between the offset and up shrinks by `pitch`, kept in
     * [1, 179] degrees (measured on the view direction when the pivot is
     * on it, as it is for look_at) */
    double polar = acos(fmax(-1.0, fmin(1.0, ddot(dscale(f, -1.0), up))));
    double lo = MIN_POLAR_DEG * (PI_D / 180.0), hi = PI_D - lo;
    double target = polar - (double)pitch;
    target = target < lo ? lo : (target > hi ? hi : target);
    double a = polar - target; /* > 0: up */
    if (a != 0.0 && dlen(r) > 0.0) {
        v = rotate(v, r, -a);
        w = rotate(w, r, -a);
    }
    if (yaw != 0.0f) {
        v = rotate(v, up, (double)yaw);
        w = rotate(w, up, (double)yaw);
    }
    c.position = fv(dadd(p, v));
    c.look_at = fv(dadd(p, w));
    return c;
}

rt_camera rt_camera_pan(rt_camera c, float dx, float dy)
{
    dvec f, r, u;
    frame(&c, &f, &r, &u);
    dvec d = dadd(dscale(r, (double)dx), dscale(u, (double)dy));
    c.position = fv(dadd(dv(c.position), d));
    c.look_at = fv(dadd(dv(c.look_at), d));
    return c;
}

rt_camera rt_camera_dolly(rt_camera c, float factor)
{
    dvec at = dv(c.look_at), off = dsub(dv(c.position), at);
    double k = (double)factor;
    k = k > 1e-4 ? k : 1e-4;
    if (!isfinite(k))
        return c;
    c.position = fv(dadd(at, dscale(off, k)));
    return c;
}

rt_camera rt_camera_walk(rt_camera c, float forward, float right, float up)
{
    dvec f, r, u;
    frame(&c, &f, &r, &u);
    dvec d = dadd(dadd(dscale(f, (double)forward), dscale(r, (double)right)),
                  dscale(dnormalize(dv(c.up)), (double)up));
    c.position = fv(dadd(dv(c.position), d));
    c.look_at = fv(dadd(dv(c.look_at), d));
    return c;
}

rt_camera rt_camera_look_at_depth(rt_camera c, float depth)
{
    dvec f, r, u;
    frame(&c, &f, &r, &u);
    if (!(depth > 0.0f) || !isfinite(depth) || dlen(f) == 0.0)
        return c;
    c.look_at = fv(dadd(dv(c.position), dscale(f, (double)depth)));
    return c;
}

float rt_camera_depth(const rt_camera *c, const rt_scene *scene, const rt_kdtree *tree)
{
    dvec f, r, u;
    frame(c, &f, &r, &u);
    if (dlen(f) == 0.0)
        return 0.0f;
    rt_ray ray = rt_ray_make(c->position, fv(f), 0.0f, INFINITY);
    rt_hit hit;
    if (tree && rt_kdtree_intersect(tree, &ray, &hit) && hit.t > 0.0f && isfinite(hit.t))
        return hit.t * rt_length(ray.dir); /* t is in units of |dir|, 1 up to rounding */
    rt_box b = rt_scene_bounds(scene);
    if (rt_box_is_empty(b))
        return 0.0f;
    dvec centre = dscale(dadd(dv(b.lo), dv(b.hi)), 0.5);
    double d = ddot(dsub(centre, dv(c->position)), f);
    return d > 0.0 && isfinite(d) ? (float)d : 0.0f;
}

float rt_camera_pan_scale(const rt_camera *c, int height)
{
    double dist = dlen(dsub(dv(c->look_at), dv(c->position)));
    double t = tan(0.5 * (double)c->vfov_deg * (PI_D / 180.0));
    return (float)(2.0 * t * dist / (double)(height > 0 ? height : 1));
}

int rt_camera_format(const rt_camera *c, char *buf, size_t size)
{
    int n = snprintf(buf, size, "camera position %.9g %.9g %.9g look_at %.9g %.9g %.9g up %.9g %.9g %.9g fov %.9g",
                     (double)c->position.x, (double)c->position.y, (double)c->position.z, (double)c->look_at.x,
                     (double)c->look_at.y, (double)c->look_at.z, (double)c->up.x, (double)c->up.y, (double)c->up.z,
                     (double)c->vfov_deg);
    if (n >= 0 && c->aperture > 0.0f)
        n += snprintf(size > (size_t)n ? buf + n : NULL, size > (size_t)n ? size - (size_t)n : 0, " aperture %.9g",
                      (double)c->aperture);
    if (n >= 0 && c->focus_distance > 0.0f)
        n += snprintf(size > (size_t)n ? buf + n : NULL, size > (size_t)n ? size - (size_t)n : 0, " focus %.9g",
                      (double)c->focus_distance);
    if (n >= 0 && c->shutter_close > c->shutter_open)
        n += snprintf(size > (size_t)n ? buf + n : NULL, size > (size_t)n ? size - (size_t)n : 0,
                      " shutter %.9g %.9g", (double)c->shutter_open, (double)c->shutter_close);
    return n;
}
