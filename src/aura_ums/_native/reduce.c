/*
 * Compiled kernels of the three landmark reductions. They mirror, operation for
 * operation, the numpy reference in _reduce.py beside this file (sector_halfplanes,
 * clip_to_sector, sensor_arc, cos_range, cap_inside, the cone and strip reductions and
 * the tail of reduce_cone_reference / reduce_strip_reference), on the polygon primitives
 * of polygon.c. One call runs a whole reduction: from the prior's vertices to the reduced
 * vertices, heading arc, centre and areas. Every buffer's capacity is computed from the
 * sizes of its inputs.
 */
#include "kernels.h"

/* Number of tangents of a sector's outer arc (see _reduce.sector_halfplanes). */
static Py_ssize_t tangent_count(double width) {
    double count = ceil(width / TANGENT_STEP);
    return count > 1.0 ? (Py_ssize_t)count : 1;
}

static void add_plane(double *planes, Py_ssize_t *k, double nx, double ny, double reach, double ax, double ay,
                      double margin) {
    planes[3 * *k] = nx;
    planes[3 * *k + 1] = ny;
    planes[3 * *k + 2] = nx * ax + ny * ay + reach + margin;
    (*k)++;
}

/* See _reduce.sector_halfplanes; `planes` holds 3 + (tangent_count(width) + 1) triples. */
static Py_ssize_t sector_halfplanes(double ax, double ay, double lo, double width, double widen, double r_min,
                                    double r_max, double *planes) {
    double hi = lo + width, middle = lo + width / 2.0, margin = widen + TOLERANCE;
    Py_ssize_t k = 0;
    add_plane(planes, &k, sin(lo), -cos(lo), 0.0, ax, ay, margin);
    add_plane(planes, &k, -sin(hi), cos(hi), 0.0, ax, ay, margin);
    add_plane(planes, &k, -cos(middle), -sin(middle), -r_min * cos(width / 2.0), ax, ay, margin);
    if (isfinite(r_max)) {
        /* np.linspace(lo, hi, count + 1): k * step + lo, the last one exactly hi. */
        Py_ssize_t count = tangent_count(width);
        double step = (hi - lo) / (double)count;
        for (Py_ssize_t j = 0; j <= count; j++) {
            double angle = j == count ? hi : (double)j * step + lo;
            add_plane(planes, &k, cos(angle), sin(angle), r_max, ax, ay, margin);
        }
    }
    return k;
}

/* See _reduce.clip_to_sector; `v` and `out` must not be w->part or w->parts. */
static int clip_to_sector(const double *v, Py_ssize_t n, double ax, double ay, double lo, double width,
                          double widen, double r_min, double r_max, double piece, Poly *out, Work *w) {
    double span = TWO_PI < width ? TWO_PI : width;
    double pieces = ceil(span / piece);
    Py_ssize_t count = pieces > 1.0 ? (Py_ssize_t)pieces : 1;
    double step = span / (double)count;
    double *planes = scratch(&w->planes, 3 * (4 + tangent_count(step)), sizeof(double));
    if (!planes) return -1;
    Py_ssize_t kept = 0;
    w->parts.n = 0;
    for (Py_ssize_t j = 0; j < count; j++) {
        Py_ssize_t k = sector_halfplanes(ax, ay, lo + (double)j * step, step, widen, r_min, r_max, planes);
        if (clip_halfplanes(v, n, planes, k, &w->part, w) < 0) return -1;
        if (w->part.n == 0) continue;
        if (reserve(&w->parts, w->parts.n + w->part.n) < 0) return -1;
        memcpy(w->parts.v + 2 * w->parts.n, w->part.v, 2 * sizeof(double) * (size_t)w->part.n);
        w->parts.n += w->part.n;
        kept++;
    }
    if (kept == 0) {
        out->n = 0;
        return 0;
    }
    if (kept == 1) return copy_into(out, w->parts.v, w->parts.n);
    return convex_hull(w->parts.v, w->parts.n, out, w);
}

/* See _reduce.sensor_arc: 0 when the sensor is at the reference point, 1 with the polygon
   in `out`, -1 on error. */
static int sensor_arc(double forward, double left, double lo, double width, Poly *out, Work *w) {
    double radius = hypot(forward, left);
    if (radius == 0.0) return 0;
    lo += atan2(left, forward);
    if (width >= TWO_PI) {
        if (reserve(out, SENSOR_ARC_SIDES) < 0) return -1;
        out->n = outer_disk(radius, SENSOR_ARC_SIDES, out->v);
        return 1;
    }
    if (width <= 0.0) {
        if (reserve(out, 1) < 0) return -1;
        out->v[0] = radius * cos(lo);
        out->v[1] = radius * sin(lo);
        out->n = 1;
        return 1;
    }
    double stop = lo + width;
    if (reserve(&w->arc_points, arc_pieces(stop - lo, ARC_STEP) + 2) < 0) return -1;
    w->arc_points.n = outer_arc(radius, lo, stop, w->arc_points.v);
    return convex_hull(w->arc_points.v, w->arc_points.n, out, w) < 0 ? -1 : 1;
}

