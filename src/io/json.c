/* json.c - JSON for the glTF loader and the part sidecars: a strict
 * grammar check of our own, then jsmn (zserge/jsmn, MIT, the Debian
 * libjsmn-dev header; not copied here) for the tokens, and the token
 * walkers of rt/io/json.h.
 *
 * The check comes first, as the image guards come before stb_image: it
 * reads the text once with a stack of the open containers, so it is linear
 * in the text, and refuses what RFC 8259 refuses and jsmn's strict mode
 * lets through (a missing or trailing comma, a value without its key),
 * bad escapes, and nesting deeper than RT_JSON_MAX_DEPTH, each with the
 * byte where it goes wrong. Only then does jsmn see the text, up to the
 * end of its one top-level object. jsmn finds the container a closing
 * bracket returns to by walking parent links back from the last token
 * (JSMN_PARENT_LINKS; without them it scans back over every token), so its
 * cost grows with the nesting depth at each closing bracket: unbounded,
 * that was quadratic (a 600 KB file of nested arrays took 104 s, glTF
 * extras 100 000 deep 11.6 s); with the depth capped it is linear.
 *
 * jsmn runs twice: once with a NULL token array to count tokens, then into
 * an array of exactly that size (the count is bounded by the text length,
 * so a lying file cannot make us allocate more than a few bytes per input
 * byte). Tokens are copied into rt_json_tok so no other file needs jsmn's
 * header. A NUL byte ends the text (GLB pads its JSON chunk with spaces;
 * only padding may follow the object). See include/rt/io/json.h.
 */
#define JSMN_PARENT_LINKS
#define JSMN_STRICT
#define JSMN_STATIC
#include <jsmn.h>

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

/* The grammar check's state: where it reads and the stack of open containers. */
typedef struct checker {
    const char *text;
    size_t len, pos;
    char open[RT_JSON_MAX_DEPTH]; /* '{' or '[' of each open container */
    int depth;
    const char *why; /* the error, with pos at its byte */
    rt_result code;  /* and its kind */
} checker;

static int fail(checker *c, rt_result code, const char *why)
{
    c->code = code;
    c->why = why;
    return -1;
}

static bool is_hex(char c)
{
    return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
}

/* A string starting at the quote at c->pos; leaves pos after the closing quote. */
static int scan_string(checker *c)
{
    for (size_t i = c->pos + 1; i < c->len && c->text[i]; i++) {
        char ch = c->text[i];
        if (ch == '"') {
            c->pos = i + 1;
            return 0;
        }
        if (ch != '\\')
            continue;
        if (i + 1 >= c->len || !c->text[i + 1])
            break;
        char e = c->text[++i];
        if (e == 'u') {
            for (int k = 1; k <= 4; k++)
                if (i + (size_t)k >= c->len || !is_hex(c->text[i + (size_t)k])) {
                    c->pos = i - 1;
                    return fail(c, RT_ERR_PARSE, "bad \\u escape in a JSON string");
                }
            i += 4;
        } else if (!strchr("\"\\/bfnrt", e)) {
            c->pos = i - 1;
            return fail(c, RT_ERR_PARSE, "bad escape in a JSON string");
        }
    }
    return fail(c, RT_ERR_PARSE, "JSON ends early (unclosed string)"); /* pos: the opening quote */
}

/* A number, true, false or null: the bytes up to the next delimiter (the
 * walkers that read them, rt_json_number and rt_json_bool, check them). */
static int scan_primitive(checker *c)
{
    size_t i = c->pos;
    for (; i < c->len && c->text[i]; i++) {
        char ch = c->text[i];
        if (ch == ' ' || ch == '\t' || ch == '\n' || ch == '\r' || ch == ',' || ch == ']' || ch == '}')
            break;
        if (ch < 32 || ch > 126) {
            c->pos = i;
            return fail(c, RT_ERR_PARSE, "invalid JSON character or structure");
        }
    }
    c->pos = i;
    return 0;
}

/* What the check waits for next. */
typedef enum expect { VALUE, KEY, COLON, COMMA_OR_CLOSE, VALUE_OR_CLOSE, KEY_OR_CLOSE } expect;

