/* fuzz_main.c - the libFuzzer entry point; RT_FUZZ_TARGET names the target
 * (see harness.h). Built by tools/fuzz.sh. A target name the harness does
 * not know stops the binary at start-up (exit 2) and, should one get past
 * that, aborts on the first input: a misspelled target fails loudly instead
 * of fuzzing nothing. Warnings are silenced (they cost more than the parse
 * on short inputs and flood the log); set RT_FUZZ_WARNINGS=1 to see them. */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "rt/base/error.h"
#include "rt/base/log.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    bool known = false;
    for (int i = 0; rt_fuzz_targets[i]; i++)
        known |= strcmp(rt_fuzz_targets[i], RT_FUZZ_TARGET) == 0;
    if (!known) {
        fprintf(stderr, "fuzz: unknown target '%s' (tests/fuzz/harness.h lists them)\n", RT_FUZZ_TARGET);
        exit(2);
    }
    const char *w = getenv("RT_FUZZ_WARNINGS");
    if (!(w && *w == '1'))
        rt_log_set_level(RT_LOG_QUIET);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (rt_fuzz_run(RT_FUZZ_TARGET, data, size) != 0)
        abort();
    return 0;
}
