/* numtext.h - numbers as text for eom-run: strict parsing of command-line
 * values (the whole string must be one finite number, nothing before or
 * after it) and the shortest decimal form that reads back to the same
 * double, used for the CSV and for --describe. */
#ifndef APPS_NUMTEXT_H
#define APPS_NUMTEXT_H

#include <stddef.h>

/* Why a string is not accepted as a number. */
enum {
    NUMTEXT_OK = 0,
    NUMTEXT_EMPTY,      /* "" */
    NUMTEXT_NOT_NUMBER, /* does not start with a number (or starts with
                           white space) */
    NUMTEXT_TRAILING,   /* a number followed by other characters */
    NUMTEXT_NONFINITE,  /* inf or nan */
    NUMTEXT_RANGE,      /* too large for a double, or for a long */
    NUMTEXT_NOT_INTEGER /* numtext_parse_long: a fraction or exponent */
};

/* A short phrase for a NUMTEXT_* code ("is not a number", ...). */
const char *numtext_error(int code);

/* Parse all of s (borrowed) as a finite double into *out; returns a
 * NUMTEXT_* code and leaves *out alone on failure. Decimal and hexadecimal
 * floating forms as strtod reads them; a value too small for a double
 * reads as 0 or a subnormal. */
int numtext_parse_double(const char *s, double *out);

/* Parse all of s as a decimal integer (optional sign, digits only). */
int numtext_parse_long(const char *s, long *out);

/* The shortest of %.15g, %.16g and %.17g that reads back as exactly v;
 * "nan", "inf" or "-inf" for non-finite values. buf needs 32 bytes. */
void numtext_format(char *buf, size_t len, double v);

#endif /* APPS_NUMTEXT_H */
