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

/* fmin and fmax without the libm calls (no NaN reaches them from checked input). Where a
   +0/-0 choice could differ from libm's, the result is only compared, never returned. */
static inline double lesser(double a, double b) { return b < a ? b : a; }
static inline double greater(double a, double b) { return b > a ? b : a; }

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

/* A monotone stand-in for the direction angle over [0, 2 pi): the "diamond angle" in
   [0, 4), one division instead of atan2. The merge only needs the order of directions
   and whether two are (nearly) equal; its slope is within [0.5, 1] of the angle's, so
   PARALLEL_EPS keeps its meaning to within a factor of two. */
static double pseudo_angle(double x, double y) {
    double p = y / (fabs(x) + fabs(y));
    if (x >= 0.0) return y >= 0.0 ? p : 4.0 + p;
    return 2.0 - p;
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
        double size = greater(fabs(edges[i].x), fabs(edges[i].y));
        if (size > largest) largest = size;
    }
    double threshold = greater(4e-16 * greater(fabs(sx), fabs(sy)), NOISE_EDGE * largest);
    /* Drop vanishing edges and compute directions (as pseudo-angles), per operand. */
    for (int p = 0; p < part_count; p++) {
        Py_ssize_t kept = 0;
        for (Py_ssize_t k = 0; k < length[p]; k++) {
            Edge e = edges[begin[p] + k];
            if (greater(fabs(e.x), fabs(e.y)) <= threshold) continue;
            e.angle = pseudo_angle(e.x, e.y);
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
        for (Py_ssize_t i = 0; i < n; i++) magnitude = greater(magnitude, greater(fabs(v[2 * i]), fabs(v[2 * i + 1])));
        for (Py_ssize_t i = 1; i < n; i++) {
            xmin = lesser(xmin, v[2 * i]);
            xmax = greater(xmax, v[2 * i]);
            ymin = lesser(ymin, v[2 * i + 1]);
            ymax = greater(ymax, v[2 * i + 1]);
        }
        double farthest = FARTHEST_MERGE * greater(xmax - xmin, ymax - ymin);
        for (Py_ssize_t i = 0; i < n; i++) {
            Py_ssize_t next = i + 1 < n ? i + 1 : 0;
            double size = greater(fabs(v[2 * next] - v[2 * i]), fabs(v[2 * next + 1] - v[2 * i + 1]));
            scratch[i] = size;
            if (size > longest) longest = size;
        }
        /* An edge's direction is good to ~1e-16 * |coordinates| / length radians. */
        double extendable = EXTENDABLE * greater(magnitude, longest);
        for (Py_ssize_t i = 0; i < n; i++) blocked[i] = scratch[i] > extendable;
        Py_ssize_t candidates = 0;
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
                if (t[i] >= 0.0 && turn_in >= 0.0 && t[i] * greater(fabs(px), fabs(py)) <= farthest)
                    cost = 0.5 * t[i] * turn_in;
            }
            /* Only removable edges are ranked: the pick stops at the first one that is not. */
            if (cost != HUGE_VAL) {
                ranked[candidates].cost = cost;
                ranked[candidates].index = i;
                candidates++;
            }
        }
        for (Py_ssize_t i = 0; i < n; i++) {
            blocked[i] = 0;
            chosen[i] = 0;
        }
        /* A heap gives the cheapest edges in order without sorting them all. */
        for (Py_ssize_t i = candidates / 2; i-- > 0;) sift_down(ranked, candidates, i);
        Py_ssize_t needed = n - max_vertices, picked = 0, size = candidates;
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

/* Every buffer of a growth of polygons of up to `n_max` vertices, in one block. */
typedef struct {
    char *block;
    double *sector, *disk, *scratch, *t;
    Edge *edges;
    Ranked *ranked;
    char *flags;
    Py_ssize_t capacity;
} Growth;

/* The growth's buffers and, after them, `extra` arrays of capacity points each (their
   first returned in *extra_out); -1 with MemoryError set on failure. */
static int growth_alloc(Growth *g, Py_ssize_t n_max, int extra, double **extra_out) {
    Py_ssize_t capacity = n_max + 2 * FULL_DISK_SIDES + SKITTER_SIDES + 8;
    /* 8-byte items first, the flags last. */
    size_t sector_size = sizeof(double) * 2 * (size_t)(FULL_DISK_SIDES + 40);
    size_t disk_size = sizeof(double) * 2 * SKITTER_SIDES;
    size_t edges_size = sizeof(Edge) * 2 * (size_t)capacity;
    size_t points_size = sizeof(double) * 2 * (size_t)capacity;
    size_t t_size = sizeof(double) * (size_t)capacity;
    size_t ranked_size = sizeof(Ranked) * (size_t)capacity;
    size_t extra_size = points_size * (size_t)extra;
    char *block = PyMem_Malloc(sector_size + disk_size + edges_size + points_size + t_size + ranked_size +
                               extra_size + 2 * (size_t)capacity);
    if (!block) {
        PyErr_NoMemory();
        return -1;
    }
    g->block = block;
    g->capacity = capacity;
    g->sector = (double *)block;
    g->disk = (double *)(block + sector_size);
    g->edges = (Edge *)(block + sector_size + disk_size);
    g->scratch = (double *)(block + sector_size + disk_size + edges_size);
    g->t = (double *)(block + sector_size + disk_size + edges_size + points_size);
    g->ranked = (Ranked *)(block + sector_size + disk_size + edges_size + points_size + t_size);
    *extra_out = (double *)(block + sector_size + disk_size + edges_size + points_size + t_size + ranked_size);
    g->flags = block + sector_size + disk_size + edges_size + points_size + t_size + ranked_size + extra_size;
    return 0;
}

/* One growth (see _growth.grow_polygon) of the n vertices into `out` (room for the
   growth's capacity, not `vertices`' buffer); returns the result's vertex count. */