/* See _reduce.cos_range. */
static void cos_range(double lo, double width, double *lowest, double *highest) {
    if (width >= TWO_PI) {
        *lowest = -1.0;
        *highest = 1.0;
        return;
    }
    double a = cos(lo), b = cos(lo + width);
    *highest = floor_mod(-lo, TWO_PI) <= width ? 1.0 : greater(a, b);
    *lowest = floor_mod(M_PI - lo, TWO_PI) <= width ? -1.0 : lesser(a, b);
}

/* See _reduce.cap_inside; works in place. -1 with MemoryError set on failure. */
static int cap_inside(Poly *p, const double *prior, Py_ssize_t prior_n, Py_ssize_t max_vertices) {
    Py_ssize_t floor_count = max_vertices > 3 ? max_vertices : 3;
    if (p->n <= floor_count) return 0;
    double *lengths = NULL;
    if (prior_n >= 3 && polygon_area(prior, prior_n) > 0.0) {
        lengths = PyMem_Malloc(sizeof(double) * (size_t)prior_n);
        if (!lengths) {
            PyErr_NoMemory();
            return -1;
        }
        for (Py_ssize_t i = 0; i < prior_n; i++) {
            Py_ssize_t j = i + 1 < prior_n ? i + 1 : 0;
            lengths[i] = hypot(prior[2 * j] - prior[2 * i], prior[2 * j + 1] - prior[2 * i + 1]);
        }
    }
    while (p->n > floor_count) {
        Py_ssize_t n = p->n, best = 0;
        double *v = p->v, best_cost = HUGE_VAL, best_x = 0.0, best_y = 0.0;
        int any = 0;
        for (Py_ssize_t i = 0; i < n; i++) {
            Py_ssize_t prev = i > 0 ? i - 1 : n - 1, next = i + 1 < n ? i + 1 : 0;
            Py_ssize_t after = next + 1 < n ? next + 1 : 0;
            double px = v[2 * i] - v[2 * prev], py = v[2 * i + 1] - v[2 * prev + 1];
            double ex = v[2 * next] - v[2 * i], ey = v[2 * next + 1] - v[2 * i + 1];
            double fx = v[2 * after] - v[2 * next], fy = v[2 * after + 1] - v[2 * next + 1];
            double denominator = px * fy - py * fx;
            int removable = denominator > 1e-12 * hypot(px, py) * hypot(fx, fy);
            double t = removable ? (ex * fy - ey * fx) / denominator : 0.0;
            double x = v[2 * i] + t * px, y = v[2 * i + 1] + t * py;
            removable = removable && point_in_convex(prior, prior_n, lengths, x, y, TOLERANCE);
            double cost = removable ? 0.5 * t * (px * ey - py * ex) : HUGE_VAL;
            any |= removable;
            /* np.argmin: the first of the cheapest. */
            if (i == 0 || cost < best_cost) {
                best = i;
                best_cost = cost;
                best_x = x;
                best_y = y;
            }
        }
        if (!any) break;
        v[2 * best] = best_x;
        v[2 * best + 1] = best_y;
        Py_ssize_t gone = best + 1 < n ? best + 1 : 0;
        memmove(v + 2 * gone, v + 2 * gone + 2, 2 * sizeof(double) * (size_t)(n - gone - 1));
        p->n = n - 1;
    }
    PyMem_Free(lengths);
    return 0;
}

/* The bearing-cone constraint of _reduce._cone_reduction on one polygon. */
typedef struct {
    double landmark_x, landmark_y, widen, cone_lo, cone_width, r_min, r_max, piece;
} Cone;

static int constrain(const Cone *cone, const double *v, Py_ssize_t n, Poly *out, Work *w) {
    if (cone->cone_width >= TWO_PI && !isfinite(cone->r_max)) return copy_into(out, v, n);
    return clip_to_sector(v, n, cone->landmark_x, cone->landmark_y, cone->cone_lo, cone->cone_width, cone->widen,
                          cone->r_min, cone->r_max, cone->piece, out, w);
}

/* See _reduce._cone_reduction (with _sensor_constrained and _bearing_headings). Returns -1 on
   error, else 0 with *reason -1 and the positions in *positions, or *reason a code. */
