"""Export runs and replays to Foxglove: as MCAP files, or live over its WebSocket protocol.

:func:`write_simulation_mcap` writes a simulation run (the meadows, landmarks, the map's
polygon and wedge, the true pose, the camera images with the expectation windows drawn
on them, and the metrics as plottable JSON), :func:`write_replay_mcap` a log replay, and
:func:`mcap_channels` lists the channels of any MCAP file. Open the file in Foxglove
(app.foxglove.dev or the desktop app: *Open local file*) and add a 3D panel (frame
``world``), an Image panel (``/camera/image``, annotations ``/camera/annotations``) and a
Plot panel (``/metrics.area_m2`` ...). The topics are listed in ``docs/interop.md``.

:func:`serve_simulation` and :func:`serve_replay` stream the same topics live, while a run
or a replay computes, from a Foxglove WebSocket server (:class:`LiveOptions`: host, port,
pace): connect Foxglove to it (*Open connection*, ``ws://localhost:8765``) and a layout
made for the files shows the live view too.

The messages and the MCAP container are the Foxglove SDK's (``foxglove-sdk``), the reader
the ``mcap`` package: both come with the optional extra, ``pip install aura-ums[foxglove]``.
Without them these functions raise :class:`~aura_ums.errors.MissingDependencyError`;
importing this package needs neither.

Examples
--------
>>> import pathlib, tempfile, numpy as np
>>> from aura_ums.sim import Scenario, run_scenario
>>> scenario = Scenario.from_toml(pathlib.Path("scenarios/paper_sidewalk.toml"))
>>> run = run_scenario(scenario, np.random.default_rng(0), keep_images=True)
>>> path = write_simulation_mcap(pathlib.Path(tempfile.mkdtemp()) / "walk.mcap", scenario, run)
>>> mcap_channels(path)["/map/polygon"], mcap_channels(path)["/metrics"]
('foxglove.SceneUpdate', 'aura_ums.SimulationMetrics')
"""

from aura_ums.export._live import (
    LiveOptions,
    LiveReplay,
    LiveSimulation,
    serve_replay,
    serve_simulation,
)
from aura_ums.export._mcap import mcap_channels, write_replay_mcap, write_simulation_mcap

__all__ = [
    "LiveOptions",
    "LiveReplay",
    "LiveSimulation",
    "mcap_channels",
    "serve_replay",
    "serve_simulation",
    "write_replay_mcap",
    "write_simulation_mcap",
]
