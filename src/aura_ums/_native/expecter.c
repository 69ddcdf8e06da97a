/*
 * Compiled kernel of the Expecter: from the map's polygon and wedge, the landmark's base
 * and the camera mount, the normalized image points whose box holds every projection of
 * the landmark. It mirrors, operation for operation, _expecter.expecter_points_reference
 * beside this file (the Minkowski sum base (+) disk (+) (-P), the swept arcs' outer
 * points, the prism cut by the plane in front of the camera, the normalization).
 */
#include "kernels.h"

/* Camera-frame point of a robot-frame ground point (x, y) raised by dz (see _clip_to_front). */
static void to_camera(const double *r, double forward, double left, double x, double y, double dz, double *out) {
    double px = x - forward, py = y - left;
    for (int j = 0; j < 3; j++) out[j] = px * r[j] + py * r[3 + j] + dz * r[6 + j];
}

PyObject *expecter_points(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    static const char *const names[] = {"base_ax", "base_ay", "base_bx", "base_by", "radius",  "heading_lo",
                                        "heading_width", "arc_step", "r00",   "r01",     "r02",    "r10",
                                        "r11",     "r12",     "r20",     "r21",     "r22",     "forward",
                                        "left",    "dz_lo",   "dz_hi",   "cut_plane"};
    enum { INTS = 4, DOUBLES = sizeof(names) / sizeof(names[0]) };
    if (nargs != 1 + INTS + DOUBLES) {
        PyErr_Format(PyExc_TypeError, "expecter_points: expected %d arguments, got %zd", 1 + INTS + DOUBLES, nargs);
        return NULL;
    }
    Py_ssize_t base_count, disk_sides, full_circle, level_count, n;
    double a[DOUBLES];
    if (parse_count(args[1], "base_count", 1, 2, &base_count) < 0 ||
        parse_count(args[2], "disk_sides", 3, 1 << 20, &disk_sides) < 0 ||
        parse_count(args[3], "full_circle", 0, 1, &full_circle) < 0 ||
        parse_count(args[4], "level_count", 1, 2, &level_count) < 0 ||
        parse_doubles(args + 1 + INTS, DOUBLES, names, a) < 0)
        return NULL;
    double radius = a[4], heading_lo = a[5], width = a[6], arc_step = a[7];
    const double *r = a + 8;
    double forward = a[17], left = a[18], dz_lo = a[19], dz_hi = a[20], cut = a[21];
    /* Arcs of 3 to 2^20 pieces per turn; a wedge narrower than a turn unless full. */
    if (!(radius >= 0.0) || !(width >= 0.0) || !(full_circle || width < TWO_PI) ||
        !(arc_step >= TWO_PI / (double)(1 << 20) && arc_step <= TWO_PI / 3.0) || !(dz_lo <= dz_hi)) {
        PyErr_SetString(PyExc_ValueError,
                        "expected radius >= 0, 0 <= heading_width < 2 pi (unless full_circle), "
                        "2 pi / 2^20 <= arc_step <= 2 pi / 3 and dz_lo <= dz_hi");
        return NULL;
    }
    Py_buffer view;
    if (get_vertices(args[0], &view, &n) < 0) return NULL;
    const double *polygon = (const double *)view.buf;
    Work local_work, *w = work_take(self, &local_work);
    PyObject *result = NULL;
    double *disk = NULL, *negated = NULL, *camera = NULL, *normalized = NULL;

    /* D = base (+) disk (+) (-P): robot-independent differences q - p (_relative_ground). */
    double base[4] = {a[0], a[1], a[2], a[3]};
    Py_ssize_t sides = radius > 0.0 ? disk_sides : 0, total = checked_add(base_count + sides, n);
    if (total < 0 || checked_multiply(total, 2) < 0) {
        PyErr_NoMemory();
        goto done;
    }
    disk = PyMem_Malloc(sizeof(double) * 2 * (size_t)(sides > 0 ? sides : 1));
    negated = PyMem_Malloc(sizeof(double) * 2 * (size_t)n);
    if (!disk || !negated) {
        PyErr_NoMemory();
        goto done;
    }
    Edge *edges = scratch(&w->edges, 2 * total, sizeof(Edge));
    if (!edges || reserve(&w->sum, total) < 0) goto done;
    for (Py_ssize_t i = 0; i < 2 * n; i++) negated[i] = -polygon[i];
    const double *parts[3] = {base, NULL, NULL};
    Py_ssize_t sizes[3] = {base_count, 0, 0};
    int part_count = 1;
    if (sides > 0) {
        outer_disk(radius, sides, disk);
        parts[part_count] = disk;
        sizes[part_count++] = sides;
    }
    parts[part_count] = negated;
    sizes[part_count++] = n;
    Py_ssize_t m = minkowski_sum(parts, sizes, part_count, edges, w->sum.v);
    const double *d = w->sum.v;

    /* Robot-frame points whose hull holds R(-h) d for every d in D and h in the wedge. */
    Poly *rel = &w->ping;
    if (full_circle) {
        double reach = 0.0;
        for (Py_ssize_t i = 0; i < m; i++) reach = greater(reach, hypot(d[2 * i], d[2 * i + 1]));
        Py_ssize_t count = arc_pieces(TWO_PI, arc_step);
        if (reserve(rel, count) < 0) goto done;
        if (reach <= 0.0) {
            rel->v[0] = 0.0;
            rel->v[1] = 0.0;
            rel->n = 1;
        } else {
            rel->n = outer_disk(reach, count, rel->v);
        }
    } else {
        Py_ssize_t count = width > 0.0 ? arc_pieces(width, arc_step) : 0;
        Py_ssize_t per = width > 0.0 ? 2 + count : 1, points = checked_multiply(m, per);
        if (points < 0) {
            PyErr_NoMemory();
            goto done;
        }
        if (reserve(rel, points) < 0) goto done;
        double *out = rel->v;
        Py_ssize_t k = 0;
        double c = cos(-heading_lo), s = sin(-heading_lo);
        for (Py_ssize_t i = 0; i < m; i++, k++) {
            out[2 * k] = c * d[2 * i] - s * d[2 * i + 1];
            out[2 * k + 1] = s * d[2 * i] + c * d[2 * i + 1];
        }
        if (width > 0.0) {
            double heading_hi = heading_lo + width;
            c = cos(-heading_hi);
            s = sin(-heading_hi);
            for (Py_ssize_t i = 0; i < m; i++, k++) {
                out[2 * k] = c * d[2 * i] - s * d[2 * i + 1];
                out[2 * k + 1] = s * d[2 * i] + c * d[2 * i + 1];
            }
            /* The tangent points: d at angle phase(d) - heading_hi + (2 j + 1) half, stretched by
               1 / cos(half); the same as rotating d by -heading_hi + (2 j + 1) half, which needs
               no per-vertex atan2, hypot, cos or sin. */
            double half = width / (2.0 * (double)count);
            double stretch = 1.0 / cos(half);
            double *turn = PyMem_Malloc(sizeof(double) * 2 * (size_t)count);
            if (!turn) {
                PyErr_NoMemory();
                goto done;
            }
            for (Py_ssize_t j = 0; j < count; j++) {
                double angle = -heading_hi + (double)(2 * j + 1) * half;
                turn[2 * j] = stretch * cos(angle);
                turn[2 * j + 1] = stretch * sin(angle);
            }
            for (Py_ssize_t i = 0; i < m; i++) {
                double x = d[2 * i], y = d[2 * i + 1];
                for (Py_ssize_t j = 0; j < count; j++, k++) {
                    out[2 * k] = turn[2 * j] * x - turn[2 * j + 1] * y;
                    out[2 * k + 1] = turn[2 * j + 1] * x + turn[2 * j] * y;
                }
            }
            PyMem_Free(turn);
        }
        rel->n = k;
    }

    /* The prism over those points, in the camera frame, cut by the plane z = cut. */
    double levels[2] = {dz_lo, dz_hi};
    double up_z = r[8], nearest = HUGE_VAL, farthest = -HUGE_VAL;
    for (Py_ssize_t i = 0; i < rel->n; i++) {
        double z = (rel->v[2 * i] - forward) * r[2] + (rel->v[2 * i + 1] - left) * r[5];
        double lo = z + dz_lo * up_z, hi = z + dz_hi * up_z;
        nearest = lesser(nearest, lesser(lo, hi));
        farthest = greater(farthest, greater(lo, hi));
    }
    if (farthest <= cut) {
        result = Py_NewRef(Py_None);
        goto done;
    }
    Py_ssize_t k = 0;
    if (nearest >= cut) {
        camera = PyMem_Malloc(sizeof(double) * 3 * (size_t)(rel->n * level_count));
        if (!camera) {
            PyErr_NoMemory();
            goto done;
        }
        for (Py_ssize_t l = 0; l < level_count; l++)
            for (Py_ssize_t i = 0; i < rel->n; i++, k++)
                to_camera(r, forward, left, rel->v[2 * i], rel->v[2 * i + 1], levels[l], camera + 3 * k);
    } else {
        /* Part of the polytope is behind: cut it along its known edges (a prism over the hull). */
        if (convex_hull(rel->v, rel->n, &w->pong, w) < 0) goto done;
        Py_ssize_t h = w->pong.n, layer = h, edge_count = 0;
        if (h >= 2) edge_count += level_count * h;
        if (level_count == 2) edge_count += h;
        double *layers = PyMem_Malloc(sizeof(double) * 3 * (size_t)(h * level_count));
        camera = PyMem_Malloc(sizeof(double) * 3 * (size_t)(h * level_count + edge_count));
        if (!layers || !camera) {
            PyMem_Free(layers);
            PyErr_NoMemory();
            goto done;
        }
        for (Py_ssize_t l = 0; l < level_count; l++)
            for (Py_ssize_t i = 0; i < h; i++)
                to_camera(r, forward, left, w->pong.v[2 * i], w->pong.v[2 * i + 1], levels[l],
                          layers + 3 * (l * layer + i));
        for (Py_ssize_t i = 0; i < h * level_count; i++) {
            if (layers[3 * i + 2] >= cut) {
                memcpy(camera + 3 * k, layers + 3 * i, 3 * sizeof(double));
                k++;
            }
        }
        for (Py_ssize_t e = 0; e < edge_count; e++) {
            const double *p, *q;
            Py_ssize_t ring = h >= 2 ? level_count * h : 0;
            if (e < ring) {
                Py_ssize_t l = e / h, i = e % h, j = i + 1 < h ? i + 1 : 0;
                p = layers + 3 * (l * layer + i);
                q = layers + 3 * (l * layer + j);
            } else {
                Py_ssize_t i = e - ring;
                p = layers + 3 * i;
                q = layers + 3 * (layer + i);
            }
            if ((p[2] - cut) * (q[2] - cut) < 0.0) {
                double t = (cut - p[2]) / (q[2] - p[2]);
                camera[3 * k] = p[0] + t * (q[0] - p[0]);
                camera[3 * k + 1] = p[1] + t * (q[1] - p[1]);
                camera[3 * k + 2] = cut;
                k++;
            }
        }
        PyMem_Free(layers);
    }
    if (k == 0) {
        result = Py_NewRef(Py_None);
        goto done;
    }
    normalized = PyMem_Malloc(sizeof(double) * 2 * (size_t)k);
    if (!normalized) {
        PyErr_NoMemory();
        goto done;
    }
    double box[4] = {HUGE_VAL, HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (Py_ssize_t i = 0; i < k; i++) {
        double x = camera[3 * i] / camera[3 * i + 2], y = camera[3 * i + 1] / camera[3 * i + 2];
        normalized[2 * i] = x;
        normalized[2 * i + 1] = y;
        box[0] = lesser(box[0], x);
        box[1] = lesser(box[1], y);
        box[2] = greater(box[2], x);
        box[3] = greater(box[3], y);
    }
    PyObject *raw = PyBytes_FromStringAndSize((const char *)normalized, (Py_ssize_t)(2 * sizeof(double) * (size_t)k));
    if (!raw) goto done;
    result = Py_BuildValue("(Ndddd)", raw, box[0], box[1], box[2], box[3]);
done:
    PyMem_Free(disk);
    PyMem_Free(negated);
    PyMem_Free(camera);
    PyMem_Free(normalized);
    work_give(self, w);
    PyBuffer_Release(&view);
    return result;
}

