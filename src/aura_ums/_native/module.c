/*
 * The extension module aura_ums._native._kernels: the kernels of growth.c, reduce.c,
 * expecter.c, distance.c, slices.c and csv.c, and the constants of kernels.h, exported so that a test can
 * check them against their Python twins.
 */
#include "kernels.h"

static PyMethodDef methods[] = {
    {"grow_commands", (PyCFunction)(void (*)(void))grow_commands, METH_FASTCALL,
     "grow_commands(vertices, center_x, center_y, wedge_center, wedge_cw, wedge_ccw, rotation_loss, rotation_sd, "
     "translation_loss, translation_sd, translation_inertial_loss, drift, skitter, skitter_sd, sigmas, commands, "
     "max_vertices) -> (vertex bytes, center_x, center_y, wedge_center unwrapped, wedge_cw, wedge_ccw) after "
     "growing by each (turn, run) of the flat sequence commands in turn"},
    {"reduce_cone", (PyCFunction)(void (*)(void))reduce_cone, METH_FASTCALL,
     "reduce_cone(vertices, center_x, center_y, wedge_center, wedge_cw, wedge_ccw, forward, left, landmark_x, "
     "landmark_y, widen, bearing, bearing_error, range_min, range_max, piece, max_vertices) -> (vertex bytes, "
     "arc_lo, arc_width, center_x, center_y, area_before, area_after), or an int reason code"},
    {"reduce_strip", (PyCFunction)(void (*)(void))reduce_strip, METH_FASTCALL,
     "reduce_strip(vertices, center_x, center_y, wedge_center, wedge_cw, wedge_ccw, forward, left, start_x, "
     "start_y, end_x, end_y, position_uncertainty, offset, offset_error, angle, angle_error, max_vertices) -> "
     "(vertex bytes, arc_lo, arc_width, center_x, center_y, area_before, area_after), or an int reason code"},
    {"reduce_sectors", (PyCFunction)(void (*)(void))reduce_sectors, METH_FASTCALL,
     "reduce_sectors(vertices, center_x, center_y, lo, step, count, half, arguments, max_vertices) -> (points, "
     "counts, sectors, values bytes): the sectors of a wedge each reduced by every (kind, ...) row in turn"},
    {"expecter_points", (PyCFunction)(void (*)(void))expecter_points, METH_FASTCALL,
     "expecter_points(vertices, base_count, disk_sides, full_circle, level_count, base_ax, base_ay, base_bx, "
     "base_by, radius, heading_lo, heading_width, arc_step, r00, r01, r02, r10, r11, r12, r20, r21, r22, forward, "
     "left, dz_lo, dz_hi, cut_plane) -> None (behind the camera) or (bytes of (k, 2) float64 normalized points, "
     "x_min, y_min, x_max, y_max)"},
    {"polygon_distance", (PyCFunction)(void (*)(void))polygon_distance, METH_FASTCALL,
     "polygon_distance(vertices, ax, ay, bx, by) -> distance from the convex polygon to the segment [a, b]"},
    {"point_in_solid_convex", (PyCFunction)(void (*)(void))point_in_solid_convex, METH_FASTCALL,
     "point_in_solid_convex(vertices, x, y, tolerance) -> whether (x, y) lies within tolerance of the convex "
     "counter-clockwise polygon of positive area (at least 3 vertices)"},
    {"merge_groups", (PyCFunction)(void (*)(void))merge_groups, METH_FASTCALL,
     "merge_groups(points, counts, max_vertices) -> tuple of vertex bytes: for each group of counts[i] "
     "consecutive rows of the (n, 2) float64 points, their convex hull with the outer vertex cap"},
    {"distribute_slices", (PyCFunction)(void (*)(void))distribute_slices, METH_FASTCALL,
     "distribute_slices(points, counts, starts, stops, sources, cells, max_vertices, max_slices, heading) -> "
     "(points, counts, lo, hi, sources bytes, wedge_center, wedge_cw, wedge_ccw): the pieces on the heading grid, "
     "each cell the capped hull of what meets it, then neighbours merged under max_slices"},
    {"grow_slices", (PyCFunction)(void (*)(void))grow_slices, METH_FASTCALL,
     "grow_slices(points, counts, lo, hi, center_x, center_y, heading, rotation_loss, rotation_sd, "
     "translation_loss, translation_sd, translation_inertial_loss, drift, skitter, skitter_sd, sigmas, commands, "
     "max_vertices) -> (points, counts, starts, stops bytes, center_x, center_y, heading unwrapped): every slice "
     "grown by the commands"},
    {"reduce_cone_slices", (PyCFunction)(void (*)(void))reduce_cone_slices, METH_FASTCALL,
     "reduce_cone_slices(points, counts, lo, hi, center_x, center_y, heading, forward, left, landmark_x, "
     "landmark_y, widen, bearing, bearing_error, range_min, range_max, piece, max_vertices) -> (points, counts, "
     "lo, hi bytes, center_x, center_y, wedge_center, wedge_cw, wedge_ccw), or an int reason code"},
    {"reduce_strip_slices", (PyCFunction)(void (*)(void))reduce_strip_slices, METH_FASTCALL,
     "reduce_strip_slices(points, counts, lo, hi, center_x, center_y, heading, forward, left, start_x, start_y, "
     "end_x, end_y, position_uncertainty, offset, offset_error, angle, angle_error, max_vertices) -> (points, "
     "counts, lo, hi bytes, center_x, center_y, wedge_center, wedge_cw, wedge_ccw), or an int reason code"},
    {"parse_float_rows", (PyCFunction)(void (*)(void))parse_float_rows, METH_FASTCALL,
     "parse_float_rows(data, rows, columns) -> bytearray of rows x columns float64 (row-major), or None "
     "when a cell is not a plain decimal number or the rows are not rows lines of columns cells"},
    {NULL, NULL, 0, NULL},
};

