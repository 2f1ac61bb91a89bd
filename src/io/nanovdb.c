/* nanovdb.c - a float density grid from a NanoVDB file into a dense
 * rt_density_grid (see rt/io/nanovdb.h). The file's segments, headers and
 * metadata are read here, byte by byte, as NanoVDB's own reader lays them
 * out (nanovdb/util/IO.h: a 16-byte header, 176 bytes of metadata and the
 * name per grid, then the grids); the grid itself through PNanoVDB.h, the C
 * header of libnanovdb-dev, with its bounds-checked buffer
 * (PNANOVDB_BUF_BOUNDS_CHECK), after the root's tile table has been checked
 * to fit, so that a hostile file reads zeros, never outside its bytes.
 */
#define PNANOVDB_C
#define PNANOVDB_BUF_BOUNDS_CHECK
#include <nanovdb/PNanoVDB.h>

#include "rt/io/nanovdb.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt/base/alloc.h"
#include "rt/base/file.h"

enum {
    HEADER_SIZE = 16,
    META_SIZE = 176,
    NANOVDB_FILE_MAJOR = 32, /* NanoVDB's ABI and file version of OpenVDB 10 */
    CODEC_NONE = 0,
};

/* Little-endian fields, whatever the host. */
static uint64_t le64(const unsigned char *p)
{
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--)
        v = v << 8 | p[i];
    return v;
}

static uint32_t le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint16_t le16(const unsigned char *p)
{
    return (uint16_t)(p[0] | p[1] << 8);
}

/* One grid's entry in a segment's table. */
typedef struct grid_entry {
    uint64_t grid_size, file_size;
    uint32_t type, grid_class;
    const char *name;   /* inside the file's bytes, NUL-terminated */
    size_t data_offset; /* where its bytes start in the file */
    size_t meta_offset;
} grid_entry;

static const char *type_name(uint32_t t)
{
    static const char *const names[] = {"unknown", "float", "double", "int16", "int32", "int64", "vec3f",
                                        "vec3d", "mask", "half", "uint32", "boolean", "rgba8", "fp4", "fp8",
                                        "fp16", "fpN", "vec4f", "vec4d", "index", "indexMask"};
    return t < sizeof names / sizeof names[0] ? names[t] : "unknown";
}

