/* doc_tables.c - prints the tables of docs/libtape.md that are generated
 * from the library's X-macro lists (status codes, operations), or, with
 * --check FILE, verifies that FILE holds them verbatim between its
 * "<!-- NAME:begin -->" and "<!-- NAME:end -->" markers. The test suite
 * runs the check, so the documentation cannot drift from the code.
 *
 * usage: doc-tables status|ops
 *        doc-tables --check docs/libtape.md */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tape/tape.h"
#include "tape_ops.h"

/* A markdown table cell: '|' must be escaped. */
static void cell(FILE *f, const char *text)
{
    for (; *text; text++) {
        if (*text == '|')
            fputc('\\', f);
        fputc(*text, f);
    }
}

static void status_table(FILE *f)
{
    fprintf(f, "| code | value | meaning |\n|---|---|---|\n");
#define ROW_(name, value, text)                                            \
    fprintf(f, "| `%s` | %d | ", #name, value);                            \
    cell(f, text);                                                         \
    fprintf(f, " |\n");
    TP_STATUS_LIST(ROW_)
#undef ROW_
}

static const char *kind_text(const char *kind)
{
    if (!strcmp(kind, "BINARY"))
        return "two values";
    if (!strcmp(kind, "UNARY"))
        return "one value";
    if (!strcmp(kind, "UCONST"))
        return "a value and a constant c";
    if (!strcmp(kind, "UINT"))
        return "a value and an integer k";
    return "leaf";
}

static void ops_table(FILE *f)
{
    fprintf(f, "| op | operands | meaning |\n|---|---|---|\n");
#define ROW_(name, kind, flags, dom, text)                                  \
    if (strcmp(#kind, "LEAF")) {                                           \
        fprintf(f, "| `%s` | %s | ", #name, kind_text(#kind));             \
        cell(f, text);                                                     \
        fprintf(f, " |\n");                                                \
    }
    TP_OP_TABLE(ROW_)
#undef ROW_
}

/* The text between the markers of table name in buf, or NULL. */
static const char *between(const char *buf, const char *name, size_t *len)
{
    char begin[64], end[64];
    const char *b, *e;
    snprintf(begin, sizeof begin, "<!-- %s:begin -->\n", name);
    snprintf(end, sizeof end, "<!-- %s:end -->", name);
    b = strstr(buf, begin);
    if (!b)
        return NULL;
    b += strlen(begin);
    e = strstr(b, end);
    if (!e)
        return NULL;
    *len = (size_t)(e - b);
    return b;
}

static int check_one(const char *doc, const char *name, const char *arg,
                     void (*gen)(FILE *))
{
    char *want = NULL;
    const char *have;
    size_t wlen = 0, hlen;
    FILE *m = open_memstream(&want, &wlen);
    int ok;
    if (!m)
        return 0;
    gen(m);
    fclose(m);
    have = between(doc, name, &hlen);
    ok = have && hlen == wlen && memcmp(have, want, wlen) == 0;
    if (!ok)
        fprintf(stderr, "the %s table in the document is out of date; "
                        "regenerate it with: doc-tables %s\n", name, arg);
    free(want);
    return ok;
}

int main(int argc, char **argv)
{
    if (argc == 2 && !strcmp(argv[1], "status")) {
        status_table(stdout);
        return 0;
    }
    if (argc == 2 && !strcmp(argv[1], "ops")) {
        ops_table(stdout);
        return 0;
    }
    if (argc == 3 && !strcmp(argv[1], "--check")) {
        FILE *f = fopen(argv[2], "rb");
        char *buf;
        long n;
        int ok;
        if (!f || fseek(f, 0, SEEK_END) || (n = ftell(f)) < 0 ||
            fseek(f, 0, SEEK_SET)) {
            fprintf(stderr, "doc-tables: cannot read %s\n", argv[2]);
            return 1;
        }
        buf = malloc((size_t)n + 1);
        if (!buf || fread(buf, 1, (size_t)n, f) != (size_t)n) {
            fprintf(stderr, "doc-tables: cannot read %s\n", argv[2]);
            return 1;
        }
        buf[n] = '\0';
        fclose(f);
        ok = check_one(buf, "status-table", "status", status_table);
        ok &= check_one(buf, "op-table", "ops", ops_table);
        free(buf);
        return ok ? 0 : 1;
    }
    fprintf(stderr, "usage: doc-tables status|ops | --check FILE\n");
    return 2;
}
