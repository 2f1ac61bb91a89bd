/* rt/number.h - strict decimal numbers, the one syntax of the scene format
 * and the command line.
 *
 * The whole string must be the number: `1.0x`, ` 5`, `0x10`, `nan` and `inf`
 * are not numbers. Integers are [+-]digits; floats are
 * [+-]digits[.digits][(e|E)[+-]digits] with at least one mantissa digit.
 * A number that is well formed but does not fit is RT_NUMBER_RANGE, so the
 * caller can say "out of range" rather than "not a number".
 *
 *   long long n;
 *   if (rt_parse_int(word, &n) != RT_NUMBER_OK || n < 1 || n > 1024) ... refuse ...
 *   float f;
 *   switch (rt_parse_float(word, &f)) { case RT_NUMBER_BAD: ... case RT_NUMBER_RANGE: ... case RT_NUMBER_OK: ... }
 */
#ifndef RT_NUMBER_H
#define RT_NUMBER_H

typedef enum rt_number_status {
    RT_NUMBER_BAD = 0, /* not a number of this kind */
    RT_NUMBER_OK,
    RT_NUMBER_RANGE, /* well formed, but beyond long long / float range (or not finite) */
} rt_number_status;

/* [+-]digits, within long long. */
rt_number_status rt_parse_int(const char *s, long long *out);
/* A decimal float, finite and within float range (about +-3.4e38). */
rt_number_status rt_parse_float(const char *s, float *out);
/* The same syntax at double precision (thresholds compared with doubles). */
rt_number_status rt_parse_double(const char *s, double *out);

#endif
