/* test_camera_control.c - the interactive camera moves
 * (rt/render/camera_control.h) against what they promise, on many random
 * cameras: orbit keeps the distance to the pivot (and look_at in place when
 * it is the pivot) and never makes the camera degenerate; a yaw and its
 * opposite come back; pan keeps the view direction and, by
 * rt_camera_pan_scale per pixel, moves the old look_at by exactly that many
 * pixels on the film (projected through rt_camera_frame); dolly scales the
 * distance; walk keeps the direction; the printed `camera` line, read
 * back by the scene parser, gives the very same floats; and the depth a
 * glTF camera orbits about is the analytic distance to a sphere.
 */
#include "test_util.h"

#include <math.h>

#include "rt/accel/kdtree.h"
#include "rt/io/scene_parse.h"
#include "rt/render/camera.h"
#include "rt/render/camera_control.h"
#include "rt/render/sampling.h"

static float uniform(uint64_t *state, float lo, float hi)
{
    *state = *state * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * (float)((*state >> 40) & 0xffffff) / 16777216.0f;
}

static rt_vec3 random_point(uint64_t *st, float r)
{
    return rt_v3(uniform(st, -r, r), uniform(st, -r, r), uniform(st, -r, r));
}

/* A usable random camera: up near +y or any direction, fov 10..120. */
static rt_camera random_camera(uint64_t *st)
{
    for (;;) {
        rt_camera c;
        memset(&c, 0, sizeof c);
        c.position = random_point(st, 10.0f);
        c.look_at = random_point(st, 10.0f);
        c.up = uniform(st, 0, 1) < 0.5f ? rt_v3(0, 1, 0) : random_point(st, 1.0f);
        c.vfov_deg = uniform(st, 10.0f, 120.0f);
        rt_camera_frame cf;
        rt_vec3 f = rt_normalize(rt_sub(c.look_at, c.position));
        if (rt_length(rt_sub(c.look_at, c.position)) > 0.5f && rt_length(c.up) > 0.1f &&
            fabsf(rt_dot(f, rt_normalize(c.up))) < 0.95f && rt_camera_frame_init(&cf, &c, 64, 48))
            return c;
    }
}

static float dist(rt_vec3 a, rt_vec3 b) { return rt_length(rt_sub(a, b)); }

static rt_vec3 view_dir(const rt_camera *c) { return rt_normalize(rt_sub(c->look_at, c->position)); }

static void assert_near(double got, double want, double tol, const char *what)
{
    if (!(fabs(got - want) <= tol))
        fail_msg("%s: got %.9g, want %.9g (tolerance %.3g)", what, got, want, tol);
}

static void assert_usable(const rt_camera *c)
{
    rt_camera_frame cf;
    if (!rt_camera_frame_init(&cf, c, 64, 48))
        fail_msg("the camera became degenerate: position %g %g %g look_at %g %g %g", c->position.x, c->position.y,
                 c->position.z, c->look_at.x, c->look_at.y, c->look_at.z);
}

static void test_orbit_keeps_distance(void **state)
{
    (void)state;
    uint64_t st = 1;
    for (int i = 0; i < 2000; i++) {
        rt_camera c = random_camera(&st);
        float yaw = uniform(&st, -7.0f, 7.0f), pitch = uniform(&st, -4.0f, 4.0f);
        /* about look_at: look_at stays where it is */
        rt_camera o = rt_camera_orbit(c, c.look_at, yaw, pitch);
        float d0 = dist(c.position, c.look_at);
        assert_near(dist(o.position, o.look_at), d0, 2e-6 * d0 + 1e-6, "distance to look_at after an orbit");
        assert_true(memcmp(&o.look_at, &c.look_at, sizeof o.look_at) == 0);
        assert_true(memcmp(&o.up, &c.up, sizeof o.up) == 0);
        assert_usable(&o);
        /* about another pivot: both points keep their distances to it */
        rt_vec3 pivot = random_point(&st, 5.0f);
        rt_camera p = rt_camera_orbit(c, pivot, yaw, pitch);
        float dp = dist(c.position, pivot), dl = dist(c.look_at, pivot);
        assert_near(dist(p.position, pivot), dp, 2e-6 * dp + 1e-5, "position's distance to the pivot");
        assert_near(dist(p.look_at, pivot), dl, 2e-6 * dl + 1e-5, "look_at's distance to the pivot");
    }
}

/* A yaw undone by the opposite yaw, a full turn, and a pitch that would go
 * over the top stopping 1 degree short of up. */
