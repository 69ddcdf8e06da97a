/*
 * Compiled growth: a run of turn-and-run commands on one terrain. For each command,
 * _growth.motion_bounds, then the polygon P (+) skitter disk (+) outer polygon of the
 * annular sector of run endpoints with the outer vertex cap (_growth.grow_polygon), the
 * wedge (_growth.grow_wedge) and the centre, operation for operation as the numpy
 * reference _growth.grow_commands_reference. Small polygons make numpy's per-call
 * overhead dominate; plain C loops do not.
 */
#include "kernels.h"

/* Every buffer of one growth step, in one block, for inputs of up to `capacity` minus
   SECTOR_POINTS_MAX + SKITTER_SIDES vertices: the Minkowski sum has at most `capacity`. */
typedef struct {
    char *block;
    double *sector, *disk, *scratch, *t;
    Edge *edges;
    Ranked *ranked;
    char *flags;
    Py_ssize_t capacity;
} Growth;

/* Size the buffers for a step from n vertices (kept when already large enough); -1 with
   MemoryError set on failure. */
static int growth_reserve(Growth *g, Py_ssize_t n) {
    Py_ssize_t capacity = checked_add(n, SECTOR_POINTS_MAX + SKITTER_SIDES);
    if (capacity < 0 || (size_t)capacity > PY_SSIZE_T_MAX / (4 * sizeof(Edge))) {
        PyErr_NoMemory();
        return -1;
    }
    if (capacity <= g->capacity) return 0;
    /* 8-byte items first, the flags last. */
    size_t sector_size = sizeof(double) * 2 * SECTOR_POINTS_MAX;
    size_t disk_size = sizeof(double) * 2 * SKITTER_SIDES;
    size_t edges_size = sizeof(Edge) * 2 * (size_t)capacity;
    size_t points_size = sizeof(double) * 2 * (size_t)capacity;
    size_t t_size = sizeof(double) * (size_t)capacity;
    size_t ranked_size = sizeof(Ranked) * (size_t)capacity;
    char *block = PyMem_Malloc(sector_size + disk_size + edges_size + points_size + t_size + ranked_size +
                               2 * (size_t)capacity);
    if (!block) {
        PyErr_NoMemory();
        return -1;
    }
    PyMem_Free(g->block);
    g->block = block;
    g->capacity = capacity;
    g->sector = (double *)block;
    g->disk = (double *)(block + sector_size);
    g->edges = (Edge *)(block + sector_size + disk_size);
    g->scratch = (double *)(block + sector_size + disk_size + edges_size);
    g->t = (double *)(block + sector_size + disk_size + edges_size + points_size);
    g->ranked = (Ranked *)(block + sector_size + disk_size + edges_size + points_size + t_size);
    g->flags = block + sector_size + disk_size + edges_size + points_size + t_size + ranked_size;
    return 0;
}

/* One growth (see _growth.grow_polygon_reference) of the n vertices into `out`, which has
   room for g->capacity points after growth_reserve(g, n); returns the result's vertex
   count, at most max(n, max_vertices). */
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

/* _growth.motion_bounds: clip */
static double clip_to(double value, double lo, double hi) { return value < lo ? lo : value > hi ? hi : value; }

/* HeadingWedge._trusted's wrap of an unwrapped centre to (-pi, pi]. */
static double wrap_center(double center) {
    double wrapped = M_PI - floor_mod(M_PI - center, TWO_PI);
    return wrapped <= -M_PI ? wrapped + TWO_PI : wrapped;
}

/* The commands as doubles (turn, run, turn, ...): a new buffer (freed by the caller) of *values
   items, or NULL with an exception set. */
