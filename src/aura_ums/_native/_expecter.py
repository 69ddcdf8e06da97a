"""The Expecter's geometry: the numpy reference and the compiled kernel behind one call.

From the map's polygon ``P`` and wedge ``W``, the landmark's ground set ``Q`` (its point
or segment, Minkowski-summed with an outer polygon of its uncertainty disk) and the
camera mount, the points whose projections' box holds every projection of the landmark:

1. ``D = Q (+) (-P)``, the differences q - p (one Minkowski sum of three operands);
2. robot-frame points whose hull holds ``R(-h) d`` for every d in D and h in W: each
   vertex of D at both ends of the wedge and at the tangent points of its swept arc's
   outer polygon (a full-circle wedge: the outer polygon of the disk through the
   farthest vertex);
3. the prism over them between the landmark's heights, in the camera frame, cut by the
   plane z = cut_plane in front of the camera (its vertices in front and its edges'
   crossings of the plane);
4. those points divided by their depth.

The numpy functions are the specification; ``expecter.c`` repeats them operation for
operation. The Expecter itself (``aura_ums.expecter``) turns the result into pixels.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from aura_ums._native import _extension
from aura_ums._native._extension import points_view
from aura_ums.geometry import convex_hull, minkowski_sum, outer_disk

if _extension.BUILT:
    from aura_ums._native._kernels import expecter_points as _compiled_expecter_points

Array = NDArray[np.float64]


class ExpectedPoints(NamedTuple):
    """Normalized image points (x / z, y / z) spanning every projection, and their box.

    Attributes
    ----------
    points : ndarray, shape (k, 2)
        The points, dimensionless (camera frame: x right, y down, divided by depth).
    x_min, y_min, x_max, y_max : float
        Their bounding box.
    """

    points: Array
    x_min: float
    y_min: float
    x_max: float
    y_max: float


def _arc_pieces(width: float, step: float) -> int:
    return max(1, math.ceil(width / step))


def _to_camera(rotation: Array, forward: float, left: float, ground: Array, dz: float) -> Array:
    """Camera-frame points of robot-frame ground points raised by ``dz`` (m): row vector @ rotation."""
    px, py = ground[:, 0] - forward, ground[:, 1] - left
    return np.column_stack(
        [px * rotation[0, j] + py * rotation[1, j] + dz * rotation[2, j] for j in range(3)]
    )


def _relative_ground(
    difference: Array, full_circle: bool, heading_lo: float, heading_width: float, arc_step: float
) -> Array:
    """Step 2: robot-frame points (m) whose hull holds R(-h) d for every d and heading h."""
    if full_circle:
        reach = float(np.max(np.hypot(difference[:, 0], difference[:, 1])))
        return outer_disk(np.zeros(2), reach, _arc_pieces(math.tau, arc_step))
    x, y = difference[:, 0], difference[:, 1]
    c, s = math.cos(-heading_lo), math.sin(-heading_lo)
    ends = [np.column_stack([c * x - s * y, s * x + c * y])]
    if heading_width > 0.0:
        heading_hi = heading_lo + heading_width
        c, s = math.cos(-heading_hi), math.sin(-heading_hi)
        ends.append(np.column_stack([c * x - s * y, s * x + c * y]))
        # The tangent points: d at angle phase(d) - heading_hi + (2 j + 1) half, stretched
        # by 1 / cos(half): d rotated by -heading_hi + (2 j + 1) half and stretched.
        count = _arc_pieces(heading_width, arc_step)
        half = heading_width / (2 * count)
        stretch = 1.0 / math.cos(half)
        angles = -heading_hi + (2 * np.arange(count) + 1) * half
        tx, ty = stretch * np.cos(angles), stretch * np.sin(angles)
        ends.append(
            np.column_stack(
                [
                    (tx[None, :] * x[:, None] - ty[None, :] * y[:, None]).ravel(),
                    (ty[None, :] * x[:, None] + tx[None, :] * y[:, None]).ravel(),
                ]
            )
        )
    return np.concatenate(ends)


def _clip_to_front(
    ground: Array,
    rotation: Array,
    forward: float,
    left: float,
    heights: tuple[float, ...],
    cut_plane: float,
) -> Array | None:
    """Step 3: camera-frame points (m) spanning the prism's part in front of the cut plane."""
    depth = (ground[:, 0] - forward) * rotation[0, 2] + (ground[:, 1] - left) * rotation[1, 2]
    depth_lo, depth_hi = depth + heights[0] * rotation[2, 2], depth + heights[-1] * rotation[2, 2]
    nearest = float(np.minimum(depth_lo, depth_hi).min())
    farthest = float(np.maximum(depth_lo, depth_hi).max())
    if farthest <= cut_plane:
        return None
    if nearest >= cut_plane:
        return np.concatenate([_to_camera(rotation, forward, left, ground, dz) for dz in heights])
    # Part of the prism is behind: cut it along its known edges (a prism over the hull).
    hull = convex_hull(ground)
    layers = [_to_camera(rotation, forward, left, hull, dz) for dz in heights]
    starts: list[Array] = []
    stops: list[Array] = []
    if len(hull) >= 2:
        for layer in layers:
            starts.append(layer)
            stops.append(np.roll(layer, -1, axis=0))
    if len(layers) == 2:
        starts.append(layers[0])
        stops.append(layers[1])
    vertices = np.concatenate(layers)
    front = vertices[vertices[:, 2] >= cut_plane]
    if not starts:
        return front if len(front) else None
    a = np.concatenate(starts)
    b = np.concatenate(stops)
    crossing = (a[:, 2] - cut_plane) * (b[:, 2] - cut_plane) < 0.0
    a, b = a[crossing], b[crossing]
    t = (cut_plane - a[:, 2]) / (b[:, 2] - a[:, 2])
    cut = a + t[:, None] * (b - a)
    cut[:, 2] = cut_plane
    points = np.concatenate([front, cut])
    return points if len(points) else None


