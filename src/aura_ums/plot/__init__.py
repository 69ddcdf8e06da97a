"""Matplotlib figures of maps, wedges and sampled outcomes, and the demo report."""

from aura_ums.plot._growth import draw_growth_figures, write_growth_report

__all__ = ["draw_growth_figures", "write_growth_report"]