static void test_orbit_turns(void **state)
{
    (void)state;
    uint64_t st = 2;
    for (int i = 0; i < 500; i++) {
        rt_camera c = random_camera(&st);
        float yaw = uniform(&st, -3.0f, 3.0f), d0 = dist(c.position, c.look_at);
        rt_camera back = rt_camera_orbit(rt_camera_orbit(c, c.look_at, yaw, 0.0f), c.look_at, -yaw, 0.0f);
        assert_near(dist(back.position, c.position), 0.0, 1e-5 * d0 + 1e-5, "yaw then -yaw");
        rt_camera full = rt_camera_orbit(c, c.look_at, 2.0f * RT_PI, 0.0f);
        assert_near(dist(full.position, c.position), 0.0, 1e-5 * d0 + 1e-5, "a full turn");
        /* yaw keeps the height along up */
        rt_vec3 u = rt_normalize(c.up);
        rt_camera y = rt_camera_orbit(c, c.look_at, yaw, 0.0f);
        assert_near(rt_dot(rt_sub(y.position, c.look_at), u), rt_dot(rt_sub(c.position, c.look_at), u),
                    1e-5 * d0 + 1e-5, "height along up after a yaw");
        for (int s = -1; s <= 1; s += 2) {
            rt_camera top = rt_camera_orbit(c, c.look_at, 0.0f, (float)s * 10.0f);
            double polar = acos(rt_dot(rt_normalize(rt_sub(top.position, top.look_at)), u)) * 180.0 / RT_PI;
            assert_near(polar, s > 0 ? 1.0 : 179.0, 1e-3, "pitch stops 1 degree short of up");
            assert_usable(&top);
        }
    }
    /* the sign: a positive pitch raises the camera, a positive yaw turns it
     * counter-clockwise seen from above (+z towards +x about +y) */
    rt_camera c = {.position = {0, 0, 5}, .look_at = {0, 0, 0}, .up = {0, 1, 0}, .vfov_deg = 40};
    rt_camera up = rt_camera_orbit(c, c.look_at, 0.0f, 0.3f);
    assert_near(up.position.y, 5.0 * sin(0.3), 1e-5, "pitch 0.3: height");
    rt_camera left = rt_camera_orbit(c, c.look_at, 0.3f, 0.0f);
    assert_near(left.position.x, 5.0 * sin(0.3), 1e-5, "yaw 0.3: x");
    assert_near(left.position.z, 5.0 * cos(0.3), 1e-5, "yaw 0.3: z");
}

/* Where point p lands on a W x H film of camera c (rt/render/camera.h's
 * convention, inverted). */
static void project(const rt_camera *c, rt_vec3 p, int w, int h, double *fx, double *fy)
{
    rt_camera_frame cf;
    assert_true(rt_camera_frame_init(&cf, c, w, h));
    rt_vec3 d = rt_sub(p, cf.origin);
    double z = rt_dot(d, cf.forward);
    double sx = rt_dot(d, cf.right) / z, sy = rt_dot(d, cf.up) / z;
    *fx = (sx / ((double)cf.tan_half * cf.aspect) + 1.0) * 0.5 * w;
    *fy = (1.0 - sy / cf.tan_half) * 0.5 * h;
}

static void test_pan_keeps_direction(void **state)
{
    (void)state;
    uint64_t st = 3;
    for (int i = 0; i < 2000; i++) {
        rt_camera c = random_camera(&st);
        int w = 64, h = 48;
        float s = rt_camera_pan_scale(&c, h);
        float px = uniform(&st, -20.0f, 20.0f), py = uniform(&st, -20.0f, 20.0f);
        rt_camera p = rt_camera_pan(c, -px * s, py * s); /* the scene follows the mouse by (px, py) pixels */
        rt_vec3 f0 = view_dir(&c), f1 = view_dir(&p);
        assert_near(rt_length(rt_sub(f0, f1)), 0.0, 1e-5, "view direction after a pan");
        float d0 = dist(c.position, c.look_at);
        assert_near(dist(p.position, p.look_at), d0, 1e-5 * d0, "distance to look_at after a pan");
        assert_near(dist(p.position, c.position), sqrt((double)px * px + (double)py * py) * s, 1e-5 * d0,
                    "pan length");
        double fx, fy;
        project(&p, c.look_at, w, h, &fx, &fy);
        assert_near(fx, 0.5 * w + px, 2e-3, "the old look_at's film x after the pan");
        assert_near(fy, 0.5 * h + py, 2e-3, "the old look_at's film y after the pan");
    }
}

