/* fuzz_model_file.c - libFuzzer target for the model-file loader: any
 * bytes are read as a model file and, when they parse, built with every
 * structural setting at its smallest value and at its default (capped),
 * so that the recorder runs on what the parser accepted. The loader must
 * return an error or a model, never crash, hang or leak. Built with
 * -Dfuzz=true and clang (tests/fuzz/meson.build); fuzz_replay.c runs the
 * seed corpus through the same function in every test run. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "eom/model_file.h"
#include "lang.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1), err[2048];
    eom_file *f = NULL;
    int pass, k;
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    if (eom_file_parse(&f, text, "fuzz", err, sizeof err) == EOM_OK) {
        /* small enough to explore many inputs a second */
        lang_file_limits(f, 200000, 200);
        for (pass = 0; pass < 2; pass++) {
            eom_model *m = NULL;
            for (k = 0; k < eom_file_nsettings(f); k++) {
                long dflt, lo, hi, v;
                eom_file_setting_range(f, k, &dflt, &lo, &hi);
                v = pass ? (dflt < lo + 20 ? dflt : lo + 20) : lo;
                eom_file_set_setting(f, eom_file_setting_name(f, k), v, err,
                                     sizeof err);
            }
            if (eom_file_build(f, &m, err, sizeof err) == EOM_OK) {
                eom_system *s = NULL;
                if (eom_model_ncoords(m) <= 50 &&
                    eom_system_new(&s, m, err, sizeof err) == EOM_OK)
                    eom_system_free(&s);
            }
            eom_model_free(&m);
        }
    }
    eom_file_free(&f);
    free(text);
    return 0;
}
