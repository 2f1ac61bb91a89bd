/* json.c - a strict JSON tokenizer and the token walkers of rt/io/json.h.
 *
 * The tokenizer is our own (it replaced jsmn, whose closing brackets walked
 * parent links back from the last token: nesting N deep cost N^2/2 hops, so
 * a 600 KB file of nested arrays took 104 s). It keeps a stack of the open
 * containers, so every byte is looked at once and a closing bracket pops
 * one entry: linear in the text. The stack is capped at RT_JSON_MAX_DEPTH
 * open containers; deeper input is refused with the byte where it goes over.
 * The grammar is RFC 8259's: objects of "key": value pairs, arrays, strings
 * with the escapes \" \\ \/ \b \f \n \r \t \uXXXX, and primitives (numbers,
 * true, false, null) read up to the next delimiter and checked by the
 * walkers that read them (rt_json_number, rt_json_bool). Tokens go into an
 * array grown by doubling; every token takes at least one byte of text, so
 * a file cannot make us allocate more than a few bytes per input byte.
 * A NUL byte ends the text (GLB pads its JSON chunk with spaces; a NUL
 * before the end is checked by rt_json_parse). See include/rt/io/json.h.
 */
#include "rt/io/json.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "rt/base/alloc.h"

static size_t skip_ws(const char *t, size_t i, size_t len)
{
    while (i < len && (t[i] == ' ' || t[i] == '\t' || t[i] == '\n' || t[i] == '\r'))
        i++;
    return i;
}

/* The tokenizer's state: the tokens so far and the stack of open containers. */
typedef struct tokenizer {
    const char *text;
    size_t len, pos;
    rt_json_tok *tok;
    size_t count, cap;
    int open[RT_JSON_MAX_DEPTH]; /* token index of each open container */
    int depth;
    const char *why; /* the error, with pos at its byte */
    rt_result code;  /* and its kind */
} tokenizer;

static int fail(tokenizer *t, rt_result code, const char *why)
{
    t->code = code;
    t->why = why;
    return -1;
}

static int add_token(tokenizer *t, rt_json_type type, size_t start, size_t end)
{
    if (t->count >= (size_t)INT32_MAX || !rt_grow((void **)&t->tok, &t->cap, t->count + 1, sizeof *t->tok)) {
        return fail(t, RT_ERR_NOMEM, "out of memory for JSON tokens");
    }
    rt_json_tok *k = &t->tok[t->count];
    k->type = (int)type;
    k->start = (int)start;
    k->end = (int)end;
    k->size = 0;
    return (int)t->count++;
}

static bool is_hex(char c)
{
    return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
}

/* A string starting at the quote at t->pos; leaves pos after the closing quote. */
static int scan_string(tokenizer *t)
{
    size_t start = t->pos + 1;
    for (size_t i = start; i < t->len && t->text[i]; i++) {
        char c = t->text[i];
        if (c == '"') {
            t->pos = i + 1;
            return add_token(t, RT_JSON_STRING, start, i);
        }
        if (c != '\\')
            continue;
        if (i + 1 >= t->len || !t->text[i + 1])
            break;
        char e = t->text[++i];
        if (e == 'u') {
            for (int k = 1; k <= 4; k++)
                if (i + (size_t)k >= t->len || !is_hex(t->text[i + (size_t)k])) {
                    t->pos = i - 1;
                    return fail(t, RT_ERR_PARSE, "bad \\u escape in a JSON string");
                }
            i += 4;
        } else if (!strchr("\"\\/bfnrt", e)) {
            t->pos = i - 1;
            return fail(t, RT_ERR_PARSE, "bad escape in a JSON string");
        }
    }
    return fail(t, RT_ERR_PARSE, "JSON ends early (unclosed string)"); /* pos: the opening quote */
}

