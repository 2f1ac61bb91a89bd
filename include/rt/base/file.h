/* rt/base/file.h - whole files into memory, and the path helpers every loader
 * shares.
 *
 * Every loader reads its input through rt_read_file(): one open that cannot
 * hang on a FIFO without a writer, a size check before any allocation, one
 * buffer with a NUL after the last byte, and errors that name the file. The
 * readers themselves take (bytes, size, name) and never open files, except
 * for the files their input names (textures, glTF buffers, MTL libraries),
 * which they read through rt_read_file too.
 *
 *   char *bytes;
 *   size_t size;
 *   if (rt_read_file("scene.txt", 0, &bytes, &size, &err) != RT_OK)
 *       return err.code;              // "scene.txt: cannot open: No such file or directory"
 *   ... parse bytes[0 .. size) ...
 *   free(bytes);
 *
 * Paths are '/'-separated byte strings; the path helpers only look at the
 * string:
 *
 *   rt_path_has_ext("Model.GLB", ".glb")              true (ASCII case-insensitive, last component)
 *   rt_path_ext("dir.d/mesh.obj")                     ".obj" ("" when the last component has no '.')
 *   rt_path_basename("a/b/mesh.obj")                  "mesh.obj"
 *   rt_path_dirname("a/b/mesh.obj", dir, sizeof dir)  "a/b/" ("" when there is no '/')
 *   rt_path_join("a/b/", "wood.png", out, size)       "a/b/wood.png"; "a/b" + "wood.png" likewise,
 *                                                     and an absolute second path is kept as it is
 */
#ifndef RT_FILE_H
#define RT_FILE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rt/base/error.h"

/* The largest file rt_read_file reads when the caller gives no limit (0). */
#define RT_FILE_MAX_BYTES (SIZE_MAX / 2)

/* Reads the whole file at path into a fresh buffer of size + 1 bytes whose
 * last byte is 0 (free it). Regular files and pipes are read; directories
 * ("path: is a directory"), devices and sockets are refused. max_size caps the size (0 = the default
 * RT_FILE_MAX_BYTES); a regular file over it is refused before anything is
 * allocated. Errors (RT_ERR_IO, RT_ERR_LIMIT, RT_ERR_NOMEM) begin with
 * "path: ". On failure *bytes is NULL and *size 0. */
rt_result rt_read_file(const char *path, size_t max_size, char **bytes, size_t *size, rt_error *err);

/* True when both paths exist and are the same file (device and inode: a
 * hard link, a symbolic link or "./x" for "x" count), so that a command
 * can refuse to write its output over one of its inputs. */
bool rt_same_file(const char *a, const char *b);
/* The identity of the file at path, (device, inode), into id; false when
 * it cannot be stat'ed. Equal ids are the same file (rt_same_file). */
bool rt_file_id(const char *path, uint64_t id[2]);

/* True when the last component of path ends in ext (".obj"), ignoring ASCII
 * case. */
bool rt_path_has_ext(const char *path, const char *ext);
/* The extension of the last component, from its last '.' (".obj"), or ""
 * when it has none. Points into path. */
const char *rt_path_ext(const char *path);
/* The last component (after the last '/'). Points into path. */
const char *rt_path_basename(const char *path);
/* The directory part of path with its trailing '/' ("a/b/" for "a/b/c",
 * "/" for "/c", "" for "c"), into out. false (and out = "") when it does not
 * fit in size bytes. */
bool rt_path_dirname(const char *path, char *out, size_t size);
/* dir joined with rel into out: rel alone when it is absolute or dir is
 * empty, else dir, a '/' unless dir ends in one, and rel. false when the
 * result does not fit in size bytes. */
bool rt_path_join(const char *dir, const char *rel, char *out, size_t size);
/* path with a tag before its extension, into out: "dir/name.EXT" gives
 * "dir/name.TAG.EXT", or "dir/name.TAG.NEWEXT" when new_ext (with its dot)
 * is given; a path without an extension gets ".TAG" (and new_ext). false
 * when the result does not fit in size bytes. */
bool rt_path_tagged(const char *path, const char *tag, const char *new_ext, char *out, size_t size);

#endif
