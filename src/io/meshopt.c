/* meshopt.c - EXT_meshopt_compression buffer views (rt/io/meshopt.h).
 *
 * The rules come from the extension's specification (KhronosGroup/glTF,
 * extensions/2.0/Vendor/EXT_meshopt_compression): ATTRIBUTES streams have a
 * byteStride that is a multiple of 4 and at most 256; TRIANGLES streams hold
 * a multiple of 3 indices of 2 or 4 bytes; INDICES streams indices of 2 or 4
 * bytes; filters apply to ATTRIBUTES only, OCTAHEDRAL with a stride of 4 or
 * 8, QUATERNION of 8, EXPONENTIAL a multiple of 4. The decoding itself is
 * libmeshoptimizer's (meshopt_decodeVertexBuffer, meshopt_decodeIndexBuffer,
 * meshopt_decodeIndexSequence and the meshopt_decodeFilter* functions, which
 * work in place), which checks the stream against its declared size. */
#include "rt/io/meshopt.h"

#include <string.h>

#include <meshoptimizer.h>

int rt_meshopt_mode_from_name(const char *name)
{
    if (strcmp(name, "ATTRIBUTES") == 0) return RT_MESHOPT_ATTRIBUTES;
    if (strcmp(name, "TRIANGLES") == 0) return RT_MESHOPT_TRIANGLES;
    if (strcmp(name, "INDICES") == 0) return RT_MESHOPT_INDICES;
    return -1;
}

int rt_meshopt_filter_from_name(const char *name)
{
    if (strcmp(name, "NONE") == 0) return RT_MESHOPT_FILTER_NONE;
    if (strcmp(name, "OCTAHEDRAL") == 0) return RT_MESHOPT_FILTER_OCTAHEDRAL;
    if (strcmp(name, "QUATERNION") == 0) return RT_MESHOPT_FILTER_QUATERNION;
    if (strcmp(name, "EXPONENTIAL") == 0) return RT_MESHOPT_FILTER_EXPONENTIAL;
    return -1;
}

const char *rt_meshopt_check(rt_meshopt_mode mode, rt_meshopt_filter filter, size_t count, size_t stride)
{
    if (count == 0)
        return "count is 0";
    switch (mode) {
    case RT_MESHOPT_ATTRIBUTES:
        if (stride == 0 || stride % 4 || stride > 256)
            return "ATTRIBUTES needs a byteStride that is a multiple of 4 in [4, 256]";
        break;
    case RT_MESHOPT_TRIANGLES:
        if (count % 3)
            return "TRIANGLES needs a count that is a multiple of 3";
        /* fall through */
    case RT_MESHOPT_INDICES:
        if (stride != 2 && stride != 4)
            return "TRIANGLES and INDICES need a byteStride of 2 or 4";
        if (filter != RT_MESHOPT_FILTER_NONE)
            return "filters apply to ATTRIBUTES only";
        break;
    default:
        return "unknown mode";
    }
    switch (filter) {
    case RT_MESHOPT_FILTER_NONE: break;
    case RT_MESHOPT_FILTER_OCTAHEDRAL:
        if (stride != 4 && stride != 8)
            return "the OCTAHEDRAL filter needs a byteStride of 4 or 8";
        break;
    case RT_MESHOPT_FILTER_QUATERNION:
        if (stride != 8)
            return "the QUATERNION filter needs a byteStride of 8";
        break;
    case RT_MESHOPT_FILTER_EXPONENTIAL:
        if (stride % 4)
            return "the EXPONENTIAL filter needs a byteStride that is a multiple of 4";
        break;
    default:
        return "unknown filter";
    }
    return NULL;
}

const char *rt_meshopt_decode(void *dst, size_t count, size_t stride, const uint8_t *src, size_t src_size,
                              rt_meshopt_mode mode, rt_meshopt_filter filter)
{
    const char *why = rt_meshopt_check(mode, filter, count, stride);
    if (why)
        return why;
    int rc;
    switch (mode) {
    case RT_MESHOPT_ATTRIBUTES: rc = meshopt_decodeVertexBuffer(dst, count, stride, src, src_size); break;
    case RT_MESHOPT_TRIANGLES: rc = meshopt_decodeIndexBuffer(dst, count, stride, src, src_size); break;
    default: rc = meshopt_decodeIndexSequence(dst, count, stride, src, src_size); break;
    }
    if (rc != 0)
        return "the compressed stream is malformed or shorter than its count needs";
    switch (filter) {
    case RT_MESHOPT_FILTER_OCTAHEDRAL: meshopt_decodeFilterOct(dst, count, stride); break;
    case RT_MESHOPT_FILTER_QUATERNION: meshopt_decodeFilterQuat(dst, count, stride); break;
    case RT_MESHOPT_FILTER_EXPONENTIAL: meshopt_decodeFilterExp(dst, count, stride); break;
    default: break;
    }
    return NULL;
}
