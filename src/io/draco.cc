// draco.cc - the C interface of rt/io/draco.h over Debian's libdraco.
//
// KHR_draco_mesh_compression (KhronosGroup/glTF, extensions/2.0/Khronos/
// KHR_draco_mesh_compression): a primitive's bufferView holds a Draco
// triangle mesh; its "attributes" object maps glTF attribute names to the
// mesh's attribute unique ids. Faces give the point indices of each
// triangle; an attribute value is found for a point through
// PointAttribute::mapped_index; boolean attributes are read as bytes (any
// nonzero byte is true), never loaded as C++ bool. Everything the library can throw (it is
// built without exceptions, but std::bad_alloc can still come from new)
// stops here.
#include "rt/io/draco.h"

#include <cstdio>
#include <memory>
#include <new>

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

struct rt_draco_mesh {
    std::unique_ptr<draco::Mesh> mesh;
};

extern "C" rt_draco_mesh *rt_draco_decode(const void *data, size_t size, char *why, size_t why_size)
{
    try {
        draco::DecoderBuffer buffer;
        buffer.Init(static_cast<const char *>(data), size);
        auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
        if (!type.ok()) {
            std::snprintf(why, why_size, "not a Draco stream (%s)", type.status().error_msg());
            return nullptr;
        }
        if (type.value() != draco::TRIANGULAR_MESH) {
            std::snprintf(why, why_size, "the Draco stream is not a triangle mesh");
            return nullptr;
        }
        draco::Decoder decoder;
        auto result = decoder.DecodeMeshFromBuffer(&buffer);
        if (!result.ok()) {
            std::snprintf(why, why_size, "cannot decode the Draco mesh (%s)", result.status().error_msg());
            return nullptr;
        }
        rt_draco_mesh *m = new rt_draco_mesh;
        m->mesh = std::move(result).value();
        return m;
    } catch (const std::bad_alloc &) {
        std::snprintf(why, why_size, "out of memory decoding the Draco mesh");
    } catch (...) {
        std::snprintf(why, why_size, "cannot decode the Draco mesh");
    }
    return nullptr;
}

extern "C" void rt_draco_free(rt_draco_mesh *m) { delete m; }

extern "C" size_t rt_draco_faces(const rt_draco_mesh *m) { return m->mesh->num_faces(); }

extern "C" size_t rt_draco_points(const rt_draco_mesh *m) { return m->mesh->num_points(); }

extern "C" void rt_draco_indices(const rt_draco_mesh *m, uint32_t *out)
{
    const draco::Mesh &mesh = *m->mesh;
    for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f) {
        const draco::Mesh::Face &face = mesh.face(f);
        for (int k = 0; k < 3; k++)
            *out++ = face[k].value();
    }
}

extern "C" int rt_draco_components(const rt_draco_mesh *m, uint32_t unique_id)
{
    const draco::PointAttribute *a = m->mesh->GetAttributeByUniqueId(unique_id);
    return a ? a->num_components() : 0;
}

extern "C" bool rt_draco_attribute(const rt_draco_mesh *m, uint32_t unique_id, int ncomp, float *out)
{
    const draco::PointAttribute *a = m->mesh->GetAttributeByUniqueId(unique_id);
    if (!a || ncomp <= 0 || ncomp > 4)
        return false;
    const int have = a->num_components();
    float v[4];
    for (draco::PointIndex p(0); p < m->mesh->num_points(); ++p) {
        v[0] = v[1] = v[2] = 0.0f;
        v[3] = 1.0f;
        draco::AttributeValueIndex i = a->mapped_index(p);
        if (i.value() >= a->size())
            return false;
        const int n = have < ncomp ? have : ncomp;
        if (a->data_type() == draco::DT_BOOL) {
            // a stream's bool bytes may hold any value; loading one as a
            // C++ bool (what ConvertValue does) is undefined unless 0 or 1
            const int64_t pos = a->GetBytePos(i);
            if (pos < 0 || pos + n > static_cast<int64_t>(a->buffer()->data_size()))
                return false;
            const uint8_t *b = a->buffer()->data() + pos;
            for (int c = 0; c < n; c++)
                v[c] = b[c] ? 1.0f : 0.0f;
        } else if (!a->ConvertValue<float>(i, static_cast<int8_t>(n), v)) {
            return false;
        }
        for (int c = 0; c < ncomp; c++)
            *out++ = v[c];
    }
    return true;
}
