/* cli_support.h - what the command-line tests share: running eom-run in
 * a child process with its standard output and error captured, a scratch
 * directory per test process, and reading a CSV of numbers back.
 *
 * The environment variable EOM_CLI_WRAPPER, if set, is a command (words
 * split at spaces) that eom-run runs under, for example
 * "valgrind -q --error-exitcode=99 --leak-check=full". Include check.h
 * before this header (CHECK_HAS uses its counters). */
#ifndef TESTS_CLI_SUPPORT_H
#define TESTS_CLI_SUPPORT_H

#include <stddef.h>

/* The program under test; set by main before the first run. */
extern const char *cli_program;

typedef struct result {
    int status;      /* exit status; 128 + signal when killed */
    char *out, *err; /* everything written to stdout and stderr */
} result;

/* Make the scratch directory ($TMPDIR or /tmp); 0, or -1 after a
 * message. cli_cleanup removes it with the files and empty directories
 * a case left in it. */
int cli_setup(void);
void cli_cleanup(void);

/* buf = the path of name in the scratch directory. */
void scratch(char *buf, size_t len, const char *name);

/* The whole file (NUL-terminated; *len its length if len is not NULL),
 * or NULL. The caller frees it. */
char *read_file(const char *path, size_t *len);

/* Run the program with args (NULL-terminated) and capture its output.
 * run_path does the same with the environment variable PATH set to path
 * for the program only (the wrapper, if any, is found on the current
 * PATH first). Exits the test on a failure to capture. */
void run(result *r, const char *const *args);
void run_path(result *r, const char *const *args, const char *path);
/* The same with the working directory dir for the program (the program's
 * path must then be absolute). */
void run_in(result *r, const char *const *args, const char *dir);
void result_free(result *r);

/* s contains word (case-sensitive); 0 when s is NULL. */
int has(const char *s, const char *word);

#define CHECK_HAS(s, word)                                                 \
    do {                                                                   \
        check_count_++;                                                    \
        if (!has((s), (word)))                                             \
            CHECK_FAIL_("'%s' not found in %s:\n%s", (word), #s,          \
                        (s) ? (s) : "(null)");                             \
    } while (0)

/* The number that follows the first occurrence of label in s (for the
 * figures of the end-of-run summary); NaN if label is missing or no
 * number follows. */
double number_after(const char *s, const char *label);

/* a and b agree to rel relative to |b| (for figures printed with a few
 * significant digits). */
#define CHECK_REL(a, b, rel)                                               \
    do {                                                                   \
        double a_ = (a), b_ = (b);                                         \
        check_count_++;                                                    \
        if (!(fabs(a_ - b_) <= (rel) * fabs(b_)))                          \
            CHECK_FAIL_("%s ~ %s failed: %.17g vs %.17g (relative %g)",    \
                        #a, #b, a_, b_, (double)(rel));                    \
    } while (0)

/* A CSV of numbers after one header row. */
typedef struct csv {
    char header[8192];
    int ncols, nrows;
    double *v; /* nrows x ncols */
} csv;

/* Parse text into *c (c->v is allocated; free it). Returns 0, or -1
 * with a message in msg (msglen bytes) if the header is missing or too
 * long, a row is ragged or a field is not a number; the rows before the
 * bad one are kept. */
int csv_parse(const char *text, csv *c, char *msg, size_t msglen);

/* The value at row, col; the index of the column named name or -1. */
double at(const csv *c, int row, int col);
int csv_col(const csv *c, const char *name);

#endif /* TESTS_CLI_SUPPORT_H */
