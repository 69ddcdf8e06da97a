/*
 * Compiled kernel of the growth step: P (+) skitter disk (+) outer polygon of the
 * annular sector of run endpoints, then the outer vertex cap.
 *
 * It mirrors, operation for operation, the numpy functions in _convex.py
 * (outer_annular_sector, outer_disk, minkowski_sum, simplify_outer), which stay
 * the reference implementation and the fallback when this extension is not built.
 * Small polygons make numpy's per-call overhead dominate; plain C loops do not.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TWO_PI (2.0 * M_PI)
#define ARC_STEP (M_PI / 16.0)
#define TINY_ANGLE 1e-12
#define PARALLEL_EPS 1e-12
#define NOISE_EDGE 1e-12
#define FARTHEST_MERGE 10.0
#define EXTENDABLE 1e-6
#define SKITTER_SIDES 8
#define FULL_DISK_SIDES 32

typedef struct {
    double x, y, angle;
} Edge;

typedef struct {
    double cost;
    Py_ssize_t index;
} Ranked;

/* Order of the greedy pick: cheaper first, then lower index (numpy's stable argsort). */
static int before(const Ranked *a, const Ranked *b) {
    return a->cost < b->cost || (a->cost == b->cost && a->index < b->index);
}

static void sift_down(Ranked *heap, Py_ssize_t size, Py_ssize_t i) {
    for (;;) {
        Py_ssize_t smallest = i, left = 2 * i + 1, right = left + 1;
        if (left < size && before(&heap[left], &heap[smallest])) smallest = left;
        if (right < size && before(&heap[right], &heap[smallest])) smallest = right;
        if (smallest == i) return;
        Ranked swap = heap[i];
        heap[i] = heap[smallest];
        heap[smallest] = swap;
        i = smallest;
    }
}

/* Outer polygon of the arc of `radius` from `start` to `stop` (see _convex.outer_arc). */
static Py_ssize_t outer_arc(double radius, double start, double stop, double *out) {
    double width = stop - start;
    Py_ssize_t count = (Py_ssize_t)ceil(width / ARC_STEP);
    if (count < 1) count = 1;
    double half = width / (2.0 * (double)count);
    double reach = radius / cos(half);
    Py_ssize_t m = 0;
    out[2 * m] = radius * cos(start);
    out[2 * m + 1] = radius * sin(start);
    m++;
    for (Py_ssize_t k = 0; k < count; k++) {
        double angle = start + (double)(2 * k + 1) * half;
        out[2 * m] = reach * cos(angle);
        out[2 * m + 1] = reach * sin(angle);
        m++;
    }
    out[2 * m] = radius * cos(stop);
    out[2 * m + 1] = radius * sin(stop);
    m++;
    return m;
}

static Py_ssize_t outer_disk(double radius, Py_ssize_t sides, double *out) {
    double reach = radius / cos(M_PI / (double)sides);
    for (Py_ssize_t j = 0; j < sides; j++) {
        double angle = (double)j * (TWO_PI / (double)sides);
        out[2 * j] = reach * cos(angle);
        out[2 * j + 1] = reach * sin(angle);
    }
    return sides;
}

/* See _convex.outer_annular_sector. */
static Py_ssize_t outer_annular_sector(double inner, double outer, double start, double stop, double *out) {
    double width = stop - start;
    if (outer <= 0.0) {
        out[0] = 0.0;
        out[1] = 0.0;
        return 1;
    }
    if (width >= TWO_PI) return outer_disk(outer, FULL_DISK_SIDES, out);
    if (width <= TINY_ANGLE) {
        double c = cos(start), s = sin(start);
        if (inner >= outer) {
            out[0] = outer * c;
            out[1] = outer * s;
            return 1;
        }
        out[0] = inner * c;
        out[1] = inner * s;
        out[2] = outer * c;
        out[3] = outer * s;
        return 2;
    }
    Py_ssize_t m = outer_arc(outer, start, stop, out);
    if (width >= M_PI || inner >= outer) return m;
    if (inner <= 0.0) {
        out[2 * m] = 0.0;
        out[2 * m + 1] = 0.0;
        return m + 1;
    }
    out[2 * m] = inner * cos(stop);
    out[2 * m + 1] = inner * sin(stop);
    out[2 * m + 2] = inner * cos(start);
    out[2 * m + 3] = inner * sin(start);
    return m + 2;
}

