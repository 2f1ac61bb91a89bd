/* test_nanovdb.c - density grids from NanoVDB files (rt/io/nanovdb.h),
 * against files written by OpenVDB itself: the test writes a .vdb with
 * python3's pyopenvdb (Debian's python3-openvdb) and converts it with
 * nanovdb_convert (libnanovdb-tools), as a user would, then checks
 *   - the values of every voxel written, at the right dense index, zero
 *     where nothing was written, and the index-to-world map (a voxel's
 *     centre lands where OpenVDB's transform puts it);
 *   - a grid picked by name, the first float grid without one, an unknown
 *     name refused;
 *   - broken files refused with the field at fault and nothing allocated
 *     for claims the bytes cannot back: every 97th prefix, a wrong magic
 *     number, a compressed codec, another file version, a root tile count
 *     past the buffer, a 10^12-voxel bounding box, a NaN density, a
 *     nonzero background; and 3000 random single-byte changes, none of
 *     which may crash (the sanitizer builds run this too).
 * Skipped, saying why, when python3-openvdb or libnanovdb-tools is missing
 * (make installs them as test tools).
 */
#define PNANOVDB_C
#include <nanovdb/PNanoVDB.h>

#include "test_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rt/base/file.h"
#include "rt/io/nanovdb.h"
#include "rt/io/scene_parse.h"

static char dir[128];
static unsigned char *file_bytes;
static size_t file_size;

static const char *const make_vdb =
    "import sys\n"
    "import pyopenvdb as vdb\n"
    "t = vdb.FloatGrid()\n"
    "t.name = 'temperature'\n"
    "t.getAccessor().setValueOn((0, 0, 0), 300.0)\n"
    "g = vdb.FloatGrid()\n"
    "g.name = 'density'\n"
    "g.gridClass = vdb.GridClass.FOG_VOLUME\n"
    "a = g.getAccessor()\n"
    "for i in range(4):\n"
    "    for j in range(3):\n"
    "        for k in range(2):\n"
    "            if (i, j, k) != (2, 1, 0):\n"
    "                a.setValueOn((i - 1, j + 5, k), 0.1 * (i + 1) + 0.01 * j + 0.001 * k)\n"
    "m = [[0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 0.5, 0], [1, 2, 3, 1]]\n"
    "g.transform = vdb.createLinearTransform(matrix=m)\n"
    "vdb.write(sys.argv[1], grids=[t, g])\n";

static int setup(void **state)
{
    (void)state;
    file_bytes = NULL;
    if (!test_make_dir(dir, sizeof dir, "nanovdb"))
        return -1;
    char script[192], vdb[192], nvdb[192], cmd[1024];
    snprintf(script, sizeof script, "%s/make.py", dir);
    snprintf(vdb, sizeof vdb, "%s/grid.vdb", dir);
    snprintf(nvdb, sizeof nvdb, "%s/grid.nvdb", dir);
    test_write_file(script, make_vdb, strlen(make_vdb));
    /* Debian's python3 (pyopenvdb is built for it), not another on the PATH */
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 %s %s >/dev/null 2>&1 && nanovdb_convert %s %s >/dev/null 2>&1",
             script, vdb, vdb, nvdb);
    if (system(cmd) != 0)
        return 0; /* the tests skip, saying why */
    rt_error err = {0};
    char *bytes;
    if (rt_read_file(nvdb, 0, &bytes, &file_size, &err) != RT_OK)
        return -1;
    file_bytes = (unsigned char *)bytes;
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    free(file_bytes);
    test_remove_dir(dir);
    return 0;
}

static void need_file(void)
{
    if (!file_bytes) {
        fprintf(stderr, "skip: cannot make a NanoVDB file: needs /usr/bin/python3 with pyopenvdb (python3-openvdb) "
                        "and nanovdb_convert (libnanovdb-tools)\n");
        skip();
    }
}

static uint64_t next_random(uint64_t *s) /* xorshift64 */
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

