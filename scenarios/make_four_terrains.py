"""Write ``four_terrains.geojson``: four meadows in a row, tile, concrete, grass and gravel.

Run: ``.venv/bin/python scenarios/make_four_terrains.py`` (from the repository root).
Each meadow is 6 m long and 4 m wide along the x axis; poles stand beside the strip at the
meadow boundaries, a shed's corner (Class II, with its vertical edge as Class I) stands
ahead, and the strip's edges are Class III lines.
"""

from __future__ import annotations

import math
from pathlib import Path

from aura_ums.expecter import PerceptualStrategy
from aura_ums.geometry import ConvexPolygon
from aura_ums.uncertainty import GroundLineLandmark, PointLandmark, TerrainTable, VerticalLineLandmark
from aura_ums.world import LandmarkRecord, Meadow, MeadowMap

VERTICAL = {"orientation": math.pi / 2, "tolerance": math.radians(10.0), "min_length": 30.0}
EDGE = {"tolerance": math.radians(20.0), "min_length": 60.0}
CORNER = {"window": 5.0, "min_interest": 150.0}


def build() -> MeadowMap:
    """Return the four-terrain map."""
    terrains = ("tile", "concrete", "grass", "gravel")
    poles = [
        VerticalLineLandmark("pole_a", 6.0, 2.6, 0.0, 5.0, symbol="pole", position_uncertainty=0.05),
        VerticalLineLandmark("pole_b", 12.0, -2.6, 0.0, 5.0, symbol="pole", position_uncertainty=0.05),
        VerticalLineLandmark("pole_c", 18.0, 2.6, 0.0, 5.0, symbol="pole", position_uncertainty=0.05),
    ]
    corner = PointLandmark("shed_corner", 28.0, 3.0, 3.0, symbol="shed corner", position_uncertainty=0.1)
    edge = VerticalLineLandmark(
        "shed_edge", 28.0, 3.0, 0.0, 3.0, symbol="shed corner", position_uncertainty=0.1
    )
    north = GroundLineLandmark("strip_north_edge", (0.0, 2.0), (24.0, 2.0), "strip edge", 0.05)
    south = GroundLineLandmark("strip_south_edge", (0.0, -2.0), (24.0, -2.0), "strip edge", 0.05)
    records = [LandmarkRecord(p, PerceptualStrategy.LINE_FINDER, VERTICAL, 20.0, 400.0) for p in poles]
    records.append(LandmarkRecord(corner, PerceptualStrategy.INTEREST_OPERATOR, CORNER, 30.0, 300.0))
    records.append(LandmarkRecord(edge, PerceptualStrategy.LINE_FINDER, VERTICAL, 30.0, 400.0))
    records.extend(
        LandmarkRecord(e, PerceptualStrategy.LINE_FINDER, EDGE, 4.0, 1500.0) for e in (north, south)
    )
    all_ids = tuple(r.id for r in records)
    meadows = [
        Meadow(
            f"{terrain}_meadow",
            ConvexPolygon([(6.0 * i, -2.0), (6.0 * (i + 1), -2.0), (6.0 * (i + 1), 2.0), (6.0 * i, 2.0)]),
            terrain,
            all_ids,
        )
        for i, terrain in enumerate(terrains)
    ]
    return MeadowMap(meadows, records, terrain_table=TerrainTable.default())


if __name__ == "__main__":
    build().to_geojson(Path(__file__).with_name("four_terrains.geojson"))