/* See _convex._lowest_vertex. */
static Py_ssize_t lowest_vertex(const double *v, Py_ssize_t n) {
    Py_ssize_t index = 0;
    for (Py_ssize_t i = 1; i < n; i++)
        if (v[2 * i + 1] < v[2 * index + 1]) index = i;
    for (Py_ssize_t step = 0; step < n - 1; step++) {
        Py_ssize_t previous = index > 0 ? index - 1 : n - 1;
        if (v[2 * previous + 1] != v[2 * index + 1] || v[2 * previous] > v[2 * index]) break;
        index = previous;
    }
    return index;
}

static int compare_angles(const void *a, const void *b) {
    double da = ((const Edge *)a)->angle, db = ((const Edge *)b)->angle;
    return (da > db) - (da < db);
}

/* Edges of a convex polygon in cyclic order from its lowest vertex: increasing direction. */
static Py_ssize_t ordered_edges(const double *v, Py_ssize_t n, Py_ssize_t low, Edge *edges) {
    if (n < 2) return 0;
    for (Py_ssize_t k = 0; k < n; k++) {
        Py_ssize_t i = low + k < n ? low + k : low + k - n;
        Py_ssize_t j = i + 1 < n ? i + 1 : 0;
        edges[k].x = v[2 * j] - v[2 * i];
        edges[k].y = v[2 * j + 1] - v[2 * i + 1];
    }
    return n;
}

/* See _convex.minkowski_sum; returns the vertex count written to `out`. Each operand's
   edges already run in increasing direction from its lowest vertex, so a linear merge
   replaces the sort (ties keep operand order, as a stable sort would). */
static Py_ssize_t minkowski_sum(const double **parts, const Py_ssize_t *sizes, int part_count, Edge *edges,
                                double *out) {
    double sx = 0.0, sy = 0.0, largest = 0.0;
    Py_ssize_t begin[3], length[3], count = 0;
    for (int p = 0; p < part_count; p++) {
        Py_ssize_t low = lowest_vertex(parts[p], sizes[p]);
        sx += parts[p][2 * low];
        sy += parts[p][2 * low + 1];
        begin[p] = count;
        length[p] = ordered_edges(parts[p], sizes[p], low, edges + count);
        count += length[p];
    }
    for (Py_ssize_t i = 0; i < count; i++) {
        double size = fmax(fabs(edges[i].x), fabs(edges[i].y));
        if (size > largest) largest = size;
    }
    double threshold = fmax(4e-16 * fmax(fabs(sx), fabs(sy)), NOISE_EDGE * largest);
    /* Drop vanishing edges and compute directions in [0, 2 pi), per operand. */
    for (int p = 0; p < part_count; p++) {
        Py_ssize_t kept = 0;
        for (Py_ssize_t k = 0; k < length[p]; k++) {
            Edge e = edges[begin[p] + k];
            if (fmax(fabs(e.x), fabs(e.y)) <= threshold) continue;
            double angle = atan2(e.y, e.x);
            e.angle = angle < 0.0 ? angle + TWO_PI : angle;
            edges[begin[p] + kept] = e;
            kept++;
        }
        length[p] = kept;
        /* Rounding can leave a tiny edge with a direction out of order; then sort this
           operand, or the merge would put other operands' edges in the wrong place. */
        for (Py_ssize_t k = 1; k < kept; k++) {
            if (edges[begin[p] + k].angle < edges[begin[p] + k - 1].angle) {
                qsort(edges + begin[p], (size_t)kept, sizeof(Edge), compare_angles);
                break;
            }
        }
    }
    Py_ssize_t cursor[3] = {0, 0, 0}, joined = 0;
    double previous_angle = 0.0, x = sx, y = sy;
    Edge *merged = edges + count; /* room reserved by the caller */
    for (;;) {
        int best = -1;
        double best_angle = 0.0;
        for (int p = 0; p < part_count; p++) {
            if (cursor[p] >= length[p]) continue;
            double angle = edges[begin[p] + cursor[p]].angle;
            if (best < 0 || angle < best_angle) {
                best = p;
                best_angle = angle;
            }
        }
        if (best < 0) break;
        Edge e = edges[begin[best] + cursor[best]];
        cursor[best]++;
        /* Join parallel neighbours, as _convex.minkowski_sum does after its sort. */
        if (joined > 0 && e.angle - previous_angle <= PARALLEL_EPS) {
            merged[joined - 1].x += e.x;
            merged[joined - 1].y += e.y;
        } else {
            merged[joined] = e;
            joined++;
        }
        previous_angle = e.angle;
    }
    if (joined == 0) {
        out[0] = sx;
        out[1] = sy;
        return 1;
    }
    for (Py_ssize_t i = 0; i < joined; i++) {
        out[2 * i] = x;
        out[2 * i + 1] = y;
        x += merged[i].x;
        y += merged[i].y;
    }
    return joined;
}

