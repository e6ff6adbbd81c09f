/* Without libFuzzer (e.g. gcc): run a fuzz target once on each file named on the command line.
 * Included at the end of each target, built with -DTF_FUZZ_REPLAY. */
#ifndef THERMOFRICTION_FUZZ_REPLAY_MAIN_H
#define THERMOFRICTION_FUZZ_REPLAY_MAIN_H
#include <stdint.h>
#include <stdio.h>

int main(int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        FILE *f = fopen(argv[i], "rb");
        if (!f) { fprintf(stderr, "cannot open %s\n", argv[i]); return 2; }
        static uint8_t buf[1 << 16];
        size_t len = fread(buf, 1, sizeof buf, f);
        fclose(f);
        LLVMFuzzerTestOneInput(buf, len);
    }
    printf("replayed %d inputs\n", argc - 1);
    return 0;
}
#endif
