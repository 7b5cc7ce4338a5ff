"""The closed-form inverse kinematics of arms with a spherical wrist, of UR arms (three parallel
inner axes) and of a design with axes 1, 2, 3 parallel and 5, 6 meeting (issue 42), two of them
also mounted wrist-first (the family at the base end), against
EAIK and IK-Geo (and of UR arms with an A-pair at joint 3, which no peer solves, against apair's
general solver), side by side on the same poses in one run
(`bench/run.py --ik-closed-only`, and in the full run): single Python calls (apair's `chain.ik(T)`,
EAIK's `IK(T)`, IK-Geo's `get_ik(R, t)`, interleaved pose by pose), apair's batched C call
(`apair._native.ik_wrist` or `ik_parallel` on N poses) against
EAIK's `IK_batched`, and how the solution sets agree (every solution of a peer that apair's fk
verifies must be among apair's); and random 6R arms of no special geometry (the 6R elimination in
one C call) against IK-Geo's general solver, with `prepare_ik` on every R arm. The load average is
recorded with the numbers."""

from __future__ import annotations

import os
import tempfile
import time

import numpy as np

import apair
from apair.ik.parallel import Parallel
from apair.ik.parallel_apair import ParallelAPair
from apair.ik.parallel_slides import ParallelSlides
from apair.ik.poses import length_scale
from apair.ik.solver import Solver
from apair.ik.three_parallel import ThreeParallel
from apair.ik.wrist import Wrist
from apair.ik.wrist_apair import WristAPair
from apair.ik.wrist_slide1 import WristSlide1
from apair.kernels import native_module

PI = np.pi
ARMS = {  # standard DH (a, alpha, d), the arms of tests/ik/test_ik_wrist.py and test_ik_parallel.py
    "PUMA560": ([0, 0.4318, 0.0203, 0, 0, 0], [-PI / 2, 0, -PI / 2, PI / 2, -PI / 2, 0], [0, 0, 0.15005, 0.4318, 0, 0]),
    "KUKA-KR6": ([0.025, 0.455, 0.035, 0, 0, 0], [-PI / 2, 0, -PI / 2, PI / 2, -PI / 2, 0], [0.4, 0, 0, 0.42, 0, 0.08]),
    "ABB-IRB6640": (
        [0.32, 1.075, 0.2, 0, 0, 0],
        [-PI / 2, 0, -PI / 2, PI / 2, -PI / 2, 0],
        [0.78, 0, 0, 1.1425, 0, 0.2],
    ),
    "Fanuc-M20": (
        [0.075, 0.84, 0.215, 0, 0, 0],
        [-PI / 2, PI, -PI / 2, PI / 2, -PI / 2, PI],
        [0.525, 0, 0, -0.89, 0, -0.09],
    ),
    "Staubli-TX90": (
        [0.05, 0.425, 0, 0, 0, 0],
        [-PI / 2, 0, PI / 2, -PI / 2, PI / 2, 0],
        [0.478, 0, 0.05, 0.425, 0, 0.1],
    ),
    "UR5": (
        [0, -0.425, -0.39225, 0, 0, 0],
        [PI / 2, 0, 0, PI / 2, -PI / 2, 0],
        [0.089159, 0, 0, 0.10915, 0.09465, 0.0823],
    ),
    "UR10e": (
        [0, -0.6127, -0.57155, 0, 0, 0],
        [PI / 2, 0, 0, PI / 2, -PI / 2, 0],
        [0.1807, 0, 0, 0.17415, 0.11985, 0.11655],
    ),
}

ARMS["1∥2∥3, 5∩6 design"] = (
    [0.3, 0.25, 0.1, 0.05, 0, 0.02],
    [0, 0, 1.1, -0.7, 0.9, 0.3],
    [0.2, 0.05, 0.1, 0.15, 0.08, 0.1],
)


def _wrist_first(a, alpha, d):
    """The arm mounted wrist-first: its reversed chain is the arm (apair.ik.reverse; a_6 = 0.05,
    α_6 = 0.4 become that chain's base)."""
    a, alpha, d = (np.asarray(x, float) for x in (a, alpha, d))
    return np.append(-a[4::-1], 0.05).tolist(), np.append(-alpha[4::-1], 0.4).tolist(), (-d[::-1]).tolist()


