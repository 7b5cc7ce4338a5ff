"""The dynamics' derivatives in the code generated for a user's chain (issue 39; `apair codegen
--kernels ...,inverse_dynamics_derivatives,forward_dynamics_derivatives`, `AChain.specialise`): on
a chain with A-pairs with legs, a prismatic pair and base and tool frames, the generated C (built
strictly, called through ctypes, single items and batches), its self-test, its NumPy module and
the specialised chain's fast path equal the runtime's AChain.inverse_dynamics_derivatives and
forward_dynamics_derivatives (generic kernels) to 1e-12; the derivatives are made only when named."""

from __future__ import annotations

import ctypes
import importlib.util
import json
import shutil
import subprocess

import numpy as np
import pytest

import apair
from apair import specialise
from apair.chain import METHODS

STRICT = ["-Wall", "-Wextra", "-Werror", "-pedantic"]
gcc = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is required")
KERNELS = ("mass_matrix", "inverse_dynamics_derivatives", "forward_dynamics_derivatives")
OUTPUTS = {"inverse_dynamics_derivatives": 2, "forward_dynamics_derivatives": 3, "mass_matrix": 1}


def _frame(rng, scale: float) -> np.ndarray:
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    T = np.eye(4)
    T[:3, :3] = Q * np.sign(np.linalg.det(Q))
    T[:3, 3] = rng.uniform(-scale, scale, 3)
    return T


def _link(rng) -> apair.Link:
    m = rng.uniform(0.5, 3.0)
    x, y, z = rng.uniform(0.05, 0.5, 3)
    principal = m / 12 * np.array([y * y + z * z, x * x + z * z, x * x + y * y])
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return apair.Link(m, rng.uniform(-0.3, 0.3, 3), Q @ np.diag(principal) @ Q.T)


def chain4() -> apair.AChain:
    """A sinusoidal and a general A-pair (a < b: a restricted range) with legs, a prismatic pair, an
    R-pair; base and tool
    frames with translations, gravity off the axes."""
    rng = np.random.default_rng(39)
    pairs = [
        apair.APair(0.12, 0.08, leg_mass=0.05),
        apair.APair(0.1, 0.15, leg_length=np.sqrt(0.5 * 0.1 * 0.15 + 0.1**2 + 0.15**2 / 4), leg_mass=0.03),
        apair.APair.prismatic(),
        apair.APair.revolute(),
    ]
    return apair.AChain(
        pairs,
        rng.uniform(-0.4, 0.4, 4),
        rng.uniform(-np.pi, np.pi, 4),
        rng.uniform(-0.2, 0.2, 4),
        rng.uniform(-np.pi, np.pi, 4),
        links=[_link(rng) for _ in range(4)],
        gravity=rng.normal(size=3) * 5,
        limits=[None, None, (-0.2, 0.3), None],
        base=_frame(rng, 0.5),
        tool=_frame(rng, 0.2),
    )


def states(chain, count, rng):
    lim = chain.limits
    mid, half = lim.mean(axis=1), (lim[:, 1] - lim[:, 0]) / 2
    q = mid + 0.95 * half * rng.uniform(-1, 1, (count, chain.n))
    return q, rng.normal(size=(count, chain.n)), rng.normal(size=(count, chain.n))


def close(got, want, tol=1e-12):
    """got = want to tol relative to the largest entry of each item (at least 1)."""
    got, want = np.asarray(got), np.asarray(want)
    assert got.shape == want.shape, (got.shape, want.shape)
    axes = tuple(range(1, want.ndim))
    scale = np.maximum(1.0, np.max(np.abs(want), axis=axes, keepdims=True))
    assert np.all(np.abs(got - want) <= tol * scale), np.max(np.abs(got - want) / scale)


def run(cmd, **kw):
    res = subprocess.run(cmd, capture_output=True, text=True, **kw)
    assert res.returncode == 0, f"{' '.join(map(str, cmd))} failed:\n{res.stdout}\n{res.stderr}"
    return res