/* A number, true, false or null: the bytes up to the next delimiter. */
static int scan_primitive(tokenizer *t)
{
    size_t start = t->pos, i = start;
    for (; i < t->len && t->text[i]; i++) {
        char c = t->text[i];
        if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == ',' || c == ']' || c == '}')
            break;
        if (c < 32 || c > 126) {
            t->pos = i;
            return fail(t, RT_ERR_PARSE, "invalid JSON character or structure");
        }
    }
    t->pos = i;
    return add_token(t, RT_JSON_PRIMITIVE, start, i);
}

/* What the tokenizer waits for next. */
typedef enum expect { VALUE, KEY, COLON, COMMA_OR_CLOSE, VALUE_OR_CLOSE, KEY_OR_CLOSE } expect;

/* One value (and everything inside it) from t->pos. */
static int tokenize(tokenizer *t)
{
    expect want = VALUE;
    for (;;) {
        t->pos = skip_ws(t->text, t->pos, t->len);
        if (t->pos >= t->len || !t->text[t->pos]) {
            return fail(t, RT_ERR_PARSE, "JSON ends early (unclosed object or array)");
        }
        char c = t->text[t->pos];
        int parent = t->depth ? t->open[t->depth - 1] : -1;
        if ((c == '}' || c == ']') && (want == COMMA_OR_CLOSE || want == VALUE_OR_CLOSE || want == KEY_OR_CLOSE)) {
            rt_json_type type = c == '}' ? RT_JSON_OBJECT : RT_JSON_ARRAY;
            if (parent < 0 || t->tok[parent].type != (int)type) {
                return fail(t, RT_ERR_PARSE, "invalid JSON character or structure");
            }
            t->tok[parent].end = (int)++t->pos;
            if (--t->depth == 0)
                return 0;
            want = COMMA_OR_CLOSE;
            continue;
        }
        if (want == COMMA_OR_CLOSE) {
            if (c != ',') {
                return fail(t, RT_ERR_PARSE, "invalid JSON character or structure");
            }
            t->pos++;
            want = t->tok[parent].type == RT_JSON_OBJECT ? KEY : VALUE;
            continue;
        }
        if (want == COLON) {
            if (c != ':') {
                return fail(t, RT_ERR_PARSE, "invalid JSON character or structure");
            }
            t->pos++;
            want = VALUE;
            continue;
        }
        if (want == KEY || want == KEY_OR_CLOSE) {
            if (c != '"') {
                return fail(t, RT_ERR_PARSE, "invalid JSON character or structure");
            }
            int k = scan_string(t);
            if (k < 0)
                return -1;
            t->tok[parent].size++;
            t->tok[k].size = 1;
            want = COLON;
            continue;
        }
        /* a value: its container (an array, or the object whose key came last) counts it */
        if (parent >= 0 && t->tok[parent].type == RT_JSON_ARRAY)
            t->tok[parent].size++;
        int v;
        if (c == '{' || c == '[') {
            if (t->depth >= RT_JSON_MAX_DEPTH)
                return fail(t, RT_ERR_LIMIT, "JSON nested deeper than " RT_JSON_MAX_DEPTH_TEXT " objects and arrays");
            if ((v = add_token(t, c == '{' ? RT_JSON_OBJECT : RT_JSON_ARRAY, t->pos, t->pos)) < 0)
                return -1;
            t->open[t->depth++] = v;
            t->pos++;
            want = c == '{' ? KEY_OR_CLOSE : VALUE_OR_CLOSE;
            continue;
        }
        if (c == '"')
            v = scan_string(t);
        else if (c == '-' || (c >= '0' && c <= '9') || c == 't' || c == 'f' || c == 'n')
            v = scan_primitive(t);
        else {
            return fail(t, RT_ERR_PARSE, "invalid JSON character or structure");
        }
        if (v < 0)
            return -1;
        if (t->depth == 0)
            return 0;
        want = COMMA_OR_CLOSE;
    }
}