static double *parse_commands(PyObject *object, Py_ssize_t *values) {
    /* A tuple of its own: converting an item can run Python code, which cannot resize it. */
    PyObject *commands = PySequence_Tuple(object);
    if (!commands) {
        if (PyErr_ExceptionMatches(PyExc_TypeError)) {
            PyErr_Clear();
            PyErr_Format(PyExc_TypeError, "commands: expected a sequence of numbers, got %.200s",
                         Py_TYPE(object)->tp_name);
        }
        return NULL;
    }
    Py_ssize_t count = PyTuple_GET_SIZE(commands);
    double *out = NULL;
    if (count % 2 != 0) {
        PyErr_Format(PyExc_ValueError, "commands: expected (turn, run) pairs, got %zd numbers", count);
        goto done;
    }
    out = PyMem_Malloc(sizeof(double) * (size_t)(count > 0 ? count : 1));
    if (!out) {
        PyErr_NoMemory();
        goto done;
    }
    for (Py_ssize_t i = 0; i < count; i += 2) {
        PyObject *turn_item = PyTuple_GET_ITEM(commands, i), *run_item = PyTuple_GET_ITEM(commands, i + 1);
        double turn = PyFloat_AsDouble(turn_item), run = PyFloat_AsDouble(run_item);
        if (PyErr_Occurred() || !isfinite(turn) || !isfinite(run)) {
            if (!PyErr_Occurred())
                PyErr_Format(PyExc_ValueError, "commands: expected finite numbers, got %R, %R at pair %zd",
                             turn_item, run_item, i / 2);
            PyMem_Free(out);
            out = NULL;
            goto done;
        }
        out[i] = turn;
        out[i + 1] = run;
    }
    *values = count;
done:
    Py_DECREF(commands);
    return out;
}

/* The terrain's numbers and sigmas, in grow_commands' argument order. */
enum { ROTATION_LOSS, ROTATION_SD, TRANSLATION_LOSS, TRANSLATION_SD, INERTIAL, DRIFT, SKITTER, SKITTER_SD, SIGMAS,
       TERRAIN_VALUES };

/* Grow the n vertices in *ping by each command in turn (ping and pong alternate; the result
   ends in *ping); state holds x, y, the wedge's centre, cw and ccw, and receives the last
   centre unwrapped in state[5]. -1 with MemoryError set on failure. */
