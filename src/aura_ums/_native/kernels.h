/*
 * Shared declarations of the compiled kernels of aura_ums._native: the constants (each
 * defined once here, exported by module.c and checked against their Python twins by
 * tests/_native), the polygon primitives of polygon.c and the argument parsing of args.c.
 *
 * Every kernel mirrors, operation for operation, a numpy reference: the polygon
 * primitives mirror geometry/_convex.py and geometry/_arcs.py; growth.c, reduce.c,
 * expecter.c and distance.c mirror the wrapper modules _growth.py, _reduce.py,
 * _expecter.py and _distance.py beside them, which also hold the references.
 */
#ifndef AURA_UMS_NATIVE_KERNELS_H
#define AURA_UMS_NATIVE_KERNELS_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* --- constants (Python twins named in the comments) --------------------------------- */

#define TWO_PI (2.0 * M_PI)
/* geometry._convex.ARC_STEP: angular step of an arc's outer polygon, rad. */
#define ARC_STEP (M_PI / 16.0)
/* geometry._convex._TINY_ANGLE: widths below this are a single direction, rad. */
#define TINY_ANGLE 1e-12
/* geometry._convex._PARALLEL_EPS: edge directions closer than this are joined. */
#define PARALLEL_EPS 1e-12
/* geometry._convex._NOISE_EDGE: edges below this fraction of the largest are noise. */
#define NOISE_EDGE 1e-12
/* geometry._convex._FARTHEST_MERGE: a merged vertex stays within this many extents. */
#define FARTHEST_MERGE 10.0
/* geometry._convex._EXTENDABLE: only edges above this fraction of the magnitude extend. */
#define EXTENDABLE 1e-6
/* geometry._convex._SUPPORT_MARGIN: outward margin of the support polygon, relative. */
#define SUPPORT_MARGIN 1e-12
/* geometry._convex.FULL_DISK_SIDES: sides of a full-circle annular sector's polygon. */
#define FULL_DISK_SIDES 32
/* geometry._convex._SAME_POINT, _MERGE_EPS, _MERGE_ROUNDING, _COLLINEAR_EPS */
#define SAME_POINT 1e-12
#define MERGE_EPS 1e-12
#define MERGE_ROUNDING 1e-14
#define COLLINEAR_EPS 1e-12
/* _native._growth.SKITTER_SIDES: sides of the skitter disk's outer polygon. */
#define SKITTER_SIDES 8
/* _native._reduce.TOLERANCE, TANGENT_STEP, SENSOR_ARC_SIDES */
#define TOLERANCE 1e-9
#define TANGENT_STEP (M_PI / 8.0)
#define SENSOR_ARC_SIDES 16

/* Most points outer_annular_sector writes: an arc narrower than 2 pi has at most
   2 pi / ARC_STEP tangent points, plus its two ends and two inner points. */
#define SECTOR_POINTS_MAX (32 + 4)

/* _native._reduce.EmptyReason: why a reduction is empty. */
enum {
    NO_POSITION = 0,
    NO_SENSOR_POSITION = 1,
    NO_BEARING_HEADING = 2,
    NO_LINE_HEADING = 3,
    NO_OFFSET_POSITION = 4,
};

/* --- small helpers --------------------------------------------------------------------- */

/* fmin and fmax without the libm calls (no NaN reaches them from checked input). Where a
   +0/-0 choice could differ from libm's, the result is only compared, never returned. */
static inline double lesser(double a, double b) { return b < a ? b : a; }
static inline double greater(double a, double b) { return b > a ? b : a; }
static inline double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

/* Where along the segment from a by e the point a + r comes nearest: t in [0, 1] (0 for a
   zero-length segment); the nearest point is a + t e. */
static inline double segment_parameter(double rx, double ry, double ex, double ey) {
    double squared = ex * ex + ey * ey;
    double t = squared > 0.0 ? (rx * ex + ry * ey) / squared : 0.0;
    return t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
}

