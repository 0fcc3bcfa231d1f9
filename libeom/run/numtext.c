/* numtext.c - strict number parsing and round-trip formatting (see
 * eom/run.h). strtod alone is too lenient for a command line: it skips
 * leading white space, stops quietly at junk and accepts "inf". */
#include "eom/run.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

const char *eom_numtext_error(int code)
{
    switch (code) {
    case EOM_NUMTEXT_OK: return "is a number";
    case EOM_NUMTEXT_EMPTY: return "is empty";
    case EOM_NUMTEXT_NOT_NUMBER: return "is not a number";
    case EOM_NUMTEXT_TRAILING:
        return "has trailing characters after the number";
    case EOM_NUMTEXT_NONFINITE: return "is not finite";
    case EOM_NUMTEXT_RANGE: return "is out of range";
    case EOM_NUMTEXT_NOT_INTEGER: return "is not an integer";
    default: return "is malformed";
    }
}

int eom_numtext_parse_double(const char *s, double *out)
{
    char *end;
    double v;
    if (!s || !*s)
        return EOM_NUMTEXT_EMPTY;
    if (isspace((unsigned char)*s))
        return EOM_NUMTEXT_NOT_NUMBER;
    errno = 0;
    v = strtod(s, &end);
    if (end == s)
        return EOM_NUMTEXT_NOT_NUMBER;
    if (*end)
        return EOM_NUMTEXT_TRAILING;
    if (isnan(v))
        return EOM_NUMTEXT_NONFINITE;
    if (isinf(v))
        /* "inf" typed out, or a literal beyond DBL_MAX (ERANGE) */
        return errno == ERANGE ? EOM_NUMTEXT_RANGE : EOM_NUMTEXT_NONFINITE;
    *out = v;
    return EOM_NUMTEXT_OK;
}

int eom_numtext_parse_long(const char *s, long *out)
{
    const char *p = s;
    char *end;
    long v;
    if (!s || !*s)
        return EOM_NUMTEXT_EMPTY;
    if (*p == '+' || *p == '-')
        p++;
    if (!isdigit((unsigned char)*p))
        return EOM_NUMTEXT_NOT_NUMBER;
    errno = 0;
    v = strtol(s, &end, 10);
    if (*end == '.' || *end == 'e' || *end == 'E')
        return EOM_NUMTEXT_NOT_INTEGER;
    if (*end)
        return EOM_NUMTEXT_TRAILING;
    if (errno == ERANGE)
        return EOM_NUMTEXT_RANGE;
    *out = v;
    return EOM_NUMTEXT_OK;
}

void eom_numtext_format(char *buf, size_t len, double v)
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
