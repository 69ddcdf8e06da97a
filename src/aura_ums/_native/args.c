/*
 * Argument parsing and checked sizes shared by the kernels: every number, count and
 * buffer a kernel reads from Python is checked here before any buffer is sized from it.
 */
#include "kernels.h"

Py_ssize_t checked_add(Py_ssize_t a, Py_ssize_t b) { return a > PY_SSIZE_T_MAX - b ? -1 : a + b; }

Py_ssize_t checked_multiply(Py_ssize_t a, Py_ssize_t b) {
    if (a == 0 || b == 0) return 0;
    return a > PY_SSIZE_T_MAX / b ? -1 : a * b;
}

int parse_doubles(PyObject *const *args, Py_ssize_t count, const char *const *names, double *values) {
    for (Py_ssize_t i = 0; i < count; i++) {
        values[i] = PyFloat_AsDouble(args[i]);
        if (values[i] == -1.0 && PyErr_Occurred()) {
            PyErr_Clear();
            PyErr_Format(PyExc_TypeError, "%s: expected a real number, got %.200s", names[i],
                         Py_TYPE(args[i])->tp_name);
            return -1;
        }
        /* Only the outer range may be unbounded (+inf: a Class I cone). */
        int unbounded = strcmp(names[i], "range_max") == 0;
        if (!isfinite(values[i]) && !(unbounded && values[i] == HUGE_VAL)) {
            PyErr_Format(PyExc_ValueError, "%s: expected a finite number%s, got %R", names[i],
                         unbounded ? " or inf" : "", args[i]);
            return -1;
        }
    }
    return 0;
}

int parse_cap(PyObject *arg, Py_ssize_t *max_vertices) {
    *max_vertices = PyNumber_AsSsize_t(arg, PyExc_OverflowError);
    if (*max_vertices == -1 && PyErr_Occurred()) return -1;
    if (*max_vertices < 3) {
        PyErr_Format(PyExc_ValueError, "max_vertices: expected at least 3, got %zd", *max_vertices);
        return -1;
    }
    return 0;
}

int parse_count(PyObject *arg, const char *name, Py_ssize_t low, Py_ssize_t high, Py_ssize_t *value) {
    *value = PyNumber_AsSsize_t(arg, PyExc_OverflowError);
    if (*value == -1 && PyErr_Occurred()) return -1;
    if (*value < low || *value > high) {
        PyErr_Format(PyExc_ValueError, "%s: expected an integer in [%zd, %zd], got %zd", name, low, high, *value);
        return -1;
    }
    return 0;
}

static int is_float64_format(const char *format) {
    if (format == NULL) return 0; /* unsigned bytes */
    if (*format == '@' || *format == '=' || (PY_LITTLE_ENDIAN && *format == '<') ||
        (!PY_LITTLE_ENDIAN && (*format == '>' || *format == '!')))
        format++;
    return strcmp(format, "d") == 0;
}

/* See kernels.h. */
int get_vertices(PyObject *object, Py_buffer *view, Py_ssize_t *n) {
    static const char *expected = "vertices: expected a C-contiguous (n, 2) float64 buffer";
    if (PyObject_GetBuffer(object, view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        PyErr_Clear();
        if (PyObject_CheckBuffer(object))
            PyErr_Format(PyExc_ValueError, "%s, got a non-contiguous %.200s", expected, Py_TYPE(object)->tp_name);
        else
            PyErr_Format(PyExc_TypeError, "%s, got %.200s", expected, Py_TYPE(object)->tp_name);
        return -1;
    }
    const char *problem = NULL;
    if (view->itemsize != (Py_ssize_t)sizeof(double) || !is_float64_format(view->format))
        problem = "format";
    else if (view->ndim > 2 || (view->ndim == 2 && view->shape[1] != 2))
        problem = "shape";
    else if (view->len < (Py_ssize_t)(2 * sizeof(double)) || view->len % (Py_ssize_t)(2 * sizeof(double)) != 0)
        problem = "length";
    if (problem == NULL) {
        *n = view->len / (Py_ssize_t)(2 * sizeof(double));
        /* Only finite coordinates: NaN would make comparisons (and sorts) inconsistent. */
        const double *v = (const double *)view->buf;
        for (Py_ssize_t i = 0; i < 2 * *n; i++) {
            if (!isfinite(v[i])) {
                PyObject *value = PyFloat_FromDouble(v[i]);
                if (value) {
                    PyErr_Format(PyExc_ValueError, "vertices: expected finite coordinates, got %R in row %zd",
                                 value, i / 2);
                    Py_DECREF(value);
                }
                PyBuffer_Release(view);
                return -1;
            }
        }
        return 0;
    }
    if (problem[0] == 'f')
        PyErr_Format(PyExc_ValueError, "%s, got format '%s' with %zd-byte items", expected,
                     view->format ? view->format : "B", view->itemsize);
    else if (problem[0] == 's')
        PyErr_Format(PyExc_ValueError, "%s, got %d dimensions with %zd in the last", expected, view->ndim,
                     view->shape[view->ndim - 1]);
    else
        PyErr_Format(PyExc_ValueError, "%s, got %zd bytes", expected, view->len);
    PyBuffer_Release(view);
    return -1;
}

