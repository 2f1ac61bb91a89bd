/* rt/json.h - JSON checked, tokenized and walked.
 *
 * The text is checked once against RFC 8259's grammar, in time linear in
 * its length (a stack of open containers, at most RT_JSON_MAX_DEPTH deep),
 * then tokenized by jsmn into a flat array of tokens in document order. A
 * token's children follow it: an object's size is its number of keys, each
 * key token has size 1 and its value right after it. The walker functions
 * never read past the token array, so a caller can walk any tokenized input
 * without further checks.
 *
 *   rt_json j;
 *   if (rt_json_parse(&j, text, len, "model.gltf", 0, &err) != RT_OK) ...
 *   for (int k = 0, i = 1; k < j.tok[0].size; k++, i = rt_json_skip(&j, i + 1))
 *       if (rt_json_key_is(&j, i, "asset")) ...   // value is token i + 1
 *   rt_json_free(&j);
 */
#ifndef RT_JSON_H
#define RT_JSON_H

#include <stdbool.h>
#include <stddef.h>

#include "rt/base/error.h"

typedef enum rt_json_type {
    RT_JSON_UNDEFINED = 0,
    RT_JSON_OBJECT = 1,
    RT_JSON_ARRAY = 2,
    RT_JSON_STRING = 3,    /* start/end exclude the quotes; escapes not decoded */
    RT_JSON_PRIMITIVE = 4, /* number, true, false, null */
} rt_json_type;

typedef struct rt_json_tok {
    int type, start, end, size;
} rt_json_tok;

typedef struct rt_json {
    const char *text;
    size_t len;
    rt_json_tok *tok;
    int count;
} rt_json;

#define RT_JSON_MAX_BYTES 0x7fffff00u /* token offsets are int */
/* Objects and arrays open at once; deeper input is RT_ERR_LIMIT. glTF
 * files and sidecars nest under 20 deep. The cap also bounds jsmn's walk
 * back up its parent links at each closing bracket (json.c), so the
 * tokens of any text cost at most a constant times its length. */
#define RT_JSON_MAX_DEPTH 64
#define RT_JSON_MAX_DEPTH_TEXT "64"

/* Tokenizes text[0, len). Errors name `name` and the byte offset of the
 * problem plus `base` (the JSON's offset within its file, for GLB). The top
 * level must be one object, nested at most RT_JSON_MAX_DEPTH deep; trailing bytes other than whitespace are an
 * error. On success j->text points at text (not copied). */
rt_result rt_json_parse(rt_json *j, const char *text, size_t len, const char *name, size_t base, rt_error *err);
void rt_json_free(rt_json *j);

/* Index of the token after token i and all its descendants. */
int rt_json_skip(const rt_json *j, int i);
/* True when token i is a string equal to s (raw compare: keys are ASCII). */
bool rt_json_key_is(const rt_json *j, int i, const char *s);
/* Token i as a finite number; false if it is not a number. */
bool rt_json_number(const rt_json *j, int i, double *out);
/* Token i as true/false; false if it is neither. */
bool rt_json_bool(const rt_json *j, int i, bool *out);
/* Decodes string token i (escapes, \uXXXX to UTF-8) into out (NUL-terminated,
 * at most cap - 1 bytes). Returns the decoded length, or -1 when the token is
 * not a string, has a bad escape, or does not fit. */
long rt_json_string(const rt_json *j, int i, char *out, size_t cap);
/* Value token of `key` in object token obj, or -1 when absent (or obj is not an object). */
int rt_json_get(const rt_json *j, int obj, const char *key);

#endif