static void test_dolly_and_walk(void **state)
{
    (void)state;
    uint64_t st = 4;
    for (int i = 0; i < 2000; i++) {
        rt_camera c = random_camera(&st);
        float k = uniform(&st, 0.1f, 3.0f), d0 = dist(c.position, c.look_at);
        rt_camera d = rt_camera_dolly(c, k);
        assert_true(memcmp(&d.look_at, &c.look_at, sizeof d.look_at) == 0);
        assert_near(dist(d.position, d.look_at), (double)k * d0, 1e-5 * d0, "distance after a dolly");
        assert_near(rt_length(rt_sub(view_dir(&d), view_dir(&c))), 0.0, 1e-5, "view direction after a dolly");
        rt_camera tiny = rt_camera_dolly(c, 0.0f); /* never onto look_at */
        assert_usable(&tiny);
        float fw = uniform(&st, -3.0f, 3.0f), rt = uniform(&st, -3.0f, 3.0f), up = uniform(&st, -3.0f, 3.0f);
        rt_camera w = rt_camera_walk(c, fw, rt, up);
        assert_near(rt_length(rt_sub(view_dir(&w), view_dir(&c))), 0.0, 1e-5, "view direction after a walk");
        rt_vec3 moved = rt_sub(w.position, c.position);
        assert_near(rt_dot(moved, view_dir(&c)), fw + up * rt_dot(rt_normalize(c.up), view_dir(&c)), 1e-4,
                    "forward component of a walk");
        assert_near(rt_dot(moved, rt_normalize(c.up)),
                    up + fw * rt_dot(rt_normalize(c.up), view_dir(&c)), 1e-4, "up component of a walk");
    }
}

/* The printed line parses back to the same camera, bit for bit. */
static void test_camera_line_round_trip(void **state)
{
    (void)state;
    uint64_t st = 5;
    for (int i = 0; i < 3000; i++) {
        rt_camera c = random_camera(&st);
        /* values of every size, signs and exponents */
        float scale = powf(10.0f, uniform(&st, -6.0f, 6.0f));
        c.position = rt_scale(c.position, scale);
        c.look_at = rt_scale(c.look_at, scale);
        if (i % 3 == 0) {
            c.aperture = uniform(&st, 0.0f, 0.5f);
            c.focus_distance = uniform(&st, 0.0f, 20.0f);
        }
        if (i % 7 == 0)
            c.up = rt_v3(0.0f, -0.0f, 1.0f);
        if (i % 5 == 0) { /* an open shutter: motion blur */
            c.shutter_open = uniform(&st, -0.1f, 0.0f);
            c.shutter_close = uniform(&st, 0.001f, 0.1f);
        }
        if (!(rt_length(rt_cross(rt_normalize(rt_sub(c.look_at, c.position)), rt_normalize(c.up))) > 1e-6f) ||
            !(rt_length2(rt_sub(c.look_at, c.position)) > 0.0f))
            continue;
        char line[1024];
        int n = rt_camera_format(&c, line, sizeof line);
        assert_true(n > 0 && (size_t)n < sizeof line);
        assert_int_equal(strncmp(line, "camera position ", 16), 0);
        assert_null(strchr(line, '\n'));
        rt_scene s;
        rt_scene_init(&s);
        rt_error err = {0};
        if (rt_scene_parse_string(&s, NULL, line, strlen(line), "<line>", "", &err) != RT_OK)
            fail_msg("'%s' does not parse: %s", line, err.message);
        assert_true(s.camera_set);
        assert_memory_equal(&s.camera.position, &c.position, sizeof c.position);
        assert_memory_equal(&s.camera.look_at, &c.look_at, sizeof c.look_at);
        assert_memory_equal(&s.camera.up, &c.up, sizeof c.up);
        assert_memory_equal(&s.camera.vfov_deg, &c.vfov_deg, sizeof(float));
        assert_memory_equal(&s.camera.aperture, &c.aperture, sizeof(float));
        assert_memory_equal(&s.camera.focus_distance, &c.focus_distance, sizeof(float));
        assert_memory_equal(&s.camera.shutter_open, &c.shutter_open, sizeof(float));
        assert_memory_equal(&s.camera.shutter_close, &c.shutter_close, sizeof(float));
        rt_scene_free(&s);
    }
    /* a short buffer: the length it would need, a cut (terminated) string */
    rt_camera c = {.position = {1, 2, 3}, .look_at = {0, 0, 0}, .up = {0, 1, 0}, .vfov_deg = 40, .aperture = 0.1f};
    char big[512], small[16];
    int n = rt_camera_format(&c, big, sizeof big);
    assert_string_equal(big, "camera position 1 2 3 look_at 0 0 0 up 0 1 0 fov 40 aperture 0.100000001");
    assert_int_equal(rt_camera_format(&c, small, sizeof small), n);
    assert_int_equal(strlen(small), sizeof small - 1);
}

