"""The generated 7-joint kernels (fk7, jacobian7, mass_matrix7, bias7, gravity7, inverse_dynamics7,
forward_dynamics7, energy7) against Pinocchio on the Panda imported by apair.load_urdf, through the
C extension and the generated NumPy kernels, at random q inside the limits."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest
from chain7_robots import panda, pin, relative

from apair import kernels

TOL = 1e-10


@pytest.fixture(params=["c", "numpy"])
def backend(request: pytest.FixtureRequest) -> Iterator[str]:
    if request.param == "c" and not kernels.c_available():
        pytest.skip("the C extension is not built")
    kernels.set_backend(request.param)
    yield request.param
    kernels.set_backend(None)


@pytest.mark.parametrize("tip", ["panda_link8", "panda_link7"])
def test_panda_seven_joints_agree_with_pinocchio(backend: str, tip: str) -> None:
    P = panda(tip)
    chain, model, data = P.chain, P.model, P.data
    assert chain.n == 7
    order = P.order()
    rng = np.random.default_rng(7)
    lim = chain.limits
    worst: dict[str, float] = {}
    for _ in range(12):
        q = rng.uniform(lim[:, 0], lim[:, 1])
        qd, qdd = rng.normal(size=(2, 7))
        qp = P.pin_q(q)
        v, a = np.zeros(7), np.zeros(7)
        v[order], a[order] = qd, qdd
        pin.forwardKinematics(model, data, qp, v)
        pin.updateFramePlacements(model, data)
        M = pin.crba(model, data, qp)
        M = (np.triu(M) + np.triu(M, 1).T)[np.ix_(order, order)]
        tau = pin.rnea(model, data, qp, v, a)[order]
        ref = {
            "fk": data.oMf[P.frame].homogeneous,
            "jacobian": pin.computeFrameJacobian(model, data, qp, P.frame, pin.LOCAL_WORLD_ALIGNED)[:, order],
            "mass_matrix": M,
            "inverse_dynamics": tau,
            "bias": pin.rnea(model, data, qp, v, np.zeros(7))[order],
            "gravity": pin.computeGeneralizedGravity(model, data, qp)[order],
            "forward_dynamics": qdd,  # aba's input torques are tau: qdd comes back
            "kinetic": pin.computeKineticEnergy(model, data, qp, v),
        }
        got = {
            "fk": chain.fk(q),
            "jacobian": chain.jacobian(q),
            "mass_matrix": chain.mass_matrix(q),
            "inverse_dynamics": chain.inverse_dynamics(q, qd, qdd),
            "bias": chain.bias(q, qd),
            "gravity": chain.gravity_torques(q),
            "forward_dynamics": chain.forward_dynamics(q, qd, tau),
            "kinetic": chain.energy(q, qd)[0],
        }
        aba = pin.aba(model, data, qp, v, pin.rnea(model, data, qp, v, a))[order]
        assert relative(aba, qdd) < 1e-9  # the oracle itself closes the loop
        for key in ref:
            worst[key] = max(worst.get(key, 0.0), relative(got[key], ref[key]))
    print(backend, tip, worst)
    for key, err in worst.items():
        assert err < TOL, (key, err)


def test_generated_seven_joint_kernels_are_listed() -> None:
    names = set(kernels.manifest()["kernels"])
    for family in ("fk", "fk_study", "jacobian", "mass_matrix", "coriolis", "gravity", "bias", "energy"):
        assert f"{family}7" in names
    assert {"inverse_dynamics7", "forward_dynamics7"} <= names
    assert "fk8" not in names
