"""Robot logs: the log folder format, dataset readers, and odometry to turn-and-run reports.

A log is a folder of a ``meta.toml`` and CSV files (``docs/log-format.md``):

- :func:`load_log` reads and validates one into a :class:`RobotLog` (SI units), and
  :func:`write_log` writes one back exactly; :func:`open_log` opens one as a
  :class:`LogStream`, which :func:`replay_log` reads block by block in bounded memory;
- :class:`RobotLog` holds :class:`LogMeta`, :class:`LogLandmark` s, :class:`LogObservation` s,
  the motion as :class:`Odometry` (velocities) or recorded position reports, and an optional
  :class:`GroundTruth`; :meth:`RobotLog.position_reports` turns the motion into the
  time-stamped :class:`~aura_ums.manager.PositionReport` s the map manager grows by
  (:func:`odometry_to_commands`);
- :func:`read_mrclam` and :func:`import_mrclam` read the UTIAS MRCLAM dataset
  (Leung et al., IJRR 2011);
- :func:`replay_log` feeds a log to the :class:`~aura_ums.manager.UncertaintyMapManager`
  (the localizer, with its outlier recovery) and records what it did against the ground
  truth; :func:`compare_on_log` sets it next to an EKF and a particle filter;
  :func:`replay_windows` judges the image windows the Expecter, an EKF's 3-sigma box and the
  disk model give for each real observation, through a camera of your choosing.
  :class:`ReplayState` is where a replay stopped, saved as versioned JSON and resumed
  (``replay_log(..., resume=state)``) to end with exactly the map of an uninterrupted one.
"""

# Replay and calibration are the lead's (_calibrate, _replay, _synthetic); the formats
# and readers are helper-logs' (_io, _log, _mrclam, _odometry).
# One sorted import block (ruff's isort), so the two are interleaved below.
from aura_ums.logs._calibrate import (
    Calibration,
    FilterNoise,
    HorizonCheck,
    MotionCalibration,
    SensorBounds,
    calibrate_logs,
    fitted_for_anchor,
    horizon_checks,
    load_noise,
    load_sensors,
    observation_errors,
    sensors_path,
)
from aura_ums.logs._compare import MethodSummary, compare_on_log, filter_settings
from aura_ums.logs._io import load_log, log_files_in, write_log
from aura_ums.logs._log import (
    GroundTruth,
    LogLandmark,
    LogMeta,
    LogObservation,
    ObservationKind,
    Odometry,
    RobotLog,
)
from aura_ums.logs._mrclam import import_mrclam, read_mrclam
from aura_ums.logs._odometry import ReverseMotion, odometry_report_arrays, odometry_to_commands
from aura_ums.logs._replay import (
    ReplayOptions,
    ReplayResult,
    ReplayStep,
    ReplayTrace,
    log_meadow_map,
    observation_for,
    replay_log,
)
from aura_ums.logs._rosbag import import_rosbag, read_camera_info, read_rosbag
from aura_ums.logs._state import ReplayState
from aura_ums.logs._stream import LogStream, open_log
from aura_ums.logs._synthetic import synthetic_log
from aura_ums.logs._windows import WindowReport, WindowRow, ekf_noise, replay_windows

__all__ = [
    "Calibration",
    "FilterNoise",
    "GroundTruth",
    "HorizonCheck",
    "LogLandmark",
    "LogMeta",
    "LogObservation",
    "LogStream",
    "MethodSummary",
    "MotionCalibration",
    "ObservationKind",
    "Odometry",
    "ReplayOptions",
    "ReplayResult",
    "ReplayState",
    "ReplayStep",
    "ReplayTrace",
    "ReverseMotion",
    "RobotLog",
    "SensorBounds",
    "WindowReport",
    "WindowRow",
    "calibrate_logs",
    "compare_on_log",
    "ekf_noise",
    "filter_settings",
    "fitted_for_anchor",
    "horizon_checks",
    "import_mrclam",
    "import_rosbag",
    "load_log",
    "load_noise",
    "load_sensors",
    "log_files_in",
    "log_meadow_map",
    "observation_errors",
    "observation_for",
    "odometry_report_arrays",
    "odometry_to_commands",
    "open_log",
    "read_camera_info",
    "read_mrclam",
    "read_rosbag",
    "replay_log",
    "replay_windows",
    "sensors_path",
    "synthetic_log",
    "write_log",
]