ARMS["PUMA560 wrist-first"] = _wrist_first(*ARMS["PUMA560"])
ARMS["UR5 wrist-first"] = _wrist_first(*ARMS["UR5"])
# IK-Geo's solver of each family (its names: h2∥h3∥h4 with h5∩h6 is three_parallel_two_intersecting)
IKGEO = {"three-inner-parallel": "three_parallel_two_intersecting"}
SAME = 1e-6


def _among(q, sols, period: float = 2 * PI) -> bool:
    """q among sols, each joint within SAME modulo `period` (4π for an A-pair's angle: every joint
    is compared modulo it, which for R-pairs' (−π, π] angles is the same)."""
    d = np.abs((np.asarray(sols).reshape(-1, 6) - q + period / 2) % period - period / 2)
    return bool(np.any(np.all(d < SAME, axis=1)))


def _ikgeo(eaik_robot, chain, make: str | None = None):
    """IK-Geo's solver `make` (default: the arm's family's, spherical wrist with 2∥3 or UR's), with its
    frame conventions read off fk at q = 0 (its rotations come transposed; its end frame differs from
    DH's by a rotation), or None where IK-Geo is missing."""
    try:
        import ik_geo
    except ImportError:
        return None
    H, P = np.asarray(eaik_robot.getOriginal_H()).T, np.asarray(eaik_robot.getOriginal_P()).T
    make = make or IKGEO.get(chain.kinematic_family().key, "spherical_two_parallel")
    geo = getattr(ik_geo.Robot, make)(H.tolist(), P.tolist())
    R0, _ = geo.forward_kinematics([0.0] * 6)
    tool = np.asarray(R0) @ chain.fk(np.zeros(6))[:3, :3]

    def solve(T):
        R = (T[:3, :3] @ tool.T).T
        return geo.get_ik(R.tolist(), T[:3, 3].tolist())

    return solve, tool


def section(quick: bool) -> dict:
    from eaik.IK_DH import DhRobot

    native, _ = native_module()
    count, batch = (300, 2000) if quick else (2000, 20000)
    out: dict = {"load_average": os.getloadavg()[0], "poses": count, "batch": batch, "arms": {}}
    for name, (a, alpha, d) in ARMS.items():
        chain = apair.AChain([apair.APair.revolute()] * 6, a=a, alpha=alpha, offset=d)
        eaik = DhRobot(np.array(alpha, float), np.array(a, float), np.array(d, float))
        reversed_ = bool(chain.kinematic_family().family.reversed)
        # IK-Geo's solvers take the forward families with a wrist or 2∥3∥4
        geo = (
            None
            if reversed_ or chain.kinematic_family().key == "three-parallel-two-intersecting"
            else _ikgeo(eaik, chain)
        )
        rng = np.random.default_rng(42)
        Ts = chain.fk(rng.uniform(-PI, PI, (count, 6)))
        chain.ik(Ts[0])
        eaik.IK(Ts[0])
        times = {"apair": [], "eaik": []}
        if geo is not None:
            times["ik_geo"] = []
            geo[0](Ts[0])
        missing = 0
        for T in Ts:  # interleaved, pose by pose
            t0 = time.perf_counter()
            ours = chain.ik(T)
            t1 = time.perf_counter()
            theirs = eaik.IK(T)
            t2 = time.perf_counter()
            times["apair"].append(t1 - t0)
            times["eaik"].append(t2 - t1)
            if geo is not None:
                t3 = time.perf_counter()
                geo[0](T)
                times["ik_geo"].append(time.perf_counter() - t3)
            for s in np.asarray(theirs.Q).reshape(-1, 6):
                if np.abs(chain.fk(s) - T).max() <= 1e-9 and not _among(s, ours):
                    missing += 1
        row = {
            "family": chain.kinematic_family().key,
            "median_us": {k: float(np.median(v) * 1e6) for k, v in times.items()},
            "eaik_solutions_missing_from_apair": missing,
        }
        if native is not None and not reversed_:  # (the batched C calls take the forward families)
            make, solve = {
                "three-inner-parallel": (Parallel, native.ik_parallel),
                "three-parallel-two-intersecting": (ThreeParallel, native.ik_three_parallel),
            }.get(chain.kinematic_family().key, (Wrist, native.ik_wrist))
            w = make(chain, length_scale(chain))
            Tb = chain.fk(rng.uniform(-PI, PI, (batch, 6)))
            best = min(_timed(lambda: solve(w.dh, w.scale, Tb, 1e-9)) for _ in range(5))
            row["batched_us_per_pose"] = {"apair": best / batch * 1e6}
            poses = [Tk for Tk in Tb]
            try:
                best_e = min(_timed(lambda: eaik.IK_batched(poses, num_worker_threads=1)) for _ in range(3))
                row["batched_us_per_pose"]["eaik_one_thread"] = best_e / batch * 1e6
            except (AttributeError, TypeError):
                pass
        out["arms"][name] = row
        med = row["median_us"]
        print(
            f"  {name:19s} {row['family']:32s} single call: apair {med['apair']:7.1f} µs, EAIK {med['eaik']:5.1f} µs"
            + (f", IK-Geo {med['ik_geo']:5.1f} µs" if "ik_geo" in med else "")
            + (
                "; batched µs/pose: " + ", ".join(f"{k} {v:.2f}" for k, v in row["batched_us_per_pose"].items())
                if "batched_us_per_pose" in row
                else ""
            )
            + f"; EAIK solutions missing from apair's: {missing}",
            flush=True,
        )
    out["a_pair_arms"] = a_pair_section(quick)
    out["general_6r"] = general_section(quick)
    return out


