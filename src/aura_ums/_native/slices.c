/*
 * Compiled merging of heading slices (_slices.merge_groups_reference, operation for
 * operation): for each group of points -- the vertices of the polygons that meet one
 * heading cell, or of neighbouring slices merged under the slice cap -- the convex hull,
 * then the outer vertex cap. One call for every group of a growth's redistribution.
 */
#include "kernels.h"

PyObject *merge_groups(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
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
    Work local_work, *w = work_take(self, &local_work);
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
        if (convex_hull(points + 2 * offset, sizes[g], &hull, w) < 0) {
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
    work_give(self, w);
    PyMem_Free(t);
    PyMem_Free(scratch_points);
    PyMem_Free(ranked);
    PyMem_Free(flags);
    PyMem_Free(sizes);
    PyBuffer_Release(&view);
    Py_DECREF(counts);
    return result;
}

/* --- packed slices in and out ------------------------------------------------------------ */

/* A C-contiguous 1-D buffer of `expected` items (-1: any count >= 1) of float64 (`kind` 'd')
   or int64 ('q'); released on failure. */
static int get_array(PyObject *object, const char *name, char kind, Py_ssize_t expected, Py_buffer *view,
                     Py_ssize_t *count) {
    const char *what = kind == 'd' ? "float64" : "int64";
    if (PyObject_GetBuffer(object, view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        PyErr_Clear();
        PyErr_Format(PyExc_TypeError, "%s: expected a C-contiguous 1-D %s buffer, got %.200s", name, what,
                     Py_TYPE(object)->tp_name);
        return -1;
    }
    const char *format = view->format ? view->format : "B";
    if (*format == '@' || *format == '=' || *format == '<') format++;
    int matches = view->itemsize == 8 && view->ndim <= 1 &&
                  (kind == 'd' ? strcmp(format, "d") == 0
                               : (strcmp(format, "q") == 0 || (sizeof(long) == 8 && strcmp(format, "l") == 0)));
    Py_ssize_t items = view->itemsize > 0 ? view->len / view->itemsize : 0;
    if (!matches || items < 1 || (expected >= 0 && items != expected)) {
        PyErr_Format(PyExc_ValueError, "%s: expected a 1-D %s buffer of %zd items, got format '%s', %zd bytes",
                     name, what, expected, view->format ? view->format : "B", view->len);
        PyBuffer_Release(view);
        return -1;
    }
    *count = items;
    return 0;
}

int get_packed(PyObject *const *args, Packed *p) {
    memset(p, 0, sizeof(*p));
    Py_ssize_t k, lo_count, hi_count;
    if (get_vertices(args[0], &p->views[0], &p->n) < 0) return -1;
    p->held = 1;
    if (get_array(args[1], "counts", 'q', -1, &p->views[1], &k) < 0) goto fail;
    p->held = 2;
    if (get_array(args[2], "lo", 'd', k, &p->views[2], &lo_count) < 0) goto fail;
    p->held = 3;
    if (get_array(args[3], "hi", 'd', k, &p->views[3], &hi_count) < 0) goto fail;
    p->held = 4;
    p->k = k;
    p->v = (const double *)p->views[0].buf;
    p->counts = (const long long *)p->views[1].buf;
    p->lo = (const double *)p->views[2].buf;
    p->hi = (const double *)p->views[3].buf;
    /* Every count at least 1 and together exactly the rows given: no slice reads past them. */
    Py_ssize_t total = 0;
    for (Py_ssize_t i = 0; i < k; i++) {
        if (p->counts[i] < 1 || p->counts[i] > p->n - total) {
            PyErr_Format(PyExc_ValueError, "counts: expected slice sizes adding up to the %zd rows, got %lld at %zd",
                         p->n, p->counts[i], i);
            goto fail;
        }
        total += (Py_ssize_t)p->counts[i];
        if (!isfinite(p->lo[i]) || !isfinite(p->hi[i])) {
            PyErr_Format(PyExc_ValueError, "lo, hi: expected finite headings, got a non-finite one at %zd", i);
            goto fail;
        }
    }
    if (total != p->n) {
        PyErr_Format(PyExc_ValueError, "counts: expected slice sizes adding up to the %zd rows, got %zd", p->n,
                     total);
        goto fail;
    }
    return 0;
fail:
    packed_release(p);
    return -1;
}

void packed_release(Packed *p) {
    for (int i = 0; i < p->held; i++) PyBuffer_Release(&p->views[i]);
    p->held = 0;
}

int slices_append(SliceList *s, const double *v, Py_ssize_t n, double lo, double hi, long long source) {
    if (s->k == s->cap) {
        Py_ssize_t cap = s->cap ? 2 * s->cap : 16;
        if ((size_t)cap > (size_t)PY_SSIZE_T_MAX / sizeof(double)) {
            PyErr_NoMemory();
            return -1;
        }
        long long *counts = PyMem_Realloc(s->counts, sizeof(long long) * (size_t)cap);
        if (counts) s->counts = counts;
        long long *sources = counts ? PyMem_Realloc(s->sources, sizeof(long long) * (size_t)cap) : NULL;
        if (sources) s->sources = sources;
        double *los = sources ? PyMem_Realloc(s->lo, sizeof(double) * (size_t)cap) : NULL;
        if (los) s->lo = los;
        double *his = los ? PyMem_Realloc(s->hi, sizeof(double) * (size_t)cap) : NULL;
        if (!his) {
            PyErr_NoMemory();
            return -1;
        }
        s->hi = his;
        s->cap = cap;
    }
    Py_ssize_t total = checked_add(s->points.n, n);
    if (total < 0 || reserve(&s->points, total) < 0) {
        if (total < 0) PyErr_NoMemory();
        return -1;
    }
    memcpy(s->points.v + 2 * s->points.n, v, 2 * sizeof(double) * (size_t)n);
    s->points.n = total;
    s->counts[s->k] = n;
    s->sources[s->k] = source;
    s->lo[s->k] = lo;
    s->hi[s->k] = hi;
    s->k++;
    return 0;
}

void slices_free(SliceList *s) {
    PyMem_Free(s->points.v);
    PyMem_Free(s->counts);
    PyMem_Free(s->sources);
    PyMem_Free(s->lo);
    PyMem_Free(s->hi);
    memset(s, 0, sizeof(*s));
}

int slices_bytes(const SliceList *s, int with_sources, PyObject **out) {
    const void *data[5] = {s->points.v, s->counts, s->lo, s->hi, s->sources};
    Py_ssize_t sizes[5] = {(Py_ssize_t)(2 * sizeof(double)) * s->points.n, 8 * s->k, 8 * s->k, 8 * s->k, 8 * s->k};
    int count = with_sources ? 5 : 4;
    for (int i = 0; i < count; i++) {
        out[i] = PyBytes_FromStringAndSize((const char *)data[i], sizes[i]);
        if (!out[i]) {
            for (int j = 0; j < i; j++) Py_CLEAR(out[j]);
            return -1;
        }
    }
    return 0;
}

/* --- headings of slices ------------------------------------------------------------------ */

double clamp_into(double heading, double lo, double hi) {
    double offset = floor_mod(heading - lo, TWO_PI);
    if (offset <= hi - lo) return lo + offset;
    /* Outside: the nearer end, the shorter way round. */
    return offset - (hi - lo) < TWO_PI - offset ? hi : lo;
}

Py_ssize_t home_slice(const double *lo, const double *hi, Py_ssize_t k, double heading) {
    Py_ssize_t best = 0;
    double best_gap = HUGE_VAL;
    for (Py_ssize_t i = 0; i < k; i++) {
        double offset = floor_mod(heading - lo[i], TWO_PI), gap;
        if (offset <= hi[i] - lo[i]) return i;
        gap = lesser(offset - (hi[i] - lo[i]), TWO_PI - offset);
        if (gap < best_gap) {
            best = i;
            best_gap = gap;
        }
    }
    return best;
}

void summary_wedge(const double *lo, const double *hi, Py_ssize_t k, double heading, double *wedge) {
    double start, stop;
    if (k == 1) {
        start = lo[0];
        stop = hi[0];
    } else {
        double reach = hi[0], widest = -HUGE_VAL;
        Py_ssize_t after = 0;
        for (Py_ssize_t i = 1; i < k; i++) {
            double gap = lo[i] - reach;
            if (gap > widest) {
                widest = gap;
                after = i;
            }
            reach = greater(reach, hi[i]);
        }
        double wrap = lo[0] + TWO_PI - reach;
        if (wrap >= widest) {
            widest = wrap;
            after = 0;
        }
        if (widest <= ANGLE_SLACK) {
            /* No gap but rounding's between neighbouring cells: every heading. */
            wedge[0] = heading;
            wedge[1] = wedge[2] = M_PI;
            return;
        }
        start = lo[after];
        stop = start + TWO_PI - widest;
    }
    if (stop - start >= TWO_PI) {
        wedge[0] = heading;
        wedge[1] = wedge[2] = M_PI;
        return;
    }
    double center = clamp_into(heading, start, stop);
    wedge[0] = center;
    wedge[1] = center - start;
    wedge[2] = stop - center;
}

/* --- redistribution onto the grid --------------------------------------------------------- */

/* One (piece, cell it meets) row of a redistribution, in the order the pieces give them. */
typedef struct {
    long long cell;
    Py_ssize_t row, piece;
    double lo, hi;
} Row;

static int compare_rows(const void *a, const void *b) {
    const Row *p = a, *q = b;
    if (p->cell != q->cell) return p->cell < q->cell ? -1 : 1;
    return (p->row > q->row) - (p->row < q->row);
}

/* The hull of a group's points with the outer vertex cap (see merge_groups), into `hull`. */
typedef struct {
    Poly hull, gathered;
    Work *w;
    double *t, *scratch_points;
    Ranked *ranked;
    char *flags;
    Py_ssize_t room;
    /* The group whose hull `hull` holds (last_count 0: none). */
    Py_ssize_t *last, last_count, last_room;
    const SliceList *last_from;
} Merger;

static void merger_free(Merger *m) {
    PyMem_Free(m->hull.v);
    PyMem_Free(m->gathered.v);
    PyMem_Free(m->t);
    PyMem_Free(m->scratch_points);
    PyMem_Free(m->ranked);
    PyMem_Free(m->flags);
    PyMem_Free(m->last);
}

static int merge_hull(Merger *m, const double *points, Py_ssize_t count, Py_ssize_t max_vertices) {
    if (convex_hull(points, count, &m->hull, m->w) < 0) return -1;
    Py_ssize_t n = m->hull.n;
    if (n > max_vertices) {
        if (n > m->room) {
            PyMem_Free(m->t);
            PyMem_Free(m->scratch_points);
            PyMem_Free(m->ranked);
            PyMem_Free(m->flags);
            m->t = PyMem_Malloc(sizeof(double) * (size_t)n);
            m->scratch_points = PyMem_Malloc(sizeof(double) * 2 * (size_t)n);
            m->ranked = PyMem_Malloc(sizeof(Ranked) * (size_t)n);
            m->flags = PyMem_Malloc(2 * (size_t)n);
            m->room = n;
            if (!m->t || !m->scratch_points || !m->ranked || !m->flags) {
                m->room = 0;
                PyErr_NoMemory();
                return -1;
            }
        }
        m->hull.n = simplify_outer(m->hull.v, n, max_vertices, m->t, m->ranked, m->flags, m->flags + m->room,
                                   m->scratch_points);
    }
    return 0;
}

/* Append the merge of slices first..last-1 of `from` (a group) to `to`: the polygon itself when
   they share one source, else the capped hull of their vertices with the source `fresh`. */
static int append_merged(SliceList *to, const SliceList *from, const Py_ssize_t *starts, const Py_ssize_t *order,
                         Py_ssize_t count, double lo, double hi, long long fresh, Py_ssize_t max_vertices,
                         Merger *m) {
    Py_ssize_t first = order[0];
    int same = 1;
    for (Py_ssize_t i = 1; i < count; i++) same &= from->sources[order[i]] == from->sources[first];
    if (same)
        return slices_append(to, from->points.v + 2 * starts[first], (Py_ssize_t)from->counts[first], lo, hi,
                             from->sources[first]);
    /* Wide pieces give many cells the same group: its hull once (the slices keep their own sources). */
    if (m->last_count == count && m->last_from == from && m->hull.n > 0 &&
        memcmp(m->last, order, sizeof(Py_ssize_t) * (size_t)count) == 0)
        return slices_append(to, m->hull.v, m->hull.n, lo, hi, fresh);
    m->gathered.n = 0;
    for (Py_ssize_t i = 0; i < count; i++) {
        Py_ssize_t piece = order[i], size = (Py_ssize_t)from->counts[piece];
        Py_ssize_t total = checked_add(m->gathered.n, size);
        if (total < 0 || reserve(&m->gathered, total) < 0) {
            if (total < 0) PyErr_NoMemory();
            return -1;
        }
        memcpy(m->gathered.v + 2 * m->gathered.n, from->points.v + 2 * starts[piece], 2 * sizeof(double) * (size_t)size);
        m->gathered.n = total;
    }
    m->last_count = 0;
    if (merge_hull(m, m->gathered.v, m->gathered.n, max_vertices) < 0) return -1;
    if (count > m->last_room) {
        Py_ssize_t *last = PyMem_Realloc(m->last, sizeof(Py_ssize_t) * (size_t)count);
        if (!last) {
            PyErr_NoMemory();
            return -1;
        }
        m->last = last;
        m->last_room = count;
    }
    memcpy(m->last, order, sizeof(Py_ssize_t) * (size_t)count);
    m->last_count = count;
    m->last_from = from;
    return slices_append(to, m->hull.v, m->hull.n, lo, hi, fresh);
}

/* Where each slice's vertices start; NULL with MemoryError set. */
static Py_ssize_t *slice_starts(const SliceList *s) {
    Py_ssize_t *starts = PyMem_Malloc(sizeof(Py_ssize_t) * (size_t)(s->k > 0 ? s->k : 1));
    if (!starts) {
        PyErr_NoMemory();
        return NULL;
    }
    Py_ssize_t at = 0;
    for (Py_ssize_t i = 0; i < s->k; i++) {
        starts[i] = at;
        at += (Py_ssize_t)s->counts[i];
    }
    return starts;
}

static long long next_source(const SliceList *s) {
    long long top = -1;
    for (Py_ssize_t i = 0; i < s->k; i++) top = s->sources[i] > top ? s->sources[i] : top;
    return top + 1;
}

/* See _native._slices.distribute_reference: the pieces (an unwrapped interval each) onto a
   grid of `cells` cells, then the cap of max_slices by merging neighbours, into `out`. */
static int distribute(const SliceList *pieces, Py_ssize_t cells, Py_ssize_t max_vertices, Py_ssize_t max_slices,
                      SliceList *out, Work *w) {
    double step = TWO_PI / (double)cells;
    Py_ssize_t k = pieces->k, total = 0;
    long long *first = PyMem_Malloc(sizeof(long long) * 2 * (size_t)k);
    Row *rows = NULL;
    Py_ssize_t *starts = NULL, *order = NULL;
    SliceList grid = {0};
    Merger m;
    memset(&m, 0, sizeof(m));
    m.w = w;
    int status = -1;
    if (!first) {
        PyErr_NoMemory();
        goto done;
    }
    long long *last = first + k;
    for (Py_ssize_t i = 0; i < k; i++) {
        double a = pieces->lo[i], b = pieces->hi[i];
        if (b - a >= TWO_PI) {
            a = 0.0;
            b = TWO_PI;
        }
        double low = floor(a / step), high = ceil(b / step) - 1.0;
        /* Headings within a few turns of 0: far inside a long long. */
        if (!(fabs(low) < 4e18) || !(fabs(high) < 4e18)) {
            PyErr_Format(PyExc_ValueError, "lo, hi: expected headings within a few turns of 0, got piece %zd", i);
            goto done;
        }
        first[i] = (long long)low;
        last[i] = (long long)high > first[i] ? (long long)high : first[i];
        /* b - a < 2 pi (or 0..2 pi): at most cells + 1 cells. */
        Py_ssize_t span = (Py_ssize_t)(last[i] - first[i] + 1);
        if (span > cells + 1) span = cells + 1, last[i] = first[i] + span - 1;
        total = checked_add(total, span);
        if (total < 0) {
            PyErr_NoMemory();
            goto done;
        }
    }
    rows = PyMem_Malloc(sizeof(Row) * (size_t)(total > 0 ? total : 1));
    starts = slice_starts(pieces);
    order = PyMem_Malloc(sizeof(Py_ssize_t) * (size_t)(total > k ? total : k > 0 ? k : 1));
    if (!rows || !starts || !order) {
        if (!PyErr_Occurred()) PyErr_NoMemory();
        goto done;
    }
    Py_ssize_t r = 0;
    for (Py_ssize_t i = 0; i < k; i++) {
        double a = pieces->lo[i], b = pieces->hi[i];
        if (b - a >= TWO_PI) {
            a = 0.0;
            b = TWO_PI;
        }
        for (long long c = first[i]; c <= last[i]; c++, r++) {
            long long cell = c % (long long)cells;
            if (cell < 0) cell += cells;
            double shift = (double)(c - cell) * step, cell_lo = (double)cell * step, cell_hi = (double)(cell + 1) * step;
            /* Rounding must not leave the cell, nor turn the interval inside out. */
            double lo = lesser(greater(greater(a, (double)c * step) - shift, cell_lo), cell_hi);
            double hi = lesser(greater(lesser(b, (double)(c + 1) * step) - shift, lo), cell_hi);
            rows[r] = (Row){cell, r, i, lo, hi};
        }
    }
    qsort(rows, (size_t)total, sizeof(Row), compare_rows);
    long long fresh = next_source(pieces);
    for (Py_ssize_t begin = 0; begin < total;) {
        Py_ssize_t end = begin;
        double low = HUGE_VAL, high = -HUGE_VAL;
        while (end < total && rows[end].cell == rows[begin].cell) {
            low = lesser(low, rows[end].lo);
            high = greater(high, rows[end].hi);
            order[end - begin] = rows[end].piece;
            end++;
        }
        if (append_merged(&grid, pieces, starts, order, end - begin, low, high, fresh + grid.k, max_vertices, &m) < 0)
            goto done;
        begin = end;
    }
    if (grid.k <= max_slices) {
        *out = grid;
        memset(&grid, 0, sizeof(grid));
        status = 0;
        goto done;
    }
    /* The cap: neighbours (in heading order) merge, size at a time. */
    PyMem_Free(starts);
    starts = slice_starts(&grid);
    if (!starts) goto done;
    Py_ssize_t size = (grid.k + max_slices - 1) / max_slices;
    fresh = next_source(&grid);
    for (Py_ssize_t begin = 0; begin < grid.k; begin += size) {
        Py_ssize_t count = grid.k - begin < size ? grid.k - begin : size;
        double high = grid.hi[begin];
        for (Py_ssize_t i = 0; i < count; i++) {
            order[i] = begin + i;
            high = greater(high, grid.hi[begin + i]);
        }
        if (append_merged(out, &grid, starts, order, count, grid.lo[begin], high, fresh + out->k, max_vertices, &m) < 0)
            goto done;
    }
    status = 0;
done:
    PyMem_Free(first);
    PyMem_Free(rows);
    PyMem_Free(starts);
    PyMem_Free(order);
    slices_free(&grid);
    merger_free(&m);
    return status;
}

/* (points, counts, lo, hi, sources bytes, wedge centre, cw, ccw) of distributed slices, or NULL. */
static PyObject *distributed_result(PyObject *self, SliceList *pieces, Py_ssize_t cells, Py_ssize_t max_vertices,
                                    Py_ssize_t max_slices, double heading) {
    SliceList grid = {0};
    PyObject *items[5], *result = NULL;
    Work local_work, *w = work_take(self, &local_work);
    int distributed = distribute(pieces, cells, max_vertices, max_slices, &grid, w);
    work_give(self, w);
    if (distributed == 0 && slices_bytes(&grid, 1, items) == 0) {
        double wedge[3];
        summary_wedge(grid.lo, grid.hi, grid.k, heading, wedge);
        result = Py_BuildValue("(NNNNNddd)", items[0], items[1], items[2], items[3], items[4], wedge[0], wedge[1],
                               wedge[2]);
    }
    slices_free(&grid);
    return result;
}

PyObject *distribute_slices(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 9) {
        PyErr_Format(PyExc_TypeError, "distribute_slices: expected 9 arguments, got %zd", nargs);
        return NULL;
    }
    Packed p;
    Py_buffer sources_view;
    Py_ssize_t cells, max_vertices, max_slices, k;
    if (parse_count(args[5], "cells", 1, 1 << 24, &cells) < 0 || parse_cap(args[6], &max_vertices) < 0 ||
        parse_count(args[7], "max_slices", 1, PY_SSIZE_T_MAX, &max_slices) < 0)
        return NULL;
    double heading = PyFloat_AsDouble(args[8]);
    if (heading == -1.0 && PyErr_Occurred()) return NULL;
    if (!isfinite(heading)) {
        PyErr_Format(PyExc_ValueError, "heading: expected a finite number, got %R", args[8]);
        return NULL;
    }
    if (get_packed(args, &p) < 0) return NULL;
    if (get_array(args[4], "sources", 'q', p.k, &sources_view, &k) < 0) {
        packed_release(&p);
        return NULL;
    }
    /* The pieces as a SliceList over the caller's buffers (read only: never appended to). */
    SliceList pieces = {{(double *)p.v, p.n, p.n}, (long long *)p.counts, (long long *)sources_view.buf,
                        (double *)p.lo, (double *)p.hi, p.k, p.k};
    PyObject *result = distributed_result(self, &pieces, cells, max_vertices, max_slices, heading);
    PyBuffer_Release(&sources_view);
    packed_release(&p);
    return result;
}
