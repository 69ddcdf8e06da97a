"""The margin each perceptual strategy needs; strategies live in world, image windows in geometry."""

from __future__ import annotations

import types
from collections.abc import Mapping

from aura_ums._validate import nonnegative_float
from aura_ums.uncertainty import LandmarkClass
from aura_ums.world import PerceptualStrategy

#: Margin (pixels, added on every side) that each perceptual strategy needs around the
#: guaranteed window. Illustrative figures in the spirit of the paper's Figure 8: a line
#: finder must see enough of the edges that meet at a feature to fit lines to them, so it
#: needs far more context than an interest operator, whose support is a few pixels (a
#: Moravec operator on a 5 x 5 neighbourhood needs 2 pixels, rounded up to 4 here). A region
#: segmenter sits in between: it needs some surrounding area to contrast the region with.
#: Read-only.
DEFAULT_MARGINS: Mapping[PerceptualStrategy, float] = types.MappingProxyType(
    {
        PerceptualStrategy.LINE_FINDER: 24.0,
        PerceptualStrategy.INTEREST_OPERATOR: 4.0,
        PerceptualStrategy.REGION_SEGMENTER: 12.0,
    }
)


def margin_pixels(margin: float | PerceptualStrategy) -> float:
    """Return a margin in pixels from a number (>= 0) or a :class:`PerceptualStrategy`.

    A strategy's margin is the context it needs on every side of the guaranteed window: a
    line finder the most (to fit lines to the edges that meet at a feature), a region
    segmenter less (to contrast the region with its surroundings), an interest operator
    the least (its support is a few pixels).

    Examples
    --------
    >>> {strategy.name: margin_pixels(strategy) for strategy in PerceptualStrategy}
    {'LINE_FINDER': 24.0, 'INTEREST_OPERATOR': 4.0, 'REGION_SEGMENTER': 12.0}
    >>> margin_pixels(7)
    7.0
    >>> margin_pixels(-1.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: margin: expected a non-negative number, got -1.0
    """
    if isinstance(margin, PerceptualStrategy):
        return DEFAULT_MARGINS[margin]
    return nonnegative_float(margin, "margin")


def class_margin(landmark_class: LandmarkClass) -> float:
    """Return the margin (pixels) of the usual strategy for a landmark class (its ``for_class`` first).

    The window's margin when none is given: the context the strategy that usually looks
    for that class needs (a line finder's for Class I and III, an interest operator's for
    Class II).

    Examples
    --------
    >>> {c.name: class_margin(c) for c in LandmarkClass}
    {'VERTICAL_LINE': 24.0, 'POINT': 4.0, 'GROUND_LINE': 24.0}
    """
    return DEFAULT_MARGINS[PerceptualStrategy.for_class(landmark_class)[0]]


#: :meth:`ImageWindow._trusted`, under the name expecter/_expecter.py and schemas/_perceive.py
#: import it by.