static double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

/* See _convex.simplify_outer; works in place, returns the new vertex count. */
static Py_ssize_t simplify_outer(double *v, Py_ssize_t n, Py_ssize_t max_vertices, double *t, Ranked *ranked,
                                 char *blocked, char *chosen, double *scratch) {
    Py_ssize_t floor_count = max_vertices > 3 ? max_vertices : 3;
    while (n > floor_count) {
        /* Edges too short for their direction to be accurate are never extended to
           replace a removed neighbour (see _convex.simplify_outer). */
        double longest = 0.0, magnitude = 0.0, xmin = v[0], xmax = v[0], ymin = v[1], ymax = v[1];
        for (Py_ssize_t i = 0; i < n; i++) magnitude = fmax(magnitude, fmax(fabs(v[2 * i]), fabs(v[2 * i + 1])));
        for (Py_ssize_t i = 1; i < n; i++) {
            xmin = fmin(xmin, v[2 * i]);
            xmax = fmax(xmax, v[2 * i]);
            ymin = fmin(ymin, v[2 * i + 1]);
            ymax = fmax(ymax, v[2 * i + 1]);
        }
        double farthest = FARTHEST_MERGE * fmax(xmax - xmin, ymax - ymin);
        for (Py_ssize_t i = 0; i < n; i++) {
            Py_ssize_t next = i + 1 < n ? i + 1 : 0;
            double size = fmax(fabs(v[2 * next] - v[2 * i]), fabs(v[2 * next + 1] - v[2 * i + 1]));
            scratch[i] = size;
            if (size > longest) longest = size;
        }
        /* An edge's direction is good to ~1e-16 * |coordinates| / length radians. */
        for (Py_ssize_t i = 0; i < n; i++) blocked[i] = scratch[i] > EXTENDABLE * fmax(magnitude, longest);
        for (Py_ssize_t i = 0; i < n; i++) {
            Py_ssize_t next = i + 1 < n ? i + 1 : 0, after = next + 1 < n ? next + 1 : 0;
            Py_ssize_t prev = i > 0 ? i - 1 : n - 1;
            double ex = v[2 * next] - v[2 * i], ey = v[2 * next + 1] - v[2 * i + 1];
            double px = v[2 * i] - v[2 * prev], py = v[2 * i + 1] - v[2 * prev + 1];
            double fx = v[2 * after] - v[2 * next], fy = v[2 * after + 1] - v[2 * next + 1];
            double denominator = cross(px, py, fx, fy);
            double cost = HUGE_VAL;
            t[i] = 0.0;
            if (denominator > 0.0 && blocked[prev] && blocked[next]) {
                t[i] = cross(ex, ey, fx, fy) / denominator;
                /* Nearly parallel neighbours meet far away: the cap yields instead. */
                double turn_in = cross(px, py, ex, ey);
                /* Both corners must turn left (t >= 0 is the far one), see _convex.py. */
                if (t[i] >= 0.0 && turn_in >= 0.0 && t[i] * fmax(fabs(px), fabs(py)) <= farthest)
                    cost = 0.5 * t[i] * turn_in;
            }
            ranked[i].cost = cost;
            ranked[i].index = i;
        }
        for (Py_ssize_t i = 0; i < n; i++) {
            blocked[i] = 0;
            chosen[i] = 0;
        }
        /* A heap gives the cheapest edges in order without sorting them all. */
        for (Py_ssize_t i = n / 2; i-- > 0;) sift_down(ranked, n, i);
        Py_ssize_t needed = n - max_vertices, picked = 0, size = n;
        while (size > 0) {
            Ranked top = ranked[0];
            ranked[0] = ranked[--size];
            sift_down(ranked, size, 0);
            Py_ssize_t index = top.index;
            if (top.cost == HUGE_VAL) break;
            if (blocked[index]) continue;
            chosen[index] = 1;
            picked++;
            if (picked == needed) break;
            blocked[index > 0 ? index - 1 : n - 1] = 1;
            blocked[index] = 1;
            blocked[index + 1 < n ? index + 1 : 0] = 1;
        }
        if (picked == 0) break;
        /* Chosen edge i: vertex i moves along the preceding edge to meet the following
           one's line, and vertex i+1 goes. */
        Py_ssize_t m = 0;
        char drop_first = chosen[n - 1];
        for (Py_ssize_t i = 0; i < n; i++) {
            if (i == 0 && drop_first) continue;
            if (i > 0 && chosen[i - 1]) continue;
            double x = v[2 * i], y = v[2 * i + 1];
            if (chosen[i]) {
                Py_ssize_t prev = i > 0 ? i - 1 : n - 1;
                x += t[i] * (v[2 * i] - v[2 * prev]);
                y += t[i] * (v[2 * i + 1] - v[2 * prev + 1]);
            }
            scratch[2 * m] = x;
            scratch[2 * m + 1] = y;
            m++;
        }
        memcpy(v, scratch, sizeof(double) * 2 * (size_t)m);
        n = m;
    }
    return n;
}