/* One value (and everything inside it) from c->pos; leaves pos after it. */
static int check_value(checker *c)
{
    expect want = VALUE;
    for (;;) {
        c->pos = skip_ws(c->text, c->pos, c->len);
        if (c->pos >= c->len || !c->text[c->pos])
            return fail(c, RT_ERR_PARSE, "JSON ends early (unclosed object or array)");
        char ch = c->text[c->pos];
        char parent = c->depth ? c->open[c->depth - 1] : 0;
        if ((ch == '}' || ch == ']') && (want == COMMA_OR_CLOSE || want == VALUE_OR_CLOSE || want == KEY_OR_CLOSE)) {
            if (parent != (ch == '}' ? '{' : '['))
                return fail(c, RT_ERR_PARSE, "invalid JSON character or structure");
            c->pos++;
            if (--c->depth == 0)
                return 0;
            want = COMMA_OR_CLOSE;
            continue;
        }
        if (want == COMMA_OR_CLOSE) {
            if (ch != ',')
                return fail(c, RT_ERR_PARSE, "invalid JSON character or structure");
            c->pos++;
            want = parent == '{' ? KEY : VALUE;
            continue;
        }
        if (want == COLON) {
            if (ch != ':')
                return fail(c, RT_ERR_PARSE, "invalid JSON character or structure");
            c->pos++;
            want = VALUE;
            continue;
        }
        if (want == KEY || want == KEY_OR_CLOSE) {
            if (ch != '"' || scan_string(c) < 0)
                return ch != '"' ? fail(c, RT_ERR_PARSE, "invalid JSON character or structure") : -1;
            want = COLON;
            continue;
        }
        if (ch == '{' || ch == '[') {
            if (c->depth >= RT_JSON_MAX_DEPTH)
                return fail(c, RT_ERR_LIMIT, "JSON nested deeper than " RT_JSON_MAX_DEPTH_TEXT " objects and arrays");
            c->open[c->depth++] = ch;
            c->pos++;
            want = ch == '{' ? KEY_OR_CLOSE : VALUE_OR_CLOSE;
            continue;
        }
        int r;
        if (ch == '"')
            r = scan_string(c);
        else if (ch == '-' || (ch >= '0' && ch <= '9') || ch == 't' || ch == 'f' || ch == 'n')
            r = scan_primitive(c);
        else
            return fail(c, RT_ERR_PARSE, "invalid JSON character or structure");
        if (r < 0)
            return -1;
        if (c->depth == 0)
            return 0;
        want = COMMA_OR_CLOSE;
    }
}

/* jsmn over text[0, end), which the check has passed: the tokens into j. */
static rt_result tokenize(rt_json *j, const char *text, size_t end, const char *name, size_t base, rt_error *err)
{
    jsmn_parser p;
    jsmn_init(&p);
    int n = jsmn_parse(&p, text, end, NULL, 0);
    if (n >= 0) {
        jsmntok_t *jt = rt_alloc((size_t)n, sizeof *jt);
        if (!jt)
            return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for %d JSON tokens", name, n);
        jsmn_init(&p);
        int m = jsmn_parse(&p, text, end, jt, (unsigned)n);
        if (m >= 0 && m != n)
            m = JSMN_ERROR_INVAL; /* cannot happen: both passes see the same text */
        if (m >= 0) {
            j->tok = rt_alloc((size_t)n, sizeof *j->tok);
            if (!j->tok) {
                free(jt);
                return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for %d JSON tokens", name, n);
            }
            for (int i = 0; i < n; i++) {
                j->tok[i].type = (int)jt[i].type;
                j->tok[i].start = jt[i].start;
                j->tok[i].end = jt[i].end;
                j->tok[i].size = jt[i].size;
            }
        }
        free(jt);
        n = m;
    }
    if (n < 0) { /* the check is stricter than jsmn, so this is a disagreement between the two */
        size_t at = p.pos < end ? p.pos : end;
        const char *why = n == JSMN_ERROR_PART ? "JSON ends early (unclosed object, array or string)"
                                               : "invalid JSON character or structure";
        return rt_fail(err, RT_ERR_PARSE, "%s: byte %zu: %s", name, base + at, why);
    }
    j->count = n;
    if (n < 1 || j->tok[0].type != RT_JSON_OBJECT || rt_json_skip(j, 0) != n) {
        rt_json_free(j);
        return rt_fail(err, RT_ERR_PARSE, "%s: byte %zu: JSON must be one object", name, base);
    }
    return RT_OK;
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
    checker *c = malloc(sizeof *c);
    if (!c)
        return rt_fail(err, RT_ERR_NOMEM, "%s: out of memory for the JSON check", name);
    memset(c, 0, sizeof *c);
    c->text = text;
    c->len = len;
    c->pos = first;
    if (check_value(c) < 0) {
        size_t at = c->pos < len ? c->pos : len;
        rt_result r = rt_fail(err, c->code, "%s: byte %zu: %s", name, base + at, c->why);
        free(c);
        return r;
    }
    size_t end = c->pos;
    free(c);
    /* a glTF (and a sidecar) is exactly one object; only padding may follow it */
    for (size_t i = skip_ws(text, end, len); i < len; i++) {
        if (text[i] != '\0' && text[i] != ' ' && text[i] != '\t' && text[i] != '\n' && text[i] != '\r')
            return rt_fail(err, RT_ERR_PARSE, "%s: byte %zu: unexpected data after the top-level JSON object",
                           name, base + i);
    }
    rt_result r = tokenize(j, text, end, name, base, err);
    if (r != RT_OK)
        return r;
    j->text = text;
    j->len = len;
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
