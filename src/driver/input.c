/* input.c - what `rt` reads and the name it writes by default (input.h):
 * rt_load for paths and the built-in scene, standard input read whole and
 * loaded from memory, the names messages use, and the default output name
 * (the scene's `output`, else NAME.png for input NAME.ext). */
#include "input.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rt/base/file.h"

void input_default_output(const rt_scene *s, const char *input, char *out, size_t size)
{
    if (s && s->settings.output[0]) {
        snprintf(out, size, "%s", s->settings.output);
        return;
    }
    if (!input || strcmp(input, "-") == 0) {
        snprintf(out, size, "out.png");
        return;
    }
    const char *base = strrchr(input, '/');
    base = base ? base + 1 : input;
    const char *dot = strrchr(base, '.');
    int len = dot && dot != base ? (int)(dot - base) : (int)strlen(base);
    snprintf(out, size, "%.*s.png", len, base);
}

/* Relative paths in a scene from standard input resolve against the
 * current directory. */
rt_result input_load(rt_scene *s, const char *input, const rt_load_options *lo, rt_load_info *info, rt_error *err)
{
    if (!input || strcmp(input, "-") != 0)
        return rt_load(s, input, lo, info, err);
    memset(info, 0, sizeof *info);
    if (isatty(0))
        return rt_fail(err, RT_ERR_IO,
                       "-: standard input is a terminal; pipe a scene in (rt - < scene.txt, or cat model.glb | rt -)");
    char *bytes;
    size_t size;
    rt_error inner = {0};
    if (rt_read_file("/dev/stdin", 0, &bytes, &size, &inner) != RT_OK) {
        const char *what = strncmp(inner.message, "/dev/stdin: ", 12) == 0 ? inner.message + 12 : inner.message;
        return rt_fail(err, inner.code, "<stdin>: %s", what);
    }
    rt_result r = rt_load_memory(s, bytes, size, "<stdin>", lo, info, err);
    free(bytes);
    return r;
}

const char *input_name(const char *input)
{
    return !input ? "<built-in scene>" : strcmp(input, "-") == 0 ? "<stdin>" : input;
}
