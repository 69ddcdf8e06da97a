from __future__ import annotations

from pathlib import Path

import matplotlib

from aura_ums.plot._expecter import draw_expecter_figures


def test_draws_figure4_pngs(tmp_path: Path) -> None:
    backend = matplotlib.get_backend()
    paths = draw_expecter_figures(tmp_path / "figures", seed=3)
    assert [p.name for p in paths] == ["figure4_top_view.png", "figure4_windows.png"]
    for path in paths:
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert path.stat().st_size > 10_000
    assert matplotlib.get_backend() == backend  # no global state touched
    assert draw_expecter_figures(tmp_path / "figures", seed=3) == paths  # rewrites in place
