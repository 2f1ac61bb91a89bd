/* test_corpus.c - every input kept in tests/corpus/<target>/ (crashes the
 * fuzzers found, and hand-made nasty files) runs through its fuzz target
 * again. They must load or fail cleanly; under `make asan` any memory error
 * or leak fails the run. */
#include "test_util.h"

#include <dirent.h>

#include "fuzz/harness.h"
#include "rt/base/error.h"
#include "rt/base/log.h"

static int run_dir(const char *target)
{
    char dir[512];
    snprintf(dir, sizeof dir, "tests/corpus/%s", target);
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (e->d_name[0] == '.')
            continue;
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        FILE *f = fopen(path, "rb");
        assert_non_null(f);
        fseek(f, 0, SEEK_END);
        long len = ftell(f);
        fseek(f, 0, SEEK_SET);
        uint8_t *buf = malloc(len > 0 ? (size_t)len : 1);
        assert_non_null(buf);
        assert_int_equal(fread(buf, 1, (size_t)len, f), (size_t)len);
        fclose(f);
        assert_int_equal(rt_fuzz_run(target, buf, (size_t)len), 0);
        free(buf);
        n++;
    }
    closedir(d);
    return n;
}

/* The inputs kept in tests/corpus/, counted apart from the replay: every
 * folder there must be a fuzz target (else its inputs would never run). */
static int count_corpus(void)
{
    DIR *top = opendir("tests/corpus");
    assert_non_null(top);
    int n = 0;
    struct dirent *t;
    while ((t = readdir(top))) {
        if (t->d_name[0] == '.')
            continue;
        bool known = false;
        for (int i = 0; rt_fuzz_targets[i]; i++)
            known |= strcmp(rt_fuzz_targets[i], t->d_name) == 0;
        if (!known)
            fail_msg("tests/corpus/%s: no fuzz target of that name (tests/fuzz/harness.c)", t->d_name);
        char dir[512];
        snprintf(dir, sizeof dir, "tests/corpus/%s", t->d_name);
        DIR *d = opendir(dir);
        assert_non_null(d);
        struct dirent *e;
        while ((e = readdir(d)))
            n += e->d_name[0] != '.';
        closedir(d);
    }
    closedir(top);
    return n;
}

static void test_corpus(void **state)
{
    (void)state;
    rt_log_set_level(RT_LOG_QUIET);
    int total = 0;
    for (int i = 0; rt_fuzz_targets[i]; i++)
        total += run_dir(rt_fuzz_targets[i]);
    /* every kept input was replayed, and there are some */
    int kept = count_corpus();
    assert_true(kept > 0);
    assert_int_equal(total, kept);
    /* the harness rejects unknown targets */
    assert_int_equal(rt_fuzz_run("no-such-target", (const uint8_t *)"", 0), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_corpus)};
    return cmocka_run_group_tests_name("corpus", tests, NULL, NULL);
}
