/* fuzz_replay.c - runs every file given on the command line through the
 * fuzz target (fuzz_model_file.c), as the default test suite's replay of
 * the seed corpus in tests/fuzz/corpus and of the shipped models: under
 * ASan/UBSan and valgrind in CI, a crash or a leak fails the test. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int main(int argc, char **argv)
{
    int k, n = 0;
    for (k = 1; k < argc; k++) {
        FILE *f = fopen(argv[k], "rb");
        unsigned char *buf;
        long len;
        if (!f) {
            fprintf(stderr, "fuzz_replay: cannot open %s\n", argv[k]);
            return 1;
        }
        fseek(f, 0, SEEK_END);
        len = ftell(f);
        fseek(f, 0, SEEK_SET);
        buf = malloc((size_t)len + 1);
        if (!buf || fread(buf, 1, (size_t)len, f) != (size_t)len) {
            fprintf(stderr, "fuzz_replay: cannot read %s\n", argv[k]);
            fclose(f);
            free(buf);
            return 1;
        }
        fclose(f);
        LLVMFuzzerTestOneInput(buf, (size_t)len);
        free(buf);
        n++;
    }
    printf("%d inputs replayed\n", n);
    return n > 0 ? 0 : 1;
}