static PyObject *grow_polygon(PyObject *self, PyObject *args) {
    Py_buffer buffer;
    double heading_lo, heading_hi, turn_min, turn_max, drift_max, chord_min, run_max, skitter_radius;
    Py_ssize_t max_vertices;
    if (!PyArg_ParseTuple(args, "y*ddddddddn", &buffer, &heading_lo, &heading_hi, &turn_min, &turn_max,
                          &drift_max, &chord_min, &run_max, &skitter_radius, &max_vertices))
        return NULL;
    Py_ssize_t n = buffer.len / (Py_ssize_t)(2 * sizeof(double));
    if (n < 1 || buffer.len != n * (Py_ssize_t)(2 * sizeof(double))) {
        PyBuffer_Release(&buffer);
        PyErr_SetString(PyExc_ValueError, "vertices: expected a C-contiguous (n, 2) float64 buffer");
        return NULL;
    }
    const double *vertices = (const double *)buffer.buf;
    Py_ssize_t capacity = n + 2 * FULL_DISK_SIDES + SKITTER_SIDES + 8;
    double *sector = PyMem_Malloc(sizeof(double) * 2 * (size_t)(FULL_DISK_SIDES + 40));
    double *disk = PyMem_Malloc(sizeof(double) * 2 * SKITTER_SIDES);
    Edge *edges = PyMem_Malloc(sizeof(Edge) * 2 * (size_t)capacity);
    double *out = PyMem_Malloc(sizeof(double) * 2 * (size_t)capacity);
    double *scratch = PyMem_Malloc(sizeof(double) * 2 * (size_t)capacity);
    double *t = PyMem_Malloc(sizeof(double) * (size_t)capacity);
    Ranked *ranked = PyMem_Malloc(sizeof(Ranked) * (size_t)capacity);
    char *flags = PyMem_Malloc(2 * (size_t)capacity);
    PyObject *result = NULL;
    if (!sector || !disk || !edges || !out || !scratch || !t || !ranked || !flags) {
        PyErr_NoMemory();
        goto done;
    }
    const double *parts[3] = {vertices, NULL, NULL};
    Py_ssize_t sizes[3] = {n, 0, 0};
    int part_count = 1;
    if (run_max > 0.0) {
        double start = heading_lo + turn_min - drift_max / 2.0;
        double stop = heading_hi + turn_max + drift_max / 2.0;
        if (heading_hi - heading_lo >= TWO_PI) stop = start + TWO_PI;
        parts[part_count] = sector;
        sizes[part_count] = outer_annular_sector(chord_min, run_max, start, stop, sector);
        part_count++;
    }
    if (skitter_radius > 0.0) {
        parts[part_count] = disk;
        sizes[part_count] = outer_disk(skitter_radius, SKITTER_SIDES, disk);
        part_count++;
    }
    Py_ssize_t m;
    if (part_count == 1) {
        memcpy(out, vertices, sizeof(double) * 2 * (size_t)n);
        m = n;
    } else {
        m = minkowski_sum(parts, sizes, part_count, edges, out);
        if (m > max_vertices)
            m = simplify_outer(out, m, max_vertices, t, ranked, flags, flags + capacity, scratch);
    }
    result = PyBytes_FromStringAndSize((const char *)out, (Py_ssize_t)(sizeof(double) * 2 * (size_t)m));
done:
    PyMem_Free(sector);
    PyMem_Free(disk);
    PyMem_Free(edges);
    PyMem_Free(out);
    PyMem_Free(scratch);
    PyMem_Free(t);
    PyMem_Free(ranked);
    PyMem_Free(flags);
    PyBuffer_Release(&buffer);
    return result;
}

static PyMethodDef methods[] = {
    {"grow_polygon", grow_polygon, METH_VARARGS,
     "grow_polygon(vertices, heading_lo, heading_hi, turn_min, turn_max, drift_max, chord_min, run_max, "
     "skitter_radius, max_vertices) -> bytes of (m, 2) float64 vertices"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_kernels",
                                    "Compiled kernel of the growth step (see _convex.py for the reference).", -1,
                                    methods};

PyMODINIT_FUNC PyInit__kernels(void) { return PyModule_Create(&module); }