static int cone_reduction(const double *prior, Py_ssize_t n, double heading_lo, double heading_width,
                          double forward, double left, double bearing, double error, const Cone *cone, Work *w,
                          int *reason, Poly **positions, double *arc_lo, double *arc_width) {
    int has_arc = sensor_arc(forward, left, heading_lo, heading_width, &w->arc, w);
    if (has_arc < 0) return -1;
    Poly *sensors;
    if (!has_arc) {
        if (constrain(cone, prior, n, &w->sensors, w) < 0) return -1;
        if (w->sensors.n == 0) {
            *reason = NO_POSITION;
            return 0;
        }
        *positions = sensors = &w->sensors;
    } else {
        if (minkowski_pair(prior, n, w->arc.v, w->arc.n, &w->sum, w) < 0) return -1;
        if (constrain(cone, w->sum.v, w->sum.n, &w->sensors, w) < 0) return -1;
        if (w->sensors.n == 0) {
            *reason = NO_SENSOR_POSITION;
            return 0;
        }
        /* p = s - R(h) o: an outer bound is the sensor region summed with the mirrored arc. */
        if (reserve(&w->mirrored, w->arc.n) < 0) return -1;
        for (Py_ssize_t i = 0; i < 2 * w->arc.n; i++) w->mirrored.v[i] = -w->arc.v[i];
        w->mirrored.n = w->arc.n;
        if (minkowski_pair(w->sensors.v, w->sensors.n, w->mirrored.v, w->mirrored.n, &w->sum, w) < 0) return -1;
        if (clip_convex(prior, n, w->sum.v, w->sum.n, TOLERANCE, &w->positions, w) < 0) return -1;
        if (w->positions.n == 0) {
            *reason = NO_POSITION;
            return 0;
        }
        *positions = &w->positions;
        /* Sensors must also be reachable from the remaining positions. */
        if (minkowski_pair(w->positions.v, w->positions.n, w->arc.v, w->arc.n, &w->sum, w) < 0) return -1;
        if (clip_convex(w->sensors.v, w->sensors.n, w->sum.v, w->sum.n, TOLERANCE, &w->narrowed, w) < 0) return -1;
        sensors = w->narrowed.n ? &w->narrowed : &w->sensors;
    }
    double seen_lo, seen_width;
    subtended_arc(sensors->v, sensors->n, cone->landmark_x, cone->landmark_y, cone->widen, &seen_lo, &seen_width);
    if (seen_width >= TWO_PI) {
        seen_width = TWO_PI;
    } else {
        /* Directions from the sensors towards the landmark are those from it, turned by pi. */
        double margin = error + TOLERANCE;
        seen_lo = seen_lo + M_PI - bearing - margin;
        seen_width = seen_width + 2.0 * margin;
    }
    if (!intersect_arcs(heading_lo, heading_width, seen_lo, seen_width, arc_lo, arc_width)) {
        *reason = NO_BEARING_HEADING;
        return 0;
    }
    *reason = -1;
    return 0;
}

/* See _reduce.reduce_ground_line. */
static int strip_reduction(const double *prior, Py_ssize_t n, double heading_lo, double heading_width,
                           double forward, double left, double start_x, double start_y, double end_x, double end_y,
                           double uncertainty, double offset, double offset_error, double angle, double angle_error,
                           Poly *out, Work *w, int *reason, double *arc_lo, double *arc_width) {
    double direction = atan2(end_y - start_y, end_x - start_x);
    /* angle = direction - heading, so the heading is direction - angle. */
    double margin = angle_error + TOLERANCE;
    if (!intersect_arcs(heading_lo, heading_width, direction - angle - margin, 0.0 + 2.0 * margin, arc_lo,
                        arc_width)) {
        *reason = NO_LINE_HEADING;
        return 0;
    }
    double nx = -sin(direction), ny = cos(direction);
    double base = nx * start_x + ny * start_y;
    double spread = offset_error + uncertainty;
    double lo = base + offset - spread, hi = base + offset + spread;
    double radius = hypot(forward, left);
    if (radius > 0.0) {
        /* normal . R(h) o = |o| cos(h + atan2(left, forward) - direction - pi/2). */
        double shift = atan2(left, forward) - direction - M_PI / 2.0, lowest, highest;
        cos_range(*arc_lo + shift, *arc_width, &lowest, &highest);
        lo -= radius * highest;
        hi -= radius * lowest;
    }
    double planes[6] = {nx, ny, hi + TOLERANCE, -nx, -ny, -lo + TOLERANCE};
    if (clip_halfplanes(prior, n, planes, 2, out, w) < 0) return -1;
    *reason = out->n ? -1 : NO_OFFSET_POSITION;
    return 0;
}

/* --- results -------------------------------------------------------------------------- */

/* The tail of _reduce.reduce_cone_reference and reduce_strip_reference: the vertex cap, the
   centre update and both areas; returns
   (vertex bytes, arc lo, arc width, centre x, centre y, area before, area after). */
/* A reduction's tail: the positions capped to max_vertices inside the prior (n vertices), and
   the centre (x, y) moved to the nearest point of them. -1 with an exception set. */