static Py_ssize_t grow_step(Growth *g, const double *vertices, Py_ssize_t n, double heading_lo, double heading_hi,
                            double turn_min, double turn_max, double drift_max, double chord_min, double run_max,
                            double skitter_radius, Py_ssize_t max_vertices, double *out) {
    const double *parts[3] = {vertices, NULL, NULL};
    Py_ssize_t sizes[3] = {n, 0, 0};
    int part_count = 1;
    if (run_max > 0.0) {
        double start = heading_lo + turn_min - drift_max / 2.0;
        double stop = heading_hi + turn_max + drift_max / 2.0;
        if (heading_hi - heading_lo >= TWO_PI) stop = start + TWO_PI;
        parts[part_count] = g->sector;
        sizes[part_count] = outer_annular_sector(chord_min, run_max, start, stop, g->sector);
        part_count++;
    }
    if (skitter_radius > 0.0) {
        parts[part_count] = g->disk;
        sizes[part_count] = outer_disk(skitter_radius, SKITTER_SIDES, g->disk);
        part_count++;
    }
    if (part_count == 1) {
        memcpy(out, vertices, sizeof(double) * 2 * (size_t)n);
        return n;
    }
    Py_ssize_t m = minkowski_sum(parts, sizes, part_count, g->edges, out);
    if (m > max_vertices)
        m = simplify_outer(out, m, max_vertices, g->t, g->ranked, g->flags, g->flags + g->capacity, g->scratch);
    return m;
}

static PyObject *grow_polygon(PyObject *self, PyObject *args) {
    (void)self;
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
    Growth g;
    double *out;
    if (growth_alloc(&g, n, 1, &out) < 0) {
        PyBuffer_Release(&buffer);
        return NULL;
    }
    Py_ssize_t m = grow_step(&g, (const double *)buffer.buf, n, heading_lo, heading_hi, turn_min, turn_max,
                             drift_max, chord_min, run_max, skitter_radius, max_vertices, out);
    PyObject *result = PyBytes_FromStringAndSize((const char *)out, (Py_ssize_t)(sizeof(double) * 2 * (size_t)m));
    PyMem_Free(g.block);
    PyBuffer_Release(&buffer);
    return result;
}

/* ===========================================================================
 * Compiled kernels of the three landmark reductions.
 *
 * They mirror, operation for operation, the numpy functions of uncertainty/_reduce.py
 * (clip_halfplanes, clip_convex, sector_halfplanes, clip_to_sector, sensor_arc,
 * _sensor_constrained, _bearing_headings, _cone_reduction, reduce_ground_line,
 * cos_range, cap_inside and the tail of reduce_map), geometry/_arcs.py
 * (intersect_arcs, nearest_on_polygon, subtended_arc) and geometry/_convex.py
 * (clip_halfplane, convex_hull, remove_collinear, polygon_area, points_in_convex),
 * which stay the reference implementation and the fallback. One call runs a whole
 * reduction: from the prior's vertices to the reduced vertices, heading arc, centre
 * and areas. Every buffer's capacity is computed from the sizes of its inputs.
 * ========================================================================= */

#define TOLERANCE 1e-9
#define SAME_POINT 1e-12
#define MERGE_EPS 1e-12
#define COLLINEAR_EPS 1e-12
#define TANGENT_STEP (M_PI / 8.0)
#define SENSOR_ARC_SIDES 16


/* Why a reduction is empty: _reduce.py maps these codes to its messages. */
enum {
    NO_POSITION = 0,
    NO_SENSOR_POSITION = 1,
    NO_BEARING_HEADING = 2,
    NO_LINE_HEADING = 3,
    NO_OFFSET_POSITION = 4,
};

/* A polygon (or point list) of n vertices stored x0, y0, x1, y1, ... with room for cap. */
typedef struct {
    double *v;
    Py_ssize_t n, cap;
} Poly;

/* A growable scratch array. */
typedef struct {
    void *data;
    size_t bytes;
} Scratch;

typedef struct {
    double x, y;
} Point;

/* Every buffer one reduction uses; all start empty and are freed by work_free. */
typedef struct {
    Poly ping, pong;       /* clip_halfplanes: alternate clip results */
    Poly part, parts;      /* clip_to_sector: one piece's part, every part */
    Poly arc_points;       /* sensor_arc: the outer arc before its hull */
    Poly arc, mirrored;    /* the sensor arc polygon and its negation */
    Poly sum;              /* Minkowski sums */
    Poly sensors, positions, narrowed;
    Scratch values, flags, cuts, planes, points, edges, lengths;
} Work;

static void work_free(Work *w) {
    Poly *polys[] = {&w->ping,  &w->pong, &w->part,    &w->parts,     &w->arc_points, &w->arc,
                     &w->mirrored, &w->sum, &w->sensors, &w->positions, &w->narrowed};
    Scratch *scratches[] = {&w->values, &w->flags, &w->cuts, &w->planes, &w->points, &w->edges, &w->lengths};
    for (size_t i = 0; i < sizeof(polys) / sizeof(polys[0]); i++) PyMem_Free(polys[i]->v);
    for (size_t i = 0; i < sizeof(scratches) / sizeof(scratches[0]); i++) PyMem_Free(scratches[i]->data);
}

/* Make room for `count` vertices (their values are kept); -1 with MemoryError set on failure. */
static int reserve(Poly *p, Py_ssize_t count) {
    if (count < 1) count = 1;
    if (count <= p->cap) return 0;
    if ((size_t)count > (size_t)PY_SSIZE_T_MAX / (2 * sizeof(double))) {
        PyErr_NoMemory();
        return -1;
    }
    double *grown = PyMem_Realloc(p->v, 2 * sizeof(double) * (size_t)count);
    if (!grown) {
        PyErr_NoMemory();
        return -1;
    }
    p->v = grown;
    p->cap = count;
    return 0;
}

/* Room for `count` items of `size` bytes (old contents are not kept); NULL with MemoryError set. */
static void *scratch(Scratch *s, Py_ssize_t count, size_t size) {
    if (count < 1) count = 1;
    if ((size_t)count > (size_t)PY_SSIZE_T_MAX / size) {
        PyErr_NoMemory();
        return NULL;
    }
    size_t bytes = (size_t)count * size;
    if (bytes <= s->bytes) return s->data;
    PyMem_Free(s->data);
    s->data = PyMem_Malloc(bytes);
    s->bytes = s->data ? bytes : 0;
    if (!s->data) PyErr_NoMemory();
    return s->data;
}

/* Copy n vertices into dst; src must not point into dst's buffer unless it is its start. */
static int copy_into(Poly *dst, const double *src, Py_ssize_t n) {
    if (src != dst->v) {
        if (reserve(dst, n) < 0) return -1;
        if (n > 0) memcpy(dst->v, src, 2 * sizeof(double) * (size_t)n);
    }
    dst->n = n;
    return 0;
}

