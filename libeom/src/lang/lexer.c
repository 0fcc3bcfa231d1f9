/* lexer.c - model-file text to tokens. Newlines end statements except
 * inside parentheses and brackets; '#' starts a comment to the end of the
 * line. Every token keeps its line, column and whether whitespace came
 * right before it (an index is written "theta[j]", a unit " [rad]"). */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lang.h"

static int push(lang_prog *p, int *cap, token t)
{
    if (lang_grow((void **)&p->toks, cap, p->ntoks + 1, sizeof t,
                  (int)LANG_MAX_FILE + 2) != 0)
        return -1;
    p->toks[p->ntoks++] = t;
    return 0;
}

/* Length of the number at s (digits, an optional fraction not followed
 * by a second '.', an optional exponent), 0 if none. */
static long number_len(const char *s, long avail, int *bad_exp)
{
    long i = 0;
    *bad_exp = 0;
    while (i < avail && isdigit((unsigned char)s[i]))
        i++;
    if (i < avail && s[i] == '.' && !(i + 1 < avail && s[i + 1] == '.')) {
        i++;
        while (i < avail && isdigit((unsigned char)s[i]))
            i++;
    }
    if (i == 0 || (i == 1 && s[0] == '.'))
        return 0;
    if (i < avail && (s[i] == 'e' || s[i] == 'E')) {
        long j = i + 1;
        if (j < avail && (s[j] == '+' || s[j] == '-'))
            j++;
        if (j < avail && isdigit((unsigned char)s[j])) {
            while (j < avail && isdigit((unsigned char)s[j]))
                j++;
            i = j;
        } else {
            *bad_exp = 1;
            return j;
        }
    }
    return i;
}