static rt_result parse(const unsigned char *b, size_t n, const char *grid, rt_density_grid *g, rt_mat4 *m,
                       rt_error *err)
{
    return rt_nanovdb_parse(b, n, "grid.nvdb", grid, g, m, err);
}

static void test_values_and_placement(void **state)
{
    (void)state;
    need_file();
    rt_density_grid g;
    rt_mat4 m;
    rt_error err = {0};
    if (parse(file_bytes, file_size, "density", &g, &m, &err) != RT_OK)
        fail_msg("%s", err.message);
    assert_int_equal(g.nx, 4);
    assert_int_equal(g.ny, 3);
    assert_int_equal(g.nz, 2);
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < 2; k++) {
                float want = (i == 2 && j == 1 && k == 0) ? 0.0f : (float)(0.1 * (i + 1) + 0.01 * j + 0.001 * k);
                float got = g.density[rt_density_grid_index(&g, i, j, k)];
                if (fabsf(got - want) > 1e-6f)
                    fail_msg("voxel (%d, %d, %d): %g, wrote %g", i, j, k, (double)got, (double)want);
                /* the centre of dense voxel (i, j, k) is OpenVDB's voxel (i-1, j+5, k): world 0.5 ijk + (1, 2, 3) */
                rt_vec3 w = rt_mat4_point(&m, rt_v3(i + 0.5f, j + 0.5f, k + 0.5f));
                assert_true(fabsf(w.x - (0.5f * (i - 1) + 1)) < 1e-5f);
                assert_true(fabsf(w.y - (0.5f * (j + 5) + 2)) < 1e-5f);
                assert_true(fabsf(w.z - (0.5f * k + 3)) < 1e-5f);
            }
    assert_true(fabsf(g.max_density - 0.421f) < 1e-6f);
    rt_density_grid_free(&g);
}

/* The file's grids (segments of a 16-byte header, 176 bytes of metadata
 * and the name per grid, then the grids), read here by the layout of
 * NanoVDB's IO.h, independently of the reader under test. */
typedef struct table_entry {
    const char *name;
    size_t data, end;
} table_entry;

static void read_table(table_entry out[2])
{
    /* nanovdb_convert writes one segment per grid: header, metadata, name, grid */
    size_t at = 0;
    for (int i = 0; i < 2; i++) {
        uint16_t count;
        memcpy(&count, file_bytes + at + 12, 2);
        assert_int_equal(count, 1);
        at += 16;
        uint64_t size;
        uint32_t name_size;
        memcpy(&size, file_bytes + at, 8);
        memcpy(&name_size, file_bytes + at + 136, 4);
        out[i].name = (const char *)file_bytes + at + 176;
        at += 176 + name_size;
        out[i].data = at;
        at += (size_t)size;
        out[i].end = at;
    }
    assert_int_equal(at, file_size);
}

static const table_entry *density_entry(const table_entry t[2])
{
    return strcmp(t[0].name, "density") == 0 ? &t[0] : &t[1];
}

static void test_grid_by_name(void **state)
{
    (void)state;
    need_file();
    rt_density_grid g;
    rt_mat4 m;
    rt_error err = {0};
    assert_int_equal(parse(file_bytes, file_size, "temperature", &g, &m, &err), RT_OK);
    assert_int_equal(g.nx * g.ny * g.nz, 1);
    assert_true(g.density[0] == 300.0f);
    rt_density_grid_free(&g);
    /* without a name: the first float grid the file lists (OpenVDB orders them its own way) */
    table_entry t[2];
    read_table(t);
    assert_int_equal(parse(file_bytes, file_size, NULL, &g, &m, &err), RT_OK);
    assert_int_equal(g.nx * g.ny * g.nz, strcmp(t[0].name, "density") == 0 ? 24 : 1);
    rt_density_grid_free(&g);
    assert_int_equal(parse(file_bytes, file_size, "smoke", &g, &m, &err), RT_ERR_INVALID);
    assert_non_null(strstr(err.message, "grid.nvdb: no grid named \"smoke\""));
}