/* Python's (and numpy's) float remainder: the result takes the divisor's sign. */
static double floor_mod(double a, double b) {
    double mod = fmod(a, b);
    if (mod != 0.0) {
        if ((b < 0.0) != (mod < 0.0)) mod += b;
    } else {
        mod = copysign(0.0, b);
    }
    return mod;
}

/* See _convex.polygon_area. */
static double polygon_area(const double *v, Py_ssize_t n) {
    if (n < 3) return 0.0;
    double x0 = v[0], y0 = v[1], xy = 0.0, yx = 0.0;
    for (Py_ssize_t i = 0; i < n; i++) {
        Py_ssize_t j = i + 1 < n ? i + 1 : 0;
        double x = v[2 * i] - x0, y = v[2 * i + 1] - y0;
        xy += x * (v[2 * j + 1] - y0);
        yx += y * (v[2 * j] - x0);
    }
    return 0.5 * (xy - yx);
}

/* See _convex.remove_collinear; works in place. */
static int remove_collinear(Poly *p, Work *w) {
    Py_ssize_t n = p->n;
    double *v = p->v;
    if (n < 2) return 0;
    double xmin = v[0], xmax = v[0], ymin = v[1], ymax = v[1];
    for (Py_ssize_t i = 1; i < n; i++) {
        xmin = lesser(xmin, v[2 * i]);
        xmax = greater(xmax, v[2 * i]);
        ymin = lesser(ymin, v[2 * i + 1]);
        ymax = greater(ymax, v[2 * i + 1]);
    }
    double span = greater(xmax - xmin, ymax - ymin);
    /* Drop each vertex too close to the next; the write index never passes the read one,
       and the first vertex (which the last edge needs) is saved first. */
    double x0 = v[0], y0 = v[1];
    /* Edge lengths, kept for the straightness test when no vertex goes (the same hypot of
       the same differences). */
    double *lengths = scratch(&w->lengths, n, sizeof(double));
    if (!lengths) return -1;
    Py_ssize_t m = 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        double nx = i + 1 < n ? v[2 * i + 2] : x0, ny = i + 1 < n ? v[2 * i + 3] : y0;
        lengths[i] = hypot(nx - v[2 * i], ny - v[2 * i + 1]);
        if (lengths[i] > MERGE_EPS * span) {
            double x = v[2 * i], y = v[2 * i + 1];
            v[2 * m] = x;
            v[2 * m + 1] = y;
            m++;
        }
    }
    int measured = m == n;
    if (m < n) {
        if (m == 0) {
            v[0] = x0;
            v[1] = y0;
            p->n = 1;
            return 0;
        }
        n = m;
        p->n = n;
    }
    if (n < 3) return 0;
    double magnitude = 0.0;
    for (Py_ssize_t i = 0; i < 2 * n; i++) magnitude = greater(magnitude, fabs(v[i]));
    char *straight = scratch(&w->flags, n, 1);
    if (!straight) return -1;
    Py_ssize_t count = 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        Py_ssize_t prev = i > 0 ? i - 1 : n - 1, next = i + 1 < n ? i + 1 : 0;
        double fx = v[2 * next] - v[2 * i], fy = v[2 * next + 1] - v[2 * i + 1];
        double px = v[2 * i] - v[2 * prev], py = v[2 * i + 1] - v[2 * prev + 1];
        double length = measured ? lengths[i] : hypot(fx, fy);
        double preceding_length = measured ? lengths[prev] : hypot(px, py);
        double turn = px * fy - py * fx;
        double noise =
            COLLINEAR_EPS * length * preceding_length + 1e-15 * magnitude * (length + preceding_length);
        straight[i] = fabs(turn) <= noise && px * fx + py * fy > 0.0;
        count += straight[i];
    }
    if (count == 0) return 0;
    m = 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        if (straight[i]) continue;
        v[2 * m] = v[2 * i];
        v[2 * m + 1] = v[2 * i + 1];
        m++;
    }
    p->n = m;
    return 0;
}

/* Cut point on edge `edge` where the signed value is zero, unless it is the inside end itself. */
static Py_ssize_t cut_point(const double *v, const double *s, Py_ssize_t count, Py_ssize_t edge, double keep_at,
                            double *out, Py_ssize_t m) {
    Py_ssize_t following = edge + 1 < count ? edge + 1 : 0;
    double s0 = s[edge], s1 = s[following];
    double t = s0 / (s0 - s1);
    if (fabs(t - keep_at) <= SAME_POINT) return m;
    double ax = v[2 * edge], ay = v[2 * edge + 1], bx = v[2 * following], by = v[2 * following + 1];
    out[2 * m] = ax + t * (bx - ax);
    out[2 * m + 1] = ay + t * (by - ay);
    return m + 1;
}

/* See _convex.clip_halfplane (and _clip_halfplane_masked): the part of a convex polygon
   where nx x + ny y <= offset, written to `out` (which must not hold `v`). */
static int clip_halfplane(const double *v, Py_ssize_t count, double nx, double ny, double offset, Poly *out,
                          Work *w) {
    double *s = scratch(&w->values, count, sizeof(double));
    if (!s) return -1;
    Py_ssize_t outside = 0;
    for (Py_ssize_t i = 0; i < count; i++) {
        s[i] = v[2 * i] * nx + v[2 * i + 1] * ny - offset;
        outside += s[i] > 0.0;
    }
    if (outside == 0) return copy_into(out, v, count);
    if (outside == count) {
        out->n = 0;
        return 0;
    }
    if (count >= 3) {
        Py_ssize_t found = 0, edges[2] = {0, 0};
        for (Py_ssize_t i = 0; i < count; i++) {
            Py_ssize_t j = i + 1 < count ? i + 1 : 0;
            if ((s[i] > 0.0) != (s[j] > 0.0)) {
                if (found < 2) edges[found] = i;
                found++;
            }
        }
        if (found == 2) {
            /* One entry edge (outside to inside) and one exit edge: keep the run between. */
            Py_ssize_t entry = s[edges[0]] > 0.0 ? edges[0] : edges[1];
            Py_ssize_t exit = s[edges[0]] > 0.0 ? edges[1] : edges[0];
            if (reserve(out, count + 2) < 0) return -1;
            double *o = out->v;
            Py_ssize_t m = cut_point(v, s, count, entry, 1.0, o, 0);
            Py_ssize_t i = entry + 1 < count ? entry + 1 : 0;
            for (;;) {
                o[2 * m] = v[2 * i];
                o[2 * m + 1] = v[2 * i + 1];
                m++;
                if (i == exit) break;
                i = i + 1 < count ? i + 1 : 0;
            }
            out->n = cut_point(v, s, count, exit, 0.0, o, m);
            return 0;
        }
    }
    /* A segment, a point, or rounding on a degenerate polygon: mask every vertex and cut. */
    if (reserve(out, 2 * count) < 0) return -1;
    double *o = out->v;
    Py_ssize_t m = 0;
    for (Py_ssize_t i = 0; i < count; i++) {
        Py_ssize_t j = i + 1 < count ? i + 1 : 0;
        int inside = s[i] <= 0.0, next_inside = s[j] <= 0.0;
        if (inside) {
            o[2 * m] = v[2 * i];
            o[2 * m + 1] = v[2 * i + 1];
            m++;
        }
        if (inside != next_inside) {
            double t = s[i] / (s[i] - s[j]);
            o[2 * m] = v[2 * i] + t * (v[2 * j] - v[2 * i]);
            o[2 * m + 1] = v[2 * i + 1] + t * (v[2 * j + 1] - v[2 * i + 1]);
            m++;
        }
    }
    out->n = m;
    return remove_collinear(out, w);
}