static int grow_run(Growth *g, Poly *ping, Poly *pong, Py_ssize_t *count, const double *commands, Py_ssize_t values,
                    const double *terrain, Py_ssize_t max_vertices, double *state) {
    double x = state[0], y = state[1], center = state[2], cw = state[3], ccw = state[4];
    const double rotation_loss = terrain[ROTATION_LOSS], rotation_sd = terrain[ROTATION_SD];
    const double translation_loss = terrain[TRANSLATION_LOSS], translation_sd = terrain[TRANSLATION_SD];
    const double inertial = terrain[INERTIAL], drift = terrain[DRIFT], skitter = terrain[SKITTER];
    const double skitter_sd = terrain[SKITTER_SD], sigmas = terrain[SIGMAS];
    double unwrapped = center;
    Py_ssize_t n = *count;
    for (Py_ssize_t i = 0; i < values; i += 2) {
        double turn = commands[i], run = commands[i + 1];
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
        /* _growth.grow_polygon_reference */
        double heading_lo = center - cw;
        if (growth_reserve(g, n) < 0 || reserve(pong, g->capacity) < 0) return -1;
        n = grow_step(g, ping->v, n, heading_lo, heading_lo + cw + ccw, turn_min, turn_max, drift_max, chord_min,
                      run_hi, skitter_radius, max_vertices, pong->v);
        Poly swap = *ping;
        *ping = *pong;
        *pong = swap;
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
    *count = n;
    state[0] = x;
    state[1] = y;
    state[2] = center;
    state[3] = cw;
    state[4] = ccw;
    state[5] = unwrapped;
    return 0;
}

PyObject *grow_commands(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
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
    Py_ssize_t max_vertices, n, values;
    if (parse_doubles(args + 1, DOUBLES, names, a) < 0 || parse_cap(args[DOUBLES + 2], &max_vertices) < 0)
        return NULL;
    double *commands = parse_commands(args[DOUBLES + 1], &values);
    if (!commands) return NULL;
    Py_buffer view;
    if (get_vertices(args[0], &view, &n) < 0) {
        PyMem_Free(commands);
        return NULL;
    }
    PyObject *result = NULL;
    Growth g = {0};
    /* The polygon alternates between two buffers, each sized before every step. */
    Poly ping = {0}, pong = {0};
    double state[6] = {a[0], a[1], a[2], a[3], a[4], a[2]};
    if (reserve(&ping, n) < 0) goto done;
    memcpy(ping.v, view.buf, sizeof(double) * 2 * (size_t)n);
    if (grow_run(&g, &ping, &pong, &n, commands, values, a + 5, max_vertices, state) < 0) goto done;
    /* The last centre unwrapped: HeadingWedge._trusted wraps it (wrapping twice may move it). */
    result = Py_BuildValue("(y#ddddd)", (const char *)ping.v, (Py_ssize_t)(sizeof(double) * 2 * (size_t)n), state[0],
                           state[1], state[5], state[3], state[4]);
done:
    PyMem_Free(g.block);
    PyMem_Free(ping.v);
    PyMem_Free(pong.v);
    PyBuffer_Release(&view);
    PyMem_Free(commands);
    return result;
}

/* See _native._slices.grow_slices_reference: every slice grown as a product map of its
   polygon and interval (the home slice's wedge centred on the map's heading clamped into it,
   the others' on their middles), each with its grown interval unwrapped. */
PyObject *grow_slices(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    (void)self;
    static const char *const names[] = {
        "center_x",      "center_y",    "heading",          "rotation_loss", "rotation_sd",
        "translation_loss", "translation_sd", "translation_inertial_loss", "drift", "skitter",
        "skitter_sd",    "sigmas"};
    enum { DOUBLES = sizeof(names) / sizeof(names[0]) };
    if (nargs != DOUBLES + 6) {
        PyErr_Format(PyExc_TypeError, "grow_slices: expected %d arguments, got %zd", DOUBLES + 6, nargs);
        return NULL;
    }
    double a[DOUBLES];
    Py_ssize_t max_vertices, values;
    if (parse_doubles(args + 4, DOUBLES, names, a) < 0 || parse_cap(args[DOUBLES + 5], &max_vertices) < 0)
        return NULL;
    double *commands = parse_commands(args[DOUBLES + 4], &values);
    if (!commands) return NULL;
    Packed p;
    if (get_packed(args, &p) < 0) {
        PyMem_Free(commands);
        return NULL;
    }
    PyObject *result = NULL, *items[4];
    Growth g = {0};
    Poly ping = {0}, pong = {0};
    SliceList grown = {0};
    double heading = a[2], x = a[0], y = a[1], new_heading = heading;
    Py_ssize_t home = home_slice(p.lo, p.hi, p.k, heading), start = 0;
    for (Py_ssize_t i = 0; i < p.k; i++) {
        Py_ssize_t n = (Py_ssize_t)p.counts[i];
        double lo = p.lo[i], hi = p.hi[i];
        double middle = i == home ? clamp_into(heading, lo, hi) : 0.5 * (lo + hi);
        double state[6] = {a[0], a[1], middle, middle - lo, greater(0.0, hi - middle), middle};
        if (reserve(&ping, n) < 0) goto done;
        memcpy(ping.v, p.v + 2 * start, sizeof(double) * 2 * (size_t)n);
        start += n;
        if (grow_run(&g, &ping, &pong, &n, commands, values, a + 3, max_vertices, state) < 0) goto done;
        if (slices_append(&grown, ping.v, n, state[5] - state[3], state[5] + state[4], (long long)i) < 0) goto done;
        if (i == home) {
            x = state[0];
            y = state[1];
            new_heading = state[5];
        }
    }
    if (slices_bytes(&grown, 0, items) == 0)
        result = Py_BuildValue("(NNNNddd)", items[0], items[1], items[2], items[3], x, y, new_heading);
done:
    PyMem_Free(g.block);
    PyMem_Free(ping.v);
    PyMem_Free(pong.v);
    slices_free(&grown);
    packed_release(&p);
    PyMem_Free(commands);
    return result;
}