static void expect_error(unsigned char *b, size_t n, rt_result code, const char *text)
{
    rt_density_grid g;
    rt_mat4 m;
    rt_error err = {0};
    rt_result r = parse(b, n, "density", &g, &m, &err);
    if (r == RT_OK) {
        rt_density_grid_free(&g);
        fail_msg("accepted, expected \"%s\"", text);
    }
    if (r != code || !strstr(err.message, text))
        fail_msg("got %d \"%s\", expected %d \"%s\"", (int)r, err.message, (int)code, text);
}

static void test_broken_files_refused(void **state)
{
    (void)state;
    need_file();
    unsigned char *b = malloc(file_size);
    assert_non_null(b);
    table_entry t[2];
    read_table(t);
    const table_entry *dens = density_entry(t);
    for (size_t n = 0; n < dens->end; n += dens->end / 97 + 1) { /* cut before the density grid ends */
        rt_density_grid g;
        rt_mat4 m;
        rt_error err = {0};
        assert_int_not_equal(parse(file_bytes, n, "density", &g, &m, &err), RT_OK);
        assert_non_null(strstr(err.message, "grid.nvdb"));
    }
    size_t grid = dens->data;
    pnanovdb_buf_t buf = pnanovdb_make_buf((uint32_t *)(void *)(file_bytes + grid), 0);
    pnanovdb_grid_handle_t gh = {pnanovdb_address_null()};
    pnanovdb_tree_handle_t tree = pnanovdb_grid_get_tree(buf, gh);
    size_t root = grid + PNANOVDB_GRID_SIZE + (size_t)pnanovdb_tree_get_node_offset_root(buf, tree);

    memcpy(b, file_bytes, file_size);
    b[0] ^= 1;
    expect_error(b, file_size, RT_ERR_PARSE, "grid.nvdb: byte 0: not a NanoVDB file");

    memcpy(b, file_bytes, file_size);
    b[14] = 1;
    expect_error(b, file_size, RT_ERR_UNSUPPORTED, "compressed (ZIP)");

    memcpy(b, file_bytes, file_size);
    uint32_t v = 31u << 21;
    memcpy(b + 8, &v, 4);
    expect_error(b, file_size, RT_ERR_UNSUPPORTED, "version 31.0");

    memcpy(b, file_bytes, file_size);
    uint32_t tiles = 0x7fffffffu;
    memcpy(b + root + PNANOVDB_ROOT_OFF_TABLE_SIZE, &tiles, 4);
    expect_error(b, file_size, RT_ERR_INVALID, "root tiles do not fit");

    memcpy(b, file_bytes, file_size);
    int32_t lo[3] = {-5000, -5000, -5000}, hi[3] = {5000, 5000, 5000}; /* 10^12 voxels */
    memcpy(b + root + PNANOVDB_ROOT_OFF_BBOX_MIN, lo, 12);
    memcpy(b + root + PNANOVDB_ROOT_OFF_BBOX_MAX, hi, 12);
    expect_error(b, file_size, RT_ERR_LIMIT, "span 10001x10001x10001");

    memcpy(b, file_bytes, file_size);
    float bg = 0.5f;
    memcpy(b + root + PNANOVDB_GRID_TYPE_GET(PNANOVDB_GRID_TYPE_FLOAT, root_off_background), &bg, 4);
    expect_error(b, file_size, RT_ERR_INVALID, "background value 0.5");

    /* every copy of the value written at (0, 5, 0) (the voxel and the
     * statistics that equal it) becomes NaN */
    memcpy(b, file_bytes, file_size);
    float first = 0.1f, nan = NAN;
    int replaced = 0;
    for (size_t i = grid; i + 4 <= dens->end; i += 4)
        if (memcmp(b + i, &first, 4) == 0) {
            memcpy(b + i, &nan, 4);
            replaced++;
        }
    assert_true(replaced >= 1);
    expect_error(b, file_size, RT_ERR_INVALID, "grid \"density\": voxel (0, 0, 0): density nan");

    /* random single-byte changes: an error or a grid, never a crash */
    uint64_t rng = 0x9e3779b97f4a7c15ull;
    int accepted = 0;
    for (int trial = 0; trial < 3000; trial++) {
        memcpy(b, file_bytes, file_size);
        size_t at = (size_t)(next_random(&rng) % file_size);
        b[at] = (unsigned char)next_random(&rng);
        rt_density_grid g;
        rt_mat4 m;
        rt_error err = {0};
        if (parse(b, file_size, "density", &g, &m, &err) == RT_OK) {
            accepted++;
            rt_density_grid_free(&g);
        }
    }
    assert_true(accepted > 0); /* most bytes are voxel values and padding */
    free(b);
}

