from typing_extensions import Buffer

def grow_polygon(
    vertices: Buffer,
    heading_lo: float,
    heading_hi: float,
    turn_min: float,
    turn_max: float,
    drift_max: float,
    chord_min: float,
    run_max: float,
    skitter_radius: float,
    max_vertices: int,
    /,
) -> bytes: ...
