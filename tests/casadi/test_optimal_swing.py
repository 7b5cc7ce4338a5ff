"""examples/optimal_swing.py: the minimum-effort swing of the 4A example converges with IPOPT on
AChain.to_casadi, inside its limits, and its torques replayed through chain.simulate end where the
optimiser's trajectory ends (to 1e-4 rad)."""

from __future__ import annotations

import importlib.util
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("casadi")
ROOT = Path(__file__).resolve().parents[2]


def example():
    spec = importlib.util.spec_from_file_location("optimal_swing", ROOT / "examples" / "optimal_swing.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_optimal_swing_converges_and_replays(tmp_path, capsys):
    swing = example()
    start = time.perf_counter()
    assert swing.main([str(tmp_path / "swing.png")]) == 0
    assert time.perf_counter() - start < 60
    out = capsys.readouterr().out
    assert "Solve_Succeeded" in out and (tmp_path / "swing.png").stat().st_size > 10_000
    chain = swing.apair.load(swing.CHAIN)
    t, q, qd, tau, stats = swing.optimise(chain)
    assert stats["success"]
    lim, slack = chain.limits, 1e-6  # IPOPT's bounds hold to its constraint tolerance
    assert np.all(q >= lim[:, 0] - slack) and np.all(q <= lim[:, 1] + slack)
    assert np.all(np.abs(tau) <= swing.TAU_MAX + slack) and np.abs(qd).max() <= swing.QD_MAX + slack
    np.testing.assert_allclose(q[0], swing.Q0, atol=1e-9)
    np.testing.assert_allclose(q[-1], swing.Q1, atol=1e-9)
    run = swing.replay(chain, t, tau)
    assert np.abs(run.q[-1] - q[-1]).max() < 1e-4
    # the file is the user's: not replaced without --force
    assert swing.main([str(tmp_path / "swing.png")]) == 2
