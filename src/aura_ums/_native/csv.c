/*
 * Compiled kernel of the numeric CSV reader: the data rows of a block of a large log file
 * (odometry, ground truth), every cell a plain decimal number. Its reference is numpy's
 * loadtxt (_csv.parse_float_rows_reference beside this file). Both give the correctly rounded
 * double of each cell; this one reads only the plain form (sign, digits, point, exponent,
 * blanks around) and gives None for anything else (nan, inf, hex, a cell too long), which the
 * caller then reads the slow, exact way.
 */
#include <float.h>
#include <stdlib.h>

#include "kernels.h"

/* Longest cell read here, bytes: a longer one (thousands of digits) goes the slow way. */
#define LONGEST_CELL 400

static int is_digit(char c) { return c >= '0' && c <= '9'; }

static int is_blank(char c) { return c == ' ' || c == '\t'; }

/* Powers of ten that are exact doubles (10^22 < 2^53 * 2^22 is the last). */
static const double EXACT_TENS[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                    1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                    1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/*
 * The end of the plain decimal number at p (before `end`), or NULL when there is none. In
 * the same pass, *exact tells whether Clinger's fast path gives its correctly rounded double
 * (then in *value): at most 15 significant digits (an integer below 2^53, exact as a double)
 * and a power of ten within 1e22 (exact too), so one multiplication or division, itself
 * correctly rounded, gives the correctly rounded result. Otherwise strtod reads the cell. Logs'
 * cells (0.785398163, 1234.56) take the fast path: about a tenth of strtod's time.
 */
static const char *plain_number(const char *p, const char *end, double *value, int *exact) {
    int negative = 0;
    if (p < end && (*p == '+' || *p == '-')) negative = *p++ == '-';
    unsigned long long mantissa = 0; /* the first 15 significant digits */
    int significant = 0, scale = 0;  /* the number is mantissa * 10^scale */
    Py_ssize_t digits = 0;
    for (; p < end && is_digit(*p); p++, digits++) {
        if (significant == 0 && *p == '0') continue;
        if (significant++ < 15) mantissa = mantissa * 10 + (unsigned long long)(*p - '0');
    }
    if (p < end && *p == '.') {
        p++;
        for (; p < end && is_digit(*p); p++, digits++) {
            if (significant == 0 && *p == '0') {
                scale--;
                continue;
            }
            if (significant++ < 15) {
                mantissa = mantissa * 10 + (unsigned long long)(*p - '0');
                scale--;
            }
        }
    }
    if (digits == 0) return NULL;
    int small_exponent = 1;
    if (p < end && (*p == 'e' || *p == 'E')) {
        p++;
        int negative_exponent = 0;
        if (p < end && (*p == '+' || *p == '-')) negative_exponent = *p++ == '-';
        Py_ssize_t exponent_digits = 0;
        int written = 0;
        for (; p < end && is_digit(*p); p++, exponent_digits++) {
            if (written > 1000) {
                small_exponent = 0; /* thousands of digits or a huge power: the slow way */
                continue;
            }
            written = written * 10 + (*p - '0');
        }
        if (exponent_digits == 0) return NULL;
        scale += negative_exponent ? -written : written;
    }
    *exact = significant <= 15 && small_exponent && (mantissa == 0 || (scale >= -22 && scale <= 22));
#if !defined(FLT_EVAL_METHOD) || FLT_EVAL_METHOD != 0
    *exact = 0; /* arithmetic in a wider type (x87) would round twice: strtod alone is exact there */
#endif
    if (*exact) {
        double result = (double)mantissa;
        if (mantissa != 0) result = scale < 0 ? result / EXACT_TENS[-scale] : result * EXACT_TENS[scale];
        *value = negative ? -result : result;
    }
    return p;
}

PyObject *parse_float_rows(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    (void)self;
    if (nargs != 3) {
        PyErr_Format(PyExc_TypeError, "parse_float_rows expects 3 arguments, got %zd", nargs);
        return NULL;
    }
    Py_ssize_t rows, columns;
    if (parse_count(args[1], "rows", 0, PY_SSIZE_T_MAX / 8, &rows) < 0) return NULL;
    if (parse_count(args[2], "columns", 1, PY_SSIZE_T_MAX / 8, &columns) < 0) return NULL;
    Py_ssize_t cells = checked_multiply(rows, columns);
    Py_ssize_t size = cells < 0 ? -1 : checked_multiply(cells, (Py_ssize_t)sizeof(double));
    if (size < 0) return PyErr_NoMemory();
    Py_buffer view;
    if (PyObject_GetBuffer(args[0], &view, PyBUF_SIMPLE) < 0) return NULL;
    PyObject *result = PyByteArray_FromStringAndSize(NULL, size);
    if (!result) {
        PyBuffer_Release(&view);
        return NULL;
    }
    double *out = (double *)(void *)PyByteArray_AS_STRING(result);
    const char *p = (const char *)view.buf, *end = p + view.len;
    char cell[LONGEST_CELL + 1];
    int plain = 1;
    for (Py_ssize_t row = 0; row < rows && plain; row++) {
        for (Py_ssize_t column = 0; column < columns; column++) {
            while (p < end && is_blank(*p)) p++;
            double fast;
            int exact;
            const char *stop = plain_number(p, end, &fast, &exact);
            if (!stop || stop - p > LONGEST_CELL) {
                plain = 0;
                break;
            }
            if (exact) {
                out[row * columns + column] = fast;
            } else {
                /* strtod on a copy: the block is not NUL-terminated, and the copy's end is known. */
                Py_ssize_t length = stop - p;
                memcpy(cell, p, (size_t)length);
                cell[length] = '\0';
                char *parsed;
                out[row * columns + column] = strtod(cell, &parsed);
                if (parsed != cell + length) { /* a locale whose decimal point is not "." */
                    plain = 0;
                    break;
                }
            }
            p = stop;
            while (p < end && is_blank(*p)) p++;
            char expected = column + 1 < columns ? ',' : '\n';
            if (p < end && *p == expected) {
                p++;
            } else if (!(p == end && column + 1 == columns)) {
                plain = 0;
                break;
            }
        }
    }
    PyBuffer_Release(&view);
    if (!plain || p != end) {
        Py_DECREF(result);
        Py_RETURN_NONE;
    }
    return result;
}