rt_result rt_json_parse(rt_json *j, const char *text, size_t len, const char *name, size_t base, rt_error *err)
{
    memset(j, 0, sizeof *j);
    if (len > RT_JSON_MAX_BYTES)
        return rt_fail(err, RT_ERR_LIMIT, "%s: byte %zu: JSON of %zu bytes is over the %u-byte limit", name, base,
                       len, RT_JSON_MAX_BYTES);
    size_t first = skip_ws(text, 0, len);
    if (first >= len)
        return rt_fail(err, RT_ERR_PARSE, "%s: byte %zu: empty JSON", name, base + first);
    if (text[first] != '{')
        return rt_fail(err, RT_ERR_PARSE, "%s: byte %zu: JSON must start with '{'", name, base + first);
    tokenizer *t = malloc(sizeof *t);
    if (!t)
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for the JSON tokenizer", name);
    memset(t, 0, sizeof *t);
    t->text = text;
    t->len = len;
    t->pos = first;
    if (tokenize(t) < 0) {
        size_t at = t->pos < len ? t->pos : len;
        rt_result r = rt_fail(err, t->code, "%s: byte %zu: %s", name, base + at, t->why);
        free(t->tok);
        free(t);
        return r;
    }
    j->text = text;
    j->len = len;
    j->tok = t->tok;
    j->count = (int)t->count;
    size_t rest = skip_ws(text, t->pos, len);
    free(t);
    /* a glTF (and a sidecar) is exactly one object; only padding may follow it */
    for (size_t i = rest; i < len; i++) {
        if (text[i] != '\0' && text[i] != ' ' && text[i] != '\t' && text[i] != '\n' && text[i] != '\r') {
            rt_json_free(j);
            return rt_fail(err, RT_ERR_PARSE, "%s: byte %zu: unexpected data after the top-level JSON object",
                           name, base + i);
        }
    }
    return RT_OK;
}

void rt_json_free(rt_json *j)
{
    free(j->tok);
    memset(j, 0, sizeof *j);
}

int rt_json_skip(const rt_json *j, int i)
{
    long pending = 1;
    while (pending > 0 && i < j->count) {
        pending += j->tok[i].size;
        pending--;
        i++;
    }
    return i;
}

bool rt_json_key_is(const rt_json *j, int i, const char *s)
{
    if (i < 0 || i >= j->count || j->tok[i].type != RT_JSON_STRING)
        return false;
    size_t n = (size_t)(j->tok[i].end - j->tok[i].start);
    return strlen(s) == n && memcmp(j->text + j->tok[i].start, s, n) == 0;
}

bool rt_json_number(const rt_json *j, int i, double *out)
{
    if (i < 0 || i >= j->count || j->tok[i].type != RT_JSON_PRIMITIVE)
        return false;
    const char *s = j->text + j->tok[i].start;
    size_t n = (size_t)(j->tok[i].end - j->tok[i].start);
    char buf[64];
    if (n == 0 || n >= sizeof buf)
        return false;
    memcpy(buf, s, n);
    buf[n] = '\0';
    /* JSON numbers: -?digits[.digits][e[+-]digits]; strtod accepts more (hex, inf, nan) */
    size_t k = 0;
    if (buf[k] == '-')
        k++;
    if (!(buf[k] >= '0' && buf[k] <= '9'))
        return false;
    for (size_t q = k; q < n; q++) {
        char c = buf[q];
        if (!((c >= '0' && c <= '9') || c == '.' || c == 'e' || c == 'E' || c == '+' || c == '-'))
            return false;
    }
    char *end = NULL;
    double v = strtod(buf, &end);
    if (end != buf + n || !isfinite(v))
        return false;
    *out = v;
    return true;
}

bool rt_json_bool(const rt_json *j, int i, bool *out)
{
    if (i < 0 || i >= j->count || j->tok[i].type != RT_JSON_PRIMITIVE)
        return false;
    const char *s = j->text + j->tok[i].start;
    size_t n = (size_t)(j->tok[i].end - j->tok[i].start);
    if (n == 4 && memcmp(s, "true", 4) == 0) {
        *out = true;
        return true;
    }
    if (n == 5 && memcmp(s, "false", 5) == 0) {
        *out = false;
        return true;
    }
    return false;
}

