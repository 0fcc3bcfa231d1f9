/* diag.c - messages about a model file: "path:line:col: message", the
 * offending line and a caret under the column, then an optional hint.
 * Also the edit distance behind "did you mean" and the growable arrays
 * every stage uses. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lang.h"

static void vdiag(const lang_prog *p, int line, int col, char *out,
                  size_t len, const char *hint, const char *fmt, va_list ap)
{
    size_t n;
    long i, start = 0, end;
    int cur = 1, k, width;
    if (!out || len == 0)
        return;
    snprintf(out, len, "%s:%d:%d: ", p->path ? p->path : "<string>", line,
             col);
    n = strlen(out);
    vsnprintf(out + n, len - n, fmt, ap);
    /* the source line, tabs kept so that the caret lines up */
    for (i = 0; i < p->text_len && cur < line; i++)
        if (p->text[i] == '\n') {
            cur++;
            start = i + 1;
        }
    if (cur != line || start > p->text_len)
        goto hint;
    for (end = start; end < p->text_len && p->text[end] != '\n' &&
                      p->text[end] != '\r';
         end++)
        ;
    width = (int)(end - start);
    if (width > 200)
        width = 200; /* a very long line: its start is enough */
    n = strlen(out);
    snprintf(out + n, len - n, "\n  %.*s\n  ", width, p->text + start);
    for (k = 1; k < col && k <= width; k++) {
        n = strlen(out);
        if (n + 2 < len) {
            out[n] = p->text[start + k - 1] == '\t' ? '\t' : ' ';
            out[n + 1] = '\0';
        }
    }
    n = strlen(out);
    snprintf(out + n, len - n, "^");
hint:
    if (hint && hint[0]) {
        n = strlen(out);
        snprintf(out + n, len - n, "\n  %s", hint);
    }
}

void lang_diag(const lang_prog *p, int tok, char *out, size_t len,
               const char *hint, const char *fmt, ...)
{
    va_list ap;
    int line = 1, col = 1;
    if (tok >= 0 && tok < p->ntoks) {
        line = p->toks[tok].line;
        col = p->toks[tok].col;
    }
    va_start(ap, fmt);
    vdiag(p, line, col, out, len, hint, fmt, ap);
    va_end(ap);
}

void lang_diag_at(const lang_prog *p, int line, int col, char *out,
                  size_t len, const char *hint, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vdiag(p, line, col, out, len, hint, fmt, ap);
    va_end(ap);
}

const char *lang_tok_text(const lang_prog *p, int t, char *buf, size_t len)
{
    const token *k;
    size_t n;
    if (len == 0)
        return buf;
    buf[0] = '\0';
    if (t < 0 || t >= p->ntoks)
        return buf;
    k = &p->toks[t];
    if (k->kind == TK_EOF)
        return snprintf(buf, len, "end of file"), buf;
    if (k->kind == TK_NL)
        return snprintf(buf, len, "end of line"), buf;
    n = (size_t)k->len < len - 1 ? (size_t)k->len : len - 1;
    memcpy(buf, p->text + k->off, n);
    buf[n] = '\0';
    return buf;
}

/* Optimal string alignment: insertions, deletions, substitutions and
 * swaps of two neighbours (cso -> cos) each count one. */
int lang_edit_distance(const char *a, const char *b, int cap)
{
    int d[3][LANG_MAX_NAME + 1]; /* rows i - 2, i - 1, i (mod 3) */
    int la = (int)strlen(a), lb = (int)strlen(b), i, j;
    if (la > LANG_MAX_NAME || lb > LANG_MAX_NAME)
        return cap + 1;
    if (la - lb > cap || lb - la > cap)
        return cap + 1;
    for (j = 0; j <= lb; j++)
        d[0][j] = j;
    for (i = 1; i <= la; i++) {
        int *cur = d[i % 3], *up = d[(i - 1) % 3], *up2 = d[(i + 1) % 3];
        int best;
        cur[0] = best = i;
        for (j = 1; j <= lb; j++) {
            int v = up[j - 1] + (a[i - 1] != b[j - 1]);
            if (up[j] + 1 < v)
                v = up[j] + 1;
            if (cur[j - 1] + 1 < v)
                v = cur[j - 1] + 1;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] &&
                a[i - 2] == b[j - 1] && up2[j - 2] + 1 < v)
                v = up2[j - 2] + 1;
            cur[j] = v;
            if (v < best)
                best = v;
        }
        if (best > cap + 1)
            return cap + 1;
    }
    return d[la % 3][lb] > cap ? cap + 1 : d[la % 3][lb];
}

int lang_grow(void **v, int *cap, int need, size_t elem, int limit)
{
    void *nv;
    int nc;
    if (need <= *cap)
        return 0;
    if (need > limit)
        return -1;
    nc = *cap ? *cap : 16;
    while (nc < need)
        nc = nc > limit / 2 ? limit : 2 * nc;
    nv = realloc(*v, (size_t)nc * elem);
    if (!nv)
        return -1;
    *v = nv;
    *cap = nc;
    return 0;
}

char *lang_strdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

void lang_copy(char *dst, size_t len, const char *src)
{
    size_t n;
    if (!dst || len == 0)
        return;
    n = strlen(src);
    if (n >= len)
        n = len - 1;
    memcpy(dst, src, n);
    dst[n] = '\0';
}

void lang_prog_release(lang_prog *p)
{
    if (!p || --p->refs > 0)
        return;
    free(p->path);
    free(p->text);
    free(p->toks);
    free(p->nodes);
    free(p->kids);
    free(p->syms);
    free(p->clauses);
    free(p->stmts);
    free(p->draws);
    free(p->var_tok);
    free(p);
}