/* rt_camera_depth against the analytic distance to a sphere of radius 1
 * at the origin: a camera looking at a point inside it gets the first
 * intersection of the view ray (the ray through the image's centre); one
 * looking past it, the depth of the bounds' centre along the view; one
 * looking away, 0. rt_camera_look_at_depth puts look_at at that distance
 * along the same view. */
static void test_depth(void **state)
{
    (void)state;
    const char *text = "material m color 0.5 0.5 0.5\nsphere 0 0 0 1 m\n";
    rt_scene s;
    rt_scene_init(&s);
    rt_error err = {0};
    if (rt_scene_parse_string(&s, NULL, text, strlen(text), "<sphere>", "", &err) != RT_OK)
        fail_msg("the test scene does not parse: %s", err.message);
    rt_kdtree tree;
    assert_int_equal(rt_kdtree_build(&tree, &s, NULL, &err), RT_OK);
    uint64_t st = 6;
    int hits = 0, past = 0, away = 0;
    for (int i = 0; i < 3000; i++) {
        rt_camera c = random_camera(&st);
        c.position = rt_scale(rt_normalize(c.position), uniform(&st, 1.5f, 30.0f));
        int kind = i % 3;
        if (kind == 0) /* at a point inside the sphere */
            c.look_at = rt_scale(random_point(&st, 1.0f), 0.55f);
        else if (kind == 1) /* past it: a point 3 units off the line to the centre, beyond it */
            c.look_at = rt_add(rt_scale(c.position, -1.0f), rt_scale(rt_normalize(rt_cross(c.position, c.up)), 3.0f));
        else /* away from it */
            c.look_at = rt_scale(c.position, 2.0f);
        rt_camera_frame cf;
        if (!rt_camera_frame_init(&cf, &c, 64, 48))
            continue;
        /* in double: the ray p + t f against |x| = 1 */
        double p[3] = {c.position.x, c.position.y, c.position.z}, f[3] = {c.look_at.x - p[0], c.look_at.y - p[1],
                                                                          c.look_at.z - p[2]};
        double fl = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
        for (int k = 0; k < 3; k++)
            f[k] /= fl;
        double b = -(p[0] * f[0] + p[1] * f[1] + p[2] * f[2]), cc = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - 1.0;
        double disc = b * b - cc, want;
        if (disc > 1e-3 && b - sqrt(disc) > 0.0) {
            want = b - sqrt(disc);
            hits++;
        } else if (b < 0.0) { /* the sphere and its centre behind the camera */
            want = 0.0;
            away++;
        } else if (disc < -1e-3) {
            want = b; /* the bounds' centre, the origin, along the view */
            past++;
        } else {
            continue; /* grazing: either answer would do */
        }
        float got = rt_camera_depth(&c, &s, &tree);
        assert_near(got, want, 1e-4 * (1.0 + want), "depth");
        if (got > 0.0f) {
            rt_camera d = rt_camera_look_at_depth(c, got);
            assert_near(dist(d.position, d.look_at), got, 1e-5 * got, "distance to the new look_at");
            assert_near(rt_length(rt_sub(view_dir(&d), view_dir(&c))), 0.0, 1e-6, "view direction");
            assert_true(memcmp(&d.position, &c.position, sizeof c.position) == 0);
        }
        rt_camera same = rt_camera_look_at_depth(c, 0.0f);
        assert_true(memcmp(&same, &c, sizeof c) == 0);
    }
    assert_true(hits > 500 && past > 500 && away > 500);
    assert_near(rt_camera_depth(&(rt_camera){.position = {0, 0, 5}, .look_at = {0, 0, 4}, .up = {0, 1, 0},
                                             .vfov_deg = 40},
                                &s, &tree),
                4.0, 1e-6, "a glTF-like camera 5 units away, look_at 1 unit ahead");
    rt_kdtree_free(&tree);
    rt_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_orbit_keeps_distance), cmocka_unit_test(test_orbit_turns),
        cmocka_unit_test(test_pan_keeps_direction),  cmocka_unit_test(test_dolly_and_walk),
        cmocka_unit_test(test_camera_line_round_trip), cmocka_unit_test(test_depth),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