/* Finds the grid to read: by name, else the first float grid. */
static rt_result find_grid(const unsigned char *b, size_t size, const char *name, const char *grid_name,
                           grid_entry *out, rt_error *err)
{
    size_t at = 0;
    bool any = false;
    while (at < size) {
        if (size - at < HEADER_SIZE)
            return rt_fail(err, RT_ERR_PARSE, "%s: byte %zu: a NanoVDB segment header needs 16 bytes, %zu are left",
                           name, at, size - at);
        uint64_t magic = le64(b + at);
        if (magic != (uint64_t)PNANOVDB_MAGIC_NUMBER)
            return rt_fail(err, RT_ERR_PARSE, "%s: byte %zu: not a NanoVDB file (no \"NanoVDB0\" magic number)", name, at);
        uint32_t version = le32(b + at + 8);
        if (version >> 21 != NANOVDB_FILE_MAJOR)
            return rt_fail(err, RT_ERR_UNSUPPORTED,
                           "%s: byte %zu: NanoVDB file version %u.%u: rt reads version %d (OpenVDB 10's "
                           "nanovdb_convert writes it)",
                           name, at + 8, version >> 21, (version >> 10) & 2047u, NANOVDB_FILE_MAJOR);
        uint16_t count = le16(b + at + 12), codec = le16(b + at + 14);
        if (codec != CODEC_NONE)
            return rt_fail(err, RT_ERR_UNSUPPORTED,
                           "%s: byte %zu: the grids are compressed (%s): rt reads uncompressed NanoVDB files; "
                           "write it with nanovdb_convert without -z or -b",
                           name, at + 14, codec == 1 ? "ZIP" : (codec == 2 ? "BLOSC" : "an unknown codec"));
        at += HEADER_SIZE;
        grid_entry entries[64];
        if (count == 0 || count > 64)
            return rt_fail(err, RT_ERR_PARSE, "%s: byte %zu: %u grids in a segment (1 to 64)", name, at - 4,
                           (unsigned)count);
        for (unsigned i = 0; i < count; i++) {
            if (size - at < META_SIZE)
                return rt_fail(err, RT_ERR_PARSE, "%s: byte %zu: grid %u's metadata cut short", name, at, i);
            const unsigned char *m = b + at;
            grid_entry *e = &entries[i];
            e->meta_offset = at;
            e->grid_size = le64(m);
            e->file_size = le64(m + 8);
            e->type = le32(m + 32);
            e->grid_class = le32(m + 36);
            uint32_t name_size = le32(m + 136);
            at += META_SIZE;
            if (name_size == 0 || name_size > size - at || b[at + name_size - 1] != '\0')
                return rt_fail(err, RT_ERR_PARSE, "%s: byte %zu: grid %u's name (%u bytes) is not a string inside the file",
                               name, at, i, name_size);
            e->name = (const char *)(b + at);
            at += name_size;
        }
        for (unsigned i = 0; i < count; i++) {
            grid_entry *e = &entries[i];
            if (e->file_size != e->grid_size || e->file_size > size - at)
                return rt_fail(err, RT_ERR_PARSE,
                               "%s: byte %zu: grid \"%s\" claims %llu bytes (%llu on disk); %zu are left in the file",
                               name, e->meta_offset, e->name, (unsigned long long)e->grid_size,
                               (unsigned long long)e->file_size, size - at);
            e->data_offset = at;
            at += (size_t)e->file_size;
            bool wanted = grid_name ? strcmp(e->name, grid_name) == 0 : e->type == PNANOVDB_GRID_TYPE_FLOAT;
            if (wanted) {
                *out = *e;
                return RT_OK;
            }
            any = true;
        }
    }
    if (grid_name)
        return rt_fail(err, RT_ERR_INVALID, "%s: no grid named \"%s\"", name, grid_name);
    return rt_fail(err, RT_ERR_INVALID, "%s: %s", name,
                   any ? "no float grid (a density grid is 32-bit float)" : "no grids");
}