def reference(chain, kernel, q, qd, x):
    """The runtime's outputs of the kernel (the generic kernels): as many as the kernel has."""
    if kernel == "mass_matrix":
        return (chain.mass_matrix(q),)
    return getattr(chain, kernel)(q, qd, x)[: OUTPUTS[kernel]]


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    chain = chain4()
    folder = tmp_path_factory.mktemp("d4")
    specialise.write_code(chain, folder, "d4", "d4.toml", kernels=KERNELS)
    return chain, folder


@pytest.mark.slow
@gcc
def test_generated_c_equals_the_runtime(generated, tmp_path):
    """Single items and batches of name_inverse_dynamics_derivatives and
    name_forward_dynamics_derivatives (ctypes) against the chain's methods, to 1e-12."""
    chain, folder = generated
    so = tmp_path / "libd4.so"
    run(["gcc", "-std=c99", *STRICT, "-O2", "-fPIC", "-shared", str(folder / "d4.c"), "-o", str(so), "-lm"])
    lib = ctypes.CDLL(str(so))
    ptr = lambda a: a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
    q, qd, x = states(chain, 25, np.random.default_rng(1))
    for kernel in KERNELS:
        ins = [np.ascontiguousarray(a) for a in ((q,) if kernel == "mass_matrix" else (q, qd, x))]
        want = reference(chain, kernel, q, qd, x)
        batch = [np.full((len(q), chain.n, chain.n), np.nan) for _ in want]
        fn = getattr(lib, f"d4_{kernel}_batch")
        fn.restype = None
        fn(ctypes.c_size_t(len(q)), *(ptr(a) for a in ins), *(ptr(o) for o in batch))
        one = getattr(lib, f"d4_{kernel}")
        one.restype = None
        for k in range(len(q)):
            single = [np.full((chain.n, chain.n), np.nan) for _ in want]
            one(*(ptr(np.ascontiguousarray(a[k])) for a in ins), *(ptr(o) for o in single))
            for s, w in zip(single, want):
                close(s[None], w[k : k + 1])
        for b, w in zip(batch, want):
            close(b, w)


@pytest.mark.slow
@gcc
def test_selftest_checks_every_output(generated, tmp_path):
    """The self-test builds strictly (C99 and C++17), passes, checks each output of the derivative
    kernels; one whose reference of ∂q''/∂q' is off fails, naming that output."""
    chain, folder = generated
    source = (folder / "d4_selftest.c").read_text()
    for output in ("dtau_dq", "dtau_dqd", "dqdd_dq", "dqdd_dqd", "Minv"):
        assert f"want_{output}[" in source, output
    for lang, cc, x in (("c99", "gcc", []), ("c++17", "g++", ["-x", "c++"])):
        if shutil.which(cc) is None:
            continue
        exe = tmp_path / f"selftest_{lang}"
        run(
            [
                cc,
                *x,
                f"-std={lang}",
                *STRICT,
                "-O2",
                str(folder / "d4_selftest.c"),
                str(folder / "d4.c"),
                "-o",
                str(exe),
                "-lm",
            ]
        )
        out = run([str(exe)]).stdout
        assert "48 checks passed (3 kernels, 4 states)" in out, out  # (1 + 2 + 3) outputs, single and batch
    bad = tmp_path / "bad"
    shutil.copytree(folder, bad)
    start = source.index("want_dqdd_dqd[")
    first = source[start:].split("{\n", 1)[1].split(",")[0].strip()
    (bad / "d4_selftest.c").write_text(source[:start] + source[start:].replace(first, f"{first} + 1e-6", 1))
    exe = tmp_path / "bad_selftest"
    run(["gcc", "-std=c99", "-O2", str(bad / "d4_selftest.c"), str(bad / "d4.c"), "-o", str(exe), "-lm"])
    res = subprocess.run([str(exe)], capture_output=True, text=True)
    assert res.returncode == 1 and "d4_forward_dynamics_derivatives dqdd_dqd (single), state 0" in res.stdout