static int capped(Poly *positions, const double *prior, Py_ssize_t n, Py_ssize_t max_vertices, double center_x,
                  double center_y, double *x, double *y) {
    if (positions->n > max_vertices) {
        if (cap_inside(positions, prior, n, max_vertices) < 0) return -1;
        /* Merging stopped above max(max_vertices, n) (rounding can block the undoing of a
           cut): the prior, which holds the positions, is the outer bound with few enough. */
        if (positions->n > max_vertices && positions->n > n && copy_into(positions, prior, n) < 0) return -1;
    }
    double distance;
    nearest_on_polygon(positions->v, positions->n, center_x, center_y, &distance, x, y);
    return 0;
}

static PyObject *finish(Poly *positions, const double *prior, Py_ssize_t n, Py_ssize_t max_vertices,
                        double center_x, double center_y, double arc_lo, double arc_width) {
    double x, y;
    if (capped(positions, prior, n, max_vertices, center_x, center_y, &x, &y) < 0) return NULL;
    double values[6] = {arc_lo, arc_width, x, y, polygon_area(prior, n), polygon_area(positions->v, positions->n)};
    PyObject *result = PyTuple_New(7);
    if (!result) return NULL;
    PyObject *raw = PyBytes_FromStringAndSize((const char *)positions->v,
                                              (Py_ssize_t)(2 * sizeof(double) * (size_t)positions->n));
    if (!raw) {
        Py_DECREF(result);
        return NULL;
    }
    PyTuple_SET_ITEM(result, 0, raw);
    for (int k = 0; k < 6; k++) {
        PyObject *value = PyFloat_FromDouble(values[k]);
        if (!value) {
            Py_DECREF(result);
            return NULL;
        }
        PyTuple_SET_ITEM(result, k + 1, value);
    }
    return result;
}

/* Heading arc (lo, width) of a wedge: see _reduce.wedge_arc. */
static void wedge_arc(double center, double cw, double ccw, double *lo, double *width) {
    double sum = cw + ccw;
    *lo = center - cw;
    *width = TWO_PI < sum ? TWO_PI : sum;
}

/* A cone's piece angle, `given` for the message: positive, at most a million pieces (each
   costs a clip). -1 with ValueError set. */
static int check_piece(double piece, PyObject *given) {
    if (!(piece > 0.0) || TWO_PI / piece > 1e6) {
        PyErr_Format(PyExc_ValueError, "piece: expected a positive angle of at least 2 pi / 1e6, got %R", given);
        return -1;
    }
    return 0;
}

/* cone_reduction of the prior over the heading arc by one observation: c holds forward, left,
   landmark x and y, widen, bearing, bearing error, range min and max, and piece. */
static int cone_step(const double *prior, Py_ssize_t n, double heading_lo, double heading_width, const double *c,
                     Work *w, int *reason, Poly **positions, double *arc_lo, double *arc_width) {
    /* The landmark is seen towards h + bearing, so the sensor lies from the landmark
       towards h + bearing + pi, for some heading h of the wedge and bearing error. */
    double margin = c[6] + TOLERANCE;
    Cone cone = {c[2], c[3], c[4], heading_lo + c[5] + M_PI - margin, heading_width + 2.0 * margin,
                 c[7], c[8], c[9]};
    return cone_reduction(prior, n, heading_lo, heading_width, c[0], c[1], c[5], c[6], &cone, w, reason, positions,
                          arc_lo, arc_width);
}

PyObject *reduce_cone(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    static const char *const names[] = {"center_x", "center_y",   "wedge_center", "wedge_cw", "wedge_ccw",
                                        "forward",  "left",       "landmark_x",   "landmark_y", "widen",
                                        "bearing",  "bearing_error", "range_min",  "range_max", "piece"};
    enum { DOUBLES = sizeof(names) / sizeof(names[0]) };
    double a[DOUBLES];
    if (nargs != DOUBLES + 2) {
        PyErr_Format(PyExc_TypeError, "reduce_cone: expected %d arguments, got %zd", DOUBLES + 2, nargs);
        return NULL;
    }
    Py_ssize_t max_vertices, n;
    if (parse_doubles(args + 1, DOUBLES, names, a) < 0 || parse_cap(args[DOUBLES + 1], &max_vertices) < 0)
        return NULL;
    if (check_piece(a[14], args[15]) < 0) return NULL;
    Py_buffer view;
    if (get_vertices(args[0], &view, &n) < 0) return NULL;
    const double *prior = (const double *)view.buf;
    Work local_work, *w = work_take(self, &local_work);
    PyObject *result = NULL;
    double heading_lo, heading_width, arc_lo = 0.0, arc_width = 0.0;
    wedge_arc(a[2], a[3], a[4], &heading_lo, &heading_width);
    int reason = -1;
    Poly *positions = NULL;
    if (cone_step(prior, n, heading_lo, heading_width, a + 5, w, &reason, &positions, &arc_lo, &arc_width) < 0)
        goto done;
    if (reason >= 0)
        result = PyLong_FromLong(reason);
    else
        result = finish(positions, prior, n, max_vertices, a[0], a[1], arc_lo, arc_width);
done:
    work_give(self, w);
    PyBuffer_Release(&view);
    return result;
}

