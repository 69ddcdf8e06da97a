"""The Expecter: image windows in which expected landmarks must appear.

From the spatial uncertainty map (polygon and wedge), a landmark of any class and a
calibrated camera, :class:`Expecter` computes a window guaranteed to hold the landmark's
projection for every pose of the map, then grows it by the margin its perceptual strategy
needs and clips it to the image. Baselines (the disk model, an EKF's 3-sigma box) use the
same machinery, for side-by-side comparisons.

The other way round, the observers (:func:`observe_vertical_line`, :func:`observe_point`,
:func:`observe_ground_line`) turn the pixels where a landmark appeared into a bounded
observation of it, from the camera's bounds on what those pixels measure.
"""

from aura_ums.expecter._baselines import disk_model_map, disk_model_window, gaussian_box_map, gaussian_window
from aura_ums.expecter._expecter import Expecter
from aura_ums.expecter._observations import observe_ground_line, observe_point, observe_vertical_line
from aura_ums.expecter._scenario import Figure4Scenario, figure4_scenario
from aura_ums.expecter._window import margin_pixels
from aura_ums.geometry import ImageWindow
from aura_ums.world import PerceptualStrategy

__all__ = [
    "Expecter",
    "Figure4Scenario",
    "ImageWindow",
    "PerceptualStrategy",
    "disk_model_map",
    "disk_model_window",
    "figure4_scenario",
    "gaussian_box_map",
    "gaussian_window",
    "margin_pixels",
    "observe_ground_line",
    "observe_point",
    "observe_vertical_line",
]
