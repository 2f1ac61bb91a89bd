/* mesh_readers.h - the interface of the mesh format readers (mesh_obj.c,
 * mesh_ply.c, mesh_off.c), private to src/io.
 *
 * A reader parses one file held in memory into a mesh buffer and nothing
 * else: the dispatcher above it (mesh_io.c) picks the reader, makes the
 * buffer, marks the scene, commits the buffer (transform, default material)
 * and rolls the scene back on any error. Readers depend only on
 * mesh_buffer.h and mesh_text.h.
 *
 *   rt_mesh_buf b = {0};
 *   rt_mesh_input in = {scene, bytes, size, "bunny.ply", material, false, &err};
 *   if (rt_ply_parse(&in, &b) == RT_OK)
 *       r = rt_mesh_commit(scene, &b, transform, in.name, &err);
 *   rt_mesh_buf_free(&b);
 *
 * Adding a format: a reader file with one rt_<format>_parse function
 * declared here, a value of rt_mesh_format with its magic and extension in
 * mesh_io.c (rt_mesh_format_of), and a case in mesh_io.c's dispatch.
 */
#ifndef RT_MESH_READERS_H
#define RT_MESH_READERS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mesh_buffer.h"
#include "rt/base/error.h"
#include "rt/scene/scene.h"

/* What a reader is given. */
typedef struct rt_mesh_input {
    rt_scene *scene;        /* OBJ appends its MTL materials and their textures; the others only read it */
    const char *bytes;      /* the file: size bytes, not NUL-terminated */
    size_t size;
    const char *name;       /* the file's path: named in messages; OBJ resolves mtllib against its directory */
    uint32_t material;      /* for faces without a material of their own; RT_NONE = "<file>:default" at commit */
    bool override_material; /* every face takes `material` (OBJ then reads no MTL) */
    rt_error *err;          /* never NULL */
} rt_mesh_input;

/* Each parses in->bytes into out (empty on entry): vertices, triangles with
 * scene material indices (or RT_NONE) and RT_TRI_* flags, and the count of
 * skipped faces. Errors name the file and the line or byte offset. */
rt_result rt_obj_parse(const rt_mesh_input *in, rt_mesh_buf *out);
rt_result rt_ply_parse(const rt_mesh_input *in, rt_mesh_buf *out);
rt_result rt_off_parse(const rt_mesh_input *in, rt_mesh_buf *out);

#endif
