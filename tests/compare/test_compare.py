"""`compare`: the twin's workspace against the exact shell of a 3R arm, the chain's against
`chain.workspace` (same samples and seed: the same numbers), a chain of R-pairs against itself (a
fair comparison finds no difference), the JSON document, the table, the report and its picture."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from compare_designs import arm3a, shell

import apair
from apair.cli.output import jsonable
from apair.compare import Comparison, compare

SAMPLES = 40_000


@pytest.fixture(scope="module")
def arm() -> tuple[apair.AChain, Comparison]:
    chain = arm3a()
    chain.name = "3A arm"
    return chain, compare(chain, samples=SAMPLES, seed=2)


def test_the_twins_workspace_is_the_3r_shell(arm):
    _, result = arm
    ws = result.twin.workspace
    assert ws.volume == pytest.approx(shell(), rel=0.05)
    assert abs(ws.volume - shell()) <= 3 * ws.volume_error


def test_the_chains_volume_is_its_workspace_volume(arm):
    chain, result = arm
    ws = chain.workspace(samples=SAMPLES, seed=2)
    assert (result.chain.workspace.volume, result.chain.workspace.volume_error) == (ws.volume, ws.volume_error)


def test_the_a_pairs_limits_shrink_the_workspace(arm):
    """The 3A arm's joints stop at their collision limits, the twin's turn fully: the twin reaches
    more, and most of what the chain reaches (the chain's rise shifts a thin layer outward)."""
    _, r = arm
    assert r.twin.workspace.volume > r.chain.workspace.volume
    assert r.shared.only_twin > r.shared.only_chain
    assert r.shared.only_chain + r.shared.only_twin + r.shared.both == pytest.approx(1.0)
    assert r.twin.full_turn == [True] * 3 and r.chain.full_turn == [False] * 3
    assert np.all(r.chain.axial_travel > 0) and np.all(r.twin.axial_travel == 0)


def test_a_chain_of_r_pairs_is_its_own_twin():
    chain = apair.AChain([apair.APair.revolute()] * 3, [0.0, 0.4, 0.3], [math.pi / 2, 0, 0], [0.3, 0, 0])
    r = compare(chain, samples=8000, seed=4)
    assert r.shared.only_chain == 0 and r.shared.only_twin == 0
    mine, theirs = jsonable(r.chain.as_dict()), jsonable(r.twin.as_dict())
    assert mine.pop("name") == "chain" and theirs.pop("name") == "chain (revolute twin)"
    assert mine == theirs
    assert mine["path"]["followed"], mine["path"]["reason"]


def test_the_json_document(arm):
    _, r = arm
    doc = json.loads(json.dumps(jsonable(r.as_dict()), allow_nan=False))
    for who in ("chain", "twin"):
        entry = doc[who]
        for key in ("volume", "volume_error", "limits", "mass", "manipulability_median", "condition_median"):
            assert isinstance(entry[key], (float, list)), (who, key)
        assert len(entry["gravity_torque_max"]) == 3 and len(entry["limits"]) == 3
        assert entry["path"]["followed"] in (True, False)
    assert doc["chain"]["volume"] == r.chain.workspace.volume
    assert doc["chain"]["manipulability_median"] == pytest.approx(float(np.median(r.chain.manipulability)))
    assert doc["chain"]["mass"] == pytest.approx(doc["twin"]["mass"] + doc["chain"]["leg_mass"])
    assert doc["settings"]["samples"] == SAMPLES and doc["settings"]["twin"] == "revolute"


def test_the_table(arm):
    _, r = arm
    text = r.table()
    assert text.startswith("3A arm beside its revolute twin (40000 workspace samples, seed 2")
    volume = f"{r.chain.workspace.volume:.3g} ± {r.chain.workspace.volume_error:.2g}"
    assert volume in text and "full full full" in text and "±120" in text


def test_the_report_is_self_contained(arm, tmp_path):
    _, r = arm
    page = r.report(tmp_path / "r.html").read_text()
    assert page.startswith("<!DOCTYPE html>") and page.count("data:image/png;base64,") == 3
    assert "http:" not in page and "https:" not in page and "<script" not in page and "<link" not in page
    assert "3A arm beside its revolute twin" in page and f"{r.chain.workspace.volume:.3g}" in page
    with pytest.raises(ValueError, match="exists; pass overwrite=True"):
        r.report(tmp_path / "r.html")


def test_the_picture_is_a_png(arm, tmp_path):
    _, r = arm
    p = r.picture(tmp_path / "main")
    assert p.suffix == ".png" and p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    ("kwargs", "start"),
    [
        ({"twin": "helical"}, "twin: expected one of revolute"),
        ({"samples": 10}, "samples: "),
        ({"seed": -1}, "seed: "),
        ({"path": [[0, 0, 0]]}, "path: expected 2 to"),
        ({"engine": "nowhere"}, "engine: "),
    ],
)
def test_bad_arguments_are_refused_in_one_line(kwargs, start):
    with pytest.raises(ValueError) as exc:
        compare(arm3a(), **kwargs)
    assert str(exc.value).startswith(start) and "\n" not in str(exc.value)


def test_a_given_path(arm):
    chain, _ = arm
    corners = [[0.45, -0.2, 0.4], [0.35, 0.25, 0.15], [0.0, 0.45, 0.3]]
    r = compare(chain, samples=8000, path=corners)
    assert r.shared.path_corners.tolist() == corners
    for m in (r.chain, r.twin):
        assert m.path.followed, m.path.reason
    assert np.allclose(chain.fk(r.chain.path.q[-1])[:3, 3], corners[-1], atol=1e-8)


def test_the_engine_does_not_change_the_result():
    chain = arm3a()
    here = compare(chain, samples=8000, seed=5)
    threads = compare(chain, samples=8000, seed=5, engine="threads")
    assert jsonable(threads.chain.as_dict()) == jsonable(here.chain.as_dict())
    assert jsonable(threads.shared.as_dict()) == jsonable(here.shared.as_dict())
