/* mesh_io.c - the mesh dispatcher (rt/io/mesh_io.h): which reader a file
 * goes to, and the steps every mesh load shares around it.
 *
 * Format: by content first (PLY's "ply" line, OFF's header keyword, from
 * the PLY specification and the Geomview OFF manual), then by extension,
 * ASCII case-insensitive: .obj, .ply, .off. OBJ has no magic.
 *
 * Every load: defaults for the options, a mark of the scene
 * (rt_scene_mark_of), the reader parses the bytes into a fresh mesh buffer
 * (mesh_readers.h), rt_mesh_commit transforms it and appends it to the
 * scene (mesh_buffer.c), and any error rolls the scene back to the mark,
 * so a failed load leaves no vertex, triangle, material or image behind.
 * The readers know nothing of this file; this file knows the readers only
 * through mesh_readers.h.
 */
#include "rt/io/mesh_io.h"

#include <stdlib.h>
#include <string.h>

#include "mesh_buffer.h"
#include "mesh_readers.h"
#include "rt/base/file.h"

/* An OFF header keyword at the start: [ST][C][N][4|n]OFF, then a blank or
 * the end (Geomview manual, "OFF Files"). 4OFF and nOFF count: the reader
 * then says they are not supported. */
static bool off_header(const char *p, size_t size)
{
    size_t i = 0;
    if (size >= 2 && p[0] == 'S' && p[1] == 'T')
        i = 2;
    if (i < size && p[i] == 'C')
        i++;
    if (i < size && p[i] == 'N')
        i++;
    if (i < size && (p[i] == '4' || p[i] == 'n'))
        i++;
    if (size - i < 3 || memcmp(p + i, "OFF", 3) != 0)
        return false;
    i += 3;
    return i == size || p[i] == ' ' || p[i] == '\t' || p[i] == '\r' || p[i] == '\n';
}

rt_mesh_format rt_mesh_format_of(const void *bytes, size_t size, const char *name)
{
    const char *p = bytes;
    if (p && size >= 4 && memcmp(p, "ply", 3) == 0 && (p[3] == '\n' || (p[3] == '\r' && size >= 5 && p[4] == '\n')))
        return RT_MESH_PLY;
    if (p && off_header(p, size))
        return RT_MESH_OFF;
    if (name && rt_path_has_ext(name, ".obj"))
        return RT_MESH_OBJ;
    if (name && rt_path_has_ext(name, ".ply"))
        return RT_MESH_PLY;
    if (name && rt_path_has_ext(name, ".off"))
        return RT_MESH_OFF;
    return RT_MESH_UNKNOWN;
}

rt_result rt_mesh_load_memory(rt_scene *s, const void *bytes, size_t size, const char *name,
                              const rt_mesh_options *options, rt_mesh_load_stats *stats, rt_error *err)
{
    static const rt_mesh_options defaults;
    rt_error local_err = {0};
    if (!err)
        err = &local_err;
    if (stats)
        memset(stats, 0, sizeof *stats);
    if (!options)
        options = &defaults;
    if (!name)
        name = "<memory>";
    if (!bytes && size)
        return rt_fail(err, RT_ERR_INVALID, "%s: no data", name);
    rt_mesh_format format = options->format ? options->format : rt_mesh_format_of(bytes, size, name);
    if (format == RT_MESH_UNKNOWN) {
        const char *ext = rt_path_ext(name);
        if (!*ext)
            return rt_fail(err, RT_ERR_UNSUPPORTED, "%s: no file extension; meshes must be .obj, .ply or .off", name);
        return rt_fail(err, RT_ERR_UNSUPPORTED, "%s: unknown mesh format '%s' (expected .obj, .ply or .off)", name,
                       ext);
    }
    rt_mesh_input in = {s, size ? bytes : "", size, name, options->material, options->override_material, err};
    rt_scene_mark mark = rt_scene_mark_of(s);
    rt_mesh_buf b;
    memset(&b, 0, sizeof b);
    rt_result r = RT_ERR_UNSUPPORTED;
    switch (format) {
    case RT_MESH_OBJ: r = rt_obj_parse(&in, &b); break;
    case RT_MESH_PLY: r = rt_ply_parse(&in, &b); break;
    case RT_MESH_OFF: r = rt_off_parse(&in, &b); break;
    case RT_MESH_UNKNOWN: break;
    }
    if (r == RT_OK)
        r = rt_mesh_commit(s, &b, options->transform, name, err);
    if (r == RT_OK && stats) {
        stats->triangles = b.nt;
        stats->vertices = b.nt ? b.nv : 0; /* a file without triangles appends nothing */
        stats->materials = s->material_count - mark.materials;
        stats->skipped_faces = b.skipped;
    }
    rt_mesh_buf_free(&b);
    if (r != RT_OK)
        rt_scene_rollback(s, &mark);
    return r;
}

rt_result rt_mesh_load(rt_scene *s, const char *path, const rt_mesh_options *options, rt_mesh_load_stats *stats,
                       rt_error *err)
{
    if (stats)
        memset(stats, 0, sizeof *stats);
    if (!path)
        return rt_fail(err, RT_ERR_INVALID, "mesh: no path given");
    char *bytes;
    size_t size;
    rt_error read_err = {0};
    rt_result r = rt_read_file(path, 0, &bytes, &size, &read_err);
    if (r != RT_OK) {
        /* a name no reader takes says so, readable or not (as it always did) */
        if (rt_mesh_format_of(NULL, 0, path) == RT_MESH_UNKNOWN)
            return rt_mesh_load_memory(s, NULL, 0, path, options, stats, err);
        if (err)
            *err = read_err;
        return r;
    }
    r = rt_mesh_load_memory(s, bytes, size, path, options, stats, err);
    free(bytes);
    return r;
}
