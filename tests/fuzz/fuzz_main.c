/* fuzz_main.c - the libFuzzer entry point; RT_FUZZ_TARGET names the target
 * (see harness.h). Built by tools/fuzz.sh. Warnings are silenced (they cost
 * more than the parse on short inputs and flood the log); set
 * RT_FUZZ_WARNINGS=1 to see them. */
#include <stdlib.h>

#include "harness.h"
#include "rt/base/error.h"
#include "rt/base/log.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    const char *w = getenv("RT_FUZZ_WARNINGS");
    if (!(w && *w == '1'))
        rt_log_set_level(RT_LOG_QUIET);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rt_fuzz_run(RT_FUZZ_TARGET, data, size);
    return 0;
}