/* Checks the grid's header and tree against its buffer before any lookup. */
static rt_result check_grid(pnanovdb_buf_t buf, uint64_t size, const char *name, const grid_entry *e,
                            pnanovdb_root_handle_t *root_out, rt_error *err)
{
    pnanovdb_grid_handle_t grid = {pnanovdb_address_null()};
    if (size < PNANOVDB_GRID_SIZE + PNANOVDB_TREE_SIZE)
        return rt_fail(err, RT_ERR_INVALID, "%s: byte %zu: grid \"%s\" is %llu bytes, less than its headers",
                       name, e->data_offset, e->name, (unsigned long long)size);
    if (pnanovdb_grid_get_magic(buf, grid) != (uint64_t)PNANOVDB_MAGIC_NUMBER ||
        pnanovdb_grid_get_grid_size(buf, grid) != size)
        return rt_fail(err, RT_ERR_INVALID, "%s: byte %zu: grid \"%s\": its header does not match its metadata",
                       name, e->data_offset, e->name);
    uint32_t type = pnanovdb_grid_get_grid_type(buf, grid), grid_class = pnanovdb_grid_get_grid_class(buf, grid);
    if (type != PNANOVDB_GRID_TYPE_FLOAT)
        return rt_fail(err, RT_ERR_UNSUPPORTED,
                       "%s: grid \"%s\" is of type %s: a density grid is 32-bit float (convert without --fp4/8/16/N)",
                       name, e->name, type_name(type));
    if (grid_class != PNANOVDB_GRID_CLASS_FOG_VOLUME && grid_class != PNANOVDB_GRID_CLASS_UNKNOWN)
        return rt_fail(err, RT_ERR_UNSUPPORTED, "%s: grid \"%s\" is a %s, not a density (fog volume)", name, e->name,
                       grid_class == PNANOVDB_GRID_CLASS_LEVEL_SET ? "level set (signed distance)" : "grid of another class");
    pnanovdb_tree_handle_t tree = pnanovdb_grid_get_tree(buf, grid);
    uint64_t root_at = PNANOVDB_GRID_SIZE + pnanovdb_tree_get_node_offset_root(buf, tree);
    uint64_t root_size = PNANOVDB_GRID_TYPE_GET(PNANOVDB_GRID_TYPE_FLOAT, root_size);
    uint64_t tile_size = PNANOVDB_GRID_TYPE_GET(PNANOVDB_GRID_TYPE_FLOAT, root_tile_size);
    if (root_at < PNANOVDB_GRID_SIZE || root_at > size || size - root_at < root_size)
        return rt_fail(err, RT_ERR_INVALID, "%s: grid \"%s\": its root node lies outside the grid's %llu bytes",
                       name, e->name, (unsigned long long)size);
    pnanovdb_root_handle_t root = pnanovdb_tree_get_root(buf, tree);
    uint64_t tiles = pnanovdb_root_get_tile_count(buf, root);
    if (tiles > (size - root_at - root_size) / tile_size)
        return rt_fail(err, RT_ERR_INVALID, "%s: grid \"%s\": %llu root tiles do not fit the grid's %llu bytes", name,
                       e->name, (unsigned long long)tiles, (unsigned long long)size);
    float background = pnanovdb_read_float(buf, pnanovdb_address_offset(root.address,
                                                 PNANOVDB_GRID_TYPE_GET(PNANOVDB_GRID_TYPE_FLOAT, root_off_background)));
    if (background != 0.0f)
        return rt_fail(err, RT_ERR_INVALID, "%s: grid \"%s\": background value %g: a density grid's background must be 0",
                       name, e->name, (double)background);
    *root_out = root;
    return RT_OK;
}

/* The file's index-to-world map, moved to the dense grid's index space
 * (voxel (0,0,0) of the dense grid is the file's voxel `lo`, its centre at
 * 0.5). */
static rt_result read_map(pnanovdb_buf_t buf, const char *name, const grid_entry *e, const int lo[3], rt_mat4 *out,
                          rt_error *err)
{
    pnanovdb_grid_handle_t grid = {pnanovdb_address_null()};
    pnanovdb_map_handle_t map = pnanovdb_grid_get_map(buf, grid);
    double m[9], v[3];
    for (int i = 0; i < 9; i++)
        m[i] = pnanovdb_map_get_matf(buf, map, (uint32_t)i);
    for (int i = 0; i < 3; i++)
        v[i] = pnanovdb_map_get_vecf(buf, map, (uint32_t)i);
    double det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                 m[2] * (m[3] * m[7] - m[4] * m[6]);
    bool finite = isfinite(det) && isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
    if (!finite || fabs(det) < 1e-30)
        return rt_fail(err, RT_ERR_INVALID, "%s: grid \"%s\": its index-to-world map is %s", name, e->name,
                       finite ? "singular" : "not finite");
    rt_mat4 r = rt_mat4_identity();
    for (int row = 0; row < 3; row++) {
        double t = v[row];
        for (int col = 0; col < 3; col++) {
            r.m[row][col] = (float)m[row * 3 + col];
            t += m[row * 3 + col] * ((double)lo[col] - 0.5);
        }
        r.m[row][3] = (float)t;
    }
    *out = r;
    return RT_OK;
}