PyObject *reduce_strip(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    static const char *const names[] = {"center_x", "center_y", "wedge_center", "wedge_cw",    "wedge_ccw",
                                        "forward",  "left",     "start_x",      "start_y",     "end_x",
                                        "end_y",    "position_uncertainty", "offset", "offset_error", "angle",
                                        "angle_error"};
    enum { DOUBLES = sizeof(names) / sizeof(names[0]) };
    double a[DOUBLES];
    if (nargs != DOUBLES + 2) {
        PyErr_Format(PyExc_TypeError, "reduce_strip: expected %d arguments, got %zd", DOUBLES + 2, nargs);
        return NULL;
    }
    Py_ssize_t max_vertices, n;
    if (parse_doubles(args + 1, DOUBLES, names, a) < 0 || parse_cap(args[DOUBLES + 1], &max_vertices) < 0)
        return NULL;
    Py_buffer view;
    if (get_vertices(args[0], &view, &n) < 0) return NULL;
    const double *prior = (const double *)view.buf;
    Work local_work, *w = work_take(self, &local_work);
    PyObject *result = NULL;
    double heading_lo, heading_width, arc_lo = 0.0, arc_width = 0.0;
    wedge_arc(a[2], a[3], a[4], &heading_lo, &heading_width);
    int reason = -1;
    if (strip_reduction(prior, n, heading_lo, heading_width, a[5], a[6], a[7], a[8], a[9], a[10], a[11], a[12],
                        a[13], a[14], a[15], &w->positions, w, &reason, &arc_lo, &arc_width) < 0)
        goto done;
    if (reason >= 0)
        result = PyLong_FromLong(reason);
    else
        result = finish(&w->positions, prior, n, max_vertices, a[0], a[1], arc_lo, arc_width);
done:
    work_give(self, w);
    PyBuffer_Release(&view);
    return result;
}


/* --- every sector of a wedge at once (the joint reduction's sectors) ------------------------ */

/* HeadingWedge._trusted's wrap of an unwrapped centre to (-pi, pi]. */
static double wrapped_center(double center) {
    double wrapped = M_PI - floor_mod(M_PI - center, TWO_PI);
    return wrapped <= -M_PI ? wrapped + TWO_PI : wrapped;
}

/* _reduce.arc_parts: the unwrapped centre and extents of the wedge of an arc narrower than
   2 pi, centred on `center` or on the arc's nearer end. */
static void arc_parts(double lo, double width, double center, double *raw, double *cw, double *ccw) {
    double offset = floor_mod(center - lo, TWO_PI);
    if (offset > width) offset = offset - width < TWO_PI - offset ? width : 0.0;
    *raw = lo + offset;
    *cw = offset;
    *ccw = width - offset;
}

enum { SECTOR_ROW = 12 };

/* reduce_sectors(vertices, center_x, center_y, lo, step, count, half, arguments, max_vertices):
   see _reduce.reduce_sectors_reference. */
