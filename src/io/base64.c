/* base64.c - strict base64 decoding (RFC 4648, section 4: the standard
 * alphabet with '=' padding). Anything else - whitespace, the URL-safe
 * alphabet, padding in the middle, a length that is not a multiple of 4,
 * non-zero bits in the unused part of the last group - is an error at the
 * offset of the offending character, so a damaged data: URI is reported
 * instead of decoded into garbage. See include/rt/base64.h.
 */
#include "rt/io/base64.h"

static int b64_value(unsigned char c)
{
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
}

rt_result rt_base64_decode(const char *src, size_t len, uint8_t *dst, size_t *out_len, size_t *bad)
{
    size_t o = 0;
    *out_len = 0;
    *bad = 0;
    for (size_t i = 0; i < len; i += 4) {
        if (len - i < 4) {
            /* find the offending position: the first character of the short group */
            for (size_t k = i; k < len; k++)
                if (src[k] != '=' && b64_value((unsigned char)src[k]) < 0) {
                    *bad = k;
                    return RT_ERR_PARSE;
                }
            *bad = len;
            return RT_ERR_PARSE;
        }
        int v[4];
        int pad = 0;
        for (int k = 0; k < 4; k++) {
            unsigned char c = (unsigned char)src[i + (size_t)k];
            if (c == '=' && k >= 2 && i + 4 == len) {
                v[k] = 0;
                pad++;
                continue;
            }
            v[k] = b64_value(c);
            if (v[k] < 0 || pad) { /* not base64, or data after padding */
                *bad = i + (size_t)k;
                return RT_ERR_PARSE;
            }
        }
        uint32_t w = (uint32_t)v[0] << 18 | (uint32_t)v[1] << 12 | (uint32_t)v[2] << 6 | (uint32_t)v[3];
        if ((pad == 1 && (w & 0xFF)) || (pad == 2 && (w & 0xFFFF))) {
            *bad = i + 3 - (size_t)pad; /* stray bits in the last group */
            return RT_ERR_PARSE;
        }
        dst[o++] = (uint8_t)(w >> 16);
        if (pad < 2) dst[o++] = (uint8_t)(w >> 8);
        if (pad < 1) dst[o++] = (uint8_t)w;
    }
    *out_len = o;
    return RT_OK;
}
