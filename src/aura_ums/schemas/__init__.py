"""Find-landmark schemas: the pilot, the schemas and the schema manager.

Before a leg, the :class:`Pilot` reads the candidate landmarks of the short-term memory
and parameterizes one :class:`FindLandmarkSchema` per landmark (perceptual strategy,
evaluation function, recognition threshold, confirm count, activation range); the
:class:`SchemaManager` instantiates them and, for every camera :class:`Frame`, steps
each through its life cycle (:class:`SchemaState`: hibernating, discovering, tracking,
suspect), posting each identification, a time-stamped bounded observation, to the
:class:`~aura_ums.manager.IdentifiedLandmarkBuffer`, and counting landmarks predicted
but not found for lost detection.

Supported perceptual strategies and record ``parameters`` per landmark class:

- Class I (vertical line): ``line_finder`` (``orientation`` in image radians, default
  pi/2; ``tolerance``, ``min_length``, ``min_gradient``, ``min_contrast``, ``smoothing``,
  ``buckets``) or ``region_segmenter`` (``threshold``, ``min_area``, ``min_aspect``);
- Class II (point): ``interest_operator`` (``window``: Moravec window size,
  ``min_interest``: its threshold, ``suppression``);
- Class III (ground line): ``line_finder`` (as Class I; without ``orientation`` it is
  tuned every frame to the line's predicted image direction).

Evaluation values are on the scale of :mod:`aura_ums.perception`'s evaluation functions
(line strength = length x contrast, corner = Moravec response, region = height in
pixels); a record's ``recognition_threshold`` is compared with them directly.
"""

from aura_ums.schemas._frame import Frame
from aura_ums.schemas._manager import SchemaManager, SchemaManagerState, StepReport
from aura_ums.schemas._pilot import Pilot
from aura_ums.schemas._schema import FindLandmarkSchema
from aura_ums.schemas._state import Detection, SchemaReport, SchemaState, SchemaStatus

__all__ = [
    "Detection",
    "FindLandmarkSchema",
    "Frame",
    "Pilot",
    "SchemaManager",
    "SchemaManagerState",
    "SchemaReport",
    "SchemaState",
    "SchemaStatus",
    "StepReport",
]