PyObject *reduce_sectors(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    static const char *const names[] = {"center_x", "center_y", "lo", "step"};
    static const char *const half_name[] = {"half"};
    static const char *const cone_names[] = {"kind", "forward", "left", "landmark_x", "landmark_y", "widen",
                                             "bearing", "bearing_error", "range_min", "range_max", "piece",
                                             "unused"};
    static const char *const strip_names[] = {"kind", "forward", "left", "start_x", "start_y", "end_x",
                                              "end_y", "position_uncertainty", "offset", "offset_error", "angle",
                                              "angle_error"};
    if (nargs != 9) {
        PyErr_Format(PyExc_TypeError, "reduce_sectors: expected 9 arguments, got %zd", nargs);
        return NULL;
    }
    double a[4], half;
    Py_ssize_t count, max_vertices;
    if (parse_doubles(args + 1, 4, names, a) < 0 || parse_count(args[5], "count", 1, 1000000, &count) < 0 ||
        parse_doubles(args + 6, 1, half_name, &half) < 0 || parse_cap(args[8], &max_vertices) < 0)
        return NULL;
    PyObject *rows = PySequence_Fast(args[7], "arguments: expected a sequence of numbers");
    if (!rows) return NULL;
    Py_ssize_t items = PySequence_Fast_GET_SIZE(rows), pairs = items / SECTOR_ROW;
    double *values = PyMem_Malloc(sizeof(double) * (size_t)(items > 0 ? items : 1));
    long long *kept = PyMem_Malloc(sizeof(long long) * (size_t)count);
    double *outcome = PyMem_Malloc(sizeof(double) * 5 * (size_t)count);
    long long *counts = PyMem_Malloc(sizeof(long long) * (size_t)count);
    PyObject *result = NULL;
    Poly current = {0}, gathered = {0};
    Py_buffer view;
    int have_view = 0;
    Work local_work, *w = NULL;
    if (!values || !kept || !outcome || !counts) {
        PyErr_NoMemory();
        goto done;
    }
    if (items == 0 || items % SECTOR_ROW) {
        PyErr_Format(PyExc_ValueError, "arguments: expected rows of %d numbers, at least one, got %zd numbers",
                     (int)SECTOR_ROW, items);
        goto done;
    }
    PyObject **objects = PySequence_Fast_ITEMS(rows);
    for (Py_ssize_t r = 0; r < pairs; r++) {
        double kind = PyFloat_AsDouble(objects[r * SECTOR_ROW]);
        if (kind == -1.0 && PyErr_Occurred()) goto done;
        if (kind != 0.0 && kind != 1.0) {
            PyErr_Format(PyExc_ValueError, "arguments: expected kind 0 (cone) or 1 (strip), got %R",
                         objects[r * SECTOR_ROW]);
            goto done;
        }
        /* A cone row's last number is unused: checked as a strip's would be, both finite. */
        if (parse_doubles(objects + r * SECTOR_ROW, SECTOR_ROW, kind == 1.0 ? strip_names : cone_names,
                          values + r * SECTOR_ROW) < 0)
            goto done;
        if (kind == 0.0 && check_piece(values[r * SECTOR_ROW + 10], objects[r * SECTOR_ROW + 10]) < 0) goto done;
    }
    Py_ssize_t n;
    if (get_vertices(args[0], &view, &n) < 0) goto done;
    have_view = 1;
    const double *prior = (const double *)view.buf;
    w = work_take(self, &local_work);
    Py_ssize_t k = 0;
    for (Py_ssize_t s = 0; s < count; s++) {
        double raw = (a[2] + (double)s * a[3]) + 0.5 * a[3];
        double center = wrapped_center(raw), cw = half, ccw = half, x = a[0], y = a[1];
        if (copy_into(&current, prior, n) < 0) goto done;
        int alive = 1;
        for (Py_ssize_t r = 0; r < pairs && alive; r++) {
            const double *row = values + r * SECTOR_ROW;
            double heading_lo, heading_width, arc_lo = 0.0, arc_width = 0.0;
            wedge_arc(center, cw, ccw, &heading_lo, &heading_width);
            int reason = -1;
            Poly *positions = NULL;
            if (row[0] == 1.0) {
                if (strip_reduction(current.v, current.n, heading_lo, heading_width, row[1], row[2], row[3], row[4],
                                    row[5], row[6], row[7], row[8], row[9], row[10], row[11], &w->positions, w,
                                    &reason, &arc_lo, &arc_width) < 0)
                    goto done;
                positions = &w->positions;
            } else if (cone_step(current.v, current.n, heading_lo, heading_width, row + 1, w, &reason, &positions,
                                 &arc_lo, &arc_width) < 0) {
                goto done;
            }
            if (reason >= 0) {
                alive = 0;
                break;
            }
            /* finish's tail, without the areas: the cap, then the centre kept or moved. */
            if (capped(positions, current.v, current.n, max_vertices, x, y, &x, &y) < 0) goto done;
            if (copy_into(&current, positions->v, positions->n) < 0) goto done;
            double sum = cw + ccw;
            if (arc_width < (sum < TWO_PI ? sum : TWO_PI)) {
                arc_parts(arc_lo, arc_width, center, &raw, &cw, &ccw);
                center = wrapped_center(raw);
            }
        }
        if (!alive) continue;
        Py_ssize_t total = checked_add(gathered.n, current.n);
        if (total < 0 || reserve(&gathered, total) < 0) {
            if (total < 0) PyErr_NoMemory();
            goto done;
        }
        memcpy(gathered.v + 2 * gathered.n, current.v, 2 * sizeof(double) * (size_t)current.n);
        gathered.n = total;
        kept[k] = (long long)s;
        counts[k] = (long long)current.n;
        double *o = outcome + 5 * k;
        o[0] = x;
        o[1] = y;
        o[2] = raw;
        o[3] = cw;
        o[4] = ccw;
        k++;
    }
    result = Py_BuildValue("(y#y#y#y#)", gathered.v ? (const char *)gathered.v : "", (Py_ssize_t)(2 * sizeof(double) * (size_t)gathered.n),
                           (const char *)counts, (Py_ssize_t)(sizeof(long long) * (size_t)k), (const char *)kept,
                           (Py_ssize_t)(sizeof(long long) * (size_t)k), (const char *)outcome,
                           (Py_ssize_t)(5 * sizeof(double) * (size_t)k));
done:
    if (w) work_give(self, w);
    if (have_view) PyBuffer_Release(&view);
    Py_DECREF(rows);
    PyMem_Free(values);
    PyMem_Free(kept);
    PyMem_Free(outcome);
    PyMem_Free(counts);
    PyMem_Free(current.v);
    PyMem_Free(gathered.v);
    return result;
}

