/*
 * Compiled kernel of the find-landmark schemas' activation test: the distance between a
 * convex polygon (a point or a segment when degenerate) and a segment (a point when both
 * ends agree). Its reference is shapely's distance (_distance.polygon_distance_reference
 * beside this file). And whether one point lies in a solid convex polygon, the dense test of
 * geometry's points_in_convex (_distance.point_in_solid_convex_reference), operation for
 * operation: a reduced map's centre is tested so, often many times a frame.
 */
#include "kernels.h"

/* Distance from the point p to the segment [a, b] (a point when a == b). */
static double point_to_segment(double px, double py, double ax, double ay, double bx, double by) {
    double ex = bx - ax, ey = by - ay, rx = px - ax, ry = py - ay;
    double t = segment_parameter(rx, ry, ex, ey);
    return hypot(rx - t * ex, ry - t * ey);
}

/* Distance between the segments [a, b] and [c, d]: 0 when they cross. */
static double segment_to_segment(double ax, double ay, double bx, double by, double cx, double cy, double dx,
                                 double dy) {
    double o1 = cross(bx - ax, by - ay, cx - ax, cy - ay), o2 = cross(bx - ax, by - ay, dx - ax, dy - ay);
    double o3 = cross(dx - cx, dy - cy, ax - cx, ay - cy), o4 = cross(dx - cx, dy - cy, bx - cx, by - cy);
    if (((o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0)) && ((o3 > 0.0 && o4 < 0.0) || (o3 < 0.0 && o4 > 0.0)))
        return 0.0;
    double best = point_to_segment(ax, ay, cx, cy, dx, dy);
    best = lesser(best, point_to_segment(bx, by, cx, cy, dx, dy));
    best = lesser(best, point_to_segment(cx, cy, ax, ay, bx, by));
    return lesser(best, point_to_segment(dx, dy, ax, ay, bx, by));
}

static int inside_convex(const double *v, Py_ssize_t n, double x, double y) {
    for (Py_ssize_t i = 0; i < n; i++) {
        Py_ssize_t j = i + 1 < n ? i + 1 : 0;
        if (cross(v[2 * j] - v[2 * i], v[2 * j + 1] - v[2 * i + 1], x - v[2 * i], y - v[2 * i + 1]) < 0.0) return 0;
    }
    return 1;
}

PyObject *polygon_distance(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    (void)self;
    static const char *const names[] = {"ax", "ay", "bx", "by"};
    double a[4];
    Py_ssize_t n;
    if (nargs != 5) {
        PyErr_Format(PyExc_TypeError, "polygon_distance: expected 5 arguments, got %zd", nargs);
        return NULL;
    }
    if (parse_doubles(args + 1, 4, names, a) < 0) return NULL;
    Py_buffer view;
    if (get_vertices(args[0], &view, &n) < 0) return NULL;
    const double *v = (const double *)view.buf;
    double best;
    if (n >= 3 && polygon_area(v, n) > 0.0 &&
        (inside_convex(v, n, a[0], a[1]) || inside_convex(v, n, a[2], a[3]))) {
        best = 0.0;
    } else if (n == 1) {
        best = point_to_segment(v[0], v[1], a[0], a[1], a[2], a[3]);
    } else {
        best = HUGE_VAL;
        Py_ssize_t edges = n == 2 ? 1 : n;
        for (Py_ssize_t i = 0; i < edges && best > 0.0; i++) {
            Py_ssize_t j = i + 1 < n ? i + 1 : 0;
            best = lesser(best, segment_to_segment(a[0], a[1], a[2], a[3], v[2 * i], v[2 * i + 1], v[2 * j],
                                                   v[2 * j + 1]));
        }
    }
    PyBuffer_Release(&view);
    return PyFloat_FromDouble(best);
}

PyObject *point_in_solid_convex(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    (void)self;
    static const char *const names[] = {"x", "y", "tolerance"};
    double a[3];
    Py_ssize_t n;
    if (nargs != 4) {
        PyErr_Format(PyExc_TypeError, "point_in_solid_convex: expected 4 arguments, got %zd", nargs);
        return NULL;
    }
    if (parse_doubles(args + 1, 3, names, a) < 0) return NULL;
    Py_buffer view;
    if (get_vertices(args[0], &view, &n) < 0) return NULL;
    if (n < 3) {
        PyBuffer_Release(&view);
        PyErr_Format(PyExc_ValueError, "vertices: expected a solid polygon of at least 3 vertices, got %zd", n);
        return NULL;
    }
    const double *v = (const double *)view.buf;
    /* The reference's np.hypot of each edge, then its signed distances: the same operations. */
    int inside = 1;
    for (Py_ssize_t i = 0; i < n && inside; i++) {
        Py_ssize_t j = i + 1 < n ? i + 1 : 0;
        double ex = v[2 * j] - v[2 * i], ey = v[2 * j + 1] - v[2 * i + 1];
        double signed_distance = (ex * (a[1] - v[2 * i + 1]) - ey * (a[0] - v[2 * i])) / hypot(ex, ey);
        inside = signed_distance >= -a[2];
    }
    PyBuffer_Release(&view);
    return PyBool_FromLong(inside);
}