/* Python's (and numpy's) float remainder: the result takes the divisor's sign. */
static inline double floor_mod(double a, double b) {
    double mod = fmod(a, b);
    if (mod != 0.0) {
        if ((b < 0.0) != (mod < 0.0)) mod += b;
    } else {
        mod = copysign(0.0, b);
    }
    return mod;
}

/* --- buffers ----------------------------------------------------------------------------- */

typedef struct {
    double x, y, angle;
} Edge;

typedef struct {
    double cost;
    Py_ssize_t index;
} Ranked;

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

/* The most a module's own Work keeps between calls, bytes (see work_give). */
#define WORK_KEPT_BYTES (1 << 20)

/* Every buffer one kernel call uses (a reduction, a redistribution's hulls, the Expecter).
   A call borrows the module's own with work_take (every count reset, the buffers kept
   from earlier calls: no allocation per call once they are large enough) and gives it
   back with work_give; a zeroed one starts empty. work_free frees the buffers. */
typedef struct {
    Poly ping, pong;       /* clip_halfplanes: alternate clip results */
    Poly part, parts;      /* clip_to_sector: one piece's part, every part */
    Poly arc_points;       /* sensor_arc: the outer arc before its hull */
    Poly arc, mirrored;    /* the sensor arc polygon and its negation */
    Poly sum;              /* Minkowski sums */
    Poly sensors, positions, narrowed;
    Scratch values, flags, cuts, planes, points, edges, lengths;
} Work;

/* The module's state: its own Work and whether a call has it. */
typedef struct {
    Work work;
    int lent;
} ModuleState;

void work_free(Work *w);
/* A Work for one kernel call of `module`: the module's own, unless a call has it already
   (a kernel called while another runs, e.g. from a garbage-collector callback or a
   finalizer that one of its allocations let run), then `local`, zeroed. */
Work *work_take(PyObject *module, Work *local);
/* End the call's use of `w`: the module's own is kept (freed first if it grew past
   WORK_KEPT_BYTES, so one huge call does not hold memory for good), a local one is freed. */
void work_give(PyObject *module, Work *w);
/* Room for `count` vertices (their values kept); -1 with MemoryError set on failure. */
int reserve(Poly *p, Py_ssize_t count);
/* Room for `count` items of `size` bytes (old contents not kept); NULL with MemoryError set. */
void *scratch(Scratch *s, Py_ssize_t count, size_t size);
/* Copy n vertices into dst; src must not point into dst's buffer unless it is its start. */
int copy_into(Poly *dst, const double *src, Py_ssize_t n);
/* a + b, or -1 when the sum would not fit a Py_ssize_t (both >= 0). */
Py_ssize_t checked_add(Py_ssize_t a, Py_ssize_t b);
/* a * b, or -1 when the product would not fit a Py_ssize_t (both >= 0). */
Py_ssize_t checked_multiply(Py_ssize_t a, Py_ssize_t b);

/* --- polygon primitives (polygon.c) -------------------------------------------------- */

/* max(1, ceil(width / step)) pieces of an arc of `width` rad (0 <= width < 2 pi, step > 0);
   1 for NaN. */
Py_ssize_t arc_pieces(double width, double step);
Py_ssize_t outer_arc(double radius, double start, double stop, double *out);
Py_ssize_t outer_disk(double radius, Py_ssize_t sides, double *out);
/* Writes at most SECTOR_POINTS_MAX points. */
Py_ssize_t outer_annular_sector(double inner, double outer, double start, double stop, double *out);
/* `edges` has room for twice the operands' total vertex count; `out` for that total. */
Py_ssize_t minkowski_sum(const double **parts, const Py_ssize_t *sizes, int part_count, Edge *edges, double *out);
/* In place; t, ranked, blocked and chosen hold n items, scratch 2 n doubles. */
Py_ssize_t simplify_outer(double *v, Py_ssize_t n, Py_ssize_t max_vertices, double *t, Ranked *ranked,
                          char *blocked, char *chosen, double *scratch);
