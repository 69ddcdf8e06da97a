from __future__ import annotations

from pathlib import Path

from aura_ums.plot import draw_growth_figures, write_growth_report

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def test_growth_figures_are_written_as_png(tmp_path: Path) -> None:
    written = draw_growth_figures(tmp_path / "figures", seed=3)
    assert [path.name for path in written] == [
        "figure5_point_transform.png",
        "figure6_heading_wedge.png",
        "figure7_map_transform.png",
    ]
    for path in written:
        assert path.read_bytes()[:8] == PNG_MAGIC
        assert path.stat().st_size > 10_000


def test_report_summarises_measured_figures(tmp_path: Path) -> None:
    summary = write_growth_report(tmp_path, seed=1)
    text = summary.read_text()
    assert "| 3 | 100.0000% of" in text  # soundness with truncated noise is exact
    assert "| tile |" in text
    assert "figures/figure7_map_transform.png" in text
    assert (tmp_path / "figures" / "figure6_heading_wedge.png").exists()