/* See _reduce.clip_halfplanes: planes are (nx, ny, offset) triples. `v` and `out` must not
   be w->ping or w->pong. */
static int clip_halfplanes(const double *v, Py_ssize_t n, const double *planes, Py_ssize_t k, Poly *out,
                           Work *w) {
    if (n == 0) {
        out->n = 0;
        return 0;
    }
    char *cuts = scratch(&w->cuts, k, 1);
    if (!cuts) return -1;
    /* Half-planes are judged on the input polygon: one that holds none of it empties it,
       one that holds all of it holds every part of it too. */
    for (Py_ssize_t j = 0; j < k; j++) {
        double nx = planes[3 * j], ny = planes[3 * j + 1], offset = planes[3 * j + 2];
        int some_inside = 0, some_outside = 0;
        /* Stop once both are seen: min > 0 and max > 0 are then settled. */
        for (Py_ssize_t i = 0; i < n && !(some_inside && some_outside); i++) {
            double s = v[2 * i] * nx + v[2 * i + 1] * ny - offset;
            if (s > 0.0)
                some_outside = 1;
            else
                some_inside = 1;
        }
        if (!some_inside) {
            out->n = 0;
            return 0;
        }
        cuts[j] = (char)some_outside;
    }
    const double *current = v;
    Py_ssize_t current_n = n;
    Poly *target = &w->ping, *spare = &w->pong;
    for (Py_ssize_t j = 0; j < k; j++) {
        if (!cuts[j]) continue;
        if (clip_halfplane(current, current_n, planes[3 * j], planes[3 * j + 1], planes[3 * j + 2], target, w) < 0)
            return -1;
        current = target->v;
        current_n = target->n;
        Poly *swap = target;
        target = spare;
        spare = swap;
        if (current_n == 0) break;
    }
    return copy_into(out, current, current_n);
}

/* See _reduce.clip_convex: `v` clipped by `other` widened by `margin`. */
static int clip_convex(const double *v, Py_ssize_t n, const double *other, Py_ssize_t m, double margin, Poly *out,
                       Work *w) {
    double *planes = scratch(&w->planes, 3 * m, sizeof(double));
    if (!planes) return -1;
    double magnitude = 1.0;
    for (Py_ssize_t i = 0; i < 2 * m; i++) magnitude = greater(magnitude, fabs(other[i]));
    Py_ssize_t k = 0;
    for (Py_ssize_t i = 0; i < m; i++) {
        Py_ssize_t j = i + 1 < m ? i + 1 : 0;
        double ex = other[2 * j] - other[2 * i], ey = other[2 * j + 1] - other[2 * i + 1];
        double length = hypot(ex, ey);
        /* Edges too short for a reliable direction are left out: that only loosens the bound. */
        if (!(length > 1e-9 * magnitude)) continue;
        double nx = ey / length, ny = -ex / length;
        planes[3 * k] = nx;
        planes[3 * k + 1] = ny;
        planes[3 * k + 2] = nx * other[2 * i] + ny * other[2 * i + 1] + margin;
        k++;
    }
    return clip_halfplanes(v, n, planes, k, out, w);
}

static int compare_points(const void *a, const void *b) {
    const Point *p = a, *q = b;
    if (p->x != q->x) return (p->x > q->x) - (p->x < q->x);
    return (p->y > q->y) - (p->y < q->y);
}

/* See _convex.convex_hull (Andrew's monotone chain); `pts` must not be in `out`'s buffer. */
static int convex_hull(const double *pts, Py_ssize_t m, Poly *out, Work *w) {
    Point *p = scratch(&w->points, m, sizeof(Point));
    if (!p) return -1;
    for (Py_ssize_t i = 0; i < m; i++) {
        p[i].x = pts[2 * i];
        p[i].y = pts[2 * i + 1];
    }
    qsort(p, (size_t)m, sizeof(Point), compare_points);
    Py_ssize_t u = 0;
    for (Py_ssize_t i = 0; i < m; i++)
        if (u == 0 || p[i].x != p[u - 1].x || p[i].y != p[u - 1].y) p[u++] = p[i];
    if (reserve(out, 2 * u) < 0) return -1;
    double *h = out->v;
    if (u <= 2) {
        for (Py_ssize_t i = 0; i < u; i++) {
            h[2 * i] = p[i].x;
            h[2 * i + 1] = p[i].y;
        }
        out->n = u;
        return 0;
    }
    Py_ssize_t size = 0;
    for (Py_ssize_t i = 0; i < u; i++) {
        while (size >= 2) {
            double ax = h[2 * size - 4], ay = h[2 * size - 3], bx = h[2 * size - 2], by = h[2 * size - 1];
            if ((bx - ax) * (p[i].y - ay) - (by - ay) * (p[i].x - ax) > 0.0) break;
            size--;
        }
        h[2 * size] = p[i].x;
        h[2 * size + 1] = p[i].y;
        size++;
    }
    /* The upper chain overwrites the lower one's last vertex, which the hull drops anyway. */
    Py_ssize_t base = size - 1, upper = 0;
    for (Py_ssize_t i = u; i-- > 0;) {
        while (upper >= 2) {
            double *a = h + 2 * (base + upper - 2), *b = h + 2 * (base + upper - 1);
            if ((b[0] - a[0]) * (p[i].y - a[1]) - (b[1] - a[1]) * (p[i].x - a[0]) > 0.0) break;
            upper--;
        }
        h[2 * (base + upper)] = p[i].x;
        h[2 * (base + upper) + 1] = p[i].y;
        upper++;
    }
    out->n = base + upper - 1;
    return remove_collinear(out, w);
}