static int add_float(PyObject *module, const char *name, double value) {
    PyObject *object = PyFloat_FromDouble(value);
    if (!object) return -1;
    int status = PyModule_AddObjectRef(module, name, object);
    Py_DECREF(object);
    return status;
}

/* Every constant of kernels.h that a Python twin repeats. */
static int add_constants(PyObject *module) {
    static const struct {
        const char *name;
        double value;
    } floats[] = {
        {"ARC_STEP", ARC_STEP},         {"TINY_ANGLE", TINY_ANGLE},   {"PARALLEL_EPS", PARALLEL_EPS},
        {"NOISE_EDGE", NOISE_EDGE},     {"FARTHEST_MERGE", FARTHEST_MERGE}, {"EXTENDABLE", EXTENDABLE},
        {"SUPPORT_MARGIN", SUPPORT_MARGIN}, {"SAME_POINT", SAME_POINT}, {"MERGE_EPS", MERGE_EPS},
        {"MERGE_ROUNDING", MERGE_ROUNDING},
        {"COLLINEAR_EPS", COLLINEAR_EPS}, {"TOLERANCE", TOLERANCE},  {"TANGENT_STEP", TANGENT_STEP},
    };
    static const struct {
        const char *name;
        long value;
    } integers[] = {
        {"FULL_DISK_SIDES", FULL_DISK_SIDES},
        {"SKITTER_SIDES", SKITTER_SIDES},
        {"SENSOR_ARC_SIDES", SENSOR_ARC_SIDES},
        {"NO_POSITION", NO_POSITION},
        {"NO_SENSOR_POSITION", NO_SENSOR_POSITION},
        {"NO_BEARING_HEADING", NO_BEARING_HEADING},
        {"NO_LINE_HEADING", NO_LINE_HEADING},
        {"NO_OFFSET_POSITION", NO_OFFSET_POSITION},
    };
    for (size_t i = 0; i < sizeof(floats) / sizeof(floats[0]); i++)
        if (add_float(module, floats[i].name, floats[i].value) < 0) return -1;
    for (size_t i = 0; i < sizeof(integers) / sizeof(integers[0]); i++)
        if (PyModule_AddIntConstant(module, integers[i].name, integers[i].value) < 0) return -1;
    return 0;
}

static int exec_module(PyObject *module) { return add_constants(module); }

/* The module's own Work (see work_take): freed with the module. */
static void free_module(void *module) {
    ModuleState *state = PyModule_GetState((PyObject *)module);
    if (state) work_free(&state->work);
}

static PyModuleDef_Slot slots[] = {{Py_mod_exec, exec_module}, {0, NULL}};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_kernels",
    "Compiled kernels of aura-ums (growth, reductions, the Expecter, the schemas' distance); private: use the "
    "typed wrappers of aura_ums._native, which hold the numpy references.",
    sizeof(ModuleState), methods, slots, NULL, NULL, free_module};

PyMODINIT_FUNC PyInit__kernels(void) { return PyModuleDef_Init(&module); }
