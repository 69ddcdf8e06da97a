/*
 * Polygon primitives shared by the kernels. Each mirrors, operation for operation, its
 * numpy reference in geometry/_convex.py (outer_arc, outer_disk, outer_annular_sector,
 * minkowski_sum, simplify_outer with _support_polygon, polygon_area, remove_collinear,
 * clip_halfplane, convex_hull, points_in_convex, distance_to_boundary) or
 * geometry/_arcs.py (nearest_on_polygon, subtended_arc, intersect_arcs), or in
 * _native/_reduce.py (clip_halfplanes, clip_convex). Every function writes only into
 * buffers whose size its documented contract (kernels.h) ties to its inputs.
 */
#include "kernels.h"

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


Py_ssize_t arc_pieces(double width, double step) {
    double pieces = ceil(width / step);
    /* NaN and anything below one piece give one; the cap only keeps the cast defined, a
       caller's width below 2 pi never reaches it. */
    if (!(pieces > 1.0)) return 1;
    return pieces < (double)(1 << 30) ? (Py_ssize_t)pieces : (Py_ssize_t)1 << 30;
}

/* Outer polygon of the arc of `radius` from `start` to `stop` (see _convex.outer_arc);
   writes arc_pieces(stop - start, ARC_STEP) + 2 points. */