rt_result rt_nanovdb_parse(const unsigned char *bytes, size_t size, const char *name, const char *grid_name,
                           rt_density_grid *out, rt_mat4 *index_to_world, rt_error *err)
{
    *out = (rt_density_grid){0};
    grid_entry e = {0};
    rt_result r = find_grid(bytes, size, name, grid_name, &e, err);
    if (r != RT_OK)
        return r;
    /* PNanoVDB reads 4- and 8-byte words: an aligned copy, a word of zeros past the end */
    size_t words = (size_t)(e.grid_size / 8 + 1) * 2;
    uint32_t *data = rt_alloc(words, sizeof *data);
    if (!data)
        return rt_fail(err, RT_ERR_NOMEM, "%s: grid \"%s\": out of memory for %llu bytes", name, e.name,
                       (unsigned long long)e.grid_size);
    memcpy(data, bytes + e.data_offset, (size_t)e.grid_size);
    pnanovdb_buf_t buf = pnanovdb_make_buf(data, e.grid_size / 4);
    pnanovdb_root_handle_t root = {pnanovdb_address_null()};
    r = check_grid(buf, e.grid_size, name, &e, &root, err);
    if (r != RT_OK)
        goto done;
    pnanovdb_coord_t bmin = pnanovdb_root_get_bbox_min(buf, root), bmax = pnanovdb_root_get_bbox_max(buf, root);
    const int lo[3] = {bmin.x, bmin.y, bmin.z};
    int64_t dims[3] = {(int64_t)bmax.x - bmin.x + 1, (int64_t)bmax.y - bmin.y + 1, (int64_t)bmax.z - bmin.z + 1};
    if (dims[0] < 1 || dims[1] < 1 || dims[2] < 1) {
        r = rt_fail(err, RT_ERR_INVALID, "%s: grid \"%s\" has no active voxels", name, e.name);
        goto done;
    }
    if ((uint64_t)dims[0] * (uint64_t)dims[1] > RT_DENSITY_MAX_VOXELS ||
        (uint64_t)dims[0] * (uint64_t)dims[1] * (uint64_t)dims[2] > RT_DENSITY_MAX_VOXELS) {
        r = rt_fail(err, RT_ERR_LIMIT,
                    "%s: grid \"%s\": its active voxels span %lldx%lldx%lld, more than the %llu voxels rt holds densely",
                    name, e.name, (long long)dims[0], (long long)dims[1], (long long)dims[2],
                    (unsigned long long)RT_DENSITY_MAX_VOXELS);
        goto done;
    }
    r = read_map(buf, name, &e, lo, index_to_world, err);
    if (r != RT_OK)
        goto done;
    r = rt_density_grid_init(out, (int)dims[0], (int)dims[1], (int)dims[2], err);
    if (r != RT_OK)
        goto done;
    pnanovdb_readaccessor_t acc;
    pnanovdb_readaccessor_init(&acc, root);
    for (int z = 0; z < out->nz; z++)
        for (int y = 0; y < out->ny; y++) {
            float *row = out->density + rt_density_grid_index(out, 0, y, z);
            for (int x = 0; x < out->nx; x++) {
                pnanovdb_coord_t ijk = {lo[0] + x, lo[1] + y, lo[2] + z};
                pnanovdb_address_t a =
                    pnanovdb_readaccessor_get_value_address(PNANOVDB_GRID_TYPE_FLOAT, buf, &acc, &ijk);
                row[x] = pnanovdb_read_float(buf, a);
            }
        }
    char source[1100];
    snprintf(source, sizeof source, "%s: grid \"%s\"", name, e.name);
    r = rt_density_grid_finish(out, source, err);
    if (r != RT_OK)
        rt_density_grid_free(out);
done:
    free(data);
    return r;
}

rt_result rt_nanovdb_load(const char *path, const char *grid_name, rt_density_grid *grid, rt_mat4 *index_to_world,
                          rt_error *err)
{
    char *bytes;
    size_t size;
    rt_result r = rt_read_file(path, 0, &bytes, &size, err);
    if (r != RT_OK)
        return r;
    r = rt_nanovdb_parse((const unsigned char *)bytes, size, path, grid_name, grid, index_to_world, err);
    free(bytes);
    return r;
}