double polygon_area(const double *v, Py_ssize_t n);
int remove_collinear(Poly *p, Work *w);
int clip_halfplane(const double *v, Py_ssize_t count, double nx, double ny, double offset, Poly *out, Work *w);
int clip_halfplanes(const double *v, Py_ssize_t n, const double *planes, Py_ssize_t k, Poly *out, Work *w);
int clip_convex(const double *v, Py_ssize_t n, const double *other, Py_ssize_t m, double margin, Poly *out,
                Work *w);
int convex_hull(const double *pts, Py_ssize_t m, Poly *out, Work *w);
int minkowski_pair(const double *a, Py_ssize_t na, const double *b, Py_ssize_t nb, Poly *out, Work *w);
void nearest_on_polygon(const double *v, Py_ssize_t n, double px, double py, double *distance, double *qx,
                        double *qy);
void subtended_arc(const double *v, Py_ssize_t n, double px, double py, double radius, double *lo,
                   double *width);
int intersect_arcs(double a_lo, double a_width, double b_lo, double b_width, double *lo, double *width);
int point_in_convex(const double *v, Py_ssize_t n, const double *lengths, double x, double y, double tolerance);

/* --- arguments (args.c) ---------------------------------------------------------------- */

int parse_doubles(PyObject *const *args, Py_ssize_t count, const char *const *names, double *values);
int parse_cap(PyObject *arg, Py_ssize_t *max_vertices);
int parse_count(PyObject *arg, const char *name, Py_ssize_t low, Py_ssize_t high, Py_ssize_t *value);
/* A C-contiguous float64 buffer of n >= 1 finite (x, y) rows; released on failure. */
int get_vertices(PyObject *object, Py_buffer *view, Py_ssize_t *n);

/* --- heading slices (slices.c) ---------------------------------------------------------- */

/* A sliced map's slices as a kernel reads them: every slice's vertices one after the other
   ((n, 2) float64), each slice's vertex count (k int64, each >= 1, adding up to n) and each
   interval's ends (k float64 each). The views are held until packed_release. */
typedef struct {
    Py_buffer views[4];
    int held;
    const double *v, *lo, *hi;
    const long long *counts;
    Py_ssize_t n, k;
} Packed;

/* Read args[0..3] (points, counts, lo, hi) into p; -1 with an exception set (nothing held). */
int get_packed(PyObject *const *args, Packed *p);
void packed_release(Packed *p);

/* Slices being built: the same layout, with each slice's source (equal sources: the same
   polygon, which merging keeps as it is). All fields start zeroed; slices_free frees them. */
typedef struct {
    Poly points;
    long long *counts, *sources;
    double *lo, *hi;
    Py_ssize_t k, cap;
} SliceList;

int slices_append(SliceList *s, const double *v, Py_ssize_t n, double lo, double hi, long long source);
void slices_free(SliceList *s);
/* New references to the bytes of the points, counts, lo and hi (and sources when `with_sources`)
   stored into out[0..]; -1 with an exception set (none stored). */
int slices_bytes(const SliceList *s, int with_sources, PyObject **out);
/* See uncertainty._slices: clamp_into, home_slice and summary_wedge (the wedge as unwrapped
   centre, cw, ccw). */
double clamp_into(double heading, double lo, double hi);
Py_ssize_t home_slice(const double *lo, const double *hi, Py_ssize_t k, double heading);
void summary_wedge(const double *lo, const double *hi, Py_ssize_t k, double heading, double *wedge);
/* Slack of a heading's test against a slice, rad (uncertainty._slices._ANGLE_SLACK). */
#define ANGLE_SLACK 1e-9

/* --- the kernels, one per concept file ------------------------------------------------- */

PyObject *grow_commands(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *reduce_cone(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *reduce_strip(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *reduce_sectors(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *expecter_points(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *polygon_distance(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *point_in_solid_convex(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *merge_groups(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *distribute_slices(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *grow_slices(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *reduce_cone_slices(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *reduce_strip_slices(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *parse_float_rows(PyObject *self, PyObject *const *args, Py_ssize_t nargs);

#endif