@pytest.mark.slow
def test_header_manifest_and_numpy_module(generated):
    chain, folder = generated
    header = (folder / "d4.h").read_text()
    for decl in (
        "void d4_inverse_dynamics_derivatives(const double q[4], const double qd[4], const double qdd[4], "
        "double dtau_dq[16], double dtau_dqd[16]);",
        "void d4_forward_dynamics_derivatives(const double q[4], const double qd[4], const double tau[4], "
        "double dqdd_dq[16], double dqdd_dqd[16], double Minv[16]);",
        "void d4_forward_dynamics_derivatives_batch(size_t count,",
    ):
        assert decl in header, decl
    assert "dddd" not in header  # d''' of the laws is built in, from q
    manifest = json.loads((folder / "manifest.json").read_text())
    assert [o["name"] for o in manifest["kernels"]["forward_dynamics_derivatives"]["outputs"]] == [
        "dqdd_dq",
        "dqdd_dqd",
        "Minv",
    ]
    spec = importlib.util.spec_from_file_location("d4_module", folder / "d4.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    q, qd, x = states(chain, 10, np.random.default_rng(2))
    for kernel in KERNELS[1:]:
        got = getattr(module, kernel)(q, qd, x)
        for g, w in zip(got, reference(chain, kernel, q, qd, x), strict=True):
            close(np.reshape(g, w.shape), w)


def test_derivatives_are_made_only_when_named():
    chain = chain4()
    assert "inverse_dynamics_derivatives" not in specialise.check_kernels(None)
    assert specialise.check_kernels(["forward_dynamics_derivatives", "fk"]) == ("fk", "forward_dynamics_derivatives")
    with pytest.raises(ValueError, match="^kernels: expected names from .*inverse_dynamics_derivatives"):
        specialise.check_kernels(["jacobian_dot"])
    hashes = {specialise.content_hash(chain, k) for k in (None, KERNELS, KERNELS[:2])}
    assert len(hashes) == 3


@pytest.mark.slow
@gcc
def test_specialised_chain_runs_them_natively():
    """chain.specialise(kernels) with the derivatives: single calls on the specialised fast path
    (the methods not chosen on the generic kernels, natively too), batches and lists, against the
    generic kernels (NumPy backend, independent of both native paths); bad input still refused."""
    chain = chain4()
    fast = chain.specialise(KERNELS)
    assert fast.specialised
    index = {family: i for i, (family, _) in enumerate(METHODS)}
    q, qd, x = states(chain, 12, np.random.default_rng(3))
    methods = ("inverse_dynamics_derivatives", "forward_dynamics_derivatives", "mass_matrix", "jacobian_dot", "energy")
    apair.set_backend("numpy")
    try:
        want = {
            m: getattr(chain, m)(
                *((q,) if m == "mass_matrix" else (q, qd) if m in ("jacobian_dot", "energy") else (q, qd, x))
            )
            for m in methods
        }
    finally:
        apair.set_backend(None)
    for m in methods:
        args = (q,) if m == "mass_matrix" else (q, qd) if m in ("jacobian_dot", "energy") else (q, qd, x)
        got = getattr(fast, m)(*args)  # (after set_backend, the first kernel call enables the fast path)
        assert fast._fast.call(index[m], *(a[4] for a in args)) is not None, m
        single = getattr(fast, m)(*(a[4] for a in args))
        listed = getattr(fast, m)(*(a[4].tolist() for a in args))
        for g, s, lst, w in zip(
            *(r if isinstance(r, tuple) else (r,) for r in (got, single, listed, want[m])), strict=True
        ):
            close(g, w)
            close(s[None], w[4:5])
            close(lst[None], w[4:5])
    z = np.zeros(chain.n)
    with pytest.raises(ValueError, match=r"^qd: .*NaN"):
        fast.forward_dynamics_derivatives(z, np.full(chain.n, np.nan), z)
    with pytest.raises(ValueError, match=r"^q: a joint is at its pair's limit"):
        fast.inverse_dynamics_derivatives(np.array([0.0, chain.pairs[1].theta_limit, 0.0, 0.0]), z, z)