int lang_lex(lang_prog *p, char *err, size_t len)
{
    const char *s = p->text;
    const long n = p->text_len;
    long i = 0, line_start = 0;
    int line = 1, depth = 0, cap = 0, space = 1;
    int open_line[LANG_MAX_NEST], open_col[LANG_MAX_NEST];
    char open_ch[LANG_MAX_NEST];

    while (i <= n) {
        token t;
        int c = i < n ? (unsigned char)s[i] : -1;
        memset(&t, 0, sizeof t);
        t.line = line;
        t.col = (int)(i - line_start) + 1;
        t.off = (int32_t)i;
        t.space_before = (uint8_t)space;
        if (c == -1) {
            if (depth > 0) {
                lang_diag_at(p, open_line[depth - 1], open_col[depth - 1],
                             err, len, NULL, "'%c' is never closed",
                             open_ch[depth - 1]);
                return -1;
            }
            t.kind = TK_NL;
            if (push(p, &cap, t) != 0)
                goto nomem;
            t.kind = TK_EOF;
            t.len = 0;
            if (push(p, &cap, t) != 0)
                goto nomem;
            return 0;
        }
        if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
            i++;
            space = 1;
            continue;
        }
        if (c == '#') {
            while (i < n && s[i] != '\n')
                i++;
            continue;
        }
        if (c == '\n') {
            if (depth == 0) {
                t.kind = TK_NL;
                t.len = 1;
                if (push(p, &cap, t) != 0)
                    goto nomem;
            }
            i++;
            line++;
            line_start = i;
            space = 1;
            continue;
        }
        space = 0;
        if (isdigit(c) || (c == '.' && i + 1 < n &&
                           isdigit((unsigned char)s[i + 1]))) {
            char buf[128];
            int bad_exp;
            long l = number_len(s + i, n - i, &bad_exp);
            if (bad_exp) {
                lang_diag_at(p, line, t.col, err, len,
                             "write an exponent as 1.5e3 or 2e-4",
                             "the exponent of this number has no digits");
                return -1;
            }
            if (l >= (long)sizeof buf) {
                lang_diag_at(p, line, t.col, err, len, NULL,
                             "a number longer than %d characters",
                             (int)sizeof buf - 1);
                return -1;
            }
            memcpy(buf, s + i, (size_t)l);
            buf[l] = '\0';
            t.kind = TK_NUM;
            t.num = strtod(buf, NULL);
            t.len = (int32_t)l;
            if (i + l < n && (isalpha((unsigned char)s[i + l]) ||
                              s[i + l] == '_')) {
                lang_diag_at(p, line, t.col + (int)l, err, len,
                             "write a product with '*', as in 2*x",
                             "a name cannot follow a number directly");
                return -1;
            }
            if (!(t.num <= 1.7976931348623157e308)) {
                lang_diag_at(p, line, t.col, err, len, NULL,
                             "the number %s is too large for a double", buf);
                return -1;
            }
            i += l;
        } else if (isalpha(c) || c == '_') {
            long l = 0;
            while (i + l < n && (isalnum((unsigned char)s[i + l]) ||
                                 s[i + l] == '_'))
                l++;
            if (l > LANG_MAX_NAME) {
                lang_diag_at(p, line, t.col, err, len, NULL,
                             "a name longer than %d characters",
                             LANG_MAX_NAME);
                return -1;
            }
            t.kind = TK_ID;
            t.len = (int32_t)l;
            i += l;
        } else if (c == '"') {
            long l = 1;
            while (i + l < n && s[i + l] != '"' && s[i + l] != '\n')
                l++;
            if (i + l >= n || s[i + l] != '"') {
                lang_diag_at(p, line, t.col, err, len,
                             "a description is one line between double "
                             "quotes",
                             "this string is not closed on its line");
                return -1;
            }
            t.kind = TK_STR;
            t.len = (int32_t)(l + 1);
            i += l + 1;
        } else {
            int two = i + 1 < n ? (unsigned char)s[i + 1] : 0;
            t.len = 1;
            switch (c) {
            case '+': t.kind = TK_PLUS; break;
            case '-': t.kind = TK_MINUS; break;
            case '*':
                if (two == '*') {
                    lang_diag_at(p, line, t.col, err, len,
                                 "write a power as x^2", "'**' is not an "
                                 "operator here");
                    return -1;
                }
                t.kind = TK_STAR;
                break;
            case '/': t.kind = TK_SLASH; break;
            case '^': t.kind = TK_CARET; break;
            case ',': t.kind = TK_COMMA; break;
            case '(':
            case '[':
                if (depth >= LANG_MAX_NEST) {
                    lang_diag_at(p, line, t.col, err, len, NULL,
                                 "brackets nest deeper than %d",
                                 LANG_MAX_NEST);
                    return -1;
                }
                open_line[depth] = line;
                open_col[depth] = t.col;
                open_ch[depth++] = (char)c;
                t.kind = c == '(' ? TK_LPAR : TK_LBRK;
                break;
            case ')':
            case ']':
                if (depth == 0 ||
                    open_ch[depth - 1] != (c == ')' ? '(' : '[')) {
                    if (depth == 0)
                        lang_diag_at(p, line, t.col, err, len, NULL,
                                     "'%c' without a matching '%c'", c,
                                     c == ')' ? '(' : '[');
                    else
                        lang_diag_at(p, open_line[depth - 1],
                                     open_col[depth - 1], err, len, NULL,
                                     "'%c' is closed by '%c' on line %d",
                                     open_ch[depth - 1], c, line);
                    return -1;
                }
                depth--;
                t.kind = c == ')' ? TK_RPAR : TK_RBRK;
                break;
            case '=':
                t.kind = two == '=' ? TK_EQ : TK_ASSIGN;
                t.len = two == '=' ? 2 : 1;
                break;
            case '!':
                if (two != '=')
                    goto bad;
                t.kind = TK_NE;
                t.len = 2;
                break;
            case '<':
                t.kind = two == '=' ? TK_LE : TK_LT;
                t.len = two == '=' ? 2 : 1;
                break;
            case '>':
                t.kind = two == '=' ? TK_GE : TK_GT;
                t.len = two == '=' ? 2 : 1;
                break;
            case '.':
                if (isalpha((unsigned char)two) || two == '_') {
                    t.kind = TK_DOT; /* a component: r.x */
                    break;
                }
                if (two != '.')
                    goto bad;
                t.kind = TK_DOTDOT;
                t.len = 2;
                break;
            default:
            bad:
                if (c >= 0x20 && c < 0x7f)
                    lang_diag_at(p, line, t.col, err, len, NULL,
                                 "unexpected character '%c'", c);
                else
                    lang_diag_at(p, line, t.col, err, len,
                                 "outside comments and descriptions a "
                                 "model file is plain ASCII",
                                 "unexpected byte 0x%02x", (unsigned)c);
                return -1;
            }
            i += t.len;
        }
        if (push(p, &cap, t) != 0)
            goto nomem;
    }
    return 0;
nomem:
    snprintf(err, len, "%s: out of memory while reading the file",
             p->path ? p->path : "<string>");
    return -1;
}
