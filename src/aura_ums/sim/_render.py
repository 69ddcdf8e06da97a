"""The synthetic camera: numpy rendering of a grayscale image of a scene from a true pose.

The image is drawn in painter's order on a float buffer:

1. the background, computed once per camera (the camera is fixed on the robot and the
   ground is flat): sky shaded by elevation above the horizon, bare ground below it;
2. ground patches and strips, clipped to the half-space in front of the camera (and, with
   lens distortion, to the cone of rays within the lens's fold,
   :func:`~aura_ums.camera.fold_radius`: the camera images no others), projected with
   :meth:`~aura_ums.camera.Camera.project_camera_frame` and filled;
3. the ground texture, looked up at the world point of every ground pixel (the point is
   fixed in the robot frame, so only a rotation and a translation per frame) and faded
   with distance;
4. poles and building walls facing the camera, farthest object first;
5. clutter lines in the image, then sensor noise; rounded to ``uint8``.

Polygons are filled by an even-odd scan-line rule on pixel centres, vectorized over the
rows and columns of their bounding box.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from aura_ums._validate import Range, check_rng, integer_at_least
from aura_ums.camera import Camera, fold_radius, undistort_points, within_fold
from aura_ums.errors import InputError
from aura_ums.sim._scene import Building, Pole, Scene
from aura_ums.uncertainty import Pose

Array = NDArray[np.float64]

#: Geometry closer to the camera than this (m, along the optical axis) is clipped away.
_CLIP_NEAR = 0.05

#: Distance (m) within which the ground texture shows at full contrast; it fades as d0/d beyond.
_TEXTURE_FADE = 4.0

#: Ground farther than this (m) gets the texture of this distance (it has faded to ~nothing).
TEXTURE_HORIZON = 500.0

#: Points per polygon edge when the camera has lens distortion (edges become curves).
DISTORTION_SUBDIVISIONS = 8

#: Bisections locating where a polygon's edge leaves the cone of the lens's fold (2**-50 of the edge).
_FOLD_BISECTIONS = 50

_SKY_SPAN = math.radians(30.0)


def fill_polygon(image: NDArray[np.float32], polygon: Array, value: float) -> None:
    """Fill a simple polygon ``(n, 2)`` of pixel coordinates ``(u, v)`` into ``image`` in place.

    A pixel is filled when its centre lies inside by the even-odd rule, edges counted
    half-open (left and top edges in, right and bottom out), so polygons that share an
    edge never both fill a pixel. Vertices may lie far outside the image.

    Examples
    --------
    >>> image = np.zeros((4, 6), dtype=np.float32)
    >>> fill_polygon(image, np.array([[0.5, 0.5], [4.5, 0.5], [4.5, 2.5], [0.5, 2.5]]), 1.0)
    >>> image.astype(int).tolist()
    [[0, 0, 0, 0, 0, 0], [0, 1, 1, 1, 1, 0], [0, 1, 1, 1, 1, 0], [0, 0, 0, 0, 0, 0]]
    >>> fill_polygon(image, np.array([[1.0, 1.0], [2.0, 1.0]]), 9.0)   # no area: nothing drawn
    >>> float(image.max())
    1.0
    """
    if len(polygon) < 3 or not np.all(np.isfinite(polygon)):
        return
    height, width = image.shape
    u, v = polygon[:, 0], polygon[:, 1]
    row0, row1 = max(math.ceil(float(v.min())), 0), min(math.ceil(float(v.max())), height)
    col0, col1 = max(math.ceil(float(u.min())), 0), min(math.ceil(float(u.max())), width)
    if row1 <= row0 or col1 <= col0:
        return
    following = np.arange(1, len(polygon) + 1) % len(polygon)
    u2, v2 = u[following], v[following]
    sloped = v != v2
    ua, va, ub, vb = u[sloped], v[sloped], u2[sloped], v2[sloped]
    rows = np.arange(row0, row1, dtype=np.float64)[:, None]
    crosses = (rows >= np.minimum(va, vb)) & (rows < np.maximum(va, vb))
    x = np.where(crosses, ua + (rows - va) * ((ub - ua) / (vb - va)), np.inf)
    x.sort(axis=1)
    pairs = int(crosses.sum(axis=1).max()) // 2
    if pairs == 0:
        return
    cols = np.arange(col0, col1, dtype=np.float64)
    mask = (cols >= x[:, 0, None]) & (cols < x[:, 1, None])
    for k in range(1, pairs):
        mask |= (cols >= x[:, 2 * k, None]) & (cols < x[:, 2 * k + 1, None])
    image[row0:row1, col0:col1][mask] = value


def _clip_convex(
    points: Array, inside: NDArray[np.bool_], cut: Callable[[Array, Array, bool], Array]
) -> Array:
    """Clip a planar polygon ``(n, 3)`` to a convex region (Sutherland-Hodgman).

    ``inside`` marks the vertices in the region; ``cut(a, b, a_inside)`` returns the point
    where the edge from vertex ``a`` to the next, ``b``, crosses the region's boundary.
    """
    if inside.all():
        return points
    if not inside.any():
        return points[:0]
    out: list[Array] = []
    n = len(points)
    for i in range(n):
        a, b = points[i], points[(i + 1) % n]
        a_in, b_in = bool(inside[i]), bool(inside[(i + 1) % n])
        if a_in:
            out.append(a)
        if a_in != b_in:
            out.append(cut(a, b, a_in))
    return np.array(out)


def _clip_near(points: Array, near: float) -> Array:
    """Clip a planar polygon ``(n, 3)`` in the camera frame to ``z >= near``."""

    def cut(a: Array, b: Array, _: bool) -> Array:
        t = (near - a[2]) / (b[2] - a[2])
        return np.asarray(a + t * (b - a), dtype=np.float64)

    return _clip_convex(points, points[:, 2] >= near, cut)


def _clip_fold(points: Array, distortion: tuple[float, float, float, float, float]) -> Array:
    """Clip a planar polygon ``(n, 3)`` in front of the camera to the rays within the lens's fold.

    The cone of rays :func:`~aura_ums.camera.within_fold` accepts (``z > 0``) is convex: each
    edge that leaves it is cut where it does, found by bisection and kept on the inside by
    that very test; the cone's curved boundary between two cuts becomes their chord, which
    lies inside.
    """
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        inside = within_fold(points[:, 0] / points[:, 2], points[:, 1] / points[:, 2], distortion)

    def cut(a: Array, b: Array, a_inside: bool) -> Array:
        start, end = (a, b) if a_inside else (b, a)
        low, high = 0.0, 1.0  # start + low * (end - start) is inside, + high * (...) outside
        for _ in range(_FOLD_BISECTIONS):
            middle = 0.5 * (low + high)
            x, y, z = start + middle * (end - start)
            if within_fold(x / z, y / z, distortion):
                low = middle
            else:
                high = middle
        return np.asarray(start + low * (end - start), dtype=np.float64)

    return _clip_convex(points, inside, cut)


#: Standard deviation of the sensor noise, gray levels: beyond 255 every pixel is black or white.
NOISE = Range(0.0, 255.0, "gray levels")
#: Clutter lines drawn over each frame (about 190 us each: 1,000,000 are minutes a frame).
CLUTTER_LINES = Range(0, 1_000_000, "lines")


class SyntheticCamera:
    """Render grayscale images of a :class:`Scene` as a :class:`~aura_ums.camera.Camera` sees it.

    Parameters
    ----------
    camera : Camera
        The camera on its mount (its size is the image's).
    scene : Scene
        What to draw.
    rng : numpy.random.Generator
        Source of the sensor noise and the clutter lines, drawn anew for every frame: a
        seed fixes the sequence of images.
    noise : float
        Standard deviation of the additive Gaussian sensor noise, gray levels, in [0, 255]
        (drawn through a table of 65536 quantiles, so within +-4.1 sigma).
    clutter_lines : int
        Random short line segments (5 to 40 pixels, random gray) drawn over every frame,
        in [0, 1000000]: image clutter that the perception must ignore.

    Examples
    --------
    >>> from aura_ums.camera import CameraIntrinsics, CameraMount
    >>> camera = Camera(CameraIntrinsics(549.0, 549.0, 255.5, 239.5, 512, 480), CameraMount(1.2))
    >>> scene = Scene(poles=(Pole(10.0, 0.0, 0.0, 6.0, 0.1),))
    >>> synthetic = SyntheticCamera(camera, scene, np.random.default_rng(0), noise=0.0)
    >>> image = synthetic.render(Pose(0.0, 0.0, 0.0))
    >>> image.shape, image.dtype, int(image[200, 255]), int(image[200, 100])   # pole, sky
    ((480, 512), dtype('uint8'), 45, 210)
    >>> bool((synthetic.render(Pose(0.0, 0.0, math.pi)) != 45).all())   # the pole behind: not drawn
    True
    """

    __slots__ = (
        "_background",
        "_camera",
        "_clutter",
        "_ground_shades",
        "_ground_sizes",
        "_ground_span",
        "_ground_world",
        "_ground_x",
        "_ground_y",
        "_noise",
        "_noise_table",
        "_rng",
        "_scene",
        "_texture_offset",
        "_texture_weight",
    )

    def __init__(
        self,
        camera: Camera,
        scene: Scene,
        rng: np.random.Generator,
        *,
        noise: float = 2.0,
        clutter_lines: int = 0,
    ) -> None:
        if not isinstance(camera, Camera):
            raise InputError(f"camera: expected a Camera, got {type(camera).__name__}")
        if not isinstance(scene, Scene):
            raise InputError(f"scene: expected a Scene, got {type(scene).__name__}")
        check_rng(rng)
        self._noise = NOISE.check(noise, "noise")
        self._clutter = integer_at_least(clutter_lines, "clutter_lines", 0)
        if self._clutter > CLUTTER_LINES.high:
            raise InputError(
                f"clutter_lines: expected at most {CLUTTER_LINES.high:,.0f} lines (each drawn in every "
                f"frame, about 190 us: 190 s a frame), got {clutter_lines!r}"
            )
        self._camera = camera
        self._scene = scene
        self._rng = rng
        from scipy.special import ndtri  # deferred: scipy takes ~0.5 s to import

        quantiles = (np.arange(65536, dtype=np.float64) + 0.5) / 65536.0
        self._noise_table = (self._noise * ndtri(quantiles)).astype(np.float32)
        self._prepare_background()
        polygons = [patch.polygon for patch in scene.patches] + [stripe.polygon() for stripe in scene.stripes]
        self._ground_sizes = [len(polygon) for polygon in polygons]
        self._ground_shades = [patch.shade for patch in scene.patches] + [
            stripe.shade for stripe in scene.stripes
        ]
        flat = np.concatenate(polygons) if polygons else np.zeros((0, 2))
        self._ground_world = np.column_stack([flat, np.zeros(len(flat))])

    def _prepare_background(self) -> None:
        k, mount = self._camera.intrinsics, self._camera.mount
        vv, uu = np.mgrid[0 : k.height, 0 : k.width]
        pixels = np.column_stack([uu.ravel(), vv.ravel()]).astype(np.float64)
        if k.distortion is None:
            normalized = np.column_stack([(pixels[:, 0] - k.cx) / k.fx, (pixels[:, 1] - k.cy) / k.fy])
        else:
            normalized = undistort_points(k, pixels)
        rays_camera = np.column_stack([normalized, np.ones(len(pixels))])
        rays = rays_camera @ mount.rotation().T  # robot frame (x forward, y left, z up)
        valid = np.all(np.isfinite(rays), axis=1)
        horizontal = np.hypot(rays[:, 0], rays[:, 1])
        elevation = np.arctan2(rays[:, 2], horizontal)
        ground = valid & (rays[:, 2] < -1e-9)
        horizon_shade, zenith_shade = self._scene.sky_shades
        sky = horizon_shade + (zenith_shade - horizon_shade) * np.clip(elevation / _SKY_SPAN, 0.0, 1.0)
        background = np.where(ground, self._scene.ground_shade, sky)
        background[~valid] = 0.0
        self._background = background.reshape(k.height, k.width).astype(np.float32)
        # Ground pixels fill the rows below the horizon: keep the span of the flat image from
        # the first to the last ground pixel (a slice, not a gather), weight 0 on sky in it.
        index = np.flatnonzero(ground)
        lo, hi = (int(index[0]), int(index[-1]) + 1) if len(index) else (0, 0)
        span = ground[lo:hi]
        t = np.where(span, mount.height / np.where(span, -rays[lo:hi, 2], 1.0), 0.0)
        ground_x = mount.forward + t * rays[lo:hi, 0]
        ground_y = mount.left + t * rays[lo:hi, 1]
        distance = np.hypot(ground_x, ground_y)
        # Beyond TEXTURE_HORIZON the texture has faded away: pull those points in, so that
        # float32 texture coordinates keep sub-cell precision.
        shrink = np.minimum(1.0, TEXTURE_HORIZON / np.maximum(distance, 1e-6))
        ground_x, ground_y = ground_x * shrink, ground_y * shrink
        weight = np.minimum(1.0, _TEXTURE_FADE / np.maximum(distance, 1e-6)) * self._scene.texture_contrast
        scale = 1.0 / self._scene.texture_cell
        self._ground_span = (lo, hi)
        size = 1 if self._scene.texture is None else self._scene.texture.shape[0]
        reach = (TEXTURE_HORIZON + abs(mount.forward) + abs(mount.left)) * scale
        self._texture_offset = float(size * (math.ceil(reach / size) + 1))
        self._ground_x = np.where(span, ground_x * scale, 0.0).astype(np.float32)
        self._ground_y = np.where(span, ground_y * scale, 0.0).astype(np.float32)
        self._texture_weight = np.where(span, weight, 0.0).astype(np.float32)

    @property
    def camera(self) -> Camera:
        """The camera."""
        return self._camera

    @property
    def scene(self) -> Scene:
        """The scene."""
        return self._scene

    def _project_polygon(self, points_camera: Array) -> Array:
        clipped = _clip_near(points_camera, _CLIP_NEAR)
        distortion = self._camera.intrinsics.distortion
        if distortion is not None and len(clipped) >= 3 and fold_radius(distortion) < math.inf:
            clipped = _clip_fold(clipped, distortion)
        if len(clipped) < 3:
            return clipped[:, :2]
        if distortion is not None:
            nxt = np.roll(clipped, -1, axis=0)
            steps = np.arange(DISTORTION_SUBDIVISIONS)[None, :, None] / DISTORTION_SUBDIVISIONS
            clipped = (clipped[:, None, :] + steps * (nxt - clipped)[:, None, :]).reshape(-1, 3)
            # A point of a chord between two cuts of the fold's cone is inside it; should rounding
            # put one out (NaN), the polygon is drawn without that point rather than not at all.
            pixels = self._camera.project_camera_frame(clipped)
            return pixels[np.isfinite(pixels).all(axis=1)]
        return self._camera.project_camera_frame(clipped)

    def _fill_all(
        self, image: NDArray[np.float32], camera_points: Array, sizes: list[int], shades: list[float]
    ) -> None:
        """Fill planar polygons given by their camera-frame vertices, concatenated, in order.

        Polygons wholly behind the near plane are skipped; those wholly in front are
        projected together and skipped when their bounding box misses the image; only the
        ones that cross the near plane are clipped one by one.
        """
        k = self._camera.intrinsics
        starts = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.intp)
        z = camera_points[:, 2]
        front = np.maximum.reduceat(z, starts) >= _CLIP_NEAR
        whole = np.minimum.reduceat(z, starts) >= _CLIP_NEAR
        if k.distortion is None:
            pixels = self._camera.project_camera_frame(camera_points)
            with np.errstate(invalid="ignore"):
                u_min, u_max = (
                    np.minimum.reduceat(pixels[:, 0], starts),
                    np.maximum.reduceat(pixels[:, 0], starts),
                )
                v_min, v_max = (
                    np.minimum.reduceat(pixels[:, 1], starts),
                    np.maximum.reduceat(pixels[:, 1], starts),
                )
                seen = (u_max > -1.0) & (u_min < k.width) & (v_max > -1.0) & (v_min < k.height)
        else:  # distorted edges are curves: subdivide them before projecting (_project_polygon)
            pixels = camera_points[:, :2]
            whole = seen = np.zeros_like(whole)
        for index in np.flatnonzero(front):
            start, size = int(starts[index]), sizes[index]
            if whole[index]:
                if seen[index]:
                    fill_polygon(image, pixels[start : start + size], shades[index])
            else:
                fill_polygon(image, self._project_polygon(camera_points[start : start + size]), shades[index])

    def _draw_ground(self, image: NDArray[np.float32], pose: Pose) -> None:
        if not self._ground_sizes:
            return
        camera_points = self._camera.to_camera_frame(pose.as_array(), self._ground_world)[0]
        self._fill_all(image, camera_points, self._ground_sizes, self._ground_shades)

    def _draw_texture(self, image: NDArray[np.float32], pose: Pose) -> None:
        tile = self._scene.texture
        lo, hi = self._ground_span
        if tile is None or self._scene.texture_contrast == 0.0 or hi == lo:
            return
        size = tile.shape[0]
        mask = size - 1  # a power of two: wrap by bitwise and
        scale = 1.0 / self._scene.texture_cell
        # The offset keeps the coordinates positive, so truncation is floor (the tile repeats).
        offset = self._texture_offset
        c, s = np.float32(math.cos(pose.heading)), np.float32(math.sin(pose.heading))
        wx = c * self._ground_x
        wx -= s * self._ground_y
        wx += np.float32(pose.x * scale % size + offset)
        wy = s * self._ground_x
        wy += c * self._ground_y
        wy += np.float32(pose.y * scale % size + offset)
        ix = wx.astype(np.int32)
        ix &= mask
        iy = wy.astype(np.int32)
        iy &= mask
        iy *= size
        iy += ix
        values = np.take(tile.reshape(-1), iy)
        values *= self._texture_weight
        image.reshape(-1)[lo:hi] += values

    def _objects(self, pose: Pose) -> list[tuple[float, Pole | Building]]:
        mount = self._camera.mount
        c, s = math.cos(pose.heading), math.sin(pose.heading)
        eye = np.array(
            [pose.x + c * mount.forward - s * mount.left, pose.y + s * mount.forward + c * mount.left]
        )
        ordered: list[tuple[float, Pole | Building]] = []
        for pole in self._scene.poles:
            ordered.append((math.hypot(pole.x - eye[0], pole.y - eye[1]) - pole.radius, pole))
        for building in self._scene.buildings:
            a = building.footprint
            d = np.roll(a, -1, axis=0) - a
            t = np.clip(np.einsum("ij,ij->i", eye - a, d) / np.einsum("ij,ij->i", d, d), 0.0, 1.0)
            ordered.append((float(np.min(np.hypot(*(a + t[:, None] * d - eye).T))), building))
        ordered.sort(key=lambda item: -item[0])
        return ordered

    def _faces(self, item: Pole | Building, eye: Array) -> list[tuple[Array, float]]:
        """World polygons ``(k, 3)`` of the faces of ``item`` that face the camera, with shades."""
        if isinstance(item, Pole):
            dx, dy = item.x - eye[0], item.y - eye[1]
            distance = math.hypot(dx, dy)
            if distance <= item.radius:
                return []
            half = item.radius * distance / math.sqrt(distance * distance - item.radius * item.radius)
            px, py = -dy / distance * half, dx / distance * half
            quad = np.array(
                [
                    [item.x - px, item.y - py, item.z_bottom],
                    [item.x + px, item.y + py, item.z_bottom],
                    [item.x + px, item.y + py, item.z_top],
                    [item.x - px, item.y - py, item.z_top],
                ]
            )
            return [(quad, item.shade)]
        faces: list[tuple[Array, float]] = []
        a = item.footprint
        b = np.roll(a, -1, axis=0)
        for i in range(len(a)):
            edge = b[i] - a[i]
            outward = (edge[1], -edge[0])  # footprints are counter-clockwise
            if (eye[0] - a[i, 0]) * outward[0] + (eye[1] - a[i, 1]) * outward[1] <= 0.0:
                continue
            wall = np.array(
                [
                    [a[i, 0], a[i, 1], item.z_bottom],
                    [b[i, 0], b[i, 1], item.z_bottom],
                    [b[i, 0], b[i, 1], item.z_top],
                    [a[i, 0], a[i, 1], item.z_top],
                ]
            )
            faces.append((wall, item.wall_shade(i)))
        height = self._camera.mount.height
        cap = 0.5 * (item.shades[0] + item.shades[1])
        if height > item.z_top:
            faces.append((np.column_stack([a, np.full(len(a), item.z_top)]), cap))
        elif height < item.z_bottom:
            faces.append((np.column_stack([a, np.full(len(a), item.z_bottom)]), cap))
        return faces

    def _draw_objects(self, image: NDArray[np.float32], pose: Pose) -> None:
        mount = self._camera.mount
        c, s = math.cos(pose.heading), math.sin(pose.heading)
        eye = np.array(
            [pose.x + c * mount.forward - s * mount.left, pose.y + s * mount.forward + c * mount.left]
        )
        faces = [face for _, item in self._objects(pose) for face in self._faces(item, eye)]
        if not faces:
            return
        camera_points = self._camera.to_camera_frame(pose.as_array(), np.concatenate([f for f, _ in faces]))[
            0
        ]
        self._fill_all(image, camera_points, [len(f) for f, _ in faces], [shade for _, shade in faces])

    def _draw_clutter(self, image: NDArray[np.float32]) -> None:
        if self._clutter == 0:
            return
        height, width = image.shape
        n = self._clutter
        start = np.column_stack([self._rng.uniform(0, width, n), self._rng.uniform(0, height, n)])
        angle = self._rng.uniform(0.0, math.pi, n)
        length = self._rng.uniform(5.0, 40.0, n)
        shade = self._rng.uniform(0.0, 255.0, n)
        direction = np.column_stack([np.cos(angle), np.sin(angle)])
        normal = np.column_stack([-direction[:, 1], direction[:, 0]]) * 0.75
        end = start + direction * length[:, None]
        for i in range(n):
            quad = np.array(
                [start[i] - normal[i], end[i] - normal[i], end[i] + normal[i], start[i] + normal[i]]
            )
            fill_polygon(image, quad, float(shade[i]))

    def render_float(self, pose: Pose) -> NDArray[np.float32]:
        """Return the image seen from ``pose`` before noise and rounding (float32 gray levels)."""
        if not isinstance(pose, Pose):
            raise InputError(f"pose: expected a Pose, got {type(pose).__name__}")
        image = self._background.copy()
        self._draw_ground(image, pose)
        self._draw_texture(image, pose)
        self._draw_objects(image, pose)
        self._draw_clutter(image)
        return image

    def render(self, pose: Pose) -> NDArray[np.uint8]:
        """Return the grayscale image ``(height, width)``, ``uint8``, seen from the true ``pose``.

        Parameters
        ----------
        pose : Pose
            The robot's true pose (the camera sits on it as its mount says).

        Returns
        -------
        ndarray of uint8, shape (height, width)
            The image, a new array.
        """
        image = self.render_float(pose)
        if self._noise > 0.0:
            draws = np.frombuffer(self._rng.bytes(2 * image.size), dtype=np.uint16)
            image.reshape(-1)[:] += np.take(self._noise_table, draws)
        image += np.float32(0.5)
        np.clip(image, 0.0, 255.0, out=image)
        return image.astype(np.uint8)
