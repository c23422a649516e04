/* pdt — the libFuzzer entry point of one target: `make fuzz` compiles this
 * file once per target with -DFUZZ_FN=fuzz_NAME and clang's
 * -fsanitize=fuzzer,address,undefined. */
#include "fuzz_targets.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    (void)FZ_TARGETS;
    return FUZZ_FN(data, size);
}