/* See _convex.minkowski_sum, for two operands; neither may be in `out`'s buffer. */
static int minkowski_pair(const double *a, Py_ssize_t na, const double *b, Py_ssize_t nb, Poly *out, Work *w) {
    Edge *edges = scratch(&w->edges, 2 * (na + nb), sizeof(Edge));
    if (!edges || reserve(out, na + nb) < 0) return -1;
    const double *parts[3] = {a, b, NULL};
    Py_ssize_t sizes[3] = {na, nb, 0};
    out->n = minkowski_sum(parts, sizes, 2, edges, out->v);
    return 0;
}

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
    /* outer_arc writes max(1, ceil((stop - lo) / ARC_STEP)) + 2 points. */
    double steps = ceil((stop - lo) / ARC_STEP);
    if (reserve(&w->arc_points, (steps > 1.0 ? (Py_ssize_t)steps : 1) + 2) < 0) return -1;
    w->arc_points.n = outer_arc(radius, lo, stop, w->arc_points.v);
    return convex_hull(w->arc_points.v, w->arc_points.n, out, w) < 0 ? -1 : 1;
}

/* See _arcs.nearest_on_polygon. */
static void nearest_on_polygon(const double *v, Py_ssize_t n, double px, double py, double *distance, double *qx,
                               double *qy) {
    if (n == 1) {
        *distance = hypot(px - v[0], py - v[1]);
        *qx = v[0];
        *qy = v[1];
        return;
    }
    if (n >= 3) {
        double lowest = HUGE_VAL, highest = -HUGE_VAL;
        for (Py_ssize_t i = 0; i < n; i++) {
            Py_ssize_t j = i + 1 < n ? i + 1 : 0;
            double ex = v[2 * j] - v[2 * i], ey = v[2 * j + 1] - v[2 * i + 1];
            double side = ex * (py - v[2 * i + 1]) - ey * (px - v[2 * i]);
            lowest = lesser(lowest, side);
            highest = greater(highest, side);
        }
        if (lowest >= 0.0 && highest > 0.0) {
            *distance = 0.0;
            *qx = px;
            *qy = py;
            return;
        }
    }
    Py_ssize_t best = 0;
    double best_squared = HUGE_VAL, best_t = 0.0;
    for (Py_ssize_t i = 0; i < n; i++) {
        Py_ssize_t j = i + 1 < n ? i + 1 : 0;
        double ex = v[2 * j] - v[2 * i], ey = v[2 * j + 1] - v[2 * i + 1];
        double rx = px - v[2 * i], ry = py - v[2 * i + 1];
        double squared = ex * ex + ey * ey;
        double t = squared > 0.0 ? (rx * ex + ry * ey) / squared : 0.0;
        t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
        double gx = rx - t * ex, gy = ry - t * ey;
        double gap = gx * gx + gy * gy;
        if (i == 0 || gap < best_squared) {
            best = i;
            best_squared = gap;
            best_t = t;
        }
    }
    Py_ssize_t j = best + 1 < n ? best + 1 : 0;
    *distance = sqrt(best_squared);
    *qx = v[2 * best] + best_t * (v[2 * j] - v[2 * best]);
    *qy = v[2 * best + 1] + best_t * (v[2 * j + 1] - v[2 * best + 1]);
}

/* See _arcs.subtended_arc. */
static void subtended_arc(const double *v, Py_ssize_t n, double px, double py, double radius, double *lo,
                          double *width) {
    double distance, qx, qy;
    nearest_on_polygon(v, n, px, py, &distance, &qx, &qy);
    if (distance <= radius) {
        *lo = 0.0;
        *width = TWO_PI;
        return;
    }
    /* The polygon does not hold the point: its directions unwrap around the first one's. */
    double reference = atan2(v[1] - py, v[0] - px);
    double lowest = HUGE_VAL, highest = -HUGE_VAL;
    for (Py_ssize_t i = 0; i < n; i++) {
        double angle = atan2(v[2 * i + 1] - py, v[2 * i] - px);
        angle = floor_mod(angle - (reference - M_PI), TWO_PI) - M_PI;
        lowest = lesser(lowest, angle);
        highest = greater(highest, angle);
    }
    double spread = radius > 0.0 ? asin(radius / distance) : 0.0;
    double low = reference + lowest - spread, high = reference + highest + spread;
    *lo = low;
    *width = high - low;
}

