/* numtext.c - strict number parsing and round-trip formatting (see
 * numtext.h). strtod alone is too lenient for a command line: it skips
 * leading white space, stops quietly at junk and accepts "inf". */
#include "numtext.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

const char *numtext_error(int code)
{
    switch (code) {
    case NUMTEXT_OK: return "is a number";
    case NUMTEXT_EMPTY: return "is empty";
    case NUMTEXT_NOT_NUMBER: return "is not a number";
    case NUMTEXT_TRAILING: return "has trailing characters after the number";
    case NUMTEXT_NONFINITE: return "is not finite";
    case NUMTEXT_RANGE: return "is out of range";
    case NUMTEXT_NOT_INTEGER: return "is not an integer";
    default: return "is malformed";
    }
}

int numtext_parse_double(const char *s, double *out)
{
    char *end;
    double v;
    if (!s || !*s)
        return NUMTEXT_EMPTY;
    if (isspace((unsigned char)*s))
        return NUMTEXT_NOT_NUMBER;
    errno = 0;
    v = strtod(s, &end);
    if (end == s)
        return NUMTEXT_NOT_NUMBER;
    if (*end)
        return NUMTEXT_TRAILING;
    if (isnan(v))
        return NUMTEXT_NONFINITE;
    if (isinf(v))
        /* "inf" typed out, or a literal beyond DBL_MAX (ERANGE) */
        return errno == ERANGE ? NUMTEXT_RANGE : NUMTEXT_NONFINITE;
    *out = v;
    return NUMTEXT_OK;
}

int numtext_parse_long(const char *s, long *out)
{
    const char *p = s;
    char *end;
    long v;
    if (!s || !*s)
        return NUMTEXT_EMPTY;
    if (*p == '+' || *p == '-')
        p++;
    if (!isdigit((unsigned char)*p))
        return NUMTEXT_NOT_NUMBER;
    errno = 0;
    v = strtol(s, &end, 10);
    if (*end == '.' || *end == 'e' || *end == 'E')
        return NUMTEXT_NOT_INTEGER;
    if (*end)
        return NUMTEXT_TRAILING;
    if (errno == ERANGE)
        return NUMTEXT_RANGE;
    *out = v;
    return NUMTEXT_OK;
}

void numtext_format(char *buf, size_t len, double v)
{
    int digits;
    if (isnan(v)) {
        /* never "-nan": the sign of a NaN carries no meaning here */
        snprintf(buf, len, "nan");
        return;
    }
    if (isinf(v)) {
        snprintf(buf, len, v > 0 ? "inf" : "-inf");
        return;
    }
    for (digits = 15; digits < 17; digits++) {
        snprintf(buf, len, "%.*g", digits, v);
        if (strtod(buf, NULL) == v)
            return;
    }
    snprintf(buf, len, "%.17g", v);
}
