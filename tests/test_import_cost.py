"""Starting the library, or the CLI, does not import what only some commands need.

networkx (path planning) and scipy (image filters, the simulator's noise table) take about
1.5 s to import on the 2-core CI machine, paid by every ``aura-ums`` command before it did
anything; they are imported where they are used.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

#: Imported lazily by the library: absent after ``import aura_ums`` and ``import aura_ums.cli``.
DEFERRED = ("networkx", "scipy", "matplotlib", "cv2", "distributed")


@pytest.mark.parametrize("module", ["aura_ums", "aura_ums.cli"])
def test_importing_does_not_load_what_only_some_commands_need(module: str) -> None:
    loaded = f"sorted(set(sys.modules) & set({list(DEFERRED)!r}))"
    code = f"import json, sys, {module}; print(json.dumps({loaded}))"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert json.loads(done.stdout) == []