/* See _arcs.intersect_arcs: 1 with the result in (lo, width), 0 when the arcs do not meet. */
static int intersect_arcs(double a_lo, double a_width, double b_lo, double b_width, double *lo, double *width) {
    if (b_width >= TWO_PI) {
        *lo = a_lo;
        *width = TWO_PI < a_width ? TWO_PI : a_width;
        return 1;
    }
    if (a_width >= TWO_PI) {
        *lo = b_lo;
        *width = b_width;
        return 1;
    }
    double d = floor_mod(b_lo - a_lo, TWO_PI), shifts[2] = {d, d - TWO_PI};
    double first = HUGE_VAL, last = -HUGE_VAL;
    int found = 0;
    for (int k = 0; k < 2; k++) {
        double start = shifts[k] > 0.0 ? shifts[k] : 0.0;
        double stop = shifts[k] + b_width < a_width ? shifts[k] + b_width : a_width;
        if (start <= stop) {
            first = found ? lesser(first, start) : start;
            last = found ? greater(last, stop) : stop;
            found = 1;
        }
    }
    if (!found) return 0;
    *lo = a_lo + first;
    *width = last - first;
    return 1;
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

/* See _convex.distance_to_boundary, for one point. */
static double distance_to_boundary(const double *v, Py_ssize_t n, double x, double y) {
    if (n == 1) return hypot(x - v[0], y - v[1]);
    double best = HUGE_VAL;
    for (Py_ssize_t i = 0; i < n; i++) {
        Py_ssize_t j = i + 1 < n ? i + 1 : 0;
        double ex = v[2 * j] - v[2 * i], ey = v[2 * j + 1] - v[2 * i + 1];
        double rx = x - v[2 * i], ry = y - v[2 * i + 1];
        double squared = ex * ex + ey * ey;
        double t = squared > 0.0 ? (rx * ex + ry * ey) / squared : 0.0;
        t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
        best = lesser(best, hypot(x - (v[2 * i] + t * ex), y - (v[2 * i + 1] + t * ey)));
    }
    return best;
}

/* See _convex.points_in_convex (its dense test), for one point. `lengths` holds the
   polygon's edge lengths (hypot of each edge, computed once per polygon) when it is solid,
   NULL when it is not. */
static int point_in_convex(const double *v, Py_ssize_t n, const double *lengths, double x, double y,
                           double tolerance) {
    if (!lengths) return distance_to_boundary(v, n, x, y) <= tolerance;
    for (Py_ssize_t i = 0; i < n; i++) {
        Py_ssize_t j = i + 1 < n ? i + 1 : 0;
        double ex = v[2 * j] - v[2 * i], ey = v[2 * j + 1] - v[2 * i + 1];
        double signed_distance = (ex * (y - v[2 * i + 1]) - ey * (x - v[2 * i])) / lengths[i];
        if (!(signed_distance >= -tolerance)) return 0;
    }
    return 1;
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

/* --- argument parsing and results -------------------------------------------------- */

static int parse_doubles(PyObject *const *args, Py_ssize_t count, const char *const *names, double *values) {
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

static int parse_cap(PyObject *arg, Py_ssize_t *max_vertices) {
    *max_vertices = PyNumber_AsSsize_t(arg, PyExc_OverflowError);
    if (*max_vertices == -1 && PyErr_Occurred()) return -1;
    if (*max_vertices < 3) {
        PyErr_Format(PyExc_ValueError, "max_vertices: expected at least 3, got %zd", *max_vertices);
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

/* Get the prior's vertices: a C-contiguous float64 buffer of n >= 1 (x, y) rows. */
static int get_vertices(PyObject *object, Py_buffer *view, Py_ssize_t *n) {
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

/* The tail of _reduce.reduce_map: the vertex cap, the centre update and both areas; returns
   (vertex bytes, arc lo, arc width, centre x, centre y, area before, area after). */
static PyObject *finish(Poly *positions, const double *prior, Py_ssize_t n, Py_ssize_t max_vertices,
                        double center_x, double center_y, double arc_lo, double arc_width) {
    if (positions->n > max_vertices && cap_inside(positions, prior, n, max_vertices) < 0) return NULL;
    double distance, x, y;
    nearest_on_polygon(positions->v, positions->n, center_x, center_y, &distance, &x, &y);
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

static PyObject *reduce_cone(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    (void)self;
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
    if (!(a[14] > 0.0)) {
        PyErr_Format(PyExc_ValueError, "piece: expected a positive angle, got %R", args[15]);
        return NULL;
    }
    Py_buffer view;
    if (get_vertices(args[0], &view, &n) < 0) return NULL;
    const double *prior = (const double *)view.buf;
    Work w;
    memset(&w, 0, sizeof(w));
    PyObject *result = NULL;
    double heading_lo, heading_width, arc_lo = 0.0, arc_width = 0.0;
    wedge_arc(a[2], a[3], a[4], &heading_lo, &heading_width);
    /* The landmark is seen towards h + bearing, so the sensor lies from the landmark
       towards h + bearing + pi, for some heading h of the wedge and bearing error. */
    double margin = a[11] + TOLERANCE;
    Cone cone = {a[7], a[8], a[9], heading_lo + a[10] + M_PI - margin, heading_width + 2.0 * margin,
                 a[12], a[13], a[14]};
    int reason = -1;
    Poly *positions = NULL;
    if (cone_reduction(prior, n, heading_lo, heading_width, a[5], a[6], a[10], a[11], &cone, &w, &reason,
                       &positions, &arc_lo, &arc_width) < 0)
        goto done;
    if (reason >= 0)
        result = PyLong_FromLong(reason);
    else
        result = finish(positions, prior, n, max_vertices, a[0], a[1], arc_lo, arc_width);
done:
    work_free(&w);
    PyBuffer_Release(&view);
    return result;
}

static PyObject *reduce_strip(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    (void)self;
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
    Work w;
    memset(&w, 0, sizeof(w));
    PyObject *result = NULL;
    double heading_lo, heading_width, arc_lo = 0.0, arc_width = 0.0;
    wedge_arc(a[2], a[3], a[4], &heading_lo, &heading_width);
    int reason = -1;
    if (strip_reduction(prior, n, heading_lo, heading_width, a[5], a[6], a[7], a[8], a[9], a[10], a[11], a[12],
                        a[13], a[14], a[15], &w.positions, &w, &reason, &arc_lo, &arc_width) < 0)
        goto done;
    if (reason >= 0)
        result = PyLong_FromLong(reason);
    else
        result = finish(&w.positions, prior, n, max_vertices, a[0], a[1], arc_lo, arc_width);
done:
    work_free(&w);
    PyBuffer_Release(&view);
    return result;
}

/* ===========================================================================
 * Compiled kernels of the Expecter and of the find-landmark schemas' activation test.
 *
 * expecter_points mirrors, operation for operation, expecter/_expecter.py
 * (_landmark_geometry, _relative_ground, _clip_to_front and the normalization in
 * Expecter.bounds), which stays the reference implementation and the fallback. The
 * three Minkowski operands (the landmark's base, the outer polygon of its position
 * disk and the negated map polygon) are merged in one pass instead of two.
 * polygon_distance is the distance shapely gives between a convex polygon (a point
 * or a segment when degenerate) and a segment (a point when both ends agree).
 * ========================================================================= */

static int parse_count(PyObject *arg, const char *name, Py_ssize_t low, Py_ssize_t high, Py_ssize_t *value) {
    *value = PyNumber_AsSsize_t(arg, PyExc_OverflowError);
    if (*value == -1 && PyErr_Occurred()) return -1;
    if (*value < low || *value > high) {
        PyErr_Format(PyExc_ValueError, "%s: expected an integer in [%zd, %zd], got %zd", name, low, high, *value);
        return -1;
    }
    return 0;
}

/* Camera-frame point of a robot-frame ground point (x, y) raised by dz (see _clip_to_front). */
static void to_camera(const double *r, double forward, double left, double x, double y, double dz, double *out) {
    double px = x - forward, py = y - left;
    for (int j = 0; j < 3; j++) out[j] = px * r[j] + py * r[3 + j] + dz * r[6 + j];
}

static PyObject *expecter_points(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    (void)self;
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
    if (!(radius >= 0.0) || !(width >= 0.0) || !(arc_step > 0.0) || !(dz_lo <= dz_hi)) {
        PyErr_SetString(PyExc_ValueError,
                        "expected radius >= 0, heading_width >= 0, arc_step > 0 and dz_lo <= dz_hi");
        return NULL;
    }
    Py_buffer view;
    if (get_vertices(args[0], &view, &n) < 0) return NULL;
    const double *polygon = (const double *)view.buf;
    Work w;
    memset(&w, 0, sizeof(w));
    PyObject *result = NULL;
    double *disk = NULL, *negated = NULL, *camera = NULL, *normalized = NULL;

    /* D = base (+) disk (+) (-P): robot-independent differences q - p (_relative_ground). */
    double base[4] = {a[0], a[1], a[2], a[3]};
    Py_ssize_t sides = radius > 0.0 ? disk_sides : 0, total = base_count + sides + n;
    disk = PyMem_Malloc(sizeof(double) * 2 * (size_t)(sides > 0 ? sides : 1));
    negated = PyMem_Malloc(sizeof(double) * 2 * (size_t)n);
    Edge *edges = scratch(&w.edges, 2 * total, sizeof(Edge));
    if (!disk || !negated) {
        PyErr_NoMemory();
        goto done;
    }
    if (!edges || reserve(&w.sum, total) < 0) goto done;
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
    Py_ssize_t m = minkowski_sum(parts, sizes, part_count, edges, w.sum.v);
    const double *d = w.sum.v;

    /* Robot-frame points whose hull holds R(-h) d for every d in D and h in the wedge. */
    Poly *rel = &w.ping;
    if (full_circle) {
        double reach = 0.0;
        for (Py_ssize_t i = 0; i < m; i++) reach = greater(reach, hypot(d[2 * i], d[2 * i + 1]));
        Py_ssize_t count = (Py_ssize_t)ceil(TWO_PI / arc_step);
        if (reserve(rel, count) < 0) goto done;
        if (reach <= 0.0) {
            rel->v[0] = 0.0;
            rel->v[1] = 0.0;
            rel->n = 1;
        } else {
            rel->n = outer_disk(reach, count, rel->v);
        }
    } else {
        Py_ssize_t count = 0;
        if (width > 0.0) {
            double steps = ceil(width / arc_step);
            count = steps > 1.0 ? (Py_ssize_t)steps : 1;
        }
        Py_ssize_t per = width > 0.0 ? 2 + count : 1;
        if (reserve(rel, m * per) < 0) goto done;
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
        if (convex_hull(rel->v, rel->n, &w.pong, &w) < 0) goto done;
        Py_ssize_t h = w.pong.n, layer = h, edge_count = 0;
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
                to_camera(r, forward, left, w.pong.v[2 * i], w.pong.v[2 * i + 1], levels[l],
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
    work_free(&w);
    PyBuffer_Release(&view);
    return result;
}

/* Distance from the point p to the segment [a, b] (a point when a == b). */
static double point_to_segment(double px, double py, double ax, double ay, double bx, double by) {
    double ex = bx - ax, ey = by - ay, rx = px - ax, ry = py - ay;
    double squared = ex * ex + ey * ey;
    double t = squared > 0.0 ? (rx * ex + ry * ey) / squared : 0.0;
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
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

static PyObject *polygon_distance(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
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

/* ===========================================================================
 * A run of growths on one terrain: _growth.motion_bounds, SpatialUncertaintyMap.grow
 * (polygon, _growth.grow_wedge, centre) and HeadingWedge._trusted's wrap, operation for
 * operation, for each command in turn. One call replaces a Python loop of grows.
 * ========================================================================= */

/* _growth._clip */
static double clip_to(double value, double lo, double hi) { return value < lo ? lo : value > hi ? hi : value; }

/* HeadingWedge._trusted's wrap of an unwrapped centre to (-pi, pi]. */
static double wrap_center(double center) {
    double wrapped = M_PI - floor_mod(M_PI - center, TWO_PI);
    return wrapped <= -M_PI ? wrapped + TWO_PI : wrapped;
}

static PyObject *grow_commands(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    (void)self;
    static const char *const names[] = {
        "center_x",      "center_y",      "wedge_center",    "wedge_cw",      "wedge_ccw",
        "rotation_loss", "rotation_sd",   "translation_loss", "translation_sd", "translation_inertial_loss",
        "drift",         "skitter",       "skitter_sd",      "sigmas"};
    enum { DOUBLES = sizeof(names) / sizeof(names[0]) };
    if (nargs != DOUBLES + 3) {
        PyErr_Format(PyExc_TypeError, "grow_commands: expected %d arguments, got %zd", DOUBLES + 3, nargs);
        return NULL;
    }
    double a[DOUBLES];
    Py_ssize_t max_vertices, n;
    if (parse_doubles(args + 1, DOUBLES, names, a) < 0 || parse_cap(args[DOUBLES + 2], &max_vertices) < 0)
        return NULL;
    PyObject *commands = PySequence_Fast(args[DOUBLES + 1], "commands: expected a sequence of numbers");
    if (!commands) return NULL;
    Py_ssize_t values = PySequence_Fast_GET_SIZE(commands);
    if (values % 2 != 0) {
        PyErr_Format(PyExc_ValueError, "commands: expected (turn, run) pairs, got %zd numbers", values);
        Py_DECREF(commands);
        return NULL;
    }
    Py_buffer view;
    if (get_vertices(args[0], &view, &n) < 0) {
        Py_DECREF(commands);
        return NULL;
    }
    PyObject *result = NULL;
    Growth g = {0};
    double *ping;
    /* The polygon alternates between two buffers, each with the growth's capacity. */
    if (growth_alloc(&g, n > max_vertices ? n : max_vertices, 2, &ping) < 0) goto done;
    double *pong = ping + 2 * g.capacity;
    memcpy(ping, view.buf, sizeof(double) * 2 * (size_t)n);
    double x = a[0], y = a[1], center = a[2], cw = a[3], ccw = a[4];
    const double rotation_loss = a[5], rotation_sd = a[6], translation_loss = a[7], translation_sd = a[8];
    const double inertial = a[9], drift = a[10], skitter = a[11], skitter_sd = a[12], sigmas = a[13];
    double unwrapped = center;
    PyObject **items = PySequence_Fast_ITEMS(commands);
    for (Py_ssize_t i = 0; i < values; i += 2) {
        double turn = PyFloat_AsDouble(items[i]), run = PyFloat_AsDouble(items[i + 1]);
        if (PyErr_Occurred()) goto done;
        if (!isfinite(turn) || !isfinite(run)) {
            PyErr_Format(PyExc_ValueError, "commands: expected finite numbers, got %R, %R at pair %zd", items[i],
                         items[i + 1], i / 2);
            goto done;
        }
        /* _growth.motion_bounds */
        double rotation_kept = 1.0 - rotation_loss, rotation_spread = sigmas * rotation_sd;
        double fraction_lo = clip_to(rotation_kept - rotation_spread, 0.0, 1.0);
        double fraction_hi = clip_to(rotation_kept + rotation_spread, 0.0, 1.0);
        double fraction_mean = clip_to(rotation_kept, 0.0, 1.0);
        double ta = turn * fraction_lo, tb = turn * fraction_hi;
        double run_kept = 1.0 - translation_loss, run_spread = sigmas * translation_sd;
        double run_lo = clip_to(run * (run_kept - run_spread) - inertial, 0.0, run);
        double run_hi = clip_to(run * (run_kept + run_spread) - inertial, 0.0, run);
        double run_mean = clip_to(run * run_kept - inertial, 0.0, run);
        double drift_max = drift * run_hi, chord_min;
        if (drift == 0.0)
            chord_min = run_lo;
        else if (drift_max <= M_PI)
            chord_min = 2.0 * sin(drift * run_lo / 2.0) / drift;
        else
            chord_min = 0.0;
        double turn_min = lesser(ta, tb), turn_max = greater(ta, tb), turn_mean = turn * fraction_mean;
        double skitter_bound = skitter + sigmas * skitter_sd;
        double skitter_radius = fabs(turn) * (skitter_bound > 0.0 ? skitter_bound : 0.0);
        /* SpatialUncertaintyMap.grow */
        double heading_lo = center - cw;
        n = grow_step(&g, ping, n, heading_lo, heading_lo + cw + ccw, turn_min, turn_max, drift_max, chord_min,
                      run_hi, skitter_radius, max_vertices, pong);
        double *swap = ping;
        ping = pong;
        pong = swap;
        /* _growth.grow_wedge */
        unwrapped = center + turn_mean;
        double new_cw = cw + (turn_mean - turn_min) + drift_max;
        double new_ccw = ccw + (turn_max - turn_mean) + drift_max;
        if (new_cw + new_ccw >= TWO_PI) {
            cw = M_PI;
            ccw = M_PI;
        } else {
            cw = new_cw;
            ccw = new_ccw;
        }
        x = x + run_mean * cos(unwrapped);
        y = y + run_mean * sin(unwrapped);
        center = wrap_center(unwrapped);
    }
    /* The last centre unwrapped: HeadingWedge._trusted wraps it (wrapping twice may move it). */
    result = Py_BuildValue("(y#ddddd)", (const char *)ping, (Py_ssize_t)(sizeof(double) * 2 * (size_t)n), x, y,
                           unwrapped, cw, ccw);
done:
    if (g.block) PyMem_Free(g.block);
    PyBuffer_Release(&view);
    Py_DECREF(commands);
    return result;
}

static PyMethodDef methods[] = {
    {"grow_polygon", grow_polygon, METH_VARARGS,
     "grow_polygon(vertices, heading_lo, heading_hi, turn_min, turn_max, drift_max, chord_min, run_max, "
     "skitter_radius, max_vertices) -> bytes of (m, 2) float64 vertices"},
    {"reduce_cone", (PyCFunction)(void (*)(void))reduce_cone, METH_FASTCALL,
     "reduce_cone(vertices, center_x, center_y, wedge_center, wedge_cw, wedge_ccw, forward, left, landmark_x, "
     "landmark_y, widen, bearing, bearing_error, range_min, range_max, piece, max_vertices) -> (vertex bytes, "
     "arc_lo, arc_width, center_x, center_y, area_before, area_after), or an int reason code"},
    {"reduce_strip", (PyCFunction)(void (*)(void))reduce_strip, METH_FASTCALL,
     "reduce_strip(vertices, center_x, center_y, wedge_center, wedge_cw, wedge_ccw, forward, left, start_x, "
     "start_y, end_x, end_y, position_uncertainty, offset, offset_error, angle, angle_error, max_vertices) -> "
     "(vertex bytes, arc_lo, arc_width, center_x, center_y, area_before, area_after), or an int reason code"},
    {"expecter_points", (PyCFunction)(void (*)(void))expecter_points, METH_FASTCALL,
     "expecter_points(vertices, base_count, disk_sides, full_circle, level_count, base_ax, base_ay, base_bx, "
     "base_by, radius, heading_lo, heading_width, arc_step, r00, r01, r02, r10, r11, r12, r20, r21, r22, forward, "
     "left, dz_lo, dz_hi, cut_plane) -> None (behind the camera) or (bytes of (k, 2) float64 normalized points, "
     "x_min, y_min, x_max, y_max)"},
    {"grow_commands", (PyCFunction)(void (*)(void))grow_commands, METH_FASTCALL,
     "grow_commands(vertices, center_x, center_y, wedge_center, wedge_cw, wedge_ccw, rotation_loss, rotation_sd, "
     "translation_loss, translation_sd, translation_inertial_loss, drift, skitter, skitter_sd, sigmas, commands, "
     "max_vertices) -> (vertex bytes, center_x, center_y, wedge_center unwrapped, wedge_cw, wedge_ccw) after "
     "growing by each (turn, run) of the flat sequence commands in turn"},
    {"polygon_distance", (PyCFunction)(void (*)(void))polygon_distance, METH_FASTCALL,
     "polygon_distance(vertices, ax, ay, bx, by) -> distance from the convex polygon to the segment [a, b]"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_kernels",
    "Compiled kernels of the growth step and the landmark reductions (see _convex.py and _reduce.py for the "
    "reference implementations).",
    -1, methods, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__kernels(void) { return PyModule_Create(&module); }