GENERAL_DESIGNS = 3  # random 6R designs (twists, lengths and offsets drawn as tests/ik/test_ik6r.py's random_arm)


def general_section(quick: bool) -> dict:
    """Six R-pairs of no special geometry (the 6R elimination in one C call, apair_ik6r): apair's single
    Python call against IK-Geo's general solver (`gen_six_dof`: about one least-squares approximation
    per pose, not every solution; EAIK refuses these arms), on the same poses; the share of
    poses certified by the elimination and whether each pose's own joints are among the answers; and
    `prepare_ik` (the homotopy's start system, into an empty cache) on each of these designs and on every
    R arm of `ARMS`."""
    count = 60 if quick else 300
    rng = np.random.default_rng(7)
    out: dict = {"designs": {}, "prepare_s": {}}
    designs = {
        f"random 6R #{k + 1}": apair.AChain(
            [apair.APair.revolute()] * 6,
            rng.uniform(0.1, 0.5, 6),
            rng.uniform(-1.5, 1.5, 6),
            rng.uniform(-0.2, 0.2, 6),
            rng.uniform(-1.0, 1.0, 6),
        )
        for k in range(GENERAL_DESIGNS)
    }
    for name, chain in designs.items():
        geo = _ikgeo_general(chain)
        qs = rng.uniform(-PI, PI, (count, 6))
        Ts = chain.fk(qs)
        chain.ik(Ts[0])
        times: dict[str, list[float]] = {"apair": []} | ({"ik_geo_general": []} if geo else {})
        found = certified = 0
        for q, T in zip(qs, Ts):  # each solver over all poses in turn: IK-Geo's general solver takes
            t0 = time.perf_counter()  # milliseconds a pose, and would leave apair's calls a cold cache
            ours = chain.ik(T)
            times["apair"].append(time.perf_counter() - t0)
            found += _among(q, ours)
        for T in Ts if geo is not None else ():
            t0 = time.perf_counter()
            geo(T)
            times["ik_geo_general"].append(time.perf_counter() - t0)
        for T in Ts[: count // 3]:  # the route and its certificate (full=True takes the validating path)
            sol = chain.ik(T, full=True)
            certified += sol.certified and sol.method == "elimination"
        out["designs"][name] = {
            "median_us": {k: float(np.median(v) * 1e6) for k, v in times.items()},
            "poses": count,
            "own_joints_found": found,
            "certified_by_elimination": certified,
            "checked_for_route": count // 3,
        }
        med = out["designs"][name]["median_us"]
        print(
            f"  {name:19s} general                          single call: apair {med['apair']:7.1f} µs"
            + (f", IK-Geo's general (approximate) {med['ik_geo_general']:7.1f} µs" if geo else "")
            + f"; own joints found at {found}/{count}, certified by the elimination at {certified}/{count // 3}",
            flush=True,
        )
    arms = {
        name: apair.AChain([apair.APair.revolute()] * 6, a=a, alpha=al, offset=d) for name, (a, al, d) in ARMS.items()
    }
    old = os.environ.get("APAIR_CACHE")
    with tempfile.TemporaryDirectory() as tmp:
        os.environ["APAIR_CACHE"] = tmp
        try:
            for name, chain in (designs | arms).items():
                t0 = time.perf_counter()
                chain.prepare_ik()
                out["prepare_s"][name] = time.perf_counter() - t0
        finally:
            if old is None:
                os.environ.pop("APAIR_CACHE", None)
            else:
                os.environ["APAIR_CACHE"] = old
    worst = max(out["prepare_s"], key=out["prepare_s"].get)
    print(
        f"  prepare_ik: at most {out['prepare_s'][worst]:.2f} s ({worst}) over {len(out['prepare_s'])} 6R arms",
        flush=True,
    )
    return out


def _ikgeo_general(chain):
    """IK-Geo's general 6R solver (`gen_six_dof`) on the chain's axes (EAIK's reading of its DH
    constants), T -> its answer, or None where IK-Geo or EAIK is missing."""
    try:
        from eaik.IK_DH import DhRobot
    except ImportError:
        return None
    robot = DhRobot(np.asarray(chain.alpha, float), np.asarray(chain.a, float), np.asarray(chain.offset, float))
    found = _ikgeo(robot, chain, "gen_six_dof")
    return None if found is None else found[0]


A_ARMS = {  # UR arms with sinusoidal A-pairs (r_b = 0.06, r_p = 0.05: h = 0.0775 m) at these joints (from 1)
    "UR5 + A-pair at joint 3": (ARMS["UR5"], (3,)),
    "UR10e + A-pair at joint 3": (ARMS["UR10e"], (3,)),
    "UR5 + A-pairs at joints 1, 5": (ARMS["UR5"], (1, 5)),
    "UR10e + A-pairs at joints 1, 5": (ARMS["UR10e"], (1, 5)),
    "PUMA560 + A-pair at joint 3": (ARMS["PUMA560"], (3,)),
    "KUKA-KR6 + A-pair at joint 3": (ARMS["KUKA-KR6"], (3,)),
    "KUKA-KR6 + A-pair at joint 1": (ARMS["KUKA-KR6"], (1,)),
}


def a_pair_section(quick: bool) -> dict:
    """UR arms with A-pairs at joint 3 or at joints 1 and 5, spherical-wrist arms with one at joint 3
    or 1 (apair.ik.parallel_apair, parallel_slides, wrist_apair, wrist_slide1: no peer solves them):
    apair's closed form against its general solver (the homotopy), single Python calls on the same
    poses, one route after the other, and whether their solution sets agree where the general solver
    certifies its set (and at how many poses it does); and the batched C call."""
    count, batch = (30, 2000) if quick else (200, 20000)
    out = {}
    for name, ((a, alpha, d), at) in A_ARMS.items():
        R, A = apair.APair.revolute(), apair.APair(0.06, 0.05)
        chain = apair.AChain([A if i + 1 in at else R for i in range(6)], a=a, alpha=alpha, offset=d)
        lo, hi = np.array(chain.limits).T  # the pairs' collision-free ranges, ±π for the R-pairs
        general = Solver(chain)
        general._closed = None  # the route before the closed form
        rng = np.random.default_rng(42)
        q = rng.uniform(lo, hi, (count, 6))
        Ts = chain.fk(q)
        chain.ik(Ts[0])
        general.solve(Ts[0])
        times: dict[str, list[float]] = {"closed_form": [], "general": []}
        ours = []
        for T in Ts:  # each route over all poses in turn: the homotopy's threads and its 10 ms per pose would
            t0 = time.perf_counter()  # otherwise leave the closed form's single calls a cold cache
            ours.append(chain.ik(T))
            times["closed_form"].append(time.perf_counter() - t0)
        differ = certified = missing = 0
        for T, mine in zip(Ts, ours):
            t0 = time.perf_counter()
            theirs = general.solve(T)
            times["general"].append(time.perf_counter() - t0)
            certified += theirs.certified
            missing += not all(_among(s, mine, 4 * PI) for s in theirs.q)  # certified or not
            if theirs.certified and (len(mine) != len(theirs.q) or not all(_among(s, theirs.q, 4 * PI) for s in mine)):
                differ += 1
        row = {
            "median_us": {k: float(np.median(v) * 1e6) for k, v in times.items()},
            "sets_differ": differ,
            "general_certified": certified,
            "general_solutions_missing_from_closed_form": missing,
        }
        native, _ = native_module()
        if native is not None:  # the batched C call (apair_ik_parallel_apair) on `batch` poses, best of 3
            form = Solver(chain)._closed
            assert isinstance(form, ParallelAPair | ParallelSlides | WristAPair | WristSlide1), name
            entry = native.ik_wrist_apair if isinstance(form, WristAPair | WristSlide1) else native.ik_parallel_apair
            Tb = chain.fk(rng.uniform(lo, hi, (batch, 6)))
            best = min(_timed(lambda: entry(form.dh, form.amplitude, form.scale, Tb, 1e-9)) for _ in range(3))
            row["batched_us_per_pose"] = best / batch * 1e6
        out[name] = row
        med = row["median_us"]
        print(
            f"  {name:31s} single call: closed form {med['closed_form']:8.1f} µs, general solver "
            f"{med['general']:8.1f} µs; sets differ at {differ} of the {certified} (of {count}) poses it certifies, "
            f"its solutions missing from the closed form's at {missing}"
            + (f"; batched {row['batched_us_per_pose']:.1f} µs/pose" if "batched_us_per_pose" in row else ""),
            flush=True,
        )
    return out


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def targets(r: dict) -> list[dict]:
    """Issue 42's targets for the special R arms (spherical wrist, UR), the general 6R arms and the arms
    with A-pairs, each met or missed."""
    out = []
    for name, row in r["arms"].items():
        med = row["median_us"]
        ratio = med["apair"] / med["eaik"]
        out.append({"target": f"{name}: single call <= 0.5 x EAIK", "measured": ratio, "met": ratio <= 0.5})
        if "ik_geo" in med:
            ratio = med["apair"] / med["ik_geo"]
            out.append({"target": f"{name}: single call <= 1.0 x IK-Geo", "measured": ratio, "met": ratio <= 1.0})
        if "batched_us_per_pose" in row:
            b = row["batched_us_per_pose"]["apair"]
            out.append({"target": f"{name}: batched <= 1 µs per pose", "measured": b, "met": b <= 1.0})
        out.append(
            {
                "target": f"{name}: every EAIK solution among apair's",
                "measured": row["eaik_solutions_missing_from_apair"],
                "met": row["eaik_solutions_missing_from_apair"] == 0,
            }
        )
    general = r.get("general_6r", {})
    for name, row in general.get("designs", {}).items():
        us = row["median_us"]["apair"]
        out.append({"target": f"{name}: single call <= 0.3 ms (300 µs) per pose", "measured": us, "met": us <= 300.0})
        out.append(
            {
                "target": f"{name}: every pose's own joints among the answers",
                "measured": row["poses"] - row["own_joints_found"],
                "met": row["own_joints_found"] == row["poses"],
            }
        )
    if general.get("prepare_s"):
        worst = max(general["prepare_s"].values())
        out.append({"target": "prepare_ik <= 1 s on every 6R arm benched", "measured": worst, "met": worst <= 1.0})
    for name, row in r.get("a_pair_arms", {}).items():
        us = row["median_us"]["closed_form"]
        out.append({"target": f"{name}: <= 50 µs per pose", "measured": us, "met": us <= 50.0})
        out.append(
            {
                "target": f"{name}: the general solver's sets",
                "measured": row["sets_differ"],
                "met": row["sets_differ"] == 0,
            }
        )
        out.append(
            {
                "target": f"{name}: every general-solver solution among the closed form's",
                "measured": row["general_solutions_missing_from_closed_form"],
                "met": row["general_solutions_missing_from_closed_form"] == 0,
            }
        )
    return out
