/*
 * Compiled merging of heading slices (_slices.merge_groups_reference, operation for
 * operation): for each group of points -- the vertices of the polygons that meet one
 * heading cell, or of neighbouring slices merged under the slice cap -- the convex hull,
 * then the outer vertex cap. One call for every group of a growth's redistribution.
 */
#include "kernels.h"

PyObject *merge_groups(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    (void)self;
    if (nargs != 3) {
        PyErr_Format(PyExc_TypeError, "merge_groups: expected 3 arguments, got %zd", nargs);
        return NULL;
    }
    Py_ssize_t max_vertices, n;
    if (parse_cap(args[2], &max_vertices) < 0) return NULL;
    PyObject *counts = PySequence_Fast(args[1], "counts: expected a sequence of integers");
    if (!counts) return NULL;
    Py_buffer view;
    if (get_vertices(args[0], &view, &n) < 0) {
        Py_DECREF(counts);
        return NULL;
    }
    Py_ssize_t groups = PySequence_Fast_GET_SIZE(counts);
    PyObject *const *items = PySequence_Fast_ITEMS(counts);
    PyObject *result = NULL;
    Py_ssize_t *sizes = PyMem_Malloc(sizeof(Py_ssize_t) * (size_t)(groups > 0 ? groups : 1));
    double *t = NULL, *scratch_points = NULL;
    Ranked *ranked = NULL;
    char *flags = NULL;
    Work w;
    memset(&w, 0, sizeof(w));
    Poly hull = {0};
    if (!sizes) {
        PyErr_NoMemory();
        goto done;
    }
    /* Every count at least 1, and together exactly the rows given: no group reads past them. */
    Py_ssize_t total = 0, largest = 0;
    for (Py_ssize_t g = 0; g < groups; g++) {
        if (parse_count(items[g], "counts[i]", 1, n, &sizes[g]) < 0) goto done;
        total = checked_add(total, sizes[g]);
        if (total < 0 || total > n) break;
        if (sizes[g] > largest) largest = sizes[g];
    }
    if (total != n) {
        PyErr_Format(PyExc_ValueError, "counts: expected group sizes adding up to the %zd rows, got %zd groups "
                                       "that do not", n, groups);
        goto done;
    }
    /* simplify_outer's buffers, for the largest hull (at most the largest group). */
    size_t room = (size_t)(largest > 3 ? largest : 3);
    t = PyMem_Malloc(sizeof(double) * room);
    scratch_points = PyMem_Malloc(sizeof(double) * 2 * room);
    ranked = PyMem_Malloc(sizeof(Ranked) * room);
    flags = PyMem_Malloc(2 * room);
    if (!t || !scratch_points || !ranked || !flags) {
        PyErr_NoMemory();
        goto done;
    }
    result = PyTuple_New(groups);
    if (!result) goto done;
    const double *points = (const double *)view.buf;
    Py_ssize_t offset = 0;
    for (Py_ssize_t g = 0; g < groups; g++) {
        if (convex_hull(points + 2 * offset, sizes[g], &hull, &w) < 0) {
            Py_CLEAR(result);
            goto done;
        }
        Py_ssize_t m = hull.n;
        if (m > max_vertices) m = simplify_outer(hull.v, m, max_vertices, t, ranked, flags, flags + room, scratch_points);
        PyObject *bytes = PyBytes_FromStringAndSize((const char *)hull.v, (Py_ssize_t)(sizeof(double) * 2) * m);
        if (!bytes) {
            Py_CLEAR(result);
            goto done;
        }
        PyTuple_SET_ITEM(result, g, bytes);
        offset += sizes[g];
    }
done:
    PyMem_Free(hull.v);
    work_free(&w);
    PyMem_Free(t);
    PyMem_Free(scratch_points);
    PyMem_Free(ranked);
    PyMem_Free(flags);
    PyMem_Free(sizes);
    PyBuffer_Release(&view);
    Py_DECREF(counts);
    return result;
}
