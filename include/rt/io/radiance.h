/* rt/io/radiance.h - a check of a Radiance HDR (RGBE) file's pixel data
 * before stb_image decodes it.
 *
 * stb_image's HDR reader trusts the data: a run-length scanline with a run
 * of 0 (which a file cut short also reads as, stb returning 0 past the end)
 * never advances and loops for ever, and flat pixels past the end are left
 * as whatever the stack held. rt_radiance_check walks the scanlines as stb
 * will, allocating nothing, and refuses such a file with a message naming
 * the byte where it goes wrong.
 *
 *   if (stbi_is_hdr_from_memory(bytes, size) && rt_radiance_check(bytes, size, "sky.hdr", &err) != RT_OK)
 *       ... "sky.hdr: Radiance HDR data ends at byte 5000, in scanline 12 of 32" ...
 */
#ifndef RT_RADIANCE_H
#define RT_RADIANCE_H

#include <stddef.h>

#include "rt/base/error.h"

/* RT_OK when the header and every scanline stb_image will read are there
 * and well formed; RT_ERR_INVALID (message "name: ...") otherwise. */
rt_result rt_radiance_check(const void *data, size_t size, const char *name, rt_error *err);

#endif
