/* rt/io/draco.h - KHR_draco_mesh_compression's meshes, decoded with Debian's
 * libdraco (a C++ library; src/io/draco.cc is the one C++ file of rt, a thin
 * wrapper with this C interface, so nothing else needs a C++ compiler's
 * view of the world).
 *
 * One call decodes a compressed triangle mesh; attributes are then read by
 * the unique id the glTF extension's "attributes" object gives, as floats
 * (normalized integer attributes mapped to [0, 1] / [-1, 1]). Input is
 * untrusted: a malformed stream, a point cloud, or an allocation failure is
 * a message, never an exception or abort crossing into C.
 *
 *   rt_draco_mesh *m; char why[160];
 *   if (!(m = rt_draco_decode(bytes, size, why, sizeof why))) ... error: why ...
 *   size_t faces = rt_draco_faces(m), points = rt_draco_points(m);
 *   rt_draco_indices(m, idx);                          // 3 * faces values
 *   int n = rt_draco_components(m, id);                // 0: no such attribute
 *   rt_draco_attribute(m, id, n, values);              // points * n floats
 *   rt_draco_free(m);
 */
#ifndef RT_DRACO_H
#define RT_DRACO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rt_draco_mesh rt_draco_mesh;

/* NULL on failure, with the reason in why. */
rt_draco_mesh *rt_draco_decode(const void *data, size_t size, char *why, size_t why_size);
void rt_draco_free(rt_draco_mesh *m);

size_t rt_draco_faces(const rt_draco_mesh *m);
size_t rt_draco_points(const rt_draco_mesh *m);
/* out: 3 * faces point indices, each below rt_draco_points. */
void rt_draco_indices(const rt_draco_mesh *m, uint32_t *out);
/* Components of the attribute with this unique id; 0 if there is none. */
int rt_draco_components(const rt_draco_mesh *m, uint32_t unique_id);
/* out: points * ncomp floats (ncomp <= the attribute's components; the
 * rest of a shorter attribute is filled as the spec's defaults: 0, alpha 1).
 * False if a value cannot be converted. */
bool rt_draco_attribute(const rt_draco_mesh *m, uint32_t unique_id, int ncomp, float *out);

#ifdef __cplusplus
}
#endif

#endif