/* --- every slice of a sliced map at once ---------------------------------------------------- */

/* See uncertainty._reduce.narrowed: a slice's interval [lo, hi] narrowed to a kernel's arc. */
static void narrowed(double arc_lo, double arc_width, double *lo, double *hi) {
    double span = *hi - *lo;
    if (arc_width >= span) return;
    if (span >= TWO_PI) {
        double start = floor_mod(arc_lo, TWO_PI);
        *lo = start;
        *hi = start + arc_width;
        return;
    }
    if (span > M_PI) return;
    double offset = floor_mod(arc_lo - *lo, TWO_PI);
    if (offset > 0.5 * (span + TWO_PI)) offset -= TWO_PI; /* the arc starts clockwise of lo */
    double new_lo = greater(*lo + offset, *lo);
    double new_hi = lesser(*lo + offset + arc_width, *hi);
    if (new_hi < new_lo) new_hi = new_lo = lesser(greater(new_lo, *lo), *hi); /* rounding at an end */
    *lo = new_lo;
    *hi = new_hi;
}

/* The arguments of one slice-by-slice reduction after the packed slices, the centre and the
   heading: the cone's or the strip's numbers and the vertex cap. */
typedef struct {
    int strip;
    double a[13];
    Py_ssize_t max_vertices;
} SliceReduction;

/* Reduce the slices one by one (_native._slices.reduce_slices_reference); the kept slices,
   narrowed and in heading order, then (x, y, wedge centre, cw, ccw), or the first slice's
   reason when none is kept. */
static PyObject *reduce_slices(PyObject *self, const Packed *p, double center_x, double center_y, double heading,
                               const SliceReduction *r) {
    Work local_work, *w = work_take(self, &local_work);
    SliceList kept = {0}, ordered = {0};
    double *centers = PyMem_Malloc(sizeof(double) * 2 * (size_t)p->k);
    Py_ssize_t *order = PyMem_Malloc(sizeof(Py_ssize_t) * (size_t)p->k), *starts = NULL;
    PyObject *result = NULL, *items[4];
    int first_reason = -1;
    if (!centers || !order) {
        PyErr_NoMemory();
        goto done;
    }
    Py_ssize_t start = 0;
    for (Py_ssize_t i = 0; i < p->k; i++) {
        const double *prior = p->v + 2 * start;
        Py_ssize_t n = (Py_ssize_t)p->counts[i];
        start += n;
        double piece_lo = p->lo[i], piece_hi = p->hi[i];
        double middle = clamp_into(heading, piece_lo, piece_hi);
        double heading_lo, heading_width, arc_lo = 0.0, arc_width = 0.0;
        wedge_arc(middle, middle - piece_lo, greater(0.0, piece_hi - middle), &heading_lo, &heading_width);
        int reason = -1;
        Poly *positions = NULL;
        const double *a = r->a;
        if (r->strip) {
            if (strip_reduction(prior, n, heading_lo, heading_width, a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7],
                                a[8], a[9], a[10], &w->positions, w, &reason, &arc_lo, &arc_width) < 0)
                goto done;
            positions = &w->positions;
        } else {
            double margin = a[6] + TOLERANCE;
            Cone cone = {a[2], a[3], a[4], heading_lo + a[5] + M_PI - margin, heading_width + 2.0 * margin,
                         a[7], a[8], a[9]};
            if (cone_reduction(prior, n, heading_lo, heading_width, a[0], a[1], a[5], a[6], &cone, w, &reason,
                               &positions, &arc_lo, &arc_width) < 0)
                goto done;
        }
        if (reason >= 0) {
            if (first_reason < 0) first_reason = reason;
            continue;
        }
        /* finish: the vertex cap, then the centre kept or moved to the nearest position. */
        if (positions->n > r->max_vertices) {
            if (cap_inside(positions, prior, n, r->max_vertices) < 0) goto done;
            if (positions->n > r->max_vertices && positions->n > n && copy_into(positions, prior, n) < 0) goto done;
        }
        double distance;
        nearest_on_polygon(positions->v, positions->n, center_x, center_y, &distance, &centers[2 * kept.k],
                           &centers[2 * kept.k + 1]);
        if (arc_width < piece_hi - piece_lo) narrowed(arc_lo, arc_width, &piece_lo, &piece_hi);
        if (slices_append(&kept, positions->v, positions->n, piece_lo, piece_hi, kept.k) < 0) goto done;
    }
    if (kept.k == 0) {
        result = PyLong_FromLong(first_reason);
        goto done;
    }
    /* A full-circle slice's arc may start anywhere: keep the slices in heading order (a
       stable insertion sort, as Python's sorted). */
    for (Py_ssize_t i = 0; i < kept.k; i++) {
        Py_ssize_t j = i, item = i;
        while (j > 0 && kept.lo[item] < kept.lo[order[j - 1]]) {
            order[j] = order[j - 1];
            j--;
        }
        order[j] = item;
    }
    SliceList *final = &kept;
    double *x_y = centers;
    int sorted = 1;
    for (Py_ssize_t i = 0; i < kept.k; i++) sorted &= order[i] == i;
    if (!sorted) {
        starts = PyMem_Malloc(sizeof(Py_ssize_t) * (size_t)kept.k);
        double *moved = PyMem_Malloc(sizeof(double) * 2 * (size_t)kept.k);
        if (!starts || !moved) {
            PyMem_Free(moved);
            PyErr_NoMemory();
            goto done;
        }
        Py_ssize_t at = 0;
        for (Py_ssize_t i = 0; i < kept.k; i++) {
            starts[i] = at;
            at += (Py_ssize_t)kept.counts[i];
        }
        for (Py_ssize_t i = 0; i < kept.k; i++) {
            Py_ssize_t from = order[i];
            moved[2 * i] = centers[2 * from];
            moved[2 * i + 1] = centers[2 * from + 1];
            if (slices_append(&ordered, kept.points.v + 2 * starts[from], (Py_ssize_t)kept.counts[from],
                              kept.lo[from], kept.hi[from], i) < 0) {
                PyMem_Free(moved);
                goto done;
            }
        }
        memcpy(centers, moved, sizeof(double) * 2 * (size_t)kept.k);
        PyMem_Free(moved);
        final = &ordered;
    }
    Py_ssize_t home = home_slice(final->lo, final->hi, final->k, heading);
    double wedge[3];
    summary_wedge(final->lo, final->hi, final->k, clamp_into(heading, final->lo[home], final->hi[home]), wedge);
    if (slices_bytes(final, 0, items) == 0)
        result = Py_BuildValue("(NNNNddddd)", items[0], items[1], items[2], items[3], x_y[2 * home],
                               x_y[2 * home + 1], wedge[0], wedge[1], wedge[2]);