static int hex4(const char *s, unsigned *out)
{
    unsigned v = 0;
    for (int i = 0; i < 4; i++) {
        char c = s[i];
        v <<= 4;
        if (c >= '0' && c <= '9') v |= (unsigned)(c - '0');
        else if (c >= 'a' && c <= 'f') v |= (unsigned)(c - 'a' + 10);
        else if (c >= 'A' && c <= 'F') v |= (unsigned)(c - 'A' + 10);
        else return 0;
    }
    *out = v;
    return 1;
}

long rt_json_string(const rt_json *j, int i, char *out, size_t cap)
{
    if (i < 0 || i >= j->count || j->tok[i].type != RT_JSON_STRING || cap == 0)
        return -1;
    const char *s = j->text + j->tok[i].start;
    size_t n = (size_t)(j->tok[i].end - j->tok[i].start), o = 0;
    for (size_t k = 0; k < n;) {
        unsigned cp = (unsigned char)s[k];
        if (cp != '\\') {
            if (o + 1 >= cap)
                return -1;
            out[o++] = (char)cp;
            k++;
            continue;
        }
        if (k + 1 >= n)
            return -1;
        char e = s[k + 1];
        k += 2;
        switch (e) {
        case '"': cp = '"'; break;
        case '\\': cp = '\\'; break;
        case '/': cp = '/'; break;
        case 'b': cp = '\b'; break;
        case 'f': cp = '\f'; break;
        case 'n': cp = '\n'; break;
        case 'r': cp = '\r'; break;
        case 't': cp = '\t'; break;
        case 'u':
            if (k + 4 > n || !hex4(s + k, &cp))
                return -1;
            k += 4;
            if (cp >= 0xD800 && cp < 0xDC00) { /* surrogate pair */
                unsigned lo;
                if (k + 6 > n || s[k] != '\\' || s[k + 1] != 'u' || !hex4(s + k + 2, &lo) || lo < 0xDC00 ||
                    lo > 0xDFFF)
                    return -1;
                k += 6;
                cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
            } else if (cp >= 0xDC00 && cp <= 0xDFFF) {
                return -1;
            }
            break;
        default: return -1;
        }
        if (cp == 0)
            return -1; /* an embedded NUL would cut names and paths short */
        char tmp[4];
        size_t m;
        if (cp < 0x80) { tmp[0] = (char)cp; m = 1; }
        else if (cp < 0x800) { tmp[0] = (char)(0xC0 | (cp >> 6)); tmp[1] = (char)(0x80 | (cp & 0x3F)); m = 2; }
        else if (cp < 0x10000) {
            tmp[0] = (char)(0xE0 | (cp >> 12)); tmp[1] = (char)(0x80 | ((cp >> 6) & 0x3F));
            tmp[2] = (char)(0x80 | (cp & 0x3F)); m = 3;
        } else {
            tmp[0] = (char)(0xF0 | (cp >> 18)); tmp[1] = (char)(0x80 | ((cp >> 12) & 0x3F));
            tmp[2] = (char)(0x80 | ((cp >> 6) & 0x3F)); tmp[3] = (char)(0x80 | (cp & 0x3F)); m = 4;
        }
        if (o + m >= cap)
            return -1;
        memcpy(out + o, tmp, m);
        o += m;
    }
    out[o] = '\0';
    return (long)o;
}

int rt_json_get(const rt_json *j, int obj, const char *key)
{
    if (obj < 0 || obj >= j->count || j->tok[obj].type != RT_JSON_OBJECT)
        return -1;
    int i = obj + 1;
    for (int k = 0; k < j->tok[obj].size && i + 1 < j->count; k++) {
        if (rt_json_key_is(j, i, key))
            return i + 1;
        i = rt_json_skip(j, i + 1);
    }
    return -1;
}
