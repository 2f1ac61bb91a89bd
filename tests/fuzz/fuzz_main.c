/* fuzz_main.c - the libFuzzer entry point; RT_FUZZ_TARGET names the target
 * (see harness.h). Built by tools/fuzz.sh. */
#include "harness.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rt_fuzz_run(RT_FUZZ_TARGET, data, size);
    return 0;
}