done:
    work_give(self, w);
    slices_free(&kept);
    slices_free(&ordered);
    PyMem_Free(centers);
    PyMem_Free(order);
    PyMem_Free(starts);
    return result;
}

/* reduce_cone_slices(points, counts, lo, hi, center_x, center_y, heading, forward, left,
   landmark_x, landmark_y, widen, bearing, bearing_error, range_min, range_max, piece,
   max_vertices) and reduce_strip_slices(points, counts, lo, hi, center_x, center_y, heading,
   forward, left, start_x, start_y, end_x, end_y, position_uncertainty, offset, offset_error,
   angle, angle_error, max_vertices). */
static PyObject *reduce_slices_call(PyObject *self, PyObject *const *args, Py_ssize_t nargs, int strip) {
    static const char *const cone_names[] = {"center_x", "center_y", "heading", "forward", "left", "landmark_x",
                                             "landmark_y", "widen", "bearing", "bearing_error", "range_min",
                                             "range_max", "piece"};
    static const char *const strip_names[] = {"center_x", "center_y", "heading", "forward", "left", "start_x",
                                              "start_y", "end_x", "end_y", "position_uncertainty", "offset",
                                              "offset_error", "angle", "angle_error"};
    Py_ssize_t doubles = strip ? 14 : 13;
    if (nargs != doubles + 5) {
        PyErr_Format(PyExc_TypeError, "%s: expected %zd arguments, got %zd",
                     strip ? "reduce_strip_slices" : "reduce_cone_slices", doubles + 5, nargs);
        return NULL;
    }
    double values[14];
    SliceReduction r;
    r.strip = strip;
    if (parse_doubles(args + 4, doubles, strip ? strip_names : cone_names, values) < 0 ||
        parse_cap(args[doubles + 4], &r.max_vertices) < 0)
        return NULL;
    memcpy(r.a, values + 3, sizeof(double) * (size_t)(doubles - 3));
    if (!strip && (!(r.a[9] > 0.0) || TWO_PI / r.a[9] > 1e6)) {
        PyErr_Format(PyExc_ValueError, "piece: expected a positive angle of at least 2 pi / 1e6, got %R", args[16]);
        return NULL;
    }
    Packed p;
    if (get_packed(args, &p) < 0) return NULL;
    PyObject *result = reduce_slices(self, &p, values[0], values[1], values[2], &r);
    packed_release(&p);
    return result;
}

PyObject *reduce_cone_slices(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    return reduce_slices_call(self, args, nargs, 0);
}

PyObject *reduce_strip_slices(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    return reduce_slices_call(self, args, nargs, 1);
}