Py_ssize_t outer_arc(double radius, double start, double stop, double *out) {
    double width = stop - start;
    Py_ssize_t count = arc_pieces(width, ARC_STEP);
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

Py_ssize_t outer_disk(double radius, Py_ssize_t sides, double *out) {
    double reach = radius / cos(M_PI / (double)sides);
    for (Py_ssize_t j = 0; j < sides; j++) {
        double angle = (double)j * (TWO_PI / (double)sides);
        out[2 * j] = reach * cos(angle);
        out[2 * j + 1] = reach * sin(angle);
    }
    return sides;
}

/* See _convex.outer_annular_sector. */
Py_ssize_t outer_annular_sector(double inner, double outer, double start, double stop, double *out) {
    double width = stop - start;
    if (outer <= 0.0) {
        out[0] = 0.0;
        out[1] = 0.0;
        return 1;
    }
    /* NaN (from infinite bounds) takes the disk too: outer_arc needs a width below 2 pi. */
    if (!(width < TWO_PI)) return outer_disk(outer, FULL_DISK_SIDES, out);
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

/* A total order of doubles, NaN last: qsort needs one even when overflow made a NaN. */
static int total_order(double a, double b) {
    int a_nan = a != a, b_nan = b != b;
    if (a_nan || b_nan) return a_nan - b_nan;
    return (a > b) - (a < b);
}

static int compare_angles(const void *a, const void *b) {
    return total_order(((const Edge *)a)->angle, ((const Edge *)b)->angle);
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
Py_ssize_t minkowski_sum(const double **parts, const Py_ssize_t *sizes, int part_count, Edge *edges, double *out) {
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

/* The bounding box of n >= 1 points: box = {xmin, ymin, xmax, ymax}. */
static void bounding_box(const double *v, Py_ssize_t n, double *box) {
    box[0] = box[2] = v[0];
    box[1] = box[3] = v[1];
    for (Py_ssize_t i = 1; i < n; i++) {
        box[0] = lesser(box[0], v[2 * i]);
        box[2] = greater(box[2], v[2 * i]);
        box[1] = lesser(box[1], v[2 * i + 1]);
        box[3] = greater(box[3], v[2 * i + 1]);
    }
}

/* See _convex._support_polygon: the intersection of the half-planes that support the
   polygon in `count` directions evenly spaced from its longest edge's outward normal, an
   outer polygon of at most `count` (< n) vertices. Works in place; `h` holds `count`
   doubles and `out` 2 `count`. Returns the new vertex count. */
static Py_ssize_t support_polygon(double *v, Py_ssize_t n, Py_ssize_t count, double *h, double *out) {
    double box[4];
    bounding_box(v, n, box);
    double cx = 0.5 * (box[0] + box[2]), cy = 0.5 * (box[1] + box[3]);
    double span = greater(box[2] - box[0], box[3] - box[1]);
    /* Above the rounding of the projections and of the corners, and of adding c back. */
    double margin = SUPPORT_MARGIN * greater(span, greater(fabs(cx), fabs(cy)));
    Py_ssize_t longest = 0;
    double best = -1.0;
    for (Py_ssize_t i = 0; i < n; i++) {
        Py_ssize_t j = i + 1 < n ? i + 1 : 0;
        double length = hypot(v[2 * j] - v[2 * i], v[2 * j + 1] - v[2 * i + 1]);
        if (length > best) {
            best = length;
            longest = i;
        }
    }
    Py_ssize_t after = longest + 1 < n ? longest + 1 : 0;
    double start = atan2(-(v[2 * after] - v[2 * longest]), v[2 * after + 1] - v[2 * longest + 1]);
    double step = TWO_PI / (double)count;
    /* Normals into `out`, support values (relative to c) into `h`. */
    for (Py_ssize_t j = 0; j < count; j++) {
        double angle = start + (double)j * step;
        double nx = cos(angle), ny = sin(angle), reach = -HUGE_VAL;
        for (Py_ssize_t i = 0; i < n; i++) reach = greater(reach, nx * (v[2 * i] - cx) + ny * (v[2 * i + 1] - cy));
        out[2 * j] = nx;
        out[2 * j + 1] = ny;
        h[j] = reach + margin;
    }
    /* Corner j joins the lines of directions j and j + 1; the first normal is kept aside,
       since corner j overwrites normal j. */
    double first_x = out[0], first_y = out[1];
    for (Py_ssize_t j = 0; j < count; j++) {
        int last = j + 1 == count;
        double ax = out[2 * j], ay = out[2 * j + 1], ha = h[j];
        double bx = last ? first_x : out[2 * j + 2], by = last ? first_y : out[2 * j + 3], hb = h[last ? 0 : j + 1];
        double det = ax * by - ay * bx;
        out[2 * j] = (ha * by - hb * ay) / det + cx;
        out[2 * j + 1] = (ax * hb - bx * ha) / det + cy;
    }
    /* Lines that touch the polygon where their neighbours meet give repeated corners. */
    double close = MERGE_EPS * span;
    Py_ssize_t m = 0;
    for (Py_ssize_t j = 0; j < count; j++) {
        if (m > 0 && greater(fabs(out[2 * j] - v[2 * m - 2]), fabs(out[2 * j + 1] - v[2 * m - 1])) <= close) continue;
        v[2 * m] = out[2 * j];
        v[2 * m + 1] = out[2 * j + 1];
        m++;
    }
    while (m > 1 && greater(fabs(v[2 * m - 2] - v[0]), fabs(v[2 * m - 1] - v[1])) <= close) m--;
    return m;
}

/* See _convex.simplify_outer; works in place, returns the new vertex count, at most
   max(max_vertices, 3): when merging edges leaves more, the support polygon follows. */
Py_ssize_t simplify_outer(double *v, Py_ssize_t n, Py_ssize_t max_vertices, double *t, Ranked *ranked,
                          char *blocked, char *chosen, double *scratch) {
    Py_ssize_t floor_count = max_vertices > 3 ? max_vertices : 3;
    while (n > floor_count) {
        /* Edges too short for their direction to be accurate are never extended to
           replace a removed neighbour (see _convex.simplify_outer). */
        double longest = 0.0, magnitude = 0.0, box[4];
        for (Py_ssize_t i = 0; i < n; i++) magnitude = greater(magnitude, greater(fabs(v[2 * i]), fabs(v[2 * i + 1])));
        bounding_box(v, n, box);
        double farthest = FARTHEST_MERGE * greater(box[2] - box[0], box[3] - box[1]);
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
    if (n > floor_count) n = support_polygon(v, n, floor_count, t, scratch);
    return n;
}

/* Every buffer of a Work, for work_free, work_take and work_give. */
#define WORK_POLYS(w)                                                                                  \
    {&(w)->ping, &(w)->pong, &(w)->part, &(w)->parts, &(w)->arc_points, &(w)->arc, &(w)->mirrored,    \
     &(w)->sum, &(w)->sensors, &(w)->positions, &(w)->narrowed}
#define WORK_SCRATCHES(w) {&(w)->values, &(w)->flags, &(w)->cuts, &(w)->planes, &(w)->points, &(w)->edges, &(w)->lengths}
#define COUNT_OF(array) (sizeof(array) / sizeof((array)[0]))

void work_free(Work *w) {
    Poly *polys[] = WORK_POLYS(w);
    Scratch *scratches[] = WORK_SCRATCHES(w);
    for (size_t i = 0; i < COUNT_OF(polys); i++) PyMem_Free(polys[i]->v);
    for (size_t i = 0; i < COUNT_OF(scratches); i++) PyMem_Free(scratches[i]->data);
}

Work *work_take(PyObject *module, Work *local) {
    ModuleState *state = module ? PyModule_GetState(module) : NULL;
    if (!state || state->lent) {
        memset(local, 0, sizeof(*local));
        return local;
    }
    state->lent = 1;
    Poly *polys[] = WORK_POLYS(&state->work);
    for (size_t i = 0; i < COUNT_OF(polys); i++) polys[i]->n = 0;
    return &state->work;
}

void work_give(PyObject *module, Work *w) {
    ModuleState *state = module ? PyModule_GetState(module) : NULL;
    if (!state || w != &state->work) {
        work_free(w);
        return;
    }
    Poly *polys[] = WORK_POLYS(w);
    Scratch *scratches[] = WORK_SCRATCHES(w);
    size_t bytes = 0;
    for (size_t i = 0; i < COUNT_OF(polys); i++) bytes += 2 * sizeof(double) * (size_t)polys[i]->cap;
    for (size_t i = 0; i < COUNT_OF(scratches); i++) bytes += scratches[i]->bytes;
    if (bytes > WORK_KEPT_BYTES) {
        work_free(w);
        memset(w, 0, sizeof(*w));
    }
    state->lent = 0;
}

/* Make room for `count` vertices (their values are kept); -1 with MemoryError set on failure. */
int reserve(Poly *p, Py_ssize_t count) {
    if (count < 1) count = 1;
    if (count <= p->cap) return 0;
    if ((size_t)count > (size_t)PY_SSIZE_T_MAX / (2 * sizeof(double))) {
        PyErr_NoMemory();
        return -1;
    }
    /* At least double: a list appended to polygon by polygon (a redistribution's slices)
       is copied a bounded number of times, not once per append. */
    if (p->cap <= PY_SSIZE_T_MAX / 4 / (Py_ssize_t)(2 * sizeof(double)) && count < 2 * p->cap) count = 2 * p->cap;
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
void *scratch(Scratch *s, Py_ssize_t count, size_t size) {
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
int copy_into(Poly *dst, const double *src, Py_ssize_t n) {
    if (src != dst->v) {
        if (reserve(dst, n) < 0) return -1;
        if (n > 0) memcpy(dst->v, src, 2 * sizeof(double) * (size_t)n);
    }
    dst->n = n;
    return 0;
}

/* See _convex.polygon_area. */
double polygon_area(const double *v, Py_ssize_t n) {
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
int remove_collinear(Poly *p, Work *w) {
    Py_ssize_t n = p->n;
    double *v = p->v;
    if (n < 2) return 0;
    double box[4];
    bounding_box(v, n, box);
    double span = greater(box[2] - box[0], box[3] - box[1]);
    double magnitude = 0.0;
    for (Py_ssize_t i = 0; i < 2 * n; i++) magnitude = greater(magnitude, fabs(v[i]));
    double close = MERGE_EPS * span + MERGE_ROUNDING * magnitude;
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
        if (lengths[i] > close) {
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
    char *straight = scratch(&w->flags, n, 1);
    if (!straight) return -1;
    /* See the reference: a straight vertex goes only if the one before it stays, pass after
       pass while one waited for its neighbour. */
    while (n >= 3) {
        if (!measured) { /* the kept vertices' own magnitude, as the reference takes it */
            magnitude = 0.0;
            for (Py_ssize_t i = 0; i < 2 * n; i++) magnitude = greater(magnitude, fabs(v[i]));
        }
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
        if (count == n) {
            /* Every corner straight to within rounding (a polygon of the noise's size): the
               segment from the first vertex to the farthest from it (the first such), not nothing. */
            Py_ssize_t far = 0;
            double farthest = -1.0;
            for (Py_ssize_t i = 0; i < n; i++) {
                double d = hypot(v[2 * i] - v[0], v[2 * i + 1] - v[1]);
                if (d > farthest) {
                    farthest = d;
                    far = i;
                }
            }
            v[2] = v[2 * far];
            v[3] = v[2 * far + 1];
            p->n = 2;
            return 0;
        }
        /* In a run of straight vertices every other one goes, from the run's first: counted
           from a vertex that is not straight (there is one), the run halves each pass. */
        Py_ssize_t first = 0;
        while (straight[first]) first++;
        int waited = 0, went = 0;
        for (Py_ssize_t k = 1; k <= n; k++) {
            Py_ssize_t i = first + k < n ? first + k : first + k - n;
            int goes = straight[i] && !went;
            waited |= straight[i] && !goes;
            went = goes;
            straight[i] = (char)(goes ? 2 : straight[i]); /* 2: goes this pass */
        }
        Py_ssize_t m = 0;
        for (Py_ssize_t i = 0; i < n; i++) {
            if (straight[i] == 2) continue;
            v[2 * m] = v[2 * i];
            v[2 * m + 1] = v[2 * i + 1];
            m++;
        }
        n = m;
        p->n = n;
        if (!waited) return 0;
        measured = 0;
    }
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
int clip_halfplane(const double *v, Py_ssize_t count, double nx, double ny, double offset, Poly *out,
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
int clip_halfplanes(const double *v, Py_ssize_t n, const double *planes, Py_ssize_t k, Poly *out,
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
int clip_convex(const double *v, Py_ssize_t n, const double *other, Py_ssize_t m, double margin, Poly *out,
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

typedef struct {
    double x, y;
} Point;

/* Whether p sorts strictly before q: by x, then y (total_order, NaN last). With `finite`
   (no coordinate is NaN) the plain comparisons give the same order, at less cost. */
static inline int point_before(const Point *p, const Point *q, int finite) {
    if (finite) return p->x < q->x || (p->x == q->x && p->y < q->y);
    int by_x = total_order(p->x, q->x);
    return by_x ? by_x < 0 : total_order(p->y, q->y) < 0;
}

/* Stable sort of p[0..m) by point_before, with tmp: room for m points, then m run bounds.
   Any stable sort orders the points alike (qsort's merge sort, before, included), so the
   hull keeps its bits. This one merges the runs the input already has: the points are
   mostly convex polygons one after the other, each at most three monotone runs in x. */
static void sort_points(Point *p, Py_ssize_t m, Point *tmp, int finite) {
    Py_ssize_t *bounds = (Py_ssize_t *)(tmp + m), runs = 0;
    for (Py_ssize_t i = 0; i < m;) {
        Py_ssize_t j = i + 1;
        if (j < m && point_before(&p[j], &p[i], finite)) {
            /* Strictly descending: reversed, it stays stable (no two of it are equal). */
            while (j + 1 < m && point_before(&p[j + 1], &p[j], finite)) j++;
            j++;
            for (Py_ssize_t a = i, b = j - 1; a < b; a++, b--) {
                Point swap = p[a];
                p[a] = p[b];
                p[b] = swap;
            }
        } else {
            while (j < m && !point_before(&p[j], &p[j - 1], finite)) j++;
        }
        bounds[runs++] = j;
        i = j;
    }
    Point *from = p, *to = tmp;
    while (runs > 1) {
        Py_ssize_t out = 0, begin = 0;
        for (Py_ssize_t r = 0; r < runs; r += 2) {
            if (r + 1 == runs) {
                memcpy(to + begin, from + begin, sizeof(Point) * (size_t)(bounds[r] - begin));
                bounds[out++] = bounds[r];
                break;
            }
            Py_ssize_t a = begin, mid = bounds[r], b = mid, end = bounds[r + 1], k = begin;
            /* Ties take the left run's first: stable. */
            while (a < mid && b < end) to[k++] = point_before(&from[b], &from[a], finite) ? from[b++] : from[a++];
            while (a < mid) to[k++] = from[a++];
            while (b < end) to[k++] = from[b++];
            bounds[out++] = end;
            begin = end;
        }
        runs = out;
        Point *swap = from;
        from = to;
        to = swap;
    }
    if (from != p) memcpy(p, from, sizeof(Point) * (size_t)m);
}

/* See _convex.convex_hull (Andrew's monotone chain); `pts` must not be in `out`'s buffer. */
int convex_hull(const double *pts, Py_ssize_t m, Poly *out, Work *w) {
    /* The points, room for as many to sort with, and the sort's run bounds. */
    Py_ssize_t twice = checked_multiply(m, 2);
    Py_ssize_t room = twice < 0 ? -1 : checked_add(twice, m / 2 + 1);
    if (room < 0) {
        PyErr_NoMemory();
        return -1;
    }
    Point *p = scratch(&w->points, room, sizeof(Point));
    if (!p) return -1;
    int finite = 1;
    for (Py_ssize_t i = 0; i < m; i++) {
        p[i].x = pts[2 * i];
        p[i].y = pts[2 * i + 1];
        finite &= p[i].x == p[i].x && p[i].y == p[i].y;
    }
    sort_points(p, m, p + m, finite);
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
int minkowski_pair(const double *a, Py_ssize_t na, const double *b, Py_ssize_t nb, Poly *out, Work *w) {
    Edge *edges = scratch(&w->edges, 2 * (na + nb), sizeof(Edge));
    if (!edges || reserve(out, na + nb) < 0) return -1;
    const double *parts[3] = {a, b, NULL};
    Py_ssize_t sizes[3] = {na, nb, 0};
    out->n = minkowski_sum(parts, sizes, 2, edges, out->v);
    return 0;
}

/* See _arcs.nearest_on_polygon. */
void nearest_on_polygon(const double *v, Py_ssize_t n, double px, double py, double *distance, double *qx,
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
        double t = segment_parameter(rx, ry, ex, ey);
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
void subtended_arc(const double *v, Py_ssize_t n, double px, double py, double radius, double *lo,
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
int intersect_arcs(double a_lo, double a_width, double b_lo, double b_width, double *lo, double *width) {
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

/* See _convex.distance_to_boundary, for one point. */
static double distance_to_boundary(const double *v, Py_ssize_t n, double x, double y) {
    if (n == 1) return hypot(x - v[0], y - v[1]);
    double best = HUGE_VAL;
    for (Py_ssize_t i = 0; i < n; i++) {
        Py_ssize_t j = i + 1 < n ? i + 1 : 0;
        double ex = v[2 * j] - v[2 * i], ey = v[2 * j + 1] - v[2 * i + 1];
        double rx = x - v[2 * i], ry = y - v[2 * i + 1];
        double t = segment_parameter(rx, ry, ex, ey);
        best = lesser(best, hypot(x - (v[2 * i] + t * ex), y - (v[2 * i + 1] + t * ey)));
    }
    return best;
}

/* See _convex.points_in_convex (its dense test), for one point. `lengths` holds the
   polygon's edge lengths (hypot of each edge, computed once per polygon) when it is solid,
   NULL when it is not. */
int point_in_convex(const double *v, Py_ssize_t n, const double *lengths, double x, double y,
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

