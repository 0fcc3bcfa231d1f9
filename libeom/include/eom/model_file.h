/* model_file.h - models written as text (.eom files, docs/models.md).
 *
 * A model file names parameters and coordinates with units, and gives T
 * and V (or L), an optional dissipation R, forces, holonomic constraints
 * and probes as expressions. Structural settings (a number of links, of
 * modes) and indexed families (theta[j] for j in 1..links) with
 * recurrences let one file describe a chain of any length. The
 * expressions are recorded onto libtape's tapes exactly as a C callback
 * would record them.
 *
 * Two steps: read (parse and check the file; structural settings may then
 * be changed) and build (an eom_model for the current settings, checked
 * by recording every part once). Errors are EOM_ERR_FILE with a message
 * "path:line:col: what is wrong", the offending line, a caret under the
 * column and, where it is knowable, what to write instead.
 */
#ifndef EOM_MODEL_FILE_H
#define EOM_MODEL_FILE_H

#include <stddef.h>

#include "eom/eom.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct eom_file eom_file;

/* Read the model file at path. On failure *out is NULL and err (errlen
 * bytes, may be NULL) holds the message. */
EOM_API int eom_file_read(eom_file **out, const char *path, char *err,
                          size_t errlen);
/* The same from text in memory; name (may be NULL: "<string>") is used in
 * messages. text is copied. */
EOM_API int eom_file_parse(eom_file **out, const char *text,
                           const char *name, char *err, size_t errlen);
EOM_API void eom_file_free(eom_file **f);

/* The file's first comment line ("" when it does not start with one). */
EOM_API const char *eom_file_summary(const eom_file *f);

/* Structural settings (whole numbers), in the order of the file. */
EOM_API int eom_file_nsettings(const eom_file *f);
EOM_API const char *eom_file_setting_name(const eom_file *f, int k);
/* "" when the file gives none. */
EOM_API const char *eom_file_setting_description(const eom_file *f, int k);
/* The default and the allowed range, inclusive (any pointer may be
 * NULL). */
EOM_API int eom_file_setting_range(const eom_file *f, int k, long *dflt,
                                   long *min, long *max);
/* The value the next build uses (the default until changed). */
EOM_API long eom_file_setting(const eom_file *f, int k);
/* Change a setting by name: EOM_ERR_NAME for an unknown name, EOM_ERR_ARG
 * outside the range, each with a message in err. */
EOM_API int eom_file_set_setting(eom_file *f, const char *name, long value,
                                 char *err, size_t errlen);

/* Build the model for the current settings; *out is a new model (the
 * caller frees it; it does not borrow f). Everything the file asks for is
 * recorded once before it returns, so a problem that depends on the
 * settings (an index out of range, a recurrence without its base case, a
 * cycle among definitions, a T that does not depend on some rate) is
 * reported here as EOM_ERR_FILE. */
EOM_API int eom_file_build(const eom_file *f, eom_model **out, char *err,
                           size_t errlen);

/* Read and build in one call, with the default settings. */
EOM_API int eom_model_from_file(eom_model **out, const char *path,
                                char *err, size_t errlen);
EOM_API int eom_model_from_string(eom_model **out, const char *text,
                                  char *err, size_t errlen);

#ifdef __cplusplus
}
#endif
#endif /* EOM_MODEL_FILE_H */