def expecter_points_reference(
    vertices: Array,
    ends: tuple[tuple[float, float], ...],
    radius: float,
    disk_sides: int,
    full_circle: bool,
    heading_lo: float,
    heading_width: float,
    arc_step: float,
    rotation: tuple[float, ...],
    forward: float,
    left: float,
    heights: tuple[float, ...],
    cut_plane: float,
) -> ExpectedPoints | None:
    """Return normalized image points whose box holds the landmark's projection from every pose.

    The numpy reference, the specification ``expecter.c`` follows: ``aura_ums._native.expecter_points``
    is this function, or :func:`expecter_points_compiled` when the kernels run compiled.

    Parameters
    ----------
    vertices : ndarray, shape (n, 2)
        The map's polygon, counter-clockwise, metres, finite.
    ends : tuple of (x, y)
        The landmark's ground point, or its segment's two ends, metres.
    radius : float
        The landmark's position uncertainty, metres, >= 0.
    disk_sides : int
        Sides of the outer polygon of that uncertainty disk, >= 3.
    full_circle : bool
        Whether any heading is possible (then ``heading_lo`` and ``heading_width`` are unused).
    heading_lo, heading_width : float
        The wedge's headings, radians, from ``heading_lo`` counter-clockwise
        (``0 <= heading_width < 2 pi``).
    arc_step : float
        Angular step of the swept arcs' outer polygons, radians, in [2 pi / 2^20, 2 pi / 3].
    rotation : tuple of 9 float
        The mount's rotation, row-major: a robot-frame row vector times it is the
        camera-frame vector.
    forward, left : float
        The camera's position in the robot frame, metres.
    heights : tuple of float
        The landmark's heights relative to the camera, metres: one, or the (lower, upper) two.
    cut_plane : float
        Depth of the plane in front of the camera that cuts the prism, metres, > 0.

    Returns
    -------
    ExpectedPoints or None
        The points and their box; None when the landmark is behind the cut plane from
        every pose.

    Examples
    --------
    >>> from aura_ums import _native
    >>> level = (0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0)   # looking along +x
    >>> here = np.array([[0.0, 0.0]])
    >>> view = (0.1, level, 0.0, 0.0, (1.0,), 0.05)                 # arc step, mount, height, cut
    >>> ahead = _native.expecter_points(here, ((10.0, 0.0),), 0.0, 64, False, 0.0, 0.0, *view)
    >>> ahead.x_max - ahead.x_min, ahead.y_min         # straight ahead, 1 m up at 10 m
    (0.0, -0.1)
    >>> _native.expecter_points(here, ((-10.0, 0.0),), 0.0, 64, False, 0.0, 0.0, *view)   # behind: None
    """
    parts = [np.array(ends, dtype=np.float64)]
    if radius > 0.0:
        parts.append(outer_disk(np.zeros(2), radius, disk_sides))
    parts.append(-np.asarray(vertices))
    difference = minkowski_sum(*parts)
    ground = _relative_ground(difference, full_circle, heading_lo, heading_width, arc_step)
    camera = _clip_to_front(
        ground, np.array(rotation, dtype=np.float64).reshape(3, 3), forward, left, heights, cut_plane
    )
    if camera is None:
        return None
    normalized = camera[:, :2] / camera[:, 2:3]
    lower, upper = normalized.min(axis=0).tolist(), normalized.max(axis=0).tolist()
    return ExpectedPoints(normalized, lower[0], lower[1], upper[0], upper[1])


def expecter_points_compiled(
    vertices: Array,
    ends: tuple[tuple[float, float], ...],
    radius: float,
    disk_sides: int,
    full_circle: bool,
    heading_lo: float,
    heading_width: float,
    arc_step: float,
    rotation: tuple[float, ...],
    forward: float,
    left: float,
    heights: tuple[float, ...],
    cut_plane: float,
) -> ExpectedPoints | None:
    """Compiled :func:`expecter_points` (needs the extension module: ``_extension.BUILT``)."""
    (ax, ay), (bx, by) = ends[0], ends[-1]
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rotation
    found = _compiled_expecter_points(
        vertices if vertices.flags.c_contiguous else np.ascontiguousarray(vertices, dtype=np.float64),
        len(ends),
        disk_sides,
        1 if full_circle else 0,
        len(heights),
        ax,
        ay,
        bx,
        by,
        radius,
        heading_lo,
        heading_width,
        arc_step,
        r00,
        r01,
        r02,
        r10,
        r11,
        r12,
        r20,
        r21,
        r22,
        forward,
        left,
        heights[0],
        heights[-1],
        cut_plane,
    )
    if found is None:
        return None
    raw, x_min, y_min, x_max, y_max = found
    return ExpectedPoints(points_view(raw), x_min, y_min, x_max, y_max)