/* A scene's `medium ... nanovdb FILE` line: the file relative to the
 * scene's directory, the grid by name, the coefficients times a `scale`
 * given before the placement, the file's map composed with the line's
 * transform (a `scale` after `translate` scales the grid), and its inverse. */
static void test_medium_line(void **state)
{
    (void)state;
    need_file();
    char scene_name[192];
    snprintf(scene_name, sizeof scene_name, "%s/scene.txt", dir);
    const char *text = "medium smoke nanovdb grid.nvdb grid density sigma_a 1 2 3 sigma_s 4 5 6 scale 0.5 g 0.2 "
                       "translate 10 0 0 scale 2\n";
    rt_scene s;
    rt_scene_init(&s);
    rt_error err = {0};
    rt_result r = rt_scene_parse_string(&s, NULL, text, strlen(text), scene_name, NULL, &err);
    if (r != RT_OK)
        fail_msg("%s", err.message);
    assert_int_equal(s.medium_count, 1);
    const rt_medium_def *m = &s.media[0];
    assert_int_equal(m->kind, RT_MEDIUM_GRID);
    assert_float_equal(m->sigma_a.z, 1.5f, 0);
    assert_float_equal(m->sigma_s.x, 2.0f, 0);
    rt_density_grid g;
    rt_mat4 file_map;
    assert_int_equal(rt_nanovdb_parse(file_bytes, file_size, "grid.nvdb", "density", &g, &file_map, &err), RT_OK);
    assert_int_equal(m->grid.nx, g.nx);
    assert_int_equal(m->grid.ny, g.ny);
    assert_int_equal(m->grid.nz, g.nz);
    rt_density_grid_free(&g);
    rt_vec3 ps[3] = {rt_v3(0, 0, 0), rt_v3(1.5f, 2.5f, 0.5f), rt_v3(-3, 7, 2)};
    for (int i = 0; i < 3; i++) {
        rt_vec3 want = rt_add(rt_scale(rt_mat4_point(&file_map, ps[i]), 2.0f), rt_v3(10, 0, 0));
        rt_vec3 got = rt_mat4_point(&m->index_to_world, ps[i]);
        assert_float_equal(got.x, want.x, 1e-4f);
        assert_float_equal(got.y, want.y, 1e-4f);
        assert_float_equal(got.z, want.z, 1e-4f);
        rt_vec3 back = rt_mat4_point(&m->world_to_index, got);
        assert_float_equal(back.x, ps[i].x, 1e-4f);
        assert_float_equal(back.y, ps[i].y, 1e-4f);
        assert_float_equal(back.z, ps[i].z, 1e-4f);
    }
    rt_scene_free(&s);
    /* no such grid: the error names the scene's line and the file */
    const char *bad = "medium smoke nanovdb grid.nvdb grid smoke sigma_a 1 1 1 sigma_s 1 1 1\n";
    rt_scene_init(&s);
    r = rt_scene_parse_string(&s, NULL, bad, strlen(bad), scene_name, NULL, &err);
    assert_int_equal(r, RT_ERR_INVALID);
    assert_non_null(strstr(err.message, "scene.txt:1:22: "));
    assert_non_null(strstr(err.message, "no grid named \"smoke\""));
    assert_int_equal(s.medium_count, 0);
    rt_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_values_and_placement),
        cmocka_unit_test(test_grid_by_name),
        cmocka_unit_test(test_broken_files_refused),
        cmocka_unit_test(test_medium_line),
    };
    return cmocka_run_group_tests_name("nanovdb", tests, setup, teardown);
}
