"""Matplotlib figures of maps, wedges, windows and sampled outcomes, and the demo report."""

from aura_ums.plot._expecter import draw_expecter_figures
from aura_ums.plot._experiment import experiment_table, paper_scenario, write_experiment_report
from aura_ums.plot._growth import draw_all_figures, draw_growth_figures, write_growth_report
from aura_ums.plot._reduction import PathRunStep, draw_path_figure, run_down_path
from aura_ums.plot._replay import draw_replay

__all__ = [
    "PathRunStep",
    "draw_all_figures",
    "draw_expecter_figures",
    "draw_growth_figures",
    "draw_path_figure",
    "draw_replay",
    "experiment_table",
    "paper_scenario",
    "run_down_path",
    "write_experiment_report",
    "write_growth_report",
]
